//! `evaluate_rates` on rate-table records: the paper's three files against a least-squares line
//! computed here from each file's per-rate means, a simulated record against its known K and
//! null, and the errors that name request fields.

use crate::common;
use common::{flag, lsq_line, paper_file, rate_means, read_long, sxx};
use gyrolab::sim::{RateTableSpec, SensorModel, PAPER_RATES_DPS};
use gyrolab::units::OutputUnit;
use gyrolab_eval::rate::{evaluate_rates, RateRequest, RateSettings};
use gyrolab_eval::EvalError;
use gyrolab_io::sim_csv::{write_rate_table_csv, SimCsvOptions};

/// K and F0 of each of the paper's files equal the LSQ line through the file's per-rate means
/// (mean of the forward and reverse stroke means, paper eq. 4 and 6), computed here from the
/// CSV text. The two computations differ only in the order of floating-point operations, so
/// 1e-10 relative is ample and any change of the fit's definition (weights, points, rest
/// records) fails it.
#[test]
fn paper_files_scale_factor_is_the_lsq_slope_of_the_per_rate_means() {
    let names = ["x", "y", "z"];
    let files: Vec<_> = names.iter().map(|a| paper_file(&format!("paper_rate_table_{a}.csv"))).collect();
    let request = RateRequest {
        files: files.clone(),
        axis_names: names.iter().map(|s| s.to_string()).collect(),
        ..Default::default()
    };
    let outcome = evaluate_rates(&request).unwrap();
    assert_eq!(outcome.axes.len(), 3);
    assert!(outcome.logs.is_empty());
    for ((axis, file), name) in outcome.axes.iter().zip(&files).zip(names) {
        assert_eq!(axis.name, name);
        let m = rate_means(&read_long(file));
        assert_eq!(m.rates.len(), 14, "the paper's 14 rates");
        let (k, f0) = lsq_line(&m.rates, &m.mean);
        let got_k = axis.evaluation.scale_factor();
        let got_f0 = axis.evaluation.zero_offset();
        assert!((got_k - k).abs() <= 1e-10 * k.abs(), "axis {name}: K = {got_k}, LSQ {k}");
        assert!((got_f0 - f0).abs() <= 1e-10 * f0.abs(), "axis {name}: F0 = {got_f0}, LSQ {f0}");
        // Order of magnitude against the paper's Table 6 (about 7.5 mV/(deg/s), null near 2.5 V).
        assert!((got_k - 0.0075).abs() < 0.0005, "axis {name}: K = {got_k}");
        assert_eq!(axis.evaluation.runs, 4);
    }
}

/// A simulated rate-table record (long layout, the paper's 14 rates, 4 runs of a forward and a
/// reverse stroke, 100 samples per plateau at 100 Hz) of a gyro with K = 7.5 mV/(deg/s), null
/// 2.5 V and white noise only (ARW 0.6 deg/sqrt(h)).
///
/// Noise: ARW N = 0.6 deg/sqrt(h) = 0.01 deg/sqrt(s) gives a per-sample sigma of
/// N / sqrt(dt) = 0.1 deg/s = 0.75 mV. Each point mean averages at least 400 samples (4 runs x
/// 100, one stroke; most points have both strokes, 800), so its standard error is at most
/// 0.75 mV / sqrt(400) = 37.5 uV. The standard error of the slope is that over
/// sqrt(Sxx of the rates) and of the intercept that over sqrt(14); the test allows 5 of each.
#[test]
fn simulated_rate_table_recovers_k_and_null() {
    const K_TRUE: f64 = 0.0075;
    const NULL: f64 = 2.5;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sim_rate.csv");
    let model = SensorModel {
        output_unit: OutputUnit::Volt,
        scale_factor_per_dps: K_TRUE,
        null: NULL,
        arw_deg_rt_h: 0.6,
        ..SensorModel::default()
    };
    let spec = RateTableSpec::default();
    assert_eq!(spec.rates_dps, PAPER_RATES_DPS.to_vec());
    let f = std::fs::File::create(&path).unwrap();
    write_rate_table_csv(std::io::BufWriter::new(f), &model, &spec, 7, &SimCsvOptions::default()).unwrap();

    let request = RateRequest { files: vec![path], ..Default::default() };
    let outcome = evaluate_rates(&request).unwrap();
    let axis = &outcome.axes[0];
    assert_eq!(axis.name, "sim_rate", "default name: the file stem");
    let sigma_sample_v = 0.6 / 60.0 / 0.01f64.sqrt() * K_TRUE;
    let se_point = sigma_sample_v / 400f64.sqrt();
    let se_k = se_point / sxx(&PAPER_RATES_DPS).sqrt();
    let se_f0 = se_point / 14f64.sqrt();
    let k = axis.evaluation.scale_factor();
    let f0 = axis.evaluation.zero_offset();
    assert!((k - K_TRUE).abs() < 5.0 * se_k, "K = {k}, truth {K_TRUE}, tolerance {}", 5.0 * se_k);
    assert!((f0 - NULL).abs() < 5.0 * se_f0, "F0 = {f0}, truth {NULL}, tolerance {}", 5.0 * se_f0);
    assert_eq!(axis.evaluation.runs, 4);
    assert_eq!(axis.evaluation.points.len(), 14);
}

/// Two files given the same axis name: a conflict naming `axis_names`, spelled by the caller.
#[test]
fn duplicate_axis_names_are_a_conflict_on_axis_names() {
    let request = RateRequest {
        files: vec![paper_file("paper_rate_table_x.csv"), paper_file("paper_rate_table_y.csv")],
        axis_names: vec!["x".into(), "x".into()],
        ..Default::default()
    };
    let e = evaluate_rates(&request).unwrap_err();
    match &e {
        EvalError::Conflict { fields, .. } => assert_eq!(fields, &["axis_names"]),
        other => panic!("expected a conflict, got {other:?}"),
    }
    let text = e.render(&flag);
    assert!(text.contains("--axis-names") && text.contains("'x'"), "{text}");
    assert!(!text.contains("{axis_names}"), "placeholder left in: {text}");
}

/// Coverage 0 is an invalid option naming the field `coverage`; the caller's spelling of the
/// field replaces it in the rendered message.
#[test]
fn coverage_zero_is_invalid_and_rendered_with_the_callers_spelling() {
    let request = RateRequest {
        files: vec![paper_file("paper_rate_table_x.csv")],
        settings: RateSettings { coverage: 0.0, ..RateSettings::default() },
        ..Default::default()
    };
    let e = evaluate_rates(&request).unwrap_err();
    match &e {
        EvalError::Invalid(i) => assert_eq!(i.field, "coverage"),
        other => panic!("expected an invalid option, got {other:?}"),
    }
    let text = e.render(&flag);
    assert!(text.starts_with("--coverage "), "{text}");
    assert!(text.contains('0'), "the value given is named: {text}");
    let plan_key = e.render(&|f| format!("options.{f}"));
    assert!(plan_key.starts_with("options.coverage "), "{plan_key}");
}
