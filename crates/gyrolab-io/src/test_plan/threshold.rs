//! Plan keys of the threshold and resolution tests: `[threshold.<axis>]` and
//! `[resolution.<axis>]` (docs/PLAN.md, "Threshold and resolution"). A child module of
//! [`crate::test_plan`], called from its `parse_plan`.

use super::Ctx;
use crate::calibration::line_col;
use crate::threshold_record::StepColumns;
use crate::DataError;
use gyrolab::validate;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::PathBuf;
use toml::Spanned;

/// `[threshold.<axis>]` as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawThreshold {
    file: Spanned<String>,
    rate_column: Option<String>,
    output_column: Option<String>,
    output_unit: Option<Spanned<String>>,
    scale_factor: Option<Spanned<f64>>,
}

/// `[resolution.<axis>]` as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawResolution {
    file: Spanned<String>,
    base_rate_dps: Option<Spanned<f64>>,
    rate_column: Option<String>,
    output_column: Option<String>,
    output_unit: Option<Spanned<String>>,
    scale_factor: Option<Spanned<f64>>,
}

/// Where the nominal scale factor K of a threshold or resolution test comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum NominalScaleFactor {
    /// Given in the plan (`scale_factor`), output units per deg/s.
    Given(f64),
    /// This plan's `[rate.<axis>]` evaluation.
    RateTable,
    /// The plan's `[options] calibration` file (axis of the same name).
    CalibrationFile(PathBuf),
}

/// A threshold or resolution test of one axis.
#[derive(Debug, Clone, PartialEq)]
pub struct StepTestPlan {
    /// Axis name.
    pub axis: String,
    /// The record, resolved against the plan's folder.
    pub file: PathBuf,
    /// The path as written in the plan.
    pub file_as_written: String,
    /// Columns and output unit.
    pub columns: StepColumns,
    /// Nominal scale factor K.
    pub scale_factor: NominalScaleFactor,
    /// Resolution only: the base rate, deg/s (`None` for a threshold test).
    pub base_rate_dps: Option<f64>,
    /// The plan key of the table (`threshold.x`), for messages.
    pub key: String,
    /// 1-based line of the table in the plan.
    pub line: u64,
}

/// The raw tables of both sections.
pub(super) struct RawStepTables<'a> {
    pub threshold: &'a BTreeMap<String, Spanned<RawThreshold>>,
    pub resolution: &'a BTreeMap<String, Spanned<RawResolution>>,
}

struct Common<'a> {
    file: &'a Spanned<String>,
    rate_column: &'a Option<String>,
    output_column: &'a Option<String>,
    output_unit: &'a Option<Spanned<String>>,
    scale_factor: &'a Option<Spanned<f64>>,
}

/// Checks the threshold and resolution tables (axes already checked against device.axes), in
/// device axis order: threshold tests, then resolution tests.
pub(super) fn parse_step_tests(
    cx: &Ctx<'_>,
    axes: &[String],
    raw: &RawStepTables<'_>,
    has_rate: &dyn Fn(&str) -> bool,
    has_calibration: Option<&PathBuf>,
) -> Result<(Vec<StepTestPlan>, Vec<StepTestPlan>), DataError> {
    let common = |section: &str,
                  axis: &str,
                  span: std::ops::Range<usize>,
                  c: Common<'_>,
                  base_rate_dps: Option<f64>|
     -> Result<StepTestPlan, DataError> {
        let prefix = format!("{section}.{axis}");
        let key = |k: &str| format!("{prefix}.{k}");
        let scale_factor = match c.scale_factor {
            Some(k) => NominalScaleFactor::Given(cx.check(
                k.span(),
                &key("scale_factor"),
                validate::scale_factor("scale_factor", *k.get_ref()),
            )?),
            None if has_rate(axis) => NominalScaleFactor::RateTable,
            None => match has_calibration {
                Some(p) => NominalScaleFactor::CalibrationFile(p.clone()),
                None => {
                    return Err(cx.err(
                        span.clone(),
                        &key("scale_factor"),
                        format!(
                            "no nominal scale factor: give {} (output units per deg/s), a [rate.{axis}] table, \
                             or an [options] calibration file",
                            key("scale_factor")
                        ),
                    ))
                }
            },
        };
        Ok(StepTestPlan {
            axis: axis.to_string(),
            file: cx.existing_file(&key("file"), c.file)?,
            file_as_written: c.file.get_ref().clone(),
            columns: StepColumns {
                rate: c.rate_column.clone(),
                output: c.output_column.clone(),
                output_unit: cx.output_unit(&key("output_unit"), c.output_unit)?,
            },
            scale_factor,
            base_rate_dps,
            key: prefix.clone(),
            line: line_col(cx.text, span.start).0,
        })
    };
    let mut thresholds = Vec::new();
    let mut resolutions = Vec::new();
    for axis in axes {
        if let Some(t) = raw.threshold.get(axis) {
            let span = t.span();
            let t = t.get_ref();
            let c = Common {
                file: &t.file,
                rate_column: &t.rate_column,
                output_column: &t.output_column,
                output_unit: &t.output_unit,
                scale_factor: &t.scale_factor,
            };
            thresholds.push(common("threshold", axis, span, c, None)?);
        }
    }
    for axis in axes {
        if let Some(r) = raw.resolution.get(axis) {
            let span = r.span();
            let r = r.get_ref();
            let key = format!("resolution.{axis}.base_rate_dps");
            let base = match &r.base_rate_dps {
                None => {
                    return Err(cx.err(
                        span,
                        &key,
                        "missing: expected the base input rate in deg/s at which the resolution is measured (the \
                         other rates in the file are base +- steps)",
                    ))
                }
                Some(b) => cx.check(b.span(), &key, validate::finite("base_rate_dps", *b.get_ref()))?,
            };
            let c = Common {
                file: &r.file,
                rate_column: &r.rate_column,
                output_column: &r.output_column,
                output_unit: &r.output_unit,
                scale_factor: &r.scale_factor,
            };
            resolutions.push(common("resolution", axis, span, c, Some(base))?);
        }
    }
    Ok((thresholds, resolutions))
}
