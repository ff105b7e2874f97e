//! A newcomer's defaults (issue 32): `simulate static` with no options simulates a typical MEMS
//! gyro (never an all-zero record); a record whose samples are all equal is a warning in
//! `allan` and `bias`; `allan` and `bias` read the scale factor and null that the simulator
//! states in its header; `simulate test-program` writes the example plan's records.

use crate::common;
use common::{gyrolab, write};
use std::path::{Path, PathBuf};

fn simulate(dir: &Path, name: &str, args: &[&str]) -> (PathBuf, String) {
    let p = dir.join(name);
    let out = gyrolab().args(["simulate", "static"]).args(args).arg("--out").arg(&p).assert().success();
    (p, String::from_utf8_lossy(&out.get_output().stderr).into_owned())
}

/// The output column of a simulated static record.
fn outputs(p: &Path) -> Vec<f64> {
    std::fs::read_to_string(p)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("time"))
        .map(|l| l.split(',').nth(1).unwrap().parse::<f64>().unwrap())
        .collect()
}

/// `gyrolab CMD FILE ARGS --json`: the document and stderr.
fn json(cmd: &str, file: &Path, args: &[&str]) -> (serde_json::Value, String) {
    let out = gyrolab().arg(cmd).arg(file).args(args).arg("--json").assert().success();
    let o = out.get_output();
    (serde_json::from_slice(&o.stdout).unwrap(), String::from_utf8_lossy(&o.stderr).into_owned())
}

#[test]
fn simulate_static_without_options_is_a_typical_mems_gyro_in_dps() {
    let dir = tempfile::tempdir().unwrap();
    let (p, stderr) = simulate(dir.path(), "s.csv", &["--duration-s", "1200", "--seed", "3"]);
    assert!(stderr.contains("typical MEMS gyro") && stderr.contains("deg/s"), "{stderr}");
    let text = std::fs::read_to_string(&p).unwrap();
    assert!(text.contains("# defaults: typical MEMS gyro"), "the record says so itself");
    assert!(text.lines().any(|l| l == "time_s,rate_dps"), "deg/s output");
    let y = outputs(&p);
    assert_eq!(y.len(), 120_000);
    // Not all equal: white noise of N = 0.3 deg/sqrt(h) at 100 Hz has a per-sample standard
    // deviation of N/60 * sqrt(100) = 0.05 deg/s.
    let mean = y.iter().sum::<f64>() / y.len() as f64;
    let sd = (y.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (y.len() - 1) as f64).sqrt();
    assert!((sd / 0.05 - 1.0).abs() < 0.05, "per-sample sd {sd}, 0.05 expected");
    // The simulated truth comes back: N within 10 %, the 20 deg/h bias within 3 sigma of its
    // 1200-s mean (about 1 deg/h from white noise and flicker).
    let (v, stderr) = json("allan", &p, &[]);
    assert!(!stderr.contains("same value"), "{stderr}");
    let n = v["noise"]["arw_deg_rt_h"].as_f64().unwrap();
    assert!((n / 0.3 - 1.0).abs() < 0.1, "N = {n}, 0.3 simulated");
    let (b, _) = json("bias", &p, &[]);
    let b0 = b["tests"][0]["bias_dph"].as_f64().unwrap_or_else(|| panic!("{b}"));
    assert!((b0 - 20.0).abs() < 5.0, "B0 = {b0} deg/h, 20 simulated");
}

#[test]
fn any_noise_flag_turns_the_typical_sensor_off() {
    let dir = tempfile::tempdir().unwrap();
    let (p, stderr) = simulate(dir.path(), "z.csv", &["--duration-s", "60", "--arw-deg-rt-h", "0"]);
    assert!(!stderr.contains("typical MEMS"), "{stderr}");
    assert!(outputs(&p).iter().all(|&v| v == 0.0), "noise set to zero on purpose: an ideal record");
}

#[test]
fn a_record_of_equal_values_is_a_warning_in_allan_and_bias() {
    let dir = tempfile::tempdir().unwrap();
    // A simulated ideal record (all zero) and a hand-written one of a constant 2.5 V (a stuck
    // analog output: the rounding of the angle sums must not hide it).
    let (zero, _) = simulate(dir.path(), "z.csv", &["--duration-s", "600", "--arw-deg-rt-h", "0"]);
    let mut text = String::from("time_s,output_v\n");
    for i in 0..20_000 {
        text.push_str(&format!("{},2.5\n", i as f64 * 0.01));
    }
    let stuck = write(dir.path(), "stuck.csv", &text);
    for f in [&zero, &stuck] {
        let out = gyrolab().arg("allan").arg(f).assert().success();
        let stderr = String::from_utf8_lossy(&out.get_output().stderr).into_owned();
        assert!(stderr.contains("warning:") && stderr.contains("every sample has the same value"), "{stderr}");
        assert!(stderr.contains("no noise term can be read"), "{stderr}");
        let out = gyrolab().arg("bias").arg(f).assert().success();
        let stderr = String::from_utf8_lossy(&out.get_output().stderr).into_owned();
        assert!(stderr.contains("warning:") && stderr.contains("every sample has the same value"), "{stderr}");
    }
    // A noisy record gives no such warning (the test can fail both ways).
    let (noisy, _) = simulate(dir.path(), "n.csv", &["--duration-s", "60", "--arw-deg-rt-h", "0.3"]);
    let out = gyrolab().arg("allan").arg(&noisy).assert().success();
    assert!(!String::from_utf8_lossy(&out.get_output().stderr).contains("same value"));
}

#[test]
fn allan_and_bias_read_the_simulators_scale_factor_and_null_from_its_header() {
    let dir = tempfile::tempdir().unwrap();
    let (p, _) = simulate(dir.path(), "v.csv", &["--preset", "adxrs646", "--duration-s", "3600", "--seed", "9"]);
    let (from_header, stderr) = json("allan", &p, &[]);
    assert!(stderr.contains("scale factor 0.0075 V/(deg/s) and null 2.5 V read from the header"), "{stderr}");
    let (given, stderr) = json("allan", &p, &["--scale-factor", "0.0075", "--null", "2.5"]);
    assert!(!stderr.contains("read from the header"), "{stderr}");
    // The same N and B (B is an upper bound on a 1-h record: the reading, value and basis, must
    // be the same) and every other noise figure, as with --scale-factor and --null.
    assert!(from_header["noise"]["arw_deg_rt_h"].as_f64().is_some(), "N read with the header's reference");
    let reading = |v: &serde_json::Value, term: &str| {
        v["noise"]["readings"].as_array().unwrap().iter().find(|r| r["term"] == term).cloned().unwrap()
    };
    assert_eq!(reading(&from_header, "bias_instability"), reading(&given, "bias_instability"));
    assert!(reading(&from_header, "bias_instability")["value"].as_f64().is_some());
    assert_eq!(from_header["noise"], given["noise"], "same as with --scale-factor");
    // The preset's truth: N = 0.6 deg/sqrt(h).
    let n = from_header["noise"]["arw_deg_rt_h"].as_f64().unwrap();
    assert!((n / 0.6 - 1.0).abs() < 0.1, "N = {n}");
    let (from_header, _) = json("bias", &p, &[]);
    let (given, _) = json("bias", &p, &["--scale-factor", "0.0075", "--null", "2.5"]);
    let b = &from_header["tests"][0]["bias_dph"];
    assert!(b.as_f64().is_some(), "{from_header}");
    assert_eq!(b, &given["tests"][0]["bias_dph"]);
    // Without a header (the same numbers, the comments removed): no reference, and the hint
    // names the flags.
    let bare: String =
        std::fs::read_to_string(&p).unwrap().lines().filter(|l| !l.starts_with('#')).fold(String::new(), |mut s, l| {
            s.push_str(l);
            s.push('\n');
            s
        });
    let bare = write(dir.path(), "bare.csv", &bare);
    let out = gyrolab().arg("allan").arg(&bare).assert().success();
    let stderr = String::from_utf8_lossy(&out.get_output().stderr).into_owned();
    assert!(stderr.contains("--scale-factor") && stderr.contains("--null") && stderr.contains("--cal"), "{stderr}");
}

#[test]
fn simulate_test_program_writes_the_example_plan_and_its_records() {
    let dir = tempfile::tempdir().unwrap();
    let target = dir.path().join("program");
    gyrolab().args(["simulate", "test-program"]).arg(&target).assert().success();
    let committed = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/test_program/plan.toml");
    assert_eq!(
        std::fs::read_to_string(target.join("plan.toml")).unwrap(),
        std::fs::read_to_string(committed).unwrap(),
        "the plan written is the committed example's"
    );
    assert!(target.join("rate_x.csv").is_file());
    // The plan without its records: the "not found" message says how to write them.
    let bare = dir.path().join("bare");
    std::fs::create_dir_all(&bare).unwrap();
    std::fs::copy(target.join("plan.toml"), bare.join("plan.toml")).unwrap();
    let out = gyrolab().arg("eval").arg(bare.join("plan.toml")).arg("--out").arg(dir.path().join("r")).assert().code(2);
    let stderr = String::from_utf8_lossy(&out.get_output().stderr).into_owned();
    assert!(stderr.contains("not found") && stderr.contains("gyrolab simulate test-program"), "{stderr}");
}
