//! `gyrolab allan FILE`: Allan-variance family with confidence intervals and noise terms, one
//! result per output channel (channels computed in parallel).

use crate::error::{CliError, CliResult};
use crate::output::{print, to_json, write_file};
use crate::reference::{Reference, ReferenceArgs};
use clap::Args;
use gyrolab::allan::{deviation_from_rate, AllanCurve, AllanError, AllanOptions, DeviationKind, TauList};
use gyrolab::noise::{fit_noise_model, slope_line_terms};
use gyrolab_io::series::{read_series_all, ChannelInfo, SeriesData, SeriesOptions};
use gyrolab_io::DataError;
use gyrolab_report::allan::{allan_csv, allan_document, allan_text, kalibr_yaml, ChannelAnalysis};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// Options of `gyrolab allan`.
#[derive(Debug, Args)]
pub struct AllanArgs {
    /// A time series: a time column `time_s` (or --sample-rate-hz) and output columns with unit
    /// suffixes (`rate_dps`, `gyro_x_v`, ...).
    #[arg(value_name = "FILE")]
    pub file: PathBuf,
    /// Output columns to analyse (default: every output column), repeatable.
    #[arg(long = "column", value_name = "NAME")]
    pub columns: Vec<String>,
    /// Sample rate in Hz (required when the file has no time column).
    #[arg(long, value_name = "HZ")]
    pub sample_rate_hz: Option<f64>,
    #[command(flatten)]
    pub reference: ReferenceArgs,
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
    #[arg(long, value_name = "LOW,HIGH", value_delimiter = ',', num_args = 2)]
    pub fit_range: Vec<f64>,
    /// Print CSV (file, channel, tau_s, m, dev, ci_low, ci_high, n_terms, alpha).
    #[arg(long, conflicts_with = "json")]
    pub csv: bool,
    /// Print JSON (keys in docs/JSON.md).
    #[arg(long)]
    pub json: bool,
    /// Write Kalibr imu.yaml gyroscope entries (first channel) to this file.
    #[arg(long, value_name = "FILE.yaml")]
    pub kalibr_yaml: Option<PathBuf>,
}

fn usage(e: impl std::fmt::Display) -> CliError {
    CliError::Usage(e.to_string())
}

/// The sample interval: from the option, or from the time column (which must be uniform).
fn sample_interval(data: &SeriesData, path: &Path, given_hz: Option<f64>) -> CliResult<f64> {
    if let Some(f) = given_hz {
        return Ok(1.0 / f);
    }
    let Some(t) = &data.time else {
        return Err(CliError::Data(DataError::new(path, "no time column (time_s): give --sample-rate-hz")));
    };
    if t.len() < 2 {
        return Err(CliError::Data(DataError::new(path, "fewer than two samples: nothing to analyse")));
    }
    let mut dts: Vec<f64> = t.windows(2).take(100_000).map(|w| w[1] - w[0]).collect();
    dts.sort_by(f64::total_cmp);
    let nominal = dts[dts.len() / 2];
    if !(nominal.is_finite() && nominal > 0.0) {
        return Err(CliError::Data(DataError::new(
            path,
            "the time stamps do not increase: expected a uniform time column",
        )));
    }
    for (i, w) in t.windows(2).enumerate() {
        let dt = w[1] - w[0];
        if !dt.is_finite() || (dt - nominal).abs() > 0.5 * nominal {
            let line = data.lines.get(i + 1).copied().unwrap_or(0);
            return Err(CliError::Data(
                DataError::new(
                    path,
                    format!(
                        "irregular sampling: interval {dt} s where the record's interval is {nominal} s; the Allan variance needs uniform samples (cut the record at the gap)"
                    ),
                )
                .at_line(line),
            ));
        }
    }
    // The mean interval over the whole record is the best estimate of tau0.
    Ok((t[t.len() - 1] - t[0]) / (t.len() - 1) as f64)
}

/// The deviation curve of one channel's rate samples; a non-finite sample is an error naming
/// its file line and column (`lines[i]` is the line of sample i).
pub fn channel_curve(
    path: &Path,
    info: &ChannelInfo,
    values: Vec<f64>,
    lines: &[u64],
    tau0_s: f64,
    opts: &AllanOptions,
) -> CliResult<AllanCurve> {
    deviation_from_rate(values, tau0_s, opts).map_err(|e| match e {
        AllanError::NonFinite { index, value } => CliError::Data(
            DataError::new(
                path,
                format!("sample {value} is not a finite number: the Allan variance needs a complete record"),
            )
            .at_line(lines.get(index).copied().unwrap_or(0))
            .at_column(info.column, Some(&info.name)),
        ),
        other => CliError::Data(DataError::new(path, format!("channel '{}': {other}", info.name))),
    })
}

/// Runs `gyrolab allan`.
pub fn run(args: &AllanArgs) -> CliResult {
    let kind = DeviationKind::parse(&args.kind).map_err(usage)?;
    let taus = if args.taus.chars().next().is_some_and(|c| c.is_ascii_digit()) && !args.taus.contains('/') {
        let v: Result<Vec<f64>, _> = args.taus.split(',').map(|s| s.trim().parse::<f64>()).collect();
        TauList::Seconds(v.map_err(|_| {
            usage(format!("--taus '{}': expected octave, decade, all, N/decade or seconds like 0.1,1,10", args.taus))
        })?)
    } else {
        TauList::parse(&args.taus).map_err(usage)?
    };
    let confidence = match args.confidence.trim() {
        "none" => None,
        c => match c.parse::<f64>() {
            Ok(x) if x > 0.0 && x < 1.0 => Some(x),
            _ => return Err(usage(format!("--confidence must lie strictly between 0 and 1, or be 'none'; got '{c}'"))),
        },
    };
    if let Some(f) = args.sample_rate_hz {
        if !(f.is_finite() && f > 0.0) {
            return Err(usage(format!("--sample-rate-hz must be a positive number, got {f}")));
        }
    }
    let fit_range = match args.fit_range.as_slice() {
        [] => None,
        [a, b] if *a > 0.0 && b > a => Some((*a, *b)),
        _ => return Err(usage("--fit-range needs two increasing positive taus in seconds: LOW,HIGH")),
    };
    let reference = Reference::from_args(&args.reference)?;
    let path = &args.file;
    let options = SeriesOptions {
        sample_rate_hz: args.sample_rate_hz,
        channels: if args.columns.is_empty() { None } else { Some(args.columns.clone()) },
        ..SeriesOptions::default()
    };
    let spinner = indicatif::ProgressBar::new_spinner();
    spinner.set_message(format!("reading {}", path.display()));
    spinner.enable_steady_tick(std::time::Duration::from_millis(200));
    let mut data = read_series_all(path, &options)?;
    let tau0 = sample_interval(&data, path, args.sample_rate_hz)?;
    data.time = None;
    spinner.set_message(format!("computing {}", kind.name().to_uppercase()));
    let opts = AllanOptions { kind, taus, confidence, max_factor: None };
    let infos = data.header.channels.clone();
    let lines = std::mem::take(&mut data.lines);
    let channels = std::mem::take(&mut data.channels);
    let results: Vec<CliResult<ChannelAnalysis>> = channels
        .into_par_iter()
        .zip(infos.into_par_iter())
        .map(|(mut values, info)| {
            let (rate_unit, calibrated) = match reference
                .for_unit(info.unit)
                .map_err(|m| usage(format!("{}: channel '{}': {m}", path.display(), info.name)))?
            {
                Some((k, null)) => {
                    let null = null.unwrap_or(0.0);
                    values.iter_mut().for_each(|v| *v = (*v - null) / k);
                    ("deg/s".to_string(), true)
                }
                None => match info.unit.native_scale_factor_per_dps() {
                    Some(k) => {
                        values.iter_mut().for_each(|v| *v /= k);
                        ("deg/s".to_string(), true)
                    }
                    None => (info.unit.symbol().to_string(), false),
                },
            };
            values.reserve_exact(1);
            let curve = channel_curve(path, &info, values, &lines, tau0, &opts)?;
            let allan_kind = matches!(kind, DeviationKind::Oadev | DeviationKind::Adev);
            let (slope_lines, model_fit, noise_note) = if !calibrated {
                (
                    None,
                    None,
                    Some(format!(
                        "the data are in {rate_unit}: give --cal or --scale-factor for noise terms in deg units"
                    )),
                )
            } else if !allan_kind {
                (None, None, Some("noise terms are read from the Allan deviation (--kind oadev or adev)".to_string()))
            } else {
                let s = slope_line_terms(&curve).ok();
                let f = fit_noise_model(&curve, fit_range).ok();
                (s, f, None)
            };
            Ok(ChannelAnalysis {
                file: path.display().to_string(),
                channel: info.name.clone(),
                rate_unit,
                curve,
                slope_lines,
                model_fit,
                noise_note,
            })
        })
        .collect();
    spinner.finish_and_clear();
    let analyses: Vec<ChannelAnalysis> = results.into_iter().collect::<Result<_, _>>()?;
    if let Some(yaml) = &args.kalibr_yaml {
        let first = analyses.first().ok_or_else(|| usage("no channel to analyse"))?;
        let text = kalibr_yaml(first, 1.0 / tau0).ok_or_else(|| {
            usage("no angle random walk could be read from the curve (calibrate the data with --cal or --scale-factor and use --kind oadev)")
        })?;
        write_file(yaml, text.as_bytes())?;
    }
    if args.json {
        let doc = allan_document(&analyses).ok_or_else(|| usage("no channel to analyse"))?;
        return print(&to_json(&doc)?);
    }
    if args.csv {
        return print(&allan_csv(&analyses));
    }
    let text: Vec<String> = analyses.iter().map(allan_text).collect();
    print(&(text.join("\n") + "\n"))
}
