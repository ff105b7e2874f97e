//! Allan and Hadamard deviations of a rate record with dense missing samples (issue 54, "Long
//! taus through dense drops"): every window is averaged over the samples present in it, so the
//! long taus survive drops spread over the whole record, and the white-noise bias this brings
//! is subtracted.
//!
//! # Why
//!
//! The gap rule of [`super::deviation_from_rate_with_gaps`] (Stable32, allantools `gradev`)
//! leaves out every term whose window holds a missing sample. A record that misses one sample in
//! four, spread evenly (PX4 `sensor_combined` stepping 4 and 8 ms on a 250 Hz grid), then has
//! no complete term beyond m of about 8: the curve ends at a few hundredths of a second. The
//! fill rule of [`super::gap_fill`] declines (it is checked for at most 1 % missing).
//!
//! # Estimator (rate samples y_i on a uniform grid of interval tau0, NaN = missing)
//!
//! For an averaging factor m, window j is the m grid slots j .. j + m - 1; k_j of them hold a
//! sample (present). The window is *usable* when k_j >= max(1, ceil(q_min m)), q_min the
//! caller's `min_present_share` (0.5 in [`DEFAULT_MIN_PRESENT_SHARE`]); its average is over the
//! present samples alone, ybar_j = (1 / k_j) sum_{i present in window j} y_i. The terms are
//! those of SP1065 eq. (9), (11), (17), (18) with these averages, summed over the term positions
//! whose windows are all usable (overlapping: every j; non-overlapping: j a multiple of m):
//!
//! - OADEV / ADEV: (ybar_{j+m} - ybar_j)^2 / 2;
//! - OHDEV / HDEV: (ybar_{j+2m} - 2 ybar_{j+m} + ybar_j)^2 / 6;
//!
//! and the raw variance is their mean (the term count is the point's `terms`). Without missing
//! samples this is the ordinary estimator (tested equal to [`super::deviation_from_rate_slice`]
//! to 1e-12). Cost: O(N) per m. The window sums come from the record's angle series (the
//! compensated cumulative sum of [`super::deviation_from_rate`], missing samples set to the
//! mean of the present ones, so they add exactly nothing to a window's sum of y - mean) and the
//! present counts from a prefix count.
//!
//! MDEV, TDEV and TOTDEV are refused ([`AllanError::GapsUnsupported`]), as by the gap rule.
//!
//! # White-noise bias and its correction (derived here)
//!
//! Write y_i = w_i + z_i, w white with per-sample variance sigma_w^2 (sigma_w^2 = N^2 / tau0 for
//! an angle random walk N), z the slower noises. The windows of one term are disjoint, so the
//! white part of a term has the expectation
//!
//! E[(sum_r c_r wbar_{j+rm})^2] / c = sigma_w^2 h_j,  h_j = (1/c) sum_r c_r^2 / k_{j+rm},
//!
//! with c_r = (-1, 1), c = 2 (Allan) or c_r = (1, -2, 1), c = 6 (Hadamard). A complete record has
//! k = m and h_j = 1/m (sum_r c_r^2 = c): the white part of the variance is sigma_w^2 / m. With
//! missing samples the mean over the terms, H_m = mean_j h_j, exceeds 1/m: at a share p missing,
//! spread evenly, about 1 / (m (1 - p)): N reads 15 % high at 25 % missing and 41 % at 50 %.
//! The corrected variance is
//!
//! AVAR_corr(m) = AVAR_raw(m) - sigma_w^2 (H_m - 1/m),
//!
//! with H_m - 1/m summed exactly as (1/(c m)) mean_j sum_r c_r^2 (m - k_{j+rm}) / k_{j+rm} (zero
//! to the last bit when no window misses a sample, so a complete record is untouched).
//!
//! sigma_w^2 is estimated from the data as half the mean squared difference of successive present
//! samples at most [`WHITE_LAG_SLOTS`] slots apart (von Neumann's mean square successive
//! difference; on a complete record exactly the m = 1 Allan variance). When no two present
//! samples are that close, all successive present pairs are used.
//!
//! **Floor.** The corrected variance is never below AVAR_raw / (m H_m): the value the point would
//! take if all of its raw variance were white (the largest bias the missing samples can cause).
//! An estimate of sigma_w^2 that is too large by chance, or slow noise at tau0, is thereby kept
//! from making a point small or negative; the curve's points say nothing about whether a floor
//! was applied, [`PresentPoint::floored`] does.
//!
//! **Assumptions.** (1) The excess is white: the part of the rate that changes from one sample
//! to the next is uncorrelated from sample to sample (angle random walk, the usual gyro case).
//! Noise correlated over a few samples (quantisation of an angle, flicker dominating at tau0)
//! makes sigma_w^2 read high and over-corrects, up to the floor. (2) The slower noises' window
//! means are not biased by the missing samples: true when the missing samples are spread out
//! within each window (single drops, short runs); a run of missing samples that covers a large
//! part of a window moves that window's centre and changes the slow noises' response (a long
//! run is better left to the gap rule; q_min bounds how much of a window may be missing).
//! (3) Which samples are missing does not depend on their values.
//!
//! # EDF and bounds
//!
//! Noise identification (lag-1 ACF, else B1) runs on the angle series with the missing samples
//! at the mean, as the gap rule does. The EDF of a point is built in two steps:
//!
//! 1. EDF_raw: Greenhall's EDF (`equivalent_dof`) of the ordinary estimator for the record
//!    length that gives the point's term count (overlapping: terms + d m phase points;
//!    non-overlapping: (terms + d - 1) m + 1; d = 2 Allan, 3 Hadamard), the gap rule's choice.
//!    For white noise at m >> 1 the overlapping estimator's EDF depends on the number of
//!    windows (T / tau), not on how many samples each holds, so missing samples spread out do
//!    not lower it; where windows hold only a few present samples (m of a few, dense drops) it
//!    overstates the EDF (up to a factor 1 / P at m = 2, P the present share), where the EDF is
//!    in the thousands.
//! 2. The correction subtracts sigma_w^2 (H_m - 1/m), a constant known far better than the point
//!    (sigma_w^2 comes from all present pairs): the absolute spread of the variance is kept, so
//!    its relative spread grows by AVAR_raw / AVAR_corr, and the EDF (2 / relative variance of
//!    the variance) shrinks by its square: EDF = EDF_raw (AVAR_corr / AVAR_raw)^2. At 50 %
//!    missing the white-noise EDF is a quarter of the complete record's.
//!
//! The bounds are the chi-square bounds of that EDF (SP1065 5.3). A complete record gets the
//! EDF and bounds of the ordinary estimator. Checked by simulation (tests): every point of 8 seeds
//! under six drop patterns lies within 3 sigma = 3 / sqrt(2 EDF) (relative) of the complete
//! record's deviation, the largest at 0.76 of that bound.
//!
//! # Sources
//!
//! - NIST SP 1065 (Riley 2008), section 5.2 (the estimators) and 8.7 (gaps; the gap rule kept in
//!   `allan::gaps`).
//! - I. Sesia and P. Tavella, "Estimating the Allan variance in the presence of long periods of
//!   missing data and outliers", Metrologia 45 (2008) S134: their abstract (the paper itself was
//!   not available here) describes an Allan variance estimator for records with missing and
//!   unequally spaced data that uses all available data and is unbiased. This module does not
//!   reproduce their algorithm; it takes from them only the aim of using every present sample.
//!   I. Sesia et al., "The Corrected Allan Variance" (IEEE TUFFC 66 (2019) 1667; abstract read
//!   only) show that an Allan variance computed from frequency data with missing samples is
//!   biased and correct it per noise type; the correction here is this module's own derivation
//!   (above) for white rate noise alone.
//! - C. Hackman and T. E. Parker, "Noise analysis of unevenly spaced time series data",
//!   Metrologia 33 (1996) 457 (read here: the abstract of their PTTI 1995 paper on the same
//!   work): missing data filled by linear interpolation or the spacing ignored both bias the
//!   variance, depending on the noise type; it is why this module neither interpolates nor
//!   closes the gaps.
//! - The window averages over present samples, the usable-window rule, the white-bias
//!   correction with its floor and the EDF (both steps) are this module's own.

use super::{
    attach_bounds, averaging_factors, map_indices, rate_to_sample_angle_in_place, validate_parameters, AllanCurve,
    AllanError, AllanOptions, AllanPoint, DeviationKind,
};

/// The least share of a window's slots that must hold a sample for the window to be used.
pub const DEFAULT_MIN_PRESENT_SHARE: f64 = 0.5;

/// Largest distance, in grid slots, of two successive present samples whose difference enters
/// the estimate of the white variance sigma_w^2.
pub const WHITE_LAG_SLOTS: usize = 4;

/// The uncorrected estimate and the correction of one point of a [`PresentAnalysis`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PresentPoint {
    /// Averaging factor m (the same as the curve's point).
    pub m: usize,
    /// Deviation of the window averages over present samples before the white-bias correction.
    pub raw_deviation: f64,
    /// m H_m: the factor by which missing samples inflate the white part of this point's
    /// variance (1 when no window of its terms misses a sample).
    pub white_inflation: f64,
    /// Whether the corrected variance was raised to the floor AVAR_raw / (m H_m).
    pub floored: bool,
}

/// A deviation curve of a record with missing samples and what its correction did.
#[derive(Clone, Debug, PartialEq)]
pub struct PresentAnalysis {
    /// The corrected curve, with noise identification, EDF and bounds as the options ask.
    pub curve: AllanCurve,
    /// Samples present (not NaN) among the record's grid slots (`curve.n_rate`).
    pub present: usize,
    /// Estimated per-sample white variance sigma_w^2 (rate units squared).
    pub white_variance: f64,
    /// Per point of the curve, in the same order: the raw deviation and the correction.
    pub points: Vec<PresentPoint>,
}

/// Deviation curve of rate samples on a uniform grid where NaN marks a missing sample, each
/// window averaged over the samples present in it and the white-noise bias subtracted (see the
/// module documentation). Kinds: OADEV, ADEV, OHDEV, HDEV. `min_present_share` (in (0, 1];
/// [`DEFAULT_MIN_PRESENT_SHARE`]) is the least share of a window's slots that must hold a sample.
/// A point none of whose terms has all windows usable is left out.
///
/// ```
/// use gyrolab::allan::present::deviation_from_rate_present;
/// use gyrolab::allan::{AllanOptions, DeviationKind, TauList};
/// // One sample in four missing: the gap rule keeps no term at m = 4, this estimator does.
/// let y: Vec<f64> = (0..400).map(|i| if i % 4 == 3 { f64::NAN } else { ((i * 7919) % 13) as f64 }).collect();
/// let o = AllanOptions::new(DeviationKind::Oadev).with_taus(TauList::Factors(vec![4, 16]));
/// let c = deviation_from_rate_present(&y, 0.004, &o, 0.5)?;
/// assert_eq!(c.points.len(), 2);
/// assert_eq!(c.points[0].terms, 400 - 2 * 4 + 1);
/// # Ok::<(), gyrolab::allan::AllanError>(())
/// ```
pub fn deviation_from_rate_present(
    rate: &[f64],
    tau0_s: f64,
    options: &AllanOptions,
    min_present_share: f64,
) -> Result<AllanCurve, AllanError> {
    analyse_rate_present(rate, tau0_s, options, min_present_share).map(|a| a.curve)
}

/// [`deviation_from_rate_present`] with the uncorrected deviations, the inflation factors and
/// the white-variance estimate beside the curve.
pub fn analyse_rate_present(
    rate: &[f64],
    tau0_s: f64,
    options: &AllanOptions,
    min_present_share: f64,
) -> Result<PresentAnalysis, AllanError> {
    validate_parameters(tau0_s, options)?;
    if !(min_present_share > 0.0 && min_present_share <= 1.0) {
        return Err(AllanError::BadPresentShare(min_present_share));
    }
    let kind = options.kind;
    let (order, overlapping) = match kind {
        DeviationKind::Oadev => (2usize, true),
        DeviationKind::Adev => (2, false),
        DeviationKind::Ohdev => (3, true),
        DeviationKind::Hdev => (3, false),
        _ => return Err(AllanError::GapsUnsupported { kind: kind.name() }),
    };
    if let Some(index) = rate.iter().position(|v| v.is_infinite()) {
        return Err(AllanError::NonFinite { index, value: rate[index] });
    }
    let n = rate.len();
    // Prefix counts of present samples and the mean of the present ones (Neumaier).
    let mut count = Vec::with_capacity(n + 1);
    count.push(0usize);
    let (mut sum, mut carry, mut present) = (0.0f64, 0.0f64, 0usize);
    for &v in rate {
        if !v.is_nan() {
            let t = sum + v;
            carry += if sum.abs() >= v.abs() { (sum - t) + v } else { (v - t) + sum };
            sum = t;
            present += 1;
        }
        count.push(present);
    }
    if present < 2 {
        return Err(AllanError::TooShort { n: present, kind: kind.name() });
    }
    let mean = (sum + carry) / present as f64;
    let white_variance = white_variance(rate);
    let ms = averaging_factors(options, n, tau0_s)?;
    let mut s = Vec::with_capacity(n + 1);
    s.extend(rate.iter().map(|&v| if v.is_nan() { mean } else { v }));
    rate_to_sample_angle_in_place(&mut s)?;
    let s = s;

    let weights: &[f64] = if order == 2 { &[-1.0, 1.0] } else { &[1.0, -2.0, 1.0] };
    let norm = if order == 2 { 2.0 } else { 6.0 };
    let sums: Vec<Option<(f64, f64, usize)>> = map_indices(s.len(), ms.len(), |i| {
        let m = ms[i];
        let span = order * m;
        if span > n {
            return None;
        }
        // usable: k >= max(1, ceil(q m)); the small allowance keeps q m = 2.0000000000000004 at 2
        let need = ((min_present_share * m as f64) * (1.0 - 1e-12)).ceil().max(1.0) as usize;
        let stride = if overlapping { 1 } else { m };
        let (mut sum, mut excess, mut terms) = (0.0f64, 0.0f64, 0usize);
        let mut j = 0usize;
        'positions: while j + span <= n {
            let (mut d, mut e) = (0.0f64, 0.0f64);
            for (r, &c) in weights.iter().enumerate() {
                let a = j + r * m;
                let k = count[a + m] - count[a];
                if k < need {
                    j += stride;
                    continue 'positions;
                }
                let kf = k as f64;
                d += c * (s[a + m] - s[a]) / kf;
                e += c * c * (m - k) as f64 / kf;
            }
            sum += d * d;
            excess += e;
            terms += 1;
            j += stride;
        }
        (terms > 0).then_some((sum, excess, terms))
    });

    let mut points = Vec::with_capacity(ms.len());
    let mut details = Vec::with_capacity(ms.len());
    for (&m, sums) in ms.iter().zip(sums) {
        let Some((sum, excess, terms)) = sums else { continue };
        let mf = m as f64;
        let tf = terms as f64;
        let raw = sum / (norm * tf);
        // H_m - 1/m, and the inflation m H_m = 1 + m (H_m - 1/m)
        let excess = excess / (norm * mf * tf);
        let inflation = 1.0 + mf * excess;
        let floor = raw / inflation;
        let lowered = raw - white_variance * excess;
        let (variance, floored) = if lowered >= floor { (lowered, false) } else { (floor, true) };
        points.push(AllanPoint::unidentified(m, mf * tau0_s, variance.sqrt(), terms));
        details.push(PresentPoint { m, raw_deviation: raw.sqrt(), white_inflation: inflation, floored });
    }
    if points.is_empty() {
        return Err(AllanError::TooShort { n: present, kind: kind.name() });
    }
    // the gap rule's record length for the term count, then the EDF scaled by (corr / raw)^2
    let n_phase = |p: &AllanPoint| if overlapping { p.terms + order * p.m } else { (p.terms + order - 1) * p.m + 1 };
    attach_bounds(&mut points, &s, kind, options.confidence, n_phase);
    if let Some(confidence) = options.confidence {
        for (p, d) in points.iter_mut().zip(&details) {
            if let (Some(edf), true) = (p.edf, d.raw_deviation > 0.0) {
                let edf = edf * (p.deviation / d.raw_deviation).powi(4);
                p.edf = Some(edf);
                let bounds = super::confidence::chi2_bounds(p.deviation, edf, confidence);
                p.lower = bounds.map(|b| b.0);
                p.upper = bounds.map(|b| b.1);
            }
        }
    }
    let curve = AllanCurve { kind, tau0_s, n_rate: n, confidence: options.confidence, points };
    Ok(PresentAnalysis { curve, present, white_variance, points: details })
}

/// Half the mean squared difference of successive present samples at most [`WHITE_LAG_SLOTS`]
/// slots apart (all successive present pairs when none is that close); 0 with fewer than two
/// present samples.
fn white_variance(rate: &[f64]) -> f64 {
    let mut near = (0.0f64, 0usize);
    let mut all = (0.0f64, 0usize);
    let mut last: Option<(usize, f64)> = None;
    for (i, &v) in rate.iter().enumerate() {
        if v.is_nan() {
            continue;
        }
        if let Some((li, lv)) = last {
            let d2 = (v - lv) * (v - lv);
            all = (all.0 + d2, all.1 + 1);
            if i - li <= WHITE_LAG_SLOTS {
                near = (near.0 + d2, near.1 + 1);
            }
        }
        last = Some((i, v));
    }
    let (sum, pairs) = if near.1 > 0 { near } else { all };
    if pairs == 0 {
        0.0
    } else {
        sum / (2.0 * pairs as f64)
    }
}

#[cfg(test)]
mod tests;
