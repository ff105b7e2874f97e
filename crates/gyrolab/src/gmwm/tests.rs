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
            // Degrees of freedom and terms as a record of 2^20 samples would give them.
            let m = f64::from(1u32 << j);
            WaveletVariance { tau_s: tau, nu2: avar / 2.0, edf: 1e6 / m, m: 1 << j, terms: 1_000_000 }
        })
        .collect();
    let fit = select_model(&wv, &PROCESSES, 0.95).unwrap();
    assert_eq!(fit.parameters.len(), 3, "{fit:?}");
    let direct = fit_processes(&wv, &[Process::Quantization, Process::White, Process::RandomWalk], 0.95).unwrap();
    // The same model and values, and the single model's intervals to 1e-9: the candidates that
    // hold the same processes plus another are dropped by the nesting rule (the extra term does
    // not pay its optimism on exact values), and those holding fewer weigh nothing beside it.
    assert_eq!(direct.parameters.len(), fit.parameters.len());
    for (d, f) in direct.parameters.iter().zip(&fit.parameters) {
        assert_eq!((d.process, d.value), (f.process, f.value));
        assert!((d.lower / f.lower - 1.0).abs() < 1e-9 && (d.upper / f.upper - 1.0).abs() < 1e-9, "{d:?} {f:?}");
    }
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
fn the_whole_procedure_against_simulated_truth() {
    // The GMWM as users get it (`gmwm`: the model chosen over every candidate, one and two
    // Gauss-Markov processes included, the intervals averaged over the candidates the nesting rule
    // leaves) on 120 seeds of 2^16 samples at 100 Hz of N = 0.01 deg/sqrt(s), K = 0.001
    // deg/s/sqrt(s). A term the chosen model leaves out counts as covered when its bound given
    // presence, [0, upper], holds the truth, as not covered without a bound. At nominal 68.3 % the
    // binomial sd is 4.2 points per term (120 intervals) and 3.0 pooled (240): the bands are about
    // 2.5 to 2.7 sd. These seeds give N 70.8 % and K 60.0 % (73.3 % and 60.0 % with every candidate
    // averaged). The test guards the level of the whole procedure against gross errors (the
    // diagonal covariance's 37 %, a broken mixture); it cannot tell the rule's few points from
    // their absence, which the hand test `average::tests::the_nesting_rule_drops_...` guards and
    // the study (bench/gmwm_study.sh, docs/METHODS.md 3.1) measures, each cell to 2.7 points over
    // 300 seeds. About 5 s in the test profile.
    let (n, k, tau0) = (0.01, 0.001, 0.01);
    let seeds = 120u64;
    let mut covered = [0u32; 2];
    for seed in 0..seeds {
        let fit = gmwm(&curve(record(3_000 + seed, 1 << 16, n, k, tau0), tau0), 0.683).unwrap();
        for (i, (p, truth)) in [(Process::White, n), (Process::RandomWalk, k)].into_iter().enumerate() {
            covered[i] += u32::from(match fit.parameter(p) {
                Some(par) => par.lower <= truth && truth <= par.upper,
                None => fit.left_out.iter().any(|b| b.process == p && truth <= b.upper),
            });
        }
    }
    let share = |c: u32, of: u64| f64::from(c) / of as f64;
    for (what, c) in [("N", covered[0]), ("K", covered[1])] {
        assert!((0.57..=0.80).contains(&share(c, seeds)), "{what}: 68.3 % coverage {:.3} of {seeds}", share(c, seeds));
    }
    let pooled = share(covered[0] + covered[1], 2 * seeds);
    assert!((0.61..=0.76).contains(&pooled), "pooled 68.3 % coverage {pooled:.3} of {}", 2 * seeds);
}

#[test]
fn white_plus_drift_against_simulated_truth() {
    // 40 seeds of 2^16 samples at 100 Hz: N = 0.01 deg/sqrt(s) and a drift R = 2e-4 deg/s^2, the
    // model white + drift. The drift's coefficients do not vary: with the chi-squared floor of
    // earlier versions its intervals covered the truth about 99 % of the time at nominal 68.3 %,
    // and without the cross term 4 c^2 var(e_bar) at the last scales they were too narrow.
    let (n, r, tau0) = (0.01, 2e-4, 0.01);
    let seeds = 40u64;
    let (mut sum_r, mut covered_r, mut covered_n) = (0.0, 0u32, 0u32);
    for seed in 0..seeds {
        let mut rate = record(900 + seed, 1 << 16, n, 0.0, tau0);
        for (i, x) in rate.iter_mut().enumerate() {
            *x += r * i as f64 * tau0;
        }
        let wv = wavelet_variance(&curve(rate, tau0)).unwrap();
        let fit = fit_processes(&wv, &[Process::White, Process::Drift], 0.683).unwrap();
        let (pn, pr) = (fit.parameter(Process::White).unwrap(), fit.parameter(Process::Drift).unwrap());
        sum_r += pr.value;
        covered_r += u32::from(pr.lower <= r && r <= pr.upper);
        covered_n += u32::from(pn.lower <= n && n <= pn.upper);
    }
    let mean_r = sum_r / seeds as f64;
    assert!((mean_r / r - 1.0).abs() < 0.01, "mean R {mean_r}");
    // 40 intervals each at nominal 68.3 % (binomial sd about 7 points).
    for (what, covered) in [("R", covered_r), ("N", covered_n)] {
        let coverage = f64::from(covered) / seeds as f64;
        assert!((0.5..=0.85).contains(&coverage), "{what}: 68.3 % interval coverage {coverage:.3}");
    }
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

/// Exact wavelet variances of white noise N, Gauss-Markov processes (sigma, T) and random walk K
/// at tau0 = 0.01 s over `scales` octaves.
fn exact_wv(n: f64, markov: &[(f64, f64)], k: f64, scales: u32) -> Vec<WaveletVariance> {
    (0..scales)
        .map(|j| {
            let m = f64::from(1u32 << j);
            let tau = 0.01 * m;
            let mut nu2 = n * n / (2.0 * tau) + k * k * tau / 6.0;
            for &(s, t) in markov {
                nu2 += s * s * gauss_markov_wavelet_variance(t, 0.01, m);
            }
            WaveletVariance { tau_s: tau, nu2, edf: 1e6 / m, m: 1 << j, terms: 1_000_000 }
        })
        .collect()
}

#[test]
fn exact_wavelet_variances_of_a_gauss_markov_model_give_its_parameters_back() {
    // N 0.01 deg/sqrt(s), GM sigma 0.02 deg/s with T 15 s, K 1e-4 deg/s/sqrt(s): 20 octaves.
    let wv = exact_wv(0.01, &[(0.02, 15.0)], 1e-4, 20);
    let fit = select_model_with_gauss_markov(&wv, &PROCESSES, MAX_GAUSS_MARKOV, 0.683).unwrap();
    let gm = fit.gauss_markov();
    assert_eq!(gm.len(), 1, "{fit:?}");
    let t = gm[0].correlation_time.unwrap();
    assert!((gm[0].value / 0.02 - 1.0).abs() < 2e-3, "{fit:?}");
    assert!((t.value_s / 15.0 - 1.0).abs() < 1e-3, "{t:?}");
    assert!(!t.at_search_edge && t.lower_s < t.value_s && t.value_s < t.upper_s);
    assert!((fit.value(Process::White).unwrap() / 0.01 - 1.0).abs() < 1e-4);
    assert!(fit.value(Process::Flicker).is_none() && fit.value(Process::Quantization).is_none());
    // K is small beside the process at long taus: over every candidate the criterion may take a
    // drift for it (a near tie on exact values); among white noise and random walk, K comes back.
    let nk = select_model_with_gauss_markov(&wv, &[Process::White, Process::RandomWalk], 1, 0.683).unwrap();
    assert!((nk.value(Process::RandomWalk).unwrap() / 1e-4 - 1.0).abs() < 1e-3, "{nk:?}");
    assert!(nk.objective < 1e-6, "{nk:?}");
    // The model without the Gauss-Markov process cannot fit these values: its criterion is far
    // larger.
    let linear = select_model(&wv, &PROCESSES, 0.683).unwrap();
    assert!(linear.criterion > fit.criterion + 100.0, "{} vs {}", linear.criterion, fit.criterion);
}

#[test]
fn two_gauss_markov_processes_are_separated() {
    // Two processes two decades apart (T 0.5 s and 80 s) on white noise.
    let wv = exact_wv(0.005, &[(0.01, 0.5), (0.004, 80.0)], 0.0, 20);
    let fit = select_model_with_gauss_markov(&wv, &PROCESSES, 2, 0.683).unwrap();
    let gm = fit.gauss_markov();
    assert_eq!(gm.len(), 2, "{fit:?}");
    for (p, (s, t)) in gm.iter().zip([(0.01, 0.5), (0.004, 80.0)]) {
        let ct = p.correlation_time.unwrap();
        assert!((p.value / s - 1.0).abs() < 1e-3, "{p:?}");
        assert!((ct.value_s / t - 1.0).abs() < 1e-2, "{ct:?}");
    }
}

/// A rate record of white noise N plus a sampled Gauss-Markov process (sigma, T), tau0 0.01 s.
fn markov_record(seed: u64, len: usize, white: f64, sigma: f64, t: f64) -> Vec<f64> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let tau0 = 0.01;
    let phi = (-tau0 / t).exp();
    let drive = sigma * (1.0 - phi * phi).sqrt();
    let x0: f64 = StandardNormal.sample(&mut rng);
    let mut x = sigma * x0;
    (0..len)
        .map(|_| {
            let w: f64 = StandardNormal.sample(&mut rng);
            let v: f64 = StandardNormal.sample(&mut rng);
            x = phi * x + drive * v;
            white / tau0.sqrt() * w + x
        })
        .collect()
}

#[test]
fn gauss_markov_against_simulated_truth() {
    // 24 records of 2^17 samples (22 min at 100 Hz): N 0.01 deg/sqrt(s), sigma 0.01 deg/s,
    // T 5 s. The chosen model holds one Gauss-Markov process in most records; sigma and T
    // average near the truth, and their 68.3 % intervals cover it at about their level.
    let (n, s, t) = (0.01, 0.01, 5.0);
    let (mut found, mut sum_s, mut sum_lnt, mut covered, mut total) = (0, 0.0, 0.0, 0, 0);
    for seed in 0..24 {
        let c = curve(markov_record(7000 + seed, 1 << 17, n, s, t), 0.01);
        let fit = gmwm(&c, 0.683).unwrap();
        let gm = fit.gauss_markov();
        if gm.len() != 1 {
            continue;
        }
        found += 1;
        let ct = gm[0].correlation_time.unwrap();
        sum_s += gm[0].value;
        sum_lnt += ct.value_s.ln();
        covered += u32::from(gm[0].lower <= s && s <= gm[0].upper);
        covered += u32::from(ct.lower_s <= t && t <= ct.upper_s);
        total += 2;
    }
    assert!(found >= 20, "one Gauss-Markov process chosen in {found} of 24");
    let mean_s = sum_s / f64::from(found);
    let mean_t = (sum_lnt / f64::from(found)).exp();
    assert!((mean_s / s - 1.0).abs() < 0.05, "mean sigma {mean_s}");
    assert!((mean_t / t - 1.0).abs() < 0.15, "geometric mean T {mean_t}");
    let coverage = f64::from(covered) / f64::from(total);
    assert!((0.5..=0.85).contains(&coverage), "68.3 % coverage of sigma and T: {coverage:.3} of {total}");
}

#[test]
fn shape_integrals_give_the_direct_covariance() {
    // The covariance from the per-shape integrals equals the direct quadrature of S(f)^2.
    let wv = exact_wv(0.01, &[(0.02, 15.0)], 1e-4, 12);
    let grid = CovarianceGrid::new(&wv);
    let shapes = [
        Shape::Linear(Process::White),
        Shape::Linear(Process::RandomWalk),
        Shape::GaussMarkov(15.0),
        Shape::Linear(Process::Flicker),
    ];
    let integrals = ShapeIntegrals::new(&grid, &shapes);
    let model = [(shapes[0], 1e-4), (shapes[2], 4e-4), (shapes[1], 1e-8)];
    let direct = grid.covariance(&model);
    let cached = integrals.covariance(&model).unwrap();
    for (a, b) in direct.iter().flatten().zip(cached.iter().flatten()) {
        assert!((a - b).abs() <= 1e-9 * a.abs().max(b.abs()), "{a} vs {b}");
    }
    assert_eq!(direct, wavelet_variance_covariance(&wv, &model));
    assert!(integrals.covariance(&[(Shape::Linear(Process::Drift), 1.0)]).is_none());
}

/// The empirical variances of the wavelet-variance estimates over `seeds` simulated records
/// (white N and random walk K as in [`record`], plus a drift of `ramp` deg/s^2) against
/// [`scale_covariance`] under the true model: (ratios per scale, ratios of the spectral part
/// alone).
fn variance_ratios(seeds: u64, white: f64, walk: f64, ramp: f64) -> (Vec<f64>, Vec<f64>) {
    let tau0 = 0.01;
    let mut rows: Vec<Vec<f64>> = Vec::new();
    let mut last = Vec::new();
    for seed in 0..seeds {
        let mut rate = record(5_000 + seed, 1 << 14, white, walk, tau0);
        for (i, r) in rate.iter_mut().enumerate() {
            *r += ramp * i as f64 * tau0;
        }
        let wv = wavelet_variance(&curve(rate, tau0)).unwrap();
        rows.push(wv.iter().map(|w| w.nu2).collect());
        last = wv;
    }
    let mut model = vec![(Shape::Linear(Process::White), white * white)];
    if walk > 0.0 {
        model.push((Shape::Linear(Process::RandomWalk), walk * walk));
    }
    if ramp > 0.0 {
        model.push((Shape::Linear(Process::Drift), ramp * ramp));
    }
    let shapes: Vec<Shape> = model.iter().map(|m| m.0).collect();
    let integrals = ShapeIntegrals::new(&CovarianceGrid::new(&last), &shapes);
    let sigma = scale_covariance(&last, &integrals, &model).unwrap();
    let spectral = integrals.covariance(&model).unwrap();
    let s = rows.len() as f64;
    let (mut full, mut spectral_only) = (Vec::new(), Vec::new());
    for j in 0..last.len() {
        let mean = rows.iter().map(|r| r[j]).sum::<f64>() / s;
        let var = rows.iter().map(|r| (r[j] - mean).powi(2)).sum::<f64>() / (s - 1.0);
        full.push(var / sigma[j][j]);
        spectral_only.push(var / spectral[j][j]);
    }
    (full, spectral_only)
}

#[test]
fn scale_covariance_equals_the_spread_over_simulated_records() {
    // 150 records of 2^14 samples: a variance ratio has a sampling error of about 12 %, so each
    // scale is held to [0.6, 1.5] and their mean to 15 %.
    let check = |ratios: &[f64], what: &str| {
        for (j, r) in ratios.iter().enumerate() {
            assert!((0.6..1.5).contains(r), "{what}: scale {j}: empirical / model variance {r} ({ratios:?})");
        }
        let mean = ratios.iter().sum::<f64>() / ratios.len() as f64;
        assert!((mean - 1.0).abs() < 0.15, "{what}: mean ratio {mean} ({ratios:?})");
    };
    let (walk, _) = variance_ratios(150, 0.01, 0.001, 0.0);
    check(&walk, "white + random walk");
    // A drift: its coefficients do not vary, but their mean beside the noise's does (the cross
    // term). Without the cross term the largest scales' variance is understated many times.
    let (drift, spectral_only) = variance_ratios(150, 0.01, 0.0, 2e-4);
    check(&drift, "white + drift");
    let last = *spectral_only.last().unwrap();
    assert!(last > 5.0, "the drift's cross term matters at the last scale: spectral part alone {last}");
}

/// The variance of the mean of `terms` Haar coefficients at averaging factor `m` by direct sums of
/// the coefficients' weights on the samples (W_t = (mean x[t+m..t+2m) - mean x[t..t+m)) / 2):
/// white noise of unit variance per sample, and a random walk of unit step variance (its start
/// cancels: each coefficient's weights sum to zero).
fn mean_coefficient_variance_by_sums(m: usize, terms: usize) -> (f64, f64) {
    let len = terms + 2 * m - 1;
    let mut g = vec![0.0; len];
    for t in 0..terms {
        for i in 0..m {
            g[t + i] -= 0.5 / (m as f64 * terms as f64);
            g[t + m + i] += 0.5 / (m as f64 * terms as f64);
        }
    }
    let white = g.iter().map(|x| x * x).sum();
    // x_i = sum of steps u_1..u_i: the step u_l carries G_l = sum over i >= l of g_i.
    let mut tail = 0.0;
    let mut walk = 0.0;
    for x in g.iter().rev() {
        tail += x;
        walk += tail * tail;
    }
    (white, walk)
}

#[test]
fn mean_coefficient_variance_equals_direct_sums() {
    // tau0 = 1 s: white noise N = 1 is unit variance per sample, a random walk K = 1 unit steps.
    let pairs = [(1usize, 2usize), (1, 50), (2, 3), (4, 7), (8, 40), (16, 16), (32, 20), (64, 129), (128, 300)];
    let wv: Vec<WaveletVariance> = pairs
        .iter()
        .map(|&(m, terms)| WaveletVariance { tau_s: m as f64, nu2: 1.0, edf: 10.0, m: m as u64, terms: terms as u64 })
        .collect();
    let grid = CovarianceGrid::new(&wv);
    let white = grid.mean_coefficient_variance(&[(Shape::Linear(Process::White), 1.0)]);
    let walk = grid.mean_coefficient_variance(&[(Shape::Linear(Process::RandomWalk), 1.0)]);
    for (i, &(m, terms)) in pairs.iter().enumerate() {
        let (w, k) = mean_coefficient_variance_by_sums(m, terms);
        assert!((white[i] / w - 1.0).abs() < 2e-3, "white m {m} M {terms}: {} vs {w}", white[i]);
        assert!((walk[i] / k - 1.0).abs() < 2e-3, "random walk m {m} M {terms}: {} vs {k}", walk[i]);
        if terms + 1 >= 2 * m {
            // The closed form (module notes) where the two ends' averages do not overlap.
            let (mf, tf) = (m as f64, terms as f64);
            let hand = (2.0 * mf * mf + 1.0) / (6.0 * mf * tf * tf);
            assert!((w / hand - 1.0).abs() < 1e-12, "m {m} M {terms}: sum {w} vs (2m^2+1)/(6mM^2) {hand}");
        }
    }
}
