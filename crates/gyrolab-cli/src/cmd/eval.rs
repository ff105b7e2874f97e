//! `gyrolab eval PLAN.toml --out DIR`: evaluate a test plan and write the report folder
//! (report.html, results.json, calibration.toml, CSV tables; report.pdf with `--pdf`). Exit code 3
//! when a limit fails, 1 when `--pdf` could not make the PDF. `--store` also keeps the evaluation
//! in the records store (docs/STORE.md).

use crate::args::AuthArgs;
use crate::error::{CliError, CliResult};
use crate::folder::write_and_finish;
use crate::progress::Bar;
use clap::Args;
use gyrolab_lab::evaluate::{prepare_store, store_report_folder};
use gyrolab_lab::test_plan::{evaluate_test_plan, read_test_plan};
use gyrolab_store::record::hash_plan_inputs;
use gyrolab_store::resolve_location;
use std::path::PathBuf;

/// Options of `gyrolab eval`.
#[derive(Debug, Args)]
pub struct EvalArgs {
    /// The test plan (TOML; keys in docs/PLAN.md).
    #[arg(value_name = "PLAN.toml")]
    pub plan: PathBuf,
    /// Folder to write report.html, results.json, calibration.toml and the CSV tables into
    /// (created if missing; existing files of the same names are replaced, all or none).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// No progress bar and no summary on standard output (errors still go to stderr).
    #[arg(long, short)]
    pub quiet: bool,
    /// Also print report.html to report.pdf with headless Chromium (/usr/bin/chromium, or
    /// chromium, chromium-browser or google-chrome on PATH, or the path in GYROLAB_CHROMIUM; at
    /// most 120 s). Without a browser, or when printing fails, the other files are still written
    /// and the exit code is 1 with a message saying how to get the PDF.
    #[arg(long)]
    pub pdf: bool,
    /// Also keep the evaluation in the records store (docs/STORE.md): an SQLite file or a
    /// postgres:// URL; without a value GYROLAB_STORE, else gyrolab.db in the current folder (where
    /// `gyrolab store` looks too). Stored
    /// after the folder is written, also when a limit fails.
    #[arg(long, value_name = "PATH|URL", num_args = 0..=1, default_missing_value = "")]
    pub store: Option<String>,
    /// With --store: the account that stores the evaluation (a store with accounts needs one).
    #[command(flatten)]
    pub auth: AuthArgs,
}

/// Runs `gyrolab eval`.
pub fn run(args: &EvalArgs) -> CliResult {
    let plan = read_test_plan(&args.plan)?;
    // With --store, a second thread opens and checks the store (connects, migrates) and hashes
    // the inputs while the plan is evaluated. A corrupt, foreign or newer store, or a server that
    // is down or refuses the password, ends the run with exit 2 before the report folder is
    // written. A store that does not exist yet is created once the folder is written.
    let location = args.store.as_deref().map(|s| resolve_location(Some(s)));
    // The password is read here, before the evaluation (a prompt, standard input, or
    // GYROLAB_PASSWORD); the account is authenticated with the store's check, before any output.
    let credentials = match &location {
        Some(_) => args.auth.credentials(true)?,
        None => None,
    };
    let bar = Bar::new(args.quiet);
    let (folder, prepared) = std::thread::scope(|scope| {
        let preparing = location.as_deref().map(|l| {
            scope.spawn(move || {
                let store = prepare_store(l, credentials.as_ref()).map_err(CliError::from);
                (store, hash_plan_inputs(&args.plan))
            })
        });
        let folder = evaluate_test_plan(&plan, &args.plan.display().to_string(), &bar);
        (folder, preparing.map(|h| h.join()))
    });
    bar.finish();
    let (store, inputs) = match prepared {
        None => (None, None),
        Some(Ok((store, inputs))) => (store?, Some(inputs)),
        Some(Err(_)) => return Err(CliError::Output("the thread opening the store failed".into())),
    };
    let result = write_and_finish(&args.out, &folder?, args.quiet, args.pdf);
    let verdict_only =
        matches!(result, Err(CliError::LimitFailed(_) | CliError::Incomplete(_) | CliError::Conditional(_)));
    if let (Some(l), true) = (&location, result.is_ok() || verdict_only) {
        let inputs = match inputs {
            Some(hashed) => Some(hashed?),
            None => None,
        };
        let stored = store_report_folder(l, store, &args.out, &args.plan, inputs)?;
        if !args.quiet || stored.revision_of.is_some() {
            eprintln!("{}", stored.line);
        }
    }
    result
}
