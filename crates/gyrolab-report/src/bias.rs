//! Reports of static (bias) tests: the summary table, data-quality findings and JSON
//! (keys in docs/JSON.md).

use comfy_table::{presets::UTF8_FULL_CONDENSED, Cell, CellAlignment, Table};
use gyrolab::format::{short, sig, sig_opt};
use gyrolab::static_test::{reported_smoothing_times, smoothing_key, QualityIssue, StaticTestResult};
use gyrolab_eval::outcome::static_test::{ChannelRepeatability, TestReport, WarmupReport};
use gyrolab_eval::static_test::FileQuality;
use serde::Serialize;

/// JSON document of `gyrolab bias --json`.
#[derive(Debug, Clone, Serialize)]
pub struct BiasJson {
    /// Program version.
    pub gyrolab_version: String,
    /// One entry per file and channel.
    pub tests: Vec<TestReport>,
    /// Bias repeatability across the files, deg/h, when every test has one channel and is
    /// calibrated (null otherwise; per channel in `repeatability`).
    pub bias_repeatability_dph: Option<f64>,
    /// Repeatability per channel (channels present in two or more files).
    pub repeatability: Vec<ChannelRepeatability>,
    /// Warm-up figures per file and channel (`--warmup-band-dph`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub warmup: Vec<WarmupJson>,
}

/// The exponential settling model in JSON.
#[derive(Debug, Clone, Serialize)]
pub struct SettlingModelJson {
    /// Settled bias B_inf, deg/h.
    pub settled_bias_dph: f64,
    /// Amplitude A at power-on, deg/h.
    pub amplitude_dph: f64,
    /// Time constant, s.
    pub time_constant_s: f64,
    /// RMS residual of the window means about the model, deg/h.
    pub rms_residual_dph: f64,
    /// The model's time to enter the band, s.
    pub settling_time_s: f64,
}

/// Warm-up figures in JSON, each key naming its unit.
#[derive(Debug, Clone, Serialize)]
pub struct WarmupJson {
    /// Source file.
    pub file: String,
    /// Channel.
    pub channel: String,
    /// Turn-on bias: the first window's mean, deg/h.
    pub turn_on_bias_dph: f64,
    /// Final bias: the mean of the record's last part, deg/h.
    pub final_bias_dph: f64,
    /// Settling band, +- deg/h.
    pub band_dph: f64,
    /// Window of the window means, s.
    pub window_s: f64,
    /// Settling time to the band, s (null: the record never stays inside it).
    pub settling_time_s: Option<f64>,
    /// Standard deviation of the final part's window means, deg/h.
    pub final_scatter_dph: f64,
    /// The exponential model, when resolved.
    pub model: Option<SettlingModelJson>,
    /// Why the model has no value (`time_constant_at_edge`, `amplitude_below_noise`,
    /// `too_few_windows`), null when resolved.
    pub model_reason: Option<String>,
}

impl WarmupJson {
    /// The JSON of a report.
    pub fn new(w: &WarmupReport) -> Self {
        use gyrolab::warmup::ModelSupport;
        let r = &w.result;
        WarmupJson {
            file: w.file.clone(),
            channel: w.channel.clone(),
            turn_on_bias_dph: r.turn_on,
            final_bias_dph: r.final_bias,
            band_dph: r.config.band,
            window_s: r.config.window_s,
            settling_time_s: r.settling_time_s,
            final_scatter_dph: r.final_scatter,
            model: r.model.map(|m| SettlingModelJson {
                settled_bias_dph: m.settled,
                amplitude_dph: m.amplitude,
                time_constant_s: m.time_constant_s,
                rms_residual_dph: m.rms_residual,
                settling_time_s: m.settling_time_s,
            }),
            model_reason: match r.model_support {
                ModelSupport::Resolved => None,
                ModelSupport::TimeConstantAtEdge => Some("time_constant_at_edge".into()),
                ModelSupport::AmplitudeBelowNoise => Some("amplitude_below_noise".into()),
                ModelSupport::TooFewWindows => Some("too_few_windows".into()),
            },
        }
    }
}

/// One line per warm-up report.
pub fn warmup_text(reports: &[WarmupReport]) -> String {
    use gyrolab::warmup::ModelSupport;
    let mut s = String::new();
    for w in reports {
        let r = &w.result;
        let settle = r.settling_time_s.map_or_else(
            || {
                format!(
                    "not settled within the record (the final window means scatter by {} deg/h: a band below about three times that, or short windows, cannot be met)",
                    sig(r.final_scatter, 3)
                )
            },
            |t| format!("{} s", short(t, 6)),
        );
        let model = match (&r.model, r.model_support) {
            (Some(m), _) => format!(
                "model B_inf + A exp(-t/tau): tau = {} s, A = {} deg/h, B_inf = {} deg/h (time to the band {} s)",
                sig(m.time_constant_s, 4),
                sig(m.amplitude, 4),
                sig(m.settled, 5),
                sig(m.settling_time_s, 4)
            ),
            (None, ModelSupport::TimeConstantAtEdge) => {
                "no model: the record does not show a transient (time constant at the edge of the range)".into()
            }
            (None, ModelSupport::AmplitudeBelowNoise) => "no model: no transient above the noise".into(),
            (None, _) => "no model: too few windows".into(),
        };
        s.push_str(&format!(
            "warm-up {} ({}): turn-on bias {} deg/h, final {} deg/h, settling time to +-{} deg/h ({}-s windows): {settle}; {model}\n",
            w.file,
            w.channel,
            sig(r.turn_on, 5),
            sig(r.final_bias, 5),
            short(r.config.band, 6),
            short(r.config.window_s, 6)
        ));
    }
    s
}

/// Builds the JSON document.
pub fn bias_json(
    tests: Vec<TestReport>,
    repeatability: Vec<ChannelRepeatability>,
    warmup: &[WarmupReport],
) -> BiasJson {
    let single = repeatability.len() == 1;
    BiasJson {
        gyrolab_version: env!("CARGO_PKG_VERSION").into(),
        bias_repeatability_dph: if single { repeatability[0].repeatability.bias_repeatability_dph } else { None },
        tests,
        repeatability,
        warmup: warmup.iter().map(WarmupJson::new).collect(),
    }
}

fn issue_text(name: &str, q: &QualityIssue) -> Option<String> {
    if q.count == 0 {
        return None;
    }
    let at = q.first.first().map(|p| match p.line {
        Some(l) => format!(", first at line {l}"),
        None => format!(", first at sample {}", p.sample),
    });
    Some(format!("{} {name}{}", q.count, at.unwrap_or_default()))
}

/// Data-quality findings of one test as text lines (empty when clean).
pub fn quality_lines(t: &TestReport) -> Vec<String> {
    let q = &t.result.quality;
    let mut v: Vec<String> = [
        issue_text("missing (NaN or empty) samples", &q.missing),
        issue_text("time gaps", &q.time_gaps),
        issue_text("repeated time stamps", &q.repeated_time),
        issue_text("decreasing time stamps", &q.decreasing_time),
    ]
    .into_iter()
    .flatten()
    .collect();
    for (name, r) in [("minimum", &q.stuck_at_min), ("maximum", &q.stuck_at_max)] {
        if r.runs > 0 {
            let at = r.first.first().and_then(|p| p.line).map(|l| format!(", first at line {l}")).unwrap_or_default();
            v.push(format!(
                "{} run(s) of {} samples stuck at the {name} {}{at}",
                r.runs,
                r.samples,
                sig_opt(r.value, 6)
            ));
        }
    }
    if let Some(o) = &q.outliers {
        if let Some(s) =
            issue_text(&format!("outliers beyond {} sigma of the drift line", short(o.k_sigma, 3)), &o.outliers)
        {
            v.push(if o.dropped {
                format!("{s} (dropped)")
            } else {
                format!("{s} (kept; --drop-outliers removes them)")
            });
        }
    }
    v
}

/// The summary table: one row per figure, one column per test.
pub fn bias_table(tests: &[TestReport], repeatability: &[ChannelRepeatability]) -> String {
    let mut t = Table::new();
    t.load_preset(UTF8_FULL_CONDENSED);
    let mut header = vec!["figure".to_string(), "unit".to_string()];
    header.extend(tests.iter().map(|r| {
        let stem =
            std::path::Path::new(&r.file).file_stem().map_or(r.file.clone(), |s| s.to_string_lossy().into_owned());
        format!("{stem}\n{}", r.result.channel)
    }));
    t.set_header(header);
    let unit = |r: &TestReport| r.result.output_unit.symbol().to_string();
    let same_unit = tests.windows(2).all(|w| w[0].result.output_unit == w[1].result.output_unit);
    let ou = if same_unit { tests.first().map(unit).unwrap_or_default() } else { "output".into() };
    let mut row = |label: String, unit: String, f: &dyn Fn(&StaticTestResult) -> String| {
        let mut cells = vec![Cell::new(label), Cell::new(unit)];
        cells.extend(tests.iter().map(|r| Cell::new(f(&r.result))));
        t.add_row(cells);
    };
    row("samples".into(), String::new(), &|r| r.valid_samples.to_string());
    row("sample rate".into(), "Hz".into(), &|r| short(r.sample_rate_hz, 6));
    row("duration".into(), "s".into(), &|r| short(r.duration_s, 6));
    row("zero-rate output mean".into(), ou.clone(), &|r| sig(r.mean_output, 8));
    row("output std".into(), ou.clone(), &|r| sig(r.std_output, 4));
    row("scale factor used".into(), format!("{ou}/(deg/s)"), &|r| sig_opt(r.scale_factor_output_per_dps, 6));
    row("bias B0".into(), "deg/s".into(), &|r| sig_opt(r.bias_dps, 5));
    row("bias B0".into(), "deg/h".into(), &|r| sig_opt(r.bias_dph, 5));
    if tests.iter().any(|r| r.result.earth_rate_component_dph.is_some()) {
        row("earth rate (subtracted)".into(), "deg/h".into(), &|r| sig_opt(r.earth_rate_component_dph, 5));
    }
    let times = reported_smoothing_times(tests.iter().map(|r| &r.result));
    let calibrated = tests.iter().any(|r| r.result.bias_stability.iter().any(|b| b.dph.is_some()));
    for &t in &times {
        let k = smoothing_key(t);
        if calibrated {
            row(format!("bias stability ({k} s)"), "deg/h".into(), &|r| {
                sig_opt(r.stability_at(t).and_then(|b| b.dph), 4)
            });
        } else {
            row(format!("bias stability ({k} s)"), ou.clone(), &|r| sig_opt(r.stability_at(t).map(|b| b.output), 4));
        }
    }
    if calibrated {
        row("drift".into(), "(deg/h)/h".into(), &|r| sig_opt(r.drift_dph_per_h, 4));
    } else {
        row("drift".into(), format!("{ou}/h"), &|r| sig_opt(r.drift_output_per_h, 4));
    }
    if tests.iter().any(|r| r.result.temperature.is_some()) {
        row("temperature range".into(), "degC".into(), &|r| {
            r.temperature
                .as_ref()
                .map_or("n/a".into(), |t| format!("{}..{}", short(t.temp_min_c, 4), short(t.temp_max_c, 4)))
        });
        row("temperature sensitivity".into(), "(deg/h)/degC".into(), &|r| {
            sig_opt(r.temperature.as_ref().and_then(|t| t.temp_sensitivity_dph_per_c), 4)
        });
        row("stability after compensation".into(), "deg/h".into(), &|r| {
            sig_opt(r.temperature.as_ref().and_then(|t| t.compensated_stability_dph), 4)
        });
    }
    for i in 2..t.column_count() {
        if let Some(c) = t.column_mut(i) {
            c.set_cell_alignment(CellAlignment::Right);
        }
    }
    let mut s = t.to_string();
    for r in repeatability {
        let rep = &r.repeatability;
        s.push_str(&format!(
            "\nchannel {} over {} tests: mean output {} {}, std {} {}",
            r.channel,
            rep.tests,
            sig(rep.mean_output, 8),
            ou,
            sig(rep.output_repeatability, 4),
            ou
        ));
        if let (Some(m), Some(b)) = (rep.mean_bias_dph, rep.bias_repeatability_dph) {
            s.push_str(&format!("; mean bias {} deg/h, bias repeatability {} deg/h", sig(m, 5), sig(b, 4)));
        }
    }
    if let Some(q) = tests.first().and_then(|r| r.result.bias_stability_quoted_s).map(smoothing_key) {
        s.push_str(&format!("\nbias stability is quoted at a smoothing time of {q} s (window means, n-1)."));
    }
    s
}

/// The warnings and notes of static tests, one line each as `gyrolab bias` prints them on stderr:
/// missing cells and dropout rows per file, each test's data-quality findings and notes, and a
/// record whose every sample has the same value.
pub fn warning_lines(files: &[FileQuality], tests: &[TestReport]) -> Vec<String> {
    let mut out = Vec::new();
    for f in files {
        if let Some(c) = f.quality.first_missing.first() {
            out.push(format!(
                "warning: {}:{}:{}: {} missing cell(s) (NaN or empty) excluded, first in column '{}'",
                f.file, c.line, c.column, f.quality.missing_cells, c.name
            ));
        }
        if let Some(l) = f.quality.first_zero_rows.first() {
            out.push(format!(
                "warning: {}:{l}: {} dropout row(s) (every channel exactly zero, far more often than chance) left out of every figure",
                f.file, f.quality.zero_rows
            ));
        }
        if let Some(l) = f.quality.first_repeated_rows.first() {
            out.push(format!(
                "warning: {}:{l}: {} dropout row(s) (every channel equal to the row before, far more often than chance) left out of every figure",
                f.file, f.quality.repeated_rows
            ));
        }
    }
    for t in tests {
        for line in quality_lines(t) {
            out.push(format!("warning: {} ({}): {line}", t.file, t.result.channel));
        }
        for note in &t.result.notes {
            out.push(format!("note: {} ({}): {note}", t.file, t.result.channel));
        }
        let r = &t.result;
        if r.valid_samples > 1 && r.std_output <= 1e-12 * r.mean_output.abs() {
            out.push(format!(
                "warning: {} ({}): every sample has the same value ({} {}): the bias is that value, but no \
                 stability or noise figure can be read from a record without noise; a stuck sensor, or a \
                 simulation without noise terms?",
                t.file, r.channel, r.mean_output, r.output_unit
            ));
        }
    }
    out
}

/// The closing notes of the static-test table: whether the earth rate was subtracted (or no
/// latitude was given) and whether the figures are in output units only (no reference).
pub fn figure_notes(tests: &[TestReport], latitude_given: bool, has_reference: bool) -> String {
    let mut text = String::new();
    if tests.iter().any(|t| t.result.earth_rate_subtracted) {
        text.push_str("The earth-rate component for a vertical input axis was subtracted from the bias.\n");
    } else if !latitude_given && tests.iter().any(|t| t.result.bias_dph.is_some()) {
        text.push_str(
            "No latitude given: the bias includes the earth-rate component (give --latitude to remove it).\n",
        );
    }
    if !has_reference && tests.iter().any(|t| t.result.bias_dps.is_none()) {
        text.push_str(
            "No scale factor given (--cal FILE.toml, or --scale-factor K --null F): figures are in output units only.\n",
        );
    }
    text
}
