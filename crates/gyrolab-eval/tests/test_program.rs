//! The example plan with every test of a lab's program (`examples/test_program/plan.toml`): its
//! SIMULATED records are written here by the same generator as `gyrolab simulate test-program`
//! (`program_sim::write_test_program`), the plan it writes must be the committed one, and the
//! evaluation gives every section, labelled SIMULATED, with the spec limits met.

use gyrolab_eval::program_sim::write_test_program;
use gyrolab_eval::progress::Silent;
use gyrolab_eval::test_plan::{evaluate_test_plan, read_test_plan};
use gyrolab_report::limits::Overall;
use serde_json::Value;
use std::path::Path;

/// The seed of `gyrolab simulate test-program`.
const SEED: u64 = gyrolab_eval::simulate::TEST_PROGRAM_SEED;

#[test]
fn the_example_test_program_evaluates_every_section() {
    let dir = tempfile::tempdir().unwrap();
    let plan_text = write_test_program(dir.path(), SEED).unwrap();
    let committed = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/test_program/plan.toml");
    assert_eq!(
        std::fs::read_to_string(&committed).unwrap(),
        plan_text,
        "examples/test_program/plan.toml is out of date: run `gyrolab simulate test-program \
         examples/test_program`"
    );
    let plan = read_test_plan(&dir.path().join("plan.toml")).unwrap();
    let folder = evaluate_test_plan(&plan, "plan.toml", &Silent).unwrap();
    assert_eq!(folder.verdict, Some(Overall::Pass), "{:?}", folder.failures);
    let get = |name: &str| &folder.outputs.iter().find(|o| o.name == name).unwrap().bytes;
    let json: Value = serde_json::from_slice(get("results.json")).unwrap();
    for section in [
        "static",
        "allan",
        "temperature",
        "threshold",
        "resolution",
        "g_sensitivity",
        "power_ups",
        "warmup",
        "uncertainty",
    ] {
        assert!(json["sections"][section]["x"].is_object(), "results.json has no sections.{section}.x");
    }
    let html = String::from_utf8(get("report.html").to_vec()).unwrap();
    // Every section carries the SIMULATED banner: count the sections and the banners.
    let sections = html.matches("<section").count();
    let banners = html.matches("<p class=\"simulated\">SIMULATED DATA").count();
    assert!(html.contains("<div class=\"sim-page\">SIMULATED DATA"), "SIMULATED on every printed page");
    assert_eq!(json["simulated"], true);
    // Every CSV of an all-simulated plan says SIMULATED DATA on its first line (summary.csv in
    // its column).
    for o in folder.outputs.iter().filter(|o| o.name.ends_with(".csv")) {
        let text = String::from_utf8_lossy(&o.bytes);
        if o.name == "summary.csv" {
            assert!(text.lines().skip(1).all(|l| l.ends_with(",SIMULATED")), "{text}");
        } else {
            assert!(text.starts_with("# SIMULATED DATA"), "{}: {}", o.name, &text[..text.len().min(100)]);
        }
    }
    // Summary, sign-off, the inputs with their SHA-256 and the methods appendix are not data
    // sections; the nine others are.
    assert!(sections == 13 && banners == 9, "{sections} sections, {banners} SIMULATED banners");
    for title in [
        "Temperature tests, axis x",
        "Threshold and resolution",
        "g-sensitivity, axis x",
        "Warm-up",
        "Measurement uncertainty",
        "Sign-off",
    ] {
        assert!(html.contains(title), "no section {title}");
    }
    let cal = String::from_utf8(get("calibration.toml").to_vec()).unwrap();
    assert!(cal.contains("[axis.temperature]"), "{cal}");
}
