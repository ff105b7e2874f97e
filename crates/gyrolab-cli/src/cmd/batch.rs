//! `gyrolab batch INPUT... --out DIR`: the Allan analysis of many records (folders, globs, lists)
//! on every core, with a progress bar (throughput, time left), one stderr line per failure, a
//! summary table, and the combined results (`results.csv`, `results.parquet`: one row per record
//! and channel). Resumable: `DIR/batch-journal.jsonl` holds each record done, by the SHA-256 of
//! its bytes, and a batch started again passes over those.
//!
//! Exit code: 0 every input evaluated (now or by an earlier run); 4 some inputs failed (the
//! others evaluated and written; the failures listed on stderr and in `DIR/failures.csv`);
//! 2 bad usage (no input found, a journal of other options); 1 an output could not be written.

use crate::args::AnalysisArgs;
use crate::error::{flag, CliError, CliResult};
use crate::output::print;
use clap::Args;
use gyrolab::validate;
use gyrolab_eval::allan::AllanRequest;
use gyrolab_eval::Progress;
use gyrolab_lab::batch::{batch_folder, BatchFolderRequest};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::path::PathBuf;

/// The journal's file name in the output folder.
const JOURNAL: &str = "batch-journal.jsonl";

/// Options of `gyrolab batch`.
#[derive(Debug, Args)]
pub struct BatchArgs {
    /// Records: files, folders (their .csv, .tsv, .txt, .dat, .parquet, .mcap, .bag, .ulg and
    /// .log files at any depth) or glob patterns (quote them: 'fleet/**/*.mcap').
    #[arg(value_name = "INPUT")]
    pub inputs: Vec<String>,
    /// A file listing inputs, one a line (blank lines and # comments passed over); repeatable.
    #[arg(long = "list", value_name = "FILE")]
    pub lists: Vec<PathBuf>,
    /// Folder of the results (created if missing): results.csv, results.parquet, failures.csv
    /// and the journal batch-journal.jsonl that lets a batch started again resume.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Worker threads (default: one per core).
    #[arg(long, value_name = "N")]
    pub jobs: Option<usize>,
    /// No progress bar and no summary on standard output (failures still go to stderr).
    #[arg(long, short)]
    pub quiet: bool,
    /// In a folder, follow symbolic links that lead out of it too (by default only links to
    /// places inside the folder given are followed; a link cycle is walked once either way).
    #[arg(long)]
    pub follow_links: bool,
    #[command(flatten)]
    pub analysis: AnalysisArgs,
}

impl BatchArgs {
    fn allan(&self) -> CliResult<AllanRequest> {
        self.analysis.request(PathBuf::new())
    }
}

/// The progress bar of a batch: position, throughput and time left; hidden when stderr is not a
/// terminal (or `--quiet`), when failure lines go to stderr directly.
struct BatchBar(ProgressBar);

impl BatchBar {
    fn new(quiet: bool) -> BatchBar {
        if quiet || !std::io::stderr().is_terminal() {
            return BatchBar(ProgressBar::hidden());
        }
        let bar = ProgressBar::new(0);
        let template = "{spinner} [{elapsed_precise}] [{bar:30}] {pos}/{len} records, {per_sec}, {eta} left {msg}";
        if let Ok(style) = ProgressStyle::with_template(template) {
            bar.set_style(style.progress_chars("=> "));
        }
        BatchBar(bar)
    }

    fn line(&self, text: &str) {
        if self.0.is_hidden() {
            eprintln!("{text}");
        } else {
            self.0.println(text);
        }
    }
}

impl Progress for BatchBar {
    fn begin(&self, steps: u64) {
        self.0.set_length(steps);
    }
    fn advance(&self, steps: u64) {
        self.0.inc(steps);
    }
}

/// Runs `gyrolab batch`.
pub fn run(args: &BatchArgs) -> CliResult {
    let allan = args.allan()?;
    if let Some(n) = args.jobs {
        validate::positive("jobs", n as f64)?;
    }
    let bar = BatchBar::new(args.quiet);
    let request = BatchFolderRequest {
        inputs: &args.inputs,
        lists: &args.lists,
        out: &args.out,
        follow_links: args.follow_links,
        allan,
        jobs: args.jobs,
        journal: JOURNAL,
    };
    let outcome = batch_folder(&request, &bar, &|line: &str| bar.line(line), &flag);
    bar.0.finish_and_clear();
    let outcome = outcome?;
    if !args.quiet {
        print(&outcome.summary)?;
    }
    if let Some(failed) = outcome.failed {
        return Err(CliError::SomeFailed(failed));
    }
    Ok(())
}
