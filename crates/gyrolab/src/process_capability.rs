//! Lot statistics of one figure over many devices: summary (n, mean, standard deviation, min,
//! max), yield against the limits, process capability Cp/Cpk (within-device sigma from the
//! average moving range) and process performance Pp/Ppk (overall sample standard deviation) with
//! confidence intervals, and outliers by Tukey's fences.
//!
//! Sources: AIAG, *Statistical Process Control* reference manual, 2nd ed. (2005), ch. IV
//! (Cp, Cpk, Pp, Ppk; sigma within = MR-bar / d2 with d2 = 1.128 for moving ranges of two);
//! D. C. Montgomery, *Introduction to Statistical Quality Control*, 7th ed., sect. 8.3.5
//! (chi-squared interval of Cp); A. F. Bissell, "How reliable is your capability index?",
//! Applied Statistics 39 (1990) 331-340 (normal approximation of the interval of Cpk);
//! J. W. Tukey, *Exploratory Data Analysis* (1977) (fences at 1.5 interquartile ranges), with
//! quartiles by linear interpolation (Hyndman & Fan type 7, numpy's default).
//!
//! Two guards keep the indices honest (issue 53). A *degenerate spread* gives no index: a sigma
//! at most [`NEGLIGIBLE_SPREAD`] (1e-9) times the magnitude of the data and limits
//! ([`spread_scale`]) is rounding, not variation (values equal to within floating-point
//! rounding gave Ppk = 1.96e15 from s = 8.5e-18), so Cp/Cpk or Pp/Ppk are `None` with the reason
//! in [`LotStatistics::indices_refused`]. *Few values* are said: indices from fewer than
//! [`MIN_VALUES_FOR_CAPABILITY`] (25) values carry a warning (the AIAG SPC manual, 2nd ed., ch. II,
//! asks for 25 or more subgroups, with individuals 25 values, before capability is judged;
//! ISO 22514-2 likewise asks for a long enough study), and n < 2 says there is no standard
//! deviation.

use statrs::distribution::{ChiSquared, ContinuousCDF, Normal};

/// d2 of moving ranges of two consecutive values (AIAG SPC manual, appendix E).
pub const D2_MOVING_RANGE: f64 = 1.128;

/// Fewest values from which capability indices are given without a warning: 25 (AIAG SPC
/// manual, 2nd ed., ch. II: 25 or more subgroups before a process is judged; individual values
/// are subgroups of one; ISO 22514-2 asks for a long enough study likewise).
pub const MIN_VALUES_FOR_CAPABILITY: usize = 25;

/// A sigma at most this fraction of [`spread_scale`] is degenerate (rounding, not variation):
/// 1e-9, a million times the relative rounding of a double (2.2e-16) and far below any spread a
/// test figure resolves (no gyro test figure is measured to nine significant digits).
pub const NEGLIGIBLE_SPREAD: f64 = 1e-9;

/// The magnitude a spread is judged against: the largest absolute value among the values and
/// the limits (so at least half the tolerance width when both limits exist). 0 for no values
/// and no limits.
pub fn spread_scale(values: &[f64], lsl: Option<f64>, usl: Option<f64>) -> f64 {
    values.iter().chain(lsl.iter()).chain(usl.iter()).map(|v| v.abs()).filter(|v| v.is_finite()).fold(0.0, f64::max)
}

/// True when `sigma` is no spread at all for data of magnitude `scale`: not finite, zero, or at
/// most [`NEGLIGIBLE_SPREAD`] x `scale` (values equal to within rounding). With `scale` 0 (every
/// value and limit zero) only a positive sigma counts.
pub fn negligible_spread(sigma: f64, scale: f64) -> bool {
    !sigma.is_finite() || sigma <= 0.0 || sigma <= NEGLIGIBLE_SPREAD * scale
}

/// A two-sided confidence interval.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Interval {
    /// Lower end.
    pub lower: f64,
    /// Upper end.
    pub upper: f64,
}

/// A capability index and its confidence interval (`None` when the data cannot give one).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Index {
    /// The estimate.
    pub value: f64,
    /// Its confidence interval at the level of [`LotStatistics::confidence`].
    pub interval: Option<Interval>,
}

/// The statistics of one figure over a lot.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct LotStatistics {
    /// Number of values.
    pub n: usize,
    /// Arithmetic mean.
    pub mean: f64,
    /// Sample standard deviation (divisor n - 1); `None` for n < 2.
    pub sd: Option<f64>,
    /// Within sigma: average moving range of consecutive values / d2 (1.128); `None` for n < 2.
    pub sigma_within: Option<f64>,
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
    /// Values inside the limits (inclusive) / n; `None` without limits.
    pub yield_fraction: Option<f64>,
    /// Cp = (USL - LSL) / (6 sigma_within); two limits needed.
    pub cp: Option<Index>,
    /// Cpk = min(USL - mean, mean - LSL) / (3 sigma_within); the sides that exist.
    pub cpk: Option<Index>,
    /// Pp = (USL - LSL) / (6 sd).
    pub pp: Option<Index>,
    /// Ppk = min(USL - mean, mean - LSL) / (3 sd).
    pub ppk: Option<Index>,
    /// Confidence level of the intervals (e.g. 0.95).
    pub confidence: f64,
    /// Indices (into the input) of the values outside Tukey's fences (1.5 IQR beyond the quartiles).
    pub outliers: Vec<usize>,
    /// Why capability indices are missing although a limit exists: n < 2 (no standard
    /// deviation) or a degenerate spread ([`negligible_spread`]); `None` when every index the
    /// limits allow is given, or without limits.
    pub indices_refused: Option<String>,
    /// What a reader must know before using these numbers: indices from fewer than
    /// [`MIN_VALUES_FOR_CAPABILITY`] values, n < 2 (no standard deviation), indices refused.
    pub warnings: Vec<String>,
}

/// Sample mean and standard deviation (divisor n - 1; `None` for n < 2).
pub fn mean_sd(values: &[f64]) -> (f64, Option<f64>) {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    if values.len() < 2 {
        return (mean, None);
    }
    let ss: f64 = values.iter().map(|v| (v - mean) * (v - mean)).sum();
    (mean, Some((ss / (n - 1.0)).sqrt()))
}

/// Average moving range of consecutive values / d2: the within sigma of individual values.
pub fn sigma_from_moving_range(values: &[f64]) -> Option<f64> {
    if values.len() < 2 {
        return None;
    }
    let mr: f64 = values.windows(2).map(|w| (w[1] - w[0]).abs()).sum::<f64>() / (values.len() - 1) as f64;
    Some(mr / D2_MOVING_RANGE)
}

/// Quantile by linear interpolation between order statistics (Hyndman & Fan type 7, numpy's
/// default): `sorted` must be sorted ascending and non-empty, `p` in [0, 1].
pub fn quantile_sorted(sorted: &[f64], p: f64) -> f64 {
    let h = (sorted.len() - 1) as f64 * p;
    let lo = h.floor() as usize;
    let hi = (lo + 1).min(sorted.len() - 1);
    sorted[lo] + (h - lo as f64) * (sorted[hi] - sorted[lo])
}

/// Indices of the values outside Tukey's fences [Q1 - 1.5 IQR, Q3 + 1.5 IQR].
pub fn tukey_outliers(values: &[f64]) -> Vec<usize> {
    if values.len() < 4 {
        return Vec::new();
    }
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let q1 = quantile_sorted(&sorted, 0.25);
    let q3 = quantile_sorted(&sorted, 0.75);
    let iqr = q3 - q1;
    let (lo, hi) = (q1 - 1.5 * iqr, q3 + 1.5 * iqr);
    values.iter().enumerate().filter(|(_, v)| **v < lo || **v > hi).map(|(i, _)| i).collect()
}

/// Chi-squared interval of Cp or Pp (Montgomery 8.3.5): C sqrt(chi2(a/2, n-1)/(n-1)) to
/// C sqrt(chi2(1-a/2, n-1)/(n-1)).
pub fn cp_interval(cp: f64, n: usize, confidence: f64) -> Option<Interval> {
    if n < 2 || !cp.is_finite() {
        return None;
    }
    let nu = (n - 1) as f64;
    let chi = ChiSquared::new(nu).ok()?;
    let a = 1.0 - confidence;
    Some(Interval {
        lower: cp * (chi.inverse_cdf(a / 2.0) / nu).sqrt(),
        upper: cp * (chi.inverse_cdf(1.0 - a / 2.0) / nu).sqrt(),
    })
}

/// Bissell's (1990) normal approximation of the interval of Cpk or Ppk:
/// C -/+ z(1-a/2) sqrt(1/(9n) + C^2/(2(n-1))).
pub fn cpk_interval_bissell(cpk: f64, n: usize, confidence: f64) -> Option<Interval> {
    if n < 2 || !cpk.is_finite() {
        return None;
    }
    let z = Normal::new(0.0, 1.0).ok()?.inverse_cdf(1.0 - (1.0 - confidence) / 2.0);
    let nf = n as f64;
    let half = z * (1.0 / (9.0 * nf) + cpk * cpk / (2.0 * (nf - 1.0))).sqrt();
    Some(Interval { lower: cpk - half, upper: cpk + half })
}

fn indices(
    mean: f64,
    sigma: Option<f64>,
    lsl: Option<f64>,
    usl: Option<f64>,
    n: usize,
    confidence: f64,
) -> (Option<Index>, Option<Index>) {
    let Some(s) = sigma.filter(|s| *s > 0.0 && s.is_finite()) else {
        return (None, None);
    };
    let cp = match (lsl, usl) {
        (Some(l), Some(u)) => {
            let v = (u - l) / (6.0 * s);
            Some(Index { value: v, interval: cp_interval(v, n, confidence) })
        }
        _ => None,
    };
    let sides: Vec<f64> =
        [usl.map(|u| (u - mean) / (3.0 * s)), lsl.map(|l| (mean - l) / (3.0 * s))].into_iter().flatten().collect();
    let cpk = sides
        .into_iter()
        .reduce(f64::min)
        .map(|v| Index { value: v, interval: cpk_interval_bissell(v, n, confidence) });
    (cp, cpk)
}

/// Lot statistics of `values` (in test order: the moving ranges follow it) against the limits
/// `lsl` (lower) and `usl` (upper); `None` for no values or a non-finite value. Capability
/// indices are refused (`None`, the reason in `indices_refused`) for n < 2 and for a degenerate
/// spread ([`negligible_spread`] against [`spread_scale`]); indices from fewer than
/// [`MIN_VALUES_FOR_CAPABILITY`] values carry a warning.
pub fn lot_statistics(values: &[f64], lsl: Option<f64>, usl: Option<f64>, confidence: f64) -> Option<LotStatistics> {
    if values.is_empty() || values.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let n = values.len();
    let (mean, sd) = mean_sd(values);
    let sigma_within = sigma_from_moving_range(values);
    let min = values.iter().copied().fold(f64::INFINITY, f64::min);
    let max = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let limits = lsl.is_some() || usl.is_some();
    let yield_fraction = if !limits {
        None
    } else {
        let inside = values.iter().filter(|v| lsl.is_none_or(|l| **v >= l) && usl.is_none_or(|u| **v <= u)).count();
        Some(inside as f64 / n as f64)
    };
    let scale = spread_scale(values, lsl, usl);
    let usable = |s: Option<f64>| s.filter(|s| !negligible_spread(*s, scale));
    let (cp, cpk) = indices(mean, usable(sigma_within), lsl, usl, n, confidence);
    let (pp, ppk) = indices(mean, usable(sd), lsl, usl, n, confidence);
    let mut warnings = Vec::new();
    let mut refused = Vec::new();
    if n < 2 && limits {
        refused.push("n = 1: no standard deviation, so no Cp, Cpk, Pp or Ppk".to_string());
    } else if n < 2 {
        warnings.push("n = 1: no standard deviation".to_string());
    } else if limits {
        let degenerate = |name: &str, what: &str, s: Option<f64>| {
            s.filter(|s| negligible_spread(*s, scale)).map(|s| {
                format!(
                    "no {name}: {what} {} is a degenerate spread (at most {NEGLIGIBLE_SPREAD:e} of the data's \
                     magnitude {}: the values are equal to within rounding)",
                    crate::format::sig(s, 2),
                    crate::format::short(scale, 4)
                )
            })
        };
        refused.extend(degenerate("Cp, Cpk", "sigma within", sigma_within));
        refused.extend(degenerate("Pp, Ppk", "s", sd));
    }
    warnings.extend(refused.iter().cloned());
    let any_index = cp.is_some() || cpk.is_some() || pp.is_some() || ppk.is_some();
    if any_index && n < MIN_VALUES_FOR_CAPABILITY {
        warnings.push(format!(
            "capability from n = {n} values, fewer than {MIN_VALUES_FOR_CAPABILITY} (AIAG SPC manual, ISO 22514-2): \
             the indices are rough estimates, see their intervals"
        ));
    }
    Some(LotStatistics {
        n,
        mean,
        sd,
        sigma_within,
        min,
        max,
        yield_fraction,
        cp,
        cpk,
        pp,
        ppk,
        confidence,
        outliers: tukey_outliers(values),
        indices_refused: (!refused.is_empty()).then(|| refused.join("; ")),
        warnings,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    // Hand calculation: values 9.8, 10.1, 10.0, 9.9, 10.2, limits 9.0 .. 11.0.
    // mean = 50.0/5 = 10.0; squares of deviations .04 .01 0 .01 .04 = .10; s = sqrt(.1/4) = 0.158113883.
    // moving ranges .3 .1 .1 .3 -> mean .2; sigma within = .2/1.128 = 0.177304965.
    // Pp = 2/(6 s) = 2.108185107; Ppk = 1/(3 s) = 2.108185107 (centred).
    // Cp = 2/(6 * 0.177304965) = 1.88
    const V: [f64; 5] = [9.8, 10.1, 10.0, 9.9, 10.2];

    #[test]
    fn hand_calculation_of_a_small_lot() {
        let s = lot_statistics(&V, Some(9.0), Some(11.0), 0.95).unwrap();
        assert_eq!(s.n, 5);
        assert_relative_eq!(s.mean, 10.0, max_relative = 1e-12);
        assert_relative_eq!(s.sd.unwrap(), 0.158113883008419, max_relative = 1e-12);
        assert_relative_eq!(s.sigma_within.unwrap(), 0.2 / 1.128, max_relative = 1e-12);
        assert_relative_eq!(s.cp.unwrap().value, 1.88, max_relative = 1e-12);
        assert_relative_eq!(s.pp.unwrap().value, 2.108185106778919, max_relative = 1e-12);
        assert_relative_eq!(s.ppk.unwrap().value, 2.108185106778919, max_relative = 1e-12);
        assert_eq!(s.yield_fraction, Some(1.0));
        assert_eq!((s.min, s.max), (9.8, 10.2));
        assert!(s.outliers.is_empty());
    }

    #[test]
    fn off_centre_and_one_sided_limits() {
        // Upper limit only: Ppk = (10.5 - 10)/(3 s) = 1.054092553; no Pp.
        let s = lot_statistics(&V, None, Some(10.5), 0.95).unwrap();
        assert!(s.pp.is_none() && s.cp.is_none());
        assert_relative_eq!(s.ppk.unwrap().value, 0.5 / (3.0 * 0.158113883008419), max_relative = 1e-12);
        // Lower limit 10.0 closer: Ppk = 0 and yield 3/5 (9.8 and 9.9 below).
        let s = lot_statistics(&V, Some(10.0), Some(11.0), 0.95).unwrap();
        assert_relative_eq!(s.ppk.unwrap().value, 0.0, epsilon = 1e-12);
        assert_eq!(s.yield_fraction, Some(0.6));
    }

    #[test]
    fn intervals_against_scipy() {
        // scipy 1.17.1: chi2.ppf(0.025, 29) = 16.04707169536489, chi2.ppf(0.975, 29) = 45.72228580417452,
        // norm.ppf(0.975) = 1.959963984540054.
        let cp = 1.5;
        let i = cp_interval(cp, 30, 0.95).unwrap();
        assert_relative_eq!(i.lower, 1.5 * (16.04707169536489f64 / 29.0).sqrt(), max_relative = 1e-9);
        assert_relative_eq!(i.upper, 1.5 * (45.72228580417452f64 / 29.0).sqrt(), max_relative = 1e-9);
        let half = 1.959963984540054 * (1.0 / 270.0 + 1.5f64 * 1.5 / 58.0).sqrt();
        let b = cpk_interval_bissell(1.5, 30, 0.95).unwrap();
        assert_relative_eq!(b.lower, 1.5 - half, max_relative = 1e-9);
        assert_relative_eq!(b.upper, 1.5 + half, max_relative = 1e-9);
    }

    #[test]
    fn tukey_fences_against_numpy_percentiles() {
        // numpy.percentile([1,2,3,4,5,6,7,8,9,100], [25, 75]) = [3.25, 7.75]; fences -3.5 .. 14.5.
        let v = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 100.0];
        let mut s = v.to_vec();
        s.sort_by(f64::total_cmp);
        assert_relative_eq!(quantile_sorted(&s, 0.25), 3.25);
        assert_relative_eq!(quantile_sorted(&s, 0.75), 7.75);
        assert_eq!(tukey_outliers(&v), vec![9]);
    }

    #[test]
    fn degenerate_lots_give_no_index_rather_than_a_wrong_one() {
        let s = lot_statistics(&[1.0], Some(0.0), Some(2.0), 0.95).unwrap();
        assert!(s.sd.is_none() && s.cp.is_none() && s.ppk.is_none());
        assert!(s.indices_refused.as_deref().is_some_and(|r| r.contains("n = 1")), "{s:?}");
        assert!(s.warnings.iter().any(|w| w.contains("no standard deviation")), "{s:?}");
        let s = lot_statistics(&[1.0, 1.0, 1.0], Some(0.0), Some(2.0), 0.95).unwrap();
        assert!(s.cpk.is_none(), "zero spread has no finite capability");
        assert!(s.indices_refused.as_deref().is_some_and(|r| r.contains("degenerate")), "{s:?}");
        assert!(lot_statistics(&[], None, None, 0.95).is_none());
        assert!(lot_statistics(&[1.0, f64::NAN], None, None, 0.95).is_none());
        // Without limits nothing is refused, but n = 1 still says there is no sd.
        let s = lot_statistics(&[1.0], None, None, 0.95).unwrap();
        assert_eq!((s.indices_refused.as_deref(), s.warnings.len()), (None, 1));
    }

    #[test]
    fn the_issues_resolution_case_gives_no_index_from_rounding() {
        // Issue 53: four values of 0.0125 deg/s equal to within rounding (0, 0, 6 and 10 units in
        // the last place, 2^-59 each), upper limit 0.0625: s = 8.498e-18 (numpy std ddof=1), and
        // (USL - mean)/(3 s) = 1.961e15 -- the Ppk the store printed. Refused now, with why.
        let ulp = 2f64.powi(-59);
        let v = [0.0125, 0.0125, 0.0125 + 6.0 * ulp, 0.0125 + 10.0 * ulp];
        let s = lot_statistics(&v, None, Some(0.0625), 0.95).unwrap();
        let sd = s.sd.unwrap();
        assert_relative_eq!(sd, 8.498374721940739e-18, max_relative = 1e-6);
        assert_relative_eq!((0.0625 - s.mean) / (3.0 * sd), 1.961159305394875e15, max_relative = 1e-6);
        assert!(s.ppk.is_none() && s.cpk.is_none() && s.pp.is_none() && s.cp.is_none(), "{s:?}");
        let why = s.indices_refused.unwrap();
        assert!(why.contains("no Pp, Ppk: s 8.5e-18 is a degenerate spread"), "{why}");
        assert!(why.contains("no Cp, Cpk: sigma within"), "{why}");
        assert!(s.warnings.iter().all(|w| !w.contains("fewer than 25")), "no index, no few-values warning");
        // The rule itself: 1e-9 of the magnitude of the values and limits.
        let scale = spread_scale(&v, None, Some(0.0625));
        assert_eq!(scale, 0.0625);
        assert!(negligible_spread(8.5e-18, scale) && negligible_spread(0.0625e-9, scale));
        assert!(!negligible_spread(0.0625e-9 * 1.01, scale));
        assert!(negligible_spread(0.0, 0.0) && !negligible_spread(1e-300, 0.0));
        assert!(negligible_spread(f64::NAN, 1.0) && negligible_spread(f64::INFINITY, 1.0));
        // Scale-free: the same lot in units 1e12 times smaller is refused alike; a real spread is not.
        let tiny: Vec<f64> = v.iter().map(|x| x * 1e-12).collect();
        assert!(lot_statistics(&tiny, None, Some(0.0625e-12), 0.95).unwrap().ppk.is_none());
        let small: Vec<f64> = V.iter().map(|x| x * 1e-12).collect();
        let s = lot_statistics(&small, Some(9e-12), Some(11e-12), 0.95).unwrap();
        assert_relative_eq!(s.pp.unwrap().value, 2.108185106778919, max_relative = 1e-9);
    }

    #[test]
    fn indices_from_fewer_than_25_values_carry_a_warning() {
        let s = lot_statistics(&V, Some(9.0), Some(11.0), 0.95).unwrap();
        assert!(s.ppk.is_some() && s.indices_refused.is_none());
        assert_eq!(s.warnings.len(), 1, "{:?}", s.warnings);
        assert!(s.warnings[0].starts_with("capability from n = 5 values, fewer than 25"), "{:?}", s.warnings);
        // 24 values warn, 25 do not.
        let many: Vec<f64> = (0..25).map(|i| 10.0 + 0.01 * ((i * 7 % 11) as f64 - 5.0)).collect();
        let s24 = lot_statistics(&many[..24], Some(9.0), Some(11.0), 0.95).unwrap();
        assert!(s24.warnings.iter().any(|w| w.contains("n = 24 values, fewer than 25")), "{:?}", s24.warnings);
        let s25 = lot_statistics(&many, Some(9.0), Some(11.0), 0.95).unwrap();
        assert!(s25.ppk.is_some() && s25.warnings.is_empty(), "{:?}", s25.warnings);
        // No limits, no index: no capability warning either.
        assert!(lot_statistics(&V, None, None, 0.95).unwrap().warnings.is_empty());
    }
}
