//! Deviations of a record with missing samples (gaps), as Stable32 and allantools' `gradev`
//! compute them: every term of the estimator whose window holds a missing sample is left out;
//! the term count is the number of terms summed and normalises the sum.
//!
//! Sources: NIST SP 1065 (Riley 2008) section 5.2 (the estimators, eq. 9-18) and section 8.7
//! ("Gaps": terms that span a gap are skipped); allantools `gradev` (gap-resistant overlapping
//! ADEV, terms with NaN left out). Kinds: OADEV, ADEV, OHDEV, HDEV (terms over a window of 2m
//! or 3m rate samples); MDEV, TDEV and TOTDEV are refused over gaps.
//!
//! Method: the missing samples are set to the mean of the valid ones and the angle series is
//! built as for a complete record ([`super::deviation_from_rate`]); a term is summed only when
//! its window of rate samples has no missing sample (a prefix count of missing samples decides
//! it in O(1)), so every summed term is the term of the valid samples alone. Noise
//! identification (lag-1 autocorrelation, else B1) runs on that series (missing samples at the
//! mean); the EDF of a point is Greenhall's for the record length that gives its term count
//! (overlapping: terms + window; non-overlapping: (terms + 1 or 2) m + 1).

use super::{
    attach_bounds, averaging_factors, compute, rate_to_sample_angle_in_place, rate_to_sample_angle_into,
    validate_parameters, AllanCurve, AllanError, AllanOptions, AllanPoint, DeviationKind,
};

/// [`deviation_from_rate_with_gaps`] of borrowed samples: a complete record is read where it is
/// and its angle series built in `buffer` (see [`super::deviation_from_rate_into`]); a record
/// with missing samples is copied into `buffer` first.
pub fn deviation_from_rate_with_gaps_into(
    rate: &[f64],
    mut buffer: Vec<f64>,
    tau0_s: f64,
    options: &AllanOptions,
) -> Result<AllanCurve, AllanError> {
    validate_parameters(tau0_s, options)?;
    match rate_to_sample_angle_into(rate, &mut buffer) {
        Ok(()) => compute(&buffer, tau0_s, options),
        Err(AllanError::NonFinite { value, .. }) if value.is_nan() => {
            buffer.clear();
            buffer.reserve_exact(rate.len() + 1);
            buffer.extend_from_slice(rate);
            deviation_from_rate_with_gaps(buffer, tau0_s, options)
        }
        Err(e) => Err(e),
    }
}

/// Computes a deviation curve from rate samples where NaN marks a missing sample (see the
/// module's rule); without NaN it is [`super::deviation_from_rate`]. Infinite samples are an
/// error; a point with no complete term is left out.
///
/// ```
/// use gyrolab::allan::{deviation_from_rate_with_gaps, AllanOptions, DeviationKind, TauList};
/// // 8 samples, the 5th missing; OADEV at m = 1: terms y[i+1] - y[i] over complete pairs
/// // (0,1), (1,2), (2,3), (5,6), (6,7): differences 1, -2, 1, 2, -1; sigma^2 = 11 / (2 * 5).
/// let y = vec![0.0, 1.0, -1.0, 0.0, f64::NAN, 1.0, 3.0, 2.0];
/// let o = AllanOptions::new(DeviationKind::Oadev).with_taus(TauList::Factors(vec![1])).with_confidence(None);
/// let c = deviation_from_rate_with_gaps(y, 1.0, &o)?;
/// assert_eq!(c.points[0].terms, 5);
/// assert!((c.points[0].deviation - (11.0f64 / 10.0).sqrt()).abs() < 1e-15);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn deviation_from_rate_with_gaps(
    mut rate: Vec<f64>,
    tau0_s: f64,
    options: &AllanOptions,
) -> Result<AllanCurve, AllanError> {
    validate_parameters(tau0_s, options)?;
    // A complete record is the common case: the angle conversion's first pass finds the first
    // non-finite sample before anything is written, so no separate NaN scan is needed.
    rate.reserve_exact(1);
    match rate_to_sample_angle_in_place(&mut rate) {
        Ok(()) => return compute(&rate, tau0_s, options),
        Err(AllanError::NonFinite { value, .. }) if value.is_nan() => {}
        Err(e) => return Err(e),
    }
    let kind = options.kind;
    if let Some(index) = rate.iter().position(|v| v.is_infinite()) {
        return Err(AllanError::NonFinite { index, value: rate[index] });
    }
    let (span_factor, overlapping) = match kind {
        DeviationKind::Oadev => (2, true),
        DeviationKind::Adev => (2, false),
        DeviationKind::Ohdev => (3, true),
        DeviationKind::Hdev => (3, false),
        _ => return Err(AllanError::GapsUnsupported { kind: kind.name() }),
    };
    let n = rate.len();
    // Prefix counts of missing samples, and the mean of the valid ones (Neumaier).
    let mut missing = Vec::with_capacity(n + 1);
    missing.push(0u32);
    let (mut sum, mut carry, mut valid) = (0.0f64, 0.0f64, 0usize);
    for &v in &rate {
        let m = *missing.last().unwrap_or(&0);
        if v.is_nan() {
            missing.push(m + 1);
        } else {
            missing.push(m);
            let t = sum + v;
            carry += if sum.abs() >= v.abs() { (sum - t) + v } else { (v - t) + sum };
            sum = t;
            valid += 1;
        }
    }
    if valid < 2 {
        return Err(AllanError::TooShort { n: valid, kind: kind.name() });
    }
    let mean = (sum + carry) / valid as f64;
    rate.iter_mut().filter(|v| v.is_nan()).for_each(|v| *v = mean);
    rate_to_sample_angle_in_place(&mut rate)?;
    let s = rate;
    let ms = averaging_factors(options, n, tau0_s)?;
    let mut points: Vec<AllanPoint> = super::map_indices(s.len(), ms.len(), |i| {
        let m = ms[i];
        let window = span_factor * m;
        if window > n {
            return None;
        }
        let stride = if overlapping { 1 } else { m };
        let mut sum = 0.0f64;
        let mut terms = 0usize;
        let mut k = 0usize;
        while k + window <= n {
            if missing[k + window] == missing[k] {
                let d = if span_factor == 2 {
                    (s[k + 2 * m] - s[k + m]) - (s[k + m] - s[k])
                } else {
                    let d1 = (s[k + 3 * m] - s[k + 2 * m]) - (s[k + 2 * m] - s[k + m]);
                    let d0 = (s[k + 2 * m] - s[k + m]) - (s[k + m] - s[k]);
                    d1 - d0
                };
                sum += d * d;
                terms += 1;
            }
            k += stride;
        }
        if terms == 0 {
            return None;
        }
        let mf = m as f64;
        let norm = if span_factor == 2 { 2.0 } else { 6.0 };
        Some(AllanPoint::unidentified(m, mf * tau0_s, (sum / (norm * mf * mf * terms as f64)).sqrt(), terms))
    })
    .into_iter()
    .flatten()
    .collect();
    if points.is_empty() {
        return Err(AllanError::TooShort { n: valid, kind: kind.name() });
    }
    // The record length (phase points) whose complete term count equals the point's.
    let n_phase = |p: &AllanPoint| {
        if overlapping {
            p.terms + span_factor * p.m
        } else {
            (p.terms + span_factor - 1) * p.m + 1
        }
    };
    attach_bounds(&mut points, &s, kind, options.confidence, n_phase);
    Ok(AllanCurve { kind, tau0_s, n_rate: n, confidence: options.confidence, points })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::allan::{deviation_from_rate, TauList};

    /// Direct computation from the SP1065 formulas on the rate samples: averages of m samples,
    /// terms with a NaN left out.
    fn direct(y: &[f64], m: usize, kind: DeviationKind) -> (f64, usize) {
        let avg = |i: usize| y[i..i + m].iter().sum::<f64>() / m as f64;
        let (span, stride) = match kind {
            DeviationKind::Oadev => (2, 1),
            DeviationKind::Adev => (2, m),
            DeviationKind::Ohdev => (3, 1),
            _ => (3, m),
        };
        let (mut sum, mut terms) = (0.0, 0usize);
        let mut k = 0;
        while k + span * m <= y.len() {
            if y[k..k + span * m].iter().all(|v| !v.is_nan()) {
                let d = if span == 2 { avg(k + m) - avg(k) } else { avg(k + 2 * m) - 2.0 * avg(k + m) + avg(k) };
                sum += d * d;
                terms += 1;
            }
            k += stride;
        }
        let norm = if span == 2 { 2.0 } else { 6.0 };
        ((sum / (norm * terms as f64)).sqrt(), terms)
    }

    fn record(n: usize, seed: u64) -> Vec<f64> {
        let mut st = seed;
        let mut walk = 0.0;
        (0..n)
            .map(|_| {
                st = st.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                let u = (st >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
                walk += 0.01 * u;
                0.5 + u + walk
            })
            .collect()
    }

    #[test]
    fn equals_the_direct_computation_with_random_gaps() {
        for seed in 1..4u64 {
            let mut y = record(3000, seed);
            let mut st = seed * 77;
            for _ in 0..20 {
                st = st.wrapping_mul(6364136223846793005).wrapping_add(1);
                let at = (st >> 33) as usize % y.len();
                let len = 1 + (st >> 20) as usize % 5;
                for v in y.iter_mut().skip(at).take(len) {
                    *v = f64::NAN;
                }
            }
            for kind in [DeviationKind::Oadev, DeviationKind::Adev, DeviationKind::Ohdev, DeviationKind::Hdev] {
                let o = AllanOptions::new(kind).with_taus(TauList::Factors(vec![1, 2, 3, 8, 50, 300]));
                let c = deviation_from_rate_with_gaps(y.clone(), 0.1, &o).unwrap();
                for p in &c.points {
                    let (d, terms) = direct(&y, p.m, kind);
                    assert_eq!(p.terms, terms, "{kind:?} m={}", p.m);
                    assert!((p.deviation / d - 1.0).abs() < 1e-9, "{kind:?} m={}: {} vs {d}", p.m, p.deviation);
                    assert!(p.edf.is_some() && p.lower.unwrap() < p.deviation && p.upper.unwrap() > p.deviation);
                }
            }
        }
    }

    #[test]
    fn without_gaps_it_is_the_complete_path() {
        let y = record(5000, 9);
        let o = AllanOptions::new(DeviationKind::Oadev);
        assert_eq!(deviation_from_rate_with_gaps(y.clone(), 0.01, &o), deviation_from_rate(y, 0.01, &o));
    }

    #[test]
    fn unsupported_kinds_and_infinities_are_errors() {
        let mut y = record(100, 2);
        y[10] = f64::NAN;
        let o = AllanOptions::new(DeviationKind::Mdev);
        assert_eq!(
            deviation_from_rate_with_gaps(y.clone(), 1.0, &o),
            Err(AllanError::GapsUnsupported { kind: "mdev" })
        );
        y[20] = f64::INFINITY;
        let o = AllanOptions::new(DeviationKind::Oadev);
        assert!(matches!(deviation_from_rate_with_gaps(y, 1.0, &o), Err(AllanError::NonFinite { index: 20, .. })));
        let all = vec![f64::NAN; 50];
        assert!(matches!(deviation_from_rate_with_gaps(all, 1.0, &o), Err(AllanError::TooShort { .. })));
    }
}
