//! Simulated records of repeated power-ups (`[power_ups.<axis>]`) and of a warm-up from power-on
//! (`[warmup.<axis>]`), from the simulator ([`gyrolab::sim`]): each power-up is a record of its
//! own seed, so the run-to-run bias and scale-factor changes (`run_to_run_bias_sigma_dph`,
//! `run_to_run_scale_factor_sigma_ppm`) are drawn afresh; the warm-up record carries the
//! transient B + A exp(-t / tau) (`warmup_amplitude_dph`, `warmup_time_constant_s`).

use crate::error::{EvalError, EvalResult};
use gyrolab::sim::{RateTableSpec, SensorModel, StaticSpec};
use gyrolab_io::sim_csv::{write_rate_table_csv, write_static_csv, SimCsvOptions};
use std::path::Path;

/// Number of power-ups simulated.
pub const POWER_UPS: usize = 6;
/// Run-to-run bias change (one standard deviation), deg/h.
pub const RUN_TO_RUN_BIAS_SIGMA_DPH: f64 = 40.0;
/// Run-to-run scale-factor change (one standard deviation), ppm.
pub const RUN_TO_RUN_SCALE_FACTOR_SIGMA_PPM: f64 = 500.0;
/// Warm-up amplitude A, deg/h.
pub const WARMUP_AMPLITUDE_DPH: f64 = 300.0;
/// Warm-up time constant tau, s.
pub const WARMUP_TIME_CONSTANT_S: f64 = 60.0;
/// Sample rate of the static records, Hz.
pub const STATIC_RATE_HZ: f64 = 20.0;

/// The simulated sensor: output in deg/s (K = 1, null 0, so no reference is needed), a constant
/// bias of 20 deg/h, white noise of 0.05 deg/sqrt(h), and the run-to-run changes above.
pub fn power_up_model() -> SensorModel {
    power_up_model_of(&SensorModel::default())
}

/// [`power_up_model`] with the output stage (unit, scale factor, null, rails) of `base`.
pub fn power_up_model_of(base: &SensorModel) -> SensorModel {
    SensorModel {
        bias_dph: 20.0,
        arw_deg_rt_h: 0.05,
        run_to_run_bias_sigma_dph: RUN_TO_RUN_BIAS_SIGMA_DPH,
        run_to_run_scale_factor_sigma_ppm: RUN_TO_RUN_SCALE_FACTOR_SIGMA_PPM,
        ..output_stage(base)
    }
}

/// An ideal sensor with the output stage of `base`.
fn output_stage(base: &SensorModel) -> SensorModel {
    SensorModel {
        output_unit: base.output_unit,
        scale_factor_per_dps: base.scale_factor_per_dps,
        null: base.null,
        output_rail_low: base.output_rail_low,
        output_rail_high: base.output_rail_high,
        ..SensorModel::default()
    }
}

fn describe(m: &SensorModel) -> String {
    format!("output in {} (K = {} per deg/s, null {})", m.output_unit.symbol(), m.scale_factor_per_dps, m.null)
}

fn write(
    dir: &Path,
    name: &str,
    f: impl FnOnce(&mut std::io::BufWriter<std::fs::File>) -> Result<(), String>,
) -> EvalResult<()> {
    let path = dir.join(name);
    let file = std::fs::File::create(&path).map_err(|e| EvalError::Output(format!("{}: {e}", path.display())))?;
    let mut w = std::io::BufWriter::new(file);
    f(&mut w).map_err(|e| EvalError::Output(format!("{}: {e}", path.display())))?;
    std::io::Write::flush(&mut w).map_err(|e| EvalError::Output(format!("{}: {e}", path.display())))
}

/// Writes [`POWER_UPS`] rate-table records (one run each: one power-up) and as many static
/// records (300 s at [`STATIC_RATE_HZ`]) of [`power_up_model`] into `dir`, each power-up with
/// its own seed; returns the `[power_ups.<axis>]` section referring to them.
pub fn write_power_up_records(dir: &Path, axis: &str, seed: u64) -> EvalResult<String> {
    write_power_up_records_of(dir, axis, seed, &SensorModel::default())
}

/// [`write_power_up_records`] of a sensor with the output stage of `base`.
pub fn write_power_up_records_of(dir: &Path, axis: &str, seed: u64, base: &SensorModel) -> EvalResult<String> {
    let model = power_up_model_of(base);
    let rate_spec = RateTableSpec { runs: 1, samples_per_plateau: 50, rest_samples: 0, ..RateTableSpec::default() };
    let static_spec = StaticSpec { sample_rate_hz: STATIC_RATE_HZ, duration_s: 300.0, ..StaticSpec::default() };
    let options = SimCsvOptions::default();
    let mut rate_files = Vec::new();
    let mut static_files = Vec::new();
    for i in 0..POWER_UPS {
        let s = seed.wrapping_mul(1000).wrapping_add(i as u64 + 1);
        let name = format!("power_up_{axis}_{}_rate.csv", i + 1);
        write(dir, &name, |w| {
            write_rate_table_csv(w, &model, &rate_spec, s, &options).map(|_| ()).map_err(|e| e.to_string())
        })?;
        rate_files.push(name);
        let name = format!("power_up_{axis}_{}_static.csv", i + 1);
        let s = s.wrapping_add(500);
        write(dir, &name, |w| {
            write_static_csv(w, &model, &static_spec, s, &options).map(|_| ()).map_err(|e| e.to_string())
        })?;
        static_files.push(name);
    }
    let list = |v: &[String]| v.iter().map(|f| format!("\"{f}\"")).collect::<Vec<_>>().join(", ");
    Ok(format!(
        "# SIMULATED: {POWER_UPS} power-ups of a sensor with {}, bias 20 deg/h, \
         run-to-run bias sigma {RUN_TO_RUN_BIAS_SIGMA_DPH} deg/h and scale-factor sigma \
         {RUN_TO_RUN_SCALE_FACTOR_SIGMA_PPM} ppm drawn per power-up (seeds {seed}*1000+1.. for the rate-table \
         records, +500 for the static records), ARW 0.05 deg/sqrt(h)\n\
         [power_ups.{axis}]\nrate_files = [{}]\nstatic_files = [{}]\nsample_rate_hz = {STATIC_RATE_HZ:?}\n",
        describe(&model),
        list(&rate_files),
        list(&static_files)
    ))
}

/// Writes a 1200-s static record from power-on at [`STATIC_RATE_HZ`] with the warm-up transient
/// A = [`WARMUP_AMPLITUDE_DPH`], tau = [`WARMUP_TIME_CONSTANT_S`] (bias 20 deg/h, ARW 0.02
/// deg/sqrt(h), output in deg/s) into `dir`; returns the `[warmup.<axis>]` section (band 5 deg/h).
pub fn write_warmup_records(dir: &Path, axis: &str, seed: u64) -> EvalResult<String> {
    write_warmup_records_of(dir, axis, seed, &SensorModel::default())
}

/// [`write_warmup_records`] of a sensor with the output stage of `base`.
pub fn write_warmup_records_of(dir: &Path, axis: &str, seed: u64, base: &SensorModel) -> EvalResult<String> {
    let model = SensorModel {
        bias_dph: 20.0,
        arw_deg_rt_h: 0.02,
        warmup_amplitude_dph: WARMUP_AMPLITUDE_DPH,
        warmup_time_constant_s: WARMUP_TIME_CONSTANT_S,
        ..output_stage(base)
    };
    let spec = StaticSpec { sample_rate_hz: STATIC_RATE_HZ, duration_s: 1200.0, ..StaticSpec::default() };
    let name = format!("warmup_{axis}.csv");
    write(dir, &name, |w| {
        write_static_csv(w, &model, &spec, seed, &SimCsvOptions::default()).map(|_| ()).map_err(|e| e.to_string())
    })?;
    Ok(format!(
        "# SIMULATED: warm-up from power-on (t = 0), bias 20 + {WARMUP_AMPLITUDE_DPH} exp(-t / \
         {WARMUP_TIME_CONSTANT_S} s) deg/h, ARW 0.02 deg/sqrt(h), {}, seed {seed}\n\
         [warmup.{axis}]\nfile = \"{name}\"\nsample_rate_hz = {STATIC_RATE_HZ:?}\nband_dph = 5.0\nwindow_s = 10.0\n",
        describe(&model)
    ))
}
