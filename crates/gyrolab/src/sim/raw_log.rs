//! Raw rate-table logs with known truth: a table that holds at setpoints joined by
//! constant-acceleration ramps, as a rate table's own log records it, with the truth of every
//! hold (its rate, when the table reached it, when it left, and its labels), for testing the
//! segmentation of raw logs (`crate::segment`) and everything read from them.
//!
//! Table profile: after each ramp the true rate overshoots by `overshoot_dps` (sign of the step)
//! and decays as exp(-t / overshoot_tau_s) (the settling the segmentation must drop); the logged
//! table rate is the true rate plus white noise. Deterministic per seed (ChaCha8; `exp` from the
//! portable version, as in the rest of the simulator).

use super::model::{finite, non_negative, positive, SimError};
use super::portable;
use crate::rate_test::Stroke;
use crate::segment::SegmentKind;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

/// Shape and noise of a simulated log.
#[derive(Debug, Clone)]
pub struct RawLogProfile {
    /// Sample interval, s.
    pub dt: f64,
    /// Duration of the rest holds, s.
    pub rest_s: f64,
    /// Duration of each rate hold, s.
    pub hold_s: f64,
    /// Table acceleration on ramps, deg/s^2.
    pub accel_dps2: f64,
    /// Overshoot at the end of a ramp, deg/s.
    pub overshoot_dps: f64,
    /// Time constant of its decay, s.
    pub overshoot_tau_s: f64,
    /// White noise on the logged table rate, deg/s (1 sigma).
    pub rate_noise_dps: f64,
}

impl Default for RawLogProfile {
    fn default() -> Self {
        RawLogProfile {
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

/// One hold of the simulated table, with its truth.
#[derive(Debug, Clone)]
pub struct RawLogHold {
    /// Setpoint, deg/s.
    pub rate: f64,
    /// Labels the segmentation must give it (two for a turning plateau: arriving, leaving).
    pub labels: Vec<SegmentKind>,
    /// Time the ramp into it ended, s.
    pub t_start: f64,
    /// Time the ramp out of it began (or the log ended), s.
    pub t_end: f64,
}

/// A simulated raw log.
#[derive(Debug, Clone)]
pub struct SimulatedRawLog {
    /// Sample times, s.
    pub time: Vec<f64>,
    /// True table rate, deg/s (what the gyro senses).
    pub true_rate: Vec<f64>,
    /// Logged table rate (true + noise), deg/s.
    pub logged_rate: Vec<f64>,
    /// The holds in order.
    pub holds: Vec<RawLogHold>,
}

fn plateau(run: u32, stroke: Stroke) -> SegmentKind {
    SegmentKind::Plateau { run, stroke }
}

/// The setpoint sequence of a test: optional rest, `runs` runs each rising through `rates`
/// (ascending) then falling back; the turning setpoints are one hold shared by two strokes.
pub fn raw_log_setpoints(rates: &[f64], runs: u32, rest_start: bool, rest_end: bool) -> Vec<(f64, Vec<SegmentKind>)> {
    let mut seq: Vec<(f64, Vec<SegmentKind>)> = Vec::new();
    if rest_start {
        seq.push((0.0, vec![SegmentKind::RestStart]));
    }
    for run in 1..=runs {
        for (k, &r) in rates.iter().enumerate() {
            let l = plateau(run, Stroke::Forward);
            if k == 0 && run > 1 {
                // The bottom turning point: the previous run's reverse stroke ends on it.
                if let Some(last) = seq.last_mut() {
                    last.1.push(l);
                }
                continue;
            }
            seq.push((r, vec![l]));
        }
        for (k, &r) in rates.iter().rev().enumerate() {
            let l = plateau(run, Stroke::Reverse);
            if k == 0 {
                if let Some(last) = seq.last_mut() {
                    last.1.push(l);
                }
                continue;
            }
            seq.push((r, vec![l]));
        }
    }
    if rest_end {
        seq.push((0.0, vec![SegmentKind::RestEnd]));
    }
    seq
}

impl RawLogProfile {
    /// Checks every field (finite; durations, interval, acceleration and time constant > 0;
    /// noise >= 0).
    pub fn validate(&self) -> Result<(), SimError> {
        positive("dt", self.dt)?;
        positive("rest_s", self.rest_s)?;
        positive("hold_s", self.hold_s)?;
        positive("accel_dps2", self.accel_dps2)?;
        finite("overshoot_dps", self.overshoot_dps)?;
        positive("overshoot_tau_s", self.overshoot_tau_s)?;
        non_negative("rate_noise_dps", self.rate_noise_dps)
    }
}

/// Simulates the log of a setpoint sequence (see [`raw_log_setpoints`]); fails on an invalid
/// profile or a setpoint that is not finite.
pub fn simulate_raw_log(
    seq: &[(f64, Vec<SegmentKind>)],
    p: &RawLogProfile,
    seed: u64,
) -> Result<SimulatedRawLog, SimError> {
    p.validate()?;
    for (rate, _) in seq {
        finite("setpoint rate", *rate)?;
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    // Timeline of holds.
    let mut holds = Vec::new();
    let mut t = 0.0;
    let mut prev: Option<f64> = None;
    for (rate, labels) in seq {
        if let Some(pr) = prev {
            t += (rate - pr).abs() / p.accel_dps2;
        }
        let rest = labels.iter().any(|l| !matches!(l, SegmentKind::Plateau { .. }));
        let dur = if rest { p.rest_s } else { p.hold_s };
        holds.push(RawLogHold { rate: *rate, labels: labels.clone(), t_start: t, t_end: t + dur });
        t += dur;
        prev = Some(*rate);
    }
    let n = (t / p.dt).floor() as usize;
    let (mut time, mut true_rate, mut logged_rate) =
        (Vec::with_capacity(n), Vec::with_capacity(n), Vec::with_capacity(n));
    let mut h = 0;
    for i in 0..n {
        let ti = i as f64 * p.dt;
        while h + 1 < holds.len() && ti >= holds[h + 1].t_start {
            h += 1;
        }
        let cur = &holds[h];
        let w = if ti < cur.t_end || h + 1 == holds.len() {
            // On the hold, with the overshoot of the ramp into it.
            let step = if h > 0 { (cur.rate - holds[h - 1].rate).signum() } else { 0.0 };
            cur.rate + step * p.overshoot_dps * portable::exp(-(ti - cur.t_start) / p.overshoot_tau_s)
        } else {
            // On the ramp to the next hold.
            let next = holds[h + 1].rate;
            cur.rate + (next - cur.rate).signum() * p.accel_dps2 * (ti - cur.t_end)
        };
        time.push(ti);
        true_rate.push(w);
        logged_rate.push(w + p.rate_noise_dps * normal(&mut rng));
    }
    Ok(SimulatedRawLog { time, true_rate, logged_rate, holds })
}

/// Gyro outputs for a true-rate sequence: offset + scale * rate + white noise of standard
/// deviation `sigma` (output units); fails when a parameter is not finite or sigma < 0.
pub fn gyro_output(true_rate: &[f64], scale: f64, offset: f64, sigma: f64, seed: u64) -> Result<Vec<f64>, SimError> {
    finite("scale", scale)?;
    finite("offset", offset)?;
    non_negative("sigma", sigma)?;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    Ok(true_rate.iter().map(|w| offset + scale * w + sigma * normal(&mut rng)).collect())
}

/// White noise of standard deviation `sigma` (n samples); fails when sigma < 0 or not finite.
pub fn white_noise(n: usize, sigma: f64, seed: u64) -> Result<Vec<f64>, SimError> {
    non_negative("sigma", sigma)?;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    Ok((0..n).map(|_| sigma * normal(&mut rng)).collect())
}

fn normal(rng: &mut ChaCha8Rng) -> f64 {
    StandardNormal.sample(rng)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn holds_follow_the_setpoints_and_bad_parameters_are_errors() {
        let seq = raw_log_setpoints(&[-10.0, 10.0], 2, true, true);
        let sim = simulate_raw_log(&seq, &RawLogProfile::default(), 1).unwrap();
        let rates: Vec<f64> = sim.holds.iter().map(|h| h.rate).collect();
        // Rest, run 1 up and down, run 2 up (from the shared turning hold) and down, rest.
        assert_eq!(rates, vec![0.0, -10.0, 10.0, -10.0, 10.0, -10.0, 0.0]);
        assert_eq!(sim.time.len(), sim.logged_rate.len());
        let p = RawLogProfile { dt: 0.0, ..RawLogProfile::default() };
        let e = simulate_raw_log(&seq, &p, 1).unwrap_err();
        assert!(e.to_string().contains("`dt`"), "{e}");
        let bad_rate = vec![(f64::NAN, vec![SegmentKind::RestStart])];
        assert!(simulate_raw_log(&bad_rate, &RawLogProfile::default(), 1).is_err());
        assert!(gyro_output(&sim.true_rate, 1.0, 0.0, -1.0, 1).is_err());
        assert!(white_noise(3, f64::NAN, 1).is_err());
    }
}
