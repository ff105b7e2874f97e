//! Tests of the simulator against truths computed independently of it (hand formulas, IEEE
//! Std 952 annex C, NIST SP 1065), with statistical tolerances justified where they are used.

use super::*;
use crate::fit::fit_line;
use crate::rate_test::RateTable;
use crate::units::OutputUnit;

fn ideal() -> SensorModel {
    SensorModel::default()
}

fn static_spec(sample_rate_hz: f64, duration_s: f64) -> StaticSpec {
    StaticSpec { sample_rate_hz, duration_s, ..StaticSpec::default() }
}

fn outputs(model: &SensorModel, spec: &StaticSpec, seed: u64) -> Vec<f64> {
    StaticGenerator::new(model, spec, seed).unwrap().map(|s| s.output).collect()
}

fn mean_std(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (n - 1.0);
    (m, var.sqrt())
}

/// Overlapping Allan deviation of rate samples at tau = m dt (methods notes section 4; SP1065).
fn oadev(rate: &[f64], dt: f64, m: usize) -> f64 {
    let mean = rate.iter().sum::<f64>() / rate.len() as f64;
    let mut phase = Vec::with_capacity(rate.len() + 1);
    phase.push(0.0);
    let mut acc = 0.0;
    for r in rate {
        acc += (r - mean) * dt;
        phase.push(acc);
    }
    let l = phase.len();
    let tau = m as f64 * dt;
    let sum: f64 = (0..l - 2 * m).map(|k| (phase[k + 2 * m] - 2.0 * phase[k + m] + phase[k]).powi(2)).sum();
    (sum / (2.0 * tau * tau * (l - 2 * m) as f64)).sqrt()
}

#[test]
fn same_seed_same_samples_different_seed_different() {
    let model = SensorModel { rrw_deg_h_rt_h: 5.0, ..SensorModel::preset(Preset::Adxrs646) };
    let spec = static_spec(100.0, 20.0);
    let bits = |seed| outputs(&model, &spec, seed).iter().map(|v| v.to_bits()).collect::<Vec<u64>>();
    assert_eq!(bits(7), bits(7));
    assert_ne!(bits(7), bits(8));
    let rt = RateTableSpec { runs: 1, samples_per_plateau: 5, rest_samples: 5, ..RateTableSpec::default() };
    let rows =
        |seed| RateTableGenerator::new(&model, &rt, seed).unwrap().map(|s| s.output.to_bits()).collect::<Vec<_>>();
    assert_eq!(rows(1), rows(1));
    assert_ne!(rows(1), rows(2));
}

#[test]
fn white_noise_sigma_matches_arw() {
    // N = 0.6 deg/sqrt(h) = 0.01 deg/sqrt(s); at dt = 0.01 s sigma = 0.01 / sqrt(0.01) = 0.1 deg/s.
    let model = SensorModel { arw_deg_rt_h: 0.6, ..ideal() };
    let n = 200_000.0;
    let v = outputs(&model, &static_spec(100.0, n / 100.0), 11);
    let (m, s) = mean_std(&v);
    // Standard error of a sample std: sigma / sqrt(2 (n - 1)) -> 0.16 %; allow 4 of them.
    assert!((s / 0.1 - 1.0).abs() < 4.0 / (2.0 * n).sqrt(), "std {s}");
    assert!(m.abs() < 4.0 * 0.1 / n.sqrt(), "mean {m}");
}

#[test]
fn rate_random_walk_increments_have_variance_k2_dt() {
    // K = 100 deg/h/sqrt(h) = 100 / 216000 deg/s/sqrt(s); dt = 0.1 s: Var(increment) = K^2 dt.
    let model = SensorModel { rrw_deg_h_rt_h: 100.0, ..ideal() };
    let v = outputs(&model, &static_spec(10.0, 10_000.0), 3);
    let d: Vec<f64> = v.windows(2).map(|w| w[1] - w[0]).collect();
    let (_, s) = mean_std(&d);
    let k = 100.0 / 216_000.0;
    let expected = k * k * 0.1;
    // Relative standard error of a sample variance: sqrt(2 / (n - 1)) = 0.45 % for n = 1e5; 4 of them.
    let n = d.len() as f64;
    assert!((s * s / expected - 1.0).abs() < 4.0 * (2.0 / n).sqrt(), "var {} vs {expected}", s * s);
}

#[test]
fn static_mean_is_null_plus_k_times_bias_and_earth_rate() {
    let model = SensorModel {
        bias_instability_dph: 0.0,
        arw_deg_rt_h: 0.06,
        bias_dph: 360.0,
        ..SensorModel::preset(Preset::Adxrs646)
    };
    let spec = StaticSpec { latitude_deg: Some(30.0), ..static_spec(100.0, 1000.0) };
    let v = outputs(&model, &spec, 5);
    let (m, _) = mean_std(&v);
    // Earth rate 7.292115e-5 rad/s, vertical part at 30 deg: times sin 30 = 0.5.
    let earth_dps = 7.292_115e-5_f64.to_degrees() * 0.5;
    let expected = 2.5 + 0.0075 * (360.0 / 3600.0 + earth_dps);
    // White noise: sigma = 0.001 deg/s / sqrt(0.01) = 0.01 deg/s per sample; std of the mean of
    // 1e5 samples 3.2e-5 deg/s (times K); 4 of them. The earth term is 2.1e-3 deg/s, 65 of them.
    let tol = 4.0 * 0.0075 * 0.01 / (v.len() as f64).sqrt();
    assert!((m - expected).abs() < tol, "mean {m}, expected {expected}, tol {tol}");
}

fn rate_table(model: &SensorModel, spec: &RateTableSpec, seed: u64) -> (RateTable, SimulatedRateTest) {
    let sim = collect_rate_test(RateTableGenerator::new(model, spec, seed).unwrap());
    (RateTable::from_observations(&sim.observations, sim.rest).unwrap(), sim)
}

#[test]
fn linear_rate_table_fit_recovers_scale_factor_and_null() {
    let model = SensorModel {
        output_unit: OutputUnit::Volt,
        scale_factor_per_dps: 0.0075,
        null: 2.5,
        arw_deg_rt_h: 0.06,
        ..ideal()
    };
    let spec = RateTableSpec { runs: 2, samples_per_plateau: 50, rest_samples: 50, ..RateTableSpec::default() };
    let (_, sim) = rate_table(&model, &spec, 9);
    assert_eq!(sim.observations.len(), 14 * 2 * 2 * 50);
    let x: Vec<f64> = sim.observations.iter().map(|o| o.rate_dps).collect();
    let y: Vec<f64> = sim.observations.iter().map(|o| o.output).collect();
    let line = fit_line(&x, &y).unwrap();
    // Noise 0.01 deg/s per sample (0.075 mV): intercept std ~ 0.075 mV / sqrt(2800) = 1.4 uV;
    // slope std ~ 0.075 mV / sqrt(2800 * 2.86e4 (deg/s)^2, the rates' variance) = 8.4e-9 V/(deg/s).
    // Allow about 6 standard errors of each.
    assert!((line.slope - 0.0075).abs() < 5e-8, "slope {}", line.slope);
    assert!((line.intercept - 2.5).abs() < 1e-5, "intercept {}", line.intercept);
    let rest = sim.rest.unwrap();
    assert!((rest.start - 2.5).abs() < 1e-4 && (rest.end - 2.5).abs() < 1e-4);
}

#[test]
fn hysteresis_is_the_forward_reverse_difference() {
    let model = SensorModel { scale_factor_per_dps: 0.0075, null: 2.5, hysteresis_dps: 0.4, ..ideal() };
    let spec = RateTableSpec { runs: 2, samples_per_plateau: 3, ..RateTableSpec::default() };
    let (table, _) = rate_table(&model, &spec, 1);
    for j in 0..table.rates_dps.len() {
        for r in 0..2 {
            let d = table.forward[j][r] - table.reverse[j][r];
            assert!((d - 0.0075 * 0.4).abs() < 1e-12, "rate {}: {d}", table.rates_dps[j]);
        }
    }
}

#[test]
fn saturation_clamps_at_the_rails() {
    let model = SensorModel { arw_deg_rt_h: 0.0, bias_instability_dph: 0.0, ..SensorModel::preset(Preset::Adxrs646) };
    let spec = RateTableSpec {
        rates_dps: vec![-400.0, -100.0, 100.0, 400.0],
        runs: 1,
        samples_per_plateau: 2,
        ..RateTableSpec::default()
    };
    let (table, _) = rate_table(&model, &spec, 1);
    assert_eq!(table.forward[0][0], 0.25);
    assert_eq!(table.forward[3][0], 4.75);
    assert!((table.forward[1][0] - (2.5 - 0.75)).abs() < 1e-12);
    assert!((table.forward[2][0] - (2.5 + 0.75)).abs() < 1e-12);
}

#[test]
fn flicker_allan_deviation_is_flat_within_band() {
    // B = 10 deg/h at 10 Hz, 1e6 samples (1e5 s). First: flat range 1..100 s (tau_min = 10 dt,
    // the shortest allowed: the worst case for point sampling; holds 1, 1, 3, 33, 333 samples).
    // Second: 100..1000 s, every process held (3, 33, 333, 3333 samples).
    let b_dps = 10.0 / 3600.0;
    let dt = 0.1;
    let cases: [(f64, f64, &[usize], u64); 2] =
        [(1.0, 100.0, &[10, 30, 100, 300, 1000], 21), (100.0, 1000.0, &[1000, 2000, 4000], 22)];
    for (tau_min, tau_max, ms, seed) in cases {
        let model = SensorModel {
            bias_instability_dph: 10.0,
            flicker_tau_min_s: tau_min,
            flicker_tau_max_s: tau_max,
            ..ideal()
        };
        let v = outputs(&model, &static_spec(10.0, 100_000.0), seed);
        let n_phase = (v.len() + 1) as f64;
        for &m in ms {
            let adev = oadev(&v, dt, m);
            let ratio = adev / (0.6643 * b_dps);
            // Statistical error: equivalent degrees of freedom of the overlapping ADEV for flicker FM
            // (NIST SP 1065, section 5.3.3): edf = 5 N^2 / (4 m (N + 3 m)); relative std of the ADEV
            // ~ 1 / sqrt(2 edf) (2 % at m = 1000, 0.2 % at m = 10). Tolerance: the stated +-3 % band
            // plus 3 standard errors.
            let mf = m as f64;
            let edf = 5.0 * n_phase * n_phase / (4.0 * mf * (n_phase + 3.0 * mf));
            let tol = 0.03 + 3.0 / (2.0 * edf).sqrt();
            assert!((ratio - 1.0).abs() < tol, "tau {} s: ADEV / 0.6643 B = {ratio}, tol {tol}", mf * dt);
        }
    }
}

#[test]
fn held_flicker_processes_change_only_at_their_updates() {
    // 100 Hz, tau_min 7.5 s: T_i = 0.75, 7.5, 75, 750 s held 2, 25, 250, 2500 samples (floor of
    // T / 30 dt); holds that are not multiples of each other. Flicker only: the output changes
    // exactly at multiples of 2 or 25.
    let model = SensorModel { bias_instability_dph: 10.0, flicker_tau_min_s: 7.5, flicker_tau_max_s: 100.0, ..ideal() };
    let generator = StaticGenerator::new(&model, &static_spec(100.0, 60.0), 3).unwrap();
    let design = generator.flicker_design().unwrap().clone();
    assert_eq!(design.hold_samples(0.01), vec![2, 25, 250, 2500]);
    let v: Vec<f64> = generator.map(|s| s.output).collect();
    for n in 1..v.len() {
        let updated = n % 2 == 0 || n % 25 == 0;
        assert_eq!(v[n] != v[n - 1], updated, "sample {n}");
    }
}

#[test]
fn flicker_sum_follows_the_held_recursion_computed_apart() {
    // Flicker only, unit scale factor, null 0: each output is the flicker sum itself. Reference:
    // the documented recursion written out here (METHODS.md section 4): initial states s z from
    // stream 0 of the seed in process order; after sample count n, every process whose hold
    // divides n, in process order, x <- phi x + s sqrt(1 - phi^2) z with phi = exp(-k dt / T).
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};
    for (tau_min_s, duration_s) in [(7.5, 60.0), (10.0, 4000.0)] {
        let model = SensorModel {
            bias_instability_dph: 10.0,
            flicker_tau_min_s: tau_min_s,
            flicker_tau_max_s: 100.0 * tau_min_s,
            ..ideal()
        };
        let generator = StaticGenerator::new(&model, &static_spec(100.0, duration_s), 11).unwrap();
        let design = generator.flicker_design().unwrap().clone();
        let outputs: Vec<f64> = generator.map(|s| s.output).collect();
        let holds = design.hold_samples(0.01);
        let s = design.sigma_each_dps;
        let phis: Vec<f64> = design
            .correlation_times_s
            .iter()
            .zip(&holds)
            .map(|(&t, &k)| portable::exp(-(k as f64) * 0.01 / t))
            .collect();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        rng.set_stream(0);
        let mut states: Vec<f64> = phis
            .iter()
            .map(|_| {
                let z: f64 = StandardNormal.sample(&mut rng);
                s * z
            })
            .collect();
        for (n, &out) in outputs.iter().enumerate() {
            let sum = states.iter().fold(0.0, |acc, &x| acc + x);
            assert_eq!(out.to_bits(), sum.to_bits(), "tau_min {tau_min_s} s, sample {n}");
            let count = n as u64 + 1;
            for ((x, &phi), &k) in states.iter_mut().zip(&phis).zip(&holds) {
                if count.is_multiple_of(k) {
                    let z: f64 = StandardNormal.sample(&mut rng);
                    *x = phi * *x + s * (1.0 - phi * phi).sqrt() * z;
                }
            }
        }
    }
}

#[test]
fn run_to_run_bias_has_the_stated_spread() {
    // Noise-free sensor, one sample per plateau: the 0 deg/s output of each run is its run bias.
    let model = SensorModel { run_to_run_bias_sigma_dph: 36.0, ..ideal() };
    let spec = RateTableSpec {
        rates_dps: vec![0.0, 10.0],
        runs: 400,
        samples_per_plateau: 1,
        settling_s: 0.0,
        rest_samples: 0,
        ..RateTableSpec::default()
    };
    let (table, _) = rate_table(&model, &spec, 4);
    let (m, s) = mean_std(&table.forward[0]);
    // Same draw for both strokes of a run.
    assert_eq!(table.forward[0], table.reverse[0]);
    // sigma 0.01 deg/s; std of a sample std of 400: 3.5 %; allow 4 of them (14 %).
    assert!((s / 0.01 - 1.0).abs() < 0.14, "std {s}");
    assert!(m.abs() < 4.0 * 0.01 / 20.0, "mean {m}");
}

#[test]
fn nonlinearity_asymmetry_and_scale_factor_error_follow_their_definitions() {
    let model = SensorModel {
        scale_factor_per_dps: 2.0,
        null: 1.0,
        scale_factor_error_ppm: 1000.0,
        scale_factor_asymmetry_ppm: 2000.0,
        nonlinearity_quadratic_per_dps: 1e-5,
        nonlinearity_cubic_per_dps2: 1e-7,
        ..ideal()
    };
    let spec =
        RateTableSpec { rates_dps: vec![-100.0, 100.0], runs: 1, samples_per_plateau: 1, ..RateTableSpec::default() };
    let (table, _) = rate_table(&model, &spec, 1);
    // w = +-100: w + k2 w^2 + k3 w^3 = 100 + 0.1 + 0.1 = 100.2 and -100 + 0.1 - 0.1 = -100.
    // K+ = 2 * 1.001 * 1.001, K- = 2 * 1.001 * 0.999.
    assert!((table.forward[1][0] - (1.0 + 2.0 * 1.001 * 1.001 * 100.2)).abs() < 1e-9);
    assert!((table.forward[0][0] - (1.0 - 2.0 * 1.001 * 0.999 * 100.0)).abs() < 1e-9);
}

#[test]
fn temperature_ramp_moves_bias_and_scale_factor() {
    // Ramp 25 -> 35 degC over 1 h; bias 36 deg/h per degC = 0.01 deg/s per degC; K +100 ppm/degC.
    let model = SensorModel { bias_temp_coeff_dph_per_c: 36.0, scale_factor_temp_coeff_ppm_per_c: 100.0, ..ideal() };
    let spec = StaticSpec {
        temperature: TemperatureProfile::Ramp { start_c: 25.0, rate_c_per_h: 10.0 },
        record_temperature: true,
        ..static_spec(1.0, 3601.0)
    };
    let v: Vec<StaticSample> = StaticGenerator::new(&model, &spec, 1).unwrap().collect();
    assert_eq!(v[0].output, 0.0);
    let last = v[3600];
    assert_eq!(last.temp_c, Some(35.0));
    assert!((last.output - 0.1 * (1.0 + 100e-6 * 10.0)).abs() < 1e-12, "{}", last.output);
    let steps = TemperatureProfile::Steps {
        start_c: 20.0,
        steps: vec![TemperatureStep { at_s: 10.0, temp_c: 30.0 }, TemperatureStep { at_s: 20.0, temp_c: 40.0 }],
    };
    assert_eq!((steps.temp_at(9.9), steps.temp_at(10.0), steps.temp_at(25.0)), (20.0, 30.0, 40.0));
}

#[test]
fn quantization_rounds_outputs_and_angle_quantization_keeps_the_mean() {
    let model = SensorModel { arw_deg_rt_h: 6.0, output_quantization_step: 0.25, ..ideal() };
    for x in outputs(&model, &static_spec(100.0, 10.0), 2) {
        assert_eq!((x / 0.25).fract(), 0.0);
    }
    // Angle steps of 0.01 deg at 100 Hz: each output is a multiple of 1 deg/s, the mean stays 0.37.
    let model = SensorModel { bias_dph: 0.37 * 3600.0, angle_quantization_deg: 0.01, ..ideal() };
    let v = outputs(&model, &static_spec(100.0, 100.0), 2);
    assert!(v.iter().all(|x| x.fract() == 0.0));
    let (m, _) = mean_std(&v);
    assert!((m - 0.37).abs() < 1.0 / v.len() as f64 + 1e-12, "mean {m}");
}

#[test]
fn settling_rows_are_dropped_or_flagged_and_rest_records_frame_the_test() {
    let base = RateTableSpec {
        rates_dps: vec![-10.0, 0.0, 10.0],
        runs: 2,
        samples_per_plateau: 4,
        settling_s: 0.05,
        sample_rate_hz: 100.0,
        rest_samples: 3,
        ..RateTableSpec::default()
    };
    let dropped: Vec<RateTableSample> = RateTableGenerator::new(&ideal(), &base, 1).unwrap().collect();
    assert_eq!(dropped.len(), 3 + 2 * 2 * 3 * 4 + 3);
    assert_eq!(dropped[0].stroke.label(), "rest_start");
    assert_eq!(dropped.last().unwrap().stroke.label(), "rest_end");
    let fwd: Vec<f64> =
        dropped.iter().filter(|s| s.run == 1 && s.stroke == SimStroke::Forward).map(|s| s.rate_dps).collect();
    assert_eq!(fwd, [-10.0, -10.0, -10.0, -10.0, 0.0, 0.0, 0.0, 0.0, 10.0, 10.0, 10.0, 10.0]);
    let flagged = RateTableSpec { settling: SettlingRows::Flag, ..base };
    let all: Vec<RateTableSample> = RateTableGenerator::new(&ideal(), &flagged, 1).unwrap().collect();
    // 5 settling samples on every plateau but rest_start.
    assert_eq!(all.len(), dropped.len() + 5 * (2 * 2 * 3 + 1));
    assert_eq!(all.iter().filter(|s| !s.settling).count(), dropped.len());
    // The time keeps running through dropped settling samples.
    assert_eq!(dropped.last().unwrap().time_s, all.last().unwrap().time_s);
}

#[test]
fn bad_parameters_are_rejected_with_the_parameter_named() {
    let name = |e: SimError| match e {
        SimError::OutOfRange { parameter, .. } => parameter,
        other => panic!("unexpected {other}"),
    };
    let spec = static_spec(100.0, 10.0);
    let e = StaticGenerator::new(&SensorModel { arw_deg_rt_h: -0.1, ..ideal() }, &spec, 0).unwrap_err();
    assert!(e.to_string().contains("arw_deg_rt_h") && e.to_string().contains(">= 0"), "{e}");
    assert_eq!(name(e), "arw_deg_rt_h");
    let e = StaticGenerator::new(&SensorModel { rrw_deg_h_rt_h: f64::NAN, ..ideal() }, &spec, 0).unwrap_err();
    assert_eq!(name(e), "rrw_deg_h_rt_h");
    for fs in [0.0, -5.0, f64::INFINITY] {
        let e = StaticGenerator::new(&ideal(), &static_spec(fs, 10.0), 0).unwrap_err();
        assert_eq!(name(e), "sample_rate_hz");
    }
    let rails_inside = SensorModel { output_rail_low: Some(2.6), ..SensorModel::preset(Preset::Adxrs646) };
    let e = StaticGenerator::new(&rails_inside, &spec, 0).unwrap_err();
    assert!(matches!(e, SimError::RailsMustEncloseNull { .. }), "{e}");
    assert!(e.to_string().contains("output_rail_low"));
    let empty = RateTableSpec { rates_dps: vec![], ..RateTableSpec::default() };
    assert_eq!(RateTableGenerator::new(&ideal(), &empty, 0).unwrap_err(), SimError::TooFewRates { found: 0 });
    let dup = RateTableSpec { rates_dps: vec![1.0, 1.0, 2.0], ..RateTableSpec::default() };
    assert!(matches!(RateTableGenerator::new(&ideal(), &dup, 0).unwrap_err(), SimError::DuplicateRate { .. }));
    let runs0 = RateTableSpec { runs: 0, ..RateTableSpec::default() };
    assert_eq!(name(RateTableGenerator::new(&ideal(), &runs0, 0).unwrap_err()), "runs");
    // Flicker range must start at 10 sample intervals or later: 1 s at 1 Hz is too short.
    let bi = SensorModel { bias_instability_dph: 1.0, flicker_tau_min_s: 1.0, ..ideal() };
    let e = StaticGenerator::new(&bi, &static_spec(1.0, 100.0), 0).unwrap_err();
    assert!(e.to_string().contains("10 s at 1 Hz"), "{e}");
    let zero_k = SensorModel { scale_factor_per_dps: 0.0, ..ideal() };
    assert_eq!(name(StaticGenerator::new(&zero_k, &spec, 0).unwrap_err()), "scale_factor_per_dps");
    let lat = StaticSpec { latitude_deg: Some(91.0), ..spec.clone() };
    assert_eq!(name(StaticGenerator::new(&ideal(), &lat, 0).unwrap_err()), "latitude_deg");
}

#[test]
fn presets_validate_and_overrides_replace_fields() {
    for p in Preset::ALL {
        let m = SensorModel::preset(p);
        m.validate().unwrap();
        assert_eq!(Preset::parse(p.name()), Some(p));
        let v = outputs(&m, &static_spec(100.0, 2.0), 1);
        assert!(v.iter().all(|x| x.is_finite()));
    }
    let o =
        SensorOverrides { arw_deg_rt_h: Some(1.5), output_rail_high: Some(Some(5.0)), ..SensorOverrides::default() };
    let m = SensorModel::preset(Preset::Adxrs646).with_overrides(&o);
    assert_eq!((m.arw_deg_rt_h, m.output_rail_high, m.bias_instability_dph), (1.5, Some(5.0), 12.0));
    let cfg = SimConfig { preset: Some(Preset::Stim300), sensor: o, ..SimConfig::default() };
    assert_eq!(cfg.sensor_model().scale_factor_error_ppm, 500.0);
    assert!(m.parameter_lines().iter().any(|(k, v)| *k == "arw_deg_rt_h" && v == "1.5"));
}

#[test]
fn blocks_give_the_samples_of_the_iterator() {
    // Every term of the model that the block path computes in its own passes: all noises, bias
    // ramp and temperature terms, earth rate, nonlinearity, asymmetry, rails, both quantizations.
    let full = SensorModel {
        bias_dph: 30.0,
        rate_ramp_dph_per_h: 50.0,
        bias_temp_coeff_dph_per_c: 2.0,
        scale_factor_temp_coeff_ppm_per_c: 40.0,
        scale_factor_asymmetry_ppm: 300.0,
        nonlinearity_quadratic_per_dps: 1e-4,
        nonlinearity_cubic_per_dps2: -1e-6,
        rrw_deg_h_rt_h: 20.0,
        ..SensorModel::preset(Preset::Adxrs646)
    };
    let models = [
        full.clone(),
        SensorModel { output_quantization_step: 1e-3, ..full.clone() },
        SensorModel { angle_quantization_deg: 1e-3, ..full.clone() },
        SensorModel { output_rail_high: Some(2.5004), ..full },
        SensorModel { arw_deg_rt_h: 0.0, rrw_deg_h_rt_h: 0.0, ..ideal() },
    ];
    let temperatures = [
        TemperatureProfile::default(),
        TemperatureProfile::Ramp { start_c: 20.0, rate_c_per_h: 30.0 },
        TemperatureProfile::Steps { start_c: 20.0, steps: vec![TemperatureStep { at_s: 7.3, temp_c: 45.0 }] },
    ];
    for (m, model) in models.iter().enumerate() {
        for (t, temperature) in temperatures.iter().enumerate() {
            let spec = StaticSpec {
                temperature: temperature.clone(),
                latitude_deg: Some(40.0),
                record_temperature: t > 0,
                ..static_spec(100.0, 20.0)
            };
            let one_by_one: Vec<StaticSample> = StaticGenerator::new(model, &spec, 5).unwrap().collect();
            for block_size in [1, 7, 256, 5000] {
                let mut generator = StaticGenerator::new(model, &spec, 5).unwrap();
                let mut block = StaticBlock::default();
                let mut from_blocks = Vec::new();
                while generator.next_block(&mut block, block_size) > 0 {
                    assert_eq!(block.first_index, from_blocks.len() as u64);
                    from_blocks.extend((0..block.len()).map(|i| block.sample(i)));
                }
                assert_eq!(from_blocks.len(), 2000);
                for (i, (a, b)) in from_blocks.iter().zip(&one_by_one).enumerate() {
                    let bits = |s: &StaticSample| (s.time_s.to_bits(), s.output.to_bits(), s.temp_c.map(f64::to_bits));
                    assert_eq!(bits(a), bits(b), "model {m}, temperature {t}, blocks of {block_size}, sample {i}");
                }
            }
        }
    }
}
