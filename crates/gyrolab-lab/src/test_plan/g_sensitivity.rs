//! The g-sensitivity part of a test plan: the `[g_sensitivity.<axis>]` records (static records
//! in several orientations) evaluated to their mean biases with this plan's K and null, fitted by
//! [`gyrolab::g_sensitivity`] (IEEE Std 1431-2004 / IEEE Std 952-1997 g-sensitive drift term;
//! GJB 2426A-2004), and returned as report sections, summary figures, `sections.g_sensitivity`
//! of results.json and a CSV table.

use super::static_part::{reference_of, StaticContext};
use gyrolab::figures::AxisFigures;
use gyrolab::format::sig;
use gyrolab::g_sensitivity::{
    fit_g_sensitivity, Coefficient, GRecord, GSensitivityConfig, GSensitivityFit, MagnitudeKind, NoStdError, SensorAxis,
};
use gyrolab::limits::{check_limits, Limit};
use gyrolab::static_test::StaticTestConfig;
use gyrolab_eval::error::{EvalError, EvalResult};
use gyrolab_eval::progress::Progress;
use gyrolab_eval::static_test::evaluate_file;
use gyrolab_io::series::SeriesOptions;
use gyrolab_io::test_plan::GSensitivityAxisPlan;
use gyrolab_io::DataError;
use gyrolab_report::html::{DataTable, FigureRow, ReportSection};
use gyrolab_report::static_report::ReferenceJson;
use serde_json::{json, Map, Value};
use std::path::Path;

/// The summary figure's key (docs/METHODS.md, g-sensitivity).
pub const FIGURE_KEY: &str = "g_sensitivity_dph_per_g";

/// What the g-sensitivity part adds to a report folder.
#[derive(Default)]
pub struct GSensitivityParts {
    /// One section per axis.
    pub sections: Vec<ReportSection>,
    /// The summary figure per axis.
    pub figures: Vec<AxisFigures>,
    /// `sections.g_sensitivity` of results.json, keyed by axis (none without tables).
    pub json: Option<Value>,
    /// CSV files (name, content).
    pub files: Vec<(String, Vec<u8>)>,
    /// Uncertainty inputs of the figure for the `[uncertainty]` part.
    pub uncertainty_inputs: Vec<super::uncertainty::FigureInput>,
}

/// One evaluated axis.
struct AxisResult<'a> {
    plan: &'a GSensitivityAxisPlan,
    fit: GSensitivityFit,
    reference: ReferenceJson,
    simulated: Option<String>,
    /// Notes (e.g. which of several output columns was evaluated).
    notes: Vec<String>,
}

/// Number of progress steps of the g-sensitivity part.
pub fn progress_steps(plans: &[GSensitivityAxisPlan]) -> u64 {
    plans.iter().map(|p| p.records.len() as u64).sum()
}

fn shown(path: &Path, base: &Path) -> String {
    path.strip_prefix(base).unwrap_or(path).display().to_string()
}

/// The orientation as written (`+x up`), or the specific-force vector.
fn orientation_text(r: &gyrolab_io::test_plan::GRecordPlan) -> String {
    r.orientation.clone().unwrap_or_else(|| force_text(r.specific_force_g))
}

fn force_text(f: [f64; 3]) -> String {
    format!("[{}, {}, {}]", sig(f[0], 4), sig(f[1], 4), sig(f[2], 4))
}

/// Evaluates one axis: the mean bias of every record, then the fit.
fn evaluate_axis<'a>(
    g: &'a GSensitivityAxisPlan,
    ctx: &StaticContext<'_>,
    plan_file: &Path,
    progress: &dyn Progress,
) -> EvalResult<AxisResult<'a>> {
    let axis = &g.axis;
    let (reference, reference_json) = reference_of(axis, ctx)?;
    let options = SeriesOptions {
        sample_rate_hz: g.sample_rate_hz,
        channels: g.channel.clone().map(|c| vec![c]),
        column_units: match (&g.channel, g.output_unit) {
            (Some(c), Some(u)) => vec![(c.clone(), u)],
            _ => Vec::new(),
        },
        ..SeriesOptions::default()
    };
    // The earth rate is handled by the fit (its projection differs between orientations).
    let config = StaticTestConfig { latitude_deg: None, ..StaticTestConfig::default() };
    let mut records = Vec::new();
    let mut notes = Vec::new();
    for r in &g.records {
        progress.message(&format!("axis {axis}: g-sensitivity record {}", shown(&r.file, ctx.base)));
        let (results, _) = evaluate_file(&r.file, &options, &reference, &config)?;
        if results.len() > 1 {
            notes.push(format!(
                "{}: {} output columns; the first, '{}', is evaluated (name one with g_sensitivity.{axis}.channel).",
                shown(&r.file, ctx.base),
                results.len(),
                results[0].channel
            ));
        }
        let Some(result) = results.into_iter().next() else {
            return Err(EvalError::Data(DataError::new(&r.file, "no output channel to evaluate")));
        };
        let Some(bias_dph) = result.bias_dph else {
            return Err(EvalError::Data(
                DataError::new(
                    plan_file,
                    format!(
                        "g_sensitivity.{axis}: no scale factor K for the outputs of {} (channel '{}', {}): give \
                         this plan a [rate.{axis}] table or an [options] calibration file with axis {axis}",
                        shown(&r.file, ctx.base),
                        result.channel,
                        result.output_unit.symbol()
                    ),
                )
                .at_line(g.line),
            ));
        };
        records.push(GRecord { specific_force_g: r.specific_force_g, bias_dph });
        progress.advance(1);
    }
    let cfg = GSensitivityConfig {
        input_axis: g.input_axis,
        latitude_deg: g.latitude_deg,
        null_contains_earth_rate: reference_json.null_contains_earth_rate,
    };
    let fit = fit_g_sensitivity(&records, &cfg).map_err(|e| {
        EvalError::Data(DataError::new(plan_file, format!("g_sensitivity.{axis}.records: {e}")).at_line(g.line))
    })?;
    Ok(AxisResult { plan: g, fit, reference: reference_json, simulated: ctx.simulated.map(|f| f(axis)), notes })
}

fn estimate_text(c: &Coefficient) -> String {
    match c {
        Coefficient::Resolved(e) => match e.std_error {
            Some(se) => format!("{} ± {}", sig(e.value, 4), sig(se, 2)),
            None => sig(e.value, 4),
        },
        Coefficient::Unresolved(r) => format!("not resolved: {}", r.text()),
    }
}

fn magnitude_words(kind: &MagnitudeKind) -> String {
    match kind {
        MagnitudeKind::Single(a) => format!("|G_{}|, the only resolved component", a.name()),
        MagnitudeKind::Vector(axes) => format!(
            "the magnitude of the resolved components ({})",
            axes.iter().map(|a| format!("G_{}", a.name())).collect::<Vec<_>>().join(", ")
        ),
    }
}

fn earth_words(a: &AxisResult<'_>) -> String {
    let input = a.plan.input_axis.name();
    match (a.plan.latitude_deg, a.fit.earth_rate_vertical_dph) {
        (Some(lat), Some(e)) => {
            let null = if a.reference.null_contains_earth_rate {
                format!(
                    " The null was measured at rest on the rate table with the input axis up, so it already holds \
                     {} deg/h: Ω_e sin φ (u_i − 1) is removed.",
                    sig(e, 4)
                )
            } else {
                String::new()
            };
            format!(
                "Earth rate: latitude {} deg, Ω_e sin φ = {} deg/h along a vertical-up input axis; each record's \
                 bias has Ω_e sin φ u_i removed, u_i the up component of the input axis (sensor {input}). \
                 Horizontal input-axis components are assumed to point east-west, where the earth-rate projection \
                 is zero.{null}",
                sig(lat, 6),
                sig(e, 4)
            )
        }
        _ => format!(
            "Earth rate: no latitude given, so no earth-rate projection is removed; the biases hold Ω_e sin φ u_i \
             (up to 15.04 deg/h), which enters B_0 and G_{input} (give g_sensitivity.{}.latitude_deg).",
            a.plan.axis
        ),
    }
}

fn section(a: &AxisResult<'_>, figures: &AxisFigures, limits: &[Limit], base: &Path) -> ReportSection {
    let f = &a.fit;
    let checks = check_limits(limits, std::slice::from_ref(figures));
    let mut rows = Vec::new();
    for (i, c) in f.g_dph_per_g.iter().enumerate() {
        rows.push(FigureRow {
            label: format!("g-sensitivity G_{}", SensorAxis::ALL[i].name()),
            key: String::new(),
            value: estimate_text(c),
            unit: "(deg/h)/g".into(),
            limit: String::new(),
            verdict: None,
            axis: None,
            check_axis: None,
        });
    }
    if let Some(m) = &f.magnitude {
        rows.push(FigureRow {
            label: format!("g-sensitivity: {}", magnitude_words(&m.kind)),
            key: FIGURE_KEY.into(),
            value: match m.std_error {
                Some(se) => format!("{} ± {} (standard error, k = 1)", sig(m.value, 4), sig(se, 2)),
                None => sig(m.value, 4),
            },
            unit: "(deg/h)/g".into(),
            limit: limits
                .iter()
                .find(|l| l.figure == FIGURE_KEY && l.applies_to(&figures.axis))
                .map_or_else(String::new, Limit::text),
            verdict: checks.iter().find(|c| c.figure == FIGURE_KEY).map(|c| c.verdict),
            axis: None,
            check_axis: Some(figures.axis.clone()),
        });
    }
    rows.push(FigureRow {
        label: "bias at zero g B_0".into(),
        key: String::new(),
        value: estimate_text(&f.bias_at_zero_g),
        unit: "deg/h".into(),
        limit: String::new(),
        verdict: None,
        axis: None,
        check_axis: None,
    });
    let se_words = match (f.std_error_absent, f.residual_std_dph) {
        (Some(NoStdError::NoResidualDegreesOfFreedom), _) => format!(
            "No standard errors: {} independent record combination(s) for {} unknown(s) leave no residual degrees \
             of freedom (record each orientation more than once, or more orientations).",
            f.records.len(),
            f.rank
        ),
        (None, Some(s)) => format!(
            "± are standard errors from the residual standard deviation s = {} deg/h with {} degree(s) of freedom.",
            sig(s, 3),
            f.residual_dof
        ),
        (None, None) => String::new(),
    };
    let table_rows = f
        .records
        .iter()
        .zip(&a.plan.records)
        .map(|(r, p)| {
            vec![
                orientation_text(p),
                force_text(r.specific_force_g),
                shown(&p.file, base),
                sig(r.bias_dph, 6),
                sig(r.earth_rate_removed_dph, 4),
                sig(r.corrected_bias_dph, 6),
                sig(r.residual_dph, 3),
            ]
        })
        .collect();
    ReportSection {
        title: format!("g-sensitivity, axis {}", a.plan.axis),
        simulated: a.simulated.is_some(),
        paragraphs: [
            a.simulated.clone().map(|s| format!("SIMULATED DATA: {s}")),
            Some(format!(
                "Bias of each static record B_i = B_0 + G_x f_x + G_y f_y + G_z f_z, f the specific force along the \
                 sensor axes in g (+x up: f = (1, 0, 0)), fitted by least squares (IEEE Std 1431-2004 and IEEE Std \
                 952-1997 g-sensitive drift term; GJB 2426A-2004; docs/METHODS.md, g-sensitivity). Components the \
                 orientations do not span are not resolved and are reported without a value. Input axis: sensor {}.",
                a.plan.input_axis.name()
            )),
            Some(format!("Reference: {}", a.reference.text)),
            Some(earth_words(a)),
            Some(se_words).filter(|s| !s.is_empty()),
        ]
        .into_iter()
        .flatten()
        .chain(a.notes.iter().cloned())
        .collect(),
        figures: rows,
        tables: vec![DataTable {
            caption: "Records: mean bias, earth-rate projection removed, and residual from the fit".into(),
            header: [
                "orientation",
                "specific force [f_x, f_y, f_z] (g)",
                "file",
                "bias (deg/h)",
                "earth rate removed (deg/h)",
                "corrected bias (deg/h)",
                "residual (deg/h)",
            ]
            .map(String::from)
            .to_vec(),
            rows: table_rows,
        }],
        ..Default::default()
    }
}

fn axis_json(a: &AxisResult<'_>, base: &Path) -> Value {
    let f = &a.fit;
    let mut o = Map::new();
    o.insert("input_axis".into(), json!(a.plan.input_axis.name()));
    let mut unresolved = Map::new();
    for (i, c) in f.g_dph_per_g.iter().enumerate() {
        let n = SensorAxis::ALL[i].name();
        match c {
            Coefficient::Resolved(e) => {
                o.insert(format!("g_sensitivity_{n}_dph_per_g"), json!(e.value));
                o.insert(format!("g_sensitivity_{n}_std_error_dph_per_g"), json!(e.std_error));
            }
            Coefficient::Unresolved(r) => {
                unresolved.insert(n.into(), json!({ "reason": r.key(), "text": r.text() }));
            }
        }
    }
    o.insert("unresolved_components".into(), Value::Object(unresolved));
    if let Some(m) = &f.magnitude {
        o.insert(FIGURE_KEY.into(), json!(m.value));
        o.insert("g_sensitivity_std_error_dph_per_g".into(), json!(m.std_error));
        let (kind, axes): (&str, Vec<&str>) = match &m.kind {
            MagnitudeKind::Single(a) => ("single_component", vec![a.name()]),
            MagnitudeKind::Vector(v) => ("magnitude", v.iter().map(|a| a.name()).collect()),
        };
        o.insert("g_sensitivity_kind".into(), json!(kind));
        o.insert("g_sensitivity_components".into(), json!(axes));
        o.insert("g_sensitivity_note".into(), json!(magnitude_words(&m.kind)));
    }
    match f.bias_at_zero_g {
        Coefficient::Resolved(e) => {
            o.insert("bias_at_zero_g_dph".into(), json!(e.value));
            o.insert("bias_at_zero_g_std_error_dph".into(), json!(e.std_error));
        }
        Coefficient::Unresolved(r) => {
            o.insert("bias_at_zero_g_unresolved".into(), json!({ "reason": r.key(), "text": r.text() }));
        }
    }
    o.insert(
        "std_error_absent".into(),
        json!(f.std_error_absent.map(|NoStdError::NoResidualDegreesOfFreedom| "no_residual_degrees_of_freedom")),
    );
    o.insert("rank".into(), json!(f.rank));
    o.insert("residual_dof".into(), json!(f.residual_dof));
    o.insert("residual_std_dph".into(), json!(f.residual_std_dph));
    o.insert("latitude_deg".into(), json!(a.plan.latitude_deg));
    o.insert("earth_rate_vertical_dph".into(), json!(f.earth_rate_vertical_dph));
    o.insert("earth_rate".into(), json!(earth_words(a)));
    o.insert("reference".into(), serde_json::to_value(&a.reference).unwrap_or(Value::Null));
    let records: Vec<Value> = f
        .records
        .iter()
        .zip(&a.plan.records)
        .map(|(r, p)| {
            json!({
                "orientation": p.orientation,
                "specific_force_g": r.specific_force_g,
                "file": shown(&p.file, base),
                "bias_dph": r.bias_dph,
                "input_axis_up": r.input_axis_up,
                "earth_rate_removed_dph": r.earth_rate_removed_dph,
                "corrected_bias_dph": r.corrected_bias_dph,
                "residual_dph": r.residual_dph,
            })
        })
        .collect();
    o.insert("records".into(), Value::Array(records));
    o.insert("notes".into(), json!(a.notes));
    o.insert("simulated".into(), json!(a.simulated));
    Value::Object(o)
}

fn records_csv(axes: &[AxisResult<'_>], base: &Path) -> String {
    let mut s = String::new();
    if axes.iter().any(|a| a.simulated.is_some()) {
        s.push_str(&format!("{}\n", gyrolab_io::provenance::SIMULATED_DATA_MARK));
    }
    s.push_str(
        "axis,orientation,f_x_g,f_y_g,f_z_g,file,bias_dph,earth_rate_removed_dph,corrected_bias_dph,residual_dph\n",
    );
    let q = |t: &str| {
        if t.contains([',', '"', '\n']) {
            format!("\"{}\"", t.replace('"', "\"\""))
        } else {
            t.to_string()
        }
    };
    for a in axes {
        for (r, p) in a.fit.records.iter().zip(&a.plan.records) {
            s.push_str(&format!(
                "{},{},{:?},{:?},{:?},{},{:?},{:?},{:?},{:?}\n",
                q(&a.plan.axis),
                q(p.orientation.as_deref().unwrap_or("")),
                r.specific_force_g[0],
                r.specific_force_g[1],
                r.specific_force_g[2],
                q(&shown(&p.file, base)),
                r.bias_dph,
                r.earth_rate_removed_dph,
                r.corrected_bias_dph,
                r.residual_dph
            ));
        }
    }
    s
}

/// Evaluates every `[g_sensitivity.<axis>]` table (K and null from this plan's rate-table
/// evaluation or its calibration file, as the static part) into sections, figures, JSON and CSV.
pub fn evaluate_g_sensitivity(
    plans: &[GSensitivityAxisPlan],
    ctx: &StaticContext<'_>,
    plan_file: &Path,
    progress: &dyn Progress,
) -> EvalResult<GSensitivityParts> {
    let mut parts = GSensitivityParts::default();
    if plans.is_empty() {
        return Ok(parts);
    }
    let mut axes = Vec::new();
    for g in plans {
        axes.push(evaluate_axis(g, ctx, plan_file, progress)?);
    }
    let mut json = Map::new();
    for a in &axes {
        let mut figs = AxisFigures {
            axis: a.plan.axis.clone(),
            output_unit: a.reference.output_unit.clone().unwrap_or_default(),
            ..Default::default()
        };
        if let Some(m) = &a.fit.magnitude {
            figs.set(FIGURE_KEY, m.value);
            parts.uncertainty_inputs.push(super::uncertainty::g_sensitivity_input(
                &a.plan.axis,
                m.value,
                m.std_error,
                a.fit.residual_dof,
            ));
        }
        if a.simulated.is_some() {
            figs.simulated = figs.values.iter().map(|(k, _)| k.clone()).collect();
        }
        parts.sections.push(section(a, &figs, ctx.limits, ctx.base));
        parts.figures.push(figs);
        json.insert(a.plan.axis.clone(), axis_json(a, ctx.base));
    }
    parts.files.push(("g_sensitivity.csv".into(), records_csv(&axes, ctx.base).into_bytes()));
    parts.json = Some(Value::Object(json));
    Ok(parts)
}
