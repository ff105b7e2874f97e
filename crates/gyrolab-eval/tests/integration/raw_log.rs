//! `evaluate_rates` on simulated raw logs (time, table rate, output), found to be raw logs by
//! their header: the plateaus and runs found equal the simulated ones and K is within the
//! noise of the truth; `segments_out` needs exactly one raw log.
//!
//! Logs (`gyrolab::sim::simulate_raw_log`, default profile): 100 Hz, holds of 10 s (rests 8 s),
//! ramps at 50 deg/s^2 with a 0.5 deg/s overshoot decaying in 0.1 s, table-rate noise
//! 0.01 deg/s; output F0 + K w + white noise of 2 mV.

use crate::common;
use common::{flag, single_axis_log, sxx, F0, K, MIN_PLATEAU_SAMPLES, SIGMA_U};
use gyrolab::segment::SegmentKind;
use gyrolab_eval::rate::raw_log::SegmentationMode;
use gyrolab_eval::rate::{evaluate_rates, RateRequest};
use gyrolab_eval::EvalError;
use gyrolab_io::rate_table::RateLayout;

const RATES: [f64; 7] = [-300.0, -100.0, -30.0, 0.0, 30.0, 100.0, 300.0];

/// Segmentation: one labelled segment per simulated hold label (a turning hold is the end of
/// one stroke and the start of the next), in order, so 2 runs x 2 strokes x 7 rates = 28
/// plateaus plus the two rests; the evaluation sees 2 runs and 7 points.
///
/// K: the slope through 7 point means, each the mean of 4 stroke-runs of at least 850 samples
/// (10 s holds less 1 s settling and the margins) with 2 mV noise, so a point mean's standard
/// error is 2 mV / sqrt(4 x 850) and the slope's that over sqrt(Sxx of the rates); F0 the
/// same over sqrt(7). Both within 5 standard errors.
#[test]
fn raw_log_plateaus_and_runs_match_the_simulation_and_k_is_recovered() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sweep.csv");
    let (sim, seq) = single_axis_log(&path, &RATES, 2, 11, false);
    // Not forced: the header (time_s, table_rate_dps, outputs) says it is a raw log.
    let request = RateRequest { files: vec![path], raw: false, ..Default::default() };
    let outcome = evaluate_rates(&request).unwrap();
    assert_eq!(outcome.logs.len(), 1);
    let log = &outcome.logs[0];
    assert_eq!(log.mode, SegmentationMode::Automatic);

    let truth: Vec<SegmentKind> = seq.iter().flat_map(|(_, labels)| labels.iter().copied()).collect();
    let found: Vec<SegmentKind> = log.segments.iter().map(|s| s.kind).collect();
    assert_eq!(found, truth, "segment labels in order");
    let plateaus = found.iter().filter(|k| matches!(k, SegmentKind::Plateau { .. })).count();
    assert_eq!(plateaus, 2 * 2 * RATES.len());
    // Each segment's mean table rate is its hold's setpoint (table noise 0.01 deg/s averaged).
    let holds: Vec<f64> = sim.holds.iter().flat_map(|h| std::iter::repeat_n(h.rate, h.labels.len())).collect();
    for (s, rate) in log.segments.iter().zip(&holds) {
        assert!((s.rate_dps - rate).abs() < 0.01, "{s:?} vs {rate}");
    }

    assert_eq!(outcome.axes.len(), 1);
    let axis = &outcome.axes[0];
    assert_eq!(axis.name, "gx");
    assert_eq!(axis.record.layout, RateLayout::Raw);
    assert_eq!(axis.evaluation.runs, 2);
    assert_eq!(axis.evaluation.points.len(), RATES.len());

    let se_point = SIGMA_U / (4.0 * MIN_PLATEAU_SAMPLES).sqrt();
    let se_k = se_point / sxx(&RATES).sqrt();
    let se_f0 = se_point / (RATES.len() as f64).sqrt();
    let k = axis.evaluation.scale_factor();
    let f0 = axis.evaluation.zero_offset();
    assert!((k - K).abs() < 5.0 * se_k, "K = {k}, truth {K}, tolerance {}", 5.0 * se_k);
    assert!((f0 - F0).abs() < 5.0 * se_f0, "F0 = {f0}, truth {F0}, tolerance {}", 5.0 * se_f0);
}

/// `segments_out` with two raw logs: a conflict naming `manual_segments` and `segments_out`.
#[test]
fn segments_out_with_two_raw_logs_is_a_conflict() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.csv");
    let b = dir.path().join("b.csv");
    single_axis_log(&a, &[-30.0, 30.0], 1, 3, false);
    single_axis_log(&b, &[-30.0, 30.0], 1, 5, false);
    let request = RateRequest {
        files: vec![a.clone(), b],
        axis_names: vec!["a".into(), "b".into()],
        segments_out: true,
        ..Default::default()
    };
    let e = evaluate_rates(&request).unwrap_err();
    match &e {
        EvalError::Conflict { fields, .. } => assert_eq!(fields, &["manual_segments", "segments_out"]),
        other => panic!("expected a conflict, got {other:?}"),
    }
    let text = e.render(&flag);
    assert!(text.contains("--manual-segments") && text.contains("--segments-out"), "{text}");
    assert!(text.contains("2 of the files"), "{text}");
    // One raw log with segments_out is accepted.
    let one = RateRequest { files: vec![a], segments_out: true, ..Default::default() };
    assert!(evaluate_rates(&one).is_ok());
}
