//! Overlapping Allan sums for long tau lists through autocorrelations computed with FFTs.
//!
//! Source: the overlapping Allan variance of NIST SP 1065 eq. (11) in phase form; the expansion
//! below is elementary algebra (derived here). With x the angle series (L points), n = L - 2m,
//! P(j) = sum_{i<j} x_i^2, R(l) = sum_{i<L-l} x_i x_{i+l}, the head sums
//! H(m) = sum_{j<m} x_j x_{j+m} and the tail sums T(m) = sum_{k=L-2m}^{L-m-1} x_k x_{k+m}:
//!
//!   S(m) = sum_{k<n} (x_{k+2m} - 2 x_{k+m} + x_k)^2
//!        = [P(L) - P(2m)] + 4 [P(L-m) - P(m)] + P(L-2m) - 8 R(m) + 4 H(m) + 4 T(m) + 2 R(2m).
//!
//! R comes from one real FFT of the zero-padded series (Wiener-Khinchin); H and T (T is H of
//! the reversed series) are prefix-limited correlations, obtained for every m at once by divide
//! and conquer: for r in [h, 2h), sum_{i<r} u_i v_{i+r} = (full correlation of u[..h] with v,
//! one FFT product of size 2h) + (the same problem of half the size on u[h..], v[2h..]), so the
//! cost is O(M log^2 M). Prefix sums of squares are kept in double-double.
//!
//! The expansion cancels: S(m) is small against the terms when the angle wanders far (random-walk
//! phase). So the least-squares quadratic q_k = a2 (k - c)^2 + (linear) is split off first,
//! x = r + q: a linear function drops out of every second difference and the quadratic leaves
//! the constant g = 2 a2 m^2, so S_x(m) = S_r(m) + 2 g D(m) + n g^2 with
//! D(m) = sum_{k<n} (r_{k+2m} - 2 r_{k+m} + r_k) = [Q(L) - Q(2m)] - 2 [Q(L-m) - Q(m)] + Q(L-2m),
//! Q the double-double prefix sums of r; the expansion is applied to the much smaller r.
//! FFT correlations carry an absolute error of order eps log2(size) sum r^2. Each S(m) is
//! returned with that error bound, and the caller recomputes directly every m whose bound is not
//! far below the required accuracy.

use gyrolab_fft::Correlator;

/// Below this many lags a prefix-limited correlation is summed directly.
const DIRECT_BELOW: usize = 128;

/// Safety factor on the FFT error bound `eps log2(size) sum r^2` (the observed errors on white,
/// random-walk and flicker-like records stay below 1/4 of the bound with this factor; see tests).
const ERROR_FACTOR: f64 = 16.0;

/// Overlapping Allan sums S(m) for every m in `ms` (sorted, each <= (L-1)/2) with an absolute
/// error bound for each; `None` if an FFT could not be planned or run.
pub(crate) fn overlapping_allan_sums_fft(s: &[f64], ms: &[usize]) -> Option<Vec<(f64, f64)>> {
    let len = s.len();
    let m_max = *ms.last()?;
    if m_max == 0 || 2 * m_max >= len {
        return None;
    }
    let (x, a2) = detrended(s);
    // prefix sums of squares and of values, double-double
    let mut p_hi = Vec::with_capacity(len + 1);
    let mut p_lo = Vec::with_capacity(len + 1);
    let mut q_hi = Vec::with_capacity(len + 1);
    let mut q_lo = Vec::with_capacity(len + 1);
    let (mut hi, mut lo, mut qh, mut ql) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    p_hi.push(0.0);
    p_lo.push(0.0);
    q_hi.push(0.0);
    q_lo.push(0.0);
    for &v in &x {
        let sq = v * v;
        let sq_err = v.mul_add(v, -sq);
        let (t, e) = two_sum(hi, sq);
        hi = t;
        lo += e + sq_err;
        p_hi.push(hi);
        p_lo.push(lo);
        let (t, e) = two_sum(qh, v);
        qh = t;
        ql += e;
        q_hi.push(qh);
        q_lo.push(ql);
    }
    let energy = hi + lo;
    let reversed: Vec<f64> = x.iter().rev().copied().collect();
    let ((r, head), tail) = if !super::parallel(len) {
        // a short record: on the calling thread (see PARALLEL_MIN_POINTS)
        ((autocorrelation(&x, 2 * m_max), head_sums(&x, m_max)), head_sums(&reversed, m_max))
    } else {
        rayon::join(
            || rayon::join(|| autocorrelation(&x, 2 * m_max), || head_sums(&x, m_max)),
            || head_sums(&reversed, m_max),
        )
    };
    let (r, head, tail) = (r?, head?, tail?);
    let fft_len = (len + 2 * m_max).next_power_of_two() as f64;
    let bound = ERROR_FACTOR * f64::EPSILON * fft_len.log2() * energy;
    let p = |j: usize| (p_hi[j], p_lo[j]);
    let q = |j: usize| (q_hi[j], q_lo[j]);
    Some(
        ms.iter()
            .map(|&m| {
                let mut d = Dd::default();
                d.add_dd(q(len));
                d.sub_dd(q(2 * m));
                d.sub_dd(scale2(q(len - m)));
                d.add_dd(scale2(q(m)));
                d.add_dd(q(len - 2 * m));
                let g = 2.0 * a2 * (m as f64) * (m as f64);
                let n = (len - 2 * m) as f64;
                let mut acc = Dd::default();
                acc.add(2.0 * g * d.value());
                acc.add(n * g * g);
                acc.add_dd(p(len));
                acc.sub_dd(p(2 * m));
                acc.add_dd(scale4(p(len - m)));
                acc.sub_dd(scale4(p(m)));
                acc.add_dd(p(len - 2 * m));
                acc.add(-8.0 * r[m]);
                acc.add(4.0 * head[m]);
                acc.add(4.0 * tail[m]);
                acc.add(2.0 * r[2 * m]);
                // rounding of the quadratic's terms (g, D and their products), a few eps each
                let q_size = q(len).0.abs()
                    + q(2 * m).0.abs()
                    + 2.0 * (q(len - m).0.abs() + q(m).0.abs())
                    + q(len - 2 * m).0.abs();
                let extra = 16.0 * f64::EPSILON * (n * g * g + 2.0 * g.abs() * (d.value().abs() + q_size));
                (acc.value(), bound + extra)
            })
            .collect(),
    )
}

/// Knuth's TwoSum.
#[inline(always)]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bp = s - a;
    (s, (a - (s - bp)) + (b - bp))
}

fn scale2((h, l): (f64, f64)) -> (f64, f64) {
    (2.0 * h, 2.0 * l)
}

fn scale4((h, l): (f64, f64)) -> (f64, f64) {
    (4.0 * h, 4.0 * l)
}

/// A double-double accumulator.
#[derive(Default)]
struct Dd {
    hi: f64,
    lo: f64,
}

impl Dd {
    fn add(&mut self, v: f64) {
        let (s, e) = two_sum(self.hi, v);
        self.hi = s;
        self.lo += e;
    }
    fn add_dd(&mut self, (h, l): (f64, f64)) {
        self.add(h);
        self.lo += l;
    }
    fn sub_dd(&mut self, (h, l): (f64, f64)) {
        self.add(-h);
        self.lo -= l;
    }
    fn value(&self) -> f64 {
        self.hi + self.lo
    }
}

/// The series minus its least-squares quadratic (orthogonal basis 1, t, t^2 - q with t = k - c),
/// and the quadratic's coefficient a2 of t^2.
fn detrended(s: &[f64]) -> (Vec<f64>, f64) {
    let n = s.len();
    let c = (n as f64 - 1.0) / 2.0;
    let qq = (n as f64 * n as f64 - 1.0) / 12.0;
    let (mut s0, mut s1, mut s2, mut n1, mut n2) = (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for (k, &v) in s.iter().enumerate() {
        let t = k as f64 - c;
        let t2 = t * t - qq;
        s0 += v;
        s1 += v * t;
        s2 += v * t2;
        n1 += t * t;
        n2 += t2 * t2;
    }
    let a0 = s0 / n as f64;
    let a1 = if n1 > 0.0 { s1 / n1 } else { 0.0 };
    let a2 = if n2 > 0.0 { s2 / n2 } else { 0.0 };
    let r = s
        .iter()
        .enumerate()
        .map(|(k, &v)| {
            let t = k as f64 - c;
            v - (a0 + a1 * t + a2 * (t * t - qq))
        })
        .collect();
    (r, a2)
}

/// R(l) = sum_{i<L-l} x_i x_{i+l} for l <= max_lag, from one zero-padded real FFT.
fn autocorrelation(x: &[f64], max_lag: usize) -> Option<Vec<f64>> {
    Correlator::new().autocorrelation(x, max_lag)
}

/// H(m) = sum_{j<m} x_j x_{j+m} for m <= m_max.
fn head_sums(x: &[f64], m_max: usize) -> Option<Vec<f64>> {
    let size = (m_max + 1).next_power_of_two();
    // u = x[..size], v = x[..2 size - 1], zero beyond the record (those terms are never used
    // for m <= m_max since j + m <= 2 m_max - 1 < len)
    let mut v = vec![0.0f64; 2 * size];
    let take = x.len().min(2 * size);
    v[..take].copy_from_slice(&x[..take]);
    let mut out = vec![0.0f64; size];
    prefix_correlation(&v[..size], &v, &mut out, &mut Correlator::new())?;
    out.truncate(m_max + 1);
    Some(out)
}

/// out[r] += sum_{i<r} u_i v_{i+r} for r < out.len() = M (a power of two); u.len() >= M,
/// v.len() >= 2M - 1.
fn prefix_correlation(u: &[f64], v: &[f64], out: &mut [f64], fft: &mut Correlator) -> Option<()> {
    let m = out.len();
    if m <= DIRECT_BELOW {
        for (r, o) in out.iter_mut().enumerate() {
            *o += u[..r].iter().zip(&v[r..2 * r]).map(|(a, b)| a * b).sum::<f64>();
        }
        return Some(());
    }
    let h = m / 2;
    let (low, high) = out.split_at_mut(h);
    prefix_correlation(u, v, low, fft)?;
    // full part: c(r) = sum_{i<h} u_i v_{i+r}, r in [h, m): correlation of a = u[..h] with
    // b = v[h..h + m - 1] at lags 0..h; indices stay below m - 1, so a size-m circle does not wrap
    let full = fft.correlation(&u[..h], &v[h..h + m - 1], m, h)?;
    for (o, c) in high.iter_mut().zip(&full) {
        *o += c;
    }
    // the rest: sum_{h<=i<r} u_i v_{i+r}, the same problem on u[h..], v[2h..]
    prefix_correlation(&u[h..], &v[2 * h..], high, fft)
}
