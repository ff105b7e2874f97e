//! Argument types shared by several commands: unit parsers, the output-to-rate reference and
//! the options of an Allan analysis (`allan`, `batch`).

use crate::error::CliResult;
use clap::Args;
use gyrolab::allan::DeviationKind;
use gyrolab::units::{OutputUnit, RateUnit};
use gyrolab_eval::allan::{parse_confidence, parse_taus, AllanRequest, GapPolicy};
use gyrolab_eval::reference::ReferenceRequest;
use gyrolab_eval::EvalError;
use std::path::PathBuf;

/// Parses a rate unit option.
pub fn parse_rate_unit(s: &str) -> Result<RateUnit, String> {
    RateUnit::parse(s).ok_or_else(|| format!("unknown rate unit '{s}': expected dps, rad_s or dph"))
}

/// Parses an output unit option.
pub fn parse_output_unit(s: &str) -> Result<OutputUnit, String> {
    OutputUnit::parse(s).ok_or_else(|| format!("unknown output unit '{s}': expected v, mv, lsb, dps or rad_s"))
}

/// Options describing a log file's layout: units, time column, names of a headerless file.
#[derive(Debug, Clone, Default, Args)]
pub struct LayoutArgs {
    /// Unit of a column, `COLUMN=UNIT` (`gx=rad/s`, `ax=m/s^2`, `stamp=ns` for the time
    /// column), or `UNIT` for every output column without one (one rate or output unit, and one
    /// acceleration unit for columns named as accelerometers such as `ax`); repeatable. Units:
    /// v, mv, lsb, dps (deg/s), dph, rad_s (rad/s), mrad_s, m_s2 (m/s^2), g, mg.
    #[arg(long = "unit", value_name = "[COLUMN=]UNIT")]
    pub units: Vec<String>,
    /// The time column (default: the first column named time, t, timestamp, stamp, ...).
    #[arg(long, value_name = "NAME")]
    pub time_column: Option<String>,
    /// Column names of a file without a header row (default c1,c2,...).
    #[arg(long, value_name = "A,B,...", value_delimiter = ',')]
    pub names: Vec<String>,
}

impl LayoutArgs {
    /// The layout request.
    pub fn layout(&self) -> gyrolab_eval::layout::LogLayout {
        gyrolab_eval::layout::LogLayout {
            units: self.units.clone(),
            time_column: self.time_column.clone(),
            names: self.names.clone(),
        }
    }
}

/// Options naming the output-to-rate reference.
#[derive(Debug, Clone, Args)]
pub struct ReferenceArgs {
    /// Calibration file written by `gyrolab rate --cal-out` (scale factor K and null F0).
    #[arg(long, value_name = "FILE.toml", conflicts_with = "scale_factor")]
    pub cal: Option<PathBuf>,
    /// Axis of the calibration file to use (needed when it has several).
    #[arg(long = "cal-axis", value_name = "NAME", requires = "cal")]
    pub cal_axis: Option<String>,
    /// Scale factor K in output units per deg/s (e.g. 0.0075 for V, 7.5 for mV outputs).
    #[arg(long, value_name = "K", allow_hyphen_values = true)]
    pub scale_factor: Option<f64>,
    /// Zero-rate output (null) in output units, with --scale-factor.
    #[arg(long, value_name = "F", allow_hyphen_values = true, requires = "scale_factor")]
    pub null: Option<f64>,
}

impl ReferenceArgs {
    /// The reference request.
    pub fn request(&self) -> ReferenceRequest {
        ReferenceRequest {
            calibration: self.cal.clone(),
            calibration_axis: self.cal_axis.clone(),
            scale_factor: self.scale_factor,
            null: self.null,
        }
    }
}

/// What to read of a static record and how to turn its outputs into rates, shared by `bias`,
/// `allan` and `batch`: topics, columns, their layout, the sample rate and the reference.
#[derive(Debug, Clone, Args)]
pub struct RecordArgs {
    /// Topic of a recording to read (default: every IMU topic), repeatable; `gyrolab inspect
    /// FILE` lists them.
    #[arg(long = "topic", value_name = "NAME")]
    pub topics: Vec<String>,
    #[command(flatten)]
    pub layout: LayoutArgs,
    /// Output columns to read (default: every output column), repeatable.
    #[arg(long = "column", value_name = "NAME")]
    pub columns: Vec<String>,
    /// Sample rate in Hz (required when the file has no time column).
    #[arg(long, value_name = "HZ")]
    pub sample_rate_hz: Option<f64>,
    #[command(flatten)]
    pub reference: ReferenceArgs,
}

/// The options of an Allan analysis of a record, shared by `allan` (one file) and `batch`
/// (many): the record's options ([`RecordArgs`]), the deviation and its taus.
#[derive(Debug, Clone, Args)]
pub struct AnalysisArgs {
    #[command(flatten)]
    pub record: RecordArgs,
    /// Deviation: oadev (default), adev, mdev, tdev, hdev, ohdev, totdev.
    #[arg(long, default_value = "oadev", value_name = "KIND")]
    pub kind: String,
    /// Taus: octave (default), decade, N/decade (e.g. 10/decade), all, or seconds (0.1,1,10).
    #[arg(long, default_value = "octave", value_name = "LIST")]
    pub taus: String,
    /// Confidence level of the bounds (default 0.683), or `none`.
    #[arg(long, default_value = "0.683", value_name = "C")]
    pub confidence: String,
    /// Fit the five-term noise model over this tau range only, seconds: LOW,HIGH.
    #[arg(long, value_name = "LOW,HIGH", value_delimiter = ',', num_args = 1..=2)]
    pub fit_range: Vec<f64>,
    /// Missing samples (gaps in the time stamps, NaN or empty cells, dropout rows): `fill`
    /// (default: runs of up to 3 missing samples filled by linear interpolation when at most 1 %
    /// of the record is missing, else as `analyse`), `analyse` (terms that touch one are left
    /// out; OADEV, ADEV, OHDEV, HDEV), `contiguous` (the samples read taken as consecutive) or
    /// `error`.
    #[arg(long, default_value = "fill", value_name = "POLICY")]
    pub gaps: String,
    /// Analyse a record whose gyro or accelerometer channels moved (the stillness check: 1 s
    /// windows against the still level, docs/METHODS.md): without it such a record is refused
    /// (exit 2); with it every output (text, JSON, Kalibr and export files) is marked MOTION.
    #[arg(long)]
    pub allow_motion: bool,
    /// Analyse the record from this many seconds after its first sample (each topic of a
    /// recording from its own first sample).
    #[arg(long, value_name = "SECONDS")]
    pub start: Option<f64>,
    /// Analyse the record up to (not including) this many seconds after its first sample.
    #[arg(long, value_name = "SECONDS")]
    pub end: Option<f64>,
}

impl AnalysisArgs {
    /// The analysis request of `file`.
    pub fn request(&self, file: PathBuf) -> CliResult<AllanRequest> {
        let kind = DeviationKind::parse(&self.kind).map_err(|e| EvalError::conflict(e.to_string()))?;
        let record = &self.record;
        Ok(AllanRequest {
            file,
            columns: record.columns.clone(),
            sample_rate_hz: record.sample_rate_hz,
            reference: record.reference.request(),
            kind,
            taus: parse_taus(&self.taus)?,
            confidence: parse_confidence(&self.confidence)?,
            fit_range_s: gyrolab::validate::increasing_pair("fit_range_s", &self.fit_range)?,
            layout: record.layout.layout(),
            gaps: GapPolicy::parse(&self.gaps)?,
            topics: record.topics.clone(),
            allow_motion: self.allow_motion,
            window_s: (self.start, self.end),
        })
    }
}

/// The note saying that a simulated record's own header gave the scale factor and null.
pub fn stated_reference_note(file: &str, r: &gyrolab_eval::simulate::StatedReference) -> String {
    let unit = r.output_unit;
    format!(
        "{file}: scale factor {} {unit}/(deg/s) and null {} {unit} read from the header comments `gyrolab \
         simulate` wrote (--scale-factor and --null, or --cal, use others)",
        r.scale_factor_per_dps, r.null
    )
}

/// Where the records store is (`gyrolab store ...`; docs/STORE.md).
#[derive(Debug, Clone, Args)]
pub struct StoreLocation {
    /// The store: an SQLite file or a postgres:// URL (default: GYROLAB_STORE, else gyrolab.db
    /// in the current folder, for every command).
    #[arg(long = "store", value_name = "PATH|URL")]
    pub store: Option<String>,
}

/// How a store query prints its table: aligned text (default), `--json` or `--csv` on standard
/// output, and optionally a Parquet file of the same table.
#[derive(Debug, Clone, Args)]
pub struct QueryOutput {
    /// Print JSON instead of the text table.
    #[arg(long, conflicts_with = "csv")]
    pub json: bool,
    /// Print CSV instead of the text table (one header row; units in a column).
    #[arg(long)]
    pub csv: bool,
    /// Also write the table to this Parquet file (same columns as the CSV; numbers DOUBLE,
    /// counts INT64, empty cells null).
    #[arg(long, value_name = "FILE.parquet")]
    pub parquet: Option<PathBuf>,
}

/// The environment variable naming the account a write to the store is made as.
pub const USER_ENV: &str = "GYROLAB_USER";
/// The environment variable holding that account's password.
pub const PASSWORD_ENV: &str = "GYROLAB_PASSWORD";

/// Who writes to the store (docs/STORE.md "Accounts and attribution"): `--user NAME` (or
/// GYROLAB_USER) with the password from GYROLAB_PASSWORD, `--password-stdin` or a prompt at the
/// terminal (no echo). A store without accounts takes writes without them.
#[derive(Debug, Clone, Default, Args)]
pub struct AuthArgs {
    /// The account to write as (default: GYROLAB_USER). Its password: `--password-stdin`, else
    /// GYROLAB_PASSWORD, else a prompt at the terminal.
    #[arg(long = "user", value_name = "NAME")]
    pub user: Option<String>,
    /// Read the password from the first line of standard input.
    #[arg(long)]
    pub password_stdin: bool,
}

/// The first line of standard input, without its line end (a password).
pub fn stdin_line() -> CliResult<String> {
    let mut line = String::new();
    std::io::stdin()
        .read_line(&mut line)
        .map_err(|e| crate::error::CliError::Usage(format!("cannot read the password from standard input: {e}")))?;
    while line.ends_with('\n') || line.ends_with('\r') {
        line.pop();
    }
    Ok(line)
}

/// A password typed at the terminal without echo (`prompt` printed on the terminal), or a usage
/// error saying where else a password may come from.
pub fn prompt_password(prompt: &str, alternatives: &str) -> CliResult<String> {
    use std::io::IsTerminal;
    if !std::io::stdin().is_terminal() {
        return Err(crate::error::CliError::Usage(format!(
            "no password: not at a terminal; give it with {alternatives}"
        )));
    }
    rpassword::prompt_password(prompt)
        .map_err(|e| crate::error::CliError::Usage(format!("cannot read the password at the terminal: {e}")))
}

impl AuthArgs {
    /// The account name given (`--user`, else GYROLAB_USER), if any.
    pub fn user(&self) -> Option<String> {
        self.user.clone().filter(|u| !u.is_empty()).or_else(|| std::env::var(USER_ENV).ok().filter(|u| !u.is_empty()))
    }

    /// The credentials (name, password) when an account is named; `stdin_free`: whether
    /// `--password-stdin` may read this password (false when standard input carries another).
    pub fn credentials(&self, stdin_free: bool) -> CliResult<Option<(String, String)>> {
        let Some(user) = self.user() else {
            if self.password_stdin && stdin_free {
                return Err(crate::error::CliError::Usage(
                    "--password-stdin without an account: name it with --user NAME or GYROLAB_USER".into(),
                ));
            }
            return Ok(None);
        };
        let password = if self.password_stdin && stdin_free {
            stdin_line()?
        } else if let Ok(p) = std::env::var(PASSWORD_ENV) {
            p
        } else {
            prompt_password(&format!("Password of {user}: "), &format!("{PASSWORD_ENV} or --password-stdin"))?
        };
        Ok(Some((user, password)))
    }
}
