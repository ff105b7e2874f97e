//! Segmentation of raw rate-table logs: steady plateaus of the table rate, their run and stroke
//! inferred from the sequence of rates, and the rest records at start and end.
//!
//! Sources: the test procedure of GJB 2426A-2004 / IEEE Std 952-1997 and the paper (Cheng et al.
//! 2014, eq. 4-6): each rate held for a while and its output averaged, forward strokes (rates
//! rising) and reverse strokes (rates falling) in each run, rest outputs F_s and F_e recorded at
//! the start and end. The detection rules (tolerance, settling, minimum duration, sequence
//! inference) are gyrolab's own and are stated in `docs/METHODS.md`, section 5.
//!
//! Everything here is O(N) in the number of samples: one pass finds the steady stretches (each
//! sample is looked at a bounded number of times), and each kept stretch is read once more.

use crate::rate_test::{RateObservation, RestRecord, Stroke};
use serde::{Deserialize, Serialize};
use std::fmt;
use thiserror::Error;

/// What to do with rest records at the start and end of a log.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RestPolicy {
    /// Rest at the start and end are both used when both are present; neither is fine; only one
    /// of them is an error (a log that starts at rest must end at rest, and the reverse).
    Auto,
    /// Rest records at both start and end are required.
    Required,
    /// Rest segments are recognised and labelled but not used as F_r; one of them alone is fine.
    Unused,
}

/// Options of the plateau detection.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SegmentOptions {
    /// Absolute part of the steadiness tolerance, deg/s.
    pub tolerance_abs_dps: f64,
    /// Relative part of the steadiness tolerance (ratio of |rate|).
    pub tolerance_rel: f64,
    /// Minimum time a plateau must span after its settling time is dropped, s.
    pub min_duration_s: f64,
    /// Time dropped at the start of each plateau (table and gyro settling), s.
    pub settling_s: f64,
    /// A steady segment whose mean |rate| is at most this is at rest, deg/s.
    pub rest_tolerance_dps: f64,
    /// Number of consecutive out-of-tolerance samples that end a plateau (shorter excursions are
    /// glitches and stay inside it).
    pub break_samples: usize,
    /// Use of the rest records.
    pub rest: RestPolicy,
}

impl Default for SegmentOptions {
    fn default() -> Self {
        SegmentOptions {
            tolerance_abs_dps: 0.05,
            tolerance_rel: 1e-3,
            min_duration_s: 5.0,
            settling_s: 1.0,
            rest_tolerance_dps: 0.05,
            break_samples: 3,
            rest: RestPolicy::Auto,
        }
    }
}

impl SegmentOptions {
    /// Steadiness tolerance at a rate: tolerance_abs_dps + tolerance_rel * |rate|, deg/s.
    pub fn tolerance_at(&self, rate_dps: f64) -> f64 {
        self.tolerance_abs_dps + self.tolerance_rel * rate_dps.abs()
    }

    fn validate(&self) -> Result<(), SegmentError> {
        let checks = [
            ("tolerance_abs_dps", self.tolerance_abs_dps, self.tolerance_abs_dps > 0.0),
            ("tolerance_rel", self.tolerance_rel, self.tolerance_rel >= 0.0),
            ("min_duration_s", self.min_duration_s, self.min_duration_s > 0.0),
            ("settling_s", self.settling_s, self.settling_s >= 0.0),
            ("rest_tolerance_dps", self.rest_tolerance_dps, self.rest_tolerance_dps >= 0.0),
        ];
        for (name, v, ok) in checks {
            if !(v.is_finite() && ok) {
                return Err(SegmentError::InvalidOption(format!("{name} must be a non-negative number, got {v}")));
            }
        }
        if self.break_samples == 0 {
            return Err(SegmentError::InvalidOption("break_samples must be at least 1".into()));
        }
        Ok(())
    }
}

/// A stretch of the log where the table rate is steady, before any run or stroke is assigned.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SteadySegment {
    /// First sample where the rate was found steady (before the settling time is dropped).
    pub steady_from_index: usize,
    /// First sample kept (after the settling time).
    pub start_index: usize,
    /// One past the last sample kept.
    pub end_index: usize,
    /// Time of the first sample kept, s.
    pub start_time_s: f64,
    /// Time of the last sample kept, s.
    pub end_time_s: f64,
    /// Mean table rate over the kept samples, deg/s.
    pub rate_dps: f64,
}

impl SteadySegment {
    /// Number of samples kept.
    pub fn samples(&self) -> usize {
        self.end_index - self.start_index
    }
}

/// Which rest record a rest segment is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SegmentKind {
    /// Rest before the test (F_s, paper eq. 5).
    RestStart,
    /// Rest after the test (F_e, paper eq. 5).
    RestEnd,
    /// A rate plateau of a run and stroke.
    Plateau {
        /// Run number, from 1.
        run: u32,
        /// Stroke.
        stroke: Stroke,
    },
}

impl SegmentKind {
    /// Label for files and messages: `rest_start`, `rest_end` or `plateau`.
    pub fn label(&self) -> &'static str {
        match self {
            SegmentKind::RestStart => "rest_start",
            SegmentKind::RestEnd => "rest_end",
            SegmentKind::Plateau { .. } => "plateau",
        }
    }

    /// Builds a kind from a label (`rest_start`, `rest_end`, `plateau`) and, for a plateau, the
    /// run and stroke; `None` when they do not make one.
    pub fn from_parts(label: &str, run: Option<u32>, stroke: Option<Stroke>) -> Option<SegmentKind> {
        match (label.trim().to_ascii_lowercase().as_str(), run, stroke) {
            ("rest_start", _, _) => Some(SegmentKind::RestStart),
            ("rest_end", _, _) => Some(SegmentKind::RestEnd),
            ("plateau", Some(run), Some(stroke)) if run > 0 => Some(SegmentKind::Plateau { run, stroke }),
            _ => None,
        }
    }
}

impl fmt::Display for SegmentKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SegmentKind::Plateau { run, stroke } => write!(f, "run {run} {stroke}"),
            other => f.write_str(other.label()),
        }
    }
}

/// A labelled segment of a raw log: a rest record or a plateau of a run and stroke.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Segment {
    /// First sample where the rate was found steady (before settling was dropped).
    pub steady_from_index: usize,
    /// First sample kept (after the settling time).
    pub start_index: usize,
    /// One past the last sample kept.
    pub end_index: usize,
    /// Time of the first sample kept, s.
    pub start_time_s: f64,
    /// Time of the last sample kept, s.
    pub end_time_s: f64,
    /// Mean table rate over the kept samples, deg/s.
    pub rate_dps: f64,
    /// The test point's rate shared by every stroke (mean over strokes of their measured rates at
    /// that point), deg/s; 0 for rest.
    pub nominal_rate_dps: f64,
    /// Rest record or plateau.
    pub kind: SegmentKind,
}

impl Segment {
    /// Number of samples kept.
    pub fn samples(&self) -> usize {
        self.end_index - self.start_index
    }

    /// The segment without its label.
    pub fn steady(&self) -> SteadySegment {
        SteadySegment {
            steady_from_index: self.steady_from_index,
            start_index: self.start_index,
            end_index: self.end_index,
            start_time_s: self.start_time_s,
            end_time_s: self.end_time_s,
            rate_dps: self.rate_dps,
        }
    }

    fn from_steady(s: &SteadySegment, kind: SegmentKind) -> Segment {
        Segment {
            steady_from_index: s.steady_from_index,
            start_index: s.start_index,
            end_index: s.end_index,
            start_time_s: s.start_time_s,
            end_time_s: s.end_time_s,
            rate_dps: s.rate_dps,
            nominal_rate_dps: if matches!(kind, SegmentKind::Plateau { .. }) { s.rate_dps } else { 0.0 },
            kind,
        }
    }
}

/// A segment given by hand (a manual segment file): a time window and its label.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ManualSegment {
    /// Start of the window, s (the first sample at or after it is kept).
    pub start_time_s: f64,
    /// End of the window, s (the last sample at or before it is kept).
    pub end_time_s: f64,
    /// Rest record or plateau.
    pub kind: SegmentKind,
}

/// Why a raw log cannot be segmented. Every variant about the data names a sample index
/// (0-based, into the slices given) and its time, so that a reader can point at a file line.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SegmentError {
    /// An option is out of range.
    #[error("invalid segmentation option: {0}")]
    InvalidOption(String),
    /// Columns of different lengths.
    #[error("the {what} column has {found} values but the time column has {expected}")]
    LengthMismatch {
        /// Which column.
        what: &'static str,
        /// Its length.
        found: usize,
        /// Length of the time column.
        expected: usize,
    },
    /// The log holds no sample.
    #[error("the log holds no samples")]
    Empty,
    /// A value is NaN or infinite.
    #[error("sample {index} (t = {time_s} s): the {what} is not a finite number")]
    NonFinite {
        /// Sample index.
        index: usize,
        /// Its time, s (NaN when the time itself is bad).
        time_s: f64,
        /// Which column.
        what: &'static str,
    },
    /// Time does not increase.
    #[error("sample {index} (t = {time_s} s): time does not increase (the previous sample is at t = {previous_s} s)")]
    TimeNotIncreasing {
        /// Sample index.
        index: usize,
        /// Its time, s.
        time_s: f64,
        /// Time of the sample before, s.
        previous_s: f64,
    },
    /// A gap in the time stamps while the table rate stays the same: samples are missing from a
    /// plateau (or the time column is corrupt).
    #[error(
        "sample {index} (t = {time_s} s): time jumps by {gap_s} s from the previous sample (t = {previous_s} s), \
         more than {GAP_INTERVALS} sampling intervals ({interval_s} s), while the table rate stays at \
         {rate_dps} deg/s: samples are missing inside a plateau (or the time column is corrupt)"
    )]
    TimeGap {
        /// Sample index after the gap.
        index: usize,
        /// Its time, s.
        time_s: f64,
        /// Time of the sample before, s.
        previous_s: f64,
        /// The gap, s.
        gap_s: f64,
        /// The nominal sampling interval, s.
        interval_s: f64,
        /// The table rate on both sides, deg/s.
        rate_dps: f64,
    },
    /// No stretch of the log is steady long enough.
    #[error(
        "no steady plateau: the table rate never stays within the tolerance for {min_duration_s} s after \
         {settling_s} s of settling; the longest steady stretch lasts {longest_s:.3} s from sample {index} \
         (t = {time_s} s): check the rate column, or lower the minimum plateau duration or raise the tolerance"
    )]
    NoPlateau {
        /// Start of the longest steady stretch.
        index: usize,
        /// Its time, s.
        time_s: f64,
        /// Its duration, s.
        longest_s: f64,
        /// The minimum plateau duration asked for, s.
        min_duration_s: f64,
        /// The settling time asked for, s.
        settling_s: f64,
    },
    /// Plateaus at rest only, or a single one away from rest.
    #[error(
        "only {found} plateau(s) away from rest (the first at sample {index}, t = {time_s} s): a rate-table \
         sweep needs at least 2 rates"
    )]
    TooFewPlateaus {
        /// Plateaus found away from rest.
        found: usize,
        /// Sample index of the first.
        index: usize,
        /// Its time, s.
        time_s: f64,
    },
    /// The log starts at rest but never returns to rest.
    #[error(
        "the table rate never returns to rest: the log starts at rest, but its last steady segment (sample \
         {index}, t = {time_s} s) turns at {rate_dps:.4} deg/s, so the rest record at the end (F_e, paper eq. 5) \
         is missing; record rest at the end of the test, or do not use rest records"
    )]
    NoFinalRest {
        /// Start of the last steady segment.
        index: usize,
        /// Its time, s.
        time_s: f64,
        /// Its rate, deg/s.
        rate_dps: f64,
    },
    /// The log ends at rest but does not start at rest (or rest is required and missing).
    #[error(
        "no rest at the start of the log: the first steady segment (sample {index}, t = {time_s} s) turns at \
         {rate_dps:.4} deg/s, so the rest record at the start (F_s, paper eq. 5) is missing; record rest before \
         the test, or do not use rest records"
    )]
    NoInitialRest {
        /// Start of the first steady segment.
        index: usize,
        /// Its time, s.
        time_s: f64,
        /// Its rate, deg/s.
        rate_dps: f64,
    },
    /// Two plateaus in a row (or in one stroke) at the same rate: the sequence is ambiguous.
    #[error(
        "sample {index} (t = {time_s} s): a second plateau at {rate_dps:.4} deg/s right after one at the same \
         rate; the sweep cannot be split into strokes (a stop and restart at one rate?): use a manual segment file"
    )]
    RepeatedRate {
        /// Start of the second plateau.
        index: usize,
        /// Its time, s.
        time_s: f64,
        /// The rate, deg/s.
        rate_dps: f64,
    },
    /// A stroke has fewer rates than the others: the run stopped midway.
    #[error(
        "run {run} {stroke} stroke stops midway: it has {found} rate(s) where the other strokes have {expected} \
         (its last plateau ends at sample {index}, t = {time_s} s)"
    )]
    IncompleteRun {
        /// Run number.
        run: u32,
        /// Stroke.
        stroke: Stroke,
        /// Rates in this stroke.
        found: usize,
        /// Rates in the fullest stroke.
        expected: usize,
        /// Last sample of the stroke's last plateau.
        index: usize,
        /// Its time, s.
        time_s: f64,
    },
    /// A run has one stroke only.
    #[error(
        "run {run} has no {missing} stroke: the log stops after its other stroke (last plateau ends at sample \
         {index}, t = {time_s} s)"
    )]
    MissingStroke {
        /// Run number.
        run: u32,
        /// The stroke missing.
        missing: Stroke,
        /// Last sample of the run's last plateau.
        index: usize,
        /// Its time, s.
        time_s: f64,
    },
    /// A stroke's rates differ from the other strokes' rates.
    #[error(
        "run {run} {stroke} stroke: the plateau at sample {index} (t = {time_s} s) turns at {rate_dps:.4} deg/s \
         where the other strokes have {expected_dps:.4} deg/s"
    )]
    RateMismatch {
        /// Run number.
        run: u32,
        /// Stroke.
        stroke: Stroke,
        /// Rate found, deg/s.
        rate_dps: f64,
        /// Rate of the first stroke at that point, deg/s.
        expected_dps: f64,
        /// Start of the plateau.
        index: usize,
        /// Its time, s.
        time_s: f64,
    },
    /// Manual segments overlap or are out of time order.
    #[error(
        "segment starting at sample {index} (t = {time_s} s) overlaps the previous segment, which ends at \
         t = {previous_end_s} s: segments must be in time order and must not overlap"
    )]
    Overlap {
        /// First sample of the offending segment.
        index: usize,
        /// Its time, s.
        time_s: f64,
        /// End of the previous segment, s.
        previous_end_s: f64,
    },
    /// A manual segment holds no sample.
    #[error(
        "segment {start_s} s .. {end_s} s holds no sample of the log (which spans {log_start_s} s .. {log_end_s} s)"
    )]
    EmptySegment {
        /// Start asked for, s.
        start_s: f64,
        /// End asked for, s.
        end_s: f64,
        /// First time of the log, s.
        log_start_s: f64,
        /// Last time of the log, s.
        log_end_s: f64,
    },
}

impl SegmentError {
    /// The sample index the error is about, when it is about one.
    pub fn sample_index(&self) -> Option<usize> {
        use SegmentError::*;
        match self {
            NonFinite { index, .. }
            | TimeNotIncreasing { index, .. }
            | TimeGap { index, .. }
            | NoPlateau { index, .. }
            | TooFewPlateaus { index, .. }
            | NoFinalRest { index, .. }
            | NoInitialRest { index, .. }
            | RepeatedRate { index, .. }
            | IncompleteRun { index, .. }
            | MissingStroke { index, .. }
            | RateMismatch { index, .. }
            | Overlap { index, .. } => Some(*index),
            InvalidOption(_) | LengthMismatch { .. } | Empty | EmptySegment { .. } => None,
        }
    }
}

/// Longest step between two time stamps inside a plateau, in nominal sampling intervals; a longer
/// one with the same table rate on both sides is a [`SegmentError::TimeGap`].
pub const GAP_INTERVALS: f64 = 100.0;

/// Finds a gap of more than [`GAP_INTERVALS`] nominal intervals with the same rate (within the
/// steadiness tolerance) on both sides.
fn check_gaps(time_s: &[f64], rate_dps: &[f64], options: &SegmentOptions) -> Result<(), SegmentError> {
    let Ok(est) = crate::sampling::estimate_interval(time_s) else { return Ok(()) };
    let limit = GAP_INTERVALS * est.nominal_s;
    for i in 1..time_s.len() {
        let gap = time_s[i] - time_s[i - 1];
        if gap > limit && (rate_dps[i] - rate_dps[i - 1]).abs() <= options.tolerance_at(rate_dps[i - 1]) {
            return Err(SegmentError::TimeGap {
                index: i,
                time_s: time_s[i],
                previous_s: time_s[i - 1],
                gap_s: gap,
                interval_s: est.nominal_s,
                rate_dps: rate_dps[i - 1],
            });
        }
    }
    Ok(())
}

/// Checks the time and rate columns: same length, finite, time strictly increasing.
fn check_log(time_s: &[f64], rate_dps: &[f64]) -> Result<(), SegmentError> {
    if rate_dps.len() != time_s.len() {
        return Err(SegmentError::LengthMismatch { what: "table rate", found: rate_dps.len(), expected: time_s.len() });
    }
    if time_s.is_empty() {
        return Err(SegmentError::Empty);
    }
    for (i, (&t, &r)) in time_s.iter().zip(rate_dps).enumerate() {
        if !t.is_finite() {
            return Err(SegmentError::NonFinite { index: i, time_s: t, what: "time" });
        }
        if !r.is_finite() {
            return Err(SegmentError::NonFinite { index: i, time_s: t, what: "table rate" });
        }
        if i > 0 && t <= time_s[i - 1] {
            return Err(SegmentError::TimeNotIncreasing { index: i, time_s: t, previous_s: time_s[i - 1] });
        }
    }
    Ok(())
}

/// Mean and least-squares slope (deg/s per s) of the rate over samples [a, b), b > a.
fn mean_and_slope(time_s: &[f64], rate_dps: &[f64], a: usize, b: usize) -> (f64, f64) {
    let n = (b - a) as f64;
    let t0 = time_s[a];
    let mt = time_s[a..b].iter().map(|t| t - t0).sum::<f64>() / n;
    let mr = rate_dps[a..b].iter().sum::<f64>() / n;
    let (mut stt, mut str_) = (0.0, 0.0);
    for (t, r) in time_s[a..b].iter().zip(&rate_dps[a..b]) {
        let dt = t - t0 - mt;
        stt += dt * dt;
        str_ += dt * (r - mr);
    }
    (mr, if stt > 0.0 { str_ / stt } else { 0.0 })
}

/// Finds the steady stretches of a raw log (time in s, strictly increasing; table rate in deg/s).
///
/// A stretch grows while each sample stays within `tolerance_at(mean)` of the running mean of
/// the stretch; `break_samples` consecutive samples outside end it (the stretch ends before them
/// and a new one starts at the first of them). A stretch is kept when, after `settling_s` is
/// dropped from its start, its samples span at least `min_duration_s` and its least-squares
/// drift (slope times span) is within the tolerance (which rejects slow ramps).
pub fn find_steady_segments(
    time_s: &[f64],
    rate_dps: &[f64],
    options: &SegmentOptions,
) -> Result<Vec<SteadySegment>, SegmentError> {
    options.validate()?;
    check_log(time_s, rate_dps)?;
    check_gaps(time_s, rate_dps, options)?;
    let n = time_s.len();
    let mut found = Vec::new();
    // Longest raw stretch seen (start index, span in s), for the message when nothing qualifies.
    let mut longest = (0usize, 0.0f64);
    let mut close = |start: usize, end: usize, found: &mut Vec<SteadySegment>| {
        let span = time_s[end - 1] - time_s[start];
        if span > longest.1 {
            longest = (start, span);
        }
        let settled = time_s[start] + options.settling_s;
        let kept = start + time_s[start..end].partition_point(|&t| t < settled);
        if kept >= end || time_s[end - 1] - time_s[kept] < options.min_duration_s {
            return;
        }
        let (mean, slope) = mean_and_slope(time_s, rate_dps, kept, end);
        if (slope * (time_s[end - 1] - time_s[kept])).abs() > options.tolerance_at(mean) {
            return;
        }
        found.push(SteadySegment {
            steady_from_index: start,
            start_index: kept,
            end_index: end,
            start_time_s: time_s[kept],
            end_time_s: time_s[end - 1],
            rate_dps: mean,
        });
    };
    let (mut start, mut sum, mut count) = (0usize, rate_dps[0], 1usize);
    let (mut outs, mut first_out) = (0usize, 0usize);
    let mut i = 1;
    while i < n {
        let mean = sum / count as f64;
        if (rate_dps[i] - mean).abs() <= options.tolerance_at(mean) {
            sum += rate_dps[i];
            count += 1;
            outs = 0;
            i += 1;
        } else {
            if outs == 0 {
                first_out = i;
            }
            outs += 1;
            if outs >= options.break_samples {
                close(start, first_out, &mut found);
                start = first_out;
                sum = rate_dps[start];
                count = 1;
                outs = 0;
                i = start + 1;
            } else {
                i += 1;
            }
        }
    }
    close(start, if outs > 0 { first_out } else { n }, &mut found);
    if found.is_empty() {
        return Err(SegmentError::NoPlateau {
            index: longest.0,
            time_s: time_s[longest.0],
            longest_s: longest.1,
            min_duration_s: options.min_duration_s,
            settling_s: options.settling_s,
        });
    }
    Ok(found)
}

/// Finds and labels the segments of a raw log: [`find_steady_segments`] then [`label_segments`].
pub fn segment_log(time_s: &[f64], rate_dps: &[f64], options: &SegmentOptions) -> Result<Vec<Segment>, SegmentError> {
    let steady = find_steady_segments(time_s, rate_dps, options)?;
    label_segments(&steady, time_s, options)
}

/// Labels steady segments as rest records and plateaus of runs and strokes.
///
/// Rules: leading and trailing segments with |rate| <= `rest_tolerance_dps` are the rest records
/// at start and end (several in a row are all rest); the plateaus between form the sweep. Each
/// maximal rising sequence of plateaus is a forward stroke, each falling one a reverse stroke; a
/// plateau where the sweep turns belongs to both strokes and is split in two halves at its
/// middle sample (the first half ends the arriving stroke, the second starts the leaving one).
/// Strokes pair into runs in order (strokes 1-2 are run 1, 3-4 run 2, ...). Every stroke must
/// hold the same rates; each plateau's `nominal_rate_dps` is the mean over strokes of the rates
/// measured at its point.
pub fn label_segments(
    steady: &[SteadySegment],
    time_s: &[f64],
    options: &SegmentOptions,
) -> Result<Vec<Segment>, SegmentError> {
    options.validate()?;
    let at_rest = |s: &SteadySegment| s.rate_dps.abs() <= options.rest_tolerance_dps;
    let lead = steady.iter().take_while(|s| at_rest(s)).count();
    if lead == steady.len() {
        let s = steady.last().copied();
        return Err(SegmentError::TooFewPlateaus {
            found: 0,
            index: s.map_or(0, |s| s.start_index),
            time_s: s.map_or(f64::NAN, |s| s.start_time_s),
        });
    }
    let trail = steady.iter().rev().take_while(|s| at_rest(s)).count();
    let sweep = &steady[lead..steady.len() - trail];
    let first = sweep[0]; // ok: lead < len, so at least one non-rest segment
    let last = sweep[sweep.len() - 1];
    let need_rest = options.rest == RestPolicy::Required;
    let auto = options.rest == RestPolicy::Auto;
    if (need_rest || (auto && lead > 0)) && trail == 0 {
        return Err(SegmentError::NoFinalRest {
            index: last.start_index,
            time_s: last.start_time_s,
            rate_dps: last.rate_dps,
        });
    }
    if (need_rest || (auto && trail > 0)) && lead == 0 {
        return Err(SegmentError::NoInitialRest {
            index: first.start_index,
            time_s: first.start_time_s,
            rate_dps: first.rate_dps,
        });
    }
    if sweep.len() < 2 {
        return Err(SegmentError::TooFewPlateaus {
            found: sweep.len(),
            index: first.start_index,
            time_s: first.start_time_s,
        });
    }
    // Direction of each step between consecutive plateaus: true = rising.
    let mut rising = Vec::with_capacity(sweep.len() - 1);
    for w in sweep.windows(2) {
        let step = w[1].rate_dps - w[0].rate_dps;
        if step.abs() <= options.tolerance_at(w[0].rate_dps.abs().max(w[1].rate_dps.abs())) {
            return Err(SegmentError::RepeatedRate {
                index: w[1].start_index,
                time_s: w[1].start_time_s,
                rate_dps: w[1].rate_dps,
            });
        }
        rising.push(step > 0.0);
    }
    let mut out: Vec<Segment> =
        steady[..lead].iter().map(|s| Segment::from_steady(s, SegmentKind::RestStart)).collect();
    // Stroke index of each step, counting direction changes.
    let mut stroke_no = 0u32;
    let kind_of = |stroke_no: u32, up: bool| SegmentKind::Plateau {
        run: stroke_no / 2 + 1,
        stroke: if up { Stroke::Forward } else { Stroke::Reverse },
    };
    for (k, s) in sweep.iter().enumerate() {
        if k == 0 {
            out.push(Segment::from_steady(s, kind_of(0, rising[0])));
        } else if k == sweep.len() - 1 || rising[k] == rising[k - 1] {
            out.push(Segment::from_steady(s, kind_of(stroke_no, rising[k - 1])));
        } else {
            // Turning plateau: split into the arriving and the leaving stroke.
            let mid = s.start_index + s.samples() / 2;
            if mid == s.start_index {
                return Err(SegmentError::RepeatedRate {
                    index: s.start_index,
                    time_s: s.start_time_s,
                    rate_dps: s.rate_dps,
                });
            }
            let (mut a, mut b) = (*s, *s);
            a.end_index = mid;
            a.end_time_s = time_s[mid - 1];
            b.steady_from_index = mid;
            b.start_index = mid;
            b.start_time_s = time_s[mid];
            out.push(Segment::from_steady(&a, kind_of(stroke_no, rising[k - 1])));
            stroke_no += 1;
            out.push(Segment::from_steady(&b, kind_of(stroke_no, rising[k])));
        }
    }
    out.extend(steady[steady.len() - trail..].iter().map(|s| Segment::from_steady(s, SegmentKind::RestEnd)));
    assign_nominal_rates(&mut out, options)?;
    Ok(out)
}

/// Checks that every run has both strokes, every stroke the same rates, and sets each plateau's
/// nominal rate to the mean over strokes of the rates measured at its point.
fn assign_nominal_rates(segments: &mut [Segment], options: &SegmentOptions) -> Result<(), SegmentError> {
    // Groups of plateau positions per (run, stroke), in order of first appearance.
    let mut groups: Vec<((u32, Stroke), Vec<usize>)> = Vec::new();
    for (i, s) in segments.iter().enumerate() {
        if let SegmentKind::Plateau { run, stroke } = s.kind {
            match groups.iter_mut().find(|g| g.0 == (run, stroke)) {
                Some(g) => g.1.push(i),
                None => groups.push(((run, stroke), vec![i])),
            }
        }
    }
    if groups.is_empty() {
        return Err(SegmentError::TooFewPlateaus { found: 0, index: 0, time_s: f64::NAN });
    }
    for (_, members) in groups.iter_mut() {
        members.sort_by(|&a, &b| segments[a].rate_dps.total_cmp(&segments[b].rate_dps));
        for w in members.windows(2) {
            let (p, q) = (&segments[w[0]], &segments[w[1]]);
            if (q.rate_dps - p.rate_dps).abs() <= options.tolerance_at(p.rate_dps.abs().max(q.rate_dps.abs())) {
                let later = if q.start_index > p.start_index { q } else { p };
                return Err(SegmentError::RepeatedRate {
                    index: later.start_index,
                    time_s: later.start_time_s,
                    rate_dps: later.rate_dps,
                });
            }
        }
    }
    let expected = groups.iter().map(|g| g.1.len()).max().unwrap_or(0);
    let last_of = |members: &[usize]| {
        let s = members.iter().map(|&i| &segments[i]).max_by_key(|s| s.end_index).copied();
        s.map_or((0, f64::NAN), |s| (s.end_index.saturating_sub(1), s.end_time_s))
    };
    for ((run, stroke), members) in &groups {
        if members.len() < expected {
            let (index, time_s) = last_of(members);
            return Err(SegmentError::IncompleteRun {
                run: *run,
                stroke: *stroke,
                found: members.len(),
                expected,
                index,
                time_s,
            });
        }
    }
    let mut runs: Vec<u32> = groups.iter().map(|g| g.0 .0).collect();
    runs.sort_unstable();
    runs.dedup();
    for run in runs {
        for missing in [Stroke::Forward, Stroke::Reverse] {
            if !groups.iter().any(|g| g.0 == (run, missing)) {
                let other: Vec<usize> = groups.iter().filter(|g| g.0 .0 == run).flat_map(|g| g.1.clone()).collect();
                let (index, time_s) = last_of(&other);
                return Err(SegmentError::MissingStroke { run, missing, index, time_s });
            }
        }
    }
    for j in 0..expected {
        let reference = segments[groups[0].1[j]].rate_dps;
        let mut sum = 0.0;
        for ((run, stroke), members) in &groups {
            let s = &segments[members[j]];
            if (s.rate_dps - reference).abs() > options.tolerance_at(reference) {
                return Err(SegmentError::RateMismatch {
                    run: *run,
                    stroke: *stroke,
                    rate_dps: s.rate_dps,
                    expected_dps: reference,
                    index: s.start_index,
                    time_s: s.start_time_s,
                });
            }
            sum += s.rate_dps;
        }
        let nominal = sum / groups.len() as f64;
        for (_, members) in &groups {
            segments[members[j]].nominal_rate_dps = nominal;
        }
    }
    Ok(())
}

/// Builds labelled segments from hand-given windows (a manual segment file) over a raw log.
///
/// Windows are used as given (no settling is dropped); they must be in time order, must not
/// overlap, must each hold at least one sample and no time gap longer than [`GAP_INTERVALS`]
/// sampling intervals. Runs and strokes are checked as for
/// automatic segmentation (every run both strokes, every stroke the same rates).
pub fn segments_from_manual(
    time_s: &[f64],
    rate_dps: &[f64],
    manual: &[ManualSegment],
    options: &SegmentOptions,
) -> Result<Vec<Segment>, SegmentError> {
    options.validate()?;
    check_log(time_s, rate_dps)?;
    let (log_start_s, log_end_s) = (time_s[0], time_s[time_s.len() - 1]);
    let nominal_s = crate::sampling::estimate_interval(time_s).ok().map(|e| e.nominal_s);
    let mut out: Vec<Segment> = Vec::with_capacity(manual.len());
    for m in manual {
        let a = time_s.partition_point(|&t| t < m.start_time_s);
        let b = time_s.partition_point(|&t| t <= m.end_time_s);
        let ordered = m.start_time_s <= m.end_time_s;
        if !ordered || b <= a {
            return Err(SegmentError::EmptySegment {
                start_s: m.start_time_s,
                end_s: m.end_time_s,
                log_start_s,
                log_end_s,
            });
        }
        if let Some(prev) = out.last() {
            if a < prev.end_index {
                return Err(SegmentError::Overlap { index: a, time_s: time_s[a], previous_end_s: prev.end_time_s });
            }
        }
        // A time gap inside a window: samples are missing from a segment the user drew.
        if let Some(nominal) = nominal_s {
            if let Some(i) = (a + 1..b).find(|&i| time_s[i] - time_s[i - 1] > GAP_INTERVALS * nominal) {
                return Err(SegmentError::TimeGap {
                    index: i,
                    time_s: time_s[i],
                    previous_s: time_s[i - 1],
                    gap_s: time_s[i] - time_s[i - 1],
                    interval_s: nominal,
                    rate_dps: rate_dps[i - 1],
                });
            }
        }
        let rate = rate_dps[a..b].iter().sum::<f64>() / (b - a) as f64;
        let steady = SteadySegment {
            steady_from_index: a,
            start_index: a,
            end_index: b,
            start_time_s: time_s[a],
            end_time_s: time_s[b - 1],
            rate_dps: rate,
        };
        out.push(Segment::from_steady(&steady, m.kind));
    }
    assign_nominal_rates(&mut out, options)?;
    Ok(out)
}

/// How the samples of a plateau become observations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PlateauReduction {
    /// One observation per plateau: the mean output of its kept samples (paper eq. 4).
    Mean,
    /// One observation per kept sample (the grid averages them, the same mean).
    EverySample,
}

/// Turns labelled segments and one output channel into rate-table observations (at each
/// plateau's nominal rate) and the rest record (mean outputs of the rest segments at start and
/// end, when both are present and `rest` is not [`RestPolicy::Unused`]), ready for
/// `RateTable::from_observations`. The two halves of a turning plateau keep the whole plateau's
/// measured rate.
pub fn rate_observations(
    segments: &[Segment],
    time_s: &[f64],
    output: &[f64],
    reduction: PlateauReduction,
    rest: RestPolicy,
) -> Result<(Vec<RateObservation>, Option<RestRecord>), SegmentError> {
    if output.len() != time_s.len() {
        return Err(SegmentError::LengthMismatch { what: "output", found: output.len(), expected: time_s.len() });
    }
    let mut obs = Vec::new();
    let (mut start, mut end) = ((0.0, 0usize), (0.0, 0usize));
    for s in segments {
        if s.end_index > output.len() || s.start_index >= s.end_index {
            return Err(SegmentError::EmptySegment {
                start_s: s.start_time_s,
                end_s: s.end_time_s,
                log_start_s: time_s.first().copied().unwrap_or(f64::NAN),
                log_end_s: time_s.last().copied().unwrap_or(f64::NAN),
            });
        }
        let values = &output[s.start_index..s.end_index];
        if let Some(k) = values.iter().position(|v| !v.is_finite()) {
            let index = s.start_index + k;
            return Err(SegmentError::NonFinite { index, time_s: time_s[index], what: "output" });
        }
        let sum: f64 = values.iter().sum();
        match s.kind {
            SegmentKind::RestStart => start = (start.0 + sum, start.1 + values.len()),
            SegmentKind::RestEnd => end = (end.0 + sum, end.1 + values.len()),
            SegmentKind::Plateau { run, stroke } => match reduction {
                PlateauReduction::Mean => obs.push(RateObservation {
                    rate_dps: s.nominal_rate_dps,
                    run,
                    stroke,
                    output: sum / values.len() as f64,
                }),
                PlateauReduction::EverySample => obs.extend(values.iter().map(|&output| RateObservation {
                    rate_dps: s.nominal_rate_dps,
                    run,
                    stroke,
                    output,
                })),
            },
        }
    }
    let rest = (rest != RestPolicy::Unused && start.1 > 0 && end.1 > 0)
        .then(|| RestRecord { start: start.0 / start.1 as f64, end: end.0 / end.1 as f64 });
    Ok((obs, rest))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rate_test::{evaluate, RateTable, RateTestOptions};
    use crate::sim::{gyro_output, raw_log_setpoints, simulate_raw_log, RawLogProfile, SimulatedRawLog};

    const RATES: [f64; 7] = [-300.0, -100.0, -30.0, 0.0, 30.0, 100.0, 300.0];

    /// A piecewise-linear rate profile through knots (time s, rate deg/s), sampled every dt.
    fn piecewise(knots: &[(f64, f64)], dt: f64) -> (Vec<f64>, Vec<f64>) {
        let end = knots[knots.len() - 1].0;
        let n = (end / dt).floor() as usize;
        let mut k = 0;
        let mut t = Vec::with_capacity(n);
        let mut r = Vec::with_capacity(n);
        for i in 0..n {
            let ti = i as f64 * dt;
            while k + 2 < knots.len() && ti >= knots[k + 1].0 {
                k += 1;
            }
            let ((t0, r0), (t1, r1)) = (knots[k], knots[k + 1]);
            t.push(ti);
            r.push(r0 + (r1 - r0) * (ti - t0) / (t1 - t0));
        }
        (t, r)
    }

    fn three_runs() -> SimulatedRawLog {
        simulate_raw_log(&raw_log_setpoints(&RATES, 3, true, true), &RawLogProfile::default(), 7).unwrap()
    }

    /// Segmentation against the simulation's truth. Bounds: the overshoot (0.5 deg/s, tau 0.1 s)
    /// falls under the tolerance (>= 0.05 deg/s) within tau ln(0.5/0.02) = 0.32 s, so the steady
    /// stretch starts between the ramp's end (less tolerance / acceleration, the part of the ramp
    /// already within tolerance) and 0.5 s later, and the kept part `settling` after that; a
    /// plateau ends within that ramp margin and a sample or two of the ramp out's start. A
    /// turning plateau splits at the middle of its kept part.
    fn check_segmentation(p: &RawLogProfile, seed: u64) {
        let sim = simulate_raw_log(&raw_log_setpoints(&RATES, 3, true, true), p, seed).unwrap();
        let o = SegmentOptions::default();
        let seg = segment_log(&sim.time, &sim.logged_rate, &o).unwrap();
        let expected: usize = sim.holds.iter().map(|h| h.labels.len()).sum();
        assert_eq!(seg.len(), expected);
        let dt = p.dt;
        let late = 0.5;
        let mut k = 0;
        for h in &sim.holds {
            let ramp = o.tolerance_at(h.rate) / p.accel_dps2;
            let (s_lo, s_hi) = (h.t_start + o.settling_s - ramp - dt, h.t_start + o.settling_s + late);
            let (e_lo, e_hi) = (h.t_end - 2.0 * dt, h.t_end + ramp + dt);
            let (m_lo, m_hi) = ((s_lo + e_lo) / 2.0 - 2.0 * dt, (s_hi + e_hi) / 2.0 + 2.0 * dt);
            for (j, label) in h.labels.iter().enumerate() {
                let s = &seg[k];
                assert_eq!(s.kind, *label, "segment {k}: {s:?}");
                let (lo, hi) = if j == 0 { (s_lo, s_hi) } else { (m_lo, m_hi) };
                assert!(s.start_time_s >= lo && s.start_time_s <= hi, "segment {k} start {s:?} not in {lo}..{hi}");
                let (lo, hi) = if j + 1 == h.labels.len() { (e_lo, e_hi) } else { (m_lo, m_hi) };
                assert!(s.end_time_s >= lo && s.end_time_s <= hi, "segment {k} end {s:?} not in {lo}..{hi}");
                // Noise 0.01 deg/s over >= 400 samples: sigma of a mean 5e-4 deg/s.
                assert!((s.rate_dps - h.rate).abs() < 2.5e-3, "{s:?}");
                assert!((s.nominal_rate_dps - h.rate).abs() < 1e-3, "{s:?}");
                assert_eq!(s.samples(), s.end_index - s.start_index);
                k += 1;
            }
        }
    }

    #[test]
    fn segmentation_matches_the_simulated_truth() {
        check_segmentation(&RawLogProfile::default(), 7);
    }

    /// 1 kHz (the top of the range): the ramp moves one tolerance per sample, and the log
    /// has about 600 000 samples (the single pass must stay fast even unoptimised).
    #[test]
    fn segmentation_matches_the_simulated_truth_at_1_khz() {
        check_segmentation(&RawLogProfile { dt: 0.001, ..RawLogProfile::default() }, 8);
    }

    /// K and F0 through `rate_test::evaluate` within 5 standard errors computed from the noise.
    #[test]
    fn scale_factor_and_offset_recovered_through_evaluate() {
        let p = RawLogProfile::default();
        let sim = three_runs();
        let (k_true, f0_true, sigma) = (0.0075, 2.5, 0.002);
        let out = gyro_output(&sim.true_rate, k_true, f0_true, sigma, 11).unwrap();
        let o = SegmentOptions::default();
        let seg = segment_log(&sim.time, &sim.logged_rate, &o).unwrap();
        let (obs, rest) = rate_observations(&seg, &sim.time, &out, PlateauReduction::Mean, o.rest).unwrap();
        let rest = rest.expect("rest at both ends");
        let table = RateTable::from_observations(&obs, Some(rest)).unwrap();
        assert_eq!(table.rates_dps.len(), RATES.len());
        assert_eq!(table.runs, vec![1, 2, 3]);
        let e = evaluate(&table, &RateTestOptions::default()).unwrap();
        // Fewest samples in a cell: half of a turning plateau, (hold - settling - 0.5 s) / 2.
        let n_min = ((p.hold_s - o.settling_s - 0.5) / 2.0 / p.dt).floor();
        let sigma_point = sigma / n_min.sqrt() / (2.0 * 3.0f64).sqrt(); // mean of 2 strokes x 3 runs
        let m = RATES.len() as f64;
        let mean_w = RATES.iter().sum::<f64>() / m;
        let sxx: f64 = RATES.iter().map(|w| (w - mean_w).powi(2)).sum();
        let se_k = sigma_point / sxx.sqrt();
        let se_f0 = sigma_point * (1.0 / m + mean_w * mean_w / sxx).sqrt();
        assert!((e.scale_factor() - k_true).abs() < 5.0 * se_k, "K {} vs {k_true} (se {se_k})", e.scale_factor());
        assert!((e.zero_offset() - f0_true).abs() < 5.0 * se_f0, "F0 {} (se {se_f0})", e.zero_offset());
        // Rest records: >= 600 samples each.
        assert!((rest.start - f0_true).abs() < 5.0 * sigma / 600f64.sqrt());
        assert!((rest.end - f0_true).abs() < 5.0 * sigma / 600f64.sqrt());
        // Every-sample reduction: the grid averages the same samples.
        let (all, _) = rate_observations(&seg, &sim.time, &out, PlateauReduction::EverySample, o.rest).unwrap();
        let e2 =
            evaluate(&RateTable::from_observations(&all, Some(rest)).unwrap(), &RateTestOptions::default()).unwrap();
        assert!((e2.scale_factor() - e.scale_factor()).abs() < 1e-12);
        // Unused rest policy drops the rest record.
        assert!(rate_observations(&seg, &sim.time, &out, PlateauReduction::Mean, RestPolicy::Unused)
            .unwrap()
            .1
            .is_none());
    }

    #[test]
    fn manual_segments_from_the_detected_windows_give_the_same_labels() {
        let sim = three_runs();
        let o = SegmentOptions::default();
        let seg = segment_log(&sim.time, &sim.logged_rate, &o).unwrap();
        let manual: Vec<ManualSegment> = seg
            .iter()
            .map(|s| ManualSegment { start_time_s: s.start_time_s, end_time_s: s.end_time_s, kind: s.kind })
            .collect();
        let again = segments_from_manual(&sim.time, &sim.logged_rate, &manual, &o).unwrap();
        for (a, b) in seg.iter().zip(&again) {
            assert_eq!((a.start_index, a.end_index, a.kind), (b.start_index, b.end_index, b.kind));
            // Equal but for the halves of turning plateaus (whole-plateau mean vs half mean: noise,
            // 0.01 deg/s over >= 400 samples).
            assert!((a.nominal_rate_dps - b.nominal_rate_dps).abs() < 1e-3);
        }
        // Overlap: the second window starts before the first ends.
        let mut bad = manual.clone();
        bad[1].start_time_s = bad[0].end_time_s - 1.0;
        let e = segments_from_manual(&sim.time, &sim.logged_rate, &bad, &o).unwrap_err();
        assert!(matches!(e, SegmentError::Overlap { .. }), "{e}");
        assert!(e.sample_index().is_some());
        // A time gap inside a window (500 intervals, beyond 100): refused at the sample after it.
        let mut gapped = sim.time.clone();
        let inside = (seg[3].start_index + seg[3].end_index) / 2;
        let dt = sim.time[1] - sim.time[0];
        gapped[inside..].iter_mut().for_each(|t| *t += 500.0 * dt);
        let shifted: Vec<ManualSegment> = manual
            .iter()
            .enumerate()
            .map(|(k, m)| {
                let d = if k > 3 { 500.0 * dt } else { 0.0 };
                ManualSegment {
                    start_time_s: m.start_time_s + d,
                    end_time_s: m.end_time_s + if k >= 3 { 500.0 * dt } else { 0.0 },
                    kind: m.kind,
                }
            })
            .collect();
        let e = segments_from_manual(&gapped, &sim.logged_rate, &shifted, &o).unwrap_err();
        assert!(matches!(e, SegmentError::TimeGap { index, .. } if index == inside), "{e}");
        // A window outside the log.
        bad = manual.clone();
        bad.push(ManualSegment { start_time_s: 1e6, end_time_s: 1e6 + 5.0, kind: SegmentKind::RestEnd });
        assert!(matches!(
            segments_from_manual(&sim.time, &sim.logged_rate, &bad, &o),
            Err(SegmentError::EmptySegment { .. })
        ));
        // A run with its reverse stroke labelled as forward: run 1 has two forward groups merged.
        bad = manual.clone();
        for m in bad.iter_mut() {
            if m.kind == (SegmentKind::Plateau { run: 3, stroke: Stroke::Reverse }) {
                m.kind = SegmentKind::Plateau { run: 3, stroke: Stroke::Forward };
            }
        }
        let e = segments_from_manual(&sim.time, &sim.logged_rate, &bad, &o).unwrap_err();
        assert!(matches!(e, SegmentError::RepeatedRate { .. }), "{e}");
    }

    #[test]
    fn a_log_with_no_steady_plateau_is_an_error() {
        let (t, _) = piecewise(&[(0.0, 0.0), (100.0, 0.0)], 0.01);
        let r: Vec<f64> = t.iter().map(|t| 100.0 * (std::f64::consts::TAU * t / 20.0).sin()).collect();
        let e = segment_log(&t, &r, &SegmentOptions::default()).unwrap_err();
        assert!(matches!(e, SegmentError::NoPlateau { .. }), "{e}");
        assert!(e.to_string().contains("no steady plateau"), "{e}");
        // A ramp so slow that each sample is within tolerance of the last: rejected by the drift test.
        let (t, r) = piecewise(&[(0.0, -50.0), (200.0, 50.0)], 0.01);
        let e = segment_log(&t, &r, &SegmentOptions::default()).unwrap_err();
        assert!(matches!(e, SegmentError::NoPlateau { .. }), "{e}");
    }

    #[test]
    fn a_rate_that_never_returns_to_rest_is_an_error() {
        let sim = simulate_raw_log(&raw_log_setpoints(&RATES, 2, true, false), &RawLogProfile::default(), 3).unwrap();
        let e = segment_log(&sim.time, &sim.logged_rate, &SegmentOptions::default()).unwrap_err();
        assert!(matches!(e, SegmentError::NoFinalRest { .. }), "{e}");
        assert!(e.to_string().contains("never returns to rest"), "{e}");
        // Without rest at either end: accepted, no rest record.
        let sim = simulate_raw_log(&raw_log_setpoints(&RATES, 2, false, false), &RawLogProfile::default(), 3).unwrap();
        let o = SegmentOptions::default();
        let seg = segment_log(&sim.time, &sim.logged_rate, &o).unwrap();
        let out = gyro_output(&sim.true_rate, 1.0, 0.0, 0.001, 1).unwrap();
        assert!(rate_observations(&seg, &sim.time, &out, PlateauReduction::Mean, o.rest).unwrap().1.is_none());
        // ... unless rest is required.
        let req = SegmentOptions { rest: RestPolicy::Required, ..o };
        assert!(matches!(segment_log(&sim.time, &sim.logged_rate, &req), Err(SegmentError::NoFinalRest { .. })));
    }

    #[test]
    fn a_run_that_stops_midway_is_an_error() {
        // Run 2's reverse stroke stops at -30 deg/s (after 300, 100, 30, 0, -30), then rest.
        let mut seq = raw_log_setpoints(&RATES, 2, true, false);
        seq.truncate(seq.len() - 2);
        seq.push((0.0, vec![SegmentKind::RestEnd]));
        let sim = simulate_raw_log(&seq, &RawLogProfile::default(), 5).unwrap();
        let e = segment_log(&sim.time, &sim.logged_rate, &SegmentOptions::default()).unwrap_err();
        assert!(
            matches!(e, SegmentError::IncompleteRun { run: 2, stroke: Stroke::Reverse, found: 5, expected: 7, .. }),
            "{e}"
        );
        assert!(e.to_string().contains("stops midway"), "{e}");
        // Run 2 without its reverse stroke.
        let mut seq = raw_log_setpoints(&RATES, 2, true, false);
        seq.truncate(seq.len() - (RATES.len() - 1));
        seq.push((0.0, vec![SegmentKind::RestEnd]));
        let sim = simulate_raw_log(&seq, &RawLogProfile::default(), 5).unwrap();
        let e = segment_log(&sim.time, &sim.logged_rate, &SegmentOptions::default()).unwrap_err();
        assert!(matches!(e, SegmentError::MissingStroke { run: 2, missing: Stroke::Reverse, .. }), "{e}");
    }

    #[test]
    fn two_plateaus_at_one_rate_in_a_row_are_ambiguous() {
        // rest, 100 deg/s, a 0.4 s excursion to 120 and back, 100 deg/s again, rest.
        let knots = [
            (0.0, 0.0),
            (10.0, 0.0),
            (12.0, 100.0),
            (22.0, 100.0),
            (22.2, 120.0),
            (22.4, 100.0),
            (32.4, 100.0),
            (34.4, 0.0),
            (44.4, 0.0),
        ];
        let (t, r) = piecewise(&knots, 0.01);
        let e = segment_log(&t, &r, &SegmentOptions::default()).unwrap_err();
        assert!(matches!(e, SegmentError::RepeatedRate { .. }), "{e}");
        let i = e.sample_index().unwrap();
        assert!((t[i] - 23.4).abs() < 0.05, "{e}");
    }

    #[test]
    fn short_glitches_stay_inside_a_plateau_and_bad_columns_are_errors() {
        let (t, mut r) = piecewise(&[(0.0, 50.0), (20.0, 50.0)], 0.01);
        r[1000] = 80.0; // one bad sample: a glitch, not a break
        r[1001] = 80.0;
        let steady = find_steady_segments(&t, &r, &SegmentOptions::default()).unwrap();
        assert_eq!(steady.len(), 1);
        assert_eq!(steady[0].end_index, t.len());
        let mut t2 = t.clone();
        t2[500] = t2[499];
        assert!(matches!(
            find_steady_segments(&t2, &r, &SegmentOptions::default()),
            Err(SegmentError::TimeNotIncreasing { index: 500, .. })
        ));
        r[7] = f64::NAN;
        assert!(matches!(
            find_steady_segments(&t, &r, &SegmentOptions::default()),
            Err(SegmentError::NonFinite { index: 7, .. })
        ));
        assert!(matches!(
            find_steady_segments(&t, &r[1..], &SegmentOptions::default()),
            Err(SegmentError::LengthMismatch { .. })
        ));
        let bad = SegmentOptions { min_duration_s: -1.0, ..Default::default() };
        assert!(matches!(find_steady_segments(&t, &r, &bad), Err(SegmentError::InvalidOption(_))));
    }

    #[test]
    fn kind_labels_round_trip() {
        for k in
            [SegmentKind::RestStart, SegmentKind::RestEnd, SegmentKind::Plateau { run: 2, stroke: Stroke::Reverse }]
        {
            let (run, stroke) = match k {
                SegmentKind::Plateau { run, stroke } => (Some(run), Some(stroke)),
                _ => (None, None),
            };
            assert_eq!(SegmentKind::from_parts(k.label(), run, stroke), Some(k));
        }
        assert_eq!(SegmentKind::from_parts("plateau", None, Some(Stroke::Forward)), None);
    }

    #[test]
    fn a_time_jump_inside_a_plateau_is_an_error_with_its_sample() {
        let mut t: Vec<f64> = (0..3000).map(|i| i as f64 * 0.01).collect();
        let r: Vec<f64> = (0..3000).map(|i| if (1000..2000).contains(&i) { 10.0 } else { 0.0 }).collect();
        for x in &mut t[1500..] {
            *x += 1e6;
        }
        let e = find_steady_segments(&t, &r, &SegmentOptions::default()).unwrap_err();
        assert!(matches!(e, SegmentError::TimeGap { index: 1500, .. }), "{e}");
        assert_eq!(e.sample_index(), Some(1500));
        assert!(e.to_string().contains("time jumps by"), "{e}");
    }
}
