//! Issue 15: the same record must give bit-identical deviations, bounds, noise types and noise
//! terms whatever the number of threads (the result used to depend on rayon's schedule through a
//! fold/reduce over blocks in the multi-tau OADEV sweep).

use gyrolab::allan::{deviation_from_rate_slice, AllanOptions, DeviationKind, TauList};
use gyrolab::noise::{fit_noise_model, slope_line_terms};
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};

/// White rate noise, a flicker-like floor (sum of AR(1) terms at octave time constants) and a
/// rate random walk on a 2.5 offset: every noise term of the slope-line method is present.
fn record(n: usize, seed: u64) -> Vec<f64> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut z = move || -> f64 { StandardNormal.sample(&mut rng) };
    let mut states = [0.0f64; 14];
    let mut walk = 0.0;
    (0..n)
        .map(|_| {
            let mut flicker = 0.0;
            for (j, st) in states.iter_mut().enumerate() {
                let a = 1.0 - 0.5f64.powi(j as i32);
                *st = a * *st + (1.0 - a * a).sqrt() * z();
                flicker += *st;
            }
            walk += 2e-6 * z();
            2.5 + 1e-2 * z() + 2e-4 * flicker + walk
        })
        .collect()
}

/// Everything computed from one record, printed with every f64 in shortest round-trip form
/// (distinct for distinct bit patterns, -0 included).
fn everything(long: &[f64], short: &[f64]) -> Vec<String> {
    let mut out = Vec::new();
    for kind in DeviationKind::ALL {
        let curve = deviation_from_rate_slice(long, 0.01, &AllanOptions::new(kind)).unwrap();
        out.push(format!("{curve:?}"));
        if matches!(kind, DeviationKind::Oadev | DeviationKind::Adev | DeviationKind::Totdev) {
            out.push(format!("{:?}", slope_line_terms(&curve)));
            out.push(format!("{:?}", fit_noise_model(&curve, None)));
        }
    }
    // >= 256 taus: the FFT expansion with directly summed taus; and a long explicit list that
    // stays on the cache-blocked multi-tau kernels (fewer than 256 taus)
    for taus in [TauList::All, TauList::PerDecade(40)] {
        let opts = AllanOptions::new(DeviationKind::Oadev).with_taus(taus);
        let curve = deviation_from_rate_slice(short, 0.1, &opts).unwrap();
        out.push(format!("{curve:?}"));
        out.push(format!("{:?}", slope_line_terms(&curve)));
        out.push(format!("{:?}", fit_noise_model(&curve, None)));
    }
    out
}

#[test]
fn results_are_bit_identical_for_1_2_3_and_7_threads() {
    let long = record(400_000, 15);
    let short = record(30_000, 16);
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(|| everything(&long, &short))
    };
    let reference = run(1);
    assert!(
        reference.iter().any(|s| s.contains("Lag1Autocorrelation")) && reference.iter().any(|s| s.contains("lower"))
    );
    for threads in [2, 3, 7] {
        let other = run(threads);
        assert_eq!(other.len(), reference.len());
        for (i, (a, b)) in reference.iter().zip(&other).enumerate() {
            assert!(a == b, "item {i} differs between 1 and {threads} threads:\n{a}\n{b}");
        }
    }
}
