//! Segmentation summaries of raw rate-table logs (`gyrolab rate` on raw logs): text and JSON.

use gyrolab::rate_test::Stroke;
use gyrolab::segment::SegmentKind;
use gyrolab_eval::outcome::segments::SegmentationReport;
use serde::Serialize;
use std::fmt::Write as _;

/// Plateaus of one run and stroke.
#[derive(Debug, Clone, Serialize)]
pub struct StrokeJson {
    /// Run number.
    pub run: u32,
    /// `fwd` or `rev`.
    pub stroke: Stroke,
    /// Plateaus found.
    pub plateaus: usize,
    /// Lowest and highest nominal rate, deg/s.
    pub rate_min_dps: f64,
    /// Highest nominal rate, deg/s.
    pub rate_max_dps: f64,
    /// File line of the stroke's first kept sample.
    pub first_line: u64,
    /// File line of its last kept sample.
    pub last_line: u64,
}

/// One segment in JSON (the `--segments-out` columns).
#[derive(Debug, Clone, Serialize)]
pub struct SegmentJson {
    /// 1-based position.
    pub index: usize,
    /// `rest_start`, `rest_end` or `plateau`.
    pub kind: &'static str,
    /// Run (plateaus only).
    pub run: Option<u32>,
    /// Stroke (plateaus only).
    pub stroke: Option<Stroke>,
    /// File line of the first kept sample.
    pub start_line: u64,
    /// File line of the last kept sample.
    pub end_line: u64,
    /// Time of the first kept sample, s.
    pub start_time_s: f64,
    /// Time of the last kept sample, s.
    pub end_time_s: f64,
    /// Kept samples.
    pub samples: usize,
    /// Mean table rate, deg/s.
    pub rate_dps: f64,
    /// Nominal rate of the test point, deg/s (0 for rest).
    pub nominal_rate_dps: f64,
}

/// JSON of one log's segmentation.
#[derive(Debug, Clone, Serialize)]
pub struct SegmentationJson {
    /// Source file.
    pub file: String,
    /// `automatic` or `manual`.
    pub mode: &'static str,
    /// Samples in the log.
    pub samples: usize,
    /// Runs found.
    pub runs: u32,
    /// Plateaus (turning plateaus count once per stroke).
    pub plateaus: usize,
    /// Kept samples of the rest at the start (0: none).
    pub rest_start_samples: usize,
    /// Kept samples of the rest at the end (0: none).
    pub rest_end_samples: usize,
    /// Samples dropped as settling at the start of steady stretches.
    pub settling_samples_dropped: usize,
    /// Per run and stroke.
    pub strokes: Vec<StrokeJson>,
    /// Every segment.
    pub segments: Vec<SegmentJson>,
}

impl SegmentationJson {
    /// Builds the JSON view of a segmentation.
    pub fn new(r: &SegmentationReport<'_>) -> SegmentationJson {
        let line = |i: usize| r.lines.get(i).copied().unwrap_or(0);
        let mut strokes: Vec<StrokeJson> = Vec::new();
        let (mut rest_start_samples, mut rest_end_samples, mut settling, mut plateaus, mut runs) = (0, 0, 0, 0, 0);
        for s in r.segments {
            settling += s.start_index - s.steady_from_index.min(s.start_index);
            match s.kind {
                SegmentKind::RestStart => rest_start_samples += s.samples(),
                SegmentKind::RestEnd => rest_end_samples += s.samples(),
                SegmentKind::Plateau { run, stroke } => {
                    plateaus += 1;
                    runs = runs.max(run);
                    let (first, last) = (line(s.start_index), line(s.end_index.saturating_sub(1)));
                    match strokes.iter_mut().find(|g| g.run == run && g.stroke == stroke) {
                        Some(g) => {
                            g.plateaus += 1;
                            g.rate_min_dps = g.rate_min_dps.min(s.nominal_rate_dps);
                            g.rate_max_dps = g.rate_max_dps.max(s.nominal_rate_dps);
                            g.first_line = g.first_line.min(first);
                            g.last_line = g.last_line.max(last);
                        }
                        None => strokes.push(StrokeJson {
                            run,
                            stroke,
                            plateaus: 1,
                            rate_min_dps: s.nominal_rate_dps,
                            rate_max_dps: s.nominal_rate_dps,
                            first_line: first,
                            last_line: last,
                        }),
                    }
                }
            }
        }
        let segments = r
            .segments
            .iter()
            .enumerate()
            .map(|(i, s)| {
                let (run, stroke) = match s.kind {
                    SegmentKind::Plateau { run, stroke } => (Some(run), Some(stroke)),
                    _ => (None, None),
                };
                SegmentJson {
                    index: i + 1,
                    kind: s.kind.label(),
                    run,
                    stroke,
                    start_line: line(s.start_index),
                    end_line: line(s.end_index.saturating_sub(1)),
                    start_time_s: s.start_time_s,
                    end_time_s: s.end_time_s,
                    samples: s.samples(),
                    rate_dps: s.rate_dps,
                    nominal_rate_dps: s.nominal_rate_dps,
                }
            })
            .collect();
        SegmentationJson {
            file: r.file.clone(),
            mode: r.mode,
            samples: r.samples,
            runs,
            plateaus,
            rest_start_samples,
            rest_end_samples,
            settling_samples_dropped: settling,
            strokes,
            segments,
        }
    }
}

/// The segmentation summary as text: one line of counts, then one line per run and stroke.
pub fn segmentation_text(r: &SegmentationReport<'_>) -> String {
    let j = SegmentationJson::new(r);
    let rest = |n: usize| if n > 0 { format!("{n} samples") } else { "none".into() };
    let mut s = format!(
        "Segmentation of {} ({}, {} samples): {} run(s), {} plateau(s); rest at start: {}, at end: {}; \
         {} settling sample(s) dropped\n",
        j.file,
        j.mode,
        j.samples,
        j.runs,
        j.plateaus,
        rest(j.rest_start_samples),
        rest(j.rest_end_samples),
        j.settling_samples_dropped
    );
    for g in &j.strokes {
        let _ = writeln!(
            s,
            "  run {} {}: {} plateaus, {} .. {} deg/s, lines {} .. {}",
            g.run,
            g.stroke,
            g.plateaus,
            gyrolab::format::short(g.rate_min_dps, 6),
            gyrolab::format::short(g.rate_max_dps, 6),
            g.first_line,
            g.last_line
        );
    }
    s
}
