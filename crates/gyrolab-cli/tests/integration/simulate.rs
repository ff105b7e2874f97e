//! `gyrolab simulate` round trips: records with known truth read back by `gyrolab rate`,
//! `gyrolab bias` and `gyrolab allan`; determinism; bad parameters; `gyrolab plan static`.

use crate::common;
use common::gyrolab;
use std::path::{Path, PathBuf};

fn sim(dir: &Path, name: &str, what: &str, args: &[&str]) -> PathBuf {
    let p = dir.join(name);
    gyrolab().args(["simulate", what]).args(args).arg("--out").arg(&p).assert().success();
    p
}

fn json(cmd: &[&str], files: &[PathBuf]) -> serde_json::Value {
    let out = gyrolab().args(cmd).args(files).arg("--json").assert().success().get_output().stdout.clone();
    serde_json::from_slice(&out).unwrap()
}

#[test]
fn rate_table_round_trip_recovers_k_f0_nonlinearity_and_hysteresis() {
    let dir = tempfile::tempdir().unwrap();
    // K = 7.5 mV/(deg/s), null 2.5 V, hysteresis 0.5 deg/s, quadratic nonlinearity 1e-5 /(deg/s),
    // white noise 0.6 deg/sqrt(h) (0.1 deg/s per sample at 100 Hz, 0.01 deg/s per 100-sample mean).
    let args = [
        "--output-unit",
        "v",
        "--scale-factor",
        "0.0075",
        "--null",
        "2.5",
        "--hysteresis-dps",
        "0.5",
        "--nonlinearity-quadratic-per-dps",
        "1e-5",
        "--arw-deg-rt-h",
        "0.6",
        "--runs",
        "3",
        "--seed",
        "4",
    ];
    let p = sim(dir.path(), "rt.csv", "rate-table", &args);
    let v = json(&["rate"], &[p]);
    let a = &v["axes"][0];
    // Truth, noise free: y_j = 2.5 + 0.0075 (w + 1e-5 w^2) (hysteresis is symmetric about the
    // mean of the strokes). Independent least squares over the paper's 14 rates.
    let w = [-300.0, -240.0, -160.0, -120.0, -60.0, -40.0, 0.0, 25.0, 70.0, 100.0, 135.0, 185.0, 230.0, 300.0];
    let y: Vec<f64> = w.iter().map(|x: &f64| 2.5 + 0.0075 * (x + 1e-5 * x * x)).collect();
    let n = w.len() as f64;
    let (mx, my) = (w.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let k = w.iter().zip(&y).map(|(a, b)| (a - mx) * (b - my)).sum::<f64>()
        / w.iter().map(|a| (a - mx).powi(2)).sum::<f64>();
    let f0 = my - k * mx;
    let fr = 2.5; // rest records: zero rate gives the null
    let fm = y.iter().map(|v| (v - fr).abs()).fold(0.0, f64::max);
    let ka = w.iter().zip(&y).map(|(x, v)| (k * x + f0 - v).abs()).fold(0.0, f64::max) / fm;
    let got_k = a["scale_factor"].as_f64().unwrap();
    // Point means carry 0.01 deg/s * K of noise: K to 1e-4 relative, F0 to 1e-4 V.
    assert!((got_k / k - 1.0).abs() < 1e-4, "K {got_k} vs {k}");
    assert!((a["zero_offset"].as_f64().unwrap() - f0).abs() < 1e-4, "{a}");
    let got_ka = a["nonlinearity_pct"].as_f64().unwrap() / 100.0;
    assert!((got_ka / ka - 1.0).abs() < 0.05, "K_a {got_ka} vs {ka}");
    // Hysteresis: K * 0.5 deg/s over Y_FS = K * 600 deg/s: 0.0833 %.
    let h = a["hysteresis_pct"].as_f64().unwrap();
    assert!((h / (100.0 * 0.5 / 600.0) - 1.0).abs() < 0.1, "hysteresis {h}");
    assert_eq!(a["rest_reference_source"], "rest_records");
}

#[test]
fn static_round_trip_recovers_bias_repeatability_and_temperature_slope() {
    let dir = tempfile::tempdir().unwrap();
    let base = ["--output-unit", "v", "--scale-factor", "0.0075", "--null", "2.5", "--sample-rate-hz", "10"];
    // Four power-ups with biases 10, 12, 9, 13 deg/h and white noise 0.1 deg/sqrt(h):
    // the mean of 3000 samples has sigma 0.1*60/sqrt(0.1)/sqrt(3000)*... = 0.35 deg/h.
    let biases = [10.0, 12.0, 9.0, 13.0];
    let files: Vec<PathBuf> = biases
        .iter()
        .enumerate()
        .map(|(i, b)| {
            let mut a: Vec<String> = base.iter().map(|s| s.to_string()).collect();
            a.extend(["--bias-dph".into(), b.to_string(), "--arw-deg-rt-h".into(), "0.1".into()]);
            a.extend(["--duration-s".into(), "300".into(), "--seed".into(), (i + 1).to_string()]);
            let a: Vec<&str> = a.iter().map(String::as_str).collect();
            sim(dir.path(), &format!("s{i}.csv"), "static", &a)
        })
        .collect();
    let v = json(&["bias", "--scale-factor", "0.0075", "--null", "2.5"], &files);
    let per_test_sigma = 0.1 * 60.0 / (300f64).sqrt(); // deg/h: N [deg/sqrt(h)] / sqrt(T [h])
    for (t, b) in v["tests"].as_array().unwrap().iter().zip(biases) {
        let got = t["bias_dph"].as_f64().unwrap();
        assert!((got - b).abs() < 5.0 * per_test_sigma, "bias {got} vs {b}");
    }
    let mean = biases.iter().sum::<f64>() / 4.0;
    let sd = (biases.iter().map(|b| (b - mean).powi(2)).sum::<f64>() / 3.0).sqrt();
    let rep = v["bias_repeatability_dph"].as_f64().unwrap();
    assert!((rep - sd).abs() < 5.0 * per_test_sigma, "repeatability {rep} vs {sd}");

    // Temperature: 2 (deg/h)/degC over a 20 -> 30 degC ramp in an hour.
    let mut a: Vec<&str> = base.to_vec();
    a.extend([
        "--bias-temp-coeff-dph-per-c",
        "2",
        "--temp-c",
        "20",
        "--temp-ramp-c-per-h",
        "10",
        "--duration-s",
        "3600",
        "--arw-deg-rt-h",
        "0.1",
        "--seed",
        "9",
    ]);
    let mut args: Vec<&str> = a.clone();
    args.push("--record-temperature");
    let t = sim(dir.path(), "temp.csv", "static", &args);
    let w = json(&["bias", "--scale-factor", "0.0075", "--null", "2.5"], &[t]);
    let s = w["tests"][0]["temperature"]["temp_sensitivity_dph_per_c"].as_f64().unwrap();
    assert!((s - 2.0).abs() < 0.1, "temperature sensitivity {s}");
}

#[test]
fn same_seed_same_bytes_and_bad_parameters() {
    let run = |seed: &str| {
        gyrolab()
            .args(["simulate", "static", "--preset", "adxrs646", "--duration-s", "20", "--seed", seed])
            .assert()
            .success()
            .get_output()
            .stdout
            .clone()
    };
    let strip = |b: Vec<u8>| {
        String::from_utf8(b).unwrap().lines().filter(|l| !l.starts_with("# command")).collect::<Vec<_>>().join("\n")
    };
    assert_eq!(strip(run("42")), strip(run("42")));
    assert_ne!(strip(run("42")), strip(run("43")));
    for bad in [
        vec!["--arw-deg-rt-h", "-1"],
        vec!["--sample-rate-hz", "0"],
        vec!["--preset", "adxrs646", "--null", "5"],
        vec!["--preset", "nosuch"],
    ] {
        let out = gyrolab().args(["simulate", "static"]).args(&bad).assert().code(2).get_output().clone();
        let e = String::from_utf8(out.stderr).unwrap();
        assert!(e.contains("error") && !e.contains("panicked"), "{bad:?}: {e}");
    }
}

#[test]
fn plan_static_text_and_json() {
    let out = gyrolab()
        .args(["plan", "static", "--precision-pct", "25", "--sample-rate-hz", "100", "--tau-s", "100", "--json"])
        .assert()
        .success()
        .get_output()
        .stdout
        .clone();
    let v: serde_json::Value = serde_json::from_slice(&out).unwrap();
    assert!(v["duration_s"].as_f64().unwrap() > 1000.0);
    let iv = v["relative_interval"].as_array().unwrap();
    assert!(iv[0].as_f64().unwrap() >= 0.75 && iv[1].as_f64().unwrap() <= 1.25);
    gyrolab()
        .args(["plan", "static", "--precision-pct", "0", "--sample-rate-hz", "100", "--tau-s", "1"])
        .assert()
        .code(2);
}
