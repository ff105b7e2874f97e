//! `gyrolab verify DIR`: recomputes the SHA-256 of a report folder's plan, inputs and outputs
//! (against its manifest.json) and names every file that changed, is missing or was added (exit
//! 3); a folder without a manifest has its outputs NOT CHECKED (exit 5); else exit 0. An issued
//! folder (`gyrolab store report` of an issued evaluation: issue.json, manifest.sig) has the
//! Ed25519 signature over its exact manifest.json bytes checked first with `--public-key`
//! (exit 3 when it does not verify); without the key its signature is NOT CHECKED (exit 5).

use crate::error::{CliError, CliResult};
use crate::output::print;
use clap::Args;
use gyrolab_lab::verify::{verify_folder, FileState};
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

/// A file's bytes, refused past `limit` bytes (a hostile folder cannot exhaust memory).
fn read_bounded(p: &std::path::Path, limit: u64) -> Result<Vec<u8>, String> {
    use std::io::Read;
    // Only a regular file is opened (a FIFO would wait for a writer forever).
    let meta = std::fs::metadata(p).map_err(|e| format!("{}: cannot read: {e}", p.display()))?;
    if !meta.is_file() {
        return Err(format!("{}: not a regular file", p.display()));
    }
    let f = std::fs::File::open(p).map_err(|e| format!("{}: cannot read: {e}", p.display()))?;
    let mut bytes = Vec::new();
    f.take(limit + 1).read_to_end(&mut bytes).map_err(|e| format!("{}: cannot read: {e}", p.display()))?;
    if bytes.len() as u64 > limit {
        return Err(format!("{}: larger than {limit} bytes", p.display()));
    }
    Ok(bytes)
}

/// The signature of an issued folder: (a line to print, the problem when it does not verify,
/// whether it was checked). A folder with neither issue.json nor manifest.sig is a draft.
fn check_signature(args: &VerifyArgs) -> CliResult<(Option<String>, Option<String>, bool)> {
    use gyrolab_store::sign;
    let dir = &args.dir;
    let sig_path = dir.join(sign::SIGNATURE_FILE);
    let issued = dir.join(sign::ISSUE_FILE).exists() || sig_path.exists();
    let key = match &args.public_key {
        Some(p) => Some(sign::read_public_key(p).map_err(CliError::Usage)?),
        None => None,
    };
    if !issued {
        return Ok(match key {
            Some(_) => (
                Some("  NOT SIGNED: a draft (no issue.json, no manifest.sig): never issued".into()),
                Some("the folder is not an issued report: it has no manifest.sig".into()),
                true,
            ),
            None => (None, None, true),
        });
    }
    let Some(key) = key else {
        return Ok((
            Some("  NOT CHECKED: the signature of manifest.json (an issued report: give the lab's key, --public-key LAB.pub)".into()),
            None,
            false,
        ));
    };
    let read = |p: &std::path::Path| read_bounded(p, gyrolab_io::text::MAX_TABLE_BYTES);
    let detached: Result<sign::DetachedSignature, String> = read(&sig_path)
        .and_then(|b| serde_json::from_slice(&b).map_err(|e| format!("manifest.sig: not a gyrolab signature: {e}")));
    let manifest = read(&dir.join("manifest.json"));
    let fp = sign::fingerprint(&key);
    Ok(match (detached, manifest) {
        (Ok(d), Ok(m)) if sign::verify_manifest(&key, &m, &d.signature) => {
            (Some(format!("  SIGNED    manifest.json: Ed25519 signature valid, key {fp}")), None, true)
        }
        (Ok(d), Ok(_)) => {
            let why = if d.key_fingerprint != fp {
                format!("manifest.sig names key {}, not the given key {fp}", d.key_fingerprint)
            } else {
                "manifest.json or manifest.sig changed since the report was issued".into()
            };
            let line = format!("  FORGED    manifest.json: the signature does NOT verify with key {fp} ({why})");
            (Some(line), Some(format!("manifest.json: the signature does NOT verify ({why})")), true)
        }
        (Err(e), _) | (_, Err(e)) => {
            (Some(format!("  MISSING   signature: {e}")), Some(format!("the signature cannot be checked: {e}")), true)
        }
    })
}

/// Runs `gyrolab verify`.
pub fn run(args: &VerifyArgs) -> CliResult {
    let (sig_line, sig_problem, sig_checked) = check_signature(args)?;
    let mut v = verify_folder(&args.dir, args.plan_dir.as_deref())?;
    // The detached signature is not in the manifest it signs.
    v.extra.retain(|e| e != gyrolab_store::sign::SIGNATURE_FILE);
    let issued_number = read_bounded(&args.dir.join(gyrolab_store::sign::ISSUE_FILE), 16 << 20)
        .ok()
        .and_then(|b| serde_json::from_slice::<serde_json::Value>(&b).ok())
        .and_then(|j| {
            let n = j["report_number"].as_str()?.to_string();
            let status = j["status"].as_str().unwrap_or_default().to_uppercase();
            Some(format!("{n}, {status}"))
        });
    let number = issued_number.unwrap_or_else(|| v.report_number.clone());
    let mut s = format!("Report {number} ({}):\n", args.dir.display());
    let mut bad = Vec::new();
    if let Some(l) = &sig_line {
        s.push_str(l);
        s.push('\n');
    }
    if let Some(p) = sig_problem {
        bad.push(p);
    }
    for c in &v.checks {
        let (word, detail) = match &c.state {
            FileState::Unchanged => ("unchanged", String::new()),
            FileState::Changed { sha256, size_bytes } => {
                ("CHANGED", format!(" (SHA-256 now {sha256}, {size_bytes} bytes; recorded {})", c.recorded_sha256))
            }
            FileState::Missing { reason } => ("MISSING", format!(" ({reason})")),
        };
        let line = format!("{word:<9} {:<9} {}{detail}", c.role.word(), c.path.display());
        if c.state != FileState::Unchanged {
            bad.push(format!("{} {}", c.role.word(), c.path.display()));
        }
        s.push_str(&format!("  {line}\n"));
    }
    match &v.outputs {
        Some(outputs) => {
            for o in outputs {
                let (word, detail) = match &o.state {
                    FileState::Unchanged => ("unchanged", String::new()),
                    FileState::Changed { sha256, size_bytes } => (
                        "CHANGED",
                        format!(" (SHA-256 now {sha256}, {size_bytes} bytes; manifest {})", o.recorded_sha256),
                    ),
                    FileState::Missing { reason } => ("MISSING", format!(" ({reason})")),
                };
                if o.state != FileState::Unchanged {
                    bad.push(format!("output {}", o.name));
                }
                s.push_str(&format!("  {word:<9} {:<9} {}{detail}\n", "output", o.name));
            }
            for e in &v.extra {
                bad.push(format!("added {e}"));
                s.push_str(&format!("  {:<9} {:<9} {e} (in the folder, not in its manifest)\n", "ADDED", "file"));
            }
            for u in &v.uncovered {
                s.push_str(&format!(
                    "  {:<9} {:<9} {u} (printed from report.html after the manifest: not covered by it)\n",
                    "uncovered", "file"
                ));
            }
        }
        None => s.push_str(
            "  NOT CHECKED: the outputs (the folder has no manifest.json: written by a gyrolab before 0.3)\n",
        ),
    }
    print(&s)?;
    if bad.is_empty() {
        if !sig_checked {
            return Err(CliError::Incomplete(format!(
                "report {number}: every file matches manifest.json, but the signature of this issued report was NOT \
                 CHECKED: verify with --public-key LAB.pub (the lab's public key)"
            )));
        }
        if !v.outputs_checked() {
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
        bad.len(),
        v.checks.len() + v.outputs.as_ref().map_or(0, Vec::len) + v.extra.len(),
        number,
        bad.join("; ")
    )))
}
