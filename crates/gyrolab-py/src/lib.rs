//! `gyrolab._gyrolab`: the native module of the Python package, a thin layer over
//! `gyrolab-eval` (never a second implementation). Arrays come in as float64 numpy arrays,
//! results go out as numpy arrays and JSON documents with the keys of the command line's
//! `--json` output; the Python package (`python/gyrolab`) wraps them in result objects.
//!
//! Long computations run with the interpreter released (`Python::detach`). Every failure is a
//! `gyrolab.Error` (a `ValueError`) carrying the evaluation's located message, with request
//! fields spelled as the Python keywords.

use gyrolab::allan::{AllanOptions, DeviationKind};
use gyrolab::rate_test::{RateObservation, Stroke};
use gyrolab::static_test::{SampleBlock, StaticTestConfig};
use gyrolab::units::OutputUnit;
use gyrolab_eval::allan::{analyse_channel_borrowed, parse_taus, ChannelSetup, GapPolicy};
use gyrolab_eval::reference::ReferenceRequest;
use gyrolab_eval::EvalError;
use gyrolab_io::series::{ChannelInfo, SeriesOptions};
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::{Path, PathBuf};

create_exception!(_gyrolab, Error, PyValueError, "A gyrolab evaluation failed: bad data or options.");

/// The Python spelling of a request field: its keyword.
fn keyword(field: &str) -> String {
    match field {
        "sample_rate_hz" => "rate_hz".into(),
        "latitude_deg" => "latitude_deg".into(),
        other => other.into(),
    }
}

fn err(e: EvalError) -> PyErr {
    Error::new_err(e.render(&keyword))
}

fn json_err(e: serde_json::Error) -> PyErr {
    Error::new_err(format!("cannot serialise the result: {e}"))
}

/// The output unit of a keyword (`dps`, `rad_s`, `v`, `mv`, `lsb`); `dph` is handled by the
/// caller (converted to deg/s).
fn output_unit(unit: &str) -> PyResult<OutputUnit> {
    OutputUnit::parse(unit)
        .ok_or_else(|| Error::new_err(format!("unit='{unit}': expected dps, dph, rad_s, v, mv or lsb")))
}

fn reference(scale_factor: Option<f64>, null: Option<f64>) -> PyResult<gyrolab_eval::reference::Reference> {
    ReferenceRequest { scale_factor, null, ..Default::default() }.resolve().map_err(err)
}

/// Allan analysis of one array: returns (JSON document as `gyrolab allan --json`, taus_s, m,
/// dev, ci_low, ci_high, n_terms, alpha); bounds are NaN where none exists.
#[pyfunction]
#[pyo3(signature = (x, rate_hz, kind, taus, confidence, unit, scale_factor=None, null=None, fit_range_s=None, name="x"))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn allan<'py>(
    py: Python<'py>,
    x: PyReadonlyArray1<'py, f64>,
    rate_hz: f64,
    kind: &str,
    taus: &str,
    confidence: Option<f64>,
    unit: &str,
    scale_factor: Option<f64>,
    null: Option<f64>,
    fit_range_s: Option<(f64, f64)>,
    name: &str,
) -> PyResult<(String, Vec<Bound<'py, PyArray1<f64>>>)> {
    gyrolab::validate::positive("sample_rate_hz", rate_hz).map_err(|e| err(e.into()))?;
    if let Some(c) = confidence {
        gyrolab::validate::confidence("confidence", c).map_err(|e| err(e.into()))?;
    }
    let kind = DeviationKind::parse(kind).map_err(|e| Error::new_err(e.to_string()))?;
    let taus = parse_taus(taus).map_err(err)?;
    let reference = reference(scale_factor, null)?;
    let (unit, per_hour) = if unit == "dph" { (OutputUnit::DegPerSec, true) } else { (output_unit(unit)?, false) };
    // The working buffer the angle series is built in (room for its extra point), on huge
    // pages; a contiguous array is read where it is, never copied (the angle conversion reads
    // it twice and writes the buffer once). Samples in deg/h and strided arrays are copied once.
    let view = x.as_array();
    let mut buffer = Vec::with_capacity(view.len() + 1);
    gyrolab_io::pages::advise_huge_pages(&mut buffer);
    let slice = x.as_slice().ok();
    let copied: Option<Vec<f64>> = match (slice, per_hour) {
        (Some(_), false) => None,
        (Some(s), true) => Some(s.iter().map(|&v| gyrolab::units::dph_to_dps(v)).collect()),
        (None, true) => Some(view.iter().map(|&v| gyrolab::units::dph_to_dps(v)).collect()),
        (None, false) => Some(view.iter().copied().collect()),
    };
    let values: &[f64] = copied.as_deref().or(slice).unwrap_or(&[]);
    let info =
        ChannelInfo { name: name.to_string(), column: 1, unit, unit_source: gyrolab_io::series::UnitSource::Column };
    let options = AllanOptions { kind, taus, confidence, max_factor: None };
    let analysis = py
        .detach(|| {
            let setup = ChannelSetup {
                path: Path::new("<array>"),
                shown: "<array>".into(),
                topic: None,
                lines: &gyrolab_io::series::LineMap::default(),
                tau0_s: 1.0 / rate_hz,
                options: &options,
                reference: &reference,
                fit_range_s,
                uncalibrated_hint: "give scale_factor (and null), or unit='dps', for noise terms in deg units",
            };
            // NaN is refused like inf: an array is a complete record
            analyse_channel_borrowed(&setup, &info, values, buffer, GapPolicy::Error)
        })
        .map_err(err)?;
    let doc = gyrolab_report::allan::allan_document(std::slice::from_ref(&analysis))
        .ok_or_else(|| Error::new_err("no curve"))?;
    let json = serde_json::to_string(&doc).map_err(json_err)?;
    let p = &analysis.curve.points;
    let col = |f: &dyn Fn(&gyrolab::allan::AllanPoint) -> f64| PyArray1::from_vec(py, p.iter().map(f).collect());
    let arrays = vec![
        col(&|q| q.tau_s),
        col(&|q| q.m as f64),
        col(&|q| q.deviation),
        col(&|q| q.lower.unwrap_or(f64::NAN)),
        col(&|q| q.upper.unwrap_or(f64::NAN)),
        col(&|q| q.terms as f64),
        col(&|q| q.alpha.map_or(f64::NAN, f64::from)),
    ];
    Ok((json, arrays))
}

/// Static test of one array: the JSON object of one `gyrolab bias --json` test.
#[pyfunction]
#[pyo3(signature = (x, rate_hz, unit, scale_factor=None, null=None, latitude_deg=None, smoothing_s=None, time_s=None, temp_c=None))]
#[allow(clippy::too_many_arguments)]
fn bias(
    py: Python<'_>,
    x: PyReadonlyArray1<'_, f64>,
    rate_hz: Option<f64>,
    unit: &str,
    scale_factor: Option<f64>,
    null: Option<f64>,
    latitude_deg: Option<f64>,
    smoothing_s: Option<Vec<f64>>,
    time_s: Option<PyReadonlyArray1<'_, f64>>,
    temp_c: Option<PyReadonlyArray1<'_, f64>>,
) -> PyResult<String> {
    if let Some(f) = rate_hz {
        gyrolab::validate::positive("sample_rate_hz", f).map_err(|e| err(e.into()))?;
    }
    if let Some(l) = latitude_deg {
        gyrolab::validate::latitude_deg("latitude_deg", l).map_err(|e| err(e.into()))?;
    }
    let reference = reference(scale_factor, null)?;
    let mut config = StaticTestConfig {
        channel: "x".into(),
        output_unit: output_unit(unit)?,
        sample_rate_hz: rate_hz,
        latitude_deg,
        ..StaticTestConfig::default()
    };
    if let Some(s) = smoothing_s {
        gyrolab::validate::smoothing_times("smoothing_s", &s).map_err(|e| err(e.into()))?;
        config.smoothing_times_s = s;
    }
    let output = x.as_array().to_vec();
    let time = time_s.map(|t| t.as_array().to_vec());
    let temp = temp_c.map(|t| t.as_array().to_vec());
    for (what, v) in [("time_s", &time), ("temp_c", &temp)] {
        if v.as_ref().is_some_and(|v| v.len() != output.len()) {
            return Err(Error::new_err(format!("{what} has a different length from x ({})", output.len())));
        }
    }
    let result = py
        .detach(|| {
            let block =
                SampleBlock { output: &output, time_s: time.as_deref(), temperature_c: temp.as_deref(), lines: None };
            gyrolab_eval::static_test::evaluate_samples(&block, &config, &reference)
        })
        .map_err(err)?;
    serde_json::to_string(&gyrolab_report::bias::TestReport { file: "<array>".into(), result }).map_err(json_err)
}

/// Rate-table evaluation of observations (rates deg/s, outputs, runs, strokes `fwd`/`rev`):
/// the JSON of `gyrolab rate --json`.
#[pyfunction]
#[pyo3(signature = (rates_dps, outputs, runs, strokes, unit, coverage=3.0, order=1, half_hysteresis=false, nonlinearity_limit_pct=None, name="x"))]
#[allow(clippy::too_many_arguments)]
fn rate_table(
    rates_dps: PyReadonlyArray1<'_, f64>,
    outputs: PyReadonlyArray1<'_, f64>,
    runs: Vec<u32>,
    strokes: Vec<String>,
    unit: &str,
    coverage: f64,
    order: i64,
    half_hysteresis: bool,
    nonlinearity_limit_pct: Option<f64>,
    name: &str,
) -> PyResult<String> {
    let rates = rates_dps.as_array();
    let out = outputs.as_array();
    let n = rates.len();
    if out.len() != n || runs.len() != n || strokes.len() != n {
        return Err(Error::new_err(format!(
            "rates_dps, outputs, runs and strokes need the same length, got {}, {}, {}, {}",
            n,
            out.len(),
            runs.len(),
            strokes.len()
        )));
    }
    let mut obs = Vec::with_capacity(n);
    for i in 0..n {
        let stroke = Stroke::from_label(&strokes[i])
            .ok_or_else(|| Error::new_err(format!("strokes[{i}] = '{}': expected fwd or rev", strokes[i])))?;
        obs.push(RateObservation { rate_dps: rates[i], run: runs[i], stroke, output: out[i] });
    }
    let settings = gyrolab_eval::rate::RateSettings { coverage, half_hysteresis, order, nonlinearity_limit_pct };
    let axis = gyrolab_eval::rate::evaluate_observations(name, &obs, output_unit(unit)?, &settings).map_err(err)?;
    serde_json::to_string(&gyrolab_report::rate::rate_json(&[axis.report()])).map_err(json_err)
}

/// Rate-table evaluation of files (long, wide or raw logs): the JSON of `gyrolab rate --json`.
#[pyfunction]
#[pyo3(signature = (files, axis_names=None, coverage=3.0, order=1))]
fn rate_table_files(
    files: Vec<PathBuf>,
    axis_names: Option<Vec<String>>,
    coverage: f64,
    order: i64,
) -> PyResult<String> {
    let request = gyrolab_eval::rate::RateRequest {
        files,
        axis_names: axis_names.unwrap_or_default(),
        settings: gyrolab_eval::rate::RateSettings { coverage, order, ..Default::default() },
        ..Default::default()
    };
    let outcome = gyrolab_eval::rate::evaluate_rates(&request).map_err(err)?;
    let reports: Vec<_> = outcome.axes.iter().map(|a| a.report()).collect();
    let mut doc = gyrolab_report::rate::rate_json(&reports);
    let segs: Vec<_> = outcome.logs.iter().map(|l| l.report()).collect();
    doc.segmentation = segs.iter().map(gyrolab_report::segments::SegmentationJson::new).collect();
    serde_json::to_string(&doc).map_err(json_err)
}

/// A simulated static record: (time_s, output, temp_c) arrays (temp_c empty unless recorded).
#[pyfunction]
#[pyo3(signature = (duration_s, rate_hz, seed=1, preset=None, arw_deg_rt_h=None, bias_instability_dph=None, rrw_deg_h_rt_h=None, bias_dph=None, temp_c=None, temp_ramp_c_per_h=None, record_temperature=false))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn simulate_static<'py>(
    py: Python<'py>,
    duration_s: f64,
    rate_hz: f64,
    seed: u64,
    preset: Option<&str>,
    arw_deg_rt_h: Option<f64>,
    bias_instability_dph: Option<f64>,
    rrw_deg_h_rt_h: Option<f64>,
    bias_dph: Option<f64>,
    temp_c: Option<f64>,
    temp_ramp_c_per_h: Option<f64>,
    record_temperature: bool,
) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>)> {
    let preset = preset
        .map(|p| gyrolab::sim::Preset::parse(p).ok_or_else(|| Error::new_err(format!("unknown preset '{p}'"))))
        .transpose()?;
    let o = gyrolab_eval::simulate::SimOverrides {
        seed: Some(seed),
        preset,
        sample_rate_hz: Some(rate_hz),
        duration_s: Some(duration_s),
        arw_deg_rt_h,
        bias_instability_dph,
        rrw_deg_h_rt_h,
        bias_dph,
        temp_c,
        temp_ramp_c_per_h,
        record_temperature,
        ..Default::default()
    };
    let cfg = gyrolab_eval::simulate::sim_config(&o).map_err(err)?;
    let s = py.detach(|| gyrolab_eval::simulate::simulate_static_samples(&cfg)).map_err(err)?;
    Ok((PyArray1::from_vec(py, s.time_s), PyArray1::from_vec(py, s.output), PyArray1::from_vec(py, s.temp_c)))
}

/// Reads a time series file: a dict of column name -> float64 array, and a dict of column name
/// -> unit symbol (outputs; `s` for time, `degC` for temperature). `units` (`["gx=rad/s",
/// "m/s^2"]`), `time_column` and `names` (a file without a header row) as `gyrolab allan`'s
/// `--unit`, `--time-column`, `--names`. Parquet tables and recordings (MCAP, ROS 1 bags, PX4
/// ULog) are read by content; `topic` picks one IMU topic of a recording (needed when it has
/// several).
#[pyfunction]
#[pyo3(signature = (path, units=None, time_column=None, names=None, topic=None))]
fn read<'py>(
    py: Python<'py>,
    path: PathBuf,
    units: Option<Vec<String>>,
    time_column: Option<String>,
    names: Option<Vec<String>>,
    topic: Option<String>,
) -> PyResult<(Bound<'py, PyDict>, Bound<'py, PyDict>)> {
    let layout = gyrolab_eval::layout::LogLayout {
        units: units.unwrap_or_default(),
        time_column,
        names: names.unwrap_or_default(),
    };
    let options = layout.apply(SeriesOptions::default()).map_err(err)?;
    let topics: Vec<String> = topic.into_iter().collect();
    let mut records =
        py.detach(|| gyrolab_io::recording::read_records(&path, &options, &topics)).map_err(|e| err(e.into()))?.records;
    if records.len() > 1 {
        let names: Vec<String> = records.iter().filter_map(|r| r.topic.as_ref().map(|t| t.topic.clone())).collect();
        return Err(err(gyrolab_eval::EvalError::conflict(format!(
            "{}: {} IMU topics ({}): choose one with topic=",
            path.display(),
            names.len(),
            names.join(", ")
        ))));
    }
    let data = records.remove(0).data;
    let arrays = PyDict::new(py);
    let units = PyDict::new(py);
    let h = &data.header;
    let name_of = |c: Option<usize>| c.and_then(|c| h.columns.get(c - 1)).map(|c| c.name.clone());
    if let (Some(t), Some(n)) = (data.time, name_of(h.time_column)) {
        arrays.set_item(&n, PyArray1::from_vec(py, t))?;
        units.set_item(&n, "s")?;
    }
    if let (Some(t), Some(n)) = (data.temperature, name_of(h.temperature_column)) {
        arrays.set_item(&n, PyArray1::from_vec(py, t))?;
        units.set_item(&n, "degC")?;
    }
    for (info, values) in h.channels.iter().zip(data.channels) {
        arrays.set_item(&info.name, PyArray1::from_vec(py, values))?;
        units.set_item(&info.name, info.unit.symbol())?;
    }
    Ok((arrays, units))
}

/// Evaluates a test plan and writes its report folder: (verdict or None, files written, failures).
#[pyfunction]
fn evaluate_plan(py: Python<'_>, plan: PathBuf, out: PathBuf) -> PyResult<(Option<String>, Vec<PathBuf>, Vec<String>)> {
    let folder = py
        .detach(|| {
            let p = gyrolab_eval::test_plan::read_test_plan(&plan)?;
            gyrolab_eval::test_plan::evaluate_test_plan(&p, &plan.display().to_string(), &gyrolab_eval::Silent)
        })
        .map_err(err)?;
    let files: Vec<(&str, &[u8])> = folder.outputs.iter().map(|o| (o.name.as_str(), &o.bytes[..])).collect();
    let written = gyrolab_io::atomic::write_folder(&out, &files).map_err(|(p, e)| {
        pyo3::exceptions::PyOSError::new_err(format!("{}: cannot write the file: {e}", p.display()))
    })?;
    Ok((folder.verdict.map(|v| v.text().to_string()), written, folder.failures))
}

/// Applies a calibration file to outputs in memory: (rates per axis, status per sample:
/// `inside`, `below`, `above`, `not_finite`).
#[pyfunction]
#[pyo3(signature = (calibration, outputs, axis=None))]
#[allow(clippy::type_complexity)]
fn apply<'py>(
    py: Python<'py>,
    calibration: PathBuf,
    outputs: Vec<PyReadonlyArray1<'py, f64>>,
    axis: Option<&str>,
) -> PyResult<(Vec<Bound<'py, PyArray1<f64>>>, Vec<&'static str>)> {
    let owned: Vec<Vec<f64>> = outputs.iter().map(|o| o.as_array().to_vec()).collect();
    let slices: Vec<&[f64]> = owned.iter().map(Vec::as_slice).collect();
    let (rates, status) = py.detach(|| gyrolab_eval::apply::apply_arrays(&calibration, axis, &slices)).map_err(err)?;
    let status = status
        .into_iter()
        .map(|s| match s {
            gyrolab::apply::RangeStatus::Inside => "inside",
            gyrolab::apply::RangeStatus::Below => "below",
            gyrolab::apply::RangeStatus::Above => "above",
            gyrolab::apply::RangeStatus::NotFinite => "not_finite",
        })
        .collect();
    Ok((rates.into_iter().map(|r| PyArray1::from_vec(py, r)).collect(), status))
}

/// The native module.
#[pymodule]
fn _gyrolab(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("Error", m.py().get_type::<Error>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(allan, m)?)?;
    m.add_function(wrap_pyfunction!(bias, m)?)?;
    m.add_function(wrap_pyfunction!(rate_table, m)?)?;
    m.add_function(wrap_pyfunction!(rate_table_files, m)?)?;
    m.add_function(wrap_pyfunction!(simulate_static, m)?)?;
    m.add_function(wrap_pyfunction!(read, m)?)?;
    m.add_function(wrap_pyfunction!(evaluate_plan, m)?)?;
    m.add_function(wrap_pyfunction!(apply, m)?)?;
    Ok(())
}
