//! The outcome of a raw rate-table log's segmentation: its labelled segments and source lines.

use gyrolab::segment::Segment;

/// The segmentation of one raw log, with what is needed to report it.
#[derive(Debug, Clone)]
pub struct SegmentationReport<'a> {
    /// Source file as given.
    pub file: String,
    /// `automatic` or `manual` (from a segment file).
    pub mode: &'static str,
    /// Samples in the log.
    pub samples: usize,
    /// The labelled segments.
    pub segments: &'a [Segment],
    /// Source line of each sample.
    pub lines: &'a [u64],
}
