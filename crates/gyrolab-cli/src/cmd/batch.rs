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
use gyrolab_lab::batch::{
    collect_inputs, journal_line, journal_rows, options_fingerprint, results_csv, results_parquet,
    run_batch, BatchRequest, BatchSink, DoneInput, FailedInput, Skipped,
};
use gyrolab_lab::batch::{failure_text, failures_csv, open_journal, summary_text};
use gyrolab_eval::{EvalError, Progress};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::sync::Mutex;

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

/// Appends each input done to the journal (one line, one write, under a lock) and shows each
/// failure.
struct JournalSink<'a> {
    file: Mutex<std::fs::File>,
    bar: &'a BatchBar,
}

impl BatchSink for JournalSink<'_> {
    fn done(&self, input: &DoneInput) -> Result<(), String> {
        let line = journal_line(input);
        let mut f = self.file.lock().unwrap_or_else(|p| p.into_inner());
        f.write_all(line.as_bytes()).map_err(|e| format!("cannot append to the journal: {e}"))
    }
    fn failed(&self, input: &FailedInput) {
        self.bar.line(&format!("failed: {}", failure_text(input, &flag)));
    }
}

/// Runs `gyrolab batch`.
pub fn run(args: &BatchArgs) -> CliResult {
    let allan = args.allan()?;
    if let Some(n) = args.jobs {
        validate::positive("jobs", n as f64)?;
    }
    let collected = collect_inputs(&args.inputs, &args.lists, Some(&args.out), args.follow_links)?;
    for (path, why) in &collected.passed_over {
        eprintln!("note: {}: passed over: {why}", gyrolab_io::text::path_text(path));
    }
    let inputs = collected.files;
    if inputs.is_empty() {
        return Err(
            EvalError::conflict("no record to evaluate: give files, folders, glob patterns or --list FILE").into()
        );
    }
    let options = options_fingerprint(&allan);
    let (mut journal, file) = open_journal(&args.out, JOURNAL, &options)?;
    if journal.unreadable_lines > 0 {
        eprintln!(
            "note: {} line(s) of {} were cut short by an interrupted run; their records are evaluated again",
            journal.unreadable_lines,
            args.out.join(JOURNAL).display()
        );
    }
    let bar = BatchBar::new(args.quiet);
    let sink = JournalSink { file: Mutex::new(file), bar: &bar };
    let request = BatchRequest { inputs, allan, jobs: args.jobs };
    let outcome = run_batch(&request, &journal, &sink, &bar);
    bar.0.finish_and_clear();
    let outcome = outcome?;
    let file = sink.file.into_inner().unwrap_or_else(|p| p.into_inner());
    file.sync_data().map_err(|e| CliError::Output(format!("{}: {e}", args.out.join(JOURNAL).display())))?;
    let now = outcome.evaluated.len();
    // The batch's inputs, which no table may overwrite (`--out .` among the records).
    let input_files: Vec<PathBuf> = outcome
        .evaluated
        .iter()
        .map(|d| d.file.clone())
        .chain(outcome.failures.iter().map(|f| f.file.clone()))
        .chain(outcome.skipped.iter().map(|s| match s {
            Skipped::AlreadyDone { file } | Skipped::SameAs { file, .. } => file.clone(),
        }))
        .collect();
    for d in outcome.evaluated {
        journal.entries.insert(d.sha256.clone(), d);
    }
    // The union of this run and the earlier ones, in file order: complete or untouched.
    let rows = journal_rows(&journal);
    let csv = results_csv(&rows);
    let parquet = results_parquet(&rows)?;
    let failures_csv = failures_csv(&outcome.failures, &flag);
    let mut files: Vec<(&str, &[u8])> = vec![("results.csv", csv.as_bytes()), ("results.parquet", &parquet)];
    if let Some(f) = &failures_csv {
        files.push(("failures.csv", f.as_bytes()));
    }
    let inputs: Vec<&std::path::Path> = input_files.iter().map(PathBuf::as_path).collect();
    gyrolab_io::atomic::write_folder(&args.out, &files, &inputs).map_err(crate::output::output_error)?;
    if failures_csv.is_none() {
        // A list of failures from an earlier run would no longer be true.
        let _ = std::fs::remove_file(args.out.join("failures.csv"));
    }
    // Byte-identical inputs: one row, both names said.
    for s in &outcome.skipped {
        if let Skipped::SameAs { file, original } = s {
            eprintln!(
                "note: {}: the same bytes as {}: evaluated once, its rows are {}'s",
                gyrolab_io::text::path_text(file),
                gyrolab_io::text::path_text(original),
                gyrolab_io::text::path_text(original)
            );
        }
    }
    let done_before = outcome.skipped.iter().filter(|s| matches!(s, Skipped::AlreadyDone { .. })).count();
    let duplicates = outcome.skipped.len() - done_before;
    if !args.quiet {
        let mut s = format!(
            "{} inputs: {now} evaluated now, {done_before} already done (journal), {duplicates} same bytes as another input, {} failed\n",
            request.inputs.len(),
            outcome.failures.len()
        );
        s.push_str(&summary_text(&rows));
        s.push_str(&format!(
            "Wrote {} ({} rows), {}{}\n",
            args.out.join("results.csv").display(),
            rows.len(),
            args.out.join("results.parquet").display(),
            if failures_csv.is_some() {
                format!(", {}", args.out.join("failures.csv").display())
            } else {
                String::new()
            }
        ));
        print(&s)?;
    }
    if !outcome.failures.is_empty() {
        return Err(CliError::SomeFailed(format!(
            "{} of {} inputs failed (listed above and in {}); the others are in {}",
            outcome.failures.len(),
            request.inputs.len(),
            args.out.join("failures.csv").display(),
            args.out.join("results.csv").display()
        )));
    }
    Ok(())
}

