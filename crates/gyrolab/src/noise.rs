//! Gyro noise terms from an Allan deviation curve (rate in deg/s, tau in s).
//!
//! Source: IEEE Std 952-1997 annex C (Allan variance noise model of a single-axis gyro):
//!   sigma^2(tau) = 3 Q^2/tau^2 + N^2/tau + (2 ln2/pi) B^2 + K^2 tau/3 + R^2 tau^2/2
//! with Q quantization (deg), N angle random walk (deg/sqrt(s)), B bias instability (deg/s),
//! K rate random walk (deg/s/sqrt(s)), R rate ramp (deg/s^2). Two extractions:
//! - slope lines (IEEE 952 annex C.2; the MathWorks "Inertial sensor noise analysis using Allan
//!   variance" example): the log-log segment whose slope is nearest -1, -1/2 (left of the
//!   minimum), +1/2, +1 (right of it) fixes a line of that exact slope, read at tau = 1 s for N,
//!   tau = 3 s for K, and through the point itself for Q and R; B = sigma_min / sqrt(2 ln2/pi)
//!   = sigma_min / 0.6643 at an interior minimum;
//! - a weighted least-squares fit of the five-term model to sigma^2 with non-negative
//!   coefficients (Lawson & Hanson, "Solving Least Squares Problems", 1974, ch. 23, NNLS), each
//!   point weighted by the inverse half-width of its confidence interval on the variance.
//!
//! Kalibr's IMU noise model (ethz-asl/kalibr wiki, "IMU Noise Model"): gyroscope_noise_density
//! = N in rad/s/sqrt(Hz), gyroscope_random_walk = K in rad/s^2/sqrt(Hz).

use crate::allan::{AllanCurve, AllanPoint, DeviationKind};
use crate::units;
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};
use statrs::distribution::ContinuousCDF;
use thiserror::Error;

/// sqrt(2 ln 2 / pi) = 0.6643: the flat-region Allan deviation per unit bias instability.
pub const BIAS_INSTABILITY_FACTOR: f64 = 0.664_282_470_267_960_1;

/// Model tolerance of a slope: a segment supports a target slope when its interval reaches
/// within this of the target (neighbouring terms bend the curve of a sum of terms).
pub const SLOPE_TOLERANCE: f64 = 0.1;

/// Weighted RMS residual above which the five-term fit is flagged as poor.
pub const FIT_RMS_LIMIT: f64 = 3.0;

/// Why noise terms could not be extracted.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum NoiseError {
    /// The curve is not an Allan-type deviation (ADEV, OADEV or TOTDEV).
    #[error("noise terms need an Allan-type deviation curve, got {0}")]
    WrongKind(&'static str),
    /// Fewer usable points (positive deviation, inside the tau range) than needed.
    #[error("{found} usable points, at least {needed} needed")]
    TooFewPoints {
        /// Points needed.
        needed: usize,
        /// Points found.
        found: usize,
    },
}

/// The five IEEE 952 noise coefficients in engineering and SI-like units; `None` where absent.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct NoiseCoefficients {
    /// Quantization noise Q in deg.
    pub quantization_deg: Option<f64>,
    /// Angle random walk N in deg/sqrt(s) (equal to the noise density in deg/s/sqrt(Hz)).
    pub arw_deg_rt_s: Option<f64>,
    /// Angle random walk N in deg/sqrt(h).
    pub arw_deg_rt_h: Option<f64>,
    /// Bias instability B in deg/s.
    pub bias_instability_dps: Option<f64>,
    /// Bias instability B in deg/h.
    pub bias_instability_dph: Option<f64>,
    /// Rate random walk K in deg/s/sqrt(s).
    pub rrw_deg_s_rt_s: Option<f64>,
    /// Rate random walk K in deg/h/sqrt(h).
    pub rrw_deg_h_rt_h: Option<f64>,
    /// Rate ramp R in deg/s per s.
    pub rate_ramp_dps_per_s: Option<f64>,
    /// Rate ramp R in deg/h per h.
    pub rate_ramp_dph_per_h: Option<f64>,
}

impl NoiseCoefficients {
    /// Builds the coefficients from Q (deg), N (deg/sqrt(s)), B (deg/s), K (deg/s/sqrt(s)), R (deg/s^2).
    pub fn from_base_units(q: Option<f64>, n: Option<f64>, b: Option<f64>, k: Option<f64>, r: Option<f64>) -> Self {
        NoiseCoefficients {
            quantization_deg: q,
            arw_deg_rt_s: n,
            arw_deg_rt_h: n.map(units::arw_deg_rt_s_to_deg_rt_h),
            bias_instability_dps: b,
            bias_instability_dph: b.map(units::bias_dps_to_dph),
            rrw_deg_s_rt_s: k,
            rrw_deg_h_rt_h: k.map(units::rrw_dps_rt_s_to_dph_rt_h),
            rate_ramp_dps_per_s: r,
            rate_ramp_dph_per_h: r.map(units::rate_ramp_dps_per_s_to_dph_per_h),
        }
    }

    /// Allan deviation (deg/s) the model predicts at tau (absent terms count as zero).
    pub fn model_deviation(&self, tau_s: f64) -> f64 {
        let q = self.quantization_deg.unwrap_or(0.0);
        let n = self.arw_deg_rt_s.unwrap_or(0.0);
        let b = self.bias_instability_dps.unwrap_or(0.0);
        let k = self.rrw_deg_s_rt_s.unwrap_or(0.0);
        let r = self.rate_ramp_dps_per_s.unwrap_or(0.0);
        let basis = model_basis(tau_s);
        (basis[0] * q * q + basis[1] * n * n + basis[2] * b * b + basis[3] * k * k + basis[4] * r * r).sqrt()
    }
}

/// Where a slope-line coefficient was read.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SlopeReading {
    /// Averaging time of the reading (the point the value was read at), s.
    pub tau_s: f64,
    /// Taus of the first and last point of the supported region, s.
    pub tau_range_s: (f64, f64),
    /// Log-log slope of the region (for K: of the curve's excess over the other terms).
    pub local_slope: f64,
}

/// Why a term is not given as a value.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Unresolved {
    /// No run of the curve supports the term's slope at the curve's confidence.
    NoSupportedRegion,
    /// The curve does not lie above the other terms by more than its confidence interval at two
    /// or more taus.
    NotAboveOtherTerms,
    /// The curve still falls at its longest tau: the term's region lies beyond a quarter of the
    /// record. `needed_record_s` is a lower limit of the record length that could resolve it.
    RecordTooShort {
        /// Record length, s, below which the term cannot be resolved.
        needed_record_s: f64,
    },
    /// The curve has no point to bound the term with.
    NoPoints,
}

impl Unresolved {
    /// Short machine-readable name (`no_supported_region`, ...).
    pub fn name(&self) -> &'static str {
        match self {
            Unresolved::NoSupportedRegion => "no_supported_region",
            Unresolved::NotAboveOtherTerms => "not_above_other_terms",
            Unresolved::RecordTooShort { .. } => "record_too_short",
            Unresolved::NoPoints => "no_points",
        }
    }

    /// Plain-language explanation.
    pub fn describe(&self) -> String {
        match self {
            Unresolved::NoSupportedRegion => "no region of the curve supports its slope".into(),
            Unresolved::NotAboveOtherTerms => "the curve does not rise above the other terms beyond its bounds".into(),
            Unresolved::RecordTooShort { needed_record_s } => {
                format!("record too short (needs more than {needed_record_s:.0} s)")
            }
            Unresolved::NoPoints => "no usable point".into(),
        }
    }
}

/// How a term is reported.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Basis {
    /// Read on a region of the curve that supports it.
    Value,
    /// Not resolved; the curve bounds it from above.
    UpperBound,
    /// Not resolved and not bounded.
    Absent,
}

impl Basis {
    /// `value`, `upper_bound` or `absent`.
    pub fn name(self) -> &'static str {
        match self {
            Basis::Value => "value",
            Basis::UpperBound => "upper_bound",
            Basis::Absent => "absent",
        }
    }
}

/// One noise term of the slope-line method, with its support. Values are in the term's base
/// unit: Q deg, N deg/sqrt(s), B and the Allan minimum deg/s, K deg/s/sqrt(s), R deg/s^2.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "basis", rename_all = "snake_case")]
pub enum Reading {
    /// Read on a region of the curve that supports the term at the curve's confidence.
    Value {
        /// The value.
        value: f64,
        /// Where it was read.
        site: SlopeReading,
    },
    /// Not resolved: the curve's upper confidence bound at `tau_s` bounds the term from above.
    UpperBound {
        /// The bound.
        value: f64,
        /// Tau at which the bound is tightest, s.
        tau_s: f64,
        /// Why no value is given.
        reason: Unresolved,
    },
    /// Neither resolved nor bounded.
    Absent {
        /// Why.
        reason: Unresolved,
    },
}

impl Reading {
    /// The value, when the term is resolved.
    pub fn value(&self) -> Option<f64> {
        match self {
            Reading::Value { value, .. } => Some(*value),
            _ => None,
        }
    }

    /// The upper bound, when the term is not resolved but bounded.
    pub fn bound(&self) -> Option<f64> {
        match self {
            Reading::UpperBound { value, .. } => Some(*value),
            _ => None,
        }
    }

    /// Where a resolved value was read.
    pub fn site(&self) -> Option<SlopeReading> {
        match self {
            Reading::Value { site, .. } => Some(*site),
            _ => None,
        }
    }

    /// The tau of the value or of the bound, s.
    pub fn tau_s(&self) -> Option<f64> {
        match self {
            Reading::Value { site, .. } => Some(site.tau_s),
            Reading::UpperBound { tau_s, .. } => Some(*tau_s),
            Reading::Absent { .. } => None,
        }
    }

    /// Why the term is not a value, if it is not.
    pub fn reason(&self) -> Option<Unresolved> {
        match self {
            Reading::Value { .. } => None,
            Reading::UpperBound { reason, .. } | Reading::Absent { reason } => Some(*reason),
        }
    }

    /// How the term is reported.
    pub fn basis(&self) -> Basis {
        match self {
            Reading::Value { .. } => Basis::Value,
            Reading::UpperBound { .. } => Basis::UpperBound,
            Reading::Absent { .. } => Basis::Absent,
        }
    }

    /// The same reading with its value (or bound) multiplied by `factor` (a unit conversion).
    pub fn scaled(&self, factor: f64) -> Reading {
        match *self {
            Reading::Value { value, site } => Reading::Value { value: value * factor, site },
            Reading::UpperBound { value, tau_s, reason } => {
                Reading::UpperBound { value: value * factor, tau_s, reason }
            }
            a @ Reading::Absent { .. } => a,
        }
    }
}

/// Result of the slope-line method.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SlopeLineResult {
    /// The resolved coefficients (values only; bounds are in the readings).
    pub coefficients: NoiseCoefficients,
    /// Quantization Q, deg (slope -1).
    pub quantization: Reading,
    /// Angle random walk N, deg/sqrt(s) (slope -1/2, line read at tau = 1 s).
    pub arw: Reading,
    /// Bias instability B in the IEEE 952 convention, deg/s: the Allan minimum of the flat
    /// region / 0.6643.
    pub bias_instability: Reading,
    /// The Allan deviation minimum of the flat region, deg/s (the figure ADI and Sensonor
    /// datasheets quote as bias instability); 0.6643 B.
    pub allan_minimum: Reading,
    /// Rate random walk K, deg/s/sqrt(s) (excess over the other terms, slope +1/2).
    pub rrw: Reading,
    /// Rate ramp R, deg/s^2 (slope +1).
    pub rate_ramp: Reading,
}

/// Quality flag of the five-term fit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FitQuality {
    /// Weighted RMS residual at most [`FIT_RMS_LIMIT`].
    Acceptable,
    /// Weighted RMS residual above [`FIT_RMS_LIMIT`]: the model does not describe the curve.
    Poor,
}

/// Result of the weighted least-squares fit of the five-term model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelFitResult {
    /// The coefficients (`None` for a term the non-negative fit set to zero).
    pub coefficients: NoiseCoefficients,
    /// Smallest and largest tau of the points fitted, s.
    pub tau_range_s: (f64, f64),
    /// Number of points fitted.
    pub points_used: usize,
    /// Root mean square of the weighted residuals (about 1 when the weights are right).
    pub weighted_rms_residual: f64,
    /// Poor when the weighted RMS residual exceeds [`FIT_RMS_LIMIT`].
    pub quality: FitQuality,
}

/// What a Kalibr entry holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum KalibrBasis {
    /// The resolved slope-line value.
    Value,
    /// The slope-line upper bound (the term is not resolved).
    UpperBound,
    /// The five-term fit's value (the term is neither resolved nor bounded).
    FitValue,
}

impl KalibrBasis {
    /// `value`, `upper_bound` or `fit_value`.
    pub fn name(self) -> &'static str {
        match self {
            KalibrBasis::Value => "value",
            KalibrBasis::UpperBound => "upper_bound",
            KalibrBasis::FitValue => "fit_value",
        }
    }
}

/// Kalibr `imu.yaml` gyroscope entries.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct KalibrGyroscope {
    /// N in rad/s/sqrt(Hz).
    pub gyroscope_noise_density: Option<f64>,
    /// K in rad/s^2/sqrt(Hz).
    pub gyroscope_random_walk: Option<f64>,
    /// What `gyroscope_noise_density` is.
    pub gyroscope_noise_density_basis: Option<KalibrBasis>,
    /// What `gyroscope_random_walk` is.
    pub gyroscope_random_walk_basis: Option<KalibrBasis>,
    /// Index of the channel each entry comes from, when channels were combined (noise density,
    /// random walk).
    pub channel_index: (usize, usize),
}

/// Kalibr's gyroscope entries from noise coefficients (both entries basis `value`).
pub fn kalibr_gyroscope(c: &NoiseCoefficients) -> KalibrGyroscope {
    let n = c.arw_deg_rt_s.map(units::arw_deg_rt_s_to_rad_s_rt_hz);
    let k = c.rrw_deg_s_rt_s.map(units::rrw_dps_rt_s_to_rad_s2_rt_hz);
    KalibrGyroscope {
        gyroscope_noise_density: n,
        gyroscope_random_walk: k,
        gyroscope_noise_density_basis: n.map(|_| KalibrBasis::Value),
        gyroscope_random_walk_basis: k.map(|_| KalibrBasis::Value),
        channel_index: (0, 0),
    }
}

/// Kalibr's gyroscope entries from the slope-line readings: the value when resolved, else the
/// upper bound, else the five-term fit's value; never zero or invented.
pub fn kalibr_from_readings(s: &SlopeLineResult, fit: Option<&ModelFitResult>) -> KalibrGyroscope {
    let pick = |r: &Reading, fit_value: Option<f64>| match r {
        Reading::Value { value, .. } => Some((*value, KalibrBasis::Value)),
        Reading::UpperBound { value, .. } => Some((*value, KalibrBasis::UpperBound)),
        Reading::Absent { .. } => fit_value.map(|v| (v, KalibrBasis::FitValue)),
    };
    let n = pick(&s.arw, fit.and_then(|f| f.coefficients.arw_deg_rt_s));
    let k = pick(&s.rrw, fit.and_then(|f| f.coefficients.rrw_deg_s_rt_s));
    KalibrGyroscope {
        gyroscope_noise_density: n.map(|x| units::arw_deg_rt_s_to_rad_s_rt_hz(x.0)),
        gyroscope_random_walk: k.map(|x| units::rrw_dps_rt_s_to_rad_s2_rt_hz(x.0)),
        gyroscope_noise_density_basis: n.map(|x| x.1),
        gyroscope_random_walk_basis: k.map(|x| x.1),
        channel_index: (0, 0),
    }
}

/// Kalibr `imu.yaml` accelerometer entries.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct KalibrAccelerometer {
    /// Velocity random walk as a noise density, m/s^2/sqrt(Hz) (= m/s/sqrt(s)).
    pub accelerometer_noise_density: Option<f64>,
    /// Acceleration random walk, m/s^3/sqrt(Hz) (= m/s^2/sqrt(s)).
    pub accelerometer_random_walk: Option<f64>,
    /// What `accelerometer_noise_density` is.
    pub accelerometer_noise_density_basis: Option<KalibrBasis>,
    /// What `accelerometer_random_walk` is.
    pub accelerometer_random_walk_basis: Option<KalibrBasis>,
    /// Index of the channel each entry comes from, when channels were combined.
    pub channel_index: (usize, usize),
}

/// Kalibr's accelerometer entries from the slope-line readings of an accelerometer curve in
/// m/s^2 (the same rule as [`kalibr_from_readings`]: value, else upper bound, else fit value).
/// The white-noise and random-walk terms of a curve in m/s^2 are already in Kalibr's units.
pub fn kalibr_accelerometer_from_readings(s: &SlopeLineResult, fit: Option<&ModelFitResult>) -> KalibrAccelerometer {
    // The gyro entries are the same terms converted deg -> rad; undo nothing: pick in base units.
    let g = kalibr_from_readings(s, fit);
    let back = |v: Option<f64>| v.map(units::rad_to_deg);
    KalibrAccelerometer {
        accelerometer_noise_density: back(g.gyroscope_noise_density),
        accelerometer_random_walk: back(g.gyroscope_random_walk),
        accelerometer_noise_density_basis: g.gyroscope_noise_density_basis,
        accelerometer_random_walk_basis: g.gyroscope_random_walk_basis,
        channel_index: (0, 0),
    }
}

/// Combines several accelerometer channels into Kalibr's single entries (the largest, as
/// [`combine_kalibr`]).
pub fn combine_kalibr_accelerometer(channels: &[KalibrAccelerometer]) -> KalibrAccelerometer {
    let as_gyro: Vec<KalibrGyroscope> = channels
        .iter()
        .map(|a| KalibrGyroscope {
            gyroscope_noise_density: a.accelerometer_noise_density,
            gyroscope_random_walk: a.accelerometer_random_walk,
            gyroscope_noise_density_basis: a.accelerometer_noise_density_basis,
            gyroscope_random_walk_basis: a.accelerometer_random_walk_basis,
            channel_index: a.channel_index,
        })
        .collect();
    let c = combine_kalibr(&as_gyro);
    KalibrAccelerometer {
        accelerometer_noise_density: c.gyroscope_noise_density,
        accelerometer_random_walk: c.gyroscope_random_walk,
        accelerometer_noise_density_basis: c.gyroscope_noise_density_basis,
        accelerometer_random_walk_basis: c.gyroscope_random_walk_basis,
        channel_index: c.channel_index,
    }
}

/// Combines several gyro channels into Kalibr's single entry per quantity: the largest value of
/// each entry over the channels (as ethz-asl allan_variance_ros does), with its basis and the
/// index of the channel it came from. Ties go to the first channel.
pub fn combine_kalibr(channels: &[KalibrGyroscope]) -> KalibrGyroscope {
    let mut out = KalibrGyroscope {
        gyroscope_noise_density: None,
        gyroscope_random_walk: None,
        gyroscope_noise_density_basis: None,
        gyroscope_random_walk_basis: None,
        channel_index: (0, 0),
    };
    for (i, c) in channels.iter().enumerate() {
        if let Some(v) = c.gyroscope_noise_density {
            if out.gyroscope_noise_density.is_none_or(|o| v > o) {
                out.gyroscope_noise_density = Some(v);
                out.gyroscope_noise_density_basis = c.gyroscope_noise_density_basis;
                out.channel_index.0 = i;
            }
        }
        if let Some(v) = c.gyroscope_random_walk {
            if out.gyroscope_random_walk.is_none_or(|o| v > o) {
                out.gyroscope_random_walk = Some(v);
                out.gyroscope_random_walk_basis = c.gyroscope_random_walk_basis;
                out.channel_index.1 = i;
            }
        }
    }
    out
}

/// Allan variance of each model term per unit coefficient squared: [3/tau^2, 1/tau, 2ln2/pi, tau/3, tau^2/2].
fn model_basis(tau: f64) -> [f64; 5] {
    [3.0 / (tau * tau), 1.0 / tau, BIAS_INSTABILITY_FACTOR * BIAS_INSTABILITY_FACTOR, tau / 3.0, tau * tau / 2.0]
}

fn usable_points(curve: &AllanCurve) -> Result<Vec<AllanPoint>, NoiseError> {
    if !matches!(curve.kind, DeviationKind::Oadev | DeviationKind::Adev | DeviationKind::Totdev) {
        return Err(NoiseError::WrongKind(curve.kind.name()));
    }
    let mut pts: Vec<AllanPoint> = curve
        .points
        .iter()
        .copied()
        .filter(|p| p.deviation > 0.0 && p.deviation.is_finite() && p.tau_s > 0.0)
        .collect();
    pts.sort_by(|a, b| a.tau_s.total_cmp(&b.tau_s));
    Ok(pts)
}

/// A curve point as the slope-line method uses it.
#[derive(Clone, Copy, Debug)]
struct Pt {
    tau: f64,
    dev: f64,
    /// Lower and upper bound of the deviation.
    lo: f64,
    hi: f64,
    /// Half-width of the interval of ln(deviation).
    h: f64,
    /// Standard deviation of ln(deviation): h over the normal quantile of the curve's
    /// confidence when the interval is the curve's, else h (z = 1).
    sd: f64,
}

/// The point's interval: its confidence bounds; else dev exp(-+ z / sqrt(2 edf)) with the EDF
/// (z = 1); else the EDF of `terms / m` independent terms (at least 1).
fn interval(p: &AllanPoint, z: f64) -> Pt {
    if let (Some(lo), Some(hi)) = (p.lower, p.upper) {
        if lo > 0.0 && hi >= lo && hi.is_finite() {
            let h = 0.5 * (hi / lo).ln();
            return Pt { tau: p.tau_s, dev: p.deviation, lo, hi, h, sd: h / z };
        }
    }
    let edf = p.edf.filter(|e| *e > 0.0).unwrap_or_else(|| (p.terms as f64 / p.m.max(1) as f64).max(1.0));
    let h = 1.0 / (2.0 * edf).sqrt();
    Pt { tau: p.tau_s, dev: p.deviation, lo: p.deviation * (-h).exp(), hi: p.deviation * h.exp(), h, sd: h }
}

/// Points at least an octave apart (the first point, then each next point at >= 2 x the last
/// kept tau): octave and decade lists are kept whole, denser lists thinned, so that every
/// segment spans at least a factor 2 in tau.
fn octave_points(pts: &[AllanPoint], z: f64) -> Vec<Pt> {
    let mut out: Vec<Pt> = Vec::new();
    for p in pts {
        if out.last().is_none_or(|l| p.tau_s >= 2.0 * l.tau * (1.0 - 1e-9)) {
            out.push(interval(p, z));
        }
    }
    out
}

/// Slope and slope half-width of the segment joining points a and b.
fn segment(a: &Pt, b: &Pt) -> (f64, f64) {
    let dl = (b.tau / a.tau).ln();
    ((b.dev / a.dev).ln() / dl, (a.h * a.h + b.h * b.h).sqrt() / dl)
}

/// Whether a segment of slope s and half-width w supports the target slope t: the interval
/// s +- w reaches t +- [`SLOPE_TOLERANCE`] and excludes the neighbouring noise types' slopes
/// t - 1/2 and t + 1/2.
fn supports(s: f64, w: f64, t: f64) -> bool {
    (s - t).abs() <= SLOPE_TOLERANCE + w && s - w > t - 0.5 && s + w < t + 0.5
}

/// Maximal runs (first segment, last segment) of consecutive segments supporting slope t, with
/// at least `min_segments` segments.
fn runs(seg: &[(f64, f64)], t: f64, min_segments: usize) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start: Option<usize> = None;
    for j in 0..=seg.len() {
        let ok = j < seg.len() && supports(seg[j].0, seg[j].1, t);
        match (ok, start) {
            (true, None) => start = Some(j),
            (false, Some(s0)) => {
                if j - s0 >= min_segments {
                    out.push((s0, j - 1));
                }
                start = None;
            }
            _ => {}
        }
    }
    out
}

/// Site of a run of segments (first, last) read at point `at`.
fn site(pts: &[Pt], run: (usize, usize), at: usize) -> SlopeReading {
    let (a, b) = (&pts[run.0], &pts[run.1 + 1]);
    SlopeReading { tau_s: pts[at].tau, tau_range_s: (a.tau, b.tau), local_slope: segment(a, b).0 }
}

/// Upper bound of a term from point `at`: g(upper confidence bound, tau). A term's line never
/// exceeds the curve, so sigma_hi(tau) bounds it at the stated confidence (one-sided).
fn bound_at(pts: &[Pt], at: usize, reason: Unresolved, g: impl Fn(f64, f64) -> f64) -> Reading {
    match pts.get(at).map(|p| (g(p.hi, p.tau), p.tau)) {
        Some((value, tau_s)) if value.is_finite() && value > 0.0 => Reading::UpperBound { value, tau_s, reason },
        _ => Reading::Absent { reason: Unresolved::NoPoints },
    }
}

/// Level of the goodness-of-fit test by which a simpler explanation of a region of the curve is
/// kept (a flat run without flicker, a rise without a random walk): 90 %.
pub const ALTERNATIVE_TEST_LEVEL: f64 = 0.9;

/// Whether one term of shape `g` (with the curve's other terms `others`, variance at each point)
/// explains a region of the curve: the least-squares coefficient c >= 0 of
/// sum ((ln sigma_i^2 - ln(others_i + c g(tau_i))) / s_i)^2, with s_i = 2 h_i / z the standard
/// deviation of ln sigma_i^2 (h_i the half-width of ln sigma at the curve's confidence, z its
/// normal quantile; `Pt::sd` is h_i / z), leaves a sum at or below the chi-square quantile at
/// [`ALTERNATIVE_TEST_LEVEL`] with n - 1 degrees of freedom (one coefficient fitted). Neighbouring
/// overlapping estimates are positively correlated, which makes the test lenient: it keeps the
/// simpler explanation more often than its level says, as an honest reading must.
fn one_term_explains(region: &[Pt], others: &dyn Fn(&Pt) -> f64, g: impl Fn(f64) -> f64) -> bool {
    if region.len() < 2 {
        return true;
    }
    let limit = crate::allan::chi_squared_quantile(ALTERNATIVE_TEST_LEVEL, (region.len() - 1) as f64);
    limit.is_some_and(|q| one_term_misfit(region, others, g) <= q)
}

/// The least sum of squares of [`one_term_explains`]: how far the best curve `others + c g`
/// (c >= 0) lies from the region's points, in their standard deviations.
fn one_term_misfit(region: &[Pt], others: &dyn Fn(&Pt) -> f64, g: impl Fn(f64) -> f64) -> f64 {
    let sum = |c: f64| -> f64 {
        region
            .iter()
            .map(|p| {
                let model = (others(p) + c * g(p.tau)).max(f64::MIN_POSITIVE);
                let sd = (2.0 * p.sd).max(1e-12);
                ((p.dev * p.dev).ln() - model.ln()).powi(2) / (sd * sd)
            })
            .sum()
    };
    // c on a log grid from the smallest to the largest one point alone asks, and 0; then golden
    // section around the best grid value.
    let scale: Vec<f64> =
        region.iter().map(|p| p.dev * p.dev / g(p.tau)).filter(|v| v.is_finite() && *v > 0.0).collect();
    let (lo, hi) = scale.iter().fold((f64::INFINITY, 0.0f64), |(a, b), &v| (a.min(v), b.max(v)));
    let mut best = (sum(0.0), 0.0);
    if lo.is_finite() && hi > 0.0 {
        let (l0, l1) = ((lo * 1e-3).ln(), (hi * 10.0).ln());
        let steps = 80;
        let mut at = 0;
        for i in 0..=steps {
            let c = (l0 + (l1 - l0) * i as f64 / steps as f64).exp();
            let v = sum(c);
            if v < best.0 {
                best = (v, c);
                at = i;
            }
        }
        if best.1 > 0.0 {
            let grid = |i: usize| l0 + (l1 - l0) * i.min(steps) as f64 / steps as f64;
            let (mut a, mut b) = (grid(at.saturating_sub(1)), grid(at + 1));
            let r = (5f64.sqrt() - 1.0) / 2.0;
            for _ in 0..40 {
                let (x1, x2) = (b - r * (b - a), a + r * (b - a));
                if sum(x1.exp()) < sum(x2.exp()) {
                    b = x2;
                } else {
                    a = x1;
                }
            }
            let v = sum((0.5 * (a + b)).exp());
            if v < best.0 {
                best = (v, (0.5 * (a + b)).exp());
            }
        }
    }
    best.0
}

/// Whether the points of a flat run are explained without a flicker floor: whether one curve
/// N^2/tau + K^2 tau/3 (white noise N and a rate random walk K >= 0), or one curve N^2/tau +
/// R^2 tau^2/2 (a rate ramp R >= 0), fits them ([`one_term_explains`]). Then the run is the
/// rounded bottom of the white noise meeting a random walk or a ramp, which a record too short or
/// too noisy to show its curvature makes look flat, and bias instability is not resolved there
/// (issue 55; docs/METHODS.md section 3, "Terms reported only where the record shows them").
fn explained_without_flicker(run: &[Pt], n: f64) -> bool {
    let white = |p: &Pt| n * n / p.tau;
    one_term_explains(run, &white, |tau| tau) || one_term_explains(run, &white, |tau| tau * tau)
}

/// Where a flat (flicker) region of level `flat_level` (deg/s) begins beside white noise `n`
/// (deg/sqrt(s)): the tau at which the white-noise line n / sqrt(tau) has fallen to half the flat
/// level, (2 n / flat_level)^2 s. The slope lines' reading of bias instability and
/// `gyrolab plan static` place B there alike (issue 55: one rule for both).
pub fn flat_start_tau_s(n: f64, flat_level: f64) -> f64 {
    (2.0 * n / flat_level).powi(2)
}

/// The shortest record in which the slope lines can read a flat run beginning at `tau_start_s`:
/// its [`FLAT_MIN_SEGMENTS`] + 1 octave points reach 2^FLAT_MIN_SEGMENTS x tau_start, and octave
/// taus reach a quarter of the record, so 4 x 2^FLAT_MIN_SEGMENTS x tau_start (32 tau_start).
pub fn flat_run_record_s(tau_start_s: f64) -> f64 {
    4.0 * (1u64 << FLAT_MIN_SEGMENTS) as f64 * tau_start_s
}

/// Minimum number of consecutive octave segments of slope 0 that make a flat (bias-instability)
/// region.
pub const FLAT_MIN_SEGMENTS: usize = 3;

/// Minimum number of taus at which the curve must lie above the other terms by more than its
/// interval for a rate random walk to be resolved.
pub const RRW_MIN_POINTS: usize = 2;

/// Slope-line method on an Allan deviation curve of a rate in deg/s, with the support rules of
/// docs/METHODS.md section 3: every term is a value only where the curve supports it at the
/// curve's confidence, else an upper bound (with the tau it bounds at) or absent.
pub fn slope_line_terms(curve: &AllanCurve) -> Result<SlopeLineResult, NoiseError> {
    let all = usable_points(curve)?;
    if all.len() < 2 {
        return Err(NoiseError::TooFewPoints { needed: 2, found: all.len() });
    }
    // The normal quantile of the curve's two-sided confidence: its bounds' half-width in
    // ln(deviation) over z is the standard deviation the alternatives' tests use.
    let z = curve
        .confidence
        .filter(|c| *c > 0.0 && *c < 1.0)
        .and_then(|c| statrs::distribution::Normal::new(0.0, 1.0).ok().map(|n| n.inverse_cdf(0.5 + c / 2.0)))
        .filter(|z| z.is_finite() && *z > 0.0)
        .unwrap_or(1.0);
    let pts = octave_points(&all, z);
    let seg: Vec<(f64, f64)> = pts.windows(2).map(|w| segment(&w[0], &w[1])).collect();
    let last = pts.len() - 1;
    let i_min = pts.iter().enumerate().min_by(|a, b| a.1.dev.total_cmp(&b.1.dev)).map_or(0, |(i, _)| i);
    // The curve has not turned: terms right of the minimum lie beyond the longest tau. Two more
    // octaves beyond it are needed, and taus reach a quarter of the record.
    let too_short = Unresolved::RecordTooShort { needed_record_s: 16.0 * pts[last].tau };
    let beyond = i_min == last;
    let sqrt3 = 3f64.sqrt();

    // N: the -1/2 run nearest tau = 1 s; read at its point nearest 1 s (extrapolating the line
    // to 1 s when 1 s lies outside the run).
    let near_one = |i: usize| pts[i].tau.ln().abs();
    let arw_runs = runs(&seg, -0.5, 1);
    let arw = arw_runs
        .iter()
        .min_by(|a, b| {
            let da = (a.0..=a.1 + 1).map(near_one).fold(f64::INFINITY, f64::min);
            let db = (b.0..=b.1 + 1).map(near_one).fold(f64::INFINITY, f64::min);
            da.total_cmp(&db)
        })
        .map(|&run| {
            let at = (run.0..=run.1 + 1).min_by(|&a, &b| near_one(a).total_cmp(&near_one(b))).unwrap_or(run.0);
            // the -1/2 line fitted (weights 1/h^2) to the run's points within three octaves of it
            let (mut sw, mut swl) = (0.0, 0.0);
            for p in &pts[run.0..=run.1 + 1] {
                if (p.tau / pts[at].tau).ln().abs() <= 3.0 * std::f64::consts::LN_2 * (1.0 + 1e-9) {
                    let wt = 1.0 / (p.h * p.h).max(1e-300);
                    sw += wt;
                    swl += wt * (p.dev * p.tau.sqrt()).ln();
                }
            }
            Reading::Value { value: (swl / sw).exp(), site: site(&pts, run, at) }
        })
        .unwrap_or_else(|| {
            let at = (0..pts.len()).min_by(|&a, &b| near_one(a).total_cmp(&near_one(b))).unwrap_or(0);
            bound_at(&pts, at, Unresolved::NoSupportedRegion, |hi, tau| hi * tau.sqrt())
        });

    // Q: the first -1 run (shortest taus), read at its first point; only left of the first
    // segment that supports a shallower slope (-1/2, 0, +1/2, +1) and not -1. The log-log slope
    // of a sum of the model's terms never decreases with tau, so a -1 run right of such a
    // segment is a chance dip of a noisy long-tau estimate, not quantization noise.
    let shallower = (0..seg.len())
        .find(|&j| {
            let (s, w) = seg[j];
            !supports(s, w, -1.0) && [-0.5, 0.0, 0.5, 1.0].iter().any(|&t| supports(s, w, t))
        })
        .unwrap_or(seg.len());
    let quantization = runs(&seg, -1.0, 1)
        .into_iter()
        .find(|r| r.1 < shallower)
        .map(|run| Reading::Value { value: pts[run.0].dev * pts[run.0].tau / sqrt3, site: site(&pts, run, run.0) })
        .unwrap_or_else(|| bound_at(&pts, 0, Unresolved::NoSupportedRegion, |hi, tau| hi * tau / sqrt3));

    // R: the last +1 run right of the minimum, read at its last point.
    let rate_ramp = runs(&seg, 1.0, 1)
        .into_iter()
        .rev()
        .find(|r| r.0 >= i_min)
        .map(|run| Reading::Value {
            value: pts[run.1 + 1].dev * 2f64.sqrt() / pts[run.1 + 1].tau,
            site: site(&pts, run, run.1 + 1),
        })
        .unwrap_or_else(|| {
            let reason = if beyond { too_short } else { Unresolved::NoSupportedRegion };
            bound_at(&pts, last, reason, |hi, tau| hi * 2f64.sqrt() / tau)
        });

    // B: a run of at least FLAT_MIN_SEGMENTS slope-0 segments lying above the N line (lower
    // bound above N / sqrt(tau)) at two or more of its points; of several, the one with the
    // largest total weight sum 1/h_i^2 (the best-determined). Its level F: weighted mean (weights
    // 1/h_i^2) of ln sqrt(sigma_i^2 - N^2/tau_i - K^2 tau_i/3) over the run, with the N line and
    // (in a second pass, once K is known) the K line removed. Allan minimum = F, read at the
    // run's lowest point; B = F / 0.6643.
    let n_val = arw.value();
    let above_n = |i: usize| n_val.is_none_or(|n| pts[i].lo > n / pts[i].tau.sqrt());
    let weight = |i: usize| 1.0 / (pts[i].h * pts[i].h).max(1e-300);
    let flat = runs(&seg, 0.0, FLAT_MIN_SEGMENTS)
        .into_iter()
        .filter(|r| (r.0..=r.1 + 1).filter(|&i| above_n(i)).count() >= 2)
        .filter(|r| !explained_without_flicker(&pts[r.0..=r.1 + 1], n_val.unwrap_or(0.0)))
        .map(|r| {
            let at = (r.0..=r.1 + 1).min_by(|&a, &b| pts[a].dev.total_cmp(&pts[b].dev)).unwrap_or(r.0);
            let total: f64 = (r.0..=r.1 + 1).map(weight).sum();
            (r, at, total)
        })
        .max_by(|a, b| a.2.total_cmp(&b.2))
        .map(|(r, at, _)| (r, at));
    let flat_level = |k: Option<f64>| {
        flat.map(|(r, _)| {
            let (mut sw, mut swl) = (0.0, 0.0);
            for p in &pts[r.0..=r.1 + 1] {
                let rest = n_val.map_or(0.0, |n| n * n / p.tau) + k.map_or(0.0, |k| k * k * p.tau / 3.0);
                let v = p.dev * p.dev - rest;
                if v > 0.0 {
                    let wt = 1.0 / (p.h * p.h).max(1e-300);
                    sw += wt;
                    swl += wt * 0.5 * v.ln();
                }
            }
            if sw > 0.0 {
                (swl / sw).exp()
            } else {
                pts[r.0..=r.1 + 1].iter().map(|p| p.dev).fold(f64::INFINITY, f64::min)
            }
        })
    };
    let level0 = flat_level(None);

    // K: right of the minimum (of the flat run when B is resolved), the curve's excess variance
    // over the resolved N, Q, B (its Allan minimum level) and R terms, where the lower bound
    // exceeds them; resolved at RRW_MIN_POINTS or more such taus whose excess slope is
    // consistent with +1/2. K = exp(weighted mean of ln K_i), weights 1/h_i^2.
    let floor = level0;
    let q_val = quantization.value();
    let r_val = rate_ramp.value();
    let others = |p: &Pt| {
        let mut v = 0.0;
        if let Some(n) = n_val {
            v += n * n / p.tau;
        }
        if let Some(q) = q_val {
            v += 3.0 * q * q / (p.tau * p.tau);
        }
        if let Some(f) = floor {
            v += f * f;
        }
        if let Some(r) = r_val {
            v += r * r * p.tau * p.tau / 2.0;
        }
        v
    };
    // Significance compares intervals: the point's lower bound against the other terms with the
    // flat level at its upper bound; only points after the flat run count.
    let floor_hi = flat.map(|f| level0.unwrap_or(0.0) * pts[f.1].h.exp());
    let others_hi = |p: &Pt| others(p) - floor.map_or(0.0, |f| f * f) + floor_hi.map_or(0.0, |f| f * f);
    let start = flat.map_or(i_min, |f| f.0 .1 + 1);
    let excess: Vec<(usize, f64)> = (start + 1..=last)
        .filter(|&i| pts[i].lo * pts[i].lo > others_hi(&pts[i]))
        .map(|i| (i, (pts[i].dev * pts[i].dev - others(&pts[i])).sqrt()))
        .collect();
    // Where the curve itself has supported +1/2 runs, K is read on their points only (there the
    // unresolved terms contribute least).
    let on_half: Vec<(usize, f64)> = {
        let half = runs(&seg, 0.5, 1);
        excess.iter().copied().filter(|&(i, _)| half.iter().any(|r| i >= r.0 && i <= r.1 + 1)).collect()
    };
    let excess = if on_half.len() >= RRW_MIN_POINTS { on_half } else { excess };
    let rrw = if excess.len() >= RRW_MIN_POINTS {
        let (ia, ea) = excess[0];
        let (ib, eb) = excess[excess.len() - 1];
        let (a, b) = (&pts[ia], &pts[ib]);
        let dl = (b.tau / a.tau).ln();
        let slope = (eb / ea).ln() / dl;
        let w = (a.h * a.h + b.h * b.h).sqrt() / dl;
        // Not resolved as K when, beside the other resolved terms, the rise right of the minimum
        // (or of the flat run) is explained as well by a flat floor (flicker; only where no flat
        // run is resolved: a resolved one has its level measured, and the rise after it is
        // compared with that level at its upper bound above), or by a ramp that fits it better
        // than a random walk does (a ramp not resolved as R).
        let region = &pts[start..=last];
        let ramp = |tau: f64| tau * tau;
        let explained = (flat.is_none() && one_term_explains(region, &others, |_| 1.0))
            || (one_term_explains(region, &others, ramp)
                && one_term_misfit(region, &others, ramp) < one_term_misfit(region, &others, |tau| tau));
        if (slope - 0.5).abs() <= SLOPE_TOLERANCE + w && !explained {
            let (mut sw, mut swl) = (0.0, 0.0);
            let mut best = (f64::INFINITY, ia);
            for &(i, e) in &excess {
                let wt = 1.0 / (pts[i].h * pts[i].h).max(1e-300);
                sw += wt;
                swl += wt * (e * (3.0 / pts[i].tau).sqrt()).ln();
                if pts[i].h < best.0 {
                    best = (pts[i].h, i);
                }
            }
            Reading::Value {
                value: (swl / sw).exp(),
                site: SlopeReading { tau_s: pts[best.1].tau, tau_range_s: (a.tau, b.tau), local_slope: slope },
            }
        } else {
            bound_at(&pts, last, Unresolved::NoSupportedRegion, |hi, tau| hi * (3.0 / tau).sqrt())
        }
    } else {
        let reason = if beyond { too_short } else { Unresolved::NotAboveOtherTerms };
        bound_at(&pts, last, reason, |hi, tau| hi * (3.0 / tau).sqrt())
    };

    let (allan_minimum, bias_instability) = match (flat, flat_level(rrw.value())) {
        (Some((run, at)), Some(level)) => {
            let s = site(&pts, run, at);
            (
                Reading::Value { value: level, site: s },
                Reading::Value { value: level / BIAS_INSTABILITY_FACTOR, site: s },
            )
        }
        _ => {
            // The curve has not turned: the record a flat run would need, from where the white
            // noise line falls to half the curve's minimum (the rule `gyrolab plan static` plans
            // by), the minimum taken at its upper bound so that the length stays a lower limit
            // (the flat level is at most the minimum). A record already as long shows no flat
            // run: the reason is then that, not its length. The record counts as far as the
            // curve's taus reach (octave taus reach between an eighth and a quarter of it; a tau
            // list cut short by the caller reaches less).
            let record_s = (curve.n_rate as f64 * curve.tau0_s).min(8.0 * pts[last].tau);
            let needed = n_val.map(|n| flat_run_record_s(flat_start_tau_s(n, pts[i_min].hi)));
            let reason = match needed {
                _ if !beyond => Unresolved::NoSupportedRegion,
                Some(need) if need <= record_s => Unresolved::NoSupportedRegion,
                Some(need) => Unresolved::RecordTooShort { needed_record_s: need },
                None => too_short,
            };
            let m = bound_at(&pts, i_min, reason, |hi, _| hi);
            (m, m.scaled(1.0 / BIAS_INSTABILITY_FACTOR))
        }
    };

    Ok(SlopeLineResult {
        coefficients: NoiseCoefficients::from_base_units(
            quantization.value(),
            arw.value(),
            bias_instability.value(),
            rrw.value(),
            rate_ramp.value(),
        ),
        quantization,
        arw,
        bias_instability,
        allan_minimum,
        rrw,
        rate_ramp,
    })
}

/// Standard uncertainty of a point's variance: half the width of its confidence interval on
/// sigma^2, else sigma^2 sqrt(2/edf), else sigma^2 itself (equal relative weights).
fn variance_uncertainty(p: &AllanPoint) -> f64 {
    let var = p.deviation * p.deviation;
    match (p.lower, p.upper, p.edf) {
        (Some(lo), Some(hi), _) if hi > lo => 0.5 * (hi * hi - lo * lo),
        (_, _, Some(edf)) if edf > 0.0 => var * (2.0 / edf).sqrt(),
        _ => var,
    }
}

/// Weighted least-squares fit of the five-term IEEE 952 model to sigma^2 over an optional tau
/// range (inclusive, s), with non-negative coefficients.
pub fn fit_noise_model(curve: &AllanCurve, tau_range_s: Option<(f64, f64)>) -> Result<ModelFitResult, NoiseError> {
    let pts: Vec<AllanPoint> = usable_points(curve)?
        .into_iter()
        .filter(|p| tau_range_s.is_none_or(|(lo, hi)| p.tau_s >= lo && p.tau_s <= hi))
        .collect();
    if pts.len() < 2 {
        return Err(NoiseError::TooFewPoints { needed: 2, found: pts.len() });
    }
    let rows = pts.len();
    let mut a = DMatrix::<f64>::zeros(rows, 5);
    let mut b = DVector::<f64>::zeros(rows);
    for (i, p) in pts.iter().enumerate() {
        let u = variance_uncertainty(p);
        let basis = model_basis(p.tau_s);
        for j in 0..5 {
            a[(i, j)] = basis[j] / u;
        }
        b[i] = p.deviation * p.deviation / u;
    }
    // scale columns to unit norm for conditioning (taus span decades)
    let scales: Vec<f64> = (0..5).map(|j| a.column(j).norm()).collect();
    for (j, &s) in scales.iter().enumerate() {
        if s > 0.0 {
            a.column_mut(j).scale_mut(1.0 / s);
        }
    }
    let x = nnls(&a, &b);
    let residual = &b - &a * &x;
    let coef: Vec<Option<f64>> =
        (0..5).map(|j| if x[j] > 0.0 && scales[j] > 0.0 { Some((x[j] / scales[j]).sqrt()) } else { None }).collect();
    let rms = (residual.norm_squared() / rows as f64).sqrt();
    Ok(ModelFitResult {
        coefficients: NoiseCoefficients::from_base_units(coef[0], coef[1], coef[2], coef[3], coef[4]),
        tau_range_s: (pts[0].tau_s, pts[rows - 1].tau_s),
        points_used: rows,
        weighted_rms_residual: rms,
        quality: if rms > FIT_RMS_LIMIT { FitQuality::Poor } else { FitQuality::Acceptable },
    })
}

/// Least squares restricted to the columns in `passive` (SVD solve); zeros elsewhere.
fn solve_on(a: &DMatrix<f64>, b: &DVector<f64>, passive: &[bool]) -> DVector<f64> {
    let cols: Vec<usize> = (0..a.ncols()).filter(|&j| passive[j]).collect();
    let mut z = DVector::zeros(a.ncols());
    if cols.is_empty() {
        return z;
    }
    let sub = a.select_columns(cols.iter());
    let svd = sub.svd(true, true);
    if let Ok(sol) = svd.solve(b, 1e-12) {
        for (k, &j) in cols.iter().enumerate() {
            z[j] = sol[k];
        }
    }
    z
}

/// Non-negative least squares min |A x - b|, x >= 0 (Lawson & Hanson's active-set algorithm).
fn nnls(a: &DMatrix<f64>, b: &DVector<f64>) -> DVector<f64> {
    let n = a.ncols();
    let mut x = DVector::zeros(n);
    let mut passive = vec![false; n];
    let tol = 1e-12 * a.norm() * b.norm().max(1e-300);
    for _ in 0..(3 * n + 10) {
        let w = a.transpose() * (b - a * &x);
        let candidate = (0..n).filter(|&j| !passive[j] && w[j] > tol).max_by(|&i, &j| w[i].total_cmp(&w[j]));
        let Some(j) = candidate else { break };
        passive[j] = true;
        for _ in 0..(3 * n + 10) {
            let z = solve_on(a, b, &passive);
            if (0..n).all(|k| !passive[k] || z[k] > 0.0) {
                x = z;
                break;
            }
            let mut step = 1.0f64;
            for k in 0..n {
                if passive[k] && z[k] <= 0.0 {
                    let denom = x[k] - z[k];
                    if denom > 0.0 {
                        step = step.min(x[k] / denom);
                    }
                }
            }
            x = &x + (z - &x) * step;
            for k in 0..n {
                if passive[k] && x[k] <= tol.max(0.0) {
                    passive[k] = false;
                    x[k] = 0.0;
                }
            }
        }
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::allan::{deviation_from_rate, AllanOptions};
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};

    /// White rate noise of density N plus a rate random walk of strength K, tau0 = 0.1 s.
    fn simulated_record(n_arw: f64, k_rrw: f64, samples: usize, seed: u64) -> Vec<f64> {
        let tau0: f64 = 0.1;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let mut walk = 0.0;
        let mut v = Vec::with_capacity(samples + 1);
        for _ in 0..samples {
            let w: f64 = StandardNormal.sample(&mut rng);
            let r: f64 = StandardNormal.sample(&mut rng);
            walk += k_rrw * tau0.sqrt() * r;
            v.push(1.0 + n_arw / tau0.sqrt() * w + walk);
        }
        v
    }

    #[test]
    fn recovers_arw_and_rrw_of_a_simulated_record() {
        // N = 1e-3 deg/sqrt(s) (0.06 deg/sqrt(h)), K = 5e-5 deg/s/sqrt(s) (10.8 deg/h/sqrt(h)),
        // 1e6 samples at 10 Hz (27.8 h): the two lines cross at tau = sqrt(3) N/K = 35 s.
        let (n_true, k_true) = (1e-3, 5e-5);
        let curve =
            deviation_from_rate(simulated_record(n_true, k_true, 1_000_000, 3), 0.1, &AllanOptions::default()).unwrap();
        let slope = slope_line_terms(&curve).unwrap();
        let c = slope.coefficients;
        let n = c.arw_deg_rt_s.unwrap();
        let k = c.rrw_deg_s_rt_s.unwrap();
        assert!((n / n_true - 1.0).abs() < 0.05, "slope-line N {n} vs {n_true}");
        assert!((k / k_true - 1.0).abs() < 0.25, "slope-line K {k} vs {k_true}");
        assert!(slope.arw.site().unwrap().tau_s < 35.0 && slope.rrw.site().unwrap().tau_s > 35.0);
        assert!(slope.quantization.value().is_none() && slope.rate_ramp.value().is_none());
        assert!(slope.bias_instability.value().is_none(), "no flicker simulated: {:?}", slope.bias_instability);
        assert!((c.arw_deg_rt_h.unwrap() - 60.0 * n).abs() < 1e-12);
        let fit = fit_noise_model(&curve, None).unwrap();
        let f = fit.coefficients;
        let n = f.arw_deg_rt_s.unwrap();
        let k = f.rrw_deg_s_rt_s.unwrap();
        assert!((n / n_true - 1.0).abs() < 0.05, "fit N {n} vs {n_true}");
        assert!((k / k_true - 1.0).abs() < 0.25, "fit K {k} vs {k_true}");
        assert!(f.quantization_deg.is_none_or(|q| q < 0.1 * n_true * 0.1f64.sqrt()));
        let kal = kalibr_gyroscope(&f);
        assert!((kal.gyroscope_noise_density.unwrap() - n.to_radians()).abs() < 1e-15);
        assert!((kal.gyroscope_random_walk.unwrap() - k.to_radians()).abs() < 1e-15);
    }

    #[test]
    fn slope_lines_on_an_exact_model_curve() {
        // Curve sampled from the model itself: each coefficient must come back (to the bias of
        // reading a line where neighbouring terms still contribute).
        let truth = NoiseCoefficients::from_base_units(None, Some(2e-3), Some(1e-4), Some(1e-6), None);
        let points = (0..30)
            .map(|i| {
                let tau = 0.01 * 2f64.powi(i);
                AllanPoint {
                    m: 1 << i,
                    tau_s: tau,
                    deviation: truth.model_deviation(tau),
                    terms: 100,
                    alpha: None,
                    noise_id: None,
                    // an exact curve: very many degrees of freedom
                    edf: Some(1e6),
                    lower: None,
                    upper: None,
                }
            })
            .collect();
        let curve = AllanCurve { kind: DeviationKind::Oadev, tau0_s: 0.01, n_rate: 1 << 32, confidence: None, points };
        let r = slope_line_terms(&curve).unwrap();
        let s = r.coefficients;
        let n = s.arw_deg_rt_s.unwrap();
        assert!((n / 2e-3 - 1.0).abs() < 0.05, "N {n}");
        // The N and K lines meet near the B level: only two octave segments have a slope within
        // 0.11 of 0 (hand computation of the model: -0.107, +0.012, +0.130), no flat region of
        // three. B is therefore an upper bound (the minimum's upper bound / 0.6643), above the truth.
        assert!(s.bias_instability_dps.is_none());
        let b = r.bias_instability.bound().unwrap();
        assert!(b > 1e-4 && b < 1.3e-4, "B bound {b}");
        let k = s.rrw_deg_s_rt_s.unwrap();
        assert!((k / 1e-6 - 1.0).abs() < 0.05, "K {k}");
        let fit = fit_noise_model(&curve, None).unwrap().coefficients;
        assert!((fit.arw_deg_rt_s.unwrap() / 2e-3 - 1.0).abs() < 1e-6);
        assert!((fit.bias_instability_dps.unwrap() / 1e-4 - 1.0).abs() < 1e-6);
        assert!((fit.rrw_deg_s_rt_s.unwrap() / 1e-6 - 1.0).abs() < 1e-6);
        assert!((fit.bias_instability_dph.unwrap() - 0.36).abs() < 1e-6);
    }

    #[test]
    fn rejects_curves_that_are_not_allan_type() {
        let curve = AllanCurve { kind: DeviationKind::Tdev, tau0_s: 1.0, n_rate: 10, confidence: None, points: vec![] };
        assert_eq!(slope_line_terms(&curve), Err(NoiseError::WrongKind("tdev")));
        let curve = AllanCurve { kind: DeviationKind::Oadev, ..curve };
        assert!(matches!(fit_noise_model(&curve, None), Err(NoiseError::TooFewPoints { .. })));
    }

    fn curve_from(taus: &[f64], devs: &[f64]) -> AllanCurve {
        let points = taus
            .iter()
            .zip(devs)
            .map(|(&tau_s, &deviation)| AllanPoint {
                m: tau_s as usize,
                tau_s,
                deviation,
                terms: 100,
                alpha: None,
                noise_id: None,
                edf: Some(100.0),
                lower: None,
                upper: None,
            })
            .collect();
        AllanCurve { kind: DeviationKind::Oadev, tau0_s: 1.0, n_rate: 1 << 20, confidence: None, points }
    }

    #[test]
    fn a_single_rising_segment_at_the_end_is_not_rate_random_walk() {
        // A flat (flicker) curve whose last octave rises with slope +1/2 by chance.
        let mut taus = Vec::new();
        let mut devs = Vec::new();
        for k in 0..12 {
            let tau = 2f64.powi(k);
            taus.push(tau);
            devs.push(if k < 11 { 1e-3 } else { 1e-3 * 2f64.sqrt() });
        }
        let curve = curve_from(&taus, &devs);
        let r = slope_line_terms(&curve).unwrap();
        assert!(r.rrw.value().is_none(), "{:?}", r.rrw);
        // ... it is an upper bound from the last point: 1.414e-3 exp(h) sqrt(3 / 2048), h = 1/sqrt(200)
        let hand = 1e-3 * 2f64.sqrt() * (1.0 / 200f64.sqrt()).exp() * (3.0f64 / 2048.0).sqrt();
        assert!((r.rrw.bound().unwrap() / hand - 1.0).abs() < 1e-12, "{:?}", r.rrw);
        assert_eq!(r.rrw.tau_s(), Some(2048.0));
        // A flat level plus a rate random walk, sigma^2 = F^2 + K^2 tau / 3 with F = 1e-3 and
        // K^2 128 / 3 = F^2 (the K line meets the flat level at tau = 128 s), is resolved: B and K
        // within 5 % of F / 0.6643 and F sqrt(3 / 128).
        let k_true = 1e-3 * (3.0f64 / 128.0).sqrt();
        let devs: Vec<f64> = taus.iter().map(|&t| (1e-6 + k_true * k_true * t / 3.0).sqrt()).collect();
        let r = slope_line_terms(&curve_from(&taus, &devs)).unwrap();
        let k = r.rrw.value().unwrap_or_else(|| panic!("K not resolved: {r:#?}"));
        assert!((k / k_true - 1.0).abs() < 0.05, "{k} {:?}", r.rrw);
        let b = r.bias_instability.value().expect("B resolved");
        assert!((b * BIAS_INSTABILITY_FACTOR / 1e-3 - 1.0).abs() < 0.05, "{b}");
    }
}
