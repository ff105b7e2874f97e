//! Warm-up (turn-on) behaviour of the bias from a static record that starts at power-on:
//! turn-on bias, bias settling time to a stated band, and an exponential settling model.
//!
//! Sources: IEEE Std 952-1997 and IEEE Std 1431-2004 (turn-on bias, warm-up time: the time from
//! power-on until the output meets its specification), GJB 2426A-2004 (warm-up time, 准备时间).
//! The standards name the figures but leave the estimator to the test procedure; ours (docs/
//! METHODS.md, "Warm-up"):
//! - window means m_k of consecutive `window_s`-second windows from power-on (t = 0);
//! - turn-on bias B_on = m_0, the first window's mean;
//! - final bias B_f = mean of the samples in the last `final_fraction` of the record;
//! - settling time T_s = start of the first window from which every later window mean lies
//!   within B_f +- band (0 when the record is settled from the start; none when even the last
//!   windows leave the band);
//! - model B(t) = B_inf + A exp(-t / tau), least squares on the window means (at their centre
//!   times): for each tau the model is linear in (B_inf, A); tau minimises the residual sum of
//!   squares (a log grid, then golden-section refinement). The model's settling time is
//!   tau ln(|A| / band) when |A| > band.

/// Options of the warm-up evaluation.
#[derive(Debug, Clone, PartialEq)]
pub struct WarmupConfig {
    /// Settling band +-, same unit as the bias (deg/h).
    pub band: f64,
    /// Window of the window means, s.
    pub window_s: f64,
    /// Fraction of the record (at its end) whose mean is the final bias, in (0, 1).
    pub final_fraction: f64,
}

impl WarmupConfig {
    /// A band with 10-s windows and the last 20 % of the record as the final bias.
    pub fn new(band: f64) -> Self {
        WarmupConfig { band, window_s: 10.0, final_fraction: 0.2 }
    }
}

/// The exponential settling model B(t) = B_inf + A exp(-t / tau).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SettlingModel {
    /// Settled bias B_inf.
    pub settled: f64,
    /// Amplitude A at power-on.
    pub amplitude: f64,
    /// Time constant tau, s.
    pub time_constant_s: f64,
    /// RMS residual of the window means about the model.
    pub rms_residual: f64,
    /// The model's time to enter the band, tau ln(|A| / band), s (0 when |A| <= band).
    pub settling_time_s: f64,
}

/// Why the model has no value.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModelSupport {
    /// Resolved.
    Resolved,
    /// The best time constant lies at the edge of the searched range (shorter than half a
    /// window, or longer than twice the record): the record does not show the transient.
    TimeConstantAtEdge,
    /// The amplitude is below three of its standard errors: no transient above the noise.
    AmplitudeBelowNoise,
    /// Fewer than four windows.
    TooFewWindows,
}

/// The warm-up figures of one record.
#[derive(Debug, Clone, PartialEq)]
pub struct WarmupResult {
    /// Turn-on bias B_on (the first window's mean).
    pub turn_on: f64,
    /// Final bias B_f.
    pub final_bias: f64,
    /// Settling time T_s, s; `None` when the window means never stay inside the band.
    pub settling_time_s: Option<f64>,
    /// Standard deviation (n - 1) of the window means of the final part: the noise the band
    /// must exceed for a settling time to exist (0 with fewer than two windows there).
    pub final_scatter: f64,
    /// The settling model, when resolved.
    pub model: Option<SettlingModel>,
    /// Whether the model is resolved, or why not.
    pub model_support: ModelSupport,
    /// (centre time s, mean) of every window.
    pub windows: Vec<(f64, f64)>,
    /// The options used.
    pub config: WarmupConfig,
}

/// Errors of the warm-up evaluation.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum WarmupError {
    /// Bad options.
    #[error("{0}")]
    Options(String),
    /// The record is too short for two windows and a final portion.
    #[error("the record ({duration_s} s) is too short: the warm-up needs at least 3 windows of {window_s} s")]
    TooShort {
        /// Record length, s.
        duration_s: f64,
        /// Window, s.
        window_s: f64,
    },
    /// The record does not start at power-on (its first stamp is far from 0).
    #[error("the record starts at t = {first_s} s, not at power-on (t = 0): a warm-up record must start when the gyro is switched on (times from power-on)")]
    NotFromPowerOn {
        /// First time stamp, s.
        first_s: f64,
    },
    /// A sample is not a finite number.
    #[error("sample {index} is not a finite number")]
    NonFinite {
        /// Its index.
        index: usize,
    },
}

/// Evaluates the warm-up of bias samples `bias` at times `t_s` (seconds from power-on,
/// increasing; the first stamp must lie within one window of 0).
pub fn evaluate_warmup(t_s: &[f64], bias: &[f64], config: &WarmupConfig) -> Result<WarmupResult, WarmupError> {
    let c = config;
    if !(c.band.is_finite() && c.band > 0.0) {
        return Err(WarmupError::Options(format!("band {}: expected a positive number", c.band)));
    }
    if !(c.window_s.is_finite() && c.window_s > 0.0) {
        return Err(WarmupError::Options(format!("window {} s: expected a positive number", c.window_s)));
    }
    if !(c.final_fraction > 0.0 && c.final_fraction < 1.0) {
        return Err(WarmupError::Options(format!("final fraction {}: expected a number in (0, 1)", c.final_fraction)));
    }
    if t_s.len() != bias.len() || t_s.is_empty() {
        return Err(WarmupError::Options("times and samples of different lengths, or none".into()));
    }
    if let Some(index) = bias.iter().chain(t_s).position(|v| !v.is_finite()) {
        return Err(WarmupError::NonFinite { index: index % bias.len() });
    }
    let first = t_s[0];
    if first.abs() > c.window_s {
        return Err(WarmupError::NotFromPowerOn { first_s: first });
    }
    let duration = t_s[t_s.len() - 1];
    if duration < 3.0 * c.window_s {
        return Err(WarmupError::TooShort { duration_s: duration, window_s: c.window_s });
    }
    // Window means from t = 0 (complete windows only).
    let mut windows = Vec::new();
    let (mut sum, mut n, mut k) = (0.0, 0usize, 0usize);
    for (&t, &b) in t_s.iter().zip(bias) {
        let w = (t.max(0.0) / c.window_s).floor() as usize;
        if w != k {
            if n > 0 {
                windows.push(((k as f64 + 0.5) * c.window_s, sum / n as f64));
            }
            (sum, n, k) = (0.0, 0, w);
        }
        sum += b;
        n += 1;
    }
    // The last, incomplete window is left out.
    let final_from = duration * (1.0 - c.final_fraction);
    let (fs, fnum) =
        t_s.iter().zip(bias).filter(|(&t, _)| t >= final_from).fold((0.0, 0usize), |a, (_, &b)| (a.0 + b, a.1 + 1));
    let final_bias = fs / fnum.max(1) as f64;
    let turn_on = windows[0].1;
    // Settling: the first window from which all later ones stay in the band.
    let inside: Vec<bool> = windows.iter().map(|&(_, m)| (m - final_bias).abs() <= c.band).collect();
    let settling_time_s = match inside.iter().rposition(|&x| !x) {
        None => Some(0.0),
        Some(last_out) if last_out + 1 < windows.len() => Some((last_out + 1) as f64 * c.window_s),
        Some(_) => None,
    };
    let tail: Vec<f64> = windows.iter().filter(|(t, _)| *t >= final_from).map(|&(_, m)| m).collect();
    let final_scatter = if tail.len() >= 2 {
        let mean = tail.iter().sum::<f64>() / tail.len() as f64;
        (tail.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / (tail.len() - 1) as f64).sqrt()
    } else {
        0.0
    };
    let (model, model_support) = fit_model(&windows, duration, c);
    Ok(WarmupResult {
        turn_on,
        final_bias,
        settling_time_s,
        final_scatter,
        model,
        model_support,
        windows,
        config: c.clone(),
    })
}

/// Least squares of (B_inf, A) for a fixed tau: the residual sum of squares and the pair.
fn linear_fit(w: &[(f64, f64)], tau: f64) -> (f64, f64, f64) {
    let n = w.len() as f64;
    let (mut sx, mut sy, mut sxx, mut sxy) = (0.0, 0.0, 0.0, 0.0);
    for &(t, m) in w {
        let x = (-t / tau).exp();
        sx += x;
        sy += m;
        sxx += x * x;
        sxy += x * m;
    }
    let det = n * sxx - sx * sx;
    if det.abs() <= f64::EPSILON * n * sxx {
        let b = sy / n;
        return (w.iter().map(|&(_, m)| (m - b).powi(2)).sum(), b, 0.0);
    }
    let a = (n * sxy - sx * sy) / det;
    let b = (sy - a * sx) / n;
    let rss = w.iter().map(|&(t, m)| (m - b - a * (-t / tau).exp()).powi(2)).sum();
    (rss, b, a)
}

fn fit_model(w: &[(f64, f64)], duration: f64, c: &WarmupConfig) -> (Option<SettlingModel>, ModelSupport) {
    if w.len() < 4 {
        return (None, ModelSupport::TooFewWindows);
    }
    let (lo, hi) = ((c.window_s / 2.0).ln(), (2.0 * duration).ln());
    let steps = 200;
    let at = |k: usize| lo + (hi - lo) * k as f64 / steps as f64;
    let rss = |ln_tau: f64| linear_fit(w, ln_tau.exp()).0;
    let best = (0..=steps).min_by(|&a, &b| rss(at(a)).total_cmp(&rss(at(b)))).unwrap_or(0);
    if best == 0 || best == steps {
        return (None, ModelSupport::TimeConstantAtEdge);
    }
    // Golden-section refinement on ln tau between the grid neighbours.
    let (mut a, mut b) = (at(best - 1), at(best + 1));
    let g = (5f64.sqrt() - 1.0) / 2.0;
    for _ in 0..100 {
        let (x1, x2) = (b - g * (b - a), a + g * (b - a));
        if rss(x1) < rss(x2) {
            b = x2;
        } else {
            a = x1;
        }
    }
    let tau = ((a + b) / 2.0).exp();
    let (r, settled, amplitude) = linear_fit(w, tau);
    let n = w.len() as f64;
    let rms = (r / n).sqrt();
    // Standard error of A at this tau (straight-line regression on x = exp(-t / tau)):
    // var(A) = s^2 / sum (x - mean x)^2, s^2 = RSS / (n - 2).
    let xs: Vec<f64> = w.iter().map(|&(t, _)| (-t / tau).exp()).collect();
    let xm = xs.iter().sum::<f64>() / n;
    let sxx: f64 = xs.iter().map(|x| (x - xm).powi(2)).sum();
    let se_a = (r / (n - 2.0) / sxx).sqrt();
    // (A NaN standard error, from a perfect fit of too few distinct x, also fails the test.)
    if amplitude.abs() < 3.0 * se_a || se_a.is_nan() {
        return (None, ModelSupport::AmplitudeBelowNoise);
    }
    let settling_time_s = if amplitude.abs() > c.band { tau * (amplitude.abs() / c.band).ln() } else { 0.0 };
    (
        Some(SettlingModel { settled, amplitude, time_constant_s: tau, rms_residual: rms, settling_time_s }),
        ModelSupport::Resolved,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A noiseless exponential: the model returns its parameters, and the settling time is the
    /// start of the first window whose mean (computed here in closed form) is inside the band.
    #[test]
    fn a_noiseless_exponential_is_recovered_and_its_settling_time_worked_by_hand() {
        let (b_inf, a, tau, fs) = (12.0, 300.0, 45.0, 10.0);
        let n = (1200.0 * fs) as usize;
        let t: Vec<f64> = (0..n).map(|i| i as f64 / fs).collect();
        let y: Vec<f64> = t.iter().map(|&t| b_inf + a * (-t / tau).exp()).collect();
        let r = evaluate_warmup(&t, &y, &WarmupConfig::new(5.0)).unwrap();
        let m = r.model.unwrap();
        assert!((m.time_constant_s / tau - 1.0).abs() < 1e-3, "{m:?}");
        assert!((m.amplitude / a - 1.0).abs() < 2e-2 && (m.settled - b_inf).abs() < 1e-2, "{m:?}");
        // Window k's mean: b_inf + a tau/(W fs) sum over its samples... by samples: the mean of
        // a exp(-i/(fs tau)) over i in [k W fs, (k+1) W fs) is a geometric series.
        let q = (-1.0 / (fs * tau)).exp();
        let per = (10.0 * fs) as i32;
        let window_mean = |k: i32| b_inf + a * q.powi(k * per) * (1.0 - q.powi(per)) / (per as f64 * (1.0 - q));
        // The final bias: the mean of the last 20 % (exp is ~1e-3 of a there).
        let final_bias = r.final_bias;
        let first_in = (0..120).find(|&k| (window_mean(k) - final_bias).abs() <= 5.0).unwrap();
        assert_eq!(r.settling_time_s, Some(first_in as f64 * 10.0));
        assert!((r.turn_on - window_mean(0)).abs() < 1e-9);
        // The model's own settling time: tau ln(A / band).
        assert!((m.settling_time_s - tau * (a / 5.0f64).ln()).abs() < 0.5);
    }

    #[test]
    fn no_transient_and_bad_records_are_said_so() {
        // White noise (a xorshift generator, sums of 12 uniforms) around a constant bias.
        let mut s = 0x9E3779B97F4A7C15u64;
        let mut uniform = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let t: Vec<f64> = (0..3000).map(|i| i as f64 * 0.1).collect();
        let y: Vec<f64> = (0..3000).map(|_| 20.0 + (0..12).map(|_| uniform()).sum::<f64>() - 6.0).collect();
        let r = evaluate_warmup(&t, &y, &WarmupConfig::new(5.0)).unwrap();
        assert_eq!(r.settling_time_s, Some(0.0));
        assert!(r.model.is_none() && r.model_support != ModelSupport::Resolved, "{:?}", r.model_support);
        let late: Vec<f64> = t.iter().map(|x| x + 100.0).collect();
        assert!(matches!(evaluate_warmup(&late, &y, &WarmupConfig::new(5.0)), Err(WarmupError::NotFromPowerOn { .. })));
        assert!(matches!(
            evaluate_warmup(&t[..200], &y[..200], &WarmupConfig::new(5.0)),
            Err(WarmupError::TooShort { .. })
        ));
        assert!(evaluate_warmup(&t, &y, &WarmupConfig::new(0.0)).is_err());
    }
}
