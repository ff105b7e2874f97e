//! The static (bias) and Allan-variance sections of the report, their plots (bias time series of
//! window means, bias against temperature, Allan deviation on log-log axes with confidence bars,
//! noise asymptotes and N, B, K read-offs), their summary figures, JSON and CSV tables.

use crate::allan::{allan_csv, allan_json};
use crate::html::{DataTable, FigureRow, PlotBlock, ReportSection};
use crate::plot::{
    scatter_fit_plot, Annotation, Axis, Figure, LegendCorner, Orientation, Panel, PlotError, RefLine, Series,
    SeriesStyle,
};
use crate::table::csv_field;
use gyrolab::figures::AxisFigures;
use gyrolab::format::{short, sig, sig_opt};
use gyrolab::limits::Limit;
use gyrolab::static_test::{reported_smoothing_times, smoothing_key, BiasRepeatability};
use gyrolab::window_means::WindowMean;
use gyrolab_eval::outcome::allan::ChannelAnalysis;
use gyrolab_eval::outcome::static_test::TestReport;
use serde::Serialize;

/// The ADEV flat level of bias instability: sigma_min = 0.6643 B (IEEE 952; the one constant).
const FLAT_FACTOR: f64 = gyrolab::noise::BIAS_INSTABILITY_FACTOR;

/// Which output-to-rate reference the static figures used.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReferenceJson {
    /// `rate_table` (this plan's rate-table evaluation), `calibration_file` or `none`.
    pub source: String,
    /// Scale factor K, output units per deg/s (null for `none`).
    pub scale_factor: Option<f64>,
    /// The static null F_null used, output units (null for `none`).
    pub null_output: Option<f64>,
    /// Which zero-rate output the null is: `rest_records`, `zero_rate_point`, `rest_reference`
    /// (a calibration file's F_r), `line_intercept` (F0); null for `none`.
    pub null_source: Option<String>,
    /// Whether the null already contains the earth-rate component (measured at rest on the same
    /// mounting): a latitude then does not subtract it again.
    pub null_contains_earth_rate: bool,
    /// Output unit of K and F0.
    pub output_unit: Option<String>,
    /// The reference in words (as in the report).
    pub text: String,
}

/// The window means of one static test.
#[derive(Debug, Clone, PartialEq)]
pub struct TestWindows {
    /// The test's file as shown.
    pub file: String,
    /// Window means in time order.
    pub windows: Vec<WindowMean>,
}

/// The `null_source` of a reference whose null is the plan's nominal null (absolute bias).
pub const NOMINAL_NULL: &str = "nominal_null";

/// The summary label of B0 when it is the absolute bias against the nominal null.
pub const ABSOLUTE_BIAS_LABEL: &str = "bias B_0 (absolute, against the nominal null)";

/// Everything evaluated for one axis's static records.
#[derive(Debug, Clone)]
pub struct StaticAxisReport {
    /// Axis name.
    pub axis: String,
    /// The output-to-rate reference used.
    pub reference: ReferenceJson,
    /// One entry per static test (file).
    pub tests: Vec<TestReport>,
    /// Bias repeatability across the tests (two or more tests).
    pub repeatability: Option<BiasRepeatability>,
    /// Window length of the bias time series, s (the quoted smoothing time).
    pub window_s: f64,
    /// Window means per test.
    pub windows: Vec<TestWindows>,
    /// The Allan analysis of one record.
    pub allan: Option<ChannelAnalysis>,
    /// Simulated data: what was simulated (preset, parameters, seeds); `None` for measured data.
    pub simulated: Option<String>,
    /// Further notes shown in the section.
    pub notes: Vec<String>,
}

fn rows<T: Copy>(v: impl Iterator<Item = Option<T>>) -> Vec<T> {
    v.flatten().collect()
}

/// A window mean as a bias, deg/h (output units when the test has no scale factor).
fn window_bias(t: &TestReport, w: &WindowMean) -> f64 {
    let r = &t.result;
    match (r.scale_factor_output_per_dps, r.null_output) {
        (Some(k), Some(null)) => {
            let earth = if r.earth_rate_subtracted { r.earth_rate_component_dph.unwrap_or(0.0) } else { 0.0 };
            gyrolab::units::dps_to_dph((w.mean_output - null) / k) - earth
        }
        _ => w.mean_output,
    }
}

impl StaticAxisReport {
    /// Whether the figures are in deg/h (a scale factor was available).
    pub fn calibrated(&self) -> bool {
        self.tests.iter().all(|t| t.result.bias_dph.is_some())
    }

    /// Unit of the bias plots and window CSV: deg/h, or the output unit.
    pub fn bias_unit(&self) -> String {
        if self.calibrated() {
            "deg/h".into()
        } else {
            self.tests.first().map_or_else(|| "output".into(), |t| t.result.output_unit.symbol().to_string())
        }
    }

    /// The smoothing times (s) reported by any test, in increasing order (one per
    /// [`smoothing_key`], which names them in figures and tables: "10", "0.01").
    pub fn smoothing_times(&self) -> Vec<f64> {
        reported_smoothing_times(self.tests.iter().map(|t| &t.result))
    }

    /// The axis's summary figures: bias (mean over the tests), bias stability and drift (the
    /// worst test), bias repeatability, temperature sensitivity, and the Allan noise terms.
    pub fn figures(&self) -> AxisFigures {
        let unit = self.tests.first().map_or_else(String::new, |t| t.result.output_unit.symbol().to_string());
        let mut f = AxisFigures { axis: self.axis.clone(), output_unit: unit, ..Default::default() };
        let biases: Option<Vec<f64>> = self.tests.iter().map(|t| t.result.bias_dph).collect();
        if let Some(m) = biases.as_deref().and_then(gyrolab::fit::mean) {
            f.set("bias_dph", m);
        }
        if self.reference.null_source.as_deref() == Some(NOMINAL_NULL) {
            f.set_label("bias_dph", ABSOLUTE_BIAS_LABEL);
        }
        for t in self.smoothing_times() {
            let worst =
                self.tests.iter().filter_map(|r| r.result.stability_at(t).and_then(|b| b.dph)).fold(f64::NAN, f64::max);
            f.set(format!("bias_stability_dph_{}s", smoothing_key(t)), worst);
        }
        if let Some(b) = self.repeatability.as_ref().and_then(|r| r.bias_repeatability_dph) {
            f.set("bias_repeatability_dph", b);
        }
        let largest = |v: Vec<f64>| v.into_iter().fold(f64::NAN, |a: f64, b| if a.abs() >= b.abs() { a } else { b });
        f.set("drift_dph_per_h", largest(rows(self.tests.iter().map(|t| t.result.drift_dph_per_h))));
        f.set(
            "temp_sensitivity_dph_per_c",
            largest(rows(
                self.tests.iter().map(|t| t.result.temperature.as_ref().and_then(|x| x.temp_sensitivity_dph_per_c)),
            )),
        );
        if let Some(s) = self.allan.as_ref().and_then(|a| a.slope_lines.as_ref()) {
            let c = &s.coefficients;
            for (k, v) in [
                ("arw_deg_rt_h", c.arw_deg_rt_h),
                ("bias_instability_dph", c.bias_instability_dph),
                ("rrw_deg_h_rt_h", c.rrw_deg_h_rt_h),
                ("quantization_deg", c.quantization_deg),
                ("rate_ramp_dph_per_h", c.rate_ramp_dph_per_h),
                ("allan_minimum_dph", s.allan_minimum.value().map(gyrolab::units::bias_dps_to_dph)),
                ("allan_minimum_tau_s", s.allan_minimum.site().map(|r| r.tau_s)),
            ] {
                if let Some(v) = v {
                    f.set(k, v);
                }
            }
            // Terms the curve does not resolve but bounds from above: "at most" figures, which a
            // limit can still decide (an upper bound under an upper limit passes).
            let b = gyrolab::noise::NoiseCoefficients::from_base_units(
                s.quantization.bound(),
                s.arw.bound(),
                s.bias_instability.bound(),
                s.rrw.bound(),
                s.rate_ramp.bound(),
            );
            for (k, v) in [
                ("arw_deg_rt_h", b.arw_deg_rt_h),
                ("bias_instability_dph", b.bias_instability_dph),
                ("rrw_deg_h_rt_h", b.rrw_deg_h_rt_h),
                ("quantization_deg", b.quantization_deg),
                ("rate_ramp_dph_per_h", b.rate_ramp_dph_per_h),
                ("allan_minimum_dph", s.allan_minimum.bound().map(gyrolab::units::bias_dps_to_dph)),
            ] {
                if let (Some(v), None) = (v, f.get(k)) {
                    f.set_bound(k, v, gyrolab::conformity::Support::UpperBound);
                }
            }
        }
        if self.simulated.is_some() {
            f.simulated = f.values.iter().map(|(k, _)| k.clone()).collect();
        }
        f
    }

    /// The `sections.static.<axis>` object of results.json.
    pub fn static_json(&self) -> serde_json::Value {
        let figs = self.figures();
        let figures: serde_json::Map<String, serde_json::Value> = figs
            .values
            .iter()
            .filter(|(k, _)| {
                gyrolab::figures::known_figure(k).is_some_and(|d| d.group != gyrolab::figures::FigureGroup::Allan)
            })
            .map(|(k, v)| (k.clone(), serde_json::json!(v)))
            .collect();
        serde_json::json!({
            "simulated": self.simulated,
            "reference": self.reference,
            "smoothing_window_s": self.window_s,
            "figures": figures,
            "tests": self.tests,
            "repeatability": self.repeatability,
            "notes": self.notes,
        })
    }

    /// The `sections.allan.<axis>` object of results.json (`gyrolab allan --json` keys plus `simulated`).
    pub fn allan_json(&self) -> Option<serde_json::Value> {
        let a = self.allan.as_ref()?;
        let mut v = serde_json::to_value(allan_json(a)).ok()?;
        if let Some(o) = v.as_object_mut() {
            o.insert("simulated".into(), serde_json::json!(self.simulated));
        }
        Some(v)
    }
}

fn simulated_comment(r: &StaticAxisReport) -> String {
    r.simulated.as_ref().map_or_else(String::new, |s| format!("{}: {s}\n", gyrolab_io::provenance::SIMULATED_DATA_MARK))
}

/// `bias_tests.csv`: one row per static test of every axis.
pub fn bias_tests_csv(axes: &[StaticAxisReport]) -> String {
    let times = reported_smoothing_times(axes.iter().flat_map(|a| a.tests.iter().map(|t| &t.result)));
    let mut s = String::from("# gyrolab: static (bias) tests; mean_output in output_unit, figures in deg/h\n");
    for a in axes.iter().filter(|a| a.simulated.is_some()) {
        s.push_str(&format!("# axis {}: {}", a.axis, simulated_comment(a).trim_start_matches("# ")));
    }
    s.push_str("axis,test,file,channel,samples,duration_s,sample_rate_hz,mean_output,std_output,output_unit,bias_dph");
    for &t in &times {
        s.push_str(&format!(",bias_stability_dph_{}s", smoothing_key(t)));
    }
    s.push_str(",drift_dph_per_h,temp_sensitivity_dph_per_c,simulated\n");
    let opt = |v: Option<f64>| v.map_or_else(String::new, |x| x.to_string());
    for a in axes {
        for (i, t) in a.tests.iter().enumerate() {
            let r = &t.result;
            s.push_str(&format!(
                "{},{},{},{},{},{},{},{},{},{},{}",
                csv_field(&a.axis),
                i + 1,
                csv_field(&t.file),
                csv_field(&r.channel),
                r.valid_samples,
                r.duration_s,
                r.sample_rate_hz,
                r.mean_output,
                r.std_output,
                r.output_unit.symbol(),
                opt(r.bias_dph)
            ));
            for &t in &times {
                s.push_str(&format!(",{}", opt(r.stability_at(t).and_then(|b| b.dph))));
            }
            s.push_str(&format!(
                ",{},{},{}\n",
                opt(r.drift_dph_per_h),
                opt(r.temperature.as_ref().and_then(|x| x.temp_sensitivity_dph_per_c)),
                a.simulated.is_some()
            ));
        }
    }
    s
}

/// `bias_windows_<axis>.csv`: the window means of every test of one axis.
pub fn bias_windows_csv(a: &StaticAxisReport) -> String {
    let u = a.bias_unit();
    let ou = a.tests.first().map_or("output", |t| t.result.output_unit.symbol());
    let mut s = format!(
        "# gyrolab: axis {} window means over {} s; mean_output in {ou}, bias in {u}\n{}",
        a.axis,
        short(a.window_s, 6),
        simulated_comment(a)
    );
    s.push_str("test,file,start_s,end_s,mean_output,bias,temp_c\n");
    for (i, (t, w)) in a.tests.iter().zip(&a.windows).enumerate() {
        for m in &w.windows {
            s.push_str(&format!(
                "{},{},{},{},{},{},{}\n",
                i + 1,
                csv_field(&w.file),
                m.start_s,
                m.end_s,
                m.mean_output,
                window_bias(t, m),
                m.mean_temp_c.map_or_else(String::new, |x| x.to_string())
            ));
        }
    }
    s
}

/// `allan_<axis>.csv`: the Allan curve of one axis (columns as `gyrolab allan --csv`).
pub fn allan_axis_csv(a: &StaticAxisReport) -> Option<String> {
    let c = a.allan.as_ref()?;
    Some(format!(
        "# gyrolab: axis {} OADEV in {} with {} bounds\n{}{}",
        a.axis,
        c.rate_unit,
        c.curve.confidence.map_or("no".into(), |x| format!("{} %", short(100.0 * x, 4))),
        simulated_comment(a),
        allan_csv(std::slice::from_ref(c))
    ))
}

/// Bias time series: the window means of each test as steps (each step one window, so the
/// window boundaries are the step edges), with the mean bias as a reference line.
pub fn bias_time_plot(a: &StaticAxisReport) -> Result<String, PlotError> {
    let u = a.bias_unit();
    let w = short(a.window_s, 4);
    let mut p =
        Panel::new(Axis::linear("time from record start (s)"), Axis::linear(format!("bias, {w}-s window means ({u})")));
    for (i, (t, tw)) in a.tests.iter().zip(&a.windows).enumerate().take(6) {
        let mut pts = Vec::with_capacity(2 * tw.windows.len());
        for m in &tw.windows {
            let b = window_bias(t, m);
            pts.push((m.start_s, b));
            pts.push((m.end_s, b));
        }
        let name = std::path::Path::new(&tw.file)
            .file_name()
            .map_or_else(|| tw.file.clone(), |n| n.to_string_lossy().into_owned());
        p.series.push(Series::new(format!("test {}: {name}", i + 1), pts, SeriesStyle::Line, i));
    }
    let longest = a.windows.iter().map(|t| t.windows.len()).max().unwrap_or(0);
    if longest <= 40 {
        if let Some(t) = a.windows.iter().max_by_key(|t| t.windows.len()) {
            for m in &t.windows {
                p.ref_lines.push(RefLine { orientation: Orientation::Vertical, at: m.start_s, label: String::new() });
            }
        }
    }
    let figs = a.figures();
    let mean = if a.calibrated() {
        figs.get("bias_dph")
    } else {
        gyrolab::fit::mean(&a.tests.iter().map(|t| t.result.mean_output).collect::<Vec<_>>())
    };
    if let Some(m) = mean {
        p.ref_lines.push(RefLine {
            orientation: Orientation::Horizontal,
            at: m,
            label: format!("mean bias {} {u}", sig(m, 4)),
        });
    }
    p.legend = LegendCorner::UpperRight;
    Figure::single(format!("Axis {}: bias time series ({w}-s window means)", a.axis), p).to_svg()
}

/// Bias against temperature: the window means of every test with their least-squares line;
/// `None` without temperature data.
pub fn bias_temperature_plot(a: &StaticAxisReport) -> Option<Result<String, PlotError>> {
    let u = a.bias_unit();
    let mut pts = Vec::new();
    for (t, tw) in a.tests.iter().zip(&a.windows) {
        for m in &tw.windows {
            if let Some(temp) = m.mean_temp_c {
                pts.push((temp, window_bias(t, m)));
            }
        }
    }
    if pts.len() < 2 {
        return None;
    }
    let (x, y): (Vec<f64>, Vec<f64>) = pts.iter().copied().unzip();
    let fit = gyrolab::fit::fit_line(&x, &y)
        .ok()
        .map(|l| (l.intercept, l.slope, format!("pooled line (all tests): {} ({u})/degC", sig(l.slope, 4))));
    Some(scatter_fit_plot(
        &format!("Axis {}: bias against temperature ({}-s window means)", a.axis, short(a.window_s, 4)),
        "temperature (degC)",
        &format!("bias ({u})"),
        pts,
        fit,
    ))
}

/// Allan deviation on log-log axes: the measured OADEV with its confidence bars, the asymptotes
/// of the read-off terms (N: σ = N/√τ; B: 0.6643 B flat; K: K √(τ/3)), the five-term model fit
/// and the N, B, K read-off points. Values in deg/h when calibrated.
pub fn allan_plot(a: &StaticAxisReport) -> Option<Result<String, PlotError>> {
    let c = a.allan.as_ref()?;
    let calibrated = c.slope_lines.is_some() || c.rate_unit == "deg/s";
    let (f, unit) = if calibrated { (3600.0, "deg/h".to_string()) } else { (1.0, c.rate_unit.clone()) };
    let pts = &c.curve.points;
    let conf = c.curve.confidence.map_or_else(String::new, |x| format!(", {} % bounds", short(100.0 * x, 4)));
    let measured = Series::new(
        format!("OADEV{conf}"),
        pts.iter().map(|p| (p.tau_s, p.deviation * f)).collect(),
        SeriesStyle::LineMarkers,
        0,
    )
    .with_error_bars(
        pts.iter().map(|p| (p.lower.map_or(f64::NAN, |x| x * f), p.upper.map_or(f64::NAN, |x| x * f))).collect(),
    );
    let mut p = Panel::new(Axis::log("averaging time τ (s)"), Axis::log(format!("Allan deviation σ(τ) ({unit})")));
    p.series.push(measured);
    let (t_lo, t_hi) = (pts.first().map_or(1.0, |p| p.tau_s), pts.last().map_or(1.0, |p| p.tau_s));
    let grid = |lo: f64, hi: f64| -> Vec<f64> {
        let n = 24;
        (0..=n).map(|i| lo * (hi / lo).powf(f64::from(i) / f64::from(n))).collect()
    };
    if let Some(s) = &c.slope_lines {
        let k = &s.coefficients;
        let t_min = s.bias_instability.site().map_or((t_lo * t_hi).sqrt(), |r| r.tau_s);
        if let Some(n) = k.arw_deg_rt_s {
            let line: Vec<(f64, f64)> =
                grid(t_lo.min(1.0), (t_min * 2.0).max(1.0)).into_iter().map(|t| (t, n / t.sqrt() * f)).collect();
            p.series.push(Series::new("N asymptote: σ = N/√τ", line, SeriesStyle::Dashed, 1));
            p.annotations.push(Annotation {
                x: 1.0,
                y: n * f,
                text: format!("N = {} deg/√h (τ = 1 s)", sig(k.arw_deg_rt_h.unwrap_or(f64::NAN), 3)),
            });
        }
        if let Some(b) = k.bias_instability_dps {
            let y = FLAT_FACTOR * b * f;
            p.series.push(Series::new("B level: σ = 0.6643 B", vec![(t_lo, y), (t_hi, y)], SeriesStyle::Dashed, 2));
            p.annotations.push(Annotation {
                x: t_min,
                y,
                text: format!("B = {} deg/h", sig(k.bias_instability_dph.unwrap_or(f64::NAN), 3)),
            });
        }
        if let Some(kk) = k.rrw_deg_s_rt_s {
            let line: Vec<(f64, f64)> = grid((t_min / 2.0).min(3.0), t_hi.max(3.0))
                .into_iter()
                .map(|t| (t, kk * (t / 3.0).sqrt() * f))
                .collect();
            p.series.push(Series::new("K asymptote: σ = K √(τ/3)", line, SeriesStyle::Dashed, 3));
            p.annotations.push(Annotation {
                x: 3.0,
                y: kk * f,
                text: format!("K = {} deg/h/√h (τ = 3 s)", sig(k.rrw_deg_h_rt_h.unwrap_or(f64::NAN), 3)),
            });
        }
    }
    if let Some(m) = &c.model_fit {
        let line: Vec<(f64, f64)> =
            grid(t_lo, t_hi).into_iter().map(|t| (t, m.coefficients.model_deviation(t) * f)).collect();
        p.series.push(Series::new("five-term model fit", line, SeriesStyle::Line, 6));
    }
    p.legend = LegendCorner::UpperRight;
    let mut fig = Figure::single(format!("Axis {}: Allan deviation (OADEV)", a.axis), p);
    fig.height = 520;
    Some(fig.to_svg())
}

/// The figure rows of a section: each key's value with its unit, limit and verdict (keys without a
/// value are left out).
pub fn figure_rows(figs: &AxisFigures, limits: &[Limit], keys: &[(String, String)]) -> Vec<FigureRow> {
    keys.iter().filter_map(|(key, label)| FigureRow::checked(figs, limits, key, label)).collect()
}

fn simulated_paragraph(a: &StaticAxisReport) -> Vec<String> {
    a.simulated.iter().map(|s| format!("SIMULATED: {s}")).collect()
}

/// The static (bias) section of one axis: figures with limits, the bias time series and the
/// bias-temperature plot, and the per-test table.
pub fn static_section(a: &StaticAxisReport, limits: &[Limit]) -> Result<ReportSection, PlotError> {
    let figs = a.figures();
    let mut keys: Vec<(String, String)> = vec![("bias_dph".into(), "bias B0 (mean over the tests)".into())];
    for k in a.smoothing_times().into_iter().map(smoothing_key) {
        keys.push((format!("bias_stability_dph_{k}s"), format!("bias stability, T = {k} s (worst test)")));
    }
    keys.push(("bias_repeatability_dph".into(), format!("bias repeatability over {} tests", a.tests.len())));
    keys.push(("drift_dph_per_h".into(), "drift (largest of the tests)".into()));
    keys.push(("temp_sensitivity_dph_per_c".into(), "bias temperature sensitivity (largest of the tests)".into()));
    let figures = figure_rows(&figs, limits, &keys);
    let ou = a.tests.first().map_or("output", |t| t.result.output_unit.symbol());
    let mut paragraphs = simulated_paragraph(a);
    paragraphs.push(format!(
        "{} static test(s): {}. Output-to-rate reference: {}",
        a.tests.len(),
        a.tests.iter().map(|t| t.file.as_str()).collect::<Vec<_>>().join(", "),
        a.reference.text
    ));
    // The earth-rate correction, stated where it is applied (or why not).
    if let Some(t) = a.tests.iter().find(|t| t.result.earth_rate_component_dph.is_some()) {
        let e = t.result.earth_rate_component_dph.unwrap_or(0.0);
        paragraphs.push(if t.result.earth_rate_subtracted {
            format!(
                "Earth rate: the component along a vertical input axis, Ω_e sin φ = {} deg/h, is subtracted from every bias.",
                sig(e, 5)
            )
        } else {
            format!(
                "Earth rate: the component along a vertical input axis, Ω_e sin φ = {} deg/h, is not subtracted (the null \
                 already contains it).",
                sig(e, 5)
            )
        });
    }
    if let Some(q) = a.tests.first().and_then(|t| t.result.bias_stability_quoted_s).map(smoothing_key) {
        paragraphs.push(format!(
            "Bias stability is the standard deviation (n − 1) of consecutive T-second window means; the bias time series \
             shows the {q}-s window means. Across the tests the summary quotes the mean bias and the worst stability and drift."
        ));
    }
    paragraphs.extend(a.notes.iter().cloned());
    let mut plots = vec![PlotBlock {
        caption: format!(
            "Axis {}: bias of each static test as {}-s window means; each horizontal step is one window, so the steps \
             mark the window boundaries. Dashed: the mean bias.",
            a.axis,
            short(a.window_s, 4)
        ),
        svg: bias_time_plot(a)?,
    }];
    if let Some(svg) = bias_temperature_plot(a) {
        plots.push(PlotBlock {
            caption: format!(
                "Axis {}: bias against temperature, {}-s window means of every test, with the least-squares line fitted to \
                 all tests pooled. The summary and the test table quote each test's own slope (the summary: the largest in \
                 magnitude), which differs from the pooled slope when the tests' biases or temperature spans differ.",
                a.axis,
                short(a.window_s, 4)
            ),
            svg: svg?,
        });
    }
    let times = a.smoothing_times();
    let u = a.bias_unit();
    let mut header = vec![
        "test".to_string(),
        "file".into(),
        "samples".into(),
        "duration (s)".into(),
        format!("mean output ({ou})"),
        format!("bias B0 ({u})"),
    ];
    header.extend(times.iter().map(|&t| format!("B_s({} s) ({u})", smoothing_key(t))));
    header.push(format!("drift ({u}/h)"));
    let mut table_rows: Vec<Vec<String>> = a
        .tests
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let r = &t.result;
            let cal = r.bias_dph.is_some();
            let mut row = vec![
                format!("{}{}", i + 1, if a.simulated.is_some() { " (SIMULATED)" } else { "" }),
                t.file.clone(),
                r.valid_samples.to_string(),
                short(r.duration_s, 6),
                sig(r.mean_output, 8),
                if cal { sig_opt(r.bias_dph, 5) } else { sig(r.mean_output, 8) },
            ];
            for &t in &times {
                let b = r.stability_at(t);
                row.push(sig_opt(if cal { b.and_then(|b| b.dph) } else { b.map(|b| b.output) }, 4));
            }
            row.push(sig_opt(if cal { r.drift_dph_per_h } else { r.drift_output_per_h }, 4));
            row
        })
        .collect();
    if let Some(rep) = &a.repeatability {
        let mut row = vec![
            "std (n − 1)".to_string(),
            format!("over {} tests", rep.tests),
            String::new(),
            String::new(),
            sig(rep.output_repeatability, 4),
            sig_opt(rep.bias_repeatability_dph, 4),
        ];
        row.extend(times.iter().map(|_| String::new()));
        row.push(String::new());
        table_rows.push(row);
    }
    Ok(ReportSection {
        title: format!(
            "Axis {}: static (bias) test{}",
            a.axis,
            if a.simulated.is_some() { " (SIMULATED)" } else { "" }
        ),
        simulated: a.simulated.is_some(),
        paragraphs,
        figures,
        plots,
        tables: vec![DataTable {
            caption: format!(
                "Axis {}: static tests (as the paper's Table 5){}",
                a.axis,
                if a.simulated.is_some() { ", SIMULATED" } else { "" }
            ),
            header,
            rows: table_rows,
        }],
        page_break_before: true,
    })
}

/// The Allan-variance section of one axis: noise terms with limits, the log-log plot and the
/// deviation table; `None` when the axis has no Allan analysis.
pub fn allan_section(a: &StaticAxisReport, limits: &[Limit]) -> Option<Result<ReportSection, PlotError>> {
    let c = a.allan.as_ref()?;
    let figs = a.figures();
    let keys: Vec<(String, String)> = [
        ("arw_deg_rt_h", "angle random walk N"),
        ("bias_instability_dph", "bias instability B"),
        ("rrw_deg_h_rt_h", "rate random walk K"),
        ("quantization_deg", "quantization noise Q"),
        ("rate_ramp_dph_per_h", "rate ramp R"),
        ("allan_minimum_dph", "Allan minimum (datasheet convention)"),
        ("allan_minimum_tau_s", "τ of the Allan minimum"),
    ]
    .iter()
    .map(|(k, l)| (k.to_string(), l.to_string()))
    .collect();
    let figures = figure_rows(&figs, limits, &keys);
    let mut paragraphs = simulated_paragraph(a);
    paragraphs.push(format!(
        "Record {} ({} samples at τ0 = {} s, {} s long), rate in {}. Overlapping Allan deviation at octave taus with \
         {} confidence bounds (NIST SP 1065). Noise terms by the slope-line method (IEEE 952): N read on the slope −1/2 \
         line at the τ nearest 1 s, B (IEEE 952) = Allan minimum of the flat region / 0.6643 (datasheets such as ADI's and \
         Sensonor's quote the Allan minimum itself), K from the curve's excess over the other terms on the rising side. \
         A term is given as a value only where the curve supports its slope at the bounds' confidence (docs/METHODS.md \
         section 3).",
        c.file,
        c.curve.n_rate,
        short(c.curve.tau0_s, 6),
        short(c.curve.n_rate as f64 * c.curve.tau0_s, 6),
        c.rate_unit,
        c.curve.confidence.map_or("no".into(), |x| format!("{} %", short(100.0 * x, 4)))
    ));
    if let Some(s) = &c.slope_lines {
        for (_, label, unit, r) in crate::allan::terms_in_units(s) {
            if r.value().is_none() {
                paragraphs.push(format!(
                    "{label} is not resolved: {} {unit} ({}).",
                    crate::allan::reading_text(&r, 3),
                    crate::allan::support_text(&r)
                ));
            }
        }
    }
    if let Some(n) = &c.noise_note {
        paragraphs.push(format!("No noise terms: {n}."));
    }
    if let Some(fit) = &c.model_fit {
        let k = &fit.coefficients;
        paragraphs.push(format!(
            "Five-term weighted least-squares fit over τ = {}..{} s ({} points): N = {} deg/√h, B = {} deg/h, K = {} deg/h/√h.",
            short(fit.tau_range_s.0, 4),
            short(fit.tau_range_s.1, 4),
            fit.points_used,
            sig_opt(k.arw_deg_rt_h, 4),
            sig_opt(k.bias_instability_dph, 4),
            sig_opt(k.rrw_deg_h_rt_h, 4)
        ));
        if fit.quality == gyrolab::noise::FitQuality::Poor {
            paragraphs.push(format!(
                "POOR FIT: the weighted RMS residual {} exceeds {}; the five-term model does not describe this curve.",
                sig(fit.weighted_rms_residual, 3),
                gyrolab::noise::FIT_RMS_LIMIT
            ));
        }
    }
    let calibrated = c.rate_unit == "deg/s";
    let (f, u) = if calibrated { (3600.0, "deg/h".to_string()) } else { (1.0, c.rate_unit.clone()) };
    let svg = match allan_plot(a)? {
        Ok(s) => s,
        Err(e) => return Some(Err(e)),
    };
    let table = DataTable {
        caption: format!(
            "Axis {}: overlapping Allan deviation{}",
            a.axis,
            if a.simulated.is_some() { ", SIMULATED" } else { "" }
        ),
        header: vec![
            "τ (s)".into(),
            "m".into(),
            format!("σ(τ) ({u})"),
            format!("lower ({u})"),
            format!("upper ({u})"),
            "noise α".into(),
        ],
        rows: c
            .curve
            .points
            .iter()
            .map(|p| {
                vec![
                    short(p.tau_s, 6),
                    p.m.to_string(),
                    sig(p.deviation * f, 4),
                    sig_opt(p.lower.map(|x| x * f), 4),
                    sig_opt(p.upper.map(|x| x * f), 4),
                    p.alpha.map_or_else(String::new, |x| x.to_string()),
                ]
            })
            .collect(),
    };
    Some(Ok(ReportSection {
        title: format!("Axis {}: Allan variance{}", a.axis, if a.simulated.is_some() { " (SIMULATED)" } else { "" }),
        simulated: a.simulated.is_some(),
        paragraphs,
        figures,
        plots: vec![PlotBlock {
            caption: format!(
                "Axis {}: overlapping Allan deviation on log-log axes with its confidence bars, the asymptotes of the \
                 read-off terms (dashed) and the N, B, K read-off points (circles).",
                a.axis
            ),
            svg,
        }],
        tables: vec![table],
        page_break_before: true,
    }))
}
