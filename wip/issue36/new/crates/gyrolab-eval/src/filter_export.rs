//! Filter noise-parameter exports of an Allan analysis (`gyrolab allan --export STACK=FILE`):
//! the white-noise and random-walk terms of the gyro and accelerometer channels by the chosen
//! estimator (slope readings, five-term fit or GMWM), optionally overbounded on each channel's
//! curve and inflated, channels combined by the largest value (docs/EXPORTS.md, docs/METHODS.md
//! "Filter exports").

use crate::allan::AllanOutcome;
use crate::error::{EvalError, EvalResult};
use gyrolab::gmwm::{overbound_factors, Process};
use gyrolab::noise::Reading;
use gyrolab::units::{self, Quantity};
use gyrolab_io::noise_export::{ExportTerm, NoiseExport, Stack, TermSource};
use gyrolab_report::allan::ChannelAnalysis;
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
    let stack = Stack::parse(stack).ok_or_else(|| {
        EvalError::conflict_on(
            &["export"],
            format!(
                "{{export}}: unknown stack '{}': expected one of {}",
                gyrolab_io::text::excerpt(stack),
                names.join(", ")
            ),
        )
    })?;
    if file.trim().is_empty() {
        return Err(EvalError::conflict_on(&["export"], format!("{{export}} {}= names no file", stack.name())));
    }
    Ok((stack, PathBuf::from(file)))
}

/// One channel's term: continuous value in the export's SI unit, before factors, its source and
/// the overbound factor.
#[derive(Clone, Debug)]
struct ChannelTerm {
    value: f64,
    source: TermSource,
    factor: Option<f64>,
}

/// The one-sided level of the upper end of a two-sided interval at `c`.
fn one_sided(c: f64) -> f64 {
    (1.0 + c) / 2.0
}

fn percent(c: f64) -> String {
    let p = c * 100.0;
    ((p * 10.0).round() / 10.0).to_string()
}

/// A channel's white-noise and random-walk terms in the curve's coefficient units (deg/sqrt(s),
/// deg/s/sqrt(s) for a gyro in deg/s; m/s/sqrt(s), m/s^2/sqrt(s) for an accelerometer) with their
/// sources.
fn channel_terms(a: &ChannelAnalysis, estimator: Estimator) -> [Option<(f64, TermSource)>; 2] {
    let name = match &a.topic {
        Some(t) => format!("{} {} ({})", a.file, t, a.channel),
        None => format!("{} ({})", a.file, a.channel),
    };
    let conf = a.curve.confidence.unwrap_or(0.683);
    match estimator {
        Estimator::Slopes => {
            let Some(s) = &a.slope_lines else { return [None, None] };
            let fit = a.model_fit.as_ref().map(|f| f.coefficients);
            let pick = |r: &Reading, fit_value: Option<f64>| -> Option<(f64, TermSource)> {
                match r {
                    Reading::Value { value, site } => Some((
                        *value,
                        TermSource { basis: "value", detail: format!("slope-line value read at tau {} s, {name}", site.tau_s) },
                    )),
                    Reading::UpperBound { value, tau_s, .. } => Some((
                        *value,
                        TermSource {
                            basis: "upper_bound",
                            detail: format!(
                                "UPPER BOUND, not a value: the upper end of the curve's {} % two-sided interval at tau {tau_s} s, i.e. a one-sided {} % bound; {name}",
                                percent(conf),
                                percent(one_sided(conf))
                            ),
                        },
                    )),
                    Reading::Absent { .. } => fit_value.map(|v| {
                        (v, TermSource { basis: "fit_value", detail: format!("five-term fit value (the slope lines neither read nor bound it); {name}") })
                    }),
                }
            };
            [pick(&s.arw, fit.and_then(|f| f.arw_deg_rt_s)), pick(&s.rrw, fit.and_then(|f| f.rrw_deg_s_rt_s))]
        }
        Estimator::Fit => {
            let Some(f) = &a.model_fit else { return [None, None] };
            let src = || TermSource {
                basis: "fit_value",
                detail: format!(
                    "weighted five-term fit over tau {} to {} s ({:?} fit); {name}",
                    f.tau_range_s.0, f.tau_range_s.1, f.quality
                ),
            };
            [f.coefficients.arw_deg_rt_s.map(|v| (v, src())), f.coefficients.rrw_deg_s_rt_s.map(|v| (v, src()))]
        }
        Estimator::Gmwm => {
            let Some(g) = &a.gmwm else { return [None, None] };
            let model: Vec<&str> = g.parameters.iter().map(|p| p.process.name()).collect();
            let term = |p: Process| {
                g.parameter(p).map(|x| {
                    (
                        x.value,
                        TermSource {
                            basis: "gmwm",
                            detail: format!(
                                "GMWM estimate, {} % two-sided interval [{:e}, {:e}] (curve units; asymptotic with scales taken as independent: too narrow), model {}; {name}",
                                percent(g.confidence),
                                x.lower,
                                x.upper,
                                model.join(" + ")
                            ),
                        },
                    )
                })
            };
            [term(Process::White), term(Process::RandomWalk)]
        }
    }
}

/// The noise export of one record (an outcome of [`crate::allan::analyse_records`]) and the
/// warnings to show (terms that are bounds, not estimated, overbound factors).
pub fn noise_export(
    outcome: &AllanOutcome,
    file: &Path,
    request: &ExportRequest,
) -> EvalResult<(NoiseExport, Vec<String>)> {
    if !(request.inflate.is_finite() && request.inflate > 0.0) {
        return Err(EvalError::conflict_on(
            &["inflate"],
            format!("{{inflate}} {} is not a positive number", request.inflate),
        ));
    }
    // Per quantity and term: the channels' values in SI continuous units.
    let mut slots: [Vec<ChannelTerm>; 4] = Default::default();
    for a in &outcome.analyses {
        let (base, to_si) = match a.quantity {
            Quantity::AngularRate => (0, units::deg_to_rad(1.0)),
            Quantity::Acceleration => (2, 1.0),
            _ => continue,
        };
        let terms = channel_terms(a, request.estimator);
        let factors = if request.overbound {
            overbound_factors(&a.curve, terms[0].as_ref().map(|t| t.0), terms[1].as_ref().map(|t| t.0), None)
        } else {
            None
        };
        for (i, t) in terms.into_iter().enumerate() {
            let Some((v, source)) = t else { continue };
            let factor = factors.and_then(|f| if i == 0 { f.white } else { f.random_walk });
            slots[base + i].push(ChannelTerm { value: v * to_si, source, factor });
        }
    }
    if slots.iter().all(Vec::is_empty) {
        return Err(EvalError::conflict(
            "no noise terms for an export: give the gyro channels a unit such as --unit rad/s (accelerometers m/s^2), or calibrate outputs, and use --kind oadev with --taus octave",
        ));
    }
    let mut warnings = Vec::new();
    let what = ["gyro white noise", "gyro random walk", "accelerometer white noise", "accelerometer random walk"];
    let mut combined: [Option<ExportTerm>; 4] = Default::default();
    for (i, list) in slots.into_iter().enumerate() {
        // The largest (after its overbound factor) over the channels, as allan_variance_ros.
        let best = list
            .into_iter()
            .max_by(|a, b| (a.value * a.factor.unwrap_or(1.0)).total_cmp(&(b.value * b.factor.unwrap_or(1.0))));
        let Some(t) = best else {
            warnings.push(format!("{} not estimated: not written to the exports", what[i]));
            continue;
        };
        if t.source.basis == "upper_bound" || t.source.basis == "fit_value" {
            warnings.push(format!("{} is a {} in the exports: {}", what[i], t.source.basis, t.source.detail));
        }
        if let Some(f) = t.factor.filter(|f| *f > 1.0) {
            warnings.push(format!("{} overbounded: x {f:.4} to lie above the curve's upper bounds", what[i]));
        }
        let value = t.value * t.factor.unwrap_or(1.0) * request.inflate;
        combined[i] = Some(ExportTerm { value, estimate: t.value, overbound_factor: t.factor, source: t.source });
    }
    let [gyro_noise, gyro_walk, accel_noise, accel_walk] = combined;
    let record = match &outcome.topic {
        Some(t) => format!("{} topic {}", file.display(), t.topic),
        None => file.display().to_string(),
    };
    let export = NoiseExport {
        record,
        rate_hz: 1.0 / outcome.sample_interval_s,
        simulated: gyrolab_io::noise_export::is_gyrolab_simulation(file),
        estimator: request.estimator.name().to_string(),
        inflation: request.inflate,
        gyro_noise,
        gyro_walk,
        accel_noise,
        accel_walk,
        rostopic: outcome.topic.as_ref().map(|t| t.topic.clone()),
        writer: env!("CARGO_PKG_VERSION").to_string(),
    };
    Ok((export, warnings))
}

/// Writes the exports of every record of a run (one file per topic when there are several:
/// imu.yaml -> imu_<topic>.yaml), all or none; returns the files written and the warnings.
pub fn write_exports(
    outcomes: &[AllanOutcome],
    file: &Path,
    request: &ExportRequest,
) -> EvalResult<(Vec<PathBuf>, Vec<String>)> {
    let several = outcomes.len() > 1;
    let mut files = Vec::new();
    let mut warnings = Vec::new();
    for outcome in outcomes {
        let (export, mut w) = noise_export(outcome, file, request)?;
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
    let written = gyrolab_io::atomic::write_files(&files)
        .map_err(|(path, e)| EvalError::Output(format!("{}: {e} (no export file was written)", path.display())))?;
    Ok((written, warnings))
}
