//! The temperature tests of a test plan (`[temperature.<axis>]`, docs/PLAN.md): records at
//! soaked temperature points, each a rate-table record, a static record, or both.

use super::Ctx;
use crate::rate_table::RateColumns;
use crate::DataError;
use gyrolab::thermal::Phase;
use gyrolab::units::OutputUnit;
use gyrolab::validate;
use serde::Deserialize;
use std::path::PathBuf;
use toml::Spanned;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawTemperature {
    order: Option<Spanned<i64>>,
    reference_temp_c: Option<Spanned<f64>>,
    sample_rate_hz: Option<Spanned<f64>>,
    channel: Option<String>,
    output_unit: Option<Spanned<String>>,
    rate_column: Option<String>,
    output_column: Option<String>,
    rate_output_unit: Option<Spanned<String>>,
    #[serde(default)]
    points: Vec<Spanned<RawPoint>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPoint {
    temperature_c: Spanned<f64>,
    phase: Option<Spanned<String>>,
    rate: Option<Spanned<String>>,
    #[serde(rename = "static")]
    static_file: Option<Spanned<String>>,
}

/// One soaked temperature point.
#[derive(Debug, Clone, PartialEq)]
pub struct TemperaturePoint {
    /// Chamber temperature after soaking, degC.
    pub temperature_c: f64,
    /// Heating or cooling to this point.
    pub phase: Phase,
    /// The rate-table record at this temperature (resolved), if any.
    pub rate_file: Option<PathBuf>,
    /// The static record at this temperature (resolved), if any.
    pub static_file: Option<PathBuf>,
    /// The paths as written in the plan (rate, static).
    pub files_as_written: (Option<String>, Option<String>),
    /// 1-based line of the point in the plan.
    pub line: u64,
}

/// The temperature tests of one axis.
#[derive(Debug, Clone, PartialEq)]
pub struct TemperaturePlan {
    /// Axis name.
    pub axis: String,
    /// Polynomial order of K(T), null(T) and bias(T) (default 1).
    pub order: usize,
    /// Reference temperature of the models, degC (default 25).
    pub reference_temp_c: f64,
    /// Sample rate of the static records, Hz (`None`: from their time stamps).
    pub sample_rate_hz: Option<f64>,
    /// Output column of the static records.
    pub channel: Option<String>,
    /// Output unit of that column.
    pub output_unit: Option<OutputUnit>,
    /// Columns of the rate-table records.
    pub rate_columns: RateColumns,
    /// The points, in plan order.
    pub points: Vec<TemperaturePoint>,
}

/// Parses and checks `[temperature.<axis>]`.
pub(crate) fn parse(cx: &Ctx<'_>, axis: &str, raw: &Spanned<RawTemperature>) -> Result<TemperaturePlan, DataError> {
    let key = |k: &str| format!("temperature.{axis}.{k}");
    let t = raw.get_ref();
    let order = match &t.order {
        Some(n) => cx.check(n.span(), &key("order"), validate::polynomial_order("order", *n.get_ref()))?,
        None => 1,
    };
    let reference_temp_c = match &t.reference_temp_c {
        Some(r) => {
            let v = *r.get_ref();
            if !(-273.15..=1000.0).contains(&v) {
                return Err(cx.err(r.span(), &key("reference_temp_c"), format!("{v} degC: expected -273.15 to 1000")));
            }
            v
        }
        None => 25.0,
    };
    let sample_rate_hz = t
        .sample_rate_hz
        .as_ref()
        .map(|f| cx.check(f.span(), &key("sample_rate_hz"), validate::positive("sample_rate_hz", *f.get_ref())))
        .transpose()?;
    if let (Some(u), None) = (&t.output_unit, &t.channel) {
        return Err(cx.err(
            u.span(),
            &key("output_unit"),
            format!("needs {} (the column it applies to)", key("channel")),
        ));
    }
    if t.points.is_empty() {
        return Err(cx.err(
            raw.span(),
            &key("points"),
            "no temperature point: expected [[temperature.<axis>.points]] tables with temperature_c and a rate \
             and/or static record",
        ));
    }
    let mut points = Vec::with_capacity(t.points.len());
    for (i, p) in t.points.iter().enumerate() {
        let line = crate::calibration::line_col(cx.text, p.span().start).0;
        let pk = |k: &str| format!("temperature.{axis}.points[{i}].{k}");
        let p_ref = p.get_ref();
        let temperature_c = *p_ref.temperature_c.get_ref();
        if !(-273.15..=1000.0).contains(&temperature_c) {
            return Err(cx.err(
                p_ref.temperature_c.span(),
                &pk("temperature_c"),
                format!("{temperature_c} degC: expected -273.15 to 1000"),
            ));
        }
        let phase = match &p_ref.phase {
            None => Phase::Unstated,
            Some(s) => match s.get_ref().as_str() {
                "heating" => Phase::Heating,
                "cooling" => Phase::Cooling,
                other => {
                    return Err(cx.err(
                        s.span(),
                        &pk("phase"),
                        format!("'{}': expected \"heating\" or \"cooling\"", crate::text::excerpt(other)),
                    ))
                }
            },
        };
        if p_ref.rate.is_none() && p_ref.static_file.is_none() {
            return Err(cx.err(
                p.span(),
                &format!("temperature.{axis}.points[{i}]"),
                format!(
                    "the point at {temperature_c} degC has no record: give rate = \"FILE\" and/or static = \"FILE\""
                ),
            ));
        }
        points.push(TemperaturePoint {
            temperature_c,
            phase,
            rate_file: p_ref.rate.as_ref().map(|f| cx.existing_file(&pk("rate"), f)).transpose()?,
            static_file: p_ref.static_file.as_ref().map(|f| cx.existing_file(&pk("static"), f)).transpose()?,
            files_as_written: (
                p_ref.rate.as_ref().map(|f| f.get_ref().clone()),
                p_ref.static_file.as_ref().map(|f| f.get_ref().clone()),
            ),
            line,
        });
    }
    // The models need order + 1 distinct temperatures among the points that carry each record.
    let distinct = |f: &dyn Fn(&TemperaturePoint) -> bool| {
        let mut v: Vec<f64> = points.iter().filter(|p| f(p)).map(|p| p.temperature_c).collect();
        v.sort_by(f64::total_cmp);
        v.dedup();
        v.len()
    };
    let (n_rate, n_static) = (distinct(&|p| p.rate_file.is_some()), distinct(&|p| p.static_file.is_some()));
    if n_rate.max(n_static) < order + 1 {
        let span = t.order.as_ref().map_or(raw.span(), |o| o.span());
        return Err(cx.err(
            span,
            &key("order"),
            format!(
                "a model of order {order} needs {} distinct temperatures; the points have {n_rate} with a rate \
                 record and {n_static} with a static record",
                order + 1
            ),
        ));
    }
    Ok(TemperaturePlan {
        axis: axis.to_string(),
        order,
        reference_temp_c,
        sample_rate_hz,
        channel: t.channel.clone(),
        output_unit: cx.output_unit(&key("output_unit"), &t.output_unit)?,
        rate_columns: RateColumns {
            output: t.output_column.clone(),
            rate: t.rate_column.clone(),
            output_unit: cx.output_unit(&key("rate_output_unit"), &t.rate_output_unit)?,
            ..RateColumns::default()
        },
        points,
    })
}
