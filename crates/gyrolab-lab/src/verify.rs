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
    use gyrolab_io::manifest::{Manifest, MANIFEST};
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
