//! `gyrolab verify DIR`: a report folder's integrity record (results.json `integrity`: the plan's
//! SHA-256 and copy, every input with its SHA-256, written by `gyrolab eval`) checked against
//! the files as they are now, so that an input or plan edited after the report was issued is
//! found (ISO/IEC 17025:2017 7.5 technical records, 7.11.3 integrity of data); and the
//! folder's own files against its manifest (manifest.json: every output with its SHA-256), so
//! that an edited, deleted or added output is found too.

use gyrolab_eval::error::EvalResult;
use gyrolab_io::input_file::sha256_file;
use gyrolab_io::DataError;
use gyrolab_report::results::IntegrityJson;
use gyrolab_store::sign::{self, VerifyingKey};
use std::path::{Path, PathBuf};

/// What a file is to the report.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    /// The copy of the plan inside the report folder.
    PlanCopy,
    /// The plan file named by results.json `plan_file`.
    Plan,
    /// An input record named by the plan.
    Input,
}

impl Role {
    /// The word printed for it.
    pub fn word(self) -> &'static str {
        match self {
            Role::PlanCopy => "plan copy",
            Role::Plan => "plan",
            Role::Input => "input",
        }
    }
}

/// A file as found now against its recorded hash.
#[derive(Debug, Clone, PartialEq)]
pub enum FileState {
    /// Same SHA-256 as recorded.
    Unchanged,
    /// A different SHA-256 now.
    Changed {
        /// The SHA-256 now.
        sha256: String,
        /// The size now, bytes.
        size_bytes: u64,
    },
    /// The file cannot be read.
    Missing {
        /// Why.
        reason: String,
    },
}

/// One file checked.
#[derive(Debug, Clone, PartialEq)]
pub struct FileCheck {
    /// What it is.
    pub role: Role,
    /// The path checked.
    pub path: PathBuf,
    /// The SHA-256 recorded when the report was made.
    pub recorded_sha256: String,
    /// What was found.
    pub state: FileState,
}

/// One output of the report folder against the manifest.
#[derive(Debug, Clone, PartialEq)]
pub struct OutputCheck {
    /// The file's name in the folder.
    pub name: String,
    /// The SHA-256 in the manifest.
    pub recorded_sha256: String,
    /// What was found.
    pub state: FileState,
}

/// The result of verifying a report folder.
#[derive(Debug, Clone, PartialEq)]
pub struct Verification {
    /// The report's number.
    pub report_number: String,
    /// Every file checked: the plan copy, the plan (when found), the inputs in plan order.
    pub checks: Vec<FileCheck>,
    /// Every output in the manifest, checked; `None` when the folder has no manifest (written
    /// by a gyrolab before 0.3): the outputs were NOT checked, which never counts as passed.
    pub outputs: Option<Vec<OutputCheck>>,
    /// Files in the folder that the manifest does not list (an added file, a leftover of an
    /// interrupted run), besides the manifest itself and a `report.pdf` printed from
    /// report.html afterwards (listed in `uncovered`).
    pub extra: Vec<String>,
    /// Files the manifest cannot cover, by design: `report.pdf`, printed from report.html after
    /// the folder was written (`--pdf`).
    pub uncovered: Vec<String>,
}

impl Verification {
    /// True when every file checked has its recorded hash, every output its manifest's, and no
    /// file was added (the outputs checked; see [`Verification::outputs_checked`]).
    pub fn all_unchanged(&self) -> bool {
        self.checks.iter().all(|c| c.state == FileState::Unchanged)
            && self.outputs.iter().flatten().all(|c| c.state == FileState::Unchanged)
            && self.extra.is_empty()
    }

    /// Whether the outputs were checked (the folder has a manifest).
    pub fn outputs_checked(&self) -> bool {
        self.outputs.is_some()
    }
}

/// The outputs of `dir` against its manifest: (checks, extra files, uncovered files); `None`
/// without a manifest. A manifest that cannot be read is an error naming it.
#[allow(clippy::type_complexity)]
fn check_outputs(dir: &Path) -> EvalResult<Option<(Vec<OutputCheck>, Vec<String>, Vec<String>)>> {
    use gyrolab_io::provenance::{Manifest, MANIFEST};
    let path = dir.join(MANIFEST);
    if !path.exists() {
        return Ok(None);
    }
    let text = gyrolab_io::text::read_text_file(&path, gyrolab_io::text::MAX_TABLE_BYTES, "a manifest")?;
    let manifest: Manifest = serde_json::from_str(&text)
        .map_err(|e| DataError::new(&path, format!("not a gyrolab manifest: {e}")).at_line(e.line() as u64))?;
    let mut checks = Vec::with_capacity(manifest.files.len());
    for f in &manifest.files {
        if Path::new(&f.name).file_name() != Some(std::ffi::OsStr::new(&f.name)) {
            return Err(DataError::new(&path, format!("'{}' is not a plain file name", f.name)).into());
        }
        let c = check(Role::PlanCopy, dir.join(&f.name), &f.sha256);
        checks.push(OutputCheck { name: f.name.clone(), recorded_sha256: f.sha256.clone(), state: c.state });
    }
    let (mut extra, mut uncovered) = (Vec::new(), Vec::new());
    let entries = std::fs::read_dir(dir).map_err(|e| DataError::io(dir, &e))?;
    for entry in entries {
        let entry = entry.map_err(|e| DataError::io(dir, &e))?;
        let name = entry.file_name().to_string_lossy().into_owned();
        if name == MANIFEST || manifest.files.iter().any(|f| f.name == name) {
            continue;
        }
        if name == "report.pdf" {
            uncovered.push(name);
        } else {
            extra.push(name);
        }
    }
    extra.sort();
    Ok(Some((checks, extra, uncovered)))
}

fn check(role: Role, path: PathBuf, recorded: &str) -> FileCheck {
    let state = match sha256_file(&path) {
        Ok((sha256, _)) if sha256 == recorded => FileState::Unchanged,
        Ok((sha256, size_bytes)) => FileState::Changed { sha256, size_bytes },
        Err(e) => FileState::Missing { reason: e.message },
    };
    FileCheck { role, path, recorded_sha256: recorded.to_string(), state }
}

/// Verifies the report folder `dir`. Inputs are resolved against `plan_dir` (default: the
/// folder of results.json's `plan_file`, as given to `gyrolab eval` from the current folder).
/// Errors (exit 2): no results.json, not gyrolab's, or without an integrity record (a folder
/// written by a gyrolab before 0.2, or the demo's built-in data).
pub fn verify_folder(dir: &Path, plan_dir: Option<&Path>) -> EvalResult<Verification> {
    let results = dir.join("results.json");
    // results.json of a large program is a few MiB; 256 MiB bounds a hostile one.
    let text = gyrolab_io::text::read_text_file(&results, gyrolab_io::text::MAX_TABLE_BYTES, "a results.json")?;
    let v: serde_json::Value = serde_json::from_str(&text)
        .map_err(|e| DataError::new(&results, format!("not JSON: {e}")).at_line(e.line() as u64))?;
    let report_number = v["report_number"].as_str().unwrap_or_default().to_string();
    let integrity: IntegrityJson = serde_json::from_value(v["integrity"].clone()).map_err(|_| {
        DataError::new(&results, "no integrity record (key `integrity`): written by a gyrolab before 0.2, or not by `gyrolab eval`; nothing to verify")
    })?;
    let Some(plan_sha256) = integrity.plan_sha256.as_deref() else {
        return Err(DataError::new(
            &results,
            "the integrity record names no plan (built-in data, as the demo's): nothing to verify",
        )
        .into());
    };
    let mut checks = Vec::new();
    if let Some(copy) = &integrity.plan_copy {
        checks.push(check(Role::PlanCopy, dir.join(copy), plan_sha256));
    }
    let plan_file = v["plan_file"].as_str().map(PathBuf::from);
    if let Some(p) = plan_file.as_ref().filter(|p| p.is_file()) {
        checks.push(check(Role::Plan, p.clone(), plan_sha256));
    }
    let base = match plan_dir {
        Some(d) => d.to_path_buf(),
        None => plan_file.as_deref().and_then(Path::parent).map_or_else(|| PathBuf::from("."), Path::to_path_buf),
    };
    for i in &integrity.inputs {
        checks.push(check(Role::Input, base.join(&i.file), &i.sha256));
    }
    let (outputs, extra, uncovered) = match check_outputs(dir)? {
        Some((o, e, u)) => (Some(o), e, u),
        None => (None, Vec::new(), Vec::new()),
    };
    Ok(Verification { report_number, checks, outputs, extra, uncovered })
}

/// A report folder verified whole ([`verify_report`]): its lines to print and its problems.
#[derive(Debug, Clone, PartialEq)]
pub struct VerifyReport {
    /// The report number (with its status when issued: `GL-2026-0001, ISSUED`).
    pub number: String,
    /// One line per check (the signature, the plan and inputs, each output), headed by the report.
    pub text: String,
    /// Every file or signature that changed, is missing or was added (empty: none).
    pub problems: Vec<String>,
    /// The signature of an issued folder was checked (false: issued, no key given).
    pub signature_checked: bool,
    /// The outputs were checked against a manifest.
    pub outputs_checked: bool,
    /// Files checked (plan, inputs, outputs, added files).
    pub files: usize,
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
fn check_signature(dir: &Path, key: Option<&VerifyingKey>) -> (Option<String>, Option<String>, bool) {
    let sig_path = dir.join(sign::SIGNATURE_FILE);
    let issued = dir.join(sign::ISSUE_FILE).exists() || sig_path.exists();
    if !issued {
        return match key {
            Some(_) => (
                Some("  NOT SIGNED: a draft (no issue.json, no manifest.sig): never issued".into()),
                Some("the folder is not an issued report: it has no manifest.sig".into()),
                true,
            ),
            None => (None, None, true),
        };
    }
    let Some(key) = key else {
        return (
            Some("  NOT CHECKED: the signature of manifest.json (an issued report: give the lab's key, --public-key LAB.pub)".into()),
            None,
            false,
        );
    };
    let read = |p: &std::path::Path| read_bounded(p, gyrolab_io::text::MAX_TABLE_BYTES);
    let detached: Result<sign::DetachedSignature, String> = read(&sig_path)
        .and_then(|b| serde_json::from_slice(&b).map_err(|e| format!("manifest.sig: not a gyrolab signature: {e}")));
    let manifest = read(&dir.join("manifest.json"));
    let fp = sign::fingerprint(key);
    match (detached, manifest) {
        (Ok(d), Ok(m)) if sign::verify_manifest(key, &m, &d.signature) => {
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
    }
}

/// Verifies the report folder `dir` (`gyrolab verify`): an issued folder's Ed25519 signature of
/// its manifest.json (with `key`; without it NOT CHECKED), then [`verify_folder`]: the plan,
/// inputs (from `plan_dir`, default the plan's folder as results.json names it) and outputs.
pub fn verify_report(dir: &Path, plan_dir: Option<&Path>, key: Option<&VerifyingKey>) -> EvalResult<VerifyReport> {
    let (sig_line, sig_problem, sig_checked) = check_signature(dir, key);
    let mut v = verify_folder(dir, plan_dir)?;
    // The detached signature is not in the manifest it signs.
    v.extra.retain(|e| e != sign::SIGNATURE_FILE);
    let issued_number = read_bounded(&dir.join(sign::ISSUE_FILE), 16 << 20)
        .ok()
        .and_then(|b| serde_json::from_slice::<serde_json::Value>(&b).ok())
        .and_then(|j| {
            let n = j["report_number"].as_str()?.to_string();
            let status = j["status"].as_str().unwrap_or_default().to_uppercase();
            Some(format!("{n}, {status}"))
        });
    let number = issued_number.unwrap_or_else(|| v.report_number.clone());
    let mut s = format!("Report {number} ({}):\n", dir.display());
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
    Ok(VerifyReport {
        files: v.checks.len() + v.outputs.as_ref().map_or(0, Vec::len) + v.extra.len(),
        outputs_checked: v.outputs_checked(),
        number,
        text: s,
        problems: bad,
        signature_checked: sig_checked,
    })
}
