//! Comparing two lots of one figure: Welch's t-test of the difference of means (unequal
//! variances, Welch-Satterthwaite degrees of freedom) and the F-test of the ratio of variances,
//! both two-sided.
//!
//! Sources: B. L. Welch, "The generalization of 'Student's' problem when several different
//! population variances are involved", Biometrika 34 (1947) 28-35; NIST/SEMATECH e-Handbook of
//! Statistical Methods, sect. 1.3.5.3 (two-sample t-test, unequal variances) and 1.3.5.9 (F-test
//! for equality of two variances). Equal to scipy.stats.ttest_ind(a, b, equal_var=False) and to
//! 2 min(F.cdf, F.sf) of scipy.stats.f.

use statrs::distribution::{ContinuousCDF, FisherSnedecor, StudentsT};

/// The comparison of two samples.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct TwoSampleComparison {
    /// Mean of the first minus mean of the second.
    pub mean_difference: f64,
    /// Welch's t statistic.
    pub t: f64,
    /// Welch-Satterthwaite degrees of freedom.
    pub t_dof: f64,
    /// Two-sided p-value of the t-test.
    pub t_p_value: f64,
    /// Ratio of the sample standard deviations (first / second).
    pub sd_ratio: f64,
    /// F = s1^2 / s2^2.
    pub f: f64,
    /// Two-sided p-value of the F-test, 2 min(P(F <= f), P(F >= f)), with (n1 - 1, n2 - 1)
    /// degrees of freedom.
    pub f_p_value: f64,
}

/// Welch's t-test and the F-test of two samples; `None` when a sample has fewer than two values
/// or no spread: a standard deviation that is zero or degenerate (at most
/// [`crate::process_capability::NEGLIGIBLE_SPREAD`] of the largest absolute value of both
/// samples: values equal to within rounding, whose t and F would be rounding noise).
pub fn compare_samples(a: &[f64], b: &[f64]) -> Option<TwoSampleComparison> {
    use crate::process_capability::{mean_sd, negligible_spread, spread_scale};
    let (ma, sa) = mean_sd(a);
    let (mb, sb) = mean_sd(b);
    let (sa, sb) = (sa?, sb?);
    let scale = spread_scale(a, None, None).max(spread_scale(b, None, None));
    if negligible_spread(sa, scale) || negligible_spread(sb, scale) {
        return None;
    }
    let (na, nb) = (a.len() as f64, b.len() as f64);
    let (va, vb) = (sa * sa / na, sb * sb / nb);
    let t = (ma - mb) / (va + vb).sqrt();
    let dof = (va + vb).powi(2) / (va * va / (na - 1.0) + vb * vb / (nb - 1.0));
    let st = StudentsT::new(0.0, 1.0, dof).ok()?;
    let t_p = (2.0 * st.cdf(-t.abs())).min(1.0);
    let f = sa * sa / (sb * sb);
    let fd = FisherSnedecor::new(na - 1.0, nb - 1.0).ok()?;
    let f_p = (2.0 * fd.cdf(f).min(fd.sf(f))).min(1.0);
    Some(TwoSampleComparison {
        mean_difference: ma - mb,
        t,
        t_dof: dof,
        t_p_value: t_p,
        sd_ratio: sa / sb,
        f,
        f_p_value: f_p,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn against_scipy() {
        let a = [1.02, 0.98, 1.05, 0.97, 1.01, 1.03, 0.99];
        let b = [1.10, 1.04, 1.12, 1.01, 1.08, 1.15];
        let c = compare_samples(&a, &b).unwrap();
        // scipy 1.17.1: r = stats.ttest_ind(a, b, equal_var=False) -> statistic
        // -3.2135252690935623, pvalue 0.013332958459766134, df 7.556983498183448;
        // f = np.var(a, ddof=1)/np.var(b, ddof=1) = 0.30892857142857216,
        // 2*min(stats.f.cdf(f, 6, 5), stats.f.sf(f, 6, 5)) = 0.18509344439172562.
        assert_relative_eq!(c.t, -3.2135252690935623, max_relative = 1e-9);
        assert_relative_eq!(c.t_dof, 7.556983498183448, max_relative = 1e-9);
        assert_relative_eq!(c.t_p_value, 0.013332958459766134, max_relative = 1e-7);
        assert_relative_eq!(c.f, 0.30892857142857216, max_relative = 1e-9);
        assert_relative_eq!(c.f_p_value, 0.18509344439172562, max_relative = 1e-7);
    }

    #[test]
    fn degenerate_samples_are_refused() {
        assert!(compare_samples(&[1.0], &[1.0, 2.0]).is_none());
        assert!(compare_samples(&[1.0, 1.0], &[1.0, 2.0]).is_none());
        // Equal to within rounding (s = 2.2e-16 of 1.0) is no spread either.
        assert!(compare_samples(&[1.0, 1.0 + f64::EPSILON], &[1.0, 2.0]).is_none());
        let c = compare_samples(&[1.0, 2.0, 3.0], &[1.0, 2.0, 3.0]).unwrap();
        assert_relative_eq!(c.t_p_value, 1.0, max_relative = 1e-12);
        assert_relative_eq!(c.f_p_value, 1.0, max_relative = 1e-12);
    }
}
