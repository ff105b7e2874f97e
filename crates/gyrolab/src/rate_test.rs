//! Rate-table (scale-factor) test evaluation: stroke means, scale factor, nonlinearity,
//! linearity, hysteresis, repeatability, accuracy, asymmetry and scale-factor repeatability.
//!
//! Sources: the paper (Cheng et al. 2014, eq. 1-9) for the line, the rest reference and the
//! nonlinearity; GJB 2426A-2004 / IEEE Std 952-1997 for asymmetry and scale-factor
//! repeatability; sensor textbooks for linearity, hysteresis, repeatability and accuracy
//! (static characteristics relative to the full-scale output). `docs/METHODS.md` gives every
//! formula with its units.

use crate::fit::{self, FitError, LineFit, PolynomialFit};
use serde::{Deserialize, Serialize};
use std::fmt;
use thiserror::Error;

/// Direction of a sweep through the rates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum Stroke {
    /// Forward stroke (rates rising).
    #[serde(rename = "fwd")]
    Forward,
    /// Reverse stroke (rates falling).
    #[serde(rename = "rev")]
    Reverse,
}

impl Stroke {
    /// Labels accepted for each stroke, for messages.
    pub const ACCEPTED: &'static str = "fwd/rev, forward/reverse, +/-, up/down, 正/反";

    /// Parses a stroke label: fwd/rev, forward/reverse, f/r, +/-, up/down, 正/反 (正行程/反行程).
    pub fn from_label(s: &str) -> Option<Stroke> {
        let t = s.trim().trim_matches('"').to_lowercase();
        match t.as_str() {
            "fwd" | "forward" | "f" | "+" | "up" | "正" | "正行程" => Some(Stroke::Forward),
            "rev" | "reverse" | "r" | "-" | "down" | "反" | "反行程" => Some(Stroke::Reverse),
            _ => None,
        }
    }

    /// The short label (`fwd` or `rev`).
    pub fn label(self) -> &'static str {
        match self {
            Stroke::Forward => "fwd",
            Stroke::Reverse => "rev",
        }
    }
}

impl fmt::Display for Stroke {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.label())
    }
}

/// One output reading at a table rate, run and stroke (several per cell are averaged, eq. 4).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RateObservation {
    /// Table rate, deg/s.
    pub rate_dps: f64,
    /// Run number as labelled in the record.
    pub run: u32,
    /// Stroke.
    pub stroke: Stroke,
    /// Gyro output, in the record's output unit.
    pub output: f64,
}

/// Rest outputs recorded with the table still, at the start and end of the test (eq. 5).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RestRecord {
    /// Mean output at rest before the test, F_s.
    pub start: f64,
    /// Mean output at rest after the test, F_e.
    pub end: f64,
}

/// Why a rate-table record cannot be evaluated.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum RateTestError {
    /// The record holds no observation.
    #[error("the record holds no observations")]
    Empty,
    /// Fewer than two distinct rates.
    #[error("the record has {0} distinct rate(s); a scale factor needs at least 2")]
    TooFewRates(usize),
    /// A cell of the (rate, run, stroke) grid has no observation.
    #[error("no data for rate {rate_dps} deg/s, run {run}, stroke {stroke}")]
    MissingCell {
        /// Rate, deg/s.
        rate_dps: f64,
        /// Run label.
        run: u32,
        /// Stroke.
        stroke: Stroke,
    },
    /// A value is NaN or infinite.
    #[error("a non-finite value (NaN or infinity) at rate {rate_dps} deg/s, run {run}")]
    NonFinite {
        /// Rate, deg/s.
        rate_dps: f64,
        /// Run label.
        run: u32,
    },
    /// The mean outputs do not change with the rate (constant output): K = 0.
    #[error("the output does not change with the rate: no scale factor (is this the right output column?)")]
    NoScaleFactor,
    /// An option is out of range.
    #[error("invalid option: {0}")]
    InvalidOption(String),
    /// A fit failed.
    #[error(transparent)]
    Fit(#[from] FitError),
}

/// The complete grid of a rate-table test: one mean output per (rate, run, stroke).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RateTable {
    /// Distinct table rates, ascending, deg/s.
    pub rates_dps: Vec<f64>,
    /// Run labels, ascending.
    pub runs: Vec<u32>,
    /// Forward-stroke output per `[point][run]` (mean of its samples, eq. 4).
    pub forward: Vec<Vec<f64>>,
    /// Reverse-stroke output per `[point][run]`.
    pub reverse: Vec<Vec<f64>>,
    /// Number of samples averaged into each forward cell.
    pub forward_samples: Vec<Vec<usize>>,
    /// Number of samples averaged into each reverse cell.
    pub reverse_samples: Vec<Vec<usize>>,
    /// Rest outputs at start and end, when recorded.
    pub rest: Option<RestRecord>,
}

fn same_rate(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 * (1.0 + a.abs().max(b.abs()))
}

impl RateTable {
    /// Builds the grid from observations, averaging repeated samples of a cell (paper eq. 4).
    ///
    /// Every (rate, run, stroke) cell must have at least one observation.
    pub fn from_observations(obs: &[RateObservation], rest: Option<RestRecord>) -> Result<Self, RateTestError> {
        if obs.is_empty() {
            return Err(RateTestError::Empty);
        }
        for o in obs {
            if !o.rate_dps.is_finite() || !o.output.is_finite() {
                return Err(RateTestError::NonFinite { rate_dps: o.rate_dps, run: o.run });
            }
        }
        let mut rates: Vec<f64> = obs.iter().map(|o| o.rate_dps).collect();
        rates.sort_by(f64::total_cmp);
        rates.dedup_by(|a, b| same_rate(*a, *b));
        if rates.len() < 2 {
            return Err(RateTestError::TooFewRates(rates.len()));
        }
        let mut runs: Vec<u32> = obs.iter().map(|o| o.run).collect();
        runs.sort_unstable();
        runs.dedup();
        let (m, q) = (rates.len(), runs.len());
        let mut sums = [vec![vec![0.0; q]; m], vec![vec![0.0; q]; m]];
        let mut counts = [vec![vec![0usize; q]; m], vec![vec![0usize; q]; m]];
        for o in obs {
            let j = rates.partition_point(|&r| r < o.rate_dps && !same_rate(r, o.rate_dps));
            let r = runs.partition_point(|&x| x < o.run);
            let s = o.stroke as usize;
            sums[s][j][r] += o.output;
            counts[s][j][r] += 1;
        }
        for (s, stroke) in [Stroke::Forward, Stroke::Reverse].into_iter().enumerate() {
            for j in 0..m {
                for r in 0..q {
                    if counts[s][j][r] == 0 {
                        return Err(RateTestError::MissingCell { rate_dps: rates[j], run: runs[r], stroke });
                    }
                    sums[s][j][r] /= counts[s][j][r] as f64;
                }
            }
        }
        if let Some(rest) = rest {
            if !rest.start.is_finite() || !rest.end.is_finite() {
                return Err(RateTestError::NonFinite { rate_dps: 0.0, run: 0 });
            }
        }
        let [forward, reverse] = sums;
        let [forward_samples, reverse_samples] = counts;
        Ok(RateTable { rates_dps: rates, runs, forward, reverse, forward_samples, reverse_samples, rest })
    }

    /// Multiplies every output (and rest output) by a factor, for a change of output unit.
    pub fn scaled(&self, factor: f64) -> RateTable {
        let mut t = self.clone();
        for row in t.forward.iter_mut().chain(t.reverse.iter_mut()) {
            row.iter_mut().for_each(|v| *v *= factor);
        }
        t.rest = t.rest.map(|r| RestRecord { start: r.start * factor, end: r.end * factor });
        t
    }
}

/// Options of the rate-table evaluation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RateTestOptions {
    /// Coverage factor k of the repeatability (3 by default; 2 is also common).
    pub coverage: f64,
    /// Quote hysteresis as half the largest forward-reverse difference (some texts do).
    pub half_hysteresis: bool,
    /// Order of the polynomial model (1 = the straight line).
    pub order: usize,
    /// Nonlinearity limit (ratio, 0.001 = 0.1 %) for the linear input range, when wanted.
    pub nonlinearity_limit: Option<f64>,
}

impl Default for RateTestOptions {
    fn default() -> Self {
        RateTestOptions { coverage: 3.0, half_hysteresis: false, order: 1, nonlinearity_limit: None }
    }
}

/// Where the rest reference F_r came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RestReferenceSource {
    /// (F_s + F_e) / 2 from rest records at start and end (paper eq. 5).
    RestRecords,
    /// The mean output at the 0 deg/s point.
    ZeroRatePoint,
    /// No rest record and no 0 deg/s point: the fitted zero offset F0 stands in.
    FitZeroOffset,
}

/// Figures at one table rate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PointSummary {
    /// Table rate, deg/s.
    pub rate_dps: f64,
    /// Forward-stroke mean over runs (Table 2, y_z).
    pub forward_mean: f64,
    /// Reverse-stroke mean over runs (Table 2, y_F).
    pub reverse_mean: f64,
    /// Mean of the two stroke means (Table 2, y).
    pub mean: f64,
    /// Sample standard deviation (n - 1) of the forward outputs across runs.
    pub forward_std: Option<f64>,
    /// Sample standard deviation (n - 1) of the reverse outputs across runs.
    pub reverse_std: Option<f64>,
    /// Output of the fitted line K * rate + F0.
    pub line_output: f64,
    /// Residual of the line, mean - line_output, output units.
    pub line_residual: f64,
    /// Point nonlinearity a_j = (line_output - mean) / F_m (paper eq. 8), ratio.
    pub nonlinearity: f64,
    /// Residual of the polynomial model, output units.
    pub polynomial_residual: f64,
}

/// Scale-factor asymmetry from separate fits of the positive and negative rates.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Asymmetry {
    /// Scale factor fitted on rates >= 0, output units per deg/s.
    pub positive_scale_factor: f64,
    /// Scale factor fitted on rates <= 0, output units per deg/s.
    pub negative_scale_factor: f64,
    /// |K+ - K-| / |(K+ + K-) / 2|, ratio.
    pub asymmetry: f64,
}

/// Scale-factor repeatability across runs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ScaleFactorRepeatability {
    /// (run label, scale factor of that run fitted on both strokes), output units per deg/s.
    pub per_run: Vec<(u32, f64)>,
    /// std(K_i, n - 1) / |mean(K_i)|, ratio.
    pub repeatability: f64,
}

/// The widest symmetric input range whose nonlinearity stays within a limit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LinearRange {
    /// The nonlinearity limit asked for, ratio.
    pub limit: f64,
    /// Largest |rate| of the range, deg/s; `None` when no range of two or more rates qualifies.
    pub max_rate_dps: Option<f64>,
    /// Nonlinearity within that range, ratio.
    pub nonlinearity: Option<f64>,
    /// Number of table rates inside the range.
    pub points: usize,
}

/// Every figure of a rate-table evaluation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RateEvaluation {
    /// Per-rate figures, ascending rate.
    pub points: Vec<PointSummary>,
    /// Number of runs.
    pub runs: usize,
    /// The least-squares line (eq. 2-3): slope K (output units per deg/s), intercept F0.
    pub line: LineFit,
    /// Rest reference F_r, output units.
    pub rest_reference: f64,
    /// Where F_r came from.
    pub rest_reference_source: RestReferenceSource,
    /// Single-sided output amplitude F_m = max |mean_j - F_r|, output units.
    pub output_amplitude: f64,
    /// Full-scale output Y_FS = |K| (rate_max - rate_min), output units.
    pub full_scale_output: f64,
    /// Scale-factor nonlinearity K_a = max |a_j| (eq. 9), ratio.
    pub nonlinearity: f64,
    /// Linearity max |mean_j - line_j| / Y_FS, ratio.
    pub linearity: f64,
    /// Hysteresis max |fwd_j - rev_j| / Y_FS (halved with `half_hysteresis`), ratio.
    pub hysteresis: f64,
    /// Repeatability k * sigma_max / Y_FS, ratio; `None` with a single run.
    pub repeatability: Option<f64>,
    /// The largest standard deviation across runs at any (rate, stroke), output units.
    pub repeatability_sigma_max: Option<f64>,
    /// Accuracy as linearity + hysteresis + repeatability (the paper's rule), ratio.
    pub accuracy_sum: Option<f64>,
    /// Accuracy as the root-sum-square of the three, ratio.
    pub accuracy_rss: Option<f64>,
    /// Asymmetry, when both signs have at least two distinct rates.
    pub asymmetry: Option<Asymmetry>,
    /// Scale-factor repeatability, with two or more runs.
    pub scale_factor_repeatability: Option<ScaleFactorRepeatability>,
    /// Polynomial model of the chosen order fitted to the point means.
    pub polynomial: PolynomialFit,
    /// Linear input range, when a nonlinearity limit was given.
    pub linear_range: Option<LinearRange>,
    /// The options used.
    pub options: RateTestOptions,
}

impl RateEvaluation {
    /// Scale factor K, output units per deg/s.
    pub fn scale_factor(&self) -> f64 {
        self.line.slope
    }

    /// Zero offset F0 of the fitted line, output units.
    pub fn zero_offset(&self) -> f64 {
        self.line.intercept
    }
}

/// Nonlinearity of a set of point means about their own least-squares line (eq. 7-9).
/// Returns (line, F_m, point nonlinearities a_j, K_a).
fn nonlinearity_of(
    rates: &[f64],
    means: &[f64],
    rest_reference: f64,
) -> Result<(LineFit, f64, Vec<f64>, f64), FitError> {
    let line = fit::fit_line(rates, means)?;
    let amplitude = means.iter().map(|y| (y - rest_reference).abs()).fold(0.0, f64::max);
    let a: Vec<f64> = rates
        .iter()
        .zip(means)
        .map(|(&w, &y)| {
            // F^_j - F_j with F^_j = K w + (F0 - F_r) and F_j = y - F_r.
            let fitted = line.slope * w + (line.intercept - rest_reference);
            let measured = y - rest_reference;
            if amplitude > 0.0 {
                (fitted - measured) / amplitude
            } else {
                0.0
            }
        })
        .collect();
    let ka = a.iter().map(|v| v.abs()).fold(0.0, f64::max);
    Ok((line, amplitude, a, ka))
}

/// Evaluates a rate-table test.
pub fn evaluate(table: &RateTable, options: &RateTestOptions) -> Result<RateEvaluation, RateTestError> {
    if !(options.coverage.is_finite() && options.coverage > 0.0) {
        return Err(RateTestError::InvalidOption(format!(
            "coverage factor must be positive, got {}",
            options.coverage
        )));
    }
    if options.order == 0 || options.order > 9 {
        return Err(RateTestError::InvalidOption(format!("polynomial order must be 1 to 9, got {}", options.order)));
    }
    if let Some(l) = options.nonlinearity_limit {
        if !(l.is_finite() && l > 0.0) {
            return Err(RateTestError::InvalidOption(format!("nonlinearity limit must be positive, got {l}")));
        }
    }
    let m = table.rates_dps.len();
    let q = table.runs.len();
    if m < 2 {
        return Err(RateTestError::TooFewRates(m));
    }
    let fwd_mean: Vec<f64> = table.forward.iter().map(|r| r.iter().sum::<f64>() / q as f64).collect();
    let rev_mean: Vec<f64> = table.reverse.iter().map(|r| r.iter().sum::<f64>() / q as f64).collect();
    let means: Vec<f64> = fwd_mean.iter().zip(&rev_mean).map(|(f, r)| 0.5 * (f + r)).collect();
    let rates = &table.rates_dps;
    let line = fit::fit_line(rates, &means)?;
    if !(line.slope != 0.0 && line.slope.is_finite()) {
        return Err(RateTestError::NoScaleFactor);
    }

    let zero_point = rates.iter().position(|&w| w == 0.0);
    let (rest_reference, rest_reference_source) = match (table.rest, zero_point) {
        (Some(r), _) => (0.5 * (r.start + r.end), RestReferenceSource::RestRecords),
        (None, Some(j)) => (means[j], RestReferenceSource::ZeroRatePoint),
        (None, None) => (line.intercept, RestReferenceSource::FitZeroOffset),
    };
    let (_, output_amplitude, point_nl, nonlinearity) = nonlinearity_of(rates, &means, rest_reference)?;

    let (rmin, rmax) = (rates[0], rates[m - 1]);
    let full_scale_output = line.slope.abs() * (rmax - rmin);
    let max_residual = rates.iter().zip(&means).map(|(&w, &y)| (y - line.eval(w)).abs()).fold(0.0, f64::max);
    let linearity = max_residual / full_scale_output;
    let max_hyst = fwd_mean.iter().zip(&rev_mean).map(|(f, r)| (f - r).abs()).fold(0.0, f64::max);
    let hysteresis = max_hyst / full_scale_output * if options.half_hysteresis { 0.5 } else { 1.0 };

    let stds_f: Vec<Option<f64>> = table.forward.iter().map(|r| fit::sample_std(r)).collect();
    let stds_r: Vec<Option<f64>> = table.reverse.iter().map(|r| fit::sample_std(r)).collect();
    let sigma_max = stds_f
        .iter()
        .chain(&stds_r)
        .flatten()
        .copied()
        .fold(None, |acc: Option<f64>, s| Some(acc.map_or(s, |a| a.max(s))));
    let repeatability = sigma_max.map(|s| options.coverage * s / full_scale_output);
    let accuracy_sum = repeatability.map(|r| linearity + hysteresis + r);
    let accuracy_rss = repeatability.map(|r| (linearity * linearity + hysteresis * hysteresis + r * r).sqrt());

    let asymmetry =
        side_fit(rates, &means, |w| w >= 0.0).zip(side_fit(rates, &means, |w| w <= 0.0)).map(|(kp, kn)| Asymmetry {
            positive_scale_factor: kp,
            negative_scale_factor: kn,
            asymmetry: (kp - kn).abs() / (0.5 * (kp + kn)).abs(),
        });

    let scale_factor_repeatability = if q >= 2 {
        let mut per_run = Vec::with_capacity(q);
        for (r, &run) in table.runs.iter().enumerate() {
            let x: Vec<f64> = rates.iter().chain(rates.iter()).copied().collect();
            let y: Vec<f64> =
                table.forward.iter().map(|row| row[r]).chain(table.reverse.iter().map(|row| row[r])).collect();
            per_run.push((run, fit::fit_line(&x, &y)?.slope));
        }
        let ks: Vec<f64> = per_run.iter().map(|p| p.1).collect();
        let mean_k = fit::mean(&ks).unwrap_or(f64::NAN);
        fit::sample_std(&ks).map(|s| ScaleFactorRepeatability { per_run, repeatability: s / mean_k.abs() })
    } else {
        None
    };

    let order = options.order.min(m - 1);
    let polynomial = fit::fit_polynomial(rates, &means, order)?;

    let linear_range = options.nonlinearity_limit.map(|limit| linear_range(rates, &means, rest_reference, limit));

    let points = (0..m)
        .map(|j| PointSummary {
            rate_dps: rates[j],
            forward_mean: fwd_mean[j],
            reverse_mean: rev_mean[j],
            mean: means[j],
            forward_std: stds_f[j],
            reverse_std: stds_r[j],
            line_output: line.eval(rates[j]),
            line_residual: means[j] - line.eval(rates[j]),
            nonlinearity: point_nl[j],
            polynomial_residual: polynomial.residuals[j],
        })
        .collect();

    Ok(RateEvaluation {
        points,
        runs: q,
        line,
        rest_reference,
        rest_reference_source,
        output_amplitude,
        full_scale_output,
        nonlinearity,
        linearity,
        hysteresis,
        repeatability,
        repeatability_sigma_max: sigma_max,
        accuracy_sum,
        accuracy_rss,
        asymmetry,
        scale_factor_repeatability,
        polynomial,
        linear_range,
        options: RateTestOptions { order, ..options.clone() },
    })
}

/// Slope of the line fitted to the points whose rate satisfies `keep`; `None` with fewer than
/// two distinct rates on that side.
fn side_fit(rates: &[f64], means: &[f64], keep: impl Fn(f64) -> bool) -> Option<f64> {
    let (x, y): (Vec<f64>, Vec<f64>) =
        rates.iter().zip(means).filter(|(w, _)| keep(**w)).map(|(w, y)| (*w, *y)).unzip();
    fit::fit_line(&x, &y).ok().map(|l| l.slope)
}

/// Widest symmetric range |rate| <= R whose nonlinearity (refitted on that range) is within
/// `limit`; candidate R are the distinct |rates| of the table; a range needs three or more rates
/// (two points always fit a line exactly).
fn linear_range(rates: &[f64], means: &[f64], rest_reference: f64, limit: f64) -> LinearRange {
    let mut bounds: Vec<f64> = rates.iter().map(|w| w.abs()).collect();
    bounds.sort_by(|a, b| b.total_cmp(a));
    bounds.dedup();
    for r in bounds {
        let (x, y): (Vec<f64>, Vec<f64>) =
            rates.iter().zip(means).filter(|(w, _)| w.abs() <= r * (1.0 + 1e-12)).map(|(w, y)| (*w, *y)).unzip();
        let mut distinct = x.clone();
        distinct.dedup();
        if distinct.len() < 3 {
            break;
        }
        if let Ok((_, _, _, ka)) = nonlinearity_of(&x, &y, rest_reference) {
            if ka <= limit {
                return LinearRange { limit, max_rate_dps: Some(r), nonlinearity: Some(ka), points: x.len() };
            }
        }
    }
    LinearRange { limit, max_rate_dps: None, nonlinearity: None, points: 0 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn obs(rate: f64, run: u32, stroke: Stroke, output: f64) -> RateObservation {
        RateObservation { rate_dps: rate, run, stroke, output }
    }

    /// A small record worked by hand: rates -10, 0, 10; two runs.
    /// fwd run1: 0.9, 2.0, 3.1   rev run1: 1.0, 2.2, 3.0
    /// fwd run2: 1.1, 2.0, 2.9   rev run2: 1.0, 2.0, 3.0
    fn hand_table() -> RateTable {
        use Stroke::*;
        let v = [
            obs(-10.0, 1, Forward, 0.9),
            obs(0.0, 1, Forward, 2.0),
            obs(10.0, 1, Forward, 3.1),
            obs(-10.0, 1, Reverse, 1.0),
            obs(0.0, 1, Reverse, 2.2),
            obs(10.0, 1, Reverse, 3.0),
            obs(-10.0, 2, Forward, 1.1),
            obs(0.0, 2, Forward, 2.0),
            obs(10.0, 2, Forward, 2.9),
            obs(-10.0, 2, Reverse, 1.0),
            obs(0.0, 2, Reverse, 2.0),
            obs(10.0, 2, Reverse, 3.0),
        ];
        RateTable::from_observations(&v, None).unwrap()
    }

    #[test]
    fn hand_checked_small_case() {
        let e = evaluate(&hand_table(), &RateTestOptions::default()).unwrap();
        // Stroke means: fwd = 1.0, 2.0, 3.0; rev = 1.0, 2.1, 3.0; means = 1.0, 2.05, 3.0.
        let p = &e.points;
        assert_relative_eq!(p[1].forward_mean, 2.0, epsilon = 1e-12);
        assert_relative_eq!(p[1].reverse_mean, 2.1, epsilon = 1e-12);
        assert_relative_eq!(p[1].mean, 2.05, epsilon = 1e-12);
        // Line through (-10, 1), (0, 2.05), (10, 3): K = 2/20 = 0.1, F0 = 6.05/3.
        assert_relative_eq!(e.scale_factor(), 0.1, epsilon = 1e-12);
        assert_relative_eq!(e.zero_offset(), 6.05 / 3.0, epsilon = 1e-12);
        // Residuals: 1 - (F0 - 1) = 2 - F0 = -0.01667; 2.05 - F0 = 0.03333; -0.01667.
        let f0 = 6.05 / 3.0;
        assert_relative_eq!(p[1].line_residual, 2.05 - f0, epsilon = 1e-12);
        // Y_FS = 0.1 * 20 = 2; linearity = 0.0333.../2.
        assert_relative_eq!(e.full_scale_output, 2.0, epsilon = 1e-12);
        assert_relative_eq!(e.linearity, (2.05 - f0) / 2.0, epsilon = 1e-12);
        // F_r = mean at 0 deg/s = 2.05; F_m = max |y - F_r| = 1.05; K_a = (2.05 - f0)/1.05.
        assert_eq!(e.rest_reference_source, RestReferenceSource::ZeroRatePoint);
        assert_relative_eq!(e.rest_reference, 2.05, epsilon = 1e-12);
        assert_relative_eq!(e.output_amplitude, 1.05, epsilon = 1e-12);
        assert_relative_eq!(e.nonlinearity, (2.05 - f0) / 1.05, epsilon = 1e-12);
        // Hysteresis: max |fwd - rev| = 0.1 -> 0.05.
        assert_relative_eq!(e.hysteresis, 0.05, epsilon = 1e-12);
        // Repeatability: stds across runs: fwd -10: (0.9, 1.1) -> 0.141421; fwd 10: same;
        // rev 0: (2.2, 2.0) -> 0.141421; sigma_max = sqrt(0.02); 3 * 0.141421 / 2.
        assert_relative_eq!(e.repeatability_sigma_max.unwrap(), 0.02f64.sqrt(), epsilon = 1e-12);
        assert_relative_eq!(e.repeatability.unwrap(), 3.0 * 0.02f64.sqrt() / 2.0, epsilon = 1e-12);
        let (l, h, r) = (e.linearity, e.hysteresis, e.repeatability.unwrap());
        assert_relative_eq!(e.accuracy_sum.unwrap(), l + h + r, epsilon = 1e-15);
        assert_relative_eq!(e.accuracy_rss.unwrap(), (l * l + h * h + r * r).sqrt(), epsilon = 1e-15);
        // Asymmetry: K+ from (0, 2.05), (10, 3) = 0.095; K- from (-10, 1), (0, 2.05) = 0.105.
        let a = e.asymmetry.unwrap();
        assert_relative_eq!(a.positive_scale_factor, 0.095, epsilon = 1e-12);
        assert_relative_eq!(a.negative_scale_factor, 0.105, epsilon = 1e-12);
        assert_relative_eq!(a.asymmetry, 0.01 / 0.1, epsilon = 1e-12);
        // Per-run K: run 1 points (-10: 0.9, 1.0), (0: 2.0, 2.2), (10: 3.1, 3.0):
        // sum w*y = -10*1.9 + 10*6.1 = 42, sum w^2 = 400 -> 0.105.
        // run 2: (-10: 1.1, 1.0), (10: 2.9, 3.0): (-21 + 59)/400 = 0.095.
        let s = e.scale_factor_repeatability.unwrap();
        assert_relative_eq!(s.per_run[0].1, 0.105, epsilon = 1e-12);
        assert_relative_eq!(s.per_run[1].1, 0.095, epsilon = 1e-12);
        assert_relative_eq!(s.repeatability, 0.01f64 / 2f64.sqrt() / 0.1, epsilon = 1e-12);
    }

    #[test]
    fn coverage_two_and_half_hysteresis() {
        let o = RateTestOptions { coverage: 2.0, half_hysteresis: true, ..Default::default() };
        let e = evaluate(&hand_table(), &o).unwrap();
        assert_relative_eq!(e.repeatability.unwrap(), 2.0 * 0.02f64.sqrt() / 2.0, epsilon = 1e-12);
        assert_relative_eq!(e.hysteresis, 0.025, epsilon = 1e-12);
    }

    #[test]
    fn samples_in_a_cell_are_averaged() {
        use Stroke::*;
        let v = [
            obs(-1.0, 1, Forward, 1.0),
            obs(-1.0, 1, Forward, 3.0),
            obs(1.0, 1, Forward, 4.0),
            obs(-1.0, 1, Reverse, 2.0),
            obs(1.0, 1, Reverse, 4.0),
        ];
        let t = RateTable::from_observations(&v, None).unwrap();
        assert_eq!(t.forward[0][0], 2.0);
        assert_eq!(t.forward_samples[0][0], 2);
        let e = evaluate(&t, &RateTestOptions::default()).unwrap();
        assert!(e.repeatability.is_none());
        assert!(e.scale_factor_repeatability.is_none());
        assert_eq!(e.rest_reference_source, RestReferenceSource::FitZeroOffset);
    }

    #[test]
    fn rest_records_set_the_reference() {
        let mut t = hand_table();
        t.rest = Some(RestRecord { start: 2.0, end: 2.2 });
        let e = evaluate(&t, &RateTestOptions::default()).unwrap();
        assert_eq!(e.rest_reference_source, RestReferenceSource::RestRecords);
        assert_relative_eq!(e.rest_reference, 2.1, epsilon = 1e-12);
        assert_relative_eq!(e.output_amplitude, 1.1, epsilon = 1e-12);
    }

    #[test]
    fn grid_errors() {
        use Stroke::*;
        assert_eq!(RateTable::from_observations(&[], None), Err(RateTestError::Empty));
        let one_rate = [obs(5.0, 1, Forward, 1.0), obs(5.0, 1, Reverse, 1.0)];
        assert_eq!(RateTable::from_observations(&one_rate, None), Err(RateTestError::TooFewRates(1)));
        let missing = [obs(5.0, 1, Forward, 1.0), obs(6.0, 1, Forward, 1.0), obs(5.0, 1, Reverse, 1.0)];
        assert!(matches!(
            RateTable::from_observations(&missing, None),
            Err(RateTestError::MissingCell { run: 1, stroke: Reverse, .. })
        ));
        let nan = [obs(5.0, 1, Forward, f64::NAN)];
        assert!(matches!(RateTable::from_observations(&nan, None), Err(RateTestError::NonFinite { .. })));
    }

    #[test]
    fn exact_line_has_zero_nonlinearity() {
        let mut v = Vec::new();
        for run in 1..=3 {
            for &w in &[-300.0, -100.0, 0.0, 50.0, 200.0, 300.0] {
                for s in [Stroke::Forward, Stroke::Reverse] {
                    v.push(obs(w, run, s, 2.5 + 0.0075 * w));
                }
            }
        }
        let t = RateTable::from_observations(&v, None).unwrap();
        let e =
            evaluate(&t, &RateTestOptions { nonlinearity_limit: Some(1e-6), order: 2, ..Default::default() }).unwrap();
        assert!(e.nonlinearity < 1e-13, "{}", e.nonlinearity);
        assert!(e.linearity < 1e-13);
        assert!(e.hysteresis < 1e-13);
        assert!(e.repeatability.unwrap() < 1e-13);
        assert!(e.asymmetry.unwrap().asymmetry < 1e-12);
        assert_relative_eq!(e.scale_factor(), 0.0075, max_relative = 1e-12);
        assert_relative_eq!(e.zero_offset(), 2.5, max_relative = 1e-12);
        assert_eq!(e.linear_range.unwrap().max_rate_dps, Some(300.0));
        assert!(e.polynomial.coefficients[2].abs() < 1e-15);
    }

    #[test]
    fn stroke_labels() {
        for l in ["fwd", "Forward", "+", "up", "正", "正行程"] {
            assert_eq!(Stroke::from_label(l), Some(Stroke::Forward), "{l}");
        }
        for l in ["rev", "REVERSE", "-", "down", "反"] {
            assert_eq!(Stroke::from_label(l), Some(Stroke::Reverse), "{l}");
        }
        assert_eq!(Stroke::from_label("sideways"), None);
    }

    mod properties {
        use super::*;
        use proptest::prelude::*;

        fn table_from(outputs: &[f64], rates: &[f64], runs: u32) -> RateTable {
            let mut v = Vec::new();
            let mut i = 0;
            for run in 1..=runs {
                for s in [Stroke::Forward, Stroke::Reverse] {
                    for &w in rates {
                        v.push(obs(w, run, s, outputs[i % outputs.len()] + 0.007 * w));
                        i += 1;
                    }
                }
            }
            RateTable::from_observations(&v, None).unwrap()
        }

        proptest! {
            #[test]
            fn scale_factor_scales_with_output_unit(noise in prop::collection::vec(-0.05f64..0.05, 24), factor in 0.001f64..1000.0) {
                let rates = [-200.0, -50.0, 0.0, 60.0, 200.0, 250.0];
                let t = table_from(&noise, &rates, 2);
                let a = evaluate(&t, &RateTestOptions::default()).unwrap();
                let b = evaluate(&t.scaled(factor), &RateTestOptions::default()).unwrap();
                prop_assert!((b.scale_factor() / a.scale_factor() - factor).abs() <= 1e-9 * factor);
                prop_assert!((b.nonlinearity - a.nonlinearity).abs() <= 1e-9);
                prop_assert!((b.linearity - a.linearity).abs() <= 1e-9);
            }

            #[test]
            fn constant_offset_moves_only_f0_and_fr(noise in prop::collection::vec(-0.05f64..0.05, 24), offset in -10.0f64..10.0) {
                let rates = [-200.0, -50.0, 0.0, 60.0, 200.0, 250.0];
                let t = table_from(&noise, &rates, 2);
                let mut u = t.clone();
                for row in u.forward.iter_mut().chain(u.reverse.iter_mut()) {
                    row.iter_mut().for_each(|v| *v += offset);
                }
                let a = evaluate(&t, &RateTestOptions::default()).unwrap();
                let b = evaluate(&u, &RateTestOptions::default()).unwrap();
                prop_assert!((b.zero_offset() - a.zero_offset() - offset).abs() < 1e-9);
                prop_assert!((b.rest_reference - a.rest_reference - offset).abs() < 1e-9);
                prop_assert!((b.scale_factor() - a.scale_factor()).abs() < 1e-12);
                prop_assert!((b.nonlinearity - a.nonlinearity).abs() < 1e-9);
                prop_assert!((b.linearity - a.linearity).abs() < 1e-9);
                prop_assert!((b.hysteresis - a.hysteresis).abs() < 1e-9);
                prop_assert!((b.repeatability.unwrap() - a.repeatability.unwrap()).abs() < 1e-9);
            }

            #[test]
            fn swapping_strokes_leaves_linearity(noise in prop::collection::vec(-0.05f64..0.05, 24)) {
                let rates = [-200.0, -50.0, 0.0, 60.0, 200.0, 250.0];
                let t = table_from(&noise, &rates, 2);
                let mut u = t.clone();
                std::mem::swap(&mut u.forward, &mut u.reverse);
                let a = evaluate(&t, &RateTestOptions::default()).unwrap();
                let b = evaluate(&u, &RateTestOptions::default()).unwrap();
                prop_assert!((b.linearity - a.linearity).abs() < 1e-12);
                prop_assert!((b.hysteresis - a.hysteresis).abs() < 1e-12);
                prop_assert!((b.nonlinearity - a.nonlinearity).abs() < 1e-12);
            }
        }
    }
}
