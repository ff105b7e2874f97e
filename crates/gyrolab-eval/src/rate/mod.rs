//! Rate-table evaluation: records in the long or wide layout, or raw logs (time, table rate,
//! outputs) segmented into plateaus, one axis per file or per output column of a raw log.
//! Figures: paper eq. 1-9 as implemented by [`gyrolab::rate_test`] (docs/METHODS.md section 1).

pub mod raw_log;

use crate::error::{EvalError, EvalResult};
use crate::outcome::rate::AxisReport;
use gyrolab::rate_test::{evaluate, RateEvaluation, RateTestOptions};
use gyrolab::validate;
use gyrolab_io::calibration::{AxisCalibration, CalibrationFile, PolynomialModel, CALIBRATION_FORMAT};
use gyrolab_io::rate_table::{parse_rate_table, read_rate_table, RateColumns, RateLayout, RateTableFile};
use gyrolab_io::raw_log::{detect_raw_log, header_names};
use raw_log::{evaluate_channels, segment_file, SegmentationRequest, SegmentedLog};
use std::path::{Path, PathBuf};

/// Evaluation options of a rate-table test, as a front end gives them (checked by
/// [`RateSettings::options`]).
#[derive(Debug, Clone, PartialEq)]
pub struct RateSettings {
    /// Coverage factor k of the repeatability (3 or 2).
    pub coverage: f64,
    /// Quote hysteresis as half the largest forward-reverse difference.
    pub half_hysteresis: bool,
    /// Order of the polynomial model, 1 to 9.
    pub order: i64,
    /// Nonlinearity limit for the widest linear input range, percent.
    pub nonlinearity_limit_pct: Option<f64>,
}

impl Default for RateSettings {
    fn default() -> Self {
        RateSettings { coverage: 3.0, half_hysteresis: false, order: 1, nonlinearity_limit_pct: None }
    }
}

impl RateSettings {
    /// The checked options (errors name the field).
    pub fn options(&self) -> EvalResult<RateTestOptions> {
        Ok(RateTestOptions {
            coverage: validate::positive("coverage", self.coverage)?,
            half_hysteresis: self.half_hysteresis,
            order: validate::polynomial_order("order", self.order)?,
            nonlinearity_limit: self
                .nonlinearity_limit_pct
                .map(|p| validate::positive_percentage("nonlinearity_limit_pct", p))
                .transpose()?
                .map(|p| p / 100.0),
        })
    }
}

/// A rate-table evaluation of one or more files.
///
/// ```
/// use gyrolab_eval::rate::{RateRequest, evaluate_rates};
/// let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/paper/paper_rate_table_x.csv");
/// let request = RateRequest { files: vec![file], axis_names: vec!["x".into()], ..Default::default() };
/// let outcome = evaluate_rates(&request)?;
/// let k = outcome.axes[0].evaluation.scale_factor();
/// assert!((k * 1000.0 - 7.56).abs() < 0.01); // mV/(deg/s); the paper's Table 6 prints 7.6
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RateRequest {
    /// Records, one axis per file (a raw log: one axis per output column).
    pub files: Vec<PathBuf>,
    /// Read every file as a raw log even if its header does not say so.
    pub raw: bool,
    /// Columns and units of long and wide records.
    pub columns: RateColumns,
    /// Segmentation of raw logs.
    pub segmentation: SegmentationRequest,
    /// Axis names in order, one per axis (default: file stems, or the output columns' names).
    pub axis_names: Vec<String>,
    /// Evaluation options.
    pub settings: RateSettings,
    /// The caller writes the segmentation of the raw log (`segments_out`): exactly one file
    /// must then be a raw log.
    pub segments_out: bool,
}

/// One evaluated axis.
#[derive(Debug, Clone)]
pub struct EvaluatedAxis {
    /// Axis name.
    pub name: String,
    /// Source path as given.
    pub file: String,
    /// What was read.
    pub record: RateTableFile,
    /// The figures.
    pub evaluation: RateEvaluation,
}

impl EvaluatedAxis {
    /// The report view of this axis.
    pub fn report(&self) -> AxisReport<'_> {
        AxisReport {
            name: self.name.clone(),
            file: self.file.clone(),
            layout: match self.record.layout {
                RateLayout::Long => "long".into(),
                RateLayout::Wide => "wide".into(),
                RateLayout::Raw => "raw".into(),
            },
            output_unit: self.record.output_unit,
            samples: self.record.samples,
            evaluation: &self.evaluation,
        }
    }

    /// The calibration entry of this axis.
    pub fn calibration(&self) -> AxisCalibration {
        let e = &self.evaluation;
        let rates = &self.record.table.rates_dps;
        AxisCalibration {
            name: self.name.clone(),
            source_file: self.file.clone(),
            output_unit: self.record.output_unit,
            scale_factor: e.scale_factor(),
            zero_offset: e.zero_offset(),
            rest_reference: e.rest_reference,
            rate_min_dps: rates.first().copied().unwrap_or(0.0),
            rate_max_dps: rates.last().copied().unwrap_or(0.0),
            polynomial: PolynomialModel {
                order: e.polynomial.order(),
                coefficients: e.polynomial.coefficients.clone(),
            },
            temperature: None,
        }
    }
}

/// The axes of a rate-table request and the raw logs they came from.
#[derive(Debug, Clone)]
pub struct RateOutcome {
    /// Evaluated axes, in file order.
    pub axes: Vec<EvaluatedAxis>,
    /// Segmented raw logs, in file order.
    pub logs: Vec<SegmentedLog>,
}

/// Evaluates an already read record.
pub fn evaluate_record(
    name: String,
    file: String,
    record: RateTableFile,
    options: &RateTestOptions,
) -> EvalResult<EvaluatedAxis> {
    let evaluation = evaluate(&record.table, options)
        .map_err(|e| EvalError::Data(gyrolab_io::DataError::new(&file, format!("cannot evaluate: {e}"))))?;
    Ok(EvaluatedAxis { name, file, record, evaluation })
}

/// Reads and evaluates a long or wide record held in memory (`name` names it in errors).
pub fn evaluate_text(axis: &str, name: &str, text: &str, options: &RateTestOptions) -> EvalResult<EvaluatedAxis> {
    let record = parse_rate_table(Path::new(name), text, &RateColumns::default())?;
    evaluate_record(axis.into(), name.into(), record, options)
}

/// Builds a calibration file from evaluated axes, stamped with the time now.
pub fn calibration_file(axes: &[EvaluatedAxis]) -> CalibrationFile {
    CalibrationFile {
        format: CALIBRATION_FORMAT.into(),
        generator: format!("gyrolab {}", env!("CARGO_PKG_VERSION")),
        created: humantime::format_rfc3339_seconds(std::time::SystemTime::now()).to_string(),
        simulated: None,
        axes: axes.iter().map(EvaluatedAxis::calibration).collect(),
        triad: None,
    }
}

/// Whether a file is read as a raw log: forced, or told by its header.
pub fn is_raw_log(path: &Path, forced: bool) -> EvalResult<bool> {
    Ok(forced || detect_raw_log(&header_names(path)?).is_some())
}

/// Evaluates every file of a request.
pub fn evaluate_rates(request: &RateRequest) -> EvalResult<RateOutcome> {
    let options = request.settings.options()?;
    let seg_options = request.segmentation.options()?;
    let mut is_raw = Vec::with_capacity(request.files.len());
    for path in &request.files {
        is_raw.push(is_raw_log(path, request.raw)?);
    }
    let raw_count = is_raw.iter().filter(|r| **r).count();
    if (request.segmentation.manual_segments.is_some() || request.segments_out) && raw_count != 1 {
        return Err(EvalError::conflict_on(&["manual_segments", "segments_out"], format!(
            "{{manual_segments}} and {{segments_out}} take exactly one raw log, but {raw_count} of the files are raw logs"
        )));
    }
    for n in &request.axis_names {
        gyrolab::validate::axis_name("axis_names", n)?;
    }
    let mut axes: Vec<EvaluatedAxis> = Vec::new();
    let mut logs: Vec<SegmentedLog> = Vec::new();
    let mut names = request.axis_names.iter().cloned();
    for (i, path) in request.files.iter().enumerate() {
        let start = axes.len();
        if is_raw[i] {
            let log = segment_file(path, &request.segmentation, &seg_options, request.columns.output.as_deref())?;
            axes.extend(evaluate_channels(&log, &options, &seg_options, &mut || names.next())?);
            logs.push(log);
        } else {
            let record = read_rate_table(path, &request.columns)?;
            let name = names.next().unwrap_or_else(|| {
                path.file_stem().map_or_else(|| format!("axis{}", i + 1), |s| s.to_string_lossy().into_owned())
            });
            axes.push(evaluate_record(name, path.display().to_string(), record, &options)?);
        }
        for a in &axes[start..] {
            if axes.iter().filter(|b| b.name == a.name).count() > 1 {
                return Err(EvalError::conflict_on(&["axis_names"], format!(
                    "two axes are named '{}': name them with {{axis_names}} (one per file, or per output column of a raw log)",
                    a.name
                )));
            }
        }
    }
    if !request.axis_names.is_empty() && request.axis_names.len() != axes.len() {
        return Err(EvalError::conflict_on(&["axis_names"], format!(
            "{{axis_names}} given {} time(s) for {} axes: give one name per file (per output column of a raw log), in order",
            request.axis_names.len(),
            axes.len()
        )));
    }
    Ok(RateOutcome { axes, logs })
}

/// Evaluates observations held in memory (one per plateau mean or sample: rate in deg/s, run,
/// stroke, output in `output_unit`) as the axis `name`, the way a file's records are.
///
/// ```
/// use gyrolab::rate_test::{RateObservation, Stroke};
/// use gyrolab::units::OutputUnit;
/// use gyrolab_eval::rate::{evaluate_observations, RateSettings};
/// let mut obs = Vec::new();
/// for run in 1..=2 {
///     for (stroke, rates) in [(Stroke::Forward, [-10.0, 0.0, 10.0]), (Stroke::Reverse, [10.0, 0.0, -10.0])] {
///         for r in rates {
///             obs.push(RateObservation { rate_dps: r, run, stroke, output: 2.5 + 0.0075 * r });
///         }
///     }
/// }
/// let axis = evaluate_observations("x", &obs, OutputUnit::Volt, &RateSettings::default())?;
/// assert!((axis.evaluation.scale_factor() - 0.0075).abs() < 1e-15);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn evaluate_observations(
    name: &str,
    observations: &[gyrolab::rate_test::RateObservation],
    output_unit: gyrolab::units::OutputUnit,
    settings: &RateSettings,
) -> EvalResult<EvaluatedAxis> {
    let options = settings.options()?;
    let table = gyrolab::rate_test::RateTable::from_observations(observations, None)
        .map_err(|e| EvalError::Data(gyrolab_io::DataError::new(name, format!("cannot read the observations: {e}"))))?;
    let record = RateTableFile {
        table,
        output_unit,
        rate_unit: gyrolab::units::RateUnit::DegPerSec,
        layout: RateLayout::Long,
        samples: observations.len(),
    };
    evaluate_record(name.into(), name.into(), record, &options)
}
