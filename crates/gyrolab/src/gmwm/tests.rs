use super::*;
use crate::allan::{deviation_from_rate, AllanOptions, AllanPoint, TauList};
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};

/// A rate record of white noise N and random walk K (deg/s units), tau0 = 0.01 s.
fn record(seed: u64, n: usize, white: f64, walk: f64, tau0: f64) -> Vec<f64> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut bias = 0.0;
    (0..n)
        .map(|_| {
            let w: f64 = StandardNormal.sample(&mut rng);
            let v: f64 = StandardNormal.sample(&mut rng);
            bias += walk * tau0.sqrt() * v;
            white / tau0.sqrt() * w + bias
        })
        .collect()
}

fn curve(rate: Vec<f64>, tau0: f64) -> AllanCurve {
    let opts =
        AllanOptions { kind: DeviationKind::Oadev, taus: TauList::Octave, confidence: Some(0.683), max_factor: None };
    deviation_from_rate(rate, tau0, &opts).unwrap()
}

#[test]
fn exact_wavelet_variances_give_the_parameters_back() {
    // nu^2 built by hand from N = 0.01, K = 0.002, Q = 1e-4 (AVAR / 2 of IEEE 952's terms).
    let (q, n, k) = (1e-3, 0.01, 0.002);
    let wv: Vec<WaveletVariance> = (0..14)
        .map(|j| {
            let tau = 0.01 * f64::from(1u32 << j);
            let avar = 3.0 * q * q / (tau * tau) + n * n / tau + k * k * tau / 3.0;
            WaveletVariance { tau_s: tau, nu2: avar / 2.0, edf: 1000.0, m: 1 << j, terms: 100_000 }
        })
        .collect();
    let fit = select_model(&wv, &PROCESSES, 0.95).unwrap();
    assert_eq!(fit.parameters.len(), 3, "{fit:?}");
    let direct = fit_processes(&wv, &[Process::Quantization, Process::White, Process::RandomWalk], 0.95).unwrap();
    assert_eq!(direct.parameters, fit.parameters);
    for (p, truth) in [(Process::Quantization, q), (Process::White, n), (Process::RandomWalk, k)] {
        let v = fit.value(p).unwrap();
        assert!((v / truth - 1.0).abs() < 1e-9, "{p:?}: {v} vs {truth}");
    }
    assert!(fit.objective < 1e-12);
}

#[test]
fn haar_wavelet_variance_is_half_the_overlapping_allan_variance() {
    let c = curve(record(1, 1 << 12, 0.01, 0.0, 0.01), 0.01);
    let wv = wavelet_variance(&c).unwrap();
    assert_eq!(wv.len(), c.points.len());
    for (w, p) in wv.iter().zip(&c.points) {
        assert_eq!(w.nu2, p.deviation * p.deviation / 2.0);
        assert_eq!(w.tau_s, p.tau_s);
    }
    let mut decade = c.clone();
    decade.points[1].m = 3;
    assert!(matches!(wavelet_variance(&decade), Err(GmwmError::Curve(_))));
}

#[test]
fn white_plus_random_walk_against_simulated_truth() {
    // 30 seeds of 2^16 samples at 100 Hz: N = 0.01 deg/sqrt(s), K = 0.001 deg/s/sqrt(s).
    let (n, k, tau0) = (0.01, 0.001, 0.01);
    let (mut sum_n, mut sum_k, mut covered, mut total) = (0.0, 0.0, 0, 0);
    let seeds = 30;
    for seed in 0..seeds {
        let c = curve(record(100 + seed, 1 << 16, n, k, tau0), tau0);
        let wv = wavelet_variance(&c).unwrap();
        let fit = fit_processes(&wv, &[Process::White, Process::RandomWalk], 0.683).unwrap();
        for (p, truth) in [(Process::White, n), (Process::RandomWalk, k)] {
            let Some(par) = fit.parameter(p) else {
                total += 1;
                continue;
            };
            if p == Process::White {
                sum_n += par.value;
            } else {
                sum_k += par.value;
            }
            total += 1;
            if par.lower <= truth && truth <= par.upper {
                covered += 1;
            }
            assert!(par.lower <= par.value && par.value <= par.upper, "{par:?}");
        }
    }
    let mean_n = sum_n / seeds as f64;
    let mean_k = sum_k / seeds as f64;
    assert!((mean_n / n - 1.0).abs() < 0.02, "mean N {mean_n}");
    assert!((mean_k / k - 1.0).abs() < 0.15, "mean K {mean_k}");
    // The intervals' coverage of the truth: 60 intervals at nominal 68.3 % (binomial sd about 6
    // points); the intervals of the diagonal (independent-scales) covariance covered 37 %, so
    // this band fails them. The 200-seed study by parameter and record length is
    // `gmwm_coverage_study` below (ignored: run by hand, figures in docs/METHODS.md 3.1).
    let coverage = f64::from(covered) / f64::from(total);
    assert!((0.5..=0.85).contains(&coverage), "GMWM 68.3 % interval coverage over {total} intervals: {coverage:.3}");
}

#[test]
fn model_choice_finds_white_and_random_walk() {
    let (n, k, tau0) = (0.01, 0.001, 0.01);
    let mut right = 0;
    for seed in 0..8 {
        let c = curve(record(500 + seed, 1 << 16, n, k, tau0), tau0);
        let fit = gmwm(&c, 0.683).unwrap();
        let has = |p| fit.value(p).is_some();
        if has(Process::White) && has(Process::RandomWalk) {
            right += 1;
        }
    }
    assert!(right >= 6, "{right} of 8");
}

#[test]
fn bad_requests_are_errors() {
    let wv = [WaveletVariance { tau_s: 1.0, nu2: 1.0, edf: 10.0, m: 1, terms: 10 }];
    assert!(matches!(fit_processes(&wv, &[Process::White], 0.683), Err(GmwmError::TooFewScales { .. })));
    assert!(matches!(fit_processes(&wv, &[Process::White], 1.5), Err(GmwmError::Confidence(_))));
}

fn point(tau_s: f64, dev: f64, upper: f64) -> AllanPoint {
    AllanPoint {
        m: 1,
        tau_s,
        deviation: dev,
        terms: 100,
        alpha: None,
        noise_id: None,
        edf: Some(100.0),
        lower: Some(dev * 0.9),
        upper: Some(upper),
    }
}

#[test]
fn overbound_factors_by_hand() {
    // N = 1, K = 1: crossing at sqrt(3) s. Upper bounds 1.5 x the model at tau 0.1 (white side)
    // and 2 x the model's random-walk term at tau 100 (random-walk side).
    let model = |t: f64| (1.0 / t + t / 3.0).sqrt();
    let u_k2: f64 = 4.0 * 100.0 / 3.0 + 1.0 / 100.0;
    let c = AllanCurve {
        kind: DeviationKind::Oadev,
        tau0_s: 0.1,
        n_rate: 10000,
        confidence: Some(0.683),
        points: vec![point(0.1, model(0.1), 1.5 * model(0.1)), point(100.0, model(100.0), u_k2.sqrt())],
    };
    let f = overbound_factors(&c, Some(1.0), Some(1.0), None).unwrap();
    // f_N^2 / 0.1 + 0.1 / 3 = 2.25 (10 + 1/30)
    let want_n = ((2.25 * (10.0 + 0.1 / 3.0) - 0.1 / 3.0) * 0.1f64).sqrt();
    assert!((f.white.unwrap() - want_n).abs() < 1e-12);
    assert!((f.random_walk.unwrap() - 2.0).abs() < 1e-12);
    // The inflated model lies on or above every upper bound.
    for p in &c.points {
        let m2 = want_n * want_n / p.tau_s + 4.0 * p.tau_s / 3.0;
        assert!(m2.sqrt() >= p.upper.unwrap() * (1.0 - 1e-12));
    }
    // A model already above the bounds needs no factor.
    let g = overbound_factors(&c, Some(10.0), Some(10.0), None).unwrap();
    assert_eq!((g.white, g.random_walk), (Some(1.0), Some(1.0)));
    assert!(overbound_factors(&c, None, None, None).is_none());
}

/// Coverage of the GMWM intervals by parameter, `seeds` records of `len` samples (N, K as in
/// the test above): (covered N, covered K, seeds).
fn coverage_study(seeds: u64, len: usize, confidence: f64, processes: &[Process]) -> (u32, u32, u32) {
    let (n, k, tau0) = (0.01, 0.001, 0.01);
    let (mut cn, mut ck) = (0, 0);
    for seed in 0..seeds {
        let c = curve(record(1000 + seed, len, n, k, tau0), tau0);
        let wv = wavelet_variance(&c).unwrap();
        let fit = fit_processes(&wv, processes, confidence).unwrap();
        let inside = |p: Process, truth: f64| fit.parameter(p).is_some_and(|x| x.lower <= truth && truth <= x.upper);
        cn += u32::from(inside(Process::White, n));
        ck += u32::from(inside(Process::RandomWalk, k));
    }
    (cn, ck, seeds as u32)
}

#[test]
#[ignore = "study: cargo test -p gyrolab --release --lib gmwm_coverage_study -- --ignored --nocapture"]
fn gmwm_coverage_study() {
    for conf in [0.683, 0.95] {
        for len in [1usize << 14, 1 << 16, 1 << 18] {
            let (cn, ck, s) = coverage_study(200, len, conf, &[Process::White, Process::RandomWalk]);
            let share = |c: u32| f64::from(c) / f64::from(s);
            eprintln!("conf {conf} len {len}: N {:.3}  K {:.3} ({s} seeds)", share(cn), share(ck));
        }
    }
}
