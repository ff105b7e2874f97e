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
use super::normal::NormalStream;
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
    /// Sample count (samples consumed) at which it is next updated.
    next_at: u64,
}

impl GaussMarkov {
    /// Advances `state` by one hold with the draw `z`.
    #[inline(always)]
    fn advance(&mut self, state: &mut f64, z: f64) {
        *state = self.phi * *state + self.drive_sigma * z;
        self.next_at = self.next_at.saturating_add(self.hold);
    }
}

/// The flicker sum: its first-order Gauss-Markov processes (in design order), their current
/// values and sum, and the samples until the next update of any of them.
///
/// The first process (the fastest in the design) is checked on its own; the others share one
/// "next update" position, so an update of the first looks at no other process.
#[derive(Debug, Clone)]
struct FlickerSum {
    /// The processes.
    terms: Vec<GaussMarkov>,
    /// Current value of each process, deg/s, padded with zeros to a multiple of 4 (adding +0.0
    /// to a sum that starts at +0.0 changes no bit), so that the sum runs four at a time.
    state: Vec<f64>,
    /// Earliest `next_at` of the processes after the first (u64::MAX without them).
    next_at_rest: u64,
    /// Sample count at the last update.
    now: u64,
    /// Samples from the last update to the next.
    step: u64,
    /// Sum of the current values, deg/s, added in process order.
    sum: f64,
    /// Samples until the next update (u64::MAX without processes).
    until_update: u64,
}

impl FlickerSum {
    /// The sum of processes with the given (phi, drive sigma, hold, initial value).
    fn new(terms: &[(f64, f64, u64, f64)]) -> FlickerSum {
        let mut state: Vec<f64> = terms.iter().map(|t| t.3).collect();
        state.resize(terms.len().div_ceil(4) * 4, 0.0);
        let mut f = FlickerSum {
            terms: terms
                .iter()
                .map(|&(phi, drive_sigma, hold, _)| GaussMarkov { phi, drive_sigma, hold, next_at: hold })
                .collect(),
            state,
            next_at_rest: u64::MAX,
            now: 0,
            step: u64::MAX,
            sum: 0.0,
            until_update: u64::MAX,
        };
        f.next_at_rest = f.terms.iter().skip(1).map(|g| g.next_at).min().unwrap_or(u64::MAX);
        f.resum();
        f.step = f.terms.iter().map(|g| g.next_at).min().unwrap_or(u64::MAX);
        f.until_update = f.step;
        f
    }

    /// Sums the current values in process order.
    #[inline(always)]
    fn resum(&mut self) {
        let mut sum = 0.0;
        for four in self.state.chunks_exact(4) {
            sum = (((sum + four[0]) + four[1]) + four[2]) + four[3];
        }
        self.sum = sum;
    }

    /// Advances every process whose hold has run out (in process order, one draw each), then
    /// sums them again.
    #[inline(never)]
    fn update(&mut self, noise: &mut NormalBatch) {
        self.now = self.now.saturating_add(self.step);
        let now = self.now;
        let (Some(first), Some(first_state)) = (self.terms.first_mut(), self.state.first_mut()) else {
            return;
        };
        if first.next_at == now {
            first.advance(first_state, noise.draw());
        }
        let next_first = first.next_at;
        if self.next_at_rest == now {
            self.advance_rest(noise);
        }
        self.resum();
        self.step = next_first.min(self.next_at_rest) - now;
        self.until_update = self.step;
    }

    /// Advances the processes after the first that are due now, in order; finds the next of
    /// their updates.
    #[cold]
    fn advance_rest(&mut self, noise: &mut NormalBatch) {
        let mut earliest = u64::MAX;
        for (gm, state) in self.terms.iter_mut().zip(self.state.iter_mut()).skip(1) {
            if gm.next_at == self.now {
                gm.advance(state, noise.draw());
            }
            earliest = earliest.min(gm.next_at);
        }
        self.next_at_rest = earliest;
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
    dead_zone_dps: f64,
    bias_dps: f64,
    run_bias_sigma_dps: f64,
    run_scale_factor_sigma: f64,
    white_sigma_dps: f64,
    flicker: Option<FlickerDesign>,
    flicker_sum: FlickerSum,
    rrw_sigma_dps: f64,
    rrw_state_dps: f64,
    ramp_dps_per_s: f64,
    warmup_amplitude_dps: f64,
    warmup_time_constant_s: f64,
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
    stream: NormalStream,
    values: Vec<f64>,
    next: usize,
}

/// Draws per batch.
const NORMAL_BATCH: usize = 4096;

impl NormalBatch {
    fn new(rng: ChaCha8Rng) -> NormalBatch {
        NormalBatch { stream: NormalStream::new(rng), values: Vec::new(), next: 0 }
    }

    /// The next standard normal draw.
    #[inline(always)]
    fn draw(&mut self) -> f64 {
        if self.next >= self.values.len() {
            self.refill();
        }
        let z = self.values[self.next];
        self.next += 1;
        z
    }

    /// Replaces the spent batch with the next `NORMAL_BATCH` draws.
    #[cold]
    #[inline(never)]
    fn refill(&mut self) {
        self.values.resize(NORMAL_BATCH, 0.0);
        self.stream.fill(&mut self.values);
        self.next = 0;
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
                    (phi, s * (1.0 - phi * phi).sqrt(), hold, state)
                })
                .collect::<Vec<_>>();
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
            dead_zone_dps: model.dead_zone_dps,
            bias_dps: units::dph_to_dps(model.bias_dph),
            run_bias_sigma_dps: units::dph_to_dps(model.run_to_run_bias_sigma_dph),
            run_scale_factor_sigma: units::ppm_to_ratio(model.run_to_run_scale_factor_sigma_ppm),
            white_sigma_dps: units::arw_deg_rt_h_to_sample_sigma_dps(model.arw_deg_rt_h, dt_s),
            flicker,
            flicker_sum: FlickerSum::new(&gauss_markov),
            rrw_sigma_dps: units::rrw_dph_rt_h_to_increment_sigma_dps(model.rrw_deg_h_rt_h, dt_s),
            rrw_state_dps: 0.0,
            ramp_dps_per_s: units::rate_ramp_dph_per_h_to_dps_per_s(model.rate_ramp_dph_per_h),
            warmup_amplitude_dps: units::dph_to_dps(model.warmup_amplitude_dph),
            warmup_time_constant_s: model.warmup_time_constant_s,
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
        let noise = self.next_noise();
        let mut w = self.sensed_rate(t_s, table_dps, stroke_sign, d_temp, noise);
        if self.angle_step_deg > 0.0 {
            w = self.quantize_angle(w);
        }
        self.output_of(w, self.run_scale_factor_at(d_temp))
    }

    /// Static samples (table still, no stroke) at times `times_s` and temperatures `temps_c`,
    /// into `outputs` (as long): the same values as [`Engine::sample`] one at a time, computed in
    /// two passes (the noise, sequential; then the sensor model, independent from sample to
    /// sample unless the angle is quantized), with the temperature terms computed once when
    /// `constant_temp_c` says every temperature is that one.
    fn static_block(&mut self, times_s: &[f64], temps_c: &[f64], constant_temp_c: Option<f64>, outputs: &mut [f64]) {
        for o in outputs.iter_mut() {
            *o = self.next_noise();
        }
        let input = self.input_offset_dps(0.0, 0.0);
        if self.angle_step_deg > 0.0 {
            for ((o, &t_s), &temp_c) in outputs.iter_mut().zip(times_s).zip(temps_c) {
                let d_temp = temp_c - self.reference_temp_c;
                let w = self.quantize_angle(input + self.bias_dps_at(t_s, d_temp) + *o);
                *o = self.output_stage(self.run_scale_factor_at(d_temp)).output(w);
            }
        } else if let Some(temp_c) = constant_temp_c.filter(|_| self.warmup_amplitude_dps == 0.0) {
            let d_temp = temp_c - self.reference_temp_c;
            let bias_base = self.temperature_bias_dps(d_temp);
            let stage = self.output_stage(self.run_scale_factor_at(d_temp));
            let ramp = self.ramp_dps_per_s;
            // Two loops, so that the one without output quantization (no rounding call) is
            // vectorized.
            if stage.output_step > 0.0 {
                for (o, &t_s) in outputs.iter_mut().zip(times_s) {
                    *o = stage.output(input + (bias_base + ramp * t_s) + *o);
                }
            } else {
                for (o, &t_s) in outputs.iter_mut().zip(times_s) {
                    *o = stage.unquantized(input + (bias_base + ramp * t_s) + *o);
                }
            }
        } else {
            for ((o, &t_s), &temp_c) in outputs.iter_mut().zip(times_s).zip(temps_c) {
                let d_temp = temp_c - self.reference_temp_c;
                let w = input + self.bias_dps_at(t_s, d_temp) + *o;
                *o = self.output_stage(self.run_scale_factor_at(d_temp)).output(w);
            }
        }
    }

    /// The noise of the next sample (white rate noise, flicker sum, rate random walk), deg/s;
    /// advances the noise state (draws: white, then any flicker updates, then the random walk).
    #[inline(always)]
    fn next_noise(&mut self) -> f64 {
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
        noise
    }

    /// The sensed rate, deg/s: input, earth rate, hysteresis offset, bias terms (at time t_s and
    /// temperature offset d_temp from the reference) and `noise`.
    #[inline(always)]
    fn sensed_rate(&self, t_s: f64, table_dps: f64, stroke_sign: f64, d_temp: f64, noise: f64) -> f64 {
        self.input_offset_dps(table_dps, stroke_sign) + self.bias_dps_at(t_s, d_temp) + noise
    }

    /// Table rate plus earth rate plus the stroke's hysteresis offset, deg/s; zero when its
    /// magnitude is below the dead zone.
    #[inline(always)]
    fn input_offset_dps(&self, table_dps: f64, stroke_sign: f64) -> f64 {
        let w = table_dps + self.earth_dps + stroke_sign * self.hysteresis_half_dps;
        if w.abs() < self.dead_zone_dps {
            0.0
        } else {
            w
        }
    }

    /// The bias at time t_s and temperature offset d_temp, deg/s.
    #[inline(always)]
    fn bias_dps_at(&self, t_s: f64, d_temp: f64) -> f64 {
        let b = self.temperature_bias_dps(d_temp) + self.ramp_dps_per_s * t_s;
        if self.warmup_amplitude_dps == 0.0 {
            b
        } else {
            b + self.warmup_amplitude_dps * (-t_s / self.warmup_time_constant_s).exp()
        }
    }

    /// Constant, run-to-run and temperature bias at temperature offset d_temp, deg/s.
    #[inline(always)]
    fn temperature_bias_dps(&self, d_temp: f64) -> f64 {
        self.bias_dps + self.run_bias_dps + self.bias_tc_dps_per_c * d_temp
    }

    /// The scale factor of this run at temperature offset d_temp (before asymmetry), output
    /// units per deg/s.
    #[inline(always)]
    fn run_scale_factor_at(&self, d_temp: f64) -> f64 {
        self.scale_factor
            * (1.0 + self.scale_factor_error + self.run_scale_factor + self.scale_factor_tc_per_c * d_temp)
    }

    /// Angle quantization: emits whole angle steps of `w` dt and carries the remainder (bounded);
    /// returns the rate of the steps emitted, deg/s.
    #[inline(always)]
    fn quantize_angle(&mut self, w: f64) -> f64 {
        self.angle_residue_deg += w * self.dt_s;
        let steps = (self.angle_residue_deg / self.angle_step_deg).floor();
        self.angle_residue_deg -= steps * self.angle_step_deg;
        steps * self.angle_step_deg / self.dt_s
    }

    /// The output for sensed rate `w` with the run's scale factor `k_run`: asymmetry,
    /// nonlinearity, null, rails, output quantization.
    #[inline(always)]
    fn output_of(&self, w: f64, k_run: f64) -> f64 {
        self.output_stage(k_run).output(w)
    }

    /// The output stage for the run's scale factor `k_run`.
    #[inline(always)]
    fn output_stage(&self, k_run: f64) -> OutputStage {
        OutputStage {
            k_positive: k_run * (1.0 + self.asymmetry_half),
            k_negative: k_run * (1.0 - self.asymmetry_half),
            k2: self.k2,
            k3: self.k3,
            null: self.null,
            rail_low: self.rail_low,
            rail_high: self.rail_high,
            output_step: self.output_step,
        }
    }
}

/// The sensor's output stage for one scale factor: from the sensed rate to the output (its
/// values copied out of the engine, so that a loop over samples keeps them in registers).
#[derive(Debug, Clone, Copy)]
struct OutputStage {
    /// Scale factor for w >= 0 and for w < 0 (asymmetry), output units per deg/s.
    k_positive: f64,
    k_negative: f64,
    /// Quadratic and cubic nonlinearity, 1/(deg/s) and 1/(deg/s)^2.
    k2: f64,
    k3: f64,
    /// Null, rails and quantization step, output units.
    null: f64,
    rail_low: f64,
    rail_high: f64,
    output_step: f64,
}

impl OutputStage {
    /// The output for sensed rate `w`, deg/s, before output quantization: asymmetry,
    /// nonlinearity, null, rails.
    #[inline(always)]
    fn unquantized(&self, w: f64) -> f64 {
        let k = if w >= 0.0 { self.k_positive } else { self.k_negative };
        let nonlinear = w * (1.0 + w * (self.k2 + w * self.k3));
        (self.null + k * nonlinear).clamp(self.rail_low, self.rail_high)
    }

    /// The output for sensed rate `w`, deg/s: asymmetry, nonlinearity, null, rails, output
    /// quantization.
    #[inline(always)]
    fn output(&self, w: f64) -> f64 {
        let out = self.unquantized(w);
        if self.output_step > 0.0 {
            (out / self.output_step).round() * self.output_step
        } else {
            out
        }
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
        // The orientation: the g-sensitive bias G · f and the input axis's share of the earth rate.
        if let Some(f) = spec.specific_force_g {
            let g = model.g_sensitivity_dph_per_g;
            engine.bias_dps += units::dph_to_dps(g[0] * f[0] + g[1] * f[1] + g[2] * f[2]);
        }
        engine.earth_dps *= spec.input_axis_up;
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

    /// The sample rate, Hz.
    pub fn sample_rate_hz(&self) -> f64 {
        self.sample_rate_hz
    }

    /// Replaces `block` with the next samples, at most `max_samples` of them (the same values as
    /// the iterator, faster); returns how many (0 at the end of the record, or when
    /// `max_samples` is 0).
    pub fn next_block(&mut self, block: &mut StaticBlock, max_samples: usize) -> usize {
        let n = usize::try_from(self.remaining()).map_or(max_samples, |r| r.min(max_samples));
        let first = self.index;
        block.first_index = first;
        // (Resized, not cleared: a block of the same length as before is written over in place.)
        block.time_s.resize(n, 0.0);
        for (t, i) in block.time_s.iter_mut().zip(first..) {
            // Sample indices stay far below 2^63: the signed conversion is exact and cheaper.
            *t = i as i64 as f64 / self.sample_rate_hz;
        }
        self.temperature.temps_at(&block.time_s, &mut block.temp_c);
        let constant_temp_c = match self.temperature {
            TemperatureProfile::Constant { temp_c } => Some(temp_c),
            _ => None,
        };
        block.output.resize(n, 0.0);
        self.engine.static_block(&block.time_s, &block.temp_c, constant_temp_c, &mut block.output);
        block.records_temperature = self.record_temperature;
        self.index += n as u64;
        n
    }
}

/// A block of consecutive static samples, in columns (see [`StaticGenerator::next_block`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct StaticBlock {
    /// Index of the first sample in the record (0 for the record's first sample).
    pub first_index: u64,
    /// Time from the record start of each sample, s.
    pub time_s: Vec<f64>,
    /// Gyro output of each sample, in the model's output unit.
    pub output: Vec<f64>,
    /// Sensor temperature at each sample, degC (kept whether or not the record carries it).
    pub temp_c: Vec<f64>,
    /// Whether the record carries the temperature (a `temp_c` column).
    pub records_temperature: bool,
}

impl StaticBlock {
    /// Number of samples in the block.
    pub fn len(&self) -> usize {
        self.output.len()
    }

    /// Whether the block holds no samples.
    pub fn is_empty(&self) -> bool {
        self.output.is_empty()
    }

    /// Sample `i` of the block, as the iterator yields it.
    pub fn sample(&self, i: usize) -> StaticSample {
        StaticSample {
            time_s: self.time_s[i],
            output: self.output[i],
            temp_c: self.records_temperature.then_some(self.temp_c[i]),
        }
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
