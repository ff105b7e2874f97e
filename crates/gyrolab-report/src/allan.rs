//! Reports of Allan-variance analyses: the deviation table, CSV, JSON (keys in docs/JSON.md),
//! the noise-coefficient summary and Kalibr's imu.yaml gyroscope entries.

use crate::format::{short, sig, sig_opt};
use comfy_table::{presets::UTF8_FULL_CONDENSED, Cell, CellAlignment, Table};
use gyrolab::allan::AllanCurve;
use gyrolab::noise::{KalibrGyroscope, ModelFitResult, NoiseCoefficients, SlopeLineResult, SlopeReading};
use serde::Serialize;

/// One analysed channel.
#[derive(Debug, Clone)]
pub struct ChannelAnalysis {
    /// Source file.
    pub file: String,
    /// Channel name.
    pub channel: String,
    /// Unit of the rate data analysed: `deg/s` when calibrated, else the output unit.
    pub rate_unit: String,
    /// The curve.
    pub curve: AllanCurve,
    /// Noise terms by slope lines (only for data in deg/s).
    pub slope_lines: Option<SlopeLineResult>,
    /// Noise terms by the weighted five-term fit (only for data in deg/s).
    pub model_fit: Option<ModelFitResult>,
    /// Why noise terms are missing, if they are.
    pub noise_note: Option<String>,
}

/// Noise coefficients in JSON, each key naming its unit.
#[derive(Debug, Clone, Serialize)]
pub struct NoiseJson {
    /// Angle random walk N, deg/sqrt(h).
    pub arw_deg_rt_h: Option<f64>,
    /// Bias instability B, deg/h (ADEV flat value / 0.6643).
    pub bias_instability_dph: Option<f64>,
    /// Rate random walk K, deg/h/sqrt(h).
    pub rrw_deg_h_rt_h: Option<f64>,
    /// Quantization noise Q, deg.
    pub quantization_deg: Option<f64>,
    /// Rate ramp R, deg/h per hour.
    pub rate_ramp_dph_per_h: Option<f64>,
    /// N as a noise density, deg/s/sqrt(Hz) (= deg/sqrt(s)).
    pub arw_deg_rt_s: Option<f64>,
    /// K, deg/s/sqrt(s).
    pub rrw_deg_s_rt_s: Option<f64>,
    /// Where each slope-line term was read: tau and the tau range of its slope region.
    pub readings: Vec<ReadingJson>,
    /// The weighted least-squares fit of the five-term model.
    pub fit: Option<FitJson>,
    /// Kalibr imu.yaml gyroscope entries (rad units).
    pub kalibr: KalibrGyroscope,
}

/// Where a term was read.
#[derive(Debug, Clone, Serialize)]
pub struct ReadingJson {
    /// Term: `quantization`, `arw`, `bias_instability`, `rrw`, `rate_ramp`.
    pub term: &'static str,
    /// Tau of the reading, s.
    pub tau_s: f64,
    /// Tau range of the slope region, s.
    pub tau_range_s: [f64; 2],
    /// Local log-log slope there.
    pub local_slope: f64,
}

/// The five-term fit in JSON.
#[derive(Debug, Clone, Serialize)]
pub struct FitJson {
    /// N, deg/sqrt(h).
    pub arw_deg_rt_h: Option<f64>,
    /// B, deg/h.
    pub bias_instability_dph: Option<f64>,
    /// K, deg/h/sqrt(h).
    pub rrw_deg_h_rt_h: Option<f64>,
    /// Q, deg.
    pub quantization_deg: Option<f64>,
    /// R, deg/h per hour.
    pub rate_ramp_dph_per_h: Option<f64>,
    /// Tau range fitted, s.
    pub tau_range_s: [f64; 2],
    /// Points used.
    pub points_used: usize,
    /// Weighted RMS residual (relative).
    pub weighted_rms_residual: f64,
}

/// JSON of one channel.
#[derive(Debug, Clone, Serialize)]
pub struct AllanJson {
    /// Source file.
    pub file: String,
    /// Channel.
    pub channel: String,
    /// Deviation kind: oadev, adev, mdev, tdev, hdev, ohdev, totdev.
    pub kind: String,
    /// Unit of `dev`, `ci_low`, `ci_high` (deg/s when calibrated; TDEV: seconds times it).
    pub dev_unit: String,
    /// Sample interval, s.
    pub tau0_s: f64,
    /// Rate samples analysed.
    pub samples: usize,
    /// Confidence level of the bounds (null: none computed).
    pub confidence: Option<f64>,
    /// Averaging times, s.
    pub taus_s: Vec<f64>,
    /// Averaging factors m.
    pub m: Vec<usize>,
    /// Deviations.
    pub dev: Vec<f64>,
    /// Lower bounds.
    pub ci_low: Vec<Option<f64>>,
    /// Upper bounds.
    pub ci_high: Vec<Option<f64>>,
    /// Number of terms in each sum.
    pub n_terms: Vec<usize>,
    /// Identified noise type alpha per tau (2 white PM ... -2 random walk FM).
    pub alpha: Vec<Option<i32>>,
    /// Equivalent degrees of freedom per tau.
    pub edf: Vec<Option<f64>>,
    /// Noise coefficients (null when the data are not in deg/s).
    pub noise: Option<NoiseJson>,
    /// Why `noise` is null, if it is.
    pub noise_note: Option<String>,
}

/// The JSON document: the first channel's keys at the top level, every channel in `channels`.
#[derive(Debug, Clone, Serialize)]
pub struct AllanDocument {
    /// Program version.
    pub gyrolab_version: String,
    /// The first channel's result.
    #[serde(flatten)]
    pub first: AllanJson,
    /// Every channel (the first included).
    pub channels: Vec<AllanJson>,
}

fn readings(s: &SlopeLineResult) -> Vec<ReadingJson> {
    let mut v = Vec::new();
    let mut push = |term, r: &Option<SlopeReading>| {
        if let Some(r) = r {
            v.push(ReadingJson {
                term,
                tau_s: r.tau_s,
                tau_range_s: [r.tau_range_s.0, r.tau_range_s.1],
                local_slope: r.local_slope,
            });
        }
    };
    push("quantization", &s.quantization);
    push("arw", &s.arw);
    push("bias_instability", &s.bias_instability);
    push("rrw", &s.rrw);
    push("rate_ramp", &s.rate_ramp);
    v
}

/// Builds the JSON of one channel.
pub fn allan_json(a: &ChannelAnalysis) -> AllanJson {
    let c = &a.curve;
    let noise = a.slope_lines.as_ref().map(|s| {
        let k = &s.coefficients;
        NoiseJson {
            arw_deg_rt_h: k.arw_deg_rt_h,
            bias_instability_dph: k.bias_instability_dph,
            rrw_deg_h_rt_h: k.rrw_deg_h_rt_h,
            quantization_deg: k.quantization_deg,
            rate_ramp_dph_per_h: k.rate_ramp_dph_per_h,
            arw_deg_rt_s: k.arw_deg_rt_s,
            rrw_deg_s_rt_s: k.rrw_deg_s_rt_s,
            readings: readings(s),
            fit: a.model_fit.as_ref().map(|f| FitJson {
                arw_deg_rt_h: f.coefficients.arw_deg_rt_h,
                bias_instability_dph: f.coefficients.bias_instability_dph,
                rrw_deg_h_rt_h: f.coefficients.rrw_deg_h_rt_h,
                quantization_deg: f.coefficients.quantization_deg,
                rate_ramp_dph_per_h: f.coefficients.rate_ramp_dph_per_h,
                tau_range_s: [f.tau_range_s.0, f.tau_range_s.1],
                points_used: f.points_used,
                weighted_rms_residual: f.weighted_rms_residual,
            }),
            kalibr: gyrolab::noise::kalibr_gyroscope(k),
        }
    });
    AllanJson {
        file: a.file.clone(),
        channel: a.channel.clone(),
        kind: c.kind.name().to_string(),
        dev_unit: if c.kind.name() == "tdev" { format!("s*{}", a.rate_unit) } else { a.rate_unit.clone() },
        tau0_s: c.tau0_s,
        samples: c.n_rate,
        confidence: c.confidence,
        taus_s: c.points.iter().map(|p| p.tau_s).collect(),
        m: c.points.iter().map(|p| p.m).collect(),
        dev: c.points.iter().map(|p| p.deviation).collect(),
        ci_low: c.points.iter().map(|p| p.lower).collect(),
        ci_high: c.points.iter().map(|p| p.upper).collect(),
        n_terms: c.points.iter().map(|p| p.terms).collect(),
        alpha: c.points.iter().map(|p| p.alpha).collect(),
        edf: c.points.iter().map(|p| p.edf).collect(),
        noise,
        noise_note: a.noise_note.clone(),
    }
}

/// Builds the JSON document of several channels (at least one).
pub fn allan_document(channels: &[ChannelAnalysis]) -> Option<AllanDocument> {
    let all: Vec<AllanJson> = channels.iter().map(allan_json).collect();
    Some(AllanDocument {
        gyrolab_version: env!("CARGO_PKG_VERSION").into(),
        first: all.first()?.clone(),
        channels: all,
    })
}

/// CSV of the curves: `file,channel,tau_s,m,dev,ci_low,ci_high,n_terms,alpha`.
pub fn allan_csv(channels: &[ChannelAnalysis]) -> String {
    let mut s = String::from("file,channel,tau_s,m,dev,ci_low,ci_high,n_terms,alpha\n");
    let opt = |v: Option<f64>| v.map_or(String::new(), |x| format!("{x:e}"));
    for a in channels {
        for p in &a.curve.points {
            s.push_str(&format!(
                "{},{},{:e},{},{:e},{},{},{},{}\n",
                a.file,
                a.channel,
                p.tau_s,
                p.m,
                p.deviation,
                opt(p.lower),
                opt(p.upper),
                p.terms,
                p.alpha.map_or(String::new(), |x| x.to_string())
            ));
        }
    }
    s
}

/// A row of the noise-term table: name, unit, slope-line value, reading, five-term fit value.
type NoiseRow<'a> = (&'a str, &'a str, Option<f64>, &'a Option<SlopeReading>, Option<f64>);

/// The deviation table and noise summary of one channel, as text.
pub fn allan_text(a: &ChannelAnalysis) -> String {
    let c = &a.curve;
    let mut t = Table::new();
    t.load_preset(UTF8_FULL_CONDENSED);
    let u = if c.kind.name() == "tdev" { format!("s*{}", a.rate_unit) } else { a.rate_unit.clone() };
    let conf = c.confidence.map_or("no bounds".to_string(), |x| format!("{} % bounds", short(100.0 * x, 4)));
    t.set_header(vec![
        "tau s".to_string(),
        "m".into(),
        format!("{} {u}", c.kind.name().to_uppercase()),
        format!("low ({conf})"),
        "high".into(),
        "terms".into(),
        "alpha".into(),
    ]);
    for p in &c.points {
        t.add_row(vec![
            Cell::new(short(p.tau_s, 6)),
            Cell::new(p.m),
            Cell::new(sig(p.deviation, 5)),
            Cell::new(sig_opt(p.lower, 4)),
            Cell::new(sig_opt(p.upper, 4)),
            Cell::new(p.terms),
            Cell::new(p.alpha.map_or("".into(), |x| x.to_string())),
        ]);
    }
    for i in 0..6 {
        if let Some(col) = t.column_mut(i) {
            col.set_cell_alignment(CellAlignment::Right);
        }
    }
    let mut s = format!(
        "{} ({}): {} of {} samples at tau0 = {} s, rate in {}\n{}\n",
        a.file,
        a.channel,
        c.kind.name().to_uppercase(),
        c.n_rate,
        short(c.tau0_s, 6),
        a.rate_unit,
        t
    );
    match (&a.slope_lines, &a.noise_note) {
        (Some(sl), _) => {
            let mut n = Table::new();
            n.load_preset(UTF8_FULL_CONDENSED);
            n.set_header(vec!["noise term", "unit", "slope lines", "read at tau s (slope region)", "five-term fit"]);
            let k = &sl.coefficients;
            let f = a.model_fit.as_ref().map(|f| f.coefficients);
            let at = |r: &Option<SlopeReading>| {
                r.map_or("not present".to_string(), |r| {
                    format!("{} ({}..{})", short(r.tau_s, 4), short(r.tau_range_s.0, 4), short(r.tau_range_s.1, 4))
                })
            };
            let rows: [NoiseRow<'_>; 5] = [
                ("angle random walk N", "deg/sqrt(h)", k.arw_deg_rt_h, &sl.arw, f.and_then(|f| f.arw_deg_rt_h)),
                (
                    "bias instability B",
                    "deg/h",
                    k.bias_instability_dph,
                    &sl.bias_instability,
                    f.and_then(|f| f.bias_instability_dph),
                ),
                ("rate random walk K", "deg/h/sqrt(h)", k.rrw_deg_h_rt_h, &sl.rrw, f.and_then(|f| f.rrw_deg_h_rt_h)),
                ("quantization Q", "deg", k.quantization_deg, &sl.quantization, f.and_then(|f| f.quantization_deg)),
                ("rate ramp R", "deg/h/h", k.rate_ramp_dph_per_h, &sl.rate_ramp, f.and_then(|f| f.rate_ramp_dph_per_h)),
            ];
            for (name, unit, v, r, fv) in rows {
                n.add_row(vec![name.to_string(), unit.to_string(), sig_opt(v, 4), at(r), sig_opt(fv, 4)]);
            }
            s.push_str(&n.to_string());
            if let Some(fit) = &a.model_fit {
                s.push_str(&format!(
                    "\nfive-term fit over tau {}..{} s ({} points, weighted RMS residual {})",
                    short(fit.tau_range_s.0, 4),
                    short(fit.tau_range_s.1, 4),
                    fit.points_used,
                    sig(fit.weighted_rms_residual, 3)
                ));
            }
            s.push_str("\nB is the flat ADEV value divided by 0.6643 (IEEE 952); N is read at tau = 1 s, K at tau = 3 s on their slope lines.\n");
        }
        (None, Some(note)) => s.push_str(&format!("noise terms: {note}\n")),
        (None, None) => {}
    }
    s
}

/// Kalibr imu.yaml gyroscope entries for one channel.
pub fn kalibr_yaml(a: &ChannelAnalysis, update_rate_hz: f64) -> Option<String> {
    let k = a.slope_lines.as_ref().map(|s| gyrolab::noise::kalibr_gyroscope(&s.coefficients))?;
    let n = k.gyroscope_noise_density?;
    let r = k.gyroscope_random_walk;
    Some(format!(
        "# Kalibr imu.yaml gyroscope entries written by gyrolab {} from {} ({})\n\
         # gyroscope_noise_density = angle random walk N in rad/s/sqrt(Hz);\n\
         # gyroscope_random_walk = rate random walk K in rad/s^2/sqrt(Hz){}\n\
         gyroscope_noise_density: {n:e}\n\
         gyroscope_random_walk: {}\n\
         update_rate: {}\n",
        env!("CARGO_PKG_VERSION"),
        a.file,
        a.channel,
        if r.is_none() { " (not present in the record: 0 written; choose a value from the datasheet)" } else { "" },
        r.map_or("0.0".to_string(), |x| format!("{x:e}")),
        short(update_rate_hz, 9)
    ))
}

/// A noise-coefficient set has at least one term.
pub fn has_terms(c: &NoiseCoefficients) -> bool {
    c.arw_deg_rt_h.is_some() || c.bias_instability_dph.is_some() || c.rrw_deg_h_rt_h.is_some()
}
