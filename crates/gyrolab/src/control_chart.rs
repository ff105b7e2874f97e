//! Shewhart control charts and their run rules: individuals / moving range (I-MR) over devices
//! in test order, X-bar / S over subgroups (lots), and the eight Nelson rules.
//!
//! Sources: AIAG, *Statistical Process Control* reference manual, 2nd ed. (2005), ch. II and
//! appendix E (I-MR limits: mean -/+ 2.66 MR-bar, MR upper limit D4 MR-bar = 3.267 MR-bar;
//! X-bar/S with c4); D. C. Montgomery, *Introduction to Statistical Quality Control*, 7th ed.,
//! sect. 6.3.2 (X-bar and S with variable subgroup size); L. S. Nelson, "The Shewhart control
//! chart - tests for special causes", Journal of Quality Technology 16 (1984) 237-239 (rules
//! 1-8; Western Electric rules 1-4 of the *Statistical Quality Control Handbook* (1956) are
//! Nelson rules 1, 5, 6 and, with eight instead of nine points, 2).

use statrs::function::gamma::ln_gamma;

/// One chart: points, centre line and 3-sigma limits (per point for varying subgroup sizes).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Chart {
    /// Plotted values.
    pub points: Vec<f64>,
    /// Centre line.
    pub center: f64,
    /// Sigma of a plotted point, per point (for the zone rules).
    pub sigma: Vec<f64>,
    /// Lower control limit, per point.
    pub lcl: Vec<f64>,
    /// Upper control limit, per point.
    pub ucl: Vec<f64>,
    /// Rule violations.
    pub violations: Vec<Violation>,
}

/// A run-rule violation: the rule and the point that completes the pattern.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct Violation {
    /// Nelson rule number (1 to 8).
    pub rule: u8,
    /// Index of the last point of the pattern.
    pub index: usize,
}

/// The text of each Nelson rule, by number - 1.
pub const NELSON_RULES: [&str; 8] = [
    "one point beyond 3 sigma",
    "nine points in a row on one side of the centre line",
    "six points in a row steadily increasing or decreasing",
    "fourteen points in a row alternating up and down",
    "two of three points in a row beyond 2 sigma on the same side",
    "four of five points in a row beyond 1 sigma on the same side",
    "fifteen points in a row within 1 sigma",
    "eight points in a row beyond 1 sigma on either side",
];

/// c4(n) = sqrt(2/(n-1)) Gamma(n/2) / Gamma((n-1)/2): the bias of the sample standard deviation.
pub fn c4(n: usize) -> f64 {
    let nf = n as f64;
    (2.0 / (nf - 1.0)).sqrt() * (ln_gamma(nf / 2.0) - ln_gamma((nf - 1.0) / 2.0)).exp()
}

/// Nelson rule violations of `points` against `center` with per-point `sigma`.
pub fn nelson_violations(points: &[f64], center: f64, sigma: &[f64]) -> Vec<Violation> {
    let z: Vec<f64> = points.iter().zip(sigma).map(|(x, s)| (x - center) / s).collect();
    let mut out = Vec::new();
    let side = |v: f64| {
        if v > 0.0 {
            1
        } else if v < 0.0 {
            -1
        } else {
            0
        }
    };
    for i in 0..z.len() {
        let window = |len: usize| if i + 1 >= len { Some(&z[i + 1 - len..=i]) } else { None };
        let mut hit = |rule: u8| out.push(Violation { rule, index: i });
        if z[i].abs() > 3.0 {
            hit(1);
        }
        if let Some(w) = window(9) {
            let s = side(w[0]);
            if s != 0 && w.iter().all(|v| side(*v) == s) {
                hit(2);
            }
        }
        if i >= 5 {
            let p = &points[i - 5..=i];
            if p.windows(2).all(|d| d[1] > d[0]) || p.windows(2).all(|d| d[1] < d[0]) {
                hit(3);
            }
        }
        if i >= 13 {
            let p = &points[i - 13..=i];
            let d: Vec<f64> = p.windows(2).map(|d| d[1] - d[0]).collect();
            if d.windows(2).all(|w| w[0] * w[1] < 0.0) {
                hit(4);
            }
        }
        for (rule, len, need, k) in [(5u8, 3usize, 2usize, 2.0), (6, 5, 4, 1.0)] {
            if let Some(w) = window(len) {
                let up = w.iter().filter(|v| **v > k).count();
                let down = w.iter().filter(|v| **v < -k).count();
                // The completing point must itself be one of the points beyond.
                if (up >= need && z[i] > k) || (down >= need && z[i] < -k) {
                    hit(rule);
                }
            }
        }
        if let Some(w) = window(15) {
            if w.iter().all(|v| v.abs() < 1.0) {
                hit(7);
            }
        }
        if let Some(w) = window(8) {
            if w.iter().all(|v| v.abs() > 1.0) && w.iter().any(|v| *v > 1.0) && w.iter().any(|v| *v < -1.0) {
                hit(8);
            }
        }
    }
    out.sort_by_key(|v| (v.index, v.rule));
    out
}

/// Individuals and moving-range charts of `values` in test order; `None` for fewer than two
/// values or no variation (MR-bar zero or degenerate: at most
/// [`crate::process_capability::NEGLIGIBLE_SPREAD`] of the largest absolute value, values equal
/// to within rounding, whose limits would flag rounding noise).
pub fn individuals_moving_range(values: &[f64]) -> Option<(Chart, Chart)> {
    use crate::process_capability::{negligible_spread, spread_scale};
    if values.len() < 2 {
        return None;
    }
    let center = values.iter().sum::<f64>() / values.len() as f64;
    let mr: Vec<f64> = values.windows(2).map(|w| (w[1] - w[0]).abs()).collect();
    let mr_bar = mr.iter().sum::<f64>() / mr.len() as f64;
    if negligible_spread(mr_bar, spread_scale(values, None, None)) {
        return None;
    }
    let sigma = mr_bar / crate::process_capability::D2_MOVING_RANGE;
    let n = values.len();
    let s = vec![sigma; n];
    let violations = nelson_violations(values, center, &s);
    let individuals = Chart {
        points: values.to_vec(),
        center,
        sigma: s,
        lcl: vec![center - 3.0 * sigma; n],
        ucl: vec![center + 3.0 * sigma; n],
        violations,
    };
    // MR chart (D3 = 0, D4 = 3.267 for n = 2); only rule 1 applies to ranges.
    let ucl = 3.267 * mr_bar;
    let mr_violations =
        mr.iter().enumerate().filter(|(_, r)| **r > ucl).map(|(i, _)| Violation { rule: 1, index: i }).collect();
    let moving_range = Chart {
        sigma: vec![(ucl - mr_bar) / 3.0; mr.len()],
        lcl: vec![0.0; mr.len()],
        ucl: vec![ucl; mr.len()],
        points: mr,
        center: mr_bar,
        violations: mr_violations,
    };
    Some((individuals, moving_range))
}

/// X-bar and S charts over subgroups (each at least two values): sigma = mean of s_i / c4(n_i),
/// centre = grand mean of all values; limits per subgroup. `None` when a subgroup has fewer than
/// two values or there is no variation (sigma zero or degenerate, as for
/// [`individuals_moving_range`]).
pub fn xbar_s(subgroups: &[Vec<f64>]) -> Option<(Chart, Chart)> {
    if subgroups.is_empty() || subgroups.iter().any(|g| g.len() < 2) {
        return None;
    }
    let stats: Vec<(usize, f64, f64)> = subgroups
        .iter()
        .map(|g| {
            let (m, s) = crate::process_capability::mean_sd(g);
            (g.len(), m, s.unwrap_or(0.0))
        })
        .collect();
    let total: usize = stats.iter().map(|s| s.0).sum();
    let center = stats.iter().map(|(n, m, _)| *n as f64 * m).sum::<f64>() / total as f64;
    let sigma = stats.iter().map(|(n, _, s)| s / c4(*n)).sum::<f64>() / stats.len() as f64;
    let scale = subgroups.iter().map(|g| crate::process_capability::spread_scale(g, None, None)).fold(0.0, f64::max);
    if crate::process_capability::negligible_spread(sigma, scale) {
        return None;
    }
    let xs: Vec<f64> = stats.iter().map(|s| s.1).collect();
    let xsig: Vec<f64> = stats.iter().map(|(n, _, _)| sigma / (*n as f64).sqrt()).collect();
    let xbar = Chart {
        violations: nelson_violations(&xs, center, &xsig),
        lcl: xsig.iter().map(|s| center - 3.0 * s).collect(),
        ucl: xsig.iter().map(|s| center + 3.0 * s).collect(),
        points: xs,
        center,
        sigma: xsig,
    };
    let ss: Vec<f64> = stats.iter().map(|s| s.2).collect();
    let ssig: Vec<f64> = stats.iter().map(|(n, _, _)| sigma * (1.0 - c4(*n).powi(2)).sqrt()).collect();
    let scenter: Vec<f64> = stats.iter().map(|(n, _, _)| c4(*n) * sigma).collect();
    let s_violations = ss
        .iter()
        .enumerate()
        .filter(|(i, s)| (**s - scenter[*i]).abs() > 3.0 * ssig[*i])
        .map(|(i, _)| Violation { rule: 1, index: i })
        .collect();
    let s_chart = Chart {
        points: ss,
        center: scenter.iter().sum::<f64>() / scenter.len() as f64,
        lcl: scenter.iter().zip(&ssig).map(|(c, s)| (c - 3.0 * s).max(0.0)).collect(),
        ucl: scenter.iter().zip(&ssig).map(|(c, s)| c + 3.0 * s).collect(),
        sigma: ssig,
        violations: s_violations,
    };
    Some((xbar, s_chart))
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn rules_at(points: &[f64]) -> Vec<(u8, usize)> {
        nelson_violations(points, 0.0, &vec![1.0; points.len()]).iter().map(|v| (v.rule, v.index)).collect()
    }

    #[test]
    fn c4_against_published_table() {
        // AIAG SPC manual appendix E: c4(2) = 0.7979, c4(5) = 0.9400, c4(10) = 0.9727, c4(25) = 0.9896.
        for (n, c) in [(2, 0.7979), (5, 0.9400), (10, 0.9727), (25, 0.9896)] {
            assert!((c4(n) - c).abs() < 5e-5, "c4({n}) = {}", c4(n));
        }
    }

    #[test]
    fn each_nelson_rule_on_a_hand_made_series() {
        // Rule 1 alone: one point at 3.5 sigma among alternating small values (+-0.1 would make
        // rule 4 after fourteen points, so only five points).
        assert_eq!(rules_at(&[0.1, -0.1, 3.5, -0.1, 0.1]), vec![(1, 2)]);
        // Rule 2: nine points at +0.5 (no trend, within 1 sigma).
        let r = rules_at(&[0.5; 9]);
        assert_eq!(r, vec![(2, 8)]);
        // Rule 3: six increasing points 0.1 .. 0.6 (rule 2 needs nine).
        assert_eq!(rules_at(&[0.1, 0.2, 0.3, 0.4, 0.5, 0.6]), vec![(3, 5)]);
        // Rule 4: fourteen points alternating up and down (+0.5 / -0.5); thirteen would not do.
        let alt: Vec<f64> = (0..14).map(|i| if i % 2 == 0 { 0.5 } else { -0.5 }).collect();
        assert_eq!(rules_at(&alt), vec![(4, 13)]);
        assert!(rules_at(&alt[..13]).is_empty());
        // Rule 5: two of three beyond +2 sigma.
        assert_eq!(rules_at(&[2.5, 0.0, 2.5]), vec![(5, 2)]);
        // Rule 6: four of five beyond +1 sigma (1.5, below 2).
        assert_eq!(rules_at(&[1.5, 1.5, -0.2, 1.5, 1.5]), vec![(6, 4)]);
        // Rule 8: eight points beyond 1 sigma on both sides (no two consecutive beyond 2 on one side).
        let r = rules_at(&[1.5, -1.5, 1.5, 1.5, -1.5, -1.5, 1.5, -1.5]);
        assert_eq!(r, vec![(8, 7)]);
        // A quiet series: no violation.
        assert!(rules_at(&[0.3, -0.2, 0.8, -0.9, 0.1, 0.0, -0.4, 1.2, -1.1, 0.2]).is_empty());
    }

    #[test]
    fn rule_7_fifteen_points_hugging_the_centre_line() {
        let v: Vec<f64> = (0..15).map(|i| [0.1, 0.3, -0.2, 0.25, -0.3][i % 5]).collect();
        assert_eq!(rules_at(&v), vec![(7, 14)]);
    }

    #[test]
    fn individuals_limits_by_hand() {
        // 10, 12, 11, 13: moving ranges 2, 1, 2 -> MR-bar 5/3; mean 11.5; UCL = 11.5 + 3 (5/3)/1.128.
        let (i, mr) = individuals_moving_range(&[10.0, 12.0, 11.0, 13.0]).unwrap();
        assert_relative_eq!(i.center, 11.5);
        assert_relative_eq!(i.ucl[0], 11.5 + 3.0 * (5.0 / 3.0) / 1.128, max_relative = 1e-12);
        assert_relative_eq!(mr.ucl[0], 3.267 * 5.0 / 3.0, max_relative = 1e-12);
        assert!(i.violations.is_empty());
    }

    #[test]
    fn xbar_s_limits_by_hand() {
        // Two subgroups of 2: {1, 3} (mean 2, s sqrt 2), {3, 5} (mean 4, s sqrt 2); c4(2) = 0.797885.
        let (x, s) = xbar_s(&[vec![1.0, 3.0], vec![3.0, 5.0]]).unwrap();
        let sigma = 2f64.sqrt() / c4(2);
        assert_relative_eq!(x.center, 3.0);
        assert_relative_eq!(x.ucl[0], 3.0 + 3.0 * sigma / 2f64.sqrt(), max_relative = 1e-12);
        assert_relative_eq!(s.points[0], 2f64.sqrt(), max_relative = 1e-12);
        assert!(xbar_s(&[vec![1.0]]).is_none());
        // Equal to within rounding: no chart of rounding noise.
        let e = f64::EPSILON;
        assert!(xbar_s(&[vec![1.0, 1.0 + e], vec![1.0, 1.0]]).is_none());
        assert!(individuals_moving_range(&[1.0, 1.0 + e, 1.0]).is_none());
    }
}
