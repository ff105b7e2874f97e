//! The measurement-uncertainty part of a test plan (`[uncertainty]`): budgets of the scale
//! factor K, the zero offset F0, the bias B0, the bias stability and the Allan noise terms N, B
//! and K per axis (JCGM 100:2008 = JJF 1059.1-2012; formulas in [`gyrolab::uncertainty`] and
//! docs/METHODS.md, "Measurement uncertainty"): the report section, summary figures and the
//! results.json section `uncertainty`.

use crate::rate::EvaluatedAxis;
use gyrolab::noise::Reading;
use gyrolab::rate_test::RestReferenceSource;
use gyrolab::uncertainty::{
    deviation_uncertainty, line_standard_errors, longest_supported_point, mean_uncertainty_from_allan,
    std_of_sample_std, Budget, Component, EvaluationType, LineUncertainty,
};
use gyrolab::units;
use gyrolab_io::test_plan::uncertainty::UncertaintyPlan;
use gyrolab_report::figures::AxisFigures;
use gyrolab_report::format::sig;
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
    let mut kc = vec![Component::new(
        "least-squares slope: scatter of the point means about the line (GUM 4.2, H.3)",
        A,
        line.slope,
        format!("{u}/(deg/s)"),
        1.0,
    )];
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
    )];
    if let Some(uo) = plan.output_standard_uncertainty() {
        fc.push(Component::new(
            format!("data-acquisition output accuracy ({})", distribution_words(plan.output_accuracy_distribution)),
            B,
            uo,
            u,
            1.0,
        ));
    }
    let kb = Budget::new("scale factor K", k, format!("{u}/(deg/s)"), kc, plan.coverage_factor);
    let fb = Budget::new("zero offset F0", e.zero_offset(), u, fc, plan.coverage_factor);
    Ok((kb, fb, line))
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
            out.push(Component::new(format!("scale factor K, {what}"), kind, u, kb.unit.clone(), c));
        }
    }
    out
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
    let k_cov = plan.coverage_factor;
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
                    )];
                    c.extend(k_components(&kb, -v / k));
                    out.budgets.push(("bias_stability", Budget::new("bias stability", v, "deg/h", c, k_cov)));
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
        )];
        c.extend(k_components(&kb, -v / k));
        out.budgets.push((key, Budget::new(label, v, unit, c, k_cov)));
    }
    out
}

/// The bias budget (deg/h) of the mean bias over the Q static tests of an axis.
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
        u_means.push(mean_uncertainty_from_allan(dev, tau, record_s).map_err(|e| e.to_string())?);
        used.push(tau);
    }
    let qf = q as f64;
    let value = biases.iter().sum::<f64>() / qf;
    let before_earth = raw.iter().sum::<f64>() / qf;
    let u_mean = u_means.iter().map(|u| u * u).sum::<f64>().sqrt() / qf;
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
    )];
    let (null_u, null_words) = match null_source {
        RestReferenceSource::FitZeroOffset => {
            (line.intercept, "null = fitted zero offset F0 (intercept standard error)")
        }
        RestReferenceSource::ZeroRatePoint | RestReferenceSource::RestRecords => {
            (line.residual_std, "null = rest reference F_r (a point mean: residual std of the line)")
        }
    };
    c.push(Component::new(null_words, A, null_u, u_out, -per_output));
    if let Some(uo) = plan.output_standard_uncertainty() {
        c.push(Component::new(
            format!(
                "data-acquisition output accuracy on the static mean ({})",
                distribution_words(plan.output_accuracy_distribution)
            ),
            B,
            uo,
            u_out,
            per_output,
        ));
    }
    c.extend(k_components(kb, -before_earth / k));
    Ok(Budget::new("bias B0", value, "deg/h", c, plan.coverage_factor))
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
        let not: Vec<Value> = self.not_given.iter().map(|(k, r)| json!({"budget": k, "reason": r})).collect();
        m.insert("not_given".into(), Value::Array(not));
        Value::Object(m)
    }

    /// One report table per budget.
    pub fn tables(&self) -> Vec<DataTable> {
        self.budgets
            .iter()
            .map(|(_, b)| {
                let mut rows: Vec<Vec<String>> = b
                    .components
                    .iter()
                    .map(|c| {
                        vec![
                            c.name.clone(),
                            format!("{:?}", c.kind),
                            format!("{} {}", sig(c.standard_uncertainty, 4), c.unit),
                            sig(c.sensitivity, 4),
                            sig(c.contribution, 4),
                        ]
                    })
                    .collect();
                rows.push(vec![
                    "combined standard uncertainty u_c (uncorrelated, GUM 5.1.2)".into(),
                    String::new(),
                    String::new(),
                    String::new(),
                    sig(b.combined, 4),
                ]);
                rows.push(vec![
                    format!("expanded uncertainty U = k u_c, k = {} (GUM 6.2)", sig(b.coverage_factor, 3)),
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
                        "sensitivity c_i".into(),
                        format!("contribution |c_i| u(x_i) ({})", b.unit),
                    ],
                    rows,
                }
            })
            .collect()
    }
}

/// Evaluates the budgets of every axis with a rate-table or static evaluation.
pub fn evaluate_uncertainty(
    plan: &UncertaintyPlan,
    rate_axes: &[EvaluatedAxis],
    static_reports: &[StaticAxisReport],
) -> UncertaintyParts {
    let mut names: Vec<&str> = rate_axes.iter().map(|a| a.name.as_str()).collect();
    for s in static_reports {
        if !names.contains(&s.axis.as_str()) {
            names.push(&s.axis);
        }
    }
    let axes: Vec<AxisUncertainty> = names
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
    let mut paragraphs = vec![format!(
        "Standard uncertainties evaluated per JCGM 100:2008 (GUM) = JJF 1059.1-2012: type A from the data (GUM 4.2), \
         type B from the plan's [uncertainty] accuracies (GUM 4.3: rate accuracy {}, output accuracy {}), combined by \
         the law of propagation for uncorrelated inputs (GUM 5.1.2) and expanded with k = {} (GUM 6.2). Contributions \
         are |c_i| u(x_i) in the figure's unit. Budgets and their limits: docs/METHODS.md, \"Measurement uncertainty\".",
        plan.rate_accuracy_ppm.map_or("not stated".to_string(), |a| format!("{} ppm", sig(a, 4))),
        plan.output_accuracy.map_or("not stated".to_string(), |a| format!("{} (axis output unit)", sig(a, 4))),
        sig(plan.coverage_factor, 3)
    )];
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
