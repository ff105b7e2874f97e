//! Bias instability (flicker rate noise) approximated by a sum of first-order Gauss-Markov
//! processes.
//!
//! Sources: IEEE Std 952-1997 annex C (bias instability B: flat Allan deviation sqrt(2 ln 2 / pi) B
//! = 0.6643 B); Gauss-Markov process and its exact discretisation from Brown & Hwang,
//! *Introduction to Random Signals and Applied Kalman Filtering* (4th ed., section 2.9 and 3.9);
//! Allan variance of a Gauss-Markov process from IEEE Std 952-1997 annex C
//! (sigma^2(tau) = (2 s^2 T / tau) [1 - (T / 2 tau)(3 - 4 e^(-tau/T) + e^(-2 tau/T))]).
//!
//! Design: correlation times T_i = tau_min / 10 * 10^i (one per decade), i = 0, 1, ... until
//! T_i >= 3 tau_max; all processes get the same stationary variance s^2 (a log-uniform mixture of
//! Lorentzian spectra is a 1/f spectrum). s^2 is set so that the continuous-time Allan deviation of
//! the sum is centred on 0.6643 B over [tau_min, tau_max] (geometric mean of its extremes). The
//! design ripple is about +-1.6 % for any range; point sampling adds up to +2 % at tau = 10 dt when
//! tau_min is the shortest allowed (10 sample intervals). The stated band is [`FLICKER_BAND`].
//!
//! Held updates: a process whose correlation time spans many samples barely moves from one sample
//! to the next, so it is advanced only every k_i = max(1, floor(T_i / (30 dt))) samples, by its
//! exact k_i-step transition x <- phi^k x + s sqrt(1 - phi^(2k)) z, and held in between
//! ([`FlickerDesign::hold_samples`]). At each update the process has exactly the distribution of
//! the per-sample recursion; in between it is constant. Effect on the Allan deviation of the sum
//! (computed exactly from the autocovariance, [`FlickerDesign::sampled_allan_variance`], and
//! tested): below 0.03 % for tau in [tau_min, tau_max], below 1 % down to tau = one sample. It
//! saves all but about 1 / 30 of the flicker draws when T_1 spans 30 or more samples.

use super::portable;

/// Ratio of the flat Allan deviation of flicker rate noise to the bias instability B:
/// sqrt(2 ln 2 / pi) (IEEE Std 952-1997 annex C).
pub const FLICKER_ADEV_FACTOR: f64 = 0.664_282_470_267_960_1;

/// Stated band: the simulated Allan deviation lies within +-3 % of 0.6643 B for tau in
/// [tau_min, tau_max] (design ripple +-1.6 % plus the point-sampling effect).
pub const FLICKER_BAND: f64 = 0.03;

/// The shortest allowed `flicker_tau_min_s`, in sample intervals (the shortest correlation time
/// is then one sample interval).
pub const FLICKER_MIN_TAU_SAMPLES: f64 = 10.0;

/// Updates per correlation time at least, for a process that is held between updates.
pub const FLICKER_UPDATES_PER_CORRELATION_TIME: f64 = 30.0;

/// Shortest correlation time relative to tau_min.
const T_LOW_OVER_TAU_MIN: f64 = 0.1;
/// Longest correlation time relative to tau_max (at least).
const T_HIGH_OVER_TAU_MAX: f64 = 3.0;
/// Grid points per decade used to centre the design.
const GRID_PER_DECADE: f64 = 20.0;

/// The Gauss-Markov sum that approximates flicker rate noise of a given bias instability.
#[derive(Debug, Clone, PartialEq)]
pub struct FlickerDesign {
    /// Bias instability B, deg/s.
    pub bias_instability_dps: f64,
    /// Lower end of the tau range over which the Allan deviation is flat, s.
    pub tau_min_s: f64,
    /// Upper end of the tau range, s.
    pub tau_max_s: f64,
    /// Correlation times T_i of the Gauss-Markov processes, s (log-spaced, one per decade).
    pub correlation_times_s: Vec<f64>,
    /// Stationary standard deviation s of each process, deg/s (the same for all).
    pub sigma_each_dps: f64,
    /// Largest relative deviation of the continuous-time model Allan deviation from 0.6643 B
    /// over [tau_min, tau_max] (design ripple, without the sampling effect).
    pub design_ripple: f64,
}

/// Allan variance of a continuous first-order Gauss-Markov process of stationary variance s2 and
/// correlation time t_s, at averaging time tau_s (IEEE Std 952-1997 annex C).
fn gauss_markov_avar(tau_s: f64, t_s: f64, s2: f64) -> f64 {
    let x = tau_s / t_s;
    let bracket = if x < 1e-3 {
        // Series for small x (avoids cancellation): 1 - (3 - 4e^-x + e^-2x) / 2x
        // = x^2/3 - x^3/4 + 7x^4/60 + O(x^5).
        x * x * (1.0 / 3.0 - x * (0.25 - x * 7.0 / 60.0))
    } else {
        1.0 - (3.0 - 4.0 * portable::exp(-x) + portable::exp(-2.0 * x)) / (2.0 * x)
    };
    2.0 * s2 * t_s / tau_s * bracket
}

impl FlickerDesign {
    /// Designs the sum for bias instability B (deg/s) flat over [tau_min_s, tau_max_s]; the
    /// caller has validated 0 < tau_min_s < tau_max_s (finite) and B >= 0.
    pub fn new(bias_instability_dps: f64, tau_min_s: f64, tau_max_s: f64) -> FlickerDesign {
        let mut times = vec![tau_min_s * T_LOW_OVER_TAU_MIN];
        let t_high = tau_max_s * T_HIGH_OVER_TAU_MAX;
        let mut t = times[0];
        while t < t_high * (1.0 - 1e-12) {
            t *= 10.0;
            times.push(t);
        }
        // Log grid over [tau_min, tau_max]: ratio 10^(1/20) from the portable exp.
        let ratio = portable::exp(std::f64::consts::LN_10 / GRID_PER_DECADE);
        let (mut lo, mut hi) = (f64::INFINITY, 0.0_f64);
        let mut tau = tau_min_s;
        loop {
            let tau_now = tau.min(tau_max_s);
            let avar: f64 = times.iter().map(|&ti| gauss_markov_avar(tau_now, ti, 1.0)).sum();
            lo = lo.min(avar);
            hi = hi.max(avar);
            if tau >= tau_max_s {
                break;
            }
            tau *= ratio;
        }
        // Unit-variance processes give Allan variance in [lo, hi]; scale to centre on the target.
        let target_avar = (FLICKER_ADEV_FACTOR * bias_instability_dps) * (FLICKER_ADEV_FACTOR * bias_instability_dps);
        let centre = (lo * hi).sqrt();
        let s2 = target_avar / centre;
        let design_ripple = (hi / lo).sqrt().sqrt() - 1.0;
        FlickerDesign {
            bias_instability_dps,
            tau_min_s,
            tau_max_s,
            correlation_times_s: times,
            sigma_each_dps: s2.sqrt(),
            design_ripple,
        }
    }

    /// Allan deviation (deg/s) of the continuous-time model at tau_s.
    pub fn model_allan_deviation_dps(&self, tau_s: f64) -> f64 {
        let s2 = self.sigma_each_dps * self.sigma_each_dps;
        self.correlation_times_s.iter().map(|&t| gauss_markov_avar(tau_s, t, s2)).sum::<f64>().sqrt()
    }

    /// Standard deviation (deg/s) of the sum of all processes (the wander of the bias).
    pub fn total_sigma_dps(&self) -> f64 {
        self.sigma_each_dps * (self.correlation_times_s.len() as f64).sqrt()
    }

    /// Samples each process is held between its updates at sample interval `dt_s`:
    /// k_i = max(1, floor(T_i / (30 dt))), so that every correlation time spans at least 30 updates.
    pub fn hold_samples(&self, dt_s: f64) -> Vec<u64> {
        self.correlation_times_s
            .iter()
            .map(|&t| {
                let k = (t / (FLICKER_UPDATES_PER_CORRELATION_TIME * dt_s)).floor();
                // Saturating conversion: a hold longer than any record keeps its first value.
                (k as u64).max(1)
            })
            .collect()
    }

    /// Allan variance ((deg/s)^2) at tau = m dt of the sampled sum (each process a per-sample
    /// recursion when `held` is false, held for `hold_samples(dt_s)` samples when true), exact
    /// from the autocovariance: sigma^2 = (Var(S) - Cov(S_1, S_2)) / m^2 for sums S of m
    /// consecutive samples. A held process, averaged over its update phase, has autocovariance
    /// R(qk + r) = s^2 [(k - r)/k phi^(kq) + r/k phi^(k(q+1))]. O(m) per process; m >= 1 (m = 0
    /// has no Allan variance and gives NaN).
    pub fn sampled_allan_variance(&self, dt_s: f64, m: u64, held: bool) -> f64 {
        let s2 = self.sigma_each_dps * self.sigma_each_dps;
        let holds = self.hold_samples(dt_s);
        let m_f = m as f64;
        let mut total = 0.0;
        for (&t, &hold) in self.correlation_times_s.iter().zip(&holds) {
            let k = if held { hold } else { 1 };
            let phi = (-dt_s / t).exp();
            let autocovariance = |lag: u64| {
                let (q, r) = (lag / k, lag % k);
                let (k_f, r_f) = (k as f64, r as f64);
                let near = phi.powf((k * q) as f64);
                s2 * ((k_f - r_f) / k_f * near + r_f / k_f * near * phi.powf(k_f))
            };
            // Var(S) = sum_{|j| < m} (m - |j|) R(j); Cov(S1, S2) = sum_{|j| < m} (m - |j|) R(m + j).
            let mut var_sum = m_f * autocovariance(0);
            let mut cov = m_f * autocovariance(m);
            for j in 1..m {
                let w = (m - j) as f64;
                var_sum += 2.0 * w * autocovariance(j);
                cov += w * (autocovariance(m + j) + autocovariance(m - j));
            }
            total += (var_sum - cov) / (m_f * m_f);
        }
        total
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn design_is_flat_within_band_over_its_range() {
        for &(a, b) in &[(1.0, 10.0), (1.0, 1000.0), (10.0, 10_000.0), (0.5, 2.0)] {
            let d = FlickerDesign::new(1.0, a, b);
            assert!(d.design_ripple < 0.02, "ripple {} for [{a}, {b}]", d.design_ripple);
            let mut tau = a;
            while tau <= b {
                let r = d.model_allan_deviation_dps(tau) / 0.6643;
                assert!((r - 1.0).abs() < FLICKER_BAND, "tau {tau}: ratio {r}");
                tau *= 1.3;
            }
        }
    }

    #[test]
    fn held_updates_change_the_allan_deviation_by_less_than_stated() {
        // T_1 from 1 to 300 samples: holds from 1 (no change) to 10 samples and more.
        for &(t1_samples, decades) in &[(1.0, 3.0), (10.0, 3.0), (100.0, 2.0), (300.0, 2.0)] {
            let dt = 0.01;
            let tau_min = 10.0 * t1_samples * dt;
            let d = FlickerDesign::new(1.0, tau_min, tau_min * 10f64.powf(decades));
            let holds = d.hold_samples(dt);
            assert_eq!(holds[0], ((t1_samples / FLICKER_UPDATES_PER_CORRELATION_TIME) as u64).max(1));
            assert!(holds
                .iter()
                .zip(&d.correlation_times_s)
                .all(|(&k, &t)| t / (k as f64 * dt) >= FLICKER_UPDATES_PER_CORRELATION_TIME || k == 1));
            let mut m = 1u64;
            while (m as f64) * dt <= d.tau_max_s {
                let held = d.sampled_allan_variance(dt, m, true).sqrt();
                let every = d.sampled_allan_variance(dt, m, false).sqrt();
                let change = (held / every - 1.0).abs();
                let tau = m as f64 * dt;
                let bound = if tau >= tau_min { 3e-4 } else { 1e-2 };
                assert!(change < bound, "T_1 {t1_samples} samples, tau {tau} s: change {change}");
                m = (m as f64 * 1.7).ceil() as u64;
            }
        }
    }

    #[test]
    fn sampled_allan_variance_approaches_the_continuous_model() {
        // Per-sample recursion, tau >> dt: the sampled sum has the continuous model's Allan deviation
        // up to the point-sampling effect (below 2 % at tau = 10 dt, shrinking with tau).
        let d = FlickerDesign::new(1.0, 1.0, 100.0);
        for &(m, tol) in &[(100u64, 0.02), (1000, 0.002), (10_000, 0.001)] {
            let sampled = d.sampled_allan_variance(0.01, m, false).sqrt();
            let model = d.model_allan_deviation_dps(m as f64 * 0.01);
            assert!((sampled / model - 1.0).abs() < tol, "m {m}: {sampled} vs {model}");
        }
    }

    #[test]
    fn gauss_markov_avar_limits() {
        // tau >> T: white noise of PSD 2 s^2 T -> sigma^2 = 2 s^2 T / tau (IEEE 952 annex C).
        let v = gauss_markov_avar(1e4, 1.0, 1.0);
        assert!((v / (2.0 / 1e4) - 1.0).abs() < 1e-3);
        // tau << T: rate random walk with q^2 = 2 s^2 / T -> sigma^2 = q^2 tau / 3.
        let v = gauss_markov_avar(1e-3, 1.0, 1.0);
        assert!((v / (2.0 * 1e-3 / 3.0) - 1.0).abs() < 1e-3);
    }
}
