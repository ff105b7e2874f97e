//! Sample generation: the per-sample sensor engine and the two streaming generators.
//!
//! Sources: IEEE Std 952-1997 annex C (white rate noise from N, rate random walk from K, rate
//! ramp R, quantization); Brown & Hwang (Gauss-Markov discretisation
//! x[k+1] = phi x[k] + s sqrt(1 - phi^2) w[k], phi = e^(-dt/T), applied over the hold of each
//! flicker process: see `flicker` for the held updates).

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

use super::flicker::FlickerDesign;
use super::model::{RateTableSpec, SensorModel, SettlingRows, SimError, StaticSpec, TemperatureProfile};
use super::portable;
use crate::rate_test::{RateObservation, RestRecord, Stroke};
use crate::units;

/// ChaCha stream of the per-sample noise.
const NOISE_STREAM: u64 = 0;
/// ChaCha stream of the run-to-run draws (separate, so that they do not shift the noise).
const RUN_STREAM: u64 = 1;

fn rng(seed: u64, stream: u64) -> ChaCha8Rng {
    let mut r = ChaCha8Rng::seed_from_u64(seed);
    r.set_stream(stream);
    r
}

fn normal(rng: &mut ChaCha8Rng) -> f64 {
    StandardNormal.sample(rng)
}

/// One first-order Gauss-Markov process of the flicker sum, advanced every `hold` samples.
#[derive(Debug, Clone)]
struct GaussMarkov {
    /// e^(-hold dt / T): the transition over one hold.
    phi: f64,
    /// Driving standard deviation over one hold, s sqrt(1 - phi^2), deg/s.
    drive_sigma: f64,
    /// Samples between updates.
    hold: u64,
    /// Samples until the next update.
    left: u64,
    /// Current value, deg/s.
    state: f64,
}

/// The flicker sum: its processes, their current sum and the samples until the next update of
/// any of them.
#[derive(Debug, Clone)]
struct FlickerSum {
    terms: Vec<GaussMarkov>,
    /// Sum of the current states, deg/s.
    sum: f64,
    /// Samples until the next update (u64::MAX without processes).
    until_update: u64,
    /// Samples from the previous update to the next.
    step: u64,
}

impl FlickerSum {
    fn new(terms: Vec<GaussMarkov>) -> FlickerSum {
        let step = terms.iter().map(|g| g.hold).min().unwrap_or(u64::MAX);
        let sum = terms.iter().map(|g| g.state).sum();
        FlickerSum { terms, sum, until_update: step, step }
    }

    /// Advances every process whose hold has run out (in order), then sums them again.
    fn update(&mut self, noise: &mut NormalBatch) {
        let mut next = u64::MAX;
        let mut sum = 0.0;
        for gm in &mut self.terms {
            gm.left -= self.step;
            if gm.left == 0 {
                gm.state = gm.phi * gm.state + gm.drive_sigma * noise.draw();
                gm.left = gm.hold;
            }
            next = next.min(gm.left);
            sum += gm.state;
        }
        self.sum = sum;
        self.until_update = next;
        self.step = next;
    }
}

/// The per-sample sensor model with its noise state.
#[derive(Debug, Clone)]
struct Engine {
    dt_s: f64,
    scale_factor: f64,
    null: f64,
    scale_factor_error: f64,
    asymmetry_half: f64,
    k2: f64,
    k3: f64,
    rail_low: f64,
    rail_high: f64,
    hysteresis_half_dps: f64,
    bias_dps: f64,
    run_bias_sigma_dps: f64,
    run_scale_factor_sigma: f64,
    white_sigma_dps: f64,
    flicker: Option<FlickerDesign>,
    flicker_sum: FlickerSum,
    rrw_sigma_dps: f64,
    rrw_state_dps: f64,
    ramp_dps_per_s: f64,
    output_step: f64,
    angle_step_deg: f64,
    angle_residue_deg: f64,
    bias_tc_dps_per_c: f64,
    scale_factor_tc_per_c: f64,
    reference_temp_c: f64,
    earth_dps: f64,
    run_bias_dps: f64,
    run_scale_factor: f64,
    noise: NormalBatch,
    runs: ChaCha8Rng,
}

/// Standard normal draws from one stream, made in batches (the same values in the same order as
/// one draw at a time: only the noise in `Engine::sample` draws from this stream).
#[derive(Debug, Clone)]
struct NormalBatch {
    rng: ChaCha8Rng,
    values: Vec<f64>,
    next: usize,
}

/// Draws per batch.
const NORMAL_BATCH: usize = 4096;

impl NormalBatch {
    fn new(rng: ChaCha8Rng) -> NormalBatch {
        NormalBatch { rng, values: Vec::new(), next: 0 }
    }

    /// The next standard normal draw.
    #[inline]
    fn draw(&mut self) -> f64 {
        if self.next == self.values.len() {
            self.values.clear();
            let rng = &mut self.rng;
            self.values.extend((0..NORMAL_BATCH).map(|_| -> f64 { StandardNormal.sample(rng) }));
            self.next = 0;
        }
        let z = self.values[self.next];
        self.next += 1;
        z
    }
}

impl Engine {
    fn new(model: &SensorModel, sample_rate_hz: f64, latitude_deg: Option<f64>, seed: u64) -> Result<Engine, SimError> {
        model.validate()?;
        model.validate_for_sample_rate(sample_rate_hz)?;
        let dt_s = 1.0 / sample_rate_hz;
        let mut noise = rng(seed, NOISE_STREAM);
        let bi_dps = units::dph_to_dps(model.bias_instability_dph);
        let (flicker, gauss_markov) = if bi_dps > 0.0 {
            let design = FlickerDesign::new(bi_dps, model.flicker_tau_min_s, model.flicker_tau_max_s);
            let s = design.sigma_each_dps;
            let gm = design
                .correlation_times_s
                .iter()
                .zip(design.hold_samples(dt_s))
                .map(|(&t, hold)| {
                    let phi = portable::exp(-(hold as f64) * dt_s / t);
                    // Start in the stationary distribution, so the record is stationary from t = 0.
                    let state = s * normal(&mut noise);
                    GaussMarkov { phi, drive_sigma: s * (1.0 - phi * phi).sqrt(), hold, left: hold, state }
                })
                .collect();
            (Some(design), gm)
        } else {
            (None, Vec::new())
        };
        let earth_dps =
            latitude_deg.map_or(0.0, |lat| units::dph_to_dps(units::EARTH_RATE_DPH) * portable::sin_deg(lat));
        Ok(Engine {
            dt_s,
            scale_factor: model.scale_factor_per_dps,
            null: model.null,
            scale_factor_error: units::ppm_to_ratio(model.scale_factor_error_ppm),
            asymmetry_half: units::ppm_to_ratio(model.scale_factor_asymmetry_ppm) / 2.0,
            k2: model.nonlinearity_quadratic_per_dps,
            k3: model.nonlinearity_cubic_per_dps2,
            rail_low: model.output_rail_low.unwrap_or(f64::NEG_INFINITY),
            rail_high: model.output_rail_high.unwrap_or(f64::INFINITY),
            hysteresis_half_dps: model.hysteresis_dps / 2.0,
            bias_dps: units::dph_to_dps(model.bias_dph),
            run_bias_sigma_dps: units::dph_to_dps(model.run_to_run_bias_sigma_dph),
            run_scale_factor_sigma: units::ppm_to_ratio(model.run_to_run_scale_factor_sigma_ppm),
            white_sigma_dps: units::arw_deg_rt_h_to_sample_sigma_dps(model.arw_deg_rt_h, dt_s),
            flicker,
            flicker_sum: FlickerSum::new(gauss_markov),
            rrw_sigma_dps: units::rrw_dph_rt_h_to_increment_sigma_dps(model.rrw_deg_h_rt_h, dt_s),
            rrw_state_dps: 0.0,
            ramp_dps_per_s: units::rate_ramp_dph_per_h_to_dps_per_s(model.rate_ramp_dph_per_h),
            output_step: model.output_quantization_step,
            angle_step_deg: model.angle_quantization_deg,
            angle_residue_deg: 0.0,
            bias_tc_dps_per_c: units::dph_to_dps(model.bias_temp_coeff_dph_per_c),
            scale_factor_tc_per_c: units::ppm_to_ratio(model.scale_factor_temp_coeff_ppm_per_c),
            reference_temp_c: model.reference_temp_c,
            earth_dps,
            run_bias_dps: 0.0,
            run_scale_factor: 0.0,
            noise: NormalBatch::new(noise),
            runs: rng(seed, RUN_STREAM),
        })
    }

    /// Draws the run-to-run bias and scale-factor changes for a new run (power-on).
    fn start_run(&mut self) {
        self.run_bias_dps = self.run_bias_sigma_dps * normal(&mut self.runs);
        self.run_scale_factor = self.run_scale_factor_sigma * normal(&mut self.runs);
    }

    /// One output sample at time t_s for table rate `table_dps`, stroke sign (+1 forward,
    /// -1 reverse, 0 none) and temperature `temp_c`; advances the noise state.
    #[inline]
    fn sample(&mut self, t_s: f64, table_dps: f64, stroke_sign: f64, temp_c: f64) -> f64 {
        let d_temp = temp_c - self.reference_temp_c;
        // Sensed rate: input + bias terms + noise, deg/s.
        let mut noise = 0.0;
        if self.white_sigma_dps > 0.0 {
            noise += self.white_sigma_dps * self.noise.draw();
        }
        noise += self.flicker_sum.sum;
        self.flicker_sum.until_update -= 1;
        if self.flicker_sum.until_update == 0 {
            self.flicker_sum.update(&mut self.noise);
        }
        if self.rrw_sigma_dps > 0.0 {
            noise += self.rrw_state_dps;
            self.rrw_state_dps += self.rrw_sigma_dps * self.noise.draw();
        }
        let bias = self.bias_dps + self.run_bias_dps + self.bias_tc_dps_per_c * d_temp + self.ramp_dps_per_s * t_s;
        let mut w = table_dps + self.earth_dps + stroke_sign * self.hysteresis_half_dps + bias + noise;
        if self.angle_step_deg > 0.0 {
            // Angle quantization: emit whole angle steps, carry the remainder (bounded).
            self.angle_residue_deg += w * self.dt_s;
            let steps = (self.angle_residue_deg / self.angle_step_deg).floor();
            self.angle_residue_deg -= steps * self.angle_step_deg;
            w = steps * self.angle_step_deg / self.dt_s;
        }
        let k_run = self.scale_factor
            * (1.0 + self.scale_factor_error + self.run_scale_factor + self.scale_factor_tc_per_c * d_temp);
        let k = if w >= 0.0 { k_run * (1.0 + self.asymmetry_half) } else { k_run * (1.0 - self.asymmetry_half) };
        let nonlinear = w * (1.0 + w * (self.k2 + w * self.k3));
        let mut out = (self.null + k * nonlinear).clamp(self.rail_low, self.rail_high);
        if self.output_step > 0.0 {
            out = (out / self.output_step).round() * self.output_step;
        }
        out
    }
}

/// One sample of a static record.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StaticSample {
    /// Time from the record start, s.
    pub time_s: f64,
    /// Gyro output, in the model's output unit.
    pub output: f64,
    /// Sensor temperature, degC, when the specification records it.
    pub temp_c: Option<f64>,
}

/// A streaming static record: yields `StaticSpec::samples()` samples in bounded memory.
#[derive(Debug, Clone)]
pub struct StaticGenerator {
    engine: Engine,
    sample_rate_hz: f64,
    temperature: TemperatureProfile,
    record_temperature: bool,
    index: u64,
    count: u64,
}

impl StaticGenerator {
    /// Sets up a static record of `model` per `spec` with the given seed (validates both).
    pub fn new(model: &SensorModel, spec: &StaticSpec, seed: u64) -> Result<StaticGenerator, SimError> {
        spec.validate()?;
        let mut engine = Engine::new(model, spec.sample_rate_hz, spec.latitude_deg, seed)?;
        engine.start_run();
        Ok(StaticGenerator {
            engine,
            sample_rate_hz: spec.sample_rate_hz,
            temperature: spec.temperature.clone(),
            record_temperature: spec.record_temperature,
            index: 0,
            count: spec.samples(),
        })
    }

    /// The flicker (bias instability) approximation in use, if B > 0.
    pub fn flicker_design(&self) -> Option<&FlickerDesign> {
        self.engine.flicker.as_ref()
    }

    /// The vertical earth-rate component in the signal, deg/s (0 without a latitude).
    pub fn earth_rate_dps(&self) -> f64 {
        self.engine.earth_dps
    }

    /// Whether samples carry the temperature.
    pub fn records_temperature(&self) -> bool {
        self.record_temperature
    }

    /// Samples still to come.
    pub fn remaining(&self) -> u64 {
        self.count - self.index
    }
}

impl Iterator for StaticGenerator {
    type Item = StaticSample;

    #[inline]
    fn next(&mut self) -> Option<StaticSample> {
        if self.index >= self.count {
            return None;
        }
        let time_s = self.index as f64 / self.sample_rate_hz;
        let temp_c = self.temperature.temp_at(time_s);
        let output = self.engine.sample(time_s, 0.0, 0.0, temp_c);
        self.index += 1;
        Some(StaticSample { time_s, output, temp_c: self.record_temperature.then_some(temp_c) })
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let n = usize::try_from(self.remaining()).unwrap_or(usize::MAX);
        (n, usize::try_from(self.remaining()).ok())
    }
}

/// The part of a rate-table test a sample belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SimStroke {
    /// Forward stroke (rates rising).
    Forward,
    /// Reverse stroke (rates falling).
    Reverse,
    /// Rest record before the test (table still).
    RestStart,
    /// Rest record after the test (table still).
    RestEnd,
}

impl SimStroke {
    /// The label written in the stroke column: `fwd`, `rev`, `rest_start`, `rest_end`.
    pub fn label(self) -> &'static str {
        match self {
            SimStroke::Forward => Stroke::Forward.label(),
            SimStroke::Reverse => Stroke::Reverse.label(),
            SimStroke::RestStart => "rest_start",
            SimStroke::RestEnd => "rest_end",
        }
    }

    /// The rate-test stroke, or none for a rest record.
    pub fn stroke(self) -> Option<Stroke> {
        match self {
            SimStroke::Forward => Some(Stroke::Forward),
            SimStroke::Reverse => Some(Stroke::Reverse),
            SimStroke::RestStart | SimStroke::RestEnd => None,
        }
    }

    fn sign(self) -> f64 {
        match self {
            SimStroke::Forward => 1.0,
            SimStroke::Reverse => -1.0,
            SimStroke::RestStart | SimStroke::RestEnd => 0.0,
        }
    }
}

/// One sample of a rate-table test (a row of the long layout `rate_dps,run,stroke,output_<unit>`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RateTableSample {
    /// Time from the test start, s.
    pub time_s: f64,
    /// Commanded table rate of the plateau, deg/s (0 for rest records).
    pub rate_dps: f64,
    /// Run number, 1-based (rest_start belongs to run 1, rest_end to the last run).
    pub run: u32,
    /// Stroke or rest record.
    pub stroke: SimStroke,
    /// Gyro output, in the model's output unit.
    pub output: f64,
    /// Sensor temperature, degC.
    pub temp_c: f64,
    /// Whether the table was still settling on the plateau's rate (only with `SettlingRows::Flag`).
    pub settling: bool,
}

impl RateTableSample {
    /// The observation for `rate_test`, or none for a rest record.
    pub fn observation(&self) -> Option<RateObservation> {
        self.stroke.stroke().map(|stroke| RateObservation {
            rate_dps: self.rate_dps,
            run: self.run,
            stroke,
            output: self.output,
        })
    }
}

/// One plateau of the test schedule.
#[derive(Debug, Clone, Copy)]
struct Plateau {
    rate_dps: f64,
    from_dps: f64,
    run: u32,
    stroke: SimStroke,
    settle: u64,
    keep: u64,
}

/// A streaming rate-table test: runs of forward then reverse strokes, optional rest records.
#[derive(Debug, Clone)]
pub struct RateTableGenerator {
    engine: Engine,
    sample_rate_hz: f64,
    temperature: TemperatureProfile,
    flag_settling: bool,
    plateaus: Vec<Plateau>,
    plateau: usize,
    within: u64,
    time_index: u64,
}

impl RateTableGenerator {
    /// Sets up a rate-table test of `model` per `spec` with the given seed (validates both).
    pub fn new(model: &SensorModel, spec: &RateTableSpec, seed: u64) -> Result<RateTableGenerator, SimError> {
        spec.validate()?;
        let rates = spec.sorted_rates()?;
        let engine = Engine::new(model, spec.sample_rate_hz, spec.latitude_deg, seed)?;
        let settle = spec.settling_samples();
        let keep = u64::from(spec.samples_per_plateau);
        let mut plateaus = Vec::new();
        let mut last = 0.0;
        let mut push = |rate_dps: f64, run: u32, stroke: SimStroke, settle: u64, keep: u64| {
            plateaus.push(Plateau { rate_dps, from_dps: last, run, stroke, settle, keep });
            last = rate_dps;
        };
        if spec.rest_samples > 0 {
            push(0.0, 1, SimStroke::RestStart, 0, u64::from(spec.rest_samples));
        }
        for run in 1..=spec.runs {
            for &r in &rates {
                push(r, run, SimStroke::Forward, settle, keep);
            }
            for &r in rates.iter().rev() {
                push(r, run, SimStroke::Reverse, settle, keep);
            }
        }
        if spec.rest_samples > 0 {
            push(0.0, spec.runs, SimStroke::RestEnd, settle, u64::from(spec.rest_samples));
        }
        Ok(RateTableGenerator {
            engine,
            sample_rate_hz: spec.sample_rate_hz,
            temperature: spec.temperature.clone(),
            flag_settling: spec.settling == SettlingRows::Flag,
            plateaus,
            plateau: 0,
            within: 0,
            time_index: 0,
        })
    }

    /// The flicker (bias instability) approximation in use, if B > 0.
    pub fn flicker_design(&self) -> Option<&FlickerDesign> {
        self.engine.flicker.as_ref()
    }

    /// The vertical earth-rate component in the signal, deg/s (0 without a latitude).
    pub fn earth_rate_dps(&self) -> f64 {
        self.engine.earth_dps
    }

    /// Whether settling samples are yielded (flagged) rather than dropped.
    pub fn flags_settling(&self) -> bool {
        self.flag_settling
    }
}

impl Iterator for RateTableGenerator {
    type Item = RateTableSample;

    fn next(&mut self) -> Option<RateTableSample> {
        loop {
            let p = *self.plateaus.get(self.plateau)?;
            if self.within == 0 && (self.plateau == 0 || self.plateaus[self.plateau - 1].run != p.run) {
                self.engine.start_run();
            }
            if self.within >= p.settle + p.keep {
                self.plateau += 1;
                self.within = 0;
                continue;
            }
            let settling = self.within < p.settle;
            let table_dps = if settling {
                // Linear ramp from the previous plateau's rate, reaching the new rate at the end.
                p.from_dps + (p.rate_dps - p.from_dps) * ((self.within + 1) as f64 / p.settle as f64)
            } else {
                p.rate_dps
            };
            let time_s = self.time_index as f64 / self.sample_rate_hz;
            let temp_c = self.temperature.temp_at(time_s);
            let output = self.engine.sample(time_s, table_dps, p.stroke.sign(), temp_c);
            self.within += 1;
            self.time_index += 1;
            if settling && !self.flag_settling {
                continue;
            }
            return Some(RateTableSample {
                time_s,
                rate_dps: p.rate_dps,
                run: p.run,
                stroke: p.stroke,
                output,
                temp_c,
                settling,
            });
        }
    }
}

/// Observations and rest record of a simulated rate-table test, ready for `RateTable::from_observations`.
#[derive(Debug, Clone, PartialEq)]
pub struct SimulatedRateTest {
    /// One observation per kept (non-settling) sample.
    pub observations: Vec<RateObservation>,
    /// Mean rest outputs at start and end, when both rest records are present.
    pub rest: Option<RestRecord>,
}

/// Collects a rate-table sample stream into observations and the rest record (settling samples skipped).
pub fn collect_rate_test(samples: impl IntoIterator<Item = RateTableSample>) -> SimulatedRateTest {
    let mut observations = Vec::new();
    let (mut start, mut end) = ((0.0, 0u64), (0.0, 0u64));
    for s in samples {
        if s.settling {
            continue;
        }
        match s.stroke {
            SimStroke::RestStart => start = (start.0 + s.output, start.1 + 1),
            SimStroke::RestEnd => end = (end.0 + s.output, end.1 + 1),
            _ => observations.extend(s.observation()),
        }
    }
    let rest =
        (start.1 > 0 && end.1 > 0).then(|| RestRecord { start: start.0 / start.1 as f64, end: end.0 / end.1 as f64 });
    SimulatedRateTest { observations, rest }
}
