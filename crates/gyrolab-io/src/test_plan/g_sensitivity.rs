//! The `[g_sensitivity.<axis>]` tables of a test plan (docs/PLAN.md, g-sensitivity): static
//! records in named orientations (`+x up`, ...) or given specific forces, checked with the key
//! and line of every fault; orientations that span no g-sensitivity component are refused here.
//! A child module of [`crate::test_plan`] (it uses the plan's error context).

use super::Ctx;
use crate::calibration::line_col;
use crate::DataError;
use gyrolab::g_sensitivity::{fit_g_sensitivity, GRecord, GSensitivityConfig, NamedOrientation, SensorAxis};
use gyrolab::units::OutputUnit;
use gyrolab::validate;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::PathBuf;
use toml::Spanned;

/// `[g_sensitivity.<axis>]` as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawGSensitivity {
    records: Spanned<Vec<Spanned<RawGRecord>>>,
    input_axis: Option<Spanned<String>>,
    channel: Option<String>,
    output_unit: Option<Spanned<String>>,
    sample_rate_hz: Option<Spanned<f64>>,
    latitude_deg: Option<Spanned<f64>>,
}

/// One record `{ orientation = "+x up", file = "..." }` or `{ specific_force_g = [..], file = ".." }`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawGRecord {
    orientation: Option<Spanned<String>>,
    specific_force_g: Option<Spanned<Vec<f64>>>,
    file: Spanned<String>,
}

/// One static record of a g-sensitivity test.
#[derive(Debug, Clone, PartialEq)]
pub struct GRecordPlan {
    /// The orientation's name (`+x up`), when it was given by name.
    pub orientation: Option<String>,
    /// Specific force along sensor x, y, z, g.
    pub specific_force_g: [f64; 3],
    /// The record, resolved against the plan's folder.
    pub file: PathBuf,
    /// The path as written in the plan.
    pub file_as_written: String,
    /// 1-based line of the record in the plan.
    pub line: u64,
}

/// The g-sensitivity records of one gyro axis (`[g_sensitivity.<axis>]`).
#[derive(Debug, Clone, PartialEq)]
pub struct GSensitivityAxisPlan {
    /// Axis name (in `device.axes`).
    pub axis: String,
    /// The sensor axis that is this gyro's input axis.
    pub input_axis: SensorAxis,
    /// The records, in plan order.
    pub records: Vec<GRecordPlan>,
    /// Name of the output column.
    pub channel: Option<String>,
    /// Output unit, overriding the column suffix.
    pub output_unit: Option<OutputUnit>,
    /// Sample rate, Hz (none: from the time stamps).
    pub sample_rate_hz: Option<f64>,
    /// Latitude of the test site, degrees (for the earth-rate projection).
    pub latitude_deg: Option<f64>,
    /// 1-based line of the table in the plan.
    pub line: u64,
}

/// Checks the `[g_sensitivity.*]` tables, in device axis order.
pub(super) fn parse_g_sensitivity(
    cx: &Ctx<'_>,
    raw: &BTreeMap<String, Spanned<RawGSensitivity>>,
    axes: &[String],
) -> Result<Vec<GSensitivityAxisPlan>, DataError> {
    let mut out = Vec::new();
    for axis in axes {
        let Some(g) = raw.get(axis) else { continue };
        let span = g.span();
        let g = g.get_ref();
        let key = |k: &str| format!("g_sensitivity.{axis}.{k}");
        let input_axis = match &g.input_axis {
            Some(s) => SensorAxis::parse(s.get_ref()).ok_or_else(|| {
                cx.err(
                    s.span(),
                    &key("input_axis"),
                    format!("'{}': expected the sensor axis x, y or z", crate::text::excerpt(s.get_ref())),
                )
            })?,
            None => SensorAxis::parse(axis).ok_or_else(|| {
                cx.err(
                    span.clone(),
                    &key("input_axis"),
                    format!(
                        "missing: axis '{axis}' is not named x, y or z, so give the sensor axis this gyro senses \
                         (input_axis = \"x\", \"y\" or \"z\")"
                    ),
                )
            })?,
        };
        let sample_rate_hz = g
            .sample_rate_hz
            .as_ref()
            .map(|f| cx.check(f.span(), &key("sample_rate_hz"), validate::positive("sample_rate_hz", *f.get_ref())))
            .transpose()?;
        let latitude_deg = g
            .latitude_deg
            .as_ref()
            .map(|l| cx.check(l.span(), &key("latitude_deg"), validate::latitude_deg("latitude_deg", *l.get_ref())))
            .transpose()?;
        if let (Some(u), None) = (&g.output_unit, &g.channel) {
            return Err(cx.err(
                u.span(),
                &key("output_unit"),
                format!("needs {} (the column it applies to)", key("channel")),
            ));
        }
        if g.records.get_ref().is_empty() {
            return Err(cx.err(
                g.records.span(),
                &key("records"),
                "no record: expected static records in at least two orientations, e.g. \
                 [{ orientation = \"+x up\", file = \"xup.csv\" }, { orientation = \"-x up\", file = \"xdown.csv\" }]",
            ));
        }
        let mut records = Vec::new();
        for (i, r) in g.records.get_ref().iter().enumerate() {
            let rspan = r.span();
            let r = r.get_ref();
            let rkey = |k: &str| format!("g_sensitivity.{axis}.records[{i}].{k}");
            let (orientation, f) = match (&r.orientation, &r.specific_force_g) {
                (Some(_), Some(v)) => {
                    return Err(cx.err(
                        v.span(),
                        &rkey("specific_force_g"),
                        "give either orientation or specific_force_g, not both",
                    ))
                }
                (None, None) => {
                    return Err(cx.err(
                        rspan,
                        &format!("g_sensitivity.{axis}.records[{i}]"),
                        format!(
                            "no orientation: expected orientation = one of {} or specific_force_g = [fx, fy, fz] (g)",
                            NamedOrientation::NAMES.map(|n| format!("\"{n}\"")).join(", ")
                        ),
                    ))
                }
                (Some(o), None) => {
                    let n = NamedOrientation::parse(o.get_ref()).ok_or_else(|| {
                        cx.err(
                            o.span(),
                            &rkey("orientation"),
                            format!(
                                "unknown orientation '{}': expected one of {} (or give specific_force_g = [fx, fy, fz] in g)",
                                crate::text::excerpt(o.get_ref()),
                                NamedOrientation::NAMES.map(|n| format!("\"{n}\"")).join(", ")
                            ),
                        )
                    })?;
                    (Some(n.name()), n.specific_force_g())
                }
                (None, Some(v)) => {
                    let vals = v.get_ref();
                    let bad = |why: &str| cx.err(v.span(), &rkey("specific_force_g"), why.to_string());
                    if vals.len() != 3 {
                        return Err(bad(&format!("expected three numbers [fx, fy, fz] in g, got {}", vals.len())));
                    }
                    if vals.iter().any(|x| !x.is_finite() || x.abs() > 100.0) {
                        return Err(bad("expected finite numbers within -100 to 100 g"));
                    }
                    (None, [vals[0], vals[1], vals[2]])
                }
            };
            records.push(GRecordPlan {
                orientation,
                specific_force_g: f,
                file: cx.existing_file(&rkey("file"), &r.file)?,
                file_as_written: r.file.get_ref().clone(),
                line: line_col(cx.text, rspan.start).0,
            });
        }
        // Whether the orientations span a component does not depend on the biases.
        let probe: Vec<GRecord> =
            records.iter().map(|r| GRecord { specific_force_g: r.specific_force_g, bias_dph: 0.0 }).collect();
        let config = GSensitivityConfig { input_axis, latitude_deg: None, null_contains_earth_rate: false };
        if let Err(e) = fit_g_sensitivity(&probe, &config) {
            return Err(cx.err(g.records.span(), &key("records"), e));
        }
        out.push(GSensitivityAxisPlan {
            axis: axis.clone(),
            input_axis,
            records,
            channel: g.channel.clone(),
            output_unit: cx.output_unit(&key("output_unit"), &g.output_unit)?,
            sample_rate_hz,
            latitude_deg,
            line: line_col(cx.text, span.start).0,
        });
    }
    Ok(out)
}
