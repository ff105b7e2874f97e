//! Rows of one layout read eight at a time with AVX-512: the vector form of the batch loop of
//! [`super::read_rows`] (`planned_rows`), for CPUs that have AVX-512 F, DQ and BW.
//!
//! Each lane of a vector is one row. The fields of eight rows are found from the positions of
//! the delimiters and line ends (one byte compare per 64 bytes); then, field by field, each
//! lane does what [`super::shaped_field`] does for its row: the same masked check of every
//! byte against the field's [`FieldShape`], the same SWAR digit arithmetic (64-bit lanes, the
//! same wrapping operations), the same conversion and the same single correctly rounded
//! multiplication or division by an exact power of ten. The values are therefore bit for bit
//! those of the scalar loop, which the property test `vector_rows_equal_the_scalar_rows` checks
//! (and, through [`super::read_rows`], the tests against `fast-float2`). A group of eight rows
//! in which a row does not fit keeps the rows before it; the scalar loop goes on from there.
//!
//! Field positions from the delimiters agree with the scalar loop's (each field starting where
//! the one before ends) whenever the checks pass: a field that fits its shape has no delimiter
//! or line end inside it and its end bytes exactly where the shape puts them. (This needs a
//! delimiter that is none of a number's bytes, digits, `.`, `e`, `E`, `+`, `-`, nor `\r` or
//! `\n`: so are `,`, `;` and tab, the delimiters of the row fast path.) The field starts of a
//! group increase (each is one past a later separator), so the window check of the last one
//! covers them all.

use super::{FieldShape, MAX_PLANNED_FIELDS, MEDIUM, ONES, OTHER, PLANNED_VALUES, POW10, POW10_U64, SMALL, WINDOW};
use std::arch::x86_64::*;

/// Whether this CPU has the instructions [`planned_groups`] uses (AVX-512 F, DQ and BW).
pub(super) fn available() -> bool {
    std::is_x86_feature_detected!("avx512f")
        && std::is_x86_feature_detected!("avx512dq")
        && std::is_x86_feature_detected!("avx512bw")
}

/// Whether rows of `plan` can be read here: every field has no exponent or one of a sign and
/// two digits that [`super::shaped_field`] reads in one step (`%e`), and at most
/// [`MAX_PLANNED_FIELDS`] fields.
pub(super) fn supports(plan: &[FieldShape]) -> bool {
    !plan.is_empty()
        && plan.len() <= MAX_PLANNED_FIELDS
        && plan.iter().all(|s| match s.kind {
            SMALL | MEDIUM => s.exp_digits == 0 || s.exp_in_run,
            OTHER => s.exp_digits == 0,
            _ => false,
        })
}

/// Bit i set where byte `at + i` is `delim` or `\n` (`at + 64 <= b.len()`).
#[inline(always)]
unsafe fn separators(b: &[u8], at: usize, delim: __m512i, line_end: __m512i) -> u64 {
    let v = _mm512_loadu_si512(b[at..at + 64].as_ptr().cast());
    _mm512_cmpeq_epi8_mask(v, delim) | _mm512_cmpeq_epi8_mask(v, line_end)
}

/// [`super::eight_digits`] in each lane.
#[inline(always)]
unsafe fn eight_digits(v: __m512i, shift: u8) -> __m512i {
    let d = _mm512_sll_epi64(
        _mm512_sub_epi64(v, _mm512_set1_epi64((0x30 * ONES) as i64)),
        _mm_cvtsi64_si128(i64::from(shift & 63)),
    );
    let pairs = _mm512_add_epi64(_mm512_mullo_epi64(d, _mm512_set1_epi64(10)), _mm512_srli_epi64::<8>(d));
    let m = _mm512_set1_epi64(0x0000_00ff_0000_00ff);
    let lo = _mm512_and_si512(pairs, m);
    let hi = _mm512_and_si512(_mm512_srli_epi64::<16>(pairs), m);
    let a = _mm512_mullo_epi64(lo, _mm512_set1_epi64(100 + (1_000_000 << 32)));
    let c = _mm512_mullo_epi64(hi, _mm512_set1_epi64(1 + (10_000 << 32)));
    _mm512_srli_epi64::<32>(_mm512_add_epi64(a, c))
}

/// `(lo | hi << 64) >> bits` truncated to 64 bits, in each lane, for `bits < 128`.
#[inline(always)]
unsafe fn funnel(lo: __m512i, hi: __m512i, bits: u32) -> __m512i {
    if bits >= 64 {
        _mm512_srl_epi64(hi, _mm_cvtsi64_si128(i64::from(bits - 64)))
    } else {
        // (With `bits` 0, the count 64 gives zero.)
        _mm512_or_si512(
            _mm512_srl_epi64(lo, _mm_cvtsi64_si128(i64::from(bits))),
            _mm512_sll_epi64(hi, _mm_cvtsi64_si128(i64::from(64 - bits))),
        )
    }
}

/// `(w_k & !keep) | ((w_k >> 8 | w_next << 56) & keep')`: the digits after the point shifted
/// down over it (see [`super::shaped_field`]).
#[inline(always)]
unsafe fn over_point(w: __m512i, next: __m512i, keep: u64) -> __m512i {
    let keep = _mm512_set1_epi64(keep as i64);
    let shifted = _mm512_or_si512(_mm512_srli_epi64::<8>(w), _mm512_slli_epi64::<56>(next));
    _mm512_or_si512(_mm512_and_si512(w, keep), _mm512_andnot_si512(keep, shifted))
}

/// The first four words (32 bytes) from each of eight starts, as four vectors: word k of row r in
/// lane r of vector k. (Eight loads and a transposition: cheaper here than gathers.) Every start
/// is at least 32 bytes before the end of `b`.
#[inline(always)]
unsafe fn windows(b: &[u8], starts: &[u64; 8]) -> [__m512i; 4] {
    let (z01, z23, z45, z67) =
        (rows_pair(b, starts, 0), rows_pair(b, starts, 2), rows_pair(b, starts, 4), rows_pair(b, starts, 6));
    // Words 0 and 1 (then 2 and 3) of four rows.
    let first = _mm512_setr_epi64(0, 4, 8, 12, 1, 5, 9, 13);
    let second = _mm512_setr_epi64(2, 6, 10, 14, 3, 7, 11, 15);
    let a01 = _mm512_permutex2var_epi64(z01, first, z23);
    let a23 = _mm512_permutex2var_epi64(z01, second, z23);
    let b01 = _mm512_permutex2var_epi64(z45, first, z67);
    let b23 = _mm512_permutex2var_epi64(z45, second, z67);
    [
        _mm512_shuffle_i64x2::<0x44>(a01, b01),
        _mm512_shuffle_i64x2::<0xee>(a01, b01),
        _mm512_shuffle_i64x2::<0x44>(a23, b23),
        _mm512_shuffle_i64x2::<0xee>(a23, b23),
    ]
}

/// The 32 bytes from `starts[r]` and from `starts[r + 1]`, in one vector. (A function, not a
/// closure: closures do not get the caller's target features and are not inlined.)
#[inline(always)]
unsafe fn rows_pair(b: &[u8], starts: &[u64; 8], r: usize) -> __m512i {
    let load = |r: usize| b[starts[r] as usize..starts[r] as usize + 32].as_ptr().cast::<__m256i>();
    _mm512_inserti64x4::<1>(_mm512_castsi256_si512(_mm256_loadu_si256(load(r))), _mm256_loadu_si256(load(r + 1)))
}

/// `lo >> right | hi << left` in each lane (a shift by 64 gives zero): a word of a field that
/// starts `right / 8` bytes into `lo`.
#[inline(always)]
unsafe fn word(lo: __m512i, hi: __m512i, right: __m512i, left: __m512i) -> __m512i {
    _mm512_or_si512(_mm512_srlv_epi64(lo, right), _mm512_sllv_epi64(hi, left))
}

/// 10^k in each lane, for k in 0..=22 (from [`POW10`] by two table permutations).
#[inline(always)]
unsafe fn power_of_ten(k: __m512i) -> __m512d {
    let low = _mm512_permutex2var_pd(_mm512_loadu_pd(POW10[..8].as_ptr()), k, _mm512_loadu_pd(POW10[8..16].as_ptr()));
    // Lane j: 10^(16 + j) (k & 7 is j for k in 16..=22; lane 7 is not used).
    let high = _mm512_permutexvar_pd(
        k,
        _mm512_setr_pd(POW10[16], POW10[17], POW10[18], POW10[19], POW10[20], POW10[21], POW10[22], POW10[22]),
    );
    _mm512_mask_blend_pd(_mm512_cmpge_epu64_mask(k, _mm512_set1_epi64(16)), low, high)
}

/// `x` with the sign bits of `sign_bits` set.
#[inline(always)]
unsafe fn with_sign(x: __m512d, sign_bits: __m512i) -> __m512d {
    _mm512_castsi512_pd(_mm512_or_si512(_mm512_castpd_si512(x), sign_bits))
}

/// The values of one field in eight rows whose fields start at `starts` (the sign, if any,
/// included), and the lanes where the field does not fit `shape`. Every start is at least
/// `WINDOW + 8` bytes before the end of `b`.
#[inline(always)]
unsafe fn field_values(b: &[u8], starts: &[u64; 8], shape: &FieldShape) -> (__m512d, u8) {
    // Words from the first byte; a sign moves them on by one byte.
    let [raw0, raw1, raw2, raw3] = windows(b, starts);
    let c0 = _mm512_and_si512(raw0, _mm512_set1_epi64(0xff));
    let negative = _mm512_cmpeq_epi64_mask(c0, _mm512_set1_epi64(i64::from(b'-')));
    let signed = negative | _mm512_cmpeq_epi64_mask(c0, _mm512_set1_epi64(i64::from(b'+')));
    let right = _mm512_maskz_mov_epi64(signed, _mm512_set1_epi64(8));
    let left = _mm512_sub_epi64(_mm512_set1_epi64(64), right);
    let (w0, w1, w2) = (word(raw0, raw1, right, left), word(raw1, raw2, right, left), word(raw2, raw3, right, left));
    // The shape's check, word by word.
    let mut bad: u8 = 0;
    for (k, w) in [w0, w1, w2].into_iter().enumerate().take(usize::from(shape.words)) {
        let y = _mm512_xor_si512(
            _mm512_and_si512(w, _mm512_set1_epi64(shape.fold[k] as i64)),
            _mm512_set1_epi64(shape.target[k] as i64),
        );
        let low = _mm512_and_si512(y, _mm512_set1_epi64((0x7f * ONES) as i64));
        let sum = _mm512_or_si512(_mm512_add_epi64(low, _mm512_set1_epi64(shape.add[k] as i64)), y);
        bad |= _mm512_test_epi64_mask(sum, _mm512_set1_epi64(shape.care[k] as i64));
    }
    let sign_bits = _mm512_maskz_mov_epi64(negative, _mm512_set1_epi64(i64::MIN));
    let lo = over_point(w0, w1, shape.before_point as u64);
    let significand = match shape.kind {
        SMALL => eight_digits(lo, shape.run_shift[0]),
        MEDIUM => {
            let hi = over_point(w1, w2, (shape.before_point >> 64) as u64);
            _mm512_add_epi64(
                _mm512_mullo_epi64(eight_digits(lo, 0), _mm512_set1_epi64(shape.high_weight as i64)),
                eight_digits(hi, shape.run_shift[1]),
            )
        }
        _ => {
            // An integer of 17 to 19 digits (`digits_at`), converted from u64.
            let n = usize::from(shape.int_digits);
            let first = _mm512_add_epi64(
                _mm512_mullo_epi64(eight_digits(w0, 0), _mm512_set1_epi64(100_000_000)),
                eight_digits(w1, 0),
            );
            let rest = eight_digits(w2, (64 - 8 * (n - 16).min(8)) as u8);
            let w = _mm512_add_epi64(_mm512_mullo_epi64(first, _mm512_set1_epi64(POW10_U64[n - 16] as i64)), rest);
            return (with_sign(_mm512_cvtepu64_pd(w), sign_bits), bad);
        }
    };
    // Below 10^16: exact or correctly rounded, as `as i64 as f64`.
    let x = _mm512_cvtepi64_pd(significand);
    if shape.exp_digits == 0 {
        return (with_sign(_mm512_div_pd(x, _mm512_set1_pd(shape.divisor)), sign_bits), bad);
    }
    // `e-05`: the sign and two digits from one shift of the first two words.
    let run = funnel(w0, w1, 8 * (u32::from(shape.exp_at) - 1));
    let c = _mm512_and_si512(run, _mm512_set1_epi64(0xff));
    let negative_exp = _mm512_cmpeq_epi64_mask(c, _mm512_set1_epi64(i64::from(b'-')));
    let sign_ok = negative_exp | _mm512_cmpeq_epi64_mask(c, _mm512_set1_epi64(i64::from(b'+')));
    let nibble = _mm512_set1_epi64(0xf);
    let e = _mm512_add_epi64(
        _mm512_mullo_epi64(_mm512_and_si512(_mm512_srli_epi64::<8>(run), nibble), _mm512_set1_epi64(10)),
        _mm512_and_si512(_mm512_srli_epi64::<16>(run), nibble),
    );
    let signed_e = _mm512_mask_sub_epi64(e, negative_exp, _mm512_setzero_si512(), e);
    let p = _mm512_sub_epi64(signed_e, _mm512_set1_epi64(i64::from(shape.frac_digits)));
    let magnitude = _mm512_abs_epi64(p);
    let exact = _mm512_cmple_epu64_mask(magnitude, _mm512_set1_epi64(22));
    let power = power_of_ten(_mm512_maskz_mov_epi64(exact, magnitude));
    let up = _mm512_cmpge_epi64_mask(p, _mm512_setzero_si512());
    let v = _mm512_mask_blend_pd(up, _mm512_div_pd(x, power), _mm512_mul_pd(x, power));
    (with_sign(v, sign_bits), bad | !(sign_ok & exact))
}

/// Reads groups of eight rows from `p` that fit `plan` (fields separated by `delim`, rows ended
/// by `\n`; see [`supports`]) into `buf` (field `ci` of row `r` at `ci * batch + r`), as long as a
/// whole group fits in `batch` rows and in `b` (with the window the checks read): returns where
/// it stopped and the rows read. A group with a row that does not fit keeps the rows before it.
///
/// # Safety
/// The CPU must have AVX-512 F, DQ and BW ([`available`]). Every load is of a bounds-checked
/// slice: 64-byte blocks for the separators, 32 bytes from each field start (each at least
/// `WINDOW + 8` bytes before the end of `b`).
#[target_feature(enable = "avx512f,avx512dq,avx512bw")]
pub(super) unsafe fn planned_groups(
    b: &[u8],
    mut p: usize,
    plan: &[FieldShape],
    delim: u8,
    buf: &mut [f64; PLANNED_VALUES],
    batch: usize,
) -> (usize, usize) {
    let nf = plan.len();
    let mut r = 0;
    if nf == 0 || nf > MAX_PLANNED_FIELDS || p + 64 > b.len() {
        return (p, 0);
    }
    let (delim, line_end) = (_mm512_set1_epi8(delim as i8), _mm512_set1_epi8(b'\n' as i8));
    let mut starts = [[0u64; 8]; MAX_PLANNED_FIELDS];
    let mut block = p;
    let mut found = separators(b, block, delim, line_end);
    while r + 8 <= batch {
        // Where each field of the next eight rows starts: after the separator before it.
        let mut at = p;
        for k in 0..8 {
            for row_starts in starts.iter_mut().take(nf) {
                row_starts[k] = at as u64;
                while found == 0 {
                    block += 64;
                    if block + 64 > b.len() {
                        return (p, r);
                    }
                    found = separators(b, block, delim, line_end);
                }
                at = block + found.trailing_zeros() as usize + 1;
                found &= found - 1;
            }
        }
        if starts[nf - 1][7] as usize + WINDOW + 8 > b.len() {
            return (p, r);
        }
        let mut bad = 0u8;
        for (ci, shape) in plan.iter().enumerate() {
            let (v, misfit) = field_values(b, &starts[ci], shape);
            bad |= misfit;
            _mm512_storeu_pd(buf[ci * batch + r..ci * batch + r + 8].as_mut_ptr(), v);
        }
        if bad != 0 {
            let good = bad.trailing_zeros() as usize;
            return (starts[0][good] as usize, r + good);
        }
        r += 8;
        p = at;
    }
    (p, r)
}
