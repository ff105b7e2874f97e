//! The streaming first pass: moments, window means, temperature windows, quality findings, and
//! the figures computed from them.

use super::config::*;
use super::extremes::{ChunkExtremes, ChunkSlope};
use super::rail::RailTracker;
use super::result::*;
use crate::fit;
use crate::sampling::SampleRateSource;
use crate::units;

/// Moments of (t, d) pairs: count, means, centred cross sums (merged pairwise).
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Moments {
    pub(super) n: f64,
    pub(super) mean_t: f64,
    pub(super) mean_d: f64,
    pub(super) ctt: f64,
    pub(super) cdd: f64,
    pub(super) ctd: f64,
}

impl Moments {
    pub(super) fn of(t: &[f64], d: &[f64]) -> Moments {
        let n = d.len() as f64;
        if d.is_empty() {
            return Moments::default();
        }
        let mean_t = t.iter().sum::<f64>() / n;
        let mean_d = d.iter().sum::<f64>() / n;
        let (mut ctt, mut cdd, mut ctd) = (0.0, 0.0, 0.0);
        for (&ti, &di) in t.iter().zip(d) {
            let (a, b) = (ti - mean_t, di - mean_d);
            ctt += a * a;
            cdd += b * b;
            ctd += a * b;
        }
        Moments { n, mean_t, mean_d, ctt, cdd, ctd }
    }

    pub(super) fn of_shifted(t: &[f64], t0: f64, x: &[f64], x0: f64) -> Moments {
        let n = x.len() as f64;
        if x.is_empty() {
            return Moments::default();
        }
        let mean_t = lane_sum(t, t0) / n;
        let mean_d = lane_sum(x, x0) / n;
        let (mut ctt, mut cdd, mut ctd) = ([0.0; 4], [0.0; 4], [0.0; 4]);
        let (tc, xc) = (t.chunks_exact(4), x.chunks_exact(4));
        let (tr, xr) = (tc.remainder(), xc.remainder());
        for (tq, xq) in tc.zip(xc) {
            for l in 0..4 {
                let (a, b) = (tq[l] - t0 - mean_t, xq[l] - x0 - mean_d);
                ctt[l] += a * a;
                cdd[l] += b * b;
                ctd[l] += a * b;
            }
        }
        for (&ti, &xi) in tr.iter().zip(xr) {
            let (a, b) = (ti - t0 - mean_t, xi - x0 - mean_d);
            ctt[0] += a * a;
            cdd[0] += b * b;
            ctd[0] += a * b;
        }
        let s = |v: [f64; 4]| (v[0] + v[1]) + (v[2] + v[3]);
        Moments { n, mean_t, mean_d, ctt: s(ctt), cdd: s(cdd), ctd: s(ctd) }
    }

    pub(super) fn of_indexed(i0: u64, fs: f64, t0: f64, x: &[f64], x0: f64) -> Moments {
        // Times i / fs; their centred sums are exact closed forms of the index.
        let n = x.len() as f64;
        if x.is_empty() {
            return Moments::default();
        }
        let mean_i = (n - 1.0) / 2.0;
        let mean_t = (i0 as f64 + mean_i) / fs - t0;
        let mean_d = lane_sum(x, x0) / n;
        let (mut cdd, mut cid) = ([0.0; 4], [0.0; 4]);
        let xc = x.chunks_exact(4);
        let rest = xc.remainder();
        for (q, xq) in xc.enumerate() {
            for l in 0..4 {
                let a = (q * 4 + l) as f64 - mean_i;
                let b = xq[l] - x0 - mean_d;
                cdd[l] += b * b;
                cid[l] += a * b;
            }
        }
        let base = x.len() - rest.len();
        for (j, &xi) in rest.iter().enumerate() {
            let (a, b) = ((base + j) as f64 - mean_i, xi - x0 - mean_d);
            cdd[0] += b * b;
            cid[0] += a * b;
        }
        let s = |v: [f64; 4]| (v[0] + v[1]) + (v[2] + v[3]);
        let cii = n * (n * n - 1.0) / 12.0;
        Moments { n, mean_t, mean_d, ctt: cii / (fs * fs), cdd: s(cdd), ctd: s(cid) / fs }
    }

    pub(super) fn merge(&mut self, o: &Moments) {
        if o.n == 0.0 {
            return;
        }
        if self.n == 0.0 {
            *self = *o;
            return;
        }
        let n = self.n + o.n;
        let (dt, dd) = (o.mean_t - self.mean_t, o.mean_d - self.mean_d);
        let f = self.n * o.n / n;
        self.ctt += o.ctt + dt * dt * f;
        self.cdd += o.cdd + dd * dd * f;
        self.ctd += o.ctd + dt * dd * f;
        self.mean_t += dt * o.n / n;
        self.mean_d += dd * o.n / n;
        self.n = n;
    }
}

/// Sum of (v - shift) over a slice, in four lanes (vectorisable).
pub(super) fn lane_sum(v: &[f64], shift: f64) -> f64 {
    let mut acc = [0.0; 4];
    let c = v.chunks_exact(4);
    let rest = c.remainder();
    for q in c {
        for l in 0..4 {
            acc[l] += q[l] - shift;
        }
    }
    let tail: f64 = rest.iter().map(|x| x - shift).sum();
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

/// Welford accumulation of window means.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Welford {
    pub(super) n: u64,
    pub(super) mean: f64,
    pub(super) m2: f64,
}

impl Welford {
    pub(super) fn add(&mut self, x: f64) {
        self.n += 1;
        let delta = x - self.mean;
        self.mean += delta / self.n as f64;
        self.m2 += delta * (x - self.mean);
    }

    pub(super) fn std(&self) -> Option<f64> {
        (self.n >= 2).then(|| (self.m2 / (self.n - 1) as f64).sqrt())
    }
}

/// Non-overlapping windows of m samples; a window's mean is over its valid samples.
#[derive(Debug, Clone)]
pub(super) struct Windows {
    pub(super) smoothing_s: f64,
    pub(super) m: u64,
    pub(super) filled: u64,
    pub(super) valid: u64,
    pub(super) sum: f64,
    pub(super) means: Welford,
    pub(super) with_missing: u64,
    pub(super) empty: u64,
}

impl Windows {
    /// Adds a slice of valid samples (deviations x - shift).
    pub(super) fn add_slice(&mut self, x: &[f64], shift: f64) {
        let mut i = 0;
        while i < x.len() {
            let take = ((self.m - self.filled) as usize).min(x.len() - i);
            self.sum += lane_sum(&x[i..i + take], shift);
            self.filled += take as u64;
            self.valid += take as u64;
            i += take;
            if self.filled == self.m {
                self.close();
            }
        }
    }

    pub(super) fn close(&mut self) {
        if self.valid == 0 {
            self.empty += 1;
        } else {
            if self.valid < self.m {
                self.with_missing += 1;
            }
            self.means.add(self.sum / self.valid as f64);
        }
        self.filled = 0;
        self.valid = 0;
        self.sum = 0.0;
    }

    #[inline]
    pub(super) fn add(&mut self, d: Option<f64>) {
        self.filled += 1;
        if let Some(d) = d {
            self.sum += d;
            self.valid += 1;
        }
        if self.filled == self.m {
            self.close();
        }
    }
}

/// Window means of temperature and output for the temperature fit.
#[derive(Debug, Clone, Default)]
pub(super) struct TempWindows {
    pub(super) m: u64,
    pub(super) filled: u64,
    pub(super) valid: u64,
    pub(super) sum_d: f64,
    pub(super) sum_c: f64,
    pub(super) points: Vec<(f64, f64)>,
}

/// An exclusion rule applied in a second pass (outliers).
#[derive(Debug, Clone, Copy)]
pub(super) struct OutlierRule {
    pub(super) line: DriftLine,
    pub(super) limit: f64,
}

/// Owned copies of the first samples, kept until the sample rate is known.
#[derive(Debug, Clone, Default)]
pub(super) struct Probe {
    pub(super) output: Vec<f64>,
    pub(super) time: Vec<f64>,
    pub(super) temp: Vec<f64>,
    pub(super) lines: Vec<u64>,
}

/// Streaming accumulator of the static-test figures of one channel (bounded memory).
#[derive(Debug, Clone)]
pub struct StaticTestAccumulator {
    pub(super) config: StaticTestConfig,
    pub(super) fs: Option<f64>,
    pub(super) fs_given: bool,
    pub(super) probe: Option<Probe>,
    pub(super) has_time: Option<bool>,
    pub(super) has_temp: Option<bool>,
    pub(super) has_lines: Option<bool>,
    pub(super) samples: u64,
    pub(super) reference: Option<(f64, f64)>,
    pub(super) prev_time: Option<f64>,
    pub(super) last_time: f64,
    pub(super) min: f64,
    pub(super) max: f64,
    pub(super) moments: Moments,
    pub(super) windows: Vec<Windows>,
    pub(super) skipped: Vec<SkippedSmoothing>,
    pub(super) temp: TempWindows,
    pub(super) rail: RailTracker,
    pub(super) quality: DataQuality,
    pub(super) rule: Option<OutlierRule>,
    pub(super) outliers: QualityIssue,
    pub(super) scratch_t: Vec<f64>,
    pub(super) scratch_d: Vec<f64>,
    pub(super) extremes: Vec<ChunkExtremes>,
    pub(super) chunk_slope: ChunkSlope,
    /// A stamp went back to or before the record's first (a clock reset, a trailer of zeros):
    /// (sample index, line, from s, to s); the record ends before it and later samples are
    /// counted in `left_out`, not analysed (the Allan analysis's rule, `crate::sampling`).
    pub(super) reset: Option<(u64, Option<u64>, f64, f64)>,
    /// Samples after a reset, left out.
    pub(super) left_out: u64,
}

impl StaticTestAccumulator {
    /// A new accumulator; fails when an option is out of range.
    pub fn new(config: StaticTestConfig) -> Result<Self, StaticTestError> {
        config.validate()?;
        let mut acc = StaticTestAccumulator {
            fs: None,
            fs_given: config.sample_rate_hz.is_some(),
            probe: None,
            has_time: None,
            has_temp: None,
            has_lines: None,
            samples: 0,
            reference: None,
            prev_time: None,
            last_time: 0.0,
            min: f64::INFINITY,
            max: f64::NEG_INFINITY,
            moments: Moments::default(),
            windows: Vec::new(),
            skipped: Vec::new(),
            temp: TempWindows::default(),
            rail: RailTracker::default(),
            quality: DataQuality::default(),
            rule: None,
            outliers: QualityIssue::default(),
            scratch_t: Vec::new(),
            scratch_d: Vec::new(),
            extremes: Vec::new(),
            chunk_slope: ChunkSlope::default(),
            reset: None,
            left_out: 0,
            config,
        };
        match acc.config.sample_rate_hz {
            Some(fs) => acc.set_rate(fs),
            None => acc.probe = Some(Probe::default()),
        }
        Ok(acc)
    }

    pub(super) fn set_rate(&mut self, fs: f64) {
        self.fs = Some(fs);
        self.quality.nominal_interval_s = 1.0 / fs;
        let mut times: Vec<f64> = Vec::new();
        if self.config.include_one_sample {
            times.push(1.0 / fs);
        }
        times.extend(self.config.smoothing_times_s.iter().copied());
        for t in times {
            let m = (t * fs).round();
            if m < 1.0 {
                self.skipped.push(SkippedSmoothing {
                    smoothing_s: t,
                    windows: 0,
                    reason: format!("shorter than one sample interval ({} s)", 1.0 / fs),
                });
                continue;
            }
            self.windows.push(Windows {
                smoothing_s: t,
                m: m as u64,
                filled: 0,
                valid: 0,
                sum: 0.0,
                means: Welford::default(),
                with_missing: 0,
                empty: 0,
            });
        }
        self.temp.m = ((self.config.temperature_window_s * fs).round() as u64).max(1);
    }

    pub(super) fn check_block(&mut self, b: &SampleBlock) -> Result<(), StaticTestError> {
        let n = b.output.len();
        let check = |what, s: Option<usize>| match s {
            Some(found) if found != n => Err(StaticTestError::LengthMismatch { what, expected: n, found }),
            _ => Ok(()),
        };
        check("time_s", b.time_s.map(<[f64]>::len))?;
        check("temperature_c", b.temperature_c.map(<[f64]>::len))?;
        check("lines", b.lines.map(<[u64]>::len))?;
        for (slot, present, what) in [
            (&mut self.has_time, b.time_s.is_some(), "time"),
            (&mut self.has_temp, b.temperature_c.is_some(), "temperature"),
            (&mut self.has_lines, b.lines.is_some(), "line-number"),
        ] {
            match *slot {
                None => *slot = Some(present),
                Some(p) if p != present => return Err(StaticTestError::InconsistentBlocks(what)),
                _ => {}
            }
        }
        if self.fs.is_none() && !b.output.is_empty() && b.time_s.is_none() {
            return Err(StaticTestError::NoSampleRate);
        }
        Ok(())
    }

    /// Adds a block of consecutive samples. A time stamp going back to or before the record's
    /// first (a clock reset, a trailer of zeros) ends the record: the samples before it are
    /// analysed, the rest counted and left out, and the figures' notes say so.
    pub fn push(&mut self, block: &SampleBlock) -> Result<(), StaticTestError> {
        self.check_block(block)?;
        if self.reset.is_some() {
            self.left_out += block.output.len() as u64;
            return Ok(());
        }
        if let Some(ts) = block.time_s {
            let first = match (&self.probe, self.reference) {
                (Some(p), _) if !p.time.is_empty() => Some(p.time[0]),
                (None, Some((_, t0))) => Some(t0),
                _ => ts.first().copied(),
            };
            let seen = self.samples + self.probe.as_ref().map_or(0, |p| p.output.len() as u64);
            let before = |i: usize| {
                if i == 0 {
                    self.probe.as_ref().and_then(|p| p.time.last().copied()).or(self.prev_time)
                } else {
                    Some(ts[i - 1])
                }
            };
            // As `crate::sampling` decides a reset: from the third stamp on, one that goes back
            // (below the stamp before it) to or before the first.
            let cut = first.and_then(|t0| {
                ts.iter()
                    .enumerate()
                    .position(|(i, &t)| seen + i as u64 >= 2 && t <= t0 && before(i).is_some_and(|p| t < p))
            });
            if let Some(i) = cut {
                let from = before(i).unwrap_or(f64::NAN);
                self.reset = Some((seen + i as u64, block.lines.map(|l| l[i]), from, ts[i]));
                self.left_out = (block.output.len() - i) as u64;
                let head = SampleBlock {
                    output: &block.output[..i],
                    time_s: Some(&ts[..i]),
                    temperature_c: block.temperature_c.map(|c| &c[..i]),
                    lines: block.lines.map(|l| &l[..i]),
                };
                return if i > 0 { self.push_checked(&head) } else { Ok(()) };
            }
        }
        self.push_checked(block)
    }

    /// [`Self::push`] of a block with no reset in it.
    fn push_checked(&mut self, block: &SampleBlock) -> Result<(), StaticTestError> {
        self.check_block(block)?;
        if let Some(probe) = self.probe.as_mut() {
            probe.output.extend_from_slice(block.output);
            if let Some(t) = block.time_s {
                probe.time.extend_from_slice(t);
            }
            if let Some(c) = block.temperature_c {
                probe.temp.extend_from_slice(c);
            }
            if let Some(l) = block.lines {
                probe.lines.extend_from_slice(l);
            }
            if probe.output.len() >= RATE_PROBE_SAMPLES {
                self.end_probe()?;
            }
            return Ok(());
        }
        self.process(block);
        Ok(())
    }

    pub(super) fn end_probe(&mut self) -> Result<(), StaticTestError> {
        let Some(p) = self.probe.take() else { return Ok(()) };
        if p.output.is_empty() {
            return Ok(());
        }
        let estimate = crate::sampling::estimate_interval(&p.time).map_err(|_| {
            StaticTestError::SampleRateUnknown(format!(
                "no increasing time stamps among the first {} samples; give sample_rate_hz",
                p.output.len()
            ))
        })?;
        if let Some(r) = estimate.reset {
            // The clean part ends there; reading past it would take the trailer as data.
            return Err(StaticTestError::SampleRateUnknown(format!(
                "the time stamps go back at sample {} (from {} s to {} s: a clock reset or a trailer of zeros); cut the record before it",
                r.index + 1,
                r.from_s,
                r.to_s
            )));
        }
        self.set_rate(estimate.rate_hz());
        let block = SampleBlock {
            output: &p.output,
            time_s: Some(&p.time),
            temperature_c: (!p.temp.is_empty()).then_some(&p.temp[..]),
            lines: (!p.lines.is_empty()).then_some(&p.lines[..]),
        };
        self.process(&block);
        Ok(())
    }

    pub(super) fn process(&mut self, b: &SampleBlock) {
        let clean = self.block_is_clean(b);
        self.track_extremes(b, clean);
        if clean {
            self.process_clean(b);
        } else {
            self.process_each(b);
        }
    }

    /// Whether every sample is finite and inside the outlier rule (then the slice loops apply).
    pub(super) fn block_is_clean(&self, b: &SampleBlock) -> bool {
        if b.output.is_empty() {
            return false;
        }
        let finite = |v: &[f64]| v.iter().fold(true, |a, x| a & x.is_finite());
        if !finite(b.output) || !b.time_s.is_none_or(finite) {
            return false;
        }
        match (self.rule, b.time_s) {
            (None, _) => true,
            (Some(r), Some(ts)) => {
                b.output.iter().zip(ts).fold(true, |a, (&x, &t)| a & ((x - r.line.eval(t)).abs() <= r.limit))
            }
            (Some(r), None) => {
                let fs = self.fs.unwrap_or(1.0); // ok: set before processing
                let i0 = self.samples;
                b.output
                    .iter()
                    .enumerate()
                    .fold(true, |a, (i, &x)| a & ((x - r.line.eval((i0 + i as u64) as f64 / fs)).abs() <= r.limit))
            }
        }
    }

    /// The fast path: a block of finite samples, processed slice by slice.
    pub(super) fn process_clean(&mut self, b: &SampleBlock) {
        let fs = self.fs.unwrap_or(1.0); // ok: process runs only once the rate is set
        let x = b.output;
        let n = x.len();
        let i0 = self.samples;
        let pos = |i: usize| Position { sample: i0 + i as u64, line: b.lines.map(|l| l[i]) };
        let t_first = b.time_s.map_or(i0 as f64 / fs, |t| t[0]);
        let (x0, t0) = *self.reference.get_or_insert((x[0], t_first));
        // Time checks.
        if let Some(ts) = b.time_s {
            let gap_limit = self.config.gap_factor / fs;
            let mut prev = self.prev_time.unwrap_or(ts[0]);
            let mut largest = self.quality.largest_interval_s.unwrap_or(f64::NEG_INFINITY);
            let start = usize::from(self.prev_time.is_none());
            // The smallest and largest interval first (no branch per sample): only when one is out
            // of bounds are the intervals looked at one by one.
            let first = if start == 0 { (ts[0] - prev, ts[0] - prev) } else { (f64::INFINITY, f64::NEG_INFINITY) };
            let (smallest, widest) = ts.windows(2).fold(first, |(lo, hi), w| {
                let dt = w[1] - w[0];
                (lo.min(dt), hi.max(dt))
            });
            let all_regular = smallest > 0.0 && widest <= gap_limit;
            if all_regular {
                largest = largest.max(widest);
                prev = ts[n - 1];
            }
            for (i, &t) in ts.iter().enumerate().skip(if all_regular { n } else { start }) {
                let dt = t - prev;
                if dt <= 0.0 || dt > gap_limit {
                    if dt == 0.0 {
                        self.quality.repeated_time.note(pos(i));
                    } else if dt < 0.0 {
                        self.quality.decreasing_time.note(pos(i));
                    } else {
                        self.quality.time_gaps.note(pos(i));
                    }
                }
                largest = largest.max(dt);
                prev = t;
            }
            if n > start {
                self.quality.largest_interval_s = Some(largest);
            }
            self.prev_time = Some(prev);
            self.last_time = prev;
        } else {
            self.last_time = (i0 + n as u64 - 1) as f64 / fs;
        }
        // Min, max and rail runs.
        let (lo, hi) = x.iter().fold((self.min, self.max), |(lo, hi), &v| (lo.min(v), hi.max(v)));
        // Runs of equal samples, in pieces of RAIL_PIECE samples. Without two equal neighbours in a
        // piece every run inside it has one sample, shorter than any rail run
        // (rail_run_samples >= 2): only its first two samples can end a longer run (the one
        // carried in), and its last one starts the run carried out.
        const RAIL_PIECE: usize = 64;
        let mut start = 0;
        while start < n {
            let piece = &x[start..(start + RAIL_PIECE).min(n)];
            let repeats = piece.windows(2).fold(false, |a, w| a | (w[0] == w[1]));
            let stepped = if repeats { piece.len() } else { piece.len().min(2) };
            for (k, &v) in piece.iter().enumerate().take(stepped) {
                self.rail_step(v, pos(start + k));
            }
            if stepped < piece.len() {
                let (lo, hi) =
                    piece[stepped..].iter().fold((self.min, self.max), |(lo, hi), &v| (lo.min(v), hi.max(v)));
                self.min = lo;
                self.max = hi;
                let last = start + piece.len() - 1;
                self.rail.run_value = x[last];
                self.rail.run_len = 1;
                self.rail.run_start = Some(pos(last));
            }
            start += piece.len();
        }
        self.min = lo;
        self.max = hi;
        // Moments of (t - t0, x - x0).
        let m = match b.time_s {
            Some(ts) => Moments::of_shifted(ts, t0, x, x0),
            None => Moments::of_indexed(i0, fs, t0, x, x0),
        };
        self.moments.merge(&m);
        self.samples += n as u64;
        // Windows.
        for w in &mut self.windows {
            if w.m > 1 {
                w.add_slice(x, x0);
            }
        }
        if let Some(c) = b.temperature_c {
            for (i, &v) in x.iter().enumerate() {
                self.add_temp(Some(v - x0), Some(c[i]));
            }
        }
    }

    /// The general path: sample by sample, with missing samples and the outlier rule.
    pub(super) fn process_each(&mut self, b: &SampleBlock) {
        let fs = self.fs.unwrap_or(1.0); // ok: process runs only once the rate is set
        let gap_limit = self.config.gap_factor / fs;
        self.scratch_t.clear();
        self.scratch_d.clear();
        for i in 0..b.output.len() {
            let idx = self.samples;
            self.samples += 1;
            let pos = Position { sample: idx, line: b.lines.map(|l| l[i]) };
            let x = b.output[i];
            let t = match b.time_s {
                Some(ts) => ts[i],
                None => idx as f64 / fs,
            };
            // Time stamps are checked whenever they are finite, even if the output is missing.
            if b.time_s.is_some() && t.is_finite() {
                if let Some(prev) = self.prev_time {
                    let dt = t - prev;
                    if dt == 0.0 {
                        self.quality.repeated_time.note(pos);
                    } else if dt < 0.0 {
                        self.quality.decreasing_time.note(pos);
                    } else if dt > gap_limit {
                        self.quality.time_gaps.note(pos);
                    }
                    if self.quality.largest_interval_s.is_none_or(|m| dt > m) {
                        self.quality.largest_interval_s = Some(dt);
                    }
                }
                self.prev_time = Some(t);
            }
            let mut ok = x.is_finite() && t.is_finite();
            if !ok {
                self.quality.missing.note(pos);
            } else if let Some(rule) = self.rule {
                if (x - rule.line.eval(t)).abs() > rule.limit {
                    self.outliers.note(pos);
                    ok = false;
                }
            }
            let temp_c = b.temperature_c.map(|c| c[i]);
            if !ok {
                self.end_run();
                for w in &mut self.windows {
                    w.add(None);
                }
                self.add_temp(None, None);
                continue;
            }
            let (x0, t0) = *self.reference.get_or_insert((x, t));
            let d = x - x0;
            self.last_time = t;
            self.scratch_t.push(t - t0);
            self.scratch_d.push(d);
            self.min = self.min.min(x);
            self.max = self.max.max(x);
            if self.rail.run_len > 0 && x == self.rail.run_value {
                self.rail.run_len += 1;
            } else {
                self.end_run();
                self.rail.run_value = x;
                self.rail.run_len = 1;
                self.rail.run_start = Some(pos);
            }
            for w in &mut self.windows {
                if w.m > 1 {
                    w.add(Some(d));
                }
            }
            self.add_temp(Some(d), temp_c);
        }
        let m = Moments::of(&self.scratch_t, &self.scratch_d);
        self.moments.merge(&m);
    }

    #[inline]
    pub(super) fn add_temp(&mut self, d: Option<f64>, c: Option<f64>) {
        let Some(c) = c else { return };
        let tw = &mut self.temp;
        tw.filled += 1;
        if let Some(d) = d {
            if c.is_finite() {
                tw.sum_d += d;
                tw.sum_c += c;
                tw.valid += 1;
            }
        }
        if tw.filled == tw.m {
            if tw.valid > 0 {
                let v = tw.valid as f64;
                tw.points.push((tw.sum_c / v, tw.sum_d / v));
            }
            tw.filled = 0;
            tw.valid = 0;
            tw.sum_c = 0.0;
            tw.sum_d = 0.0;
        }
    }
    /// Finishes the record and computes the figures (no outlier pass; see
    /// [`OutlierScan`](super::OutlierScan)).
    pub fn finish(mut self) -> Result<FirstPass, StaticTestError> {
        if self.probe.is_some() {
            if self.has_time == Some(false) {
                return Err(StaticTestError::NoSampleRate);
            }
            self.end_probe()?;
        }
        self.end_run();
        let valid = self.moments.n as u64;
        if valid < 2 {
            return Err(StaticTestError::TooFewSamples { found: valid, needed: 2 });
        }
        let fs = self.fs.unwrap_or(1.0); // ok: set once samples exist
        let cfg = &self.config;
        let mut notes = Vec::new();
        if let Some((sample, line, from, to)) = self.reset {
            let at = line.map_or(format!("sample {}", sample + 1), |l| format!("line {l}"));
            notes.push(format!(
                "the time stamps go back at {at} (from {from} s to {to} s: a clock reset or a trailer of zeros): the record ends before it, {} sample(s) from there left out",
                self.left_out
            ));
        }
        let (x0, t0) = self.reference.unwrap_or((0.0, 0.0)); // ok: valid >= 2
        let mo = self.moments;
        let mean_output = x0 + mo.mean_d;
        let std_output = (mo.cdd / (mo.n - 1.0)).sqrt();
        let k = cfg.effective_scale_factor();
        let null = cfg.effective_null_output();
        let earth = cfg.latitude_deg.map(units::earth_rate_vertical_dph);
        let subtract = earth.filter(|_| !cfg.null_contains_earth_rate);
        if earth.is_some() && cfg.null_contains_earth_rate {
            notes.push(
                "earth rate not subtracted: the null was measured at rest on the same mounting and already contains it"
                    .into(),
            );
        }
        let (bias_dps, bias_dph, earth_done) = match (k, null) {
            (Some(k), Some(f0)) => {
                let raw_dph = units::dps_to_dph((mean_output - f0) / k);
                let dph = raw_dph - subtract.unwrap_or(0.0);
                (Some(units::dph_to_dps(dph)), Some(dph), subtract.is_some())
            }
            _ => {
                notes.push(match k {
                    None => "bias in deg/s not computed: no scale factor given".to_string(),
                    Some(_) => "bias in deg/s not computed: no zero-rate reference (null_output) given".to_string(),
                });
                (None, None, false)
            }
        };
        if subtract.is_some() && !earth_done {
            notes.push("earth rate not subtracted: the bias could not be computed".into());
        }
        let to_dph = |v_out: f64| k.map(|k| units::dps_to_dph(v_out / k.abs()));

        let mut stability: Vec<BiasStability> = Vec::new();
        let mut skipped = self.skipped.clone();
        for w in &self.windows {
            let (n, std) = if w.m == 1 { (valid, Some(std_output)) } else { (w.means.n, w.means.std()) };
            if n < cfg.min_windows {
                skipped.push(SkippedSmoothing {
                    smoothing_s: w.smoothing_s,
                    windows: n,
                    reason: format!("{n} whole windows of {} samples fit, at least {} needed", w.m, cfg.min_windows),
                });
                continue;
            }
            let Some(std) = std else { continue };
            let entry = BiasStability { smoothing_s: w.smoothing_s, output: std, dph: to_dph(std), windows: n };
            // One entry per key: a later smoothing time with the same key replaces the earlier one.
            let key = entry.key();
            match stability.iter_mut().find(|b| b.key() == key) {
                Some(b) => *b = entry,
                None => stability.push(entry),
            }
            if w.with_missing > 0 || w.empty > 0 {
                notes.push(format!(
                    "smoothing {} s: {} windows had missing samples (mean over the valid ones), {} had none and were dropped",
                    w.smoothing_s, w.with_missing, w.empty
                ));
            }
        }
        stability.sort_by(|a, b| a.smoothing_s.total_cmp(&b.smoothing_s));
        let find = |t: f64| stability.iter().find(|b| b.key() == smoothing_key(t)).map(|b| b.smoothing_s);
        let quoted = find(10.0).or_else(|| find(1.0)).or_else(|| {
            if self.config.include_one_sample {
                find(1.0 / fs)
            } else {
                None
            }
        });

        let (drift_out, drift_dph, drift_line) = if mo.ctt > 0.0 {
            let slope = mo.ctd / mo.ctt;
            let ssr = (mo.cdd - slope * mo.ctd).max(0.0);
            let resid = if mo.n > 2.0 { (ssr / (mo.n - 2.0)).sqrt() } else { 0.0 };
            let line = DriftLine {
                t0_s: t0,
                output_at_t0: x0 + mo.mean_d - slope * mo.mean_t,
                slope_output_per_s: slope,
                residual_std_output: resid,
            };
            (Some(units::per_s_to_per_h(slope)), k.map(|k| units::dps_per_s_to_dph_per_h(slope / k)), Some(line))
        } else {
            notes.push("drift not computed: all time stamps are equal".into());
            (None, None, None)
        };

        let temperature = if self.has_temp == Some(true) {
            match temperature_fit(&self.temp.points, x0, cfg, k) {
                Ok(t) => Some(t),
                Err(why) => {
                    notes.push(format!("temperature model not computed: {why}"));
                    None
                }
            }
        } else {
            None
        };

        let rule_line = drift_line.unwrap_or(DriftLine {
            t0_s: 0.0,
            output_at_t0: mean_output,
            slope_output_per_s: 0.0,
            residual_std_output: std_output,
        });
        let outlier_scan_needed = rule_line.residual_std_output > 0.0
            && self.outliers_possible(&rule_line, self.config.outlier_k_sigma * rule_line.residual_std_output);
        let mut quality = self.quality;
        quality.stuck_at_min =
            if self.rail.at_min.value == Some(self.min) { self.rail.at_min } else { RailRuns::default() };
        quality.stuck_at_max =
            if self.rail.at_max.value == Some(self.max) { self.rail.at_max } else { RailRuns::default() };
        let result = StaticTestResult {
            channel: self.config.channel.clone(),
            output_unit: self.config.output_unit,
            samples: self.samples,
            valid_samples: valid,
            sample_rate_hz: fs,
            sample_rate_source: if self.fs_given { SampleRateSource::Given } else { SampleRateSource::TimeStamps },
            duration_s: self.last_time - t0,
            mean_output,
            std_output,
            scale_factor_output_per_dps: k,
            null_output: null,
            bias_dps,
            bias_dph,
            earth_rate_component_dph: earth,
            earth_rate_subtracted: earth_done,
            bias_stability: stability,
            bias_stability_quoted_s: quoted,
            bias_stability_skipped: skipped,
            drift_output_per_h: drift_out,
            drift_dph_per_h: drift_dph,
            drift_line,
            temperature,
            quality,
            notes,
        };
        Ok(FirstPass { result, outlier_scan_needed })
    }
}

pub(super) fn temperature_fit(
    points: &[(f64, f64)],
    x0: f64,
    cfg: &StaticTestConfig,
    k: Option<f64>,
) -> Result<TemperatureResult, String> {
    let needed = if cfg.temperature_quadratic { 4 } else { 3 };
    if points.len() < needed {
        return Err(format!(
            "{} windows of {} s with temperature, at least {needed} needed",
            points.len(),
            cfg.temperature_window_s
        ));
    }
    let temps: Vec<f64> = points.iter().map(|p| p.0).collect();
    let outs: Vec<f64> = points.iter().map(|p| p.1).collect();
    let span =
        temps.iter().copied().fold(f64::NEG_INFINITY, f64::max) - temps.iter().copied().fold(f64::INFINITY, f64::min);
    if span < crate::thermal::MIN_WITHIN_RECORD_SPAN_C {
        return Err(format!(
            "the record's temperature spans only {span:.3} degC (at least {} degC needed for a bias temperature \
             slope: below it drift and noise dominate; soaked temperature points in a plan measure the sensitivity)",
            crate::thermal::MIN_WITHIN_RECORD_SPAN_C
        ));
    }
    let line = fit::fit_line(&temps, &outs).map_err(|e| e.to_string())?;
    let n = points.len() as f64;
    let window_std = fit::sample_std(&outs).unwrap_or(0.0); // ok: len >= 3
    let ssr_line: f64 = points.iter().map(|&(c, d)| (d - line.eval(c)).powi(2)).sum();
    let (quadratic, model, ssr, params) = if cfg.temperature_quadratic {
        let q = fit::fit_polynomial(&temps, &outs, 2).map_err(|e| e.to_string())?;
        let c = &q.coefficients;
        let ssr: f64 = q.residuals.iter().map(|r| r * r).sum();
        (Some([c[0] + x0, c[1], c[2]]), "quadratic", ssr, 3.0)
    } else {
        (None, "linear", ssr_line, 2.0)
    };
    let comp = (ssr / (n - params)).sqrt();
    let to_dph = |v: f64| k.map(|k| units::dps_to_dph(v / k));
    Ok(TemperatureResult {
        window_s: cfg.temperature_window_s,
        windows: points.len() as u64,
        temp_min_c: temps.iter().copied().fold(f64::INFINITY, f64::min),
        temp_max_c: temps.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        slope_output_per_c: line.slope,
        intercept_output: line.intercept + x0,
        temp_sensitivity_dph_per_c: k.map(|k| units::dps_per_c_to_dph_per_c(line.slope / k)),
        quadratic_output: quadratic,
        compensation_model: model.into(),
        window_std_output: window_std,
        compensated_stability_output: comp,
        compensated_stability_dph: to_dph(comp).map(f64::abs),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn a_tiny_temperature_span_gives_no_temperature_slope() {
        // Four windows over 0.04 degC whose outputs rise by 0.1: a slope of 2.5 output/degC that
        // is noise, not temperature; refused with the span named. Over 4 degC it is fitted.
        let cfg = StaticTestConfig::default();
        let tiny: Vec<(f64, f64)> = (0..4).map(|i| (25.0 + 0.01 * i as f64, 0.1 * i as f64 / 3.0)).collect();
        let e = temperature_fit(&tiny, 0.0, &cfg, Some(1.0)).unwrap_err();
        assert!(e.contains("spans only 0.030 degC"), "{e}");
        let wide: Vec<(f64, f64)> = (0..4).map(|i| (25.0 + i as f64, 0.1 * i as f64)).collect();
        let r = temperature_fit(&wide, 0.0, &cfg, Some(1.0)).unwrap();
        assert!((r.slope_output_per_c - 0.1).abs() < 1e-12);
    }

    /// Feeds blocks through the sample-by-sample path only (the reference for the block path).
    fn each_path(config: &StaticTestConfig, blocks: &[SampleBlock]) -> StaticTestResult {
        let mut acc = StaticTestAccumulator::new(config.clone()).unwrap();
        for b in blocks {
            acc.check_block(b).unwrap();
            acc.track_extremes(b, false);
            acc.process_each(b);
        }
        acc.finish().unwrap().result
    }

    /// A stamp going back to or before the first ends the record (issue 54, the Allan
    /// analysis's rule): the figures equal those of the record cut there, however the blocks
    /// fall, and a note says where and how many samples were left out.
    #[test]
    fn a_reset_ends_the_record() {
        let n = 500;
        let x: Vec<f64> = (0..n).map(|i| 1.0 + ((i * 7919) % 101) as f64 * 1e-3).collect();
        let mut t: Vec<f64> = (0..n).map(|i| 10.0 + i as f64 * 0.01).collect();
        for v in t.iter_mut().skip(400) {
            *v = 0.0; // a trailer of zeros
        }
        let lines: Vec<u64> = (2..n as u64 + 2).collect();
        let config = StaticTestConfig { smoothing_times_s: vec![0.1], min_windows: 2, ..StaticTestConfig::default() };
        let run = |x: &[f64], t: &[f64], l: &[u64], split: usize| {
            let mut acc = StaticTestAccumulator::new(config.clone()).unwrap();
            for ((o, ts), l) in x.chunks(split).zip(t.chunks(split)).zip(l.chunks(split)) {
                acc.push(&SampleBlock { output: o, time_s: Some(ts), temperature_c: None, lines: Some(l) }).unwrap();
            }
            acc.finish().unwrap().result
        };
        let cut = run(&x[..400], &t[..400], &lines[..400], 64);
        for split in [1, 7, 64, 399, 400, 401, 500] {
            let r = run(&x, &t, &lines, split);
            assert_eq!(r.valid_samples, 400, "split {split}");
            assert_eq!(r.mean_output.to_bits(), cut.mean_output.to_bits(), "split {split}");
            let note = r.notes.iter().find(|n| n.contains("go back")).unwrap_or_else(|| panic!("{:?}", r.notes));
            assert!(note.contains("at line 402") && note.contains("100 sample(s) from there left out"), "{note}");
        }
    }

    proptest! {
        /// The block path (slice loops, rail runs by pieces, interval extremes first) finds the same
        /// quality findings and figures as the sample-by-sample path, on records with long runs at
        /// the rails, repeated values and irregular time stamps, split into random blocks.
        #[test]
        fn block_path_equals_sample_path(
            runs in prop::collection::vec((0u8..6, 1usize..30), 2..40),
            stamps in prop::collection::vec((0u8..40, 0usize..2000), 0..6),
            split in 1usize..300,
        ) {
            let x: Vec<f64> = runs.iter().flat_map(|&(v, len)| std::iter::repeat_n(2.0 + 0.25 * f64::from(v), len)).collect();
            let n = x.len();
            let mut t: Vec<f64> = (0..n).map(|i| i as f64 * 0.5).collect();
            for &(kind, at) in &stamps {
                // From the 10th sample on: the six shifts (at most -3.6 s) never take a stamp back
                // to the first, which would end the record (a reset, tested on its own below).
                if at >= 10 && at < n {
                    // A repeated stamp, a decreasing one, a gap; each followed by regular stamps.
                    let shift = match kind {
                        0 => -0.5,
                        1 => -0.6,
                        2 => 3.0,
                        _ => 0.0,
                    };
                    t.iter_mut().skip(at).for_each(|v| *v += shift);
                }
            }
            let lines: Vec<u64> = (1..=n as u64).collect();
            let config = StaticTestConfig { sample_rate_hz: Some(2.0), smoothing_times_s: vec![1.0, 3.0], min_windows: 2, rail_run_samples: 4, ..StaticTestConfig::default() };
            let blocks: Vec<SampleBlock> = x
                .chunks(split)
                .zip(t.chunks(split))
                .zip(lines.chunks(split))
                .map(|((o, ts), l)| SampleBlock { output: o, time_s: Some(ts), temperature_c: None, lines: Some(l) })
                .collect();
            let mut acc = StaticTestAccumulator::new(config.clone()).unwrap();
            for b in &blocks {
                acc.push(b).unwrap();
            }
            let fast = acc.finish().unwrap().result;
            let reference = each_path(&config, &blocks);
            prop_assert_eq!(&fast.quality, &reference.quality);
            prop_assert_eq!(fast.valid_samples, reference.valid_samples);
            prop_assert!((fast.mean_output - reference.mean_output).abs() < 1e-12);
            prop_assert_eq!(fast.bias_stability.len(), reference.bias_stability.len());
            for (f, r) in fast.bias_stability.iter().zip(&reference.bias_stability) {
                prop_assert_eq!(f.smoothing_s, r.smoothing_s);
                prop_assert!((f.output - r.output).abs() < 1e-12 * (1.0 + r.output.abs()));
            }
        }
    }
}
