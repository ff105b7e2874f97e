//! Fast, exact reading of the numbers logs are written with (`-12.3456`, `+0.5`, `7`,
//! `-1.2345670e-02`, nanosecond stamps `1700000000002500096`) from text rows.
//!
//! Exactness: a decimal with at most 15 significant digits has a significand w < 10^15, exact in
//! f64; with a power 10^p, |p| <= 22 (the point and the exponent together), also exact, w x 10^p
//! is one correctly rounded multiplication or division: the value every correct parser returns
//! (Clinger 1990, "How to read floating point numbers accurately", the fast path). An integer of
//! at most 19 digits is below 2^64, and its conversion to f64 is one correctly rounded operation
//! too. Anything else is left to the full parser (`fast-float2`) by returning `None`.
//!
//! Speed: digits are read eight at a time (SWAR: "SIMD within a register", one `u64` per eight
//! bytes), and the rows of a long record, which nearly always repeat the layout of the row
//! before, are read against a remembered [`FieldShape`] per column: every byte of a field (its
//! digits, point, exponent and end character) is checked where the shape puts it, a word at a
//! time, so no field waits for the previous one to be scanned. Once every column has a
//! shape, rows are read a batch at a time by a loop over the shapes alone ([`read_rows`]). A
//! row that does not fit is scanned field by field (its shapes taken for the rows after), and a
//! row that does not fit that either is left to the general reader ([`crate::series`]), which
//! reads or reports it.

#[cfg(target_arch = "x86_64")]
mod avx512;

/// Exact powers of ten representable in f64 (10^0 to 10^22).
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20,
    1e21, 1e22,
];

/// Powers of ten as integers (10^0 to 10^15).
const POW10_U64: [u64; 16] = {
    let mut t = [1u64; 16];
    let mut k = 1;
    while k < 16 {
        t[k] = t[k - 1] * 10;
        k += 1;
    }
    t
};

/// Most significant digits read by the fast paths (w < 10^15 stays exact in f64).
const MAX_DIGITS: usize = 15;

/// One in every byte of a word.
const ONES: u64 = 0x0101_0101_0101_0101;

/// Eight bytes from `i` (little-endian, so the first byte is the lowest), zero-padded past the end.
#[inline(always)]
fn load8(b: &[u8], i: usize) -> u64 {
    let mut a = [0u8; 8];
    match b.get(i..i + 8) {
        Some(s) => a.copy_from_slice(s),
        None => {
            let rest = b.get(i..).unwrap_or(&[]);
            a[..rest.len()].copy_from_slice(rest);
        }
    }
    u64::from_le_bytes(a)
}

/// How many of the eight bytes in `v`, from the first, are ASCII digits (0 to 8).
///
/// A byte is a digit when neither `b + 0x46` (b > b'9') nor `b - 0x30` (b < b'0') sets its top
/// bit. Carries and borrows only move towards later bytes, and every byte before the first
/// non-digit is a digit (no carry, no borrow), so the first non-digit is found exactly.
#[inline(always)]
fn leading_digits(v: u64) -> usize {
    let non_digit = (v.wrapping_add(0x46 * ONES) | v.wrapping_sub(0x30 * ONES)) & (0x80 * ONES);
    (non_digit.trailing_zeros() / 8) as usize
}

/// The value of the first `n` (0 to 8) bytes of `v`, all ASCII digits, by SWAR: the digits are
/// moved to the top bytes (zeros below act as leading zeros), then pairs, quads and the two
/// halves are combined with three multiplications.
#[inline(always)]
fn digits_value(v: u64, n: usize) -> u64 {
    if n == 0 {
        return 0;
    }
    eight_digits(v, (64 - 8 * n.min(8)) as u8)
}

/// Reads a run of digits from `i`, eight at a time, appending them to `w` (the value of the
/// digits before, with at most 19 - `limit` digits): returns (value, digits read, next index), or
/// `None` when more than `limit` digits follow (leading zeros count), so the value keeps at most
/// 19 digits (below 10^19 < 2^64).
#[inline(always)]
fn digit_run(b: &[u8], mut i: usize, mut w: u64, limit: usize) -> Option<(u64, usize, usize)> {
    let mut digits = 0;
    loop {
        let v = load8(b, i);
        let n = leading_digits(v);
        digits += n;
        if digits > limit {
            return None;
        }
        // No overflow: w has at most 19 - n digits before, so w < 10^19 after.
        w = w * POW10_U64[n] + digits_value(v, n);
        i += n;
        if n < 8 {
            return Some((w, digits, i));
        }
    }
}

/// `v` (>= 0) negated when `negative`, without a branch: the sign of a log's numbers is often
/// random (noise about zero), and a branch on it would be mispredicted half the time.
#[inline(always)]
fn with_sign(v: f64, negative: bool) -> f64 {
    f64::from_bits(v.to_bits() | (u64::from(negative) << 63))
}

/// The value w / 10^decimals with its sign: one correctly rounded division (w < 10^15).
#[inline(always)]
fn exact_quotient(w: u64, decimals: usize, negative: bool) -> f64 {
    with_sign(w as f64 / POW10[decimals], negative)
}

/// A scanned plain decimal `[+-]digits[.digits]` from `start` (at most 15 digits, at least one).
struct ScannedDecimal {
    /// The digits as an integer (< 10^15).
    significand: u64,
    /// Digits after the point.
    frac_digits: usize,
    /// Whether the sign is `-`.
    negative: bool,
    /// Index of the first byte after the number.
    end: usize,
}

impl ScannedDecimal {
    /// Scans from `start`; `None` when there is no digit or more than 15 of them.
    #[inline(always)]
    fn scan(b: &[u8], start: usize) -> Option<ScannedDecimal> {
        let c0 = b.get(start).copied();
        let negative = c0 == Some(b'-');
        let q = start + usize::from(negative || c0 == Some(b'+'));
        let (int_w, int_digits, i) = digit_run(b, q, 0, MAX_DIGITS)?;
        let (significand, frac_digits, end) =
            if b.get(i) == Some(&b'.') { digit_run(b, i + 1, int_w, MAX_DIGITS - int_digits)? } else { (int_w, 0, i) };
        (int_digits + frac_digits > 0).then_some(ScannedDecimal { significand, frac_digits, negative, end })
    }

    /// The value: one correctly rounded division.
    #[inline(always)]
    fn value(&self) -> f64 {
        exact_quotient(self.significand, self.frac_digits, self.negative)
    }
}

/// Fast path for the plain decimals that fill most logs (`-12.3456`, `+0.5`, `7`): at most 15
/// significant digits, no exponent (see the module notes for why the value is exact). Returns
/// the value and the bytes used, or `None` for anything else (left to the full parser).
#[inline]
pub fn plain_decimal(b: &[u8]) -> Option<(f64, usize)> {
    let d = ScannedDecimal::scan(b, 0)?;
    match b.get(d.end) {
        Some(b'.') => None,
        Some(b'e' | b'E') => exponent_decimal(b, &d),
        _ => Some((d.value(), d.end)),
    }
}

/// A decimal with an exponent (`-1.2345670e-02`, as `printf("%e")` and `np.savetxt` write
/// them): w x 10^p with w < 10^15 the digits and p = exponent - digits after the point. For
/// |p| <= 22 both w and 10^p are exact doubles, so one multiplication (p >= 0) or division
/// (p < 0) is correctly rounded (Clinger 1990, the fast path); other exponents are left to the
/// full parser (`None`).
#[inline]
fn exponent_decimal(b: &[u8], d: &ScannedDecimal) -> Option<(f64, usize)> {
    let mut i = d.end + 1;
    let negative_exp = match b.get(i) {
        Some(b'-') => {
            i += 1;
            true
        }
        Some(b'+') => {
            i += 1;
            false
        }
        _ => false,
    };
    let start = i;
    let mut e: i32 = 0;
    while let Some(c) = b.get(i).filter(|c| c.is_ascii_digit()) {
        if i - start >= 3 {
            return None;
        }
        e = e * 10 + i32::from(c - b'0');
        i += 1;
    }
    if i == start || matches!(b.get(i), Some(b'.' | b'e' | b'E')) {
        return None;
    }
    let p = if negative_exp { -e } else { e } - d.frac_digits as i32;
    if !(-22..=22).contains(&p) {
        return None;
    }
    let w = d.significand as f64;
    let v = if p >= 0 { w * POW10[p as usize] } else { w / POW10[(-p) as usize] };
    Some((if d.negative { -v } else { v }, i))
}

/// Bytes of the window a shape is checked in, from the first byte after the sign (three words
/// for the masks, and room for an eight-byte load at any digit of them). A field is read
/// against its shape only when 40 bytes from its first byte (its sign, if any) are in the
/// buffer; fields closer to the end are scanned.
const WINDOW: usize = 32;

/// Most bytes a shape covers after the sign, its end bytes included (the delimiter, or the line
/// end: `\n`, or `\r\n`), in three words.
const SHAPE_BYTES: usize = 24;

/// Most digits of an integer without a point or exponent: w < 10^19 < 2^64, and `w as f64` is
/// one correctly rounded conversion.
const MAX_INTEGER_DIGITS: usize = 19;

/// The layout of a number after its sign and of the bytes that end it: digits before the point,
/// whether there is a point, digits after it, the exponent's sign and digits, the end character
/// (and the `\n` after a `\r`); with the masks that check a field against it a word at a time.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct FieldShape {
    /// Digits before the point.
    int_digits: u8,
    /// Digits after the point.
    frac_digits: u8,
    /// Digits of the exponent (0: no exponent).
    exp_digits: u8,
    /// Whether the exponent has a sign (`e-05`, `e+05`; else `e05`).
    exp_signed: bool,
    /// Bytes from the first digit to the next field (the end bytes included).
    step: u8,
    /// Words of the window the check reads (1 to 3: those the shape covers).
    words: u8,
    /// Per word, the check of [`shaped_field`]: each byte is masked (bit 5 of the exponent's
    /// `e` cleared, so that `e` and `E` are one), xored with `target` (`0` at digits, the
    /// expected character elsewhere) and must then be at most 9 at a digit and 0 at a
    /// character: `add` holds 0x7f minus that limit, `care` the top bit of every byte checked
    /// (all but the exponent's sign, checked apart, and the bytes after the field).
    fold: [u64; 3],
    /// See `fold`.
    target: [u64; 3],
    /// See `fold`.
    add: [u64; 3],
    /// See `fold`.
    care: [u64; 3],
    /// The bytes before the point (all ones): the digits after it, shifted down over the
    /// point, join those before it in one run.
    before_point: u128,
    /// How the value is made: [`SMALL`], [`MEDIUM`] or [`OTHER`] (read by
    /// [`shaped_field`]).
    kind: u8,
    /// Bits the first (and second) eight digits of the run are shifted up by, so that they fill
    /// the top bytes of their word.
    run_shift: [u8; 2],
    /// 10^(digits - 8): the weight of the first eight digits when there are more.
    high_weight: u64,
    /// 10^(digits after the point): the divisor of a number without an exponent.
    divisor: f64,
    /// Where the exponent's digits start in the window, and their shift (as `run_shift`).
    exp_at: u8,
    /// The shift of the exponent's digits.
    exp_shift: u8,
    /// Whether the exponent is a sign and two digits inside the first two words (`e-05`, as
    /// `%e` writes it), read in one step.
    exp_in_run: bool,
}

/// [`FieldShape::kind`]: at most 8 digits (point and exponent as the shape says).
const SMALL: u8 = 0;
/// [`FieldShape::kind`]: 9 to 16 digits.
const MEDIUM: u8 = 1;
/// [`FieldShape::kind`]: 17 to 19 digits (an integer).
const OTHER: u8 = 2;

impl FieldShape {
    /// The shape of `int_digits[.frac_digits][e[+-]exp_digits]` followed by `end` (the end
    /// character, then `\n` after a `\r`); `None` when it does not fit the fast path (more than
    /// 15 digits, or 19 for an integer; more than 24 bytes with the end bytes).
    fn new(
        int_digits: usize,
        has_point: bool,
        frac_digits: usize,
        exp: Option<(bool, usize)>,
        end: &[u8],
    ) -> Option<FieldShape> {
        let digits = int_digits + frac_digits;
        let integer = !has_point && exp.is_none();
        let most = if integer { MAX_INTEGER_DIGITS } else { MAX_DIGITS };
        let mantissa = digits + usize::from(has_point);
        let (exp_signed, exp_digits) = exp.unwrap_or((false, 0));
        let exp_len = if exp.is_some() { 1 + usize::from(exp_signed) + exp_digits } else { 0 };
        let len = mantissa + exp_len;
        let step = len + end.len();
        if digits == 0 || digits > most || step > SHAPE_BYTES || (exp.is_some() && !(1..=3).contains(&exp_digits)) {
            return None;
        }
        let (mut fold, mut target, mut add, mut care) = ([u64::MAX; 3], [0u64; 3], [0u64; 3], [0u64; 3]);
        // Byte k must be `c` to `c + limit` (under `mask`).
        let mut set = |k: usize, mask: u8, c: u8, limit: u8| {
            let at = 8 * (k % 8);
            fold[k / 8] &= !(u64::from(!mask) << at);
            target[k / 8] |= u64::from(c & mask) << at;
            add[k / 8] |= u64::from(0x7f - limit) << at;
            care[k / 8] |= 0x80 << at;
        };
        let exp_digits_from = mantissa + 1 + usize::from(exp_signed);
        for k in (0..int_digits).chain(int_digits + usize::from(has_point)..mantissa).chain(exp_digits_from..len) {
            set(k, 0xff, b'0', 9);
        }
        if has_point {
            set(int_digits, 0xff, b'.', 0);
        }
        if exp.is_some() {
            set(mantissa, 0xdf, b'E', 0);
        }
        for (i, &c) in end.iter().enumerate() {
            set(len + i, 0xff, c, 0);
        }
        let before_point = if int_digits >= 16 || !has_point { u128::MAX } else { (1u128 << (8 * int_digits)) - 1 };
        let kind = match digits {
            0..=8 => SMALL,
            9..=16 => MEDIUM,
            _ => OTHER,
        };
        Some(FieldShape {
            kind,
            run_shift: [(64 - 8 * digits.min(8)) as u8, (64 - 8 * digits.saturating_sub(8).clamp(1, 8)) as u8],
            high_weight: POW10_U64[digits.saturating_sub(8).min(15)],
            divisor: POW10[frac_digits.min(22)],
            exp_at: exp_digits_from as u8,
            exp_shift: (64 - 8 * exp_digits.clamp(1, 8)) as u8,
            exp_in_run: exp_signed && exp_digits == 2 && exp_digits_from + 2 <= 16,
            before_point,
            int_digits: int_digits as u8,
            frac_digits: frac_digits as u8,
            exp_digits: exp_digits as u8,
            exp_signed,
            step: step as u8,
            words: step.div_ceil(8) as u8,
            fold,
            target,
            add,
            care,
        })
    }

    /// The exponent's fields, for tests: (digits, signed).
    #[cfg(test)]
    fn exponent(&self) -> (u8, bool) {
        (self.exp_digits, self.exp_signed)
    }
}

/// What a row's fields end with: `delim` between fields, a line end after the last.
#[derive(Debug, Clone, Copy)]
pub struct RowLayout {
    /// The field separator (not whitespace).
    pub delim: u8,
    /// Lines end in `\r\n` (else `\n`).
    pub crlf: bool,
}

/// The eight bytes of `w` from `k` as a little-endian word.
#[inline(always)]
fn word_at(w: &[u8; WINDOW], k: usize) -> u64 {
    let mut a = [0u8; 8];
    if let Some(s) = w.get(k..k + 8) {
        a.copy_from_slice(s);
    }
    u64::from_le_bytes(a)
}

/// The value of the `n` (0 to 19) ASCII digits of `w` from `k` (k + 16 + 8 <= 32 when n > 16).
#[inline(always)]
fn digits_at(w: &[u8; WINDOW], k: usize, n: usize) -> u64 {
    if n <= 8 {
        digits_value(word_at(w, k), n)
    } else if n <= 16 {
        digits_value(word_at(w, k), 8) * POW10_U64[n - 8] + digits_value(word_at(w, k + 8), n - 8)
    } else {
        let first = digits_value(word_at(w, k), 8) * 100_000_000 + digits_value(word_at(w, k + 8), 8);
        first * POW10_U64[n - 16] + digits_value(word_at(w, k + 16), n - 16)
    }
}

/// w x 10^p with its sign, for w < 10^15 (exact in f64) and |p| <= 22 (10^|p| exact): one
/// correctly rounded multiplication or division (Clinger's fast path); `None` for other powers.
#[inline(always)]
fn scaled(w: u64, p: i32, negative: bool) -> Option<f64> {
    power_scaled(w as f64, p, negative)
}

/// x x 10^p with its sign, for an exact `x` (below 2^53) and |p| <= 22: as [`scaled`], for a
/// significand already converted.
#[inline(always)]
fn power_scaled(x: f64, p: i32, negative: bool) -> Option<f64> {
    let m = *POW10.get(p.unsigned_abs() as usize)?;
    Some(with_sign(if p >= 0 { x * m } else { x / m }, negative))
}

/// Reads the field at `p` against `shape`: the value and the index of the next field, or `None`
/// when the field (its end bytes included) does not have that shape, 40 bytes from its first
/// byte are not available, or its exponent leaves a power outside the exact range.
///
/// The check is one masked comparison per word of the window (see [`FieldShape::fold`]): the
/// bytes that must be digits are, and the point, the `e` and the end bytes are those
/// characters. The exponent's sign is checked apart.
#[inline(always)]
fn shaped_field(b: &[u8], p: usize, shape: &FieldShape) -> Option<(f64, usize)> {
    let field: &[u8; WINDOW + 8] = b.get(p..p + WINDOW + 8)?.try_into().ok()?;
    let c0 = field[0];
    let negative = c0 == b'-';
    let sign = usize::from(negative | (c0 == b'+'));
    let q = p + sign;
    let w: &[u8; WINDOW] = field[sign..sign + WINDOW].try_into().ok()?;
    let word = |k: usize| word_at(w, 8 * k);
    let misfit = |k: usize, v: u64| {
        let y = (v & shape.fold[k]) ^ shape.target[k];
        (((y & (0x7f * ONES)) + shape.add[k]) | y) & shape.care[k]
    };
    // (The second word is checked even when the shape ends in the first: it cares for none of
    // its bytes then.)
    let (w0, w1) = (word(0), word(1));
    let mut bad = misfit(0, w0) | misfit(1, w1);
    if shape.words > 2 {
        bad |= misfit(2, word(2));
    }
    if bad != 0 {
        return None;
    }
    let next = q + usize::from(shape.step);
    // The mantissa's digits in one run: those after the point shifted down over it (bytes
    // past the run are shifted out by `run_shift`).
    let keep = shape.before_point as u64;
    let lo = (w0 & keep) | (((w0 >> 8) | (w1 << 56)) & !keep);
    let significand = match shape.kind {
        SMALL => eight_digits(lo, shape.run_shift[0]),
        MEDIUM => {
            let keep = (shape.before_point >> 64) as u64;
            let w2 = word(2);
            let hi = (w1 & keep) | (((w1 >> 8) | (w2 << 56)) & !keep);
            eight_digits(lo, 0) * shape.high_weight + eight_digits(hi, shape.run_shift[1])
        }
        _ => {
            let w = digits_at(w, 0, usize::from(shape.int_digits));
            return Some((with_sign(w as f64, negative), next));
        }
    };
    // Below 10^16 < 2^63: the conversion from i64 is exact (below 2^53) or correctly rounded.
    let x = significand as i64 as f64;
    if shape.exp_digits == 0 {
        return Some((with_sign(x / shape.divisor, negative), next));
    }
    // The exponent: its sign if the shape has one, its digits.
    if shape.exp_in_run {
        // `e-05` in the first two words: the sign and the two digits from one shift.
        let run = ((u128::from(w0) | (u128::from(w1) << 64)) >> (8 * (usize::from(shape.exp_at) - 1))) as u32;
        let c = run as u8;
        let negative_exp = c == b'-';
        if !negative_exp && c != b'+' {
            return None;
        }
        let e = (((run >> 8) & 0xf) * 10 + ((run >> 16) & 0xf)) as i32;
        let p = if negative_exp { -e } else { e } - i32::from(shape.frac_digits);
        return Some((power_scaled(x, p, negative)?, next));
    }
    let e = eight_digits(word_at(w, usize::from(shape.exp_at)), shape.exp_shift) as i32;
    let negative_exp = if shape.exp_signed {
        let c = w[usize::from(shape.exp_at - 1) % WINDOW];
        if c != b'-' && c != b'+' {
            return None;
        }
        c == b'-'
    } else {
        false
    };
    let p = if negative_exp { -e } else { e } - i32::from(shape.frac_digits);
    Some((power_scaled(x, p, negative)?, next))
}

/// The value of the ASCII digits of `v` that `shift` (bits) moves to the top bytes (those
/// shifted out are ignored; zeros below act as leading zeros): [`digits_value`] with the shift
/// made beforehand.
#[inline(always)]
fn eight_digits(v: u64, shift: u8) -> u64 {
    let d = v.wrapping_sub(0x30 * ONES) << (shift & 63);
    // Bytes hold digits d0..d7 (d0 lowest = most significant). Pairs: 10 d0 + d1 in every
    // even byte; quads in bits 0..32 and 32..64: 100 p0 + p1, then the halves 10^4 q0 + q1.
    let pairs = d.wrapping_mul(10).wrapping_add(d >> 8);
    let lo = pairs & 0x0000_00ff_0000_00ff;
    let hi = (pairs >> 16) & 0x0000_00ff_0000_00ff;
    (lo.wrapping_mul(100 + (1_000_000 << 32)).wrapping_add(hi.wrapping_mul(1 + (10_000 << 32)))) >> 32
}

/// Reads the field at `p` by scanning for `end_char`: the value, the index of the end character
/// and the field's shape; `None` when it is not a number the fast path takes ending there: a
/// plain decimal of at most 15 digits, an integer of at most 19, or a decimal of at most 15
/// digits with an exponent of 1 to 3 digits that leaves w x 10^p with |p| <= 22.
#[inline(always)]
fn scanned_field(b: &[u8], p: usize, end_char: u8, end: &[u8]) -> Option<(f64, usize, Option<FieldShape>)> {
    let c0 = b.get(p).copied();
    let negative = c0 == Some(b'-');
    let q = p + usize::from(negative || c0 == Some(b'+'));
    let (int_w, ni, i) = digit_run(b, q, 0, MAX_INTEGER_DIGITS)?;
    let at = b.get(i).copied();
    if at == Some(end_char) && ni > 0 {
        // An integer of up to 19 digits: one correctly rounded conversion.
        return Some((exact_quotient(int_w, 0, negative), i, FieldShape::new(ni, false, 0, None, end)));
    }
    if ni > MAX_DIGITS {
        return None;
    }
    let (significand, nf, i, has_point) = if at == Some(b'.') {
        let (w, nf, i) = digit_run(b, i + 1, int_w, MAX_DIGITS - ni)?;
        (w, nf, i, true)
    } else {
        (int_w, 0, i, false)
    };
    if ni + nf == 0 {
        return None;
    }
    match b.get(i).copied() {
        Some(c) if c == end_char => {
            Some((exact_quotient(significand, nf, negative), i, FieldShape::new(ni, has_point, nf, None, end)))
        }
        Some(b'e' | b'E') => {
            let sign = b.get(i + 1).copied();
            let signed = matches!(sign, Some(b'-' | b'+'));
            let s = i + 1 + usize::from(signed);
            let (e, ne, at) = digit_run(b, s, 0, 3)?;
            if ne == 0 || b.get(at) != Some(&end_char) {
                return None;
            }
            let e = if sign == Some(b'-') { -(e as i32) } else { e as i32 };
            let v = scaled(significand, e - nf as i32, negative)?;
            Some((v, at, FieldShape::new(ni, has_point, nf, Some((signed, ne)), end)))
        }
        _ => None,
    }
}

/// Reads one row of numbers (see [`read_rows`]); `None` leaves `cols` as it was.
#[inline(always)]
fn read_row(
    b: &[u8],
    start: usize,
    layout: RowLayout,
    targets: &[u32],
    shapes: &mut [Option<FieldShape>],
    cols: &mut [Vec<f64>],
) -> Option<usize> {
    let mut p = start;
    let last = targets.len().checked_sub(1)?;
    if shapes.len() < targets.len() {
        return None;
    }
    for (ci, (&slot, shape)) in targets.iter().zip(shapes.iter_mut()).enumerate() {
        let parsed = match shape.as_ref().and_then(|s| shaped_field(b, p, s)) {
            Some(hit) => Some(hit),
            None => {
                let end: &[u8] = match (ci == last, layout.crlf) {
                    (false, _) => std::slice::from_ref(&layout.delim),
                    (true, false) => b"\n",
                    (true, true) => b"\r\n",
                };
                scanned_field(b, p, end[0], end)
                    .filter(|&(_, e, _)| end.len() == 1 || b.get(e + 1) == Some(&b'\n'))
                    .map(|(v, e, s)| {
                        *shape = s;
                        (v, e + end.len())
                    })
            }
        };
        match parsed {
            Some((v, next)) => {
                if slot != SKIP_COLUMN {
                    cols[slot as usize].push(v);
                }
                p = next;
            }
            None => {
                // Take back this row's values: the general reader reads the row again.
                for &s in &targets[..ci] {
                    if s != SKIP_COLUMN {
                        cols[s as usize].pop();
                    }
                }
                return None;
            }
        }
    }
    Some(p)
}

/// The target slot of a column that is not kept.
pub const SKIP_COLUMN: u32 = u32::MAX;

/// Reads rows of numbers from `start` (each: fields separated by `layout.delim`, the last ending
/// in `\n` or, with `layout.crlf`, `\r\n`; no spaces or empty cells; each number a plain decimal of
/// at most 15 digits, an integer of at most 19, or at most 15 digits with an exponent that
/// leaves a power of ten within 10^±22, as `scanned_field` takes them), pushing field `ci`'s value onto `cols[targets[ci]]` (none for [`SKIP_COLUMN`]), until
/// a row does not fit, `b` ends, or `room` rows are read. `shapes` (one per field, carried from
/// call to call) remembers each column's last layout. Returns where it stopped and the rows read.
pub fn read_rows(
    b: &[u8],
    start: usize,
    layout: RowLayout,
    targets: &[u32],
    shapes: &mut RowShapes,
    cols: &mut [Vec<f64>],
    room: usize,
) -> (usize, usize) {
    let mut p = start;
    let mut rows = 0;
    let nf = targets.len();
    let RowShapes { shapes, buf } = shapes;
    let plannable = (1..=MAX_PLANNED_FIELDS).contains(&nf) && shapes.len() == nf;
    let mut plan = [FieldShape::default(); MAX_PLANNED_FIELDS];
    // Rows to read field by field before the batches are tried again: where layouts change
    // every few rows (numbers printed with `%g`), a batch would stop at once and its row be
    // read twice.
    let mut field_rows = 0usize;
    while rows < room && p < b.len() {
        // Once every column has a shape: rows that fit them all, a batch at a time through
        // `buf` (field `ci` of row `r` at `ci * batch + r`), then copied to the columns.
        if field_rows > 0 {
            field_rows -= 1;
        } else if plannable && shapes.iter().all(Option::is_some) {
            let before = rows;
            for (k, s) in shapes.iter().enumerate() {
                plan[k] = s.unwrap_or_default();
            }
            buf.resize(PLANNED_VALUES, 0.0);
            let Ok(buf) = <&mut [f64; PLANNED_VALUES]>::try_from(&mut buf[..PLANNED_VALUES]) else { break };
            loop {
                let batch = (PLANNED_VALUES / nf).min(room - rows);
                let (next, n) = planned_rows(b, p, &plan[..nf], layout.delim, buf, batch);
                for (ci, &slot) in targets.iter().enumerate() {
                    if slot != SKIP_COLUMN {
                        cols[slot as usize].extend_from_slice(&buf[ci * batch..ci * batch + n]);
                    }
                }
                p = next;
                rows += n;
                if n < batch || rows >= room {
                    break;
                }
            }
            if rows >= room || p >= b.len() {
                break;
            }
            if rows - before < SHORT_BATCH {
                field_rows = FIELD_ROWS;
            }
        }
        // A row that does not fit the shapes (or before there are shapes): field by field, its
        // fields scanned where they do not fit, their shapes taken for the rows after.
        match read_row(b, p, layout, targets, shapes, cols) {
            Some(next) => {
                p = next;
                rows += 1;
            }
            None => break,
        }
    }
    (p, rows)
}

/// What [`read_rows`] carries from call to call: each column's last shape, and the buffer
/// a batch of rows is read into.
#[derive(Debug, Clone, Default)]
pub struct RowShapes {
    /// Per field of a row, the layout of its last number read (none before the first).
    shapes: Vec<Option<FieldShape>>,
    /// The values of a batch of rows ([`PLANNED_VALUES`] once used).
    buf: Vec<f64>,
}

impl RowShapes {
    /// No shapes yet, for rows of `fields` fields.
    pub fn new(fields: usize) -> RowShapes {
        RowShapes { shapes: vec![None; fields], buf: Vec::new() }
    }

    /// The fields of a row these shapes are for.
    pub fn len(&self) -> usize {
        self.shapes.len()
    }

    /// Whether they are for rows of no fields.
    pub fn is_empty(&self) -> bool {
        self.shapes.is_empty()
    }
}

/// Rows of batches that stop this soon make [`read_rows`] read [`FIELD_ROWS`] rows field by
/// field.
const SHORT_BATCH: usize = 8;

/// See [`SHORT_BATCH`].
const FIELD_ROWS: usize = 64;

/// Values of the batch buffer of [`read_rows`].
const PLANNED_VALUES: usize = 2048;

/// Most fields of a row read a batch at a time (rows of more are read field by field).
const MAX_PLANNED_FIELDS: usize = 16;

/// Reads up to `batch` rows from `p` that fit `plan` (every field's shape; fields separated by
/// `delim`) into `buf`, field `ci` of row `r` at `ci * batch + r`: returns where it stopped and
/// the rows read. Where the CPU has AVX-512, groups of eight rows are read at once first
/// ([`avx512::planned_groups`], the same values bit for bit), and the rest row by row.
#[inline(never)]
fn planned_rows(
    b: &[u8],
    mut p: usize,
    plan: &[FieldShape],
    delim: u8,
    buf: &mut [f64; PLANNED_VALUES],
    batch: usize,
) -> (usize, usize) {
    let mut r = 0;
    #[cfg(target_arch = "x86_64")]
    if avx512::available() && avx512::supports(plan) {
        // SAFETY: the CPU has AVX-512 F, DQ and BW (checked just above); see the function's doc.
        (p, r) = unsafe { avx512::planned_groups(b, p, plan, delim, buf, batch) };
    }
    let _ = delim;
    scalar_rows(b, p, r, plan, buf, batch)
}

/// The row-by-row loop of [`planned_rows`], from row `r` at `p`.
#[inline(always)]
fn scalar_rows(
    b: &[u8],
    mut p: usize,
    mut r: usize,
    plan: &[FieldShape],
    buf: &mut [f64; PLANNED_VALUES],
    batch: usize,
) -> (usize, usize) {
    'rows: while r < batch {
        let mut at = p;
        for (ci, shape) in plan.iter().enumerate() {
            match shaped_field(b, at, shape) {
                Some((v, next)) => {
                    if let Some(slot) = buf.get_mut(ci * batch + r) {
                        *slot = v;
                    }
                    at = next;
                }
                None => break 'rows,
            }
        }
        p = at;
        r += 1;
    }
    (p, r)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn digits_value_of_every_length() {
        let text = b"98765432";
        for n in 0..=8 {
            let want: u64 = if n == 0 { 0 } else { std::str::from_utf8(&text[..n]).unwrap().parse().unwrap() };
            assert_eq!(digits_value(load8(text, 0), n), want, "n = {n}");
        }
    }

    #[test]
    fn rows_by_shape_and_by_scan() {
        // The second row changes the time's width and the sign of the output: scanned, then
        // the third row fits the new shape.
        let text = b"9.99,2.5000001\n10.00,-0.0000003\n10.01,-0.0000004\n10.02,1e30\n";
        let mut shapes = RowShapes::new(2);
        let mut cols = vec![Vec::new(), Vec::new()];
        let (p, rows) =
            read_rows(text, 0, RowLayout { delim: b',', crlf: false }, &[0, 1], &mut shapes, &mut cols, 100);
        assert_eq!(rows, 3);
        assert_eq!(&text[p..], b"10.02,1e30\n");
        assert_eq!(cols[0], vec![9.99, 10.0, 10.01]);
        assert_eq!(cols[1], vec![2.5000001, -0.0000003, -0.0000004]);
        // The rejected row left nothing behind.
        assert_eq!(cols[0].len(), 3);
    }

    #[test]
    fn fifteen_digit_integers_by_shape() {
        // The shape of a 15-digit integer without a point reaches the 16th byte.
        let text = b"123456789012345\n123456789012345\n-999999999999999\n0\n";
        let mut shapes = RowShapes::new(1);
        let mut cols = vec![Vec::new()];
        let (_, rows) = read_rows(text, 0, RowLayout { delim: b',', crlf: false }, &[0], &mut shapes, &mut cols, 100);
        assert_eq!(rows, 4);
        assert_eq!(cols[0], vec![123456789012345.0, 123456789012345.0, -999999999999999.0, 0.0]);
        // Too few shapes for the columns: nothing taken, nothing pushed.
        let mut cols = vec![Vec::new(), Vec::new()];
        let (_, rows) =
            read_rows(b"1,2\n", 0, RowLayout { delim: b',', crlf: false }, &[0, 1], &mut shapes, &mut cols, 9);
        assert_eq!((rows, cols[0].len()), (0, 0));
    }

    #[test]
    fn exponents_and_nanosecond_stamps_by_shape() {
        // np.savetxt's `%.7e` and a Kalibr stamp in ns (19 digits): shapes are taken on the
        // second row; the last row's exponent leaves 10^-27, outside the exact range.
        let text = b"1700000000000000000,3.2996040e-04,-9.1236815E+00\n\
1700000000002500096,-4.2611644e-03,9.8125078e+00\n\
1700000000005000192,0.0000000e+00,1e5\n\
1700000000007500288,1.0000000e-20,1e5\n";
        let mut shapes = RowShapes::new(3);
        let mut cols = vec![Vec::new(); 3];
        let (p, rows) =
            read_rows(text, 0, RowLayout { delim: b',', crlf: false }, &[0, 1, 2], &mut shapes, &mut cols, 100);
        assert_eq!((rows, &text[p..]), (3, &b"1700000000007500288,1.0000000e-20,1e5\n"[..]));
        let full = |t: &str| fast_float2::parse::<f64, _>(t).unwrap();
        assert_eq!(
            cols[0],
            vec![full("1700000000000000000"), full("1700000000002500096"), full("1700000000005000192")]
        );
        assert_eq!(cols[1], vec![3.2996040e-04, -4.2611644e-03, 0.0]);
        assert_eq!(cols[2], vec![-9.1236815, 9.8125078, 1e5]);
        assert_eq!(shapes.shapes[1].map(|s| s.exponent()), Some((2, true)));
    }

    #[test]
    fn crlf_rows() {
        let text = b"1.5,2\r\n-3,4.25\r\n5,6\n";
        let mut shapes = RowShapes::new(2);
        let mut cols = vec![Vec::new(), Vec::new()];
        let layout = RowLayout { delim: b',', crlf: true };
        let (p, rows) = read_rows(text, 0, layout, &[0, 1], &mut shapes, &mut cols, 100);
        assert_eq!((rows, &text[p..]), (2, &b"5,6\n"[..]));
        assert_eq!(cols, vec![vec![1.5, -3.0], vec![2.0, 4.25]]);
    }

    /// Whether a field is a number the fast path must take: `[+-]digits[.digits]` with 1 to 15
    /// digits (either side of the point may be empty, not both), or 1 to 19 without a point;
    /// or 1 to 15 digits with an exponent `[eE][+-]d{1,3}` for which exponent - (digits after
    /// the point) is within -22..=22.
    fn is_plain(f: &str) -> bool {
        let body = f.strip_prefix(['-', '+']).unwrap_or(f);
        let (mantissa, exp) = match body.split_once(['e', 'E']) {
            Some((m, e)) => (m, Some(e)),
            None => (body, None),
        };
        let (int, frac) = mantissa.split_once('.').unwrap_or((mantissa, ""));
        let digits = int.len() + frac.len();
        let is_digits = |t: &str| t.bytes().all(|c| c.is_ascii_digit());
        if !is_digits(int) || !is_digits(frac) || digits == 0 {
            return false;
        }
        match exp {
            None if !mantissa.contains('.') => digits <= 19,
            None => digits <= 15,
            Some(e) => {
                let e_digits = e.strip_prefix(['-', '+']).unwrap_or(e);
                if digits > 15 || !is_digits(e_digits) || !(1..=3).contains(&e_digits.len()) {
                    return false;
                }
                let p: i64 = e.parse::<i64>().unwrap() - frac.len() as i64;
                (-22..=22).contains(&p)
            }
        }
    }

    /// A random number's parts: sign, digits before the point and their value, digits after it
    /// and their value, exponent (sign, case, value).
    type NumberParts = (u8, u32, u64, usize, u64, Option<(u8, bool, u32)>);

    /// A number as text: sign, 0 to 20 digits before the point, 0 to 9 after it, and an
    /// exponent (`e`/`E`, an optional sign, 1 to 4 digits) when `exp` says so.
    fn number_text((sign, int_digits, int, width, frac, exp): NumberParts) -> String {
        let sign = ["", "-", "+"][sign as usize];
        let int = if int_digits == 0 {
            String::new()
        } else if int_digits <= 19 {
            format!("{}", int % 10u64.pow(int_digits))
        } else {
            format!("{int}{}", int % 10)
        };
        let int = if int.is_empty() && width == 0 { "0".to_string() } else { int };
        let frac = format!("{frac:09}");
        let mantissa =
            if width == 0 { format!("{sign}{int}") } else { format!("{sign}{int}.{}", &frac[..width.min(9)]) };
        match exp {
            None => mantissa,
            Some((s, upper, e)) => {
                let e_sign = ["", "-", "+"][s as usize % 3];
                let width = 1 + (e % 4) as usize;
                format!(
                    "{mantissa}{}{e_sign}{:0width$}",
                    if upper { 'E' } else { 'e' },
                    e / 4 % 10u32.pow(width as u32)
                )
            }
        }
    }

    /// Reads `text` with [`read_rows`] as the reader does (refused rows are skipped here, as the
    /// general reader would read them) and checks every row: taken rows hold exactly the full
    /// parser's values, and a row is refused only if one of its fields is not a plain decimal.
    fn check_rows(text: &str, ncols: usize, targets: &[u32]) -> Result<(), TestCaseError> {
        check_rows_by(text, ncols, targets, 3, RowLayout { delim: b',', crlf: false })
    }

    /// [`check_rows`] reading up to `room` rows a call, of any layout.
    fn check_rows_by(
        text: &str,
        ncols: usize,
        targets: &[u32],
        room: usize,
        layout: RowLayout,
    ) -> Result<(), TestCaseError> {
        let d = layout.delim as char;
        let b = text.as_bytes();
        let mut shapes = RowShapes::new(ncols);
        let mut cols = vec![Vec::new(); ncols];
        let mut want: Vec<Vec<f64>> = vec![Vec::new(); ncols];
        let mut p = 0;
        while p < b.len() {
            let (np, rows) = read_rows(b, p, layout, targets, &mut shapes, &mut cols, room);
            for line in std::str::from_utf8(&b[p..np]).unwrap().split_terminator('\n') {
                let line = if layout.crlf {
                    prop_assert!(line.ends_with('\r'), "took {:?}", line);
                    &line[..line.len() - 1]
                } else {
                    line
                };
                let f: Vec<&str> = line.split(d).collect();
                prop_assert_eq!(f.len(), ncols, "{:?}", line);
                for c in 0..ncols {
                    prop_assert!(is_plain(f[c]), "took {:?}", line);
                    if targets[c] != SKIP_COLUMN {
                        want[c].push(fast_float2::parse::<f64, _>(f[c]).unwrap());
                    }
                }
            }
            if rows == 0 {
                let end = b[p..].iter().position(|&c| c == b'\n').map_or(b.len(), |i| p + i);
                let line = std::str::from_utf8(&b[p..end]).unwrap();
                // With CRLF layouts a line must end in `\r` to be taken.
                let (line, ends_right) = match line.strip_suffix('\r') {
                    Some(l) if layout.crlf => (l, true),
                    _ => (line, !layout.crlf),
                };
                let f: Vec<&str> = line.split(d).collect();
                // A last line without its line end may be refused too (the reader adds one).
                let unterminated = end == b.len();
                prop_assert!(
                    unterminated || !ends_right || f.len() != ncols || !f.iter().all(|x| is_plain(x)),
                    "refused {:?}",
                    line
                );
                p = end + 1;
            } else {
                p = np;
            }
        }
        for c in 0..ncols {
            // The bound the reader relies on to skip its magnitude check of fast-path rows.
            prop_assert!(cols[c].iter().all(|v| v.abs() < 1e42), "column {}", c);
            let got: Vec<u64> = cols[c].iter().map(|v| v.to_bits()).collect();
            let exp: Vec<u64> = want[c].iter().map(|v| v.to_bits()).collect();
            prop_assert_eq!(got, exp, "column {}", c);
        }
        Ok(())
    }

    /// `rows` rows of the column layouts `layout` (random digits; now and then a sign changed,
    /// and an exponent's sign), separated by `delim`, ending in `\n` or `\r\n`, with the bytes
    /// of `corrupt` written over them.
    fn layout_text(
        layout: &[NumberParts],
        rows: usize,
        seed: u64,
        delim: u8,
        crlf: bool,
        corrupt: &[(prop::sample::Index, u8)],
    ) -> String {
        let ncols = layout.len();
        let mut state = seed | 1;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let mut text = String::new();
        for _ in 0..rows {
            for (ci, &(sign, int_digits, _, width, _, exp)) in layout.iter().enumerate() {
                let r = next();
                let sign = if r % 16 == 0 { (sign + 1) % 3 } else { sign };
                // The exponent's width kept, its value (0 to 30, as logs have them) and now
                // and then its sign changed from row to row.
                let exp = exp.map(|(s, upper, e)| {
                    (if r % 8 == 1 { (s + 1) % 3 } else { s }, upper, 4 * (next() % 31) as u32 + e % 4)
                });
                text.push_str(&number_text((sign, int_digits, next(), width, next() % 1_000_000_000, exp)));
                text.push_str(match (ci + 1 == ncols, crlf) {
                    (false, _) => {
                        if delim == b',' {
                            ","
                        } else if delim == b';' {
                            ";"
                        } else {
                            "\t"
                        }
                    }
                    (true, false) => "\n",
                    (true, true) => "\r\n",
                });
            }
        }
        let mut bytes = text.into_bytes();
        for &(at, c) in corrupt {
            let i = at.index(bytes.len());
            bytes[i] = c;
        }
        String::from_utf8(bytes).unwrap()
    }

    /// Reads `text` from its second row on, a batch of `batch` rows at a time, against the
    /// shapes of its first row, by the vector loop then the scalar one, and by the scalar loop
    /// alone: both must stop at the same place with the same values, bit for bit. Returns the
    /// rows the vector loop read.
    #[cfg(target_arch = "x86_64")]
    fn check_vector_rows(text: &str, ncols: usize, layout: RowLayout, batch: usize) -> Result<usize, TestCaseError> {
        let b = text.as_bytes();
        let targets: Vec<u32> = (0..ncols as u32).collect();
        let mut shapes = vec![None; ncols];
        let mut cols = vec![Vec::new(); ncols];
        let Some(mut p) = read_row(b, 0, layout, &targets, &mut shapes, &mut cols) else { return Ok(0) };
        let Some(plan) = shapes.into_iter().collect::<Option<Vec<FieldShape>>>() else { return Ok(0) };
        if !avx512::supports(&plan) {
            return Ok(0);
        }
        let batch = batch.min(PLANNED_VALUES / ncols);
        let mut by_vector = 0;
        while p < b.len() {
            let (mut vb, mut sb) = ([f64::NAN; PLANNED_VALUES], [f64::NAN; PLANNED_VALUES]);
            // SAFETY: the caller checked that the CPU has AVX-512 F, DQ and BW.
            let (vp, vr) = unsafe { avx512::planned_groups(b, p, &plan, layout.delim, &mut vb, batch) };
            by_vector += vr;
            let (vp, vr) = scalar_rows(b, vp, vr, &plan, &mut vb, batch);
            let (sp, sr) = scalar_rows(b, p, 0, &plan, &mut sb, batch);
            prop_assert_eq!((vp, vr), (sp, sr), "from byte {}", p);
            for ci in 0..ncols {
                let got: Vec<u64> = vb[ci * batch..ci * batch + vr].iter().map(|v| v.to_bits()).collect();
                let want: Vec<u64> = sb[ci * batch..ci * batch + sr].iter().map(|v| v.to_bits()).collect();
                prop_assert_eq!(got, want, "column {} from byte {}", ci, p);
            }
            p = if sr == 0 { b[p..].iter().position(|&c| c == b'\n').map_or(b.len(), |i| p + i + 1) } else { sp };
        }
        Ok(by_vector)
    }

    #[cfg(target_arch = "x86_64")]
    #[test]
    fn vector_rows_read_runs() {
        if !avx512::available() {
            eprintln!("SKIPPED: vector_rows_read_runs and vector_rows_equal_the_scalar_rows need AVX-512 F, DQ and BW, which this CPU lacks (the scalar loop is tested as ever)");
            return;
        }
        // `%.7e` as C writes it (two exponent digits; Rust's `{:e}` writes one).
        let c_exp = |x: f64| {
            let s = format!("{x:.7e}");
            let (m, e) = s.split_once('e').unwrap();
            let e: i32 = e.parse().unwrap();
            format!("{m}e{}{:02}", if e < 0 { '-' } else { '+' }, e.abs())
        };
        let mut text = String::from("time_s,rate_dps\n");
        for i in 0..5000u32 {
            let t = f64::from(i) * 0.01 + 12345.0;
            let x = 0.5 + f64::from(i % 97) * 1e-4 - if i % 3 == 0 { 1.0 } else { 0.0 };
            text.push_str(&format!("{t:.2},{}\n", c_exp(x)));
        }
        let text = &text[text.find('\n').unwrap() + 1..];
        let layout = RowLayout { delim: b',', crlf: false };
        let by_vector = check_vector_rows(text, 2, layout, 1000).unwrap();
        // All but the first row and those within 64 bytes of the end.
        assert!(by_vector > 4900, "{by_vector}");
        // The exponent's sign is checked apart from the shape's masks: a row where it is not
        // one stops both loops at that row.
        for c in ["0", "x", " ", "e"] {
            let at = text.match_indices("e-").nth(100).unwrap().0 + 1;
            let bad = format!("{}{c}{}", &text[..at], &text[at + 1..]);
            check_vector_rows(&bad, 2, layout, 1000).unwrap();
        }
        let mut kalibr = String::new();
        for i in 0..3000u64 {
            kalibr.push_str(&format!("{}", 1_700_000_000_000_000_000 + i * 2_500_000));
            for c in 0..6u64 {
                let v = (i * 7 + c * 13) as f64 * 1.234e-3 - 4.0;
                kalibr.push_str(&format!(",{}", c_exp(v)));
            }
            kalibr.push('\n');
        }
        let by_vector = check_vector_rows(&kalibr, 7, layout, 292).unwrap();
        assert!(by_vector > 1000, "{by_vector}");
    }

    /// A number of a form the vector loop reads: at most 15 digits (or an integer of 17 to 19),
    /// with no exponent or with `e`/`E`, a sign and two digits (`%e`).
    fn vector_number() -> impl Strategy<Value = NumberParts> {
        let digits = prop_oneof![(0u32..9, 0usize..7), (9u32..13, 0usize..4), (17u32..20, Just(0usize))];
        let exp =
            prop_oneof![Just(None), (1u8..3, any::<bool>(), 0u32..100).prop_map(|(s, u, e)| Some((s, u, 4 * e + 1)))];
        (0u8..3, digits, any::<u64>(), 0u64..1_000_000_000, exp).prop_map(
            |(sign, (int_digits, width), int, frac, exp)| {
                (sign, int_digits, int, width, frac, if int_digits >= 17 { None } else { exp })
            },
        )
    }

    fn number() -> impl Strategy<Value = NumberParts> {
        (
            0u8..3,
            prop_oneof![0u32..9, 9u32..17, 17u32..21],
            any::<u64>(),
            prop_oneof![0usize..10, Just(0usize)],
            0u64..1_000_000_000,
            prop_oneof![Just(None), (0u8..3, any::<bool>(), 0u32..400).prop_map(Some)],
        )
    }

    proptest! {
        /// Rows of numbers whose widths change (so shapes fit, miss and change), with corrupted
        /// bytes: every row taken gives exactly the full parser's values, and only rows with a
        /// field that is not a plain decimal are refused.
        #[test]
        fn rows_equal_the_full_parser(
            fields in prop::collection::vec(number(), 2..80),
            ncols in 1usize..4,
            skip in 0usize..4,
            corrupt in prop::collection::vec((any::<prop::sample::Index>(), prop::sample::select(b"x.-+,e \r\n05".to_vec())), 0..4),
        ) {
            let mut text = String::new();
            for row in fields.chunks_exact(ncols) {
                for (ci, &f) in row.iter().enumerate() {
                    text.push_str(&number_text(f));
                    text.push(if ci + 1 == ncols { '\n' } else { ',' });
                }
            }
            let mut bytes = text.into_bytes();
            for (at, c) in corrupt {
                if !bytes.is_empty() {
                    let i = at.index(bytes.len());
                    bytes[i] = c;
                }
            }
            let text = String::from_utf8(bytes).unwrap();
            let targets: Vec<u32> = (0..ncols as u32).map(|c| if c as usize == skip { SKIP_COLUMN } else { c }).collect();
            check_rows(&text, ncols, &targets)?;
        }

        /// Long runs of rows of one layout, as in `runs_of_one_layout_equal_the_full_parser`
        /// (the numbers of the forms the vector loop takes: no exponent, or a sign and two
        /// digits), read a batch at a time by the AVX-512 loop then the row loop, and by
        /// the row loop alone: the same stopping row and the same values, bit for bit.
        #[cfg(target_arch = "x86_64")]
        #[test]
        fn vector_rows_equal_the_scalar_rows(
            layout in prop::collection::vec(vector_number(), 1..12),
            rows in 20usize..200,
            seed in any::<u64>(),
            batch in prop_oneof![Just(8usize), 9usize..70, Just(2048usize)],
            (delim, crlf) in prop::sample::select(vec![(b',', false), (b';', true), (b'\t', false), (b',', true)]),
            corrupt in prop::collection::vec((any::<prop::sample::Index>(), prop::sample::select(b"x.-+,;\te9 \r\n05E".to_vec())), 0..6),
        ) {
            if avx512::available() {
                let text = layout_text(&layout, rows, seed, delim, crlf, &corrupt);
                check_vector_rows(&text, layout.len(), RowLayout { delim, crlf }, batch)?;
            }
        }

        /// Long runs of rows of one layout (the digits random, the sign and the exponent's sign
        /// now and then changed), as logs are, comma, semicolon or tab separated, with LF or
        /// CRLF line ends, with corrupted bytes: the rows read a batch at a time against every
        /// column's shape give exactly the full parser's values, and only rows with a field that
        /// is not a plain decimal (or, with CRLF, a line not ending in it) are refused.
        #[test]
        fn runs_of_one_layout_equal_the_full_parser(
            layout in prop::collection::vec(number(), 1..8),
            rows in 40usize..300,
            seed in any::<u64>(),
            room in prop_oneof![Just(7usize), Just(1000usize)],
            (delim, crlf) in prop::sample::select(vec![(b',', false), (b';', true), (b'\t', false), (b',', true)]),
            corrupt in prop::collection::vec((any::<prop::sample::Index>(), prop::sample::select(b"x.-+,;\te9 \r\n05E".to_vec())), 0..6),
        ) {
            let ncols = layout.len();
            let text = layout_text(&layout, rows, seed, delim, crlf, &corrupt);
            let targets: Vec<u32> = (0..ncols as u32).collect();
            check_rows_by(&text, ncols, &targets, room, RowLayout { delim, crlf })?;
        }

        /// Any text made of number characters: the same checks.
        #[test]
        fn rows_on_any_text(text in "[-+0-9.eE,x \r\n]{0,80}") {
            check_rows(&text, 2, &[0, 1])?;
        }
    }
}
