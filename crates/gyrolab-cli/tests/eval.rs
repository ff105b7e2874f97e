//! `gyrolab eval` and `gyrolab demo --out`: the report folder, results.json snapshot for the
//! paper's plan, exit code 3 on a failed limit, plan errors (exit 2, key and line named), and a
//! report that references no external resource.

mod common;
use common::{gyrolab, write};
use std::path::{Path, PathBuf};

fn example_plan() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/paper_plan.toml")
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// Every way a report could fetch something from outside: URLs in attributes, scripts,
/// CSS imports and url() references.
fn assert_self_contained(html: &str) {
    let lower = html.to_lowercase();
    for bad in ["http://", "https://", "<script", "@import", "url(", "<link", "<iframe", "<object", "<embed", "<img"] {
        assert!(!lower.contains(bad), "the report contains '{bad}'");
    }
    for attr in ["src=", "href=", "xlink:href="] {
        for (i, _) in lower.match_indices(attr) {
            let value = &lower[i + attr.len()..];
            let value = value.trim_start_matches(['"', '\'']);
            assert!(value.starts_with('#'), "{attr} is not a fragment link: {}", &value[..value.len().min(60)]);
            assert!(!value.starts_with("//"));
        }
    }
}

#[test]
fn paper_plan_writes_every_output_and_fails_its_limits_with_exit_3() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("report");
    let a = gyrolab().arg("eval").arg(example_plan()).arg("--out").arg(&out).assert().code(3);
    let o = a.get_output();
    let stdout = String::from_utf8_lossy(&o.stdout);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(stdout.contains("Spec limits: FAIL"), "{stdout}");
    assert!(stderr.starts_with("FAIL: 3 spec limit check(s) failed"), "{stderr}");
    assert!(stderr.contains("axis x: linearity_pct = 5.543 % FS (limit ≤ 0.02)"), "{stderr}");
    assert!(!stderr.contains("panicked"));
    for f in [
        "report.html",
        "results.json",
        "calibration.toml",
        "summary.csv",
        "points_x.csv",
        "points_z.csv",
        "scale_factor_runs.csv",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let cal = gyrolab_io::calibration::read_calibration(&out.join("calibration.toml")).unwrap();
    assert_eq!(cal.axes.len(), 3);
    let html = read(&out.join("report.html"));
    assert_self_contained(&html);
    assert!(html.contains("<span class=\"verdict FAIL\">FAIL</span>"));
    assert!(html.contains("<span class=\"verdict PASS\">PASS</span>"));
    assert!(html.contains("<span class=\"verdict NOT_EVALUATED\">NOT EVALUATED</span>"));
    assert_eq!(html.matches("<svg class=\"plot\"").count(), 9, "three plots per axis");
    let summary = read(&out.join("summary.csv"));
    assert!(summary.contains("x,linearity_pct,% FS,5.5432247913663435,,0.02,FAIL"), "{summary}");
    assert!(summary.contains("z,bias_stability_dph_10s,deg/h,,,20,NOT EVALUATED"), "{summary}");
}

#[test]
fn results_json_snapshot_of_the_paper_plan() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r");
    gyrolab().arg("eval").arg(example_plan()).arg("--out").arg(&out).arg("--quiet").assert().code(3).stdout("");
    let v: serde_json::Value = serde_json::from_str(&read(&out.join("results.json"))).unwrap();
    insta::assert_json_snapshot!("paper_plan_results", v, {
        ".created" => "[time]",
        ".plan_file" => "[path]",
        ".gyrolab_version" => "[version]",
    });
}

#[test]
fn passing_limits_exit_0_and_quiet_prints_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let text = read(&example_plan())
        .replace("../data/paper/", &format!("{}/", common::paper("").display()))
        .replace("linearity_pct = { max = 0.02 }", "linearity_pct = { max = 6 }");
    let plan = write(dir.path(), "plan.toml", &text);
    let out = dir.path().join("out");
    gyrolab().arg("eval").arg(&plan).arg("--out").arg(&out).arg("-q").assert().code(0).stdout("").stderr("");
    let v: serde_json::Value = serde_json::from_str(&read(&out.join("results.json"))).unwrap();
    assert_eq!(v["verdict"], "PASS");
}

fn plan_error(edit: impl Fn(&str) -> String) -> String {
    let dir = tempfile::tempdir().unwrap();
    let text = read(&example_plan()).replace("../data/paper/", &format!("{}/", common::paper("").display()));
    let plan = write(dir.path(), "plan.toml", &edit(&text));
    let out = gyrolab().arg("eval").arg(&plan).arg("--out").arg(dir.path().join("o")).assert().code(2);
    let err = String::from_utf8_lossy(&out.get_output().stderr).into_owned();
    assert!(err.starts_with("error: ") && err.contains("plan.toml:"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(!dir.path().join("o").exists(), "nothing written on a plan error");
    err
}

fn line_of(text: &str, needle: &str) -> usize {
    read(&example_plan()).lines().position(|l| l.contains(needle)).map(|i| i + 1).unwrap_or_else(|| panic!("{text}"))
}

#[test]
fn plan_errors_name_key_and_line() {
    let l = line_of("", "coverage = 3");
    let e = plan_error(|t| t.replace("coverage = 3", "covrage = 3"));
    assert!(e.contains(&format!("plan.toml:{l}:")) && e.contains("covrage"), "{e}");

    let l = line_of("", "[rate.y]") + 1;
    let e = plan_error(|t| t.replace("paper_rate_table_y.csv", "missing_y.csv"));
    assert!(e.contains(&format!("plan.toml:{l}:")) && e.contains("rate.y.file") && e.contains("missing_y.csv"), "{e}");

    let l = line_of("", "[rate.z]") + 1;
    let e =
        plan_error(|t| t.replace("paper_rate_table_z.csv\"", "paper_rate_table_z.csv\"\noutput_unit = \"furlongs\""));
    assert!(
        e.contains(&format!("plan.toml:{}:", l + 1))
            && e.contains("rate.z.output_unit: unknown output unit 'furlongs'"),
        "{e}"
    );

    let l = line_of("", "hysteresis_pct = { max = 1.0 }");
    let e = plan_error(|t| t.replace("hysteresis_pct = { max = 1.0 }", "hysteresis = { max = 1.0 }"));
    assert!(
        e.contains(&format!("plan.toml:{l}:")) && e.contains("limits.hysteresis: 'hysteresis' is not a figure"),
        "{e}"
    );
}

#[test]
fn demo_out_writes_the_papers_report() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("demo");
    gyrolab().arg("demo").arg("--out").arg(&out).arg("--quiet").assert().code(0).stdout("");
    let html = read(&out.join("report.html"));
    assert_self_contained(&html);
    assert!(html.contains("The paper&#39;s printed tables beside the recomputation"));
    assert!(html.contains("Axis z: rate-table test"));
    let v: serde_json::Value = serde_json::from_str(&read(&out.join("results.json"))).unwrap();
    assert_eq!(v["rate_axes"].as_array().unwrap().len(), 3);
    assert!(v["verdict"].is_null());
    assert_eq!(v["sections"]["paper"]["table2_x"].as_array().unwrap().len(), 14);
    // Same inputs, same report apart from the time stamp.
    let out2 = dir.path().join("demo2");
    gyrolab().arg("demo").arg("--out").arg(&out2).arg("--quiet").assert().code(0);
    let strip = |s: String| s.lines().filter(|l| !l.contains("<td><b>date</b>")).collect::<Vec<_>>().join("\n");
    assert_eq!(strip(html), strip(read(&out2.join("report.html"))));
}
