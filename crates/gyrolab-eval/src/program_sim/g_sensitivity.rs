//! Simulated g-sensitivity records with known truth: static records of one gyro axis in the six
//! orientations `+x up` ... `-z up` (two records each), from the simulator with a stated
//! g-sensitivity G ([`SensorModel::g_sensitivity_dph_per_g`]) and the earth rate's projection on
//! the input axis at a stated latitude.
//!
//! The sensor is the ADXRS646 preset (output in V, K = 0.0075 V/(deg/s), null 2.5 V, ARW
//! 0.6 deg/√h) with the bias instability lowered to [`BIAS_INSTABILITY_DPH`] (the preset's
//! 12 deg/h makes record means scatter by about 30 deg/h, hiding a G of tens of (deg/h)/g), and
//! with [`BIAS_DPH`] and [`TRUTH_G_DPH_PER_G`]. The
//! section is meant to be evaluated with a `[rate.<axis>]` table of the same sensor (K and the
//! null from its rate-table evaluation, e.g. [`write_rate_table_record`]) or an
//! `[options] calibration` with K = 0.0075 V/(deg/s) and null 2.5 V. G does not depend on the
//! null; the fitted B_0 is the zero-g bias relative to the reference null (with a rate-table
//! null measured at rest, input axis up, at the same latitude: B_0 = [`BIAS_DPH`] + Ω_e sin φ −
//! (null − 2.5 V) / K, since the simulator's rate-table records carry no g-sensitive bias).

use crate::error::{EvalError, EvalResult};
use gyrolab::g_sensitivity::{input_axis_up, NamedOrientation, SensorAxis};
use gyrolab::sim::{Preset, RateTableSpec, SensorModel, StaticSpec};
use gyrolab_io::sim_csv::{write_rate_table_csv, write_static_csv, SimCsvOptions};
use std::path::Path;

/// The simulated g-sensitivity G along sensor x, y, z, (deg/h)/g.
pub const TRUTH_G_DPH_PER_G: [f64; 3] = [40.0, -25.0, 15.0];
/// The simulated bias instability B, deg/h.
pub const BIAS_INSTABILITY_DPH: f64 = 1.0;
/// The simulated constant bias, deg/h.
pub const BIAS_DPH: f64 = 20.0;
/// The simulated site latitude, deg (also written as the section's `latitude_deg`).
pub const LATITUDE_DEG: f64 = 30.0;
/// Sample rate of the records, Hz.
pub const SAMPLE_RATE_HZ: f64 = 100.0;
/// Length of each record, s.
pub const RECORD_S: f64 = 120.0;
/// Records per orientation.
pub const RECORDS_PER_ORIENTATION: usize = 2;

/// The simulated sensor: the ADXRS646 preset with [`BIAS_INSTABILITY_DPH`], [`BIAS_DPH`] and
/// [`TRUTH_G_DPH_PER_G`].
pub fn sensor_model() -> SensorModel {
    SensorModel {
        bias_dph: BIAS_DPH,
        bias_instability_dph: BIAS_INSTABILITY_DPH,
        g_sensitivity_dph_per_g: TRUTH_G_DPH_PER_G,
        ..SensorModel::preset(Preset::Adxrs646)
    }
}

/// The sensor axis that is the input axis of `axis`: x, y or z by name, else x.
pub fn input_axis_of(axis: &str) -> SensorAxis {
    SensorAxis::parse(axis).unwrap_or(SensorAxis::X)
}

fn io_err(path: &Path, e: impl std::fmt::Display) -> EvalError {
    EvalError::Output(format!("{}: cannot write the simulated record: {e}", path.display()))
}

/// Writes a rate-table record (long format: 7 rates from -200 to 200 deg/s, 2 runs, rest
/// records, at [`LATITUDE_DEG`], input axis up) of the same sensor as `rate_<axis>.csv` into `dir`; returns its file name.
pub fn write_rate_table_record(dir: &Path, axis: &str, seed: u64) -> EvalResult<String> {
    let name = format!("rate_{axis}.csv");
    let path = dir.join(&name);
    // Rates within +-200 deg/s keep the ADXRS646 class's outputs off its rails (2.5 +- 2.25 V at 300).
    let spec = RateTableSpec {
        rates_dps: vec![-200.0, -100.0, -50.0, 0.0, 50.0, 100.0, 200.0],
        runs: 2,
        latitude_deg: Some(LATITUDE_DEG),
        ..RateTableSpec::default()
    };
    let f = std::fs::File::create(&path).map_err(|e| io_err(&path, e))?;
    write_rate_table_csv(std::io::BufWriter::new(f), &sensor_model(), &spec, seed, &SimCsvOptions::default())
        .map_err(|e| io_err(&path, e))?;
    Ok(name)
}

/// Writes the static records of `axis` in the six orientations ([`RECORDS_PER_ORIENTATION`]
/// each, seeds from `seed` on) into `dir` and returns the TOML of its `[g_sensitivity.<axis>]`
/// section (relative file names; the truth in a comment).
pub fn write_g_sensitivity_records(dir: &Path, axis: &str, seed: u64) -> EvalResult<String> {
    let model = sensor_model();
    let input = input_axis_of(axis);
    let mut records = Vec::new();
    let mut k = 0u64;
    for name in NamedOrientation::NAMES {
        let o = NamedOrientation::parse(name).ok_or_else(|| EvalError::Output(format!("bad orientation {name}")))?;
        let f = o.specific_force_g();
        for rep in 0..RECORDS_PER_ORIENTATION {
            let file = format!("g_{axis}_{}{}_{}.csv", if o.positive_up { "p" } else { "m" }, o.axis.name(), rep + 1);
            let path = dir.join(&file);
            let spec = StaticSpec {
                sample_rate_hz: SAMPLE_RATE_HZ,
                duration_s: RECORD_S,
                latitude_deg: Some(LATITUDE_DEG),
                specific_force_g: Some(f),
                input_axis_up: input_axis_up(f, input),
                ..StaticSpec::default()
            };
            let out = std::fs::File::create(&path).map_err(|e| io_err(&path, e))?;
            write_static_csv(std::io::BufWriter::new(out), &model, &spec, seed + k, &SimCsvOptions::default())
                .map_err(|e| io_err(&path, e))?;
            k += 1;
            records.push(format!("    {{ orientation = \"{name}\", file = \"{file}\" }},"));
        }
    }
    let g = TRUTH_G_DPH_PER_G;
    Ok(format!(
        "# SIMULATED g-sensitivity records (gyrolab_eval::program_sim::g_sensitivity, seed {seed}): ADXRS646 preset\n\
         # (K = 0.0075 V/(deg/s), null 2.5 V, ARW 0.6 deg/sqrt(h)), bias instability {BIAS_INSTABILITY_DPH} deg/h,\n\
         # bias {BIAS_DPH} deg/h,\n\
         # truth G = ({}, {}, {}) (deg/h)/g, |G| = {} (deg/h)/g; input axis {}; latitude {LATITUDE_DEG} deg;\n\
         # {RECORDS_PER_ORIENTATION} records of {RECORD_S} s at {SAMPLE_RATE_HZ} Hz per orientation. Evaluate with a [rate.{axis}]\n\
         # table of the same sensor (write_rate_table_record) or a calibration with K = 0.0075 V/(deg/s), null 2.5 V.\n\
         [g_sensitivity.{axis}]\n\
         input_axis = \"{}\"\n\
         sample_rate_hz = {SAMPLE_RATE_HZ:?}\n\
         latitude_deg = {LATITUDE_DEG:?}\n\
         records = [\n{}\n]\n",
        g[0],
        g[1],
        g[2],
        (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt(),
        input.name(),
        input.name(),
        records.join("\n")
    ))
}
