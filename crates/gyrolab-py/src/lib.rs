//! `gyrolab._gyrolab`: the native module of the Python package, a thin layer over
//! `gyrolab-eval` (never a second implementation). Arrays come in as float64 numpy arrays,
//! results go out as numpy arrays and JSON documents with the keys of the command line's
//! `--json` output; the Python package (`python/gyrolab`) wraps them in result objects.
//!
//! Long computations run with the interpreter released (`Python::detach`) on the package's own
//! thread pool, which a process made by `fork` builds again (see `POOL`): gyrolab works in
//! the workers of a fork-based `multiprocessing.Pool` after a call in the parent. Every failure
//! is a `gyrolab.Error` (a `ValueError` defined in `gyrolab/_errors.py`, so that it pickles)
//! carrying the evaluation's located message, with request fields spelled as the Python
//! keywords, and its file, line, column or keyword as attributes.

use gyrolab::allan::{AllanOptions, DeviationKind, TauList};
use gyrolab::rate_test::{RateObservation, Stroke};
use gyrolab::static_test::{SampleBlock, StaticTestConfig};
use gyrolab::units::OutputUnit;
use gyrolab_eval::allan::{analyse_channel_borrowed, on_grid, parse_taus, ChannelSetup, GapPolicy};
use gyrolab_eval::reference::ReferenceRequest;
use gyrolab_eval::EvalError;
use gyrolab_io::series::{ChannelInfo, SeriesOptions};
use numpy::{PyArray1, PyReadonlyArray1, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyType};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

mod store;

/// The Python class of every failure, `gyrolab.Error` (defined in `gyrolab/_errors.py` so that
/// it pickles: its module imports).
static ERROR_TYPE: PyOnceLock<Py<PyType>> = PyOnceLock::new();

/// Where a failure is, as the attributes of `gyrolab.Error`.
#[derive(Default)]
struct Location {
    file: Option<String>,
    line: Option<u64>,
    column: Option<String>,
    keyword: Option<String>,
}

/// A `gyrolab.Error` with `message` and its location.
fn raise(message: String, at: Location) -> PyErr {
    Python::attach(|py| {
        let made = (|| -> PyResult<PyErr> {
            let class = ERROR_TYPE.import(py, "gyrolab._errors", "Error")?;
            let kwargs = PyDict::new(py);
            kwargs.set_item("file", at.file)?;
            kwargs.set_item("line", at.line)?;
            kwargs.set_item("column", at.column)?;
            kwargs.set_item("keyword", at.keyword)?;
            Ok(PyErr::from_value(class.call((message.as_str(),), Some(&kwargs))?))
        })();
        made.unwrap_or_else(|e| e)
    })
}

/// A `gyrolab.Error` with a message and no location.
fn error(message: impl Into<String>) -> PyErr {
    raise(message.into(), Location::default())
}

/// A `gyrolab.Error` about the keyword argument `keyword`.
fn keyword_error(keyword: &str, message: impl Into<String>) -> PyErr {
    raise(message.into(), Location { keyword: Some(keyword.into()), ..Location::default() })
}

/// The Python spelling of a request field: its keyword.
fn keyword(field: &str) -> String {
    match field {
        "sample_rate_hz" => "rate_hz".into(),
        "topics" => "topic".into(),
        other => other.into(),
    }
}

/// The `gyrolab.Error` of an evaluation's failure: the message with request fields spelled as
/// keywords, and the file, line, column or keyword it names.
fn err(e: EvalError) -> PyErr {
    let message = e.render(&keyword);
    let at = match &e {
        EvalError::Data(d) => Location {
            file: Some(d.file.display().to_string()),
            line: d.line,
            column: d.column.as_ref().map(|c| c.name.clone().unwrap_or_else(|| c.index.to_string())),
            keyword: None,
        },
        EvalError::Invalid(i) => Location { keyword: Some(keyword(i.field)), ..Location::default() },
        EvalError::Conflict { fields, .. } => {
            Location { keyword: fields.first().map(|f| keyword(f)), ..Location::default() }
        }
        EvalError::Output(_) => Location::default(),
        EvalError::PoorFit(_) => Location { keyword: Some(keyword("allow_poor_fit")), ..Location::default() },
    };
    raise(message, at)
}

fn json_err(e: serde_json::Error) -> PyErr {
    error(format!("cannot serialise the result: {e}"))
}

/// The process that built [`POOL`]'s threads, and the pool.
type OwnedPool = (u32, Arc<rayon::ThreadPool>);

/// The package's own thread pool (rayon's global pool is never used): built on first use, and
/// built again in a child process made by `fork`, where the parent's threads do not exist (a
/// pool whose threads are gone would wait for them forever). The old pool is leaked there on
/// purpose: dropping it would signal threads that are not in this process.
static POOL: Mutex<Option<OwnedPool>> = Mutex::new(None);

/// The thread pool of this process (see [`POOL`]); `RAYON_NUM_THREADS` sets its size.
fn pool() -> PyResult<Arc<rayon::ThreadPool>> {
    let pid = std::process::id();
    let mut slot = POOL.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    if let Some((owner, pool)) = slot.as_ref() {
        if *owner == pid {
            return Ok(pool.clone());
        }
    }
    if let Some(inherited) = slot.take() {
        std::mem::forget(inherited);
    }
    let pool = Arc::new(
        rayon::ThreadPoolBuilder::new()
            .thread_name(|i| format!("gyrolab-{i}"))
            .build()
            .map_err(|e| error(format!("cannot start the worker threads: {e}")))?,
    );
    *slot = Some((pid, pool.clone()));
    Ok(pool)
}

/// Runs `work` on the package's thread pool with the interpreter released.
fn run<T: Send>(py: Python<'_>, work: impl FnOnce() -> T + Send) -> PyResult<T> {
    let pool = pool()?;
    Ok(py.detach(|| pool.install(work)))
}

/// The units `allan` reads, as listed in its docstring and errors.
const ALLAN_UNITS: &str = "dps (deg/s), dph (deg/h), rad_s (rad/s), mrad_s (mrad/s), m/s^2 (m/s2), g, mg, ug, \
     v, mv, lsb, or 1 (no unit)";

/// How samples in a unit reach the engine: its unit there, and a factor applied first (deg/h
/// to deg/s; micro-g to milli-g).
fn input_unit(text: &str) -> PyResult<(OutputUnit, Option<f64>)> {
    let t: String = text.trim().to_ascii_lowercase().chars().filter(|c| !c.is_whitespace()).collect();
    let parsed = match t.as_str() {
        "dph" | "deg/h" | "deg_h" => Some((OutputUnit::DegPerSec, Some(gyrolab::units::dph_to_dps(1.0)))),
        "m/s2" | "m/s**2" | "m·s^-2" | "m/s²" => Some((OutputUnit::MeterPerSec2, None)),
        "ug" | "µg" | "μg" | "micro-g" => Some((OutputUnit::MilliG, Some(1e-3))),
        "1" | "" | "none" | "unitless" => Some((OutputUnit::Unitless, None)),
        _ => OutputUnit::parse(&t).map(|u| (u, None)),
    };
    parsed.ok_or_else(|| keyword_error("units", format!("unit '{text}' is not known: expected {ALLAN_UNITS}")))
}

/// The output unit of a keyword (`dps`, `rad_s`, `v`, `mv`, `lsb`, ...).
fn output_unit(unit: &str) -> PyResult<OutputUnit> {
    OutputUnit::parse(unit).ok_or_else(|| {
        keyword_error(
            "unit",
            format!("unit='{unit}': expected v, mv, lsb, dps (deg/s), dph (deg/h), rad_s (rad/s) or mrad_s"),
        )
    })
}

fn reference(scale_factor: Option<f64>, null: Option<f64>) -> PyResult<gyrolab_eval::reference::Reference> {
    ReferenceRequest { scale_factor, null, ..Default::default() }.resolve().map_err(err)
}

/// The deviation, the taus (averaging factors replace the tau list when given) and the fit
/// range of an Allan call, checked.
#[allow(clippy::type_complexity)]
fn analysis_choices(
    kind: &str,
    taus: &str,
    factors: Option<Vec<usize>>,
    fit_range_s: Option<Vec<f64>>,
) -> PyResult<(DeviationKind, TauList, Option<(f64, f64)>)> {
    let kind = DeviationKind::parse(kind).map_err(|e| keyword_error("kind", e.to_string()))?;
    let taus = match factors {
        Some(m) => TauList::Factors(m),
        None => parse_taus(taus).map_err(err)?,
    };
    let fit_range_s = match fit_range_s {
        None => None,
        Some(v) => gyrolab::validate::increasing_pair("fit_range_s", &v).map_err(|e| err(e.into()))?,
    };
    Ok((kind, taus, fit_range_s))
}

/// One channel's samples as the engine reads them: borrowed where they can be, else a copy.
enum Samples<'a> {
    Borrowed(&'a [f64]),
    Owned(Vec<f64>),
}

/// Allan analysis of channels of one record in one native call, the channels in parallel on
/// the package's pool: returns (JSON list of the channels of `gyrolab allan --json` (its
/// `channels` key, each `gmwm` null: the GMWM is computed when asked for), per channel the
/// arrays taus_s, m, dev, ci_low, ci_high, n_terms, alpha; bounds NaN where none exists, and the
/// [`AllanChannels`] that computes each channel's GMWM fit and filter terms). `rate_hz`
/// or `time_s` (seconds, one per sample) gives the sampling; gaps in `time_s` and NaN samples
/// follow `gaps` (`error` or `analyse`). `factors` replaces `taus` by averaging factors.
#[pyfunction]
#[pyo3(signature = (columns, names, units, rate_hz, time_s, kind, taus, factors, confidence, scale_factor=None, null=None, fit_range_s=None, gaps="error", record="<array>", allow_motion=false))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn allan_channels<'py>(
    py: Python<'py>,
    columns: Vec<PyReadonlyArray1<'py, f64>>,
    names: Vec<String>,
    units: Vec<String>,
    rate_hz: Option<f64>,
    time_s: Option<PyReadonlyArray1<'py, f64>>,
    kind: &str,
    taus: &str,
    factors: Option<Vec<usize>>,
    confidence: Option<f64>,
    scale_factor: Option<f64>,
    null: Option<f64>,
    fit_range_s: Option<Vec<f64>>,
    gaps: &str,
    record: &str,
    allow_motion: bool,
) -> PyResult<(String, Vec<Vec<Bound<'py, PyArray1<f64>>>>, AllanChannels)> {
    let policy = GapPolicy::parse(gaps).map_err(|e| err(e.into()))?;
    if let Some(f) = rate_hz {
        gyrolab::validate::positive("sample_rate_hz", f).map_err(|e| err(e.into()))?;
    }
    if let Some(c) = confidence {
        gyrolab::validate::confidence("confidence", c).map_err(|e| err(e.into()))?;
    }
    let (kind, taus, fit_range_s) = analysis_choices(kind, taus, factors, fit_range_s)?;
    if columns.len() != names.len() || columns.len() != units.len() || columns.is_empty() {
        return Err(error(format!(
            "give one name and one unit per channel: {} channels, {} names, {} units",
            columns.len(),
            names.len(),
            units.len()
        )));
    }
    let parsed: Vec<(OutputUnit, Option<f64>)> = units.iter().map(|u| input_unit(u)).collect::<PyResult<_>>()?;
    if scale_factor.is_some() || null.is_some() {
        let calibrated = |u: &OutputUnit| u.quantity() != gyrolab::units::Quantity::SensorOutput;
        if let Some((i, (u, _))) = parsed.iter().enumerate().find(|(_, (u, _))| calibrated(u)) {
            let given = if scale_factor.is_some() { "scale_factor" } else { "null" };
            return Err(keyword_error(
                given,
                format!(
                    "{given} applies to outputs in v, mv or lsb, but channel '{}' is in {}: leave {given} out",
                    names[i],
                    u.symbol()
                ),
            ));
        }
    }
    let reference = reference(scale_factor, null)?;
    let path = Path::new(record);
    let n = columns[0].len();
    if let Some((i, c)) = columns.iter().enumerate().find(|(_, c)| c.len() != n) {
        return Err(error(format!(
            "channel '{}' has {} samples where '{}' has {n}: the channels of a record have one length",
            names[i],
            c.len(),
            names[0]
        )));
    }
    // The sampling: the given rate, else the time stamps' (gaps found there are missing samples).
    let mut grid_gaps: Vec<gyrolab::sampling::Gap> = Vec::new();
    let mut missing = 0usize;
    // Samples analysed: all, or those before a stamp going back (as the command line ends it).
    let mut used = n;
    let tau0_s = match (&time_s, rate_hz) {
        (None, None) => {
            return Err(keyword_error(
                "rate_hz",
                "give rate_hz (the sample rate, Hz) or time= (time stamps in seconds, a column or an array)",
            ))
        }
        (None, Some(f)) => 1.0 / f,
        (Some(t), given) => {
            let t = t.as_slice().map_err(|_| error("time: expected a contiguous float64 array"))?;
            if t.len() != n {
                return Err(keyword_error("time", format!("time has {} stamps for {n} samples", t.len())));
            }
            let e = gyrolab::sampling::estimate_interval(t)
                .map_err(|_| keyword_error("time", "time: fewer than two stamps, or stamps that do not increase"))?;
            // A stamp going back to or before the first one (a clock reset, a trailer of zeros)
            // ends the record, with the command line's words as a UserWarning.
            if let Some(r) = e.reset {
                used = r.index;
                let text = format!(
                    "{record}: the time stamps go back at time[{}] (from {} s to {} s: a clock reset or a trailer of zeros): the record ends before it, {} sample(s) from there left out",
                    r.index, r.from_s, r.to_s, r.left_out
                );
                let text =
                    std::ffi::CString::new(text).map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
                PyErr::warn(py, &py.get_type::<pyo3::exceptions::PyUserWarning>(), &text, 1)?;
            }
            if let Some(g) = e.first_non_increasing {
                return Err(keyword_error(
                    "time",
                    format!(
                        "time[{}] does not increase (interval {} s): expected increasing time stamps",
                        g.index, g.interval_s
                    ),
                ));
            }
            if policy == GapPolicy::Error {
                if let Some(g) = e.gaps.first() {
                    return Err(keyword_error(
                        "gaps",
                        format!(
                            "a gap in the time stamps before time[{}]: {} sample(s) missing (interval {} s where the record's is {} s); gaps='analyse' computes over them",
                            g.index, g.missing, g.interval_s, e.interval_s
                        ),
                    ));
                }
            }
            if let Some(f) = given {
                if let Some(msg) = gyrolab_eval::allan::rate_disagreement(t, f, "rate_hz", path) {
                    return Err(keyword_error("rate_hz", msg));
                }
            }
            // A given rate builds the grid at that rate (as the command line's does).
            grid_gaps = match given {
                Some(f) => gyrolab::sampling::gaps_at(t, 1.0 / f, &e.clock, e.reset.map_or(usize::MAX, |r| r.index)),
                None => e.gaps,
            };
            missing = grid_gaps.iter().map(|g| g.missing).sum();
            given.map_or(e.interval_s, |f| 1.0 / f)
        }
    };
    let infos: Vec<ChannelInfo> = names
        .iter()
        .zip(&parsed)
        .enumerate()
        .map(|(i, (name, (unit, _)))| ChannelInfo {
            name: name.clone(),
            column: i + 1,
            unit: *unit,
            unit_source: gyrolab_io::series::UnitSource::Column,
        })
        .collect();
    // A contiguous array in its unit is read where it is, never copied (the angle conversion
    // reads it twice and writes the working buffer once); a strided array, a unit converted
    // first and a record with gaps are copied once.
    let samples: Vec<Samples<'_>> = columns
        .iter()
        .zip(&parsed)
        .map(|(c, (_, factor))| {
            let owned = |v: Vec<f64>| -> Vec<f64> {
                let v = match factor {
                    Some(f) => v.into_iter().map(|x| x * f).collect(),
                    None => v,
                };
                if missing > 0 {
                    on_grid(v, &grid_gaps, missing)
                } else {
                    v
                }
            };
            match c.as_slice() {
                Ok(s) if factor.is_none() && missing == 0 => Samples::Borrowed(&s[..used]),
                Ok(s) => Samples::Owned(owned(s[..used].to_vec())),
                Err(_) => Samples::Owned(owned(c.as_array().iter().take(used).copied().collect())),
            }
        })
        .collect();
    let options = AllanOptions { kind, taus, confidence, max_factor: None };
    let lines = gyrolab_io::series::LineMap::default();
    let setup = ChannelSetup {
        path,
        shown: record.to_string(),
        topic: None,
        lines: &lines,
        tau0_s,
        options: &options,
        reference: &reference,
        fit_range_s,
        uncalibrated_hint: "give scale_factor (and null), or a rate unit such as 'dps', for noise terms",
        allow_motion,
    };
    // Missing samples in the record (NaN or gaps) are computed over only when asked for.
    let missing_policy = if policy == GapPolicy::Analyse { GapPolicy::Analyse } else { GapPolicy::Error };
    let one = |(s, info): (&Samples<'_>, &ChannelInfo)| {
        let values: &[f64] = match s {
            Samples::Borrowed(s) => s,
            Samples::Owned(v) => v,
        };
        let mut buffer = Vec::with_capacity(values.len() + 1);
        gyrolab_io::pages::advise_huge_pages(&mut buffer);
        analyse_channel_borrowed(&setup, info, values, buffer, missing_policy)
    };
    // The lengths as they reach the analysis (a record with gaps is padded to its grid), the
    // channels one after another: all of them together below the core's parallel size.
    let analysed: usize = samples
        .iter()
        .map(|s| match s {
            Samples::Borrowed(v) => v.len(),
            Samples::Owned(v) => v.len(),
        })
        .map(|len| len.saturating_add(1))
        .sum();
    let analyses = if gyrolab::allan::runs_serially(analysed.saturating_sub(1)) {
        // A short record on the calling thread, the interpreter released: the hand-off to a pool
        // thread cost a 10 min record at 100 Hz a fifth of its call (issue 56). Below this size
        // the core calls no rayon function, so no pool is used or started.
        py.detach(|| samples.iter().zip(infos.iter()).map(one).collect::<Result<Vec<_>, _>>())
    } else {
        run(py, || samples.par_iter().zip(infos.par_iter()).map(one).collect::<Result<Vec<_>, _>>())?
    }
    .map_err(err)?;
    gyrolab_eval::allan::refuse_motion(&analyses, path, allow_motion).map_err(err)?;
    channels_out(py, analyses)
}
/// The channel JSON, per-channel arrays and lazy GMWM holder of analysed channels (the return
/// of [`allan_channels`] and [`allan_table`]).
#[allow(clippy::type_complexity)]
fn channels_out<'py>(
    py: Python<'py>,
    analyses: Vec<gyrolab_eval::outcome::allan::ChannelAnalysis>,
) -> PyResult<(String, Vec<Vec<Bound<'py, PyArray1<f64>>>>, AllanChannels)> {
    // The GMWM and the filter terms (which hold it) are left to the first call that needs them
    // (`AllanChannels`): most calls read the curve and the slope terms only (issue 56).
    let doc = gyrolab_report::allan::allan_document_with(&analyses, false).ok_or_else(|| error("no channel"))?;
    let json = serde_json::to_string(&doc.channels).map_err(json_err)?;
    let arrays = analyses
        .iter()
        .map(|a| {
            let p = &a.curve.points;
            let col =
                |f: &dyn Fn(&gyrolab::allan::AllanPoint) -> f64| PyArray1::from_vec(py, p.iter().map(f).collect());
            vec![
                col(&|q| q.tau_s),
                col(&|q| q.m as f64),
                col(&|q| q.deviation),
                col(&|q| q.lower.unwrap_or(f64::NAN)),
                col(&|q| q.upper.unwrap_or(f64::NAN)),
                col(&|q| q.terms as f64),
                col(&|q| q.alpha.map_or(f64::NAN, f64::from)),
            ]
        })
        .collect();
    Ok((json, arrays, AllanChannels { analyses }))
}

/// Allan analysis of a named table (a DataFrame, a dict of columns) read exactly as the
/// command line reads a delimited file with that header (issue 55: one reading for every front
/// end): the time column and its unit, units from the names or `units` (`COLUMN=UNIT` or a
/// bare unit per quantity, the CLI's `--unit`), temperature and other columns skipped with a
/// note, resets, gaps and dropouts as `gyrolab allan` handles them (`gaps`: fill, analyse,
/// contiguous or error). Returns what [`allan_channels`] returns, and the reader's notes as
/// (is_warning, text) with keywords spelled as Python's.
#[pyfunction]
#[pyo3(signature = (columns, names, units, time_column, rate_hz, kind, taus, factors, confidence, scale_factor=None, null=None, fit_range_s=None, gaps="fill", record="<table>", allow_motion=false, start_s=None, end_s=None))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn allan_table<'py>(
    py: Python<'py>,
    columns: Vec<PyReadonlyArray1<'py, f64>>,
    names: Vec<String>,
    units: Vec<String>,
    time_column: Option<String>,
    rate_hz: Option<f64>,
    kind: &str,
    taus: &str,
    factors: Option<Vec<usize>>,
    confidence: Option<f64>,
    scale_factor: Option<f64>,
    null: Option<f64>,
    fit_range_s: Option<Vec<f64>>,
    gaps: &str,
    record: &str,
    allow_motion: bool,
    start_s: Option<f64>,
    end_s: Option<f64>,
) -> PyResult<(String, Vec<Vec<Bound<'py, PyArray1<f64>>>>, AllanChannels, Vec<(bool, String)>)> {
    use gyrolab_eval::allan::{analyse_data, AllanRequest};
    if columns.len() != names.len() || columns.is_empty() {
        return Err(error(format!("give one name per column: {} columns, {} names", columns.len(), names.len())));
    }
    let (kind, taus, fit_range_s) = analysis_choices(kind, taus, factors, fit_range_s)?;
    let layout = gyrolab_eval::layout::LogLayout { units, time_column, names: Vec::new() };
    let request = AllanRequest {
        file: PathBuf::from(record),
        columns: Vec::new(),
        sample_rate_hz: rate_hz,
        reference: ReferenceRequest { scale_factor, null, ..Default::default() },
        kind,
        taus,
        confidence,
        fit_range_s,
        layout: layout.clone(),
        gaps: GapPolicy::parse(gaps).map_err(|e| err(e.into()))?,
        topics: Vec::new(),
        allow_motion,
        window_s: (start_s, end_s),
    };
    let options = layout
        .apply(SeriesOptions { sample_rate_hz: rate_hz, tolerant: true, ..SeriesOptions::default() })
        .map_err(err)?;
    let reference = request.reference.resolve().map_err(err)?;
    let data: Vec<Vec<f64>> = columns.iter().map(|c| c.as_array().iter().copied().collect()).collect();
    let work = || {
        let data = gyrolab_io::series::series_from_columns(
            Path::new(record),
            &names,
            data,
            gyrolab_io::series::RowKind::Row,
            &options,
        )?;
        let mut outcome = analyse_data(&request, &reference, data, None)?;
        if let Some(g) = gyrolab_eval::allan::gravity_of(&mut outcome.analyses) {
            outcome.notes.push(gyrolab_eval::allan::ReadNote::Gravity(g));
        }
        gyrolab_eval::allan::refuse_motion(&outcome.analyses, Path::new(record), allow_motion)?;
        Ok::<_, EvalError>(outcome)
    };
    // A short record on the calling thread with the interpreter released (no pool, no thread
    // started), as `allan_channels` does; else on the package's pool.
    let samples: usize = columns.iter().map(|c| c.len()).sum();
    let outcome = if gyrolab::allan::runs_serially(samples) { py.detach(work) } else { run(py, work)? };
    let outcome = outcome.map_err(err)?;
    // Warnings, and the note that channels without a unit get no noise terms, reach Python as
    // UserWarnings (the command line prints them on stderr).
    let notes = outcome
        .notes
        .iter()
        .map(|n| (n.is_warning() || matches!(n, gyrolab_eval::allan::ReadNote::Unitless { .. }), n.render(&keyword)))
        .collect();
    let (json, arrays, lazy) = channels_out(py, outcome.analyses)?;
    Ok((json, arrays, lazy, notes))
}

/// The analyses of one `allan_channels` call, kept for what is computed only when asked for:
/// each channel's GMWM fit and its filter terms (JSON texts, the keys of docs/JSON.md).
#[pyclass(frozen, module = "gyrolab._gyrolab")]
struct AllanChannels {
    analyses: Vec<gyrolab_eval::outcome::allan::ChannelAnalysis>,
}

impl AllanChannels {
    fn channel(&self, index: usize) -> PyResult<&gyrolab_eval::outcome::allan::ChannelAnalysis> {
        self.analyses.get(index).ok_or_else(|| error(format!("no channel {index}")))
    }
}

#[pymethods]
impl AllanChannels {
    /// The handle itself (it never changes): `copy.copy` of a result.
    fn __copy__(slf: Py<Self>) -> Py<Self> {
        slf
    }

    /// The handle itself (it never changes): `copy.deepcopy` and `dataclasses.asdict` of a result.
    fn __deepcopy__(slf: Py<Self>, _memo: &Bound<'_, PyAny>) -> Py<Self> {
        slf
    }

    /// The GMWM fit of channel `index` as JSON (the `gmwm` key of docs/JSON.md), `None` when the
    /// channel has none; computed on the first call, with the interpreter released.
    fn gmwm(&self, py: Python<'_>, index: usize) -> PyResult<Option<String>> {
        let a = self.channel(index)?;
        json_or_none(run(py, || gyrolab_report::allan::gmwm_json(a))?)
    }

    /// The filter terms of channel `index` as JSON (what `render_export` takes), `None` when the
    /// channel has none (the GMWM computed first if it was not).
    fn filter_terms(&self, py: Python<'_>, index: usize) -> PyResult<Option<String>> {
        let a = self.channel(index)?;
        json_or_none(run(py, || gyrolab_eval::filter_export::channel_filter_terms(a))?)
    }
}

/// A value as JSON text, `None` as `None`.
fn json_or_none<T: serde::Serialize>(value: Option<T>) -> PyResult<Option<String>> {
    value.map(|v| serde_json::to_string(&v)).transpose().map_err(json_err)
}

/// The text of one filter stack's noise-parameter file from the filter terms `allan_channels`
/// returned (JSON, one per channel): returns (text, warnings). `stack`: kalibr, openvins,
/// vins, orbslam3, basalt, px4, px4-qgc, ros-covariance; `estimator`: slopes, fit or gmwm.
#[pyfunction]
#[pyo3(signature = (terms, record, rate_hz, stack, estimator="slopes", inflate=1.0, overbound=false, motion=Vec::new(), allow_poor_fit=false))]
#[allow(clippy::too_many_arguments)]
fn render_export(
    terms: Vec<String>,
    record: &str,
    rate_hz: f64,
    stack: &str,
    estimator: &str,
    inflate: f64,
    overbound: bool,
    motion: Vec<String>,
    allow_poor_fit: bool,
) -> PyResult<(String, Vec<String>)> {
    use gyrolab_eval::filter_export::{ChannelFilterTerms, Estimator, ExportRecord, ExportRequest};
    let channels: Vec<ChannelFilterTerms> =
        terms.iter().map(|t| serde_json::from_str(t)).collect::<Result<_, _>>().map_err(json_err)?;
    let request = ExportRequest {
        targets: Vec::new(),
        estimator: Estimator::parse(estimator).map_err(|e| keyword_error("estimator", e.to_string()))?,
        inflate,
        overbound,
        allow_poor_fit,
    };
    let export_record = ExportRecord {
        record: record.to_string(),
        rate_hz,
        simulated: gyrolab_io::provenance::is_gyrolab_simulation(Path::new(record)),
        rostopic: None,
        motion,
    };
    gyrolab_eval::filter_export::render_export(&export_record, &channels, stack, &request).map_err(err)
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
            return Err(error(format!("{what} has a different length from x ({})", output.len())));
        }
    }
    let result = run(py, || {
        let block =
            SampleBlock { output: &output, time_s: time.as_deref(), temperature_c: temp.as_deref(), lines: None };
        gyrolab_eval::static_test::evaluate_samples(&block, &config, &reference)
    })?
    .map_err(err)?;
    serde_json::to_string(&gyrolab_eval::outcome::static_test::TestReport { file: "<array>".into(), result })
        .map_err(json_err)
}

/// Rate-table evaluation of observations (rates deg/s, outputs, runs, strokes `fwd`/`rev`):
/// the JSON of `gyrolab rate --json`.
#[pyfunction]
#[pyo3(signature = (rates_dps, outputs, runs, strokes, unit, coverage=3.0, order=1, half_hysteresis=false, nonlinearity_limit_pct=None, name="x"))]
#[allow(clippy::too_many_arguments)]
fn rate_table(
    py: Python<'_>,
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
        return Err(error(format!(
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
            .ok_or_else(|| error(format!("strokes[{i}] = '{}': expected fwd or rev", strokes[i])))?;
        obs.push(RateObservation { rate_dps: rates[i], run: runs[i], stroke, output: out[i] });
    }
    let settings = gyrolab_eval::rate::RateSettings { coverage, half_hysteresis, order, nonlinearity_limit_pct };
    let unit = output_unit(unit)?;
    let axis = run(py, || gyrolab_eval::rate::evaluate_observations(name, &obs, unit, &settings))?.map_err(err)?;
    serde_json::to_string(&gyrolab_report::rate::rate_json(&[axis.report()])).map_err(json_err)
}

/// Rate-table evaluation of files (long, wide or raw logs): the JSON of `gyrolab rate --json`.
/// `unit` overrides the output unit the files declare.
#[pyfunction]
#[pyo3(signature = (files, axis_names=None, coverage=3.0, order=1, unit=None, half_hysteresis=false, nonlinearity_limit_pct=None))]
#[allow(clippy::too_many_arguments)]
fn rate_table_files(
    py: Python<'_>,
    files: Vec<PathBuf>,
    axis_names: Option<Vec<String>>,
    coverage: f64,
    order: i64,
    unit: Option<&str>,
    half_hysteresis: bool,
    nonlinearity_limit_pct: Option<f64>,
) -> PyResult<String> {
    let mut columns = gyrolab_io::rate_table::RateColumns::default();
    if let Some(u) = unit {
        columns.output_unit = Some(output_unit(u)?);
    }
    let request = gyrolab_eval::rate::RateRequest {
        files,
        columns,
        axis_names: axis_names.unwrap_or_default(),
        settings: gyrolab_eval::rate::RateSettings { coverage, order, half_hysteresis, nonlinearity_limit_pct },
        ..Default::default()
    };
    let outcome = run(py, || gyrolab_eval::rate::evaluate_rates(&request))?.map_err(err)?;
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
        .map(|p| {
            gyrolab::sim::Preset::parse(p).ok_or_else(|| {
                let known: Vec<&str> = gyrolab::sim::Preset::ALL.iter().map(|p| p.name()).collect();
                keyword_error("preset", format!("unknown preset '{p}': expected one of {}", known.join(", ")))
            })
        })
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
    // The command line's defaults: no preset and no noise term simulate a typical MEMS gyro in
    // deg/s (said in a UserWarning, as `gyrolab simulate static` says it on stderr).
    let (cfg, typical) = gyrolab_eval::simulate::static_sim_config(&o).map_err(err)?;
    if let Some(t) = typical {
        let text = format!("no preset and no noise term given: simulating a {} (output in deg/s)", t.describe());
        let text = std::ffi::CString::new(text).map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
        PyErr::warn(py, &py.get_type::<pyo3::exceptions::PyUserWarning>(), &text, 1)?;
    }
    let s = run(py, || gyrolab_eval::simulate::simulate_static_samples(&cfg))?.map_err(err)?;
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
        run(py, || gyrolab_io::recording::read_records(&path, &options, &topics))?.map_err(|e| err(e.into()))?.records;
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

/// Evaluates a test plan and writes its report folder: (overall result or None, files written,
/// failed checks, checks CONDITIONAL or NOT EVALUATED with their reasons).
#[pyfunction]
#[allow(clippy::type_complexity)]
fn evaluate_plan(
    py: Python<'_>,
    plan: PathBuf,
    out: PathBuf,
) -> PyResult<(Option<String>, Vec<PathBuf>, Vec<String>, Vec<String>)> {
    let folder = run(py, || {
        let p = gyrolab_lab::test_plan::read_test_plan(&plan)?;
        gyrolab_lab::test_plan::evaluate_test_plan(&p, &plan.display().to_string(), &gyrolab_eval::Silent)
    })?
    .map_err(err)?;
    let files: Vec<(&str, &[u8])> = folder.outputs.iter().map(|o| (o.name.as_str(), &o.bytes[..])).collect();
    let inputs: Vec<&std::path::Path> = folder.inputs.iter().map(PathBuf::as_path).collect();
    let written = gyrolab_io::atomic::write_folder(&out, &files, &inputs).map_err(|e| {
        if e.is_usage() {
            pyo3::exceptions::PyValueError::new_err(e.to_string())
        } else {
            pyo3::exceptions::PyOSError::new_err(e.to_string())
        }
    })?;
    Ok((folder.verdict.map(|v| v.text().to_string()), written, folder.failures, folder.undecided))
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
    let (rates, status) = run(py, || gyrolab_eval::apply::apply_arrays(&calibration, axis, &slices))?.map_err(err)?;
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
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(allan_channels, m)?)?;
    m.add_function(wrap_pyfunction!(allan_table, m)?)?;
    m.add_class::<AllanChannels>()?;
    m.add_function(wrap_pyfunction!(render_export, m)?)?;
    m.add_function(wrap_pyfunction!(bias, m)?)?;
    m.add_function(wrap_pyfunction!(rate_table, m)?)?;
    m.add_function(wrap_pyfunction!(rate_table_files, m)?)?;
    m.add_function(wrap_pyfunction!(simulate_static, m)?)?;
    m.add_function(wrap_pyfunction!(read, m)?)?;
    m.add_function(wrap_pyfunction!(evaluate_plan, m)?)?;
    m.add_function(wrap_pyfunction!(apply, m)?)?;
    m.add_function(wrap_pyfunction!(store::store_history, m)?)?;
    m.add_function(wrap_pyfunction!(store::store_history_svg, m)?)?;
    m.add_function(wrap_pyfunction!(store::store_lot, m)?)?;
    m.add_function(wrap_pyfunction!(store::store_compare, m)?)?;
    m.add_function(wrap_pyfunction!(store::store_chart, m)?)?;
    m.add_function(wrap_pyfunction!(store::store_figures, m)?)?;
    m.add_function(wrap_pyfunction!(store::store_evaluation, m)?)?;
    m.add_function(wrap_pyfunction!(store::store_add, m)?)?;
    m.add_function(wrap_pyfunction!(store::store_masked, m)?)?;
    m.add_function(wrap_pyfunction!(store::store_report, m)?)?;
    m.add_function(wrap_pyfunction!(store::store_check, m)?)?;
    m.add_function(wrap_pyfunction!(store::store_accounts, m)?)?;
    m.add_function(wrap_pyfunction!(store::store_add_user, m)?)?;
    m.add_function(wrap_pyfunction!(store::store_issue, m)?)?;
    m.add_function(wrap_pyfunction!(store::store_reevaluate, m)?)?;
    m.add_function(wrap_pyfunction!(store::store_inputs, m)?)?;
    Ok(())
}
