//! Threshold and resolution in a test plan: `[rate.x]` the paper's table 1 record, plus the
//! simulated threshold and resolution records of `program_sim::threshold` (a known dead zone);
//! the threshold recovered between the tried rates that bracket the dead zone, the report
//! section, results.json and limits; bad plans give errors naming the key and its line.

use gyrolab::limits::Overall;
use gyrolab_eval::program_sim::threshold::{
    write_threshold_records, BASE_RATE_DPS, DEAD_ZONE_DPS, RESOLUTION_STEPS_DPS, THRESHOLD_RATES_DPS,
};
use gyrolab_eval::progress::Silent;
use gyrolab_eval::EvalError;
use gyrolab_lab::report_folder::ReportFolder;
use gyrolab_lab::test_plan::{evaluate_test_plan, read_test_plan};
use std::path::{Path, PathBuf};

fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn output<'a>(folder: &'a ReportFolder, name: &str) -> &'a [u8] {
    &folder.outputs.iter().find(|o| o.name == name).unwrap_or_else(|| panic!("no {name}")).bytes
}

const HEAD: &str = r#"[device]
model = "ADXRS646 (simulated threshold)"
serial = "TH-1"
axes = ["x"]

[rate.x]
file = "rate_x.csv"

[limits]
threshold_dps = { max = 0.15 }
resolution_dps = { max = 0.1 }

"#;

/// A folder with the paper's x record, the simulated records and `plan` written as plan.toml.
fn folder(plan: &str, seed: u64) -> (tempfile::TempDir, PathBuf, String) {
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(repo_root().join("data/paper/paper_rate_table_x.csv"), dir.path().join("rate_x.csv")).unwrap();
    let sections = write_threshold_records(dir.path(), "x", seed).unwrap();
    let text = plan.replace("{SECTIONS}", &sections);
    let p = dir.path().join("plan.toml");
    std::fs::write(&p, &text).unwrap();
    (dir, p, text)
}

/// 1-based line of the first line of `text` that starts with `prefix`.
fn line_of(text: &str, prefix: &str) -> u64 {
    text.lines().position(|l| l.trim_start().starts_with(prefix)).expect("line present") as u64 + 1
}

fn located(e: &EvalError) -> (String, Option<u64>) {
    match e {
        EvalError::Data(d) => (d.to_string(), d.line),
        other => (other.to_string(), None),
    }
}

#[test]
fn threshold_is_recovered_between_the_tried_rates_that_bracket_the_dead_zone() {
    for seed in [1, 2] {
        let (_dir, p, _) = folder(&format!("{HEAD}{{SECTIONS}}"), seed);
        let plan = read_test_plan(&p).unwrap();
        assert_eq!((plan.threshold.len(), plan.resolution.len()), (1, 1));
        let f = evaluate_test_plan(&plan, "plan.toml", &Silent).unwrap();
        let json: serde_json::Value = serde_json::from_slice(output(&f, "results.json")).unwrap();
        let t = &json["sections"]["threshold"]["x"];
        // The truth: the smallest tried rate at or above the dead zone, the largest below it.
        let at = THRESHOLD_RATES_DPS.iter().copied().find(|&r| r >= DEAD_ZONE_DPS).unwrap();
        let below = THRESHOLD_RATES_DPS.iter().copied().filter(|&r| r < DEAD_ZONE_DPS).fold(0.0, f64::max);
        assert_eq!(t["threshold_support"], "value", "{t}");
        assert_eq!(t["threshold_dps"].as_f64(), Some(at), "{t}");
        assert_eq!(t["above_dps"].as_f64(), Some(below), "{t}");
        let rows = t["rates_tried"].as_array().unwrap();
        assert_eq!(rows.len(), 2 * THRESHOLD_RATES_DPS.len());
        for r in rows {
            let rate = r["rate_dps"].as_f64().unwrap();
            let ratio = r["ratio"].as_f64().unwrap();
            // Inside the dead zone no output change (ratio 0); outside the full K rate (ratio 1,
            // K from the paper's fit of a sensor with K = 7.5 mV/(deg/s) within a few per cent).
            // Noise of the difference of two 20 s means: white 0.1 deg/s per sample / sqrt(2000)
            // x sqrt(2) = 0.0032 deg/s, flicker about sqrt(2) x 0.6643 x 12 deg/h = 0.003 deg/s;
            // 4 sigma of both is below 0.02 deg/s.
            let want = if rate.abs() >= DEAD_ZONE_DPS { 1.0 } else { 0.0 };
            assert!((ratio - want).abs() < 0.02 / rate.abs() + 0.05, "{r}");
            assert_eq!(r["pass"], rate.abs() >= DEAD_ZONE_DPS, "{r}");
            for k in ["mean_output", "output_change", "expected_change", "marginal", "mean_output_std_error"] {
                assert!(!r[k].is_null(), "{k} in {r}");
            }
        }
        let r = &json["sections"]["resolution"]["x"];
        assert_eq!(r["resolution_support"], "upper_bound", "{r}");
        assert_eq!(r["resolution_dps"].as_f64(), Some(RESOLUTION_STEPS_DPS[0]), "{r}");
        assert_eq!(r["base_rate_dps"].as_f64(), Some(BASE_RATE_DPS));
        assert_eq!(r["rates_tried"].as_array().unwrap().len(), 2 * RESOLUTION_STEPS_DPS.len());
        // Summary figures and limits: 0.12 <= 0.15 and 0.05 <= 0.1.
        assert_eq!(f.verdict, Some(Overall::Pass), "{:?}", f.failures);
        let html = String::from_utf8(output(&f, "report.html").to_vec()).unwrap();
        assert!(html.contains("Threshold and resolution"));
        assert!(html.contains("at most 0.05 deg/s"), "the resolution's bound is stated");
        assert!(html.contains("SIMULATED"));
        let csv = String::from_utf8(output(&f, "threshold_resolution.csv").to_vec()).unwrap();
        assert!(csv.starts_with("# SIMULATED DATA: "), "{csv}");
        assert_eq!(csv.lines().count(), 2 + 2 * (THRESHOLD_RATES_DPS.len() + RESOLUTION_STEPS_DPS.len()));
    }
}

#[test]
fn a_limit_below_the_threshold_fails() {
    let (_dir, p, _) = folder(&format!("{}{{SECTIONS}}", HEAD.replace("max = 0.15", "max = 0.1")), 3);
    let f = evaluate_test_plan(&read_test_plan(&p).unwrap(), "plan.toml", &Silent).unwrap();
    assert_eq!(f.verdict, Some(Overall::Fail));
    assert!(f.failures.iter().any(|m| m.contains("threshold_dps")), "{:?}", f.failures);
}

#[test]
fn an_axis_with_only_a_threshold_test_and_a_given_scale_factor() {
    let plan = r#"[device]
model = "m"
serial = "s"
axes = ["x"]

[threshold.x]
file = "threshold_x.csv"
scale_factor = 0.0075
"#;
    let (_dir, p, _) = folder(plan, 4);
    let f = evaluate_test_plan(&read_test_plan(&p).unwrap(), "plan.toml", &Silent).unwrap();
    let json: serde_json::Value = serde_json::from_slice(output(&f, "results.json")).unwrap();
    let t = &json["sections"]["threshold"]["x"];
    assert_eq!(t["scale_factor"].as_f64(), Some(0.0075));
    assert_eq!(t["threshold_dps"].as_f64(), THRESHOLD_RATES_DPS.iter().copied().find(|&r| r >= DEAD_ZONE_DPS));
}

#[test]
fn bad_plans_name_the_key_and_its_line() {
    let good = format!("{HEAD}{{SECTIONS}}");
    let parse_err = |plan: &str| {
        let (_dir, p, text) = folder(plan, 5);
        (located(&read_test_plan(&p).unwrap_err()), text)
    };
    // The threshold file is missing.
    let plan = format!("{HEAD}[threshold.x]\nfile = \"nope.csv\"\n");
    let ((msg, line), text) = parse_err(&plan);
    assert!(msg.contains("threshold.x.file") && msg.contains("nope.csv") && msg.contains("not found"), "{msg}");
    assert_eq!(line, Some(line_of(&text, "file = \"nope.csv\"")));
    // A resolution without its base rate.
    let plan = format!("{HEAD}[resolution.x]\nfile = \"resolution_x.csv\"\n");
    let ((msg, line), text) = parse_err(&plan);
    assert!(msg.contains("resolution.x.base_rate_dps: missing"), "{msg}");
    assert_eq!(line, Some(line_of(&text, "[resolution.x]")));
    // An axis not in device.axes.
    let plan = format!("{HEAD}[threshold.y]\nfile = \"threshold_x.csv\"\n");
    let ((msg, line), text) = parse_err(&plan);
    assert!(msg.contains("threshold.y: axis 'y' is not in device.axes (x)"), "{msg}");
    assert_eq!(line, Some(line_of(&text, "[threshold.y]")));
    // No nominal scale factor anywhere.
    let plan = "[device]\nmodel = \"m\"\nserial = \"s\"\naxes = [\"x\"]\n\n[threshold.x]\nfile = \"threshold_x.csv\"\n";
    let ((msg, line), _) = parse_err(plan);
    assert!(msg.contains("threshold.x.scale_factor: no nominal scale factor"), "{msg}");
    assert_eq!(line, Some(6));
    // An unknown key.
    let plan = format!("{HEAD}[threshold.x]\nfile = \"threshold_x.csv\"\nbase_rate_dps = 1\n");
    let ((msg, line), text) = parse_err(&plan);
    assert!(msg.contains("base_rate_dps"), "{msg}");
    assert_eq!(line, Some(line_of(&text, "base_rate_dps = 1")));

    // The base rate is not among the file's rates: found when the file is read.
    let (_dir, p, text) = folder(&good, 6);
    let text2 = text.replace("base_rate_dps = 1.0", "base_rate_dps = 2.0");
    std::fs::write(&p, &text2).unwrap();
    let e = evaluate_test_plan(&read_test_plan(&p).unwrap(), "plan.toml", &Silent).unwrap_err();
    let (msg, line) = located(&e);
    assert!(msg.contains("resolution.x.base_rate_dps: 2 deg/s is not among the rates"), "{msg}");
    assert!(msg.contains("plan.toml"), "{msg}");
    assert_eq!(line, Some(line_of(&text2, "[resolution.x]")));
    // A threshold record without zero-rate rows names the record and the plan key.
    let t = std::fs::read_to_string(p.with_file_name("threshold_x.csv")).unwrap();
    let no_zero: String = t.lines().filter(|l| l.split(',').nth(1) != Some("0")).map(|l| format!("{l}\n")).collect();
    std::fs::write(p.with_file_name("threshold_x.csv"), no_zero).unwrap();
    std::fs::write(&p, &text).unwrap();
    let e = evaluate_test_plan(&read_test_plan(&p).unwrap(), "plan.toml", &Silent).unwrap_err();
    let (msg, _) = located(&e);
    assert!(msg.contains("threshold_x.csv") && msg.contains("threshold.x.file: no 0 deg/s rows"), "{msg}");
}
