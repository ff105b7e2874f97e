//! Helpers shared by the library tests: an independent least-squares line, the per-rate means
//! of a long-layout record read by hand, and simulated raw logs written the way a rate table's
//! logger writes them. Nothing here calls gyrolab-eval: these are the independent side of every
//! comparison.
#![allow(dead_code)]

use gyrolab::segment::SegmentKind;
use gyrolab::sim::{raw_log_setpoints, simulate_raw_log, white_noise, RawLogProfile, SimulatedRawLog};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The repository root (the tests read `data/paper` and `examples` from it).
pub fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A file of `data/paper`.
pub fn paper_file(name: &str) -> PathBuf {
    repo_root().join("data/paper").join(name)
}

/// Ordinary least-squares line y = a + b x, written out: b = Sxy / Sxx about the means.
/// Returns (slope b, intercept a).
pub fn lsq_line(x: &[f64], y: &[f64]) -> (f64, f64) {
    assert_eq!(x.len(), y.len());
    let n = x.len() as f64;
    let mx = x.iter().sum::<f64>() / n;
    let my = y.iter().sum::<f64>() / n;
    let sxx: f64 = x.iter().map(|v| (v - mx) * (v - mx)).sum();
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let b = sxy / sxx;
    (b, my - b * mx)
}

/// Sum of squared deviations of `x` about its mean.
pub fn sxx(x: &[f64]) -> f64 {
    let m = x.iter().sum::<f64>() / x.len() as f64;
    x.iter().map(|v| (v - m) * (v - m)).sum()
}

/// One row of a long-layout record: (rate, run, stroke, output).
pub type LongRow = (f64, u32, String, f64);

/// Reads a long-layout record (`rate_dps,run,stroke,output_*`, `#` comments) by hand.
pub fn read_long(path: &Path) -> Vec<LongRow> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines().filter(|l| !l.trim_start().starts_with('#') && !l.trim().is_empty());
    let header = lines.next().unwrap();
    assert!(header.starts_with("rate_dps,run,stroke,output_"), "{header}");
    lines
        .map(|l| {
            let c: Vec<&str> = l.split(',').collect();
            (c[0].parse().unwrap(), c[1].parse().unwrap(), c[2].to_string(), c[3].parse().unwrap())
        })
        .collect()
}

/// Per-rate means of every output at that rate (rates ascending), and per-rate forward and
/// reverse means, from the rows of a long-layout record. Each rate's point mean is the mean of
/// its forward and reverse stroke means (paper eq. 4), which equals the mean of all its
/// outputs when both strokes have the same number of samples.
pub struct RateMeans {
    pub rates: Vec<f64>,
    pub forward: Vec<f64>,
    pub reverse: Vec<f64>,
    pub mean: Vec<f64>,
}

pub fn rate_means(rows: &[LongRow]) -> RateMeans {
    // Key by the rate's bits (rates are exact decimal values written once per row).
    let mut by_rate: BTreeMap<i64, (f64, Vec<f64>, Vec<f64>)> = BTreeMap::new();
    for (rate, _, stroke, out) in rows {
        let e = by_rate.entry((rate * 1e6).round() as i64).or_insert((*rate, Vec::new(), Vec::new()));
        match stroke.as_str() {
            "fwd" => e.1.push(*out),
            "rev" => e.2.push(*out),
            _ => {}
        }
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let mut m = RateMeans { rates: Vec::new(), forward: Vec::new(), reverse: Vec::new(), mean: Vec::new() };
    for (_, (rate, f, r)) in by_rate {
        m.rates.push(rate);
        m.forward.push(mean(&f));
        m.reverse.push(mean(&r));
        m.mean.push((mean(&f) + mean(&r)) / 2.0);
    }
    m
}

/// Writes a simulated raw log as CSV: `time_s,table_rate_dps,<names...>`, one output column per
/// entry of `outputs` (a comment line, then the header: the first data line is line 3).
pub fn write_raw_log(path: &Path, sim: &SimulatedRawLog, names: &[&str], outputs: &[Vec<f64>]) {
    let mut s = format!("# simulated raw log\ntime_s,table_rate_dps,{}\n", names.join(","));
    for i in 0..sim.time.len() {
        s.push_str(&format!("{:.3},{:.6}", sim.time[i], sim.logged_rate[i]));
        for o in outputs {
            s.push_str(&format!(",{:.8}", o[i]));
        }
        s.push('\n');
    }
    std::fs::write(path, s).unwrap();
}

/// Output noise of the simulated gyros, V (1 sigma per sample).
pub const SIGMA_U: f64 = 0.002;
/// Scale factor of the single-axis simulated gyro, V/(deg/s).
pub const K: f64 = 0.0075;
/// Its null, V.
pub const F0: f64 = 2.5;
/// Smallest number of samples a plateau mean keeps in the default profile: holds of 10 s at
/// 100 Hz, less the 1 s settling time and the segmentation's margin at the ramps.
pub const MIN_PLATEAU_SAMPLES: f64 = 850.0;

/// A single-axis raw log (output F0 + K w + white noise of SIGMA_U) of the setpoints of
/// `runs` runs over `rates`, rests at both ends; `second` adds a second output column in mV.
pub fn single_axis_log(
    path: &Path,
    rates: &[f64],
    runs: u32,
    seed: u64,
    second: bool,
) -> (SimulatedRawLog, Vec<(f64, Vec<SegmentKind>)>) {
    let seq = raw_log_setpoints(rates, runs, true, true);
    let sim = simulate_raw_log(&seq, &RawLogProfile::default(), seed).unwrap();
    let e = white_noise(sim.time.len(), SIGMA_U, seed + 1).unwrap();
    let gx: Vec<f64> = sim.true_rate.iter().zip(&e).map(|(w, e)| F0 + K * w + e).collect();
    if second {
        let e2 = white_noise(sim.time.len(), SIGMA_U * 1e3, seed + 2).unwrap();
        let gy: Vec<f64> = sim.true_rate.iter().zip(&e2).map(|(w, e)| 1200.0 + 9.0 * w + e).collect();
        write_raw_log(path, &sim, &["gx_v", "gy_mv"], &[gx, gy]);
    } else {
        write_raw_log(path, &sim, &["gx_v"], &[gx]);
    }
    (sim, seq)
}

/// Misalignment of gyro i towards table axis j, rad, and the triad's scale factors and biases.
pub const ANGLE: [[f64; 3]; 3] = [[0.0, 3e-3, -2e-3], [4e-3, 0.0, 2.5e-3], [-5e-3, 3.5e-3, 0.0]];
pub const KT: [f64; 3] = [0.0075, 0.0076, 0.0074];
pub const BT: [f64; 3] = [2.50, 2.51, 2.49];
pub const TRIAD_RATES: [f64; 6] = [-300.0, -100.0, -30.0, 30.0, 100.0, 300.0];

/// The true matrix S: S_ii = K_i, S_ij = K_i tan(angle_ij).
pub fn s_true() -> [[f64; 3]; 3] {
    let mut s = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            s[i][j] = if i == j { KT[i] } else { KT[i] * ANGLE[i][j].tan() };
        }
    }
    s
}

/// A log of rotations about table axis `axis` (0, 1, 2) seen by the triad: output i =
/// b_i + S_i,axis w + noise; one run over TRIAD_RATES, rests at both ends.
pub fn triad_log(dir: &Path, axis: usize, seed: u64) -> PathBuf {
    let seq = raw_log_setpoints(&TRIAD_RATES, 1, true, true);
    let sim = simulate_raw_log(&seq, &RawLogProfile::default(), seed).unwrap();
    let s = s_true();
    let outs: Vec<Vec<f64>> = (0..3)
        .map(|i| {
            let e = white_noise(sim.time.len(), SIGMA_U, seed * 10 + i as u64).unwrap();
            sim.true_rate.iter().zip(&e).map(|(w, e)| BT[i] + s[i][axis] * w + e).collect()
        })
        .collect();
    let path = dir.join(format!("turn_{}.csv", ["x", "y", "z"][axis]));
    write_raw_log(&path, &sim, &["gx_v", "gy_v", "gz_v"], &outs);
    path
}

/// Spells a request field as a command-line flag.
pub fn flag(f: &str) -> String {
    format!("--{}", f.replace('_', "-"))
}
