//! Evaluate and store (`gyrolab eval --store`): the store opened, migrated and the account
//! authenticated before anything is written (while the plan is evaluated, on another thread), then
//! the written report folder stored as a new evaluation.

use gyrolab_store::record::{from_report_folder_with, EvaluationRecord, FileRecord};
use gyrolab_store::{Actor, Changes, Revision, RevisionKind, Store, StoreError, StoreResult};
use rayon::prelude::*;
use std::path::Path;

/// Opens the store at `location` for writing and authenticates `credentials` (name, password):
/// the store and the actor, or `None` for a store that does not exist yet (created when the
/// folder is stored; its folder must take a new file now). A store with accounts refuses a write
/// without one; a corrupt, foreign or newer store, or a server down, is an error.
pub fn prepare_store(location: &str, credentials: Option<&(String, String)>) -> StoreResult<Option<(Store, Actor)>> {
    match Store::open_for_writing(location, false) {
        Ok(mut s) => match credentials {
            Some((user, password)) => s.authenticate(user, password).map(|a| Some((s, a))),
            None => match s.has_accounts()? {
                false => Ok(Some((s, Actor::unauthenticated()))),
                true => Err(StoreError::Refused {
                    store: s.name().to_string(),
                    message: "this store has accounts: every write needs one (--user NAME or GYROLAB_USER, \
                              the password from GYROLAB_PASSWORD, --password-stdin or a prompt); nothing \
                              was written"
                        .into(),
                }),
            },
        },
        // A new store has no account to authenticate.
        Err(StoreError::NotFound { store, .. }) if credentials.is_some() => Err(StoreError::Auth { store }),
        // Created once the folder is written: its folder must take a new file now, so that a store
        // that cannot be made ends the run before anything is written.
        Err(StoreError::NotFound { .. }) => creatable(location).map(|()| None),
        Err(e) => Err(e),
    }
}

/// What `eval --store` stored: the evaluation's id and the line saying where (and, for the
/// same plan and inputs evaluated again, that it is a re-evaluation of the current one).
#[derive(Debug, Clone, PartialEq)]
pub struct Stored {
    /// The evaluation's id.
    pub id: i64,
    /// The current evaluation of the same serial, plan and inputs it supersedes, if any.
    pub revision_of: Option<i64>,
    /// The store's name (its password masked).
    pub store: String,
    /// The line saying so.
    pub line: String,
}

/// Stores the report folder `out` of `plan` (its inputs' hashes made while it was evaluated, or
/// `None`) in the store `prepared` by [`prepare_store`], else in a new store at `location`.
/// The same plan (its SHA-256) and inputs (paths and SHA-256) of a serial evaluated again, while
/// an evaluation of them is current, is stored as that evaluation's re-evaluation (a revision,
/// said so), not as a second current original (issue 53).
pub fn store_report_folder(
    location: &str,
    prepared: Option<(Store, Actor)>,
    out: &Path,
    plan: &Path,
    inputs: Option<Vec<FileRecord>>,
) -> StoreResult<Stored> {
    let mut record = from_report_folder_with(out, Some(plan), inputs, false, &[])?;
    let (mut s, actor) = match prepared {
        Some(s) => s,
        None => (Store::open_for_writing(location, true)?, Actor::unauthenticated()),
    };
    store_record(&mut s, &actor, &mut record)
}

/// Stores one finished report folder (`gyrolab store add`, Python's `Store.add`) in the store at
/// `location` (see [`gyrolab_store::resolve_location`]), created when missing, as the account
/// `credentials` (name, password) authenticates, or without an account (which a store that has
/// accounts refuses). The same folder added again (the same results.json of the same serial,
/// still current) adds nothing ([`StoreError::AlreadyStored`]; issue 53: re-adding a folder
/// made a second current original); another folder of the same plan and inputs is stored as a
/// re-evaluation of the current one, said so ([`store_report_folder`]).
pub fn add_report_folder(
    dir: &Path,
    plan: Option<&Path>,
    location: Option<&str>,
    credentials: Option<(&str, &str)>,
) -> StoreResult<Stored> {
    let mut record = from_report_folder_with(dir, plan, None, false, &[])?;
    let mut store = Store::open_for_writing(&gyrolab_store::resolve_location(location), true)?;
    let actor = match credentials {
        Some((user, password)) => store.authenticate(user, password)?,
        None => Actor::unauthenticated(),
    };
    if let Some(id) = store.current_with_results(&record.serial, &record.results_json)? {
        return Err(StoreError::AlreadyStored { store: store.name().to_string(), id });
    }
    store_record(&mut store, &actor, &mut record)
}

/// Stores `record` as a new original, or as the re-evaluation of the current evaluation of the
/// same serial, plan and inputs (said so in the line).
fn store_record(s: &mut Store, actor: &Actor, record: &mut EvaluationRecord) -> StoreResult<Stored> {
    // The raw records the store does not hold yet, read, checked against the hashes of the
    // bytes evaluated and compressed, on every core: the others are kept already (by SHA-256).
    let kept = s.kept_contents(&record.inputs.iter().map(|f| f.sha256.clone()).collect::<Vec<_>>())?;
    record
        .inputs
        .par_iter_mut()
        .filter(|f| !kept.contains(&f.sha256))
        .try_for_each(|f| gyrolab_store::record::pack_inputs(std::slice::from_mut(f)))?;
    let record = &*record;
    let same = s.current_of_same_inputs(record)?;
    let id = match same {
        None => s.add_as(record, actor)?,
        Some(old) => {
            let revision = Revision {
                supersedes: old,
                kind: RevisionKind::Reevaluation,
                by: actor.label(),
                reason: "the same plan and inputs evaluated again (gyrolab eval --store)".into(),
            };
            s.revise_as(&revision, &Changes::default(), Some(record), actor)?
        }
    };
    let line = match same {
        None => format!("Stored as evaluation {id} in {}", s.name()),
        Some(old) => format!(
            "Stored as evaluation {id} in {}: a re-evaluation of evaluation {old}, the current one of the same serial, \
             plan and inputs (it supersedes it; both are kept: gyrolab store history {})",
            s.name(),
            record.serial
        ),
    };
    Ok(Stored { id, revision_of: same, line, store: s.name().to_string() })
}

/// Whether an SQLite store can be created at `location` (a path): its folder exists and takes a
/// new file. A usage error (exit 2) naming the folder otherwise.
fn creatable(location: &str) -> StoreResult<()> {
    let path = std::path::Path::new(location);
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => std::path::Path::new("."),
    };
    tempfile::Builder::new().prefix(".gyrolab-store-check-").tempfile_in(dir).map(drop).map_err(|e| StoreError::Input {
        path: gyrolab_store::mask_location(location),
        message: format!(
            "the store does not exist and cannot be created in its folder: {}; nothing was written",
            e.kind()
        ),
    })
}
