//! The temperature-test section of the report (soaked temperature points): K(T) and bias(T) per
//! point with their models, the temperature sensitivities and thermal hysteresis, plots of both
//! against temperature, results.json `sections.temperature.<axis>` and the CSV table.

use crate::html::{DataTable, PlotBlock, ReportSection};
use crate::plot::{Axis, Figure, Panel, PlotError, Series, SeriesStyle};
use crate::static_report::figure_rows;
use gyrolab::figures::AxisFigures;
use gyrolab::format::{sig, sig_opt};
use gyrolab::limits::Limit;
use gyrolab::thermal::{Hysteresis, NotResolved, Phase, Sensitivity, TemperatureModel};
use serde::Serialize;

/// One soaked temperature point as evaluated.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PointReport {
    /// Chamber temperature, degC.
    pub temperature_c: f64,
    /// Heating, cooling or unstated.
    pub phase: Phase,
    /// The rate-table record as written in the plan.
    pub rate_file: Option<String>,
    /// The static record as written in the plan.
    pub static_file: Option<String>,
    /// Scale factor K of the point's rate-table test, output units per deg/s.
    pub scale_factor: Option<f64>,
    /// Zero-rate output of the rate-table test (its rest reference F_r), output units.
    pub rate_test_null: Option<f64>,
    /// Mean output of the static record, output units.
    pub static_mean: Option<f64>,
    /// Mean of the record's own temperature column, degC (a check of the soak).
    pub recorded_temperature_c: Option<f64>,
    /// Bias at this point, deg/h: (static mean - reference null) / K.
    pub bias_dph: Option<f64>,
}

/// A model or the reason it has none.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum ModelOrReason {
    /// Fitted.
    Model(TemperatureModel),
    /// Not fitted, and why.
    NotResolved(NotResolved),
}

/// A figure with its value and support, or the reason it has none.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum Resolved<T> {
    /// A value.
    Value(T),
    /// No value, and why.
    NotResolved(NotResolved),
}

impl<T> Resolved<T> {
    /// From a core result.
    pub fn from(r: Result<T, NotResolved>) -> Self {
        match r {
            Ok(v) => Resolved::Value(v),
            Err(e) => Resolved::NotResolved(e),
        }
    }

    /// The value, if any.
    pub fn value(&self) -> Option<&T> {
        match self {
            Resolved::Value(v) => Some(v),
            Resolved::NotResolved(_) => None,
        }
    }

    fn reason(&self) -> Option<String> {
        match self {
            Resolved::Value(_) => None,
            Resolved::NotResolved(r) => Some(r.text()),
        }
    }
}

/// Everything evaluated for one axis's temperature points.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TemperatureAxisReport {
    /// Axis name.
    pub axis: String,
    /// Output unit of K and the null.
    pub output_unit: String,
    /// Polynomial order of the models.
    pub order: usize,
    /// Reference temperature, degC.
    pub reference_temp_c: f64,
    /// The null the biases are taken against, output units, and where it came from.
    pub bias_null: f64,
    /// Where the bias null came from, in words.
    pub bias_null_source: String,
    /// The points in plan order.
    pub points: Vec<PointReport>,
    /// K(T), output units per deg/s.
    pub scale_factor_model: ModelOrReason,
    /// Null F(T), output units (from the static means, else the rate tests' rest references).
    pub null_model: ModelOrReason,
    /// Which records the null model was fitted to: `static_means` or `rate_test_nulls`.
    pub null_model_source: Option<String>,
    /// Bias B(T), deg/h.
    pub bias_model: ModelOrReason,
    /// Scale-factor temperature sensitivity, ppm/degC.
    pub scale_factor_temp_sensitivity_ppm_per_c: Resolved<Sensitivity>,
    /// Bias temperature sensitivity, (deg/h)/degC.
    pub bias_temp_sensitivity_dph_per_c: Resolved<Sensitivity>,
    /// Scale-factor thermal hysteresis, ppm.
    pub scale_factor_thermal_hysteresis_ppm: Resolved<Hysteresis>,
    /// Bias thermal hysteresis, deg/h.
    pub bias_thermal_hysteresis_dph: Resolved<Hysteresis>,
    /// Whether calibration.toml carries this axis's compensation (and if not, why).
    pub compensation: String,
    /// Simulated data: the description.
    pub simulated: Option<String>,
}

impl TemperatureAxisReport {
    /// Summary figures (only those with values).
    pub fn figures(&self) -> AxisFigures {
        let mut f =
            AxisFigures { axis: self.axis.clone(), output_unit: self.output_unit.clone(), ..Default::default() };
        if let Some(s) = self.scale_factor_temp_sensitivity_ppm_per_c.value() {
            f.set("scale_factor_temp_sensitivity_ppm_per_c", s.value);
        }
        if let Some(s) = self.bias_temp_sensitivity_dph_per_c.value() {
            f.set("bias_temp_sensitivity_dph_per_c", s.value);
        }
        if let Some(h) = self.scale_factor_thermal_hysteresis_ppm.value() {
            f.set("scale_factor_thermal_hysteresis_ppm", h.value);
        }
        if let Some(h) = self.bias_thermal_hysteresis_dph.value() {
            f.set("bias_thermal_hysteresis_dph", h.value);
        }
        if self.simulated.is_some() {
            f.simulated = f.values.iter().map(|(k, _)| k.clone()).collect();
        }
        f
    }

    /// The `sections.temperature.<axis>` object of results.json.
    pub fn json(&self) -> serde_json::Value {
        serde_json::to_value(self).unwrap_or(serde_json::Value::Null)
    }
}

fn model_text(m: &ModelOrReason, unit: &str) -> String {
    match m {
        ModelOrReason::NotResolved(r) => format!("not fitted: {}", r.text()),
        ModelOrReason::Model(m) => {
            let terms: Vec<String> = m
                .coefficients
                .iter()
                .enumerate()
                .map(|(k, c)| match k {
                    0 => sig(*c, 7),
                    1 => format!("{} x", sig(*c, 5)),
                    _ => format!("{} x^{k}", sig(*c, 5)),
                })
                .collect();
            format!(
                "{} {unit}, x = T − {} degC, fitted on {} .. {} degC (RMS residual {}, {} residual degree(s) of freedom)",
                terms.join(" + "),
                sig(m.reference_temp_c, 4),
                sig(m.temp_min_c, 4),
                sig(m.temp_max_c, 4),
                sig(m.rms_residual, 3),
                m.residual_dof
            )
        }
    }
}

fn model_curve(m: &ModelOrReason, scale: impl Fn(f64) -> f64) -> Vec<(f64, f64)> {
    match m {
        ModelOrReason::Model(m) if m.temp_max_c > m.temp_min_c => (0..=60)
            .map(|i| {
                let t = m.temp_min_c + (m.temp_max_c - m.temp_min_c) * i as f64 / 60.0;
                (t, scale(m.eval(t)))
            })
            .collect(),
        _ => Vec::new(),
    }
}

fn phase_series(points: Vec<(Phase, f64, f64)>) -> Vec<Series> {
    let mut out = Vec::new();
    for (k, (phase, name)) in
        [(Phase::Heating, "heating"), (Phase::Cooling, "cooling"), (Phase::Unstated, "points")].into_iter().enumerate()
    {
        let p: Vec<(f64, f64)> = points.iter().filter(|x| x.0 == phase).map(|x| (x.1, x.2)).collect();
        if !p.is_empty() {
            out.push(Series::new(name, p, SeriesStyle::Markers, k));
        }
    }
    out
}

fn plot(
    title: String,
    y_label: &str,
    points: Vec<(Phase, f64, f64)>,
    curve: Vec<(f64, f64)>,
    curve_name: &str,
) -> Result<Option<String>, PlotError> {
    if points.is_empty() {
        return Ok(None);
    }
    let mut p = Panel::new(Axis::linear("temperature (degC)"), Axis::linear(y_label));
    p.series = phase_series(points);
    if curve.len() > 1 {
        p.series.push(Series::new(curve_name, curve, SeriesStyle::Line, 3));
    }
    p.place_legend();
    Figure::single(title, p).to_svg().map(Some)
}

/// The report section of one axis.
pub fn temperature_section(r: &TemperatureAxisReport, limits: &[Limit]) -> Result<ReportSection, PlotError> {
    let u = &r.output_unit;
    let figs = r.figures();
    let keys: Vec<(String, String)> = vec![
        (
            "scale_factor_temp_sensitivity_ppm_per_c".into(),
            "scale-factor temperature sensitivity (straight-line slope / K(T_ref))".into(),
        ),
        ("bias_temp_sensitivity_dph_per_c".into(), "bias temperature sensitivity (straight-line slope)".into()),
        ("scale_factor_thermal_hysteresis_ppm".into(), "scale-factor thermal hysteresis (heating − cooling)".into()),
        ("bias_thermal_hysteresis_dph".into(), "bias thermal hysteresis (heating − cooling)".into()),
    ];
    let figures = figure_rows(&figs, limits, &keys);
    let mut paragraphs: Vec<String> = r.simulated.iter().map(|s| format!("SIMULATED: {s}")).collect();
    paragraphs.push(format!(
        "{} soaked temperature point(s) of axis {}. Each point's rate-table record gives K(T_i) (least squares, as \
         the rate-table test) and its static record the mean output; bias B_i = (static mean − {} {u}) / K, the null \
         being {}. Models: polynomials of order {} in x = T − {} degC (docs/METHODS.md, \"Temperature tests\"; IEEE \
         Std 952-1997 and 1431-2004 annex B model terms, GJB 2426A-2004 temperature tests).",
        r.points.len(),
        r.axis,
        sig(r.bias_null, 7),
        r.bias_null_source,
        r.order,
        sig(r.reference_temp_c, 4)
    ));
    for (name, res) in [
        ("Scale-factor temperature sensitivity", r.scale_factor_temp_sensitivity_ppm_per_c.reason()),
        ("Bias temperature sensitivity", r.bias_temp_sensitivity_dph_per_c.reason()),
        ("Scale-factor thermal hysteresis", r.scale_factor_thermal_hysteresis_ppm.reason()),
        ("Bias thermal hysteresis", r.bias_thermal_hysteresis_dph.reason()),
    ] {
        if let Some(why) = res {
            paragraphs.push(format!("{name}: no value ({why})."));
        }
    }
    paragraphs.push(format!("K(T) = {}.", model_text(&r.scale_factor_model, &format!("{u}/(deg/s)"))));
    paragraphs.push(format!(
        "Null F(T) = {}{}.",
        model_text(&r.null_model, u),
        r.null_model_source.as_deref().map_or(String::new(), |s| format!(" (fitted to the {})", s.replace('_', " ")))
    ));
    paragraphs.push(format!("Bias B(T) = {}.", model_text(&r.bias_model, "deg/h")));
    paragraphs.push(format!("Compensation: {}", r.compensation));
    let mut plots = Vec::new();
    let k_points: Vec<(Phase, f64, f64)> =
        r.points.iter().filter_map(|p| Some((p.phase, p.temperature_c, p.scale_factor?))).collect();
    if let Some(svg) = plot(
        format!("Axis {}: scale factor against temperature", r.axis),
        &format!("K ({u}/(deg/s))"),
        k_points,
        model_curve(&r.scale_factor_model, |v| v),
        "model K(T)",
    )? {
        plots.push(PlotBlock {
            caption: format!("Scale factor K at each soaked point and the order-{} model K(T).", r.order),
            svg,
        });
    }
    let b_points: Vec<(Phase, f64, f64)> =
        r.points.iter().filter_map(|p| Some((p.phase, p.temperature_c, p.bias_dph?))).collect();
    if let Some(svg) = plot(
        format!("Axis {}: bias against temperature", r.axis),
        "bias (deg/h)",
        b_points,
        model_curve(&r.bias_model, |v| v),
        "model B(T)",
    )? {
        plots.push(PlotBlock {
            caption: format!(
                "Bias at each soaked point (one static record each) and the order-{} model B(T); the summary's \
                 sensitivity is the straight-line slope over the same points.",
                r.order
            ),
            svg,
        });
    }
    let rows = r
        .points
        .iter()
        .map(|p| {
            vec![
                sig(p.temperature_c, 4),
                p.phase.word().to_string(),
                sig_opt(p.recorded_temperature_c, 4),
                sig_opt(p.scale_factor, 7),
                sig_opt(p.rate_test_null, 7),
                sig_opt(p.static_mean, 7),
                sig_opt(p.bias_dph, 5),
                [p.rate_file.as_deref(), p.static_file.as_deref()].into_iter().flatten().collect::<Vec<_>>().join(", "),
            ]
        })
        .collect();
    Ok(ReportSection {
        title: format!("Temperature tests, axis {}", r.axis),
        simulated: r.simulated.is_some(),
        paragraphs,
        figures,
        plots,
        tables: vec![DataTable {
            caption: format!("Soaked temperature points of axis {} (plan order)", r.axis),
            header: [
                "T (degC)".to_string(),
                "phase".into(),
                "recorded T (degC)".into(),
                format!("K ({u}/(deg/s))"),
                format!("rate-test null ({u})"),
                format!("static mean ({u})"),
                "bias (deg/h)".into(),
                "records".into(),
            ]
            .to_vec(),
            rows,
        }],
        page_break_before: true,
    })
}

/// The CSV table of every axis's points.
pub fn temperature_points_csv(reports: &[TemperatureAxisReport]) -> String {
    let mut s = String::from(
        "axis,temperature_c,phase,recorded_temperature_c,scale_factor,rate_test_null,static_mean,bias_dph,rate_file,static_file\n",
    );
    let num = |v: Option<f64>| v.map_or_else(String::new, |v| format!("{v:?}"));
    for r in reports {
        for p in &r.points {
            s.push_str(&format!(
                "{},{:?},{},{},{},{},{},{},{},{}\n",
                r.axis,
                p.temperature_c,
                p.phase.word(),
                num(p.recorded_temperature_c),
                num(p.scale_factor),
                num(p.rate_test_null),
                num(p.static_mean),
                num(p.bias_dph),
                p.rate_file.as_deref().unwrap_or(""),
                p.static_file.as_deref().unwrap_or(""),
            ));
        }
    }
    s
}
