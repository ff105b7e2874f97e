//! Plan sections `[power_ups.<axis>]` (repeatability across power-ups: one record per power-up)
//! and `[warmup.<axis>]` (a static record from power-on), read and checked with key and line.
//! A child module of [`crate::test_plan`] (it uses the plan's error context); keys in
//! docs/PLAN.md, "Repeated power-ups and warm-up".

use super::Ctx;
use crate::calibration::line_col;
use crate::rate_table::RateColumns;
use crate::DataError;
use gyrolab::units::{OutputUnit, RateUnit};
use gyrolab::validate;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::PathBuf;
use toml::Spanned;

/// `[power_ups.<axis>]` as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawPowerUps {
    rate_files: Option<Spanned<Vec<String>>>,
    rate_column: Option<String>,
    run_column: Option<String>,
    stroke_column: Option<String>,
    output_column: Option<String>,
    rate_unit: Option<Spanned<String>>,
    rate_output_unit: Option<Spanned<String>>,
    static_files: Option<Spanned<Vec<String>>>,
    sample_rate_hz: Option<Spanned<f64>>,
    channel: Option<String>,
    output_unit: Option<Spanned<String>>,
    allow_motion: Option<bool>,
}

/// `[warmup.<axis>]` as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawWarmup {
    file: Spanned<String>,
    sample_rate_hz: Spanned<f64>,
    band_dph: Spanned<f64>,
    window_s: Option<Spanned<f64>>,
    channel: Option<String>,
    output_unit: Option<Spanned<String>>,
    power_on_s: Option<Spanned<f64>>,
}

/// One record per power-up of one axis (`[power_ups.<axis>]`): rate-table records (the scale
/// factor of each power-up) and/or static records (the bias of each power-up).
#[derive(Debug, Clone, PartialEq)]
pub struct PowerUpsPlan {
    /// Axis name.
    pub axis: String,
    /// Rate-table records, one per power-up (resolved), with the paths as written.
    pub rate_files: Vec<(PathBuf, String)>,
    /// Column names and units of the rate-table records, as for `gyrolab rate`.
    pub rate_columns: RateColumns,
    /// Static records, one per power-up (resolved), with the paths as written.
    pub static_files: Vec<(PathBuf, String)>,
    /// Sample rate of the static records, Hz (required with `static_files`).
    pub sample_rate_hz: Option<f64>,
    /// Output column of the static records.
    pub channel: Option<String>,
    /// Output unit of `channel`, overriding its suffix.
    pub output_unit: Option<OutputUnit>,
    /// Evaluate static records whose stillness check finds motion (`allow_motion = true`; they
    /// are refused otherwise).
    pub allow_motion: bool,
    /// 1-based line of the section in the plan.
    pub line: u64,
}

/// A static record from power-on of one axis (`[warmup.<axis>]`).
#[derive(Debug, Clone, PartialEq)]
pub struct WarmupPlan {
    /// Axis name.
    pub axis: String,
    /// The record (resolved).
    pub file: PathBuf,
    /// The path as written.
    pub file_as_written: String,
    /// 1-based line of `file` in the plan (errors about the record's start name it).
    pub file_line: u64,
    /// Sample rate, Hz.
    pub sample_rate_hz: f64,
    /// Settling band +-, deg/h.
    pub band_dph: f64,
    /// Window of the window means, s (default 10).
    pub window_s: f64,
    /// Output column.
    pub channel: Option<String>,
    /// Output unit of `channel`, overriding its suffix.
    pub output_unit: Option<OutputUnit>,
    /// Time stamp of power-on in the record's time column, s (default 0).
    pub power_on_s: f64,
}

/// Default window of the warm-up window means, s.
pub const DEFAULT_WARMUP_WINDOW_S: f64 = 10.0;

impl Ctx<'_> {
    /// A list of one record per power-up: at least two, each existing.
    fn power_up_files(&self, key: &str, v: &Spanned<Vec<String>>) -> Result<Vec<(PathBuf, String)>, DataError> {
        let n = v.get_ref().len();
        if n < 2 {
            return Err(self.err(
                v.span(),
                key,
                format!(
                    "{n} file(s): repeatability across power-ups needs at least two power-ups (one record per \
                     power-up, three or more for a supported figure)"
                ),
            ));
        }
        v.get_ref()
            .iter()
            .enumerate()
            .map(|(i, f)| {
                let p = self.existing_file(&format!("{key}[{i}]"), &Spanned::new(v.span(), f.clone()))?;
                Ok((p, f.clone()))
            })
            .collect()
    }

    fn channel_unit(
        &self,
        key: &dyn Fn(&str) -> String,
        channel: &Option<String>,
        unit: &Option<Spanned<String>>,
    ) -> Result<Option<OutputUnit>, DataError> {
        if let (Some(u), None) = (unit, channel) {
            return Err(self.err(
                u.span(),
                &key("output_unit"),
                format!("needs {} (the column it applies to)", key("channel")),
            ));
        }
        self.output_unit(&key("output_unit"), unit)
    }
}

/// Checks that every section's axis is in `device.axes`.
pub(super) fn check_axes<T>(
    cx: &Ctx<'_>,
    table: &str,
    sections: &BTreeMap<String, Spanned<T>>,
    axes: &[String],
) -> Result<(), DataError> {
    for (k, v) in sections {
        if !axes.contains(k) {
            return Err(cx.err(
                v.span(),
                &format!("{table}.{k}"),
                format!("axis '{k}' is not in device.axes ({})", axes.join(", ")),
            ));
        }
    }
    Ok(())
}

/// Reads the `[power_ups.*]` tables in device axis order.
pub(super) fn power_ups(
    cx: &Ctx<'_>,
    raw: &BTreeMap<String, Spanned<RawPowerUps>>,
    axes: &[String],
) -> Result<Vec<PowerUpsPlan>, DataError> {
    check_axes(cx, "power_ups", raw, axes)?;
    let mut out = Vec::new();
    for axis in axes {
        let Some(s) = raw.get(axis) else { continue };
        let span = s.span();
        let s = s.get_ref();
        let key = |k: &str| format!("power_ups.{axis}.{k}");
        if s.rate_files.is_none() && s.static_files.is_none() {
            return Err(cx.err(
                span,
                &format!("power_ups.{axis}"),
                "expected rate_files = [...] (one rate-table record per power-up) or static_files = [...] (one \
                 static record per power-up), or both",
            ));
        }
        let rate_files = s.rate_files.as_ref().map(|f| cx.power_up_files(&key("rate_files"), f)).transpose()?;
        let static_files = s.static_files.as_ref().map(|f| cx.power_up_files(&key("static_files"), f)).transpose()?;
        let sample_rate_hz = match (&s.sample_rate_hz, &static_files) {
            (Some(f), _) => {
                Some(cx.check(f.span(), &key("sample_rate_hz"), validate::positive("sample_rate_hz", *f.get_ref()))?)
            }
            (None, Some(_)) => {
                return Err(cx.err(
                    span,
                    &key("sample_rate_hz"),
                    "missing: static_files need the sample rate of their records (Hz)",
                ))
            }
            (None, None) => None,
        };
        let rate_unit = s
            .rate_unit
            .as_ref()
            .map(|u| {
                RateUnit::parse(u.get_ref()).ok_or_else(|| {
                    cx.err(
                        u.span(),
                        &key("rate_unit"),
                        format!("unknown rate unit '{}': expected dps, rad_s or dph", u.get_ref()),
                    )
                })
            })
            .transpose()?;
        out.push(PowerUpsPlan {
            axis: axis.clone(),
            rate_files: rate_files.unwrap_or_default(),
            rate_columns: RateColumns {
                rate: s.rate_column.clone(),
                run: s.run_column.clone(),
                stroke: s.stroke_column.clone(),
                output: s.output_column.clone(),
                rate_unit,
                output_unit: cx.output_unit(&key("rate_output_unit"), &s.rate_output_unit)?,
            },
            static_files: static_files.unwrap_or_default(),
            sample_rate_hz,
            channel: s.channel.clone(),
            output_unit: cx.channel_unit(&key, &s.channel, &s.output_unit)?,
            allow_motion: s.allow_motion.unwrap_or(false),
            line: line_col(cx.text, span.start).0,
        });
    }
    Ok(out)
}

/// Reads the `[warmup.*]` tables in device axis order.
pub(super) fn warmups(
    cx: &Ctx<'_>,
    raw: &BTreeMap<String, Spanned<RawWarmup>>,
    axes: &[String],
) -> Result<Vec<WarmupPlan>, DataError> {
    check_axes(cx, "warmup", raw, axes)?;
    let mut out = Vec::new();
    for axis in axes {
        let Some(w) = raw.get(axis) else { continue };
        let w = w.get_ref();
        let key = |k: &str| format!("warmup.{axis}.{k}");
        let positive =
            |v: &Spanned<f64>, k: &'static str| cx.check(v.span(), &key(k), validate::positive(k, *v.get_ref()));
        let power_on_s = match &w.power_on_s {
            Some(p) if !p.get_ref().is_finite() => {
                return Err(cx.err(p.span(), &key("power_on_s"), "expected a finite time stamp, s"))
            }
            Some(p) => *p.get_ref(),
            None => 0.0,
        };
        out.push(WarmupPlan {
            axis: axis.clone(),
            file: cx.existing_file(&key("file"), &w.file)?,
            file_as_written: w.file.get_ref().clone(),
            file_line: line_col(cx.text, w.file.span().start).0,
            sample_rate_hz: positive(&w.sample_rate_hz, "sample_rate_hz")?,
            band_dph: positive(&w.band_dph, "band_dph")?,
            window_s: w
                .window_s
                .as_ref()
                .map(|v| positive(v, "window_s"))
                .transpose()?
                .unwrap_or(DEFAULT_WARMUP_WINDOW_S),
            channel: w.channel.clone(),
            output_unit: cx.channel_unit(&key, &w.channel, &w.output_unit)?,
            power_on_s,
        });
    }
    Ok(out)
}
