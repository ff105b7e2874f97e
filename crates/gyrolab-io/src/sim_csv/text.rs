//! Number text for the simulated-record writers: fixed decimals by SWAR digits and the shortest
//! round-trip form (Ryu), written into a buffer with room to spare.
//!
//! Fixed decimals: one correctly rounded multiply by an exact power of ten, round half away from
//! zero, then integer digits (eight at a time). Both forms are byte-identical on every platform.

/// Exact powers of ten 10^0 ..= 10^15 (all exactly representable in f64).
const POW10: [f64; 16] = [1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15];
/// Largest magnitude written through the integer path (2^53).
const EXACT_INT_LIMIT: f64 = 9_007_199_254_740_992.0;
/// Room needed for each number: the longest number text (a sign, 16 digits, a point, 15
/// decimals; Ryu's at most 24 bytes) plus the 8 bytes a word store may write past its end.
pub(super) const NUMBER_ROOM: usize = 48;
/// Eight ASCII zeros.
const ZEROS: u64 = u64::from_le_bytes([b'0'; 8]);

/// The eight decimal digits of `n` < 10^8 as ASCII, zero-padded, the first digit in the lowest
/// byte (SWAR: both four-digit halves, then both digit pairs of each, then both digits of each
/// pair, are split at once with multiplications by reciprocals that are exact in these ranges).
#[inline(always)]
fn eight_digits(n: u64) -> u64 {
    // Lanes of 32 bits: the first four digits (n / 10^4) in the low lane.
    let quads = (n / 10_000) | ((n % 10_000) << 32);
    // In each lane, abcd / 100 = (abcd * 5243) >> 19 for abcd < 10^4; pairs in 16-bit lanes.
    let hundreds = ((quads * 5243) >> 19) & 0x0000_007f_0000_007f;
    let pairs = hundreds | ((quads - hundreds * 100) << 16);
    // In each 16-bit lane, ab / 10 = (ab * 103) >> 10 for ab < 100; digits in bytes.
    let tens = ((pairs * 103) >> 10) & 0x000f_000f_000f_000f;
    let digits = tens | ((pairs - tens * 10) << 8);
    digits + ZEROS
}

/// Leading zero digits of eight ASCII digits from [`eight_digits`], at most 7 (one digit stays).
#[inline(always)]
fn leading_zero_digits(digits: u64) -> usize {
    // Each byte minus '0' is the digit itself (no borrow): the zero bytes at the low end are the
    // leading zeros.
    (((digits - ZEROS).trailing_zeros() / 8) as usize).min(7)
}

/// Text under construction: a buffer that grows as needed, with room to spare past the end
/// (numbers are stored a word at a time through a [`Cursor`]).
pub(super) struct TextBuf {
    /// Text in `bytes[..end]`; the rest is room.
    pub(super) bytes: Vec<u8>,
    /// End of the text.
    pub(super) end: usize,
}

impl TextBuf {
    /// An empty buffer for about `size` bytes of text.
    pub(super) fn new(size: usize) -> TextBuf {
        TextBuf { bytes: vec![0; size + 4 * NUMBER_ROOM], end: 0 }
    }

    /// Makes sure `n` more bytes fit after the end.
    #[inline(always)]
    pub(super) fn make_room(&mut self, n: usize) {
        if self.end + n > self.bytes.len() {
            self.grow(n);
        }
    }

    /// Room for `n` more bytes, and some: the buffer at least doubles.
    #[cold]
    #[inline(never)]
    fn grow(&mut self, n: usize) {
        let len = (self.end + n).max(2 * self.bytes.len());
        self.bytes.resize(len, 0);
    }

    /// Appends bytes.
    pub(super) fn text(&mut self, s: &[u8]) {
        self.make_room(s.len());
        self.bytes[self.end..self.end + s.len()].copy_from_slice(s);
        self.end += s.len();
    }

    /// Appends one byte.
    pub(super) fn byte(&mut self, b: u8) {
        self.text(&[b]);
    }

    /// Appends a `# ` comment line per line of `line` (so that no text can end the comment block
    /// early).
    pub(super) fn comment(&mut self, line: &str) {
        for part in line.split('\n') {
            self.text(b"# ");
            self.text(part.trim_end_matches('\r').as_bytes());
            self.byte(b'\n');
        }
    }

    /// Makes room for `room` bytes and appends through a cursor (see [`Cursor`]); `write` must
    /// not write more than that.
    #[inline(always)]
    pub(super) fn with_room<R>(&mut self, room: usize, write: impl FnOnce(&mut Cursor<'_>) -> R) -> R {
        self.make_room(room);
        let mut cursor = Cursor { bytes: &mut self.bytes, end: self.end };
        let r = write(&mut cursor);
        self.end = cursor.end;
        r
    }
}

/// Appends text into a buffer with room made beforehand ([`TextBuf::with_room`]), through a
/// slice and an end of its own: kept in registers, where a store through `TextBuf`'s own fields
/// would make the compiler load them again after every byte. Numbers need [`NUMBER_ROOM`] bytes
/// each, since words are stored whole.
pub(super) struct Cursor<'a> {
    bytes: &'a mut [u8],
    end: usize,
}

impl Cursor<'_> {
    /// Appends one byte.
    #[inline(always)]
    pub(super) fn byte(&mut self, b: u8) {
        self.bytes[self.end] = b;
        self.end += 1;
    }

    /// Appends bytes.
    #[inline(always)]
    pub(super) fn text(&mut self, s: &[u8]) {
        self.bytes[self.end..self.end + s.len()].copy_from_slice(s);
        self.end += s.len();
    }

    /// Stores the word's eight bytes (lowest first) and keeps the first `len` of them.
    #[inline(always)]
    fn word(&mut self, word: u64, len: usize) {
        self.bytes[self.end..self.end + 8].copy_from_slice(&word.to_le_bytes());
        self.end += len;
    }

    /// Appends `n` < 10^16 in decimal, without leading zeros.
    #[inline(always)]
    pub(super) fn integer(&mut self, n: u64) {
        if n < 100_000_000 {
            let digits = eight_digits(n);
            let zeros = leading_zero_digits(digits);
            self.word(digits >> (8 * zeros), 8 - zeros);
        } else {
            // n / 10^8 is at least 1 (no zero run of 8) and below 10^8.
            let high = eight_digits(n / 100_000_000);
            let zeros = leading_zero_digits(high);
            self.word(high >> (8 * zeros), 8 - zeros);
            self.word(eight_digits(n % 100_000_000), 8);
        }
    }

    /// Appends the shortest text that reads back to `v` (Ryu).
    pub(super) fn shortest(&mut self, v: f64) {
        self.text(ryu::Buffer::new().format(v).as_bytes());
    }

    /// Appends `m` / 10^D in fixed notation (D digits after the point, at least one before it),
    /// with a minus sign when `negative`; `m` < 10^16, D <= 15.
    #[inline(always)]
    pub(super) fn fixed<const D: usize>(&mut self, m: u64, negative: bool) {
        let unit = const { 10u64.pow(D as u32) };
        if negative {
            self.byte(b'-');
        }
        if D > 0 && D < 8 && m < 100_000_000 {
            // All digits from one word: the integer part (leading zeros dropped, one kept), the
            // point, the last D digits.
            let digits = eight_digits(m);
            let zeros = leading_zero_digits(digits).min(7 - D.min(7));
            self.word(digits >> (8 * zeros), 8 - D - zeros);
            self.byte(b'.');
            self.word(digits >> (8 * (8 - D.min(8))), D);
            return;
        }
        self.integer(m / unit);
        self.fraction::<D>(m % unit);
    }

    /// As [`Cursor::fixed`], for a column whose integer part often repeats from one row to the
    /// next (time stamps: for a whole second): its text is kept in `repeat`.
    #[inline(always)]
    pub(super) fn fixed_repeating<const D: usize>(&mut self, m: u64, negative: bool, repeat: &mut IntegerText) {
        let unit = const { 10u64.pow(D as u32) };
        if negative {
            self.byte(b'-');
        }
        let integer = m / unit;
        if integer < 100_000_000 {
            if integer != repeat.value {
                let digits = eight_digits(integer);
                let zeros = leading_zero_digits(digits);
                *repeat = IntegerText { value: integer, word: digits >> (8 * zeros), len: 8 - zeros };
            }
            self.word(repeat.word, repeat.len);
        } else {
            self.integer(integer);
        }
        self.fraction::<D>(m % unit);
    }

    /// Appends the point and the D digits of `fraction` < 10^D (nothing for D = 0).
    #[inline(always)]
    fn fraction<const D: usize>(&mut self, fraction: u64) {
        if D == 0 {
            return;
        }
        self.byte(b'.');
        if D <= 8 {
            // The last D of eight zero-padded digits (D >= 1: the shift is below 64).
            self.word(eight_digits(fraction) >> (8 * (8 - D.min(8))), D);
        } else {
            // D - 8 digits (1 to 7), then eight.
            let high = eight_digits(fraction / 100_000_000);
            self.word(high >> (8 * (16 - D.clamp(9, 15))), D - 8);
            self.word(eight_digits(fraction % 100_000_000), 8);
        }
    }
}

/// The text of the integer part last written in a column: its value (u64::MAX: none yet) and its
/// digits as one word.
#[derive(Debug, Clone, Copy)]
pub(super) struct IntegerText {
    value: u64,
    word: u64,
    len: usize,
}

impl Default for IntegerText {
    fn default() -> Self {
        IntegerText { value: u64::MAX, word: 0, len: 0 }
    }
}

/// The time column of a record whose times all have exact D-decimal texts, written from each
/// sample's index: the integer part (kept while it repeats) and one of `rate` fraction texts.
///
/// Exact, hence the same bytes as writing each f64 time: with an integer sample rate f that
/// divides 10^D, the time of sample k is M / 10^D with M = k 10^D / f an integer; the f64 time k / f
/// and its product by 10^D each round once, so the product is within M 2^-52 of M, below 1/4 for
/// M < 2^50, and rounds to M.
#[derive(Debug, Clone)]
pub(super) struct CountedTime {
    /// Samples per second.
    rate: u64,
    /// The point and D digits of the fraction of each sample within a second, 16 bytes each.
    fractions: Vec<[u8; 16]>,
    /// Bytes of each fraction text (D + 1; 0 for D = 0).
    fraction_len: usize,
    /// Text of the current whole second (below 10^8).
    second: IntegerText,
    /// The current sample within the second.
    within: usize,
}

/// Largest sample rate with a fraction table (16 bytes a sample of one second).
const COUNTED_TIME_MAX_RATE: f64 = 100_000.0;

impl CountedTime {
    /// The counted time column for `samples` samples at `sample_rate_hz` written with `decimals`
    /// decimals (none for the shortest form), when it is exact (see the type) and the record is
    /// shorter than 10^8 s; none otherwise.
    pub(super) fn new(sample_rate_hz: f64, samples: u64, decimals: Option<usize>) -> Option<CountedTime> {
        let d = decimals?;
        let ok_rate = (1.0..=COUNTED_TIME_MAX_RATE).contains(&sample_rate_hz) && sample_rate_hz.fract() == 0.0;
        if !ok_rate || d >= POW10.len() {
            return None;
        }
        let rate = sample_rate_hz as u64;
        let unit = 10u64.pow(d as u32);
        if !unit.is_multiple_of(rate) {
            return None;
        }
        let step = unit / rate;
        let last = samples.saturating_sub(1);
        if last.checked_mul(step)? >= 1 << 50 || last / rate >= 100_000_000 {
            return None;
        }
        let fractions = (0..rate)
            .map(|r| {
                let mut entry = [0u8; 16];
                if d > 0 {
                    let text = format!(".{:0d$}", r * step);
                    entry[..text.len()].copy_from_slice(text.as_bytes());
                }
                entry
            })
            .collect();
        let fraction_len = if d > 0 { d + 1 } else { 0 };
        let mut counted = CountedTime { rate, fractions, fraction_len, second: IntegerText::default(), within: 0 };
        counted.start_at(0);
        Some(counted)
    }

    /// Moves to sample `index` (the next one written).
    pub(super) fn start_at(&mut self, index: u64) {
        self.set_second(index / self.rate);
        self.within = (index % self.rate) as usize;
    }

    /// Makes `second` the current whole second, with its text.
    fn set_second(&mut self, second: u64) {
        let digits = eight_digits(second);
        let zeros = leading_zero_digits(digits);
        self.second = IntegerText { value: second, word: digits >> (8 * zeros), len: 8 - zeros };
    }

    /// Appends the time of the current sample (a number: [`NUMBER_ROOM`] bytes) and moves on to
    /// the next sample.
    #[inline(always)]
    pub(super) fn put_and_advance(&mut self, text: &mut Cursor<'_>) {
        text.word(self.second.word, self.second.len);
        let fraction = &self.fractions[self.within];
        text.bytes[text.end..text.end + 16].copy_from_slice(fraction);
        text.end += self.fraction_len;
        self.within += 1;
        if self.within == self.fractions.len() {
            self.within = 0;
            self.set_second(self.second.value + 1);
        }
    }
}

/// How a number column is written (chosen once per record, so that the row loop is compiled for
/// it; see [`with_number_text`]).
pub(super) trait NumberText {
    /// Decimals written, or none for the shortest form.
    const DECIMALS: Option<usize>;

    /// Appends `v` (a number: [`NUMBER_ROOM`] bytes).
    fn put(text: &mut Cursor<'_>, v: f64);

    /// Appends `v` of a column whose integer part often repeats (its text kept in `repeat`).
    #[inline(always)]
    fn put_repeating(text: &mut Cursor<'_>, v: f64, _repeat: &mut IntegerText) {
        Self::put(text, v);
    }
}

/// Shortest round-trip text (Ryu).
pub(super) struct Shortest;

impl NumberText for Shortest {
    const DECIMALS: Option<usize> = None;

    #[inline]
    fn put(text: &mut Cursor<'_>, v: f64) {
        text.shortest(v);
    }
}

/// `D` decimals: v 10^D rounded half away from zero, as integer digits with the point put in;
/// values too large for that (|v 10^D| >= 2^53) and non-finite ones in the shortest form.
pub(super) struct Fixed<const D: usize>;

impl<const D: usize> NumberText for Fixed<D> {
    const DECIMALS: Option<usize> = Some(D);

    #[inline(always)]
    fn put(text: &mut Cursor<'_>, v: f64) {
        match Self::scaled(v) {
            Some((m, negative)) => text.fixed::<D>(m, negative),
            None => text.shortest(v),
        }
    }

    #[inline(always)]
    fn put_repeating(text: &mut Cursor<'_>, v: f64, repeat: &mut IntegerText) {
        match Self::scaled(v) {
            Some((m, negative)) => text.fixed_repeating::<D>(m, negative, repeat),
            None => text.shortest(v),
        }
    }
}

impl<const D: usize> Fixed<D> {
    /// |v| 10^D rounded half away from zero and whether it is written with a minus sign; none
    /// when it is not below 2^53 (or not finite): then the shortest form is written.
    #[inline(always)]
    fn scaled(v: f64) -> Option<(u64, bool)> {
        let unrounded = v * POW10[D];
        let magnitude = unrounded.abs();
        if magnitude.is_nan() || magnitude >= EXACT_INT_LIMIT {
            return None;
        }
        // Round half away from zero, as `f64::round`: below 2^53 the truncation and the
        // remainder are exact, and the result stays below 2^53 (from 2^52 on every value is an
        // integer).
        // (Through i64: the same values below 2^53, converted by single instructions on x86-64.)
        let whole = magnitude as i64;
        let m = (whole + i64::from(magnitude - whole as f64 >= 0.5)) as u64;
        // A negative value that rounds to zero is written without its sign.
        Some((m, unrounded < 0.0 && m != 0))
    }
}

/// Calls `$run::<N>($args)` with the [`NumberText`] `N` of a [`NumberFormat`], or returns an
/// invalid-option error for more than 15 decimals.
macro_rules! with_number_text {
    ($format:expr, $run:ident ( $($arg:expr),* $(,)? )) => {
        match $format {
            NumberFormat::Shortest => $run::<Shortest, _>($($arg),*),
            NumberFormat::Fixed { decimals } => match decimals {
                0 => $run::<Fixed<0>, _>($($arg),*),
                1 => $run::<Fixed<1>, _>($($arg),*),
                2 => $run::<Fixed<2>, _>($($arg),*),
                3 => $run::<Fixed<3>, _>($($arg),*),
                4 => $run::<Fixed<4>, _>($($arg),*),
                5 => $run::<Fixed<5>, _>($($arg),*),
                6 => $run::<Fixed<6>, _>($($arg),*),
                7 => $run::<Fixed<7>, _>($($arg),*),
                8 => $run::<Fixed<8>, _>($($arg),*),
                9 => $run::<Fixed<9>, _>($($arg),*),
                10 => $run::<Fixed<10>, _>($($arg),*),
                11 => $run::<Fixed<11>, _>($($arg),*),
                12 => $run::<Fixed<12>, _>($($arg),*),
                13 => $run::<Fixed<13>, _>($($arg),*),
                14 => $run::<Fixed<14>, _>($($arg),*),
                15 => $run::<Fixed<15>, _>($($arg),*),
                _ => Err(SimCsvError::InvalidOption(format!("fixed decimals = {decimals}: must be within 0..=15"))),
            },
        }
    };
}
pub(super) use with_number_text;

#[cfg(test)]
mod tests {
    use super::*;

    proptest::proptest! {
        /// Fixed notation by SWAR digits equals the plain integer formatting of the same value.
        #[test]
        fn fixed_equals_integer_formatting(
            v in 0u64..10_000_000_000_000_000,
            digits in 1u32..17,
            decimals in 0usize..16,
            negative: bool,
        ) {
            // Every length of integer, so that the one-word path (below 10^8) is taken often.
            let v = v % 10u64.pow(digits);
            let mut text = TextBuf::new(1024);
            fixed_any(&mut text, v, decimals, negative, None);
            let unit = 10u64.pow(decimals as u32);
            let sign = if negative { "-" } else { "" };
            let want = if decimals == 0 {
                format!("{sign}{v}")
            } else {
                format!("{sign}{}.{:0decimals$}", v / unit, v % unit)
            };
            proptest::prop_assert_eq!(String::from_utf8(text.bytes[..text.end].to_vec()).unwrap(), want);
        }

        /// Integers by SWAR digits equal the standard formatting, for every length.
        #[test]
        fn integer_equals_standard_formatting(v: u64, digits in 1u32..17) {
            let v = v % 10u64.pow(digits);
            let mut text = TextBuf::new(1024);
            text.with_room(NUMBER_ROOM, |c| c.integer(v));
            proptest::prop_assert_eq!(String::from_utf8(text.bytes[..text.end].to_vec()).unwrap(), v.to_string());
        }
    }

    proptest::proptest! {
        /// A column written with its repeating integer part kept gives the same text as one
        /// written value by value, whatever the sequence of values.
        #[test]
        fn repeating_integer_text_changes_nothing(
            values in proptest::collection::vec((0u64..10_000_000_000_000_000, 1u32..17, 0u64..3), 1..40),
            decimals in 0usize..16,
        ) {
            let mut repeat = IntegerText::default();
            let (mut kept, mut each) = (TextBuf::new(16), TextBuf::new(16));
            let mut previous = 0u64;
            for &(v, digits, step) in &values {
                // Runs of values with the same integer part, and jumps.
                let v = if step < 2 { previous + step } else { v % 10u64.pow(digits) };
                previous = v;
                let negative = step == 1 && v % 3 == 0;
                fixed_any(&mut kept, v, decimals, negative, Some(&mut repeat));
                fixed_any(&mut each, v, decimals, negative, None);
                kept.byte(b' ');
                each.byte(b' ');
            }
            proptest::prop_assert_eq!(&kept.bytes[..kept.end], &each.bytes[..each.end]);
        }
    }

    /// `Cursor::fixed` (or `fixed_repeating` with `repeat`) with D given at run time.
    fn fixed_any(text: &mut TextBuf, v: u64, decimals: usize, negative: bool, repeat: Option<&mut IntegerText>) {
        fn put<const D: usize>(text: &mut TextBuf, v: u64, negative: bool, repeat: Option<&mut IntegerText>) {
            text.with_room(NUMBER_ROOM, |c| match repeat {
                Some(r) => c.fixed_repeating::<D>(v, negative, r),
                None => c.fixed::<D>(v, negative),
            });
        }
        let put = [
            put::<0>, put::<1>, put::<2>, put::<3>, put::<4>, put::<5>, put::<6>, put::<7>, put::<8>, put::<9>,
            put::<10>, put::<11>, put::<12>, put::<13>, put::<14>, put::<15>,
        ];
        put[decimals](text, v, negative, repeat);
    }

    /// `Fixed::<D>::scaled` with D given at run time.
    fn scaled_any(v: f64, decimals: usize) -> Option<(u64, bool)> {
        let scaled = [
            Fixed::<0>::scaled,
            Fixed::<1>::scaled,
            Fixed::<2>::scaled,
            Fixed::<3>::scaled,
            Fixed::<4>::scaled,
            Fixed::<5>::scaled,
            Fixed::<6>::scaled,
            Fixed::<7>::scaled,
            Fixed::<8>::scaled,
            Fixed::<9>::scaled,
            Fixed::<10>::scaled,
            Fixed::<11>::scaled,
            Fixed::<12>::scaled,
            Fixed::<13>::scaled,
            Fixed::<14>::scaled,
            Fixed::<15>::scaled,
        ];
        scaled[decimals](v)
    }

    /// The scaled integer by `f64::round` (half away from zero): none at or above 2^53.
    fn scaled_by_round(v: f64, decimals: usize) -> Option<(u64, bool)> {
        let unrounded = v * 10f64.powi(decimals as i32);
        let r = unrounded.round();
        (unrounded.abs() < EXACT_INT_LIMIT && r.abs() < EXACT_INT_LIMIT).then(|| (r.abs() as u64, r < 0.0))
    }

    proptest::proptest! {
        /// Rounding by truncation and remainder equals `f64::round` below 2^53.
        #[test]
        fn scaled_rounds_as_f64_round(x in -9.0e15f64..9.0e15, k in 0i32..6, decimals in 0usize..16) {
            let v = x / 10f64.powi(k * 3 + decimals as i32);
            proptest::prop_assert_eq!(scaled_any(v, decimals), scaled_by_round(v, decimals), "{} at {}", v, decimals);
        }
    }

    #[test]
    fn scaled_at_halves_and_limits() {
        let values = [
            0.5,
            -0.5,
            1.5,
            -2.5,
            0.49999999999999994,
            -0.49999999999999994,
            4503599627370495.5,
            4503599627370496.0,
            9007199254740991.0,
            9007199254740992.0,
            0.0,
            -0.0,
            f64::NAN,
            f64::INFINITY,
        ];
        for v in values {
            assert_eq!(scaled_any(v, 0), scaled_by_round(v, 0), "{v}");
        }
        assert_eq!(scaled_any(-0.0, 3), Some((0, false)));
        assert_eq!(scaled_any(-0.03125, 1), Some((0, false)));
        assert_eq!(scaled_any(-0.1875, 1), Some((2, true)));
        assert_eq!(scaled_any(-0.25, 1), Some((3, true)));
    }

    #[test]
    fn eight_digits_of_edge_values() {
        for n in [0u64, 1, 9, 10, 99, 100, 999, 1_000, 9_999, 10_000, 12_345_678, 99_999_999] {
            assert_eq!(eight_digits(n).to_le_bytes(), *format!("{n:08}").as_bytes(), "{n}");
        }
        // The two four-digit lanes are computed apart (masked): n = k * 10^4 + k gives every
        // value 0..=9999 in both, so this covers every lane value exhaustively.
        for n in (0u64..10_000).map(|k| k * 10_000 + k) {
            assert_eq!(eight_digits(n).to_le_bytes(), *format!("{n:08}").as_bytes(), "{n}");
        }
    }

    /// The values written by `put`, each followed by a space.
    fn written(values: &[f64], put: fn(&mut Cursor<'_>, f64)) -> String {
        let mut text = TextBuf::new(0);
        for &v in values {
            text.with_room(NUMBER_ROOM + 1, |c| {
                put(c, v);
                c.byte(b' ');
            });
        }
        String::from_utf8(text.bytes[..text.end].to_vec()).unwrap()
    }

    #[test]
    fn fixed_decimals_are_rounded_and_padded() {
        let values = [2.5, -0.00004, -0.00006, 1.23456, 0.0, 12345.25, 1e300, f64::NAN, -f64::INFINITY];
        // A negative value that rounds to zero is written without its sign.
        let want = "2.5000 0.0000 -0.0001 1.2346 0.0000 12345.2500 1e300 NaN -inf ";
        assert_eq!(written(&values, Fixed::<4>::put), want);
        let want = "0.005 -0.005 10.000 1234567.000 99.000 ";
        assert_eq!(written(&[0.005, -0.005, 9.9996, 1234567.0, 99.0], Fixed::<3>::put), want);
        // Just below 2^53 after scaling: integer digits; at 2^53: the shortest form.
        let values = [9_007_199_254_740_991.0, 9_007_199_254_740_992.0, 900_719_925_474_099.1];
        assert_eq!(written(&values, Fixed::<0>::put), "9007199254740991 9007199254740992.0 900719925474099 ");
        let want = "9007199254740991.0 9007199254740992.0 900719925474099.1 ";
        assert_eq!(written(&values, Fixed::<1>::put), want);
    }

    #[test]
    fn the_buffer_grows_past_its_first_size() {
        let mut text = TextBuf::new(0);
        for i in 0..10_000u64 {
            text.with_room(NUMBER_ROOM + 1, |c| {
                c.integer(i);
                c.byte(b',');
            });
        }
        let want: String = (0..10_000).map(|i| format!("{i},")).collect();
        assert_eq!(String::from_utf8(text.bytes[..text.end].to_vec()).unwrap(), want);
    }
}
