//! The stillness check: did a gyro or accelerometer channel move during its record?
//!
//! Noise terms (IEEE Std 952-1997 annex C; IEEE Std 1293-2018 for accelerometers) are those of
//! a sensor at rest: a record that rotates or accelerates adds its motion to the deviations and
//! the terms read from them are not the sensor's. The rule (docs/METHODS.md, "Stillness check"):
//!
//! - the record is cut into consecutive windows of `window_s` seconds (at least
//!   [`MIN_WINDOW_SAMPLES`] samples), and the last partial window is judged when it holds at
//!   least half a window;
//! - the white-noise level sigma (per sample) is estimated from the data itself by the
//!   first-difference estimator sigma = rms(x\[i+1\] - x\[i\]) / sqrt(2) (von Neumann et al. 1941,
//!   "Distribution of the ratio of the mean square successive difference to the variance",
//!   Ann. Math. Stat. 12; insensitive to slow bias changes), computed within each window and
//!   made robust to moving windows by taking the median over windows (the median of the
//!   per-window variances divided by (1 - 2 / (9 m))^3, m = samples per window - 1, the
//!   Wilson-Hilferty median of a chi-square of m degrees of freedom over m, so that the median
//!   does not understate sigma in short windows);
//! - the still level is the median of the window means;
//! - a window moved when its mean departs from the still level by more than both
//!   `k_sigma` x sigma / sqrt(n) (n samples in the window: the standard error of a mean of white
//!   noise) and the absolute `floor` (the bias drift a still MEMS sensor may show over a record),
//!   or when its spread exceeds the white noise: its variance v is above
//!   sigma^2 q / (n - 1), q the chi-square quantile of n - 1 degrees of freedom at
//!   1 - [`SPREAD_TAIL`] (1e-9, the one-sided normal tail beyond 6 sigma), and the excess
//!   sqrt(v - sigma^2) is above the `floor` (this catches motion that averages out within a
//!   window, such as shaking);
//! - consecutive moved windows form one motion episode; the check reports the share of moved
//!   windows and the first and the largest episode (largest peak departure).
//!
//! Defaults ([`StillnessRule::for_quantity`]): 1 s windows, k = 6; floor 1 deg/s for a gyro
//! (consumer MEMS gyros hold their bias within a few tenths of a deg/s over a warm-up; the
//! rotations of a handled or flying sensor are 5 to 200 deg/s) and 0.05 g = 0.490 m/s^2 for an
//! accelerometer (a tilt of 2.9 degrees; still MEMS accelerometers drift by a few mg). For a
//! three-axis accelerometer, [`gravity_check`] compares the magnitude of each window's mean
//! specific-force vector with standard gravity (9.80665 m/s^2) within a tolerance
//! (default [`GRAVITY_TOLERANCE_M_S2`], 0.1 g: the scale and bias errors of an uncalibrated
//! MEMS accelerometer stay within a few percent).

use serde::Serialize;

use crate::units::{Quantity, STANDARD_GRAVITY_M_S2};

/// Fewest samples in a window: windows are `window_s` long or this many samples, whichever is longer.
pub const MIN_WINDOW_SAMPLES: u64 = 10;

/// Fewest judged windows for a verdict: a shorter record is not evaluated.
pub const MIN_WINDOWS: usize = 3;

/// Tail probability of the spread test of one still window (the one-sided normal tail beyond
/// 6 sigma is 9.9e-10).
pub const SPREAD_TAIL: f64 = 1e-9;

/// Default window length, s.
pub const DEFAULT_WINDOW_S: f64 = 1.0;

/// Default multiple of the white noise's standard error a window must exceed.
pub const DEFAULT_K_SIGMA: f64 = 6.0;

/// Default floor of a gyro channel, deg/s.
pub const GYRO_FLOOR_DPS: f64 = 1.0;

/// Default floor of an accelerometer channel, m/s^2 (0.05 g).
pub const ACCEL_FLOOR_M_S2: f64 = 0.05 * STANDARD_GRAVITY_M_S2;

/// Default tolerance of a three-axis accelerometer's magnitude about 1 g, m/s^2 (0.1 g).
pub const GRAVITY_TOLERANCE_M_S2: f64 = 0.1 * STANDARD_GRAVITY_M_S2;

/// The thresholds of the check.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct StillnessRule {
    /// Window length, s.
    pub window_s: f64,
    /// Multiple of the white noise's standard error a window must exceed.
    pub k_sigma: f64,
    /// Absolute floor a window's departure must exceed, in `unit`.
    pub floor: f64,
    /// Unit of the channel's samples and of every level of the check (`deg/s` or `m/s^2`).
    pub unit: &'static str,
}

impl StillnessRule {
    /// The default rule of a calibrated channel: gyro in deg/s or accelerometer in m/s^2;
    /// `None` for other quantities (no physical threshold applies).
    pub fn for_quantity(quantity: Quantity) -> Option<StillnessRule> {
        let (floor, unit) = match quantity {
            Quantity::AngularRate => (GYRO_FLOOR_DPS, "deg/s"),
            Quantity::Acceleration => (ACCEL_FLOOR_M_S2, "m/s^2"),
            Quantity::SensorOutput | Quantity::Unitless => return None,
        };
        Some(StillnessRule { window_s: DEFAULT_WINDOW_S, k_sigma: DEFAULT_K_SIGMA, floor, unit })
    }
}

/// One run of consecutive moved windows.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MotionEpisode {
    /// Start of its first window, s from the record start.
    pub start_s: f64,
    /// End of its last window, s from the record start.
    pub end_s: f64,
    /// Moved windows in the episode.
    pub windows: usize,
    /// Largest departure of a window from the still level (mean departure or spread excess),
    /// in the rule's unit.
    pub peak_departure: f64,
}

/// The verdict of the check on one channel.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StillnessCheck {
    /// Whether the check could be made (at least [`MIN_WINDOWS`] judged windows). A check not
    /// evaluated never counts as still.
    pub evaluated: bool,
    /// Why it was not evaluated.
    pub not_evaluated_reason: Option<String>,
    /// Whether the channel moved (false when not evaluated).
    pub moved: bool,
    /// The rule applied.
    pub rule: StillnessRule,
    /// Samples per window.
    pub window_samples: u64,
    /// Windows judged.
    pub windows: usize,
    /// Windows that moved.
    pub moved_windows: usize,
    /// moved_windows / windows (0 when no window was judged).
    pub moved_share: f64,
    /// White-noise standard deviation per sample from first differences (median over windows), in `rule.unit`.
    pub white_noise_sigma: f64,
    /// Still level: the median of the window means, in `rule.unit`.
    pub still_level: f64,
    /// The first motion episode.
    pub first_episode: Option<MotionEpisode>,
    /// The episode with the largest peak departure.
    pub largest_episode: Option<MotionEpisode>,
    /// Window means (start s, mean in `rule.unit`) of the judged windows, for [`gravity_check`].
    #[serde(skip)]
    pub window_means: Vec<(f64, f64)>,
}

#[derive(Debug, Clone, Copy, Default)]
struct WindowStats {
    start_index: u64,
    samples: u64,
    n: u64,
    /// Mean and sum of squared deviations, set by `settle` from the shifted sums.
    mean: f64,
    m2: f64,
    /// The window's first finite sample; s1 and s2 sum (x - shift) and (x - shift)^2 (no division
    /// per sample; the shift keeps the sums of a still record small, so m2 = s2 - s1^2 / n loses
    /// no digits that matter).
    shift: f64,
    s1: f64,
    s2: f64,
    diff_sq: f64,
    diff_n: u64,
    prev: Option<f64>,
}

impl WindowStats {
    fn push(&mut self, x: f64) {
        self.samples += 1;
        if !x.is_finite() {
            self.prev = None;
            return;
        }
        if self.n == 0 {
            self.shift = x;
        }
        self.n += 1;
        let d = x - self.shift;
        self.s1 += d;
        self.s2 += d * d;
        if let Some(p) = self.prev {
            self.diff_sq += (x - p) * (x - p);
            self.diff_n += 1;
        }
        self.prev = Some(x);
    }

    /// The mean and the sum of squared deviations from the shifted sums.
    fn settle(mut self) -> Self {
        if self.n > 0 {
            let n = self.n as f64;
            self.mean = self.shift + self.s1 / n;
            self.m2 = (self.s2 - self.s1 * self.s1 / n).max(0.0);
        }
        self
    }
}

impl StillnessCheck {
    /// A check that could not be made, and why.
    pub fn not_evaluated(rule: StillnessRule, reason: impl Into<String>) -> StillnessCheck {
        StillnessCheck {
            evaluated: false,
            not_evaluated_reason: Some(reason.into()),
            moved: false,
            rule,
            window_samples: 0,
            windows: 0,
            moved_windows: 0,
            moved_share: 0.0,
            white_noise_sigma: f64::NAN,
            still_level: f64::NAN,
            first_episode: None,
            largest_episode: None,
            window_means: Vec::new(),
        }
    }

    /// What moved and when, in words: `moved in 12 of 200 windows of 1 s (6 %): first episode
    /// 20 to 22 s (peak departure 6.1 deg/s from the still level 0.28 deg/s), largest ...`;
    /// `None` when the channel did not move.
    pub fn motion_summary(&self) -> Option<String> {
        if !self.moved {
            return None;
        }
        let u = self.rule.unit;
        let episode = |e: &MotionEpisode| {
            format!("{:.1} to {:.1} s (peak departure {:.3} {u})", e.start_s, e.end_s, e.peak_departure)
        };
        let mut s = format!(
            "moved in {} of {} windows of {} s ({:.1} %; still level {:.4} {u}, white noise {:.4} {u} per sample)",
            self.moved_windows,
            self.windows,
            self.rule.window_s,
            100.0 * self.moved_share,
            self.still_level,
            self.white_noise_sigma
        );
        if let Some(e) = &self.first_episode {
            s.push_str(&format!(": first episode {}", episode(e)));
        }
        if let Some(e) = self.largest_episode.as_ref().filter(|l| Some(*l) != self.first_episode.as_ref()) {
            s.push_str(&format!(", largest {}", episode(e)));
        }
        Some(s)
    }
}

/// Streams a channel's samples (missing samples as NaN, on the sample grid) in blocks and
/// keeps per-window sums only: memory proportional to the number of windows.
#[derive(Debug, Clone)]
pub struct StillnessAccumulator {
    rule: StillnessRule,
    tau0_s: f64,
    window_samples: u64,
    index: u64,
    current: WindowStats,
    windows: Vec<WindowStats>,
}

impl StillnessAccumulator {
    /// An accumulator for samples `tau0_s` apart; `None` when `tau0_s` or the rule's window is
    /// not a positive finite number.
    pub fn new(rule: StillnessRule, tau0_s: f64) -> Option<StillnessAccumulator> {
        if !(tau0_s.is_finite() && tau0_s > 0.0 && rule.window_s.is_finite() && rule.window_s > 0.0) {
            return None;
        }
        let by_time = (rule.window_s / tau0_s).round();
        let window_samples = if by_time >= MIN_WINDOW_SAMPLES as f64 { by_time as u64 } else { MIN_WINDOW_SAMPLES };
        Some(StillnessAccumulator {
            rule,
            tau0_s,
            window_samples,
            index: 0,
            current: WindowStats::default(),
            windows: Vec::new(),
        })
    }

    /// Adds a block of samples (in the rule's unit; NaN for a missing sample).
    ///
    /// Whole windows of finite samples that start at a window's start are summed
    /// `LANES` windows at a time (`whole_windows`): each window's sums are formed in the
    /// same order as sample by sample, so the check is the same bit for bit, in a quarter of the
    /// time (the sums of one window are chains of dependent additions; those of different
    /// windows are not; issue 56).
    pub fn push(&mut self, samples: &[f64]) {
        let w = self.window_samples as usize;
        let mut rest = samples;
        while !rest.is_empty() {
            if self.current.samples == 0 && rest.len() >= LANES * w {
                let (group, tail) = rest.split_at(LANES * w);
                // every sample finite (a fold without a short cut, so that it vectorises)
                if group.iter().fold(true, |all, x| all & x.is_finite()) {
                    for stats in whole_windows(group, w, self.index) {
                        self.windows.push(stats.settle());
                    }
                    self.index += group.len() as u64;
                    self.current = WindowStats { start_index: self.index, ..WindowStats::default() };
                    rest = tail;
                    continue;
                }
            }
            let x = rest[0];
            rest = &rest[1..];
            self.current.push(x);
            self.index += 1;
            if self.current.samples == self.window_samples {
                self.close_window();
            }
        }
    }

    /// Passes over `missing` missing samples (a gap in the time stamps) as `missing` NaN
    /// samples would, in time proportional to the windows it ends, not to `missing`: windows
    /// left without a sample are not kept (they are never judged).
    pub fn skip(&mut self, missing: u64) {
        let mut left = missing;
        while left > 0 {
            let take = left.min(self.window_samples - self.current.samples);
            self.current.samples += take;
            self.current.prev = None;
            self.index += take;
            left -= take;
            if self.current.samples == self.window_samples {
                self.close_window();
            }
            if self.current.samples == 0 && left >= self.window_samples {
                let whole = left / self.window_samples * self.window_samples;
                self.index += whole;
                left -= whole;
                self.current.start_index = self.index;
            }
        }
    }

    /// Keeps the full current window (unless it holds no sample) and starts the next.
    fn close_window(&mut self) {
        let next = WindowStats { start_index: self.index, ..WindowStats::default() };
        let full = std::mem::replace(&mut self.current, next);
        if full.n > 0 {
            self.windows.push(full.settle());
        }
    }

    /// The verdict with the record's interval learnt after the windows were cut (a streamed
    /// record: its windows hold the samples of `window_s` at the interval estimated from its
    /// start; their times are reported at `tau0_s`). A `tau0_s` that is not a positive finite
    /// number keeps the estimate.
    pub fn finish_at_interval(mut self, tau0_s: f64) -> StillnessCheck {
        if tau0_s.is_finite() && tau0_s > 0.0 {
            self.tau0_s = tau0_s;
        }
        self.finish()
    }

    /// The verdict.
    pub fn finish(mut self) -> StillnessCheck {
        if 2 * self.current.samples >= self.window_samples {
            self.windows.push(self.current.settle());
        }
        // a window is judged when at least half its samples are present
        let judged: Vec<WindowStats> =
            self.windows.into_iter().filter(|w| 2 * w.n >= self.window_samples && w.diff_n > 0).collect();
        let rule = self.rule;
        let mut check = StillnessCheck {
            window_samples: self.window_samples,
            windows: judged.len(),
            ..StillnessCheck::not_evaluated(rule, "")
        };
        if judged.len() < MIN_WINDOWS {
            check.not_evaluated_reason = Some(format!(
                "the record holds {} window(s) of {} samples with enough samples; the check needs {MIN_WINDOWS}",
                judged.len(),
                self.window_samples
            ));
            return check;
        }
        check.not_evaluated_reason = None;
        let mut variances: Vec<f64> = judged.iter().map(|w| w.diff_sq / w.diff_n as f64 / 2.0).collect();
        let m = (self.window_samples - 1) as f64;
        let median_of_chi2_over_dof = (1.0 - 2.0 / (9.0 * m)).powi(3);
        let sigma = (median(&mut variances) / median_of_chi2_over_dof).sqrt();
        let mut spread_limit: (u64, f64) = (0, f64::INFINITY);
        let mut means: Vec<f64> = judged.iter().map(|w| w.mean).collect();
        let level = median(&mut means);
        check.white_noise_sigma = sigma;
        check.still_level = level;
        check.evaluated = true;
        let mut episodes: Vec<MotionEpisode> = Vec::new();
        let mut last_moved: Option<u64> = None;
        for w in &judged {
            let n = w.n as f64;
            let start_s = w.start_index as f64 * self.tau0_s;
            check.window_means.push((start_s, w.mean));
            let mean_departure = (w.mean - level).abs();
            let mean_moved = mean_departure > (rule.k_sigma * sigma / n.sqrt()).max(rule.floor);
            let variance = if w.n > 1 { w.m2 / (n - 1.0) } else { 0.0 };
            let excess = (variance - sigma * sigma).max(0.0).sqrt();
            if w.n > 1 && spread_limit.0 != w.n {
                let q = crate::allan::chi_squared_quantile(1.0 - SPREAD_TAIL, n - 1.0).unwrap_or(f64::INFINITY);
                spread_limit = (w.n, q / (n - 1.0));
            }
            let spread_moved = w.n > 1 && variance > sigma * sigma * spread_limit.1 && excess > rule.floor;
            if !(mean_moved || spread_moved) {
                continue;
            }
            check.moved_windows += 1;
            let departure = mean_departure.max(excess);
            let end_s = (w.start_index + w.samples) as f64 * self.tau0_s;
            let adjacent = last_moved.is_some_and(|i| i == w.start_index);
            match episodes.last_mut() {
                Some(e) if adjacent => {
                    e.end_s = end_s;
                    e.windows += 1;
                    e.peak_departure = e.peak_departure.max(departure);
                }
                _ => episodes.push(MotionEpisode { start_s, end_s, windows: 1, peak_departure: departure }),
            }
            last_moved = Some(w.start_index + w.samples);
        }
        check.moved = check.moved_windows > 0;
        check.moved_share = check.moved_windows as f64 / judged.len() as f64;
        check.first_episode = episodes.first().copied();
        check.largest_episode =
            episodes.iter().copied().reduce(|a, b| if b.peak_departure > a.peak_departure { b } else { a });
        check
    }
}

/// Windows per parallel piece of [`check_channel`].
const PIECE_WINDOWS: usize = 256;

/// Windows summed side by side by [`whole_windows`].
const LANES: usize = 4;

/// The sums of [`LANES`] consecutive whole windows of `w` finite samples each (`group` holds
/// them, the first starting at sample `start_index`), each exactly as [`WindowStats::push`]
/// forms them sample by sample (the same additions in the same order), the windows' chains of
/// additions interleaved (and, on a CPU with AVX2, in one vector: the same operations on four
/// values at once, never contracted into fused multiply-adds).
fn whole_windows(group: &[f64], w: usize, start_index: u64) -> [WindowStats; LANES] {
    #[cfg(target_arch = "x86_64")]
    {
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2 (checked just above); the function is safe code
            // compiled for it.
            return unsafe { whole_windows_avx2(group, w, start_index) };
        }
    }
    whole_windows_body(group, w, start_index)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn whole_windows_avx2(group: &[f64], w: usize, start_index: u64) -> [WindowStats; LANES] {
    whole_windows_body(group, w, start_index)
}

#[inline(always)]
fn whole_windows_body(group: &[f64], w: usize, start_index: u64) -> [WindowStats; LANES] {
    let (a, rest) = group.split_at(w);
    let (b, rest) = rest.split_at(w);
    let (c, d) = rest.split_at(w);
    let lanes = [a, b, c, &d[..w]];
    let shift: [f64; LANES] = std::array::from_fn(|l| lanes[l][0]);
    // the first sample: its deviation from the shift (zero), no difference yet
    let mut s1: [f64; LANES] = std::array::from_fn(|l| 0.0 + (lanes[l][0] - shift[l]));
    let mut s2: [f64; LANES] = std::array::from_fn(|l| {
        let d = lanes[l][0] - shift[l];
        0.0 + d * d
    });
    let mut dsq = [0.0f64; LANES];
    for (((pa, pb), pc), pd) in a.windows(2).zip(b.windows(2)).zip(c.windows(2)).zip(lanes[3].windows(2)) {
        let x = [pa[1], pb[1], pc[1], pd[1]];
        let prev = [pa[0], pb[0], pc[0], pd[0]];
        for l in 0..LANES {
            let dev = x[l] - shift[l];
            s1[l] += dev;
            s2[l] += dev * dev;
            let step = x[l] - prev[l];
            dsq[l] += step * step;
        }
    }
    std::array::from_fn(|l| WindowStats {
        start_index: start_index + (l * w) as u64,
        samples: w as u64,
        n: w as u64,
        mean: 0.0,
        m2: 0.0,
        shift: shift[l],
        s1: s1[l],
        s2: s2[l],
        diff_sq: dsq[l],
        diff_n: w as u64 - 1,
        prev: Some(lanes[l][w - 1]),
    })
}

/// The check of a whole channel in memory (samples on the grid, NaN for missing ones);
/// `None` for a quantity without a rule or a sampling interval that is not positive.
///
/// A long record's whole windows are summed in parallel pieces that start at window starts:
/// each window's sums are the same whichever piece holds it, so the check is the same bit for
/// bit as one pass would give.
pub fn check_channel(samples: &[f64], tau0_s: f64, quantity: Quantity) -> Option<StillnessCheck> {
    use rayon::prelude::*;
    let mut acc = StillnessAccumulator::new(StillnessRule::for_quantity(quantity)?, tau0_s)?;
    let piece = acc.window_samples as usize * PIECE_WINDOWS;
    if samples.len() >= crate::allan::PARALLEL_MIN_POINTS && samples.len() >= 2 * piece {
        let (head, tail) = samples.split_at(samples.len() / piece * piece);
        let pieces: Vec<Vec<WindowStats>> = head
            .par_chunks(piece)
            .enumerate()
            .map(|(k, chunk)| {
                let start = (k * piece) as u64;
                let mut part = StillnessAccumulator {
                    index: start,
                    current: WindowStats { start_index: start, ..WindowStats::default() },
                    windows: Vec::with_capacity(PIECE_WINDOWS),
                    ..acc.clone()
                };
                part.push(chunk);
                part.windows
            })
            .collect();
        acc.windows = pieces.concat();
        acc.index = head.len() as u64;
        acc.current = WindowStats { start_index: acc.index, ..WindowStats::default() };
        acc.push(tail);
    } else {
        acc.push(samples);
    }
    Some(acc.finish())
}

/// The gravity check of a three-axis accelerometer: windows whose mean specific-force vector
/// has a magnitude further than `tolerance_m_s2` from standard gravity.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GravityCheck {
    /// Tolerance about 9.80665 m/s^2, m/s^2.
    pub tolerance_m_s2: f64,
    /// Windows compared (windows judged on all three axes at the same time).
    pub windows: usize,
    /// Windows outside the tolerance.
    pub outside_windows: usize,
    /// Median magnitude of the window-mean vectors, m/s^2.
    pub median_magnitude_m_s2: f64,
    /// Largest departure of a window's magnitude from standard gravity, m/s^2.
    pub largest_departure_m_s2: f64,
    /// Start of the first window outside the tolerance, s from the record start.
    pub first_outside_s: Option<f64>,
}

/// Compares the magnitude of the window-mean vector of three accelerometer axes (their checks
/// from the same record and rule) with standard gravity; `None` when the axes share no window.
pub fn gravity_check(axes: [&StillnessCheck; 3], tolerance_m_s2: f64) -> Option<GravityCheck> {
    let mut magnitudes: Vec<(f64, f64)> = Vec::new();
    // The windows of the other axes by start time (a map: linear in the windows, not quadratic).
    let by_start = |c: &StillnessCheck| -> std::collections::HashMap<u64, f64> {
        c.window_means.iter().map(|&(s, m)| (s.to_bits(), m)).collect()
    };
    if axes.iter().any(|c| c.window_means.iter().any(|(s, _)| !s.is_finite())) {
        return None;
    }
    let (ys, zs) = (by_start(axes[1]), by_start(axes[2]));
    for &(t, x) in &axes[0].window_means {
        if let (Some(&y), Some(&z)) = (ys.get(&t.to_bits()), zs.get(&t.to_bits())) {
            magnitudes.push((t, (x * x + y * y + z * z).sqrt()));
        }
    }
    if magnitudes.is_empty() {
        return None;
    }
    let outside: Vec<&(f64, f64)> =
        magnitudes.iter().filter(|(_, m)| (m - STANDARD_GRAVITY_M_S2).abs() > tolerance_m_s2).collect();
    let largest = magnitudes.iter().map(|(_, m)| (m - STANDARD_GRAVITY_M_S2).abs()).fold(0.0, f64::max);
    let mut values: Vec<f64> = magnitudes.iter().map(|(_, m)| *m).collect();
    Some(GravityCheck {
        tolerance_m_s2,
        windows: magnitudes.len(),
        outside_windows: outside.len(),
        median_magnitude_m_s2: median(&mut values),
        largest_departure_m_s2: largest,
        first_outside_s: outside.first().map(|(t, _)| *t),
    })
}

/// Median of finite values (NaN when empty); reorders `values`. By selection (linear time):
/// the same middle values a full sort gives.
fn median(values: &mut [f64]) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    let n = values.len();
    let (below, &mut middle, _) = values.select_nth_unstable_by(n / 2, f64::total_cmp);
    if n % 2 == 1 {
        middle
    } else {
        let lower = below.iter().copied().max_by(f64::total_cmp).unwrap_or(middle);
        0.5 * (lower + middle)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::{SensorModel, StaticGenerator, StaticSpec, TemperatureProfile};

    #[test]
    fn window_sums_equal_a_two_pass_mean_and_variance() {
        // Shifted sums against the two-pass mean and sum of squared deviations, on a level far
        // from zero (9.81 m/s^2 plus noise, a gap) and on a drifting window.
        use rand::SeedableRng;
        use rand_distr::{Distribution, StandardNormal};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
        for (level, slope) in [(9.81, 0.0), (-1.0e4, 1e-3), (0.0, 5.0)] {
            let xs: Vec<f64> = (0..5000)
                .map(|i| {
                    let e: f64 = StandardNormal.sample(&mut rng);
                    if i % 997 == 3 {
                        f64::NAN
                    } else {
                        level + slope * i as f64 + 0.01 * e
                    }
                })
                .collect();
            let mut w = WindowStats::default();
            for &x in &xs {
                w.push(x);
            }
            let w = w.settle();
            let fin: Vec<f64> = xs.iter().copied().filter(|x| x.is_finite()).collect();
            let mean = fin.iter().sum::<f64>() / fin.len() as f64;
            let m2: f64 = fin.iter().map(|x| (x - mean) * (x - mean)).sum();
            assert_eq!(w.n as usize, fin.len());
            assert!((w.mean - mean).abs() <= 1e-12 * mean.abs().max(1.0), "{} vs {mean}", w.mean);
            assert!((w.m2 / m2 - 1.0).abs() < 1e-9, "{} vs {m2}", w.m2);
        }
    }

    /// A noisy consumer MEMS gyro at rest: white noise (3 deg/sqrt(h), 0.35 deg/s per sample at
    /// 200 Hz), bias instability, rate random walk, a warm-up transient, a turn-on bias, and a
    /// 30 degC/h temperature ramp through a 36 (deg/h)/degC coefficient (0.3 deg/s over 1000 s).
    fn still_gyro(seed: u64, duration_s: f64) -> Vec<f64> {
        let model = SensorModel {
            arw_deg_rt_h: 3.0,
            bias_instability_dph: 20.0,
            flicker_tau_min_s: 1.0,
            flicker_tau_max_s: 1000.0,
            rrw_deg_h_rt_h: 50.0,
            bias_dph: 1000.0,
            warmup_amplitude_dph: 720.0,
            warmup_time_constant_s: 60.0,
            bias_temp_coeff_dph_per_c: 36.0,
            ..SensorModel::default()
        };
        let spec = StaticSpec {
            sample_rate_hz: 200.0,
            duration_s,
            temperature: TemperatureProfile::Ramp { start_c: 20.0, rate_c_per_h: 30.0 },
            ..StaticSpec::default()
        };
        StaticGenerator::new(&model, &spec, seed).unwrap().map(|s| s.output).collect()
    }

    #[test]
    fn still_records_of_several_seeds_are_never_flagged() {
        for seed in 1..=6 {
            let x = still_gyro(seed, 1000.0);
            let c = check_channel(&x, 1.0 / 200.0, Quantity::AngularRate).unwrap();
            assert!(c.evaluated);
            assert!(!c.moved, "seed {seed}: {c:?}");
            assert_eq!(c.windows, 1000);
            // the first-difference sigma is the simulated white noise: N / 60 deg/s/sqrt(s) x sqrt(200 Hz)
            let truth = 3.0 / 60.0 * 200f64.sqrt();
            assert!(
                (c.white_noise_sigma / truth - 1.0).abs() < 0.03,
                "seed {seed}: {} vs {truth}",
                c.white_noise_sigma
            );
        }
    }

    #[test]
    fn short_windows_of_a_noisy_slow_record_are_not_flagged() {
        // 1 Hz, white noise 0.573 deg/s per sample (N = 34.4 deg/sqrt(h)), 10,000 s: windows of
        // 10 samples, where a normal approximation of the sample variance would flag about one
        // record in twenty; 20 seeds never flagged.
        let model = SensorModel { arw_deg_rt_h: 0.573 * 60.0, ..SensorModel::default() };
        let spec = StaticSpec { sample_rate_hz: 1.0, duration_s: 10_000.0, ..StaticSpec::default() };
        for seed in 1..=20 {
            let x: Vec<f64> = StaticGenerator::new(&model, &spec, seed).unwrap().map(|s| s.output).collect();
            let c = check_channel(&x, 1.0, Quantity::AngularRate).unwrap();
            assert_eq!(c.window_samples, 10);
            assert!(c.evaluated && !c.moved, "seed {seed}: {:?}", c.motion_summary());
            assert!((c.white_noise_sigma / 0.573 - 1.0).abs() < 0.06, "seed {seed}: {}", c.white_noise_sigma);
        }
    }

    /// Adds a rate episode from `start_s` lasting `length_s`: a step or a sinusoid.
    fn with_episode(x: &mut [f64], start_s: f64, length_s: f64, amplitude_dps: f64, sinusoid_hz: Option<f64>) {
        for (i, v) in x.iter_mut().enumerate() {
            let t = i as f64 / 200.0;
            if t >= start_s && t < start_s + length_s {
                *v += match sinusoid_hz {
                    Some(f) => amplitude_dps * (std::f64::consts::TAU * f * (t - start_s)).sin(),
                    None => amplitude_dps,
                };
            }
        }
    }

    #[test]
    fn rotation_episodes_are_always_flagged_and_located_within_a_window() {
        let cases = [
            (5.0, None, 137.3, 4.0),
            (30.0, None, 412.6, 3.0),
            (-8.0, None, 55.5, 6.0),
            (10.0, Some(0.2), 250.2, 5.0),
            // shaking at 3 Hz: the mean of a 1 s window hardly moves; its spread does
            (20.0, Some(3.0), 700.0, 4.0),
        ];
        for (seed, (amplitude, freq, start, length)) in (11..).zip(cases) {
            let mut x = still_gyro(seed, 1000.0);
            with_episode(&mut x, start, length, amplitude, freq);
            let c = check_channel(&x, 1.0 / 200.0, Quantity::AngularRate).unwrap();
            assert!(c.moved, "seed {seed} amplitude {amplitude}: {c:?}");
            let e = c.first_episode.unwrap();
            assert!((e.start_s - start).abs() <= 1.0, "seed {seed}: start {} vs {start}", e.start_s);
            assert!((e.end_s - (start + length)).abs() <= 1.0, "seed {seed}: end {} vs {}", e.end_s, start + length);
            assert_eq!(c.largest_episode, Some(e), "one episode only");
            assert!(e.peak_departure <= amplitude.abs() * 1.1 && e.peak_departure > 0.5 * amplitude.abs());
            assert!(c.moved_share < 0.01);
        }
    }

    #[test]
    fn largest_episode_and_share_are_reported() {
        let mut x = still_gyro(21, 200.0);
        with_episode(&mut x, 20.0, 2.0, 6.0, None);
        with_episode(&mut x, 100.0, 10.0, -50.0, None);
        let c = check_channel(&x, 1.0 / 200.0, Quantity::AngularRate).unwrap();
        let first = c.first_episode.unwrap();
        let largest = c.largest_episode.unwrap();
        assert_eq!((first.start_s, first.end_s, first.windows), (20.0, 22.0, 2));
        assert_eq!((largest.start_s, largest.end_s, largest.windows), (100.0, 110.0, 10));
        assert!((largest.peak_departure - 50.0).abs() < 1.0);
        assert_eq!(c.moved_windows, 12);
        let said = c.motion_summary().unwrap();
        assert!(said.starts_with("moved in 12 of 200 windows of 1 s (6.0 %"), "{said}");
        assert!(said.contains("first episode 20.0 to 22.0 s") && said.contains("largest 100.0 to 110.0 s"), "{said}");
        assert!((c.moved_share - 12.0 / 200.0).abs() < 1e-12);
    }

    #[test]
    fn missing_samples_are_skipped_and_short_records_not_evaluated() {
        let mut x = still_gyro(31, 60.0);
        for v in &mut x[1000..1150] {
            *v = f64::NAN;
        }
        let c = check_channel(&x, 1.0 / 200.0, Quantity::AngularRate).unwrap();
        assert!(c.evaluated && !c.moved, "{c:?}");
        let short = check_channel(&x[..400], 1.0 / 200.0, Quantity::AngularRate).unwrap();
        assert!(!short.evaluated && !short.moved);
        assert!(short.not_evaluated_reason.unwrap().contains("needs 3"));
        assert!(check_channel(&x, 1.0 / 200.0, Quantity::Unitless).is_none());
        assert!(check_channel(&x, 0.0, Quantity::AngularRate).is_none());
    }

    #[test]
    fn accelerometer_tilt_is_flagged_and_gravity_is_checked() {
        // three axes at rest, +z up, white noise 0.02 m/s^2, 100 Hz, 120 s (deterministic noise
        // from a linear congruential sequence: sums of 12 uniforms)
        let mut state = 7u64;
        let mut noise = move || {
            let mut s = 0.0;
            for _ in 0..12 {
                state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                s += (state >> 11) as f64 / (1u64 << 53) as f64;
            }
            0.02 * (s - 6.0)
        };
        let n = 12_000;
        let mut ax: Vec<f64> = (0..n).map(|_| noise()).collect();
        let ay: Vec<f64> = (0..n).map(|_| noise()).collect();
        let az: Vec<f64> = (0..n).map(|_| STANDARD_GRAVITY_M_S2 + noise()).collect();
        let check = |v: &[f64]| check_channel(v, 0.01, Quantity::Acceleration).unwrap();
        let (cx, cy, cz) = (check(&ax), check(&ay), check(&az));
        assert!(!cx.moved && !cy.moved && !cz.moved);
        let g = gravity_check([&cx, &cy, &cz], GRAVITY_TOLERANCE_M_S2).unwrap();
        assert_eq!((g.windows, g.outside_windows), (120, 0));
        assert!((g.median_magnitude_m_s2 - STANDARD_GRAVITY_M_S2).abs() < 0.01);
        // a 10 degree tilt about y for 5 s from 50 s: x reads g sin(10 deg) = 1.70 m/s^2
        for v in &mut ax[5000..5500] {
            *v += STANDARD_GRAVITY_M_S2 * 10f64.to_radians().sin();
        }
        let cx = check(&ax);
        let e = cx.first_episode.unwrap();
        assert_eq!((e.start_s, e.end_s), (50.0, 55.0));
        // data in g read as m/s^2: a magnitude of 1 instead of 9.8 fails the gravity check
        let scaled = |v: &[f64]| v.iter().map(|a| a / STANDARD_GRAVITY_M_S2).collect::<Vec<f64>>();
        let (gx, gy, gz) = (check(&scaled(&ay)), check(&scaled(&ay)), check(&scaled(&az)));
        let g = gravity_check([&gx, &gy, &gz], GRAVITY_TOLERANCE_M_S2).unwrap();
        assert_eq!(g.outside_windows, 120);
        assert_eq!(g.first_outside_s, Some(0.0));
    }

    /// The check with every sample pushed one at a time (the plain path, no whole windows).
    fn check_sample_by_sample(samples: &[f64], tau0_s: f64, quantity: Quantity) -> StillnessCheck {
        let mut acc = StillnessAccumulator::new(StillnessRule::for_quantity(quantity).unwrap(), tau0_s).unwrap();
        for x in samples {
            acc.push(std::slice::from_ref(x));
        }
        acc.finish()
    }

    #[test]
    fn whole_windows_side_by_side_equal_the_sample_by_sample_check_bit_for_bit() {
        for seed in 0..6u64 {
            let mut x = still_gyro(seed, 37.3);
            if seed % 2 == 1 {
                with_episode(&mut x, 12.0, 3.0, 20.0, Some(0.7));
            }
            if seed >= 3 {
                // missing samples inside some windows, and a block pushed in uneven pieces
                for i in (50..x.len()).step_by(997) {
                    x[i] = f64::NAN;
                }
            }
            let want = check_sample_by_sample(&x, 0.005, Quantity::AngularRate);
            let mut acc =
                StillnessAccumulator::new(StillnessRule::for_quantity(Quantity::AngularRate).unwrap(), 0.005).unwrap();
            for piece in x.chunks(1234 + seed as usize * 77) {
                acc.push(piece);
            }
            let got = acc.finish();
            assert_eq!(format!("{got:?}"), format!("{want:?}"), "seed {seed}");
            assert_eq!(
                check_channel(&x, 0.005, Quantity::AngularRate).map(|c| format!("{c:?}")),
                Some(format!("{want:?}"))
            );
            assert!(want.evaluated && want.moved == (seed % 2 == 1), "seed {seed}");
        }
    }

    #[test]
    fn a_long_record_checked_in_parallel_pieces_equals_one_pass() {
        // 412,345 samples read at 400 Hz: pieces of 4,096 windows of 400 samples, and a tail.
        let mut x = still_gyro(11, 2100.0);
        x.truncate(400_000 + 12_345);
        for i in (777..x.len()).step_by(50_001) {
            x[i] = f64::NAN;
        }
        for v in &mut x[300_000..301_000] {
            *v += 30.0;
        }
        let rule = StillnessRule { window_s: 1.0, ..StillnessRule::for_quantity(Quantity::AngularRate).unwrap() };
        let mut one = StillnessAccumulator::new(rule, 1.0 / 400.0).unwrap();
        one.push(&x);
        let want = one.finish();
        assert!(x.len() >= crate::allan::PARALLEL_MIN_POINTS && x.len() >= 2 * 400 * PIECE_WINDOWS);
        let got = check_channel(&x, 1.0 / 400.0, Quantity::AngularRate).unwrap();
        assert_eq!(format!("{got:?}"), format!("{want:?}"));
        assert!(want.moved && want.windows > 1000);
    }

    #[test]
    fn the_median_by_selection_is_the_sorted_one() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(4);
        for n in 1..60 {
            let v: Vec<f64> = (0..n).map(|_| (rng.gen::<f64>() * 10.0).round() - 5.0).collect();
            let mut sorted = v.clone();
            sorted.sort_by(f64::total_cmp);
            let want = if n % 2 == 1 { sorted[n / 2] } else { 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]) };
            assert_eq!(median(&mut v.clone()).to_bits(), want.to_bits(), "n {n}");
        }
        assert!(median(&mut []).is_nan());
    }

    #[test]
    fn skipping_missing_samples_equals_pushing_nans() {
        // a still gyro with a rotation episode, gaps of 0 to 5000 samples at several offsets
        // (inside a window, across windows, over many whole windows); the check (windows,
        // episodes and their times, sigma, level) is the same as with the NaNs pushed
        let mut x = still_gyro(3, 300.0);
        for v in &mut x[40_000..41_000] {
            *v += 20.0;
        }
        let rule = StillnessRule::for_quantity(Quantity::AngularRate).unwrap();
        for (at, gap) in [(0usize, 0u64), (150, 1), (10_000, 37), (20_000, 200), (33_333, 1_999), (45_000, 5_000)] {
            let mut pushed = StillnessAccumulator::new(rule, 1.0 / 200.0).unwrap();
            let mut skipped = pushed.clone();
            pushed.push(&x[..at]);
            skipped.push(&x[..at]);
            pushed.push(&vec![f64::NAN; gap as usize]);
            skipped.skip(gap);
            pushed.push(&x[at..]);
            skipped.push(&x[at..]);
            let (a, b) = (pushed.finish(), skipped.finish());
            assert_eq!(a, b, "gap of {gap} at {at}");
            assert!(a.moved, "gap of {gap} at {at}");
        }
    }
}
