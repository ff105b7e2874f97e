//! `gyrolab bias` end to end: JSON keys, repeatability of known offsets, calibration files,
//! and bad input.

mod common;
use approx::assert_relative_eq;
use common::{gyrolab, paper, write};

/// A static record at 10 Hz: null + offset + a fixed zero-mean pattern (so means are exact).
fn record(offset_v: f64, n: usize) -> String {
    let mut s = String::from("# synthetic static test\ntime_s,output_v\n");
    for i in 0..n {
        let pattern = [0.001, -0.002, 0.0005, 0.0005][i % 4];
        s.push_str(&format!("{},{}\n", i as f64 * 0.1, 2.5 + offset_v + pattern));
    }
    s
}

#[test]
fn repeatability_of_known_offsets() {
    let dir = tempfile::tempdir().unwrap();
    // Offsets of 0, 1e-4, -1e-4, 2e-4 V with K = 0.0075 V/(deg/s): biases 0, 48, -48, 96 deg/h.
    let offsets = [0.0, 1e-4, -1e-4, 2e-4];
    let files: Vec<_> =
        offsets.iter().enumerate().map(|(i, o)| write(dir.path(), &format!("t{i}.csv"), &record(*o, 4000))).collect();
    let out = gyrolab()
        .args(["bias", "--json", "--scale-factor", "0.0075", "--null", "2.5"])
        .args(&files)
        .assert()
        .success()
        .get_output()
        .stdout
        .clone();
    let v: serde_json::Value = serde_json::from_slice(&out).unwrap();
    let tests = v["tests"].as_array().unwrap();
    assert_eq!(tests.len(), 4);
    let b: Vec<f64> = offsets.iter().map(|o| o / 0.0075 * 3600.0).collect();
    let mean = b.iter().sum::<f64>() / 4.0;
    let sd = (b.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / 3.0).sqrt();
    assert_relative_eq!(v["bias_repeatability_dph"].as_f64().unwrap(), sd, max_relative = 1e-6);
    let t = &tests[1];
    for key in ["file", "channel", "samples", "mean_output", "bias_dps", "drift_dph_per_h"] {
        assert!(!t[key].is_null(), "{key}: {t}");
    }
    assert_eq!(t["samples"], 4000);
    assert_relative_eq!(t["mean_output"].as_f64().unwrap(), 2.5001, max_relative = 1e-12);
    assert_relative_eq!(t["bias_dps"].as_f64().unwrap(), 1e-4 / 0.0075, max_relative = 1e-6);
    // Windows of 10 samples (1 s) average the 4-sample pattern unevenly; 4-sample windows do not
    // exist, but at 100 s the window means are all equal.
    let stab = t["bias_stability_dph"].as_object().unwrap();
    assert!(stab.contains_key("1") && stab.contains_key("10") && stab.contains_key("0.1"), "{stab:?}");
    assert!(!stab.contains_key("100"), "only 4 windows of 100 s fit: {stab:?}");
}

#[test]
fn calibration_file_from_rate_gives_the_reference() {
    let dir = tempfile::tempdir().unwrap();
    let cal = dir.path().join("cal.toml");
    gyrolab()
        .args(["rate", "--axis", "x"])
        .arg(paper("paper_rate_table_x.csv"))
        .arg("--cal-out")
        .arg(&cal)
        .assert()
        .success();
    let f = write(dir.path(), "s.csv", &record(0.0, 400));
    let out =
        gyrolab().args(["bias", "--json", "--cal"]).arg(&cal).arg(&f).assert().success().get_output().stdout.clone();
    let v: serde_json::Value = serde_json::from_slice(&out).unwrap();
    let k = v["tests"][0]["scale_factor_output_per_dps"].as_f64().unwrap();
    assert_relative_eq!(k, 0.0075616, epsilon = 5e-8);
    // A file in mV uses the same calibration converted to mV.
    let mv = record(0.0, 400)
        .replace("output_v", "output_mv")
        .lines()
        .map(|l| match l.split_once(',') {
            Some((t, v)) if !l.starts_with('#') && !l.starts_with("time") => {
                format!("{t},{}", v.parse::<f64>().unwrap() * 1e3)
            }
            _ => l.to_string(),
        })
        .collect::<Vec<_>>()
        .join("\n");
    let fm = write(dir.path(), "mv.csv", &mv);
    let out =
        gyrolab().args(["bias", "--json", "--cal"]).arg(&cal).arg(&fm).assert().success().get_output().stdout.clone();
    let w: serde_json::Value = serde_json::from_slice(&out).unwrap();
    assert_relative_eq!(
        w["tests"][0]["bias_dps"].as_f64().unwrap(),
        v["tests"][0]["bias_dps"].as_f64().unwrap(),
        max_relative = 1e-9
    );
}

fn bias_error(text: &str, extra: &[&str]) -> String {
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "bad.csv", text);
    let out = gyrolab().arg("bias").args(extra).arg(&p).assert().code(2).get_output().clone();
    let e = String::from_utf8(out.stderr).unwrap();
    assert!(e.starts_with("error: ") && e.contains("bad.csv") && !e.contains("panicked"), "{e}");
    e
}

#[test]
fn bad_inputs() {
    let e = bias_error("time_s,output_v\n0,1\n0.1,abc\n", &[]);
    assert!(e.contains("bad.csv:3:2"), "{e}");
    let e = bias_error("time_s,output_v\n0,1\n0.1,1,3\n", &[]);
    assert!(e.contains("bad.csv:3"), "{e}");
    let e = bias_error("time_s,output_v\n0,1\n0.1,NaN\n", &[]);
    assert!(e.contains("bad.csv:3:2"), "{e}");
    let e = bias_error("", &[]);
    assert!(e.contains("empty"), "{e}");
    let e = bias_error("output_v\n1\n2\n", &[]);
    assert!(e.contains("sample rate") || e.contains("time"), "{e}");
    // A selected column whose bracketed unit is unknown (an unknown suffix is no unit at all).
    let e = bias_error("time_s,output [amps]\n0,1\n", &["--column", "output"]);
    assert!(e.contains("bad.csv:1:2") && e.contains("unknown unit 'amps'"), "{e}");
}

#[test]
fn gaps_and_unsorted_time_are_reported_with_lines() {
    let dir = tempfile::tempdir().unwrap();
    let mut s = String::from("time_s,output_v\n");
    for i in 0..200 {
        let t = if i == 50 {
            4.85
        } else if i >= 100 {
            i as f64 * 0.1 + 1.0
        } else {
            i as f64 * 0.1
        };
        s.push_str(&format!("{t},2.5\n"));
    }
    let p = write(dir.path(), "g.csv", &s);
    let out = gyrolab().args(["bias", "--sample-rate-hz", "10"]).arg(&p).assert().success().get_output().clone();
    let e = String::from_utf8(out.stderr).unwrap();
    assert!(e.contains("time gaps"), "{e}");
    assert!(e.contains("decreasing time stamps, first at line 52"), "{e}");
}

#[test]
fn short_record_and_bad_options() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "short.csv", &record(0.0, 30));
    let out = gyrolab().args(["bias", "--json"]).arg(&p).assert().success().get_output().clone();
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let skipped = v["tests"][0]["bias_stability_skipped"].as_array().unwrap();
    assert!(skipped.iter().any(|s| s["smoothing_s"] == 10.0), "{skipped:?}");
    gyrolab().args(["bias", "--smoothing", "0"]).arg(&p).assert().code(2);
    gyrolab().args(["bias", "--latitude", "95"]).arg(&p).assert().code(2);
    gyrolab().args(["bias", "--null", "2.5"]).arg(&p).assert().code(2);
    gyrolab().args(["bias", "--scale-factor", "0"]).arg(&p).assert().code(2);
}
