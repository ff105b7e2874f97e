//! `gyrolab bias` end to end: JSON keys, repeatability of known offsets, calibration files,
//! and bad input.

use crate::common;
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

/// Warm-up against simulated truth: bias B + A exp(-t/tau) from power-on with A = 300 deg/h,
/// tau = 60 s, B = 30 deg/h, white noise N = 0.1 deg/sqrt(h) (10-s window means scatter by
/// N / sqrt(10 s) = 1.9 deg/h). Truth: the model's tau and A; the settling time to +-10 deg/h,
/// tau ln(A / 10) = 204 s, within two windows; the turn-on bias, B + A (tau / W)(1 - e^(-W/tau))
/// = 306.3 deg/h for the first 10-s window, within 2 deg/h.
#[test]
fn warmup_figures_recover_the_simulated_transient() {
    let dir = tempfile::tempdir().unwrap();
    let f = dir.path().join("wu.csv");
    gyrolab()
        .args(["simulate", "static", "--seed", "7", "--sample-rate-hz", "100", "--duration-s", "1200"])
        .args(["--arw-deg-rt-h", "0.1", "--bias-dph", "30", "--warmup-amplitude-dph", "300"])
        .args(["--warmup-time-constant-s", "60", "--out", f.to_str().unwrap()])
        .assert()
        .success();
    let out = gyrolab().args(["bias", f.to_str().unwrap(), "--warmup-band-dph", "10", "--json"]).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let w = &v["warmup"][0];
    let m = &w["model"];
    let tau = m["time_constant_s"].as_f64().unwrap();
    let a = m["amplitude_dph"].as_f64().unwrap();
    assert!((tau / 60.0 - 1.0).abs() < 0.05, "tau {tau}");
    assert!((a / 300.0 - 1.0).abs() < 0.05, "A {a}");
    assert!((m["settled_bias_dph"].as_f64().unwrap() - 30.0).abs() < 2.0, "{m}");
    let ts = w["settling_time_s"].as_f64().unwrap();
    let truth = 60.0 * (300.0f64 / 10.0).ln();
    assert!((ts - truth).abs() <= 20.0, "settling {ts} s, truth {truth} s");
    let turn_on = 30.0 + 300.0 * 6.0 * (1.0 - (-10.0f64 / 60.0).exp());
    assert!((w["turn_on_bias_dph"].as_f64().unwrap() - turn_on).abs() < 2.0, "{w}");
    // A record that does not start at power-on is refused, naming the file.
    let late = dir.path().join("late.csv");
    let text = std::fs::read_to_string(&f).unwrap();
    let shifted: String = text
        .lines()
        .map(|l| match l.split_once(',') {
            Some((t, rest)) if t.parse::<f64>().is_ok() => format!("{},{rest}\n", t.parse::<f64>().unwrap() + 600.0),
            _ => format!("{l}\n"),
        })
        .collect();
    std::fs::write(&late, shifted).unwrap();
    let out = gyrolab().args(["bias", late.to_str().unwrap(), "--warmup-band-dph", "10"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("late.csv") && err.contains("not at power-on"), "{err}");
}

/// Repeated-row dropouts (every 250th row written again, 16 of them) in a two-channel deg/s
/// log: `gyrolab bias` warns with their count and first line, and the mean is that of the other
/// rows (computed here).
#[test]
fn repeated_rows_are_left_out_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let n = 4000;
    let mut s = String::from("time_s,gx_dps,gy_dps\n");
    let mut rows: Vec<[f64; 2]> = Vec::new();
    let mut kept = Vec::new();
    for i in 0..n {
        let r = if i % 250 == 249 {
            rows[i - 1]
        } else {
            kept.push(i);
            [0.01 + ((i * 37) % 101) as f64 * 1e-4, -0.02 + ((i * 53) % 97) as f64 * 1e-4]
        };
        s.push_str(&format!("{},{:.6},{:.6}\n", i as f64 * 0.1, r[0], r[1]));
        rows.push([(r[0] * 1e6).round() / 1e6, (r[1] * 1e6).round() / 1e6]);
    }
    let file = write(dir.path(), "rep.csv", &s);
    let out = gyrolab().args(["bias", "--json"]).arg(&file).assert().success().get_output().clone();
    let stderr = String::from_utf8_lossy(&out.stderr);
    // Row 249 is on line 251 (header on line 1).
    assert!(stderr.contains("rep.csv:251: 16 dropout row(s) (every channel equal to the row before"), "{stderr}");
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let mean = kept.iter().map(|&i| rows[i][0]).sum::<f64>() / kept.len() as f64;
    assert_relative_eq!(v["tests"][0]["mean_output"].as_f64().unwrap(), mean, max_relative = 1e-12);
}
