//! The records store from Python (crate `gyrolab-store`, docs/STORE.md): the queries of `gyrolab
//! store` as tables (column names, column kinds, one Python list per column) that
//! `gyrolab.store.Store` turns into DataFrames, the stored evaluation as JSON, and storing a
//! report folder. Each call opens the store and closes it again with the interpreter released
//! (no connection outlives a call, so a process made by `fork` never shares one).

use gyrolab_lab::records as tables;
use gyrolab_report::table::{Cell, Table};
use gyrolab_store::{query, resolve_location, Store, StoreError};
use pyo3::prelude::*;
use pyo3::types::PyList;
use std::path::PathBuf;

/// A query's table for Python: column names, column kinds (`text`, `number`, `count`) and the
/// values of each column (text or None, float or None, int or None).
type PyTable<'py> = (Vec<String>, Vec<&'static str>, Vec<Bound<'py, PyList>>);

/// The `gyrolab.Error` of a store failure (its message names the store, password masked).
fn store_err(e: StoreError) -> PyErr {
    crate::error(e.to_string())
}

/// Opens the store at `location` (None: `GYROLAB_STORE`, else `gyrolab.db` in the current
/// folder), runs `query` on it with the interpreter released, and closes it.
fn with_store<T: Send>(
    py: Python<'_>,
    location: Option<String>,
    create: bool,
    query: impl FnOnce(&mut Store) -> Result<T, StoreError> + Send,
) -> PyResult<T> {
    opened(py, Store::open, location, create, query)
}

/// Like [`with_store`], the store opened for writing (its quick check first).
fn with_store_writing<T: Send>(
    py: Python<'_>,
    location: Option<String>,
    create: bool,
    write: impl FnOnce(&mut Store) -> Result<T, StoreError> + Send,
) -> PyResult<T> {
    opened(py, Store::open_for_writing, location, create, write)
}

/// The store at `location` opened by `open`, `f` run on it with the interpreter released.
fn opened<T: Send>(
    py: Python<'_>,
    open: fn(&str, bool) -> Result<Store, StoreError>,
    location: Option<String>,
    create: bool,
    f: impl FnOnce(&mut Store) -> Result<T, StoreError> + Send,
) -> PyResult<T> {
    py.detach(|| f(&mut open(&resolve_location(location.as_deref()), create)?)).map_err(store_err)
}

/// A table as Python lists, one per column.
fn table_out(py: Python<'_>, table: Table) -> PyResult<PyTable<'_>> {
    let mut columns: Vec<Vec<Py<PyAny>>> =
        (0..table.columns.len()).map(|_| Vec::with_capacity(table.rows.len())).collect();
    for row in table.rows {
        for (i, cell) in row.into_iter().enumerate() {
            let v = match cell {
                Cell::Empty => py.None(),
                Cell::Text(t) => t.into_pyobject(py)?.into_any().unbind(),
                Cell::Number(x) => x.into_pyobject(py)?.into_any().unbind(),
                Cell::Count(n) => n.into_pyobject(py)?.into_any().unbind(),
            };
            if let Some(c) = columns.get_mut(i) {
                c.push(v);
            }
        }
    }
    let lists = columns.into_iter().map(|c| PyList::new(py, c)).collect::<PyResult<Vec<_>>>()?;
    Ok((table.columns, table.kinds.iter().map(|k| k.as_str()).collect(), lists))
}

/// Every figure of every evaluation (all revisions) of a serial, oldest first; only `figure`
/// when given.
#[pyfunction]
#[pyo3(signature = (location, serial, figure=None))]
pub fn store_history(
    py: Python<'_>,
    location: Option<String>,
    serial: String,
    figure: Option<String>,
) -> PyResult<PyTable<'_>> {
    let rows = with_store(py, location, false, |s| tables::history(s, &serial, figure.as_deref()))?;
    table_out(py, tables::history_table(&rows))
}

/// The trend plot of a serial's history as an SVG document (the `--svg` file of `gyrolab store
/// history`); only `figure` when given. `None`: no value to plot.
#[pyfunction]
#[pyo3(signature = (location, serial, figure=None))]
pub fn store_history_svg(
    py: Python<'_>,
    location: Option<String>,
    serial: String,
    figure: Option<String>,
) -> PyResult<Option<String>> {
    let rows = with_store(py, location, false, |s| tables::history(s, &serial, figure.as_deref()))?;
    tables::history_svg(&serial, &rows).map_err(|e| crate::error(e.to_string()))
}

/// Lot statistics per figure (capability intervals at `confidence`): values, bounds and devices
/// not evaluated counted apart, the notes in the `notes` column.
#[pyfunction]
#[pyo3(signature = (location, lot, confidence))]
pub fn store_lot(py: Python<'_>, location: Option<String>, lot: String, confidence: f64) -> PyResult<PyTable<'_>> {
    if !(confidence > 0.0 && confidence < 1.0) {
        return Err(crate::keyword_error("confidence", format!("confidence {confidence}: must be between 0 and 1")));
    }
    let rows = with_store(py, location, false, |s| query::lot(s, &lot, confidence))?;
    table_out(py, tables::lot_table(&rows))
}

/// Two lots compared per figure.
#[pyfunction]
pub fn store_compare(py: Python<'_>, location: Option<String>, lot1: String, lot2: String) -> PyResult<PyTable<'_>> {
    let rows = with_store(py, location, false, |s| query::compare(s, &lot1, &lot2))?;
    table_out(py, tables::compare_table(&rows))
}

/// Control charts of one figure of one axis (individuals over `lot`, or every device), and
/// their notes (the devices left out: bounds, not evaluated; why a chart is missing).
#[pyfunction]
#[pyo3(signature = (location, axis, figure, lot=None))]
pub fn store_chart(
    py: Python<'_>,
    location: Option<String>,
    axis: String,
    figure: String,
    lot: Option<String>,
) -> PyResult<(PyTable<'_>, Vec<String>)> {
    let charts = with_store(py, location, false, |s| query::control_charts(s, lot.as_deref(), &axis, &figure))?;
    Ok((table_out(py, tables::chart_table(&charts))?, tables::chart_notes(&charts)))
}

/// The current figures of a lot's devices (every device: `lot` None), one row per device and
/// figure.
#[pyfunction]
#[pyo3(signature = (location, lot=None))]
pub fn store_figures(py: Python<'_>, location: Option<String>, lot: Option<String>) -> PyResult<PyTable<'_>> {
    let series = with_store(py, location, false, |s| query::lot_series(s, lot.as_deref()))?;
    table_out(py, tables::figures_table(&series))
}

/// One stored evaluation (device, plan, inputs, revisions, figures) as the JSON of `gyrolab
/// store show --json`.
#[pyfunction]
pub fn store_evaluation(py: Python<'_>, location: Option<String>, id: i64) -> PyResult<String> {
    // The JSON of `gyrolab store show --json`: the evaluation, its issue and its audit trail.
    let (e, issued, events) =
        with_store(py, location, false, |s| Ok((s.evaluation(id)?, s.issue_of(id)?, s.audit_events(Some(id))?)))?;
    let v = tables::evaluation_json(&e, issued.as_ref(), &events).map_err(crate::json_err)?;
    serde_json::to_string(&v).map_err(crate::json_err)
}

/// Stores a finished report folder (its plan: `plan`, else the one its results.json names), the
/// store created when missing: (evaluation id, store name with the password masked).
/// `user` and `password`: the account that stores it (a store with accounts needs one).
#[pyfunction]
#[pyo3(signature = (location, folder, plan=None, user=None, password=None))]
pub fn store_add(
    py: Python<'_>,
    location: Option<String>,
    folder: PathBuf,
    plan: Option<PathBuf>,
    user: Option<String>,
    password: Option<String>,
) -> PyResult<(i64, String)> {
    let credentials = credentials(user, password)?;
    let credentials = credentials.as_ref().map(|(u, p)| (u.as_str(), p.as_str()));
    // A folder stored already gives the evaluation that holds it (adding is idempotent).
    match py.detach(|| {
        gyrolab_lab::evaluate::add_report_folder(&folder, plan.as_deref(), location.as_deref(), credentials)
            .map(|s| (s.id, s.line))
    }) {
        Err(gyrolab_store::StoreError::AlreadyStored { store, id }) => Ok((id, store)),
        other => other.map_err(store_err),
    }
}

/// The location as the store's messages show it: a URL's whole user information and its query
/// masked as `***`, a keyword string's password as `***` (gyrolab_store::location).
#[pyfunction]
pub fn store_masked(location: &str) -> String {
    gyrolab_store::mask_location(location)
}

/// Writes the stored report folder of evaluation `id` to `out` (every file checked against its
/// SHA-256; all files or none): the files written.
#[pyfunction]
pub fn store_report(py: Python<'_>, location: Option<String>, id: i64, out: PathBuf) -> PyResult<Vec<PathBuf>> {
    with_store(py, location, false, |s| s.write_report(id, &out))
}

/// An account's name and password, both or neither.
fn credentials(user: Option<String>, password: Option<String>) -> PyResult<Option<(String, String)>> {
    match (user, password) {
        (Some(u), Some(p)) => Ok(Some((u, p))),
        (None, None) => Ok(None),
        (Some(u), None) => Err(crate::error(format!("user {u:?} needs its password (password=...)"))),
        (None, Some(_)) => Err(crate::error("a password needs its user (user=...)")),
    }
}

/// Opens the store for writing (its quick check first) and authenticates `user` (no account
/// when none is given, which a store with accounts refuses at the write).
fn as_actor(
    store: &mut Store,
    user: Option<String>,
    password: Option<String>,
) -> Result<gyrolab_store::Actor, StoreError> {
    match (user, password) {
        (Some(u), Some(p)) => store.authenticate(&u, &p),
        _ => Ok(gyrolab_store::Actor::unauthenticated()),
    }
}

/// `gyrolab store check --json`: the full check's report as JSON (`problems` empty when whole).
#[pyfunction]
pub fn store_check(py: Python<'_>, location: Option<String>) -> PyResult<String> {
    let r = with_store(py, location, false, |s| s.check())?;
    serde_json::to_string(&r).map_err(|e| crate::error(e.to_string()))
}

/// `gyrolab store user list --json`: every account as JSON.
#[pyfunction]
pub fn store_accounts(py: Python<'_>, location: Option<String>) -> PyResult<String> {
    let a = with_store(py, location, false, |s| s.accounts())?;
    serde_json::to_string(&a).map_err(|e| crate::error(e.to_string()))
}

/// `gyrolab store user add`: the account `name` with `role` and `new_password`, added by the
/// admin `user` (the store's first account: an admin, by no one); the line saying so.
#[pyfunction]
#[pyo3(signature = (location, name, role, new_password, display_name=None, user=None, password=None))]
#[allow(clippy::too_many_arguments)]
pub fn store_add_user(
    py: Python<'_>,
    location: Option<String>,
    name: String,
    role: String,
    new_password: String,
    display_name: Option<String>,
    user: Option<String>,
    password: Option<String>,
) -> PyResult<String> {
    let role = gyrolab_store::Role::parse(&role)
        .ok_or_else(|| crate::error(format!("role {role:?}: expected viewer, operator, approver or admin")))?;
    credentials(user.clone(), password.clone())?;
    with_store_writing(py, location, true, |s| {
        let actor = as_actor(s, user, password)?;
        let display = display_name.as_deref().unwrap_or(&name);
        tables::add_account(s, &actor, &name, display, role, &new_password)
    })
}

/// `gyrolab store issue` (`amend_reason` None) or `store amend`: evaluation `id` issued by the
/// approver `user` with the lab's private key file `signing_key`; the issued report as JSON.
#[pyfunction]
#[pyo3(signature = (location, id, user, password, signing_key, meaning, report_number=None, amend_reason=None))]
#[allow(clippy::too_many_arguments)]
pub fn store_issue(
    py: Python<'_>,
    location: Option<String>,
    id: i64,
    user: String,
    password: String,
    signing_key: PathBuf,
    meaning: String,
    report_number: Option<String>,
    amend_reason: Option<String>,
) -> PyResult<String> {
    let meaning = match meaning.as_str() {
        "approved" => gyrolab_store::issue::Meaning::Approved,
        "reviewed" => gyrolab_store::issue::Meaning::Reviewed,
        other => return Err(crate::error(format!("meaning {other:?}: expected approved or reviewed"))),
    };
    let key = gyrolab_store::sign::read_signing_key(&signing_key).map_err(crate::error)?;
    let r = with_store_writing(py, location, false, |s| {
        let actor = s.authenticate(&user, &password)?;
        let req = gyrolab_lab::issue::Issue {
            evaluation: id,
            meaning,
            key: &key,
            report_number: report_number.as_deref(),
            amend_reason: amend_reason.as_deref(),
        };
        gyrolab_lab::issue::issue(s, &actor, &req)
    })?;
    serde_json::to_string(&r).map_err(|e| crate::error(e.to_string()))
}

/// `gyrolab store reevaluate --json`: evaluation `id` evaluated again under this build (from its
/// files where unchanged, else the store's raw records) into `out`, stored as a revision by the
/// account `user` (or `by` in a store without accounts) for `reason`; the changes as JSON.
#[pyfunction]
#[pyo3(signature = (location, id, out, reason, by=None, user=None, password=None))]
#[allow(clippy::too_many_arguments)]
pub fn store_reevaluate(
    py: Python<'_>,
    location: Option<String>,
    id: i64,
    out: PathBuf,
    reason: String,
    by: Option<String>,
    user: Option<String>,
    password: Option<String>,
) -> PyResult<String> {
    credentials(user.clone(), password.clone())?;
    let r = with_store_writing(py, location, false, |s| {
        let actor = as_actor(s, user, password)?;
        let who = tables::revision_author(&actor, by.as_deref())
            .map_err(|m| StoreError::Refused { store: s.name().to_string(), message: m })?;
        gyrolab_lab::reevaluate::reevaluate_as(s, id, &who, &reason, &out, &actor)
    })?;
    serde_json::to_string(&r).map_err(|e| crate::error(e.to_string()))
}

/// `gyrolab store report ID --inputs`: the plan and raw records of evaluation `id` written into
/// the new folder `out`, laid out as they stood relative to the plan: (the plan, the records).
#[pyfunction]
pub fn store_inputs(
    py: Python<'_>,
    location: Option<String>,
    id: i64,
    out: PathBuf,
) -> PyResult<(PathBuf, Vec<PathBuf>)> {
    let r = with_store(py, location, false, |s| gyrolab_lab::raw_records::restore_inputs(s, id, &out))?;
    Ok((r.plan, r.inputs.into_iter().map(|(_, p)| p).collect()))
}
