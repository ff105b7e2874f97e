//! Report sections "Repeatability across power-ups" and "Warm-up" of a test plan, their
//! results.json objects (`sections.power_ups.<axis>`, `sections.warmup.<axis>`) and the warm-up
//! plot. Formulas: [`gyrolab::power_ups`], [`gyrolab::warmup`]; docs/METHODS.md.

use crate::bias::{warmup_text, WarmupJson};
use crate::html::{DataTable, FigureRow, PlotBlock, ReportSection};
use crate::plot::{Axis, Figure, LegendCorner, Panel, PlotError, Series, SeriesStyle};
use crate::static_report::ReferenceJson;
use gyrolab::figures::{known_figure, AxisFigures};
use gyrolab::format::{short, sig};
use gyrolab::limits::Limit;
use gyrolab::power_ups::PowerUpSpread;
use gyrolab_eval::outcome::static_test::WarmupReport;
use serde::Serialize;

/// One figure across power-ups: the per-record values and their spread (or why none).
#[derive(Debug, Clone)]
pub struct PowerUpFigure {
    /// (file as shown, value) per power-up, in plan order.
    pub values: Vec<(String, f64)>,
    /// The spread, or why there is none.
    pub spread: Result<PowerUpSpread, String>,
}

/// The power-up repeatability of one axis.
#[derive(Debug, Clone)]
pub struct PowerUpsReport {
    /// Axis name.
    pub axis: String,
    /// Scale factors K_i (output unit per deg/s) of the rate-table records, if any.
    pub scale_factor: Option<PowerUpFigure>,
    /// Output unit of K_i.
    pub scale_factor_unit: String,
    /// Biases B0_i (deg/h) of the static records, if any.
    pub bias: Option<PowerUpFigure>,
    /// The output-to-rate reference of the biases.
    pub reference: Option<ReferenceJson>,
    /// Simulated data: what was simulated.
    pub simulated: Option<String>,
    /// Notes shown in the section and in JSON (`notes`): static records that moved, evaluated
    /// because the plan allowed motion.
    pub notes: Vec<String>,
}

/// One power-up in JSON.
#[derive(Debug, Clone, Serialize)]
pub struct PowerUpValueJson {
    /// The record.
    pub file: String,
    /// Its value (K_i in `output_unit`/(deg/s), or B0_i in deg/h).
    pub value: f64,
    /// Deviation from the mean, same unit (null when there is no mean).
    pub deviation: Option<f64>,
}

/// The scale-factor repeatability across power-ups in JSON.
#[derive(Debug, Clone, Serialize)]
pub struct ScaleFactorPowerUpsJson {
    /// Number of power-ups.
    pub n: usize,
    /// Fewer than three power-ups (little support).
    pub few_power_ups: bool,
    /// std(K_i, n - 1) / |mean K_i|, ppm (null with `reason`).
    pub scale_factor_repeatability_power_up_ppm: Option<f64>,
    /// Mean K, output unit per deg/s.
    pub mean_scale_factor: Option<f64>,
    /// Output unit of K.
    pub output_unit: String,
    /// Why there is no value.
    pub reason: Option<String>,
    /// K_i per power-up.
    pub power_ups: Vec<PowerUpValueJson>,
}

/// The bias repeatability across power-ups in JSON.
#[derive(Debug, Clone, Serialize)]
pub struct BiasPowerUpsJson {
    /// Number of power-ups.
    pub n: usize,
    /// Fewer than three power-ups (little support).
    pub few_power_ups: bool,
    /// std(B0_i, n - 1), deg/h (null with `reason`).
    pub bias_repeatability_power_up_dph: Option<f64>,
    /// Mean bias, deg/h.
    pub mean_bias_dph: Option<f64>,
    /// Why there is no value.
    pub reason: Option<String>,
    /// The output-to-rate reference.
    pub reference: Option<ReferenceJson>,
    /// B0_i (`value`, deg/h) per power-up.
    pub power_ups: Vec<PowerUpValueJson>,
}

fn values_json(f: &PowerUpFigure) -> Vec<PowerUpValueJson> {
    f.values
        .iter()
        .enumerate()
        .map(|(i, (file, v))| PowerUpValueJson {
            file: file.clone(),
            value: *v,
            deviation: f.spread.as_ref().ok().map(|s| s.deviations[i]),
        })
        .collect()
}

impl PowerUpsReport {
    /// The scale-factor repeatability across power-ups, ppm.
    pub fn scale_factor_ppm(&self) -> Option<f64> {
        self.scale_factor.as_ref()?.spread.as_ref().ok()?.relative_ppm()
    }

    /// The bias repeatability across power-ups, deg/h.
    pub fn bias_dph(&self) -> Option<f64> {
        Some(self.bias.as_ref()?.spread.as_ref().ok()?.std)
    }

    /// Summary figures of the axis.
    pub fn figures(&self) -> AxisFigures {
        let mut f =
            AxisFigures { axis: self.axis.clone(), output_unit: self.scale_factor_unit.clone(), ..Default::default() };
        if let Some(v) = self.scale_factor_ppm() {
            f.set("scale_factor_repeatability_power_up_ppm", v);
        }
        if let Some(v) = self.bias_dph() {
            f.set("bias_repeatability_power_up_dph", v);
        }
        if self.simulated.is_some() {
            f.simulated = f.values.iter().map(|(k, _)| k.clone()).collect();
        }
        f
    }

    /// The `sections.power_ups.<axis>` object.
    pub fn json(&self) -> serde_json::Value {
        let sf = self.scale_factor.as_ref().map(|f| ScaleFactorPowerUpsJson {
            n: f.values.len(),
            few_power_ups: f.values.len() < gyrolab::power_ups::SUPPORTED_POWER_UPS,
            scale_factor_repeatability_power_up_ppm: self.scale_factor_ppm(),
            mean_scale_factor: f.spread.as_ref().ok().map(|s| s.mean),
            output_unit: self.scale_factor_unit.clone(),
            reason: reason(f, self.scale_factor_ppm().is_none()),
            power_ups: values_json(f),
        });
        let bias = self.bias.as_ref().map(|f| BiasPowerUpsJson {
            n: f.values.len(),
            few_power_ups: f.values.len() < gyrolab::power_ups::SUPPORTED_POWER_UPS,
            bias_repeatability_power_up_dph: self.bias_dph(),
            mean_bias_dph: f.spread.as_ref().ok().map(|s| s.mean),
            reason: reason(f, self.bias_dph().is_none()),
            reference: self.reference.clone(),
            power_ups: values_json(f),
        });
        serde_json::json!({ "scale_factor": sf, "bias": bias, "notes": self.notes, "simulated": self.simulated })
    }
}

fn reason(f: &PowerUpFigure, missing: bool) -> Option<String> {
    match &f.spread {
        Err(e) => Some(e.clone()),
        Ok(_) if missing => Some("the mean scale factor is 0: no relative spread".into()),
        Ok(_) => None,
    }
}

fn figure_rows(figs: &AxisFigures, limits: &[Limit], keys: &[&str]) -> Vec<FigureRow> {
    keys.iter()
        .filter_map(|key| {
            let label = known_figure(key).map_or_else(|| key.to_string(), |d| d.label.to_string());
            FigureRow::checked(figs, limits, key, &label)
        })
        .collect()
}

/// The reference in words; with none, outputs that are rates are converted by their own unit.
fn reference_text(r: &ReferenceJson) -> String {
    if r.source == "none" {
        "Reference: none (no rate-table record of this axis in the plan and no calibration file): the outputs \
         are rates in their own unit (deg/s, rad/s), converted to deg/h with K = 1 in that unit and null 0."
            .to_string()
    } else {
        format!("Reference: {}", r.text)
    }
}

fn support_text(what: &str, f: &PowerUpFigure) -> String {
    match &f.spread {
        Err(e) => format!("{what}: no value ({e})."),
        Ok(s) if s.few => format!(
            "{what}: from {} power-ups only (fewer than three): the standard deviation has {} degree of freedom and \
             little support.",
            s.n,
            s.n - 1
        ),
        Ok(s) => format!("{what}: from {} power-ups.", s.n),
    }
}

fn table(caption: String, unit: &str, dev_unit: &str, f: &PowerUpFigure, dev: &dyn Fn(f64, f64) -> f64) -> DataTable {
    let rows = f
        .values
        .iter()
        .enumerate()
        .map(|(i, (file, v))| {
            let d = f.spread.as_ref().ok().map_or_else(|| "—".to_string(), |s| sig(dev(s.deviations[i], s.mean), 4));
            vec![(i + 1).to_string(), file.clone(), sig(*v, 7), d]
        })
        .collect();
    DataTable {
        caption,
        header: vec![
            "power-up".into(),
            "file".into(),
            format!("value ({unit})"),
            format!("deviation from the mean ({dev_unit})"),
        ],
        rows,
    }
}

/// The section "Repeatability across power-ups" of one axis.
pub fn power_ups_section(r: &PowerUpsReport, limits: &[Limit]) -> ReportSection {
    let mut paragraphs = vec![format!(
        "Repeatability across power-ups (GJB 2426A-2004 bias and scale-factor repeatability; IEEE Std 952 / 1431 \
         turn-on to turn-on): one record per power-up under the same conditions, the standard deviation (n − 1) of \
         the per-power-up values. These are not the within-run figures: the rate-table section's scale-factor \
         repeatability is across the runs inside one record (within one power-up), and the static section's bias \
         repeatability is across the files of [static.{}]. docs/METHODS.md, \"Repeatability across power-ups\".",
        r.axis
    )];
    let mut tables = Vec::new();
    if let Some(f) = &r.scale_factor {
        paragraphs.push(support_text("Scale-factor repeatability across power-ups (std(K_i) / |mean K_i|)", f));
        tables.push(table(
            format!(
                "Scale factor K_i per power-up, axis {} ({}/(deg/s)); deviation in ppm of the mean",
                r.axis, r.scale_factor_unit
            ),
            &format!("{}/(deg/s)", r.scale_factor_unit),
            "ppm",
            f,
            &|d, m| if m != 0.0 { gyrolab::units::ratio_to_ppm(d / m.abs()) } else { f64::NAN },
        ));
    }
    if let Some(f) = &r.bias {
        paragraphs.push(support_text("Bias repeatability across power-ups (std(B0_i))", f));
        if let Some(re) = &r.reference {
            paragraphs.push(format!("B0_i = (mean output − null) / K per record. {}", reference_text(re)));
        }
        tables.push(table(format!("Bias B0_i per power-up, axis {} (deg/h)", r.axis), "deg/h", "deg/h", f, &|d, _| d));
    }
    paragraphs.extend(r.notes.iter().cloned());
    let figs = r.figures();
    ReportSection {
        title: format!("Repeatability across power-ups — axis {}", r.axis),
        simulated: r.simulated.is_some(),
        paragraphs,
        figures: figure_rows(
            &figs,
            limits,
            &["scale_factor_repeatability_power_up_ppm", "bias_repeatability_power_up_dph"],
        ),
        plots: Vec::new(),
        tables,
        page_break_before: false,
    }
}

/// The warm-up of one axis.
#[derive(Debug, Clone)]
pub struct WarmupAxisReport {
    /// Axis name.
    pub axis: String,
    /// The evaluated record.
    pub report: WarmupReport,
    /// Time stamp of power-on in the record, s.
    pub power_on_s: f64,
    /// Samples before power-on left out.
    pub dropped_before_power_on: usize,
    /// Whether the record has a time column (else the first sample is taken as power-on).
    pub timed: bool,
    /// The output-to-rate reference.
    pub reference: ReferenceJson,
    /// Simulated data: what was simulated.
    pub simulated: Option<String>,
}

impl WarmupAxisReport {
    /// Summary figures: `turn_on_bias_dph`, `warmup_settling_time_s` (when settled).
    pub fn figures(&self) -> AxisFigures {
        let r = &self.report.result;
        let mut f = AxisFigures { axis: self.axis.clone(), ..Default::default() };
        f.set("turn_on_bias_dph", r.turn_on);
        if self.reference.null_source.as_deref() == Some(crate::static_report::NOMINAL_NULL) {
            f.set_label("turn_on_bias_dph", "turn-on bias (absolute, against the nominal null)");
        }
        if let Some(t) = r.settling_time_s {
            f.set("warmup_settling_time_s", t);
        }
        if self.simulated.is_some() {
            f.simulated = f.values.iter().map(|(k, _)| k.clone()).collect();
        }
        f
    }

    /// The `sections.warmup.<axis>` object.
    pub fn json(&self) -> serde_json::Value {
        let mut v = serde_json::to_value(WarmupJson::new(&self.report)).unwrap_or_default();
        if let Some(o) = v.as_object_mut() {
            let settled = self.report.result.settling_time_s.is_some();
            o.insert("warmup_settling_time_s".into(), serde_json::json!(self.report.result.settling_time_s));
            o.insert(
                "settling_reason".into(),
                serde_json::json!(
                    (!settled).then_some("the window means never stay inside the band; see final_scatter_dph")
                ),
            );
            o.insert("power_on_s".into(), serde_json::json!(self.power_on_s));
            o.insert("samples_before_power_on".into(), serde_json::json!(self.dropped_before_power_on));
            o.insert("reference".into(), serde_json::to_value(&self.reference).unwrap_or_default());
            o.insert("simulated".into(), serde_json::json!(self.simulated));
        }
        v
    }
}

/// The window-mean bias against time from power-on with the band about the final bias and the
/// fitted model; the legend sits in the corner the transient leaves empty, above headroom.
pub fn warmup_plot(w: &WarmupAxisReport) -> Result<String, PlotError> {
    let r = &w.report.result;
    let band = r.config.band;
    let mut p = Panel::new(Axis::linear("time from power-on (s)"), Axis::linear("bias, window mean (deg/h)"));
    p.series.push(Series::new(
        format!("{}-s window means", short(r.config.window_s, 6)),
        r.windows.clone(),
        SeriesStyle::Markers,
        0,
    ));
    let t_end = r.windows.last().map_or(0.0, |w| w.0 + r.config.window_s / 2.0);
    let hi = r.final_bias + band;
    let lo = r.final_bias - band;
    p.series.push(Series::new(
        format!("band ±{} deg/h about the final bias", short(band, 6)),
        vec![(0.0, hi), (t_end, hi)],
        SeriesStyle::Dashed,
        6,
    ));
    p.series.push(Series::new("", vec![(0.0, lo), (t_end, lo)], SeriesStyle::Dashed, 6));
    if let Some(m) = &r.model {
        let pts = (0..=200)
            .map(|i| {
                let t = t_end * i as f64 / 200.0;
                (t, m.settled + m.amplitude * (-t / m.time_constant_s).exp())
            })
            .collect();
        p.series.push(Series::new(format!("model, τ = {} s", sig(m.time_constant_s, 3)), pts, SeriesStyle::Line, 1));
    }
    // Headroom for the legend on the side the transient leaves: it decays from above (A > 0) or
    // rises from below.
    let ys = r.windows.iter().map(|w| w.1).chain([hi, lo]);
    let (ymin, ymax) = ys.fold((f64::INFINITY, f64::NEG_INFINITY), |a, y| (a.0.min(y), a.1.max(y)));
    let span = (ymax - ymin).max(band);
    let decays = r.turn_on >= r.final_bias;
    if decays {
        p.legend = LegendCorner::UpperRight;
        p.y.range = Some((ymin - 0.05 * span, ymax + 0.45 * span));
    } else {
        p.legend = LegendCorner::LowerRight;
        p.y.range = Some((ymin - 0.45 * span, ymax + 0.05 * span));
    }
    Figure::single(format!("Warm-up, axis {}", w.axis), p).to_svg()
}

/// The section "Warm-up" of one axis.
pub fn warmup_section(w: &WarmupAxisReport, limits: &[Limit]) -> Result<ReportSection, PlotError> {
    let r = &w.report.result;
    let mut paragraphs = vec![
        format!(
            "Warm-up from power-on (IEEE Std 952 / 1431 turn-on bias and warm-up time, GJB 2426A-2004): bias window \
             means from power-on, the settling time to ±{} deg/h about the final bias (mean of the last 20 % of the \
             record), and the model B(t) = B_inf + A exp(−t/τ) fitted to the window means. docs/METHODS.md, \"Warm-up\".",
            short(r.config.band, 6)
        ),
        if w.timed {
            format!(
                "Power-on at time stamp {} s; {} sample(s) before it left out.",
                sig(w.power_on_s, 6),
                w.dropped_before_power_on
            )
        } else {
            "The record has no time column: its first sample is taken as power-on.".to_string()
        },
        warmup_text(std::slice::from_ref(&w.report)).trim_end().to_string(),
        reference_text(&w.reference),
    ];
    if r.settling_time_s.is_none() {
        paragraphs.push(format!(
            "No settling time: the window means never stay inside the band; the final window means scatter by {} \
             deg/h.",
            sig(r.final_scatter, 3)
        ));
    }
    let mut tables = Vec::new();
    if let Some(m) = &r.model {
        tables.push(DataTable {
            caption: format!("Settling model, axis {}", w.axis),
            header: vec![
                "B_inf (deg/h)".into(),
                "A (deg/h)".into(),
                "τ (s)".into(),
                "RMS residual (deg/h)".into(),
                "model time to the band (s)".into(),
            ],
            rows: vec![vec![
                sig(m.settled, 6),
                sig(m.amplitude, 5),
                sig(m.time_constant_s, 5),
                sig(m.rms_residual, 3),
                sig(m.settling_time_s, 4),
            ]],
        });
    }
    let figs = w.figures();
    Ok(ReportSection {
        title: format!("Warm-up — axis {}", w.axis),
        simulated: w.simulated.is_some(),
        paragraphs,
        figures: figure_rows(&figs, limits, &["turn_on_bias_dph", "warmup_settling_time_s"]),
        plots: vec![PlotBlock {
            caption: "Window-mean bias from power-on, the band about the final bias (dashed) and the fitted model"
                .into(),
            svg: warmup_plot(w)?,
        }],
        tables,
        page_break_before: false,
    })
}
