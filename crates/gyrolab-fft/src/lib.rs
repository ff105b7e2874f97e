//! Correlations of real `f64` series by real FFTs (the `realfft` and `rustfft` crates), for the
//! overlapping Allan sums of `gyrolab::allan` over long tau lists (docs/METHODS.md, "Allan
//! variance").
//!
//! Source: the Wiener-Khinchin theorem for the discrete Fourier transform (a circular correlation
//! is the inverse transform of one spectrum times the conjugate of the other; e.g. Oppenheim and
//! Schafer, "Discrete-Time Signal Processing", 3rd ed., 2010, section 8.6.5), with zero padding so
//! that no product wraps around the circle.
//!
//! Why a crate of its own: `rustfft` is generic over the float type and builds its planner's every
//! algorithm (scalar, SSE, AVX butterflies of many sizes) in the crate that names the type. In
//! `gyrolab` that was 422,000 of its 988,000 lines of LLVM IR (`cargo llvm-lines --release -p
//! gyrolab --lib`), compiled on the critical path of every build and again for its unit tests.
//! Here they are compiled once, beside the other dependencies, behind non-generic functions
//! (docs/PERFORMANCE.md, issue 32).

#![deny(missing_docs)]

use realfft::num_complex::Complex;
use realfft::RealFftPlanner;

/// Real FFT plans of `f64` series, kept between calls (planning a size costs more than one
/// transform of it).
#[derive(Default)]
pub struct Correlator {
    planner: RealFftPlanner<f64>,
}

impl Correlator {
    /// A correlator with no plans yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// The autocorrelation R(l) = sum over i < L - l of x_i x_(i+l), for l = 0..=max_lag (L the
    /// length of `x`), from one real FFT of the series zero-padded to the power of two at or above
    /// L + max_lag + 1. `None` when a transform fails. The absolute error is of order
    /// eps log2(size) sum x_i^2.
    ///
    /// ```
    /// let r = gyrolab_fft::Correlator::new().autocorrelation(&[1.0, 2.0, 3.0], 2).unwrap(); // ok: fixed input, sizes valid
    /// // 1 + 4 + 9, 1*2 + 2*3, 1*3
    /// for (got, want) in r.iter().zip([14.0, 8.0, 3.0]) {
    ///     assert!((got - want).abs() < 1e-12);
    /// }
    /// ```
    pub fn autocorrelation(&mut self, x: &[f64], max_lag: usize) -> Option<Vec<f64>> {
        let size = (x.len() + max_lag + 1).next_power_of_two();
        let fwd = self.planner.plan_fft_forward(size);
        let inv = self.planner.plan_fft_inverse(size);
        let mut buf = fwd.make_input_vec();
        buf[..x.len()].copy_from_slice(x);
        let mut spec = fwd.make_output_vec();
        fwd.process(&mut buf, &mut spec).ok()?;
        for c in spec.iter_mut() {
            *c = Complex::new(c.norm_sqr(), 0.0);
        }
        inv.process(&mut spec, &mut buf).ok()?;
        let scale = 1.0 / size as f64;
        buf.truncate(max_lag + 1);
        buf.iter_mut().for_each(|v| *v *= scale);
        Some(buf)
    }

    /// The correlation c(r) = sum over i < a.len() of a_i b_(i+r) (b taken as zero beyond its
    /// end), for r = 0..lags, by one circular correlation of size `size`, an even number with
    /// a.len() + lags - 1 <= size, b.len() <= size and 1 <= lags <= size (so that no product
    /// wraps around and every lag is a bin). `None` when those do not hold or a transform fails.
    ///
    /// ```
    /// let c = gyrolab_fft::Correlator::new().correlation(&[1.0, 2.0], &[3.0, 4.0, 5.0], 4, 2).unwrap(); // ok: sizes valid
    /// // 1*3 + 2*4, 1*4 + 2*5
    /// assert!((c[0] - 11.0).abs() < 1e-12 && (c[1] - 14.0).abs() < 1e-12);
    /// ```
    pub fn correlation(&mut self, a: &[f64], b: &[f64], size: usize, lags: usize) -> Option<Vec<f64>> {
        if !size.is_multiple_of(2) || lags == 0 || lags > size || b.len() > size || a.len() + lags - 1 > size {
            return None;
        }
        let fwd = self.planner.plan_fft_forward(size);
        let inv = self.planner.plan_fft_inverse(size);
        let mut x = fwd.make_input_vec();
        x[..a.len()].copy_from_slice(a);
        let mut y = fwd.make_input_vec();
        y[..b.len()].copy_from_slice(b);
        let mut fx = fwd.make_output_vec();
        let mut fy = fwd.make_output_vec();
        fwd.process(&mut x, &mut fx).ok()?;
        fwd.process(&mut y, &mut fy).ok()?;
        for (p, q) in fy.iter_mut().zip(&fx) {
            *p *= q.conj();
        }
        // The first and last bins of a real series' spectrum are real.
        if let Some(first) = fy.first_mut() {
            first.im = 0.0;
        }
        if let Some(last) = fy.last_mut() {
            last.im = 0.0;
        }
        inv.process(&mut fy, &mut x).ok()?;
        let scale = 1.0 / size as f64;
        x.truncate(lags);
        x.iter_mut().for_each(|v| *v *= scale);
        Some(x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic pseudo-random series in [-1, 1) (a linear congruential generator).
    fn series(len: usize, seed: u64) -> Vec<f64> {
        let mut state = seed;
        (0..len)
            .map(|_| {
                state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
                (state >> 11) as f64 / (1u64 << 52) as f64 - 1.0
            })
            .collect()
    }

    /// Both correlations against direct sums, over lengths that pad to several powers of two.
    #[test]
    fn correlations_equal_direct_sums() {
        let mut c = Correlator::new();
        for (len, lags) in [(1, 1), (7, 3), (100, 40), (1000, 513), (4096, 1)] {
            let x = series(len, len as u64);
            let r = c.autocorrelation(&x, lags - 1).unwrap();
            let energy: f64 = x.iter().map(|v| v * v).sum();
            for (l, got) in r.iter().enumerate() {
                let want: f64 = (0..len.saturating_sub(l)).map(|i| x[i] * x[i + l]).sum();
                assert!(
                    (got - want).abs() <= 1e-12 * energy.max(1.0),
                    "autocorrelation len {len} lag {l}: {got} {want}"
                );
            }
            let (a, b) = (&x[..len.div_ceil(2)], series(len, 7 * len as u64));
            let size = (a.len() + lags).max(b.len()).next_power_of_two().max(2);
            let cc = c.correlation(a, &b, size, lags).unwrap();
            for (r, got) in cc.iter().enumerate() {
                let want: f64 = a.iter().enumerate().filter(|(i, _)| i + r < b.len()).map(|(i, v)| v * b[i + r]).sum();
                assert!((got - want).abs() <= 1e-12 * (len as f64), "correlation len {len} lag {r}: {got} {want}");
            }
        }
    }

    /// Sizes that would wrap around are refused.
    #[test]
    fn sizes_that_wrap_are_refused() {
        let mut c = Correlator::new();
        assert!(c.correlation(&[1.0; 3], &[1.0; 4], 4, 3).is_none());
        assert!(c.correlation(&[1.0; 2], &[1.0; 5], 4, 2).is_none());
        assert!(c.correlation(&[1.0; 2], &[1.0; 3], 3, 1).is_none());
        assert!(c.correlation(&[1.0; 5], &[1.0; 4], 4, 0).is_none());
        assert!(c.correlation(&[], &[1.0; 4], 4, 5).is_none());
        // At the boundary (a.len() + lags - 1 = size): 1*1 + 2*2, 1*2 + 2*3, 1*3 + 2*4.
        let got = c.correlation(&[1.0, 2.0], &[1.0, 2.0, 3.0, 4.0], 4, 3).unwrap();
        for (g, w) in got.iter().zip([5.0, 8.0, 11.0]) {
            assert!((g - w).abs() < 1e-12, "{got:?}");
        }
        assert_eq!(got.len(), 3);
    }
}
