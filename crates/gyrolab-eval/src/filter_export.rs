//! Filter noise-parameter exports of an Allan analysis (`gyrolab allan --export STACK=FILE`):
//! the white-noise and random-walk terms of the gyro and accelerometer channels by the chosen
//! estimator (slope readings, five-term fit or GMWM), optionally overbounded on each channel's
//! curve and inflated, channels combined by the largest value (docs/EXPORTS.md, docs/METHODS.md
//! "Filter exports").

use crate::allan::AllanOutcome;
use crate::error::{EvalError, EvalResult};
use crate::outcome::allan::ChannelAnalysis;
use gyrolab::gmwm::{gauss_markov_filter_bound, overbound_factors, MarkovBound, Process};
use gyrolab::noise::Reading;
use gyrolab::units::{self, Quantity};
use gyrolab_io::noise_export::{real_text, ExportTerm, NoiseExport, Stack, TermSource};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Which estimate the exported values are.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Estimator {
    /// Slope readings: the value where resolved, else the upper bound, else the five-term fit.
    #[default]
    Slopes,
    /// The weighted five-term fit.
    Fit,
    /// GMWM (the model chosen by the criterion).
    Gmwm,
}

impl Estimator {
    /// Parses `slopes`, `fit` or `gmwm`.
    pub fn parse(text: &str) -> EvalResult<Estimator> {
        match text.trim() {
            "slopes" => Ok(Estimator::Slopes),
            "fit" => Ok(Estimator::Fit),
            "gmwm" => Ok(Estimator::Gmwm),
            other => Err(EvalError::conflict_on(
                &["estimator"],
                format!("{{estimator}} '{}': expected slopes, fit or gmwm", gyrolab_io::text::excerpt(other)),
            )),
        }
    }

    /// `slopes`, `fit` or `gmwm`.
    pub fn name(self) -> &'static str {
        match self {
            Estimator::Slopes => "slopes",
            Estimator::Fit => "fit",
            Estimator::Gmwm => "gmwm",
        }
    }
}

/// How the exported values are made.
#[derive(Clone, Debug, PartialEq)]
pub struct ExportRequest {
    /// (stack, file) pairs, written all or none.
    pub targets: Vec<(Stack, PathBuf)>,
    /// The estimator of the values.
    pub estimator: Estimator,
    /// Factor applied to every value (>= 1 is the usual use; 1: none).
    pub inflate: f64,
    /// Overbound each value on its channel's curve (the factors are recorded).
    pub overbound: bool,
    /// Write values from a GMWM fit flagged POOR FIT (its model does not describe the curve);
    /// without it such an export is refused ([`EvalError::PoorFit`]).
    pub allow_poor_fit: bool,
}

/// Parses a stack name.
fn parse_stack(stack: &str) -> EvalResult<Stack> {
    let names: Vec<&str> = gyrolab_io::noise_export::STACKS.iter().map(|s| s.name()).collect();
    Stack::parse(stack).ok_or_else(|| {
        EvalError::conflict_on(
            &["export"],
            format!(
                "{{export}}: unknown stack '{}': expected one of {}",
                gyrolab_io::text::excerpt(stack),
                names.join(", ")
            ),
        )
    })
}

/// Parses `STACK=FILE`.
pub fn parse_target(text: &str) -> EvalResult<(Stack, PathBuf)> {
    let names: Vec<&str> = gyrolab_io::noise_export::STACKS.iter().map(|s| s.name()).collect();
    let (stack, file) = text.split_once('=').ok_or_else(|| {
        EvalError::conflict_on(
            &["export"],
            format!(
                "{{export}} '{}': expected STACK=FILE (STACK one of {})",
                gyrolab_io::text::excerpt(text),
                names.join(", ")
            ),
        )
    })?;
    let stack = parse_stack(stack)?;
    if file.trim().is_empty() {
        return Err(EvalError::conflict_on(&["export"], format!("{{export}} {}= names no file", stack.name())));
    }
    Ok((stack, PathBuf::from(file)))
}

/// One estimate of a channel's term, continuous time in the export's SI unit (gyro white noise
/// rad/s/sqrt(Hz), gyro random walk rad/s^2/sqrt(Hz), accelerometer m/s^2/sqrt(Hz) and
/// m/s^3/sqrt(Hz)), before any factor.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TermEstimate {
    /// The value.
    pub value: f64,
    /// `value`, `upper_bound`, `fit_value`, `gmwm`, `gmwm_gauss_markov_bound` (the GMWM term
    /// plus the white noise or random walk bounding the model's Gauss-Markov processes) or
    /// `gmwm_upper_bound` (a term the chosen GMWM model leaves out: its model-averaged bound).
    pub basis: String,
    /// What the basis means for this term (confidence and sidedness, the channel).
    pub detail: String,
    /// The factor that puts this estimator's model on or above the channel curve's upper
    /// confidence bounds at every tau (applied only when overbounding is asked for).
    pub overbound_factor: Option<f64>,
}

/// The white-noise and random-walk terms of one gyro or accelerometer channel by every
/// estimator: what an export is made from (the CLI combines them at once; Python keeps them
/// with its result, so `result.export(...)` needs no second analysis).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ChannelFilterTerms {
    /// The channel's name.
    pub channel: String,
    /// An accelerometer channel (else a gyro).
    pub accelerometer: bool,
    /// Slope readings: the value where resolved, else the upper bound, else the five-term fit;
    /// [white noise, random walk].
    pub slopes: [Option<TermEstimate>; 2],
    /// The weighted five-term fit; [white noise, random walk].
    pub fit: [Option<TermEstimate>; 2],
    /// GMWM; [white noise, random walk].
    pub gmwm: [Option<TermEstimate>; 2],
    /// Terms of the GMWM's chosen model that no stack takes and the GMWM values leave out (a
    /// flicker floor, quantization, drift), one line each.
    #[serde(default)]
    pub gmwm_unrepresented: Vec<String>,
}

impl ChannelFilterTerms {
    fn of(&self, estimator: Estimator) -> &[Option<TermEstimate>; 2] {
        match estimator {
            Estimator::Slopes => &self.slopes,
            Estimator::Fit => &self.fit,
            Estimator::Gmwm => &self.gmwm,
        }
    }
}

/// The one-sided level of the upper end of a two-sided interval at `c`.
fn one_sided(c: f64) -> f64 {
    (1.0 + c) / 2.0
}

fn percent(c: f64) -> String {
    let p = c * 100.0;
    ((p * 10.0).round() / 10.0).to_string()
}

/// A model weight in percent, "below 0.1" where it would round to 0.
fn weight_percent(w: f64) -> String {
    if w < 5e-4 {
        "below 0.1".to_string()
    } else {
        percent(w)
    }
}

/// A channel's white-noise and random-walk terms by one estimator, in the curve's coefficient
/// units (deg/sqrt(s), deg/s/sqrt(s) for a gyro in deg/s; m/s/sqrt(s), m/s^2/sqrt(s) for an
/// accelerometer) with their sources (intervals written in SI units, `to_si` the conversion: deg to rad as the Kalibr writer converts, to the last bit).
fn channel_terms(
    a: &ChannelAnalysis,
    estimator: Estimator,
    to_si: fn(f64) -> f64,
) -> [Option<(f64, String, String)>; 2] {
    let name = match &a.topic {
        Some(t) => format!("{} {} ({})", a.file, t, a.channel),
        None => format!("{} ({})", a.file, a.channel),
    };
    let conf = a.curve.confidence.unwrap_or(0.683);
    match estimator {
        Estimator::Slopes => {
            let Some(s) = &a.slope_lines else { return [None, None] };
            let fit = a.model_fit.as_ref().map(|f| f.coefficients);
            let pick = |r: &Reading, fit_value: Option<f64>| -> Option<(f64, String, String)> {
                match r {
                    Reading::Value { value, site } => Some((
                        *value,
                        "value".into(),
                        format!("slope-line value read at tau {} s, {name}", site.tau_s),
                    )),
                    Reading::UpperBound { value, tau_s, .. } => Some((
                        *value,
                        "upper_bound".into(),
                        format!(
                            "UPPER BOUND, not a value: the upper end of the curve's {} % two-sided interval at tau {tau_s} s, i.e. a one-sided {} % bound; {name}",
                            percent(conf),
                            percent(one_sided(conf))
                        ),
                    )),
                    Reading::Absent { .. } => fit_value.map(|v| {
                        (v, "fit_value".into(), format!("five-term fit value (the slope lines neither read nor bound it); {name}"))
                    }),
                }
            };
            [pick(&s.arw, fit.and_then(|f| f.arw_deg_rt_s)), pick(&s.rrw, fit.and_then(|f| f.rrw_deg_s_rt_s))]
        }
        Estimator::Fit => {
            let Some(f) = &a.model_fit else { return [None, None] };
            let src = || {
                format!(
                    "weighted five-term fit over tau {} to {} s ({:?} fit); {name}",
                    f.tau_range_s.0, f.tau_range_s.1, f.quality
                )
            };
            [
                f.coefficients.arw_deg_rt_s.map(|v| (v, "fit_value".into(), src())),
                f.coefficients.rrw_deg_s_rt_s.map(|v| (v, "fit_value".into(), src())),
            ]
        }
        Estimator::Gmwm => {
            let Some(g) = a.gmwm() else { return [None, None] };
            let model: Vec<String> = g
                .parameters
                .iter()
                .map(|p| match p.correlation_time {
                    Some(t) => format!(
                        "gauss_markov(sigma {} {}, T {} s)",
                        real_text(to_si(p.value)),
                        if a.quantity == Quantity::Acceleration { "m/s^2" } else { "rad/s" },
                        real_text(t.value_s)
                    ),
                    None => p.process.name().to_string(),
                })
                .collect();
            let interval = |x: &gyrolab::gmwm::GmwmParameter, unit: &str| {
                format!(
                    "{} % two-sided interval [{}, {}] {unit} (asymptotic sandwich covariance with the scales' covariance under the fitted model, averaged over the candidate models by their criterion weights, a candidate dropped where a simpler one nested in it has a criterion as small; coverage in simulation: docs/METHODS.md 3.1)",
                    percent(g.confidence),
                    real_text(to_si(x.lower)),
                    real_text(to_si(x.upper)),
                )
            };
            let accel = a.quantity == Quantity::Acceleration;
            let poor = if g.quality == gyrolab::noise::FitQuality::Poor {
                format!(
                    "GMWM POOR FIT (weighted RMS residual {}): the model does not describe the curve; ",
                    real_text(g.weighted_rms_residual)
                )
            } else {
                String::new()
            };
            let model = format!("{}{}", poor, model.join(" + "));
            // A filter without Gauss-Markov states takes each Gauss-Markov process as the white
            // noise or the random walk that bounds it over the curve's taus (the tighter one;
            // `gauss_markov_filter_bound`), added to the model's own.
            let (tau_lo, tau_hi) = match (a.curve.points.first(), a.curve.points.last()) {
                (Some(f), Some(l)) => (f.tau_s, l.tau_s),
                _ => (a.curve.tau0_s, a.curve.tau0_s),
            };
            let (mut markov_n2, mut markov_k2, mut as_white, mut as_walk) = (0.0, 0.0, 0usize, 0usize);
            for p in g.gauss_markov() {
                let Some(t) = p.correlation_time else { continue };
                match gauss_markov_filter_bound(p.value, t.value_s, a.curve.tau0_s, tau_lo, tau_hi) {
                    MarkovBound::White { n2 } => {
                        markov_n2 += n2;
                        as_white += 1;
                    }
                    MarkovBound::RandomWalk { k2 } => {
                        markov_k2 += k2;
                        as_walk += 1;
                    }
                }
            }
            let term = |process: Process, extra2: f64, extra: usize, unit: &str, rule: &str| {
                let own = g.parameter(process);
                let total2 = own.map_or(0.0, |x| x.value * x.value) + extra2;
                if total2 <= 0.0 {
                    // A process the chosen model leaves out: its upper bound given that it is
                    // there, averaged over the candidate models holding it.
                    return g.left_out.iter().find(|b| b.process == process).map(|b| {
                        (
                            b.upper,
                            "gmwm_upper_bound".to_string(),
                            format!(
                                "GMWM: left out by the chosen model ({model}); one-sided {} % upper bound {} {unit} given that it is there (nominal: in simulation such bounds held the truth less often), from the intervals averaged over the candidate models holding it, which weigh {} % (docs/METHODS.md 3.1); {name}",
                                percent(1.0 - (1.0 - g.confidence) / 2.0),
                                real_text(to_si(b.upper)),
                                weight_percent(b.model_weight),
                            ),
                        )
                    });
                }
                if extra == 0 {
                    return own.map(|x| {
                        (
                            x.value,
                            "gmwm".to_string(),
                            format!("GMWM estimate, {}, model {model}; {name}", interval(&x, unit)),
                        )
                    });
                }
                Some((
                    total2.sqrt(),
                    "gmwm_gauss_markov_bound".to_string(),
                    format!(
                        "GMWM: {} plus {rule} bounding {extra} Gauss-Markov process(es) of the model (on or above its Allan variance at every tau, all sampled at the record's rate: the tighter of white noise sigma^2 tau0 (1 + phi) / (1 - phi), about 2 sigma^2 T, and random walk 2 sigma^2 / T over the curve's taus; docs/METHODS.md 3.1), model {model}; {name}",
                        match own {
                            Some(x) => format!("the estimate {} {unit}", real_text(to_si(x.value))),
                            None => "no term of its own".to_string(),
                        }
                    ),
                ))
            };
            let white = term(
                Process::White,
                markov_n2,
                as_white,
                if accel { "m/s^2/sqrt(Hz)" } else { "rad/s/sqrt(Hz)" },
                "the white noise N^2 = sigma^2 tau0 (1 + phi) / (1 - phi)",
            );
            let random_walk = term(
                Process::RandomWalk,
                markov_k2,
                as_walk,
                if accel { "m/s^3/sqrt(Hz)" } else { "rad/s^2/sqrt(Hz)" },
                "the random walk K^2 = 2 sigma^2 / T",
            );
            [white, random_walk]
        }
    }
}

/// The filter terms of one analysed channel by every estimator, with their overbound factors
/// on the channel's curve; `None` for a channel that is neither a gyro nor an accelerometer
/// (in calibrated units).
pub fn channel_filter_terms(a: &ChannelAnalysis) -> Option<ChannelFilterTerms> {
    let (accelerometer, to_si) = match a.quantity {
        Quantity::AngularRate => (false, units::deg_to_rad as fn(f64) -> f64),
        Quantity::Acceleration => (true, std::convert::identity as fn(f64) -> f64),
        _ => return None,
    };
    let terms = |estimator: Estimator| -> [Option<TermEstimate>; 2] {
        let t = channel_terms(a, estimator, to_si);
        let factors = overbound_factors(&a.curve, t[0].as_ref().map(|x| x.0), t[1].as_ref().map(|x| x.0), None);
        let mut out: [Option<TermEstimate>; 2] = Default::default();
        for (i, x) in t.into_iter().enumerate() {
            out[i] = x.map(|(value, basis, detail)| TermEstimate {
                value: to_si(value),
                basis,
                detail,
                overbound_factor: factors.and_then(|f| if i == 0 { f.white } else { f.random_walk }),
            });
        }
        out
    };
    // No stack has a bias-instability (flicker), quantization or drift state, and a white noise
    // or a random walk bounds none of them over the whole curve without overstating it at its
    // other end: they are named, not folded in (docs/EXPORTS.md).
    let gmwm_unrepresented = a
        .gmwm()
        .map(|g| {
            [
                (Process::Flicker, "a flicker floor (bias instability B", "rad/s", "m/s^2"),
                (Process::Quantization, "a quantization term (Q", "rad", "m/s"),
                (Process::Drift, "a drift (rate ramp R", "rad/s^2", "m/s^3"),
            ]
            .into_iter()
            .filter_map(|(process, what, gyro_unit, accel_unit)| {
                let p = g.parameter(process)?;
                Some(format!(
                    "{}: the GMWM model holds {what} = {} {}) that no stack takes; the exported values do not model it (with --overbound they are raised until the model lies on or above the curve's upper confidence bounds at the curve's taus)",
                    a.channel,
                    real_text(to_si(p.value)),
                    if accelerometer { accel_unit } else { gyro_unit }
                ))
            })
            .collect()
        })
        .unwrap_or_default();
    Some(ChannelFilterTerms {
        channel: a.channel.clone(),
        accelerometer,
        slopes: terms(Estimator::Slopes),
        fit: terms(Estimator::Fit),
        gmwm: terms(Estimator::Gmwm),
        gmwm_unrepresented,
    })
}

/// Checks `--inflate`: a positive finite factor (front ends call it before any analysis).
pub fn check_inflate(inflate: f64) -> EvalResult<()> {
    if !(inflate.is_finite() && inflate > 0.0) {
        return Err(EvalError::conflict_on(&["inflate"], format!("{{inflate}} {inflate} is not a positive number")));
    }
    Ok(())
}

/// The record an export is made for.
#[derive(Clone, Debug, PartialEq)]
pub struct ExportRecord {
    /// The record's name (file, and topic of a recording).
    pub record: String,
    /// The sample rate, Hz.
    pub rate_hz: f64,
    /// The record was written by gyrolab's simulator.
    pub simulated: bool,
    /// The ROS topic, when the record is a topic of a recording.
    pub rostopic: Option<String>,
    /// The `MOTION: ...` line of each channel that moved (the stillness check), for every
    /// file's header.
    pub motion: Vec<String>,
}

/// The noise export of one record from its channels' terms: per quantity and term the largest
/// value over the channels (after its overbound factor when overbounding), times the
/// inflation; with the warnings to show (terms that are bounds or fit values, not estimated,
/// overbound factors above 1).
pub fn combine_terms(
    record: &ExportRecord,
    channels: &[ChannelFilterTerms],
    request: &ExportRequest,
) -> EvalResult<(NoiseExport, Vec<String>)> {
    check_inflate(request.inflate)?;
    let mut slots: [Vec<&TermEstimate>; 4] = Default::default();
    for c in channels {
        let base = if c.accelerometer { 2 } else { 0 };
        for (i, t) in c.of(request.estimator).iter().enumerate() {
            if let Some(t) = t {
                slots[base + i].push(t);
            }
        }
    }
    if slots.iter().all(Vec::is_empty) {
        return Err(EvalError::conflict(
            "no noise terms for an export: give the gyro channels a unit such as --unit rad/s (accelerometers m/s^2), or calibrate outputs, and use --kind oadev with --taus octave",
        ));
    }
    let factor = |t: &TermEstimate| if request.overbound { t.overbound_factor.unwrap_or(1.0) } else { 1.0 };
    let mut warnings = Vec::new();
    let what = ["gyro white noise", "gyro random walk", "accelerometer white noise", "accelerometer random walk"];
    let mut combined: [Option<ExportTerm>; 4] = Default::default();
    for (i, list) in slots.into_iter().enumerate() {
        // The largest (after its overbound factor) over the channels, as allan_variance_ros.
        let Some(t) = list.into_iter().max_by(|a, b| (a.value * factor(a)).total_cmp(&(b.value * factor(b)))) else {
            warnings.push(format!("{} not estimated: not written to the exports", what[i]));
            continue;
        };
        if t.detail.contains("GMWM POOR FIT") {
            if !request.allow_poor_fit {
                return Err(EvalError::PoorFit(format!(
                    "{}: the {} would come from a GMWM POOR FIT ({}): a filter would take values of a model that does not describe the curve; no export file was written (allow it with {{allow_poor_fit}}, or export the slope readings)",
                    record.record, what[i], t.detail
                )));
            }
            warnings.push(format!("{} is from a GMWM POOR FIT in the exports: {}", what[i], t.detail));
        }
        if t.basis == "upper_bound" || t.basis == "fit_value" || t.basis == "gmwm_upper_bound" {
            let kind = match t.basis.as_str() {
                "upper_bound" => "an upper bound, not a value,",
                "gmwm_upper_bound" => "a GMWM bound given that the term is there (its level nominal), not a value,",
                _ => "a five-term fit value",
            };
            warnings.push(format!("{} is {kind} in the exports: {}", what[i], t.detail));
        }
        let f = request.overbound.then(|| factor(t));
        if let Some(f) = f.filter(|f| *f > 1.0) {
            warnings.push(format!("{} overbounded: x {f:.4} to lie above the curve's upper bounds", what[i]));
        }
        combined[i] = Some(ExportTerm {
            value: t.value * f.unwrap_or(1.0) * request.inflate,
            estimate: t.value,
            overbound_factor: f,
            source: TermSource { basis: t.basis.clone(), detail: t.detail.clone() },
        });
    }
    let unrepresented: Vec<String> = if request.estimator == Estimator::Gmwm {
        channels.iter().flat_map(|c| c.gmwm_unrepresented.iter().cloned()).collect()
    } else {
        Vec::new()
    };
    warnings.extend(unrepresented.iter().map(|u| format!("not represented in the exports: {u}")));
    let per_axis = per_axis_values(channels, request);
    let [gyro_noise, gyro_walk, accel_noise, accel_walk] = combined;
    let export = NoiseExport {
        record: record.record.clone(),
        rate_hz: record.rate_hz,
        simulated: record.simulated,
        estimator: request.estimator.name().to_string(),
        inflation: request.inflate,
        gyro_noise,
        gyro_walk,
        accel_noise,
        accel_walk,
        rostopic: record.rostopic.clone(),
        motion: record.motion.clone(),
        unrepresented,
        writer: env!("CARGO_PKG_VERSION").to_string(),
        per_axis,
    };
    Ok((export, warnings))
}

/// The axis (0 x, 1 y, 2 z) a channel's name names: a token `x`, `y`, `z` (`gyro_x_rad_s`,
/// `accel_y [m/s^2]`, a Vector3Stamped's `z`) or a two-letter token ending in one (`gx`, `ay`,
/// `wz`); `None` otherwise.
pub fn axis_of(name: &str) -> Option<usize> {
    let axis = |c: char| match c {
        'x' | 'X' => Some(0),
        'y' | 'Y' => Some(1),
        'z' | 'Z' => Some(2),
        _ => None,
    };
    name.split(|c: char| !c.is_ascii_alphanumeric()).find_map(|token| {
        let mut chars = token.chars();
        match (chars.next(), chars.next(), chars.next()) {
            (Some(c), None, None) => axis(c),
            (Some(_), Some(c), None) => axis(c),
            _ => None,
        }
    })
}

/// The per-axis values of each term (gyro noise, gyro walk, accelerometer noise and walk), each
/// with its overbound factor when overbounding and the inflation, where exactly one channel of
/// that kind names each of x, y and z.
fn per_axis_values(channels: &[ChannelFilterTerms], request: &ExportRequest) -> [Option<[f64; 3]>; 4] {
    let mut out = [None; 4];
    for (accelerometer, base) in [(false, 0), (true, 2)] {
        let of_kind: Vec<&ChannelFilterTerms> = channels.iter().filter(|c| c.accelerometer == accelerometer).collect();
        for term in 0..2 {
            let mut values: [Option<f64>; 3] = [None; 3];
            let mut ok = of_kind.len() == 3;
            for c in &of_kind {
                let (Some(axis), Some(t)) = (axis_of(&c.channel), &c.of(request.estimator)[term]) else {
                    ok = false;
                    break;
                };
                let f = if request.overbound { t.overbound_factor.unwrap_or(1.0) } else { 1.0 };
                if values[axis].replace(t.value * f * request.inflate).is_some() {
                    ok = false;
                }
            }
            if let (true, [Some(x), Some(y), Some(z)]) = (ok, values) {
                out[base + term] = Some([x, y, z]);
            }
        }
    }
    out
}

/// The text of one stack's file (by its name: kalibr, openvins, vins, orbslam3, basalt, px4,
/// px4-qgc, ros-covariance) from the channels' terms, with the warnings (see
/// [`combine_terms`]); the Python package's `result.export(...)`.
pub fn render_export(
    record: &ExportRecord,
    channels: &[ChannelFilterTerms],
    stack: &str,
    request: &ExportRequest,
) -> EvalResult<(String, Vec<String>)> {
    let stack = parse_stack(stack)?;
    let (export, warnings) = combine_terms(record, channels, request)?;
    Ok((export.render(stack), warnings))
}

/// Whether two output paths name one file as written ([`gyrolab_io::atomic::same_written_path`]).
pub fn same_path(a: &Path, b: &Path) -> bool {
    gyrolab_io::atomic::same_written_path(a, b)
}

/// The noise export of one record (an outcome of [`crate::allan::analyse_records`]) and the
/// warnings to show (terms that are bounds, not estimated, overbound factors).
pub fn noise_export(
    outcome: &AllanOutcome,
    file: &Path,
    request: &ExportRequest,
) -> EvalResult<(NoiseExport, Vec<String>)> {
    let channels: Vec<ChannelFilterTerms> = outcome.analyses.iter().filter_map(channel_filter_terms).collect();
    let record = ExportRecord {
        record: match &outcome.topic {
            Some(t) => format!("{} topic {}", file.display(), t.topic),
            None => file.display().to_string(),
        },
        rate_hz: 1.0 / outcome.sample_interval_s,
        simulated: gyrolab_io::provenance::is_gyrolab_simulation(file),
        rostopic: outcome.topic.as_ref().map(|t| t.topic.clone()),
        motion: outcome.analyses.iter().filter_map(|a| a.motion_line()).collect(),
    };
    combine_terms(&record, &channels, request)
}

/// The `MOTION: ...` lines of every channel of every topic of a recording that moved (the
/// stillness check), for every output of the recording: one recording moved or did not.
pub fn recording_motion(outcomes: &[AllanOutcome]) -> Vec<String> {
    outcomes.iter().flat_map(|o| o.analyses.iter().filter_map(|a| a.motion_line())).collect()
}

/// A Kalibr or imu_utils file's text with every `MOTION:` line of its recording in its header
/// (a topic that did not move is still of a recording that did), after a `%YAML` directive.
pub fn with_motion(text: String, motion: &[String]) -> String {
    let missing: Vec<&String> = motion.iter().filter(|m| !text.contains(m.as_str())).collect();
    if missing.is_empty() {
        return text;
    }
    let lines: String = missing.iter().map(|m| format!("# {m}\n")).collect();
    match text.strip_prefix("%YAML:1.0\n---\n") {
        Some(rest) => format!("%YAML:1.0\n---\n{lines}{rest}"),
        None => format!("{lines}{text}"),
    }
}

/// The export files of every record of a run (one file per topic when there are several:
/// `imu.yaml` -> `imu_<topic>.yaml`), made and checked but not written, and the warnings.
#[allow(clippy::type_complexity)]
pub fn export_files(
    outcomes: &[AllanOutcome],
    file: &Path,
    request: &ExportRequest,
) -> EvalResult<(Vec<(PathBuf, Vec<u8>)>, Vec<String>)> {
    let several = outcomes.len() > 1;
    let mut files = Vec::new();
    let mut warnings = Vec::new();
    // Motion is the recording's: every topic's file carries every channel that moved.
    let motion = recording_motion(outcomes);
    for outcome in outcomes {
        let (mut export, mut w) = noise_export(outcome, file, request)?;
        export.motion = motion.clone();
        // A channel that is neither a gyro's rate nor an accelerometer's specific force (no unit,
        // a typo in its name's unit, or a sensor output without a scale factor) has no terms a
        // stack takes: said, not dropped in silence.
        w.extend(outcome.analyses.iter().filter_map(|a| {
            let fix = match a.quantity {
                Quantity::AngularRate | Quantity::Acceleration => return None,
                Quantity::SensorOutput => "it is a sensor output (V, mV, LSB): give --scale-factor or --cal",
                Quantity::Unitless => "it has no unit: give one with --unit or in its name (gyro_x_dps, accel_x_m_s2)",
            };
            Some(format!("{}: not a gyro or accelerometer channel, so the exports leave it out; {fix}", a.channel))
        }));
        if several {
            if let Some(t) = &outcome.topic {
                w.iter_mut().for_each(|x| *x = format!("topic {}: {x}", t.topic));
            }
        }
        warnings.append(&mut w);
        for (stack, path) in &request.targets {
            let target = match (&outcome.topic, several) {
                (Some(t), true) => crate::recording::per_topic_path(path, &t.topic),
                _ => path.clone(),
            };
            files.push((target, export.render(*stack).into_bytes()));
        }
    }
    // Every file once: two targets (or two topics' names) meeting on one path would leave only
    // the last.
    for (i, (path, _)) in files.iter().enumerate() {
        if files[i + 1..].iter().any(|(other, _)| same_path(other, path)) {
            return Err(EvalError::conflict(format!(
                "{}: two exports would write this file (each output needs its own file; topics whose names clean up alike need their own target): no export file was written",
                path.display()
            )));
        }
    }
    Ok((files, warnings))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The terms cross to Python and back as JSON (`render_export`): every value must come back
    /// to the last bit. serde_json's default float parsing missed by a unit in the last place for
    /// 9,826 of these 100,000 values (a scratch build without the workspace's `float_roundtrip`
    /// feature, 2026-11-30), which changed exported digits.
    #[test]
    fn filter_terms_cross_json_to_the_last_bit() {
        let mut x: u64 = 0x9e37_79b9_7f4a_7c15;
        for _ in 0..100_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let value = (x >> 11) as f64 / (1u64 << 53) as f64 * 1e-4;
            let term =
                TermEstimate { value, basis: "value".into(), detail: String::new(), overbound_factor: Some(value) };
            let back: TermEstimate = serde_json::from_str(&serde_json::to_string(&term).unwrap()).unwrap();
            assert_eq!(back.value.to_bits(), value.to_bits(), "{value:e}");
            assert_eq!(back.overbound_factor.map(f64::to_bits), Some(value.to_bits()));
        }
    }

    /// A recording's MOTION lines go into a Kalibr or imu_utils file's header once, after the
    /// `%YAML` directive, and a line already there is not repeated.
    #[test]
    fn motion_lines_join_the_header_once() {
        let m = vec!["MOTION: a".to_string(), "MOTION: b".to_string()];
        assert_eq!(
            with_motion("%YAML:1.0\n---\nx: 1\n".into(), &m),
            "%YAML:1.0\n---\n# MOTION: a\n# MOTION: b\nx: 1\n"
        );
        assert_eq!(with_motion("# MOTION: a\nx: 1\n".into(), &m), "# MOTION: b\n# MOTION: a\nx: 1\n");
        assert_eq!(with_motion("x: 1\n".into(), &[]), "x: 1\n");
    }

    /// Axis names as channels are named (issue 54, per-axis values for Basalt).
    #[test]
    fn axes_are_read_from_channel_names() {
        for (name, axis) in [
            ("gyro_x_rad_s", Some(0)),
            ("accel_y [m/s^2]", Some(1)),
            ("z", Some(2)),
            ("gz", Some(2)),
            ("wx", Some(0)),
            ("rate_dps", None),
            ("temp_c", None),
            ("gyro", None),
        ] {
            assert_eq!(axis_of(name), axis, "{name}");
        }
    }

    /// Three gyro channels give per-axis values whose largest is the combined one; two
    /// channels, or two on one axis, give none.
    #[test]
    fn per_axis_values_need_the_three_axes_once() {
        let term = |v: f64| {
            Some(TermEstimate { value: v, basis: "value".into(), detail: String::new(), overbound_factor: Some(2.0) })
        };
        let ch = |name: &str, n: f64| ChannelFilterTerms {
            channel: name.into(),
            accelerometer: false,
            slopes: [term(n), term(n / 10.0)],
            fit: [None, None],
            gmwm: [None, None],
            gmwm_unrepresented: Vec::new(),
        };
        let request = ExportRequest {
            targets: Vec::new(),
            estimator: Estimator::Slopes,
            inflate: 3.0,
            overbound: false,
            allow_poor_fit: false,
        };
        let three = [ch("gyro_z", 3.0), ch("gyro_x", 1.0), ch("gyro_y", 2.0)];
        let v = per_axis_values(&three, &request);
        assert_eq!(v[0], Some([3.0, 6.0, 9.0]));
        assert_eq!(v[1], Some([0.30000000000000004, 0.6000000000000001, 0.8999999999999999]));
        assert_eq!((v[2], v[3]), (None, None));
        let record =
            ExportRecord { record: "r".into(), rate_hz: 100.0, simulated: false, rostopic: None, motion: Vec::new() };
        let (export, _) = combine_terms(&record, &three, &request).unwrap();
        assert_eq!(export.gyro_noise.as_ref().unwrap().value, 9.0);
        let basalt = export.per_axis[0].unwrap();
        assert!(export.render(Stack::Basalt).contains(&format!(
            "\"gyro_noise_std\": [{}, {}, {}]",
            real_text(basalt[0]),
            real_text(basalt[1]),
            real_text(basalt[2])
        )));
        assert_eq!(per_axis_values(&three[..2], &request)[0], None);
        assert_eq!(per_axis_values(&[ch("gyro_x", 1.0), ch("gx", 1.0), ch("gyro_z", 1.0)], &request)[0], None);
        // Overbounding multiplies each axis by its own factor.
        let over = ExportRequest { overbound: true, ..request };
        assert_eq!(per_axis_values(&three, &over)[0], Some([6.0, 12.0, 18.0]));
    }

    /// Paths that name one file as written: `./k.yaml` and `k.yaml`, a folder's `.`; not `..`.
    #[test]
    fn same_path_drops_dot_components() {
        assert!(same_path(Path::new("k.yaml"), Path::new("./k.yaml")));
        assert!(same_path(Path::new("a/./k.yaml"), Path::new("a/k.yaml")));
        assert!(!same_path(Path::new("a/k.yaml"), Path::new("b/k.yaml")));
    }
}
