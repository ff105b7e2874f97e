//! Sums of squared finite differences of the angle (phase) series, the core of every variance.
//!
//! Source: NIST SP 1065 (Riley, Handbook of Frequency Stability Analysis, 2008), section 5.2:
//! eq. (9) non-overlapping Allan, eq. (11) overlapping Allan, eq. (13) modified Allan,
//! eq. (17)/(18) Hadamard (non-overlapping / overlapping), eq. (25) total variance with reflection.
//!
//! The angle series `s` here is in "sample units": s_k = sum_{i<k} (y_i - mean y), i.e. the
//! phase divided by tau0. With tau = m tau0 the factor tau0 cancels from every variance, so the
//! kernels need only m. The inner loops use 16 independent accumulators over `chunks_exact`, so
//! that LLVM vectorises them; an AVX2+FMA copy is selected at run time on x86-64. The multi-tau
//! OADEV sweep uses explicit AVX2+FMA kernels that share loads between taus: an octave run
//! (m, 2m, 4m, ...) needs one load per tau, any other group of up to 8 taus two.

/// Sum over k of (c_k - 2 b_k + a_k)^2 for k < n, where a, b, c are three views of one series.
#[inline(always)]
fn second_difference_sq_sum_body(a: &[f64], b: &[f64], c: &[f64]) -> f64 {
    const LANES: usize = 16;
    let n = a.len().min(b.len()).min(c.len());
    let (a, b, c) = (&a[..n], &b[..n], &c[..n]);
    let mut acc = [0.0f64; LANES];
    let ac = a.chunks_exact(LANES);
    let bc = b.chunks_exact(LANES);
    let cc = c.chunks_exact(LANES);
    let (ar, br, cr) = (ac.remainder(), bc.remainder(), cc.remainder());
    for ((x, y), z) in ac.zip(bc).zip(cc) {
        for l in 0..LANES {
            let d = (z[l] - y[l]) - (y[l] - x[l]);
            acc[l] += d * d;
        }
    }
    let mut tail = 0.0;
    for ((x, y), z) in ar.iter().zip(br).zip(cr) {
        let d = (z - y) - (y - x);
        tail += d * d;
    }
    pairwise_lanes(&acc) + tail
}

/// Sum over k of (d_k - 3 c_k + 3 b_k - a_k)^2 for k < n (third differences, Hadamard).
#[inline(always)]
fn third_difference_sq_sum_body(a: &[f64], b: &[f64], c: &[f64], d: &[f64]) -> f64 {
    const LANES: usize = 16;
    let n = a.len().min(b.len()).min(c.len()).min(d.len());
    let (a, b, c, d) = (&a[..n], &b[..n], &c[..n], &d[..n]);
    let mut acc = [0.0f64; LANES];
    let ac = a.chunks_exact(LANES);
    let bc = b.chunks_exact(LANES);
    let cc = c.chunks_exact(LANES);
    let dc = d.chunks_exact(LANES);
    let (ar, br, cr, dr) = (ac.remainder(), bc.remainder(), cc.remainder(), dc.remainder());
    for (((w, x), y), z) in ac.zip(bc).zip(cc).zip(dc) {
        for l in 0..LANES {
            let e = ((z[l] - y[l]) - (y[l] - x[l])) - ((y[l] - x[l]) - (x[l] - w[l]));
            acc[l] += e * e;
        }
    }
    let mut tail = 0.0;
    for (((w, x), y), z) in ar.iter().zip(br).zip(cr).zip(dr) {
        let e = ((z - y) - (y - x)) - ((y - x) - (x - w));
        tail += e * e;
    }
    pairwise_lanes(&acc) + tail
}

#[inline(always)]
fn pairwise_lanes(acc: &[f64; 16]) -> f64 {
    let mut v = *acc;
    let mut width = 16;
    while width > 1 {
        width /= 2;
        for l in 0..width {
            v[l] += v[l + width];
        }
    }
    v[0]
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn second_difference_sq_sum_avx2(a: &[f64], b: &[f64], c: &[f64]) -> f64 {
    second_difference_sq_sum_body(a, b, c)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn third_difference_sq_sum_avx2(a: &[f64], b: &[f64], c: &[f64], d: &[f64]) -> f64 {
    third_difference_sq_sum_body(a, b, c, d)
}

/// Sum of squared second differences c - 2b + a over the common length of three views.
pub(crate) fn second_difference_sq_sum(a: &[f64], b: &[f64], c: &[f64]) -> f64 {
    #[cfg(target_arch = "x86_64")]
    {
        if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
            // SAFETY: the CPU supports AVX2 and FMA (checked just above).
            return unsafe { second_difference_sq_sum_avx2(a, b, c) };
        }
    }
    second_difference_sq_sum_body(a, b, c)
}

/// Sum of squared third differences d - 3c + 3b - a over the common length of four views.
pub(crate) fn third_difference_sq_sum(a: &[f64], b: &[f64], c: &[f64], d: &[f64]) -> f64 {
    #[cfg(target_arch = "x86_64")]
    {
        if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
            // SAFETY: the CPU supports AVX2 and FMA (checked just above).
            return unsafe { third_difference_sq_sum_avx2(a, b, c, d) };
        }
    }
    third_difference_sq_sum_body(a, b, c, d)
}

/// Overlapping Allan: (sum of squared second differences at lag m, number of terms L - 2m).
pub(crate) fn overlapping_allan_sum(s: &[f64], m: usize) -> (f64, usize) {
    let n = s.len() - 2 * m;
    (second_difference_sq_sum(&s[..n], &s[m..m + n], &s[2 * m..2 * m + n]), n)
}

/// Non-overlapping Allan: stride m; number of terms floor((L-1)/m) - 1.
pub(crate) fn allan_sum(s: &[f64], m: usize) -> (f64, usize) {
    let n = (s.len() - 1) / m - 1;
    let sum = (0..n)
        .map(|j| {
            let k = j * m;
            let d = (s[k + 2 * m] - s[k + m]) - (s[k + m] - s[k]);
            d * d
        })
        .sum();
    (sum, n)
}

/// Overlapping Hadamard: third differences at lag m; number of terms L - 3m.
pub(crate) fn overlapping_hadamard_sum(s: &[f64], m: usize) -> (f64, usize) {
    let n = s.len() - 3 * m;
    (third_difference_sq_sum(&s[..n], &s[m..m + n], &s[2 * m..2 * m + n], &s[3 * m..3 * m + n]), n)
}

/// Non-overlapping Hadamard: stride m; number of terms floor((L-1)/m) - 2.
pub(crate) fn hadamard_sum(s: &[f64], m: usize) -> (f64, usize) {
    let n = (s.len() - 1) / m - 2;
    let sum = (0..n)
        .map(|j| {
            let k = j * m;
            let d1 = (s[k + 3 * m] - s[k + 2 * m]) - (s[k + 2 * m] - s[k + m]);
            let d0 = (s[k + 2 * m] - s[k + m]) - (s[k + m] - s[k]);
            (d1 - d0) * (d1 - d0)
        })
        .sum();
    (sum, n)
}

/// Modified Allan: sum over j of (sum_{i=j}^{j+m-1} second difference_i)^2, L - 3m + 1 terms.
///
/// The inner window sum slides (add the entering, drop the leaving second difference); it is
/// recomputed from scratch every max(4096, m) steps, so rounding cannot accumulate along long
/// records while the recomputation costs at most one extra pass.
pub(crate) fn modified_allan_sum(s: &[f64], m: usize) -> (f64, usize) {
    let n = s.len() - 3 * m + 1;
    let d2 = |i: usize| (s[i + 2 * m] - s[i + m]) - (s[i + m] - s[i]);
    let mut total = 0.0;
    let mut window = 0.0;
    let refresh = m.max(4096);
    for j in 0..n {
        if j % refresh == 0 {
            window = (j..j + m).map(d2).sum();
        } else {
            window += d2(j + m - 1) - d2(j - 1);
        }
        total += window * window;
    }
    (total, n)
}

/// Total variance numerator: the series reflected at both ends (SP1065 eq. 25), second
/// differences at lag m centred on i = 1..L-2; number of terms L - 2. The reflected series
/// x*_{-(L-2)} .. x*_{2L-3} (3L - 4 values) is never built: its values are made from `s` a block
/// at a time, in the order and with the arithmetic of [`second_difference_sq_sum`] over the
/// built series (same lanes, same additions, bit for bit; tested against
/// [`reflect_for_total`]), so TOTDEV needs no memory proportional to N beyond `s`.
pub(crate) fn total_sum(s: &[f64], m: usize) -> (f64, usize) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
            // SAFETY: the CPU supports AVX2 and FMA (checked just above).
            return unsafe { total_sum_avx2(s, m) };
        }
    }
    total_sum_body(s, m)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn total_sum_avx2(s: &[f64], m: usize) -> (f64, usize) {
    total_sum_body(s, m)
}

/// Values of the reflected series per block (a multiple of the 16 lanes).
const TOTAL_BLOCK: usize = 1024;

#[inline(always)]
fn total_sum_body(s: &[f64], m: usize) -> (f64, usize) {
    const LANES: usize = 16;
    let len = s.len();
    let n = len - 2;
    // Index of x*_i in the reflected series is i + L - 2; the centre x*_1 is at L - 1.
    let centre = len - 1;
    let mut acc = [0.0f64; LANES];
    let mut tail = 0.0;
    let (mut a, mut b, mut c) = ([0.0f64; TOTAL_BLOCK], [0.0f64; TOTAL_BLOCK], [0.0f64; TOTAL_BLOCK]);
    let mut k0 = 0;
    while k0 < n {
        let width = TOTAL_BLOCK.min(n - k0);
        reflected_into(s, centre - m + k0, &mut a[..width]);
        reflected_into(s, centre + k0, &mut b[..width]);
        reflected_into(s, centre + m + k0, &mut c[..width]);
        let ac = a[..width].chunks_exact(LANES);
        let bc = b[..width].chunks_exact(LANES);
        let cc = c[..width].chunks_exact(LANES);
        let (ar, br, cr) = (ac.remainder(), bc.remainder(), cc.remainder());
        for ((x, y), z) in ac.zip(bc).zip(cc) {
            for l in 0..LANES {
                let d = (z[l] - y[l]) - (y[l] - x[l]);
                acc[l] += d * d;
            }
        }
        // Only the last block can leave a remainder (a block is a multiple of the lanes).
        for ((x, y), z) in ar.iter().zip(br).zip(cr) {
            let d = (z - y) - (y - x);
            tail += d * d;
        }
        k0 += width;
    }
    (pairwise_lanes(&acc) + tail, n)
}

/// Writes x*_j for the reflected-series indices j = e0 .. e0 + out.len() (index L - 2 is x_0):
/// 2 x_0 - x_{L-2-j} before x_0, x_{j-(L-2)} over the record, 2 x_{L-1} - x_{3L-4-j} after it
/// (SP1065 eq. 25; the expressions of [`reflect_for_total`]).
#[inline(always)]
fn reflected_into(s: &[f64], e0: usize, out: &mut [f64]) {
    let len = s.len();
    let (first, last) = (s[0], s[len - 1]);
    let mut e = e0;
    let mut i = 0;
    while i < out.len() && e < len - 2 {
        out[i] = 2.0 * first - s[len - 2 - e];
        i += 1;
        e += 1;
    }
    if i < out.len() && e < 2 * len - 2 {
        let take = (out.len() - i).min(2 * len - 2 - e);
        let from = e - (len - 2);
        out[i..i + take].copy_from_slice(&s[from..from + take]);
        i += take;
        e += take;
    }
    while i < out.len() {
        out[i] = 2.0 * last - s[3 * len - 4 - e];
        i += 1;
        e += 1;
    }
}

/// Builds the doubly reflected series of SP1065 eq. (25) for the total variance (the reference
/// [`total_sum`] is tested against).
#[cfg(test)]
pub(crate) fn reflect_for_total(s: &[f64]) -> Vec<f64> {
    let len = s.len();
    let mut out = Vec::with_capacity(3 * len - 4);
    // x*_{-j} = 2 x_0 - x_j for j = L-2 down to 1
    for j in (1..=len - 2).rev() {
        out.push(2.0 * s[0] - s[j]);
    }
    out.extend_from_slice(s);
    // x*_{L-1+j} = 2 x_{L-1} - x_{L-1-j} for j = 1..=L-2
    for j in 1..=len - 2 {
        out.push(2.0 * s[len - 1] - s[len - 1 - j]);
    }
    out
}

/// The total variance numerator over a built reflected series (the reference of the tests).
#[cfg(test)]
pub(crate) fn total_sum_reflected(extended: &[f64], len: usize, m: usize) -> (f64, usize) {
    let n = len - 2;
    let centre = len - 1;
    (
        second_difference_sq_sum(
            &extended[centre - m..centre - m + n],
            &extended[centre..centre + n],
            &extended[centre + m..centre + m + n],
        ),
        n,
    )
}

/// Four consecutive values as an array (one bounds check; vectorises).
#[inline(always)]
fn quad(s: &[f64], j: usize) -> [f64; 4] {
    let q = &s[j..j + 4];
    [q[0], q[1], q[2], q[3]]
}

/// Sums, for the G taus m 2^i (i < G) of an octave run, of the squared second differences over
/// k in `k0..k1`: with a_i = s[k + 2^i m] - s[k], the second difference at 2^i m is
/// a_{i+1} - 2 a_i (one rounding; 2 a_i is exact). One load per tau and k instead of three,
/// shared by neighbouring taus; 4 lanes per tau so that LLVM keeps each tau's accumulator in a
/// vector register (portable version; x86-64 with AVX2+FMA uses [`octave_run_avx2`]).
#[inline(always)]
fn octave_run_body<const G: usize>(s: &[f64], m: usize, k0: usize, k1: usize) -> [f64; G] {
    const L: usize = 4;
    let mut out = [0.0f64; G];
    if k1 <= k0 {
        return out;
    }
    let n = k1 - k0;
    let base = &s[k0..k1];
    let first = &s[k0 + m..k1 + m];
    let w: [&[f64]; G] = std::array::from_fn(|i| &s[k0 + (m << (i + 1))..k1 + (m << (i + 1))]);
    let madd = |a: f64, b: f64, c: f64| a * b + c;
    let mut acc = [[0.0f64; L]; G];
    let full = n - n % L;
    let mut j = 0;
    while j < full {
        let b = quad(base, j);
        let f = quad(first, j);
        let mut prev = [f[0] - b[0], f[1] - b[1], f[2] - b[2], f[3] - b[3]];
        for (wi, ai) in w.iter().zip(acc.iter_mut()) {
            let x = quad(wi, j);
            let next = [x[0] - b[0], x[1] - b[1], x[2] - b[2], x[3] - b[3]];
            for l in 0..L {
                let d = madd(-2.0, prev[l], next[l]);
                ai[l] = madd(d, d, ai[l]);
            }
            prev = next;
        }
        j += L;
    }
    for j in full..n {
        let mut prev = first[j] - base[j];
        for i in 0..G {
            let next = w[i][j] - base[j];
            let d = madd(-2.0, prev, next);
            acc[i][0] = madd(d, d, acc[i][0]);
            prev = next;
        }
    }
    for i in 0..G {
        out[i] = (acc[i][0] + acc[i][2]) + (acc[i][1] + acc[i][3]);
    }
    out
}

/// AVX2+FMA version of [`octave_run_body`] with explicit vectors (LLVM's SLP vectoriser
/// transposes the portable body across taus, which is slower than scalar code).
///
/// # Safety
/// The CPU must support AVX2 and FMA. Every vector load reads 4 values from a slice that was
/// bounds-checked to hold them (`&x[j..j + 4]`), so no access leaves the record.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn octave_run_avx2<const G: usize>(s: &[f64], m: usize, k0: usize, k1: usize) -> [f64; G] {
    use std::arch::x86_64::*;
    let mut out = [0.0f64; G];
    if k1 <= k0 {
        return out;
    }
    let n = k1 - k0;
    let base = &s[k0..k1];
    let first = &s[k0 + m..k1 + m];
    let w: [&[f64]; G] = std::array::from_fn(|i| &s[k0 + (m << (i + 1))..k1 + (m << (i + 1))]);
    let load = |x: &[f64], j: usize| _mm256_loadu_pd(x[j..j + 4].as_ptr());
    let minus2 = _mm256_set1_pd(-2.0);
    let mut acc = [_mm256_setzero_pd(); G];
    let full = n - n % 4;
    let mut j = 0;
    while j < full {
        let b = load(base, j);
        let mut prev = _mm256_sub_pd(load(first, j), b);
        for i in 0..G {
            let next = _mm256_sub_pd(load(w[i], j), b);
            let d = _mm256_fmadd_pd(minus2, prev, next);
            acc[i] = _mm256_fmadd_pd(d, d, acc[i]);
            prev = next;
        }
        j += 4;
    }
    for i in 0..G {
        let mut lanes = [0.0f64; 4];
        _mm256_storeu_pd(lanes.as_mut_ptr(), acc[i]);
        out[i] = (lanes[0] + lanes[2]) + (lanes[1] + lanes[3]);
    }
    for j in full..n {
        let mut prev = first[j] - base[j];
        for i in 0..G {
            let next = w[i][j] - base[j];
            let d = (-2.0f64).mul_add(prev, next);
            out[i] = d.mul_add(d, out[i]);
            prev = next;
        }
    }
    out
}

/// AVX-512 version of [`octave_run_avx2`]: 8 lanes per vector and two accumulators per tau
/// (16 k per step), so that the FMA latency does not bound a run of few taus. On CPUs with a
/// 512-bit floating-point datapath (AMD Zen 5, Intel server cores) it does twice the work of
/// the AVX2 kernel per instruction.
///
/// # Safety
/// The CPU must support AVX-512F. Every vector load reads 8 values from a slice that was
/// bounds-checked to hold them (`&x[j..j + 8]`), so no access leaves the record.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
unsafe fn octave_run_avx512<const G: usize>(s: &[f64], m: usize, k0: usize, k1: usize) -> [f64; G] {
    use std::arch::x86_64::*;
    let mut out = [0.0f64; G];
    if k1 <= k0 {
        return out;
    }
    let n = k1 - k0;
    let base = &s[k0..k1];
    let first = &s[k0 + m..k1 + m];
    let w: [&[f64]; G] = std::array::from_fn(|i| &s[k0 + (m << (i + 1))..k1 + (m << (i + 1))]);
    let load = |x: &[f64], j: usize| _mm512_loadu_pd(x[j..j + 8].as_ptr());
    let minus2 = _mm512_set1_pd(-2.0);
    let mut acc0 = [_mm512_setzero_pd(); G];
    let mut acc1 = [_mm512_setzero_pd(); G];
    let full = n - n % 16;
    let mut j = 0;
    while j < full {
        let b0 = load(base, j);
        let b1 = load(base, j + 8);
        let mut p0 = _mm512_sub_pd(load(first, j), b0);
        let mut p1 = _mm512_sub_pd(load(first, j + 8), b1);
        for i in 0..G {
            let n0 = _mm512_sub_pd(load(w[i], j), b0);
            let n1 = _mm512_sub_pd(load(w[i], j + 8), b1);
            let d0 = _mm512_fmadd_pd(minus2, p0, n0);
            let d1 = _mm512_fmadd_pd(minus2, p1, n1);
            acc0[i] = _mm512_fmadd_pd(d0, d0, acc0[i]);
            acc1[i] = _mm512_fmadd_pd(d1, d1, acc1[i]);
            p0 = n0;
            p1 = n1;
        }
        j += 16;
    }
    for i in 0..G {
        out[i] = _mm512_reduce_add_pd(_mm512_add_pd(acc0[i], acc1[i]));
    }
    for j in full..n {
        let mut prev = first[j] - base[j];
        for i in 0..G {
            let next = w[i][j] - base[j];
            let d = (-2.0f64).mul_add(prev, next);
            out[i] = d.mul_add(d, out[i]);
            prev = next;
        }
    }
    out
}

fn octave_run_g<const G: usize>(s: &[f64], m: usize, k0: usize, k1: usize, out: &mut [f64]) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::is_x86_feature_detected!("avx512f") {
            // SAFETY: the CPU supports AVX-512F (checked just above); see the function's doc.
            let r = unsafe { octave_run_avx512::<G>(s, m, k0, k1) };
            out.iter_mut().zip(r).for_each(|(o, v)| *o += v);
            return;
        }
        if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
            // SAFETY: the CPU supports AVX2 and FMA (checked just above); see the function's doc.
            let r = unsafe { octave_run_avx2::<G>(s, m, k0, k1) };
            out.iter_mut().zip(r).for_each(|(o, v)| *o += v);
            return;
        }
    }
    let r = octave_run_body::<G>(s, m, k0, k1);
    out.iter_mut().zip(r).for_each(|(o, v)| *o += v);
}

/// Adds to `out[i]` the sum over k in `k0..k1` of the squared second difference at m 2^i,
/// for i < out.len() <= [`RUN_MAX`].
fn octave_run(s: &[f64], m: usize, k0: usize, k1: usize, out: &mut [f64]) {
    match out.len() {
        0 => {}
        1 => octave_run_g::<1>(s, m, k0, k1, out),
        2 => octave_run_g::<2>(s, m, k0, k1, out),
        3 => octave_run_g::<3>(s, m, k0, k1, out),
        4 => octave_run_g::<4>(s, m, k0, k1, out),
        5 => octave_run_g::<5>(s, m, k0, k1, out),
        6 => octave_run_g::<6>(s, m, k0, k1, out),
        7 => octave_run_g::<7>(s, m, k0, k1, out),
        _ => octave_run_g::<RUN_MAX>(s, m, k0, k1, &mut out[..RUN_MAX]),
    }
}

/// Portable version of [`spread_run_avx2`]: sums over k in `k0..k1` of the squared second
/// difference for each of G arbitrary factors `ms`, as (a_{2m} - 2 a_m) with a_j = s[k + j] - s[k].
#[inline(always)]
fn spread_run_body<const G: usize>(s: &[f64], ms: &[usize; G], k0: usize, k1: usize) -> [f64; G] {
    let mut out = [0.0f64; G];
    if k1 <= k0 {
        return out;
    }
    let base = &s[k0..k1];
    for (o, &m) in out.iter_mut().zip(ms) {
        let near = &s[k0 + m..k1 + m];
        let far = &s[k0 + 2 * m..k1 + 2 * m];
        *o = base
            .iter()
            .zip(near)
            .zip(far)
            .map(|((b, x), z)| {
                let d = (z - b) - 2.0 * (x - b);
                d * d
            })
            .sum();
    }
    out
}

/// AVX2+FMA sums for G arbitrary factors sharing the loads of s[k] (a consecutive tau list has
/// no shared windows otherwise): 2 loads, 2 subtractions and 2 FMAs per tau and 4 k.
///
/// # Safety
/// The CPU must support AVX2 and FMA. Every vector load reads 4 values from a slice that was
/// bounds-checked to hold them (`&x[j..j + 4]`), so no access leaves the record.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn spread_run_avx2<const G: usize>(s: &[f64], ms: &[usize; G], k0: usize, k1: usize) -> [f64; G] {
    use std::arch::x86_64::*;
    let mut out = [0.0f64; G];
    if k1 <= k0 {
        return out;
    }
    let n = k1 - k0;
    let base = &s[k0..k1];
    let near: [&[f64]; G] = std::array::from_fn(|i| &s[k0 + ms[i]..k1 + ms[i]]);
    let far: [&[f64]; G] = std::array::from_fn(|i| &s[k0 + 2 * ms[i]..k1 + 2 * ms[i]]);
    let load = |x: &[f64], j: usize| _mm256_loadu_pd(x[j..j + 4].as_ptr());
    let minus2 = _mm256_set1_pd(-2.0);
    let mut acc = [_mm256_setzero_pd(); G];
    let full = n - n % 4;
    let mut j = 0;
    while j < full {
        let b = load(base, j);
        for i in 0..G {
            let a = _mm256_sub_pd(load(near[i], j), b);
            let c = _mm256_sub_pd(load(far[i], j), b);
            let d = _mm256_fmadd_pd(minus2, a, c);
            acc[i] = _mm256_fmadd_pd(d, d, acc[i]);
        }
        j += 4;
    }
    for i in 0..G {
        let mut lanes = [0.0f64; 4];
        _mm256_storeu_pd(lanes.as_mut_ptr(), acc[i]);
        out[i] = (lanes[0] + lanes[2]) + (lanes[1] + lanes[3]);
        for j in full..n {
            let d = (-2.0f64).mul_add(near[i][j] - base[j], far[i][j] - base[j]);
            out[i] = d.mul_add(d, out[i]);
        }
    }
    out
}

fn spread_run_g<const G: usize>(s: &[f64], ms: &[usize], k0: usize, k1: usize, out: &mut [f64]) {
    let mut m = [0usize; G];
    m.copy_from_slice(&ms[..G]);
    #[cfg(target_arch = "x86_64")]
    {
        if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
            // SAFETY: the CPU supports AVX2 and FMA (checked just above); see the function's doc.
            let r = unsafe { spread_run_avx2::<G>(s, &m, k0, k1) };
            out.iter_mut().zip(r).for_each(|(o, v)| *o += v);
            return;
        }
    }
    let r = spread_run_body::<G>(s, &m, k0, k1);
    out.iter_mut().zip(r).for_each(|(o, v)| *o += v);
}

/// Adds to `out[i]` the sum over k in `k0..k1` of the squared second difference at `ms[i]`
/// (`ms.len() == out.len()`, at most [`RUN_MAX`]).
fn spread_run(s: &[f64], ms: &[usize], k0: usize, k1: usize, out: &mut [f64]) {
    match out.len() {
        0 => {}
        1 => spread_run_g::<1>(s, ms, k0, k1, out),
        2 => spread_run_g::<2>(s, ms, k0, k1, out),
        3 => spread_run_g::<3>(s, ms, k0, k1, out),
        4 => spread_run_g::<4>(s, ms, k0, k1, out),
        5 => spread_run_g::<5>(s, ms, k0, k1, out),
        6 => spread_run_g::<6>(s, ms, k0, k1, out),
        7 => spread_run_g::<7>(s, ms, k0, k1, out),
        _ => spread_run_g::<RUN_MAX>(s, ms, k0, k1, &mut out[..RUN_MAX]),
    }
}

/// Most taus summed in one fused pass (8 vector accumulators, registers to spare).
const RUN_MAX: usize = 8;

/// Overlapping-Allan sums for many averaging factors at once, cache-blocked over k.
///
/// The sorted factors are cut into runs of at most [`RUN_MAX`] in which each is twice the
/// previous (an octave list is one long run); a run is summed in one fused pass per block
/// ([`octave_run_body`]). The k range is cut into blocks of 4096; within a block every run is
/// summed before moving on, so the windows s[k + 2^i m ..] stay in cache, and the blocks run in
/// parallel (rayon). A tau whose last term lies inside a block (the staircase n_i = L - 2 m_i)
/// is fused up to the run's common end and finished alone. Blocks are grouped and combined in a
/// fixed order, so the sums do not depend on the number of threads.
pub(crate) fn overlapping_allan_sums(s: &[f64], ms: &[usize]) -> Vec<f64> {
    const BLOCK: usize = 1024;
    let len = s.len();
    // groups: (first index into ms, count, octave run?)
    let mut runs: Vec<(usize, usize, bool)> = Vec::new();
    for (i, &m) in ms.iter().enumerate() {
        match runs.last_mut() {
            Some((start, count, octave))
                if *count < RUN_MAX && ms[*start + *count - 1] * 2 == m && (*octave || *count == 1) =>
            {
                *count += 1;
                *octave = true;
            }
            Some((_, count, false)) if *count < RUN_MAX => *count += 1,
            _ => runs.push((i, 1, false)),
        }
    }
    let n_max = ms.iter().map(|&m| len.saturating_sub(2 * m)).max().unwrap_or(0);
    let blocks = n_max.div_ceil(BLOCK);
    // Fixed partition, independent of the thread count: the blocks are cut into at most
    // GROUPS_MAX consecutive groups (fewer for long tau lists, so that the per-group sums stay
    // within GROUP_BUDGET values); each group sums its blocks in order, and the groups' sums are
    // added in group order. The result is bit-identical whatever rayon's schedule.
    const GROUPS_MAX: usize = 64;
    const GROUP_BUDGET: usize = 1 << 22;
    let groups = (GROUP_BUDGET / ms.len().max(1)).clamp(1, GROUPS_MAX).min(blocks.max(1));
    let per_group = blocks.div_ceil(groups).max(1);
    let partial: Vec<Vec<f64>> = super::map_indices(len, groups, |g| {
        let mut acc = vec![0.0f64; ms.len()];
        for b in g * per_group..((g + 1) * per_group).min(blocks) {
            sum_block(s, ms, &runs, b * BLOCK, BLOCK, &mut acc);
        }
        acc
    });
    let mut total = vec![0.0f64; ms.len()];
    for acc in &partial {
        total.iter_mut().zip(acc).for_each(|(t, v)| *t += v);
    }
    total
}

/// Adds to `acc` the sums of every run over k in `k0..k0 + block` (see [`overlapping_allan_sums`]).
fn sum_block(s: &[f64], ms: &[usize], runs: &[(usize, usize, bool)], k0: usize, block: usize, acc: &mut [f64]) {
    let len = s.len();
    for &(start, count, octave) in runs {
        let n_of = |i: usize| len.saturating_sub(2 * ms[i]);
        // taus of a group sorted by m, so their term counts decrease along it
        let active = (0..count).take_while(|&i| n_of(start + i) > k0).count();
        if active == 0 {
            continue;
        }
        let common_end = (k0 + block).min(n_of(start + active - 1));
        let slots = &mut acc[start..start + active];
        if octave {
            octave_run(s, ms[start], k0, common_end, slots);
        } else {
            spread_run(s, &ms[start..start + active], k0, common_end, slots);
        }
        for i in 0..active - 1 {
            let end = (k0 + block).min(n_of(start + i));
            if end > common_end {
                spread_run(s, &ms[start + i..start + i + 1], common_end, end, &mut acc[start + i..start + i + 1]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The streamed total variance sum equals, bit for bit, the sum over the built reflected
    /// series (SP1065 eq. 25), portable and AVX2, for lengths around the block and lane sizes
    /// and every lag from 1 to L - 2.
    #[test]
    fn total_sum_streamed_equals_the_built_reflection_bit_for_bit() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for len in [3usize, 4, 17, 18, 35, 1023, 1026, 2051, 3000, 5000] {
            let mut s = vec![0.0];
            for _ in 1..len {
                let last = s[s.len() - 1];
                s.push(last + next());
            }
            let extended = reflect_for_total(&s);
            let lags: Vec<usize> =
                if len < 40 { (1..=len - 2).collect() } else { vec![1, 2, 7, 16, 100, len / 2, len - 2] };
            for m in lags {
                let want = total_sum_reflected(&extended, len, m);
                assert_eq!(total_sum_body(&s, m).0.to_bits(), want.0.to_bits(), "len {len} m {m}");
                assert_eq!(total_sum(&s, m), want, "len {len} m {m}");
            }
        }
    }

    /// The octave-run kernels (portable, AVX2, AVX-512 where the CPU has them) against the
    /// three-view sum of [`second_difference_sq_sum`] at each tau, on records and ranges that
    /// leave every kind of remainder (not a multiple of 4, 8 or 16 k).
    fn check_octave_kernels(s: &[f64], m: usize, k0: usize, k1: usize) -> Result<(), TestCaseError> {
        const G: usize = 5;
        let plain: Vec<f64> = (0..G)
            .map(|i| {
                let mi = m << i;
                second_difference_sq_sum(&s[k0..k1], &s[k0 + mi..k1 + mi], &s[k0 + 2 * mi..k1 + 2 * mi])
            })
            .collect();
        let mut got: Vec<(&str, [f64; G])> = vec![("portable", octave_run_body::<G>(s, m, k0, k1))];
        #[cfg(target_arch = "x86_64")]
        {
            if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
                // SAFETY: checked just above.
                got.push(("avx2", unsafe { octave_run_avx2::<G>(s, m, k0, k1) }));
            } else {
                eprintln!("SKIPPED: the AVX2 octave kernel (this CPU has no AVX2+FMA)");
            }
            if std::is_x86_feature_detected!("avx512f") {
                // SAFETY: checked just above.
                got.push(("avx512", unsafe { octave_run_avx512::<G>(s, m, k0, k1) }));
            } else {
                eprintln!("SKIPPED: the AVX-512 octave kernel (this CPU has no AVX-512F)");
            }
        }
        for (name, sums) in got {
            for (i, (a, b)) in sums.iter().zip(&plain).enumerate() {
                prop_assert!((a - b).abs() <= 1e-12 * b.abs().max(1e-300), "{} tau {}: {} vs {}", name, i, a, b);
            }
        }
        Ok(())
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]
        #[test]
        fn octave_kernels_equal_the_three_view_sums(
            y in prop::collection::vec(-1e3f64..1e3, 200..1200),
            m in 1usize..6,
            k0 in 0usize..40,
            len in 0usize..100,
        ) {
            let mut s = vec![0.0];
            for v in &y {
                s.push(s[s.len() - 1] + v);
            }
            let k1 = (k0 + len).min(s.len() - 2 * (m << 4));
            let k0 = k0.min(k1);
            check_octave_kernels(&s, m, k0, k1)?;
        }
    }
}
