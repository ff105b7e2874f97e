//! The measurement-uncertainty part of a test plan (`[uncertainty]`): budgets of the scale
//! factor K, the zero offset F0, the bias B0, the bias stability and the Allan noise terms N, B
//! and K per axis (JCGM 100:2008 = JJF 1059.1-2012; formulas in [`gyrolab::uncertainty`] and
//! docs/METHODS.md, "Measurement uncertainty"): the report section, summary figures and the
//! results.json section `uncertainty`.

use gyrolab::figures::AxisFigures;
use gyrolab::format::sig;
use gyrolab::noise::Reading;
use gyrolab::rate_test::RestReferenceSource;
use gyrolab::uncertainty::{
    deviation_uncertainty, line_standard_errors, longest_supported_point, mean_uncertainty_from_allan,
    std_of_sample_std, Budget, Component, Correlation, Coverage, EvaluationType, LineUncertainty,
};
use gyrolab::units;
use gyrolab_eval::rate::EvaluatedAxis;
use gyrolab_io::test_plan::uncertainty::UncertaintyPlan;
use gyrolab_report::html::{DataTable, ReportSection};
use gyrolab_report::static_report::StaticAxisReport;
use serde_json::{json, Map, Value};

use EvaluationType::{A, B};

/// What the uncertainty part adds to a report folder.
pub struct UncertaintyParts {
    /// The "Measurement uncertainty" section.
    pub sections: Vec<ReportSection>,
    /// Summary figures per axis (`*_expanded_uncertainty_*`).
    pub figures: Vec<AxisFigures>,
    /// The results.json section `uncertainty`, keyed by axis.
    pub json: Value,
}

/// The budgets of one axis, and the figures that have none with the reason.
#[derive(Debug, Clone, Default)]
pub struct AxisUncertainty {
    /// Axis name.
    pub axis: String,
    /// Output unit symbol of the rate-table record (unit of K's numerator and of F0).
    pub output_unit: String,
    /// Budgets by key: `scale_factor`, `zero_offset`, `bias`, `bias_stability`, `arw`,
    /// `bias_instability`, `rrw`.
    pub budgets: Vec<(&'static str, Budget)>,
    /// Budgets of further summary figures, by figure key (nonlinearity, hysteresis,
    /// repeatabilities, temperature sensitivities, thermal hysteresis, threshold, resolution,
    /// warm-up settling time): their U is the figure's own and decides its guard band.
    pub figure_budgets: Vec<(String, Budget)>,
    /// Smoothing time of the bias-stability budget, s.
    pub bias_stability_smoothing_s: Option<f64>,
    /// (figure key, reason) of the budgets not given.
    pub not_given: Vec<(&'static str, String)>,
    /// Simulated data: the description.
    pub simulated: Option<String>,
}

impl AxisUncertainty {
    /// The budget of a key.
    pub fn budget(&self, key: &str) -> Option<&Budget> {
        self.budgets.iter().find(|(k, _)| *k == key).map(|(_, b)| b)
    }
}

/// The K and F0 budgets of a rate-table axis with the line's standard errors.
pub fn rate_budgets(
    axis: &EvaluatedAxis,
    plan: &UncertaintyPlan,
) -> Result<(Budget, Budget, LineUncertainty), gyrolab::uncertainty::UncertaintyError> {
    let e = &axis.evaluation;
    let rates: Vec<f64> = e.points.iter().map(|p| p.rate_dps).collect();
    let means: Vec<f64> = e.points.iter().map(|p| p.mean).collect();
    let line = line_standard_errors(&rates, &means)?;
    let u = axis.record.output_unit.symbol();
    let k = e.scale_factor();
    let dof = line.dof as f64;
    let mut kc = vec![Component::new(
        "least-squares slope: scatter of the point means about the line (GUM 4.2, H.3)",
        A,
        line.slope,
        format!("{u}/(deg/s)"),
        1.0,
    )
    .with_dof(dof)];
    if let Some(rel) = plan.rate_standard_uncertainty_rel() {
        kc.push(Component::new(
            format!("rate-table rate accuracy ({})", distribution_words(plan.rate_accuracy_distribution)),
            B,
            units::ratio_to_ppm(rel),
            "ppm",
            -k * units::ppm_to_ratio(1.0),
        ));
    }
    let mut fc = vec![Component::new(
        "least-squares intercept: scatter of the point means about the line (GUM 4.2, H.3)",
        A,
        line.intercept,
        u,
        1.0,
    )
    .with_dof(dof)];
    if let Some(uo) = plan.output_standard_uncertainty() {
        fc.push(Component::new(
            format!("data-acquisition output accuracy ({})", distribution_words(plan.output_accuracy_distribution)),
            B,
            uo,
            u,
            1.0,
        ));
    }
    let kb = budget("scale factor K", k, &format!("{u}/(deg/s)"), kc, plan);
    let fb = budget("zero offset F0", e.zero_offset(), u, fc, plan);
    Ok((kb, fb, line))
}

/// A budget of uncorrelated components expanded as the plan says (one k, or k_p from ν_eff).
fn budget(quantity: &str, value: f64, unit: &str, components: Vec<Component>, plan: &UncertaintyPlan) -> Budget {
    Budget::correlated(quantity, value, unit, components, Vec::new(), plan.coverage())
}

fn distribution_words(d: gyrolab::uncertainty::Distribution) -> &'static str {
    match d {
        gyrolab::uncertainty::Distribution::Rectangular => "rectangular half-width a, u = a/√3",
        gyrolab::uncertainty::Distribution::Normal => "stated as a standard uncertainty",
    }
}

/// The components of u(K) carried into a figure y with ∂y/∂K = `c` (split into K's type A and
/// type B parts so that every line of a budget is one type).
fn k_components(kb: &Budget, c: f64) -> Vec<Component> {
    let mut out = Vec::new();
    for kind in [A, B] {
        let u = kb.components.iter().filter(|x| x.kind == kind).map(|x| x.contribution.powi(2)).sum::<f64>().sqrt();
        if kb.components.iter().any(|x| x.kind == kind) {
            let what = if kind == A { "type A part (slope standard error)" } else { "type B part (rate accuracy)" };
            let mut comp = Component::new(format!("scale factor K, {what}"), kind, u, kb.unit.clone(), c);
            comp.dof = kb.components.iter().find(|x| x.kind == kind).and_then(|x| x.dof);
            out.push(comp);
        }
    }
    out
}

/// The uncertainty inputs of one summary figure from the part that evaluated it (components from
/// its data); the `[uncertainty]` part adds the plan's type-B terms, combines and expands them
/// with the report's coverage and hands the figure its U (docs/METHODS.md, "Measurement
/// uncertainty").
#[derive(Debug, Clone, PartialEq)]
pub struct FigureInput {
    /// Axis name.
    pub axis: String,
    /// The summary figure key (`threshold_dps`).
    pub figure: &'static str,
    /// What the figure is, in words.
    pub quantity: String,
    /// Its value, in `unit`.
    pub value: f64,
    /// Unit of the value.
    pub unit: String,
    /// Components from the data; empty with `not_given`.
    pub components: Vec<Component>,
    /// The figure is a table rate: the plan's rate accuracy applies to it in proportion.
    pub rate_proportional: bool,
    /// Why the figure has no budget (its data cannot support one).
    pub not_given: Option<String>,
}

impl FigureInput {
    fn new(
        axis: &str,
        figure: &'static str,
        quantity: &str,
        value: f64,
        unit: &str,
        components: Vec<Component>,
    ) -> Self {
        FigureInput {
            axis: axis.to_string(),
            figure,
            quantity: quantity.to_string(),
            value,
            unit: unit.to_string(),
            components,
            rate_proportional: false,
            not_given: None,
        }
    }

    fn refused(axis: &str, figure: &'static str, why: impl Into<String>) -> Self {
        FigureInput { not_given: Some(why.into()), ..FigureInput::new(axis, figure, "", f64::NAN, "", Vec::new()) }
    }
}

/// The standard-deviation component of a figure that is a sample standard deviation s of n values
/// (GUM E.4.3: u(s) = s/√(2(n − 1)), ν = n − 1), scaled by `c`.
fn std_component(what: &str, s: f64, n: usize, unit: &str, c: f64) -> Option<Component> {
    let u = std_of_sample_std(s, n).ok()?;
    Some(
        Component::new(
            format!("{what}: standard deviation of {n} values, u(s) = s/√(2(n − 1)) (GUM E.4.3)"),
            A,
            u,
            unit,
            c,
        )
        .with_dof(n as f64 - 1.0),
    )
}

/// The budgets of the rate-table figures of an axis beyond K and F0: nonlinearity, linearity,
/// hysteresis, repeatability and scale-factor repeatability. A point mean ȳ_j = (ȳ_fwd + ȳ_rev)/2
/// has u² = (s_fwd² + s_rev²) / (4R) from the scatter across the R runs (ν = R − 1 each).
fn rate_figure_inputs(axis: &EvaluatedAxis, plan: &UncertaintyPlan) -> Vec<FigureInput> {
    let e = &axis.evaluation;
    let name = axis.name.as_str();
    let u_out = axis.record.output_unit.symbol();
    let runs = e.runs;
    let mut out = Vec::new();
    let one_run = "a single run: no scatter across runs to evaluate the point means' uncertainty";
    // The two stroke means of point j, each with its scatter across the runs, with sensitivity
    // c_f and c_r.
    let stroke_parts = |j: usize, c_f: f64, c_r: f64| -> Option<Vec<Component>> {
        let p = &e.points[j];
        let (sf, sr) = (p.forward_std?, p.reverse_std?);
        let rf = (runs as f64).sqrt();
        let line = |stroke: &str, std: f64, c: f64| {
            Component::new(
                format!("{stroke}-stroke mean at {} deg/s: s/√R across {runs} runs", sig(p.rate_dps, 6)),
                A,
                std / rf,
                u_out,
                c,
            )
            .with_dof(runs as f64 - 1.0)
        };
        Some(vec![line("forward", sf, c_f), line("reverse", sr, c_r)])
    };
    let daq = |c: f64| {
        plan.output_standard_uncertainty().map(|uo| {
            Component::new(
                format!(
                    "data-acquisition output accuracy at that point ({}), all of it: the part K and F0 do not absorb \
                     is not stated",
                    distribution_words(plan.output_accuracy_distribution)
                ),
                B,
                uo,
                u_out,
                c,
            )
        })
    };
    let argmax = |f: &dyn Fn(&gyrolab::rate_test::PointSummary) -> f64| {
        (0..e.points.len()).max_by(|&a, &b| f(&e.points[a]).abs().total_cmp(&f(&e.points[b]).abs()))
    };
    let y_fs = e.full_scale_output;
    // Nonlinearity K_a = max |a_j|, a_j = (line_j − ȳ_j)/F_m (ratio): ∂a/∂ȳ = −1/F_m.
    if let Some(j) = argmax(&|p| p.nonlinearity) {
        let sign = -e.points[j].nonlinearity.signum();
        for (key, scale) in [("nonlinearity_pct", 100.0), ("nonlinearity_ppm", 1e6)] {
            let c = sign * scale / e.output_amplitude;
            let value = e.nonlinearity * scale;
            match stroke_parts(j, 0.5 * c, 0.5 * c) {
                Some(mut comps) => {
                    comps.extend(daq(c));
                    out.push(FigureInput::new(
                        name,
                        key,
                        "nonlinearity K_a",
                        value,
                        if scale == 100.0 { "%" } else { "ppm" },
                        comps,
                    ));
                }
                None => out.push(FigureInput::refused(name, key, one_run)),
            }
        }
    }
    // Linearity max |ȳ_j − line_j| / Y_FS.
    if let Some(j) = argmax(&|p| p.line_residual) {
        let c = e.points[j].line_residual.signum() * 100.0 / y_fs;
        match stroke_parts(j, 0.5 * c, 0.5 * c) {
            Some(mut comps) => {
                comps.extend(daq(c));
                out.push(FigureInput::new(name, "linearity_pct", "linearity δ_L", e.linearity * 100.0, "% FS", comps));
            }
            None => out.push(FigureInput::refused(name, "linearity_pct", one_run)),
        }
    }
    // Hysteresis max |ȳ_fwd − ȳ_rev| / Y_FS (× 1/2 with half_hysteresis); the output accuracy of
    // the two strokes at one rate is the same reading level of one instrument and cancels.
    if let Some(j) = argmax(&|p| p.forward_mean - p.reverse_mean) {
        let p = &e.points[j];
        let half = if e.options.half_hysteresis { 0.5 } else { 1.0 };
        let c = (p.forward_mean - p.reverse_mean).signum() * half * 100.0 / y_fs;
        match stroke_parts(j, c, -c) {
            Some(comps) => out.push(FigureInput::new(
                name,
                "hysteresis_pct",
                "hysteresis δ_H",
                e.hysteresis * 100.0,
                "% FS",
                comps,
            )),
            None => out.push(FigureInput::refused(name, "hysteresis_pct", one_run)),
        }
    }
    // Repeatability k_R σ_max / Y_FS (k_R of the figure's definition, not a coverage factor).
    if let (Some(r), Some(smax)) = (e.repeatability, e.repeatability_sigma_max) {
        let c = e.options.coverage * 100.0 / y_fs;
        let what = format!(
            "σ_max, the largest scatter across runs at one rate and stroke (× k_R = {} / Y_FS)",
            sig(e.options.coverage, 3)
        );
        if let Some(comp) = std_component(&what, smax, runs, u_out, c) {
            out.push(FigureInput::new(name, "repeatability_pct", "repeatability δ_R", r * 100.0, "% FS", vec![comp]));
        }
    }
    if let Some(sr) = &e.scale_factor_repeatability {
        let n = sr.per_run.len();
        for (key, scale, unit) in
            [("scale_factor_repeatability_ppm", 1e6, "ppm"), ("scale_factor_repeatability_pct", 100.0, "%")]
        {
            let v = sr.repeatability * scale;
            if let Some(comp) = std_component("the runs' scale factors K_i (relative)", v, n, unit, 1.0) {
                out.push(FigureInput::new(name, key, "scale-factor repeatability K_r", v, unit, vec![comp]));
            }
        }
    }
    out
}

/// A temperature slope: figure key, words, unit, the slope, the temperatures of its points.
type SlopeSeries<'a> = (&'static str, &'a str, &'a str, Option<&'a gyrolab::thermal::Sensitivity>, Vec<f64>);

/// A thermal hysteresis: figure key, words, unit, value, the model whose scatter gives u, whether
/// the figure is relative to the model's value at the reference temperature (ppm).
type HysteresisSeries<'a> =
    (&'static str, &'a str, &'a str, Option<f64>, &'a gyrolab_report::thermal::ModelOrReason, bool);

/// The uncertainty inputs of a temperature test's figures: the slopes' standard errors (ν = m − 2)
/// and the chamber's temperature accuracy (the plan's, added by [`evaluate_uncertainty`]); the
/// thermal hysteresis from the scatter of the soaked points about the temperature model (√2 s, ν
/// its residual degrees of freedom; the scatter holds the hysteresis too, so the figure's u is
/// not understated).
pub fn temperature_inputs(r: &gyrolab_report::thermal::TemperatureAxisReport) -> Vec<FigureInput> {
    use gyrolab_report::thermal::ModelOrReason;
    let mut out = Vec::new();
    let axis = r.axis.as_str();
    let temps = |f: &dyn Fn(&gyrolab_report::thermal::PointReport) -> Option<f64>| -> Vec<f64> {
        r.points.iter().filter(|p| f(p).is_some()).map(|p| p.temperature_c).collect()
    };
    let series: [SlopeSeries<'_>; 2] = [
        (
            "scale_factor_temp_sensitivity_ppm_per_c",
            "scale-factor temperature sensitivity",
            "ppm/degC",
            r.scale_factor_temp_sensitivity_ppm_per_c.value(),
            temps(&|p| p.scale_factor),
        ),
        (
            "bias_temp_sensitivity_dph_per_c",
            "bias temperature sensitivity (soaked points)",
            "(deg/h)/degC",
            r.bias_temp_sensitivity_dph_per_c.value(),
            temps(&|p| p.bias_dph),
        ),
    ];
    for (key, quantity, unit, sens, t) in series {
        let Some(sens) = sens else { continue };
        match sens.standard_error {
            Some(se) => {
                let comp = Component::new(
                    format!("least-squares slope over {} soaked points: standard error (GUM 4.2, H.3)", t.len()),
                    A,
                    se,
                    unit,
                    1.0,
                )
                .with_dof(t.len() as f64 - 2.0);
                let mut input = FigureInput::new(axis, key, quantity, sens.value, unit, vec![comp]);
                input.components.extend(temperature_slope_component(sens.value, &t));
                out.push(input);
            }
            None => out.push(FigureInput::refused(
                axis,
                key,
                "two temperatures: a line through two points has no standard error",
            )),
        }
    }
    let model_scatter = |m: &ModelOrReason| match m {
        ModelOrReason::Model(m) if m.residual_dof > 0 => {
            let n = m.residual_dof + m.coefficients.len();
            Some((
                m.rms_residual * (n as f64 / m.residual_dof as f64).sqrt(),
                m.residual_dof,
                m.coefficients.first().copied(),
            ))
        }
        _ => None,
    };
    let hyst: [HysteresisSeries<'_>; 2] = [
        (
            "bias_thermal_hysteresis_dph",
            "bias thermal hysteresis",
            "deg/h",
            r.bias_thermal_hysteresis_dph.value().map(|h| h.value),
            &r.bias_model,
            false,
        ),
        (
            "scale_factor_thermal_hysteresis_ppm",
            "scale-factor thermal hysteresis",
            "ppm",
            r.scale_factor_thermal_hysteresis_ppm.value().map(|h| h.value),
            &r.scale_factor_model,
            true,
        ),
    ];
    for (key, quantity, unit, value, model, relative) in hyst {
        let Some(value) = value else { continue };
        let Some((s, dof, k_ref)) = model_scatter(model) else {
            out.push(FigureInput::refused(axis, key, "no temperature model with residual degrees of freedom"));
            continue;
        };
        let (s, words) = match (relative, k_ref) {
            (true, Some(k)) if k != 0.0 => {
                (s / k.abs() * 1e6, "the soaked points' K scatter about the temperature model, relative")
            }
            (true, _) => continue,
            (false, _) => (s, "the soaked points' bias scatter about the temperature model"),
        };
        let comp = Component::new(
            format!("difference of two soaked points, each with u = s ({words}, ν = {dof}): √2 s"),
            A,
            s,
            unit,
            std::f64::consts::SQRT_2,
        )
        .with_dof(dof as f64);
        out.push(FigureInput::new(axis, key, quantity, value, unit, vec![comp]));
    }
    out
}

/// The chamber-temperature component of a slope over the soaked temperatures: sensitivity
/// |slope| / √S_TT per degC of independent error at each point; its standard uncertainty is the
/// plan's (`uncertainty.temperature_accuracy_c`), set by [`evaluate_uncertainty`].
fn temperature_slope_component(slope: f64, temps: &[f64]) -> Option<Component> {
    let n = temps.len() as f64;
    let mt = temps.iter().sum::<f64>() / n;
    let stt: f64 = temps.iter().map(|t| (t - mt).powi(2)).sum();
    (stt > 0.0).then(|| Component::new(TEMPERATURE_ACCURACY, B, 0.0, "degC", slope.abs() / stt.sqrt()))
}

/// The name of the chamber-temperature component, whose u comes from the plan.
const TEMPERATURE_ACCURACY: &str =
    "chamber temperature accuracy at each soaked point (rectangular half-width a, u = a/√3)";

/// The uncertainty inputs of a threshold or resolution test: the figure is the smallest tried step
/// that passes, so the truth lies between the largest failing step below it and the figure
/// (rectangular over that interval, u = (value − below)/√12, GUM 4.3.7), plus the table's rate
/// accuracy on the value.
pub fn step_inputs(r: &gyrolab_report::threshold::StepReport) -> Option<FigureInput> {
    use gyrolab::threshold::Support;
    let e = &r.estimate;
    let key = r.kind.figure();
    match (e.support, e.value_dps) {
        (Support::Value, Some(v)) => {
            let below = e.above_dps.unwrap_or(0.0);
            let comp = Component::new(
                format!(
                    "steps tried: the value lies in ({} deg/s, {} deg/s], rectangular, u = width/√12",
                    sig(below, 4),
                    sig(v, 4)
                ),
                B,
                (v - below) / 12f64.sqrt(),
                "deg/s",
                1.0,
            );
            let mut input = FigureInput::new(&r.axis, key, r.kind.word(), v, "deg/s", vec![comp]);
            input.rate_proportional = true;
            Some(input)
        }
        (Support::UpperBound, Some(_)) => Some(FigureInput::refused(
            &r.axis,
            key,
            "every step tried passes: an upper bound, which decides without an uncertainty",
        )),
        _ => None,
    }
}

/// The uncertainty inputs of a warm-up: the settling time is the start of a window, so it is
/// known to one window (rectangular, u = window/√12).
pub fn warmup_inputs(r: &gyrolab_report::power_ups::WarmupAxisReport) -> Option<FigureInput> {
    let res = &r.report.result;
    let t = res.settling_time_s?;
    let w = res.config.window_s;
    let comp = Component::new(
        format!(
            "the settling time is the start of a {} s window: rectangular over one window, u = window/√12",
            sig(w, 4)
        ),
        B,
        w / 12f64.sqrt(),
        "s",
        1.0,
    );
    Some(FigureInput::new(&r.axis, "warmup_settling_time_s", "warm-up settling time", t, "s", vec![comp]))
}

/// The uncertainty input of the g-sensitivity |G|: the least-squares standard error of the fit
/// (ν = its residual degrees of freedom); none without residual degrees of freedom.
pub fn g_sensitivity_input(axis: &str, value: f64, std_error: Option<f64>, dof: usize) -> FigureInput {
    let key = "g_sensitivity_dph_per_g";
    match std_error {
        Some(se) if dof > 0 => {
            let comp = Component::new(
                format!("least-squares fit of the records' biases on the gravity components: standard error of |G| (ν = {dof})"),
                A,
                se,
                "(deg/h)/g",
                1.0,
            )
            .with_dof(dof as f64);
            FigureInput::new(axis, key, "g-sensitivity |G|", value, "(deg/h)/g", vec![comp])
        }
        _ => FigureInput::refused(axis, key, "the fit has no residual degrees of freedom: no standard error"),
    }
}

/// The uncertainty inputs of the repeatabilities across power-ups (standard deviations of n
/// values, GUM E.4.3).
pub fn power_up_inputs(r: &gyrolab_report::power_ups::PowerUpsReport) -> Vec<FigureInput> {
    let n_sf = r.scale_factor.as_ref().and_then(|f| f.spread.as_ref().ok()).map(|s| s.n);
    let n_b = r.bias.as_ref().and_then(|f| f.spread.as_ref().ok()).map(|s| s.n);
    [
        (
            "scale_factor_repeatability_power_up_ppm",
            "scale-factor repeatability across power-ups",
            "the power-ups' scale factors (relative)",
            r.scale_factor_ppm().zip(n_sf),
            "ppm",
        ),
        (
            "bias_repeatability_power_up_dph",
            "bias repeatability across power-ups",
            "the power-ups' biases",
            r.bias_dph().zip(n_b),
            "deg/h",
        ),
    ]
    .into_iter()
    .filter_map(|(figure, quantity, what, vn, unit)| {
        let (v, n) = vn?;
        let c = std_component(what, v, n, unit, 1.0)?;
        Some(FigureInput::new(&r.axis, figure, quantity, v, unit, vec![c]))
    })
    .collect()
}

/// A noise term: budget key, label, unit, conversion from its base unit, its reading.
type NoiseTerm<'a> = (&'static str, &'static str, &'static str, fn(f64) -> f64, Option<&'a Reading>);

/// The budgets of one axis.
pub fn axis_uncertainty(
    name: &str,
    rate: Option<&EvaluatedAxis>,
    stat: Option<&StaticAxisReport>,
    plan: &UncertaintyPlan,
) -> AxisUncertainty {
    let mut out = AxisUncertainty { axis: name.to_string(), ..Default::default() };
    out.simulated = stat.and_then(|s| s.simulated.clone());
    let mut rate_part = None;
    match rate {
        None => {
            for key in ["scale_factor", "zero_offset"] {
                out.not_given.push((key, "no rate-table record for this axis in the plan".into()));
            }
        }
        Some(r) => {
            out.output_unit = r.record.output_unit.symbol().to_string();
            match rate_budgets(r, plan) {
                Ok((kb, fb, line)) => {
                    out.budgets.push(("scale_factor", kb.clone()));
                    out.budgets.push(("zero_offset", fb));
                    for input in rate_figure_inputs(r, plan) {
                        match &input.not_given {
                            Some(why) => out.not_given.push((input.figure, why.clone())),
                            None => out.figure_budgets.push((input.figure.to_string(), finish_input(&input, plan))),
                        }
                    }
                    rate_part = Some((r, kb, line));
                }
                Err(e) => {
                    for key in ["scale_factor", "zero_offset"] {
                        out.not_given.push((key, e.to_string()));
                    }
                }
            }
        }
    }
    let Some(stat) = stat else {
        return out;
    };
    if let Some(b) = stat.repeatability.as_ref().and_then(|r| r.bias_repeatability_dph) {
        if let Some(c) = std_component("the tests' biases B_0i", b, stat.tests.len(), "deg/h", 1.0) {
            out.figure_budgets
                .push(("bias_repeatability_dph".into(), budget("bias repeatability B_r", b, "deg/h", vec![c], plan)));
        }
    }
    let Some((r, kb, line)) = rate_part else {
        let why = "K and the null do not come from this plan's rate-table evaluation, so their uncertainties \
                   are not known";
        for key in ["bias", "bias_stability", "arw", "bias_instability", "rrw"] {
            out.not_given.push((key, why.into()));
        }
        return out;
    };
    let k = kb.value;
    let u_out = r.record.output_unit.symbol();
    // Bias B0 (mean over the Q tests).
    match bias_budget(stat, &kb, &line, r.evaluation.rest_reference_source, plan, u_out) {
        Ok(b) => out.budgets.push(("bias", b)),
        Err(why) => out.not_given.push(("bias", why)),
    }
    // Bias stability at the quoted smoothing time, the worst test (as the summary quotes it).
    let quoted = stat.tests.first().and_then(|t| t.result.bias_stability_quoted_s);
    let worst = quoted.and_then(|t| {
        stat.tests
            .iter()
            .filter_map(|x| x.result.stability_at(t))
            .filter(|b| b.dph.is_some())
            .max_by(|a, b| a.dph.unwrap_or(0.0).total_cmp(&b.dph.unwrap_or(0.0)))
    });
    match worst {
        Some(bs) => {
            let v = bs.dph.unwrap_or(f64::NAN);
            match std_of_sample_std(v, bs.windows as usize) {
                Ok(us) => {
                    let mut c = vec![Component::new(
                        format!(
                            "standard deviation of {} window means of {} s (normal theory, GUM E.4.3: s/√(2(n−1)))",
                            bs.windows,
                            sig(bs.smoothing_s, 4)
                        ),
                        A,
                        us,
                        "deg/h",
                        1.0,
                    )
                    .with_dof(bs.windows as f64 - 1.0)];
                    c.extend(k_components(&kb, -v / k));
                    out.budgets.push(("bias_stability", budget("bias stability", v, "deg/h", c, plan)));
                    out.bias_stability_smoothing_s = Some(bs.smoothing_s);
                }
                Err(e) => out.not_given.push(("bias_stability", e.to_string())),
            }
        }
        None => out.not_given.push(("bias_stability", "no quoted bias stability in deg/h".into())),
    }
    // Noise terms at the tau each was read.
    let analysis = stat.allan.as_ref();
    let lines = analysis.and_then(|a| a.slope_lines.as_ref());
    let terms: [NoiseTerm<'_>; 3] = [
        ("arw", "angle random walk N", "deg/√h", units::arw_deg_rt_s_to_deg_rt_h, lines.map(|l| &l.arw)),
        ("bias_instability", "bias instability B", "deg/h", units::bias_dps_to_dph, lines.map(|l| &l.bias_instability)),
        ("rrw", "rate random walk K", "deg/h/√h", units::rrw_dps_rt_s_to_dph_rt_h, lines.map(|l| &l.rrw)),
    ];
    for (key, label, unit, to_unit, reading) in terms {
        let Some(analysis) = analysis else {
            out.not_given.push((key, "no Allan analysis".into()));
            continue;
        };
        let Some(Reading::Value { value, site }) = reading else {
            out.not_given.push((key, "the term is not resolved (no value, so no uncertainty)".into()));
            continue;
        };
        let curve = &analysis.curve;
        if curve.confidence.is_none_or(|c| (c - gyrolab::allan::DEFAULT_CONFIDENCE).abs() > 1e-9) {
            out.not_given.push((key, "the Allan curve has no 68.3 % confidence intervals".into()));
            continue;
        }
        let nearest = curve
            .points
            .iter()
            .min_by(|a, b| (a.tau_s / site.tau_s).ln().abs().total_cmp(&(b.tau_s / site.tau_s).ln().abs()));
        let rel =
            nearest.and_then(|p| deviation_uncertainty(p.deviation, p.lower, p.upper).map(|u| (p, u / p.deviation)));
        let Some((p, rel)) = rel else {
            out.not_given.push((key, "no confidence interval at the tau the term was read".into()));
            continue;
        };
        let v = to_unit(*value);
        let mut c = vec![Component::new(
            format!(
                "Allan deviation at τ = {} s: 68.3 % interval [{}, {}] about {}, the wider side (relative {} %)",
                sig(p.tau_s, 4),
                sig(p.lower.unwrap_or(f64::NAN), 4),
                sig(p.upper.unwrap_or(f64::NAN), 4),
                sig(p.deviation, 4),
                sig(units::ratio_to_pct(rel), 3)
            ),
            A,
            v * rel,
            unit,
            1.0,
        )
        .with_dof(p.edf.unwrap_or(f64::INFINITY))];
        c.extend(k_components(&kb, -v / k));
        out.budgets.push((key, budget(label, v, unit, c, plan)));
    }
    out
}

/// The bias budget (deg/h) of the mean bias over the Q static tests of an axis: the bias shift
/// against the rate test's zero-rate output (its scatter and the data acquisition's accuracy on
/// both readings, correlated as the plan states), or the absolute bias against a nominal null
/// (exact by definition: only the static reading's accuracy).
fn bias_budget(
    stat: &StaticAxisReport,
    kb: &Budget,
    line: &LineUncertainty,
    null_source: RestReferenceSource,
    plan: &UncertaintyPlan,
    u_out: &str,
) -> Result<Budget, String> {
    let q = stat.tests.len();
    let mut biases = Vec::new();
    let mut raw = Vec::new();
    let mut u_means = Vec::new();
    let analysis = stat.allan.as_ref().ok_or("no Allan analysis of the static records")?;
    if analysis.rate_unit != "deg/s" {
        return Err(format!("the Allan deviation is in {}, not deg/s", analysis.rate_unit));
    }
    let curve = &analysis.curve;
    let allan_record_s = curve.n_rate as f64 * curve.tau0_s;
    let taus: Vec<f64> = curve.points.iter().map(|p| p.tau_s).collect();
    let devs: Vec<f64> = curve.points.iter().map(|p| units::bias_dps_to_dph(p.deviation)).collect();
    let mut used = Vec::new();
    for t in &stat.tests {
        let r = &t.result;
        let (Some(b), Some(kk), Some(null)) = (r.bias_dph, r.scale_factor_output_per_dps, r.null_output) else {
            return Err(format!("test {} has no bias in deg/h", t.file));
        };
        biases.push(b);
        raw.push(units::bias_dps_to_dph((r.mean_output - null) / kk));
        let record_s = r.valid_samples as f64 / r.sample_rate_hz;
        let (tau, dev) =
            longest_supported_point(&taus, &devs, record_s.min(allan_record_s)).map_err(|e| e.to_string())?;
        let edf = curve.points.iter().find(|p| p.tau_s == tau).and_then(|p| p.edf);
        u_means.push((mean_uncertainty_from_allan(dev, tau, record_s).map_err(|e| e.to_string())?, edf));
        used.push(tau);
    }
    let qf = q as f64;
    let value = biases.iter().sum::<f64>() / qf;
    let before_earth = raw.iter().sum::<f64>() / qf;
    let u_mean = u_means.iter().map(|(u, _)| u * u).sum::<f64>().sqrt() / qf;
    // ν of the mean of Q record means (Welch-Satterthwaite over the tests, each ν = the EDF of the
    // Allan point used).
    // A test whose Allan point has no EDF counts as infinite ν (adds nothing).
    let ws: f64 = u_means.iter().filter_map(|(u, edf)| edf.map(|nu| (u / qf).powi(4) / nu)).sum();
    let mean_dof = if ws > 0.0 { u_mean.powi(4) / ws } else { f64::INFINITY };
    let k = kb.value;
    let per_output = units::bias_dps_to_dph(1.0 / k);
    let taus_text = used.iter().map(|t| sig(*t, 4)).collect::<Vec<_>>().join(", ");
    let mut c = vec![Component::new(
        format!(
            "mean output of the {q} static record(s): OADEV σ(τ)·√(τ/T) at the longest τ ≤ T/4 (τ = {taus_text} s), \
             root-sum-square / Q"
        ),
        A,
        u_mean,
        "deg/h",
        1.0,
    )
    .with_dof(mean_dof)];
    let nominal = stat.reference.null_source.as_deref() == Some(gyrolab_report::static_report::NOMINAL_NULL);
    let mut correlations = Vec::new();
    if nominal {
        if let Some(uo) = plan.output_standard_uncertainty() {
            c.push(Component::new(
                format!(
                    "data-acquisition output accuracy on the static mean ({}); the nominal null is exact by \
                     definition",
                    distribution_words(plan.output_accuracy_distribution)
                ),
                B,
                uo,
                u_out,
                per_output,
            ));
        }
    } else {
        let (null_u, null_words) = match null_source {
            RestReferenceSource::FitZeroOffset => {
                (line.intercept, "null = fitted zero offset F0 (intercept standard error)")
            }
            RestReferenceSource::ZeroRatePoint | RestReferenceSource::RestRecords => {
                (line.residual_std, "null = rest reference F_r (a point mean: residual std of the line)")
            }
        };
        c.push(Component::new(null_words, A, null_u, u_out, -per_output).with_dof(line.dof as f64));
        if let Some(uo) = plan.output_standard_uncertainty() {
            let words = distribution_words(plan.output_accuracy_distribution);
            c.push(Component::new(
                format!("data-acquisition output accuracy on the static mean ({words})"),
                B,
                uo,
                u_out,
                per_output,
            ));
            c.push(Component::new(
                format!("data-acquisition output accuracy on the null reading ({words})"),
                B,
                uo,
                u_out,
                -per_output,
            ));
            let r = plan.output_accuracy_correlation;
            correlations.push(Correlation {
                first: c.len() - 2,
                second: c.len() - 1,
                coefficient: r,
                reason: format!(
                    "r = {}: the same data acquisition reads the static records and the rate test's zero-rate \
                     output, at nearly the same level, so its offset error is common to both and cancels in \
                     their difference to that degree (uncertainty.output_accuracy_correlation)",
                    sig(r, 3)
                ),
            });
        }
    }
    c.extend(k_components(kb, -before_earth / k));
    let quantity = if nominal { "bias B0 (absolute, against the nominal null)" } else { "bias B0 (shift)" };
    Ok(Budget::correlated(quantity, value, "deg/h", c, correlations, plan.coverage()))
}

/// The figure key of an expanded uncertainty, and its value, from a budget.
fn figure_of(key: &str, b: &Budget) -> Option<(&'static str, f64)> {
    match key {
        "scale_factor" => {
            b.relative_expanded().map(|r| ("scale_factor_expanded_uncertainty_ppm", units::ratio_to_ppm(r)))
        }
        "zero_offset" => Some(("zero_offset_expanded_uncertainty", b.expanded)),
        "bias" => Some(("bias_expanded_uncertainty_dph", b.expanded)),
        "bias_stability" => Some(("bias_stability_expanded_uncertainty_dph", b.expanded)),
        "arw" => Some(("arw_expanded_uncertainty_deg_rt_h", b.expanded)),
        "bias_instability" => Some(("bias_instability_expanded_uncertainty_dph", b.expanded)),
        "rrw" => Some(("rrw_expanded_uncertainty_deg_h_rt_h", b.expanded)),
        _ => None,
    }
}

/// The JSON key stem (with the unit suffix of u and U) of a budget key.
fn json_stem(key: &str) -> (&'static str, &'static str) {
    match key {
        "scale_factor" => ("scale_factor", ""),
        "zero_offset" => ("zero_offset", ""),
        "bias" => ("bias", "_dph"),
        "bias_stability" => ("bias_stability", "_dph"),
        "arw" => ("arw", "_deg_rt_h"),
        "bias_instability" => ("bias_instability", "_dph"),
        _ => ("rrw", "_deg_h_rt_h"),
    }
}

impl AxisUncertainty {
    /// Summary figures of this axis.
    pub fn figures(&self) -> AxisFigures {
        let mut f =
            AxisFigures { axis: self.axis.clone(), output_unit: self.output_unit.clone(), ..Default::default() };
        for (key, b) in &self.budgets {
            if let Some((name, v)) = figure_of(key, b) {
                f.set(name, v);
            }
        }
        for (key, b) in &self.figure_budgets {
            f.set_uncertainty(key.clone(), b.expanded);
        }
        if let (Some(t), Some(b)) = (self.bias_stability_smoothing_s, self.budget("bias_stability")) {
            f.set_uncertainty(format!("bias_stability_dph_{}s", gyrolab::static_test::smoothing_key(t)), b.expanded);
        }
        if self.simulated.is_some() {
            f.simulated = f.values.iter().map(|(k, _)| k.clone()).collect();
        }
        f
    }

    /// The `sections.uncertainty.<axis>` object of results.json.
    pub fn json(&self) -> Value {
        let mut m = Map::new();
        m.insert("simulated".into(), json!(self.simulated));
        m.insert("output_unit".into(), json!(self.output_unit));
        for (key, b) in &self.budgets {
            let (stem, unit) = json_stem(key);
            m.insert(format!("{stem}_u{unit}"), json!(b.combined));
            m.insert(format!("{stem}_expanded{unit}"), json!(b.expanded));
            if *key == "scale_factor" {
                if let (Some(r), Some(x)) = (b.relative_combined(), b.relative_expanded()) {
                    m.insert("scale_factor_u_ppm".into(), json!(units::ratio_to_ppm(r)));
                    m.insert("scale_factor_expanded_ppm".into(), json!(units::ratio_to_ppm(x)));
                }
            }
            if *key == "bias_stability" {
                m.insert("bias_stability_smoothing_s".into(), json!(self.bias_stability_smoothing_s));
            }
            m.insert("coverage_factor".into(), json!(b.coverage_factor));
        }
        let budgets: Map<String, Value> =
            self.budgets.iter().map(|(k, b)| (k.to_string(), serde_json::to_value(b).unwrap_or(Value::Null))).collect();
        m.insert("budgets".into(), Value::Object(budgets));
        let figures: Map<String, Value> = self
            .figure_budgets
            .iter()
            .map(|(k, b)| (k.clone(), serde_json::to_value(b).unwrap_or(Value::Null)))
            .collect();
        for (key, b) in &self.figure_budgets {
            m.insert(format!("{key}_expanded_uncertainty"), json!(b.expanded));
        }
        m.insert("figure_budgets".into(), Value::Object(figures));
        let not: Vec<Value> = self.not_given.iter().map(|(k, r)| json!({"budget": k, "reason": r})).collect();
        m.insert("not_given".into(), Value::Array(not));
        Value::Object(m)
    }

    /// One report table per budget.
    pub fn tables(&self) -> Vec<DataTable> {
        self.budgets
            .iter()
            .map(|(_, b)| b)
            .chain(self.figure_budgets.iter().map(|(_, b)| b))
            .map(|b| {
                let mut rows: Vec<Vec<String>> = b
                    .components
                    .iter()
                    .map(|c| {
                        vec![
                            c.name.clone(),
                            format!("{:?}", c.kind),
                            format!("{} {}", sig(c.standard_uncertainty, 4), c.unit),
                            c.dof.map_or("∞".into(), |d| sig(d, 3)),
                            sig(c.sensitivity, 4),
                            sig(c.contribution, 4),
                        ]
                    })
                    .collect();
                for r in &b.correlations {
                    rows.push(vec![
                        format!("correlation of lines {} and {}: {}", r.first + 1, r.second + 1, r.reason),
                        String::new(),
                        String::new(),
                        String::new(),
                        sig(r.coefficient, 3),
                        String::new(),
                    ]);
                }
                let how = if b.correlations.is_empty() {
                    "uncorrelated, GUM 5.1.2"
                } else {
                    "with the correlations, GUM 5.2.2"
                };
                rows.push(vec![
                    format!("combined standard uncertainty u_c ({how})"),
                    String::new(),
                    String::new(),
                    b.effective_dof.map_or("∞".into(), |d| sig(d, 3)),
                    String::new(),
                    sig(b.combined, 4),
                ]);
                rows.push(vec![
                    format!(
                        "expanded uncertainty U = k u_c, k = {}, coverage probability {} % at ν_eff (GUM 6.2, G.4)",
                        sig(b.coverage_factor, 3),
                        sig(b.coverage_probability * 100.0, 3)
                    ),
                    String::new(),
                    String::new(),
                    String::new(),
                    String::new(),
                    sig(b.expanded, 4),
                ]);
                let rel = b
                    .relative_expanded()
                    .map(|r| format!(" ({} ppm)", sig(units::ratio_to_ppm(r), 3)))
                    .filter(|_| b.quantity == "scale factor K")
                    .unwrap_or_default();
                DataTable {
                    caption: format!(
                        "Axis {}: {} = {} {}, U = {} {}{rel}",
                        self.axis,
                        b.quantity,
                        sig(b.value, 7),
                        b.unit,
                        sig(b.expanded, 3),
                        b.unit
                    ),
                    header: vec![
                        "component".into(),
                        "type".into(),
                        "standard uncertainty u(x_i)".into(),
                        "ν_i (ν_eff)".into(),
                        "sensitivity c_i".into(),
                        format!("contribution |c_i| u(x_i) ({})", b.unit),
                    ],
                    rows,
                }
            })
            .collect()
    }
}

/// The budget of a figure input, with the plan's type-B terms: the table's rate accuracy on a
/// rate figure, the chamber's temperature accuracy on a temperature slope (left out when the plan
/// states none).
fn finish_input(input: &FigureInput, plan: &UncertaintyPlan) -> Budget {
    let mut comps = Vec::new();
    for c in &input.components {
        if c.name == TEMPERATURE_ACCURACY {
            if let Some(a) = plan.temperature_accuracy_c {
                let u = gyrolab::uncertainty::Distribution::Rectangular.standard_uncertainty(a);
                comps.push(Component::new(c.name.clone(), B, u, "degC", c.sensitivity));
            }
        } else {
            comps.push(c.clone());
        }
    }
    if input.rate_proportional {
        if let Some(rel) = plan.rate_standard_uncertainty_rel() {
            comps.push(Component::new(
                format!("rate-table rate accuracy ({})", distribution_words(plan.rate_accuracy_distribution)),
                B,
                units::ratio_to_ppm(rel),
                "ppm",
                input.value * units::ppm_to_ratio(1.0),
            ));
        }
    }
    budget(&input.quantity, input.value, &input.unit, comps, plan)
}

/// K as stated for the device, not for one power-up at one temperature: its budget takes the
/// scatter of K across the plan's power-ups (type A, ν = n − 1) and the K temperature
/// coefficient times the test temperature's standard uncertainty (type B, from
/// `uncertainty.temperature_accuracy_c`), when the plan measured them for this axis.
fn widen_scale_factor_budget(a: &mut AxisUncertainty, inputs: &[FigureInput], plan: &UncertaintyPlan) {
    let Some(i) = a.budgets.iter().position(|(k, _)| *k == "scale_factor") else { return };
    let kb = &a.budgets[i].1;
    let per_ppm = kb.value.abs() * units::ppm_to_ratio(1.0);
    let find = |figure: &str| inputs.iter().find(|x| x.axis == a.axis && x.figure == figure && x.not_given.is_none());
    let mut comps = kb.components.clone();
    if let Some(p) = find("scale_factor_repeatability_power_up_ppm") {
        let n = p.components.first().and_then(|c| c.dof).map_or(f64::INFINITY, |d| d + 1.0);
        comps.push(
            Component::new(
                format!(
                    "scale-factor repeatability across {} power-ups (K is stated for the device; each power-up has \
                     its own)",
                    n as usize
                ),
                A,
                p.value,
                "ppm",
                per_ppm,
            )
            .with_dof(n - 1.0),
        );
    }
    if let (Some(t), Some(acc)) = (find("scale_factor_temp_sensitivity_ppm_per_c"), plan.temperature_accuracy_c) {
        comps.push(Component::new(
            format!(
                "test temperature (uncertainty.temperature_accuracy_c, rectangular) through K's temperature \
                 coefficient {} ppm/degC",
                sig(t.value, 3)
            ),
            B,
            gyrolab::uncertainty::Distribution::Rectangular.standard_uncertainty(acc),
            "degC",
            t.value * per_ppm,
        ));
    }
    if comps.len() > kb.components.len() {
        let b = Budget::correlated(kb.quantity.clone(), kb.value, kb.unit.clone(), comps, Vec::new(), plan.coverage());
        a.budgets[i].1 = b;
    }
}

/// The words of the report's coverage.
fn coverage_words(plan: &UncertaintyPlan) -> String {
    match plan.coverage() {
        Coverage::Factor(k) => format!(
            "expanded with one coverage factor k = {} for every budget of this report (GUM 6.2); each budget states \
             its effective degrees of freedom ν_eff (Welch-Satterthwaite, GUM G.4.1) and the coverage probability \
             k gives at ν_eff (Student's t)",
            sig(k, 3)
        ),
        Coverage::Probability(p) => format!(
            "expanded to a coverage probability of {} %: each budget's k_p = t_p(ν_eff), ν_eff by Welch-Satterthwaite \
             (GUM G.4.1) truncated to an integer, so k differs between budgets as the plan asks \
             (uncertainty.coverage_probability)",
            sig(p * 100.0, 4)
        ),
    }
}

/// Evaluates the budgets of every axis with a rate-table or static evaluation, and of every
/// figure input the other parts of the plan give.
pub fn evaluate_uncertainty(
    plan: &UncertaintyPlan,
    rate_axes: &[EvaluatedAxis],
    static_reports: &[StaticAxisReport],
    inputs: &[FigureInput],
) -> UncertaintyParts {
    let mut names: Vec<&str> = rate_axes.iter().map(|a| a.name.as_str()).collect();
    for n in static_reports.iter().map(|s| s.axis.as_str()).chain(inputs.iter().map(|i| i.axis.as_str())) {
        if !names.contains(&n) {
            names.push(n);
        }
    }
    let mut axes: Vec<AxisUncertainty> = names
        .iter()
        .map(|n| {
            axis_uncertainty(
                n,
                rate_axes.iter().find(|a| a.name == *n),
                static_reports.iter().find(|s| s.axis == *n),
                plan,
            )
        })
        .collect();
    for input in inputs {
        let Some(a) = axes.iter_mut().find(|a| a.axis == input.axis) else { continue };
        match &input.not_given {
            Some(why) => a.not_given.push((input.figure, why.clone())),
            None => a.figure_budgets.push((input.figure.to_string(), finish_input(input, plan))),
        }
    }
    for a in &mut axes {
        widen_scale_factor_budget(a, inputs, plan);
    }
    let correlated: Vec<String> = axes
        .iter()
        .flat_map(|a| {
            a.budgets.iter().flat_map(move |(_, b)| {
                b.correlations.iter().map(move |c| format!("axis {}, {}: {}", a.axis, b.quantity, c.reason))
            })
        })
        .collect();
    let mut paragraphs = vec![format!(
        "Standard uncertainties evaluated per JCGM 100:2008 (GUM) = JJF 1059.1-2012: type A from the data (GUM 4.2), \
         type B from the plan's [uncertainty] accuracies (GUM 4.3: rate accuracy {}, output accuracy {}, chamber \
         temperature accuracy {}), combined by the law of propagation (GUM 5.1.2; correlated inputs by GUM 5.2.2) and \
         {}. Contributions are |c_i| u(x_i) in the figure's unit; ν = ∞ for a type-B accuracy. Values with a U are \
         printed rounded to the decimal of U's second significant digit, \"value ± U\". Budgets and their limits: docs/METHODS.md, \
         \"Measurement uncertainty\".",
        plan.rate_accuracy_ppm.map_or("not stated".to_string(), |a| format!("{} ppm", sig(a, 4))),
        plan.output_accuracy.map_or("not stated".to_string(), |a| format!("{} (axis output unit)", sig(a, 4))),
        plan.temperature_accuracy_c.map_or("not stated".to_string(), |a| format!("{} degC", sig(a, 4))),
        coverage_words(plan),
    )];
    for c in correlated {
        paragraphs.push(format!("Correlation: {c}."));
    }
    for a in &axes {
        for (k, why) in &a.not_given {
            paragraphs.push(format!("Axis {}: no {} budget: {why}.", a.axis, k.replace('_', " ")));
        }
        if let Some(s) = &a.simulated {
            paragraphs.push(format!("Axis {}: {s}", a.axis));
        }
    }
    let section = ReportSection {
        title: "Measurement uncertainty".into(),
        simulated: axes.iter().any(|a| a.simulated.is_some()),
        paragraphs,
        tables: axes.iter().flat_map(AxisUncertainty::tables).collect(),
        ..Default::default()
    };
    let json: Map<String, Value> = axes.iter().map(|a| (a.axis.clone(), a.json())).collect();
    UncertaintyParts {
        sections: vec![section],
        figures: axes.iter().map(AxisUncertainty::figures).collect(),
        json: Value::Object(json),
    }
}
