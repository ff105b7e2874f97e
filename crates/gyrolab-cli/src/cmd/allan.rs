//! `gyrolab allan FILE`: Allan-variance family with confidence intervals and noise terms, one
//! result per output channel (channels computed in parallel).

use crate::args::AnalysisArgs;
use crate::error::CliResult;
use crate::output::{print, simulated_lines, to_json};
use crate::progress::Bar;
use clap::Args;
use gyrolab_eval::allan::AllanRequest;
use gyrolab_eval::allan_memory::{analyse_records_within, default_memory_bytes, parse_memory, MemoryPath};
use gyrolab_eval::filter_export::{check_inflate, export_files, parse_target, same_path, Estimator, ExportRequest};
use gyrolab_eval::simulate::reference_from_headers;
use gyrolab_eval::EvalError;
use gyrolab_report::allan::{allan_csv, allan_document_in, allan_text};
use std::path::PathBuf;

/// Options of `gyrolab allan`.
#[derive(Debug, Args)]
pub struct AllanArgs {
    /// A time series (`-`: standard input): a time column (`time_s`, `timestamp [ns]`, ...; or
    /// --sample-rate-hz) and gyro or accelerometer columns, their units in the names
    /// (`rate_dps`, `gyro_x [rad/s]`, `ax_m_s2`) or given with --unit; no header row: c1..cN.
    /// Also, by content: Parquet tables, and recordings (ROS 2 MCAP, ROS 1 bags, PX4 ULog):
    /// every IMU topic, six channels each.
    #[arg(value_name = "FILE")]
    pub file: PathBuf,
    #[command(flatten)]
    pub analysis: AnalysisArgs,
    /// Print CSV (file, channel, tau_s, m, dev, ci_low, ci_high, n_terms, alpha).
    #[arg(long, conflicts_with = "json")]
    pub csv: bool,
    /// Print JSON (keys in docs/JSON.md).
    #[arg(long)]
    pub json: bool,
    /// Write a Kalibr imu.yaml (gyro and accelerometer noise densities and random walks,
    /// update_rate, rostopic): channels combined by the largest value per entry; unresolved
    /// terms hold their upper bound (or the five-term fit value), named in a comment and in a
    /// `warning:` on stderr.
    #[arg(long, value_name = "FILE.yaml")]
    pub kalibr_yaml: Option<PathBuf>,
    /// Write an imu_utils-style YAML (gyr_n, gyr_w, acc_n, acc_w as continuous-time densities, as
    /// imu_utils prints them), by the same rule; for VINS-Fusion's per-sample values use
    /// `--export vins=FILE`.
    #[arg(long, value_name = "FILE.yaml")]
    pub imu_utils_yaml: Option<PathBuf>,
    /// Memory ceiling (such as 1GiB, 512MiB, 2GB; default: half the machine's memory): a
    /// delimited text file, a recording (MCAP, ROS 1 bag, ULog) or a Parquet table whose estimated in-memory
    /// size exceeds it is streamed (octave OADEV; long taus from every stride-th angle point,
    /// their EDF loss reported; docs/METHODS.md 3.2).
    #[arg(long, value_name = "SIZE")]
    pub memory: Option<String>,
    /// Write noise parameters for a filter stack, repeatable (all files or none): kalibr,
    /// openvins, vins, orbslam3, basalt, px4 (`param set` lines), px4-qgc (QGroundControl
    /// .params), ros-covariance; each in the stack's keys, units and time convention, with a
    /// header naming the record, rate, basis of each value and factors (docs/EXPORTS.md).
    #[arg(long = "export", value_name = "STACK=FILE")]
    pub exports: Vec<String>,
    /// Multiply every exported value by X (variances by X^2; default 1); recorded in the files.
    /// For the --export files only.
    #[arg(long, value_name = "X", allow_negative_numbers = true)]
    pub inflate: Option<f64>,
    /// Overbound each exported value: the smallest factor per parameter that puts the model's
    /// Allan deviation on or above the curve's upper confidence bound at every tau (factors
    /// recorded in the files and on stderr). For the --export files only.
    #[arg(long)]
    pub overbound: bool,
    /// Basis of the exported values: slopes (default: slope readings, else bounds, else the
    /// five-term fit), fit (five-term fit) or gmwm. For the --export files only (the text and
    /// JSON report every estimator).
    #[arg(long, value_name = "NAME")]
    pub estimator: Option<String>,
    /// Write the --export files even when their values come from a GMWM fit flagged POOR FIT
    /// (its model does not describe the curve); without it such a run writes nothing and exits
    /// with code 7.
    #[arg(long)]
    pub allow_poor_fit: bool,
}

impl AllanArgs {
    fn request(&self) -> CliResult<AllanRequest> {
        self.analysis.request(self.file.clone())
    }

    /// The export request (targets checked, before any analysis), or None without --export; the
    /// export options without --export, or two outputs naming one file, are usage errors.
    fn export_request(&self) -> CliResult<Option<ExportRequest>> {
        if self.exports.is_empty() {
            let given: Vec<&str> = [
                (self.inflate.is_some(), "--inflate"),
                (self.overbound, "--overbound"),
                (self.estimator.is_some(), "--estimator"),
                (self.allow_poor_fit, "--allow-poor-fit"),
            ]
            .into_iter()
            .filter_map(|(on, name)| on.then_some(name))
            .collect();
            if !given.is_empty() {
                return Err(EvalError::conflict(format!(
                    "{} applies to the --export files only: add --export STACK=FILE (--kalibr-yaml and --imu-utils-yaml write the slope readings as they are, with no factor)",
                    given.join(", ")
                ))
                .into());
            }
            self.check_distinct_outputs(Vec::new())?;
            return Ok(None);
        }
        let targets = self.exports.iter().map(|t| parse_target(t)).collect::<Result<Vec<_>, _>>()?;
        if let Some(x) = self.inflate {
            check_inflate(x)?;
        }
        self.check_distinct_outputs(
            targets.iter().map(|(stack, path)| (format!("--export {}=", stack.name()), path)).collect(),
        )?;
        Ok(Some(ExportRequest {
            estimator: Estimator::parse(self.estimator.as_deref().unwrap_or("slopes"))?,
            inflate: self.inflate.unwrap_or(1.0),
            overbound: self.overbound,
            allow_poor_fit: self.allow_poor_fit,
            targets,
        }))
    }

    /// Every output file named once (`outputs`: the exports' option and path, then the YAML
    /// files'): a second output to the same path would overwrite the first.
    fn check_distinct_outputs<'a>(&'a self, mut outputs: Vec<(String, &'a PathBuf)>) -> CliResult<()> {
        outputs.extend(self.kalibr_yaml.iter().map(|p| ("--kalibr-yaml".to_string(), p)));
        outputs.extend(self.imu_utils_yaml.iter().map(|p| ("--imu-utils-yaml".to_string(), p)));
        for (i, (first, path)) in outputs.iter().enumerate() {
            if let Some((second, _)) = outputs[i + 1..].iter().find(|(_, other)| same_path(other, path)) {
                return Err(EvalError::conflict(format!(
                    "{first} and {second} both name {}: each output needs its own file",
                    path.display()
                ))
                .into());
            }
        }
        Ok(())
    }
}

/// Runs `gyrolab allan`.
pub fn run(args: &AllanArgs) -> CliResult {
    let export = args.export_request()?;
    let mut request = args.request()?;
    if let Some((reference, stated)) = reference_from_headers(std::slice::from_ref(&args.file), &request.reference) {
        eprintln!("note: {}", crate::args::stated_reference_note(&args.file.display().to_string(), &stated));
        request.reference = reference;
    }
    let memory = match &args.memory {
        Some(text) => parse_memory(text)?,
        None => default_memory_bytes(),
    };
    let spinner = Bar::spinner(format!("analysing {}", args.file.display()));
    let outcomes = analyse_records_within(&request, memory);
    spinner.finish();
    let (outcomes, path) = outcomes?;
    if !args.csv || export.is_some() {
        // The text, the JSON and the exports show the GMWM: the channels' fits made side by side.
        gyrolab_eval::allan::prepare_gmwm(outcomes.iter().flat_map(|o| &o.analyses));
    }
    let streamed = match &path {
        MemoryPath::Streaming(s) => {
            eprintln!("note: {}", s.note(&args.file.display().to_string()));
            Some(s)
        }
        MemoryPath::InMemory { .. } => None,
    };
    for outcome in &outcomes {
        for n in &outcome.notes {
            let level = if n.is_warning() { "warning" } else { "note" };
            eprintln!("{level}: {}", n.render(&crate::error::flag));
        }
    }
    // Every file of the run made first, then written together: all or none, never over the record.
    let (mut files, mut warnings) =
        gyrolab_lab::exports::stack_files(&outcomes, args.kalibr_yaml.as_deref(), args.imu_utils_yaml.as_deref())?;
    if let Some(request) = &export {
        let (export_files, export_warnings) = export_files(&outcomes, &args.file, request)?;
        files.extend(export_files);
        warnings.extend(export_warnings);
    }
    if !files.is_empty() {
        let outputs = files.iter().map(|(p, b)| gyrolab_io::atomic::OutputFile::bytes(p.clone(), &b[..])).collect();
        let written = gyrolab_io::atomic::write_outputs(outputs, &[args.file.as_path()]).map_err(EvalError::from)?;
        for w in &warnings {
            eprintln!("warning: {w}");
        }
        if written.len() > 1 {
            eprintln!("note: wrote {}", written.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", "));
        }
    }
    let analyses: Vec<_> = outcomes.into_iter().flat_map(|o| o.analyses).collect();
    let analyses = &analyses;
    for line in analyses.iter().filter_map(|a| a.advice()) {
        eprintln!("{line}");
    }
    if args.json {
        let doc = allan_document_in(analyses, &path).ok_or_else(|| EvalError::conflict("no channel to analyse"))?;
        return print(&to_json(&doc)?);
    }
    if args.csv {
        return print(&allan_csv(analyses));
    }
    let simulated = simulated_lines(std::slice::from_ref(&args.file));
    let mut text: Vec<String> = analyses.iter().map(allan_text).collect();
    if let Some(s) = streamed {
        text.push(format!("memory: {}", s.note(&args.file.display().to_string())));
    }
    print(&(simulated + &text.join("\n") + "\n"))
}
