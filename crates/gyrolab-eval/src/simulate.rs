//! Simulator set-ups: a TOML configuration (optional) with overrides applied, for static
//! records and rate-table tests with known truth ([`gyrolab::sim`], docs/METHODS.md section 4).

use crate::error::{EvalError, EvalResult};
use gyrolab::sim::{Preset, SimConfig, TemperatureProfile};
use gyrolab::units::OutputUnit;
pub use gyrolab_io::sim_csv::StatedReference;
use gyrolab_io::sim_csv::{
    read_sim_config, read_stated_reference, write_rate_table_csv, write_static_csv, NumberFormat, SimCsvError,
    SimCsvOptions,
};
use std::io::Write;
use std::path::PathBuf;

/// Overrides of a simulator set-up; `None` keeps the configuration's (or the default) value.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SimOverrides {
    /// A TOML set-up (seed, preset, `[sensor]`, `[static_record]`, `[rate_table]`).
    pub config: Option<PathBuf>,
    /// Seed (default 1).
    pub seed: Option<u64>,
    /// Sensor preset.
    pub preset: Option<Preset>,
    /// Sample rate, Hz.
    pub sample_rate_hz: Option<f64>,
    /// Output unit.
    pub output_unit: Option<OutputUnit>,
    /// Scale factor, output units per deg/s.
    pub scale_factor: Option<f64>,
    /// Null, output units.
    pub null: Option<f64>,
    /// Constant bias, deg/h.
    pub bias_dph: Option<f64>,
    /// Angle random walk N, deg/sqrt(h).
    pub arw_deg_rt_h: Option<f64>,
    /// Bias instability B, deg/h.
    pub bias_instability_dph: Option<f64>,
    /// Rate random walk K, deg/h/sqrt(h).
    pub rrw_deg_h_rt_h: Option<f64>,
    /// Rate ramp R, deg/h per hour.
    pub rate_ramp_dph_per_h: Option<f64>,
    /// Warm-up transient amplitude, deg/h.
    pub warmup_amplitude_dph: Option<f64>,
    /// Warm-up time constant, s.
    pub warmup_time_constant_s: Option<f64>,
    /// Output quantization step, output units.
    pub output_quantization_step: Option<f64>,
    /// Bias temperature coefficient, (deg/h)/degC.
    pub bias_temp_coeff_dph_per_c: Option<f64>,
    /// Constant temperature (or the ramp's start), degC.
    pub temp_c: Option<f64>,
    /// Temperature ramp, degC per hour.
    pub temp_ramp_c_per_h: Option<f64>,
    /// Latitude, degrees.
    pub latitude_deg: Option<f64>,
    /// Static record length, s.
    pub duration_s: Option<f64>,
    /// Add a temperature column to the static record.
    pub record_temperature: bool,
    /// Table rates, deg/s (empty: keep).
    pub rates_dps: Vec<f64>,
    /// Runs of the rate-table test.
    pub runs: Option<u32>,
    /// Samples per plateau.
    pub samples_per_plateau: Option<u32>,
    /// Settling time per plateau, s.
    pub settling_s: Option<f64>,
    /// Rest samples at the start and end.
    pub rest_samples: Option<u32>,
    /// Hysteresis, deg/s.
    pub hysteresis_dps: Option<f64>,
    /// Quadratic nonlinearity, 1/(deg/s).
    pub nonlinearity_quadratic_per_dps: Option<f64>,
    /// Scale-factor asymmetry, ppm.
    pub scale_factor_asymmetry_ppm: Option<f64>,
    /// Run-to-run scale-factor change (1 sigma), ppm.
    pub run_to_run_scale_factor_sigma_ppm: Option<f64>,
}

/// The set-up: the configuration file (if any) with the overrides applied.
///
/// ```
/// use gyrolab_eval::simulate::{sim_config, SimOverrides};
/// # fn main() -> Result<(), gyrolab_eval::EvalError> {
/// let cfg = sim_config(&SimOverrides { seed: Some(7), duration_s: Some(60.0), ..Default::default() })?;
/// assert_eq!((cfg.seed, cfg.static_record.duration_s), (7, 60.0));
/// # Ok(())
/// # }
/// ```
pub fn sim_config(o: &SimOverrides) -> EvalResult<SimConfig> {
    let mut cfg = match &o.config {
        Some(p) => read_sim_config(p)?,
        None => SimConfig { seed: 1, ..SimConfig::default() },
    };
    if let Some(s) = o.seed {
        cfg.seed = s;
    }
    if o.preset.is_some() {
        cfg.preset = o.preset;
    }
    let s = &mut cfg.sensor;
    macro_rules! set {
        ($($f:ident),*) => { $( if let Some(v) = o.$f { s.$f = Some(v); } )* };
    }
    set!(
        output_unit,
        null,
        bias_dph,
        arw_deg_rt_h,
        bias_instability_dph,
        rrw_deg_h_rt_h,
        rate_ramp_dph_per_h,
        warmup_amplitude_dph,
        warmup_time_constant_s,
        output_quantization_step,
        bias_temp_coeff_dph_per_c,
        hysteresis_dps,
        nonlinearity_quadratic_per_dps,
        scale_factor_asymmetry_ppm,
        run_to_run_scale_factor_sigma_ppm
    );
    if let Some(k) = o.scale_factor {
        s.scale_factor_per_dps = Some(k);
    }
    if s.output_unit.is_some() && s.scale_factor_per_dps.is_none() && cfg.preset.is_none() {
        // An output that is already a rate (rad/s, deg/h, mrad/s) has its exact scale factor:
        // the sensor's rate in that unit (before, rad/s outputs held deg/s numbers).
        s.scale_factor_per_dps = s.output_unit.and_then(OutputUnit::native_scale_factor_per_dps);
        if let Some(OutputUnit::Volt | OutputUnit::Millivolt | OutputUnit::Lsb) = s.output_unit {
            return Err(EvalError::conflict_on(
                &["scale_factor", "null", "preset"],
                "an analog or digital output needs {scale_factor} (and usually {null}), or a {preset}",
            ));
        }
    }
    let temperature = match (o.temp_c, o.temp_ramp_c_per_h) {
        (None, None) => None,
        (t, None) => Some(TemperatureProfile::Constant { temp_c: t.unwrap_or(25.0) }),
        (t, Some(r)) => Some(TemperatureProfile::Ramp { start_c: t.unwrap_or(25.0), rate_c_per_h: r }),
    };
    if let Some(t) = temperature {
        cfg.static_record.temperature = t.clone();
        cfg.rate_table.temperature = t;
    }
    if let Some(l) = o.latitude_deg {
        cfg.static_record.latitude_deg = Some(l);
        cfg.rate_table.latitude_deg = Some(l);
    }
    if let Some(f) = o.sample_rate_hz {
        cfg.static_record.sample_rate_hz = f;
        cfg.rate_table.sample_rate_hz = f;
    }
    if let Some(d) = o.duration_s {
        cfg.static_record.duration_s = d;
    }
    if o.record_temperature {
        cfg.static_record.record_temperature = true;
    }
    let rt = &mut cfg.rate_table;
    if !o.rates_dps.is_empty() {
        rt.rates_dps = o.rates_dps.clone();
    }
    if let Some(v) = o.runs {
        rt.runs = v;
    }
    if let Some(v) = o.samples_per_plateau {
        rt.samples_per_plateau = v;
    }
    if let Some(v) = o.settling_s {
        rt.settling_s = v;
    }
    if let Some(v) = o.rest_samples {
        rt.rest_samples = v;
    }
    Ok(cfg)
}

/// The sensor `simulate static` simulates when neither a set-up file, a preset nor any error
/// term is given: a typical MEMS gyro (consumer to industrial grade, such as the ADIS16470 or
/// BMI088 classes) in deg/s, so that a record made with no options has noise to analyse.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TypicalMems {
    /// Angle random walk N, deg/sqrt(h).
    pub arw_deg_rt_h: f64,
    /// Bias instability B (IEEE 952), deg/h.
    pub bias_instability_dph: f64,
    /// Constant (turn-on) bias, deg/h.
    pub bias_dph: f64,
}

/// The typical MEMS gyro of [`TypicalMems`]: N = 0.3 deg/sqrt(h), B = 5 deg/h, bias 20 deg/h
/// (the middle of the MEMS class: ADIS16470 0.34 deg/sqrt(h) and 8 deg/h, BMI088 about
/// 0.8 deg/sqrt(h); methods notes section 5).
pub const TYPICAL_MEMS: TypicalMems = TypicalMems { arw_deg_rt_h: 0.3, bias_instability_dph: 5.0, bias_dph: 20.0 };

impl TypicalMems {
    /// One line for stderr and the record's comments.
    pub fn describe(&self) -> String {
        format!(
            "typical MEMS gyro: angle random walk {} deg/sqrt(h), bias instability {} deg/h, bias {} deg/h",
            self.arw_deg_rt_h, self.bias_instability_dph, self.bias_dph
        )
    }
}

/// Whether the typical MEMS gyro applies to these overrides: no set-up file, no preset and no
/// error term (bias, noise, ramp, warm-up, quantization, temperature coefficient) given.
pub fn uses_typical_mems(o: &SimOverrides) -> bool {
    o.config.is_none()
        && o.preset.is_none()
        && [
            o.bias_dph,
            o.arw_deg_rt_h,
            o.bias_instability_dph,
            o.rrw_deg_h_rt_h,
            o.rate_ramp_dph_per_h,
            o.warmup_amplitude_dph,
            o.output_quantization_step,
            o.bias_temp_coeff_dph_per_c,
        ]
        .iter()
        .all(Option::is_none)
}

/// The set-up of a static record: [`sim_config`], with the [`TYPICAL_MEMS`] gyro's error terms
/// when [`uses_typical_mems`] (returned, for the front end to say so), so that a static record
/// is never all one value unless an error term was set to zero on purpose.
///
/// ```
/// use gyrolab_eval::simulate::{static_sim_config, SimOverrides, TYPICAL_MEMS};
/// # fn main() -> Result<(), gyrolab_eval::EvalError> {
/// let (cfg, typical) = static_sim_config(&SimOverrides::default())?;
/// assert_eq!(typical, Some(TYPICAL_MEMS));
/// assert_eq!(cfg.sensor.arw_deg_rt_h, Some(0.3));
/// let (cfg, typical) = static_sim_config(&SimOverrides { arw_deg_rt_h: Some(0.0), ..Default::default() })?;
/// assert_eq!((typical, cfg.sensor.bias_instability_dph), (None, None));
/// # Ok(())
/// # }
/// ```
pub fn static_sim_config(o: &SimOverrides) -> EvalResult<(SimConfig, Option<TypicalMems>)> {
    if !uses_typical_mems(o) {
        return Ok((sim_config(o)?, None));
    }
    let t = TYPICAL_MEMS;
    let o = SimOverrides {
        arw_deg_rt_h: Some(t.arw_deg_rt_h),
        bias_instability_dph: Some(t.bias_instability_dph),
        bias_dph: Some(t.bias_dph),
        ..o.clone()
    };
    Ok((sim_config(&o)?, Some(t)))
}

/// The scale factor and null that gyrolab's simulator states in the header comments of every
/// file in `files` (all the same), when `request` gives no reference of its own and the output
/// unit is not already a rate in deg/s: the request with them set, and what was read (for the
/// front end's note). `None` otherwise (a file from elsewhere, files that disagree, standard
/// input, or a reference given).
///
/// ```
/// use gyrolab_eval::reference::ReferenceRequest;
/// use gyrolab_eval::simulate::reference_from_headers;
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// let dir = tempfile::tempdir()?;
/// let p = dir.path().join("s.csv");
/// let lines = ["# gyrolab simulated static record", "# sensor.output_unit = V"];
/// let more = ["# sensor.scale_factor_per_dps = 0.0075", "# sensor.null = 2.5", "time_s,output_v", "0,2.5"];
/// std::fs::write(&p, [&lines[..], &more[..]].concat().join("\n"))?;
/// let (r, _) = reference_from_headers(&[p], &ReferenceRequest::default()).ok_or("no reference")?;
/// assert_eq!((r.scale_factor, r.null), (Some(0.0075), Some(2.5)));
/// # Ok(())
/// # }
/// ```
pub fn reference_from_headers(
    files: &[PathBuf],
    request: &crate::reference::ReferenceRequest,
) -> Option<(crate::reference::ReferenceRequest, StatedReference)> {
    if request.calibration.is_some() || request.scale_factor.is_some() || request.null.is_some() {
        return None;
    }
    let mut stated = None;
    for f in files {
        let r = read_stated_reference(f)?;
        if stated.is_some_and(|s| s != r) {
            return None;
        }
        stated = Some(r);
    }
    let r = stated?;
    if r.output_unit.native_scale_factor_per_dps() == Some(r.scale_factor_per_dps) && r.null == 0.0 {
        return None;
    }
    let request = crate::reference::ReferenceRequest {
        scale_factor: Some(r.scale_factor_per_dps),
        null: Some(r.null),
        ..request.clone()
    };
    Some((request, r))
}

/// The seed of the example test program's records (`gyrolab simulate test-program`), the one
/// `examples/test_program/plan.toml` was written with.
pub const TEST_PROGRAM_SEED: u64 = 2026;

/// Writes the example test program (every test of a lab's program on one axis, SIMULATED
/// records with known truth, [`crate::program_sim::write_test_program`]) into `dir`, created if
/// missing: `plan.toml` and the CSV records it names.
///
/// All or none: the records are made in a temporary folder inside `dir`, then written in place
/// together ([`gyrolab_io::atomic::write_outputs`]); a failure leaves `dir` as it was.
pub fn write_test_program_folder(dir: &std::path::Path, seed: u64) -> EvalResult<()> {
    std::fs::create_dir_all(dir)
        .map_err(|e| EvalError::Output(format!("{}: cannot create the folder: {e}", dir.display())))?;
    let staging = tempfile::Builder::new()
        .prefix(".gyrolab-staging-")
        .tempdir_in(dir)
        .map_err(|e| EvalError::Output(format!("{}: cannot make a temporary folder in it: {e}", dir.display())))?;
    crate::program_sim::write_test_program(staging.path(), seed)?;
    let mut names: Vec<std::ffi::OsString> = std::fs::read_dir(staging.path())
        .map_err(|e| EvalError::Output(format!("{}: {e}", staging.path().display())))?
        .filter_map(|e| e.ok().map(|e| e.file_name()))
        .collect();
    names.sort();
    let outputs = names
        .iter()
        .map(|name| {
            let from = staging.path().join(name);
            gyrolab_io::atomic::OutputFile::stream(dir.join(name), move |w| {
                std::io::copy(&mut std::fs::File::open(&from)?, w).map(drop)
            })
        })
        .collect();
    gyrolab_io::atomic::write_outputs(outputs, &[])?;
    Ok(())
}

/// CSV options of a simulated record: `decimals` fixed decimals (0 to 15) or the shortest form;
/// `comments` are written at the top.
pub fn csv_options(decimals: Option<u8>, comments: Vec<String>) -> EvalResult<SimCsvOptions> {
    // Simulating on a second thread while this one formats gives the same bytes, faster.
    let pipelined = std::thread::available_parallelism().is_ok_and(|n| n.get() > 1);
    let mut o = SimCsvOptions { pipelined, ..SimCsvOptions::default() };
    if let Some(d) = decimals {
        if d > 15 {
            return Err(gyrolab::validate::InvalidOption::new("decimals", format!("must be 0 to 15, got {d}")).into());
        }
        o.number_format = NumberFormat::Fixed { decimals: d };
    }
    o.comments.extend(comments);
    Ok(o)
}

/// What was simulated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SimRecord {
    /// A static record.
    Static,
    /// A rate-table test.
    RateTable,
}

/// Default bound on the samples (rows) of a simulated record: 1e9, tens of GB of CSV. A larger
/// record needs an explicit, larger bound (`--max-samples`).
pub const DEFAULT_MAX_SAMPLES: u64 = 1_000_000_000;

/// Bytes per row of a simulated CSV record, roughly (for the size announced in errors).
const APPROX_ROW_BYTES: f64 = 30.0;

/// The samples (rows) a record of this set-up would have (a real number: it may be too large
/// for any integer type).
pub fn record_samples(record: SimRecord, cfg: &SimConfig) -> f64 {
    match record {
        SimRecord::Static => cfg.static_record.duration_s * cfg.static_record.sample_rate_hz,
        SimRecord::RateTable => {
            let rt = &cfg.rate_table;
            let settling = match rt.settling {
                gyrolab::sim::SettlingRows::Flag => rt.settling_s * rt.sample_rate_hz,
                gyrolab::sim::SettlingRows::Drop => 0.0,
            };
            let per_plateau = f64::from(rt.samples_per_plateau) + settling.max(0.0).ceil();
            rt.rates_dps.len() as f64 * f64::from(rt.runs) * 2.0 * per_plateau + 2.0 * f64::from(rt.rest_samples)
        }
    }
}

/// Refuses, before anything is written, a record of more than `max_samples` samples; the error
/// states the record's size and names the bound (`max_samples`). Returns the samples.
///
/// ```
/// use gyrolab_eval::simulate::{check_record_size, sim_config, SimOverrides, SimRecord};
/// # fn main() -> Result<(), gyrolab_eval::EvalError> {
/// let cfg = sim_config(&SimOverrides { duration_s: Some(1e10), ..Default::default() })?;
/// let e = check_record_size(SimRecord::Static, &cfg, 1_000_000_000).unwrap_err();
/// assert!(e.to_string().contains("1e12 samples"), "{e}");
/// # Ok(())
/// # }
/// ```
pub fn check_record_size(record: SimRecord, cfg: &SimConfig, max_samples: u64) -> EvalResult<f64> {
    let n = record_samples(record, cfg);
    if n.is_finite() && n <= max_samples as f64 {
        return Ok(n);
    }
    if n.is_nan() {
        // An invalid duration or rate: left to the set-up's own validation, which names it.
        return Ok(n);
    }
    let what = match record {
        SimRecord::Static => "static record",
        SimRecord::RateTable => "rate-table test",
    };
    let bytes = gyrolab_io::text::size_text((n * APPROX_ROW_BYTES).min(u64::MAX as f64) as u64);
    Err(EvalError::conflict_on(
        &["max_samples"],
        format!(
            "the {what} would have {n:e} samples (about {bytes} of CSV), more than the bound of {max_samples:e} \
             samples: shorten it, or raise the bound with {{max_samples}} if you mean it"
        ),
    ))
}

/// Writes the record to `w`.
pub fn simulate_to(
    record: SimRecord,
    cfg: &SimConfig,
    opts: &SimCsvOptions,
    w: &mut (dyn Write + Send),
) -> Result<(), SimCsvError> {
    let model = cfg.sensor_model();
    match record {
        SimRecord::Static => write_static_csv(w, &model, &cfg.static_record, cfg.seed, opts).map(|_| ()),
        SimRecord::RateTable => write_rate_table_csv(w, &model, &cfg.rate_table, cfg.seed, opts).map(|_| ()),
    }
}

/// A simulated static record in memory: time from the start (s), the output in the model's
/// output unit, and the temperature (degC) when the set-up records it.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct StaticSamples {
    /// Time of each sample, s.
    pub time_s: Vec<f64>,
    /// Output of each sample.
    pub output: Vec<f64>,
    /// Temperature of each sample, degC (empty unless recorded).
    pub temp_c: Vec<f64>,
}

/// Simulates the static record of a set-up into memory (the same samples `simulate static`
/// writes for the same seed, before formatting).
pub fn simulate_static_samples(cfg: &SimConfig) -> EvalResult<StaticSamples> {
    let model = cfg.sensor_model();
    let mut generator = gyrolab::sim::StaticGenerator::new(&model, &cfg.static_record, cfg.seed)
        .map_err(|e| EvalError::conflict(format!("invalid simulation parameters: {e}")))?;
    let n = usize::try_from(generator.remaining()).unwrap_or(usize::MAX);
    let mut out = StaticSamples { time_s: Vec::with_capacity(n), output: Vec::with_capacity(n), temp_c: Vec::new() };
    let mut block = gyrolab::sim::StaticBlock::default();
    while generator.next_block(&mut block, 1 << 16) > 0 {
        out.time_s.extend_from_slice(&block.time_s);
        out.output.extend_from_slice(&block.output);
        if block.records_temperature {
            out.temp_c.extend_from_slice(&block.temp_c);
        }
    }
    Ok(out)
}

/// The error of a simulated record not written: the system's (an output failure) or the
/// parameters' (a conflict).
fn sim_error(e: SimCsvError) -> EvalError {
    match e {
        SimCsvError::Io(io) => EvalError::Output(format!("cannot write the simulated record: {io}")),
        other => EvalError::conflict(format!("invalid simulation parameters: {other}")),
    }
}

/// Writes a simulated record with `write`: into `out` whole or not at all (never a part of a
/// record left behind), else to standard output (a closed pipe ends it quietly).
pub fn write_simulated(
    out: Option<&std::path::Path>,
    write: impl FnOnce(&mut (dyn Write + Send)) -> Result<(), SimCsvError>,
) -> EvalResult<()> {
    match out {
        Some(path) => {
            let mut failure = None;
            let r = gyrolab_io::atomic::write_atomic_with(path, |w| {
                write(w).map_err(|e| {
                    let msg = e.to_string();
                    failure = Some(e);
                    std::io::Error::other(msg)
                })
            });
            match (r, failure) {
                (_, Some(e)) => Err(sim_error(e)),
                (Err(e), None) => Err(EvalError::Output(format!("{}: cannot write the file: {e}", path.display()))),
                (Ok(()), None) => Ok(()),
            }
        }
        None => {
            // Not locked: the writer may hand the output to a thread of its own (blocks of 64 KiB
            // or more go out in one write each).
            let mut stdout = std::io::stdout();
            match write(&mut stdout) {
                Err(SimCsvError::Io(e)) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
                r => r.map_err(sim_error),
            }
        }
    }
}
