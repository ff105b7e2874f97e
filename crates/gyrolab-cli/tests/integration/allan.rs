//! `gyrolab allan` end to end: known truth from the simulator, JSON keys, Kalibr YAML, bad input.

use crate::common;
use common::{gyrolab, write};

fn json(args: &[&str], file: &std::path::Path) -> serde_json::Value {
    let out = gyrolab().arg("allan").arg(file).args(args).arg("--json").assert().success().get_output().stdout.clone();
    serde_json::from_slice(&out).unwrap()
}

fn simulate(dir: &std::path::Path, name: &str, args: &[&str]) -> std::path::PathBuf {
    let p = dir.join(name);
    gyrolab().args(["simulate", "static"]).args(args).arg("--out").arg(&p).assert().success();
    p
}

/// Relative error.
fn rel(a: f64, b: f64) -> f64 {
    (a / b - 1.0).abs()
}

#[test]
fn recovers_known_noise_terms_of_simulated_records() {
    // 10 h at 10 Hz. Tolerances: N within 5 % (thousands of degrees of freedom at short tau);
    // B and K within 25 % (few degrees of freedom at long tau; the support rules and their
    // checks over seeds are in docs/METHODS.md section 3).
    let dir = tempfile::tempdir().unwrap();
    let nb = simulate(
        dir.path(),
        "nb.csv",
        &[
            "--duration-s",
            "36000",
            "--sample-rate-hz",
            "10",
            "--arw-deg-rt-h",
            "0.6",
            "--bias-instability-dph",
            "12",
            "--seed",
            "5",
        ],
    );
    let v = json(&[], &nb);
    let n = &v["noise"];
    assert!(rel(n["arw_deg_rt_h"].as_f64().unwrap(), 0.6) < 0.05, "{n}");
    assert!(rel(n["bias_instability_dph"].as_f64().unwrap(), 12.0) < 0.25, "{n}");
    assert!(rel(n["fit"]["bias_instability_dph"].as_f64().unwrap(), 12.0) < 0.25, "{n}");
    assert!(n["rrw_deg_h_rt_h"].is_null(), "no rate random walk was simulated: {n}");
    let nk = simulate(
        dir.path(),
        "nk.csv",
        &[
            "--duration-s",
            "36000",
            "--sample-rate-hz",
            "10",
            "--arw-deg-rt-h",
            "0.6",
            "--rrw-deg-h-rt-h",
            "60",
            "--seed",
            "5",
        ],
    );
    let w = json(&[], &nk);
    let k = &w["noise"];
    assert!(rel(k["arw_deg_rt_h"].as_f64().unwrap(), 0.6) < 0.05, "{k}");
    assert!(rel(k["fit"]["rrw_deg_h_rt_h"].as_f64().unwrap(), 60.0) < 0.25, "{k}");
    assert!(rel(k["rrw_deg_h_rt_h"].as_f64().unwrap(), 60.0) < 0.25, "{k}");
}

#[test]
fn json_keys_csv_and_kalibr() {
    let dir = tempfile::tempdir().unwrap();
    let p =
        simulate(dir.path(), "w.csv", &["--duration-s", "600", "--sample-rate-hz", "100", "--arw-deg-rt-h", "0.36"]);
    let v = json(&["--kind", "oadev", "--taus", "decade"], &p);
    for key in ["kind", "taus_s", "dev", "ci_low", "ci_high", "n_terms"] {
        assert!(!v[key].is_null(), "{key}");
    }
    assert_eq!(v["kind"], "oadev");
    assert_eq!(v["taus_s"].as_array().unwrap().len(), v["dev"].as_array().unwrap().len());
    // White noise: ADEV(tau) = N / sqrt(tau) with N = 0.36 / 60 deg/sqrt(s); at tau = 1 s: 0.006.
    let taus = v["taus_s"].as_array().unwrap();
    let i = taus.iter().position(|t| t.as_f64() == Some(1.0)).unwrap();
    assert!(rel(v["dev"][i].as_f64().unwrap(), 0.006) < 0.05, "{}", v["dev"][i]);
    let lo = v["ci_low"][i].as_f64().unwrap();
    let hi = v["ci_high"][i].as_f64().unwrap();
    assert!(lo < v["dev"][i].as_f64().unwrap() && hi > v["dev"][i].as_f64().unwrap());
    let out = gyrolab().arg("allan").arg(&p).arg("--csv").assert().success().get_output().stdout.clone();
    let csv = String::from_utf8(out).unwrap();
    assert!(csv.starts_with("file,channel,tau_s,m,dev,ci_low,ci_high,n_terms,alpha\n"), "{csv}");
    let yaml = dir.path().join("imu.yaml");
    gyrolab().arg("allan").arg(&p).arg("--kalibr-yaml").arg(&yaml).assert().success();
    let y = std::fs::read_to_string(&yaml).unwrap();
    // N = 0.006 deg/sqrt(s) = 1.047e-4 rad/s/sqrt(Hz).
    let line = y.lines().find(|l| l.starts_with("gyroscope_noise_density:")).unwrap();
    let nd: f64 = line.split(':').nth(1).unwrap().split('#').next().unwrap().trim().parse().unwrap();
    assert!(rel(nd, 0.006_f64.to_radians()) < 0.05, "{y}");
    assert!(y.contains("update_rate: 100"), "{y}");
}

#[test]
fn constant_data_gives_zero_not_nan() {
    let dir = tempfile::tempdir().unwrap();
    let text: String = std::iter::once("rate_dps\n".to_string()).chain((0..100).map(|_| "0.5\n".to_string())).collect();
    let p = write(dir.path(), "c.csv", &text);
    let v = json(&["--sample-rate-hz", "1"], &p);
    for d in v["dev"].as_array().unwrap() {
        assert_eq!(d.as_f64(), Some(0.0));
    }
}

fn allan_error(text: &str, args: &[&str]) -> String {
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "bad.csv", text);
    let out = gyrolab().arg("allan").arg(&p).args(args).assert().code(2).get_output().clone();
    let e = String::from_utf8(out.stderr).unwrap();
    assert!(e.starts_with("error: ") && !e.contains("panicked"), "{e}");
    e
}

#[test]
fn bad_input() {
    let e = allan_error("rate_dps\n1\n", &["--sample-rate-hz", "1"]);
    assert!(e.contains("too short"), "{e}");
    // A NaN cell is a missing sample: computed over by default, refused with --gaps error.
    let e = allan_error("rate_dps\n1\n2\nnan\n4\n5\n6\n7\n8\n9\n", &["--sample-rate-hz", "1", "--gaps", "error"]);
    assert!(e.contains("bad.csv:4"), "{e}");
    let ok = "rate_dps\n1\n2\n3\n4\n5\n6\n7\n8\n9\n";
    let e = allan_error(ok, &["--sample-rate-hz", "1", "--kind", "xdev"]);
    assert!(e.contains("unknown deviation kind 'xdev'"), "{e}");
    let e = allan_error(ok, &["--sample-rate-hz", "1", "--taus", "weekly"]);
    assert!(e.contains("weekly"), "{e}");
    let e = allan_error(ok, &["--sample-rate-hz", "1", "--confidence", "1.5"]);
    assert!(e.contains("confidence"), "{e}");
    // Two samples missing before line 5: refused with --gaps error, and a reversed stamp always.
    let e = allan_error("time_s,rate_dps\n0,1\n1,2\n2,3\n5,4\n6,5\n7,6\n", &["--gaps", "error"]);
    assert!(e.contains("bad.csv:5") && e.contains("2 sample(s) missing"), "{e}");
    let e = allan_error("time_s,rate_dps\n0,1\n1,2\n2,3\n1.5,4\n6,5\n7,6\n", &[]);
    assert!(e.contains("bad.csv:5") && e.contains("does not increase"), "{e}");
    let e = allan_error(ok, &[]);
    assert!(e.contains("sample rate") || e.contains("time"), "{e}");
}

/// Three gyro columns of white noise (N = 0.1, 0.3, 0.2 deg/sqrt(h), 100 Hz, 600 s): Kalibr gets
/// the largest noise density (y's) and, rate random walk being unresolved in every channel, the
/// largest upper bound K <= ci_high(tau_last) sqrt(3 / tau_last) (recomputed here from each
/// channel's curve); the file names the basis, stderr warns, and no entry is 0.
#[test]
fn kalibr_yaml_combines_three_channels_and_writes_bounds_not_zero() {
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};
    let dir = tempfile::tempdir().unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(15);
    let n_dph = [0.1, 0.3, 0.2];
    let mut text = String::from("time_s,gyro_x_dps,gyro_y_dps,gyro_z_dps\n");
    for i in 0..60_000 {
        text.push_str(&format!("{}", i as f64 * 0.01));
        for n in n_dph {
            // white rate noise: sample sigma = N / sqrt(dt), N in deg/sqrt(s)
            let z: f64 = StandardNormal.sample(&mut rng);
            text.push_str(&format!(",{:e}", n / 60.0 / 0.01f64.sqrt() * z));
        }
        text.push('\n');
    }
    let p = write(dir.path(), "xyz.csv", &text);
    let yaml = dir.path().join("imu.yaml");
    let out = gyrolab().arg("allan").arg(&p).arg("--kalibr-yaml").arg(&yaml).assert().success().get_output().clone();
    let stderr = String::from_utf8(out.stderr).unwrap();
    let y = std::fs::read_to_string(&yaml).unwrap();
    let entry = |key: &str| -> f64 {
        let line = y.lines().find(|l| l.starts_with(&format!("{key}:"))).unwrap();
        line.split(':').nth(1).unwrap().split('#').next().unwrap().trim().parse().unwrap()
    };
    let nd = entry("gyroscope_noise_density");
    assert!(rel(nd, (0.3f64 / 60.0).to_radians()) < 0.05, "{y}");
    let v = json(&[], &p);
    let channels = v["channels"].as_array().unwrap();
    assert_eq!(channels.len(), 3);
    let bounds: Vec<f64> = channels
        .iter()
        .map(|c| {
            let taus = c["taus_s"].as_array().unwrap();
            let t = taus.last().unwrap().as_f64().unwrap();
            let hi = c["ci_high"].as_array().unwrap().last().unwrap().as_f64().unwrap();
            (hi * (3.0 / t).sqrt()).to_radians()
        })
        .collect();
    let largest = bounds.iter().cloned().fold(0.0, f64::max);
    let rw = entry("gyroscope_random_walk");
    assert!(rw > 0.0 && rel(rw, largest) < 1e-6, "{rw} vs {largest}: {y}");
    assert!(!y.contains(": 0.0\n") && !y.contains(": 0\n"), "{y}");
    assert!(y.contains("# gyroscope_random_walk: from") && y.contains("UPPER BOUND"), "{y}");
    assert!(y.contains("largest value per entry"), "{y}");
    assert!(stderr.contains("warning: Kalibr gyroscope_random_walk is upper_bound"), "{stderr}");
    assert!(!stderr.contains("gyroscope_noise_density is"), "{stderr}");
    // The JSON names the basis of each term and of the Kalibr entries.
    let noise = &channels[1]["noise"];
    assert_eq!(noise["kalibr"]["gyroscope_random_walk_basis"], "upper_bound", "{noise}");
    assert!(noise["rrw_deg_h_rt_h"].is_null() && noise["bias_instability_dph"].is_null(), "{noise}");
    let rrw = noise["readings"].as_array().unwrap().iter().find(|r| r["term"] == "rrw").unwrap();
    assert_eq!(rrw["basis"], "upper_bound", "{rrw}");
    assert!(rrw["reason"].is_string() && rrw["tau_s"].as_f64().is_some(), "{rrw}");
}

#[test]
fn fit_range_takes_low_comma_high_as_the_readme_writes_it() {
    // `--fit-range 0.1,1000` (one argument) and `--fit-range 0.1 1000` (two) are the same range;
    // the fit then covers only taus inside it.
    let dir = tempfile::tempdir().unwrap();
    let f = simulate(dir.path(), "w.csv", &["--duration-s", "600", "--arw-deg-rt-h", "0.5", "--seed", "3"]);
    let a = json(&["--fit-range", "0.1,10"], &f);
    let b = json(&["--fit-range", "0.1", "10"], &f);
    assert_eq!(a["noise"]["fit"], b["noise"]["fit"]);
    let range = a["noise"]["fit"]["tau_range_s"].as_array().unwrap();
    assert!(range[0].as_f64().unwrap() >= 0.1 && range[1].as_f64().unwrap() <= 10.0, "{range:?}");
    let e = allan_error("time_s,rate_dps\n0,1\n0.1,2\n0.2,1\n0.3,2\n", &["--fit-range", "10,1"]);
    assert!(e.contains("--fit-range needs two increasing positive taus"), "{e}");
}

/// A record's temperature column is carried into the JSON and the text (issue 54): a simulated
/// ramp of 12 degC/h from 25 degC over 600 s reads mean 26, range 2 degC, drift 12 degC/h (the
/// simulator's truth) and warns that it moved; a constant 25 degC does not warn.
#[test]
fn the_temperature_column_is_reported_with_its_drift() {
    let dir = tempfile::tempdir().unwrap();
    for (ramp, moved) in [("12", true), ("0", false)] {
        let p = dir.path().join(format!("t{ramp}.csv"));
        gyrolab()
            .args(["simulate", "static", "--duration-s", "600", "--sample-rate-hz", "100", "--arw-deg-rt-h", "0.3"])
            .args(["--temp-c", "25", "--temp-ramp-c-per-h", ramp, "--record-temperature", "--seed", "4", "--out"])
            .arg(&p)
            .assert()
            .success();
        let out = gyrolab().arg("allan").arg(&p).arg("--json").output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{err}");
        let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let t = &doc["channels"][0]["temperature"];
        assert_eq!(t["column"], "temp_c");
        assert_eq!(t["moved"], moved, "{t}");
        let slope = t["slope_c_per_h"].as_f64().unwrap();
        let want: f64 = ramp.parse().unwrap();
        assert!((slope - want).abs() < 1e-6, "{slope}");
        assert!((t["mean_c"].as_f64().unwrap() - (25.0 + want * 300.0 / 3600.0)).abs() < 1e-3, "{t}");
        assert_eq!(err.contains("the temperature (temp_c) moved"), moved, "{err}");
    }
}

/// `--start`/`--end` (issue 54): the part of a record analysed equals the same rows cut by hand
/// into their own file (every deviation to the last bit), the note names the rows kept; an
/// inverted or empty window is a usage error naming the record's length.
#[test]
fn start_and_end_cut_the_record_as_a_hand_cut_file() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("r.csv");
    gyrolab()
        .args(["simulate", "static", "--duration-s", "300", "--sample-rate-hz", "100", "--arw-deg-rt-h", "0.3"])
        .args(["--rrw-deg-h-rt-h", "5", "--seed", "9", "--out"])
        .arg(&p)
        .assert()
        .success();
    let text = std::fs::read_to_string(&p).unwrap();
    let mut cut = String::new();
    let mut rows = 0;
    for line in text.lines() {
        let t = line.split(',').next().and_then(|x| x.parse::<f64>().ok());
        match t {
            Some(t) if !(50.0..200.0).contains(&t) => continue,
            Some(_) => rows += 1,
            None => {}
        }
        cut.push_str(line);
        cut.push('\n');
    }
    // The cut file's stamps start at 50 s; the tool counts from the record's first sample, 0 s.
    let q = common::write(dir.path(), "cut.csv", &cut);
    let run = |file: &std::path::Path, extra: &[&str]| -> (serde_json::Value, String) {
        let out = gyrolab().arg("allan").arg(file).args(extra).arg("--json").output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr).into_owned();
        assert!(out.status.success(), "{err}");
        (serde_json::from_slice(&out.stdout).unwrap(), err)
    };
    let (windowed, err) = run(&p, &["--start", "50", "--end", "200"]);
    let (by_hand, _) = run(&q, &[]);
    assert!(
        err.contains(&format!(
            "analysed from 50 s to 199.99 s of the record (--start, --end): {rows} of 30000 samples"
        )),
        "{err}"
    );
    assert_eq!(rows, 15000);
    for key in ["dev", "taus_s", "n_terms", "ci_low", "ci_high"] {
        let (a, b) = (&windowed["channels"][0][key], &by_hand["channels"][0][key]);
        assert!(a.as_array().is_some_and(|v| v.len() >= 8), "{key}: {a}");
        assert_eq!(a, b, "{key}");
    }
    assert_eq!(windowed["channels"][0]["samples"], 15000);
    for (args, word) in [
        (["--start", "200", "--end", "50"], "is not after"),
        (["--start", "400", "--end", "500"], "the record is 299.99 s long"),
    ] {
        let out = gyrolab().arg("allan").arg(&p).args(args).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(err.contains(word), "{err}");
    }
    // `bias` cuts the record alike: its figures equal those of the hand-cut file.
    let bias = |file: &std::path::Path, extra: &[&str]| -> (serde_json::Value, String) {
        let out = gyrolab().arg("bias").arg(file).args(extra).arg("--json").output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr).into_owned();
        assert!(out.status.success(), "{err}");
        (serde_json::from_slice(&out.stdout).unwrap(), err)
    };
    let (windowed, err) = bias(&p, &["--start", "50", "--end", "200"]);
    let (by_hand, _) = bias(&q, &[]);
    assert!(err.contains(&format!("{rows} of 30000 samples")), "{err}");
    let (a, b) = (&windowed["tests"][0], &by_hand["tests"][0]);
    assert_eq!(a["samples"], 15000, "{a}");
    for key in
        ["samples", "mean_output", "std_output", "sample_rate_hz", "bias_dph", "bias_stability_dph", "drift_line"]
    {
        assert!(!a[key].is_null(), "{key}: {a}");
        assert_eq!(a[key], b[key], "{key}");
    }
}
