//! Per-chunk extremes of the first pass, which prove when the outlier pass cannot find anything.

use super::accumulator::StaticTestAccumulator;
use super::config::SampleBlock;
use super::result::DriftLine;

/// Extremes of the valid samples of a run of consecutive samples (at most [`EXTREMES_CHUNK`]),
/// kept so the outlier pass can be skipped when it cannot find anything. The extremes are of
/// y = x - s t with a provisional slope s (the fit of the previous chunks' means), so that the
/// residuals about the final drift line can be bounded tightly.
#[derive(Debug, Clone, Copy)]
pub(super) struct ChunkExtremes {
    pub(super) samples: u64,
    pub(super) slope: f64,
    pub(super) t_min: f64,
    pub(super) t_max: f64,
    pub(super) y_min: f64,
    pub(super) y_max: f64,
    pub(super) valid: u64,
    pub(super) t_sum: f64,
    pub(super) x_sum: f64,
}

/// Samples per [`ChunkExtremes`] entry (memory: 72 bytes per 1024 samples, 7 MB per 1e8).
pub(super) const EXTREMES_CHUNK: u64 = 1024;
/// Samples per entry for the first [`EXTREMES_SHORT_CHUNKS`] entries, while the provisional
/// slope is still poorly known.
pub(super) const EXTREMES_SHORT_CHUNK: u64 = 128;
/// Number of short entries at the start of a record.
pub(super) const EXTREMES_SHORT_CHUNKS: usize = 16;

/// Running least-squares slope of the chunk means (values relative to the first chunk's mean).
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct ChunkSlope {
    pub(super) reference: Option<(f64, f64)>,
    pub(super) n: f64,
    pub(super) st: f64,
    pub(super) sx: f64,
    pub(super) stt: f64,
    pub(super) stx: f64,
}

impl ChunkSlope {
    pub(super) fn add(&mut self, t: f64, x: f64) {
        let (t0, x0) = *self.reference.get_or_insert((t, x));
        let (t, x) = (t - t0, x - x0);
        self.n += 1.0;
        self.st += t;
        self.sx += x;
        self.stt += t * t;
        self.stx += t * x;
    }

    pub(super) fn slope(&self) -> f64 {
        let d = self.n * self.stt - self.st * self.st;
        if self.n >= 2.0 && d > 0.0 {
            (self.n * self.stx - self.st * self.sx) / d
        } else {
            0.0
        }
    }
}

impl StaticTestAccumulator {
    /// Records the extremes of the block's valid samples, chunk by chunk (`clean`: every sample
    /// is valid, see [`Self::block_is_clean`]).
    pub(super) fn track_extremes(&mut self, b: &SampleBlock, clean: bool) {
        let fs = self.fs.unwrap_or(1.0); // ok: process runs only once the rate is set
        let i0 = self.samples;
        let n = b.output.len();
        let mut i = 0;
        while i < n {
            let size = if self.extremes.len() <= EXTREMES_SHORT_CHUNKS { EXTREMES_SHORT_CHUNK } else { EXTREMES_CHUNK };
            if self.extremes.last().is_none_or(|c| c.samples >= size) {
                if let Some(c) = self.extremes.last() {
                    if c.valid > 0 {
                        self.chunk_slope.add(c.t_sum / c.valid as f64, c.x_sum / c.valid as f64);
                    }
                }
                self.extremes.push(ChunkExtremes {
                    samples: 0,
                    slope: self.chunk_slope.slope(),
                    t_min: f64::INFINITY,
                    t_max: f64::NEG_INFINITY,
                    y_min: f64::INFINITY,
                    y_max: f64::NEG_INFINITY,
                    valid: 0,
                    t_sum: 0.0,
                    x_sum: 0.0,
                });
            }
            let size = if self.extremes.len() <= EXTREMES_SHORT_CHUNKS { EXTREMES_SHORT_CHUNK } else { EXTREMES_CHUNK };
            let Some(c) = self.extremes.last_mut() else { return };
            let take = ((size - c.samples) as usize).min(n - i);
            if let (true, Some(ts)) = (clean, b.time_s) {
                // Every sample valid: the same sums without a test per sample.
                let slope = c.slope;
                for (&x, &t) in b.output[i..i + take].iter().zip(&ts[i..i + take]) {
                    let y = x - slope * t;
                    c.y_min = c.y_min.min(y);
                    c.y_max = c.y_max.max(y);
                    c.t_min = c.t_min.min(t);
                    c.t_max = c.t_max.max(t);
                    c.t_sum += t;
                    c.x_sum += x;
                }
                c.valid += take as u64;
                c.samples += take as u64;
                i += take;
                continue;
            }
            for j in i..i + take {
                let x = b.output[j];
                let t = b.time_s.map_or((i0 + j as u64) as f64 / fs, |ts| ts[j]);
                if x.is_finite() && t.is_finite() {
                    let y = x - c.slope * t;
                    c.y_min = c.y_min.min(y);
                    c.y_max = c.y_max.max(y);
                    c.t_min = c.t_min.min(t);
                    c.t_max = c.t_max.max(t);
                    c.valid += 1;
                    c.t_sum += t;
                    c.x_sum += x;
                }
            }
            c.samples += take as u64;
            i += take;
        }
    }

    /// Whether any chunk could hold a sample beyond `limit` from `line` (a conservative bound:
    /// r = x - A - b t = y - A - (b - s) t with y = x - s t).
    pub(super) fn outliers_possible(&self, line: &DriftLine, limit: f64) -> bool {
        let limit = limit * (1.0 - 1e-9);
        let intercept = line.output_at_t0 - line.slope_output_per_s * line.t0_s;
        self.extremes.iter().any(|c| {
            if c.valid == 0 {
                return false;
            }
            let d = line.slope_output_per_s - c.slope;
            let (p, q) = (d * c.t_min, d * c.t_max);
            let upper = c.y_max - intercept - p.min(q);
            let lower = c.y_min - intercept - p.max(q);
            upper > limit || lower < -limit
        })
    }
}
