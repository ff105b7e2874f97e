//! SIMULATED records of a temperature test with known truth: a rate-table record and a static
//! record at each soaked point of a heating and cooling cycle, from the simulator's temperature
//! coefficients (`bias_temp_coeff_dph_per_c`, `scale_factor_temp_coeff_ppm_per_c`), with a
//! thermal hysteresis put in as a bias step on the cooling branch.

use crate::error::{EvalError, EvalResult};
use gyrolab::sim::{Preset, RateTableSpec, SensorModel, SettlingRows, StaticSpec, TemperatureProfile};
use gyrolab_io::sim_csv::{write_rate_table_csv, write_static_csv, SimCsvOptions};
use std::path::Path;

/// The truth of [`write_temperature_records`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TemperatureTruth {
    /// Bias temperature coefficient, (deg/h)/degC.
    pub bias_temp_coeff_dph_per_c: f64,
    /// Scale-factor temperature coefficient, ppm/degC.
    pub scale_factor_temp_coeff_ppm_per_c: f64,
    /// Bias step of the cooling branch (thermal hysteresis), deg/h.
    pub bias_hysteresis_dph: f64,
}

/// The simulated truth of the records.
pub const TRUTH: TemperatureTruth = TemperatureTruth {
    bias_temp_coeff_dph_per_c: 0.5,
    scale_factor_temp_coeff_ppm_per_c: 150.0,
    bias_hysteresis_dph: 6.0,
};

/// The soaked points: (temperature, phase) of a heating run from -40 to 85 degC and a cooling
/// run back through 25 and -10 degC.
pub const POINTS: [(f64, &str); 7] = [
    (-40.0, "heating"),
    (-10.0, "heating"),
    (25.0, "heating"),
    (60.0, "heating"),
    (85.0, "heating"),
    (25.0, "cooling"),
    (-10.0, "cooling"),
];

/// The sensor of these records: the ADXRS646 preset's output stage (rails at +-300 deg/s, so the
/// tables stop at +-200 deg/s) with low noise and the
/// temperature coefficients of [`TRUTH`].
pub fn sensor(hysteresis_dph: f64) -> SensorModel {
    let mut m = SensorModel::preset(Preset::Adxrs646);
    m.arw_deg_rt_h = 0.3;
    m.bias_instability_dph = 0.0;
    m.rrw_deg_h_rt_h = 0.0;
    m.rate_ramp_dph_per_h = 0.0;
    m.run_to_run_bias_sigma_dph = 0.0;
    m.run_to_run_scale_factor_sigma_ppm = 0.0;
    m.bias_dph = 20.0 + hysteresis_dph;
    m.bias_temp_coeff_dph_per_c = TRUTH.bias_temp_coeff_dph_per_c;
    m.scale_factor_temp_coeff_ppm_per_c = TRUTH.scale_factor_temp_coeff_ppm_per_c;
    m.reference_temp_c = 25.0;
    m
}

fn write(path: &Path, f: impl FnOnce(&mut std::io::BufWriter<std::fs::File>) -> Result<(), String>) -> EvalResult<()> {
    let file = std::fs::File::create(path).map_err(|e| EvalError::Output(format!("{}: {e}", path.display())))?;
    let mut w = std::io::BufWriter::new(file);
    f(&mut w).map_err(|e| EvalError::Output(format!("{}: {e}", path.display())))?;
    std::io::Write::flush(&mut w).map_err(|e| EvalError::Output(format!("{}: {e}", path.display())))
}

/// Writes a room-temperature rate-table record `rate_<axis>.csv` and, per point of [`POINTS`],
/// `tc_<axis>_<i>_rate.csv` and `tc_<axis>_<i>_static.csv` into `dir`; returns the plan's
/// `[rate.<axis>]` and `[temperature.<axis>]` tables (paths relative to `dir`).
pub fn write_temperature_records(dir: &Path, axis: &str, seed: u64) -> EvalResult<String> {
    let options = SimCsvOptions::default();
    let rate_spec = |t: f64| RateTableSpec {
        rates_dps: vec![-200.0, -100.0, -50.0, 0.0, 50.0, 100.0, 200.0],
        runs: 2,
        sample_rate_hz: 100.0,
        samples_per_plateau: 100,
        settling_s: 0.5,
        settling: SettlingRows::Drop,
        rest_samples: 200,
        temperature: TemperatureProfile::Constant { temp_c: t },
        latitude_deg: None,
    };
    let room = format!("rate_{axis}.csv");
    write(&dir.join(&room), |w| {
        write_rate_table_csv(w, &sensor(0.0), &rate_spec(25.0), seed, &options).map(|_| ()).map_err(|e| e.to_string())
    })?;
    let mut toml = format!(
        "# SIMULATED temperature test (gyrolab-eval program_sim::temperature): bias temperature coefficient \
         {} (deg/h)/degC, scale-factor temperature coefficient {} ppm/degC, a bias step of {} deg/h on the cooling \
         branch (thermal hysteresis).\n[rate.{axis}]\nfile = \"{room}\"\n\n[temperature.{axis}]\norder = 1\n\
         reference_temp_c = 25\nsample_rate_hz = 100\n",
        TRUTH.bias_temp_coeff_dph_per_c, TRUTH.scale_factor_temp_coeff_ppm_per_c, TRUTH.bias_hysteresis_dph
    );
    for (i, (t, phase)) in POINTS.iter().enumerate() {
        let model = sensor(if *phase == "cooling" { TRUTH.bias_hysteresis_dph } else { 0.0 });
        let rate = format!("tc_{axis}_{i}_rate.csv");
        let stat = format!("tc_{axis}_{i}_static.csv");
        let s = seed.wrapping_add(1 + 2 * i as u64);
        write(&dir.join(&rate), |w| {
            write_rate_table_csv(w, &model, &rate_spec(*t), s, &options).map(|_| ()).map_err(|e| e.to_string())
        })?;
        let spec = StaticSpec {
            sample_rate_hz: 100.0,
            duration_s: 300.0,
            temperature: TemperatureProfile::Constant { temp_c: *t },
            latitude_deg: None,
            record_temperature: true,
            ..StaticSpec::default()
        };
        write(&dir.join(&stat), |w| {
            write_static_csv(w, &model, &spec, s + 1, &options).map(|_| ()).map_err(|e| e.to_string())
        })?;
        toml.push_str(&format!(
            "\n[[temperature.{axis}.points]]\ntemperature_c = {t:?}\nphase = \"{phase}\"\nrate = \"{rate}\"\nstatic = \"{stat}\"\n"
        ));
    }
    Ok(toml)
}
