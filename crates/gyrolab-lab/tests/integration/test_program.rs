//! The example plan with every test of a lab's program (`examples/test_program/plan.toml`): its
//! SIMULATED records are written here by the same generator as `gyrolab simulate test-program`
//! (`program_sim::write_test_program`), the plan it writes must be the committed one, and the
//! evaluation gives every section, labelled SIMULATED, with the spec limits met.

use gyrolab::limits::Overall;
use gyrolab_eval::program_sim::write_test_program;
use gyrolab_eval::progress::Silent;
use gyrolab_lab::test_plan::{evaluate_test_plan, read_test_plan};
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
    // The methods appendix gives U(K) with every line the budget holds: the power-ups' scatter
    // and the test temperature (issue 53).
    let appendix = &html[html.find("Appendix: methods").unwrap()..];
    let row = appendix.split("<tr id=").find(|r| r.contains(">scale_factor_expanded_uncertainty_ppm<")).unwrap();
    assert!(row.contains("u_PU") && row.contains("power-ups") && row.contains("u_T"), "{row}");
    let cal = String::from_utf8(get("calibration.toml").to_vec()).unwrap();
    assert!(cal.contains("[axis.temperature]"), "{cal}");
    // The calibration of simulated records says so, in a comment and in a key (issue 53).
    assert!(cal.starts_with("# SIMULATED DATA: this calibration comes from simulated records"), "{cal}");
    let parsed = gyrolab_io::calibration::parse_calibration(Path::new("calibration.toml"), &cal).unwrap();
    assert!(parsed.simulated.is_some());
}

fn num(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

fn close(got: f64, want: f64, rel: f64, what: &str) {
    assert!((got - want).abs() <= rel * want.abs(), "{what}: got {got}, want {want}");
}

/// Sample standard deviation (n − 1), written out here.
fn std_dev(x: &[f64]) -> f64 {
    let n = x.len() as f64;
    let m = x.iter().sum::<f64>() / n;
    (x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
}

/// The budgets of the figures beyond K, F0 and the static ones, recomputed here from the
/// numbers of results.json by their textbook formulas (docs/METHODS.md, section 11, "Further
/// figures"), k = 2, and each figure's U handed to its limit check.
#[test]
fn figure_budgets_of_the_test_program_equal_a_recomputation() {
    let dir = tempfile::tempdir().unwrap();
    write_test_program(dir.path(), SEED).unwrap();
    let plan = read_test_plan(&dir.path().join("plan.toml")).unwrap();
    let folder = evaluate_test_plan(&plan, "plan.toml", &Silent).unwrap();
    let json: Value =
        serde_json::from_slice(&folder.outputs.iter().find(|o| o.name == "results.json").unwrap().bytes).unwrap();
    let s = &json["sections"];
    let u = &s["uncertainty"]["x"];
    let expanded = |figure: &str| num(&u[format!("{figure}_expanded_uncertainty")]);
    let check_u = |figure: &str| {
        let c = json["limit_checks"].as_array().unwrap().iter().find(|c| c["figure"] == figure).unwrap().clone();
        num(&c["expanded_uncertainty"])
    };
    let (out_acc, rate_ppm, temp_acc) = (2e-4, 50.0, 0.5);
    // Threshold 0.12 deg/s above the failing 0.08: rectangular over (0.08, 0.12], plus 50 ppm
    // rectangular of the rate.
    let t = &s["threshold"]["x"];
    let (v, below) = (num(&t["threshold_dps"]), num(&t["above_dps"]));
    let want = 2.0 * (((v - below) / 12f64.sqrt()).powi(2) + (v * rate_ppm * 1e-6 / 3f64.sqrt()).powi(2)).sqrt();
    close(expanded("threshold_dps"), want, 1e-12, "threshold");
    close(check_u("threshold_dps"), want, 1e-12, "threshold check");
    // Warm-up: one 10 s window, rectangular.
    let w = num(&s["warmup"]["x"]["window_s"]);
    close(expanded("warmup_settling_time_s"), 2.0 * w / 12f64.sqrt(), 1e-12, "settling time");
    // Power-ups: s of the six biases, u = s/√(2(n − 1)).
    let biases: Vec<f64> =
        s["power_ups"]["x"]["bias"]["power_ups"].as_array().unwrap().iter().map(|p| num(&p["value"])).collect();
    let sd = std_dev(&biases);
    close(num(&s["power_ups"]["x"]["bias"]["bias_repeatability_power_up_dph"]), sd, 1e-12, "power-up s");
    close(
        expanded("bias_repeatability_power_up_dph"),
        2.0 * sd / (2.0 * (biases.len() as f64 - 1.0)).sqrt(),
        1e-12,
        "power-up bias repeatability",
    );
    // Bias temperature sensitivity: the slope's textbook standard error over the soaked points
    // and the chamber's 0.5 degC rectangular through |slope| / √S_TT.
    let pts: Vec<(f64, f64)> = s["temperature"]["x"]["points"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|p| p["bias_dph"].is_number())
        .map(|p| (num(&p["temperature_c"]), num(&p["bias_dph"])))
        .collect();
    let n = pts.len() as f64;
    let mt = pts.iter().map(|p| p.0).sum::<f64>() / n;
    let mb = pts.iter().map(|p| p.1).sum::<f64>() / n;
    let stt: f64 = pts.iter().map(|p| (p.0 - mt).powi(2)).sum();
    let slope = pts.iter().map(|p| (p.0 - mt) * (p.1 - mb)).sum::<f64>() / stt;
    let ss: f64 = pts.iter().map(|p| (p.1 - mb - slope * (p.0 - mt)).powi(2)).sum();
    let se = (ss / (n - 2.0) / stt).sqrt();
    let tb = slope.abs() * temp_acc / 3f64.sqrt() / stt.sqrt();
    close(expanded("bias_temp_sensitivity_dph_per_c"), 2.0 * (se * se + tb * tb).sqrt(), 1e-9, "bias temp slope");
    // Nonlinearity: the point of the largest |a_j|, its two stroke means' scatter across the
    // runs (s/√R, weight 1/2) and the output accuracy, all over F_m, in %.
    let a = &json["rate_axes"][0];
    let r = num(&a["runs"]);
    let p = a["points"]
        .as_array()
        .unwrap()
        .iter()
        .max_by(|x, y| num(&x["nonlinearity_pct"]).abs().total_cmp(&num(&y["nonlinearity_pct"]).abs()))
        .unwrap();
    let (sf, sr) = (num(&p["fwd_std"]) / r.sqrt(), num(&p["rev_std"]) / r.sqrt());
    let u_point = (0.25 * sf * sf + 0.25 * sr * sr + (out_acc / 3f64.sqrt()).powi(2)).sqrt();
    let want = 2.0 * u_point * 100.0 / num(&a["output_amplitude"]);
    close(expanded("nonlinearity_pct"), want, 1e-9, "nonlinearity");
    close(check_u("nonlinearity_pct"), want, 1e-9, "nonlinearity check");
    // K for the device: the power-up scatter of K and the test temperature through its
    // coefficient join the slope and rate-accuracy lines.
    let k = num(&a["scale_factor"]);
    let kb = &u["budgets"]["scale_factor"]["components"];
    let s_k = num(&s["power_ups"]["x"]["scale_factor"]["scale_factor_repeatability_power_up_ppm"]);
    close(num(&kb[2]["contribution"]), s_k * k * 1e-6, 1e-9, "K power-up line");
    let alpha = num(&s["temperature"]["x"]["scale_factor_temp_sensitivity_ppm_per_c"]["value"]);
    close(num(&kb[3]["contribution"]), alpha.abs() * k * 1e-6 * temp_acc / 3f64.sqrt(), 1e-9, "K temperature line");
    let parts: f64 = kb.as_array().unwrap().iter().map(|c| num(&c["contribution"]).powi(2)).sum();
    close(num(&u["scale_factor_expanded_ppm"]), 2.0 * parts.sqrt() / k * 1e6, 1e-9, "U(K) ppm");
    // The summary prints value ± U, U to two significant digits and the value to its decimal:
    // the power-up scale-factor repeatability 581.29 ppm with U = 367.6 ppm reads 580 ± 370.
    let html =
        String::from_utf8(folder.outputs.iter().find(|o| o.name == "report.html").unwrap().bytes.clone()).unwrap();
    let v = num(&s["power_ups"]["x"]["scale_factor"]["scale_factor_repeatability_power_up_ppm"]);
    let big_u = expanded("scale_factor_repeatability_power_up_ppm");
    assert!((v - 581.29).abs() < 0.01 && (big_u - 367.64).abs() < 0.01, "seeded values changed: {v}, {big_u}");
    assert!(html.contains("<td>580 ± 370 <span class=\"verdict PASS\">"), "no '580 ± 370' in the summary");
    // The bias stability's U reaches its check.
    close(check_u("bias_stability_dph_10s"), num(&u["bias_stability_expanded_dph"]), 1e-12, "bias stability check");
}

/// One verdict per check (issue 53): under `decision_rule = "guarded_acceptance"` every row of
/// the report that shows a limit's verdict, in the summary and in the sections, shows the one
/// results.json gives for that check (before, the sections printed NOT EVALUATED for twelve
/// figures whose check was PASS or CONDITIONAL: they were checked before the uncertainty part
/// had computed the guard band).
#[test]
fn every_table_shows_the_one_verdict_of_each_check() {
    let dir = tempfile::tempdir().unwrap();
    let plan_text = write_test_program(dir.path(), SEED).unwrap();
    let guarded =
        plan_text.replacen("[uncertainty]", "[options]\ndecision_rule = \"guarded_acceptance\"\n\n[uncertainty]", 1);
    assert_ne!(guarded, plan_text);
    std::fs::write(dir.path().join("plan.toml"), guarded).unwrap();
    let plan = read_test_plan(&dir.path().join("plan.toml")).unwrap();
    let folder = evaluate_test_plan(&plan, "plan.toml", &Silent).unwrap();
    let get = |name: &str| &folder.outputs.iter().find(|o| o.name == name).unwrap().bytes;
    let json: Value = serde_json::from_slice(get("results.json")).unwrap();
    let checks = json["limit_checks"].as_array().unwrap();
    let verdict_of = |key: &str| -> Option<String> {
        checks
            .iter()
            .find(|c| c["figure"] == key && c["axis"] == "x")
            .map(|c| c["verdict"].as_str().unwrap().replace('_', " "))
    };
    let html = String::from_utf8(get("report.html").to_vec()).unwrap();
    let mut compared = 0;
    let mut verdicts = std::collections::BTreeSet::new();
    for row in html.split("<tr>").skip(1) {
        let row = row.split("</tr>").next().unwrap();
        let (Some(k), Some(v)) = (row.find("href=\"#def-"), row.find("class=\"verdict ")) else { continue };
        let key = &row[k + 11..][..row[k + 11..].find('"').unwrap()];
        let verdict = row[v + 15..].split('>').nth(1).unwrap().split('<').next().unwrap();
        let Some(want) = verdict_of(key) else { continue };
        assert_eq!(verdict, want, "{key}: the row says {verdict}, results.json {want}");
        compared += 1;
        verdicts.insert(want);
    }
    assert!(compared >= 20, "{compared} rows compared");
    assert!(verdicts.contains("PASS") && verdicts.contains("CONDITIONAL"), "{verdicts:?}");
}

/// Expired equipment calibration (issue 53): with the test date after the DAQ's due date, the
/// plan's default rule withholds every verdict (each check NOT EVALUATED naming the item, the
/// overall INCOMPLETE) and the report states it; `expired_calibration = "stated"` keeps the
/// verdicts (PASS) and still states it; an unknown rule is refused with its line and key.
#[test]
fn expired_equipment_calibration_withholds_the_verdicts() {
    let dir = tempfile::tempdir().unwrap();
    let plan_text = write_test_program(dir.path(), SEED).unwrap();
    let late = plan_text.replacen("date = \"2026-11-20\"", "date = \"2027-05-01\"", 1);
    assert_ne!(late, plan_text);
    let run = |text: &str| {
        std::fs::write(dir.path().join("plan.toml"), text).unwrap();
        let plan = read_test_plan(&dir.path().join("plan.toml"))?;
        evaluate_test_plan(&plan, "plan.toml", &Silent)
    };
    let folder = run(&late).unwrap();
    assert_eq!(folder.verdict, Some(Overall::Incomplete));
    let json: Value =
        serde_json::from_slice(&folder.outputs.iter().find(|o| o.name == "results.json").unwrap().bytes).unwrap();
    let checks = json["limit_checks"].as_array().unwrap();
    assert!(checks.len() >= 10);
    for c in checks {
        assert_eq!(c["verdict"], "NOT_EVALUATED", "{c}");
        assert!(c["reason"].as_str().unwrap().contains("past its calibration due date (DAQ-07)"), "{c}");
    }
    let html =
        String::from_utf8_lossy(&folder.outputs.iter().find(|o| o.name == "report.html").unwrap().bytes).into_owned();
    assert!(html.contains("CALIBRATION EXPIRED on the test date: data acquisition (DAQ-07, due 2027-03-31)"));
    assert!(!html.contains("\">PASS</span>"), "no PASS verdict anywhere in the report");
    let stated = late.replacen("[uncertainty]", "[options]\nexpired_calibration = \"stated\"\n\n[uncertainty]", 1);
    let folder = run(&stated).unwrap();
    assert_eq!(folder.verdict, Some(Overall::Pass));
    let html =
        String::from_utf8_lossy(&folder.outputs.iter().find(|o| o.name == "report.html").unwrap().bytes).into_owned();
    assert!(html.contains("the verdicts stand as the plan&#39;s rule expired_calibration"), "stated");
    let bad = late.replacen("[uncertainty]", "[options]\nexpired_calibration = \"ignore\"\n\n[uncertainty]", 1);
    let e = run(&bad).unwrap_err().to_string();
    assert!(e.contains("options.expired_calibration: unknown rule 'ignore'"), "{e}");
}
