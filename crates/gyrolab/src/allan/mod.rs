//! Allan-variance family of a gyro rate record: ADEV, overlapping ADEV, MDEV, TDEV, HDEV,
//! overlapping HDEV and TOTDEV, with noise identification and confidence intervals.
//!
//! Sources: NIST Special Publication 1065, W. J. Riley, "Handbook of Frequency Stability
//! Analysis" (2008), section 5.2 (definitions, eq. 9-25) and 5.3 (confidence, EDF); IEEE Std
//! 952-1997 annex C (the Allan variance applied to gyro rate data); Riley & Greenhall (EFTF 2004)
//! lag-1 noise identification; Greenhall & Riley (PTTI 2003) EDF algorithm. Stop limits and
//! term counts follow Stable32 (read off its result files in `reference/stable32`).
//!
//! Gyro rate samples play the role of fractional frequency y ("freq" data in allantools), the
//! integrated angle that of phase x: x_0 = 0, x_k = tau0 * sum_{i<k} (y_i - mean y). The mean is
//! a double-double sum (compensated), and the cumulative sum is compensated too (double-double
//! running total, plain sums only inside blocks of 8), so that a record with a large offset (a
//! 2.5 V null with 1e-4 V noise) gives the same deviations as the offset-free record: to relative
//! 1e-9, tested at 1e6 samples; the same error analysis holds at 1e8 samples (the mean is exact
//! to one rounding, y_i - mean is exact by Sterbenz's lemma, the cumulative sum is compensated).
//!
//! Speed: the conversion runs in two parallel passes; OADEV sums all taus of a list in one
//! cache-blocked parallel sweep with fused, AVX2+FMA kernels (`kernels`); lists of 256 taus and
//! more go through the FFT expansion of `fast` (O(N log N + M log^2 M) instead of O(N M)), with
//! every tau whose error bound is not below 1e-10 relative summed directly.
//!
//! Memory: the owning entry points convert the caller's `Vec` to the angle series in place (it
//! needs capacity N + 1 to avoid one reallocation); OADEV, ADEV, MDEV, TDEV, HDEV and OHDEV then
//! allocate nothing proportional to N (the noise identification streams over the record) except
//! the FFT path of long OADEV tau lists (a few copies of the record) and the B1 fallback's N/m
//! averages (m > N/30 in practice). TOTDEV makes the reflected series of SP1065 eq. (25) a block
//! at a time from the angle series (never 3N values at once).

mod chi2;
mod confidence;
mod fast;
pub mod gap_fill;
mod gaps;
mod kernels;
mod lag1_sweep;
pub mod present;
pub mod streaming;

pub use gaps::{deviation_from_rate_with_gaps, deviation_from_rate_with_gaps_into};
pub use present::{analyse_rate_present, deviation_from_rate_present};

pub use chi2::{chi_squared_cdf, chi_squared_quantile};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Default confidence level of the intervals: 68.3 % (one sigma), as Stable32.
pub const DEFAULT_CONFIDENCE: f64 = 0.683;

/// Which deviation to compute.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum DeviationKind {
    /// Overlapping Allan deviation (SP1065 eq. 11); the default.
    #[default]
    Oadev,
    /// Non-overlapping Allan deviation (SP1065 eq. 9).
    Adev,
    /// Modified Allan deviation (SP1065 eq. 13).
    Mdev,
    /// Time deviation, tau / sqrt(3) * MDEV (SP1065 eq. 15); in angle units.
    Tdev,
    /// Non-overlapping Hadamard deviation (SP1065 eq. 17).
    Hdev,
    /// Overlapping Hadamard deviation (SP1065 eq. 18).
    Ohdev,
    /// Total deviation (SP1065 eq. 25).
    Totdev,
}

impl DeviationKind {
    /// All kinds, in a fixed order.
    pub const ALL: [DeviationKind; 7] = [
        DeviationKind::Oadev,
        DeviationKind::Adev,
        DeviationKind::Mdev,
        DeviationKind::Tdev,
        DeviationKind::Hdev,
        DeviationKind::Ohdev,
        DeviationKind::Totdev,
    ];

    /// Parses a name such as "oadev", "ADEV", "totdev".
    pub fn parse(name: &str) -> Result<DeviationKind, AllanError> {
        let lower = name.trim().to_ascii_lowercase();
        DeviationKind::ALL
            .into_iter()
            .find(|k| k.name() == lower)
            .ok_or_else(|| AllanError::UnknownKind(name.to_string()))
    }

    /// Lower-case short name ("oadev", ...).
    pub fn name(self) -> &'static str {
        match self {
            DeviationKind::Oadev => "oadev",
            DeviationKind::Adev => "adev",
            DeviationKind::Mdev => "mdev",
            DeviationKind::Tdev => "tdev",
            DeviationKind::Hdev => "hdev",
            DeviationKind::Ohdev => "ohdev",
            DeviationKind::Totdev => "totdev",
        }
    }

    /// Largest averaging factor Stable32 computes for n rate samples (its default "stop" rule:
    /// N/4 for OADEV, MDEV, TDEV, OHDEV; N/5 for ADEV, HDEV; N/2 for TOTDEV).
    pub fn stable32_max_factor(self, n_rate: usize) -> usize {
        let limit = match self {
            DeviationKind::Oadev | DeviationKind::Mdev | DeviationKind::Tdev | DeviationKind::Ohdev => n_rate / 4,
            DeviationKind::Adev | DeviationKind::Hdev => n_rate / 5,
            DeviationKind::Totdev => n_rate / 2,
        };
        limit.min(self.hard_max_factor(n_rate))
    }

    /// Largest averaging factor for which the estimator has at least one term.
    pub fn hard_max_factor(self, n_rate: usize) -> usize {
        match self {
            DeviationKind::Oadev | DeviationKind::Adev => n_rate / 2,
            DeviationKind::Mdev | DeviationKind::Tdev => (n_rate + 1) / 3,
            DeviationKind::Ohdev | DeviationKind::Hdev => n_rate / 3,
            DeviationKind::Totdev => n_rate.saturating_sub(1),
        }
    }

    /// Difference order of the estimator (2 Allan family, 3 Hadamard).
    fn difference_order(self) -> u32 {
        match self {
            DeviationKind::Hdev | DeviationKind::Ohdev => 3,
            _ => 2,
        }
    }
}

/// Which averaging factors m (tau = m tau0) to evaluate.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
pub enum TauList {
    /// m = 1, 2, 4, 8, ... (powers of two); the default.
    #[default]
    Octave,
    /// m = 1, 2, 4, 10, 20, 40, 100, ... (1, 2, 4 x 10^k), as Stable32's "decade".
    Decade,
    /// n log-spaced values per decade, rounded to unique integers.
    PerDecade(u32),
    /// Every m from 1 to the stop limit.
    All,
    /// Explicit averaging factors (each >= 1; those beyond what the record allows are dropped).
    Factors(Vec<usize>),
    /// Explicit taus in seconds (each must be a whole multiple of tau0 within 1e-6 relative).
    Seconds(Vec<f64>),
}

impl TauList {
    /// Parses "octave", "decade", "all", "N/decade" or "N per decade" (e.g. "10/decade").
    pub fn parse(text: &str) -> Result<TauList, AllanError> {
        let t = text.trim().to_ascii_lowercase();
        match t.as_str() {
            "octave" => Ok(TauList::Octave),
            "decade" => Ok(TauList::Decade),
            "all" => Ok(TauList::All),
            _ => {
                let head = t.strip_suffix("/decade").or_else(|| t.strip_suffix(" per decade"));
                match head.and_then(|h| h.trim().parse::<u32>().ok()) {
                    Some(n) if n > 0 => Ok(TauList::PerDecade(n)),
                    _ => Err(AllanError::UnknownTauList(text.to_string())),
                }
            }
        }
    }
}

/// Options of a deviation computation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AllanOptions {
    /// Deviation to compute.
    pub kind: DeviationKind,
    /// Averaging factors to evaluate.
    pub taus: TauList,
    /// Confidence level of the intervals (e.g. 0.683); `None` skips noise identification and bounds.
    pub confidence: Option<f64>,
    /// Largest averaging factor; `None` uses Stable32's stop rule for the kind (lists other than
    /// `Factors`/`Seconds`); explicit lists are only limited by what the record allows.
    pub max_factor: Option<usize>,
}

impl Default for AllanOptions {
    fn default() -> Self {
        AllanOptions {
            kind: DeviationKind::Oadev,
            taus: TauList::Octave,
            confidence: Some(DEFAULT_CONFIDENCE),
            max_factor: None,
        }
    }
}

impl AllanOptions {
    /// Options for one kind with octave taus and 68.3 % intervals.
    pub fn new(kind: DeviationKind) -> Self {
        AllanOptions { kind, ..AllanOptions::default() }
    }

    /// Same options with another tau list.
    pub fn with_taus(mut self, taus: TauList) -> Self {
        self.taus = taus;
        self
    }

    /// Same options with another confidence level (`None`: no intervals).
    pub fn with_confidence(mut self, confidence: Option<f64>) -> Self {
        self.confidence = confidence;
        self
    }
}

/// How the noise type of a point was identified.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NoiseIdMethod {
    /// Lag-1 autocorrelation (Riley & Greenhall) of the frequency averages, >= 30 of them.
    Lag1Autocorrelation,
    /// B1 ratio with R(n) (SP1065 5.6), used where fewer than 30 averages remain.
    B1Ratio,
    /// Taken over from the next smaller averaging factor (too few terms for B1 either).
    Previous,
}

/// One point of a deviation curve.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct AllanPoint {
    /// Averaging factor m.
    pub m: usize,
    /// Averaging time tau = m tau0 in seconds.
    pub tau_s: f64,
    /// Deviation in rate units (TDEV: rate units x seconds, i.e. angle).
    pub deviation: f64,
    /// Number of terms in the estimator's sum (Stable32's `#` column).
    pub terms: usize,
    /// Identified power-law noise exponent alpha of the rate PSD (2 white PM .. -2 random-walk FM).
    pub alpha: Option<i32>,
    /// How alpha was identified.
    pub noise_id: Option<NoiseIdMethod>,
    /// Equivalent degrees of freedom used for the interval.
    pub edf: Option<f64>,
    /// Lower bound of the deviation's confidence interval.
    pub lower: Option<f64>,
    /// Upper bound of the deviation's confidence interval.
    pub upper: Option<f64>,
}

impl AllanPoint {
    /// A point whose noise is not identified yet (no alpha, EDF or bounds).
    pub fn unidentified(m: usize, tau_s: f64, deviation: f64, terms: usize) -> AllanPoint {
        AllanPoint { m, tau_s, deviation, terms, alpha: None, noise_id: None, edf: None, lower: None, upper: None }
    }
}

/// A deviation curve with the context needed to interpret it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AllanCurve {
    /// Which deviation.
    pub kind: DeviationKind,
    /// Sample interval in seconds.
    pub tau0_s: f64,
    /// Number of rate samples (angle points minus one).
    pub n_rate: usize,
    /// Confidence level of the intervals, if computed.
    pub confidence: Option<f64>,
    /// The points, in increasing tau.
    pub points: Vec<AllanPoint>,
}

/// Why a deviation could not be computed.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum AllanError {
    /// The record has too few samples for any requested tau.
    #[error("record of {n} samples is too short for any tau of {kind}")]
    TooShort {
        /// Number of rate samples.
        n: usize,
        /// Short name of the deviation.
        kind: &'static str,
    },
    /// A sample is NaN or infinite.
    #[error("sample {index} is not finite ({value})")]
    NonFinite {
        /// Zero-based index of the first bad sample.
        index: usize,
        /// The bad value.
        value: f64,
    },
    /// tau0 is not a positive finite number.
    #[error("sample interval tau0 = {0} s must be positive and finite")]
    BadTau0(f64),
    /// The kind cannot be computed over missing samples.
    #[error("{kind} cannot be computed over missing samples (gaps): oadev, adev, hdev and ohdev can")]
    GapsUnsupported {
        /// Short name of the deviation.
        kind: &'static str,
    },
    /// The least share of present samples a window needs is not in (0, 1].
    #[error("least share of present samples in a window {0} must lie in (0, 1]")]
    BadPresentShare(f64),
    /// Unknown deviation name.
    #[error("unknown deviation kind '{0}' (expected adev, oadev, mdev, tdev, hdev, ohdev, totdev)")]
    UnknownKind(String),
    /// Unknown tau-list name.
    #[error("unknown tau list '{0}' (expected octave, decade, all, or N/decade)")]
    UnknownTauList(String),
    /// An explicit tau is zero, negative or not a whole multiple of tau0.
    #[error("tau {0} is not a positive whole multiple of tau0")]
    BadTau(f64),
    /// The confidence level is not in (0, 1).
    #[error("confidence level {0} must lie strictly between 0 and 1")]
    BadConfidence(f64),
}

/// Neumaier-compensated sum (Neumaier 1974), accurate for values of mixed size.
pub fn compensated_sum(values: &[f64]) -> f64 {
    let mut sum = 0.0f64;
    let mut carry = 0.0f64;
    for &v in values {
        let t = sum + v;
        if sum.abs() >= v.abs() {
            carry += (sum - t) + v;
        } else {
            carry += (v - t) + sum;
        }
        sum = t;
    }
    sum + carry
}

fn check_finite(values: &[f64]) -> Result<(), AllanError> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(AllanError::NonFinite { index, value: values[index] }),
        None => Ok(()),
    }
}

/// Knuth's branch-free TwoSum: `s + e == a + b` exactly, `s = fl(a + b)`.
#[inline(always)]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bp = s - a;
    (s, (a - (s - bp)) + (b - bp))
}

/// Elements per chunk of the parallel angle conversion (128 KiB of f64).
const PHASE_CHUNK: usize = 1 << 14;

/// Records shorter than this many points are computed on the calling thread alone: their
/// parallel pieces take tens of microseconds, about what waking another thread costs (a 10 min
/// record at 100 Hz spent more time in the scheduler than in its sums; issue 56). Every
/// parallel sum has a fixed partition, so the results do not depend on it.
pub const PARALLEL_MIN_POINTS: usize = 1 << 18;

/// Whether the analysis of `rate_samples` rate samples (the angle series has one point more)
/// runs on the calling thread without any rayon call ([`PARALLEL_MIN_POINTS`]): a caller that
/// runs it outside a thread pool asks this of the samples as they reach the analysis (after
/// any gap filling or padding to the sample grid).
pub fn runs_serially(rate_samples: usize) -> bool {
    !parallel(rate_samples.saturating_add(1))
}

/// Whether a record of `points` points is computed in parallel ([`PARALLEL_MIN_POINTS`]).
/// Below it no rayon function is called at all (not even to ask a pool's size): a caller may
/// run a short record on its own thread, outside any pool (the Python package does: handing a
/// 10 min record to a pool thread cost a fifth of its call), and no global pool is started.
pub(crate) fn parallel(points: usize) -> bool {
    points >= PARALLEL_MIN_POINTS
}

/// `f` of each index `0..n`, in order: in parallel (the current rayon pool) for a record of
/// `points` points that is [`parallel`], else on the calling thread.
pub(crate) fn map_indices<R: Send>(points: usize, n: usize, f: impl Fn(usize) -> R + Sync + Send) -> Vec<R> {
    if parallel(points) {
        (0..n).into_par_iter().map(f).collect()
    } else {
        (0..n).map(f).collect()
    }
}

/// Double-double sum (hi, lo) of one chunk, 8 compensated lanes (vectorisable, branch-free),
/// and whether every value is finite (x * 0 is 0 for finite x, NaN otherwise).
fn chunk_sum_dd(values: &[f64]) -> (f64, f64, bool) {
    const LANES: usize = 8;
    let mut hi = [0.0f64; LANES];
    let mut lo = [0.0f64; LANES];
    let mut zero = [0.0f64; LANES];
    let chunks = values.chunks_exact(LANES);
    let rest = chunks.remainder();
    for c in chunks {
        for l in 0..LANES {
            let (s, e) = two_sum(hi[l], c[l]);
            hi[l] = s;
            lo[l] += e;
            zero[l] += c[l] * 0.0;
        }
    }
    let (mut h, mut e_sum, mut z) = (0.0f64, 0.0f64, 0.0f64);
    for l in 0..LANES {
        let (s, e) = two_sum(h, hi[l]);
        h = s;
        e_sum += e + lo[l];
        z += zero[l];
    }
    for &v in rest {
        let (s, e) = two_sum(h, v);
        h = s;
        e_sum += e;
        z += v * 0.0;
    }
    let (s, e) = two_sum(h, e_sum);
    (s, e, z == 0.0)
}

/// Turns rate samples into the angle series in sample units (angle / tau0), in place:
/// s_0 = 0, s_k = sum_{i<k} (y_i - mean y). The vector grows by one element. On an error (a
/// non-finite sample, found before anything is written) the samples are left as they were.
///
/// Two parallel passes. Pass 1 ([`angle_plan`]): double-double sums of each chunk of
/// [`PHASE_CHUNK`] samples (also the finiteness check); they give the mean (the record's
/// double-double sum over n, rounded once) and each chunk's starting angle
/// sum_{i<start} y_i - start * mean in double-double (the product by an exact FMA split). Pass 2:
/// every chunk runs its own compensated (TwoSum) cumulative sum of y_i - mean from that start;
/// four chunks are interleaved per thread so that the add latency chain does not bound the
/// speed. The result is the compensated cumulative sum of the sequential version up to a few
/// units of rounding.
fn rate_to_sample_angle_in_place(data: &mut Vec<f64>) -> Result<(), AllanError> {
    let plan = angle_plan(data)?;
    if parallel(data.len()) {
        data.par_chunks_mut(PHASE_CHUNK)
            .zip(plan.starts)
            .for_each(|(chunk, start)| cumulative_chunk(chunk, plan.mean, start));
    } else {
        data.chunks_mut(PHASE_CHUNK)
            .zip(plan.starts)
            .for_each(|(chunk, start)| cumulative_chunk(chunk, plan.mean, start));
    }
    data.push(plan.end);
    Ok(())
}

/// The angle series of borrowed rate samples written into `out` (cleared first): the same
/// passes and the same numbers as [`rate_to_sample_angle_in_place`], but the samples are read
/// where they are, so the record is never copied first (pass 2 reads the samples and writes
/// the angle). Give `out` capacity N + 1 to spare a reallocation.
fn rate_to_sample_angle_into(rate: &[f64], out: &mut Vec<f64>) -> Result<(), AllanError> {
    let plan = angle_plan(rate)?;
    out.clear();
    out.reserve_exact(rate.len() + 1);
    let dst = &mut out.spare_capacity_mut()[..rate.len()];
    if parallel(rate.len()) {
        dst.par_chunks_mut(PHASE_CHUNK)
            .zip(rate.par_chunks(PHASE_CHUNK))
            .zip(plan.starts)
            .for_each(|((dst, src), start)| cumulative_chunk_into(src, dst, plan.mean, start));
    } else {
        dst.chunks_mut(PHASE_CHUNK)
            .zip(rate.chunks(PHASE_CHUNK))
            .zip(plan.starts)
            .for_each(|((dst, src), start)| cumulative_chunk_into(src, dst, plan.mean, start));
    }
    // SAFETY: the loop above wrote every one of the first rate.len() elements (the chunks of
    // the spare capacity and of `rate` pair one to one and have equal lengths).
    unsafe { out.set_len(rate.len()) };
    out.push(plan.end);
    Ok(())
}

/// What pass 1 of the angle conversion gives pass 2.
struct AnglePlan {
    /// Mean of the rate samples.
    mean: f64,
    /// Double-double starting angle of each chunk of [`PHASE_CHUNK`] samples.
    starts: Vec<(f64, f64)>,
    /// The last angle point, s_N.
    end: f64,
}

/// Pass 1 of the angle conversion (see [`rate_to_sample_angle_in_place`]); the first non-finite
/// sample is an error.
fn angle_plan(data: &[f64]) -> Result<AnglePlan, AllanError> {
    let n = data.len();
    if n == 0 {
        return Ok(AnglePlan { mean: 0.0, starts: Vec::new(), end: 0.0 });
    }
    let sums: Vec<(f64, f64, bool)> = if parallel(n) {
        data.par_chunks(PHASE_CHUNK).map(chunk_sum_dd).collect()
    } else {
        data.chunks(PHASE_CHUNK).map(chunk_sum_dd).collect()
    };
    if sums.iter().any(|s| !s.2) {
        check_finite(data)?;
    }
    let (mut hi, mut lo) = (0.0f64, 0.0f64);
    for &(h, l, _) in &sums {
        let (s, e) = two_sum(hi, h);
        hi = s;
        lo += e + l;
    }
    let mean = (hi + lo) / n as f64;
    // starting angle of every chunk, double-double
    let mut starts = Vec::with_capacity(sums.len() + 1);
    let (mut ah, mut al) = (0.0f64, 0.0f64);
    for (i, &(h, l, _)) in sums.iter().enumerate() {
        starts.push((ah, al));
        let len = (n - i * PHASE_CHUNK).min(PHASE_CHUNK) as f64;
        let p = len * mean;
        let p_err = len.mul_add(mean, -p);
        let (s1, e1) = two_sum(ah, h);
        let (s2, e2) = two_sum(s1, -p);
        ah = s2;
        al += (e1 + e2) + (l - p_err);
    }
    Ok(AnglePlan { mean, starts, end: ah + al })
}

/// Block of the cumulative sum: 8 samples get a plain local prefix sum (vectorisable; its
/// rounding is that of at most 8 terms of the size of y).
const PREFIX_BLOCK: usize = 8;

/// The angles of one block of [`PREFIX_BLOCK`] samples from the running total (hi, lo), and the
/// block's sum of y - mean.
#[inline(always)]
fn prefix_block(y: &[f64], mean: f64, hi: f64, lo: f64) -> ([f64; PREFIX_BLOCK], f64) {
    let mut q = [0.0f64; PREFIX_BLOCK];
    let mut run = 0.0f64;
    for l in 0..PREFIX_BLOCK {
        q[l] = run;
        run += y[l] - mean;
    }
    (std::array::from_fn(|l| hi + (lo + q[l])), run)
}

/// In-place exclusive cumulative sum of y - mean over one chunk, starting from the double-double
/// `start`: each block's local prefix sum ([`prefix_block`]) is added to the compensated running
/// total (hi, lo).
#[inline]
fn cumulative_chunk(chunk: &mut [f64], mean: f64, start: (f64, f64)) {
    let (mut hi, mut lo) = start;
    let mut blocks = chunk.chunks_exact_mut(PREFIX_BLOCK);
    for block in &mut blocks {
        let (angles, run) = prefix_block(block, mean, hi, lo);
        block.copy_from_slice(&angles);
        let (s, e) = two_sum(hi, run);
        hi = s;
        lo += e;
    }
    for v in blocks.into_remainder() {
        let y = *v - mean;
        *v = hi + lo;
        let (s, e) = two_sum(hi, y);
        hi = s;
        lo += e;
    }
}

/// [`cumulative_chunk`] from the samples `src` into `dst` (of equal length).
#[inline]
fn cumulative_chunk_into(src: &[f64], dst: &mut [std::mem::MaybeUninit<f64>], mean: f64, start: (f64, f64)) {
    let (mut hi, mut lo) = start;
    let mut blocks = dst.chunks_exact_mut(PREFIX_BLOCK);
    let mut sources = src.chunks_exact(PREFIX_BLOCK);
    for (block, y) in (&mut blocks).zip(&mut sources) {
        let (angles, run) = prefix_block(y, mean, hi, lo);
        for (d, a) in block.iter_mut().zip(angles) {
            d.write(a);
        }
        let (s, e) = two_sum(hi, run);
        hi = s;
        lo += e;
    }
    for (d, &v) in blocks.into_remainder().iter_mut().zip(sources.remainder()) {
        let y = v - mean;
        d.write(hi + lo);
        let (s, e) = two_sum(hi, y);
        hi = s;
        lo += e;
    }
}

/// Computes a deviation curve from gyro rate samples at interval `tau0_s`, consuming the record.
///
/// The vector is turned into the angle series in place; hand it over with capacity N + 1
/// (`Vec::with_capacity(n + 1)`) so that peak memory stays at one copy of the record.
pub fn deviation_from_rate(mut rate: Vec<f64>, tau0_s: f64, options: &AllanOptions) -> Result<AllanCurve, AllanError> {
    validate_parameters(tau0_s, options)?;
    rate.reserve_exact(1);
    rate_to_sample_angle_in_place(&mut rate)?;
    compute(&rate, tau0_s, options)
}

/// Computes a deviation curve from borrowed gyro rate samples (the angle series is built in a
/// new vector; the samples are not copied first).
pub fn deviation_from_rate_slice(rate: &[f64], tau0_s: f64, options: &AllanOptions) -> Result<AllanCurve, AllanError> {
    deviation_from_rate_into(rate, Vec::new(), tau0_s, options)
}

/// Computes a deviation curve from borrowed gyro rate samples, building the angle series in
/// `buffer` (its contents are discarded; its allocation is reused when it holds N + 1 values):
/// the samples are read twice where they are and never copied (see
/// [`deviation_from_rate_slice`]). A caller that wants the buffer on particular pages (huge
/// pages, say) allocates it so.
pub fn deviation_from_rate_into(
    rate: &[f64],
    mut buffer: Vec<f64>,
    tau0_s: f64,
    options: &AllanOptions,
) -> Result<AllanCurve, AllanError> {
    validate_parameters(tau0_s, options)?;
    rate_to_sample_angle_into(rate, &mut buffer)?;
    compute(&buffer, tau0_s, options)
}

/// Computes a deviation curve from angle (phase) samples at interval `tau0_s`, consuming them.
///
/// Angle in rate units x seconds (deg for a rate in deg/s); N + 1 angle points correspond to N
/// rate samples y_i = (x_{i+1} - x_i) / tau0.
pub fn deviation_from_angle(
    mut angle: Vec<f64>,
    tau0_s: f64,
    options: &AllanOptions,
) -> Result<AllanCurve, AllanError> {
    if angle.is_empty() {
        return Err(AllanError::TooShort { n: 0, kind: options.kind.name() });
    }
    validate(&angle[1..], tau0_s, options)?;
    check_finite(&angle)?;
    let x0 = angle[0];
    for v in angle.iter_mut() {
        *v = (*v - x0) / tau0_s;
    }
    compute(&angle, tau0_s, options)
}

/// Computes a deviation curve from borrowed angle (phase) samples (copies them once).
pub fn deviation_from_angle_slice(
    angle: &[f64],
    tau0_s: f64,
    options: &AllanOptions,
) -> Result<AllanCurve, AllanError> {
    deviation_from_angle(angle.to_vec(), tau0_s, options)
}

fn validate(rate: &[f64], tau0_s: f64, options: &AllanOptions) -> Result<(), AllanError> {
    validate_parameters(tau0_s, options)?;
    check_finite(rate)
}

fn validate_parameters(tau0_s: f64, options: &AllanOptions) -> Result<(), AllanError> {
    if !(tau0_s.is_finite() && tau0_s > 0.0) {
        return Err(AllanError::BadTau0(tau0_s));
    }
    if let Some(c) = options.confidence {
        if !(c > 0.0 && c < 1.0) {
            return Err(AllanError::BadConfidence(c));
        }
    }
    Ok(())
}

/// The averaging factors the options select for a record of `n_rate` rate samples.
pub fn averaging_factors(options: &AllanOptions, n_rate: usize, tau0_s: f64) -> Result<Vec<usize>, AllanError> {
    let kind = options.kind;
    let hard = kind.hard_max_factor(n_rate);
    let stop = options.max_factor.unwrap_or_else(|| kind.stable32_max_factor(n_rate)).min(hard);
    let mut ms: Vec<usize> = match &options.taus {
        TauList::Octave => {
            std::iter::successors(Some(1usize), |m| m.checked_mul(2)).take_while(|&m| m <= stop).collect()
        }
        TauList::Decade => {
            let mut v = Vec::new();
            let mut decade = 1usize;
            'outer: loop {
                for f in [1, 2, 4] {
                    let m = decade.saturating_mul(f);
                    if m > stop {
                        break 'outer;
                    }
                    v.push(m);
                }
                decade = decade.saturating_mul(10);
            }
            v
        }
        TauList::PerDecade(n) => {
            let n = f64::from((*n).max(1));
            let mut v = Vec::new();
            let mut i = 0u32;
            loop {
                let m = 10f64.powf(f64::from(i) / n).round() as usize;
                if m > stop {
                    break;
                }
                v.push(m);
                i += 1;
            }
            v
        }
        TauList::All => (1..=stop).collect(),
        TauList::Factors(f) => {
            if f.contains(&0) {
                return Err(AllanError::BadTau(0.0));
            }
            let cap = options.max_factor.unwrap_or(hard).min(hard);
            f.iter().copied().filter(|&m| m <= cap).collect()
        }
        TauList::Seconds(taus) => {
            let cap = options.max_factor.unwrap_or(hard).min(hard);
            let mut v = Vec::with_capacity(taus.len());
            for &t in taus {
                let m = (t / tau0_s).round();
                if !(t.is_finite() && m >= 1.0 && ((t / tau0_s) - m).abs() <= 1e-6 * m) {
                    return Err(AllanError::BadTau(t));
                }
                if (m as usize) <= cap {
                    v.push(m as usize);
                }
            }
            v
        }
    };
    ms.sort_unstable();
    ms.dedup();
    if ms.is_empty() {
        return Err(AllanError::TooShort { n: n_rate, kind: kind.name() });
    }
    Ok(ms)
}

/// Core: `s` is the angle series in sample units, L = N + 1 points.
fn compute(s: &[f64], tau0_s: f64, options: &AllanOptions) -> Result<AllanCurve, AllanError> {
    let kind = options.kind;
    let n_rate = s.len().saturating_sub(1);
    let ms = averaging_factors(options, n_rate, tau0_s)?;
    // OADEV, the common case, is summed for all taus in one cache-blocked sweep
    let oadev_sums = (kind == DeviationKind::Oadev).then(|| oadev_sums(s, &ms));
    let mut points: Vec<AllanPoint> = map_indices(s.len(), ms.len(), |i| {
        let m = ms[i];
        let (variance, terms) = match &oadev_sums {
            Some(sums) => {
                let n = s.len() - 2 * m;
                (sums[i] / (2.0 * (m as f64).powi(2) * n as f64), n)
            }
            None => variance_at(s, kind, m),
        };
        let mut deviation = variance.sqrt();
        if kind == DeviationKind::Tdev {
            deviation *= m as f64 * tau0_s / 3f64.sqrt();
        }
        AllanPoint::unidentified(m, m as f64 * tau0_s, deviation, terms)
    });
    attach_bounds(&mut points, s, kind, options.confidence, |_| s.len());
    Ok(AllanCurve { kind, tau0_s, n_rate, confidence: options.confidence, points })
}

/// Identifies the noise type of every point (lag-1 ACF, else B1, else the previous point's)
/// and attaches its EDF and chi-squared bounds; `n_phase` gives the record length (phase
/// points) the EDF of a point is computed for.
fn attach_bounds(
    points: &mut [AllanPoint],
    s: &[f64],
    kind: DeviationKind,
    confidence: Option<f64>,
    n_phase: impl Fn(&AllanPoint) -> usize,
) {
    if let Some(confidence) = confidence {
        let ms: Vec<usize> = points.iter().map(|p| p.m).collect();
        let lag1 = lag1_sweep::lag1_noise_ids(s, &ms, kind.difference_order() as usize);
        let ids: Vec<Option<(i32, NoiseIdMethod)>> = {
            let points = &*points;
            map_indices(s.len(), points.len(), |i| identify_noise(s, points[i].m, kind, points[i].terms, lag1[i]))
        };
        let mut previous: Option<i32> = None;
        for (p, id) in points.iter_mut().zip(ids) {
            match id {
                Some((a, method)) => {
                    p.alpha = Some(a);
                    p.noise_id = Some(method);
                    previous = Some(a);
                }
                None if p.deviation > 0.0 => {
                    p.alpha = previous;
                    p.noise_id = previous.map(|_| NoiseIdMethod::Previous);
                }
                None => {}
            }
            if let Some(alpha) = p.alpha {
                let edf = equivalent_dof(kind, alpha, p.m, n_phase(p));
                p.edf = Some(edf);
                if let Some((lo, hi)) = confidence::chi2_bounds(p.deviation, edf, confidence) {
                    p.lower = Some(lo);
                    p.upper = Some(hi);
                }
            } else if p.deviation == 0.0 {
                p.lower = Some(0.0);
                p.upper = Some(0.0);
            }
        }
    }
}

/// Tau lists at least this long (and records at least 4 times as long) use the FFT expansion.
const FAST_MIN_TAUS: usize = 256;

/// Relative accuracy demanded of an FFT-expanded sum's error bound; sums that miss it are
/// recomputed directly. The bound is at least 4 times the observed error (fast.rs tests), so the
/// FFT-expanded values are good to a few 1e-11, well inside the 1e-9 promised.
const FAST_RELATIVE_BOUND: f64 = 1e-10;

/// Overlapping Allan sums for the sorted factors `ms`: directly (fused octave runs) for short
/// lists, through [`fast::overlapping_allan_sums_fft`] for long ones, with the factors whose
/// error bound is too loose (small m on wandering records) summed directly.
fn oadev_sums(s: &[f64], ms: &[usize]) -> Vec<f64> {
    if ms.len() >= FAST_MIN_TAUS && s.len() >= 4 * FAST_MIN_TAUS {
        if let Some(fast) = fast::overlapping_allan_sums_fft(s, ms) {
            let redo: Vec<usize> = (0..ms.len())
                .filter(|&i| !(fast[i].1 <= FAST_RELATIVE_BOUND * fast[i].0 && fast[i].0.is_finite()))
                .collect();
            let redo_ms: Vec<usize> = redo.iter().map(|&i| ms[i]).collect();
            let direct = kernels::overlapping_allan_sums(s, &redo_ms);
            let mut sums: Vec<f64> = fast.iter().map(|f| f.0).collect();
            for (&i, d) in redo.iter().zip(direct) {
                sums[i] = d;
            }
            return sums;
        }
    }
    kernels::overlapping_allan_sums(s, ms)
}

/// Variance (rate units squared; TDEV: MVAR) and number of terms at averaging factor m.
fn variance_at(s: &[f64], kind: DeviationKind, m: usize) -> (f64, usize) {
    let mf = m as f64;
    match kind {
        DeviationKind::Oadev => {
            let (sum, n) = kernels::overlapping_allan_sum(s, m);
            (sum / (2.0 * mf * mf * n as f64), n)
        }
        DeviationKind::Adev => {
            let (sum, n) = kernels::allan_sum(s, m);
            (sum / (2.0 * mf * mf * n as f64), n)
        }
        DeviationKind::Mdev | DeviationKind::Tdev => {
            let (sum, n) = kernels::modified_allan_sum(s, m);
            (sum / (2.0 * mf.powi(4) * n as f64), n)
        }
        DeviationKind::Ohdev => {
            let (sum, n) = kernels::overlapping_hadamard_sum(s, m);
            (sum / (6.0 * mf * mf * n as f64), n)
        }
        DeviationKind::Hdev => {
            let (sum, n) = kernels::hadamard_sum(s, m);
            (sum / (6.0 * mf * mf * n as f64), n)
        }
        DeviationKind::Totdev => {
            let (sum, n) = kernels::total_sum(s, m);
            (sum / (2.0 * mf * mf * n as f64), n)
        }
    }
}

/// Noise identification at m, Stable32's rule: lag-1 ACF of the frequency averages when there
/// are >= 30 of them; else the B1 ratio with R(n) (B1 theory at N = `terms`) when the estimator
/// has at least [`confidence::B1_MIN_TERMS`] independent terms (its terms, divided by m for the
/// overlapping ones); else `None` (the caller keeps the previous tau's alpha). `lag1` is the
/// lag-1 identification at m (`lag1_sweep::lag1_noise_ids`).
fn identify_noise(
    s: &[f64],
    m: usize,
    kind: DeviationKind,
    terms: usize,
    lag1: Option<i32>,
) -> Option<(i32, NoiseIdMethod)> {
    if let Some(a) = lag1 {
        return Some((a, NoiseIdMethod::Lag1Autocorrelation));
    }
    let independent = match kind {
        DeviationKind::Adev | DeviationKind::Hdev => terms as f64,
        _ => terms as f64 / m as f64,
    };
    if independent < confidence::B1_MIN_TERMS {
        return None;
    }
    let averages: Vec<f64> =
        s.iter().step_by(m).collect::<Vec<_>>().windows(2).map(|w| (w[1] - w[0]) / m as f64).collect();
    let rn = || {
        if 3 * m > s.len() - 1 {
            return None;
        }
        let (msum, mn) = kernels::modified_allan_sum(s, m);
        let (asum, an) = kernels::overlapping_allan_sum(s, m);
        let mvar = msum / (2.0 * (m as f64).powi(4) * mn as f64);
        let avar = asum / (2.0 * (m as f64).powi(2) * an as f64);
        (avar > 0.0).then(|| mvar / avar)
    };
    confidence::b1_noise_id(&averages, m, terms, rn).map(|a| (a, NoiseIdMethod::B1Ratio))
}

/// Equivalent degrees of freedom of a deviation of `kind` at averaging factor `m` for noise
/// type `alpha` and `n_phase` phase points (Greenhall & Riley 2004; totdev: SP1065 table 12).
pub fn equivalent_dof(kind: DeviationKind, alpha: i32, m: usize, n_phase: usize) -> f64 {
    match kind {
        DeviationKind::Adev => confidence::edf_greenhall(alpha, 2, m, n_phase, false, false),
        DeviationKind::Oadev => confidence::edf_greenhall(alpha, 2, m, n_phase, true, false),
        DeviationKind::Mdev | DeviationKind::Tdev => confidence::edf_greenhall(alpha, 2, m, n_phase, true, true),
        DeviationKind::Hdev => confidence::edf_greenhall(alpha, 3, m, n_phase, false, false),
        DeviationKind::Ohdev => confidence::edf_greenhall(alpha, 3, m, n_phase, true, false),
        DeviationKind::Totdev => confidence::edf_total(n_phase, m, alpha),
    }
}

/// Chi-squared confidence bounds (low, high) of a deviation with `edf` degrees of freedom at the
/// two-sided `confidence` level (SP1065 section 5.3).
pub fn deviation_bounds(deviation: f64, edf: f64, confidence: f64) -> Option<(f64, f64)> {
    confidence::chi2_bounds(deviation, edf, confidence)
}

#[cfg(test)]
mod tests;
