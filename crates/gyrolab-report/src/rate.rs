//! Reports of rate-table evaluations: the Table-6-like text table, per-point tables and JSON.
//! JSON keys are documented in docs/JSON.md; each key names its unit or says it is in output
//! units (the axis's `output_unit`).

use crate::segments::segmentation_text;
use comfy_table::{presets::UTF8_FULL_CONDENSED, Cell, CellAlignment, Table};
use gyrolab::figures::AxisFigures;
use gyrolab::format::{short, sig, sig_opt};
use gyrolab::rate_test::{RateEvaluation, RestReferenceSource};
use gyrolab::units::{ratio_to_pct, ratio_to_ppm, OutputUnit};
use gyrolab_eval::outcome::rate::AxisReport;
use gyrolab_eval::outcome::segments::SegmentationReport;
use serde::Serialize;

/// JSON document of `gyrolab rate --json`.
#[derive(Debug, Clone, Serialize)]
pub struct RateJson {
    /// Program version.
    pub gyrolab_version: String,
    /// One entry per file (per output channel of a raw log).
    pub axes: Vec<AxisJson>,
    /// Segmentation of each raw log read (absent when none was).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub segmentation: Vec<crate::segments::SegmentationJson>,
}

/// JSON of one axis.
#[derive(Debug, Clone, Serialize)]
pub struct AxisJson {
    /// Axis name.
    pub name: String,
    /// Source file.
    pub file: String,
    /// Layout read (`long`, `wide`).
    pub layout: String,
    /// Unit of every output-valued field of this axis.
    pub output_unit: String,
    /// Unit of `scale_factor`, such as `V/(deg/s)`.
    pub scale_factor_unit: String,
    /// Number of runs.
    pub runs: usize,
    /// Number of output samples read.
    pub samples: usize,
    /// K, output units per deg/s.
    pub scale_factor: f64,
    /// 1/K, deg/s per output unit.
    pub scale_factor_inverse_dps_per_output: f64,
    /// F0, output units.
    pub zero_offset: f64,
    /// F_r, output units.
    pub rest_reference: f64,
    /// Where F_r came from.
    pub rest_reference_source: RestReferenceSource,
    /// F_m, output units.
    pub output_amplitude: f64,
    /// Y_FS, output units.
    pub full_scale_output: f64,
    /// K_a, %.
    pub nonlinearity_pct: f64,
    /// K_a, ppm.
    pub nonlinearity_ppm: f64,
    /// Linearity, % of full scale.
    pub linearity_pct: f64,
    /// Hysteresis, % of full scale.
    pub hysteresis_pct: f64,
    /// `full` or `half` (the largest forward-reverse difference or half of it).
    pub hysteresis_convention: &'static str,
    /// Repeatability, % of full scale (null with one run).
    pub repeatability_pct: Option<f64>,
    /// Coverage factor k of the repeatability.
    pub repeatability_coverage: f64,
    /// sigma_max, output units.
    pub repeatability_sigma_max: Option<f64>,
    /// Accuracy as the sum of linearity, hysteresis and repeatability, %.
    pub accuracy_pct: Option<f64>,
    /// Accuracy as their root-sum-square, %.
    pub accuracy_rss_pct: Option<f64>,
    /// Scale-factor asymmetry, %.
    pub asymmetry_pct: Option<f64>,
    /// K+ (rates >= 0), output units per deg/s.
    pub positive_scale_factor: Option<f64>,
    /// K- (rates <= 0), output units per deg/s.
    pub negative_scale_factor: Option<f64>,
    /// Scale-factor repeatability across runs, %.
    pub scale_factor_repeatability_pct: Option<f64>,
    /// Scale-factor repeatability across runs, ppm.
    pub scale_factor_repeatability_ppm: Option<f64>,
    /// K of each run, output units per deg/s.
    pub scale_factor_per_run: Vec<RunScaleFactor>,
    /// Polynomial model.
    pub polynomial: PolynomialJson,
    /// Linear input range, when a nonlinearity limit was given.
    pub linear_range: Option<LinearRangeJson>,
    /// Per-point figures, ascending rate.
    pub points: Vec<PointJson>,
}

/// K of one run.
#[derive(Debug, Clone, Serialize)]
pub struct RunScaleFactor {
    /// Run label.
    pub run: u32,
    /// K, output units per deg/s.
    pub scale_factor: f64,
}

/// Polynomial model in JSON.
#[derive(Debug, Clone, Serialize)]
pub struct PolynomialJson {
    /// Order.
    pub order: usize,
    /// c_0..c_n: output = sum c_k rate_dps^k.
    pub coefficients: Vec<f64>,
    /// RMS residual, output units.
    pub rms_residual: f64,
}

/// Linear range in JSON.
#[derive(Debug, Clone, Serialize)]
pub struct LinearRangeJson {
    /// The limit asked for, %.
    pub nonlinearity_limit_pct: f64,
    /// Largest |rate| of the range, deg/s (null when none qualifies).
    pub max_rate_dps: Option<f64>,
    /// K_a within the range, %.
    pub nonlinearity_pct: Option<f64>,
    /// Table rates inside the range.
    pub points: usize,
}

/// One point in JSON (Table 2 and residuals).
#[derive(Debug, Clone, Serialize)]
pub struct PointJson {
    /// Table rate, deg/s.
    pub rate_dps: f64,
    /// Forward-stroke mean, output units.
    pub fwd_mean: f64,
    /// Reverse-stroke mean, output units.
    pub rev_mean: f64,
    /// Mean of both strokes, output units.
    pub mean: f64,
    /// Forward std across runs, output units.
    pub fwd_std: Option<f64>,
    /// Reverse std across runs, output units.
    pub rev_std: Option<f64>,
    /// K * rate + F0, output units.
    pub line_output: f64,
    /// mean - line_output, output units.
    pub line_residual: f64,
    /// a_j, %.
    pub nonlinearity_pct: f64,
    /// Residual of the polynomial model, output units.
    pub polynomial_residual: f64,
}

impl AxisJson {
    /// Builds the JSON of one axis.
    pub fn new(a: &AxisReport<'_>) -> AxisJson {
        let e = a.evaluation;
        AxisJson {
            name: a.name.clone(),
            file: a.file.clone(),
            layout: a.layout.clone(),
            output_unit: a.output_unit.symbol().into(),
            scale_factor_unit: format!("{}/(deg/s)", a.output_unit.symbol()),
            runs: e.runs,
            samples: a.samples,
            scale_factor: e.scale_factor(),
            scale_factor_inverse_dps_per_output: 1.0 / e.scale_factor(),
            zero_offset: e.zero_offset(),
            rest_reference: e.rest_reference,
            rest_reference_source: e.rest_reference_source,
            output_amplitude: e.output_amplitude,
            full_scale_output: e.full_scale_output,
            nonlinearity_pct: ratio_to_pct(e.nonlinearity),
            nonlinearity_ppm: ratio_to_ppm(e.nonlinearity),
            linearity_pct: ratio_to_pct(e.linearity),
            hysteresis_pct: ratio_to_pct(e.hysteresis),
            hysteresis_convention: if e.options.half_hysteresis { "half" } else { "full" },
            repeatability_pct: e.repeatability.map(ratio_to_pct),
            repeatability_coverage: e.options.coverage,
            repeatability_sigma_max: e.repeatability_sigma_max,
            accuracy_pct: e.accuracy_sum.map(ratio_to_pct),
            accuracy_rss_pct: e.accuracy_rss.map(ratio_to_pct),
            asymmetry_pct: e.asymmetry.map(|s| ratio_to_pct(s.asymmetry)),
            positive_scale_factor: e.asymmetry.map(|s| s.positive_scale_factor),
            negative_scale_factor: e.asymmetry.map(|s| s.negative_scale_factor),
            scale_factor_repeatability_pct: e
                .scale_factor_repeatability
                .as_ref()
                .map(|s| ratio_to_pct(s.repeatability)),
            scale_factor_repeatability_ppm: e
                .scale_factor_repeatability
                .as_ref()
                .map(|s| ratio_to_ppm(s.repeatability)),
            scale_factor_per_run: e
                .scale_factor_repeatability
                .as_ref()
                .map(|s| s.per_run.iter().map(|&(run, k)| RunScaleFactor { run, scale_factor: k }).collect())
                .unwrap_or_default(),
            polynomial: PolynomialJson {
                order: e.polynomial.order(),
                coefficients: e.polynomial.coefficients.clone(),
                rms_residual: e.polynomial.rms_residual,
            },
            linear_range: e.linear_range.map(|r| LinearRangeJson {
                nonlinearity_limit_pct: ratio_to_pct(r.limit),
                max_rate_dps: r.max_rate_dps,
                nonlinearity_pct: r.nonlinearity.map(ratio_to_pct),
                points: r.points,
            }),
            points: e
                .points
                .iter()
                .map(|p| PointJson {
                    rate_dps: p.rate_dps,
                    fwd_mean: p.forward_mean,
                    rev_mean: p.reverse_mean,
                    mean: p.mean,
                    fwd_std: p.forward_std,
                    rev_std: p.reverse_std,
                    line_output: p.line_output,
                    line_residual: p.line_residual,
                    nonlinearity_pct: ratio_to_pct(p.nonlinearity),
                    polynomial_residual: p.polynomial_residual,
                })
                .collect(),
        }
    }
}

/// Builds the JSON document for several axes.
pub fn rate_json(axes: &[AxisReport<'_>]) -> RateJson {
    RateJson {
        gyrolab_version: env!("CARGO_PKG_VERSION").into(),
        axes: axes.iter().map(AxisJson::new).collect(),
        segmentation: Vec::new(),
    }
}

fn new_table(header: Vec<String>) -> Table {
    let mut t = Table::new();
    t.load_preset(UTF8_FULL_CONDENSED);
    t.set_header(header);
    t
}

fn right(t: &mut Table, from: usize) {
    for i in from..t.column_count() {
        if let Some(c) = t.column_mut(i) {
            c.set_cell_alignment(CellAlignment::Right);
        }
    }
}

/// The summary table (like the paper's Table 6): one row per figure, one column per axis.
pub fn rate_summary_table(axes: &[AxisReport<'_>]) -> String {
    let mut header = vec!["figure".to_string(), "unit".to_string()];
    header.extend(axes.iter().map(|a| a.name.clone()));
    let mut t = new_table(header);
    let units: Vec<(OutputUnit, f64)> = axes.iter().map(|a| a.output_unit.scale_factor_display()).collect();
    let same_unit = axes.iter().all(|a| a.output_unit == axes[0].output_unit);
    let mut row = |label: &str, unit: String, f: &dyn Fn(usize, &RateEvaluation) -> String| {
        let mut cells = vec![Cell::new(label), Cell::new(unit)];
        cells.extend(axes.iter().enumerate().map(|(i, a)| Cell::new(f(i, a.evaluation))));
        t.add_row(cells);
    };
    let out_unit = |i: usize| if same_unit { String::new() } else { format!(" {}", axes[i].output_unit) };
    let k_unit = if same_unit { format!("{}/(deg/s)", units[0].0) } else { "see cells".into() };
    row("scale factor K", k_unit, &|i, e| {
        format!(
            "{}{}",
            sig(e.scale_factor() * units[i].1, 5),
            if same_unit { String::new() } else { format!(" {}/(deg/s)", units[i].0) }
        )
    });
    let o_unit = if same_unit { axes[0].output_unit.symbol().to_string() } else { "see cells".into() };
    row("zero offset F0", o_unit.clone(), &|i, e| format!("{}{}", sig(e.zero_offset(), 7), out_unit(i)));
    row("rest reference F_r", o_unit.clone(), &|i, e| {
        let src = match e.rest_reference_source {
            RestReferenceSource::RestRecords => "rest",
            RestReferenceSource::ZeroRatePoint => "0 deg/s",
            RestReferenceSource::FitZeroOffset => "F0",
        };
        format!("{}{} ({src})", sig(e.rest_reference, 7), out_unit(i))
    });
    row("full-scale output Y_FS", o_unit, &|i, e| format!("{}{}", sig(e.full_scale_output, 5), out_unit(i)));
    row("nonlinearity K_a", "%".into(), &|_, e| sig(ratio_to_pct(e.nonlinearity), 4));
    row("nonlinearity K_a", "ppm".into(), &|_, e| sig(ratio_to_ppm(e.nonlinearity), 4));
    row("linearity", "% FS".into(), &|_, e| sig(ratio_to_pct(e.linearity), 4));
    let hyst = if axes.first().is_some_and(|a| a.evaluation.options.half_hysteresis) {
        "hysteresis (half)"
    } else {
        "hysteresis"
    };
    row(hyst, "% FS".into(), &|_, e| sig(ratio_to_pct(e.hysteresis), 4));
    let k = axes.first().map_or(3.0, |a| a.evaluation.options.coverage);
    row(&format!("repeatability (k = {k})"), "% FS".into(), &|_, e| sig_opt(e.repeatability.map(ratio_to_pct), 4));
    row("accuracy (sum, paper)", "% FS".into(), &|_, e| sig_opt(e.accuracy_sum.map(ratio_to_pct), 4));
    row("accuracy (RSS)", "% FS".into(), &|_, e| sig_opt(e.accuracy_rss.map(ratio_to_pct), 4));
    row("asymmetry", "%".into(), &|_, e| sig_opt(e.asymmetry.map(|a| ratio_to_pct(a.asymmetry)), 4));
    row("scale-factor repeatability", "ppm".into(), &|_, e| {
        sig_opt(e.scale_factor_repeatability.as_ref().map(|s| ratio_to_ppm(s.repeatability)), 4)
    });
    row("runs x rates", String::new(), &|_, e| format!("{} x {}", e.runs, e.points.len()));
    if axes.iter().any(|a| a.evaluation.polynomial.order() > 1) {
        row("polynomial RMS residual", o_unit_plain(axes), &|_, e| {
            format!("{} (order {})", sig(e.polynomial.rms_residual, 4), e.polynomial.order())
        });
    }
    if let Some(limit) = axes.iter().find_map(|a| a.evaluation.linear_range.map(|r| r.limit)) {
        row(&format!("linear range (K_a <= {} %)", short(ratio_to_pct(limit), 4)), "deg/s".into(), &|_, e| match e
            .linear_range
            .and_then(|r| r.max_rate_dps.zip(r.nonlinearity))
        {
            Some((r, ka)) => format!("±{} ({} %)", short(r, 6), sig(ratio_to_pct(ka), 3)),
            None => "none".into(),
        });
    }
    right(&mut t, 2);
    t.to_string()
}

fn o_unit_plain(axes: &[AxisReport<'_>]) -> String {
    axes.first().map(|a| a.output_unit.symbol().to_string()).unwrap_or_default()
}

/// The per-point table of one axis (the paper's Table 2 plus fit residuals).
pub fn rate_points_table(a: &AxisReport<'_>) -> String {
    let u = a.output_unit.symbol();
    let mut t = new_table(vec![
        "i".into(),
        "rate deg/s".into(),
        format!("fwd mean {u}"),
        format!("rev mean {u}"),
        format!("mean {u}"),
        format!("line residual {u}"),
        "a_j %".into(),
        format!("poly residual {u}"),
    ]);
    for (i, p) in a.evaluation.points.iter().enumerate() {
        t.add_row(vec![
            (i + 1).to_string(),
            sig(p.rate_dps, 6),
            format!("{:.8}", p.forward_mean),
            format!("{:.8}", p.reverse_mean),
            format!("{:.8}", p.mean),
            sig(p.line_residual, 4),
            sig(ratio_to_pct(p.nonlinearity), 4),
            sig(p.polynomial_residual, 4),
        ]);
    }
    right(&mut t, 0);
    t.to_string()
}

/// The rate-table figures of an axis, from its JSON.
pub fn rate_figures(a: &AxisJson) -> AxisFigures {
    let mut f = AxisFigures { axis: a.name.clone(), output_unit: a.output_unit.clone(), ..Default::default() };
    let opt = [
        ("scale_factor", Some(a.scale_factor)),
        ("zero_offset", Some(a.zero_offset)),
        ("nonlinearity_pct", Some(a.nonlinearity_pct)),
        ("nonlinearity_ppm", Some(a.nonlinearity_ppm)),
        ("linearity_pct", Some(a.linearity_pct)),
        ("hysteresis_pct", Some(a.hysteresis_pct)),
        ("repeatability_pct", a.repeatability_pct),
        ("accuracy_pct", a.accuracy_pct),
        ("accuracy_rss_pct", a.accuracy_rss_pct),
        ("asymmetry_pct", a.asymmetry_pct),
        ("scale_factor_repeatability_ppm", a.scale_factor_repeatability_ppm),
        ("scale_factor_repeatability_pct", a.scale_factor_repeatability_pct),
    ];
    for (k, v) in opt {
        if let Some(v) = v {
            f.set(k, v);
        }
    }
    f
}

/// The text of `gyrolab rate`: each raw log's segmentation, where the segments were written, the
/// summary table, the per-point tables (`points`), and where the calibration was written.
pub fn rate_text(
    reports: &[AxisReport<'_>],
    seg_reports: &[SegmentationReport<'_>],
    points: bool,
    segments_out: Option<&std::path::Path>,
    cal_out: Option<&std::path::Path>,
) -> String {
    let mut text = String::new();
    for r in seg_reports {
        text.push_str(&segmentation_text(r));
        text.push('\n');
    }
    if let Some(out) = segments_out {
        text.push_str(&format!("Segments written to {}\n\n", out.display()));
    }
    text.push_str(&rate_summary_table(reports));
    text.push('\n');
    if points {
        for r in reports {
            text.push_str(&format!("\nAxis {} ({}): per-point means and residuals\n", r.name, r.file));
            text.push_str(&rate_points_table(r));
            text.push('\n');
        }
    }
    if let Some(cal) = cal_out {
        text.push_str(&format!("\nCalibration written to {}\n", cal.display()));
    }
    text
}
