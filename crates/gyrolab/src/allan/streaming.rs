//! Octave overlapping Allan deviation (OADEV) of a record streamed in blocks, in memory bounded
//! whatever its length: the short taus at full resolution (stride 1: the estimator of
//! section 3 of docs/METHODS.md, term for term), the long ones from the angle kept every
//! `stride`-th point (the overlapping estimator with its terms taken at every `stride`-th start,
//! a stated loss of degrees of freedom).
//!
//! Source: the overlapping Allan variance of NIST SP 1065 (Riley 2008) eq. 11 in angle form,
//! sigma^2(m tau0) = sum_j (x_{j+2m} - 2 x_{j+m} + x_j)^2 / (2 m^2 tau0^2 (N - 2m)) over the
//! N angle points; EDF of Greenhall & Riley (2004) as in [`super::equivalent_dof`]. The strided
//! estimator at m = m' b is the overlapping estimator of the angle series decimated by b at
//! factor m' (every term a term of the full estimator), so its EDF is that of N / b angle
//! points at m' (computed and returned with the full-record EDF for comparison).
//!
//! Numerics: a second difference of the angle is a difference of two adjacent sums of m rate
//! samples, x_{j+2m} - 2 x_{j+m} + x_j = W_m(j+m) - W_m(j) with W_m(i) = sum of y_i .. y_{i+m-1};
//! the full-resolution factors (octaves) take their window sums from a pyramid of the samples
//! less the first one, W_2m(i) = W_m(i) + W_m(i+m) (pairwise sums of m small values: the size of
//! the angle, which grows with the record's mean rate times its length, does not enter the
//! deviations). The kept angle is accumulated in double-double (TwoSum) and detrended by the
//! record's mean in double-double before the long taus are computed.

use super::{
    averaging_factors, deviation_bounds, deviation_from_angle, equivalent_dof, two_sum, AllanCurve, AllanError,
    AllanOptions, AllanPoint, DeviationKind, NoiseIdMethod, TauList,
};

/// Octaves of full resolution above the stride: factors m >= 2^4 x stride come from the kept
/// angle at m / stride >= 16, where the EDF lost to the stride is at most 1 / (m / stride)
/// (6.25 %; docs/METHODS.md, measured in the tests).
pub const FULL_RESOLUTION_OCTAVES: u32 = 4;

/// How a streamed record is split between full resolution and kept angle points.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StreamingPlan {
    /// Every `stride`-th angle point is kept (a power of two; 1 keeps every point).
    pub stride: usize,
    /// Averaging factors below this are summed at full resolution as the samples arrive
    /// ([`FULL_RESOLUTION_OCTAVES`] octaves above `stride`, i.e. 16 x `stride`; with stride 1
    /// every factor comes from the kept angle).
    pub full_resolution_below: usize,
    /// Rate samples kept at full resolution from the start of the record, to identify the
    /// noise type of the short taus (their EDF is then computed for the whole record).
    pub head_samples: usize,
}

impl StreamingPlan {
    /// The plan for a record of about `n_rate` samples per channel and `channels` channels
    /// within `memory_bytes`: the kept angle (16 bytes a point, double-double) takes at most a
    /// quarter of each channel's share (the rest leaves room for computing from it), the head
    /// at most an eighth.
    pub fn for_memory(n_rate: usize, channels: usize, memory_bytes: usize) -> StreamingPlan {
        let share = (memory_bytes / channels.max(1)).max(1 << 16);
        let mut stride = 1usize;
        while (n_rate / stride + 1).saturating_mul(16) > share / 4 {
            stride *= 2;
        }
        let head_samples = (share / 8 / 8).min(n_rate.max(1));
        StreamingPlan {
            stride,
            full_resolution_below: if stride == 1 { 1 } else { stride << FULL_RESOLUTION_OCTAVES },
            head_samples,
        }
    }
}

/// A point of a streamed curve with how it was estimated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StreamedPoint {
    /// The point (deviation, terms, alpha, EDF and bounds of the estimator used).
    pub point: AllanPoint,
    /// Stride of the terms: 1 at full resolution, else the plan's stride.
    pub stride: usize,
    /// The EDF the full-resolution estimator would have for the same noise type (the loss is
    /// 1 - edf / edf_full).
    pub edf_full: Option<f64>,
}

impl StreamedPoint {
    /// The fraction of EDF lost to the stride, 1 - edf / edf_full (0 at full resolution; `None`
    /// without noise identification).
    pub fn edf_loss(&self) -> Option<f64> {
        if self.stride == 1 {
            return self.point.edf.map(|_| 0.0);
        }
        match (self.point.edf, self.edf_full) {
            (Some(e), Some(f)) if f > 0.0 => Some(1.0 - e / f),
            _ => None,
        }
    }
}

/// Octave OADEV of a record pushed in blocks of rate samples ([`StreamingOadev::push`]), then
/// finished ([`StreamingOadev::finish`]).
#[derive(Debug, Clone)]
pub struct StreamingOadev {
    options: AllanOptions,
    plan: StreamingPlan,
    /// Factors summed at full resolution (1, 2, 4, ... below `plan.full_resolution_below`).
    exact: Vec<usize>,
    /// The first sample, subtracted from every sample (keeps the angle small).
    offset: Option<f64>,
    /// The current angle (double-double, sample units).
    hi: f64,
    lo: f64,
    /// Recent rate samples less the offset: the last 2 m_max - 1 before the next block, then
    /// the block's own.
    hist: Vec<f64>,
    /// Index in the record of the first sample of `hist`.
    base: usize,
    /// The window sums of the current level of the pyramid, and the next level's.
    level: Vec<f64>,
    next_level: Vec<f64>,
    /// Angle points seen.
    points: usize,
    /// Neumaier sums (sum, carry) of squared second differences per exact factor.
    sums: Vec<(f64, f64)>,
    /// Every stride-th angle point, double-double.
    kept: Vec<(f64, f64)>,
    /// The first `head_samples` rate samples.
    head: Vec<f64>,
}

impl StreamingOadev {
    /// A streamed OADEV (octave taus only; `options.kind` must be OADEV). The sampling interval
    /// is given to [`StreamingOadev::finish`] (a reader knows it once the stamps are read).
    pub fn new(options: &AllanOptions, plan: StreamingPlan) -> Result<StreamingOadev, AllanError> {
        if let Some(c) = options.confidence {
            if !(c > 0.0 && c < 1.0) {
                return Err(AllanError::BadConfidence(c));
            }
        }
        if options.kind != DeviationKind::Oadev || options.taus != TauList::Octave || !plan.stride.is_power_of_two() {
            return Err(AllanError::UnknownTauList(
                "streaming computes octave OADEV only (power-of-two stride)".to_string(),
            ));
        }
        let exact: Vec<usize> = std::iter::successors(Some(1usize), |m| m.checked_mul(2))
            .take_while(|&m| m < plan.full_resolution_below)
            .collect();
        let mut s = StreamingOadev {
            options: options.clone(),
            plan,
            sums: vec![(0.0, 0.0); exact.len()],
            exact,
            offset: None,
            hi: 0.0,
            lo: 0.0,
            hist: Vec::new(),
            base: 0,
            level: Vec::new(),
            next_level: Vec::new(),
            points: 1,
            kept: vec![(0.0, 0.0)],
            head: Vec::new(),
        };
        s.hist.reserve(1 << 16);
        Ok(s)
    }

    /// Rate samples pushed so far.
    pub fn samples(&self) -> usize {
        self.points - 1
    }

    /// Pushes the next rate samples; a non-finite sample is an error (its index in the record).
    pub fn push(&mut self, rate: &[f64]) -> Result<(), AllanError> {
        if let Some(i) = rate.iter().position(|v| !v.is_finite()) {
            return Err(AllanError::NonFinite { index: self.samples() + i, value: rate[i] });
        }
        if rate.is_empty() {
            return Ok(());
        }
        let room = self.plan.head_samples.saturating_sub(self.head.len()).min(rate.len());
        self.head.extend_from_slice(&rate[..room]);
        let offset = *self.offset.get_or_insert(rate[0]);
        // Angle points start..end are new: point k is the sum of samples 0 .. k - 1.
        let start = self.points;
        let end = start + rate.len();
        let b = self.plan.stride;
        for (k, &y) in (start..end).zip(rate) {
            let v = y - offset;
            let (s, e) = two_sum(self.hi, v);
            self.hi = s;
            self.lo += e;
            if k % b == 0 {
                self.kept.push((self.hi, self.lo));
            }
            self.hist.push(v);
        }
        // The term ending at point k (k - 2m >= 0) is W_m(k - m) - W_m(k - 2m): samples
        // k - 2m .. k - 1, all in `hist` (which starts at sample `base`).
        let o = self.base;
        self.level.clear();
        self.level.extend_from_slice(&self.hist);
        for (i, &m) in self.exact.iter().enumerate() {
            if i > 0 {
                // W_m(j) = W_{m/2}(j) + W_{m/2}(j + m/2), for every j whose window is in `hist`.
                let half = m / 2;
                let len = self.level.len().saturating_sub(half);
                self.next_level.clear();
                self.next_level.extend(self.level[..len].iter().zip(&self.level[half..]).map(|(a, c)| a + c));
                std::mem::swap(&mut self.level, &mut self.next_level);
            }
            let from = start.max(2 * m);
            if from >= end {
                break;
            }
            let n = end - from;
            let (later, earlier) = (from - m - o, from - 2 * m - o);
            let sub = sum_of_squared_differences(&self.level[later..later + n], &self.level[earlier..earlier + n]);
            let (sum, carry) = &mut self.sums[i];
            for v in sub {
                let t = *sum + v;
                *carry += if sum.abs() >= v { (*sum - t) + v } else { (v - t) + *sum };
                *sum = t;
            }
        }
        self.points = end;
        // Keep the last 2 m_max - 1 samples for the next block.
        let keep = (2 * self.exact.last().copied().unwrap_or(0)).saturating_sub(1);
        if self.hist.len() > keep {
            let cut = self.hist.len() - keep;
            self.hist.drain(..cut);
            self.base += cut;
        }
        Ok(())
    }

    /// The curve: the factors of [`averaging_factors`] for the whole record, each at full
    /// resolution when below the plan's limit (or when the stride is 1), else from the kept angle.
    /// `tau0_s` is the sampling interval (positive, finite).
    pub fn finish(self, tau0_s: f64) -> Result<(AllanCurve, Vec<StreamedPoint>), AllanError> {
        if !(tau0_s.is_finite() && tau0_s > 0.0) {
            return Err(AllanError::BadTau0(tau0_s));
        }
        let n_rate = self.samples();
        let ms = averaging_factors(&self.options, n_rate, tau0_s)?;
        let b = self.plan.stride;
        let mut out: Vec<StreamedPoint> = Vec::with_capacity(ms.len());
        // Short taus: the full-resolution sums; noise type from the head, EDF for the whole record.
        let exact_ms: Vec<usize> = ms.iter().copied().filter(|m| b > 1 && self.exact.contains(m)).collect();
        if !exact_ms.is_empty() {
            let head_curve = match self.options.confidence {
                Some(_) => {
                    let opts = AllanOptions { taus: TauList::Factors(exact_ms.clone()), ..self.options.clone() };
                    super::deviation_from_rate_slice(&self.head, tau0_s, &opts).ok()
                }
                None => None,
            };
            // The in-memory rule: a tau whose noise type is not identified (here: beyond the
            // head) takes the previous tau's.
            let mut previous: Option<i32> = None;
            for &m in &exact_ms {
                let i = self.exact.iter().position(|&e| e == m).unwrap_or(0); // ok: exact_ms is a subset of exact
                let terms = self.points - 2 * m;
                let variance = (self.sums[i].0 + self.sums[i].1) / (2.0 * (m as f64).powi(2) * terms as f64);
                let deviation = variance.sqrt();
                let identified = head_curve
                    .as_ref()
                    .and_then(|c| c.points.iter().find(|p| p.m == m))
                    .and_then(|p| p.alpha.zip(p.noise_id));
                let (alpha, noise_id) = match identified {
                    Some((a, id)) => (Some(a), Some(id)),
                    None if deviation > 0.0 && previous.is_some() => (previous, Some(NoiseIdMethod::Previous)),
                    None => (None, None),
                };
                previous = alpha.or(previous);
                let edf = alpha.map(|a| equivalent_dof(DeviationKind::Oadev, a, m, self.points));
                let bounds = match (edf, self.options.confidence) {
                    (Some(e), Some(c)) => deviation_bounds(deviation, e, c),
                    (None, Some(_)) if deviation == 0.0 => Some((0.0, 0.0)),
                    _ => None,
                };
                out.push(StreamedPoint {
                    point: AllanPoint {
                        m,
                        tau_s: m as f64 * tau0_s,
                        deviation,
                        terms,
                        alpha,
                        noise_id,
                        edf,
                        lower: bounds.map(|x| x.0),
                        upper: bounds.map(|x| x.1),
                    },
                    stride: 1,
                    edf_full: edf,
                });
            }
        }
        // Long taus: the kept angle, detrended by the mean rate in double-double, at m / stride.
        let long: Vec<usize> = ms.iter().copied().filter(|m| !exact_ms.contains(m)).collect();
        if !long.is_empty() {
            let (eh, el) = (self.hi, self.lo);
            let n = n_rate as f64;
            let kept = self.kept;
            let scaled: Vec<f64> = kept
                .iter()
                .enumerate()
                .map(|(k, &(h, l))| {
                    // x_k - (k b / n) x_N, in double-double, then rounded once.
                    let f = (k * b) as f64 / n;
                    let p = eh * f;
                    let p_err = eh.mul_add(f, -p) + el * f;
                    let (s, e) = two_sum(h, -p);
                    // In sample units (sums of rate samples): times tau0 it is the angle in
                    // rate x seconds that deviation_from_angle takes at its interval b tau0.
                    (s + (e + l - p_err)) * tau0_s
                })
                .collect();
            drop(kept);
            let opts = AllanOptions {
                taus: TauList::Factors(long.iter().map(|m| m / b).collect()),
                max_factor: None,
                ..self.options.clone()
            };
            let curve = deviation_from_angle(scaled, b as f64 * tau0_s, &opts)?;
            for p in curve.points {
                let m = p.m * b;
                let edf_full = p.alpha.map(|a| equivalent_dof(DeviationKind::Oadev, a, m, self.points));
                out.push(StreamedPoint { point: AllanPoint { m, tau_s: m as f64 * tau0_s, ..p }, stride: b, edf_full });
            }
        }
        out.sort_by_key(|p| p.point.m);
        let curve = AllanCurve {
            kind: DeviationKind::Oadev,
            tau0_s,
            n_rate,
            confidence: self.options.confidence,
            points: out.iter().map(|p| p.point).collect(),
        };
        Ok((curve, out))
    }
}

/// Terms of each sub-sum of [`sum_of_squared_differences`] (plain sums in 4 lanes: relative
/// rounding at most about 256 units, then joined by the caller's compensated sum).
const SUB_SUM: usize = 1024;

/// Sums of the squared differences later_j - earlier_j (the second differences of the angle,
/// from window sums), one per run of [`SUB_SUM`] terms (independent terms, 4 lanes:
/// vectorisable).
fn sum_of_squared_differences(later: &[f64], earlier: &[f64]) -> Vec<f64> {
    let n = later.len().min(earlier.len());
    let mut out = Vec::with_capacity(n / SUB_SUM + 1);
    for (l, e) in later[..n].chunks(SUB_SUM).zip(earlier[..n].chunks(SUB_SUM)) {
        let mut lanes = [0.0f64; 4];
        let (lc, ec) = (l.chunks_exact(4), e.chunks_exact(4));
        let (lr, er) = (lc.remainder(), ec.remainder());
        for (x, y) in lc.zip(ec) {
            for (lane, acc) in lanes.iter_mut().enumerate() {
                let d = x[lane] - y[lane];
                *acc += d * d;
            }
        }
        let rest: f64 = lr.iter().zip(er).map(|(x, y)| (x - y) * (x - y)).sum();
        out.push((lanes[0] + lanes[1]) + (lanes[2] + lanes[3]) + rest);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::allan::deviation_from_rate_slice;

    /// White noise, a random walk and a large constant rate (xorshift64*, no dependencies).
    fn record(n: usize, seed: u64, walk_step: f64) -> Vec<f64> {
        let mut x = seed | 1;
        let mut next = move || {
            x ^= x >> 12;
            x ^= x << 25;
            x ^= x >> 27;
            (x.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let mut walk = 0.0;
        (0..n)
            .map(|_| {
                walk += walk_step * next();
                250.0 + next() + walk
            })
            .collect()
    }

    fn streamed(
        rate: &[f64],
        tau0: f64,
        plan: StreamingPlan,
        options: &AllanOptions,
    ) -> (AllanCurve, Vec<StreamedPoint>) {
        let mut s = StreamingOadev::new(options, plan).unwrap();
        for block in rate.chunks(4099) {
            s.push(block).unwrap();
        }
        s.finish(tau0).unwrap()
    }

    fn rel(a: f64, b: f64) -> f64 {
        (a / b - 1.0).abs()
    }

    /// Stride 8, full resolution below 128, on three seeds and two noise mixes: every m < 128
    /// equals the in-memory curve (deviation, terms, alpha, EDF, bounds) to 1e-12; every m >= 128
    /// is a subset of the same terms, so it lies inside the in-memory point's 68.3 % interval,
    /// with the same noise type, ceil((N - 2m) / 8) terms, and an EDF loss of at most 8 / m.
    #[test]
    fn full_resolution_taus_equal_the_in_memory_curve_and_strided_ones_lie_within_its_bounds() {
        for (seed, walk) in [(7, 0.002), (11, 0.002), (23, 0.02)] {
            let rate = record(300_000, seed, walk);
            let options = AllanOptions::default();
            let memory = deviation_from_rate_slice(&rate, 0.01, &options).unwrap();
            let plan = StreamingPlan { stride: 8, full_resolution_below: 128, head_samples: rate.len() };
            let (curve, points) = streamed(&rate, 0.01, plan, &options);
            assert_eq!(curve.points.len(), memory.points.len());
            assert_eq!(curve.n_rate, memory.n_rate);
            for ((p, s), q) in curve.points.iter().zip(&points).zip(&memory.points) {
                assert_eq!((p.m, s.stride), (q.m, if q.m < 128 { 1 } else { 8 }));
                if s.stride == 1 {
                    assert!(rel(p.deviation, q.deviation) < 1e-12, "m {}: {} vs {}", p.m, p.deviation, q.deviation);
                    assert_eq!((p.terms, p.alpha), (q.terms, q.alpha), "m {}", p.m);
                    assert!(rel(p.edf.unwrap(), q.edf.unwrap()) < 1e-12, "m {}", p.m);
                    assert!(rel(p.lower.unwrap(), q.lower.unwrap()) < 1e-12, "m {}", p.m);
                    assert!(rel(p.upper.unwrap(), q.upper.unwrap()) < 1e-12, "m {}", p.m);
                    assert_eq!(s.edf_loss(), Some(0.0));
                } else {
                    assert!(
                        p.deviation > q.lower.unwrap() && p.deviation < q.upper.unwrap(),
                        "seed {seed} m {}: {} outside [{}, {}]",
                        p.m,
                        p.deviation,
                        q.lower.unwrap(),
                        q.upper.unwrap()
                    );
                    assert_eq!(p.alpha, q.alpha, "seed {seed} m {}", p.m);
                    assert_eq!(p.terms, q.terms.div_ceil(8), "m {}", p.m);
                    let loss = s.edf_loss().unwrap();
                    assert!((-1e-3..=8.0 / p.m as f64).contains(&loss), "seed {seed} m {}: EDF loss {loss}", p.m);
                    assert!(rel(s.edf_full.unwrap(), q.edf.unwrap()) < 1e-12, "m {}", p.m);
                }
            }
        }
    }

    /// Noise identified on a head of 20,000 samples: the deviations are still the in-memory ones
    /// to 1e-12, the EDF is that of the whole record for the head's noise type.
    #[test]
    fn a_short_head_leaves_the_full_resolution_deviations_exact() {
        let rate = record(200_000, 5, 0.002);
        let options = AllanOptions::default();
        let memory = deviation_from_rate_slice(&rate, 0.01, &options).unwrap();
        let plan = StreamingPlan { stride: 4, full_resolution_below: 64, head_samples: 20_000 };
        let (curve, _) = streamed(&rate, 0.01, plan, &options);
        for (p, q) in curve.points.iter().zip(&memory.points).filter(|(p, _)| p.m < 64) {
            assert!(rel(p.deviation, q.deviation) < 1e-12, "m {}", p.m);
            let edf = equivalent_dof(DeviationKind::Oadev, p.alpha.unwrap(), p.m, rate.len() + 1);
            assert_eq!(p.edf, Some(edf));
        }
    }

    /// With stride 1 (a record that fits), every tau equals the in-memory curve to 1e-12:
    /// deviation, terms, noise type, EDF and both bounds; three seeds.
    #[test]
    fn a_stride_of_one_gives_the_in_memory_curve_at_every_tau() {
        for seed in [3, 4, 9] {
            let rate = record(100_003, seed, 0.002);
            let options = AllanOptions::default();
            let memory = deviation_from_rate_slice(&rate, 0.005, &options).unwrap();
            let plan = StreamingPlan::for_memory(rate.len(), 1, 1 << 30);
            assert_eq!(plan.stride, 1);
            let (curve, _) = streamed(&rate, 0.005, plan, &options);
            assert_eq!(curve.points.len(), memory.points.len());
            for (p, q) in curve.points.iter().zip(&memory.points) {
                assert_eq!((p.m, p.terms, p.alpha), (q.m, q.terms, q.alpha));
                assert!(rel(p.deviation, q.deviation) < 1e-12, "m {}: {} vs {}", p.m, p.deviation, q.deviation);
                assert!(rel(p.edf.unwrap(), q.edf.unwrap()) < 1e-12, "m {}", p.m);
                assert!(rel(p.lower.unwrap(), q.lower.unwrap()) < 1e-12, "m {}", p.m);
                assert!(rel(p.upper.unwrap(), q.upper.unwrap()) < 1e-12, "m {}", p.m);
            }
        }
    }

    /// The full-resolution sums from the pyramid of window sums against brute force on a
    /// record far from zero whose rate ramps away from its first sample (angle up to about 2e5
    /// sample units): each term summed anew as the compensated sum of the m differences
    /// y_{j+m+i} - y_{j+i} (no large value is ever formed), the squares summed compensated; every factor below the limit agrees to 1e-13, in blocks of odd sizes.
    #[test]
    fn full_resolution_sums_equal_brute_force_window_sums_on_a_ramping_rate() {
        let n = 20_000;
        let noise = record(n, 17, 0.0);
        let rate: Vec<f64> = noise.iter().enumerate().map(|(k, y)| y + 1e-3 * (k as f64) - 1e5).collect();
        let plan = StreamingPlan { stride: 4, full_resolution_below: 128, head_samples: 0 };
        let mut s = StreamingOadev::new(&AllanOptions::default(), plan).unwrap();
        for block in rate.chunks(997) {
            s.push(block).unwrap();
        }
        for (i, &m) in s.exact.iter().enumerate() {
            let terms: Vec<f64> = (0..=n - 2 * m)
                .map(|j| {
                    let pairs: Vec<f64> = (0..m).map(|i| rate[j + m + i] - rate[j + i]).collect();
                    let d = crate::allan::compensated_sum(&pairs);
                    d * d
                })
                .collect();
            let brute = crate::allan::compensated_sum(&terms);
            let streamed = s.sums[i].0 + s.sums[i].1;
            assert!(rel(streamed, brute) < 1e-13, "m {m}: {streamed} vs {brute}");
        }
        assert_eq!(s.exact.len(), 7);
    }

    #[test]
    fn the_plan_keeps_a_day_at_1_khz_on_six_channels_within_the_ceiling() {
        let n = 86_400_000;
        let plan = StreamingPlan::for_memory(n, 6, 1 << 30);
        assert_eq!(plan.stride, 32);
        let kept = (n / plan.stride + 1) * 16 * 6;
        let head = plan.head_samples * 8 * 6;
        assert!(kept + head < (1 << 30) / 2, "{kept} + {head}");
        assert_eq!(plan.full_resolution_below, 512);
    }

    #[test]
    fn a_bad_sample_or_option_is_an_error() {
        let plan = StreamingPlan { stride: 4, full_resolution_below: 32, head_samples: 10 };
        let mut s = StreamingOadev::new(&AllanOptions::default(), plan).unwrap();
        s.push(&[1.0, 2.0]).unwrap();
        match s.push(&[3.0, f64::NAN]) {
            Err(AllanError::NonFinite { index, value }) => assert!(index == 3 && value.is_nan()),
            other => panic!("{other:?}"),
        }
        let mdev = AllanOptions::new(DeviationKind::Mdev);
        assert!(StreamingOadev::new(&mdev, plan).is_err());
        let s = StreamingOadev::new(&AllanOptions::default(), plan).unwrap();
        assert_eq!(s.finish(0.0).unwrap_err(), AllanError::BadTau0(0.0));
    }
}
