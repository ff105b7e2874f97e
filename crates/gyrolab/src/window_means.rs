//! Means of consecutive, non-overlapping windows of a record (the window means behind the bias
//! stability, and the bias time series and bias-temperature plots of the report), computed in
//! one streaming pass with memory proportional to the number of windows, not of samples.

use serde::{Deserialize, Serialize};

/// The mean of one window of `samples` consecutive samples.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct WindowMean {
    /// Start of the window, s from the record start (sample index / sample rate).
    pub start_s: f64,
    /// End of the window, s from the record start.
    pub end_s: f64,
    /// Mean output, output units.
    pub mean_output: f64,
    /// Mean temperature, degC (when the record has a temperature channel).
    pub mean_temp_c: Option<f64>,
}

/// Streaming window means: push output (and temperature) samples in blocks, then `finish`.
/// Only whole windows are kept; a window with a non-finite sample is left out.
#[derive(Debug, Clone)]
pub struct WindowMeanAccumulator {
    window_samples: u64,
    sample_rate_hz: f64,
    index: u64,
    in_window: u64,
    sum: f64,
    sum_temp: f64,
    temp_seen: bool,
    bad: bool,
    out: Vec<WindowMean>,
}

impl WindowMeanAccumulator {
    /// Windows of `window_s` seconds at `sample_rate_hz` (at least one sample per window);
    /// `None` when either is not a positive finite number.
    pub fn new(window_s: f64, sample_rate_hz: f64) -> Option<WindowMeanAccumulator> {
        if !(window_s.is_finite() && window_s > 0.0 && sample_rate_hz.is_finite() && sample_rate_hz > 0.0) {
            return None;
        }
        let window_samples = (window_s * sample_rate_hz).round().max(1.0) as u64;
        Some(WindowMeanAccumulator {
            window_samples,
            sample_rate_hz,
            index: 0,
            in_window: 0,
            sum: 0.0,
            sum_temp: 0.0,
            temp_seen: false,
            bad: false,
            out: Vec::new(),
        })
    }

    /// Samples per window.
    pub fn window_samples(&self) -> u64 {
        self.window_samples
    }

    /// Adds a block of output samples with their temperatures (same length, or `None`).
    pub fn push(&mut self, output: &[f64], temp_c: Option<&[f64]>) {
        for (i, &y) in output.iter().enumerate() {
            let t = temp_c.and_then(|t| t.get(i).copied());
            if !y.is_finite() || t.is_some_and(|t| !t.is_finite()) {
                self.bad = true;
            }
            self.sum += y;
            if let Some(t) = t {
                self.sum_temp += t;
                self.temp_seen = true;
            }
            self.in_window += 1;
            self.index += 1;
            if self.in_window == self.window_samples {
                let n = self.window_samples as f64;
                if !self.bad {
                    let end = self.index as f64 / self.sample_rate_hz;
                    self.out.push(WindowMean {
                        start_s: end - n / self.sample_rate_hz,
                        end_s: end,
                        mean_output: self.sum / n,
                        mean_temp_c: self.temp_seen.then(|| self.sum_temp / n),
                    });
                }
                self.in_window = 0;
                self.sum = 0.0;
                self.sum_temp = 0.0;
                self.temp_seen = false;
                self.bad = false;
            }
        }
    }

    /// The means of the whole windows, in time order.
    pub fn finish(self) -> Vec<WindowMean> {
        self.out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn whole_windows_only_across_blocks() {
        let mut a = WindowMeanAccumulator::new(1.0, 4.0).unwrap();
        let y: Vec<f64> = (0..10).map(f64::from).collect();
        let t = [20.0; 10];
        a.push(&y[..3], Some(&t[..3]));
        a.push(&y[3..], Some(&t[3..]));
        let w = a.finish();
        assert_eq!(w.len(), 2);
        assert_eq!(w[0].mean_output, 1.5);
        assert_eq!(w[1].mean_output, 5.5);
        assert_eq!((w[1].start_s, w[1].end_s), (1.0, 2.0));
        assert_eq!(w[0].mean_temp_c, Some(20.0));
        assert!(WindowMeanAccumulator::new(0.0, 4.0).is_none());
        let mut b = WindowMeanAccumulator::new(0.5, 4.0).unwrap();
        b.push(&[1.0, f64::NAN, 2.0, 2.0], None);
        assert_eq!(b.finish().len(), 1);
    }
}
