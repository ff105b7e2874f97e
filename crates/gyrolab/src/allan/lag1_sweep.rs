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
//! At the octave factors whose delta = r1 / (1 + r1) is at least 0.25 and whose estimator allows
//! differencing, a second sweep sums the first and second differences of the averages (the
//! residual's differences are those of the averages less a constant, a1, for the first, and
//! equal for the second; r1 does not change with a constant), so those factors are decided
//! without two passes each over their averages (white data need no second sweep). Elsewhere (factors not powers of two), or where a difference's variance is a
//! tiny part of its raw moments (a pure trend), it goes to [`lag1_noise_id`] as before. The sums
//! are the same as [`lag1_noise_id`]'s in another order, so r1 differs from it by rounding only
//! (tested: within 1e-12); alpha = -round(2 delta) could differ only if delta fell within that
//! rounding of 0.25 or 0.75.

use super::confidence::{lag1_alpha, lag1_noise_id, LAG1_MIN_AVERAGES};

/// Factors with at least this many averages are swept; shorter series are summed one by one
/// (they are at most 1/16384 of the record each).
const SWEEP_MIN_AVERAGES: usize = 1 << 14;

/// In an octave list (every factor a power of two) every factor the rule identifies by lag 1
/// (at least [`LAG1_MIN_AVERAGES`] averages) is swept: the octave sweep's levels above the first
/// cost a pairwise sum each, less than a factor's own two passes (a 10 min record at 100 Hz
/// spent a sixth of its analysis in those; issue 56). Other lists keep
/// [`SWEEP_MIN_AVERAGES`]: their sweep keeps sums per factor and part, which for every factor
/// of a long all-tau list would hold hundreds of MB.
const OCTAVE_SWEEP_MIN_AVERAGES: usize = LAG1_MIN_AVERAGES;

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
    let octave = ms.iter().all(|m| m.is_power_of_two());
    let min_averages = if octave { OCTAVE_SWEEP_MIN_AVERAGES } else { SWEEP_MIN_AVERAGES };
    lag1_noise_ids_with(s, ms, dmax, min_averages, BLOCK)
}

fn lag1_noise_ids_with(s: &[f64], ms: &[usize], dmax: usize, min_averages: usize, block: usize) -> Vec<Option<i32>> {
    let min_averages = min_averages.max(LAG1_MIN_AVERAGES).max(3 * PARTS);
    let averages = |m: usize| if m == 0 || s.len() < 2 { 0 } else { (s.len() - 1) / m };
    let mut swept: Vec<usize> = ms.iter().copied().filter(|&m| averages(m) >= min_averages).collect();
    swept.sort_unstable();
    swept.dedup();
    let r1: Vec<SweptR1> = if swept.iter().all(|m| m.is_power_of_two()) {
        octave_r1(s, &swept, block, dmax.saturating_sub(1).min(2))
    } else {
        order0_r1(s, &swept, block).into_iter().map(|order0| SweptR1 { order0, diffs: None }).collect()
    };
    let differences = dmax.saturating_sub(1).min(2);
    super::map_indices(s.len(), ms.len(), |i| {
        let m = ms[i];
        match swept.binary_search(&m) {
            Ok(i) => {
                let delta = r1[i].order0.map(|r| r / (1.0 + r))?;
                if delta < 0.25 || differences == 0 {
                    Some(lag1_alpha(delta, 0))
                } else {
                    match r1[i].diffs.map(|d| differenced_alpha(&d, differences)) {
                        Some(Ok(alpha)) => alpha,
                        _ => lag1_noise_id(s, m, dmax),
                    }
                }
            }
            Err(_) => lag1_noise_id(s, m, dmax),
        }
    })
}

/// A factor's r1 from a sweep: of the detrended averages (`None`: no spread), and, from the
/// octave sweep, of their first and second differences (`Err`: left to [`lag1_noise_id`]).
#[derive(Clone, Copy, Debug)]
struct SweptR1 {
    order0: Option<f64>,
    diffs: Option<[Result<Option<f64>, ()>; 2]>,
}

/// [`lag1_noise_id`]'s differencing steps (order 0 gave delta >= 0.25) from the differences'
/// r1: difference while delta >= 0.25 and `differences` allow; `Err` where an r1 is unknown.
fn differenced_alpha(diffs: &[Result<Option<f64>, ()>; 2], differences: usize) -> Result<Option<i32>, ()> {
    for d in 1..=differences {
        let Some(r1) = diffs[d - 1]? else { return Ok(None) };
        let delta = r1 / (1.0 + r1);
        if delta < 0.25 || d >= differences {
            return Ok(Some(lag1_alpha(delta, d)));
        }
    }
    Err(())
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
/// Raw moments of one factor's averages w_t over part of the record, in lanes: sum w,
/// sum w (t - c), sum w^2, sum w_t w_{t+1}, with the first and last average of the part; and
/// the sums of the first and second differences (each difference counted in the part of its
/// last average).
#[derive(Clone, Copy, Default)]
struct RawSums {
    s0: [f64; LANES],
    s1: [f64; LANES],
    w2: [f64; LANES],
    w11: [f64; LANES],
    first: f64,
    last: f64,
    started: bool,
    diffs: [ResidualSums; 2],
}

/// Cancellation allowed in the one-sweep residual sums: the residual's sum of squares must be
/// at least this fraction of the raw magnitudes it is formed from, else the factor is summed
/// again in two sweeps (six of sixteen digits lost at most, so r1 stays good to about 1e-9).
const RAW_MIN_FRACTION: f64 = 1e-6;

/// r1 of the order-0 residuals at power-of-two factors `ms` (sorted, each with at least
/// [`PARTS`] averages) in ONE sweep: per block, the factor-1 averages are the first differences
/// of the angle, and each factor's averages are the pair sums of the previous factor's
/// (w^{2m}_j = w^m_{2j} + w^m_{2j+1}, exact in real arithmetic), all while the block is in cache.
/// The residual sums of the least-squares line are formed from raw moments (sum w, sum w u,
/// sum w^2, sum w_t w_{t+1} with u = t - c; the expansion in docs/METHODS.md section 3); a factor
/// whose residual variance is a tiny part of its raw moments (a strong trend: the expansion
/// would cancel) is summed again by [`order0_r1`]'s two sweeps.
fn octave_r1(s: &[f64], ms: &[usize], block: usize, differences: usize) -> Vec<SweptR1> {
    let Some(&top_m) = ms.last() else { return Vec::new() };
    let n_rate = s.len() - 1;
    let levels = top_m.trailing_zeros() as usize + 1;
    let mut wanted = vec![None; levels];
    for (i, &m) in ms.iter().enumerate() {
        wanted[m.trailing_zeros() as usize] = Some(i);
    }
    // blocks hold a whole number of the largest factor's averages
    let block = block.next_power_of_two().max(top_m);
    let bounds = |p: usize| {
        let lo = n_rate * p / PARTS / block * block;
        let hi = if p + 1 == PARTS { n_rate } else { n_rate * (p + 1) / PARTS / block * block };
        (lo, hi)
    };
    let ns: Vec<usize> = (0..levels).map(|k| n_rate >> k).collect();
    let cs: Vec<f64> = ns.iter().map(|&n| (n as f64 - 1.0) / 2.0).collect();
    let sweep = |raw: &[bool], diff: &[bool]| -> Vec<Vec<RawSums>> {
        super::map_indices(s.len(), PARTS, |p| {
            let (lo, hi) = bounds(p);
            octave_part(s, raw, diff, &cs, lo, hi, block)
        })
    };
    // The sweep of the averages (order 0) at every wanted factor.
    let raw: Vec<bool> = wanted.iter().map(Option::is_some).collect();
    let parts = sweep(&raw, &vec![false; levels]);
    let mut r1 = vec![SweptR1 { order0: None, diffs: None }; ms.len()];
    let mut again = Vec::new();
    for k in 0..levels {
        let Some(i) = wanted[k] else { continue };
        match raw_r1(parts.iter().map(|p| &p[k]), ns[k], cs[k]) {
            Ok(v) => r1[i].order0 = v,
            Err(()) => again.push(i),
        }
    }
    if !again.is_empty() {
        let again_ms: Vec<usize> = again.iter().map(|&i| ms[i]).collect();
        for (&i, v) in again.iter().zip(order0_r1(s, &again_ms, block)) {
            r1[i].order0 = v;
        }
    }
    // A second sweep of the differences, at the factors that need them (delta >= 0.25 and the
    // estimator allows differencing); white data need none.
    let need: Vec<bool> = (0..levels)
        .map(|k| differences > 0 && wanted[k].and_then(|i| r1[i].order0).is_some_and(|r| r / (1.0 + r) >= 0.25))
        .collect();
    if need.iter().any(|&b| b) {
        let parts = sweep(&vec![false; levels], &need);
        for k in (0..levels).filter(|&k| need[k]) {
            let Some(i) = wanted[k] else { continue };
            r1[i].diffs = Some(std::array::from_fn(|d| {
                let sums = combine(parts.iter().map(|p| &p[k].diffs[d]));
                moment_r1(&sums, ns[k].saturating_sub(d + 1), true)
            }));
        }
    }
    r1
}

/// The raw sums of every wanted level over angle points `lo..hi` (see [`octave_r1`]); the AVX2
/// copy of the same code is taken where the CPU has it (the sums vectorise four wide).
fn octave_part(s: &[f64], raw: &[bool], diff: &[bool], cs: &[f64], lo: usize, hi: usize, block: usize) -> Vec<RawSums> {
    #[cfg(target_arch = "x86_64")]
    {
        if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
            // SAFETY: the CPU supports AVX2 and FMA (checked just above); the function is safe
            // code compiled for those features.
            return unsafe { octave_part_avx2(s, raw, diff, cs, lo, hi, block) };
        }
    }
    octave_part_body(s, raw, diff, cs, lo, hi, block)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn octave_part_avx2(
    s: &[f64],
    raw: &[bool],
    diff: &[bool],
    cs: &[f64],
    lo: usize,
    hi: usize,
    block: usize,
) -> Vec<RawSums> {
    octave_part_body(s, raw, diff, cs, lo, hi, block)
}

#[inline(always)]
fn octave_part_body(
    s: &[f64],
    raw: &[bool],
    diff: &[bool],
    cs: &[f64],
    lo: usize,
    hi: usize,
    block: usize,
) -> Vec<RawSums> {
    // Levels up to the last one summed (the pair sums stop there).
    let levels = raw.iter().zip(diff).rposition(|(&r, &d)| r || d).map_or(0, |k| k + 1);
    let mut acc = vec![RawSums::default(); raw.len()];
    // Work buffers no longer than the part (a short record's part is a fraction of a block:
    // zeroing whole blocks cost it more than its sums, issue 56).
    let span = block.min(hi.saturating_sub(lo));
    let mut scratch = take_scratch(4 * span + 4);
    octave_part_blocks(s, raw, diff, cs, (lo, hi), block, span, levels, &mut acc, &mut scratch[..4 * span + 4]);
    give_back_scratch(scratch);
    acc
}

thread_local! {
    /// The work buffer of this thread's sweeps, kept between calls: a new zeroed buffer per
    /// call cost a short record more in page faults and zeroing than its sums (issue 56).
    static SCRATCH: std::cell::RefCell<Vec<f64>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// This thread's work buffer, at least `len` values long (contents unspecified: its users write
/// each value before they read it); give it back with [`give_back_scratch`].
fn take_scratch(len: usize) -> Vec<f64> {
    let mut buf = SCRATCH.with(|cell| cell.take());
    if buf.len() < len {
        buf.resize(len, 0.0);
    }
    buf
}

/// Keeps `buf` as this thread's work buffer for the next sweep.
fn give_back_scratch(buf: Vec<f64>) {
    SCRATCH.with(|cell| cell.replace(buf));
}

/// The blocks of one part of [`octave_part_body`], its work buffers cut from `scratch`
/// (4 `span` + 4 values, each written before it is read).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn octave_part_blocks(
    s: &[f64],
    raw: &[bool],
    diff: &[bool],
    cs: &[f64],
    (lo, hi): (usize, usize),
    block: usize,
    span: usize,
    levels: usize,
    acc: &mut [RawSums],
    scratch: &mut [f64],
) {
    let (mut cur, rest) = scratch.split_at_mut(span);
    let (mut next, rest) = rest.split_at_mut(span);
    let (d1, d2) = rest.split_at_mut(span + 2);
    // Per level: the two averages before the block (read straight from the angle at the start
    // of a part after the first), and how many of them there are.
    let mut carry: Vec<([f64; 2], usize)> = (0..levels)
        .map(|k| {
            let (m, j0) = (1usize << k, lo >> k);
            let w = |j: usize| s[(j + 1) * m] - s[j * m];
            match j0 {
                0 => ([0.0; 2], 0),
                1 => ([0.0, w(0)], 1),
                _ => ([w(j0 - 2), w(j0 - 1)], 2),
            }
        })
        .collect();
    let mut b0 = lo;
    while b0 < hi {
        let b1 = (b0 + block).min(hi);
        let count = b1 - b0;
        for ((w, a), b) in cur[..count].iter_mut().zip(&s[b0..b1]).zip(&s[b0 + 1..=b1]) {
            *w = b - a;
        }
        for k in 0..levels {
            let count_k = count >> k;
            if count_k == 0 {
                break;
            }
            let w = &cur[..count_k];
            if raw[k] {
                raw_sums(w, (b0 >> k) as f64 - cs[k], &mut acc[k]);
            }
            if diff[k] {
                difference_sums(w, &mut carry[k], d1, d2, &mut acc[k].diffs);
            }
            if k + 1 < levels {
                let half = count_k / 2;
                for (v, pair) in next[..half].iter_mut().zip(cur[..2 * half].chunks_exact(2)) {
                    *v = pair[0] + pair[1];
                }
                std::mem::swap(&mut cur, &mut next);
            }
        }
        b0 = b1;
    }
}

/// Adds one block's averages `w` (the first at position t with t - c = `p0`) to the raw sums.
#[inline(always)]
fn raw_sums(w: &[f64], p0: f64, acc: &mut RawSums) {
    let Some(&head) = w.first() else { return };
    if acc.started {
        acc.w11[0] += acc.last * head;
    } else {
        acc.first = head;
        acc.started = true;
    }
    let mut p = ramp(p0);
    let chunks = w.chunks_exact(LANES);
    let rest = chunks.remainder();
    for c in chunks {
        for l in 0..LANES {
            acc.s0[l] += c[l];
            acc.s1[l] += c[l] * p[l];
            acc.w2[l] += c[l] * c[l];
            p[l] += LANES as f64;
        }
    }
    for (l, &v) in rest.iter().enumerate() {
        acc.s0[l] += v;
        acc.s1[l] += v * p[l];
        acc.w2[l] += v * v;
    }
    neighbour_products(w, &mut acc.w11);
    acc.last = w[w.len() - 1];
}

/// Adds the first and second differences that end in the block `w` (the two averages before it
/// in `carry`, updated) to their sums; `d1` and `d2` are work buffers (len >= w.len() + 2).
#[inline(always)]
fn difference_sums(
    w: &[f64],
    carry: &mut ([f64; 2], usize),
    d1: &mut [f64],
    d2: &mut [f64],
    acc: &mut [ResidualSums; 2],
) {
    let ([c2, c1], have) = *carry;
    let k = w.len();
    // d1[i] = (the average before w[i]) to w[i]: d1[0] = c1 - c2, d1[1] = w[0] - c1, ...
    d1[0] = c1 - c2;
    d1[1] = w[0] - c1;
    for ((d, &a), &b) in d1[2..=k].iter_mut().zip(&w[..k - 1]).zip(&w[1..]) {
        *d = b - a;
    }
    for ((d, &a), &b) in d2[..k].iter_mut().zip(&d1[..k]).zip(&d1[1..=k]) {
        *d = b - a;
    }
    // The first differences ending in w[i] need one average before it, the second two.
    let skip1 = 1usize.saturating_sub(have);
    let skip2 = 2usize.saturating_sub(have);
    if skip1 < k {
        moment_sums(&d1[1 + skip1..=k], &mut acc[0]);
    }
    if skip2 < k {
        moment_sums(&d2[skip2..k], &mut acc[1]);
    }
    *carry = match k {
        1 => ([c1, w[0]], (have + 1).min(2)),
        _ => ([w[k - 2], w[k - 1]], 2),
    };
}

/// The parts' sums of one series in part order: (sum, sum of squares, sum of neighbour
/// products across the joins too, first, last).
fn combine<'a>(parts: impl Iterator<Item = &'a ResidualSums> + Clone) -> (f64, f64, f64, f64, f64) {
    let (first, last, joins) = joined_ends(parts.clone().filter(|r| r.started).map(|r| (r.first, r.last)));
    let (mut sum1, mut sum2, mut sum11) = ([0.0f64; LANES], [0.0f64; LANES], [0.0f64; LANES]);
    for r in parts.filter(|r| r.started) {
        for l in 0..LANES {
            sum1[l] += r.sum1[l];
            sum2[l] += r.sum2[l];
            sum11[l] += r.sum11[l];
        }
    }
    (pairwise(&sum1), pairwise(&sum2), pairwise(&sum11) + joins, first, last)
}

/// The first value of the first part, the last of the last, and the sum of the neighbour
/// products across the joins (each part's last value times the next part's first), from the
/// (first, last) of the parts in order.
fn joined_ends(parts: impl Iterator<Item = (f64, f64)>) -> (f64, f64, f64) {
    let mut ends: Option<(f64, f64)> = None;
    let mut joins = 0.0f64;
    for (first, last) in parts {
        ends = Some(match ends {
            Some((f, l)) => {
                joins += l * first;
                (f, last)
            }
            None => (first, last),
        });
    }
    let (first, last) = ends.unwrap_or((0.0, 0.0));
    (first, last, joins)
}

/// r1 of a series of `len` values from its sums (as [`lag1_noise_id`]): `Ok(None)` for fewer
/// than 3 values or no spread. With `guard`, a variance under [`RAW_MIN_FRACTION`] of the sum
/// of squares (the mean is nearly all of it: cancellation) is `Err`.
fn moment_r1(sums: &(f64, f64, f64, f64, f64), len: usize, guard: bool) -> Result<Option<f64>, ()> {
    let &(sum1, sum2, sum11, first, last) = sums;
    if len < 3 {
        return Ok(None);
    }
    let lf = len as f64;
    let mu = sum1 / lf;
    let den = sum2 - lf * mu * mu;
    if guard && sum2 > 0.0 && den < RAW_MIN_FRACTION * sum2 {
        return Err(());
    }
    if den <= 0.0 || !den.is_finite() {
        return Ok(None);
    }
    let num = sum11 - mu * ((sum1 - last) + (sum1 - first)) + (lf - 1.0) * mu * mu;
    Ok(Some(num / den))
}

/// r1 of the residuals e_t = w_t - a0 - a1 u_t (u_t = t - c, n averages) from the parts' raw
/// sums, combined in part order; `Err` when the expansion would cancel (see [`RAW_MIN_FRACTION`]).
fn raw_r1<'a>(parts: impl Iterator<Item = &'a RawSums> + Clone, n: usize, c: f64) -> Result<Option<f64>, ()> {
    let (wf, wl, joins) = joined_ends(parts.clone().filter(|r| r.started).map(|r| (r.first, r.last)));
    let (mut s0, mut s1, mut w2, mut w11) = ([0.0f64; LANES], [0.0f64; LANES], [0.0f64; LANES], [0.0f64; LANES]);
    for r in parts.filter(|r| r.started) {
        for l in 0..LANES {
            s0[l] += r.s0[l];
            s1[l] += r.s1[l];
            w2[l] += r.w2[l];
            w11[l] += r.w11[l];
        }
    }
    let (s0, s1, w2, w11) = (pairwise(&s0), pairwise(&s1), pairwise(&w2), pairwise(&w11) + joins);
    let lf = n as f64;
    if n < 3 {
        return Ok(None);
    }
    let n1 = lf * (lf * lf - 1.0) / 12.0;
    let (a0, a1) = (s0 / lf, s1 / n1);
    // residual sums: e, e^2, e_t e_{t+1} (t < n - 1), first and last e
    let se = s0 - lf * a0;
    let see = w2 - a0 * s0 - a1 * s1;
    let head = a0 * (s0 - wl) + a1 * (s1 - wl * c + s0 - wl);
    let tail = a0 * (s0 - wf) + a1 * (s1 + wf * c - s0 + wf);
    let lines = (lf - 1.0) * (a0 * a0 + a0 * a1) - c * (2.0 * a0 * a1 + a1 * a1) + a1 * a1 * (n1 - c * c);
    let se11 = w11 - head - tail + lines;
    let (ef, el) = (wf - a0 + a1 * c, wl - a0 - a1 * c);
    let mu = se / lf;
    let den = see - lf * mu * mu;
    let magnitude = w2 + (a0 * s0).abs() + (a1 * s1).abs() + w11.abs() + head.abs() + tail.abs() + lines.abs();
    if !magnitude.is_finite() {
        return Ok(None);
    }
    if magnitude == 0.0 {
        // a series of zeros: no identification, as in the two sweeps
        return Ok(None);
    }
    if den < RAW_MIN_FRACTION * magnitude || !den.is_finite() {
        return Err(());
    }
    let num = se11 - mu * ((se - el) + (se - ef)) + (lf - 1.0) * mu * mu;
    Ok(Some(num / den))
}

fn order0_r1(s: &[f64], ms: &[usize], block: usize) -> Vec<Option<f64>> {
    if ms.is_empty() {
        return Vec::new();
    }
    let ns: Vec<usize> = ms.iter().map(|&m| (s.len() - 1) / m).collect();
    let cs: Vec<f64> = ns.iter().map(|&n| (n as f64 - 1.0) / 2.0).collect();
    let last_point = s.len() - 1;
    let bounds = |p: usize| (last_point * p / PARTS, last_point * (p + 1) / PARTS);
    // sweep 1: the lines
    let trend: Vec<Vec<TrendSums>> = super::map_indices(s.len(), PARTS, |p| {
        let (lo, hi) = bounds(p);
        let mut acc = vec![TrendSums::default(); ms.len()];
        for_each_block(s, ms, &ns, lo, hi, block, |i, j0, w| trend_sums(w, j0 as f64 - cs[i], &mut acc[i]));
        acc
    });
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
    let resid: Vec<Vec<ResidualSums>> = super::map_indices(s.len(), PARTS, |p| {
        let (lo, hi) = bounds(p);
        let mut acc = vec![ResidualSums::default(); ms.len()];
        for_each_block(s, ms, &ns, lo, hi, block, |i, j0, w| {
            let (a0, a1) = lines[i];
            residual_sums(w, j0 as f64 - cs[i], a0, a1, &mut acc[i])
        });
        acc
    });
    (0..ms.len()).map(|i| moment_r1(&combine(resid.iter().map(|part| &part[i])), ns[i], false).ok().flatten()).collect()
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
    let len = block.min(hi.saturating_sub(lo)) + 1;
    let mut scratch = take_scratch(len);
    let buf = &mut scratch[..len];
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
    give_back_scratch(scratch);
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
    moment_sums(w, acc);
}

/// Adds v, v^2 and the products of neighbours (with the part's previous value) of `w` to the
/// lanes.
#[inline(always)]
fn moment_sums(w: &[f64], acc: &mut ResidualSums) {
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
    neighbour_products(w, &mut acc.sum11);
    acc.last = w[w.len() - 1];
}

/// Adds the products of neighbours w_t w_{t+1} within `w` to the lanes.
#[inline(always)]
fn neighbour_products(w: &[f64], lanes: &mut [f64; LANES]) {
    let (a, b) = (&w[..w.len() - 1], &w[1..]);
    let (ac, bc) = (a.chunks_exact(LANES), b.chunks_exact(LANES));
    let (ar, br) = (ac.remainder(), bc.remainder());
    for (x, y) in ac.zip(bc) {
        for l in 0..LANES {
            lanes[l] += x[l] * y[l];
        }
    }
    for (l, (x, y)) in ar.iter().zip(br).enumerate() {
        lanes[l] += x * y;
    }
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

    /// The plain r1 of the d-th differences of the detrended averages.
    fn plain_diff_r1(s: &[f64], m: usize, d: usize) -> Option<f64> {
        let z: Vec<f64> = s.iter().step_by(m).copied().collect();
        let mut w: Vec<f64> = z.windows(2).map(|p| p[1] - p[0]).collect();
        super::super::confidence::detrend_linear(&mut w);
        for _ in 0..d {
            w = w.windows(2).map(|p| p[1] - p[0]).collect();
        }
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

    /// The one-sweep octave path (pair sums, raw moments) against the plain r1 of the
    /// detrended averages and against the factor-by-factor identification, on white, random-walk
    /// and integrated random-walk rates with an offset and a ramp, record lengths that are not
    /// multiples of the block, and blocks smaller than the largest factor.
    #[test]
    fn octave_sweep_equals_the_factor_by_factor_identification() {
        let (mut checked, mut differenced) = (0, 0);
        for (n, integrations, seed) in [(5000, 0, 1), (4999, 1, 2), (7777, 2, 3), (60_000, 0, 4), (60_001, 1, 5)] {
            let s = angle(n, integrations, seed);
            let ms: Vec<usize> = (0..12).map(|k| 1 << k).filter(|&m| (s.len() - 1) / m >= 30).collect();
            for block in [7, 64, 1000, BLOCK] {
                let octave = octave_r1(&s, &ms, block, 2);
                for (&m, r1) in ms.iter().zip(&octave) {
                    let (r1_0, plain) = (r1.order0.unwrap(), plain_r1(&s, m).unwrap());
                    assert!((r1_0 - plain).abs() <= 1e-9, "n={n} m={m} block={block}: {r1_0} vs {plain}");
                    // The differences are summed where delta >= 0.25, and only there; their r1
                    // against the plain r1 of the differenced residual.
                    assert_eq!(r1.diffs.is_some(), r1_0 / (1.0 + r1_0) >= 0.25, "n={n} m={m}");
                    if let Some(diffs) = r1.diffs {
                        for d in 1..=2 {
                            let (r1_d, plain) = (diffs[d - 1].unwrap().unwrap(), plain_diff_r1(&s, m, d).unwrap());
                            assert!((r1_d - plain).abs() <= 1e-9, "n={n} m={m} d={d} block={block}: {r1_d} vs {plain}");
                        }
                        differenced += 1;
                    }
                    checked += 1;
                }
                for dmax in [1, 2, 3] {
                    let fast = lag1_noise_ids_with(&s, &ms, dmax, 30, block);
                    let plain: Vec<Option<i32>> = ms.iter().map(|&m| lag1_noise_id(&s, m, dmax)).collect();
                    assert_eq!(fast, plain, "n={n} integrations={integrations} dmax={dmax} block={block}");
                }
            }
        }
        assert!(checked > 100);
        assert!(differenced > 40, "{differenced}");
    }

    /// A pure line w_t = a + b t has no residual: the one-sweep path must not invent one from
    /// rounding (it falls back to the two sweeps, which find den <= 0 or a tiny residual).
    #[test]
    fn octave_sweep_on_a_pure_trend_falls_back() {
        let s: Vec<f64> = (0..20_001).map(|k| 0.5 * (k as f64) * (k as f64) * 1e-3 + 3.0 * k as f64).collect();
        let ms = [1, 2, 4, 8];
        // the expansion is refused for every factor: the residual is rounding only
        for &m in &ms {
            let n = (s.len() - 1) / m;
            let c = (n as f64 - 1.0) / 2.0;
            let w: Vec<f64> = (0..n).map(|j| s[(j + 1) * m] - s[j * m]).collect();
            let mut r = RawSums::default();
            raw_sums(&w, -c, &mut r);
            assert!(raw_r1(std::iter::once(&r), n, c).is_err(), "m={m}");
        }
        let octave = octave_r1(&s, &ms, 64, 2);
        let two = order0_r1(&s, &ms, 64);
        assert_eq!(octave.len(), 4);
        for (a, b) in octave.iter().zip(&two) {
            assert_eq!(a.order0.map(f64::to_bits), b.map(f64::to_bits));
        }
        // The first differences of a line are a constant: refused (left to the factor-by-factor
        // rule), not read from rounding.
        let n_rate = s.len() - 1;
        let cs: Vec<f64> = (0..4).map(|k| ((n_rate >> k) as f64 - 1.0) / 2.0).collect();
        let part = octave_part(&s, &[false; 4], &[true; 4], &cs, 0, n_rate, 64);
        for (k, sums) in part.iter().enumerate() {
            let first = combine(std::iter::once(&sums.diffs[0]));
            assert!(moment_r1(&first, (n_rate >> k) - 1, true).is_err(), "m={}", 1 << k);
        }
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
            // the one-sweep octave path
            let octave: Vec<usize> = (0..6).map(|k| 1usize << k).collect();
            let fast = lag1_noise_ids_with(&s, &octave, dmax, 30, block);
            let plain: Vec<Option<i32>> = octave.iter().map(|&m| lag1_noise_id(&s, m, dmax)).collect();
            prop_assert_eq!(fast, plain);
        }
    }
}
