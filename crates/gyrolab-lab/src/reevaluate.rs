//! Re-evaluation: the stored plan and inputs evaluated again under this build: where they are,
//! when the plan file and every input still have the SHA-256 stored with the evaluation, else
//! from the raw records the store keeps ([`crate::raw_records`]); the new report folder is
//! written, stored as a revision of kind `reevaluation`, and every changed figure and verdict
//! is listed.

use crate::test_plan::{evaluate_test_plan, read_test_plan};
use gyrolab_store::query::{diff_figures, FigureChange};
use gyrolab_store::record::{from_report_folder, from_report_folder_with, hash_bytes, hash_file, EvaluationRecord};
use gyrolab_store::{Changes, Revision, RevisionKind, Store, StoreError, StoreResult};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Why evaluation `id`'s plan and inputs cannot be evaluated where they were: the first one
/// missing or changed since (its SHA-256 and size against the stored ones).
fn in_place(rec: &EvaluationRecord, id: i64) -> Result<(), String> {
    let plan_bytes =
        std::fs::read(&rec.plan_path).map_err(|e| format!("{}: cannot read the plan's file: {e}", rec.plan_path))?;
    if hash_bytes(&plan_bytes) != rec.plan_sha256 {
        return Err(format!(
            "{}: changed since evaluation {id} (SHA-256 {} stored, {} now)",
            rec.plan_path,
            rec.plan_sha256,
            hash_bytes(&plan_bytes)
        ));
    }
    for f in &rec.inputs {
        let (sha, size) = hash_file(Path::new(&f.path)).map_err(|e| e.to_string())?;
        if sha != f.sha256 || size != f.size_bytes {
            return Err(format!(
                "{}: changed since evaluation {id} (SHA-256 {}, {} bytes stored; {sha}, {size} bytes now)",
                f.path, f.sha256, f.size_bytes
            ));
        }
    }
    Ok(())
}

/// A temporary folder named `prefix`..., removed when dropped.
fn staging(prefix: &str) -> StoreResult<tempfile::TempDir> {
    tempfile::Builder::new().prefix(prefix).tempdir().map_err(|e| StoreError::Input {
        path: std::env::temp_dir().display().to_string(),
        message: format!("cannot write: {e}"),
    })
}

/// Writes the report `folder` to `out`, all or none, never over one of its inputs.
fn write_report(folder: &crate::report_folder::ReportFolder, out: &Path) -> StoreResult<()> {
    let files: Vec<(&str, &[u8])> = folder.outputs.iter().map(|o| (o.name.as_str(), o.bytes.as_slice())).collect();
    let inputs: Vec<&Path> = folder.inputs.iter().map(PathBuf::as_path).collect();
    gyrolab_io::atomic::write_folder(out, &files, &inputs)
        .map(drop)
        .map_err(|e| StoreError::Input { path: e.path.display().to_string(), message: e.to_string() })
}

/// The report `folder` of the plan and raw records `restored` from the store, written to `out`
/// and read back as the record of a revision: its inputs those stored (`inputs`, not packed
/// again), its plan path the original `plan_path`.
fn written_record(
    folder: &crate::report_folder::ReportFolder,
    out: &Path,
    restored: &crate::raw_records::RestoredInputs,
    inputs: Vec<gyrolab_store::record::FileRecord>,
    plan_path: &str,
) -> StoreResult<EvaluationRecord> {
    write_report(folder, out)?;
    let mut new = from_report_folder_with(out, Some(&restored.plan), Some(inputs), false, &restored.moved)?;
    new.plan_path = plan_path.to_string();
    Ok(new)
}

/// Where a re-evaluation reads the plan and its inputs.
enum Restored {
    /// The plan file where it was, its inputs as it names them.
    InPlace(PathBuf),
    /// The store's copies, laid out in a temporary folder.
    Store(crate::raw_records::RestoredInputs),
}

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
    // In place when the plan and every input are still where they were, with the hashes
    // stored; else from the raw records the store keeps (schema 6), laid out in a temporary
    // folder as they stood relative to the plan. The report names the original plan either way.
    let in_place = in_place(rec, id);
    let staged;
    let (eval_plan, inputs_from_store) = match in_place {
        Ok(()) => (Restored::InPlace(plan_path.clone()), None),
        Err(why) => {
            staged = staging("gyrolab-reevaluate-")?;
            let restored = crate::raw_records::restore_into(store, id, staged.path()).map_err(|e| match e {
                StoreError::Refused { store, message } => {
                    StoreError::Refused { store, message: format!("{why}; and from the store: {message}") }
                }
                e => e,
            })?;
            (Restored::Store(restored), Some(rec.inputs.clone()))
        }
    };
    let plan = match &eval_plan {
        Restored::InPlace(p) => read_test_plan(p).map_err(|e| e.to_string()),
        Restored::Store(r) => r.plan().map_err(|e| e.to_string()),
    }
    .map_err(|message| StoreError::Input { path: rec.plan_path.clone(), message })?;
    let folder = evaluate_test_plan(&plan, &rec.plan_path, &gyrolab_eval::Silent)
        .map_err(|e| StoreError::Input { path: rec.plan_path.clone(), message: e.to_string() })?;
    let mut new = match (&eval_plan, inputs_from_store) {
        // The raw records are the store's already: not packed twice.
        (Restored::Store(r), Some(stored)) => written_record(&folder, out, r, stored, &rec.plan_path)?,
        _ => {
            write_report(&folder, out)?;
            from_report_folder(out, Some(&plan_path))?
        }
    };
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

/// The record of a correction of evaluation `id` with `changes` (issue 53: "a corrected serial
/// still shows the old serial in the stored report"): its report drawn again with the corrected
/// device and test fields, from the plan and raw records the store keeps, when this build gives
/// exactly the stored figures (values, verdicts, bounds); else `None` and the report files are
/// those of the revision corrected (said in the returned line). Changes of the approver alone
/// keep the files (the sign-off is the issue's).
pub fn corrected(store: &mut Store, id: i64, changes: &Changes) -> StoreResult<(Option<EvaluationRecord>, String)> {
    let header = changes.serial.is_some()
        || changes.model.is_some()
        || changes.lot.is_some()
        || changes.operator.is_some()
        || changes.test_date.is_some();
    if !header {
        return Ok((None, String::new()));
    }
    let old = store.evaluation(id)?.record;
    let kept = |why: String| -> StoreResult<(Option<EvaluationRecord>, String)> {
        Ok((None, format!("the report files are those of evaluation {id}, its body unchanged: {why}\n")))
    };
    let staged = staging("gyrolab-correct-")?;
    let restored = match crate::raw_records::restore_into(store, id, staged.path()) {
        Ok(r) => r,
        Err(StoreError::Refused { message, .. }) => return kept(message),
        Err(e) => return Err(e),
    };
    let mut plan =
        restored.plan().map_err(|e| StoreError::Input { path: old.plan_path.clone(), message: e.to_string() })?;
    if let Some(v) = &changes.serial {
        plan.device.serial = v.clone();
    }
    if let Some(v) = &changes.model {
        plan.device.model = v.clone();
    }
    if let Some(v) = &changes.lot {
        plan.device.lot = Some(v.clone());
    }
    if let Some(v) = &changes.operator {
        plan.test.operator = Some(v.clone());
    }
    if let Some(v) = &changes.test_date {
        plan.test.date = Some(v.clone());
    }
    let folder = match evaluate_test_plan(&plan, &old.plan_path, &gyrolab_eval::Silent) {
        Ok(f) => f,
        Err(e) => return kept(format!("it does not evaluate under this build ({e})")),
    };
    let new = written_record(&folder, &staged.path().join("report"), &restored, old.inputs.clone(), &old.plan_path)?;
    if new.figures != old.figures {
        return kept(format!(
            "this build (gyrolab {}) gives other figures than gyrolab {} did; re-evaluate it to change them",
            new.software_version, old.software_version
        ));
    }
    Ok((
        Some(new),
        format!("its report drawn again with the corrected fields (the figures of evaluation {id}, unchanged)\n"),
    ))
}
