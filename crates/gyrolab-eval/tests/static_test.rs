//! `evaluate_static_tests` on simulated static records of a gyro with a deg/s output (no preset:
//! K = 1, null 0), a constant bias and white rate noise (ARW) only.

mod common;
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
