//! The first-order Gauss-Markov process sampled every tau0 (a stationary AR(1) of autocovariance
//! R(k) = sigma^2 phi^|k|, phi = exp(-tau0 / T)): its Haar wavelet variance and its spectral
//! density per sample, for the GMWM (docs/METHODS.md 3.1, "GMWM").
//!
//! Sources: the Haar wavelet variance at averaging factor m is AVAR(m tau0) / 2 (D. B. Percival
//! and A. T. Walden, *Wavelet Methods for Time Series Analysis*, 2000, section 8.4); the Allan
//! variance of adjacent means of m samples of a stationary sequence is Var(ybar) - Cov(ybar_0,
//! ybar_1) (IEEE Std 952-1997, annex C, its definition), which for R(k) above sums in closed form
//! to
//!
//! AVAR(m tau0) = sigma^2 / m^2 [m (1 + phi) / (1 - phi) - (2 phi (1 - phi^m) + phi (1 - phi^m)^2) / (1 - phi)^2];
//!
//! where m u < 1e-2 (u = tau0 / T) the bracket cancels, and its Taylor series in u is used instead
//! (derived from the closed form; the neglected terms are below 1e-12 of the value there):
//!
//! ```text
//! u (2m^3/3 + m/3) - u^2 m^4/2 + u^3 (7m^5/30 - m^3/18 - m/90) - u^4 (m^6/12 - m^4/24)
//!   + u^5 (31 m^7/1260 - 7 m^5/360 + m^3/360 + m/2520)
//! ```
//!
//! At m = 1 the bracket is 1 - phi; for m tau0 >> T it tends to white noise of N^2 = 2 sigma^2 T,
//! for m tau0 << T to a random walk of K^2 = 2 sigma^2 / T, the limits of the continuous-time
//! process of IEEE Std 952-1997 annex C. The spectral density of the AR(1) per sample (f in
//! cycles per sample, integrating to sigma^2 over [-1/2, 1/2]) is sigma^2 (1 - phi^2) / (1 -
//! 2 phi cos(2 pi f) + phi^2), the standard AR(1) spectrum (tested by its integral).

/// The Haar wavelet variance nu^2 = AVAR(m tau0) / 2 of a unit-variance (sigma^2 = 1)
/// first-order Gauss-Markov process of correlation time `correlation_time_s`, sampled every
/// `tau0_s`, at averaging factor `m` (>= 1). NaN unless all three are finite and positive.
///
/// ```
/// use gyrolab::gmwm::gauss_markov_wavelet_variance;
/// // At m = 1 the Allan variance of a sampled AR(1) is 1 - phi, phi = exp(-tau0 / T).
/// let nu2 = gauss_markov_wavelet_variance(2.0, 0.5, 1.0);
/// assert!((nu2 - (1.0 - (-0.25f64).exp()) / 2.0).abs() < 1e-15);
/// ```
pub fn gauss_markov_wavelet_variance(correlation_time_s: f64, tau0_s: f64, m: f64) -> f64 {
    if !(correlation_time_s.is_finite() && correlation_time_s > 0.0 && tau0_s.is_finite() && tau0_s > 0.0 && m >= 1.0) {
        return f64::NAN;
    }
    let u = tau0_s / correlation_time_s;
    let bracket = if m * u < 1e-2 {
        let (m2, m3) = (m * m, m * m * m);
        let (m4, m5) = (m2 * m2, m2 * m3);
        let (m6, m7) = (m3 * m3, m3 * m4);
        let c1 = 2.0 * m3 / 3.0 + m / 3.0;
        let c2 = -m4 / 2.0;
        let c3 = 7.0 * m5 / 30.0 - m3 / 18.0 - m / 90.0;
        let c4 = -(m6 / 12.0 - m4 / 24.0);
        let c5 = 31.0 * m7 / 1260.0 - 7.0 * m5 / 360.0 + m3 / 360.0 + m / 2520.0;
        u * (c1 + u * (c2 + u * (c3 + u * (c4 + u * c5))))
    } else {
        let one_minus_phi = -(-u).exp_m1();
        let phi = 1.0 - one_minus_phi;
        let one_minus_phi_m = -(-u * m).exp_m1();
        m * (1.0 + phi) / one_minus_phi
            - (2.0 * phi * one_minus_phi_m + phi * one_minus_phi_m * one_minus_phi_m) / (one_minus_phi * one_minus_phi)
    };
    0.5 * bracket / (m * m)
}

/// The spectral density per sample of a unit-variance first-order Gauss-Markov process of
/// correlation time `correlation_time_s` sampled every `tau0_s`, at `f` cycles per sample:
/// (1 - phi^2) / (1 - 2 phi cos(2 pi f) + phi^2), phi = exp(-tau0 / T).
pub fn gauss_markov_spectral_density(correlation_time_s: f64, tau0_s: f64, f: f64) -> f64 {
    let u = tau0_s / correlation_time_s;
    let one_minus_phi = -(-u).exp_m1();
    let phi = 1.0 - one_minus_phi;
    // 1 - 2 phi cos(w) + phi^2 = (1 - phi)^2 + 4 phi sin^2(w / 2), without cancellation.
    let s = (std::f64::consts::PI * f).sin();
    one_minus_phi * (1.0 + phi) / (one_minus_phi * one_minus_phi + 4.0 * phi * s * s)
}

/// How a filter without Gauss-Markov states takes a Gauss-Markov process: as the white noise or
/// the random walk whose Allan variance lies on or above the process's at every tau, all three
/// sampled at the record's rate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MarkovBound {
    /// White rate noise of N^2 = sigma^2 tau0 (1 + phi) / (1 - phi) (the sampled process's
    /// long-tau limit; 2 sigma^2 T when T >> tau0).
    White {
        /// N^2, (curve unit)^2 s.
        n2: f64,
    },
    /// Random walk of K^2 = 2 sigma^2 / T (the process's short-tau limit).
    RandomWalk {
        /// K^2, (curve unit)^2 / s.
        k2: f64,
    },
}

/// h(x) = 1 - (3 - 4 e^-x + e^-2x) / (2x): the continuous-time process's Allan variance is
/// (2 sigma^2 T / tau) h(tau / T) (IEEE Std 952-1997 annex C); 0 < h < 1 and h <= x^2 / 3.
fn continuous_shape(x: f64) -> f64 {
    if x < 1e-3 {
        x * x * (1.0 / 3.0 - x * (0.25 - x * 7.0 / 60.0))
    } else {
        1.0 - (3.0 - 4.0 * (-x).exp() + (-2.0 * x).exp()) / (2.0 * x)
    }
}

/// The bound of a Gauss-Markov process (sigma, T) sampled every `tau0_s` that a filter without
/// its states can take over the taus `tau_min_s..tau_max_s` of a curve. Compared as sampled
/// processes (the filter's own noise is sampled at the same rate), both bound the process at
/// every tau: white noise of N^2 = sigma^2 tau0 (1 + phi) / (1 - phi), the sum of the process's
/// autocovariance (m AVAR(m tau0) rises to it), and the random walk K^2 = 2 sigma^2 / T, whose
/// sampled Allan variance u (2m^3/3 + m/3) sigma^2 / m^2 is the first term of the process's
/// alternating series (module doc). The one chosen is the tighter over the range, judged on the
/// continuous-time shape h: white noise exceeds the process most at tau_min, by 1 / h(tau_min /
/// T); the random walk at tau_max, by (x^2 / 3) / h(x), x = tau_max / T.
///
/// ```
/// use gyrolab::gmwm::{gauss_markov_filter_bound, MarkovBound};
/// // T = 1 s seen from 0.01 s to 1000 s by 100 Hz samples acts as white noise,
/// // N^2 = sigma^2 tau0 (1 + phi) / (1 - phi), about 2 sigma^2 T.
/// let MarkovBound::White { n2 } = gauss_markov_filter_bound(0.5, 1.0, 0.01, 0.01, 1000.0) else { panic!() };
/// let phi = (-0.01f64).exp();
/// assert!((n2 - 0.25 * 0.01 * (1.0 + phi) / (1.0 - phi)).abs() < 1e-12 * n2);
/// assert!((n2 / (2.0 * 0.25 * 1.0) - 1.0).abs() < 1e-4);
/// ```
pub fn gauss_markov_filter_bound(
    sigma: f64,
    correlation_time_s: f64,
    tau0_s: f64,
    tau_min_s: f64,
    tau_max_s: f64,
) -> MarkovBound {
    let (s2, t) = (sigma * sigma, correlation_time_s);
    let white_excess = 1.0 / continuous_shape(tau_min_s / t);
    let x = tau_max_s / t;
    let walk_excess = x * x / 3.0 / continuous_shape(x);
    if white_excess <= walk_excess {
        let one_minus_phi = -(-tau0_s / t).exp_m1();
        MarkovBound::White { n2: s2 * tau0_s * (2.0 - one_minus_phi) / one_minus_phi }
    } else {
        MarkovBound::RandomWalk { k2: 2.0 * s2 / t }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Var(ybar) - Cov(ybar_0, ybar_1) summed directly over the autocovariance phi^|k|.
    fn brute_force_avar(t: f64, tau0: f64, m: usize) -> f64 {
        let phi = (-tau0 / t).exp();
        let r = |k: i64| phi.powi(k.unsigned_abs() as i32);
        let (mut var, mut cov) = (0.0, 0.0);
        for i in 0..m as i64 {
            for j in 0..m as i64 {
                var += r(i - j);
                cov += r(j + m as i64 - i);
            }
        }
        (var - cov) / (m * m) as f64
    }

    #[test]
    fn closed_form_and_series_equal_the_direct_sum() {
        for &t in &[0.013, 0.2, 1.0, 7.5, 120.0, 5e4] {
            for &m in &[1usize, 2, 3, 8, 33, 256] {
                let want = brute_force_avar(t, 0.01, m) / 2.0;
                let got = gauss_markov_wavelet_variance(t, 0.01, m as f64);
                assert!((got / want - 1.0).abs() < 1e-8, "T {t} m {m}: {got} vs {want}");
            }
        }
    }

    #[test]
    fn series_and_closed_form_agree_where_they_meet() {
        // m u = 1e-2 exactly at the switch: both sides within 1e-10.
        for &m in &[1.0, 4.0, 1024.0] {
            let t = 0.01 * m / 1e-2;
            let below = gauss_markov_wavelet_variance(t * (1.0 + 1e-12), 0.01, m);
            let above = gauss_markov_wavelet_variance(t * (1.0 - 1e-12), 0.01, m);
            assert!((below / above - 1.0).abs() < 1e-10, "m {m}: {below} vs {above}");
        }
    }

    #[test]
    fn limits_are_white_noise_and_random_walk() {
        // Long averaging: nu^2 -> N^2 / (2 tau) with N^2 = 2 T (sigma = 1); short: K^2 tau / 6,
        // K^2 = 2 / T.
        let (t, tau0) = (1.0, 0.001);
        let m = 1e7;
        let white = 2.0 * t / (2.0 * m * tau0);
        // (the next term, -3 T^2 / (m tau0)^2 relative, is 1.5e-4 here)
        assert!((gauss_markov_wavelet_variance(t, tau0, m) / white - 1.0).abs() < 1e-3);
        let (t, m) = (1e6, 64.0);
        let walk = 2.0 / t * (m * tau0) / 6.0;
        assert!((gauss_markov_wavelet_variance(t, tau0, m) / walk - 1.0).abs() < 1e-3);
    }

    #[test]
    fn the_sampled_white_noise_and_random_walk_bound_it() {
        // Sampled at tau0 = 0.01 s: nu^2 of the process <= that of white noise N^2 = sigma^2
        // tau0 (1 + phi) / (1 - phi), N^2 / (2 m tau0), and <= that of the sampled random walk
        // K^2 = 2 / T, K^2 tau0 (2 m^2 + 1) / (12 m) (sigma = 1), over 24 octaves.
        let tau0: f64 = 0.01;
        for &t in &[0.01, 0.03, 1.0, 40.0, 3e3, 1e6] {
            let phi = (-tau0 / t).exp();
            let n2 = tau0 * (1.0 + phi) / (1.0 - phi);
            for j in 0..24 {
                let m = f64::from(1u32 << j);
                let nu2 = gauss_markov_wavelet_variance(t, tau0, m);
                let white = n2 / (2.0 * m * tau0);
                let walk = 2.0 / t * tau0 * (2.0 * m * m + 1.0) / (12.0 * m);
                assert!(nu2 <= white * (1.0 + 1e-9), "T {t} m {m}: {nu2} > white {white}");
                assert!(nu2 <= walk * (1.0 + 1e-12), "T {t} m {m}: {nu2} > walk {walk}");
            }
        }
    }

    #[test]
    fn the_filter_bound_lies_on_or_above_the_process() {
        // Both continuous-time bounds above the continuous-time Allan variance at every tau; the
        // choice follows T.
        for &t in &[0.01, 0.5, 30.0, 2000.0] {
            for j in 0..40 {
                let tau = 0.01 * 1.5f64.powi(j);
                let avar = 2.0 * t / tau * continuous_shape(tau / t);
                assert!(2.0 * t / tau >= avar && 2.0 / t * tau / 3.0 >= avar * (1.0 - 1e-12), "T {t} tau {tau}");
            }
        }
        assert!(matches!(gauss_markov_filter_bound(1.0, 0.02, 0.01, 0.01, 1000.0), MarkovBound::White { .. }));
        assert!(matches!(gauss_markov_filter_bound(1.0, 800.0, 0.01, 0.01, 1000.0), MarkovBound::RandomWalk { .. }));
        // A process the record sees from both sides: the tighter bound over the range.
        let b = gauss_markov_filter_bound(1.0, 3.0, 0.01, 0.01, 1000.0);
        let white = 1.0 / continuous_shape(0.01 / 3.0);
        let walk = (1000.0f64 / 3.0).powi(2) / 3.0 / continuous_shape(1000.0 / 3.0);
        assert_eq!(matches!(b, MarkovBound::White { .. }), white <= walk, "{b:?} {white} {walk}");
        // At T = tau0 the sampled white noise is 8 % above 2 sigma^2 T.
        let MarkovBound::White { n2 } = gauss_markov_filter_bound(1.0, 0.01, 0.01, 0.01, 1000.0) else { panic!() };
        let phi = (-1.0f64).exp();
        assert!((n2 / (0.01 * (1.0 + phi) / (1.0 - phi)) - 1.0).abs() < 1e-12 && n2 > 1.08 * 0.02);
    }

    #[test]
    fn spectral_density_integrates_to_the_variance() {
        for &t in &[0.02, 1.0, 50.0] {
            let n = 200_000;
            let total: f64 = (0..n)
                .map(|i| gauss_markov_spectral_density(t, 0.01, -0.5 + (i as f64 + 0.5) / n as f64) / n as f64)
                .sum();
            assert!((total - 1.0).abs() < 2e-3, "T {t}: {total}");
        }
        assert!(gauss_markov_wavelet_variance(-1.0, 0.01, 1.0).is_nan());
    }
}
