//! The queries of the store: one evaluation, the history of a serial, lot statistics, the
//! comparison of two lots, control charts. The statistics are the core crate's
//! (`gyrolab::process_capability`, `gyrolab::two_sample`, `gyrolab::control_chart`); here they
//! are only fed with the right values in the right order.
//!
//! Which values count: the *current* revision of an evaluation is the one no other revision
//! supersedes; for lot statistics and charts each device (serial) counts once, with its latest
//! current evaluation (highest id), in test order (test date, else evaluation time, then id).
//! Only values enter means, spreads, indices, tests and charts ([`classify`]): a figure stored
//! as a bound is counted apart, and a device whose figure has no value, or the verdict NOT
//! EVALUATED, or (in a lot) no such figure at all, is counted as not evaluated (issue 53).

use crate::db::{first_int, Columns, DbError, Kind, Row, Val};
use crate::record::{EvaluationRecord, FigureRecord, FileRecord};
use crate::{Store, StoreError, StoreResult};
use gyrolab::control_chart::{individuals_moving_range, xbar_s, Chart};
use gyrolab::process_capability::{lot_statistics, LotStatistics};
use gyrolab::two_sample::{compare_samples, TwoSampleComparison};
use serde::Serialize;
use std::collections::{BTreeMap, HashMap};

/// One stored evaluation and its place among the revisions.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StoredEvaluation {
    /// Id.
    pub id: i64,
    /// The evaluation this one supersedes.
    pub supersedes: Option<i64>,
    /// The revision that supersedes this one (`None`: this is current).
    pub superseded_by: Option<i64>,
    /// original, reevaluation, correction, approval.
    pub revision_kind: String,
    /// Who made the revision.
    pub revision_by: Option<String>,
    /// Why.
    pub revision_reason: Option<String>,
    /// When it was stored (RFC 3339 UTC).
    pub stored_at: String,
    /// The record.
    pub record: EvaluationRecord,
}

/// The columns of an evaluation row, by name.
const EVALUATION_COLUMNS: Columns<'static> = &[
    ("id", Kind::I),
    ("supersedes", Kind::IOpt),
    ("revision_kind", Kind::T),
    ("revision_by", Kind::T),
    ("revision_reason", Kind::T),
    ("stored_at", Kind::T),
    ("serial", Kind::T),
    ("model", Kind::T),
    ("lot", Kind::T),
    ("operator", Kind::T),
    ("approver", Kind::T),
    ("test_date", Kind::T),
    ("evaluated_at", Kind::T),
    ("software_version", Kind::T),
    ("plan_path", Kind::T),
    ("plan_text", Kind::T),
    ("plan_sha256", Kind::T),
    ("results_json", Kind::T),
    ("verdict", Kind::T),
    ("simulated", Kind::I),
];

/// The columns of a figure row (the figure's own, without its evaluation), by name.
const FIGURE_COLUMNS: Columns<'static> = &[
    ("axis", Kind::T),
    ("figure", Kind::T),
    ("value", Kind::F),
    ("unit", Kind::T),
    ("basis", Kind::T),
    ("expanded_uncertainty", Kind::F),
    ("coverage_factor", Kind::F),
    ("limit_min", Kind::F),
    ("limit_max", Kind::F),
    ("verdict", Kind::T),
    ("simulated", Kind::I),
];

/// A figure read by name; `prefix` before each column's name (`f_` where the evaluation's
/// columns share the row).
fn figure_of(r: &Row, prefix: &str) -> Result<FigureRecord, DbError> {
    let c = |n: &str| format!("{prefix}{n}");
    Ok(FigureRecord {
        axis: r.string(&c("axis"))?,
        figure: r.string(&c("figure"))?,
        value: r.float(&c("value"))?,
        unit: r.string(&c("unit"))?,
        basis: r.string(&c("basis"))?,
        expanded_uncertainty: r.float(&c("expanded_uncertainty"))?,
        coverage_factor: r.float(&c("coverage_factor"))?,
        limit_min: r.float(&c("limit_min"))?,
        limit_max: r.float(&c("limit_max"))?,
        verdict: r.string_opt(&c("verdict"))?,
        simulated: r.int(&c("simulated"))? != 0,
    })
}

/// One evaluation by id.
pub fn evaluation(store: &mut Store, id: i64) -> StoreResult<StoredEvaluation> {
    let rows = store.rows(
        "SELECT id, supersedes, revision_kind, revision_by, revision_reason, stored_at, serial, model, lot, operator, \
         approver, test_date, evaluated_at, software_version, plan_path, plan_text, plan_sha256, results_json, verdict, simulated \
         FROM evaluation WHERE id = $1",
        &[Val::I(id)],
        EVALUATION_COLUMNS,
    )?;
    let Some(r) = rows.into_iter().next() else {
        return Err(StoreError::NotFound { store: store.name().to_string(), message: format!("no evaluation {id}") });
    };
    let later = store.rows("SELECT id FROM evaluation WHERE supersedes = $1", &[Val::I(id)], &[("id", Kind::I)])?;
    let files = |store: &mut Store, sql: &str| -> StoreResult<Vec<FileRecord>> {
        let rows =
            store.rows(sql, &[Val::I(id)], &[("name", Kind::T), ("sha256", Kind::T), ("size_bytes", Kind::I)])?;
        rows.iter()
            .map(|f| {
                Ok(FileRecord {
                    path: f.string("name")?,
                    sha256: f.string("sha256")?,
                    size_bytes: f.int("size_bytes")? as u64,
                    content: None,
                    packed: None,
                })
            })
            .collect::<Result<_, DbError>>()
            .map_err(|e| store.row_error(e))
    };
    let inputs =
        files(store, "SELECT path AS name, sha256, size_bytes FROM input_file WHERE evaluation_id = $1 ORDER BY path")?;
    let mut report_files =
        files(store, "SELECT name, sha256, size_bytes FROM report_file WHERE evaluation_id = $1 ORDER BY name")?;
    let mut contents: HashMap<String, Vec<u8>> =
        read_report_files(store, id)?.into_iter().filter_map(|(n, b)| b.map(|b| (n, b))).collect();
    for f in &mut report_files {
        f.content = contents.remove(&f.path);
    }
    let figures = store
        .rows(
            "SELECT axis, figure, value, unit, basis, expanded_uncertainty, coverage_factor, limit_min, limit_max, verdict, simulated \
             FROM figure WHERE evaluation_id = $1",
            &[Val::I(id)],
            FIGURE_COLUMNS,
        )?
        .iter()
        .map(|f| figure_of(f, ""))
        .collect::<Result<Vec<_>, DbError>>()
        .map_err(|e| store.row_error(e))?;
    let read = || -> Result<StoredEvaluation, DbError> {
        Ok(StoredEvaluation {
            id: r.int("id")?,
            supersedes: r.int_opt("supersedes")?,
            superseded_by: later.first().map(|l| l.int("id")).transpose()?,
            revision_kind: r.string("revision_kind")?,
            revision_by: r.string_opt("revision_by")?,
            revision_reason: r.string_opt("revision_reason")?,
            stored_at: r.string("stored_at")?,
            record: EvaluationRecord {
                serial: r.string("serial")?,
                model: r.string("model")?,
                lot: r.string_opt("lot")?,
                operator: r.string_opt("operator")?,
                approver: r.string_opt("approver")?,
                test_date: r.string_opt("test_date")?,
                evaluated_at: r.string("evaluated_at")?,
                software_version: r.string("software_version")?,
                plan_path: r.string("plan_path")?,
                plan_text: r.string("plan_text")?,
                plan_sha256: r.string("plan_sha256")?,
                results_json: r.string("results_json")?,
                verdict: r.string_opt("verdict")?,
                simulated: r.int("simulated")? != 0,
                inputs,
                report_files,
                figures,
            },
        })
    };
    read().map_err(|e| store.row_error(e))
}

/// One figure of one evaluation, as history lists it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HistoryRow {
    /// Evaluation id.
    pub evaluation: i64,
    /// The evaluation it supersedes.
    pub supersedes: Option<i64>,
    /// True when no revision supersedes it.
    pub current: bool,
    /// original, reevaluation, correction, approval.
    pub revision_kind: String,
    /// Test date, else the evaluation time.
    pub tested: String,
    /// gyrolab version of the evaluation.
    pub software_version: String,
    /// Lot.
    pub lot: Option<String>,
    /// Overall verdict.
    pub overall_verdict: Option<String>,
    /// SIMULATED inputs.
    pub simulated: bool,
    /// The figure.
    #[serde(flatten)]
    pub figure: FigureRecord,
    /// The evaluation's report: `DRAFT`, `ISSUED <number>`, or `SUPERSEDED <number> by <number>`.
    pub report: String,
}

/// Every figure of every evaluation (all revisions) of a serial, oldest first.
pub fn history(store: &mut Store, serial: &str) -> StoreResult<Vec<HistoryRow>> {
    let mut columns: Vec<(&str, Kind)> = vec![
        ("id", Kind::I),
        ("supersedes", Kind::IOpt),
        ("current", Kind::I),
        ("revision_kind", Kind::T),
        ("tested", Kind::T),
        ("software_version", Kind::T),
        ("lot", Kind::T),
        ("verdict", Kind::T),
        ("simulated", Kind::I),
    ];
    let figure_columns: Vec<(String, Kind)> = FIGURE_COLUMNS.iter().map(|(n, k)| (format!("f_{n}"), *k)).collect();
    columns.extend(figure_columns.iter().map(|(n, k)| (n.as_str(), *k)));
    let rows = store.rows(
        "SELECT e.id AS id, e.supersedes AS supersedes, \
         CAST(CASE WHEN EXISTS (SELECT 1 FROM evaluation s WHERE s.supersedes = e.id) THEN 0 ELSE 1 END AS BIGINT) AS current, \
         e.revision_kind AS revision_kind, COALESCE(e.test_date, e.evaluated_at) AS tested, e.software_version AS software_version, \
         e.lot AS lot, e.verdict AS verdict, e.simulated AS simulated, \
         f.axis AS f_axis, f.figure AS f_figure, f.value AS f_value, f.unit AS f_unit, f.basis AS f_basis, \
         f.expanded_uncertainty AS f_expanded_uncertainty, f.coverage_factor AS f_coverage_factor, f.limit_min AS f_limit_min, \
         f.limit_max AS f_limit_max, f.verdict AS f_verdict, f.simulated AS f_simulated \
         FROM evaluation e JOIN figure f ON f.evaluation_id = e.id WHERE e.serial = $1 ORDER BY e.id, f.axis, f.figure",
        &[Val::T(Some(serial.to_string()))],
        &columns,
    )?;
    if rows.is_empty() {
        let any = store.rows(
            "SELECT COUNT(*) AS n FROM evaluation WHERE serial = $1",
            &[Val::T(Some(serial.to_string()))],
            &[("n", Kind::I)],
        )?;
        if first_int(&any, "n", 0).map_err(|e| store.row_error(e))? == 0 {
            return Err(StoreError::NotFound {
                store: store.name().to_string(),
                message: format!("no evaluation of serial {serial:?}"),
            });
        }
    }
    let issued: HashMap<i64, String> = store
        .rows(
            "SELECT i.evaluation_id AS evaluation_id, i.report_number AS report_number, \
             (SELECT s.report_number FROM issue s WHERE s.amends = i.id) AS superseded_by FROM issue i \
             JOIN evaluation e ON e.id = i.evaluation_id WHERE e.serial = $1",
            &[Val::T(Some(serial.to_string()))],
            &[("evaluation_id", Kind::I), ("report_number", Kind::T), ("superseded_by", Kind::T)],
        )?
        .iter()
        .map(|r| {
            let number = r.string("report_number")?;
            let status = match r.text("superseded_by")? {
                Some(by) => format!("SUPERSEDED {number} by {by}"),
                None => format!("ISSUED {number}"),
            };
            Ok((r.int("evaluation_id")?, status))
        })
        .collect::<Result<_, DbError>>()
        .map_err(|e| store.row_error(e))?;
    rows.iter()
        .map(|r| {
            let id = r.int("id")?;
            Ok(HistoryRow {
                report: issued.get(&id).cloned().unwrap_or_else(|| "DRAFT".into()),
                evaluation: id,
                supersedes: r.int_opt("supersedes")?,
                current: r.int("current")? == 1,
                revision_kind: r.string("revision_kind")?,
                tested: r.string("tested")?,
                software_version: r.string("software_version")?,
                lot: r.string_opt("lot")?,
                overall_verdict: r.string_opt("verdict")?,
                simulated: r.int("simulated")? != 0,
                figure: figure_of(r, "f_")?,
            })
        })
        .collect::<Result<_, DbError>>()
        .map_err(|e| store.row_error(e))
}

/// The verdict of a figure that was not evaluated (`gyrolab::limits`).
pub const NOT_EVALUATED: &str = "NOT EVALUATED";

/// What one device's current evaluation gives for a figure, as stored.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DeviceReading {
    /// Serial.
    pub serial: String,
    /// Evaluation id.
    pub evaluation: i64,
    /// The stored basis: `value`, `upper_bound`, `lower_bound`, `absent`...
    pub basis: String,
    /// The stored number: the value, or the bound (`None`: none stored).
    pub value: Option<f64>,
    /// The stored verdict (`None`: no limit).
    pub verdict: Option<String>,
}

/// What a stored figure row counts as in lot statistics.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reading {
    /// A value: basis `value`, a finite number, a verdict other than NOT EVALUATED. Only these
    /// enter means, standard deviations, indices, comparisons and charts.
    Value,
    /// Only a bound: basis `upper_bound` or `lower_bound` with a finite number (whatever its
    /// verdict). Counted, never averaged.
    Bound,
    /// Not evaluated: no finite number, another basis (`absent`), or a value whose verdict is
    /// NOT EVALUATED (the evaluation itself declined to use it).
    NotEvaluated,
}

/// The class of a stored figure row (see [`Reading`]).
pub fn classify(basis: &str, value: Option<f64>, verdict: Option<&str>) -> Reading {
    match (basis, value.filter(|v| v.is_finite())) {
        ("value", Some(_)) if verdict != Some(NOT_EVALUATED) => Reading::Value,
        ("upper_bound" | "lower_bound", Some(_)) => Reading::Bound,
        _ => Reading::NotEvaluated,
    }
}

/// One figure of one axis over a lot's devices, in test order: the values, the bounds, the
/// devices not evaluated and (lot queries) the devices whose current evaluation lacks the figure.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FigureSeries {
    /// Axis.
    pub axis: String,
    /// Figure key.
    pub figure: String,
    /// Unit.
    pub unit: String,
    /// Lower limit (of the latest evaluation).
    pub limit_min: Option<f64>,
    /// Upper limit (of the latest evaluation).
    pub limit_max: Option<f64>,
    /// (serial, evaluation id, value) in test order: the values only ([`Reading::Value`]).
    pub values: Vec<(String, i64, f64)>,
    /// Any row of this figure from SIMULATED records.
    pub simulated: bool,
    /// Devices that give only a bound ([`Reading::Bound`]), in test order.
    pub bounds: Vec<DeviceReading>,
    /// Devices whose figure is stored but not evaluated ([`Reading::NotEvaluated`]), in test order.
    pub not_evaluated: Vec<DeviceReading>,
    /// Serials of the lot's devices whose current evaluation has no such figure while others
    /// have it, in test order (empty for the every-lot series).
    pub missing: Vec<String>,
    /// Devices counted: every device of the lot (each once) for a lot; the devices with this
    /// figure for the every-lot series.
    pub n_devices: usize,
}

/// One figure row of a chosen evaluation: serial, id, test order key, class, basis, number, verdict.
type SeriesRow<'a> = (&'a str, i64, &'a str, Reading, &'a str, Option<f64>, Option<&'a str>);

/// Rows, limits and id of the latest evaluation, simulated; texts borrowed from the query's rows
/// (no copy per row).
type Group<'a> = (Vec<SeriesRow<'a>>, Option<f64>, Option<f64>, i64, bool);

/// One series per (axis, figure, unit) of the current evaluations in `lot` (all lots: `None`),
/// each device once (its latest current evaluation): values, bounds and devices not evaluated
/// apart.
pub fn lot_series(store: &mut Store, lot: Option<&str>) -> StoreResult<Vec<FigureSeries>> {
    // Two queries: the lot's current evaluations (one row each), then their figures (only the
    // columns that change per figure). Figures of evaluations not chosen by the first query
    // (superseded ones, or ones stored in between) are passed over. Every figure row is read
    // (values, bounds, rows without a value) and classified here (`classify`).
    const EVAL_LOT: &str =
        "SELECT e.id AS id, e.serial AS serial, COALESCE(e.test_date, e.evaluated_at) AS tested FROM evaluation e \
         WHERE e.lot = $1 AND NOT EXISTS (SELECT 1 FROM evaluation s WHERE s.supersedes = e.id)";
    const EVAL_ALL: &str =
        "SELECT e.id AS id, e.serial AS serial, COALESCE(e.test_date, e.evaluated_at) AS tested FROM evaluation e \
         WHERE NOT EXISTS (SELECT 1 FROM evaluation s WHERE s.supersedes = e.id)";
    const FIG_LOT: &str =
        "SELECT f.evaluation_id AS evaluation_id, f.axis AS axis, f.figure AS figure, f.unit AS unit, f.value AS value, \
         f.basis AS basis, f.verdict AS verdict, f.limit_min AS limit_min, f.limit_max AS limit_max, f.simulated AS simulated \
         FROM figure f JOIN evaluation e ON e.id = f.evaluation_id WHERE e.lot = $1";
    const FIG_ALL: &str =
        "SELECT f.evaluation_id AS evaluation_id, f.axis AS axis, f.figure AS figure, f.unit AS unit, f.value AS value, \
         f.basis AS basis, f.verdict AS verdict, f.limit_min AS limit_min, f.limit_max AS limit_max, f.simulated AS simulated \
         FROM figure f";
    let eval_kinds: Columns<'_> = &[("id", Kind::I), ("serial", Kind::T), ("tested", Kind::T)];
    let fig_kinds: Columns<'_> = &[
        ("evaluation_id", Kind::I),
        ("axis", Kind::T),
        ("figure", Kind::T),
        ("unit", Kind::T),
        ("value", Kind::F),
        ("basis", Kind::T),
        ("verdict", Kind::T),
        ("limit_min", Kind::F),
        ("limit_max", Kind::F),
        ("simulated", Kind::I),
    ];
    let lot_param = [Val::T(lot.map(str::to_string))];
    let (evals, rows) = match lot {
        Some(_) => (store.rows(EVAL_LOT, &lot_param, eval_kinds)?, store.rows(FIG_LOT, &lot_param, fig_kinds)?),
        None => (store.rows(EVAL_ALL, &[], eval_kinds)?, store.rows(FIG_ALL, &[], fig_kinds)?),
    };
    let groups = group_series(&evals, &rows, lot.is_some()).map_err(|e| store.row_error(e))?;
    Ok(groups)
}

/// The series of [`lot_series`] from its two queries' rows; `whole_lot`: every chosen device
/// counts in each figure (a device without the figure is `missing`).
fn group_series(evals: &[Row], rows: &[Row], whole_lot: bool) -> Result<Vec<FigureSeries>, DbError> {
    // The latest current evaluation per serial: id -> (serial, test order key).
    let mut latest: HashMap<&str, (i64, &str)> = HashMap::with_capacity(evals.len());
    for r in evals {
        let (id, serial, date) =
            (r.int("id")?, r.text("serial")?.unwrap_or_default(), r.text("tested")?.unwrap_or_default());
        let e = latest.entry(serial).or_insert((id, date));
        if id > e.0 {
            *e = (id, date);
        }
    }
    let chosen: HashMap<i64, (&str, &str)> = latest.into_iter().map(|(s, (id, d))| (id, (s, d))).collect();
    let mut index: HashMap<(&str, &str, &str), usize> = HashMap::new();
    let mut groups: Vec<((&str, &str, &str), Group)> = Vec::new();
    for r in rows {
        let id = r.int("evaluation_id")?;
        let Some(&(serial, date)) = chosen.get(&id) else { continue };
        let (value, basis, verdict) = (r.float("value")?, r.text("basis")?.unwrap_or_default(), r.text("verdict")?);
        let key = (
            r.text("axis")?.unwrap_or_default(),
            r.text("figure")?.unwrap_or_default(),
            r.text("unit")?.unwrap_or_default(),
        );
        let i = *index.entry(key).or_insert_with(|| {
            groups.push((key, (Vec::new(), None, None, i64::MIN, false)));
            groups.len() - 1
        });
        let g = &mut groups[i].1;
        g.0.push((serial, id, date, classify(basis, value, verdict), basis, value, verdict));
        if id > g.3 {
            g.1 = r.float("limit_min")?;
            g.2 = r.float("limit_max")?;
            g.3 = id;
        }
        g.4 |= r.int("simulated")? != 0;
    }
    groups.sort_by(|a, b| a.0.cmp(&b.0));
    let mut devices: Vec<(&str, i64, &str)> = chosen.iter().map(|(id, (s, d))| (*s, *id, *d)).collect();
    devices.sort_by(|a, b| a.2.cmp(b.2).then(a.1.cmp(&b.1)));
    Ok(groups
        .into_iter()
        .map(|((axis, figure, unit), (mut v, lo, hi, _, sim))| {
            v.sort_by(|a, b| a.2.cmp(b.2).then(a.1.cmp(&b.1)));
            let reading = |r: &SeriesRow| DeviceReading {
                serial: r.0.to_string(),
                evaluation: r.1,
                basis: r.4.to_string(),
                value: r.5,
                verdict: r.6.map(str::to_string),
            };
            let missing: Vec<String> = if whole_lot {
                devices.iter().filter(|d| !v.iter().any(|r| r.1 == d.1)).map(|d| d.0.to_string()).collect()
            } else {
                Vec::new()
            };
            FigureSeries {
                axis: axis.to_string(),
                figure: figure.to_string(),
                unit: unit.to_string(),
                limit_min: lo,
                limit_max: hi,
                values: v
                    .iter()
                    .filter(|r| r.3 == Reading::Value)
                    .filter_map(|r| r.5.map(|x| (r.0.to_string(), r.1, x)))
                    .collect(),
                simulated: sim,
                bounds: v.iter().filter(|r| r.3 == Reading::Bound).map(reading).collect(),
                not_evaluated: v.iter().filter(|r| r.3 == Reading::NotEvaluated).map(reading).collect(),
                n_devices: v.len() + missing.len(),
                missing,
            }
        })
        .collect())
}

/// Serials as a note lists them: at most ten, then how many more.
fn serial_list<'a>(serials: impl Iterator<Item = &'a str>) -> String {
    let all: Vec<&str> = serials.collect();
    let mut s = all.iter().take(10).copied().collect::<Vec<_>>().join(", ");
    if all.len() > 10 {
        s.push_str(&format!(" and {} more", all.len() - 10));
    }
    s
}

/// "1 device" / "3 devices".
fn devices(n: usize) -> String {
    format!("{n} device{}", if n == 1 { "" } else { "s" })
}

/// The notes of a series' bounds and devices not evaluated (empty when every device gives a value).
fn series_notes(s: &FigureSeries) -> Vec<String> {
    let mut notes = Vec::new();
    let unit = if s.unit.is_empty() { String::new() } else { format!(" {}", s.unit) };
    let uppers: Vec<f64> = s.bounds.iter().filter(|b| b.basis == "upper_bound").filter_map(|b| b.value).collect();
    let lowers: Vec<f64> = s.bounds.iter().filter(|b| b.basis == "lower_bound").filter_map(|b| b.value).collect();
    if let Some(x) = uppers.iter().copied().reduce(f64::max) {
        notes.push(format!(
            "{} give{} only an upper bound (each at most {}{unit}, the largest bound): kept out of the statistics",
            devices(uppers.len()),
            if uppers.len() == 1 { "s" } else { "" },
            gyrolab::format::short(x, 6)
        ));
    }
    if let Some(x) = lowers.iter().copied().reduce(f64::min) {
        notes.push(format!(
            "{} give{} only a lower bound (each above {}{unit}, the smallest bound): kept out of the statistics",
            devices(lowers.len()),
            if lowers.len() == 1 { "s" } else { "" },
            gyrolab::format::short(x, 6)
        ));
    }
    if !s.not_evaluated.is_empty() {
        notes.push(format!(
            "{} NOT EVALUATED (no value, or the verdict NOT EVALUATED): {}",
            devices(s.not_evaluated.len()),
            serial_list(s.not_evaluated.iter().map(|r| r.serial.as_str()))
        ));
    }
    if !s.missing.is_empty() {
        notes.push(format!(
            "{} without this figure in {} current evaluation, counted as NOT EVALUATED: {}",
            devices(s.missing.len()),
            if s.missing.len() == 1 { "its" } else { "their" },
            serial_list(s.missing.iter().map(String::as_str))
        ));
    }
    notes
}

/// The statistics of one figure over a lot: the values' statistics, and every device of the lot
/// counted (values, bounds, not evaluated) with the yield over all of them.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LotFigure {
    /// Axis.
    pub axis: String,
    /// Figure key.
    pub figure: String,
    /// Unit.
    pub unit: String,
    /// Lower limit.
    pub limit_min: Option<f64>,
    /// Upper limit.
    pub limit_max: Option<f64>,
    /// Statistics of the values only (capability intervals: chi-squared for Cp/Pp, Bissell for
    /// Cpk/Ppk); `None` when no device gives a value (`warnings` says why).
    pub statistics: Option<LotStatistics>,
    /// Serial numbers of the outliers (Tukey's fences).
    pub outlier_serials: Vec<String>,
    /// Any row of this figure from SIMULATED records.
    pub simulated: bool,
    /// Devices of the lot, each once (its latest current evaluation): n_evaluated + n_bounds +
    /// n_not_evaluated.
    pub n_devices: usize,
    /// Devices that give a value (the statistics' n).
    pub n_evaluated: usize,
    /// Devices that give only a bound (upper or lower), kept out of the statistics.
    pub n_bounds: usize,
    /// Devices that give only an upper bound.
    pub n_upper_bounds: usize,
    /// The largest upper bound (each of those devices is at most it).
    pub largest_upper_bound: Option<f64>,
    /// Devices that give only a lower bound.
    pub n_lower_bounds: usize,
    /// The smallest lower bound (each of those devices is above it).
    pub smallest_lower_bound: Option<f64>,
    /// Devices NOT EVALUATED on this figure: stored without a usable value, with the verdict NOT
    /// EVALUATED, or (`n_missing`) without the figure in their current evaluation.
    pub n_not_evaluated: usize,
    /// Of the devices not evaluated, those whose current evaluation lacks the figure.
    pub n_missing: usize,
    /// Serials of the devices that give only a bound, in test order.
    pub bound_serials: Vec<String>,
    /// Serials of the devices not evaluated (missing ones included), in test order.
    pub not_evaluated_serials: Vec<String>,
    /// Devices that conform to the limits: a value inside them (inclusive), or a bound that
    /// decides (an upper bound at most the upper limit without a lower limit, a lower bound at
    /// least the lower limit without an upper limit); `None` without limits.
    pub conforming_devices: Option<usize>,
    /// conforming_devices / n_devices: the lot's yield, a device not evaluated counting as not
    /// conforming (`statistics.yield_fraction` is the yield among the values only).
    pub yield_devices: Option<f64>,
    /// Notes: bounds, devices not evaluated, then the statistics' warnings (few values, n < 2,
    /// indices refused).
    pub warnings: Vec<String>,
}

/// Lot statistics of every figure of `lot` at `confidence` (e.g. 0.95): every figure any
/// device of the lot has, with every device of the lot counted (values, bounds, not evaluated).
pub fn lot(store: &mut Store, lot: &str, confidence: f64) -> StoreResult<Vec<LotFigure>> {
    let series = lot_series(store, Some(lot))?;
    if series.is_empty() {
        return Err(StoreError::NotFound {
            store: store.name().to_string(),
            message: format!("no figures stored for lot {lot:?}"),
        });
    }
    Ok(series.into_iter().map(|s| lot_figure(s, confidence)).collect())
}

/// The lot statistics of one series.
fn lot_figure(s: FigureSeries, confidence: f64) -> LotFigure {
    let values: Vec<f64> = s.values.iter().map(|v| v.2).collect();
    let statistics = lot_statistics(&values, s.limit_min, s.limit_max, confidence);
    let outlier_serials =
        statistics.as_ref().map_or_else(Vec::new, |st| st.outliers.iter().map(|i| s.values[*i].0.clone()).collect());
    let upper = |b: &&DeviceReading| b.basis == "upper_bound";
    let uppers: Vec<f64> = s.bounds.iter().filter(upper).filter_map(|b| b.value).collect();
    let lowers: Vec<f64> = s.bounds.iter().filter(|b| !upper(b)).filter_map(|b| b.value).collect();
    let (lo, hi) = (s.limit_min, s.limit_max);
    let conforming = (lo.is_some() || hi.is_some()).then(|| {
        values.iter().filter(|v| lo.is_none_or(|l| **v >= l) && hi.is_none_or(|u| **v <= u)).count()
            + uppers.iter().filter(|b| lo.is_none() && hi.is_some_and(|u| **b <= u)).count()
            + lowers.iter().filter(|b| hi.is_none() && lo.is_some_and(|l| **b >= l)).count()
    });
    let mut warnings = series_notes(&s);
    match &statistics {
        Some(st) => warnings.extend(st.warnings.iter().cloned()),
        None => warnings.push("no device gives a value: no statistics".into()),
    }
    let mut not_evaluated: Vec<String> = s.not_evaluated.iter().map(|r| r.serial.clone()).collect();
    not_evaluated.extend(s.missing.iter().cloned());
    LotFigure {
        n_evaluated: values.len(),
        n_bounds: s.bounds.len(),
        n_upper_bounds: uppers.len(),
        largest_upper_bound: uppers.iter().copied().reduce(f64::max),
        n_lower_bounds: lowers.len(),
        smallest_lower_bound: lowers.iter().copied().reduce(f64::min),
        n_not_evaluated: not_evaluated.len(),
        n_missing: s.missing.len(),
        bound_serials: s.bounds.iter().map(|b| b.serial.clone()).collect(),
        not_evaluated_serials: not_evaluated,
        conforming_devices: conforming,
        yield_devices: conforming.filter(|_| s.n_devices > 0).map(|c| c as f64 / s.n_devices as f64),
        n_devices: s.n_devices,
        warnings,
        axis: s.axis,
        figure: s.figure,
        unit: s.unit,
        limit_min: s.limit_min,
        limit_max: s.limit_max,
        statistics,
        outlier_serials,
        simulated: s.simulated,
    }
}

/// The comparison of one figure between two lots, from the values only.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LotComparison {
    /// Axis.
    pub axis: String,
    /// Figure key.
    pub figure: String,
    /// Unit.
    pub unit: String,
    /// Values in the first lot (devices that give a value).
    pub n1: usize,
    /// Values in the second lot.
    pub n2: usize,
    /// Mean of the first lot's values (`None`: no value).
    pub mean1: Option<f64>,
    /// Mean of the second lot's values.
    pub mean2: Option<f64>,
    /// Welch's t-test and the F-test (`None`: a lot has fewer than two values, or no spread or a
    /// degenerate one).
    pub test: Option<TwoSampleComparison>,
    /// Devices of the first lot (values, bounds and not evaluated).
    pub n_devices1: usize,
    /// Devices of the second lot.
    pub n_devices2: usize,
    /// Devices of the first lot that give only a bound.
    pub n_bounds1: usize,
    /// Devices of the second lot that give only a bound.
    pub n_bounds2: usize,
    /// Devices of the first lot not evaluated (missing ones included).
    pub n_not_evaluated1: usize,
    /// Devices of the second lot not evaluated.
    pub n_not_evaluated2: usize,
    /// Notes: each lot's bounds and devices not evaluated (`lot A: ...`), and why there is no test.
    pub notes: Vec<String>,
}

/// Every figure present in both lots, compared on the values only.
pub fn compare(store: &mut Store, lot1: &str, lot2: &str) -> StoreResult<Vec<LotComparison>> {
    let a = lot_series(store, Some(lot1))?;
    let b = lot_series(store, Some(lot2))?;
    for (l, s) in [(lot1, &a), (lot2, &b)] {
        if s.is_empty() {
            return Err(StoreError::NotFound {
                store: store.name().to_string(),
                message: format!("no figures stored for lot {l:?}"),
            });
        }
    }
    let mean = |v: &[f64]| (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64);
    Ok(a.iter()
        .filter_map(|x| {
            let y = b.iter().find(|y| y.axis == x.axis && y.figure == x.figure && y.unit == x.unit)?;
            let xv: Vec<f64> = x.values.iter().map(|v| v.2).collect();
            let yv: Vec<f64> = y.values.iter().map(|v| v.2).collect();
            let test = compare_samples(&xv, &yv);
            let mut notes: Vec<String> = series_notes(x).into_iter().map(|n| format!("lot {lot1}: {n}")).collect();
            notes.extend(series_notes(y).into_iter().map(|n| format!("lot {lot2}: {n}")));
            if test.is_none() {
                notes.push(if xv.len() < 2 || yv.len() < 2 {
                    "no test: a lot has fewer than two values".into()
                } else {
                    "no test: a lot's values have no spread (zero or degenerate)".into()
                });
            }
            Some(LotComparison {
                axis: x.axis.clone(),
                figure: x.figure.clone(),
                unit: x.unit.clone(),
                n1: xv.len(),
                n2: yv.len(),
                mean1: mean(&xv),
                mean2: mean(&yv),
                test,
                n_devices1: x.n_devices,
                n_devices2: y.n_devices,
                n_bounds1: x.bounds.len(),
                n_bounds2: y.bounds.len(),
                n_not_evaluated1: x.not_evaluated.len() + x.missing.len(),
                n_not_evaluated2: y.not_evaluated.len() + y.missing.len(),
                notes,
            })
        })
        .collect())
}

/// Control charts of one figure of one axis, from the values only.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ControlCharts {
    /// Axis.
    pub axis: String,
    /// Figure key.
    pub figure: String,
    /// Unit.
    pub unit: String,
    /// Serial of each individual point, in test order.
    pub serials: Vec<String>,
    /// Individuals chart (`None`: fewer than two devices or no variation).
    pub individuals: Option<Chart>,
    /// Moving-range chart.
    pub moving_range: Option<Chart>,
    /// Lot of each X-bar/S point.
    pub lots: Vec<String>,
    /// X-bar chart over lots (lots of at least two devices; `None` without such lots).
    pub xbar: Option<Chart>,
    /// S chart over lots.
    pub s: Option<Chart>,
    /// Devices of the individuals chart's series (the lot's, or every device with the figure).
    pub n_devices: usize,
    /// Of them, devices that give only a bound (no point).
    pub n_bounds: usize,
    /// Of them, devices not evaluated (no point; missing ones included).
    pub n_not_evaluated: usize,
    /// Devices of the X-bar/S lots left out: bounds or not evaluated.
    pub n_left_out_of_lots: usize,
    /// Notes: the bounds and devices not evaluated left out, and why a chart is missing.
    pub notes: Vec<String>,
}

/// I-MR charts over the devices of `lot` (all lots: `None`) and X-bar/S over every lot, from the
/// values only (each device once, its latest current evaluation).
pub fn control_charts(store: &mut Store, lot: Option<&str>, axis: &str, figure: &str) -> StoreResult<ControlCharts> {
    let series = lot_series(store, lot)?;
    let Some(s) = series.into_iter().find(|s| s.axis == axis && s.figure == figure) else {
        return Err(StoreError::NotFound {
            store: store.name().to_string(),
            message: format!(
                "no values of figure {figure:?} on axis {axis:?}{}",
                lot.map_or(String::new(), |l| format!(" in lot {l:?}"))
            ),
        });
    };
    let values: Vec<f64> = s.values.iter().map(|v| v.2).collect();
    let im = individuals_moving_range(&values);
    // X-bar/S: every lot, devices grouped by their lot; each serial's latest current
    // evaluation (highest id), then only its value counts.
    let rows = store.rows(
        "SELECT e.id AS id, e.serial AS serial, e.lot AS lot, f.value AS value, f.basis AS basis, f.verdict AS verdict \
         FROM evaluation e JOIN figure f ON f.evaluation_id = e.id \
         WHERE e.lot IS NOT NULL AND f.axis = $1 AND f.figure = $2 \
         AND NOT EXISTS (SELECT 1 FROM evaluation s WHERE s.supersedes = e.id) ORDER BY e.id",
        &[Val::T(Some(axis.to_string())), Val::T(Some(figure.to_string()))],
        &[
            ("id", Kind::I),
            ("serial", Kind::T),
            ("lot", Kind::T),
            ("value", Kind::F),
            ("basis", Kind::T),
            ("verdict", Kind::T),
        ],
    )?;
    let mut per_serial: BTreeMap<String, (String, Option<f64>, i64)> = BTreeMap::new();
    for r in rows {
        let read = || -> Result<_, DbError> {
            let (value, basis, verdict) = (r.float("value")?, r.string("basis")?, r.text("verdict")?);
            let v = value.filter(|_| classify(&basis, value, verdict) == Reading::Value);
            Ok((v, r.string("serial")?, r.string("lot")?, r.int("id")?))
        };
        let (value, serial, lot, id) = read().map_err(|e| store.row_error(e))?;
        per_serial.insert(serial, (lot, value, id));
    }
    let left_out = per_serial.values().filter(|v| v.1.is_none()).count();
    let mut lots: BTreeMap<String, (i64, Vec<f64>)> = BTreeMap::new();
    for (lot, v, id) in per_serial.into_values() {
        let Some(v) = v else { continue };
        let e = lots.entry(lot).or_insert((i64::MAX, Vec::new()));
        e.0 = e.0.min(id);
        e.1.push(v);
    }
    let mut ordered: Vec<(String, (i64, Vec<f64>))> = lots.into_iter().filter(|(_, g)| g.1.len() >= 2).collect();
    ordered.sort_by_key(|(_, g)| g.0);
    let groups: Vec<Vec<f64>> = ordered.iter().map(|(_, g)| g.1.clone()).collect();
    let xs = xbar_s(&groups);
    let mut notes: Vec<String> = series_notes(&s).into_iter().map(|n| format!("{n}: no point")).collect();
    if im.is_none() {
        notes.push(if values.len() < 2 {
            "no individuals chart: fewer than two values".into()
        } else {
            "no individuals chart: the values have no spread (zero or degenerate)".into()
        });
    }
    if left_out > 0 {
        notes.push(format!(
            "X-bar/S: {} of the lots give no value (bounds or NOT EVALUATED): left out",
            devices(left_out)
        ));
    }
    Ok(ControlCharts {
        n_devices: s.n_devices,
        n_bounds: s.bounds.len(),
        n_not_evaluated: s.not_evaluated.len() + s.missing.len(),
        n_left_out_of_lots: left_out,
        notes,
        axis: s.axis,
        figure: s.figure,
        unit: s.unit,
        serials: s.values.iter().map(|v| v.0.clone()).collect(),
        individuals: im.as_ref().map(|c| c.0.clone()),
        moving_range: im.map(|c| c.1),
        lots: ordered.into_iter().map(|(l, _)| l).collect(),
        xbar: xs.as_ref().map(|c| c.0.clone()),
        s: xs.map(|c| c.1),
    })
}

/// The changes between two evaluations: every figure whose value or verdict differs.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FigureChange {
    /// Axis.
    pub axis: String,
    /// Figure key.
    pub figure: String,
    /// Unit.
    pub unit: String,
    /// Value before.
    pub before: Option<f64>,
    /// Value after.
    pub after: Option<f64>,
    /// after - before.
    pub difference: Option<f64>,
    /// Verdict before.
    pub verdict_before: Option<String>,
    /// Verdict after.
    pub verdict_after: Option<String>,
}

/// Every figure whose value (bit for bit) or verdict changed from `before` to `after`, and
/// figures present in only one of them.
pub fn diff_figures(before: &[FigureRecord], after: &[FigureRecord]) -> Vec<FigureChange> {
    let key = |f: &FigureRecord| (f.axis.clone(), f.figure.clone());
    let mut out = Vec::new();
    for b in before {
        let a = after.iter().find(|a| key(a) == key(b));
        let (av, aver) = (a.and_then(|a| a.value), a.and_then(|a| a.verdict.clone()));
        if a.is_none() || av.map(f64::to_bits) != b.value.map(f64::to_bits) || aver != b.verdict {
            out.push(FigureChange {
                axis: b.axis.clone(),
                figure: b.figure.clone(),
                unit: b.unit.clone(),
                before: b.value,
                after: av,
                difference: av.zip(b.value).map(|(a, b)| a - b),
                verdict_before: b.verdict.clone(),
                verdict_after: aver,
            });
        }
    }
    for a in after.iter().filter(|a| !before.iter().any(|b| key(b) == key(a))) {
        out.push(FigureChange {
            axis: a.axis.clone(),
            figure: a.figure.clone(),
            unit: a.unit.clone(),
            before: None,
            after: a.value,
            difference: None,
            verdict_before: None,
            verdict_after: a.verdict.clone(),
        });
    }
    out
}

/// The report files of evaluation `id` with their bytes (decompressed, each checked against its
/// recorded size and SHA-256), by name. A file stored without its bytes (stored under schema
/// version 1, or larger than [`crate::record::MAX_KEPT_FILE_BYTES`]) is an error naming it.
pub fn report_files(store: &mut Store, id: i64) -> StoreResult<Vec<(String, Vec<u8>)>> {
    // The evaluation reads (and checks) its report files' bytes already: they are used as read.
    let name = store.name().to_string();
    evaluation(store, id)?
        .record
        .report_files
        .into_iter()
        .map(|f| {
            let file = f.path;
            f.content.map(|b| (file.clone(), b)).ok_or_else(|| StoreError::NotFound {
                store: name.clone(),
                message: format!(
                    "evaluation {id}: report file {file:?} was stored as a hash only (stored before schema version 2, \
                     or larger than {} bytes)",
                    crate::record::MAX_KEPT_FILE_BYTES
                ),
            })
        })
        .collect()
}

/// Every report file of evaluation `id` by name, with its bytes when stored (decompressed and
/// checked against the recorded size and SHA-256: a mismatch is an error).
fn read_report_files(store: &mut Store, id: i64) -> StoreResult<Vec<(String, Option<Vec<u8>>)>> {
    let rows = store.rows(
        "SELECT name, sha256, size_bytes, content_zstd FROM report_file WHERE evaluation_id = $1 ORDER BY name",
        &[Val::I(id)],
        &[("name", Kind::T), ("sha256", Kind::T), ("size_bytes", Kind::I), ("content_zstd", Kind::B)],
    )?;
    let name = store.name().to_string();
    let mut out = Vec::with_capacity(rows.len());
    for r in rows {
        let read = || -> Result<_, DbError> {
            Ok((r.string("name")?, r.string("sha256")?, r.int("size_bytes")?, r.bytes("content_zstd")?))
        };
        let (file, sha256, size, packed) = read().map_err(|e| store.row_error(e))?;
        let Some(packed) = packed else {
            out.push((file, None));
            continue;
        };
        let size = usize::try_from(size).ok().filter(|s| *s as u64 <= crate::record::MAX_KEPT_FILE_BYTES);
        let bytes = size
            .and_then(|s| zstd::bulk::decompress(packed, s.max(1)).ok())
            .filter(|b| Some(b.len()) == size && crate::record::hash_bytes(b) == sha256)
            .ok_or_else(|| StoreError::Database {
                store: name.clone(),
                message: format!(
                    "evaluation {id}: report file {file:?} does not match its recorded size and SHA-256 {sha256}"
                ),
            })?;
        out.push((file, Some(bytes)));
    }
    Ok(out)
}

/// Writes the stored report folder of evaluation `id` to `out` (every file or none; each checked
/// against its SHA-256 first); the files written.
/// An issued evaluation's folder is the issued one (crate::issue: the signed manifest, manifest.sig
/// and issue.json, superseded when amended), every file checked against the signed manifest and
/// the signature against the lab key recorded in the store.
pub fn write_report(store: &mut Store, id: i64, out: &std::path::Path) -> StoreResult<Vec<std::path::PathBuf>> {
    let files = match store.issued_files(id)? {
        Some(f) => f,
        None => report_files(store, id)?,
    };
    let refs: Vec<(&str, &[u8])> = files.iter().map(|(n, b)| (n.as_str(), b.as_slice())).collect();
    gyrolab_io::atomic::write_folder(out, &refs, &[])
        .map_err(|e| StoreError::Input { path: e.path.display().to_string(), message: e.to_string() })
}

/// Writes the raw record of SHA-256 `sha256` kept in the store (schema 6, `input_content`) to
/// `out`, decompressed on the way and checked against its SHA-256 and size: `Ok(false)` when the
/// store holds no copy (an input over [`crate::record::MAX_KEPT_INPUT_BYTES`], or stored before
/// version 6), an error when the copy does not match.
pub fn write_input_content(store: &mut Store, sha256: &str, out: &mut dyn std::io::Write) -> StoreResult<bool> {
    use sha2::Digest;
    let rows = store.rows(
        "SELECT size_bytes, content_zstd FROM input_content WHERE sha256 = $1",
        &[Val::T(Some(sha256.to_string()))],
        &[("size_bytes", Kind::I), ("content_zstd", Kind::B)],
    )?;
    let Some(r) = rows.into_iter().next() else { return Ok(false) };
    let read = || -> Result<_, DbError> { Ok((r.int("size_bytes")?, r.bytes("content_zstd")?.unwrap_or_default())) };
    let (size, packed) = read().map_err(|e| store.row_error(e))?;
    let name = store.name().to_string();
    let broken = |why: String| StoreError::Database {
        store: name.clone(),
        message: format!("the kept raw record of SHA-256 {sha256} {why}"),
    };
    let mut decoder =
        zstd::stream::Decoder::new(packed).map_err(|e| broken(format!("cannot be decompressed ({e})")))?;
    let mut hasher = sha2::Sha256::new();
    let mut block = vec![0u8; 1 << 20];
    let mut total = 0i64;
    loop {
        let n = std::io::Read::read(&mut decoder, &mut block)
            .map_err(|e| broken(format!("cannot be decompressed ({e})")))?;
        if n == 0 {
            break;
        }
        total += n as i64;
        if total > size {
            return Err(broken(format!("is longer than its recorded {size} bytes")));
        }
        hasher.update(&block[..n]);
        out.write_all(&block[..n]).map_err(|e| broken(format!("cannot be written out ({e})")))?;
    }
    let sha: String = hasher.finalize().iter().map(|b| format!("{b:02x}")).collect();
    if sha != sha256 || total != size {
        return Err(broken(format!("does not match: {total} bytes, SHA-256 {sha} ({size} bytes recorded)")));
    }
    Ok(true)
}
