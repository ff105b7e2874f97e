//! The temperature tests of a plan (`[temperature.<axis>]`): each soaked point's rate-table record
//! (K, rest reference) and static record (mean output, bias), the models K(T), F(T) and B(T), the
//! temperature sensitivities and thermal hysteresis ([`gyrolab::thermal`]), and the compensation
//! written into calibration.toml.

use crate::test_plan::static_part::{reference_of, static_null_of, StaticContext};
use gyrolab::rate_test::RateTestOptions;
use gyrolab::thermal::{fit_model, hysteresis, sensitivity, NotResolved, PointSeries};
use gyrolab::units::OutputUnit;
use gyrolab_eval::error::{EvalError, EvalResult};
use gyrolab_eval::progress::Progress;
use gyrolab_eval::rate::{evaluate_record, EvaluatedAxis};
use gyrolab_eval::reference::Reference;
use gyrolab_io::calibration::TemperatureSection;
use gyrolab_io::rate_table::read_rate_table;
use gyrolab_io::series::{read_series, SeriesOptions};
use gyrolab_io::test_plan::temperature::TemperaturePlan;
use gyrolab_io::DataError;
use gyrolab_report::thermal::{ModelOrReason, PointReport, Resolved, TemperatureAxisReport};
use std::path::Path;

/// What the temperature part adds to a report: one report per axis and the compensation models
/// for calibration.toml (axis, section).
pub struct TemperatureParts {
    /// Evaluated axes.
    pub reports: Vec<TemperatureAxisReport>,
    /// Compensation models by axis.
    pub compensation: Vec<(String, TemperatureSection)>,
}

/// Mean output (in `unit`) and mean recorded temperature of a static record's channel.
fn static_mean(
    path: &Path,
    plan: &TemperaturePlan,
    unit: Option<OutputUnit>,
    key: &str,
) -> EvalResult<(f64, Option<f64>, OutputUnit)> {
    let options = SeriesOptions {
        sample_rate_hz: plan.sample_rate_hz,
        channels: plan.channel.clone().map(|c| vec![c]),
        column_units: match (&plan.channel, plan.output_unit) {
            (Some(c), Some(u)) => vec![(c.clone(), u)],
            _ => Vec::new(),
        },
        ..SeriesOptions::default()
    };
    let (mut sum, mut n, mut tsum, mut tn) = (0.0f64, 0u64, 0.0f64, 0u64);
    let summary = read_series(path, &options, |_, b| {
        if let Some(c) = b.channels.first() {
            sum += c.iter().sum::<f64>();
            n += c.len() as u64;
        }
        if let Some(t) = b.temp {
            tsum += t.iter().sum::<f64>();
            tn += t.len() as u64;
        }
        Ok(())
    })?;
    let Some(ch) = summary.header.channels.first() else {
        return Err(EvalError::Data(DataError::new(path, format!("{key}: no output channel in the static record"))));
    };
    if n == 0 {
        return Err(EvalError::Data(DataError::new(path, format!("{key}: the static record has no sample"))));
    }
    let target = unit.unwrap_or(ch.unit);
    let factor = ch.unit.factor_to(target).ok_or_else(|| {
        EvalError::Data(
            DataError::new(
                path,
                format!("{key}: the static record is in {} but the rate-table records are in {}", ch.unit, target),
            )
            .at_line(summary.header.header_line)
            .at_column(ch.column, Some(&ch.name)),
        )
    })?;
    Ok((sum / n as f64 * factor, (tn > 0).then(|| tsum / tn as f64), target))
}

fn model_or(r: Result<gyrolab::thermal::TemperatureModel, NotResolved>) -> ModelOrReason {
    match r {
        Ok(m) => ModelOrReason::Model(m),
        Err(e) => ModelOrReason::NotResolved(e),
    }
}

/// Evaluates one axis.
fn evaluate_axis(
    plan: &TemperaturePlan,
    options: &RateTestOptions,
    ctx: &StaticContext<'_>,
    progress: &dyn Progress,
) -> EvalResult<(TemperatureAxisReport, Option<TemperatureSection>)> {
    let axis = &plan.axis;
    let order = plan.order;
    let tref = plan.reference_temp_c;
    // Rate-table records: K_i and the rest reference of each point.
    let mut rated: Vec<Option<EvaluatedAxis>> = Vec::with_capacity(plan.points.len());
    for (i, p) in plan.points.iter().enumerate() {
        rated.push(match &p.rate_file {
            None => None,
            Some(path) => {
                progress.message(&format!("axis {axis}: rate-table test at {} degC", p.temperature_c));
                let record = read_rate_table(path, &plan.rate_columns)?;
                let shown = p.files_as_written.0.clone().unwrap_or_default();
                let e = evaluate_record(axis.clone(), shown, record, options).map_err(|e| match e {
                    EvalError::Data(d) => EvalError::Data(DataError::new(
                        path,
                        format!("temperature.{axis}.points[{i}].rate: {}", d.message),
                    )),
                    other => other,
                })?;
                Some(e)
            }
        });
    }
    let unit = rated.iter().flatten().map(|e| e.record.output_unit).next();
    if let Some(u) = unit {
        if let Some((i, e)) =
            rated.iter().enumerate().find_map(|(i, e)| e.as_ref().filter(|e| e.record.output_unit != u).map(|e| (i, e)))
        {
            return Err(EvalError::conflict(format!(
                "temperature.{axis}.points[{i}].rate: outputs in {} where the other points' are in {u}: the points \
                 of one axis must share a unit",
                e.record.output_unit
            )));
        }
    }
    let (reference, _) = reference_of(axis, ctx)?;
    let (ref_k, ref_null, ref_unit) = match reference {
        Reference::Calibrated { scale_factor, null, unit } => (Some(scale_factor), Some(null), Some(unit)),
        _ => (None, None, None),
    };
    let unit = unit.or(ref_unit);
    // Static records: mean output of each point.
    let mut statics: Vec<Option<(f64, Option<f64>)>> = Vec::with_capacity(plan.points.len());
    let mut static_unit = unit;
    for (i, p) in plan.points.iter().enumerate() {
        statics.push(match &p.static_file {
            None => None,
            Some(path) => {
                progress.message(&format!("axis {axis}: static test at {} degC", p.temperature_c));
                let key = format!("temperature.{axis}.points[{i}].static");
                let (m, t, u) = static_mean(path, plan, static_unit, &key)?;
                static_unit = Some(u);
                Some((m, t))
            }
        });
        progress.advance(1);
    }
    let unit = static_unit.or(unit).unwrap_or(OutputUnit::Unitless);
    let convert = |v: f64, from: Option<OutputUnit>| from.and_then(|f| f.factor_to(unit)).map_or(v, |k| v * k);
    let temps: Vec<f64> = plan.points.iter().map(|p| p.temperature_c).collect();
    let phases: Vec<_> = plan.points.iter().map(|p| p.phase).collect();
    let pick = |f: &dyn Fn(usize) -> Option<f64>| -> (Vec<f64>, Vec<gyrolab::thermal::Phase>, Vec<f64>) {
        let idx: Vec<usize> = (0..temps.len()).filter(|&i| f(i).is_some()).collect();
        (
            idx.iter().map(|&i| temps[i]).collect(),
            idx.iter().map(|&i| phases[i]).collect(),
            idx.iter().filter_map(|&i| f(i)).collect(),
        )
    };
    let k_of = |i: usize| rated[i].as_ref().map(|e| e.evaluation.scale_factor());
    let (kt, kp, kv) = pick(&k_of);
    let k_model = fit_model(&kt, &kv, order, tref);
    // K at the reference temperature: the straight line's value there (the sensitivity's divisor).
    let k_line_ref = fit_model(&kt, &kv, 1, tref).ok().map(|m| m.coefficients[0]);
    // Null model: the static means, else the rate tests' rest references.
    let (st, _, sv) = pick(&|i| statics[i].map(|s| s.0));
    let (rt, _, rv) = pick(&|i| rated[i].as_ref().map(static_null_of));
    let (null_model, null_source) = match fit_model(&st, &sv, order, tref) {
        Ok(m) => (Ok(m), Some("static_means")),
        Err(e) if rt.is_empty() => (Err(e), None),
        Err(_) => match fit_model(&rt, &rv, order, tref) {
            Ok(m) => (Ok(m), Some("rate_test_nulls")),
            Err(e) => (Err(e), None),
        },
    };
    // The null the biases are taken against.
    let nearest = (0..temps.len())
        .filter(|&i| statics[i].is_some())
        .min_by(|&a, &b| (temps[a] - tref).abs().total_cmp(&(temps[b] - tref).abs()));
    let (bias_null, bias_null_source) = match (ref_null, nearest) {
        (Some(n), _) => (
            convert(n, ref_unit),
            format!("the static null of this plan's reference for axis {axis} (its [rate.{axis}] record or the calibration file)"),
        ),
        (None, Some(i)) => (
            statics[i].map_or(0.0, |s| s.0),
            format!(
                "the static mean at the point nearest the reference temperature ({} degC): biases are relative to it",
                temps[i]
            ),
        ),
        (None, None) => (0.0, "none (no static record)".into()),
    };
    let mut points = Vec::with_capacity(plan.points.len());
    for (i, p) in plan.points.iter().enumerate() {
        let k = k_of(i)
            .or_else(|| k_model.as_ref().ok().map(|m| m.eval(p.temperature_c)))
            .or(ref_k.map(|k| convert(k, ref_unit)));
        let bias_dph = match (statics[i], k) {
            (Some((m, _)), Some(k)) => Some((m - bias_null) / k * 3600.0),
            (Some(_), None) => {
                return Err(EvalError::conflict(format!(
                    "temperature.{axis}.points[{i}].static: no scale factor to turn the output into a bias: give the \
                     points rate-table records, or the plan a [rate.{axis}] table or options.calibration"
                )))
            }
            _ => None,
        };
        points.push(PointReport {
            temperature_c: p.temperature_c,
            phase: p.phase,
            rate_file: p.files_as_written.0.clone(),
            static_file: p.files_as_written.1.clone(),
            scale_factor: k_of(i),
            rate_test_null: rated[i].as_ref().map(static_null_of),
            static_mean: statics[i].map(|s| s.0),
            recorded_temperature_c: statics[i].and_then(|s| s.1),
            bias_dph,
        });
    }
    let (bt, bp, bv) = pick(&|i| points[i].bias_dph);
    let per_ppm = k_line_ref.map(|k| k / 1e6);
    let k_sens = match per_ppm {
        Some(per) => sensitivity(&kt, &kv, tref, per),
        None => Err(NotResolved::TooFewPoints { found: kt.len(), needed: 2 }),
    };
    let k_hyst = match per_ppm {
        Some(per) => hysteresis(&PointSeries { temps_c: &kt, phases: &kp, values: &kv }, per),
        None => Err(NotResolved::NoHeatingCoolingPair),
    };
    let (compensation, section) = match (&k_model, &null_model) {
        (Ok(k), Ok(f)) => {
            let s = TemperatureSection {
                reference_temp_c: tref,
                temp_min_c: k.temp_min_c.max(f.temp_min_c),
                temp_max_c: k.temp_max_c.min(f.temp_max_c),
                scale_factor_coefficients: k.coefficients.clone(),
                null_coefficients: f.coefficients.clone(),
            };
            match s.compensation() {
                Ok(_) if ctx.rate_axes.iter().any(|a| a.name == *axis) => (
                    format!(
                        "K(T) and F(T) are written into calibration.toml ([axis.temperature] of axis {axis}); \
                         `gyrolab apply` brings each output to {} degC by them when its input has a temperature column.",
                        tref
                    ),
                    Some(s),
                ),
                Ok(_) => (
                    format!(
                        "not written: the plan has no [rate.{axis}] table, so calibration.toml has no entry for axis \
                         {axis} (the models are in results.json)"
                    ),
                    None,
                ),
                Err(e) => (format!("not written: {e}"), None),
            }
        }
        (Err(e), _) | (_, Err(e)) => (format!("not written: {}", e.text()), None),
    };
    let report = TemperatureAxisReport {
        axis: axis.clone(),
        output_unit: unit.symbol().to_string(),
        order,
        reference_temp_c: tref,
        bias_null,
        bias_null_source,
        scale_factor_model: model_or(k_model),
        null_model: model_or(null_model),
        null_model_source: null_source.map(str::to_string),
        bias_model: model_or(fit_model(&bt, &bv, order, tref)),
        scale_factor_temp_sensitivity_ppm_per_c: Resolved::from(k_sens),
        bias_temp_sensitivity_dph_per_c: Resolved::from(sensitivity(&bt, &bv, tref, 1.0)),
        scale_factor_thermal_hysteresis_ppm: Resolved::from(k_hyst),
        bias_thermal_hysteresis_dph: Resolved::from(hysteresis(
            &PointSeries { temps_c: &bt, phases: &bp, values: &bv },
            1.0,
        )),
        compensation,
        simulated: ctx.simulated.map(|f| f(axis)),
        points,
    };
    Ok((report, section))
}

/// Number of progress steps of the temperature part.
pub fn progress_steps(plans: &[TemperaturePlan]) -> u64 {
    plans.iter().map(|p| p.points.len() as u64).sum()
}

/// Evaluates every `[temperature.<axis>]` table.
pub fn evaluate_temperature(
    plans: &[TemperaturePlan],
    options: &RateTestOptions,
    ctx: &StaticContext<'_>,
    progress: &dyn Progress,
) -> EvalResult<TemperatureParts> {
    let mut parts = TemperatureParts { reports: Vec::new(), compensation: Vec::new() };
    for p in plans {
        let (r, s) = evaluate_axis(p, options, ctx, progress)?;
        if let Some(s) = s {
            parts.compensation.push((p.axis.clone(), s));
        }
        parts.reports.push(r);
    }
    Ok(parts)
}
