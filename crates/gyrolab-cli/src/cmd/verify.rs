//! `gyrolab verify DIR`: recomputes the SHA-256 of a report folder's plan, inputs and outputs
//! (against its manifest.json) and names every file that changed, is missing or was added (exit
//! 3); a folder without a manifest has its outputs NOT CHECKED (exit 5); else exit 0. An issued
//! folder (`gyrolab store report` of an issued evaluation: issue.json, manifest.sig) has the
//! Ed25519 signature over its exact manifest.json bytes checked first with `--public-key`
//! (exit 3 when it does not verify); without the key its signature is NOT CHECKED (exit 5).

use crate::error::{CliError, CliResult};
use crate::output::print;
use clap::Args;
use gyrolab_lab::verify::verify_report;
use std::path::PathBuf;

/// Options of `gyrolab verify`.
#[derive(Debug, Args)]
pub struct VerifyArgs {
    /// A report folder written by `gyrolab eval` (its results.json holds the integrity record).
    #[arg(value_name = "DIR")]
    pub dir: PathBuf,
    /// The folder the plan's relative input paths start from (default: the folder of the plan
    /// named in results.json, as given to `gyrolab eval` from the current folder).
    #[arg(long, value_name = "DIR")]
    pub plan_dir: Option<PathBuf>,
    /// The lab's public key (`lab.pub` of `gyrolab store key init`): the signature of an issued
    /// folder's manifest.json is checked with it (without it, NOT CHECKED: exit 5).
    #[arg(long, value_name = "FILE.pub")]
    pub public_key: Option<PathBuf>,
}

/// Runs `gyrolab verify`.
pub fn run(args: &VerifyArgs) -> CliResult {
    let key =
        args.public_key.as_deref().map(gyrolab_store::sign::read_public_key).transpose().map_err(CliError::Usage)?;
    let r = verify_report(&args.dir, args.plan_dir.as_deref(), key.as_ref())?;
    print(&r.text)?;
    let number = &r.number;
    if r.problems.is_empty() {
        if !r.signature_checked {
            return Err(CliError::Incomplete(format!(
                "report {number}: every file matches manifest.json, but the signature of this issued report was NOT \
                 CHECKED: verify with --public-key LAB.pub (the lab's public key)"
            )));
        }
        if !r.outputs_checked {
            return Err(CliError::Incomplete(format!(
                "report {}: the plan and inputs are unchanged, but the outputs were NOT CHECKED (no manifest.json in {})",
                number,
                args.dir.display()
            )));
        }
        return Ok(());
    }
    Err(CliError::Changed(format!(
        "{} of {} files of report {} changed, missing or added since it was made: {}",
        r.problems.len(),
        r.files,
        number,
        r.problems.join("; ")
    )))
}
