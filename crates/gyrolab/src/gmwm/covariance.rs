//! The covariance of the Haar wavelet-variance estimates of a fitted composite model, across
//! scales, for the GMWM's intervals (docs/METHODS.md 3.1, "GMWM").
//!
//! Source: D. B. Percival and A. T. Walden, *Wavelet Methods for Time Series Analysis*, 2000,
//! section 8.3-8.4: for a Gaussian process with spectral density S(f) (f in cycles per sample),
//! the MODWT wavelet-variance estimate at level j from M_j coefficients has the large-sample
//! variance 2 A_j / M_j, A_j = integral over [-1/2, 1/2] of |H_j(f)|^4 S(f)^2 df; the same
//! argument gives cov(nu_hat^2_j, nu_hat^2_k) = 2 / M integral |H_j(f)|^2 |H_k(f)|^2 S(f)^2 df
//! (M = min(M_j, M_k) here). The Haar squared gain at averaging factor m (width 2m) is
//! |H(f)|^2 = sin^4(pi f m) / (m^2 sin^2(pi f)), so that nu^2 = integral |H|^2 S = AVAR(m tau0) / 2.
//! Spectral densities per sample of each process, from the one-sided continuous power-law
//! coefficients h_alpha of IEEE Std 1139 / NIST SP 1065 (S_d(f) = S_y(f / tau0) / (2 tau0)):
//! white N: N^2 / tau0; quantization Q: 4 Q^2 sin^2(pi f) / tau0^2 (differenced white angle noise);
//! flicker floor B: B^2 / (2 pi |f|); random walk K: K^2 tau0 / (4 sin^2(pi f)); drift: none
//! (deterministic); a first-order Gauss-Markov process of variance sigma^2: sigma^2 times its AR(1)
//! spectrum (module `gauss_markov`). Each reproduces its AVAR of IEEE 952 annex C at long averaging
//! times.
//!
//! A drift is deterministic: its Haar coefficients are one constant c_j per scale (c_j^2 its
//! wavelet variance), so nu_hat^2_j = c_j^2 + 2 c_j e_bar_j + mean(e^2), e the coefficients of the
//! rest. Beside the stochastic part's variance this adds 4 c_j^2 var(e_bar_j) (the third moments of
//! a Gaussian rest vanish). The mean of M Haar coefficients at averaging factor m telescopes to
//! half the difference of two averages of M m-sample means, m samples apart, so var(e_bar_j) =
//! integral over [-1/2, 1/2] of |H_j(f)|^2 F_M(f) S(f) df with the Fejer kernel F_M(f) =
//! sin^2(pi f M) / (M^2 sin^2(pi f)) (derived here from the filters above; white noise of variance
//! sigma^2 per sample gives (2 m^2 + 1) sigma^2 / (6 m M^2) when M >= 2m - 1, and the tests check
//! it and a random walk against direct sums of the coefficients' weights). On a record with gaps
//! the means telescope once per segment; the term is then understated (not corrected: a curve
//! does not carry its segments).

use super::{Process, Shape, WaveletVariance};

/// A model's terms prepared for the spectral density: (shape, weight, phi) with phi = exp(-tau0/T)
/// for a Gauss-Markov process (0 otherwise).
fn prepare(model: &[(Shape, f64)], tau0_s: f64) -> Vec<(Shape, f64, f64, f64)> {
    model
        .iter()
        .map(|&(shape, t)| match shape {
            Shape::GaussMarkov(tc) => {
                let one_minus_phi = -(-tau0_s / tc).exp_m1();
                (shape, t, 1.0 - one_minus_phi, one_minus_phi)
            }
            Shape::Linear(_) => (shape, t, 0.0, 0.0),
        })
        .collect()
}

/// The model's spectral density per sample at frequency `f` (cycles per sample, 0 < f <= 1/2)
/// with s2 = sin^2(pi f), (curve unit)^2 per cycle per sample.
fn spectral_density(model: &[(Shape, f64, f64, f64)], tau0_s: f64, f: f64, s2: f64) -> f64 {
    model
        .iter()
        .map(|&(shape, t, phi, one_minus_phi)| match shape {
            Shape::Linear(Process::White) => t / tau0_s,
            Shape::Linear(Process::Quantization) => 4.0 * t * s2 / (tau0_s * tau0_s),
            Shape::Linear(Process::Flicker) => t / (2.0 * std::f64::consts::PI * f),
            Shape::Linear(Process::RandomWalk) => t * tau0_s / (4.0 * s2),
            Shape::Linear(Process::Drift | Process::GaussMarkov) => 0.0,
            // gauss_markov_spectral_density, phi taken once per model.
            Shape::GaussMarkov(_) => t * one_minus_phi * (1.0 + phi) / (one_minus_phi * one_minus_phi + 4.0 * phi * s2),
        })
        .sum()
}

/// The Haar squared gain at averaging factor `m`; `averaged` replaces sin^4(pi f m) by its mean
/// 3/8 (where the grid does not resolve its oscillation and the rest of the integrand is smooth).
fn haar_gain(m: f64, f: f64, averaged: bool) -> f64 {
    let s = (std::f64::consts::PI * f).sin();
    let num = if averaged { 0.375 } else { (std::f64::consts::PI * f * m).sin().powi(4) };
    num / (m * m * s * s)
}

/// The nodes and weights (f, step) of the midpoint rule over (a, b] in `n` steps, uniform or
/// uniform in log f when `log`; none when b <= a.
fn midpoints(a: f64, b: f64, n: usize, log: bool) -> impl Iterator<Item = (f64, f64)> {
    let n = if b > a { n } else { 0 };
    (0..n).map(move |i| {
        let u = (i as f64 + 0.5) / n as f64;
        if log {
            let f = a * (b / a).powf(u);
            (f, f * (b / a).ln() / n as f64)
        } else {
            (a + u * (b - a), (b - a) / n as f64)
        }
    })
}

/// Midpoint-rule points of the product of the two scales' gains over (a, b] in `n` steps
/// (uniform, or uniform in log f when `log`), appended as (f, sin^2(pi f), step x gains x
/// `scale`).
#[allow(clippy::too_many_arguments)]
fn points(
    out: &mut Vec<[f64; 3]>,
    (m_lo, avg_lo): (f64, bool),
    (m_hi, avg_hi): (f64, bool),
    a: f64,
    b: f64,
    n: usize,
    log: bool,
    scale: f64,
) {
    push_points(out, (a, b), n, log, scale, |f, _, sw| sw * haar_gain(m_lo, f, avg_lo) * haar_gain(m_hi, f, avg_hi));
}

/// Appends (f, sin^2(pi f), weight(f, sin(pi f), scale x step)) at the midpoints of (a, b] in `n`
/// steps (uniform, or uniform in log f when `log`): the one loop of [`points`] and [`mean_points`].
fn push_points(
    out: &mut Vec<[f64; 3]>,
    (a, b): (f64, f64),
    n: usize,
    log: bool,
    scale: f64,
    weight: impl Fn(f64, f64, f64) -> f64,
) {
    for (f, w) in midpoints(a, b, n, log) {
        let s = (std::f64::consts::PI * f).sin();
        out.push([f, s * s, weight(f, s, scale * w)]);
    }
}

/// Midpoint-rule points of |H_j(f)|^2 F_M(f) (Haar gain at averaging factor `m`, Fejer kernel
/// of `terms` = M terms) over (a, b] in `n` steps (uniform, or uniform in log f when `log`), each
/// oscillation averaged where asked (sin^4 to 3/8, sin^2 to 1/2), appended as (f, sin^2(pi f),
/// step x kernel x `scale`).
#[allow(clippy::too_many_arguments)]
fn mean_points(
    out: &mut Vec<[f64; 3]>,
    (m, avg_m): (f64, bool),
    (terms, avg_terms): (f64, bool),
    a: f64,
    b: f64,
    n: usize,
    log: bool,
    scale: f64,
) {
    push_points(out, (a, b), n, log, scale, |f, s, sw| {
        let fejer_num = if avg_terms { 0.5 } else { (std::f64::consts::PI * f * terms).sin().powi(2) };
        let fejer = fejer_num / (terms * terms * s * s);
        sw * haar_gain(m, f, avg_m) * fejer
    });
}

/// The quadrature of the covariance integrals of one set of scales, made once and used for every
/// model fitted to them: per pair of scales j <= k, the points f, sin^2(pi f) and their weights
/// (the step, both Haar gains and the factor 2 / sqrt(M_j M_k) x 2), so that a model's covariance is the
/// weighted sum of its S(f)^2. The integral over [-1/2, 1/2] is twice that over (0, 1/2], in three
/// parts: up to 32 / m_hi exactly (512 steps), then with the larger scale's oscillation averaged up
/// to 32 / m_lo (512 steps), then both averaged (256 log steps).
pub struct CovarianceGrid {
    n: usize,
    tau0_s: f64,
    /// Points of pair (j, k), j <= k, at index j n + k.
    pairs: Vec<Vec<[f64; 3]>>,
    /// Points of the variance of the mean coefficient at scale j (module notes: the drift's
    /// cross term), each weight the step times |H_j|^2 F_M times 2 (both halves of the band).
    means: Vec<Vec<[f64; 3]>>,
}

impl CovarianceGrid {
    /// The quadrature of the scales `wv`.
    pub fn new(wv: &[WaveletVariance]) -> Self {
        let n = wv.len();
        let tau0_s = wv.first().map_or(1.0, |w| w.tau_s / w.m as f64);
        let mut pairs = vec![Vec::new(); n * n];
        for j in 0..n {
            for k in j..n {
                let (a, b) = (&wv[j], &wv[k]);
                let (m_lo, m_hi) = ((a.m.min(b.m)) as f64, (a.m.max(b.m)) as f64);
                let f1 = (32.0 / m_hi).min(0.5);
                let f2 = (32.0 / m_lo).min(0.5);
                // 2 / sqrt(M_j M_k): the matrix stays a scaled Gram matrix (positive
                // semi-definite); 2 / min(M_j, M_k) raised the correlations of scales with
                // different numbers of terms above 1.
                let terms = ((a.terms.max(1) as f64) * (b.terms.max(1) as f64)).sqrt();
                let scale = 2.0 / terms * 2.0;
                let out = &mut pairs[j * n + k];
                out.reserve(1280);
                points(out, (m_lo, false), (m_hi, false), 0.0, f1, 512, false, scale);
                points(out, (m_lo, false), (m_hi, true), f1, f2, 512, false, scale);
                points(out, (m_lo, true), (m_hi, true), f2, 0.5, 256, true, scale);
            }
        }
        let means = wv
            .iter()
            .map(|w| {
                let (m, terms) = (w.m as f64, w.terms.max(1) as f64);
                let (lo, hi) = (m.min(terms), m.max(terms));
                let (f1, f2) = ((32.0 / hi).min(0.5), (32.0 / lo).min(0.5));
                // Which oscillation is averaged first: the faster one (the larger of m and M).
                let fast_is_m = m >= terms;
                let mut out = Vec::with_capacity(1280);
                mean_points(&mut out, (m, false), (terms, false), 0.0, f1, 512, false, 2.0);
                mean_points(&mut out, (m, fast_is_m), (terms, !fast_is_m), f1, f2, 512, false, 2.0);
                mean_points(&mut out, (m, true), (terms, true), f2, 0.5, 256, true, 2.0);
                out
            })
            .collect();
        CovarianceGrid { n, tau0_s, pairs, means }
    }

    /// The variances of the wavelet-variance estimates under `model` (the diagonal of
    /// [`CovarianceGrid::covariance`] plus a drift's cross term, module notes), (curve unit)^4.
    pub fn variances(&self, wv: &[WaveletVariance], model: &[(Shape, f64)]) -> Vec<f64> {
        let prepared = prepare(model, self.tau0_s);
        let drift = Shape::Linear(Process::Drift);
        let weight: f64 = model.iter().filter(|(s, _)| *s == drift).map(|(_, t)| *t).sum();
        let means = if weight > 0.0 { self.mean_coefficient_variance(model) } else { vec![0.0; self.n] };
        (0..self.n)
            .map(|j| {
                let spectral: f64 = self.pairs[j * self.n + j]
                    .iter()
                    .map(|&[f, s2, w]| {
                        let s = spectral_density(&prepared, self.tau0_s, f, s2);
                        w * s * s
                    })
                    .sum();
                spectral + wv.get(j).map_or(0.0, |w| 4.0 * weight * drift.unit(w) * means[j])
            })
            .collect()
    }

    /// The variance of the mean of the wavelet coefficients at each scale under the stochastic
    /// part of `model` (its drift has no spectrum), (curve unit)^2 (module notes).
    pub fn mean_coefficient_variance(&self, model: &[(Shape, f64)]) -> Vec<f64> {
        let prepared = prepare(model, self.tau0_s);
        self.means
            .iter()
            .map(|pts| pts.iter().map(|&[f, s2, w]| w * spectral_density(&prepared, self.tau0_s, f, s2)).sum())
            .collect()
    }

    /// Covariance matrix of the wavelet-variance estimates under the model (shape, weight: the
    /// squared coefficient or a Gauss-Markov sigma^2): entries (curve unit)^4.
    #[allow(clippy::needless_range_loop)] // a symmetric fill: cov[j][k] and cov[k][j] at once
    pub fn covariance(&self, model: &[(Shape, f64)]) -> Vec<Vec<f64>> {
        let n = self.n;
        let prepared = prepare(model, self.tau0_s);
        let mut cov = vec![vec![0.0; n]; n];
        for j in 0..n {
            for k in j..n {
                let c: f64 = self.pairs[j * n + k]
                    .iter()
                    .map(|&[f, s2, w]| {
                        let s = spectral_density(&prepared, self.tau0_s, f, s2);
                        w * s * s
                    })
                    .sum();
                cov[j][k] = c;
                cov[k][j] = c;
            }
        }
        cov
    }
}

/// The covariance integrals of a set of shapes on a [`CovarianceGrid`], made in one pass over its
/// points: for every two shapes a <= b and every pair of scales j <= k, the sum over the pair's
/// points of w s_a(f) s_b(f) (unit weights). The covariance of any model of these shapes is then
/// sum over a, b of theta_a theta_b times them, without another pass over the points.
pub struct ShapeIntegrals {
    shapes: Vec<Shape>,
    n: usize,
    /// Index (a, b), a <= b, at a p + b; each over the pairs of scales at j n + k.
    values: Vec<Vec<f64>>,
    /// Per shape, per scale: the variance of the mean coefficient per unit weight.
    means: Vec<Vec<f64>>,
}

impl ShapeIntegrals {
    /// The integrals of `shapes` on `grid`.
    pub fn new(grid: &CovarianceGrid, shapes: &[Shape]) -> Self {
        let p = shapes.len();
        let n = grid.n;
        let unit: Vec<(Shape, f64)> = shapes.iter().map(|&s| (s, 1.0)).collect();
        let prepared = prepare(&unit, grid.tau0_s);
        let mut values = vec![vec![0.0; n * n]; p * p];
        let mut dens = vec![0.0; p];
        for j in 0..n {
            for k in j..n {
                let idx = j * n + k;
                let mut acc = vec![0.0; p * p];
                for &[f, s2, w] in &grid.pairs[idx] {
                    for (d, term) in dens.iter_mut().zip(&prepared) {
                        *d = spectral_density(std::slice::from_ref(term), grid.tau0_s, f, s2);
                    }
                    for a in 0..p {
                        let wa = w * dens[a];
                        for b in a..p {
                            acc[a * p + b] += wa * dens[b];
                        }
                    }
                }
                for a in 0..p {
                    for b in a..p {
                        values[a * p + b][idx] = acc[a * p + b];
                    }
                }
            }
        }
        let means = unit.iter().map(|term| grid.mean_coefficient_variance(std::slice::from_ref(term))).collect();
        ShapeIntegrals { shapes: shapes.to_vec(), n, values, means }
    }

    /// The drift's cross term 4 c_j^2 var(e_bar_j) at each scale under `model` (module notes),
    /// (curve unit)^4: zero without a drift. `None` when a shape is not among these.
    pub fn drift_cross_variance(&self, wv: &[WaveletVariance], model: &[(Shape, f64)]) -> Option<Vec<f64>> {
        let drift = Shape::Linear(Process::Drift);
        let weight: f64 = model.iter().filter(|(s, _)| *s == drift).map(|(_, t)| *t).sum();
        let mut out = vec![0.0; self.n];
        if weight <= 0.0 {
            return Some(out);
        }
        for (s, t) in model {
            let a = self.shapes.iter().position(|x| x == s)?;
            for (o, v) in out.iter_mut().zip(&self.means[a]) {
                *o += t * v;
            }
        }
        for (o, w) in out.iter_mut().zip(wv) {
            *o *= 4.0 * weight * drift.unit(w);
        }
        Some(out)
    }

    /// The covariance of the wavelet-variance estimates under `model`, whose shapes must all be
    /// among these (None otherwise).
    #[allow(clippy::needless_range_loop)] // a symmetric fill: cov[j][k] and cov[k][j] at once
    pub fn covariance(&self, model: &[(Shape, f64)]) -> Option<Vec<Vec<f64>>> {
        let p = self.shapes.len();
        let at: Vec<(usize, f64)> = model
            .iter()
            .map(|(s, t)| self.shapes.iter().position(|x| x == s).map(|i| (i, *t)))
            .collect::<Option<_>>()?;
        let n = self.n;
        let mut cov = vec![vec![0.0; n]; n];
        for j in 0..n {
            for k in j..n {
                let idx = j * n + k;
                let mut c = 0.0;
                for (x, &(a, ta)) in at.iter().enumerate() {
                    for &(b, tb) in &at[x..] {
                        let (lo, hi) = if a <= b { (a, b) } else { (b, a) };
                        let v = self.values[lo * p + hi][idx];
                        c += if a == b { ta * tb * v } else { 2.0 * ta * tb * v };
                    }
                }
                cov[j][k] = c;
                cov[k][j] = c;
            }
        }
        Some(cov)
    }
}

/// Covariance matrix of the wavelet-variance estimates `wv` under the model (shape, weight: the
/// squared coefficient or a Gauss-Markov sigma^2): entries (curve unit)^4 ([`CovarianceGrid`]).
pub fn wavelet_variance_covariance(wv: &[WaveletVariance], model: &[(Shape, f64)]) -> Vec<Vec<f64>> {
    CovarianceGrid::new(wv).covariance(model)
}
