//! A deterministic raw rate-table log generator for the CLI tests (the idea of the core's
//! `testsim`, which is test-only there): holds at setpoints joined by constant-acceleration
//! ramps, an overshoot after each ramp decaying with a time constant (the settling the
//! segmentation must drop), white noise on the logged table rate; with the truth of every hold.
#![allow(dead_code)]

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

/// What a hold must be labelled: `rest_start`, `rest_end`, or a plateau of (run, stroke).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Label {
    RestStart,
    RestEnd,
    Plateau(u32, &'static str),
}

/// Shape and noise of a log.
#[derive(Debug, Clone)]
pub struct Profile {
    pub dt: f64,
    pub rest_s: f64,
    pub hold_s: f64,
    pub accel_dps2: f64,
    pub overshoot_dps: f64,
    pub overshoot_tau_s: f64,
    pub rate_noise_dps: f64,
}

impl Default for Profile {
    fn default() -> Self {
        Profile {
            dt: 0.01,
            rest_s: 8.0,
            hold_s: 10.0,
            accel_dps2: 50.0,
            overshoot_dps: 0.5,
            overshoot_tau_s: 0.1,
            rate_noise_dps: 0.01,
        }
    }
}

/// One hold with its truth.
#[derive(Debug, Clone)]
pub struct Hold {
    pub rate: f64,
    pub labels: Vec<Label>,
    pub t_start: f64,
    pub t_end: f64,
}

/// A simulated log.
#[derive(Debug, Clone)]
pub struct SimLog {
    pub time: Vec<f64>,
    pub true_rate: Vec<f64>,
    pub logged_rate: Vec<f64>,
    pub holds: Vec<Hold>,
}

/// Setpoints of a test: optional rests, `runs` runs rising through `rates` then falling back;
/// a turning setpoint is one hold shared by two strokes.
pub fn sweep(rates: &[f64], runs: u32, rest_start: bool, rest_end: bool) -> Vec<(f64, Vec<Label>)> {
    let mut seq: Vec<(f64, Vec<Label>)> = Vec::new();
    if rest_start {
        seq.push((0.0, vec![Label::RestStart]));
    }
    for run in 1..=runs {
        for (k, &r) in rates.iter().enumerate() {
            let l = Label::Plateau(run, "fwd");
            if k == 0 && run > 1 {
                seq.last_mut().unwrap().1.push(l);
                continue;
            }
            seq.push((r, vec![l]));
        }
        for (k, &r) in rates.iter().rev().enumerate() {
            let l = Label::Plateau(run, "rev");
            if k == 0 {
                seq.last_mut().unwrap().1.push(l);
                continue;
            }
            seq.push((r, vec![l]));
        }
    }
    if rest_end {
        seq.push((0.0, vec![Label::RestEnd]));
    }
    seq
}

/// Generates the log of a setpoint sequence.
pub fn generate(seq: &[(f64, Vec<Label>)], p: &Profile, seed: u64) -> SimLog {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let noise = Normal::new(0.0, p.rate_noise_dps).unwrap();
    let mut holds = Vec::new();
    let mut t = 0.0;
    let mut prev: Option<f64> = None;
    for (rate, labels) in seq {
        if let Some(pr) = prev {
            t += (rate - pr).abs() / p.accel_dps2;
        }
        let rest = labels.iter().any(|l| !matches!(l, Label::Plateau(..)));
        let dur = if rest { p.rest_s } else { p.hold_s };
        holds.push(Hold { rate: *rate, labels: labels.clone(), t_start: t, t_end: t + dur });
        t += dur;
        prev = Some(*rate);
    }
    let n = (t / p.dt).floor() as usize;
    let (mut time, mut true_rate, mut logged_rate) = (Vec::new(), Vec::new(), Vec::new());
    let mut h = 0;
    for i in 0..n {
        let ti = i as f64 * p.dt;
        while h + 1 < holds.len() && ti >= holds[h + 1].t_start {
            h += 1;
        }
        let cur = &holds[h];
        let w = if ti < cur.t_end || h + 1 == holds.len() {
            let step = if h > 0 { (cur.rate - holds[h - 1].rate).signum() } else { 0.0 };
            cur.rate + step * p.overshoot_dps * (-(ti - cur.t_start) / p.overshoot_tau_s).exp()
        } else {
            let next = holds[h + 1].rate;
            cur.rate + (next - cur.rate).signum() * p.accel_dps2 * (ti - cur.t_end)
        };
        time.push(ti);
        true_rate.push(w);
        logged_rate.push(w + noise.sample(&mut rng));
    }
    SimLog { time, true_rate, logged_rate, holds }
}

/// White noise samples (1 sigma `sigma`).
pub fn noise(n: usize, sigma: f64, seed: u64) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let d = Normal::new(0.0, sigma).unwrap();
    (0..n).map(|_| d.sample(&mut rng)).collect()
}

/// The log as CSV: `time_s,table_rate_dps,<names...>` with one output column per entry.
pub fn csv(sim: &SimLog, names: &[&str], outputs: &[Vec<f64>]) -> String {
    let mut s = format!("# simulated raw log\ntime_s,table_rate_dps,{}\n", names.join(","));
    for i in 0..sim.time.len() {
        s.push_str(&format!("{:.3},{:.6}", sim.time[i], sim.logged_rate[i]));
        for o in outputs {
            s.push_str(&format!(",{:.8}", o[i]));
        }
        s.push('\n');
    }
    s
}
