//! The records store's queries for every front end: their results as [`Table`]s (the command
//! line prints or exports them; Python turns them into DataFrames), a serial's history as a
//! trend plot, and the plain-text summaries of stored evaluations, checks, accounts and
//! re-evaluations. Column names are the keys of the JSON output; units are in a `unit` column beside
//! each value. The store queries; gyrolab-report renders; this module joins them.

use gyrolab_report::table::to_text;
use gyrolab_report::table::ColumnKind::{self, Count as C, Number as N, Text as T};
use gyrolab_report::table::{Cell, Table};
use gyrolab_report::trend::{trend_svg, TrendPanel};
use gyrolab_store::issue::IssuedReport;
use gyrolab_store::{query, Account, Actor, AuditEvent, Changes, CheckReport, Revision, Store, StoreResult};

fn num(v: Option<f64>) -> Cell {
    Cell::number(v)
}

fn text(v: &str) -> Cell {
    Cell::Text(v.to_string())
}

fn opt(v: &Option<String>) -> Cell {
    Cell::text(v.as_deref())
}

/// Column names and kinds from (name, kind) pairs.
fn columns(v: &[(&str, ColumnKind)]) -> (Vec<String>, Vec<ColumnKind>) {
    (v.iter().map(|(n, _)| n.to_string()).collect(), v.iter().map(|(_, k)| *k).collect())
}

/// The history of a serial: one row per figure of each evaluation (all revisions), oldest first.
pub fn history_table(rows: &[query::HistoryRow]) -> Table {
    let (head, kinds) = columns(&[
        ("evaluation", C),
        ("supersedes", C),
        ("current", T),
        ("revision", T),
        ("tested", T),
        ("gyrolab", T),
        ("axis", T),
        ("figure", T),
        ("value", N),
        ("unit", T),
        ("basis", T),
        ("U", N),
        ("k", N),
        ("limit_min", N),
        ("limit_max", N),
        ("verdict", T),
        ("simulated", T),
        ("report", T),
    ]);
    let body = rows
        .iter()
        .map(|r| {
            vec![
                Cell::Count(r.evaluation),
                r.supersedes.map_or(Cell::Empty, Cell::Count),
                text(if r.current { "yes" } else { "no" }),
                text(&r.revision_kind),
                text(&r.tested),
                text(&r.software_version),
                text(&r.figure.axis),
                text(&r.figure.figure),
                num(r.figure.value),
                text(&r.figure.unit),
                text(&r.figure.basis),
                num(r.figure.expanded_uncertainty),
                num(r.figure.coverage_factor),
                num(r.figure.limit_min),
                num(r.figure.limit_max),
                opt(&r.figure.verdict),
                text(if r.figure.simulated { "SIMULATED" } else { "" }),
                text(&r.report),
            ]
        })
        .collect();
    Table { columns: head, kinds, rows: body }
}

fn index_cols(i: Option<gyrolab::process_capability::Index>) -> [Cell; 3] {
    match i {
        Some(i) => [num(Some(i.value)), num(i.interval.map(|c| c.lower)), num(i.interval.map(|c| c.upper))],
        None => [Cell::Empty, Cell::Empty, Cell::Empty],
    }
}

/// Lot statistics: one row per (axis, figure) with n (the values counted), n_devices (every
/// device of the lot), n_bounds and n_not_evaluated, mean, sd, range, limits, yield (over every
/// device) and yield_evaluated (over the values), the four capability indices with their
/// confidence intervals, outliers, the SIMULATED mark and the notes (bounds, devices not
/// evaluated, few values, indices refused), joined by "; ".
pub fn lot_table(rows: &[query::LotFigure]) -> Table {
    let (head, kinds) = columns(&[
        ("axis", T),
        ("figure", T),
        ("unit", T),
        ("n", C),
        ("n_devices", C),
        ("n_bounds", C),
        ("n_not_evaluated", C),
        ("mean", N),
        ("sd", N),
        ("min", N),
        ("max", N),
        ("limit_min", N),
        ("limit_max", N),
        ("yield", N),
        ("yield_evaluated", N),
        ("Cp", N),
        ("Cp_lo", N),
        ("Cp_hi", N),
        ("Cpk", N),
        ("Cpk_lo", N),
        ("Cpk_hi", N),
        ("Pp", N),
        ("Pp_lo", N),
        ("Pp_hi", N),
        ("Ppk", N),
        ("Ppk_lo", N),
        ("Ppk_hi", N),
        ("outliers", T),
        ("simulated", T),
        ("notes", T),
    ]);
    let body = rows
        .iter()
        .map(|r| {
            let s = r.statistics.as_ref();
            let mut v = vec![
                text(&r.axis),
                text(&r.figure),
                text(&r.unit),
                Cell::Count(r.n_evaluated as i64),
                Cell::Count(r.n_devices as i64),
                Cell::Count(r.n_bounds as i64),
                Cell::Count(r.n_not_evaluated as i64),
                num(s.map(|s| s.mean)),
                num(s.and_then(|s| s.sd)),
                num(s.map(|s| s.min)),
                num(s.map(|s| s.max)),
                num(r.limit_min),
                num(r.limit_max),
                num(r.yield_devices),
                num(s.and_then(|s| s.yield_fraction)),
            ];
            for i in s.map_or([None; 4], |s| [s.cp, s.cpk, s.pp, s.ppk]) {
                v.extend(index_cols(i));
            }
            v.push(text(&r.outlier_serials.join(" ")));
            v.push(text(if r.simulated { "SIMULATED" } else { "" }));
            v.push(text(&r.warnings.join("; ")));
            v
        })
        .collect();
    Table { columns: head, kinds, rows: body }
}

/// Lot statistics as text (`gyrolab store lot`): the table of [`lot_table`] without its notes
/// column, then each figure's notes on lines of their own under `notes:` (what the numbers
/// leave out or cannot carry: bounds, devices not evaluated, few values, indices refused).
pub fn lot_text(rows: &[query::LotFigure]) -> String {
    let mut table = lot_table(rows);
    table.columns.pop();
    table.kinds.pop();
    for r in &mut table.rows {
        r.pop();
    }
    let mut out = to_text(&table);
    if rows.iter().any(|r| !r.warnings.is_empty()) {
        out.push_str("notes:\n");
        for r in rows {
            for w in &r.warnings {
                out.push_str(&format!("  {} {}: {w}\n", r.axis, r.figure));
            }
        }
    }
    out.push_str(
        "n: devices with a value (the statistics' n); n_devices: every device of the lot (its latest current \
         evaluation); yield: conforming devices / n_devices (not evaluated = not conforming); yield_evaluated: \
         values inside the limits / n\n",
    );
    out
}

/// Two lots compared: one row per (axis, figure) with the values counted (n1, n2) of the
/// devices (n_devices1, n_devices2), both means, their difference, Welch's t-test and the
/// F-test of the spreads, from the values only, and the notes (bounds, devices not evaluated,
/// why there is no test).
pub fn compare_table(rows: &[query::LotComparison]) -> Table {
    let (head, kinds) = columns(&[
        ("axis", T),
        ("figure", T),
        ("unit", T),
        ("n1", C),
        ("n2", C),
        ("n_devices1", C),
        ("n_devices2", C),
        ("mean1", N),
        ("mean2", N),
        ("difference", N),
        ("welch_t", N),
        ("dof", N),
        ("p_means", N),
        ("sd_ratio", N),
        ("F", N),
        ("p_spreads", N),
        ("notes", T),
    ]);
    let body = rows
        .iter()
        .map(|r| {
            let t = r.test;
            vec![
                text(&r.axis),
                text(&r.figure),
                text(&r.unit),
                Cell::Count(r.n1 as i64),
                Cell::Count(r.n2 as i64),
                Cell::Count(r.n_devices1 as i64),
                Cell::Count(r.n_devices2 as i64),
                num(r.mean1),
                num(r.mean2),
                num(r.mean1.zip(r.mean2).map(|(a, b)| a - b)),
                num(t.map(|t| t.t)),
                num(t.map(|t| t.t_dof)),
                num(t.map(|t| t.t_p_value)),
                num(t.map(|t| t.sd_ratio)),
                num(t.map(|t| t.f)),
                num(t.map(|t| t.f_p_value)),
                text(&r.notes.join("; ")),
            ]
        })
        .collect();
    Table { columns: head, kinds, rows: body }
}

/// Control charts: one row per point of each chart (individuals, moving range, X-bar, S) with its
/// centre line, limits and the Nelson rules it violates.
pub fn chart_table(c: &query::ControlCharts) -> Table {
    let (head, kinds) = columns(&[
        ("chart", T),
        ("point", C),
        ("label", T),
        ("value", N),
        ("center", N),
        ("lcl", N),
        ("ucl", N),
        ("violations", T),
    ]);
    let mut body = Vec::new();
    let mut add = |name: &str, chart: &Option<gyrolab::control_chart::Chart>, labels: &dyn Fn(usize) -> String| {
        if let Some(ch) = chart {
            for (i, v) in ch.points.iter().enumerate() {
                let rules: Vec<String> =
                    ch.violations.iter().filter(|x| x.index == i).map(|x| format!("nelson {}", x.rule)).collect();
                body.push(vec![
                    text(name),
                    Cell::Count(i as i64 + 1),
                    Cell::Text(labels(i)),
                    num(Some(*v)),
                    num(Some(ch.center)),
                    num(Some(ch.lcl[i])),
                    num(Some(ch.ucl[i])),
                    text(&rules.join(" ")),
                ]);
            }
        }
    };
    add("individuals", &c.individuals, &|i| c.serials.get(i).cloned().unwrap_or_default());
    add("moving_range", &c.moving_range, &|i| {
        format!(
            "{}-{}",
            c.serials.get(i).cloned().unwrap_or_default(),
            c.serials.get(i + 1).cloned().unwrap_or_default()
        )
    });
    add("xbar", &c.xbar, &|i| c.lots.get(i).cloned().unwrap_or_default());
    add("s", &c.s, &|i| c.lots.get(i).cloned().unwrap_or_default());
    Table { columns: head, kinds, rows: body }
}

/// A re-evaluation's changes: one row per figure whose value or verdict changed.
pub fn diff_table(rows: &[query::FigureChange]) -> Table {
    let (head, kinds) = columns(&[
        ("axis", T),
        ("figure", T),
        ("unit", T),
        ("before", N),
        ("after", N),
        ("difference", N),
        ("verdict_before", T),
        ("verdict_after", T),
    ]);
    let body = rows
        .iter()
        .map(|r| {
            vec![
                text(&r.axis),
                text(&r.figure),
                text(&r.unit),
                num(r.before),
                num(r.after),
                num(r.difference),
                opt(&r.verdict_before),
                opt(&r.verdict_after),
            ]
        })
        .collect();
    Table { columns: head, kinds, rows: body }
}

/// The current figures of a lot's devices (every lot: `lot_series(store, None)`), long form: one
/// row per device and (axis, figure), in test order within each figure (values, then bounds,
/// then devices not evaluated), with the limits of the latest evaluation; `series_simulated` is
/// SIMULATED when any row of that figure in the lot comes from SIMULATED records. `value` holds
/// values only: a bound is in `bound` (its `basis` upper_bound or lower_bound), a device not
/// evaluated has neither; `verdict` is the stored verdict of a bound or of a device not
/// evaluated (empty for values).
pub fn figures_table(series: &[query::FigureSeries]) -> Table {
    let (head, kinds) = columns(&[
        ("axis", T),
        ("figure", T),
        ("unit", T),
        ("serial", T),
        ("evaluation", C),
        ("value", N),
        ("limit_min", N),
        ("limit_max", N),
        ("series_simulated", T),
        ("basis", T),
        ("bound", N),
        ("verdict", T),
    ]);
    let mut body = Vec::new();
    for s in series {
        let row =
            |serial: &str, id: i64, value: Option<f64>, basis: &str, bound: Option<f64>, verdict: Option<&str>| {
                vec![
                    text(&s.axis),
                    text(&s.figure),
                    text(&s.unit),
                    text(serial),
                    Cell::Count(id),
                    num(value),
                    num(s.limit_min),
                    num(s.limit_max),
                    text(if s.simulated { "SIMULATED" } else { "" }),
                    text(basis),
                    num(bound),
                    Cell::text(verdict),
                ]
            };
        for (serial, id, value) in &s.values {
            body.push(row(serial, *id, Some(*value), "value", None, None));
        }
        for b in &s.bounds {
            body.push(row(&b.serial, b.evaluation, None, &b.basis, b.value, b.verdict.as_deref()));
        }
        for r in &s.not_evaluated {
            body.push(row(&r.serial, r.evaluation, None, &r.basis, None, r.verdict.as_deref()));
        }
    }
    Table { columns: head, kinds, rows: body }
}

/// The notes of control charts: the devices left out (bounds, not evaluated) and why a chart is
/// missing; the command line prints them on standard error beside the table, Python in the
/// frame's `attrs["notes"]`.
pub fn chart_notes(c: &query::ControlCharts) -> Vec<String> {
    c.notes.clone()
}

/// The history of a serial (every figure of every evaluation, all revisions, oldest first), only
/// `figure` when given.
pub fn history(store: &mut Store, serial: &str, figure: Option<&str>) -> StoreResult<Vec<query::HistoryRow>> {
    let mut rows = query::history(store, serial)?;
    if let Some(f) = figure {
        rows.retain(|r| r.figure.figure == f);
    }
    Ok(rows)
}

/// The trend plot of a history as an SVG document: one panel per (axis, figure), value against
/// evaluation id, the latest evaluation's limits as horizontal lines; SIMULATED in the title when
/// any value is. `Ok(None)`: no value to plot.
pub fn history_svg(
    serial: &str,
    rows: &[query::HistoryRow],
) -> Result<Option<String>, gyrolab_report::plot::PlotError> {
    let mut keys: Vec<(&str, &str, &str)> = Vec::new();
    for r in rows {
        let k = (r.figure.axis.as_str(), r.figure.figure.as_str(), r.figure.unit.as_str());
        if !keys.contains(&k) {
            keys.push(k);
        }
    }
    let panels: Vec<TrendPanel> = keys
        .into_iter()
        .map(|(axis, figure, unit)| {
            let pts: Vec<&query::HistoryRow> =
                rows.iter().filter(|r| r.figure.axis == axis && r.figure.figure == figure).collect();
            let last = pts.last();
            TrendPanel {
                axis: axis.to_string(),
                figure: figure.to_string(),
                unit: unit.to_string(),
                points: pts.iter().filter_map(|r| r.figure.value.map(|v| (r.evaluation as f64, v))).collect(),
                limit_min: last.and_then(|r| r.figure.limit_min),
                limit_max: last.and_then(|r| r.figure.limit_max),
            }
        })
        .collect();
    let simulated = if rows.iter().any(|r| r.figure.simulated) { " (SIMULATED)" } else { "" };
    trend_svg(&format!("History of serial {serial}{simulated}"), &panels)
}

/// A stored evaluation as text (`gyrolab store show`): its device, revisions, plan, inputs and
/// figures, its report's issue (or DRAFT) and its audit trail.
pub fn evaluation_text(e: &query::StoredEvaluation, issued: Option<&IssuedReport>, events: &[AuditEvent]) -> String {
    let mut text = show_text(e);
    match issued {
        Some(r) => text.push_str(&issue_line(r)),
        None => text.push_str("report: DRAFT (not issued: gyrolab store issue)\n"),
    }
    text.push_str("audit trail (the store's clock):\n");
    if events.is_empty() {
        text.push_str("  (none: stored before schema version 4)\n");
    }
    for ev in events {
        text.push_str(&format!(
            "  {} {} by {}{}\n",
            ev.at,
            ev.action,
            ev.actor,
            ev.detail.as_deref().map_or_else(String::new, |d| format!(": {d:?}"))
        ));
    }
    text
}

/// The issue line of `store show`.
fn issue_line(r: &IssuedReport) -> String {
    let mut s = format!(
        "report {} {} {}: {} by {} ({}, {}), key {}\n",
        r.report_number,
        r.status(),
        r.issued_at,
        r.meaning,
        r.signer_display_name,
        r.signer,
        r.signer_role,
        r.key_fingerprint
    );
    if let (Some(old), Some(n)) = (&r.amends_report, r.amendment_no) {
        s.push_str(&format!("amendment {n} to report {old}: {}\n", r.amend_reason.as_deref().unwrap_or_default()));
    }
    s
}

/// The check report of `gyrolab store check` as text.
pub fn check_text(r: &CheckReport, name: &str) -> String {
    let rows: Vec<String> = r.rows.iter().map(|(t, n)| format!("{t} {n}")).collect();
    let mut out = format!(
        "store {name}\ntriggers: {} of {} present and unaltered\nrows: {}\nchain: {} of {} link(s) re-verified against \
         their rows\nreport files: {} re-hashed equal to their SHA-256, {} stored as hashes only\nchain head: {}\n",
        r.triggers_ok.len(),
        r.triggers_expected,
        rows.join(", "),
        r.links_checked,
        r.links,
        r.files_checked,
        r.files_hash_only,
        r.head.as_deref().unwrap_or("(empty store)")
    );
    if r.problems.is_empty() {
        out.push_str("whole: nothing changed, deleted or inserted outside the store\n");
    }
    for p in &r.problems {
        out.push_str(&format!("BROKEN: {p}\n"));
    }
    out
}

/// The accounts of a store as text (`gyrolab store user list`).
pub fn accounts_text(accounts: &[Account]) -> String {
    let mut out = String::from("name\tdisplay name\trole\tstate\tcreated\tcreated by\n");
    for x in accounts {
        out.push_str(&format!(
            "{}\t{}\t{}\t{}\t{}\t{}\n",
            x.name,
            x.display_name,
            x.role.as_str(),
            if x.disabled { "DISABLED" } else { "active" },
            x.created_at,
            x.created_by
        ));
    }
    if accounts.is_empty() {
        out.push_str("(no accounts: writes to this store need no authentication)\n");
    }
    out
}

/// The outcome of a re-evaluation as text, its report in `out` (`gyrolab store reevaluate`).
pub fn reevaluation_text(r: &crate::reevaluate::Reevaluation, out_dir: &std::path::Path) -> String {
    let mut out = format!(
        "re-evaluated evaluation {} (gyrolab {}) under gyrolab {}: evaluation {}, report in {}\n\
         overall verdict: {} -> {}\n{} figure(s) changed\n",
        r.superseded,
        r.software_before,
        r.software_after,
        r.revision,
        out_dir.display(),
        r.verdict_before.as_deref().unwrap_or("none"),
        r.verdict_after.as_deref().unwrap_or("none"),
        r.changes.len()
    );
    if !r.changes.is_empty() {
        out.push_str(&to_text(&diff_table(&r.changes)));
    }
    out
}

/// The text of a stored evaluation without its issue and audit trail.
fn show_text(e: &query::StoredEvaluation) -> String {
    let r = &e.record;
    let o = |v: &Option<String>| v.clone().unwrap_or_else(|| "-".into());
    let mut s = format!(
        "evaluation {} ({}{}{})\n",
        e.id,
        e.revision_kind,
        e.supersedes.map_or_else(String::new, |x| format!(", supersedes {x}")),
        e.superseded_by.map_or_else(|| ", current".to_string(), |x| format!(", superseded by {x}"))
    );
    if let (Some(by), Some(why)) = (&e.revision_by, &e.revision_reason) {
        s.push_str(&format!("revision by {by:?}: {why:?}\n"));
    }
    s.push_str(&format!(
        "stored {}\ndevice {:?} serial {:?} lot {}\noperator {} approver {} tested {}\nevaluated {} with gyrolab {}\nplan {} (SHA-256 {})\nverdict {}{}\n",
        e.stored_at,
        r.model,
        r.serial,
        o(&r.lot),
        o(&r.operator),
        o(&r.approver),
        o(&r.test_date),
        r.evaluated_at,
        r.software_version,
        r.plan_path,
        r.plan_sha256,
        o(&r.verdict),
        if r.simulated { " (SIMULATED inputs)" } else { "" }
    ));
    s.push_str("inputs:\n");
    for f in &r.inputs {
        s.push_str(&format!("  {} {} bytes SHA-256 {}\n", f.path, f.size_bytes, f.sha256));
    }
    s.push_str(&format!("{} figures, {} report files\n", r.figures.len(), r.report_files.len()));
    s
}

/// Stores finished report folders (`gyrolab store add`) as the account `credentials` (name,
/// password) authenticates: one line per folder (stored, or stored already with its id).
pub fn add_folders(
    dirs: &[std::path::PathBuf],
    plan: Option<&std::path::Path>,
    location: Option<&str>,
    credentials: Option<(&str, &str)>,
) -> StoreResult<String> {
    let mut out = String::new();
    for d in dirs {
        match crate::evaluate::add_report_folder(d, plan, location, credentials) {
            Ok(stored) => match stored.revision_of {
                None => {
                    out.push_str(&format!("stored {} as evaluation {} in {}\n", d.display(), stored.id, stored.store))
                }
                Some(_) => out.push_str(&format!("{}: {}\n", d.display(), stored.line)),
            },
            Err(gyrolab_store::StoreError::AlreadyStored { store, id }) => out.push_str(&format!(
                "{} is stored already as evaluation {id} in {store} (the same results.json): nothing added\n",
                d.display()
            )),
            Err(e) => return Err(e),
        }
    }
    Ok(out)
}

/// What `gyrolab store report` wrote: `n` files of evaluation `id` to `out`, issued (the signed
/// manifest checked) or a draft.
pub fn written_report_text(store: &mut Store, id: i64, n: usize, out: &std::path::Path) -> StoreResult<String> {
    let what = match store.issue_of(id)? {
        Some(r) => format!(
            "issued report {} ({}): each file equal to its signed manifest, the signature verified with the \
             store's lab key {}; check it with the lab's own public key: gyrolab verify {} --public-key LAB.pub",
            r.report_number,
            r.status(),
            r.key_fingerprint,
            out.display()
        ),
        None => "a DRAFT: each equal to its stored SHA-256".into(),
    };
    Ok(format!("wrote the {} report file(s) of evaluation {} to {} ({what})\n", n, id, out.display()))
}

/// The note printed when a revision supersedes an issued evaluation: the new revision is a
/// draft, issued only as an amendment (empty otherwise).
pub fn draft_note(s: &mut Store, superseded: i64, revision: i64) -> StoreResult<String> {
    Ok(match s.issue_of(superseded)? {
        Some(r) => format!(
            "evaluation {superseded} is issued as report {}, which stays as issued: evaluation {revision} is a DRAFT \
             until an approver issues it as an amendment (gyrolab store amend {revision} --reason ...)\n",
            r.report_number
        ),
        None => String::new(),
    })
}

/// Who a revision is recorded as made by: the account (a different `--by` refused), else `--by`.
pub fn revision_author(actor: &Actor, given: Option<&str>) -> Result<String, String> {
    match (actor.account(), given) {
        (Some(a), Some(b)) if b != a.name => {
            Err(format!("--by {b:?}: the revision is made by the authenticated account {:?} (leave --by out)", a.name))
        }
        (Some(a), _) => Ok(a.name.clone()),
        (None, Some(b)) => Ok(b.to_string()),
        (None, None) => Err("a revision needs who made it (--by NAME, or --user NAME)".into()),
    }
}

/// Stores the revision `r` (a correction or an approval) with `changes` as `actor`: the line
/// saying so, and the draft note when it supersedes an issued evaluation.
pub fn revise(store: &mut Store, r: &Revision, changes: &Changes, actor: &Actor) -> StoreResult<String> {
    let (record, how) = match r.kind {
        gyrolab_store::RevisionKind::Correction => crate::reevaluate::corrected(store, r.supersedes, changes)?,
        _ => (None, String::new()),
    };
    let id = store.revise_as(r, changes, record.as_ref(), actor)?;
    let note = draft_note(store, r.supersedes, id)?;
    Ok(format!(
        "stored {} of evaluation {} as evaluation {id} in {}\n{how}{note}",
        r.kind.as_str(),
        r.supersedes,
        store.name()
    ))
}

/// A stored evaluation as the JSON of `gyrolab store show --json`: its record with its issue and
/// audit trail.
pub fn evaluation_json(
    e: &query::StoredEvaluation,
    issued: Option<&IssuedReport>,
    events: &[AuditEvent],
) -> Result<serde_json::Value, serde_json::Error> {
    let mut v = serde_json::to_value(e)?;
    v["issue"] = serde_json::to_value(issued)?;
    v["audit"] = serde_json::to_value(events)?;
    Ok(v)
}

/// Adds the account `name` (`gyrolab store user add`) as `actor`: the line saying so.
pub fn add_account(
    store: &mut Store,
    actor: &Actor,
    name: &str,
    display: &str,
    role: gyrolab_store::Role,
    password: &str,
) -> StoreResult<String> {
    store.add_account(actor, name, display, role, password)?;
    Ok(format!("added account {name} ({display}, {}) to {}\n", role.as_str(), store.name()))
}

/// Disables the account `name` as `actor`: the line saying so.
pub fn disable_account(store: &mut Store, actor: &Actor, name: &str) -> StoreResult<String> {
    store.disable_account(actor, name)?;
    Ok(format!("disabled account {name} in {}\n", store.name()))
}

/// Sets a new password of the account `name` as `actor`: the line saying so.
pub fn reset_password(store: &mut Store, actor: &Actor, name: &str, password: &str) -> StoreResult<String> {
    store.reset_password(actor, name, password)?;
    Ok(format!("set a new password of account {name} in {}\n", store.name()))
}
