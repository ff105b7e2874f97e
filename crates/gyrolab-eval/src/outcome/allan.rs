//! The outcome of an Allan-variance analysis of one channel: its curve, noise terms, GMWM (computed
//! when first asked for), stillness, gravity and temperature checks.

use gyrolab::allan::AllanCurve;
use gyrolab::noise::{ModelFitResult, SlopeLineResult};
use gyrolab::units::Quantity;

/// The largest Allan deviation of a flat curve, in the channel's unit: far below any sensor's
/// noise, above the rounding of a constant record's angle sums.
pub const FLAT_DEVIATION: f64 = 1e-9;

/// One analysed channel.
#[derive(Debug, Clone)]
pub struct ChannelAnalysis {
    /// Source file.
    pub file: String,
    /// The topic of a recording (MCAP, ROS 1 bag, ULog) the channel belongs to.
    pub topic: Option<String>,
    /// Channel name.
    pub channel: String,
    /// Unit of the rate data analysed: `deg/s` when calibrated, `m/s^2` for an accelerometer,
    /// else the output unit.
    pub rate_unit: String,
    /// What the analysed data measure: [`Quantity::AngularRate`] (deg/s) or
    /// [`Quantity::Acceleration`] (m/s^2) when noise terms are given; else the raw output.
    pub quantity: Quantity,
    /// The curve.
    pub curve: AllanCurve,
    /// Noise terms by slope lines (only for data in deg/s).
    pub slope_lines: Option<SlopeLineResult>,
    /// Noise terms by the weighted five-term fit (only for data in deg/s).
    pub model_fit: Option<ModelFitResult>,
    /// Why noise terms are missing, if they are.
    pub noise_note: Option<String>,
    /// The GMWM fit (model chosen by its criterion), beside the slope lines and the five-term
    /// fit: computed when first asked for ([`ChannelAnalysis::gmwm`]), so that outputs without it
    /// (batch tables, Python calls that read no GMWM attribute) do not pay for it.
    pub gmwm: LazyGmwm,
    /// The stillness check of the channel (`None`: no rule for its quantity: not a gyro in
    /// deg/s nor an accelerometer in m/s^2).
    pub stillness: Option<gyrolab::stillness::StillnessCheck>,
    /// The analysis of a channel that moved was asked for (`--allow-motion`, `allow_motion=True`).
    pub allow_motion: bool,
    /// The gravity check of the three accelerometer axes this channel is one of (the same on
    /// each of them; `None` unless a record has exactly three accelerometer channels in m/s^2).
    pub gravity: Option<gyrolab::stillness::GravityCheck>,
    /// The record's temperature (the same on every channel of the record), when it has a
    /// temperature column.
    pub temperature: Option<gyrolab::record_temperature::RecordTemperature>,
}

/// A channel's GMWM fit, computed from its curve the first time it is asked for and kept
/// (thread-safe): the GMWM is the costliest part of an analysis of a short record (issue 56).
#[derive(Debug, Clone, Default)]
pub struct LazyGmwm {
    /// The confidence of its intervals; `None`: no GMWM for this channel (not a calibrated
    /// rate or acceleration, or not an Allan deviation).
    confidence: Option<f64>,
    fit: std::sync::OnceLock<Option<gyrolab::gmwm::GmwmFit>>,
}

impl LazyGmwm {
    /// A GMWM to compute with intervals at `confidence` when asked for.
    pub fn at_confidence(confidence: f64) -> LazyGmwm {
        LazyGmwm { confidence: Some(confidence), fit: std::sync::OnceLock::new() }
    }

    /// No GMWM for this channel.
    pub fn none() -> LazyGmwm {
        LazyGmwm::default()
    }

    /// The fit of `curve` (computed on the first call), `None` when the channel has no GMWM or
    /// the fit failed.
    pub fn get(&self, curve: &AllanCurve) -> Option<&gyrolab::gmwm::GmwmFit> {
        let confidence = self.confidence?;
        if let Some(fit) = self.fit.get() {
            return fit.as_ref();
        }
        // Computed outside the cell: the fit runs rayon work, and a rayon worker waiting in it
        // may take up another caller's request for this same fit (a `get_or_init` would then
        // re-enter the cell it is filling). Two callers at once both compute it (the same fit,
        // deterministically); the first stored is kept.
        let fit = gyrolab::gmwm::gmwm(curve, confidence).ok();
        let _ = self.fit.set(fit);
        self.fit.get().and_then(Option::as_ref)
    }
}

impl ChannelAnalysis {
    /// Whether the channel's curve is flat at zero: every deviation at or below
    /// [`FLAT_DEVIATION`] (every sample has the same value).
    pub fn is_flat(&self) -> bool {
        !self.curve.points.is_empty() && self.curve.points.iter().all(|p| p.deviation.abs() <= FLAT_DEVIATION)
    }

    /// A warning for a flat channel, or a hint for a channel left in output units (no noise
    /// terms), as a line (`warning: ...`, `hint: ...`); `None` otherwise.
    pub fn advice(&self) -> Option<String> {
        if self.is_flat() {
            Some(format!(
                "warning: {} ({}): every sample has the same value (the Allan deviation is 0 at every tau): no \
                 noise term can be read from a record without noise; a stuck sensor, or a simulation without \
                 noise terms?",
                self.file, self.channel
            ))
        } else if self.slope_lines.is_none() && self.quantity == Quantity::SensorOutput {
            Some(format!(
                "hint: {} ({}): the data are in {}: give --scale-factor K (output units per deg/s) and --null F, \
                 or --cal FILE.toml (from `gyrolab rate --cal-out`), for noise terms in deg units",
                self.file, self.channel, self.rate_unit
            ))
        } else {
            None
        }
    }
    /// The GMWM fit of the channel's curve, computed on the first call ([`LazyGmwm`]).
    pub fn gmwm(&self) -> Option<&gyrolab::gmwm::GmwmFit> {
        self.gmwm.get(&self.curve)
    }

    /// The line marking a channel that moved: `MOTION: the record is not static: FILE (CHANNEL)
    /// moved in ...: noise terms are not a still sensor's`; `None` when it did not move.
    pub fn motion_line(&self) -> Option<String> {
        let summary = self.stillness.as_ref()?.motion_summary()?;
        let topic = self.topic.as_ref().map_or(String::new(), |t| format!(" topic {t}"));
        Some(format!(
            "MOTION: the record is not static: {}{topic} ({}) {summary}: noise terms are not a still sensor's",
            self.file, self.channel
        ))
    }
}
