//! `[power_ups.<axis>]` and `[warmup.<axis>]` of a test plan, on simulated records
//! (`gyrolab_eval::program_sim::power_ups`): the figures against a computation done here from the
//! records themselves (least-squares K_i, mean B0_i, window means), the warm-up model against the
//! simulated truth, limits on the new figures, and bad plans naming the plan key and line.

use gyrolab_eval::program_sim::power_ups::{
    write_power_up_records, write_warmup_records, WARMUP_AMPLITUDE_DPH, WARMUP_TIME_CONSTANT_S,
};
use gyrolab_eval::progress::Silent;
use gyrolab_eval::EvalError;
use gyrolab_lab::test_plan::{evaluate_test_plan, read_test_plan};
use std::path::Path;

const DEVICE: &str = "[device]\nmodel = \"simulated\"\nserial = \"P-1\"\naxes = [\"x\"]\n\n";

/// The numeric rows of a simulated CSV (comment lines and the header skipped).
fn rows(path: &Path) -> Vec<Vec<String>> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect()
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

fn std1(v: &[f64]) -> f64 {
    let m = mean(v);
    (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (v.len() - 1) as f64).sqrt()
}

/// Least-squares slope of output on rate over every row (every point has the same number of
/// samples, so it equals the slope fitted to the point means).
fn slope(path: &Path) -> f64 {
    let r = rows(path);
    let x: Vec<f64> = r.iter().map(|r| r[0].parse().unwrap()).collect();
    let y: Vec<f64> = r.iter().map(|r| r[3].parse().unwrap()).collect();
    let (mx, my) = (mean(&x), mean(&y));
    let sxy: f64 = x.iter().zip(&y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = x.iter().map(|a| (a - mx).powi(2)).sum();
    sxy / sxx
}

fn files(section: &str, key: &str) -> Vec<String> {
    let line = section.lines().find(|l| l.starts_with(key)).unwrap();
    line.split('"').skip(1).step_by(2).map(str::to_string).collect()
}

fn evaluate(dir: &Path, plan_text: &str) -> serde_json::Value {
    let p = dir.join("plan.toml");
    std::fs::write(&p, plan_text).unwrap();
    let plan = read_test_plan(&p).unwrap();
    let folder = evaluate_test_plan(&plan, "plan.toml", &Silent).unwrap();
    let html = folder.outputs.iter().find(|o| o.name == "report.html").unwrap();
    let html = String::from_utf8_lossy(&html.bytes);
    assert_eq!(html.contains("Repeatability across power-ups"), plan_text.contains("[power_ups"));
    assert_eq!(html.contains("Warm-up — axis"), plan_text.contains("[warmup"));
    let json = folder.outputs.iter().find(|o| o.name == "results.json").unwrap();
    serde_json::from_slice(&json.bytes).unwrap()
}

#[test]
fn power_up_figures_equal_a_computation_from_the_records() {
    let dir = tempfile::tempdir().unwrap();
    let section = write_power_up_records(dir.path(), "x", 7).unwrap();
    let limits = "\n[limits]\nscale_factor_repeatability_power_up_ppm = { max = 1e5 }\nbias_repeatability_power_up_dph = { max = 1e4 }\n";
    let v = evaluate(dir.path(), &format!("{DEVICE}{section}{limits}"));
    let s = &v["sections"]["power_ups"]["x"];

    // Scale factors: least squares on each record, computed here.
    let k: Vec<f64> = files(&section, "rate_files").iter().map(|f| slope(&dir.path().join(f))).collect();
    let sf = &s["scale_factor"];
    assert_eq!(sf["n"], 6);
    assert_eq!(sf["few_power_ups"], false);
    for (i, ki) in k.iter().enumerate() {
        let got = sf["power_ups"][i]["value"].as_f64().unwrap();
        assert!((got / ki - 1.0).abs() < 1e-9, "K_{i}: {got} vs {ki}");
        let dev = sf["power_ups"][i]["deviation"].as_f64().unwrap();
        assert!((dev - (ki - mean(&k))).abs() < 1e-9);
    }
    let ppm = std1(&k) / mean(&k).abs() * 1e6;
    let got = sf["scale_factor_repeatability_power_up_ppm"].as_f64().unwrap();
    assert!((got / ppm - 1.0).abs() < 1e-6, "{got} vs {ppm}");
    // Against the simulated truth: 500 ppm drawn per power-up (6 draws: a chi-square spread).
    assert!(ppm > 0.3 * 500.0 && ppm < 2.0 * 500.0, "{ppm}");

    // Biases: outputs in deg/s with no rate-table record, so B0_i = mean output * 3600.
    let b: Vec<f64> = files(&section, "static_files")
        .iter()
        .map(|f| {
            let out: Vec<f64> = rows(&dir.path().join(f)).iter().map(|r| r[1].parse().unwrap()).collect();
            mean(&out) * 3600.0
        })
        .collect();
    let bias = &s["bias"];
    assert_eq!(bias["n"], 6);
    for (i, bi) in b.iter().enumerate() {
        let got = bias["power_ups"][i]["value"].as_f64().unwrap();
        assert!((got - bi).abs() < 1e-6, "B0_{i}: {got} vs {bi}");
    }
    let got = bias["bias_repeatability_power_up_dph"].as_f64().unwrap();
    assert!((got - std1(&b)).abs() < 1e-6, "{got} vs {}", std1(&b));
    assert!(std1(&b) > 0.3 * 40.0 && std1(&b) < 2.0 * 40.0, "{}", std1(&b));
    // The limits were checked on the new figures.
    let checks = v["limit_checks"].as_array().unwrap();
    assert!(checks.iter().any(|c| c["figure"] == "bias_repeatability_power_up_dph"), "{checks:?}");
}

#[test]
fn two_power_ups_give_a_flagged_value() {
    let dir = tempfile::tempdir().unwrap();
    let section = write_power_up_records(dir.path(), "x", 3).unwrap();
    let st = files(&section, "static_files");
    let text = format!("{DEVICE}[power_ups.x]\nstatic_files = [\"{}\", \"{}\"]\nsample_rate_hz = 20.0\n", st[0], st[1]);
    let v = evaluate(dir.path(), &text);
    let bias = &v["sections"]["power_ups"]["x"]["bias"];
    assert_eq!(bias["n"], 2);
    assert_eq!(bias["few_power_ups"], true);
    let b: Vec<f64> = bias["power_ups"].as_array().unwrap().iter().map(|p| p["value"].as_f64().unwrap()).collect();
    let got = bias["bias_repeatability_power_up_dph"].as_f64().unwrap();
    assert!((got - (b[0] - b[1]).abs() / 2f64.sqrt()).abs() < 1e-9);
    assert!(v["sections"]["power_ups"]["x"]["scale_factor"].is_null());
}

#[test]
fn warmup_model_recovers_the_simulated_transient() {
    let dir = tempfile::tempdir().unwrap();
    let section = write_warmup_records(dir.path(), "x", 11).unwrap();
    let limits = "\n[limits]\nwarmup_settling_time_s = { max = 600 }\nturn_on_bias_dph = { max = 1000 }\n";
    let v = evaluate(dir.path(), &format!("{DEVICE}{section}{limits}"));
    let w = &v["sections"]["warmup"]["x"];
    let tau = w["model"]["time_constant_s"].as_f64().unwrap();
    assert!((tau / WARMUP_TIME_CONSTANT_S - 1.0).abs() < 0.1, "tau {tau}");
    let a = w["model"]["amplitude_dph"].as_f64().unwrap();
    assert!((a / WARMUP_AMPLITUDE_DPH - 1.0).abs() < 0.1, "A {a}");
    assert!((w["model"]["settled_bias_dph"].as_f64().unwrap() - 20.0).abs() < 2.0);

    // Turn-on bias and settling time from the record, computed here: 10-s window means of
    // output * 3600 from t = 0, final bias the mean of the last 20 % of the samples.
    let r = rows(&dir.path().join("warmup_x.csv"));
    let t: Vec<f64> = r.iter().map(|r| r[0].parse().unwrap()).collect();
    let b: Vec<f64> = r.iter().map(|r| r[1].parse::<f64>().unwrap() * 3600.0).collect();
    let per = 200; // 10 s at 20 Hz
    let windows: Vec<f64> = b.chunks(per).filter(|c| c.len() == per).map(mean).collect();
    assert!((w["turn_on_bias_dph"].as_f64().unwrap() - windows[0]).abs() < 1e-6);
    let end = t[t.len() - 1];
    let tail: Vec<f64> = t.iter().zip(&b).filter(|(t, _)| **t >= 0.8 * end).map(|(_, b)| *b).collect();
    let fin = mean(&tail);
    let last_out = windows.iter().rposition(|m| (m - fin).abs() > 5.0).unwrap();
    let settle = (last_out + 1) as f64 * 10.0;
    assert_eq!(w["warmup_settling_time_s"].as_f64(), Some(settle));
    // The truth: 300 exp(-t/60) falls below 5 deg/h at 60 ln 60 = 245.7 s: the window containing it.
    assert!((settle - 60.0 * 60f64.ln()).abs() <= 20.0, "{settle}");
    let checks = v["limit_checks"].as_array().unwrap();
    assert!(checks.iter().any(|c| c["figure"] == "warmup_settling_time_s"), "{checks:?}");
}

fn plan_error(dir: &Path, text: &str) -> gyrolab_io::DataError {
    let p = dir.join("plan.toml");
    std::fs::write(&p, text).unwrap();
    let r = read_test_plan(&p).and_then(|plan| evaluate_test_plan(&plan, "plan.toml", &Silent).map(|_| ()));
    match r {
        Err(EvalError::Data(d)) => d,
        other => panic!("expected a data error, got {other:?}"),
    }
}

#[test]
fn bad_plans_name_the_key_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let section = write_power_up_records(d, "x", 5).unwrap();
    let st = files(&section, "static_files");
    // A warm-up record that starts 100 s after power-on (line 7 holds warmup.x.file).
    let mut late = String::from("time_s,output_dps\n");
    for i in 0..400 {
        late.push_str(&format!("{},0.01\n", 100.0 + i as f64));
    }
    std::fs::write(d.join("late.csv"), late).unwrap();
    let e = plan_error(d, &format!("{DEVICE}[warmup.x]\nfile = \"late.csv\"\nsample_rate_hz = 1.0\nband_dph = 5\n"));
    assert_eq!(e.line, Some(7), "{e}");
    assert!(e.message.contains("warmup.x.file") && e.message.contains("starts 100 s after power-on"), "{e}");
    // The same record with power_on_s = 100 is accepted past that check.
    let e = plan_error(
        d,
        &format!("{DEVICE}[warmup.x]\nfile = \"late.csv\"\nsample_rate_hz = 1.0\nband_dph = 5\npower_on_s = 40\n"),
    );
    assert!(e.message.contains("starts 60 s after power-on"), "{e}");

    // One power-up only.
    let e = plan_error(d, &format!("{DEVICE}[power_ups.x]\nstatic_files = [\"{}\"]\nsample_rate_hz = 20.0\n", st[0]));
    assert_eq!(e.line, Some(7), "{e}");
    assert!(e.message.contains("power_ups.x.static_files") && e.message.contains("at least two power-ups"), "{e}");
    // A missing file.
    let e = plan_error(
        d,
        &format!("{DEVICE}[power_ups.x]\nsample_rate_hz = 20.0\nstatic_files = [\"{}\", \"gone.csv\"]\n", st[0]),
    );
    assert_eq!(e.line, Some(8), "{e}");
    assert!(e.message.contains("power_ups.x.static_files[1]") && e.message.contains("gone.csv"), "{e}");
    // An axis that is not the device's.
    let two = format!("static_files = [\"{}\", \"{}\"]\nsample_rate_hz = 20.0\n", st[0], st[1]);
    let e = plan_error(d, &format!("{DEVICE}[power_ups.x]\n{two}\n[power_ups.y]\n{two}"));
    assert!(e.message.contains("power_ups.y: axis 'y' is not in device.axes"), "{e}");
    // static_files without a sample rate.
    let e = plan_error(d, &format!("{DEVICE}[power_ups.x]\nstatic_files = [\"{}\", \"{}\"]\n", st[0], st[1]));
    assert!(e.message.contains("power_ups.x.sample_rate_hz: missing"), "{e}");
}
