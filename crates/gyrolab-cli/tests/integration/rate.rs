//! `gyrolab rate` and `gyrolab demo` end to end.

use crate::common;
use approx::assert_relative_eq;
use common::{gyrolab, paper, write};
use predicates::str::contains;

#[test]
fn demo_shows_the_paper_comparison() {
    let out = gyrolab().arg("demo").assert().success().get_output().stdout.clone();
    let s = String::from_utf8(out).unwrap();
    assert!(s.contains("7.5616"), "{s}");
    assert!(s.contains("NO: forward mean, mean"));
    assert!(s.contains("Rows 11 (135 deg/s), 14 (300 deg/s) do not reproduce"));
    assert!(s.contains("rounds to 7.6, not the printed 7.5"));
    assert!(s.contains("saturates"));
}

#[test]
fn demo_json_is_valid() {
    let out = gyrolab().args(["demo", "--json"]).assert().success().get_output().stdout.clone();
    let v: serde_json::Value = serde_json::from_slice(&out).unwrap();
    assert_eq!(v["rate"]["axes"].as_array().unwrap().len(), 3);
    let t6 = v["table6"].as_array().unwrap();
    assert!(t6.iter().any(|r| r["axis"] == "y" && r["figure"] == "scale factor" && r["supported"] == false));
}

#[test]
fn rate_json_has_the_documented_keys() {
    let out = gyrolab()
        .args(["rate", "--json", "--axis", "x", "--axis", "y"])
        .arg(paper("paper_rate_table_x.csv"))
        .arg(paper("paper_rate_table_y.csv"))
        .assert()
        .success()
        .get_output()
        .stdout
        .clone();
    let v: serde_json::Value = serde_json::from_slice(&out).unwrap();
    let axes = v["axes"].as_array().unwrap();
    assert_eq!(axes.len(), 2);
    let x = &axes[0];
    assert_eq!(x["name"], "x");
    assert_eq!(x["output_unit"], "V");
    for key in [
        "scale_factor",
        "zero_offset",
        "nonlinearity_pct",
        "linearity_pct",
        "hysteresis_pct",
        "repeatability_pct",
        "accuracy_pct",
        "accuracy_rss_pct",
        "asymmetry_pct",
        "scale_factor_repeatability_pct",
    ] {
        assert!(x[key].is_number(), "{key} missing: {x}");
    }
    assert_relative_eq!(x["scale_factor"].as_f64().unwrap(), 0.0075616, epsilon = 5e-8);
    let p = &x["points"][0];
    for key in ["rate_dps", "fwd_mean", "rev_mean", "mean"] {
        assert!(p[key].is_number(), "{key}");
    }
    assert_eq!(p["rate_dps"], -300.0);
}

#[test]
fn rate_text_table_and_options() {
    gyrolab()
        .args(["rate", "--points", "--order", "3", "--nonlinearity-limit", "5", "--coverage", "2"])
        .arg(paper("paper_rate_table_x.csv"))
        .assert()
        .success()
        .stdout(contains("paper_rate_table_x"))
        .stdout(contains("repeatability (k = 2)"))
        .stdout(contains("linear range (K_a <= 5 %)"))
        .stdout(contains("polynomial RMS residual"))
        .stdout(contains("per-point means"));
}

#[test]
fn cal_out_writes_a_readable_calibration() {
    let dir = tempfile::tempdir().unwrap();
    let cal = dir.path().join("cal.toml");
    gyrolab()
        .args(["rate", "--axis", "x"])
        .arg(paper("paper_rate_table_x.csv"))
        .arg("--cal-out")
        .arg(&cal)
        .assert()
        .success();
    let c = gyrolab_io_read(&cal);
    assert!(c.contains("name = \"x\""), "{c}");
    assert!(c.contains("scale_factor = 0.00756"), "{c}");
    assert!(c.contains("created = \"20"), "{c}");
}

fn gyrolab_io_read(p: &std::path::Path) -> String {
    std::fs::read_to_string(p).unwrap()
}

#[test]
fn unit_of_output_scales_k() {
    // The same record in mV gives K a thousand times larger.
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(paper("paper_rate_table_x.csv")).unwrap();
    let mv: String = text
        .lines()
        .map(|l| {
            if l.starts_with('#') || l.starts_with("rate") {
                l.replace("output_v", "output_mv")
            } else {
                let mut f: Vec<String> = l.split(',').map(str::to_string).collect();
                let v: f64 = f[3].parse().unwrap();
                f[3] = format!("{}", v * 1000.0);
                f.join(",")
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    let p = write(dir.path(), "x_mv.csv", &mv);
    let out = gyrolab().args(["rate", "--json"]).arg(&p).assert().success().get_output().stdout.clone();
    let v: serde_json::Value = serde_json::from_slice(&out).unwrap();
    assert_eq!(v["axes"][0]["output_unit"], "mV");
    assert_relative_eq!(v["axes"][0]["scale_factor"].as_f64().unwrap(), 7.5616, epsilon = 5e-5);
}
