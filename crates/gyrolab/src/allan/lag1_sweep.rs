//! Lag-1 autocorrelation noise identification at many averaging factors at once: the rule of
//! [`lag1_noise_id`] (W. J. Riley, C. A. Greenhall, "Power law noise identification using the
//! lag 1 autocorrelation", EFTF 2004, applied as Stable32 does; see `confidence`), computed for
//! the long series (small m) in two sweeps over the angle series instead of two per factor.
//!
//! For every factor m with at least [`SWEEP_MIN_AVERAGES`] averages, the averages
//! w_j = s[(j+1) m] - s[j m] (the factor 1/m does not change r1) are formed block by block
//! (blocks of [`BLOCK`] angle points, which stay in cache while every factor takes its
//! averages from them) into a small buffer, and summed in [`LANES`] independent lanes (the
//! sums vectorise and no add waits for the previous one). Sweep 1 gives each factor's
//! least-squares line (orthogonal polynomials 1 and t - c; sum (t - c)^2 = n (n^2 - 1) / 12 in
//! closed form); sweep 2 the residual's sums w, w^2, w_t w_{t+1}, first and last, hence
//! r1 = (S11 - mu (S1 - w_last + S1 - w_first) + (n - 1) mu^2) / (S2 - n mu^2) as in
//! [`lag1_noise_id`]. The record is cut into [`PARTS`] pieces summed in parallel and combined in
//! a fixed order, so the result does not depend on the number of threads.
//!
//! Only the undifferenced series (order 0) is swept: a factor whose delta = r1 / (1 + r1) is at
//! least 0.25 and whose estimator allows differencing goes to [`lag1_noise_id`] as before. The
//! sums are the same as [`lag1_noise_id`]'s in another order, so r1 differs from it by rounding
//! only (tested: within 1e-12); alpha = -round(2 delta) could differ only if delta fell within
//! that rounding of 0.25 or 0.75.

use super::confidence::{lag1_alpha, lag1_noise_id, LAG1_MIN_AVERAGES};
use rayon::prelude::*;

/// Factors with at least this many averages are swept; shorter series are summed one by one
/// (they are at most 1/16384 of the record each).
const SWEEP_MIN_AVERAGES: usize = 1 << 14;

/// Angle points per block of a sweep (256 KiB of f64: stays in the 1 MiB L2 cache while every
/// factor reads its averages from it).
const BLOCK: usize = 1 << 15;

/// Independent accumulators per sum.
const LANES: usize = 8;

/// Pieces of the record summed in parallel (fixed, so that results do not depend on threads).
const PARTS: usize = 4;

/// Lag-1 noise identification at every factor of `ms`, equal to `lag1_noise_id(s, m, dmax)` at
/// each (up to the rounding of r1, see the module documentation).
pub(crate) fn lag1_noise_ids(s: &[f64], ms: &[usize], dmax: usize) -> Vec<Option<i32>> {
    lag1_noise_ids_with(s, ms, dmax, SWEEP_MIN_AVERAGES, BLOCK)
}

fn lag1_noise_ids_with(s: &[f64], ms: &[usize], dmax: usize, min_averages: usize, block: usize) -> Vec<Option<i32>> {
    let min_averages = min_averages.max(LAG1_MIN_AVERAGES).max(3 * PARTS);
    let averages = |m: usize| if m == 0 || s.len() < 2 { 0 } else { (s.len() - 1) / m };
    let mut swept: Vec<usize> = ms.iter().copied().filter(|&m| averages(m) >= min_averages).collect();
    swept.sort_unstable();
    swept.dedup();
    let r1 = order0_r1(s, &swept, block);
    let can_difference = dmax.saturating_sub(1) > 0;
    ms.par_iter()
        .map(|&m| match swept.binary_search(&m) {
            Ok(i) => {
                let r1 = r1[i]?;
                let delta = r1 / (1.0 + r1);
                if delta < 0.25 || !can_difference {
                    Some(lag1_alpha(delta, 0))
                } else {
                    lag1_noise_id(s, m, dmax)
                }
            }
            Err(_) => lag1_noise_id(s, m, dmax),
        })
        .collect()
}

/// Per factor, per lane: sums of w and of w (t - c).
#[derive(Clone, Copy, Default)]
struct TrendSums {
    s0: [f64; LANES],
    s1: [f64; LANES],
}

/// Per factor: lane sums of the residual r, r^2 and r_t r_{t+1}, and the first and last residual
/// of a part.
#[derive(Clone, Copy, Default)]
struct ResidualSums {
    sum1: [f64; LANES],
    sum2: [f64; LANES],
    sum11: [f64; LANES],
    first: f64,
    last: f64,
    started: bool,
}

/// The undifferenced lag-1 autocorrelation r1 of the detrended averages at every factor of
/// `ms` (each with at least 3 averages); `None` where the residual has no spread.
fn order0_r1(s: &[f64], ms: &[usize], block: usize) -> Vec<Option<f64>> {
    if ms.is_empty() {
        return Vec::new();
    }
    let ns: Vec<usize> = ms.iter().map(|&m| (s.len() - 1) / m).collect();
    let cs: Vec<f64> = ns.iter().map(|&n| (n as f64 - 1.0) / 2.0).collect();
    let last_point = s.len() - 1;
    let bounds = |p: usize| (last_point * p / PARTS, last_point * (p + 1) / PARTS);
    // sweep 1: the lines
    let trend: Vec<Vec<TrendSums>> = (0..PARTS)
        .into_par_iter()
        .map(|p| {
            let (lo, hi) = bounds(p);
            let mut acc = vec![TrendSums::default(); ms.len()];
            for_each_block(s, ms, &ns, lo, hi, block, |i, j0, w| trend_sums(w, j0 as f64 - cs[i], &mut acc[i]));
            acc
        })
        .collect();
    let lines: Vec<(f64, f64)> = (0..ms.len())
        .map(|i| {
            let (mut s0, mut s1) = ([0.0f64; LANES], [0.0f64; LANES]);
            for part in &trend {
                for l in 0..LANES {
                    s0[l] += part[i].s0[l];
                    s1[l] += part[i].s1[l];
                }
            }
            let n = ns[i] as f64;
            let n1 = n * (n * n - 1.0) / 12.0;
            (pairwise(&s0) / n, pairwise(&s1) / n1)
        })
        .collect();
    // sweep 2: the residuals' sums
    let resid: Vec<Vec<ResidualSums>> = (0..PARTS)
        .into_par_iter()
        .map(|p| {
            let (lo, hi) = bounds(p);
            let mut acc = vec![ResidualSums::default(); ms.len()];
            for_each_block(s, ms, &ns, lo, hi, block, |i, j0, w| {
                let (a0, a1) = lines[i];
                residual_sums(w, j0 as f64 - cs[i], a0, a1, &mut acc[i])
            });
            acc
        })
        .collect();
    (0..ms.len())
        .map(|i| {
            let (mut sum1, mut sum2, mut sum11) = ([0.0f64; LANES], [0.0f64; LANES], [0.0f64; LANES]);
            let (mut first, mut last, mut started) = (0.0f64, 0.0f64, false);
            let mut joins = 0.0f64;
            for part in &resid {
                let r = &part[i];
                if !r.started {
                    continue;
                }
                if started {
                    joins += last * r.first;
                } else {
                    first = r.first;
                    started = true;
                }
                last = r.last;
                for l in 0..LANES {
                    sum1[l] += r.sum1[l];
                    sum2[l] += r.sum2[l];
                    sum11[l] += r.sum11[l];
                }
            }
            let (sum1, sum2, sum11) = (pairwise(&sum1), pairwise(&sum2), pairwise(&sum11) + joins);
            let lf = ns[i] as f64;
            let mu = sum1 / lf;
            let den = sum2 - lf * mu * mu;
            if den <= 0.0 || !den.is_finite() {
                return None;
            }
            let num = sum11 - mu * ((sum1 - last) + (sum1 - first)) + (lf - 1.0) * mu * mu;
            Some(num / den)
        })
        .collect()
}

/// Calls `f(factor index, j0, averages w_j0 ..)` for every block of angle points in
/// [`lo`, `hi`) and every factor: the averages whose first point s[j m] lies in the block.
fn for_each_block(
    s: &[f64],
    ms: &[usize],
    ns: &[usize],
    lo: usize,
    hi: usize,
    block: usize,
    mut f: impl FnMut(usize, usize, &mut [f64]),
) {
    let mut buf = vec![0.0f64; block + 1];
    let mut b0 = lo;
    while b0 < hi {
        let b1 = (b0 + block).min(hi);
        for (i, (&m, &n)) in ms.iter().zip(ns).enumerate() {
            let (j0, j1) = (b0.div_ceil(m).min(n), b1.div_ceil(m).min(n));
            if j0 >= j1 {
                continue;
            }
            let w = &mut buf[..j1 - j0];
            if m == 1 {
                let (a, b) = (&s[j0..j1], &s[j0 + 1..=j1]);
                for ((w, a), b) in w.iter_mut().zip(a).zip(b) {
                    *w = b - a;
                }
            } else {
                let z = &s[j0 * m..=j1 * m];
                let (mut at, mut prev) = (0usize, z[0]);
                for w in w.iter_mut() {
                    at += m;
                    let v = z[at];
                    *w = v - prev;
                    prev = v;
                }
            }
            f(i, j0, w);
        }
        b0 = b1;
    }
}

/// Position ramps t - c of the lanes, starting at `p0`.
#[inline(always)]
fn ramp(p0: f64) -> [f64; LANES] {
    std::array::from_fn(|l| p0 + l as f64)
}

/// Adds w and w (t - c) to the lanes; `p0` is t - c of `w[0]`.
fn trend_sums(w: &[f64], p0: f64, acc: &mut TrendSums) {
    let mut p = ramp(p0);
    let chunks = w.chunks_exact(LANES);
    let rest = chunks.remainder();
    for c in chunks {
        for l in 0..LANES {
            acc.s0[l] += c[l];
            acc.s1[l] += c[l] * p[l];
            p[l] += LANES as f64;
        }
    }
    for (l, &v) in rest.iter().enumerate() {
        acc.s0[l] += v;
        acc.s1[l] += v * p[l];
    }
}

/// Replaces `w` by its residual from the line a0 + a1 (t - c) and adds r, r^2 and the products of
/// neighbours (with the part's previous residual) to the lanes.
fn residual_sums(w: &mut [f64], p0: f64, a0: f64, a1: f64, acc: &mut ResidualSums) {
    let mut p = ramp(p0);
    let mut chunks = w.chunks_exact_mut(LANES);
    for c in &mut chunks {
        for l in 0..LANES {
            c[l] -= a0 + a1 * p[l];
            p[l] += LANES as f64;
        }
    }
    for (l, v) in chunks.into_remainder().iter_mut().enumerate() {
        *v -= a0 + a1 * p[l];
    }
    let Some((&head, _)) = w.split_first() else { return };
    if acc.started {
        acc.sum11[0] += acc.last * head;
    } else {
        acc.first = head;
        acc.started = true;
    }
    let chunks = w.chunks_exact(LANES);
    let rest = chunks.remainder();
    for c in chunks {
        for (l, &v) in c.iter().enumerate() {
            acc.sum1[l] += v;
            acc.sum2[l] += v * v;
        }
    }
    for (l, &v) in rest.iter().enumerate() {
        acc.sum1[l] += v;
        acc.sum2[l] += v * v;
    }
    let (a, b) = (&w[..w.len() - 1], &w[1..]);
    let (ac, bc) = (a.chunks_exact(LANES), b.chunks_exact(LANES));
    let (ar, br) = (ac.remainder(), bc.remainder());
    for (x, y) in ac.zip(bc) {
        for l in 0..LANES {
            acc.sum11[l] += x[l] * y[l];
        }
    }
    for (l, (x, y)) in ar.iter().zip(br).enumerate() {
        acc.sum11[l] += x * y;
    }
    acc.last = w[w.len() - 1];
}

/// Pairwise sum of the lanes.
fn pairwise(v: &[f64; LANES]) -> f64 {
    let mut v = *v;
    let mut width = LANES;
    while width > 1 {
        width /= 2;
        for l in 0..width {
            v[l] += v[l + width];
        }
    }
    v[0]
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};

    /// Angle series (cumulative sums from 0) of `n` rate samples: white, random walk, or
    /// integrated random walk noise, plus a rate offset and ramp.
    fn angle(n: usize, integrations: usize, seed: u64) -> Vec<f64> {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let mut y: Vec<f64> = (0..n).map(|_| StandardNormal.sample(&mut rng)).collect();
        for _ in 0..integrations {
            for i in 1..n {
                y[i] += y[i - 1];
            }
        }
        let mut s = vec![0.0];
        for (i, v) in y.iter().enumerate() {
            s.push(s[i] + v + 0.3 + 1e-4 * i as f64);
        }
        s
    }

    /// The plain r1 of the detrended averages: copies, [`detrend_linear`], [`lag1_acf`].
    fn plain_r1(s: &[f64], m: usize) -> Option<f64> {
        let z: Vec<f64> = s.iter().step_by(m).copied().collect();
        let mut w: Vec<f64> = z.windows(2).map(|p| p[1] - p[0]).collect();
        super::super::confidence::detrend_linear(&mut w);
        super::super::confidence::lag1_acf(&w)
    }

    #[test]
    fn sweep_equals_the_factor_by_factor_identification() {
        let mut swept_count = 0;
        for (n, integrations, seed) in [(5000, 0, 1), (4999, 1, 2), (7777, 2, 3), (60_000, 0, 4), (60_001, 1, 5)] {
            let s = angle(n, integrations, seed);
            let ms: Vec<usize> = (0..14).map(|k| 1 << k).chain([3, 5, 7, 10, 33, 100]).collect();
            for dmax in [1, 2, 3] {
                for block in [7, 64, 1000, BLOCK] {
                    let fast = lag1_noise_ids_with(&s, &ms, dmax, 30, block);
                    let plain: Vec<Option<i32>> = ms.iter().map(|&m| lag1_noise_id(&s, m, dmax)).collect();
                    assert_eq!(fast, plain, "n={n} integrations={integrations} dmax={dmax} block={block}");
                }
            }
            let swept: Vec<usize> = ms.iter().copied().filter(|&m| (s.len() - 1) / m >= 30).collect();
            let mut sorted = swept.clone();
            sorted.sort_unstable();
            for block in [7, 64, BLOCK] {
                for (&m, r1) in sorted.iter().zip(order0_r1(&s, &sorted, block)) {
                    let (r1, plain) = (r1.unwrap(), plain_r1(&s, m).unwrap());
                    assert!((r1 - plain).abs() <= 1e-12, "m={m}: {r1} vs {plain}");
                    swept_count += 1;
                }
            }
        }
        assert!(swept_count > 100);
    }

    #[test]
    fn constant_and_short_series() {
        assert_eq!(lag1_noise_ids_with(&[1.0; 200], &[1, 2], 2, 30, 16), vec![None, None]);
        assert_eq!(lag1_noise_ids(&[0.0], &[1], 2), vec![None]);
        assert_eq!(lag1_noise_ids(&[], &[1], 2), vec![None]);
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]
        #[test]
        fn sweep_agrees_on_arbitrary_records(
            y in prop::collection::vec(-1e3f64..1e3, 40..3000),
            block in 5usize..300,
            dmax in 1usize..4,
            walk in any::<bool>(),
        ) {
            let mut s = vec![0.0];
            let mut rate = 0.0;
            for v in &y {
                rate = if walk { rate + v } else { *v };
                s.push(s[s.len() - 1] + rate);
            }
            let ms: Vec<usize> = (1..=40).collect();
            let fast = lag1_noise_ids_with(&s, &ms, dmax, 30, block);
            let plain: Vec<Option<i32>> = ms.iter().map(|&m| lag1_noise_id(&s, m, dmax)).collect();
            prop_assert_eq!(fast, plain);
        }
    }
}
