//! Reports of Allan-variance analyses: the deviation table, CSV, JSON (keys in docs/JSON.md),
//! the noise-coefficient summary and Kalibr's imu.yaml gyroscope entries.

use comfy_table::{presets::UTF8_FULL_CONDENSED, Cell, CellAlignment, Table};
use gyrolab::format::{short, sig, sig_opt};
use gyrolab::noise::{
    combine_kalibr, combine_kalibr_accelerometer, kalibr_accelerometer_from_readings, kalibr_from_readings, FitQuality,
    KalibrAccelerometer, KalibrBasis, KalibrGyroscope, NoiseCoefficients, Reading, SlopeLineResult, Unresolved,
    FIT_RMS_LIMIT,
};
use gyrolab::units::{self, Quantity};
use gyrolab_eval::outcome::allan::ChannelAnalysis;

/// sqrt(2 ln 2 / pi): Allan minimum per unit IEEE bias instability.
const BIAS_FACTOR: f64 = gyrolab::noise::BIAS_INSTABILITY_FACTOR;
use serde::Serialize;

/// The stillness check in JSON: the check's keys (levels in `rule.unit`, times in s from the
/// record start) and whether motion was allowed.
#[derive(Debug, Clone, Serialize)]
pub struct StillnessJson {
    /// The check.
    #[serde(flatten)]
    pub check: gyrolab::stillness::StillnessCheck,
    /// The analysis of a channel that moved was asked for.
    pub allow_motion: bool,
    /// The `MOTION: the record is not static: ...` line every output of a channel that moved
    /// carries (absent when it did not move).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub motion: Option<String>,
}

/// One GMWM parameter in JSON.
#[derive(Debug, Clone, Serialize)]
pub struct GmwmParameterJson {
    /// `quantization`, `white`, `flicker`, `random_walk`, `drift` or `gauss_markov`.
    pub process: &'static str,
    /// The coefficient, in `unit` (for `gauss_markov` its stationary standard deviation sigma).
    pub value: f64,
    /// Lower end of the two-sided interval at the fit's confidence.
    pub lower: f64,
    /// Upper end of the two-sided interval.
    pub upper: f64,
    /// The coefficient's unit (Q deg, N deg/sqrt(s), B deg/s, K deg/s/sqrt(s), R deg/s^2, a
    /// Gauss-Markov sigma deg/s for a gyro in deg/s; m/s, m/s/sqrt(s), m/s^2, m/s^2/sqrt(s), m/s^3,
    /// m/s^2 for an accelerometer).
    pub unit: &'static str,
    /// A Gauss-Markov process's correlation time T, s (absent for the other processes).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub correlation_time_s: Option<f64>,
    /// Lower end of T's two-sided interval at the fit's confidence, s (from the interval on ln T).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub correlation_time_lower_s: Option<f64>,
    /// Upper end of T's two-sided interval, s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub correlation_time_upper_s: Option<f64>,
    /// True when T sits at an end of the range searched (the first or last tau): the record does
    /// not resolve it and its interval means nothing.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub correlation_time_at_search_edge: Option<bool>,
    /// The summed weight (0 to 1) of the candidate models holding this process (for
    /// `gauss_markov`: holding one), exp(-criterion / 2) normalised over the candidates the nesting
    /// rule leaves (a candidate with a simpler nested one of criterion as small is dropped); the
    /// linear processes' intervals are averaged over the candidates with these weights
    /// (docs/METHODS.md 3.1).
    pub model_weight: f64,
}

/// A process the chosen GMWM model leaves out, with its upper bound given that it is there.
#[derive(Debug, Clone, Serialize)]
pub struct GmwmBoundJson {
    /// `quantization`, `white`, `flicker`, `random_walk` or `drift`.
    pub process: &'static str,
    /// The upper bound of its coefficient, in `unit`.
    pub upper: f64,
    /// The coefficient's unit.
    pub unit: &'static str,
    /// One-sided confidence of the bound, 1 - (1 - confidence) / 2 (0.8415 for 0.683), nominal
    /// (in simulation such bounds held the truth less often; docs/METHODS.md 3.1).
    pub confidence_one_sided: f64,
    /// The summed weight of the candidate models holding the process, every candidate with its
    /// plain weight (the nesting rule not applied, as for the bound itself).
    pub model_weight: f64,
}

/// The GMWM fit in JSON.
#[derive(Debug, Clone, Serialize)]
pub struct GmwmJson {
    /// Confidence level of the intervals.
    pub confidence: f64,
    /// Always `two-sided`.
    pub sided: &'static str,
    /// How the intervals are made and what they are worth (asymptotic, scales taken as
    /// correlated as the fitted model makes them; their simulated coverage: docs/METHODS.md 3.1).
    pub intervals: &'static str,
    /// The parameters of the chosen model.
    pub parameters: Vec<GmwmParameterJson>,
    /// Processes the chosen model leaves out but candidate models hold: an upper bound for each
    /// given that it is there (one-sided; the mixture of the candidates holding it, their weights
    /// renormalised), with the weight of those candidates.
    pub left_out: Vec<GmwmBoundJson>,
    /// Scales (octave taus) used.
    pub scales: usize,
    /// The objective at the estimate.
    pub objective: f64,
    /// The objective's estimated optimism, 2 tr(Omega H Sigma) (docs/METHODS.md 3.1).
    pub optimism: f64,
    /// The model-choice criterion (wavelet information criterion), objective + optimism.
    pub criterion: f64,
    /// The weighted RMS residual sqrt(objective / scales) (about 1 when the model describes the
    /// curve).
    pub weighted_rms_residual: f64,
    /// `acceptable`, or `poor` when the weighted RMS residual exceeds 3: no model searched
    /// describes the curve, and the parameters are not to be used.
    pub quality: gyrolab::noise::FitQuality,
}

/// What the GMWM intervals are (text and JSON).
pub const GMWM_INTERVALS: &str =
    "asymptotic: sandwich covariance with the wavelet variances correlated across scales as the fitted model makes them (Percival and Walden 2000, ch. 8), the linear processes' intervals averaged over the candidate models by their criterion weights (MATA-Wald, Turek and Fletcher 2012), a candidate dropped where a simpler one nested in it has a criterion as small (the nesting rule, Richards 2008); simulated coverage in docs/METHODS.md 3.1";

/// The unit of a GMWM coefficient for the curve's quantity.
pub fn gmwm_unit(process: gyrolab::gmwm::Process, quantity: Quantity) -> &'static str {
    use gyrolab::gmwm::Process as P;
    let accel = quantity == Quantity::Acceleration;
    match (process, accel) {
        (P::Quantization, false) => "deg",
        (P::White, false) => "deg/sqrt(s)",
        (P::Flicker, false) => "deg/s",
        (P::RandomWalk, false) => "deg/s/sqrt(s)",
        (P::Drift, false) => "deg/s^2",
        (P::GaussMarkov, false) => "deg/s",
        (P::Quantization, true) => "m/s",
        (P::White, true) => "m/s/sqrt(s)",
        (P::Flicker, true) => "m/s^2",
        (P::RandomWalk, true) => "m/s^2/sqrt(s)",
        (P::Drift, true) => "m/s^3",
        (P::GaussMarkov, true) => "m/s^2",
    }
}

/// The GMWM fit of a channel in JSON.
pub fn gmwm_json(a: &ChannelAnalysis) -> Option<GmwmJson> {
    let g = a.gmwm()?;
    Some(GmwmJson {
        confidence: g.confidence,
        sided: "two-sided",
        intervals: GMWM_INTERVALS,
        parameters: g
            .parameters
            .iter()
            .map(|p| GmwmParameterJson {
                process: p.process.name(),
                value: p.value,
                lower: p.lower,
                upper: p.upper,
                unit: gmwm_unit(p.process, a.quantity),
                correlation_time_s: p.correlation_time.map(|t| t.value_s),
                correlation_time_lower_s: p.correlation_time.map(|t| t.lower_s),
                correlation_time_upper_s: p.correlation_time.map(|t| t.upper_s),
                correlation_time_at_search_edge: p.correlation_time.map(|t| t.at_search_edge),
                model_weight: p.model_weight,
            })
            .collect(),
        left_out: g
            .left_out
            .iter()
            .map(|b| GmwmBoundJson {
                process: b.process.name(),
                upper: b.upper,
                unit: gmwm_unit(b.process, a.quantity),
                confidence_one_sided: 1.0 - (1.0 - g.confidence) / 2.0,
                model_weight: b.model_weight,
            })
            .collect(),
        scales: g.scales,
        objective: g.objective,
        optimism: g.optimism,
        criterion: g.criterion,
        weighted_rms_residual: g.weighted_rms_residual,
        quality: g.quality,
    })
}

/// The GMWM line of the text report.
pub fn gmwm_text(a: &ChannelAnalysis) -> Option<String> {
    let g = a.gmwm()?;
    let parts: Vec<String> = g
        .parameters
        .iter()
        .map(|p| {
            let main = format!(
                "{} {}{} [{}, {}] {}",
                p.process.name(),
                if p.correlation_time.is_some() { "sigma " } else { "" },
                sig(p.value, 4),
                sig(p.lower, 3),
                sig(p.upper, 3),
                gmwm_unit(p.process, a.quantity)
            );
            match p.correlation_time {
                Some(t) if t.at_search_edge => {
                    format!("{main}, T {} s (at the edge of the taus searched: not resolved)", sig(t.value_s, 3))
                }
                Some(t) => format!("{main}, T {} [{}, {}] s", sig(t.value_s, 3), sig(t.lower_s, 3), sig(t.upper_s, 3)),
                None => main,
            }
        })
        .collect();
    let left_out: String = g
        .left_out
        .iter()
        .map(|b| {
            format!(
                "; left out by the chosen model: {} < {} {} if present (one-sided {} % nominal, held less often in simulation; models holding it weigh {} %)",
                b.process.name(),
                sig(b.upper, 3),
                gmwm_unit(b.process, a.quantity),
                short(100.0 * (1.0 - (1.0 - g.confidence) / 2.0), 4),
                if b.model_weight < 5e-5 { "below 0.01".to_string() } else { short(100.0 * b.model_weight, 2) }
            )
        })
        .collect();
    let mut text = format!(
        "GMWM (Haar wavelet variance, model chosen by the wavelet information criterion over {} scales; {} % two-sided intervals, {}): {}{}; weighted RMS residual {}\n",
        g.scales,
        short(100.0 * g.confidence, 4),
        GMWM_INTERVALS,
        parts.join("; "),
        left_out,
        sig(g.weighted_rms_residual, 3)
    );
    if g.quality == FitQuality::Poor {
        text.push_str(&format!(
            "warning: GMWM POOR FIT: the weighted RMS residual exceeds {}: no model of the processes searched describes this curve; do not use its values\n",
            short(FIT_RMS_LIMIT, 3)
        ));
    }
    Some(text)
}

/// Noise coefficients in JSON, each key naming its unit.
#[derive(Debug, Clone, Serialize)]
pub struct NoiseJson {
    /// Angle random walk N, deg/sqrt(h).
    pub arw_deg_rt_h: Option<f64>,
    /// Bias instability B in the IEEE 952 convention, deg/h (Allan minimum of the flat region
    /// / 0.6643); null unless resolved.
    pub bias_instability_dph: Option<f64>,
    /// The Allan deviation minimum of the flat region, deg/h (the ADI / Sensonor datasheet
    /// convention; 0.6643 x `bias_instability_dph`); null unless resolved.
    pub allan_minimum_dph: Option<f64>,
    /// Tau of the Allan minimum, s; null unless resolved.
    pub allan_minimum_tau_s: Option<f64>,
    /// Rate random walk K, deg/h/sqrt(h).
    pub rrw_deg_h_rt_h: Option<f64>,
    /// Quantization noise Q, deg.
    pub quantization_deg: Option<f64>,
    /// Rate ramp R, deg/h per hour.
    pub rate_ramp_dph_per_h: Option<f64>,
    /// N as a noise density, deg/s/sqrt(Hz) (= deg/sqrt(s)).
    pub arw_deg_rt_s: Option<f64>,
    /// K, deg/s/sqrt(s).
    pub rrw_deg_s_rt_s: Option<f64>,
    /// Every slope-line term with its basis (`value`, `upper_bound`, `absent`), where it was
    /// read or bounded, and why it is not a value.
    pub readings: Vec<ReadingJson>,
    /// The weighted least-squares fit of the five-term model.
    pub fit: Option<FitJson>,
    /// Kalibr imu.yaml gyroscope entries (rad units) with their basis (`value`, `upper_bound`,
    /// `fit_value`).
    pub kalibr: KalibrGyroscope,
}

/// Accelerometer noise coefficients in JSON (a channel in m/s^2), each key naming its unit
/// (IEEE Std 1293 terms: velocity random walk, bias instability, acceleration random walk).
#[derive(Debug, Clone, Serialize)]
pub struct AccelNoiseJson {
    /// Velocity random walk, m/s/sqrt(h).
    pub vrw_m_s_rt_h: Option<f64>,
    /// Velocity random walk as a noise density, m/s^2/sqrt(Hz) (= m/s/sqrt(s)).
    pub vrw_m_s2_rt_hz: Option<f64>,
    /// Bias instability in the IEEE convention (Allan minimum / 0.6643), m/s^2.
    pub bias_instability_m_s2: Option<f64>,
    /// The same in micro-g.
    pub bias_instability_ug: Option<f64>,
    /// The Allan deviation minimum of the flat region (datasheet convention), micro-g.
    pub allan_minimum_ug: Option<f64>,
    /// Tau of the Allan minimum, s.
    pub allan_minimum_tau_s: Option<f64>,
    /// Acceleration random walk, m/s^2/sqrt(h).
    pub accel_random_walk_m_s2_rt_h: Option<f64>,
    /// Acceleration random walk as a density, m/s^3/sqrt(Hz) (= m/s^2/sqrt(s)).
    pub accel_random_walk_m_s3_rt_hz: Option<f64>,
    /// Velocity quantization, m/s.
    pub quantization_m_s: Option<f64>,
    /// Acceleration ramp, m/s^2 per hour.
    pub ramp_m_s2_per_h: Option<f64>,
    /// Every slope-line term with its basis and support (units as the keys above).
    pub readings: Vec<ReadingJson>,
    /// Kalibr imu.yaml accelerometer entries with their basis.
    pub kalibr: KalibrAccelerometer,
}

/// One slope-line term: its basis and support.
#[derive(Debug, Clone, Serialize)]
pub struct ReadingJson {
    /// Term: `quantization`, `arw`, `bias_instability`, `allan_minimum`, `rrw`, `rate_ramp`.
    pub term: &'static str,
    /// `value`, `upper_bound` or `absent`.
    pub basis: &'static str,
    /// The value or the upper bound, in `unit`; null when absent.
    pub value: Option<f64>,
    /// Unit of `value` (that of the term's top-level key).
    pub unit: &'static str,
    /// Tau of the reading or of the bound, s.
    pub tau_s: Option<f64>,
    /// Tau range of the supported region, s (values only).
    pub tau_range_s: Option<[f64; 2]>,
    /// Log-log slope of the region (values only; for rrw the slope of the excess over the other
    /// terms).
    pub local_slope: Option<f64>,
    /// Why the term is not a value: `no_supported_region`, `not_above_other_terms`,
    /// `record_too_short`, `no_points`.
    pub reason: Option<&'static str>,
    /// For `record_too_short`: the record length below which the term cannot be resolved, s.
    pub needed_record_s: Option<f64>,
}

/// The five-term fit in JSON.
#[derive(Debug, Clone, Serialize)]
pub struct FitJson {
    /// N, deg/sqrt(h).
    pub arw_deg_rt_h: Option<f64>,
    /// B, deg/h.
    pub bias_instability_dph: Option<f64>,
    /// K, deg/h/sqrt(h).
    pub rrw_deg_h_rt_h: Option<f64>,
    /// Q, deg.
    pub quantization_deg: Option<f64>,
    /// R, deg/h per hour.
    pub rate_ramp_dph_per_h: Option<f64>,
    /// Tau range fitted, s.
    pub tau_range_s: [f64; 2],
    /// Points used.
    pub points_used: usize,
    /// Weighted RMS residual (relative).
    pub weighted_rms_residual: f64,
    /// `acceptable`, or `poor` when the weighted RMS residual exceeds `quality_limit`.
    pub quality: FitQuality,
    /// The residual limit of `quality`.
    pub quality_limit: f64,
}

/// JSON of one channel.
#[derive(Debug, Clone, Serialize)]
pub struct AllanJson {
    /// Source file.
    pub file: String,
    /// Topic of a recording (absent for tables).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub topic: Option<String>,
    /// Channel.
    pub channel: String,
    /// Deviation kind: oadev, adev, mdev, tdev, hdev, ohdev, totdev.
    pub kind: String,
    /// Unit of `dev`, `ci_low`, `ci_high` (deg/s when calibrated; TDEV: seconds times it).
    pub dev_unit: String,
    /// Sample interval, s.
    pub tau0_s: f64,
    /// Rate samples analysed.
    pub samples: usize,
    /// Confidence level of the bounds (null: none computed).
    pub confidence: Option<f64>,
    /// Averaging times, s.
    pub taus_s: Vec<f64>,
    /// Averaging factors m.
    pub m: Vec<usize>,
    /// Deviations.
    pub dev: Vec<f64>,
    /// Lower bounds.
    pub ci_low: Vec<Option<f64>>,
    /// Upper bounds.
    pub ci_high: Vec<Option<f64>>,
    /// Number of terms in each sum.
    pub n_terms: Vec<usize>,
    /// Identified noise type alpha per tau (2 white PM ... -2 random walk FM).
    pub alpha: Vec<Option<i32>>,
    /// Equivalent degrees of freedom per tau.
    pub edf: Vec<Option<f64>>,
    /// What the channel measures: `angular_rate`, `acceleration`, `sensor_output`, `unitless`.
    pub quantity: Quantity,
    /// Gyro noise coefficients (null when the data are not an angular rate in deg/s).
    pub noise: Option<NoiseJson>,
    /// Accelerometer noise coefficients (null unless the channel is an accelerometer in m/s^2).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub accel_noise: Option<AccelNoiseJson>,
    /// Why `noise` is null, if it is.
    pub noise_note: Option<String>,
    /// The GMWM fit beside the slope lines and the five-term fit (null when not made).
    pub gmwm: Option<GmwmJson>,
    /// The stillness check (null when no rule applies: not a gyro in deg/s nor an
    /// accelerometer in m/s^2).
    pub stillness: Option<StillnessJson>,
    /// The gravity check of a three-axis accelerometer (the magnitude of each window's mean
    /// vector against 1 g; absent for other channels).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gravity: Option<gyrolab::stillness::GravityCheck>,
    /// The record's temperature column (mean, range, drift; `moved` above 1 degC of range),
    /// absent without one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub temperature: Option<gyrolab::record_temperature::RecordTemperature>,
}

/// The JSON document: the first channel's keys at the top level, every channel in `channels`.
#[derive(Debug, Clone, Serialize)]
pub struct AllanDocument {
    /// Program version.
    pub gyrolab_version: String,
    /// The first channel's result.
    #[serde(flatten)]
    pub first: AllanJson,
    /// Every channel (the first included).
    pub channels: Vec<AllanJson>,
}

/// The terms in report order: key, label, unit, reading in that unit (gyro units).
pub fn terms_in_units(s: &SlopeLineResult) -> [(&'static str, &'static str, &'static str, Reading); 6] {
    terms_for(s, Quantity::AngularRate).map(|(k, l, u, f, r)| (k, l, u, r.scaled(f)))
}

/// The terms of a curve of `quantity` in report order: key, label, unit, the factor from the
/// per-second base units of the slope lines to that unit, and the base reading. Gyro curves in
/// deg/s (IEEE Std 952 units), accelerometer curves in m/s^2 (IEEE Std 1293 terms).
fn terms_for(s: &SlopeLineResult, quantity: Quantity) -> [(&'static str, &'static str, &'static str, f64, Reading); 6] {
    if quantity == Quantity::Acceleration {
        return [
            ("vrw", "velocity random walk", "m/s/sqrt(h)", units::vrw_m_s_rt_s_to_m_s_rt_h(1.0), s.arw),
            ("bias_instability", "bias instability B (IEEE)", "ug", units::m_s2_to_ug(1.0), s.bias_instability),
            ("allan_minimum", "Allan minimum (datasheet)", "ug", units::m_s2_to_ug(1.0), s.allan_minimum),
            (
                "accel_random_walk",
                "acceleration random walk",
                "m/s^2/sqrt(h)",
                units::accel_rw_m_s2_rt_s_to_m_s2_rt_h(1.0),
                s.rrw,
            ),
            ("quantization", "velocity quantization", "m/s", 1.0, s.quantization),
            ("rate_ramp", "acceleration ramp", "m/s^2/h", units::accel_ramp_per_s_to_per_h(1.0), s.rate_ramp),
        ];
    }
    [
        ("arw", "angle random walk N", "deg/sqrt(h)", units::arw_deg_rt_s_to_deg_rt_h(1.0), s.arw),
        ("bias_instability", "bias instability B (IEEE 952)", "deg/h", units::bias_dps_to_dph(1.0), s.bias_instability),
        ("allan_minimum", "Allan minimum (datasheet)", "deg/h", units::bias_dps_to_dph(1.0), s.allan_minimum),
        ("rrw", "rate random walk K", "deg/h/sqrt(h)", units::rrw_dps_rt_s_to_dph_rt_h(1.0), s.rrw),
        ("quantization", "quantization Q", "deg", 1.0, s.quantization),
        ("rate_ramp", "rate ramp R", "deg/h/h", units::rate_ramp_dps_per_s_to_dph_per_h(1.0), s.rate_ramp),
    ]
}

/// The five-term fit's value of a term, in the base units of [`terms_for`].
fn fit_base_value(c: &NoiseCoefficients, term: &str) -> Option<f64> {
    match term {
        "arw" | "vrw" => c.arw_deg_rt_s,
        "bias_instability" => c.bias_instability_dps,
        "allan_minimum" => c.bias_instability_dps.map(|b| b * BIAS_FACTOR),
        "rrw" | "accel_random_walk" => c.rrw_deg_s_rt_s,
        "quantization" => c.quantization_deg,
        _ => c.rate_ramp_dps_per_s,
    }
}

fn readings(s: &SlopeLineResult, quantity: Quantity) -> Vec<ReadingJson> {
    terms_for(s, quantity)
        .into_iter()
        .map(|(term, _, unit, f, r)| (term, unit, r.scaled(f)))
        .map(|(term, unit, r)| ReadingJson {
            term,
            basis: r.basis().name(),
            value: r.value().or(r.bound()),
            unit,
            tau_s: r.tau_s(),
            tau_range_s: r.site().map(|x| [x.tau_range_s.0, x.tau_range_s.1]),
            local_slope: r.site().map(|x| x.local_slope),
            reason: r.reason().map(|x| x.name()),
            needed_record_s: match r.reason() {
                Some(Unresolved::RecordTooShort { needed_record_s }) => Some(needed_record_s),
                _ => None,
            },
        })
        .collect()
}

/// Builds the JSON of one channel.
pub fn allan_json(a: &ChannelAnalysis) -> AllanJson {
    allan_json_with(a, true)
}

/// [`allan_json`] with or without the `gmwm` key's fit (`with_gmwm = false` leaves it `null`
/// and the GMWM uncomputed: for outputs that do not show it, such as batch tables).
pub fn allan_json_with(a: &ChannelAnalysis, with_gmwm: bool) -> AllanJson {
    let c = &a.curve;
    let accel = a.quantity == Quantity::Acceleration;
    let accel_noise = a.slope_lines.as_ref().filter(|_| accel).map(|s| {
        let k = &s.coefficients;
        AccelNoiseJson {
            vrw_m_s_rt_h: k.arw_deg_rt_s.map(units::vrw_m_s_rt_s_to_m_s_rt_h),
            vrw_m_s2_rt_hz: k.arw_deg_rt_s,
            bias_instability_m_s2: k.bias_instability_dps,
            bias_instability_ug: k.bias_instability_dps.map(units::m_s2_to_ug),
            allan_minimum_ug: s.allan_minimum.value().map(units::m_s2_to_ug),
            allan_minimum_tau_s: s.allan_minimum.site().map(|x| x.tau_s),
            accel_random_walk_m_s2_rt_h: k.rrw_deg_s_rt_s.map(units::accel_rw_m_s2_rt_s_to_m_s2_rt_h),
            accel_random_walk_m_s3_rt_hz: k.rrw_deg_s_rt_s,
            quantization_m_s: k.quantization_deg,
            ramp_m_s2_per_h: k.rate_ramp_dps_per_s.map(units::accel_ramp_per_s_to_per_h),
            readings: readings(s, Quantity::Acceleration),
            kalibr: kalibr_accelerometer_from_readings(s, a.model_fit.as_ref()),
        }
    });
    let noise = a.slope_lines.as_ref().filter(|_| !accel).map(|s| {
        let k = &s.coefficients;
        NoiseJson {
            arw_deg_rt_h: k.arw_deg_rt_h,
            bias_instability_dph: k.bias_instability_dph,
            allan_minimum_dph: s.allan_minimum.value().map(units::bias_dps_to_dph),
            allan_minimum_tau_s: s.allan_minimum.site().map(|x| x.tau_s),
            rrw_deg_h_rt_h: k.rrw_deg_h_rt_h,
            quantization_deg: k.quantization_deg,
            rate_ramp_dph_per_h: k.rate_ramp_dph_per_h,
            arw_deg_rt_s: k.arw_deg_rt_s,
            rrw_deg_s_rt_s: k.rrw_deg_s_rt_s,
            readings: readings(s, Quantity::AngularRate),
            fit: a.model_fit.as_ref().map(|f| FitJson {
                arw_deg_rt_h: f.coefficients.arw_deg_rt_h,
                bias_instability_dph: f.coefficients.bias_instability_dph,
                rrw_deg_h_rt_h: f.coefficients.rrw_deg_h_rt_h,
                quantization_deg: f.coefficients.quantization_deg,
                rate_ramp_dph_per_h: f.coefficients.rate_ramp_dph_per_h,
                tau_range_s: [f.tau_range_s.0, f.tau_range_s.1],
                points_used: f.points_used,
                weighted_rms_residual: f.weighted_rms_residual,
                quality: f.quality,
                quality_limit: FIT_RMS_LIMIT,
            }),
            kalibr: kalibr_from_readings(s, a.model_fit.as_ref()),
        }
    });
    AllanJson {
        file: a.file.clone(),
        topic: a.topic.clone(),
        channel: a.channel.clone(),
        kind: c.kind.name().to_string(),
        dev_unit: if c.kind.name() == "tdev" { format!("s*{}", a.rate_unit) } else { a.rate_unit.clone() },
        tau0_s: c.tau0_s,
        samples: c.n_rate,
        confidence: c.confidence,
        taus_s: c.points.iter().map(|p| p.tau_s).collect(),
        m: c.points.iter().map(|p| p.m).collect(),
        dev: c.points.iter().map(|p| p.deviation).collect(),
        ci_low: c.points.iter().map(|p| p.lower).collect(),
        ci_high: c.points.iter().map(|p| p.upper).collect(),
        n_terms: c.points.iter().map(|p| p.terms).collect(),
        alpha: c.points.iter().map(|p| p.alpha).collect(),
        edf: c.points.iter().map(|p| p.edf).collect(),
        quantity: a.quantity,
        noise,
        accel_noise,
        noise_note: a.noise_note.clone(),
        gmwm: if with_gmwm { gmwm_json(a) } else { None },
        stillness: a.stillness.clone().map(|check| StillnessJson {
            check,
            allow_motion: a.allow_motion,
            motion: a.motion_line(),
        }),
        gravity: a.gravity.clone(),
        temperature: a.temperature.clone(),
    }
}

/// Builds the JSON document of several channels (at least one).
pub fn allan_document(channels: &[ChannelAnalysis]) -> Option<AllanDocument> {
    allan_document_with(channels, true)
}

/// [`allan_document`] with or without the channels' GMWM fits ([`allan_json_with`]).
pub fn allan_document_with(channels: &[ChannelAnalysis], with_gmwm: bool) -> Option<AllanDocument> {
    let all: Vec<AllanJson> = channels.iter().map(|a| allan_json_with(a, with_gmwm)).collect();
    Some(AllanDocument {
        gyrolab_version: env!("CARGO_PKG_VERSION").into(),
        first: all.first()?.clone(),
        channels: all,
    })
}

/// CSV of the curves: `file,channel,tau_s,m,dev,ci_low,ci_high,n_terms,alpha`.
pub fn allan_csv(channels: &[ChannelAnalysis]) -> String {
    let mut s = String::from("file,channel,tau_s,m,dev,ci_low,ci_high,n_terms,alpha\n");
    let opt = |v: Option<f64>| v.map_or(String::new(), |x| format!("{x:e}"));
    for a in channels {
        for p in &a.curve.points {
            s.push_str(&format!(
                "{},{},{:e},{},{:e},{},{},{},{}\n",
                a.file,
                a.topic.as_ref().map_or(a.channel.clone(), |t| format!("{t}/{}", a.channel)),
                p.tau_s,
                p.m,
                p.deviation,
                opt(p.lower),
                opt(p.upper),
                p.terms,
                p.alpha.map_or(String::new(), |x| x.to_string())
            ));
        }
    }
    s
}

/// A reading as text: the value, `< bound`, or `absent`.
pub fn reading_text(r: &Reading, digits: usize) -> String {
    match r {
        Reading::Value { value, .. } => sig(*value, digits),
        Reading::UpperBound { value, .. } => format!("< {}", sig(*value, digits)),
        Reading::Absent { .. } => "absent".into(),
    }
}

/// Where a reading was read or bounded, and why it is not a value.
pub fn support_text(r: &Reading) -> String {
    match r {
        Reading::Value { site, .. } => format!(
            "tau {} s on slope {} over {}..{} s",
            short(site.tau_s, 4),
            short(site.local_slope, 2),
            short(site.tau_range_s.0, 4),
            short(site.tau_range_s.1, 4)
        ),
        Reading::UpperBound { tau_s, reason, .. } => {
            format!("upper bound at tau {} s: {}", short(*tau_s, 4), reason.describe())
        }
        Reading::Absent { reason } => reason.describe(),
    }
}

/// The deviation table and noise summary of one channel, as text.
pub fn allan_text(a: &ChannelAnalysis) -> String {
    let c = &a.curve;
    let mut t = Table::new();
    t.load_preset(UTF8_FULL_CONDENSED);
    let u = if c.kind.name() == "tdev" { format!("s*{}", a.rate_unit) } else { a.rate_unit.clone() };
    let conf = c.confidence.map_or("no bounds".to_string(), |x| format!("{} % bounds", short(100.0 * x, 4)));
    t.set_header(vec![
        "tau s".to_string(),
        "m".into(),
        format!("{} {u}", c.kind.name().to_uppercase()),
        format!("low ({conf})"),
        "high".into(),
        "terms".into(),
        "alpha".into(),
    ]);
    for p in &c.points {
        t.add_row(vec![
            Cell::new(short(p.tau_s, 6)),
            Cell::new(p.m),
            Cell::new(sig(p.deviation, 5)),
            Cell::new(sig_opt(p.lower, 4)),
            Cell::new(sig_opt(p.upper, 4)),
            Cell::new(p.terms),
            Cell::new(p.alpha.map_or("".into(), |x| x.to_string())),
        ]);
    }
    for i in 0..6 {
        if let Some(col) = t.column_mut(i) {
            col.set_cell_alignment(CellAlignment::Right);
        }
    }
    let mut s = format!(
        "{} ({}): {} of {} samples at tau0 = {} s, rate in {}\n{}\n",
        a.file,
        a.topic.as_ref().map_or(a.channel.clone(), |t| format!("{t} {}", a.channel)),
        c.kind.name().to_uppercase(),
        c.n_rate,
        short(c.tau0_s, 6),
        a.rate_unit,
        t
    );
    match (&a.slope_lines, &a.noise_note) {
        (Some(sl), _) => {
            let mut n = Table::new();
            n.load_preset(UTF8_FULL_CONDENSED);
            n.set_header(vec!["noise term", "unit", "slope lines", "support", "five-term fit"]);
            let f = a.model_fit.as_ref().map(|f| f.coefficients);
            for (term, label, unit, factor, r) in terms_for(sl, a.quantity) {
                let r = r.scaled(factor);
                let fv = f.and_then(|f| fit_base_value(&f, term)).map(|v| v * factor);
                n.add_row(vec![
                    label.to_string(),
                    unit.to_string(),
                    reading_text(&r, 4),
                    support_text(&r),
                    sig_opt(fv, 4),
                ]);
            }
            s.push_str(&n.to_string());
            if let Some(fit) = &a.model_fit {
                s.push_str(&format!(
                    "\nfive-term fit over tau {}..{} s ({} points, weighted RMS residual {})",
                    short(fit.tau_range_s.0, 4),
                    short(fit.tau_range_s.1, 4),
                    fit.points_used,
                    sig(fit.weighted_rms_residual, 3)
                ));
                if fit.quality == FitQuality::Poor {
                    s.push_str(&format!(
                        "\nwarning: POOR FIT: the weighted RMS residual exceeds {}: the five-term model does not describe this curve; do not use its values",
                        short(FIT_RMS_LIMIT, 3)
                    ));
                }
            }
            if a.quantity == Quantity::Acceleration {
                s.push_str("\nAccelerometer terms (IEEE Std 1293): velocity random walk, bias instability (1 ug = 9.80665e-6 m/s^2), acceleration random walk.");
            }
            s.push_str(
                "\nEach term is a value only where the curve supports its slope at the bounds' confidence; '< x' is an upper bound (docs/METHODS.md section 3). \
                 B (IEEE 952) = Allan minimum / 0.6643; datasheets (ADI, Sensonor) quote the Allan minimum itself. N is read at the tau nearest 1 s on its -1/2 region.\n",
            );
            if let Some(g) = gmwm_text(a) {
                s.push_str(&g);
            }
        }
        (None, Some(note)) => s.push_str(&format!("noise terms: {note}\n")),
        (None, None) => {}
    }
    s.push_str(&stillness_text(a));
    if let Some(t) = &a.temperature {
        s.push_str(&temperature_text(t));
    }
    s
}

/// The temperature line of a channel's text: mean, range and drift of the record's
/// temperature column; a warning when it moved.
pub fn temperature_text(t: &gyrolab::record_temperature::RecordTemperature) -> String {
    let line = format!(
        "temperature ({}): mean {} degC, range {} to {} degC ({} degC), drift {} degC/h",
        t.column,
        sig(t.mean_c, 4),
        sig(t.min_c, 4),
        sig(t.max_c, 4),
        sig(t.span_c, 3),
        sig(t.slope_c_per_h, 3)
    );
    if t.moved {
        format!(
            "warning: {line}: the temperature moved by more than {} degC during the record, so slow terms (bias instability, rate random walk, rate ramp) may be the temperature's\n",
            gyrolab::record_temperature::MOVED_SPAN_C
        )
    } else {
        format!("{line}\n")
    }
}

/// The stillness lines of a channel's text: a `warning:` naming what moved and when, the rule
/// of a still channel, or why the check was not made.
pub fn stillness_text(a: &ChannelAnalysis) -> String {
    let Some(c) = &a.stillness else { return String::new() };
    let r = &c.rule;
    if let Some(line) = a.motion_line() {
        let allowed = if a.allow_motion { " (analysed because motion was allowed)" } else { "" };
        return format!("warning: {line}{allowed}\n");
    }
    if !c.evaluated {
        return format!(
            "stillness: not evaluated ({}): nothing says the record is static\n",
            c.not_evaluated_reason.as_deref().unwrap_or("no reason given")
        );
    }
    // The window used: its samples at the record's interval (a slow record's windows hold at
    // least the rule's minimum of samples, so they can be longer than the rule's nominal 1 s).
    let window_s = c.window_samples as f64 * a.curve.tau0_s;
    format!(
        "stillness: still: no window of {} s ({} samples) departed from the still level {} {u} by more than {} sigma and {} {u} \
         ({} windows; docs/METHODS.md, stillness check)\n",
        short(window_s, 4),
        c.window_samples,
        sig(c.still_level, 4),
        short(r.k_sigma, 3),
        sig(r.floor, 3),
        c.windows,
        u = r.unit
    )
}

/// Kalibr's entries for the gyro and accelerometer channels, as written to imu.yaml.
#[derive(Debug, Clone, PartialEq)]
pub struct KalibrFile {
    /// The YAML text.
    pub text: String,
    /// The combined gyro entries (none when no gyro channel has noise terms).
    pub entries: Option<KalibrGyroscope>,
    /// The combined accelerometer entries (none when no accelerometer channel has noise terms).
    pub accelerometer: Option<KalibrAccelerometer>,
    /// One line per entry that is not a resolved value or is missing (to print as `warning:`
    /// on stderr).
    pub warnings: Vec<String>,
}

fn basis_comment(b: Option<KalibrBasis>) -> &'static str {
    match b {
        Some(KalibrBasis::Value) => "resolved slope-line value",
        Some(KalibrBasis::UpperBound) => {
            "UPPER BOUND: the term is not resolved by the record; the curve's upper confidence bound limits it"
        }
        Some(KalibrBasis::FitValue) => "FIVE-TERM FIT VALUE: the term is neither resolved nor bounded by slope lines",
        None => "",
    }
}

/// One channel's filter entries: index, noise density, basis, random walk, basis, whether it is
/// an accelerometer.
type ChannelEntries = (usize, Option<f64>, Option<KalibrBasis>, Option<f64>, Option<KalibrBasis>, bool);

/// One combined entry of a filter file: key, value, basis, channel index.
type Entry = (&'static str, Option<f64>, Option<KalibrBasis>, usize);

/// The combined continuous-time entries of the analysed channels: gyro (rad/s/sqrt(Hz),
/// rad/s^2/sqrt(Hz)) and accelerometer (m/s^2/sqrt(Hz), m/s^3/sqrt(Hz)), each the largest
/// over its channels, with the per-channel values for comments.
struct FilterEntries {
    gyro: Option<KalibrGyroscope>,
    accel: Option<KalibrAccelerometer>,
    /// Per channel: index, noise density, basis, random walk, basis, accelerometer or not.
    per: Vec<ChannelEntries>,
}

fn filter_entries(channels: &[ChannelAnalysis]) -> FilterEntries {
    let mut gyro = Vec::new();
    let mut accel = Vec::new();
    let mut per = Vec::new();
    for (i, a) in channels.iter().enumerate() {
        let Some(s) = a.slope_lines.as_ref() else { continue };
        match a.quantity {
            Quantity::AngularRate => {
                let mut g = kalibr_from_readings(s, a.model_fit.as_ref());
                g.channel_index = (i, i);
                per.push((
                    i,
                    g.gyroscope_noise_density,
                    g.gyroscope_noise_density_basis,
                    g.gyroscope_random_walk,
                    g.gyroscope_random_walk_basis,
                    false,
                ));
                gyro.push(g);
            }
            Quantity::Acceleration => {
                let mut g = kalibr_accelerometer_from_readings(s, a.model_fit.as_ref());
                g.channel_index = (i, i);
                per.push((
                    i,
                    g.accelerometer_noise_density,
                    g.accelerometer_noise_density_basis,
                    g.accelerometer_random_walk,
                    g.accelerometer_random_walk_basis,
                    true,
                ));
                accel.push(g);
            }
            _ => {}
        }
    }
    // Combined entries name the channel of the analysis list, not of the per-quantity list.
    let g = (!gyro.is_empty()).then(|| {
        let mut c = combine_kalibr(&gyro);
        c.channel_index = (gyro[c.channel_index.0].channel_index.0, gyro[c.channel_index.1].channel_index.1);
        c
    });
    let acc = (!accel.is_empty()).then(|| {
        let mut c = combine_kalibr_accelerometer(&accel);
        c.channel_index = (accel[c.channel_index.0].channel_index.0, accel[c.channel_index.1].channel_index.1);
        c
    });
    FilterEntries { gyro: g, accel: acc, per }
}

impl FilterEntries {
    fn list(&self) -> [Entry; 4] {
        let g = self.gyro;
        let a = self.accel;
        [
            (
                "gyroscope_noise_density",
                g.and_then(|g| g.gyroscope_noise_density),
                g.and_then(|g| g.gyroscope_noise_density_basis),
                g.map_or(0, |g| g.channel_index.0),
            ),
            (
                "gyroscope_random_walk",
                g.and_then(|g| g.gyroscope_random_walk),
                g.and_then(|g| g.gyroscope_random_walk_basis),
                g.map_or(0, |g| g.channel_index.1),
            ),
            (
                "accelerometer_noise_density",
                a.and_then(|a| a.accelerometer_noise_density),
                a.and_then(|a| a.accelerometer_noise_density_basis),
                a.map_or(0, |a| a.channel_index.0),
            ),
            (
                "accelerometer_random_walk",
                a.and_then(|a| a.accelerometer_random_walk),
                a.and_then(|a| a.accelerometer_random_walk_basis),
                a.map_or(0, |a| a.channel_index.1),
            ),
        ]
    }
}

/// The unit of a continuous-time filter entry.
fn entry_unit(key: &str) -> &'static str {
    match key {
        "gyroscope_noise_density" | "gyr_n" => "rad/s/sqrt(Hz)",
        "gyroscope_random_walk" | "gyr_w" => "rad/s^2/sqrt(Hz)",
        "accelerometer_noise_density" | "acc_n" => "m/s^2/sqrt(Hz)",
        _ => "m/s^3/sqrt(Hz)",
    }
}

/// The discrete-time value of a continuous-time entry at `rate_hz` (Kalibr wiki, "IMU Noise
/// Model"): white noise sigma_d = sigma_c * sqrt(rate); random walk sigma_bd = sigma_b / sqrt(rate).
fn discrete(key: &str, v: f64, rate_hz: f64) -> f64 {
    if key.ends_with("noise_density") || key.ends_with("_n") {
        v * rate_hz.sqrt()
    } else {
        v / rate_hz.sqrt()
    }
}

/// Filter files (Kalibr, imu_utils) for the analysed channels; `None` when no channel has noise
/// terms. Each entry is the largest over its channels (as ethz-asl allan_variance_ros combines
/// its axes), with its basis in a comment, the discrete-time value beside it, and a warning for
/// every entry that is an upper bound, a fit value, or missing.
fn filter_file(channels: &[ChannelAnalysis], update_rate_hz: f64, imu_utils: bool) -> Option<KalibrFile> {
    let fe = filter_entries(channels);
    if fe.gyro.is_none() && fe.accel.is_none() {
        return None;
    }
    let name = |i: usize| format!("{} ({})", channels[i].file, channels[i].channel);
    let mut text = if imu_utils {
        format!(
            "%YAML:1.0\n---\n# imu_utils style IMU noise parameters written by gyrolab {}\n\
             # Continuous-time values, as imu_utils prints them. VINS-Fusion's propagation takes its gyr_n,\n\
             # gyr_w, acc_n, acc_w per IMU sample instead (density x sqrt(2 rate), walk x sqrt(rate)):\n\
             # `--export vins=FILE` writes those (docs/EXPORTS.md).\n\
             # gyr_n: gyro white noise density, rad/s/sqrt(Hz); gyr_w: gyro random walk, rad/s^2/sqrt(Hz);\n\
             # acc_n: accelerometer white noise density, m/s^2/sqrt(Hz); acc_w: accelerometer random walk, m/s^3/sqrt(Hz).\n",
            env!("CARGO_PKG_VERSION")
        )
    } else {
        format!(
            "# Kalibr imu.yaml written by gyrolab {}\n\
             # Continuous-time noise densities and random walks (Kalibr's convention; the discrete-time\n\
             # values at update_rate are in the comments: white noise x sqrt(rate), random walk / sqrt(rate)).\n\
             # gyroscope_noise_density = angle random walk N in rad/s/sqrt(Hz);\n\
             # gyroscope_random_walk = rate random walk K in rad/s^2/sqrt(Hz);\n\
             # accelerometer_noise_density = velocity random walk in m/s^2/sqrt(Hz);\n\
             # accelerometer_random_walk = acceleration random walk in m/s^3/sqrt(Hz).\n",
            env!("CARGO_PKG_VERSION")
        )
    };
    text.push_str(&format!(
        "# Channels combined by the largest value per entry (as allan_variance_ros): {}\n",
        fe.per.iter().map(|x| name(x.0)).collect::<Vec<_>>().join(", ")
    ));
    for (i, n, nb, k, kb, accel) in &fe.per {
        text.push_str(&format!(
            "#   {} [{}]: noise density {} ({}), random walk {} ({})\n",
            name(*i),
            if *accel { "accelerometer" } else { "gyro" },
            n.map_or("none".into(), |x| format!("{x:e}")),
            nb.map_or("none", |b| b.name()),
            k.map_or("none".into(), |x| format!("{x:e}")),
            kb.map_or("none", |b| b.name()),
        ));
    }
    let mut warnings = Vec::new();
    for line in channels.iter().filter_map(ChannelAnalysis::motion_line) {
        text.push_str(&format!("# {line}\n"));
        warnings.push(format!("{} file: {line}", if imu_utils { "imu_utils" } else { "Kalibr" }));
    }
    let mut body = String::new();
    for (key, value, basis, ch) in fe.list() {
        let out_key = if imu_utils {
            match key {
                "gyroscope_noise_density" => "gyr_n",
                "gyroscope_random_walk" => "gyr_w",
                "accelerometer_noise_density" => "acc_n",
                _ => "acc_w",
            }
        } else {
            key
        };
        match value {
            Some(v) => {
                text.push_str(&format!("# {out_key}: from {}; {}\n", name(ch), basis_comment(basis)));
                body.push_str(&format!(
                    "{out_key}: {v:e}   # {}; discrete-time at {} Hz: {:e}\n",
                    entry_unit(key),
                    short(update_rate_hz, 9),
                    discrete(key, v, update_rate_hz)
                ));
                if basis != Some(KalibrBasis::Value) {
                    warnings.push(format!(
                        "{} {out_key} is {} ({}), not a resolved value: {}",
                        if imu_utils { "imu_utils" } else { "Kalibr" },
                        basis.map_or("none", |b| b.name()),
                        name(ch),
                        basis_comment(basis)
                    ));
                }
            }
            None => {
                let what = if key.starts_with("gyro") { "gyro" } else { "accelerometer" };
                body.push_str(&format!(
                    "# {out_key}: not written: no {what} channel with noise terms (give the {what} columns a unit)\n"
                ));
                warnings.push(format!(
                    "{} {out_key} not written: no {what} channel with noise terms",
                    if imu_utils { "imu_utils" } else { "Kalibr" }
                ));
            }
        }
    }
    text.push_str(&body);
    if imu_utils {
        text.push_str(&format!("imu_rate: {}\n", short(update_rate_hz, 9)));
    } else {
        let topic = channels
            .first()
            .and_then(|c| c.topic.clone())
            .filter(|t| channels.iter().all(|c| c.topic.as_deref() == Some(t.as_str())));
        match topic {
            Some(t) => text.push_str(&format!("update_rate: {}\nrostopic: {t}\n", short(update_rate_hz, 9))),
            None => text.push_str(&format!(
                "update_rate: {}\n# rostopic: not known from this file; /imu0 is Kalibr's example topic: set yours\nrostopic: /imu0\n",
                short(update_rate_hz, 9)
            )),
        }
    }
    Some(KalibrFile { text, entries: fe.gyro, accelerometer: fe.accel, warnings })
}

/// Kalibr imu.yaml for the analysed channels (gyro and accelerometer entries, `update_rate`,
/// `rostopic`); see `filter_file`. `None` when no channel has noise terms.
pub fn kalibr_yaml(channels: &[ChannelAnalysis], update_rate_hz: f64) -> Option<KalibrFile> {
    filter_file(channels, update_rate_hz, false)
}

/// imu_utils-style YAML (`gyr_n`, `gyr_w`, `acc_n`, `acc_w`, continuous time, as imu_utils prints
/// them; VINS-Fusion's per-sample values are the `vins` export's) for the
/// analysed channels. `None` when no channel has noise terms.
pub fn imu_utils_yaml(channels: &[ChannelAnalysis], update_rate_hz: f64) -> Option<KalibrFile> {
    filter_file(channels, update_rate_hz, true)
}

/// A noise-coefficient set has at least one term.
pub fn has_terms(c: &NoiseCoefficients) -> bool {
    c.arw_deg_rt_h.is_some() || c.bias_instability_dph.is_some() || c.rrw_deg_h_rt_h.is_some()
}

/// The text of `gyrolab plan static`: the record a noise term's precision needs (`precision_pct`
/// at `confidence`, as asked), with its EDF and interval and their sources.
pub fn record_length_text(plan: &gyrolab::record_length::RecordLength, precision_pct: f64, confidence: f64) -> String {
    use gyrolab::record_length::NoiseTerm;
    let term = match plan.request.term {
        NoiseTerm::BiasInstability => "bias instability (flicker rate noise, alpha = -1)",
        NoiseTerm::AngleRandomWalk => "angle random walk (white rate noise, alpha = 0)",
    };
    let flat = plan.flat_run_record_s.map_or(String::new(), |f| {
        format!(
            "The slope lines read it on a flat run of octave points from {:.4} s to {:.4} s, within a quarter of the record:\n\
             at least {f:.0} s whatever the precision (`gyrolab allan` calls a shorter record too short by the same rule).\n",
            plan.request.tau_s,
            (1u64 << gyrolab::noise::FLAT_MIN_SEGMENTS) as f64 * plan.request.tau_s
        )
    });
    format!(
        "To measure {term} from the overlapping Allan deviation at tau = {:.4} s (m = {}, {} Hz)\n\
         within +-{} % at {} % confidence, record at least {} samples: {:.0} s = {:.2} h.\n\
         {flat}\
         Such a record gives {:.1} equivalent degrees of freedom and an interval of {:.3} to {:.3} times the value.\n\
         (EDF by Greenhall & Riley 2004; chi-squared bounds, NIST SP 1065 section 5.3.)\n",
        plan.request.tau_s,
        plan.m,
        plan.request.sample_rate_hz,
        precision_pct,
        100.0 * confidence,
        plan.samples,
        plan.duration_s,
        plan.duration_h,
        plan.required_edf,
        plan.relative_interval.0,
        plan.relative_interval.1
    )
}

/// The document of `gyrolab allan --json` with the `memory` object (which path the analysis
/// took; docs/JSON.md) after its keys.
#[derive(Debug, Clone, Serialize)]
pub struct AllanMemoryDocument<'a> {
    /// The channels' document.
    #[serde(flatten)]
    pub doc: AllanDocument,
    /// In memory or streamed, with the estimates.
    pub memory: &'a gyrolab_eval::allan_memory::MemoryPath,
}

/// [`allan_document`] with the memory path of the analysis; `None` without channels.
pub fn allan_document_in<'a>(
    channels: &[ChannelAnalysis],
    memory: &'a gyrolab_eval::allan_memory::MemoryPath,
) -> Option<AllanMemoryDocument<'a>> {
    allan_document(channels).map(|doc| AllanMemoryDocument { doc, memory })
}

#[cfg(test)]
mod tests {
    use super::*;
    use gyrolab::allan::{AllanCurve, AllanPoint, DeviationKind};
    use gyrolab::noise::{fit_noise_model, slope_line_terms};
    use gyrolab_eval::outcome::allan::LazyGmwm;

    /// A hand-made white-noise curve (sigma = 1e-3 / sqrt(tau), edf 1000), optionally with a 30 %
    /// bump at three taus.
    fn analysis(bump: bool) -> ChannelAnalysis {
        let points = (0..12)
            .map(|k| {
                let tau_s = 0.01 * f64::from(1u32 << k);
                let f = if bump && (5..8).contains(&k) { 1.3 } else { 1.0 };
                AllanPoint {
                    m: 1 << k,
                    tau_s,
                    deviation: f * 1e-3 / tau_s.sqrt(),
                    terms: 1000,
                    alpha: None,
                    noise_id: None,
                    edf: Some(1000.0),
                    lower: None,
                    upper: None,
                }
            })
            .collect();
        let curve = AllanCurve { kind: DeviationKind::Oadev, tau0_s: 0.01, n_rate: 1 << 20, confidence: None, points };
        ChannelAnalysis {
            file: "hand.csv".into(),
            topic: None,
            channel: "rate_dps".into(),
            rate_unit: "deg/s".into(),
            quantity: Quantity::AngularRate,
            slope_lines: slope_line_terms(&curve).ok(),
            model_fit: fit_noise_model(&curve, None).ok(),
            gmwm: LazyGmwm::at_confidence(0.683),
            curve,
            noise_note: None,
            stillness: None,
            allow_motion: false,
            gravity: None,
            temperature: None,
        }
    }

    #[test]
    fn text_and_json_show_bounds_and_flag_a_poor_fit() {
        let good = analysis(false);
        let text = allan_text(&good);
        // B is not resolved on white noise: printed as '< x' with its reason, never as a value.
        let b_row = text.lines().find(|l| l.contains("bias instability B")).unwrap();
        assert!(b_row.contains("< ") && b_row.contains("record too short"), "{b_row}");
        assert!(!text.contains("POOR FIT"), "{text}");
        // N = 1e-3 deg/sqrt(s) = 0.06 deg/sqrt(h) by hand.
        let j = allan_json(&good);
        let noise = j.noise.unwrap();
        assert!((noise.arw_deg_rt_h.unwrap() - 0.06).abs() < 1e-12);
        assert!(noise.bias_instability_dph.is_none() && noise.allan_minimum_dph.is_none());
        let b = noise.readings.iter().find(|r| r.term == "bias_instability").unwrap();
        assert_eq!((b.basis, b.reason), ("upper_bound", Some("record_too_short")));
        let text = allan_text(&analysis(true));
        assert!(text.contains("POOR FIT"), "{text}");
    }
}
