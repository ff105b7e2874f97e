//! Static-test figures against hand values and records with known properties.

use approx::assert_relative_eq;
use gyrolab::static_test::*;
use gyrolab::units::{OutputUnit, EARTH_RATE_DPH};
use proptest::prelude::*;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

fn cfg(fs: f64) -> StaticTestConfig {
    StaticTestConfig { sample_rate_hz: Some(fs), ..StaticTestConfig::default() }
}

fn run(x: &[f64], c: &StaticTestConfig) -> StaticTestResult {
    evaluate_static(&SampleBlock::output_only(x), c).unwrap()
}

/// The bias stability at smoothing time `t` (panics when not reported).
fn at(r: &StaticTestResult, t: f64) -> BiasStability {
    *r.stability_at(t).unwrap_or_else(|| panic!("no bias stability at {t} s"))
}

/// x = 1 3 2 4 6 5 7 9 8 10 at 1 Hz.
const HAND: [f64; 10] = [1.0, 3.0, 2.0, 4.0, 6.0, 5.0, 7.0, 9.0, 8.0, 10.0];

fn hand_cfg() -> StaticTestConfig {
    StaticTestConfig {
        smoothing_times_s: vec![2.0, 3.0],
        min_windows: 2,
        scale_factor: Some(2.0),
        null_output: Some(0.5),
        ..cfg(1.0)
    }
}

#[test]
fn hand_record_mean_bias_stability_drift() {
    let r = run(&HAND, &hand_cfg());
    // Mean 55/10 = 5.5; bias (5.5 - 0.5) / 2 = 2.5 deg/s = 9000 deg/h.
    assert_relative_eq!(r.mean_output, 5.5, epsilon = 1e-15);
    assert_relative_eq!(r.bias_dps.unwrap(), 2.5, epsilon = 1e-15);
    assert_relative_eq!(r.bias_dph.unwrap(), 9000.0, epsilon = 1e-10);
    // One sample: squares of deviations from 5.5 sum to 82.5; std = sqrt(82.5 / 9).
    assert_relative_eq!(at(&r, 1.0).output, (82.5f64 / 9.0).sqrt(), epsilon = 1e-14);
    // T = 2 s: window means 2 3 5.5 8 9, deviations -3.5 -2.5 0 2.5 3.5, sum of squares 37, std sqrt(37/4).
    assert_relative_eq!(at(&r, 2.0).output, (37.0f64 / 4.0).sqrt(), epsilon = 1e-14);
    assert_eq!(at(&r, 2.0).windows, 5);
    // T = 3 s: windows 2 5 8 (the 10th sample is a partial window, dropped): std 3; / K * 3600 = 5400 deg/h.
    assert_relative_eq!(at(&r, 3.0).output, 3.0, epsilon = 1e-14);
    assert_eq!(at(&r, 3.0).windows, 3);
    assert_relative_eq!(at(&r, 3.0).dph.unwrap(), 5400.0, epsilon = 1e-9);
    let times: Vec<f64> = r.bias_stability.iter().map(|b| b.smoothing_s).collect();
    assert_eq!(times, vec![1.0, 2.0, 3.0], "increasing smoothing time");
    // Drift: sum (t-4.5)(x-5.5) = 79.5, sum (t-4.5)^2 = 82.5 -> 0.963636 V/s = 3469.0909 V/h;
    // / K = 0.4818 (deg/s)/s * 3600 * 3600 = 6 244 363.6 (deg/h)/h.
    assert_relative_eq!(r.drift_output_per_h.unwrap(), 79.5 / 82.5 * 3600.0, epsilon = 1e-9);
    assert_relative_eq!(r.drift_dph_per_h.unwrap(), 79.5 / 82.5 / 2.0 * 3600.0 * 3600.0, epsilon = 1e-5);
    assert_eq!(r.bias_stability_quoted_s, Some(1.0)); // one sample is 1 s at 1 Hz
    assert_eq!(r.quoted_stability(), r.stability_at(1.0));
    assert!(!r.earth_rate_subtracted);
}

#[test]
fn blocks_and_time_column_do_not_change_results() {
    let whole = run(&HAND, &hand_cfg());
    let time: Vec<f64> = (0..10).map(|i| i as f64).collect();
    for split in 1..=10 {
        for with_time in [false, true] {
            let mut c = hand_cfg();
            if with_time {
                c.sample_rate_hz = None; // estimated from the time stamps: 1 Hz
            }
            let mut acc = StaticTestAccumulator::new(c).unwrap();
            for (xs, ts) in HAND.chunks(split).zip(time.chunks(split)) {
                let b = SampleBlock { output: xs, time_s: with_time.then_some(ts), temperature_c: None, lines: None };
                acc.push(&b).unwrap();
            }
            let r = acc.finish().unwrap().result;
            assert_relative_eq!(r.mean_output, whole.mean_output, epsilon = 1e-14);
            assert_eq!(r.bias_stability.len(), whole.bias_stability.len());
            for (b, w) in r.bias_stability.iter().zip(&whole.bias_stability) {
                assert_eq!(b.smoothing_s, w.smoothing_s);
                assert_relative_eq!(b.output, w.output, epsilon = 1e-13);
            }
            assert_relative_eq!(r.drift_output_per_h.unwrap(), whole.drift_output_per_h.unwrap(), epsilon = 1e-9);
        }
    }
}

proptest! {
    #[test]
    fn random_splits_and_missing_samples_give_the_same_figures(
        xs in prop::collection::vec(-5.0f64..5.0, 40..200),
        nan_at in prop::collection::vec(0usize..200, 0..4),
        split in 1usize..60,
    ) {
        let mut x = xs.clone();
        for i in nan_at { if i < x.len() { x[i] = f64::NAN; } }
        let c = StaticTestConfig { smoothing_times_s: vec![2.0, 5.0], min_windows: 2, ..cfg(1.0) };
        let whole = StaticTestAccumulator::new(c.clone()).and_then(|mut a| { a.push(&SampleBlock::output_only(&x))?; a.finish() }).map(|f| f.result);
        let mut acc = StaticTestAccumulator::new(c).unwrap();
        for part in x.chunks(split) { acc.push(&SampleBlock::output_only(part)).unwrap(); }
        let parts = acc.finish().map(|f| f.result);
        let (w, p) = (whole.unwrap(), parts.unwrap());
        prop_assert_eq!(w.valid_samples, p.valid_samples);
        prop_assert_eq!(&w.quality, &p.quality);
        prop_assert!((w.mean_output - p.mean_output).abs() < 1e-12);
        prop_assert_eq!(w.bias_stability.len(), p.bias_stability.len());
        for (a, b) in w.bias_stability.iter().zip(&p.bias_stability) {
            prop_assert_eq!(a.smoothing_s, b.smoothing_s);
            prop_assert!((b.output - a.output).abs() < 1e-12 * (1.0 + a.output.abs()));
        }
    }
}

#[test]
fn white_noise_stability_matches_sigma_over_sqrt_m() {
    // 1e6 samples at 100 Hz, sigma = 1e-3 V, K = 0.01 V/(deg/s): B_s(T) = sigma / sqrt(T fs) / K * 3600 deg/h.
    // The sample std s of n window means satisfies (n-1) s^2 / sigma_T^2 ~ chi^2(n-1), so s / sigma_T
    // has relative standard deviation about 1 / sqrt(2 (n-1)); the tolerance is 4 of those.
    let (fs, sigma, k, n) = (100.0, 1e-3, 0.01, 1_000_000usize);
    let mut rng = ChaCha8Rng::seed_from_u64(952);
    let noise = Normal::new(0.0, sigma).unwrap();
    let x: Vec<f64> = (0..n).map(|_| 2.5 + noise.sample(&mut rng)).collect();
    let c = StaticTestConfig { scale_factor: Some(k), null_output: Some(2.5), ..cfg(fs) };
    let r = run(&x, &c);
    for t in [0.01, 1.0, 10.0, 100.0] {
        let m = t * fs;
        let windows = (n as f64 / m).floor();
        assert_eq!(at(&r, t).windows as f64, windows);
        let expected = sigma / m.sqrt() / k * 3600.0;
        let tol = 4.0 / (2.0 * (windows - 1.0)).sqrt();
        let got = at(&r, t).dph.unwrap();
        assert!((got / expected - 1.0).abs() < tol, "T = {t}: {got} vs {expected} (tol {tol})");
    }
    assert_eq!(r.bias_stability_quoted_s, Some(10.0));
    // The mean of 1e6 samples is within 4 sigma / sqrt(n) of the null: bias within 4e-6 / 0.01 deg/s.
    assert!(r.bias_dps.unwrap().abs() < 4.0 * sigma / (n as f64).sqrt() / k);
    // 1000 s of white noise: drift consistent with zero (slope SE = sigma / sqrt(sum (t - tbar)^2)).
    let se = sigma / ((n as f64).powi(3) / 12.0).sqrt() * fs;
    assert!(r.drift_output_per_h.unwrap().abs() < 4.0 * se * 3600.0);
    let o = r.quality.outliers.as_ref().unwrap();
    assert_eq!(o.outliers.count, 0, "6 sigma has probability 2e-9 per sample");
}

#[test]
fn mean_and_std_keep_precision_on_a_large_offset() {
    // 2.5 V null, alternating +-1e-4 V, 4e6 samples: mean 2.5 and std 1e-4 * sqrt(n / (n-1)).
    let n = 4_000_000usize;
    let x: Vec<f64> = (0..n).map(|i| if i % 2 == 0 { 2.5 + 1e-4 } else { 2.5 - 1e-4 }).collect();
    let r = run(&x, &cfg(1000.0));
    assert!((r.mean_output - 2.5).abs() < 1e-15 * 2.5 * 10.0, "{}", r.mean_output - 2.5);
    let expected = 1e-4 * (n as f64 / (n as f64 - 1.0)).sqrt();
    assert_relative_eq!(r.std_output, expected, max_relative = 1e-9);
    // Windows of 1 s = 1000 samples (an even count): every window mean is 2.5, std below 1e-15.
    assert!(at(&r, 1.0).output < 1e-14);
}

fn constant_record(v: f64, n: usize) -> Vec<f64> {
    // Alternating +-1e-6 around v: the mean is v exactly (to rounding); no rail runs.
    (0..n).map(|i| v + if i % 2 == 0 { 1e-6 } else { -1e-6 }).collect()
}

#[test]
fn repeatability_of_known_bias_offsets() {
    // Biases 10 12 9 13 deg/h: mean 11, deviations -1 1 -2 2, std sqrt(10/3) = 1.8257 deg/h.
    let (k, null) = (0.0075, 2.5);
    let results: Vec<StaticTestResult> = [10.0, 12.0, 9.0, 13.0]
        .iter()
        .map(|b_dph| {
            let x = constant_record(null + k * b_dph / 3600.0, 1200);
            run(&x, &StaticTestConfig { scale_factor: Some(k), null_output: Some(null), ..cfg(1.0) })
        })
        .collect();
    let rep = bias_repeatability(&results).unwrap();
    assert_eq!(rep.tests, 4);
    assert_relative_eq!(rep.mean_bias_dph.unwrap(), 11.0, epsilon = 1e-6);
    assert_relative_eq!(rep.bias_repeatability_dph.unwrap(), (10.0f64 / 3.0).sqrt(), epsilon = 1e-6);
    assert!(matches!(bias_repeatability(&results[..1]), Err(StaticTestError::TooFewTests { .. })));
}

#[test]
fn repeatability_needs_the_scale_factor_only() {
    // The same biases with K given and no null: B0_i = (F_i - F_null) / K, the null cancels in
    // the spread, so the repeatability is still sqrt(10/3) deg/h; the mean bias needs the null.
    let (k, null) = (0.0075, 2.5);
    let results: Vec<StaticTestResult> = [10.0, 12.0, 9.0, 13.0]
        .iter()
        .map(|b_dph| {
            run(
                &constant_record(null + k * b_dph / 3600.0, 1200),
                &StaticTestConfig { scale_factor: Some(k), ..cfg(1.0) },
            )
        })
        .collect();
    assert!(results.iter().all(|r| r.bias_dph.is_none()));
    let rep = bias_repeatability(&results).unwrap();
    assert_relative_eq!(rep.bias_repeatability_dph.unwrap(), (10.0f64 / 3.0).sqrt(), epsilon = 1e-6);
    assert!(rep.mean_bias_dph.is_none());
}

#[test]
fn a_null_measured_on_the_mounting_keeps_its_earth_rate() {
    // Output = null + K (bias + earth): with a null measured at rest on the same mounting the
    // earth rate is already in it; the bias is (F - null) / K with nothing subtracted, and the
    // component is still reported (Omega_e sin 40 deg = 9.668 deg/h).
    let (k, null) = (0.0075, 2.5);
    let x = constant_record(null + k * 20.0 / 3600.0, 1200);
    let base =
        StaticTestConfig { scale_factor: Some(k), null_output: Some(null), latitude_deg: Some(40.0), ..cfg(1.0) };
    let kept = run(&x, &StaticTestConfig { null_contains_earth_rate: true, ..base.clone() });
    assert_relative_eq!(kept.bias_dph.unwrap(), 20.0, epsilon = 1e-6);
    assert!(!kept.earth_rate_subtracted);
    let earth = 15.041_067_178_669_1 * 40f64.to_radians().sin();
    assert_relative_eq!(kept.earth_rate_component_dph.unwrap(), earth, epsilon = 1e-3);
    assert!(kept.notes.iter().any(|n| n.contains("already contains")));
    let subtracted = run(&x, &base);
    assert_relative_eq!(subtracted.bias_dph.unwrap(), 20.0 - earth, epsilon = 1e-3);
}

#[test]
fn paper_table5_x_mean_reproduces() {
    // Paper Table 5, axis x: 2.513789 2.529938 2.518372 2.528373, printed mean 2.522618.
    let results: Vec<StaticTestResult> =
        [2.513789, 2.529938, 2.518372, 2.528373].iter().map(|&v| run(&constant_record(v, 1200), &cfg(1.0))).collect();
    let rep = bias_repeatability(&results).unwrap();
    assert!((rep.mean_output - 2.522618).abs() < 5e-7);
    assert!(rep.bias_repeatability_dph.is_none(), "uncalibrated volts have no deg/h figure");
}

#[test]
fn known_drift_recovered() {
    // 1e-6 V/s on 2.5 V at 10 Hz for 1000 s: 3.6e-3 V/h; / K = 1e-4 (deg/s)/s = 1296 (deg/h)/h.
    let x: Vec<f64> = (0..10_000).map(|i| 2.5 + 1e-6 * (i as f64 / 10.0)).collect();
    let r = run(&x, &StaticTestConfig { scale_factor: Some(0.01), ..cfg(10.0) });
    assert_relative_eq!(r.drift_output_per_h.unwrap(), 3.6e-3, max_relative = 1e-8);
    assert_relative_eq!(r.drift_dph_per_h.unwrap(), 1296.0, max_relative = 1e-8);
    assert!(r.bias_dps.is_none(), "no null given for a volt output");
    assert!(r.notes.iter().any(|n| n.contains("null_output")));
}

#[test]
fn known_temperature_slope_recovered() {
    // Temperature ramps 20 -> 40 degC over 2000 s at 10 Hz; output = 2.5 + 2e-4 V/degC (T - 20) + noise
    // (sigma 1e-4 V). Sensitivity 2e-4 / 0.01 * 3600 = 72 (deg/h)/degC. After compensation the
    // 10-s window means scatter by sigma / sqrt(100) = 1e-5 V = 3.6 deg/h (200 windows: 3 x 5 %).
    let (fs, n) = (10.0, 20_000usize);
    let mut rng = ChaCha8Rng::seed_from_u64(2426);
    let noise = Normal::new(0.0, 1e-4).unwrap();
    let temp: Vec<f64> = (0..n).map(|i| 20.0 + 20.0 * i as f64 / n as f64).collect();
    let x: Vec<f64> = temp.iter().map(|t| 2.5 + 2e-4 * (t - 20.0) + noise.sample(&mut rng)).collect();
    let c = StaticTestConfig { scale_factor: Some(0.01), null_output: Some(2.5), ..cfg(fs) };
    let b = SampleBlock { output: &x, time_s: None, temperature_c: Some(&temp), lines: None };
    let r = evaluate_static(&b, &c).unwrap();
    let t = r.temperature.unwrap();
    assert_eq!(t.windows, 200);
    assert_relative_eq!(t.slope_output_per_c, 2e-4, max_relative = 0.01);
    assert_relative_eq!(t.temp_sensitivity_dph_per_c.unwrap(), 72.0, max_relative = 0.01);
    assert_relative_eq!(t.compensated_stability_dph.unwrap(), 3.6, max_relative = 0.15);
    assert!(t.window_std_output > 1e-3, "the uncompensated window means span 4e-3 V");
}

#[test]
fn quadratic_temperature_model_recovered() {
    // Temperature steps every 10 s (so each window has one temperature): 20, 21, ... 59 degC;
    // output = 2.5 + 1e-4 (T-20) + 3e-6 (T-20)^2 = c0 + c1 T + c2 T^2 with
    // c2 = 3e-6, c1 = 1e-4 - 2 * 20 * 3e-6 = -2e-5, c0 = 2.5 - 20e-4 + 400 * 3e-6 = 2.4992.
    let fs = 1.0;
    let temp: Vec<f64> = (0..400).map(|i| 20.0 + (i / 10) as f64).collect();
    let x: Vec<f64> = temp.iter().map(|t| 2.5 + 1e-4 * (t - 20.0) + 3e-6 * (t - 20.0).powi(2)).collect();
    let c = StaticTestConfig { temperature_quadratic: true, ..cfg(fs) };
    let b = SampleBlock { output: &x, time_s: None, temperature_c: Some(&temp), lines: None };
    let t = evaluate_static(&b, &c).unwrap().temperature.unwrap();
    let q = t.quadratic_output.unwrap();
    assert_relative_eq!(q[0], 2.4992, epsilon = 1e-10);
    assert_relative_eq!(q[1], -2e-5, epsilon = 1e-11);
    assert_relative_eq!(q[2], 3e-6, epsilon = 1e-12);
    assert!(t.compensated_stability_output < 1e-12);
    assert_eq!(t.compensation_model, "quadratic");
}

#[test]
fn earth_rate_subtracted_when_latitude_given() {
    // A deg/s output reading 0.01 deg/s = 36 deg/h; latitude 30 deg: earth component 15.041/2 deg/h.
    let x = constant_record(0.01, 600);
    let mut c = StaticTestConfig { output_unit: OutputUnit::DegPerSec, ..cfg(1.0) };
    let plain = run(&x, &c);
    assert_relative_eq!(plain.bias_dph.unwrap(), 36.0, epsilon = 1e-9);
    assert!(!plain.earth_rate_subtracted);
    c.latitude_deg = Some(30.0);
    let r = run(&x, &c);
    assert!(r.earth_rate_subtracted);
    assert_relative_eq!(r.earth_rate_component_dph.unwrap(), EARTH_RATE_DPH / 2.0, epsilon = 1e-12);
    assert_relative_eq!(r.bias_dph.unwrap(), 36.0 - 15.041_07 / 2.0, epsilon = 1e-4);
}

#[test]
fn quality_findings_with_positions() {
    // 100 samples at 1 Hz with lines 101..200; gap after sample 10 (dt 3 s), repeated stamp at 20,
    // decreasing stamp at 30, a run of 12 samples stuck at the maximum 5.0 from sample 50,
    // a run of 12 identical mid values (not a rail) from 70, a NaN at 80, a spike at 90.
    let n = 100;
    let mut t: Vec<f64> = (0..n).map(|i| i as f64).collect();
    for v in t.iter_mut().skip(11) {
        *v += 2.0;
    }
    t[20] = t[19];
    t[30] = t[29] - 0.5;
    let mut x: Vec<f64> = (0..n).map(|i| 2.5 + 0.01 * ((i * 7) % 5) as f64).collect();
    for v in x.iter_mut().skip(50).take(12) {
        *v = 5.0;
    }
    for v in x.iter_mut().skip(70).take(12) {
        *v = 2.52;
    }
    x[80] = f64::NAN;
    x[90] = -3.0;
    let lines: Vec<u64> = (101..=200).collect();
    let b = SampleBlock { output: &x, time_s: Some(&t), temperature_c: None, lines: Some(&lines) };
    let r = evaluate_static(&b, &StaticTestConfig { outlier_k_sigma: 3.0, ..cfg(1.0) }).unwrap();
    let q = &r.quality;
    let at = |s: u64| Position { sample: s, line: Some(101 + s) };
    // The stamps after the repeated and the decreasing one are late too (dt 2 and 2.5 s).
    assert_eq!(q.time_gaps.count, 3);
    assert_eq!(q.time_gaps.first, vec![at(11), at(21), at(31)]);
    assert_eq!(q.largest_interval_s, Some(3.0));
    assert_eq!(q.repeated_time.first, vec![at(20)]);
    assert_eq!(q.decreasing_time.count, 1);
    assert_eq!(q.decreasing_time.first, vec![at(30)]);
    assert_eq!(q.stuck_at_max.value, Some(5.0));
    assert_eq!((q.stuck_at_max.runs, q.stuck_at_max.samples), (1, 12));
    assert_eq!(q.stuck_at_max.first, vec![at(50)]);
    assert_eq!(q.stuck_at_min.runs, 0, "the minimum -3.0 is a single sample");
    assert_eq!(q.missing.first, vec![at(80)]);
    assert_eq!(r.valid_samples, 99);
    let o = q.outliers.as_ref().unwrap();
    assert!(!o.dropped);
    assert!(o.outliers.first.contains(&at(90)), "{o:?}");
}

#[test]
fn dropping_outliers_recomputes_the_mean() {
    // 1000 samples alternating 1 +- 0.001 and one spike of 100 at sample 500. With the spike the
    // mean is (999 * 1 + 0.001 (the spike replaced a -0.001 sample) + 100) / 1000; without it,
    // the 999 others average (999 - 0.001... ) -> compare with the hand mean of the kept samples.
    let mut x: Vec<f64> = (0..1000).map(|i| if i % 2 == 0 { 1.001 } else { 0.999 }).collect();
    x[500] = 100.0;
    let kept_mean = (x.iter().sum::<f64>() - 100.0) / 999.0;
    let counted = run(&x, &cfg(1.0));
    assert_relative_eq!(counted.mean_output, x.iter().sum::<f64>() / 1000.0, epsilon = 1e-12);
    assert_eq!(counted.quality.outliers.as_ref().unwrap().outliers.count, 1);
    let dropped = run(&x, &StaticTestConfig { drop_outliers: true, ..cfg(1.0) });
    let o = dropped.quality.outliers.as_ref().unwrap();
    assert!(o.dropped);
    assert_eq!(o.outliers.first, vec![Position { sample: 500, line: None }]);
    assert_eq!(dropped.valid_samples, 999);
    assert_relative_eq!(dropped.mean_output, kept_mean, epsilon = 1e-12);
}

#[test]
fn short_record_skips_smoothing_times_with_reasons() {
    // 50 samples at 1 Hz: 50 one-sample windows, 50 of 1 s, 5 of 10 s, 0 of 100 s.
    let r = run(&constant_record(1.0, 50), &cfg(1.0));
    assert!(r.stability_at(1.0).is_some());
    let skipped: Vec<(f64, u64)> = r.bias_stability_skipped.iter().map(|s| (s.smoothing_s, s.windows)).collect();
    assert_eq!(skipped, vec![(10.0, 5), (100.0, 0)]);
    assert!(r.bias_stability_skipped[0].reason.contains("at least 10"));
    assert_eq!(r.bias_stability_quoted_s, Some(1.0));
}

#[test]
fn errors_are_reported_not_panicked() {
    let no_rate = StaticTestConfig::default();
    let mut acc = StaticTestAccumulator::new(no_rate).unwrap();
    assert_eq!(acc.push(&SampleBlock::output_only(&[1.0, 2.0])), Err(StaticTestError::NoSampleRate));
    assert!(matches!(
        evaluate_static(&SampleBlock::output_only(&[1.0]), &cfg(1.0)),
        Err(StaticTestError::TooFewSamples { found: 1, needed: 2 })
    ));
    assert!(matches!(
        StaticTestAccumulator::new(StaticTestConfig { scale_factor: Some(0.0), ..cfg(1.0) }),
        Err(StaticTestError::InvalidOption(_))
    ));
    let t = [0.0, 0.0, 0.0];
    let b = SampleBlock { output: &[1.0, 2.0, 3.0], time_s: Some(&t), temperature_c: None, lines: None };
    assert!(matches!(evaluate_static(&b, &StaticTestConfig::default()), Err(StaticTestError::SampleRateUnknown(_))));
    let b = SampleBlock { output: &[1.0, 2.0], time_s: Some(&t), temperature_c: None, lines: None };
    assert!(matches!(evaluate_static(&b, &cfg(1.0)), Err(StaticTestError::LengthMismatch { .. })));
    assert_eq!(smoothing_key(0.01), "0.01");
    assert_eq!(smoothing_key(100.0), "100");
}

/// The outlier pass is skipped only when the first pass proves it cannot find anything; the
/// result is then identical to running it.
#[test]
fn skipping_the_outlier_pass_changes_nothing() {
    use gyrolab::static_test::{evaluate_static, OutlierScan, SampleBlock, StaticTestAccumulator, StaticTestConfig};
    use rand_distr::StandardNormal;
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let mut x: Vec<f64> = (0..200_000)
        .map(|i| {
            let z: f64 = StandardNormal.sample(&mut rng);
            2.5 + 1e-6 * i as f64 + 1e-3 * z
        })
        .collect();
    let cfg = StaticTestConfig { sample_rate_hz: Some(100.0), ..StaticTestConfig::default() };
    let two_pass = |x: &[f64]| {
        let block = SampleBlock { output: x, time_s: None, temperature_c: None, lines: None };
        let mut acc = StaticTestAccumulator::new(cfg.clone()).unwrap();
        acc.push(&block).unwrap();
        let first = acc.finish().unwrap();
        let needed = first.outlier_scan_needed;
        let mut scan = OutlierScan::new(&first, &cfg).unwrap();
        scan.push(&block).unwrap();
        (needed, scan.finish(first).unwrap())
    };
    let block = SampleBlock { output: &x, time_s: None, temperature_c: None, lines: None };
    let (needed, full) = two_pass(&x);
    assert!(!needed, "Gaussian noise stays within 6 sigma of the drift line here");
    assert_eq!(evaluate_static(&block, &cfg).unwrap(), full);
    // A spike of 20 sigma: the pass is needed and finds it.
    x[123_456] += 0.02;
    let (needed, full) = two_pass(&x);
    assert!(needed);
    let o = full.quality.outliers.as_ref().unwrap();
    assert_eq!(o.outliers.count, 1);
    assert_eq!(o.outliers.first[0].sample, 123_456);
    let block = SampleBlock { output: &x, time_s: None, temperature_c: None, lines: None };
    assert_eq!(evaluate_static(&block, &cfg).unwrap(), full);
}

/// The JSON form keeps the earlier string-keyed objects: keys in string order ("0.01" < "1" <
/// "10" < "100" < "2"), the quoted smoothing time as its key string; it reads back to the same
/// typed entries.
#[test]
fn json_keeps_string_keyed_stability_objects() {
    let x: Vec<f64> = (0..4000).map(|i| 2.5 + 1e-3 * ((i * 7919) % 13) as f64).collect();
    let c = StaticTestConfig {
        smoothing_times_s: vec![2.0, 10.0, 1.0, 100.0],
        min_windows: 2,
        scale_factor: Some(0.01),
        null_output: Some(2.5),
        ..cfg(100.0)
    };
    let r = run(&x, &c);
    let times: Vec<f64> = r.bias_stability.iter().map(|b| b.smoothing_s).collect();
    assert_eq!(times, vec![0.01, 1.0, 2.0, 10.0]);
    let j = serde_json::to_string(&r).unwrap();
    let keys = |name: &str| {
        let v: serde_json::Value = serde_json::from_str(&j).unwrap();
        v[name].as_object().unwrap().keys().cloned().collect::<Vec<_>>()
    };
    for name in ["bias_stability_output", "bias_stability_dph", "bias_stability_windows"] {
        assert_eq!(keys(name), vec!["0.01", "1", "10", "2"], "{name}");
    }
    let order = ["\"bias_stability_output\":{\"0.01\":", "\"bias_stability_dph\":{\"0.01\":", "\"bias_stability_windows\":{\"0.01\":4000,\"1\":40,\"10\":4,\"2\":20},\"bias_stability_quoted_s\":\"10\",\"bias_stability_skipped\""];
    let pos: Vec<usize> = order.iter().map(|s| j.find(s).unwrap_or_else(|| panic!("{s} in {j}"))).collect();
    assert!(pos.windows(2).all(|w| w[0] < w[1]), "{j}");
    assert!(!j.contains("outlier_scan_needed"));
    let back: StaticTestResult = serde_json::from_str(&j).unwrap();
    // serde_json without its float_roundtrip feature may read a number back 1 ulp off.
    assert_eq!(back.bias_stability.len(), r.bias_stability.len());
    for (b, a) in back.bias_stability.iter().zip(&r.bias_stability) {
        assert_eq!((b.smoothing_s, b.windows), (a.smoothing_s, a.windows));
        assert_relative_eq!(b.output, a.output, max_relative = 1e-15);
        assert_relative_eq!(b.dph.unwrap(), a.dph.unwrap(), max_relative = 1e-15);
    }
    assert_eq!(back.bias_stability_quoted_s, Some(10.0));
}
