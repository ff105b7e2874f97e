//! How often a noise term is reported as a value when the record does not hold its process, and
//! how often the reading holds the truth when it does (issue 55; bench/term_detection_study.sh;
//! the table goes into docs/METHODS.md section 3, "Terms reported only where the record shows
//! them").
//!
//! Six simulated gyros at 100 Hz (gyrolab's simulator, [`gyrolab::sim`]): white noise alone;
//! white noise and a rate random walk (two strengths: the curve's minimum near 260 s and near
//! 60 s); white noise and bias instability (flicker over every
//! scale, from 0.1 s to the record's length); all three; white noise and a rate ramp. Each for
//! 10 min, 30 min, 1 h and 4 h, SEEDS records each (default 100). For bias instability B and
//! rate random walk K, of the slope lines (`gyrolab allan`'s noise terms, [`slope_line_terms`])
//! and of the GMWM ([`gmwm`], its chosen model): how often the term is reported as a value where
//! the process is absent (the false-detection rate, goal at most 5 %), and where it is present,
//! how often a value is reported, how often the GMWM's 68.3 % interval (or the bound of a term its
//! model leaves out) holds the truth, and how often the slope lines' bound, where they give one,
//! lies at or above it.
//!
//! Usage: term_detection_study [SEEDS] (default 100); one line of the table per case, term and
//! length.

use gyrolab::allan::{deviation_from_rate, AllanOptions, DeviationKind, TauList};
use gyrolab::gmwm::{gmwm, Process};
use gyrolab::noise::{slope_line_terms, Reading};
use gyrolab::sim::{SensorModel, StaticBlock, StaticGenerator, StaticSpec};
use rayon::prelude::*;

/// The study's sample rate, Hz.
const RATE_HZ: f64 = 100.0;

/// One simulated gyro: its label, its noise terms (N deg/sqrt(h), B deg/h, K deg/h/sqrt(h), R
/// deg/h/h).
struct Case {
    label: &'static str,
    n: f64,
    b: f64,
    k: f64,
    r: f64,
}

/// What one record said of one term.
#[derive(Default, Clone, Copy)]
struct Said {
    /// The slope lines gave a value.
    slope_value: bool,
    /// The slope lines gave a bound at or above the truth.
    slope_bound_holds: bool,
    /// The slope lines gave a bound.
    slope_bound: bool,
    /// Relative error of the slope lines' value.
    slope_error: f64,
    /// The GMWM's chosen model holds the term.
    gmwm_value: bool,
    /// The GMWM's interval (or its left-out bound) holds the truth.
    gmwm_covers: bool,
}

fn record(case: &Case, hours: f64, seed: u64) -> Option<Vec<f64>> {
    let model = SensorModel {
        arw_deg_rt_h: case.n,
        bias_instability_dph: case.b,
        rrw_deg_h_rt_h: case.k,
        rate_ramp_dph_per_h: case.r,
        flicker_tau_min_s: 0.1,
        flicker_tau_max_s: (hours * 3600.0).max(1.0),
        ..SensorModel::default()
    };
    let spec = StaticSpec { sample_rate_hz: RATE_HZ, duration_s: hours * 3600.0, ..StaticSpec::default() };
    let mut generator = StaticGenerator::new(&model, &spec, seed).ok()?;
    let mut samples = Vec::with_capacity(spec.samples() as usize);
    let mut block = StaticBlock::default();
    while generator.next_block(&mut block, 1 << 16) > 0 {
        samples.extend_from_slice(&block.output);
    }
    Some(samples)
}

/// B (deg/s) and K (deg/s/sqrt(s)) as the slope lines and the GMWM read them from one record.
fn read(case: &Case, hours: f64, seed: u64) -> Option<[Said; 2]> {
    let samples = record(case, hours, seed)?;
    let opts =
        AllanOptions { kind: DeviationKind::Oadev, taus: TauList::Octave, confidence: Some(0.683), max_factor: None };
    let curve = deviation_from_rate(samples, 1.0 / RATE_HZ, &opts).ok()?;
    let slope = slope_line_terms(&curve).ok()?;
    let g = gmwm(&curve, 0.683).ok();
    let truths = [case.b / 3600.0, case.k / 3600.0 / 60.0];
    let mut out = [Said::default(); 2];
    for (i, (reading, process)) in
        [(slope.bias_instability, Process::Flicker), (slope.rrw, Process::RandomWalk)].into_iter().enumerate()
    {
        let truth = truths[i];
        let said = &mut out[i];
        match reading {
            Reading::Value { value, .. } => {
                said.slope_value = true;
                said.slope_error = if truth > 0.0 { value / truth - 1.0 } else { f64::NAN };
            }
            Reading::UpperBound { value, .. } => {
                said.slope_bound = true;
                said.slope_bound_holds = value >= truth;
            }
            Reading::Absent { .. } => {}
        }
        if let Some(g) = &g {
            if let Some(p) = g.parameter(process) {
                said.gmwm_value = true;
                said.gmwm_covers = p.lower <= truth && truth <= p.upper;
            } else if let Some(b) = g.left_out.iter().find(|b| b.process == process) {
                said.gmwm_covers = truth <= b.upper;
            }
        }
    }
    Some(out)
}

fn pct(k: usize, n: usize) -> String {
    if n == 0 {
        "-".into()
    } else {
        format!("{:.1} % ({k} of {n})", 100.0 * k as f64 / n as f64)
    }
}

fn main() {
    let seeds: u64 = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(100);
    let cases = [
        Case { label: "white (N 0.25 deg/sqrt(h))", n: 0.25, b: 0.0, k: 0.0, r: 0.0 },
        Case { label: "white + random walk (N 0.25, K 6 deg/h/sqrt(h))", n: 0.25, b: 0.0, k: 6.0, r: 0.0 },
        // A consumer-grade MEMS gyro: the curve's minimum near 60 s, well inside 30 min.
        Case { label: "white + strong random walk (N 0.6, K 60)", n: 0.6, b: 0.0, k: 60.0, r: 0.0 },
        Case { label: "white + bias instability (N 0.25, B 4 deg/h)", n: 0.25, b: 4.0, k: 0.0, r: 0.0 },
        Case { label: "white + bias instability + random walk (N 0.25, B 4, K 6)", n: 0.25, b: 4.0, k: 6.0, r: 0.0 },
        Case { label: "white + rate ramp (N 0.25, R 20 deg/h/h)", n: 0.25, b: 0.0, k: 0.0, r: 20.0 },
    ];
    let lengths = [(10.0 / 60.0, "10 min"), (0.5, "30 min"), (1.0, "1 h"), (4.0, "4 h")];
    println!("| gyro | term | record | slope lines: a value where the process is absent | slope lines: a value where present (bias / RMSE of the values) | slope lines: bound at or above the truth, where bounded | GMWM: in the chosen model where absent | GMWM: in the chosen model where present | GMWM 68.3 % interval or left-out bound holds the truth |");
    println!("|---|---|---|---|---|---|---|---|---|");
    for case in &cases {
        for &(hours, length) in &lengths {
            let said: Vec<[Said; 2]> =
                (0..seeds).into_par_iter().filter_map(|s| read(case, hours, 55_000 + s)).collect();
            let n = said.len();
            for (i, (term, present)) in [("B", case.b > 0.0), ("K", case.k > 0.0)].into_iter().enumerate() {
                let values = said.iter().filter(|s| s[i].slope_value).count();
                let bounds = said.iter().filter(|s| s[i].slope_bound).count();
                let holds = said.iter().filter(|s| s[i].slope_bound_holds).count();
                let gm = said.iter().filter(|s| s[i].gmwm_value).count();
                let covers = said.iter().filter(|s| s[i].gmwm_covers).count();
                let errors: Vec<f64> = said.iter().filter(|s| s[i].slope_value).map(|s| s[i].slope_error).collect();
                let (bias, rmse) = if errors.is_empty() {
                    (f64::NAN, f64::NAN)
                } else {
                    let m = errors.len() as f64;
                    (errors.iter().sum::<f64>() / m, (errors.iter().map(|e| e * e).sum::<f64>() / m).sqrt())
                };
                let (absent_slope, present_slope, absent_gm, present_gm, cover) = if present {
                    (
                        "-".to_string(),
                        format!("{} ({:+.1} % / {:.1} %)", pct(values, n), 100.0 * bias, 100.0 * rmse),
                        "-".to_string(),
                        pct(gm, n),
                        pct(covers, n),
                    )
                } else {
                    ("-".to_string(), "-".to_string(), "-".to_string(), "-".to_string(), "-".to_string())
                };
                let (absent_slope, absent_gm) =
                    if present { (absent_slope, absent_gm) } else { (pct(values, n), pct(gm, n)) };
                let bound = if present { pct(holds, bounds) } else { "-".to_string() };
                println!(
                    "| {} | {term} | {length} | {absent_slope} | {present_slope} | {bound} | {absent_gm} | {present_gm} | {cover} |",
                    case.label
                );
            }
        }
    }
}
