//! Re-evaluation: the stored plan and inputs evaluated again under this build, hash-checked
//! first (the plan file and every input must still have the SHA-256 stored with the
//! evaluation); the new report folder is written, stored as a revision of kind `reevaluation`,
//! and every changed figure and verdict is listed.

use crate::test_plan::{evaluate_test_plan, read_test_plan};
use gyrolab_store::query::{diff_figures, FigureChange};
use gyrolab_store::record::{from_report_folder, hash_bytes, hash_file};
use gyrolab_store::{Changes, Revision, RevisionKind, Store, StoreError, StoreResult};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// The outcome of a re-evaluation.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Reevaluation {
    /// The evaluation re-evaluated (the current revision it superseded).
    pub superseded: i64,
    /// The new revision.
    pub revision: i64,
    /// gyrolab version of the superseded evaluation.
    pub software_before: String,
    /// gyrolab version now.
    pub software_after: String,
    /// Overall verdict before.
    pub verdict_before: Option<String>,
    /// Overall verdict after.
    pub verdict_after: Option<String>,
    /// Every figure whose value or verdict changed.
    pub changes: Vec<FigureChange>,
}

/// Re-evaluates evaluation `id` (which must be current) into the report folder `out` and stores
/// the result as its revision by `by` for `reason`.
pub fn reevaluate(store: &mut Store, id: i64, by: &str, reason: &str, out: &Path) -> StoreResult<Reevaluation> {
    reevaluate_as(store, id, by, reason, out, &gyrolab_store::Actor::unauthenticated())
}

/// [`reevaluate`] as `actor` (recorded in the audit trail; a store with accounts needs one).
pub fn reevaluate_as(
    store: &mut Store,
    id: i64,
    by: &str,
    reason: &str,
    out: &Path,
    actor: &gyrolab_store::Actor,
) -> StoreResult<Reevaluation> {
    let old = store.evaluation(id)?;
    if let Some(later) = old.superseded_by {
        return Err(StoreError::Refused {
            store: store.name().to_string(),
            message: format!("evaluation {id} is superseded by {later}: re-evaluate the current revision"),
        });
    }
    let rec = &old.record;
    let plan_path = PathBuf::from(&rec.plan_path);
    let plan_bytes = std::fs::read(&plan_path).map_err(|e| StoreError::Input {
        path: rec.plan_path.clone(),
        message: format!("cannot read the stored plan's file: {e}"),
    })?;
    if hash_bytes(&plan_bytes) != rec.plan_sha256 {
        return Err(StoreError::Input {
            path: rec.plan_path.clone(),
            message: format!(
                "changed since evaluation {id} (SHA-256 {} stored, {} now): not re-evaluated",
                rec.plan_sha256,
                hash_bytes(&plan_bytes)
            ),
        });
    }
    for f in &rec.inputs {
        let (sha, size) = hash_file(Path::new(&f.path))?;
        if sha != f.sha256 || size != f.size_bytes {
            return Err(StoreError::Input {
                path: f.path.clone(),
                message: format!(
                    "changed since evaluation {id} (SHA-256 {}, {} bytes stored; {sha}, {size} bytes now): not re-evaluated",
                    f.sha256, f.size_bytes
                ),
            });
        }
    }
    let plan = read_test_plan(&plan_path)
        .map_err(|e| StoreError::Input { path: rec.plan_path.clone(), message: e.to_string() })?;
    let folder = evaluate_test_plan(&plan, &rec.plan_path, &gyrolab_eval::Silent)
        .map_err(|e| StoreError::Input { path: rec.plan_path.clone(), message: e.to_string() })?;
    let files: Vec<(&str, &[u8])> = folder.outputs.iter().map(|o| (o.name.as_str(), o.bytes.as_slice())).collect();
    let inputs: Vec<&Path> = folder.inputs.iter().map(PathBuf::as_path).collect();
    gyrolab_io::atomic::write_folder(out, &files, &inputs)
        .map_err(|e| StoreError::Input { path: e.path.display().to_string(), message: e.to_string() })?;
    let mut new = from_report_folder(out, Some(&plan_path))?;
    // The facts recorded about the device stay those of the revision superseded (corrections
    // included); the figures are the new ones.
    new.serial = rec.serial.clone();
    new.model = rec.model.clone();
    new.lot = rec.lot.clone();
    new.operator = rec.operator.clone();
    new.approver = rec.approver.clone();
    new.test_date = rec.test_date.clone();
    let revision =
        Revision { supersedes: id, kind: RevisionKind::Reevaluation, by: by.to_string(), reason: reason.to_string() };
    let new_id = store.revise_as(&revision, &Changes::default(), Some(&new), actor)?;
    Ok(Reevaluation {
        superseded: id,
        revision: new_id,
        software_before: rec.software_version.clone(),
        software_after: new.software_version.clone(),
        verdict_before: rec.verdict.clone(),
        verdict_after: new.verdict.clone(),
        changes: diff_figures(&rec.figures, &new.figures),
    })
}
