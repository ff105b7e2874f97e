//! `gyrolab simulate static|rate-table|test-program`: records with known truth, in exactly the
//! layouts that `gyrolab bias`, `gyrolab allan`, `gyrolab rate` and `gyrolab eval` read.

use crate::error::CliResult;
use clap::{Args, Subcommand};
use gyrolab::sim::Preset;
use gyrolab::units::OutputUnit;
use gyrolab_eval::simulate::{
    check_record_size, csv_options, sim_config, simulate_to, static_sim_config, write_simulated,
    write_test_program_folder, SimOverrides, SimRecord, DEFAULT_MAX_SAMPLES, TEST_PROGRAM_SEED,
};
use std::path::PathBuf;

/// What to simulate.
#[derive(Debug, Subcommand)]
pub enum SimulateCommand {
    /// A static (bias) record: time_s and the output (deg/s by default), optional temp_c. With
    /// no --preset, --config or error-term flag, a typical MEMS gyro (said on stderr).
    Static(Box<StaticArgs>),
    /// A rate-table test: rate_dps, run, stroke, output per sample, with rest records.
    RateTable(Box<RateTableArgs>),
    /// The example test program: plan.toml and its SIMULATED records (every test of a lab's
    /// program on one axis, about 17 MB) written into DIR, for `gyrolab eval DIR/plan.toml`.
    TestProgram(TestProgramArgs),
}

/// Options of `gyrolab simulate test-program`.
#[derive(Debug, Args)]
pub struct TestProgramArgs {
    /// Folder to write plan.toml and the records into (created if missing).
    #[arg(value_name = "DIR")]
    pub dir: PathBuf,
    /// Seed (default 2026: the records examples/test_program/plan.toml describes).
    #[arg(long)]
    pub seed: Option<u64>,
}

/// Options shared by both records.
#[derive(Debug, Args)]
pub struct CommonArgs {
    /// Write to this file (default: standard output); written whole or not at all.
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// A TOML set-up (seed, preset, [sensor], [static_record], [rate_table]); flags override it.
    #[arg(long, value_name = "FILE.toml")]
    pub config: Option<PathBuf>,
    /// Most samples (rows) the record may have (default 1e9): a larger record is refused before
    /// anything is written, with its size.
    #[arg(long, value_name = "N", value_parser = parse_max_samples)]
    pub max_samples: Option<u64>,
    /// Seed: the same seed gives the same bytes on every run (default 1).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Start from a sensor preset: adxrs646 (the paper's family), adis16470, stim300.
    #[arg(long, value_parser = parse_preset)]
    pub preset: Option<Preset>,
    /// Sample rate, Hz.
    #[arg(long, value_name = "HZ")]
    pub sample_rate_hz: Option<f64>,
    /// Output unit: dps (default without a preset), v, mv, lsb, rad_s.
    #[arg(long, value_name = "UNIT", value_parser = crate::args::parse_output_unit)]
    pub output_unit: Option<OutputUnit>,
    /// Scale factor, output units per deg/s.
    #[arg(long, value_name = "K", allow_hyphen_values = true)]
    pub scale_factor: Option<f64>,
    /// Zero-rate output (null), output units.
    #[arg(long, value_name = "F", allow_hyphen_values = true)]
    pub null: Option<f64>,
    /// Constant bias, deg/h.
    #[arg(long, value_name = "DPH", allow_hyphen_values = true)]
    pub bias_dph: Option<f64>,
    /// Angle random walk N, deg/sqrt(h).
    #[arg(long, value_name = "N", allow_hyphen_values = true)]
    pub arw_deg_rt_h: Option<f64>,
    /// Bias instability B, deg/h (flicker noise).
    #[arg(long, value_name = "B", allow_hyphen_values = true)]
    pub bias_instability_dph: Option<f64>,
    /// Rate random walk K, deg/h/sqrt(h).
    #[arg(long, value_name = "K", allow_hyphen_values = true)]
    pub rrw_deg_h_rt_h: Option<f64>,
    /// Rate ramp R, deg/h per hour.
    #[arg(long, value_name = "R", allow_hyphen_values = true)]
    pub rate_ramp_dph_per_h: Option<f64>,
    /// Warm-up transient: bias B + A exp(-t/tau) after power-on (the record's start), A in deg/h.
    #[arg(long, value_name = "A", allow_hyphen_values = true, requires = "warmup_time_constant_s")]
    pub warmup_amplitude_dph: Option<f64>,
    /// Warm-up time constant tau, s.
    #[arg(long, value_name = "TAU", allow_hyphen_values = true)]
    pub warmup_time_constant_s: Option<f64>,
    /// Output quantization step, output units.
    #[arg(long, value_name = "STEP", allow_hyphen_values = true)]
    pub output_quantization_step: Option<f64>,
    /// Bias temperature coefficient, (deg/h)/degC.
    #[arg(long, value_name = "C", allow_hyphen_values = true)]
    pub bias_temp_coeff_dph_per_c: Option<f64>,
    /// Constant temperature, degC (with --temp-ramp-c-per-h: the start temperature).
    #[arg(long, value_name = "C", allow_hyphen_values = true)]
    pub temp_c: Option<f64>,
    /// Temperature ramp, degC per hour.
    #[arg(long, value_name = "C_PER_H", allow_hyphen_values = true)]
    pub temp_ramp_c_per_h: Option<f64>,
    /// Latitude, degrees: adds the earth rate seen by a vertical input axis.
    #[arg(long, value_name = "DEG", allow_hyphen_values = true)]
    pub latitude: Option<f64>,
    /// Write numbers with this many decimals instead of the shortest round-trip form.
    #[arg(long, value_name = "N")]
    pub decimals: Option<u8>,
}

/// Options of `gyrolab simulate static`.
#[derive(Debug, Args)]
pub struct StaticArgs {
    #[command(flatten)]
    pub common: CommonArgs,
    /// Record length, seconds.
    #[arg(long, value_name = "S")]
    pub duration_s: Option<f64>,
    /// Add a temp_c column.
    #[arg(long)]
    pub record_temperature: bool,
}

/// Options of `gyrolab simulate rate-table`.
#[derive(Debug, Args)]
pub struct RateTableArgs {
    #[command(flatten)]
    pub common: CommonArgs,
    /// Table rates, deg/s (default: the paper's 14 rates).
    #[arg(long, value_name = "DPS,...", value_delimiter = ',', allow_hyphen_values = true)]
    pub rates: Vec<f64>,
    /// Number of runs (each a forward then a reverse stroke).
    #[arg(long)]
    pub runs: Option<u32>,
    /// Samples recorded on each plateau (after settling).
    #[arg(long, value_name = "N")]
    pub samples_per_plateau: Option<u32>,
    /// Settling time at the start of each plateau, dropped, seconds.
    #[arg(long, value_name = "S")]
    pub settling_s: Option<f64>,
    /// Rest samples at the start and at the end (0: no rest records).
    #[arg(long, value_name = "N")]
    pub rest_samples: Option<u32>,
    /// Hysteresis: forward-minus-reverse offset, deg/s.
    #[arg(long, value_name = "DPS", allow_hyphen_values = true)]
    pub hysteresis_dps: Option<f64>,
    /// Quadratic nonlinearity coefficient k2 (rate' = w + k2 w^2 + k3 w^3), 1/(deg/s).
    #[arg(long, value_name = "K2", allow_hyphen_values = true)]
    pub nonlinearity_quadratic_per_dps: Option<f64>,
    /// Scale-factor asymmetry (K+ - K-)/K, ppm.
    #[arg(long, value_name = "PPM", allow_hyphen_values = true)]
    pub scale_factor_asymmetry_ppm: Option<f64>,
    /// Run-to-run scale-factor change (1 sigma), ppm.
    #[arg(long, value_name = "PPM")]
    pub run_to_run_scale_factor_sigma_ppm: Option<f64>,
}

fn parse_preset(s: &str) -> Result<Preset, String> {
    Preset::parse(s).ok_or_else(|| {
        let names: Vec<&str> = Preset::ALL.iter().map(|p| p.name()).collect();
        format!("unknown preset '{s}': expected one of {}", names.join(", "))
    })
}

/// Parses `--max-samples`: a whole number, in plain or exponent form (`1e10`).
fn parse_max_samples(s: &str) -> Result<u64, String> {
    let v: f64 = s.trim().parse().map_err(|_| format!("'{s}' is not a number of samples"))?;
    if v.is_finite() && v >= 1.0 && v.fract() == 0.0 && v <= u64::MAX as f64 {
        Ok(v as u64)
    } else {
        Err(format!("{s}: expected a whole number of samples, at least 1"))
    }
}

fn overrides(c: &CommonArgs) -> SimOverrides {
    SimOverrides {
        config: c.config.clone(),
        seed: c.seed,
        preset: c.preset,
        sample_rate_hz: c.sample_rate_hz,
        output_unit: c.output_unit,
        scale_factor: c.scale_factor,
        null: c.null,
        bias_dph: c.bias_dph,
        arw_deg_rt_h: c.arw_deg_rt_h,
        bias_instability_dph: c.bias_instability_dph,
        rrw_deg_h_rt_h: c.rrw_deg_h_rt_h,
        rate_ramp_dph_per_h: c.rate_ramp_dph_per_h,
        warmup_amplitude_dph: c.warmup_amplitude_dph,
        warmup_time_constant_s: c.warmup_time_constant_s,
        output_quantization_step: c.output_quantization_step,
        bias_temp_coeff_dph_per_c: c.bias_temp_coeff_dph_per_c,
        temp_c: c.temp_c,
        temp_ramp_c_per_h: c.temp_ramp_c_per_h,
        latitude_deg: c.latitude,
        ..SimOverrides::default()
    }
}

/// Runs `gyrolab simulate`.
pub fn run(cmd: &SimulateCommand) -> CliResult {
    let (record, common, o) = match cmd {
        SimulateCommand::TestProgram(a) => {
            write_test_program_folder(&a.dir, a.seed.unwrap_or(TEST_PROGRAM_SEED))?;
            eprintln!(
                "wrote {} (plan.toml and its SIMULATED records): gyrolab eval {}/plan.toml --out report/",
                a.dir.display(),
                a.dir.display()
            );
            return Ok(());
        }
        SimulateCommand::Static(a) => (
            SimRecord::Static,
            &a.common,
            SimOverrides { duration_s: a.duration_s, record_temperature: a.record_temperature, ..overrides(&a.common) },
        ),
        SimulateCommand::RateTable(a) => (
            SimRecord::RateTable,
            &a.common,
            SimOverrides {
                rates_dps: a.rates.clone(),
                runs: a.runs,
                samples_per_plateau: a.samples_per_plateau,
                settling_s: a.settling_s,
                rest_samples: a.rest_samples,
                hysteresis_dps: a.hysteresis_dps,
                nonlinearity_quadratic_per_dps: a.nonlinearity_quadratic_per_dps,
                scale_factor_asymmetry_ppm: a.scale_factor_asymmetry_ppm,
                run_to_run_scale_factor_sigma_ppm: a.run_to_run_scale_factor_sigma_ppm,
                ..overrides(&a.common)
            },
        ),
    };
    let (cfg, typical) = match record {
        SimRecord::Static => static_sim_config(&o)?,
        SimRecord::RateTable => (sim_config(&o)?, None),
    };
    check_record_size(record, &cfg, common.max_samples.unwrap_or(DEFAULT_MAX_SAMPLES))?;
    let mut comments = vec![format!("command: {}", std::env::args().collect::<Vec<_>>().join(" "))];
    if let Some(t) = typical {
        let unit = cfg.sensor_model().output_unit;
        eprintln!(
            "note: no --preset and no noise flag given: simulating a {}, output in {unit} (--preset NAME, \
             or --arw-deg-rt-h, --bias-instability-dph, --bias-dph ... for another sensor; --arw-deg-rt-h 0 for \
             a noise-free record)",
            t.describe()
        );
        comments.push(format!("defaults: {} (no preset and no noise flag given)", t.describe()));
    }
    let opts = csv_options(common.decimals, comments)?;
    Ok(write_simulated(common.out.as_deref(), |w| simulate_to(record, &cfg, &opts, w))?)
}
