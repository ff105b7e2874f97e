//! A calibration applied to a time series of outputs, streaming: outputs in, rates out
//! ([`gyrolab::apply`]: the polynomial model inverted per sample, or the three-axis model).

use crate::error::{EvalError, EvalResult};
use gyrolab::apply::{SingleAxisCalibration, TriadApplier};
use gyrolab::units::split_unit_suffix;
use gyrolab_io::apply_csv::{apply_file, ApplyModel, ApplyPlan, ApplySummary, StreamError};
use gyrolab_io::calibration::read_calibration;
use gyrolab_io::raw_log::{detect_raw_log, header_names};
use gyrolab_io::DataError;
use std::io::Write;
use std::path::{Path, PathBuf};

/// A calibration to apply to a file.
///
/// ```
/// use gyrolab_eval::apply::{apply_to, prepare_apply, ApplyRequest};
/// use gyrolab_eval::rate::{calibration_file, evaluate_rates, RateRequest};
/// // A calibration of the paper's axis x (K about 7.3 mV/(deg/s)), written as `rate --cal-out` does.
/// let paper = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/paper/paper_rate_table_x.csv");
/// let rate = RateRequest { files: vec![paper], axis_names: vec!["x".into()], ..Default::default() };
/// let axes = evaluate_rates(&rate)?.axes;
/// let (k, f0) = (axes[0].evaluation.scale_factor(), axes[0].evaluation.zero_offset());
/// let dir = tempfile::tempdir()?;
/// let cal = dir.path().join("cal.toml");
/// std::fs::write(&cal, calibration_file(&axes).to_toml()?)?;
/// // Outputs at 0 and 100 deg/s by that line.
/// let input = dir.path().join("outputs.csv");
/// std::fs::write(&input, format!("time_s,output_v\n0,{f0}\n0.01,{}\n", f0 + 100.0 * k))?;
/// let request = ApplyRequest { calibration: cal, input: input.clone(), calibration_axis: None, columns: vec![] };
/// let plan = prepare_apply(&request)?;
/// assert_eq!(plan.columns, ["output_v"]);
/// let mut out = Vec::new();
/// let summary = apply_to(&input, &plan, &mut out, &mut |_| {})?;
/// assert_eq!(summary.rows, 2);
/// let text = String::from_utf8(out)?;
/// let rates: Vec<f64> = text.lines().skip(1).map(|l| l.split(',').nth(1).map_or(Ok(f64::NAN), str::parse)).collect::<Result<_, _>>()?;
/// assert!(rates[0].abs() < 1e-9 && (rates[1] - 100.0).abs() < 1e-9, "{text}");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct ApplyRequest {
    /// Calibration file (written by `gyrolab rate --cal-out`).
    pub calibration: PathBuf,
    /// Time series of outputs.
    pub input: PathBuf,
    /// The `[[axis]]` to apply (default: the `[triad]` when there is one, else the only axis).
    pub calibration_axis: Option<String>,
    /// Output column(s): one for an axis, three (x, y, z) for a `[triad]` (default: the file's
    /// only output, or the columns named after the axes).
    pub columns: Vec<String>,
}

/// Chooses the output columns: given, the file's only ones, or those whose base name is an axis name.
fn choose_columns(input: &Path, given: &[String], axis_names: &[String], skip: &[String]) -> EvalResult<Vec<String>> {
    let n = axis_names.len();
    if !given.is_empty() {
        if given.len() != n {
            return Err(EvalError::conflict_on(
                &["columns"],
                format!("{{columns}} needs {n} name(s) for this calibration, got {}", given.len()),
            ));
        }
        return Ok(given.to_vec());
    }
    let names = header_names(input)?;
    let outputs: Vec<&String> = names
        .iter()
        .filter(|c| {
            let (base, sfx) = split_unit_suffix(c);
            let special = matches!(base.as_str(), "time" | "t" | "timestamp" | "temp" | "temperature");
            !special && sfx.is_some() && !skip.iter().any(|s| s.eq_ignore_ascii_case(c))
        })
        .collect();
    if outputs.len() == n {
        return Ok(outputs.into_iter().cloned().collect());
    }
    let by_axis: Option<Vec<String>> = axis_names
        .iter()
        .map(|a| outputs.iter().find(|c| split_unit_suffix(c).0.eq_ignore_ascii_case(a)).map(|c| c.to_string()))
        .collect();
    by_axis.ok_or_else(|| {
        EvalError::conflict_on(
            &["columns"],
            format!(
                "{}: {} output column(s) ({}) where the calibration needs {n} ({}): choose with {{columns}}",
                input.display(),
                outputs.len(),
                outputs.iter().map(|s| s.as_str()).collect::<Vec<_>>().join(", "),
                axis_names.join(", ")
            ),
        )
    })
}

/// The model of a calibration file: its `[triad]` (unless an axis is named) or the named (or
/// only) `[[axis]]`, with its output unit and the names of the axes it gives rates for.
#[allow(clippy::type_complexity)]
fn model_of(
    calibration: &Path,
    axis: Option<&str>,
) -> EvalResult<(ApplyModel, gyrolab::units::OutputUnit, Vec<String>, Option<gyrolab::thermal::Compensation>)> {
    let cal = read_calibration(calibration)?;
    let cal_err = |msg: String| EvalError::Data(DataError::new(calibration, msg));
    Ok(match (&cal.triad, axis) {
        (Some(t), None) => {
            let model = TriadApplier::new(&t.calibration()).map_err(|e| cal_err(format!("[triad]: {e}")))?;
            (ApplyModel::Triad(model), t.output_unit, t.axes.to_vec(), None)
        }
        (_, name) => {
            let axis = cal.axis(name).map_err(cal_err)?;
            let model =
                SingleAxisCalibration::polynomial(&axis.polynomial.coefficients, axis.rate_min_dps, axis.rate_max_dps)
                    .map_err(|e| cal_err(format!("axis '{}': {e}", axis.name)))?;
            let temperature = axis
                .temperature
                .as_ref()
                .map(|t| t.compensation())
                .transpose()
                .map_err(|e| cal_err(format!("axis '{}', [axis.temperature]: {e}", axis.name)))?;
            (ApplyModel::Single(model), axis.output_unit, vec![axis.name.clone()], temperature)
        }
    })
}

/// The streaming plan of a request: the model, the columns it reads and writes.
pub fn prepare_apply(request: &ApplyRequest) -> EvalResult<ApplyPlan> {
    let (model, output_unit, axes, temperature) = model_of(&request.calibration, request.calibration_axis.as_deref())?;
    let names = header_names(&request.input)?;
    // A raw log's table rate is passed through (as table_rate_dps), beside the calibrated rate.
    let table_rate = detect_raw_log(&names);
    let skip: Vec<String> = table_rate.iter().cloned().collect();
    let rate_names = match model {
        ApplyModel::Triad(_) => axes.iter().map(|a| format!("rate_{a}_dps")).collect(),
        ApplyModel::Single(_) => vec!["rate_dps".into()],
    };
    Ok(ApplyPlan {
        model,
        output_unit,
        columns: choose_columns(&request.input, &request.columns, &axes, &skip)?,
        rate_names,
        table_rate_column: table_rate,
        temperature,
    })
}

/// Rates from outputs held in memory (one array for an axis, three x, y, z for a `[triad]`, in
/// the calibration's output unit): the rates (deg/s, one array per axis) and each sample's range
/// status.
pub fn apply_arrays(
    calibration: &Path,
    axis: Option<&str>,
    outputs: &[&[f64]],
) -> EvalResult<(Vec<Vec<f64>>, Vec<gyrolab::apply::RangeStatus>)> {
    let (model, _, axes, temperature) = model_of(calibration, axis)?;
    if temperature.is_some() {
        return Err(EvalError::conflict(format!(
            "{}: the calibration compensates for temperature; arrays without temperatures cannot be applied \
             (apply a file with a temperature column)",
            calibration.display()
        )));
    }
    let n = outputs.first().map_or(0, |o| o.len());
    if outputs.len() != axes.len() || outputs.iter().any(|o| o.len() != n) {
        return Err(EvalError::conflict(format!(
            "the calibration needs {} output array(s) of one length ({}), got {}",
            axes.len(),
            axes.join(", "),
            outputs.len()
        )));
    }
    match model {
        ApplyModel::Single(m) => {
            let mut out = Vec::with_capacity(n);
            m.apply_block(outputs[0], &mut out);
            Ok((vec![out.iter().map(|r| r.rate_dps).collect()], out.iter().map(|r| r.status).collect()))
        }
        ApplyModel::Triad(m) => {
            let mut out = Vec::with_capacity(n);
            m.apply_block(outputs[0], outputs[1], outputs[2], &mut out)
                .map_err(|e| EvalError::Data(DataError::new(calibration, format!("[triad]: {e}"))))?;
            let rates = (0..3).map(|k| out.iter().map(|r| r.rates_dps[k]).collect()).collect();
            Ok((rates, out.iter().map(|r| r.status).collect()))
        }
    }
}

/// An input as the streaming apply reads it: a delimited text file as it is, or one IMU topic of
/// a recording (MCAP, ROS 1 bag, ULog) or a Parquet table written to a temporary CSV file
/// (`timestamp_ns` or `time_s` and the channels with their units in the names).
#[derive(Debug)]
pub struct StagedInput {
    /// The file to stream.
    pub path: PathBuf,
    /// What was staged, for a note (`None` for a text file).
    pub note: Option<String>,
    /// The temporary folder holding the staged file (removed when dropped).
    _dir: Option<tempfile::TempDir>,
}

/// Stages `input` for [`prepare_apply`] and [`apply_to`]: a text file is used as it is; a
/// recording's IMU topic (`topic`, needed when it has several) or a Parquet table is written as
/// CSV to a temporary folder, so every input takes the one streaming path.
pub fn stage_input(input: &Path, topic: Option<&str>) -> EvalResult<StagedInput> {
    use gyrolab_io::recording::{read_recording, sniff_format, FileFormat, RecordingOptions};
    let format = sniff_format(input)?;
    if format == FileFormat::Text {
        if let Some(t) = topic {
            return Err(EvalError::conflict_on(
                &["topics"],
                format!(
                    "{}: {{topics}} '{t}' given, but this is a delimited text file, not a recording",
                    input.display()
                ),
            ));
        }
        return Ok(StagedInput { path: input.to_path_buf(), note: None, _dir: None });
    }
    let dir = tempfile::Builder::new()
        .prefix(".gyrolab-apply-")
        .tempdir()
        .map_err(|e| EvalError::Output(format!("cannot create a temporary folder: {e}")))?;
    let stem = input.file_stem().map_or("input".into(), |s| s.to_string_lossy().to_string());
    let path = dir.path().join(format!("{stem}.csv"));
    let write_err = |e: std::io::Error| EvalError::Output(format!("{}: cannot write the file: {e}", path.display()));
    let note = if format == FileFormat::Parquet {
        let data = gyrolab_io::parquet_table::read_parquet(input, &gyrolab_io::series::SeriesOptions::default())?;
        let mut names: Vec<String> = Vec::new();
        let mut cols: Vec<&[f64]> = Vec::new();
        if let Some(t) = &data.time {
            names.push("time_s".into());
            cols.push(t);
        }
        for (info, c) in data.header.channels.iter().zip(&data.channels) {
            names.push(info.name.clone());
            cols.push(c);
        }
        gyrolab_io::atomic::write_atomic_with(&path, |w| {
            let mut w = std::io::BufWriter::new(w);
            writeln!(w, "{}", names.join(","))?;
            let mut fmt = ryu::Buffer::new();
            for i in 0..data.lines.len() {
                let row: Vec<String> = cols.iter().map(|c| fmt.format(c[i]).to_string()).collect();
                writeln!(w, "{}", row.join(","))?;
            }
            w.flush()
        })
        .map_err(write_err)?;
        format!("{}: Parquet table, {} rows", input.display(), data.lines.len())
    } else {
        let topics: Vec<String> = topic.map(str::to_string).into_iter().collect();
        let rec = read_recording(input, &RecordingOptions { topics, ..Default::default() })?;
        if rec.imu.len() > 1 {
            let names: Vec<String> = rec.imu.iter().map(|t| gyrolab_io::text::excerpt(&t.topic)).collect();
            return Err(EvalError::conflict_on(
                &["topics"],
                format!(
                    "{}: {} IMU topics ({}): choose one with {{topics}}",
                    input.display(),
                    names.len(),
                    names.join(", ")
                ),
            ));
        }
        let t = &rec.imu[0];
        gyrolab_io::atomic::write_atomic_with(&path, |w| gyrolab_io::recording::write_topic_csv(w, t))
            .map_err(write_err)?;
        let mut note =
            format!("{}: topic {} ({}), {} messages", input.display(), t.topic, t.message_type, t.stamps_ns.len());
        if let Some(w) = &rec.truncated {
            note.push_str(&format!("; {w}"));
        }
        note
    };
    Ok(StagedInput { path, note: Some(note), _dir: Some(dir) })
}

/// Streams the input through the plan into `out`; `progress` gets the rows done so far.
pub fn apply_to(
    input: &Path,
    plan: &ApplyPlan,
    out: &mut dyn Write,
    progress: &mut dyn FnMut(u64),
) -> Result<ApplySummary, StreamError> {
    apply_file(input, plan, out, progress)
}

/// Streams the input through the plan into the file `out`, written whole or not at all and never
/// over one of `inputs` (the record, the calibration); `progress` gets the rows done so far.
pub fn apply_into(
    input: &Path,
    plan: &ApplyPlan,
    out: &Path,
    inputs: &[&Path],
    progress: &mut dyn FnMut(u64),
) -> EvalResult<ApplySummary> {
    let (mut data_error, mut done) = (None, None);
    let output = gyrolab_io::atomic::OutputFile::stream(out, |w| match apply_to(input, plan, w, progress) {
        Ok(s) => {
            done = Some(s);
            Ok(())
        }
        Err(StreamError::Write(e)) => Err(e),
        Err(StreamError::Data(d)) => {
            data_error = Some(d);
            Err(std::io::Error::other("bad input"))
        }
    });
    let r = gyrolab_io::atomic::write_outputs(vec![output], inputs);
    if let Some(d) = data_error {
        return Err(EvalError::Data(d));
    }
    r?;
    Ok(done.unwrap_or_default())
}

/// The lines `gyrolab apply` prints on stderr: the rows applied (to `out`) and flagged, and the
/// rows compensated for temperature.
pub fn summary_lines(s: &ApplySummary, out: Option<&Path>) -> Vec<String> {
    let mut lines = Vec::new();
    let flagged = s.below + s.above + s.not_finite;
    if flagged > 0 || out.is_some() {
        let dest = out.map_or_else(String::new, |p| format!(" to {}", p.display()));
        lines.push(format!(
            "applied the calibration to {} rows{dest}; flagged: {} below, {} above the calibrated range, {} not finite",
            s.rows, s.below, s.above, s.not_finite
        ));
    }
    if s.temperature_compensated > 0 {
        lines.push(format!(
            "note: {} rows compensated for temperature (the calibration's [axis.temperature]); {} of them outside \
             the model's temperature range, where the range's end was used",
            s.temperature_compensated, s.temperature_outside
        ));
    }
    lines
}
