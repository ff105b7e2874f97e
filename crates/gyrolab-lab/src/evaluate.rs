//! Evaluate and store (`gyrolab eval --store`): the store opened, migrated and the account
//! authenticated before anything is written (while the plan is evaluated, on another thread), then
//! the written report folder stored as a new evaluation.

use gyrolab_store::record::{from_report_folder_with, FileRecord};
use gyrolab_store::{Actor, Store, StoreError, StoreResult};
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

/// Stores the report folder `out` of `plan` (its inputs' hashes made while it was evaluated, or
/// `None`) in the store `prepared` by [`prepare_store`], else in a new store at `location`:
/// (evaluation id, store name).
pub fn store_report_folder(
    location: &str,
    prepared: Option<(Store, Actor)>,
    out: &Path,
    plan: &Path,
    inputs: Option<Vec<FileRecord>>,
) -> StoreResult<(i64, String)> {
    let record = from_report_folder_with(out, Some(plan), inputs, true, &[])?;
    let (mut s, actor) = match prepared {
        Some(s) => s,
        None => (Store::open_for_writing(location, true)?, Actor::unauthenticated()),
    };
    let id = s.add_as(&record, &actor)?;
    Ok((id, s.name().to_string()))
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
