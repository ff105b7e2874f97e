//! The sampling interval of a record from its time stamps, and the samples missing from it:
//! the one estimator every command, the static test and the Allan analysis use.
//!
//! Rule (docs/METHODS.md, "Sampling interval"):
//! - a first interval: the span over the count, `(t[n-1] - t[0]) / (n - 1)`, unless it differs
//!   by more than 5 % from the median of the mean intervals of blocks of [`BLOCK`] intervals
//!   (then a long gap stretches the span, and the block median is taken); block means are
//!   insensitive to jitter and to the bursts of host-stamped logs (a PC stamping an MPU6050
//!   read over USB: intervals of 0.9 ms, then long ones, about 100 Hz on average);
//! - a gap (missing samples) is a persistent shift of the time line, not one long interval: at
//!   every interval longer than 1.5 intervals, the floor (minimum) of the lateness
//!   `e_j = t_j - j dt` over [`WINDOW`] samples after it is compared with the floor over the
//!   [`WINDOW`] samples before it (back to the previous gap); a shift of k intervals (rounded,
//!   k >= 1) is a gap of k missing samples. A late stamp followed by a short interval (jitter, a
//!   burst) leaves the floor where it was: no gap;
//! - the estimate is the span over the count of intervals including the missing samples,
//!   `(t[n-1] - t[0]) / (n - 1 + missing)`, found again once with that interval (exact for
//!   uniform stamps, whatever their rounding; the mean rate of jittered or bursty stamps);
//! - a stamp that does not increase (repeated, reversed, not finite) is irregular: counted and
//!   the first one reported; it is no gap.
//!
//! The clock model (docs/METHODS.md, "Clock model"), decided from the intervals themselves
//! before the gap search:
//! - a **sample clock**: at least [`ON_GRID_SHARE`] of the intervals lie within
//!   [`GRID_TOLERANCE`] of a whole multiple of one base interval (the median of the intervals
//!   up to 1.5 times their 5th percentile). Each interval of k > 1 base intervals is a gap of
//!   k - 1 dropped samples (a PX4 `sensor_combined` topic stepping by 4.000 and 8.000 ms is
//!   250 Hz with its drops, not 211.7 Hz);
//! - else **arrival stamps** (jitter and bursts about a steady mean, stamped by a host): the
//!   floor rule below finds gaps only where the time line shifts by more than the stamps' own
//!   spread (the range of the lateness over the windows on either side), so bursts of 0.5 to
//!   1 ms every 30 to 70 ms invent no gaps; the rate is the samples over the span.
//! - a stamp going back to or before the record's first stamp (a clock reset, a trailer of
//!   zeros) ends the record: the estimate is that of the stamps before it, and
//!   [`IntervalEstimate::reset`] says where (the reader's clean part is never refused).
//!
//! The mean rather than the median: stamps written with a few decimals or by a host clock
//! jitter around the true interval; their median is one of the jittered values (0.9 ms for the
//! MPU6050 log, 1125 Hz), their mean over the span converges on the true one.

use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Intervals per block of the robust first interval.
pub const BLOCK: usize = 64;

/// Samples on each side of a long interval over which the floor of the lateness is taken.
pub const WINDOW: usize = 32;

/// Where the sample rate of a record came from (serialized as [`SampleRateSource::text`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SampleRateSource {
    /// Given by the user (option or plan).
    Given,
    /// Estimated from the time stamps by [`estimate_interval`].
    TimeStamps,
}

impl SampleRateSource {
    /// The description used in reports and JSON.
    pub fn text(self) -> &'static str {
        match self {
            SampleRateSource::Given => "given",
            SampleRateSource::TimeStamps => "estimated from the time stamps (mean interval)",
        }
    }
}

impl Serialize for SampleRateSource {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.text())
    }
}

impl<'de> Deserialize<'de> for SampleRateSource {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let text = String::deserialize(d)?;
        [SampleRateSource::Given, SampleRateSource::TimeStamps]
            .into_iter()
            .find(|s| s.text() == text)
            .ok_or_else(|| serde::de::Error::custom(format!("unknown sample-rate source '{text}'")))
    }
}

/// The first interval outside ±50 % of the nominal one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IrregularInterval {
    /// Index of the sample that ends the interval (the interval is `t[index] - t[index - 1]`).
    pub index: usize,
    /// The interval, s (may be negative or not finite).
    pub interval_s: f64,
}

/// Samples missing before one sample (a gap in the time stamps).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Gap {
    /// Index of the first sample after the gap.
    pub index: usize,
    /// Number of samples missing before it.
    pub missing: usize,
    /// The interval that holds the gap, s.
    pub interval_s: f64,
}

/// The estimated sampling interval of a record.
#[derive(Debug, Clone, PartialEq)]
pub struct IntervalEstimate {
    /// The estimate: the mean interval (see the module's rule), s.
    pub interval_s: f64,
    /// The first interval of the rule (span over count, or the median block mean), s.
    pub nominal_s: f64,
    /// The first irregular interval (a gap or a stamp that does not increase), if any.
    pub first_irregular: Option<IrregularInterval>,
    /// Number of irregular intervals (gaps and stamps that do not increase).
    pub irregular: usize,
    /// The gaps, in order.
    pub gaps: Vec<Gap>,
    /// Samples missing in all gaps.
    pub missing: usize,
    /// The first stamp that does not increase (repeated, reversed or not finite), if any.
    pub first_non_increasing: Option<IrregularInterval>,
    /// The clock model the gaps were found with.
    pub clock: ClockModel,
    /// A stamp going back that ended the record (the estimate covers the stamps before it).
    pub reset: Option<Reset>,
}

impl IntervalEstimate {
    /// The sample rate, Hz.
    pub fn rate_hz(&self) -> f64 {
        1.0 / self.interval_s
    }
}

/// Share of the examined intervals that must lie on the grid of one base interval for a
/// sample clock.
pub const ON_GRID_SHARE: f64 = 0.99;

/// Largest distance of an interval from a whole multiple of the base interval, in base
/// intervals, for it to lie on the grid.
pub const GRID_TOLERANCE: f64 = 0.1;

/// Intervals examined for the clock model: all of them up to this many, else this many in
/// eight windows spread over the record.
pub const CLOCK_EXAMINED: usize = 1 << 16;

/// Share of the examined intervals within [`STEADY_TOLERANCE`] of their median for arrival
/// stamps to be a steady stream ([`ClockModel::steady_s`]).
pub const STEADY_SHARE: f64 = 0.9;

/// Largest relative distance of an interval from the median interval for it to be regular.
pub const STEADY_TOLERANCE: f64 = 0.25;

/// What kind of clock made a record's time stamps (see the module's rule).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ClockKind {
    /// Intervals at whole multiples of one base interval: drops counted from the multiples.
    SampleClock,
    /// Jitter and bursts about a steady mean: rate = samples / span, gaps only where the
    /// stream stopped.
    ArrivalStamps,
}

/// The clock model of a record and the evidence it was decided on.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ClockModel {
    /// The kind decided.
    pub kind: ClockKind,
    /// The base interval the grid was tried with (the median of the intervals up to 1.5
    /// times their 5th percentile), s.
    pub base_s: f64,
    /// Intervals examined.
    pub examined: usize,
    /// Share of them within [`GRID_TOLERANCE`] of a whole multiple of `base_s`.
    pub on_grid: f64,
    /// The shortest examined interval, s.
    pub shortest_s: f64,
    /// The longest examined interval, s.
    pub longest_s: f64,
    /// Arrival stamps of a steady stream (at least [`STEADY_SHARE`] of the intervals within
    /// [`STEADY_TOLERANCE`] of their median): the mean of those regular intervals, s, from
    /// which the gap search starts. A dropped sample then shows as a shift of the time line by
    /// one interval, which a start from the span over the count (stretched by the drops
    /// themselves) would hide in the lateness's drift.
    pub steady_s: Option<f64>,
}

impl std::fmt::Display for ClockModel {
    /// The decision with its evidence, as a note.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let ms = |s: f64| s * 1e3;
        match self.kind {
            ClockKind::SampleClock => write!(
                f,
                "sample clock: {:.2} % of {} intervals lie within {} % of a whole multiple of {:.6} ms (intervals {:.6} to {:.6} ms); longer multiples are dropped samples",
                self.on_grid * 100.0,
                self.examined,
                GRID_TOLERANCE * 100.0,
                ms(self.base_s),
                ms(self.shortest_s),
                ms(self.longest_s)
            ),
            ClockKind::ArrivalStamps => {
                write!(
                    f,
                    "arrival stamps: only {:.2} % of {} intervals lie within {} % of a whole multiple of the shortest regular one ({:.6} ms; intervals {:.6} to {:.6} ms): ",
                    self.on_grid * 100.0,
                    self.examined,
                    GRID_TOLERANCE * 100.0,
                    ms(self.base_s),
                    ms(self.shortest_s),
                    ms(self.longest_s)
                )?;
                match self.steady_s {
                    Some(s) => write!(
                        f,
                        "a steady stream ({} % or more of the intervals within {} % of {:.6} ms, their mean): jitter is no gap, a shift of the time line by whole intervals (a long interval followed by regular ones) is that many dropped samples",
                        STEADY_SHARE * 100.0,
                        STEADY_TOLERANCE * 100.0,
                        ms(s)
                    ),
                    None => write!(
                        f,
                        "the rate is the samples over the span, jitter and bursts are no gaps, only a stop of the stream is"
                    ),
                }
            }
        }
    }
}

/// A stamp that goes back to or before the record's first stamp (a clock reset, a trailer of
/// zeros): the record ends before it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Reset {
    /// Index of the stamp that goes back (the first one left out).
    pub index: usize,
    /// The stamp before it, s.
    pub from_s: f64,
    /// The stamp, s.
    pub to_s: f64,
    /// Stamps left out (from `index` to the end).
    pub left_out: usize,
}

/// Why no interval could be estimated.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SamplingError {
    /// Fewer than two stamps.
    #[error("fewer than two samples: no sampling interval")]
    TooShort,
    /// No finite, increasing pair of stamps.
    #[error("the time stamps do not increase: expected increasing time stamps")]
    NotIncreasing,
}

/// Time stamps the estimator reads: a slice of seconds, or [`CompactStamps`]; both give the
/// same values, so the same estimate.
pub trait Stamps {
    /// Number of stamps.
    fn len(&self) -> usize;
    /// Whether there are none.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// The stamps as a slice, when they are held as one.
    fn as_slice(&self) -> Option<&[f64]>;
    /// Appends stamps `from..to` to `out`.
    fn copy_range(&self, from: usize, to: usize, out: &mut Vec<f64>);
}

impl Stamps for [f64] {
    fn len(&self) -> usize {
        <[f64]>::len(self)
    }
    fn as_slice(&self) -> Option<&[f64]> {
        Some(self)
    }
    fn copy_range(&self, from: usize, to: usize, out: &mut Vec<f64>) {
        out.extend_from_slice(&self[from..to]);
    }
}

/// Stamps decoded per row of one decoding step.
const CHECK: usize = 64;
/// The code of a stamp stored whole.
const ESCAPE: i8 = i8::MIN;

/// Time stamps stored losslessly in about 1.4 bytes each instead of 8, for the gap search of a
/// long record: the second difference of consecutive stamps' bit patterns in one byte (it is
/// within a few units for stamps written with a fixed number of decimals or by a steady
/// clock), the whole bit pattern where it is not, and the state at every 64th stamp (and at
/// the start of every appended part) for access at any row. Every stamp reads back bit for bit
/// as pushed (NaN and infinities too). Parts encoded apart (the pieces of a file read in
/// parallel) are joined by [`CompactStamps::append`]; equality compares the stamps, not the
/// encoding.
#[derive(Debug, Clone, Default)]
pub struct CompactStamps {
    /// Per stamp: its second difference, or [`ESCAPE`].
    codes: Vec<i8>,
    /// The bit patterns of the escaped stamps, in order.
    escaped: Vec<u64>,
    /// Access points, by increasing row: the row, its stamp's bit pattern, its first
    /// difference, and the escaped stamps up to and including it.
    checks: Vec<(usize, u64, u64, usize)>,
    prev_bits: u64,
    prev_d1: u64,
}

impl PartialEq for CompactStamps {
    /// The same stamps, bit for bit (however they were encoded and joined).
    fn eq(&self, other: &Self) -> bool {
        let bits = |c: &CompactStamps| c.to_vec().iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        self.codes.len() == other.codes.len() && bits(self) == bits(other)
    }
}

impl Eq for CompactStamps {}

/// The code of a second difference of bit patterns: itself when it fits in -127..=127, else
/// [`ESCAPE`] (the stamp is then stored whole).
#[inline(always)]
fn code_of(d2: u64) -> i8 {
    let d2 = d2 as i64;
    if (-127..=127).contains(&d2) {
        d2 as i8
    } else {
        ESCAPE
    }
}

/// `out[i]` = the code of stamp `t[i + 2]` ([`code_of`] its bit patterns' second difference),
/// for `out.len() == t.len() - 2`: independent per stamp, so vectorised (AVX-512 or AVX2 where
/// the CPU has them, chosen at run time; the same integer operations everywhere).
fn second_difference_codes(t: &[f64], out: &mut [i8]) {
    #[inline(always)]
    fn body(t: &[f64], out: &mut [i8]) {
        let n = out.len();
        let (a, b, c) = (&t[..n], &t[1..n + 1], &t[2..n + 2]);
        for (o, ((a, b), c)) in out.iter_mut().zip(a.iter().zip(b).zip(c)) {
            let (a, b, c) = (a.to_bits(), b.to_bits(), c.to_bits());
            *o = code_of(c.wrapping_sub(b).wrapping_sub(b.wrapping_sub(a)));
        }
    }
    #[cfg(target_arch = "x86_64")]
    {
        #[target_feature(enable = "avx512f,avx512bw")]
        unsafe fn body_avx512(t: &[f64], out: &mut [i8]) {
            body(t, out)
        }
        #[target_feature(enable = "avx2")]
        unsafe fn body_avx2(t: &[f64], out: &mut [i8]) {
            body(t, out)
        }
        if std::is_x86_feature_detected!("avx512f") && std::is_x86_feature_detected!("avx512bw") {
            // SAFETY: the CPU has AVX-512 F and BW (checked just above).
            return unsafe { body_avx512(t, out) };
        }
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2 (checked just above).
            return unsafe { body_avx2(t, out) };
        }
    }
    body(t, out)
}

impl CompactStamps {
    /// Appends a stamp.
    pub fn push(&mut self, t: f64) {
        let n = self.codes.len();
        let bits = t.to_bits();
        let d1 = if n == 0 { 0 } else { bits.wrapping_sub(self.prev_bits) };
        let code = if n == 0 { ESCAPE } else { code_of(d1.wrapping_sub(self.prev_d1)) };
        self.codes.push(code);
        if code == ESCAPE {
            self.escaped.push(bits);
        }
        if n.is_multiple_of(CHECK) {
            self.checks.push((n, bits, d1, self.escaped.len()));
        }
        self.prev_bits = bits;
        self.prev_d1 = d1;
    }

    /// Appends stamps: the same codes as [`CompactStamps::push`] one by one. A stamp's code
    /// depends only on it and the two stamps before (push's state is their differences), so
    /// after the first two stamps the codes are made in one sweep that does not wait from stamp
    /// to stamp; the escaped stamps and the access points are then taken in order.
    pub fn extend_from_slice(&mut self, t: &[f64]) {
        let head = t.len().min(2);
        for &v in &t[..head] {
            self.push(v);
        }
        let Some(&last) = t.get(2..).and_then(<[f64]>::last) else { return };
        let base = self.codes.len();
        self.codes.resize(base + t.len() - 2, 0);
        second_difference_codes(t, &mut self.codes[base..]);
        let end = self.codes.len();
        // Row r (base <= r < end) is stamp t[r + 2 - base]; row base - 1 is t[1].
        let bits = |r: usize| t[r + 2 - base].to_bits();
        let mut scanned = base;
        let mut check = base.next_multiple_of(CHECK);
        loop {
            // The escaped stamps up to the next access point (included), then the point.
            let upto = if check < end { check + 1 } else { end };
            let codes = &self.codes[scanned..upto];
            // (Escapes are rare: a branch-free test of the run first, which vectorises.)
            if codes.iter().fold(false, |any, &c| any | (c == ESCAPE)) {
                for (k, &c) in codes.iter().enumerate() {
                    if c == ESCAPE {
                        self.escaped.push(bits(scanned + k));
                    }
                }
            }
            scanned = upto;
            if check >= end {
                break;
            }
            let d1 = bits(check).wrapping_sub(t[check + 1 - base].to_bits());
            self.checks.push((check, bits(check), d1, self.escaped.len()));
            check += CHECK;
        }
        self.prev_bits = last.to_bits();
        self.prev_d1 = self.prev_bits.wrapping_sub(t[t.len() - 2].to_bits());
    }

    /// Appends the stamps of `other` (encoded on its own, as a piece of a file read in
    /// parallel): the result reads back as if every stamp had been pushed here. Only `other`'s
    /// first two stamps are encoded again (its first difference now follows this part's last
    /// stamp), so the cost is a copy of its codes.
    pub fn append(&mut self, mut other: CompactStamps) {
        if other.codes.is_empty() {
            return;
        }
        if self.codes.is_empty() {
            *self = other;
            return;
        }
        let base = self.codes.len();
        // Other's first stamp is stored whole; its first difference becomes the real one.
        let bits0 = other.escaped[0];
        let d1_0 = bits0.wrapping_sub(self.prev_bits);
        // Its second stamp's code was taken against a first difference of zero.
        let mut inserted = false;
        if other.codes.len() > 1 && other.codes[1] != ESCAPE {
            let d1_1 = other.codes[1] as i64 as u64;
            other.codes[1] = code_of(d1_1.wrapping_sub(d1_0));
            if other.codes[1] == ESCAPE {
                other.escaped.insert(1, bits0.wrapping_add(d1_1));
                inserted = true;
            }
        }
        let ebase = self.escaped.len();
        self.checks.extend(other.checks.iter().map(|&(row, bits, d1, e)| {
            let d1 = if row == 0 { d1_0 } else { d1 };
            let e = e + ebase + usize::from(inserted && row >= 1);
            (row + base, bits, d1, e)
        }));
        self.codes.extend_from_slice(&other.codes);
        self.escaped.extend_from_slice(&other.escaped);
        self.prev_bits = other.prev_bits;
        self.prev_d1 = if other.codes.len() == 1 { d1_0 } else { other.prev_d1 };
    }

    /// Bytes held (capacity of the three parts).
    pub fn bytes(&self) -> usize {
        self.codes.capacity() + 8 * self.escaped.capacity() + 32 * self.checks.capacity()
    }

    /// Every stamp.
    pub fn to_vec(&self) -> Vec<f64> {
        let mut v = Vec::with_capacity(self.codes.len());
        self.copy_range(0, self.codes.len(), &mut v);
        v
    }
}

impl Stamps for CompactStamps {
    fn len(&self) -> usize {
        self.codes.len()
    }
    fn as_slice(&self) -> Option<&[f64]> {
        None
    }
    fn copy_range(&self, from: usize, to: usize, out: &mut Vec<f64>) {
        let to = to.min(self.codes.len());
        if from >= to {
            return;
        }
        // The last access point at or before `from` (the first is at row 0).
        let k = self.checks.partition_point(|c| c.0 <= from).saturating_sub(1);
        let (start, mut bits, mut d1, mut e) = self.checks[k];
        out.reserve(to - from);
        if start >= from {
            out.push(f64::from_bits(bits));
        }
        let mut step = |code: i8| {
            if code == ESCAPE {
                let b = self.escaped[e];
                e += 1;
                d1 = b.wrapping_sub(bits);
                bits = b;
            } else {
                d1 = d1.wrapping_add(code as i64 as u64);
                bits = bits.wrapping_add(d1);
            }
            bits
        };
        // Decode up to `from` (at most 63 stamps), then keep the stamps.
        if start + 1 < from {
            self.codes[start + 1..from].iter().for_each(|&c| {
                step(c);
            });
        }
        out.extend(self.codes[from.max(start + 1)..to].iter().map(|&c| f64::from_bits(step(c))));
    }
}

/// Stamps read in order by chunks (with the few before the current one kept), for the
/// estimator's passes over [`Stamps`] of either kind.
struct Cursor<'a, S: Stamps + ?Sized> {
    t: &'a S,
    buf: Vec<f64>,
    from: usize,
}

/// Stamps per chunk of a [`Cursor`] and of the passes over the stamps (small in tests, so
/// that chunk bounds fall everywhere).
const CHUNK: usize = if cfg!(test) { 97 } else { 8192 };

impl<'a, S: Stamps + ?Sized> Cursor<'a, S> {
    fn new(t: &'a S) -> Self {
        Cursor { t, buf: Vec::new(), from: 0 }
    }

    fn get(&mut self, i: usize) -> f64 {
        if let Some(s) = self.t.as_slice() {
            return s[i];
        }
        if i < self.from || i >= self.from + self.buf.len() {
            self.from = i.saturating_sub(2 * WINDOW);
            self.buf.clear();
            self.t.copy_range(self.from, (self.from + CHUNK).min(self.t.len()), &mut self.buf);
        }
        self.buf[i - self.from]
    }
}

/// Estimates the sampling interval from time stamps in seconds and finds the gaps (see the
/// module's rule).
///
/// ```
/// use gyrolab::sampling::estimate_interval;
/// let t: Vec<f64> = (0..1000).map(|i| i as f64 * 0.01).collect();
/// let e = estimate_interval(&t)?;
/// assert!((e.interval_s - 0.01).abs() < 1e-15);
/// assert!(e.first_irregular.is_none());
/// // Samples 500 and 501 missing: one gap of two samples before index 500.
/// let t: Vec<f64> = (0..1000).filter(|&i| i != 500 && i != 501).map(|i| i as f64 * 0.01).collect();
/// let e = estimate_interval(&t)?;
/// assert_eq!((e.gaps[0].index, e.gaps[0].missing, e.missing), (500, 2, 2));
/// assert!((e.interval_s - 0.01).abs() < 1e-15);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn estimate_interval(t: &[f64]) -> Result<IntervalEstimate, SamplingError> {
    estimate_interval_of(t)
}

/// [`estimate_interval`] over stamps of either kind (a slice, or [`CompactStamps`] a reader
/// filled block by block): the same rule, the same arithmetic, the same result.
pub fn estimate_interval_of<S: Stamps + Sync + ?Sized>(t: &S) -> Result<IntervalEstimate, SamplingError> {
    match estimate_core(t)? {
        Core::Estimate(e) => Ok(e),
        Core::Reset(r) => {
            // The stamps before the reset have no stamp that does not increase: no second reset.
            let mut e = match estimate_core(&Prefix { t, n: r.index })? {
                Core::Estimate(e) => e,
                Core::Reset(_) => return Err(SamplingError::NotIncreasing),
            };
            e.reset = Some(r);
            Ok(e)
        }
    }
}

/// The gaps of the first `end` stamps of `t` on the grid of a given interval `dt` (a rate the
/// user gave) rather than the stamps' own: by the multiples of `dt` for a sample clock, by the
/// shifts of the time line for arrival stamps (`clock` as [`estimate_interval`] decided it).
/// An interval of k given intervals (rounded, k >= 2) holds k - 1 missing samples.
pub fn gaps_at<S: Stamps + Sync + ?Sized>(t: &S, dt: f64, clock: &ClockModel, end: usize) -> Vec<Gap> {
    let prefix = Prefix { t, n: end.min(t.len()) };
    if !(dt.is_finite() && dt > 0.0) || prefix.n < 2 {
        return Vec::new();
    }
    match clock.kind {
        ClockKind::SampleClock => grid_gaps(&prefix, dt),
        ClockKind::ArrivalStamps => find_gaps(&prefix, dt, clock.steady_s.is_some()),
    }
}

/// The first `n` stamps of `t`.
struct Prefix<'a, S: ?Sized> {
    t: &'a S,
    n: usize,
}

impl<S: Stamps + ?Sized> Stamps for Prefix<'_, S> {
    fn len(&self) -> usize {
        self.n
    }
    fn as_slice(&self) -> Option<&[f64]> {
        self.t.as_slice().map(|s| &s[..self.n])
    }
    fn copy_range(&self, from: usize, to: usize, out: &mut Vec<f64>) {
        self.t.copy_range(from, to.min(self.n), out);
    }
}

/// The estimate, or the reset that ends the record first.
enum Core {
    Estimate(IntervalEstimate),
    Reset(Reset),
}

/// The estimator's rule over all of `t`, stopping at a stamp that goes back to or before the
/// first one.
fn estimate_core<S: Stamps + Sync + ?Sized>(t: &S) -> Result<Core, SamplingError> {
    let n = t.len();
    if n < 2 {
        return Err(SamplingError::TooShort);
    }
    let increasing = |d: f64| d.is_finite() && d > 0.0;
    // One pass, in parallel parts joined in order: stamps that do not increase, the first and
    // last finite stamps, and every BLOCK-th stamp for the block means.
    let pass = parallel_parts(n, |from, to| first_pass(t, from, to)).into_iter().reduce(FirstPass::join);
    let FirstPass { first, last, non_increasing, first_non_increasing, marks, longest } = pass.unwrap_or_default();
    // A stamp going back to or before the first one: the record ends there.
    if let (Some(g), Some((_, t_first))) = (first_non_increasing, first) {
        if g.index >= 2 && g.interval_s < 0.0 {
            let mut one = Vec::with_capacity(1);
            t.copy_range(g.index, g.index + 1, &mut one);
            if let Some(&to_s) = one.first() {
                if to_s <= t_first {
                    return Ok(Core::Reset(Reset {
                        index: g.index,
                        from_s: to_s - g.interval_s,
                        to_s,
                        left_out: n - g.index,
                    }));
                }
            }
        }
    }
    // First interval: the span over the count, or the median block mean when a long gap
    // stretches the span.
    let (Some((first, t_first)), Some((last, t_last))) = (first, last) else {
        return Err(SamplingError::NotIncreasing);
    };
    let span = t_last - t_first;
    if span.is_nan() || span <= 0.0 || last == first {
        return Err(SamplingError::NotIncreasing);
    }
    let span_dt = span / (last - first) as f64;
    let nominal = if n - 1 < 4 * BLOCK {
        // Too few blocks: the median interval.
        let mut all = Vec::with_capacity(n);
        t.copy_range(0, n, &mut all);
        let mut d: Vec<f64> = all.windows(2).map(|w| w[1] - w[0]).filter(|d| increasing(*d)).collect();
        if d.is_empty() {
            return Err(SamplingError::NotIncreasing);
        }
        let mid = d.len() / 2;
        *d.select_nth_unstable_by(mid, f64::total_cmp).1
    } else {
        let mut blocks: Vec<f64> =
            marks.windows(2).map(|w| (w[1] - w[0]) / BLOCK as f64).filter(|d| increasing(*d)).collect();
        if blocks.is_empty() {
            span_dt
        } else {
            // The median (the element a sort would put in the middle; no sort needed).
            let mid = blocks.len() / 2;
            let median = *blocks.select_nth_unstable_by(mid, f64::total_cmp).1;
            if (span_dt / median - 1.0).abs() <= 0.05 {
                span_dt
            } else {
                median
            }
        }
    };
    drop(marks);
    let clock = clock_model(t, nominal);
    let count = (last - first) as f64;
    let (gaps, nominal) = if clock.kind == ClockKind::SampleClock {
        // Drops from the multiples of the base interval, then once more with the mean interval
        // that counts them (a base read from a few windows may be off in its last digits).
        let mut gaps = if longest > GAP_FACTOR * clock.base_s { grid_gaps(t, clock.base_s) } else { Vec::new() };
        let missing: usize = gaps.iter().map(|g| g.missing).sum();
        if missing > 0 {
            gaps = grid_gaps(t, span / (count + missing as f64));
        }
        (gaps, clock.base_s)
    } else {
        // No interval over 1.5 times the nominal one: no gap, and no second pass to find one.
        // A steady stream's search starts from its regular intervals' mean (drops stretch the
        // span over the count, and the lateness drifts by that much over a window).
        let start = clock.steady_s.unwrap_or(nominal);
        let steady = clock.steady_s.is_some();
        let mut gaps = if longest > GAP_FACTOR * start { find_gaps(t, start, steady) } else { Vec::new() };
        let mut missing: usize = gaps.iter().map(|g| g.missing).sum();
        // Again with the interval that counts the missing samples, until the count holds.
        for _ in 0..3 {
            if missing == 0 {
                break;
            }
            let again = find_gaps(t, span / (count + missing as f64), steady);
            let m: usize = again.iter().map(|g| g.missing).sum();
            gaps = again;
            if m == missing {
                break;
            }
            missing = m;
        }
        (gaps, nominal)
    };
    let missing: usize = gaps.iter().map(|g| g.missing).sum();
    let interval_s = span / (count + missing as f64);
    let gap_irregular = gaps.first().map(|g| IrregularInterval { index: g.index, interval_s: g.interval_s });
    let first_irregular = match (gap_irregular, first_non_increasing) {
        (Some(a), Some(b)) => Some(if a.index <= b.index { a } else { b }),
        (a, b) => a.or(b),
    };
    Ok(Core::Estimate(IntervalEstimate {
        interval_s,
        nominal_s: nominal,
        first_irregular,
        irregular: gaps.len() + non_increasing,
        gaps,
        missing,
        first_non_increasing,
        clock,
        reset: None,
    }))
}

/// The clock model of `t` (see the module's rule) from its increasing intervals: all of them
/// up to [`CLOCK_EXAMINED`], else that many in eight windows spread over the record.
/// `nominal` stands in when no interval increases.
fn clock_model<S: Stamps + ?Sized>(t: &S, nominal: f64) -> ClockModel {
    let n = t.len();
    let mut stamps = Vec::new();
    let mut d: Vec<f64> = Vec::with_capacity(CLOCK_EXAMINED.min(n));
    let windows = if n <= CLOCK_EXAMINED + 1 { 1 } else { 8 };
    let width = (CLOCK_EXAMINED / windows + 1).min(n);
    for w in 0..windows {
        let from = if windows == 1 { 0 } else { (n - width) * w / (windows - 1) };
        stamps.clear();
        t.copy_range(from, (from + width).min(n), &mut stamps);
        d.extend(stamps.windows(2).map(|p| p[1] - p[0]).filter(|x| x.is_finite() && *x > 0.0));
    }
    let fallback = ClockModel {
        kind: ClockKind::ArrivalStamps,
        base_s: nominal,
        examined: d.len(),
        on_grid: 0.0,
        shortest_s: nominal,
        longest_s: nominal,
        steady_s: None,
    };
    if d.is_empty() {
        return fallback;
    }
    let shortest = d.iter().copied().fold(f64::INFINITY, f64::min);
    let longest = d.iter().copied().fold(0.0, f64::max);
    let q05 = {
        let k = d.len() / 20;
        *d.select_nth_unstable_by(k, f64::total_cmp).1
    };
    let mut low: Vec<f64> = d.iter().copied().filter(|&x| x <= 1.5 * q05).collect();
    let mid = low.len() / 2;
    let base = *low.select_nth_unstable_by(mid, f64::total_cmp).1;
    let on = d
        .iter()
        .filter(|&&x| {
            let m = x / base;
            m.round() >= 1.0 && (m - m.round()).abs() <= GRID_TOLERANCE
        })
        .count();
    let on_grid = on as f64 / d.len() as f64;
    let kind = if on_grid >= ON_GRID_SHARE { ClockKind::SampleClock } else { ClockKind::ArrivalStamps };
    let steady_s = if kind == ClockKind::ArrivalStamps { steady_interval(&mut d) } else { None };
    ClockModel { kind, base_s: base, examined: d.len(), on_grid, shortest_s: shortest, longest_s: longest, steady_s }
}

/// The mean of the regular intervals of a steady stream (see [`ClockModel::steady_s`]), or
/// `None` when fewer than [`STEADY_SHARE`] of `d` lie within [`STEADY_TOLERANCE`] of their
/// median (bursts, or a stream without a steady rate). `d` is reordered.
fn steady_interval(d: &mut [f64]) -> Option<f64> {
    if d.is_empty() {
        return None;
    }
    let mid = d.len() / 2;
    let median = *d.select_nth_unstable_by(mid, f64::total_cmp).1;
    let (mut sum, mut count) = (0.0, 0usize);
    for &x in d.iter() {
        if (x / median - 1.0).abs() <= STEADY_TOLERANCE {
            sum += x;
            count += 1;
        }
    }
    (count as f64 >= STEADY_SHARE * d.len() as f64 && count > 0).then(|| sum / count as f64)
}

/// The gaps of stamps on a sample clock of base interval `base`: every interval of k > 1 base
/// intervals (rounded) holds k - 1 dropped samples.
fn grid_gaps<S: Stamps + Sync + ?Sized>(t: &S, base: f64) -> Vec<Gap> {
    let n = t.len();
    let mut c = Cursor::new(t);
    let mut gaps = Vec::new();
    let mut i = 1;
    while i < n {
        let Some(next) = next_long_interval(t, i, GAP_FACTOR * base) else { break };
        let d = c.get(next) - c.get(next - 1);
        let k = (d / base).round();
        if d.is_finite() && k >= 2.0 {
            gaps.push(Gap { index: next, missing: k as usize - 1, interval_s: d });
        }
        i = next + 1;
    }
    gaps
}

/// Stamps from which the passes over them run in parallel parts (few in tests, so that parts
/// and their joins are tested).
const PARALLEL_STAMPS: usize = if cfg!(test) { 300 } else { 1 << 20 };

/// Parts of a parallel pass (fixed, so that results do not depend on the number of threads).
const PASS_PARTS: usize = 8;

/// `f(from, to)` on [`PASS_PARTS`] parts of `0..n` (cut at multiples of [`BLOCK`]) in parallel,
/// the results in order; one part below [`PARALLEL_STAMPS`].
fn parallel_parts<T: Send>(n: usize, f: impl Fn(usize, usize) -> T + Sync) -> Vec<T> {
    use rayon::prelude::*;
    if n < PARALLEL_STAMPS {
        return vec![f(0, n)];
    }
    let cut = |k: usize| if k == PASS_PARTS { n } else { n * k / PASS_PARTS / BLOCK * BLOCK };
    (0..PASS_PARTS).into_par_iter().map(|k| f(cut(k), cut(k + 1))).collect()
}

/// What the estimator's first pass finds in a run of stamps.
#[derive(Debug, Default)]
struct FirstPass {
    /// (index, stamp) of the first finite stamp.
    first: Option<(usize, f64)>,
    /// (index, stamp) of the last finite stamp.
    last: Option<(usize, f64)>,
    /// Intervals (ending in the run) that do not increase.
    non_increasing: usize,
    /// The first of them.
    first_non_increasing: Option<IrregularInterval>,
    /// The stamps at multiples of [`BLOCK`].
    marks: Vec<f64>,
    /// The longest finite interval (ending in the run); -inf when there is none. No interval is
    /// longer than a limit exactly when this is not: the gap search is skipped then.
    longest: f64,
}

impl FirstPass {
    /// The pass over this run and the next.
    fn join(mut self, next: FirstPass) -> FirstPass {
        self.first = self.first.or(next.first);
        self.last = next.last.or(self.last);
        self.non_increasing += next.non_increasing;
        self.first_non_increasing = self.first_non_increasing.or(next.first_non_increasing);
        self.marks.extend(next.marks);
        self.longest = self.longest.max(next.longest);
        self
    }
}

/// The first pass over stamps `from..to` (intervals ending in them, the one ending at `from`
/// included when from > 0).
fn first_pass<S: Stamps + ?Sized>(t: &S, from: usize, to: usize) -> FirstPass {
    let increasing = |d: f64| d.is_finite() && d > 0.0;
    let mut out = FirstPass {
        marks: Vec::with_capacity((to - from) / BLOCK + 1),
        longest: f64::NEG_INFINITY,
        ..FirstPass::default()
    };
    let mut prev = f64::NAN;
    if from > 0 {
        let mut one = Vec::with_capacity(1);
        t.copy_range(from - 1, from, &mut one);
        prev = one[0];
    }
    for_each_chunk(t, from, to, |at, chunk| {
        if out.first.is_none() {
            out.first = chunk.iter().position(|v| v.is_finite()).map(|k| (at + k, chunk[k]));
        }
        if let Some(k) = chunk.iter().rposition(|v| v.is_finite()) {
            out.last = Some((at + k, chunk[k]));
        }
        // Intervals that do not increase: counted in one branch-free sweep, then found (rare)
        // one by one. The interval across the chunk bound comes first.
        let bound = usize::from(at > 0 && !increasing(chunk[0] - prev));
        // The longest finite interval in the same sweep (the one across the bound included;
        // `prev` is NaN before the record's first stamp, so that difference is not finite).
        let (inside, longest) = interval_sweep(chunk);
        out.longest = out.longest.max(longest).max(finite_or(chunk[0] - prev));
        if bound + inside > 0 {
            let mut p = prev;
            for (k, &v) in chunk.iter().enumerate() {
                if at + k > 0 && !increasing(v - p) {
                    out.first_non_increasing.get_or_insert(IrregularInterval { index: at + k, interval_s: v - p });
                }
                p = v;
            }
            out.non_increasing += bound + inside;
        }
        let skip = (BLOCK - at % BLOCK) % BLOCK;
        out.marks.extend(chunk.iter().skip(skip).step_by(BLOCK));
        prev = chunk[chunk.len() - 1];
        true
    });
    out
}

/// Over the intervals between consecutive stamps of `t`: how many do not increase (not finite,
/// or not above zero), and the longest finite one (-inf when there is none). Eight lanes of
/// running counts and maxima, so that the sweep is vectorised (the maximum does not depend on
/// the order, but for the sign of a zero, which the comparison with a positive limit that reads
/// it cannot see). Compiled for AVX-512 and AVX2 too, chosen at run time (the same operations).
fn interval_sweep(t: &[f64]) -> (usize, f64) {
    #[cfg(target_arch = "x86_64")]
    {
        #[target_feature(enable = "avx512f")]
        unsafe fn sweep_avx512(t: &[f64]) -> (usize, f64) {
            interval_sweep_body(t)
        }
        #[target_feature(enable = "avx2")]
        unsafe fn sweep_avx2(t: &[f64]) -> (usize, f64) {
            interval_sweep_body(t)
        }
        if std::is_x86_feature_detected!("avx512f") {
            // SAFETY: the CPU has AVX-512 F (checked just above).
            return unsafe { sweep_avx512(t) };
        }
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2 (checked just above).
            return unsafe { sweep_avx2(t) };
        }
    }
    interval_sweep_body(t)
}

/// The loop of [`interval_sweep`].
#[inline(always)]
fn interval_sweep_body(t: &[f64]) -> (usize, f64) {
    const LANES: usize = 8;
    if t.len() < 2 {
        return (0, f64::NEG_INFINITY);
    }
    let (a, b) = (&t[..t.len() - 1], &t[1..]);
    let mut bad = [0u64; LANES];
    let mut long = [f64::NEG_INFINITY; LANES];
    #[inline(always)]
    fn lane(d: f64, bad: &mut u64, long: &mut f64) {
        *bad += u64::from(!(d > 0.0 && d < f64::INFINITY));
        let finite = if d < f64::INFINITY { d } else { f64::NEG_INFINITY };
        *long = if finite > *long { finite } else { *long };
    }
    let full = a.len() / LANES * LANES;
    for (xa, xb) in a[..full].chunks_exact(LANES).zip(b[..full].chunks_exact(LANES)) {
        let (Ok(xa), Ok(xb)) = (<&[f64; LANES]>::try_from(xa), <&[f64; LANES]>::try_from(xb)) else { continue };
        for l in 0..LANES {
            lane(xb[l] - xa[l], &mut bad[l], &mut long[l]);
        }
    }
    for (k, (&x, &y)) in a[full..].iter().zip(&b[full..]).enumerate() {
        lane(y - x, &mut bad[k], &mut long[k]);
    }
    let longest = long.iter().fold(f64::NEG_INFINITY, |m, &v| if v > m { v } else { m });
    (bad.iter().sum::<u64>() as usize, longest)
}

/// `d` when finite, else -inf (so that it is never the longest interval).
#[inline(always)]
fn finite_or(d: f64) -> f64 {
    if d.is_finite() {
        d
    } else {
        f64::NEG_INFINITY
    }
}

/// Calls `f(first index, stamps)` on the stamps `from..to` in order, a chunk at a time (one
/// slice when the stamps are held as one), until it returns `false`.
fn for_each_chunk<S: Stamps + ?Sized>(t: &S, from: usize, to: usize, mut f: impl FnMut(usize, &[f64]) -> bool) {
    if from >= to {
        return;
    }
    if let Some(s) = t.as_slice() {
        f(from, &s[from..to]);
        return;
    }
    let mut buf = Vec::with_capacity(CHUNK);
    let mut at = from;
    while at < to {
        let end = (at + CHUNK).min(to);
        buf.clear();
        t.copy_range(at, end, &mut buf);
        if !f(at, &buf) {
            return;
        }
        at = end;
    }
}

/// The first index `i >= from` (from >= 1) whose interval `t[i] - t[i-1]` is finite and over
/// `limit`: the next [`CHUNK`] stamps first (where bursty stamps find one), then the rest in
/// parallel parts.
fn next_long_interval<S: Stamps + Sync + ?Sized>(t: &S, from: usize, limit: f64) -> Option<usize> {
    use rayon::prelude::*;
    let n = t.len();
    let near = (from + CHUNK).min(n);
    if let Some(i) = long_interval_in(t, from, near, limit) {
        return Some(i);
    }
    let rest = n - near;
    if rest < PARALLEL_STAMPS {
        return long_interval_in(t, near, n, limit);
    }
    let cut = |k: usize| near + rest * k / PASS_PARTS;
    (0..PASS_PARTS).into_par_iter().find_map_first(|k| long_interval_in(t, cut(k), cut(k + 1), limit))
}

/// The first index `i` in `from..to` (from >= 1) whose interval is finite and over `limit`.
fn long_interval_in<S: Stamps + ?Sized>(t: &S, from: usize, to: usize, limit: f64) -> Option<usize> {
    if from >= to {
        return None;
    }
    let long = |a: f64, b: f64| {
        let d = b - a;
        d.is_finite() && d > limit
    };
    let mut found = None;
    let mut prev: Option<f64> = None;
    for_each_chunk(t, from - 1, to, |at, chunk| {
        // The interval across the chunk bound, then those inside the chunk.
        if let (Some(p), Some(&v)) = (prev, chunk.first()) {
            if long(p, v) {
                found = Some(at);
                return false;
            }
        }
        if let Some(k) = chunk.windows(2).position(|w| long(w[0], w[1])) {
            found = Some(at + k + 1);
            return false;
        }
        prev = chunk.last().copied();
        true
    });
    found
}

/// An interval longer than this many sampling intervals is examined as a possible gap.
const GAP_FACTOR: f64 = 1.5;

/// The gaps of `t` at interval `dt` (see the module's rule); `steady`: a steady stream ([`ClockModel::steady_s`]), whose window after a long interval ends at the next one.
fn find_gaps<S: Stamps + Sync + ?Sized>(t: &S, dt: f64, steady: bool) -> Vec<Gap> {
    let n = t.len();
    let mut c = Cursor::new(t);
    let t0 = c.get(0);
    let mut gaps = Vec::new();
    let mut previous = 0usize;
    let mut i = 1;
    // The floor (minimum) and the range of the lateness over samples from..to.
    let floor = |c: &mut Cursor<'_, S>, from: usize, to: usize| {
        (from..to)
            .map(|j| c.get(j) - t0 - j as f64 * dt)
            .filter(|e| e.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), e| (lo.min(e), hi.max(e)))
    };
    while i < n {
        // The next interval longer than 1.5 dt (read chunk by chunk).
        let Some(next) = next_long_interval(t, i, GAP_FACTOR * dt) else { break };
        i = next;
        let d = c.get(i) - c.get(i - 1);
        // The floor of the lateness needs samples on both sides: within WINDOW / 2 samples of
        // either end of the record no gap is judged (a late last stamp is not a stop).
        if i < WINDOW / 2 || n - i < WINDOW / 2 {
            i += 1;
            continue;
        }
        if d.is_finite() && d > GAP_FACTOR * dt {
            let (before, top_before) = floor(&mut c, previous.max(i.saturating_sub(WINDOW)), i);
            // In a steady stream the window after ends before the next long interval (another
            // drop would widen the spread and hide this one); bursty stamps keep the whole
            // window (their long intervals come every few samples).
            let mut to = (i + WINDOW).min(n);
            if steady {
                if let Some(j) = (i + 1..to).find(|&j| c.get(j) - c.get(j - 1) > GAP_FACTOR * dt) {
                    to = j;
                }
            }
            let (after, top_after) = floor(&mut c, i, to);
            let shift = (after - before) / dt;
            // A shift within the stamps' own spread on either side is jitter or a burst.
            let spread = ((top_before - before).max(top_after - after) / dt).max(0.0);
            if shift.is_finite() && shift >= 0.5 && shift > spread {
                let missing = shift.round() as usize;
                // The gap sits at the longest interval among the next few (a host stamp may
                // hold the delay over a burst).
                let end = (i + WINDOW / 2).min(to);
                let intervals: Vec<(usize, f64)> = (i..end).map(|a| (a, c.get(a) - c.get(a - 1))).collect();
                let at = intervals.iter().max_by(|x, y| x.1.total_cmp(&y.1).then(y.0.cmp(&x.0))).map_or(i, |x| x.0);
                gaps.push(Gap { index: at, missing, interval_s: c.get(at) - c.get(at - 1) });
                previous = at;
                i = at + 1;
                continue;
            }
        }
        i += 1;
    }
    gaps
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_stamps_give_the_span_over_the_count() {
        // Stamps rounded to 3 decimals, as a logger writes them: the hand value is 1/100 Hz.
        let t: Vec<f64> = (0..50_001).map(|i| ((i as f64) * 0.01 * 1000.0).round() / 1000.0).collect();
        let e = estimate_interval(&t).unwrap();
        assert_eq!(e.interval_s, (t[50_000] - t[0]) / 50_000.0);
        assert!((e.rate_hz() - 100.0).abs() < 1e-9);
        assert_eq!(e.irregular, 0);
    }

    #[test]
    fn a_gap_is_reported_and_does_not_stretch_the_mean() {
        let mut t: Vec<f64> = (0..1000).map(|i| i as f64 * 0.5).collect();
        for v in t.iter_mut().skip(600) {
            *v += 10.0; // a 10 s gap before sample 600
        }
        let e = estimate_interval(&t).unwrap();
        assert_eq!(e.first_irregular.map(|g| g.index), Some(600));
        assert_eq!(e.irregular, 1);
        assert_eq!((e.gaps[0].index, e.gaps[0].missing), (600, 20));
        assert!((e.interval_s - 0.5).abs() < 1e-12);
    }

    #[test]
    fn jittered_stamps_give_the_true_mean_interval() {
        // Alternating +-20 % jitter around 0.01 s: the median is one of the jittered values
        // (0.008 or 0.012); the mean is the true 0.01.
        let mut t = vec![0.0];
        for i in 1..2001 {
            let d = if i % 2 == 0 { 0.012 } else { 0.008 };
            t.push(t[i - 1] + d);
        }
        let e = estimate_interval(&t).unwrap();
        assert!((e.interval_s - 0.01).abs() < 1e-12, "{}", e.interval_s);
        assert!((e.nominal_s - 0.01).abs() < 1e-12, "{}", e.nominal_s);
    }

    /// A small deterministic generator (splitmix64) for jitter: uniform in [0, 1).
    fn uniform(state: &mut u64) -> f64 {
        *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = *state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }

    #[test]
    fn bursty_host_stamps_give_the_true_rate() {
        // An MPU6050 at 100.3 Hz read by a PC: samples reach the host in USB frames every 20 ms
        // (plus 0 to 5 ms of scheduling delay) and are stamped on arrival, 0.9 ms apart within a
        // frame. The median interval is 0.9 ms (1125 Hz); the true rate is 100.3 Hz.
        let rate = 100.3;
        let mut st = 7u64;
        let mut t = Vec::new();
        let mut last = f64::NEG_INFINITY;
        for i in 0..60_000 {
            let true_t = i as f64 / rate;
            let frame = (true_t / 0.02).ceil() * 0.02 + 0.005 * uniform(&mut st);
            let stamp = frame.max(last + 0.0009);
            t.push(stamp);
            last = stamp;
        }
        let e = estimate_interval(&t).unwrap();
        assert!((e.rate_hz() / rate - 1.0).abs() < 0.005, "{} Hz", e.rate_hz());
        assert_eq!(e.missing, 0, "{:?}", &e.gaps[..e.gaps.len().min(5)]);
    }

    /// Host stamps of a 50 Hz stream (the ArDrone bag's pattern): each sample stamped on
    /// arrival, 0 to 6 ms late (so no interval is a whole multiple of one base), with 1.5 %
    /// of the samples dropped one at a time, each drop a single 40 ms interval followed by
    /// regular ones. Over 10 seeds every drop is counted and the rate is 50 Hz to 0.05 %; the
    /// span over the count (48.9 Hz here) would hide them in the lateness's drift.
    #[test]
    fn single_drops_in_steady_host_stamps_are_counted() {
        for seed in 0..10u64 {
            let mut st = 1000 + seed;
            let (rate, n) = (50.0, 4_600usize);
            let mut t = Vec::new();
            let mut dropped = 0usize;
            let mut last_drop = 0usize;
            for i in 0..n {
                // Isolated drops, at least 10 samples apart, away from the ends.
                if i > 40 && i + 40 < n && i - last_drop > 10 && uniform(&mut st) < 0.016 {
                    dropped += 1;
                    last_drop = i;

                    continue;
                }
                t.push(i as f64 / rate + 0.006 * uniform(&mut st));
            }
            let e = estimate_interval(&t).unwrap();
            assert_eq!(e.clock.kind, ClockKind::ArrivalStamps, "seed {seed}: {}", e.clock);
            assert!(e.clock.steady_s.is_some(), "seed {seed}: {}", e.clock);
            assert_eq!(e.missing, dropped, "seed {seed}: {:?}", e.gaps.iter().map(|g| g.index).collect::<Vec<_>>());
            assert!(e.gaps.iter().all(|g| g.missing == 1), "seed {seed}");
            assert!((e.rate_hz() / rate - 1.0).abs() < 5e-4, "seed {seed}: {} Hz", e.rate_hz());
            let plain = t.len() as f64 / (t[t.len() - 1] - t[0]);
            assert!(plain / rate < 0.99, "seed {seed}: the plain rate {plain} should show the drops' bias");
        }
    }

    #[test]
    fn a_dozen_dropped_samples_in_jittered_stamps_are_found() {
        // 2 h at 200 Hz, stamps jittered uniformly by +-30 % of the interval, a clock 50 ppm
        // fast; 12 single and double drops at known places.
        let (rate, n) = (200.0 * (1.0 + 50e-6), 1_440_000usize);
        let drops: Vec<(usize, usize)> = (0..12).map(|k| (50_000 + k * 113_000, 1 + k % 2)).collect();
        let mut st = 11u64;
        let mut t = Vec::with_capacity(n);
        let mut expected = Vec::new();
        let mut i = 0usize;
        let mut d = 0;
        while i < n {
            if d < drops.len() && i == drops[d].0 {
                expected.push((t.len(), drops[d].1));
                i += drops[d].1;
                d += 1;
                continue;
            }
            t.push((i as f64 + 0.6 * (uniform(&mut st) - 0.5)) / rate);
            i += 1;
        }
        let e = estimate_interval(&t).unwrap();
        let found: Vec<(usize, usize)> = e.gaps.iter().map(|g| (g.index, g.missing)).collect();
        assert_eq!(found, expected);
        assert_eq!(e.missing, 18);
        assert!((e.rate_hz() / rate - 1.0).abs() < 1e-6, "{}", e.rate_hz());
    }

    #[test]
    fn long_gaps_are_counted() {
        // 1 h at 100 Hz with a 10 s and a 600 s gap: 1000 and 60 000 samples missing.
        let t: Vec<f64> = (0..360_000usize)
            .filter(|&i| !(100_000..101_000).contains(&i) && !(200_000..260_000).contains(&i))
            .map(|i| i as f64 * 0.01)
            .collect();
        let e = estimate_interval(&t).unwrap();
        let found: Vec<(usize, usize)> = e.gaps.iter().map(|g| (g.index, g.missing)).collect();
        assert_eq!(found, vec![(100_000, 1000), (199_000, 60_000)]);
        assert!((e.interval_s - 0.01).abs() < 1e-12);
    }

    #[test]
    fn one_missing_sample_is_a_gap() {
        // One sample dropped (an interval of 2 dt, the shortest gap), once in a short record and
        // once in a record long enough for the parallel passes; the stamps as compact ones too.
        for n in [5_000usize, 3_000_000] {
            let t: Vec<f64> = (0..n).filter(|&i| i != n / 2).map(|i| i as f64 * 0.01).collect();
            let mut c = CompactStamps::default();
            c.extend_from_slice(&t);
            for e in [estimate_interval(&t).unwrap(), estimate_interval_of(&c).unwrap()] {
                let found: Vec<(usize, usize)> = e.gaps.iter().map(|g| (g.index, g.missing)).collect();
                assert_eq!(found, vec![(n / 2, 1)], "n = {n}");
                assert_eq!(e.missing, 1);
                assert!((e.interval_s - 0.01).abs() < 1e-12);
            }
        }
    }

    /// PX4 `sensor_combined` as a logger writes it: 250 Hz stamps in whole microseconds, a
    /// run of 1 to 3 messages dropped after about one message in twelve (intervals of 4.000,
    /// 8.000, 12.000, 16.000 ms). The true rate is 250 Hz and the drops are known.
    #[test]
    fn a_sample_clock_with_drops_reads_its_base_rate_and_every_drop() {
        let mut st = 3u64;
        let (mut t, mut expected, mut i) = (Vec::new(), Vec::new(), 0u64);
        while t.len() < 30_000 {
            t.push((1_234_567 + i * 4000) as f64 * 1e-6);
            i += 1;
            if uniform(&mut st) < 0.08 {
                let k = 1 + (uniform(&mut st) * 3.0) as usize;
                expected.push((t.len(), k));
                i += k as u64;
            }
        }
        for e in [estimate_interval(&t).unwrap(), {
            let mut c = CompactStamps::default();
            c.extend_from_slice(&t);
            estimate_interval_of(&c).unwrap()
        }] {
            assert_eq!(e.clock.kind, ClockKind::SampleClock, "{}", e.clock);
            assert!((e.rate_hz() - 250.0).abs() < 1e-6, "{} Hz", e.rate_hz());
            let found: Vec<(usize, usize)> = e.gaps.iter().map(|g| (g.index, g.missing)).collect();
            assert_eq!(found, expected);
            assert_eq!(e.missing, expected.iter().map(|x| x.1).sum::<usize>());
        }
    }

    /// A host stamping a 100.22 Hz sensor when the driver hands samples over: bursts every 30
    /// to 70 ms, 0.5 to 1 ms apart inside a burst. The rate is the samples over the span; no
    /// gap is invented.
    fn burst_stamps(rate: f64, n: usize, seed: u64) -> Vec<f64> {
        let mut st = seed;
        let (mut t, mut next_burst, mut last) = (Vec::with_capacity(n), 0.0f64, f64::NEG_INFINITY);
        let mut i = 0usize;
        while t.len() < n {
            next_burst += 0.03 + 0.04 * uniform(&mut st);
            // Every sample taken by then is handed over in this burst.
            while t.len() < n && i as f64 / rate <= next_burst {
                let stamp = next_burst.max(last + 0.0005 + 0.0005 * uniform(&mut st));
                t.push(stamp);
                last = stamp;
                i += 1;
            }
        }
        t
    }

    #[test]
    fn bursts_of_arrival_stamps_invent_no_gaps() {
        for seed in [1u64, 2, 3, 4] {
            let t = burst_stamps(100.22, 7000, seed);
            let e = estimate_interval(&t).unwrap();
            assert_eq!(e.clock.kind, ClockKind::ArrivalStamps, "{}", e.clock);
            assert_eq!(e.missing, 0, "seed {seed}: {:?}", &e.gaps[..e.gaps.len().min(5)]);
            assert_eq!(e.interval_s, (t[t.len() - 1] - t[0]) / (t.len() - 1) as f64);
            assert!((e.rate_hz() / 100.22 - 1.0).abs() < 2e-3, "{} Hz", e.rate_hz());
        }
    }

    #[test]
    fn a_stopped_stream_of_arrival_stamps_is_a_gap() {
        // The bursty stream of the test above stops for 2 s (about 200 samples) after 3500.
        let mut t = burst_stamps(100.22, 7000, 9);
        for v in t.iter_mut().skip(3500) {
            *v += 2.0;
        }
        let e = estimate_interval(&t).unwrap();
        assert_eq!(e.clock.kind, ClockKind::ArrivalStamps);
        assert_eq!(e.gaps.len(), 1, "{:?}", e.gaps);
        assert!((e.gaps[0].index as i64 - 3500).abs() <= 8, "{:?}", e.gaps);
        assert!((e.gaps[0].missing as f64 - 200.4).abs() <= 8.0, "{:?}", e.gaps);
        assert!((e.rate_hz() / 100.22 - 1.0).abs() < 2e-3, "{} Hz", e.rate_hz());
    }

    #[test]
    fn a_zero_trailer_ends_the_record() {
        // 6280 clean rows at 100 Hz, then 720 rows of zeros (stamp included).
        let mut t: Vec<f64> = (0..6280).map(|i| 12.5 + i as f64 * 0.01).collect();
        t.extend(std::iter::repeat_n(0.0, 720));
        let e = estimate_interval(&t).unwrap();
        let r = e.reset.unwrap();
        assert_eq!((r.index, r.left_out, r.to_s), (6280, 720, 0.0));
        assert!((r.from_s - 75.29).abs() < 1e-9);
        assert!((e.rate_hz() - 100.0).abs() < 1e-9);
        assert_eq!((e.missing, e.irregular, e.first_non_increasing), (0, 0, None));
    }

    #[test]
    fn a_clock_reset_ends_the_record_there() {
        // A 200 Hz clock reset to zero after 5000 samples, then running on for 3000.
        let mut t: Vec<f64> = (0..5000).map(|i| 40.0 + i as f64 * 0.005).collect();
        t.extend((0..3000).map(|i| i as f64 * 0.005));
        let mut c = CompactStamps::default();
        c.extend_from_slice(&t);
        for e in [estimate_interval(&t).unwrap(), estimate_interval_of(&c).unwrap()] {
            let r = e.reset.unwrap();
            assert_eq!((r.index, r.left_out), (5000, 3000));
            assert!((e.rate_hz() - 200.0).abs() < 1e-9);
        }
        // A stamp going back but not to the start stays a stamp that does not increase.
        let mut t: Vec<f64> = (0..1000).map(|i| i as f64 * 0.01).collect();
        t[500] = t[498];
        let e = estimate_interval(&t).unwrap();
        assert_eq!(e.reset, None);
        assert_eq!(e.first_non_increasing.map(|g| g.index), Some(500));
    }

    #[test]
    fn sparse_drops_in_host_stamps_over_twenty_minutes_are_found() {
        // A ROS bag: 250 Hz, 20 min, stamps on arrival jittered by +-10 % of the interval,
        // one message dropped about every 150.
        let (rate, n) = (250.0, 300_000usize);
        let mut st = 5u64;
        let (mut t, mut expected, mut i) = (Vec::with_capacity(n), Vec::new(), 0usize);
        while t.len() < n {
            if i > 0 && uniform(&mut st) < 1.0 / 150.0 && expected.last().is_none_or(|&(k, _)| t.len() > k + 40) {
                expected.push((t.len(), 1usize));
                i += 1;
            }
            t.push((i as f64 + 0.2 * (uniform(&mut st) - 0.5)) / rate);
            i += 1;
        }
        let e = estimate_interval(&t).unwrap();
        let found: Vec<(usize, usize)> = e.gaps.iter().map(|g| (g.index, g.missing)).collect();
        assert_eq!(found.len(), expected.len());
        assert_eq!(found, expected);
        assert!((e.rate_hz() / rate - 1.0).abs() < 1e-6, "{}", e.rate_hz());
    }

    #[test]
    fn too_short_and_not_increasing_are_errors() {
        assert_eq!(estimate_interval(&[1.0]), Err(SamplingError::TooShort));
        assert_eq!(estimate_interval(&[1.0, 1.0, 0.5]), Err(SamplingError::NotIncreasing));
        assert_eq!(estimate_interval(&[f64::NAN, f64::NAN]), Err(SamplingError::NotIncreasing));
    }

    /// Stamps of every kind the estimator meets: uniform with a few decimals, jittered, with
    /// gaps, bursts, repeated or reversed stamps, NaN, negative and huge (ns epoch) stamps.
    fn stamps_case(kind: u8, n: usize, seed: u64, dt: f64, t0: f64) -> Vec<f64> {
        let mut st = seed;
        let mut t = Vec::with_capacity(n);
        let mut i = 0usize;
        while t.len() < n {
            let u = uniform(&mut st);
            let v = match kind {
                0 => ((t0 + i as f64 * dt) * 100.0).round() / 100.0,
                1 => t0 + (i as f64 + 0.6 * (u - 0.5)) * dt,
                2 => {
                    if u < 0.01 {
                        i += 1 + (u * 1000.0) as usize;
                    }
                    t0 + i as f64 * dt
                }
                3 => {
                    if u < 0.01 {
                        f64::NAN
                    } else if u < 0.02 {
                        t0
                    } else {
                        t0 + i as f64 * dt
                    }
                }
                _ => (t0 * 1e9 + (i as f64 * dt * 1e9).round()) * 1e-9,
            };
            t.push(v);
            i += 1;
        }
        t
    }

    mod prop {
        use super::*;
        use proptest::prelude::*;

        proptest! {
            #![proptest_config(ProptestConfig::with_cases(48))]
            /// The compact stamps read back bit for bit, and the estimate over them is the
            /// estimate over the slice (same gaps, same interval, same irregular stamps).
            #[test]
            fn compact_stamps_give_the_slice_estimate(
                kind in 0u8..5,
                n in 0usize..3000,
                seed in 0u64..1000,
                dt in prop_oneof![Just(0.01), Just(0.0025), Just(0.001_234_5), 1e-4..2.0f64],
                t0 in prop_oneof![Just(0.0), Just(-3.0), Just(1.7e9), -1e5..1e5f64],
            ) {
                let t = stamps_case(kind, n, seed, dt, t0);
                let mut c = CompactStamps::default();
                // Fed in blocks, as a reader does.
                for b in t.chunks(97) {
                    c.extend_from_slice(b);
                }
                let back = c.to_vec();
                prop_assert_eq!(back.len(), t.len());
                for (a, b) in back.iter().zip(&t) {
                    prop_assert_eq!(a.to_bits(), b.to_bits());
                }
                let mut part = Vec::new();
                let (from, to) = (n / 3, (n / 3 + 77).min(n));
                c.copy_range(from, to, &mut part);
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                prop_assert_eq!(bits(&part), bits(&t[from..to]));
                let whole = estimate_interval(&t);
                let compact = estimate_interval_of(&c);
                prop_assert_eq!(format!("{whole:?}"), format!("{compact:?}"));
            }

            /// The first pass in parallel parts (from compact stamps, chunk by chunk) finds what
            /// the plain loop over the slice finds.
            #[test]
            fn first_pass_in_parts_equals_the_plain_loop(
                kind in 0u8..5,
                n in 2usize..3000,
                seed in 0u64..1000,
                dt in prop_oneof![Just(0.01), 1e-4..2.0f64],
            ) {
                let t = stamps_case(kind, n, seed, dt, 0.0);
                let mut c = CompactStamps::default();
                c.extend_from_slice(&t);
                let got = parallel_parts(n, |a, b| first_pass(&c, a, b)).into_iter().reduce(FirstPass::join).unwrap();
                let finite: Vec<usize> = (0..n).filter(|&i| t[i].is_finite()).collect();
                let bad: Vec<usize> = (1..n).filter(|&i| !((t[i] - t[i - 1]).is_finite() && t[i] - t[i - 1] > 0.0)).collect();
                prop_assert_eq!(got.first.map(|f| f.0), finite.first().copied());
                prop_assert_eq!(got.last.map(|f| f.0), finite.last().copied());
                prop_assert_eq!(got.non_increasing, bad.len());
                prop_assert_eq!(got.first_non_increasing.map(|g| g.index), bad.first().copied());
                let marks: Vec<u64> = t.iter().step_by(BLOCK).map(|v| v.to_bits()).collect();
                prop_assert_eq!(got.marks.iter().map(|v| v.to_bits()).collect::<Vec<_>>(), marks);
                let longest = (1..n).map(|i| t[i] - t[i - 1]).filter(|d| d.is_finite()).fold(f64::NEG_INFINITY, f64::max);
                prop_assert_eq!(got.longest.to_bits(), longest.to_bits());
                // The gap search is skipped exactly when it would find no interval to examine:
                // at the nominal interval and at limits either side of the longest interval.
                for limit in [GAP_FACTOR * dt, longest, longest * (1.0 - 1e-12), longest / GAP_FACTOR] {
                    prop_assert_eq!(next_long_interval(&c, 1, limit).is_some(), got.longest > limit, "limit {}", limit);
                }
            }

            /// Parts encoded apart and appended read back bit for bit, at any row (the access
            /// points of a part start at its own first row), and stamps pushed after the join
            /// follow on as if all had been pushed to one.
            #[test]
            fn appended_parts_read_back_bit_for_bit(
                kind in 0u8..5,
                n in 1usize..2000,
                seed in 0u64..1000,
                dt in prop_oneof![Just(0.01), Just(0.0025), 1e-4..2.0f64],
                t0 in prop_oneof![Just(0.0), Just(1.7e9), -1e5..1e5f64],
                cuts in proptest::collection::vec(0usize..2000, 0..5),
                from in 0usize..2000,
            ) {
                let t = stamps_case(kind, n + 5, seed, dt, t0);
                let (body, tail) = t.split_at(n);
                let mut cuts: Vec<usize> = cuts.into_iter().map(|c| c % (n + 1)).collect();
                cuts.push(0);
                cuts.push(n);
                cuts.sort_unstable();
                let mut joined = CompactStamps::default();
                for w in cuts.windows(2) {
                    let mut part = CompactStamps::default();
                    part.extend_from_slice(&body[w[0]..w[1]]);
                    joined.append(part);
                }
                joined.extend_from_slice(tail);
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                prop_assert_eq!(bits(&joined.to_vec()), bits(&t));
                // From any row, and from the first row of each part (its own access point).
                for from in cuts.iter().copied().chain([from % t.len()]) {
                    let to = (from + 131).min(t.len());
                    let mut part = Vec::new();
                    joined.copy_range(from, to, &mut part);
                    prop_assert_eq!(bits(&part), bits(&t[from..to]));
                }
                let mut whole = CompactStamps::default();
                whole.extend_from_slice(&t);
                prop_assert_eq!(&joined, &whole);
                prop_assert_eq!(format!("{:?}", estimate_interval_of(&joined)), format!("{:?}", estimate_interval(&t)));
            }
        }
    }

    #[test]
    fn compact_stamps_of_a_steady_logger_take_under_two_bytes_each() {
        let t = stamps_case(0, 1_000_000, 1, 0.01, 0.0);
        let mut c = CompactStamps::default();
        c.extend_from_slice(&t);
        assert!(c.bytes() < 2 * t.len(), "{} bytes", c.bytes());
        assert_eq!(format!("{:?}", estimate_interval(&t)), format!("{:?}", estimate_interval_of(&c)));
    }
}
