//! The `[power_ups.<axis>]` and `[warmup.<axis>]` sections of a test plan: the scale factor and
//! bias of each power-up's record and their spread across power-ups ([`gyrolab::power_ups`]),
//! and the warm-up of a record from power-on ([`gyrolab::warmup`]); report sections, summary
//! figures, `sections.power_ups` and `sections.warmup` of results.json.

use super::static_part::{motion_of_static_record, reference_of, shown, StaticContext, StaticParts};
use super::{evaluate_plan_rates, PlanRates};
use gyrolab::static_test::StaticTestConfig;
use gyrolab::warmup::{evaluate_warmup, WarmupConfig};
use gyrolab_eval::error::{EvalError, EvalResult};
use gyrolab_eval::outcome::static_test::WarmupReport;
use gyrolab_eval::progress::{Progress, Silent};
use gyrolab_eval::static_test::evaluate_file;
use gyrolab_io::series::{read_series_all, SeriesOptions};
use gyrolab_io::test_plan::{PowerUpsPlan, RateAxisPlan, SegmentationPlan, TestPlan, WarmupPlan};
use gyrolab_io::DataError;
use gyrolab_report::power_ups::{power_ups_section, warmup_section, PowerUpFigure, PowerUpsReport, WarmupAxisReport};

/// Number of progress steps of these sections.
pub fn progress_steps(plan: &TestPlan) -> u64 {
    let p: usize = plan.power_ups.iter().map(|p| p.rate_files.len() + p.static_files.len()).sum();
    (p + plan.warmup.len()) as u64
}

fn series_options(
    sample_rate_hz: f64,
    channel: &Option<String>,
    unit: Option<gyrolab::units::OutputUnit>,
) -> SeriesOptions {
    SeriesOptions {
        sample_rate_hz: Some(sample_rate_hz),
        channels: channel.clone().map(|c| vec![c]),
        column_units: match (channel, unit) {
            (Some(c), Some(u)) => vec![(c.clone(), u)],
            _ => Vec::new(),
        },
        ..SeriesOptions::default()
    }
}

fn spread_of(values: Vec<(String, f64)>) -> PowerUpFigure {
    let v: Vec<f64> = values.iter().map(|x| x.1).collect();
    PowerUpFigure { spread: gyrolab::power_ups::spread(&v).map_err(|e| e.to_string()), values }
}

/// The scale factor K_i of each rate-table record (evaluated as `[rate.<axis>]` with the plan's
/// options), with the output unit.
fn scale_factors(
    plan: &TestPlan,
    p: &PowerUpsPlan,
    progress: &dyn Progress,
) -> EvalResult<(Vec<(String, f64)>, String)> {
    let mut out = Vec::new();
    let mut unit = String::new();
    for (i, (file, written)) in p.rate_files.iter().enumerate() {
        progress.message(&format!("axis {}: power-up {} rate-table record {written}", p.axis, i + 1));
        let one = TestPlan {
            rate: vec![RateAxisPlan {
                axis: p.axis.clone(),
                file: file.clone(),
                file_as_written: written.clone(),
                columns: p.rate_columns.clone(),
                raw: false,
                segmentation: SegmentationPlan::default(),
            }],
            ..plan.clone()
        };
        let (axes, _): PlanRates = evaluate_plan_rates(&one, &Silent)
            .map_err(|e| locate(e, &format!("power_ups.{}.rate_files[{i}]", p.axis)))?;
        let Some(a) = axes.into_iter().next() else {
            return Err(EvalError::Data(DataError::new(file, "no axis evaluated")));
        };
        let c = a.calibration();
        unit = c.output_unit.symbol().to_string();
        out.push((written.clone(), c.scale_factor));
        progress.advance(1);
    }
    Ok((out, unit))
}

/// Adds the plan key to a data error's message.
fn locate(e: EvalError, key: &str) -> EvalError {
    match e {
        EvalError::Data(mut d) => {
            d.message = format!("{key}: {}", d.message);
            EvalError::Data(d)
        }
        other => other,
    }
}

/// The bias B0_i of each static record, deg/h, with the reference used; a record that moved is
/// refused unless the plan allows motion (then a note in `notes`).
fn biases(
    p: &PowerUpsPlan,
    ctx: &StaticContext<'_>,
    progress: &dyn Progress,
    notes: &mut Vec<String>,
) -> EvalResult<(Vec<(String, f64)>, gyrolab_report::static_report::ReferenceJson)> {
    let axis = &p.axis;
    let (reference, reference_json) = reference_of(axis, ctx)?;
    let fs = p.sample_rate_hz.unwrap_or(1.0); // ok: the plan requires it with static_files
    let options = series_options(fs, &p.channel, p.output_unit);
    let config = StaticTestConfig {
        null_contains_earth_rate: reference_json.null_contains_earth_rate,
        ..StaticTestConfig::default()
    };
    let mut out = Vec::new();
    for (i, (path, written)) in p.static_files.iter().enumerate() {
        progress.message(&format!("axis {axis}: power-up {} static record {written}", i + 1));
        let key = format!("power_ups.{axis}.static_files[{i}]");
        if let Some(t) = gyrolab_eval::allan::first_times(path, &options, 10_000)? {
            if let Some(msg) =
                gyrolab_eval::allan::rate_disagreement(&t, fs, &format!("power_ups.{axis}.sample_rate_hz"), path)
            {
                return Err(EvalError::conflict(msg));
            }
        }
        let (results, _) = evaluate_file(path, &options, &reference, &config).map_err(|e| locate(e, &key))?;
        let Some(r) = results.into_iter().next() else {
            return Err(EvalError::Data(DataError::new(path, format!("{key}: no output channel to evaluate"))));
        };
        let record_key = format!("static_files[{i}]");
        let motion = ("power_ups", record_key.as_str(), fs, p.allow_motion);
        notes.extend(motion_of_static_record(path, &options, &reference, axis, motion, ctx.base)?);
        let Some(b) = r.bias_dph else {
            return Err(EvalError::Data(DataError::new(
                path,
                format!(
                    "{key}: the bias in deg/h needs a scale factor: give the axis a [rate.{axis}] record or an \
                     [options] calibration (outputs in deg/s or rad/s need none)"
                ),
            )));
        };
        out.push((shown(path, ctx.base), b));
        progress.advance(1);
    }
    Ok((out, reference_json))
}

/// Evaluates one `[power_ups.<axis>]` table.
pub fn evaluate_power_ups_axis(
    plan: &TestPlan,
    p: &PowerUpsPlan,
    ctx: &StaticContext<'_>,
    progress: &dyn Progress,
) -> EvalResult<PowerUpsReport> {
    let (scale_factor, unit) = if p.rate_files.is_empty() {
        (None, String::new())
    } else {
        let (v, u) = scale_factors(plan, p, progress)?;
        (Some(spread_of(v)), u)
    };
    let mut notes = Vec::new();
    let (bias, reference) = if p.static_files.is_empty() {
        (None, None)
    } else {
        let (v, r) = biases(p, ctx, progress, &mut notes)?;
        (Some(spread_of(v)), Some(r))
    };
    Ok(PowerUpsReport {
        axis: p.axis.clone(),
        scale_factor,
        scale_factor_unit: unit,
        bias,
        reference,
        simulated: ctx.simulated.map(|f| f(&p.axis)),
        notes,
    })
}

/// Evaluates one `[warmup.<axis>]` table: the record's outputs turned into bias in deg/h with
/// the axis's reference, times taken from power-on.
pub fn evaluate_warmup_axis(plan: &TestPlan, w: &WarmupPlan, ctx: &StaticContext<'_>) -> EvalResult<WarmupAxisReport> {
    let axis = &w.axis;
    let key = |k: &str| format!("warmup.{axis}.{k}");
    let (reference, reference_json) = reference_of(axis, ctx)?;
    let options = series_options(w.sample_rate_hz, &w.channel, w.output_unit);
    let data = read_series_all(&w.file, &options).map_err(|e| locate(EvalError::Data(e), &key("file")))?;
    let dt = 1.0 / w.sample_rate_hz;
    if let Some(t) = &data.time {
        if let Some(msg) = gyrolab_eval::allan::rate_disagreement(t, w.sample_rate_hz, &key("sample_rate_hz"), &w.file)
        {
            return Err(EvalError::conflict(msg));
        }
    }
    let n = data.lines.len();
    let timed = data.time.is_some();
    let time: Vec<f64> = match &data.time {
        Some(t) => t.clone(),
        None => (0..n).map(|i| w.power_on_s + i as f64 * dt).collect(),
    };
    let Some(&first) = time.first() else {
        return Err(EvalError::Data(DataError::new(&w.file, format!("{}: the record has no samples", key("file")))));
    };
    if first - w.power_on_s > dt * (1.0 + 1e-6) {
        return Err(EvalError::Data(
            DataError::new(
                &plan.file,
                format!(
                    "{}: the record starts {} s after power-on (its first time stamp is {first} s, power-on at \
                     power_on_s = {} s): a warm-up record must start at power-on, within one sampling interval \
                     ({dt} s); set warmup.{axis}.power_on_s to the stamp of power-on ({})",
                    key("file"),
                    gyrolab::format::short(first - w.power_on_s, 6),
                    w.power_on_s,
                    w.file.display()
                ),
            )
            .at_line(w.file_line),
        ));
    }
    let (Some(info), Some(values)) = (data.header.channels.first(), data.channels.first()) else {
        return Err(EvalError::Data(DataError::new(&w.file, format!("{}: no output channel", key("file")))));
    };
    let mut rate = values.clone();
    let converted = reference
        .to_rate(info.unit, &mut rate)
        .map_err(|m| EvalError::conflict(format!("{}: {m}", w.file.display())))?;
    if !converted {
        return Err(EvalError::Data(DataError::new(
            &w.file,
            format!(
                "{}: the warm-up needs the bias in deg/h: give the axis a [rate.{axis}] record or an [options] \
                 calibration (outputs in deg/s or rad/s need none)",
                key("file")
            ),
        )));
    }
    // Samples stamped before power-on (logging started first) are left out.
    let tol = dt * 1e-6;
    let keep: Vec<usize> = (0..n).filter(|&i| time[i] >= w.power_on_s - tol).collect();
    let dropped = n - keep.len();
    let t_rel: Vec<f64> = keep.iter().map(|&i| (time[i] - w.power_on_s).max(0.0)).collect();
    let bias: Vec<f64> = keep.iter().map(|&i| gyrolab::units::dps_to_dph(rate[i])).collect();
    let config = WarmupConfig { band: w.band_dph, window_s: w.window_s, ..WarmupConfig::new(w.band_dph) };
    let result = evaluate_warmup(&t_rel, &bias, &config)
        .map_err(|e| EvalError::Data(DataError::new(&w.file, format!("{}: warm-up: {e}", key("file")))))?;
    Ok(WarmupAxisReport {
        axis: axis.clone(),
        report: WarmupReport { file: shown(&w.file, ctx.base), channel: info.name.clone(), result },
        power_on_s: w.power_on_s,
        dropped_before_power_on: dropped,
        timed,
        reference: reference_json,
        simulated: ctx.simulated.map(|f| f(axis)),
    })
}

/// Evaluates every `[power_ups.*]` and `[warmup.*]` table into sections, figures, JSON.
pub fn evaluate_power_ups(
    plan: &TestPlan,
    ctx: &StaticContext<'_>,
    progress: &dyn Progress,
) -> EvalResult<StaticParts> {
    let mut parts = StaticParts::default();
    let mut json = serde_json::Map::new();
    for p in &plan.power_ups {
        let r = evaluate_power_ups_axis(plan, p, ctx, progress)?;
        parts.sections.push(power_ups_section(&r, ctx.limits));
        parts.figures.push(r.figures());
        parts.uncertainty_inputs.extend(super::uncertainty::power_up_inputs(&r));
        json.insert(r.axis.clone(), r.json());
    }
    if !json.is_empty() {
        parts.json.insert("power_ups".into(), serde_json::Value::Object(json));
    }
    let mut json = serde_json::Map::new();
    for w in &plan.warmup {
        progress.message(&format!("axis {}: warm-up of {}", w.axis, w.file_as_written));
        let r = evaluate_warmup_axis(plan, w, ctx)?;
        parts.sections.push(warmup_section(&r, ctx.limits).map_err(|e| EvalError::Output(e.to_string()))?);
        parts.figures.push(r.figures());
        parts.uncertainty_inputs.extend(super::uncertainty::warmup_inputs(&r));
        json.insert(r.axis.clone(), r.json());
        parts.files.push((format!("warmup_windows_{}.csv", r.axis), warmup_csv(&r).into_bytes()));
        progress.advance(1);
    }
    if !json.is_empty() {
        parts.json.insert("warmup".into(), serde_json::Value::Object(json));
    }
    Ok(parts)
}

/// The window means of a warm-up as CSV (time from power-on, bias).
fn warmup_csv(r: &WarmupAxisReport) -> String {
    let mut s = String::new();
    if let Some(sim) = &r.simulated {
        s.push_str(&format!("{}: {sim}\n", gyrolab_io::provenance::SIMULATED_DATA_MARK));
    }
    s.push_str("time_from_power_on_s,window_mean_bias_dph\n");
    for (t, b) in &r.report.result.windows {
        s.push_str(&format!("{t},{b}\n"));
    }
    s
}
