//! `gyrolab eval PLAN.toml --out DIR`: evaluate a test plan and write the report folder
//! (report.html, results.json, calibration.toml, CSV tables; report.pdf with `--pdf`). Exit code 3
//! when a limit fails, 1 when `--pdf` could not make the PDF. `--store` also keeps the evaluation
//! in the records store (docs/STORE.md).

use crate::args::AuthArgs;
use crate::error::{CliError, CliResult};
use crate::folder::write_and_finish;
use crate::progress::Bar;
use clap::Args;
use gyrolab_lab::test_plan::{evaluate_test_plan, read_test_plan};
use gyrolab_store::record::{from_report_folder_with, hash_plan_inputs};
use gyrolab_store::{resolve_location, Actor, Store, StoreError};
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
    /// postgres:// URL; without a value GYROLAB_STORE, else gyrolab.db beside the plan. Stored
    /// after the folder is written, also when a limit fails.
    #[arg(long, value_name = "PATH|URL", num_args = 0..=1, default_missing_value = "")]
    pub store: Option<String>,
    /// With --store: the account that stores the evaluation (a store with accounts needs one).
    #[command(flatten)]
    pub auth: AuthArgs,
}

/// Whether an SQLite store can be created at `location` (a path): its folder exists and takes a
/// new file. A usage error (exit 2) naming the folder otherwise.
fn creatable(location: &str) -> CliResult<()> {
    let path = std::path::Path::new(location);
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => std::path::Path::new("."),
    };
    tempfile::Builder::new().prefix(".gyrolab-store-check-").tempfile_in(dir).map(drop).map_err(|e| {
        CliError::Usage(format!(
            "{}: the store does not exist and cannot be created in its folder: {}; nothing was written",
            gyrolab_store::mask_location(location),
            e.kind()
        ))
    })
}

/// Runs `gyrolab eval`.
pub fn run(args: &EvalArgs) -> CliResult {
    let plan = read_test_plan(&args.plan)?;
    // With --store, a second thread opens and checks the store (connects, migrates) and hashes
    // the inputs while the plan is evaluated. A corrupt, foreign or newer store, or a server that
    // is down or refuses the password, ends the run with exit 2 before the report folder is
    // written. A store that does not exist yet is created once the folder is written.
    let location = args.store.as_deref().map(|s| {
        let plan_dir = args.plan.parent().filter(|p| !p.as_os_str().is_empty());
        resolve_location(Some(s), plan_dir)
    });
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
                let store = match Store::open_for_writing(l, false) {
                    Ok(mut s) => match &credentials {
                        Some((user, password)) => {
                            s.authenticate(user, password).map(|a| Some((s, a))).map_err(CliError::from)
                        }
                        None => match s.has_accounts() {
                            Ok(false) => Ok(Some((s, Actor::unauthenticated()))),
                            Ok(true) => Err(CliError::from(StoreError::Refused {
                                store: s.name().to_string(),
                                message:
                                    "this store has accounts: every write needs one (--user NAME or GYROLAB_USER, \
                                          the password from GYROLAB_PASSWORD, --password-stdin or a prompt); nothing \
                                          was written"
                                        .into(),
                            })),
                            Err(e) => Err(CliError::from(e)),
                        },
                    },
                    // A new store has no account to authenticate.
                    Err(StoreError::NotFound { store, .. }) if credentials.is_some() => {
                        Err(CliError::from(StoreError::Auth { store }))
                    }
                    // Created once the folder is written: its folder must take a new file now,
                    // so that a store that cannot be made ends the run before anything is written.
                    Err(StoreError::NotFound { .. }) => creatable(l).map(|()| None),
                    Err(e) => Err(CliError::from(e)),
                };
                (store, hash_plan_inputs(&args.plan))
            })
        });
        let folder = evaluate_test_plan(&plan, &args.plan.display().to_string(), &bar);
        (folder, preparing.map(|h| h.join()))
    });
    bar.finish();
    let (mut store, inputs) = match prepared {
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
        let record = from_report_folder_with(&args.out, Some(&args.plan), inputs)?;
        let (mut s, actor) = match store.take() {
            Some(s) => s,
            None => (Store::open_for_writing(l, true)?, Actor::unauthenticated()),
        };
        let id = s.add_as(&record, &actor)?;
        if !args.quiet {
            eprintln!("Stored as evaluation {id} in {}", s.name());
        }
    }
    result
}
