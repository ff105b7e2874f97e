//! `evaluate_static_tests` on simulated static records of a gyro with a deg/s output (no preset:
//! K = 1, null 0), a constant bias and white rate noise (ARW) only.

use crate::common;
use common::flag;
use gyrolab::sim::{SensorModel, StaticSpec};
use gyrolab_eval::static_test::{evaluate_static_tests, StaticTestRequest};
use gyrolab_eval::EvalError;
use gyrolab_io::sim_csv::{write_static_csv, SimCsvOptions};
use std::path::{Path, PathBuf};

/// ARW of the simulated gyro, deg/sqrt(h).
const ARW: f64 = 0.5;
/// Length of each record, s (100 Hz).
const DURATION_S: f64 = 600.0;

fn write_record(path: &Path, bias_dph: f64, seed: u64) -> PathBuf {
    let model = SensorModel { arw_deg_rt_h: ARW, bias_dph, ..SensorModel::default() };
    let spec = StaticSpec { sample_rate_hz: 100.0, duration_s: DURATION_S, ..StaticSpec::default() };
    let f = std::fs::File::create(path).unwrap();
    write_static_csv(std::io::BufWriter::new(f), &model, &spec, seed, &SimCsvOptions::default()).unwrap();
    path.to_path_buf()
}

/// Each test's bias is the simulated one within 5 standard errors of a mean of white noise:
/// ARW N = 0.5 deg/sqrt(h) = N/60 deg/sqrt(s), so the mean over T = 600 s has a standard error
/// of (N/60) / sqrt(T) deg/s = 1.22 deg/h. The repeatability (paper eq. 12) equals the
/// sample standard deviation (n - 1) of the two biases computed here, |b1 - b2| / sqrt(2).
#[test]
fn biases_within_the_noise_and_repeatability_is_their_sample_std() {
    let dir = tempfile::tempdir().unwrap();
    let truth = [36.0, 72.0];
    let files: Vec<PathBuf> = truth
        .iter()
        .enumerate()
        .map(|(k, b)| write_record(&dir.path().join(format!("static_{k}.csv")), *b, 100 + k as u64))
        .collect();
    let outcome = evaluate_static_tests(&StaticTestRequest::new(files)).unwrap();
    assert_eq!(outcome.tests.len(), 2);
    let se_dph = ARW / 60.0 / DURATION_S.sqrt() * 3600.0;
    let mut biases = Vec::new();
    for (t, want) in outcome.tests.iter().zip(truth) {
        assert_eq!(t.result.samples, (DURATION_S * 100.0) as u64);
        let b = t.result.bias_dph.expect("a deg/s output gives a bias in deg/h");
        assert!((b - want).abs() < 5.0 * se_dph, "bias {b} deg/h, truth {want}, tolerance {}", 5.0 * se_dph);
        biases.push(b);
    }
    let mean = (biases[0] + biases[1]) / 2.0;
    let std = (biases.iter().map(|b| (b - mean).powi(2)).sum::<f64>() / (biases.len() - 1) as f64).sqrt();
    assert_eq!(outcome.repeatability.len(), 1);
    let r = outcome.repeatability[0].repeatability.bias_repeatability_dph.unwrap();
    assert!((r - std).abs() <= 1e-9 * std, "repeatability {r}, sample std {std}");
    // And near the truth's |36 - 72| / sqrt(2), within the two biases' errors.
    assert!((r - 36.0 / 2f64.sqrt()).abs() < 5.0 * se_dph * 2f64.sqrt(), "repeatability {r}");
}

/// A latitude of 91 degrees is an invalid option naming `latitude_deg`.
#[test]
fn latitude_91_is_invalid() {
    let dir = tempfile::tempdir().unwrap();
    let file = write_record(&dir.path().join("s.csv"), 0.0, 1);
    let mut request = StaticTestRequest::new(vec![file]);
    request.latitude_deg = Some(91.0);
    let e = evaluate_static_tests(&request).unwrap_err();
    match &e {
        EvalError::Invalid(i) => assert_eq!(i.field, "latitude_deg"),
        other => panic!("expected an invalid option, got {other:?}"),
    }
    let text = e.render(&flag);
    assert!(text.starts_with("--latitude-deg ") && text.contains("91"), "{text}");
}

/// splitmix64 in [0, 1): a small deterministic generator for the dropout tests.
fn uniform01(state: &mut u64) -> f64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
}

/// Writes `rows` (time, three deg/s channels) as `time_s,gx_dps,gy_dps,gz_dps` with 6 decimals
/// (so the values read back are the ones given, rounded as the test rounds them).
fn write_rows(path: &Path, rows: &[(f64, [f64; 3])]) {
    let mut text = String::from("time_s,gx_dps,gy_dps,gz_dps\n");
    for (t, r) in rows {
        text.push_str(&format!("{t:.3},{:.6},{:.6},{:.6}\n", r[0], r[1], r[2]));
    }
    std::fs::write(path, text).unwrap();
}

/// Mean and sample standard deviation (n - 1), computed here.
fn mean_std(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, var.sqrt())
}

/// A logger that writes the last row again when the sensor delivers nothing (repeated-row
/// dropouts): 58 rows, single and in runs of two. `bias` finds them (gyrolab::dropout's rule,
/// the one `allan` uses), counts them in the file's quality, and leaves them out of every
/// figure: samples used, mean, standard deviation and bias equal those computed here from the
/// rows without them.
#[test]
fn repeated_row_dropouts_are_left_out_of_every_figure() {
    let dir = tempfile::tempdir().unwrap();
    let n = 20_000usize;
    let mut st = 5u64;
    let mut rows: Vec<(f64, [f64; 3])> = Vec::with_capacity(n);
    let mut dropped = Vec::new();
    for i in 0..n {
        let t = i as f64 * 0.01;
        // Twenty single repeats (every 997th row) and nineteen runs of two (rows 1009 k and
        // 1009 k + 1 both repeat the row before 1009 k): 58 rows.
        let repeat = i >= 997 && (i % 997 == 0 || i % 1_009 <= 1);
        if repeat {
            let prev = rows[i - 1].1;
            rows.push((t, prev));
            dropped.push(i);
            continue;
        }
        // A gyro at rest with a 0.01 deg/s bias on x and white noise, written with 6 decimals.
        let r = [0.01, -0.02, 0.005].map(|b| b + 0.05 * (uniform01(&mut st) - 0.5));
        rows.push((t, r.map(|v| (v * 1e6).round() / 1e6)));
    }
    assert_eq!(dropped.len(), 58);
    let path = dir.path().join("repeats.csv");
    write_rows(&path, &rows);
    let outcome = evaluate_static_tests(&StaticTestRequest::new(vec![path])).unwrap();
    assert_eq!(outcome.files[0].quality.repeated_rows, dropped.len() as u64);
    assert_eq!(outcome.files[0].quality.zero_rows, 0);
    // Line of row i is i + 2 (header on line 1).
    assert_eq!(outcome.files[0].quality.first_repeated_rows[0], dropped[0] as u64 + 2);
    assert_eq!(outcome.tests.len(), 3);
    for (c, t) in outcome.tests.iter().enumerate() {
        let kept: Vec<f64> =
            rows.iter().enumerate().filter(|(i, _)| !dropped.contains(i)).map(|(_, r)| r.1[c]).collect();
        let (mean, std) = mean_std(&kept);
        assert_eq!(t.result.valid_samples, kept.len() as u64);
        assert!((t.result.mean_output - mean).abs() <= 1e-12, "{} {mean}", t.result.mean_output);
        assert!((t.result.std_output - std).abs() <= 1e-12 * std.max(1.0), "{} {std}", t.result.std_output);
        let b = t.result.bias_dph.unwrap();
        assert!((b - mean * 3600.0).abs() <= 1e-8, "{b} {}", mean * 3600.0);
    }
}

/// A quantized output (three channels of seven levels, as a low-resolution sensor writes them)
/// repeats a whole row by chance about once in 343 rows (and is all zero as often): nothing is
/// a dropout, every row is used.
#[test]
fn rows_repeated_by_chance_are_not_dropouts() {
    let dir = tempfile::tempdir().unwrap();
    let n = 20_000usize;
    let mut st = 9u64;
    let rows: Vec<(f64, [f64; 3])> = (0..n)
        .map(|i| {
            let r = [0, 1, 2].map(|_| ((uniform01(&mut st) * 7.0).floor() - 3.0) * 0.01);
            (i as f64 * 0.01, r)
        })
        .collect();
    let chance = (1..n).filter(|&i| rows[i].1 == rows[i - 1].1).count();
    assert!(chance > 20, "the record must repeat rows by chance: {chance}");
    let path = dir.path().join("quantized.csv");
    write_rows(&path, &rows);
    let outcome = evaluate_static_tests(&StaticTestRequest::new(vec![path])).unwrap();
    assert_eq!(outcome.files[0].quality.repeated_rows, 0);
    assert_eq!(outcome.files[0].quality.zero_rows, 0);
    for (c, t) in outcome.tests.iter().enumerate() {
        let all: Vec<f64> = rows.iter().map(|r| r.1[c]).collect();
        assert_eq!(t.result.valid_samples, n as u64);
        assert!((t.result.mean_output - mean_std(&all).0).abs() <= 1e-12);
    }
}
