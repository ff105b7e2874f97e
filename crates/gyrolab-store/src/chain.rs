//! The hash chain over every stored record (issue 53; docs/STORE.md "Threat model and checks").
//!
//! Every row the store inserts into a record table ([`CHAINED`]: `evaluation`, `input_file`,
//! `report_file`, `figure`, from schema version 6 `input_content`; approvals and corrections are `evaluation` rows; from schema version
//! 4 also `account`, `account_change`, `audit_event`, `signing_key` and `issue`) gets one link in the
//! append-only table `chain` (`seq`, `tbl`, `row_id`, `fields`, `hash`), computed here in Rust,
//! inside the transaction that inserts the row, from the row **as read back** from the database:
//!
//! ```text
//! canonical(row) = lp(table) || i64(id) || u32(number of columns)
//!                  || for each column, in the order of CHAINED: lp(column name) || tag || value
//!     tag 0 null (no value) | 1 integer: i64 | 2 real: the IEEE-754 bits as u64
//!         | 3 text: lp(UTF-8) | 4 bytes: lp(bytes)
//! lp(x) = u64(byte length of x) || x;   integers big-endian
//! row digest  = SHA-256(canonical(row))
//! hash(seq)   = SHA-256(hash(seq - 1) || u64(seq) || row digest),  hash(0) = 32 zero bytes
//! ```
//!
//! `hash` is stored as 64 lower-case hex digits; the last one is the chain head. `fields` holds,
//! for diagnosis only (it is not hashed), the first 8 bytes of SHA-256 of each column's encoding
//! (`lp(name) || tag || value`) in hex, space-separated: when a row no longer matches its link,
//! the check names the columns that differ.
//!
//! Links are appended per evaluation in one order: the `evaluation` row, then its `input_file`,
//! `report_file`, `figure` and `input_content` rows, each by `id`, then its audit event; an account, an account
//! change, a signing key or an issue is chained when it is inserted, then its audit event
//! ([`append_row`]). Migration 3 builds the chain over the rows of an existing store in that
//! order, evaluations by `id` ([`build_existing`]).

use crate::db::{first_int, Column, DbError, Exec, Kind, Row, Val};
use crate::schema;
use sha2::{Digest, Sha256};
use std::collections::HashMap;

/// A chained table: its name and its columns (the first is `id`) with their kinds.
#[derive(Debug, Clone, Copy)]
pub struct ChainedTable {
    /// Table name.
    pub name: &'static str,
    /// Columns in canonical order, with the kind each is read as.
    pub columns: &'static [(&'static str, Kind)],
}

use Kind::{IOpt, B, F, T};

/// Every table whose rows are records, in the order an evaluation's rows are chained.
pub const CHAINED: [ChainedTable; 10] = [
    ChainedTable {
        name: "evaluation",
        columns: &[
            ("id", IOpt),
            ("supersedes", IOpt),
            ("revision_kind", T),
            ("revision_by", T),
            ("revision_reason", T),
            ("stored_at", T),
            ("serial", T),
            ("model", T),
            ("lot", T),
            ("operator", T),
            ("approver", T),
            ("test_date", T),
            ("evaluated_at", T),
            ("software_version", T),
            ("plan_path", T),
            ("plan_text", T),
            ("plan_sha256", T),
            ("results_json", T),
            ("verdict", T),
            ("simulated", IOpt),
        ],
    },
    ChainedTable {
        name: "input_file",
        columns: &[("id", IOpt), ("evaluation_id", IOpt), ("path", T), ("sha256", T), ("size_bytes", IOpt)],
    },
    ChainedTable {
        name: "report_file",
        columns: &[
            ("id", IOpt),
            ("evaluation_id", IOpt),
            ("name", T),
            ("sha256", T),
            ("size_bytes", IOpt),
            ("content_zstd", B),
        ],
    },
    ChainedTable {
        name: "figure",
        columns: &[
            ("id", IOpt),
            ("evaluation_id", IOpt),
            ("axis", T),
            ("figure", T),
            ("value", F),
            ("unit", T),
            ("basis", T),
            ("expanded_uncertainty", F),
            ("coverage_factor", F),
            ("limit_min", F),
            ("limit_max", F),
            ("verdict", T),
            ("simulated", IOpt),
        ],
    },
    // Schema version 6: the raw records, one row per SHA-256, chained after the figures of the
    // evaluation that first brought them (an evaluation before version 6 has none, so its links
    // are unchanged).
    ChainedTable {
        name: "input_content",
        columns: &[("id", IOpt), ("evaluation_id", IOpt), ("sha256", T), ("size_bytes", IOpt), ("content_zstd", B)],
    },
    // Schema version 4 (issue 53): accounts, their changes, the audit trail, the lab's public
    // keys and issued reports, each row chained when the store inserts it ([`append_row`]).
    ChainedTable {
        name: "account",
        columns: &[
            ("id", IOpt),
            ("name", T),
            ("display_name", T),
            ("role", T),
            ("password_hash", T),
            ("created_at", T),
            ("created_by", T),
        ],
    },
    ChainedTable {
        name: "account_change",
        columns: &[
            ("id", IOpt),
            ("account_id", IOpt),
            ("change", T),
            ("password_hash", T),
            ("changed_at", T),
            ("changed_by", IOpt),
        ],
    },
    ChainedTable {
        name: "audit_event",
        columns: &[
            ("id", IOpt),
            ("at", T),
            ("account_id", IOpt),
            ("actor", T),
            ("action", T),
            ("evaluation_id", IOpt),
            ("detail", T),
        ],
    },
    ChainedTable {
        name: "signing_key",
        columns: &[("id", IOpt), ("public_key", T), ("fingerprint", T), ("added_at", T), ("added_by", T)],
    },
    ChainedTable {
        name: "issue",
        columns: &[
            ("id", IOpt),
            ("evaluation_id", IOpt),
            ("report_number", T),
            ("issued_at", T),
            ("signer_account_id", IOpt),
            ("signer_name", T),
            ("signer_display_name", T),
            ("signer_role", T),
            ("meaning", T),
            ("key_fingerprint", T),
            ("chain_head", T),
            ("issue_json", T),
            ("report_html_zstd", B),
            ("manifest", T),
            ("signature", T),
            ("amends", IOpt),
            ("amendment_no", IOpt),
            ("amend_reason", T),
            ("superseded_issue_json", T),
            ("superseded_manifest", T),
            ("superseded_signature", T),
        ],
    },
];

/// How many of [`CHAINED`]'s tables (the first ones) hold an evaluation's rows.
pub const EVALUATION_TABLES: usize = 5;

/// How many of the last links the quick check (every write) verifies.
pub const QUICK_LINKS: i64 = 32;

fn table(name: &str) -> Option<&'static ChainedTable> {
    CHAINED.iter().find(|t| t.name == name)
}

fn lp(out: &mut Vec<u8>, b: &[u8]) {
    out.extend_from_slice(&(b.len() as u64).to_be_bytes());
    out.extend_from_slice(b);
}

fn encode_field(out: &mut Vec<u8>, name: &str, v: &Val) {
    lp(out, name.as_bytes());
    match v {
        Val::I(i) | Val::IOpt(Some(i)) => {
            out.push(1);
            out.extend_from_slice(&i.to_be_bytes());
        }
        Val::F(Some(f)) => {
            out.push(2);
            out.extend_from_slice(&f.to_bits().to_be_bytes());
        }
        Val::T(Some(t)) => {
            out.push(3);
            lp(out, t.as_bytes());
        }
        Val::B(Some(b)) => {
            out.push(4);
            lp(out, b);
        }
        Val::IOpt(None) | Val::F(None) | Val::T(None) | Val::B(None) => out.push(0),
    }
}

/// The canonical bytes of one row of `t` (see the module's documentation); `row` holds the
/// values of `t.columns` in order, the first being the id.
pub fn canonical(t: &ChainedTable, row: &[Val]) -> Vec<u8> {
    let mut out = Vec::new();
    lp(&mut out, t.name.as_bytes());
    out.extend_from_slice(&row[0].int().to_be_bytes());
    out.extend_from_slice(&(t.columns.len() as u32).to_be_bytes());
    for ((name, _), v) in t.columns.iter().zip(row) {
        encode_field(&mut out, name, v);
    }
    out
}

/// The diagnostic per-column digests of a row (the `fields` column of a link).
pub fn field_digests(t: &ChainedTable, row: &[Val]) -> String {
    t.columns
        .iter()
        .zip(row)
        .map(|((name, _), v)| {
            let mut b = Vec::new();
            encode_field(&mut b, name, v);
            hex(&Sha256::digest(&b)[..8])
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// SHA-256 of a row's canonical bytes.
pub fn row_digest(t: &ChainedTable, row: &[Val]) -> [u8; 32] {
    Sha256::digest(canonical(t, row)).into()
}

/// The hash of link `seq` from the previous link's hash and the row's digest.
pub fn link_hash(previous: &[u8; 32], seq: i64, digest: &[u8; 32]) -> [u8; 32] {
    let mut h = Sha256::new();
    h.update(previous);
    h.update((seq as u64).to_be_bytes());
    h.update(digest);
    h.finalize().into()
}

/// Lower-case hex.
pub fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02x}")).collect()
}

fn unhex(s: &str) -> Option<[u8; 32]> {
    if s.len() != 64 || !s.is_ascii() {
        return None;
    }
    let mut out = [0u8; 32];
    for (i, o) in out.iter_mut().enumerate() {
        *o = u8::from_str_radix(&s[2 * i..2 * i + 2], 16).ok()?;
    }
    Some(out)
}

/// The values of a row of `t` read by name, in the order of `t.columns` (the canonical order).
pub fn chained_values(t: &ChainedTable, row: &Row) -> Result<Vec<Val>, DbError> {
    t.columns.iter().map(|(name, _)| row.get(name).cloned()).collect()
}

fn columns_sql(t: &ChainedTable) -> String {
    t.columns.iter().map(|c| c.0).collect::<Vec<_>>().join(", ")
}

/// The rows of one evaluation in chain order: (table, row).
#[allow(clippy::type_complexity)]
fn evaluation_rows(
    x: &mut dyn Exec,
    eval_id: i64,
    tables: usize,
) -> Result<Vec<(&'static ChainedTable, i64, Vec<Val>)>, DbError> {
    let mut out = Vec::new();
    for t in &CHAINED[..tables] {
        let filter = if t.name == "evaluation" { "id" } else { "evaluation_id" };
        // ok: table and column names from the constant CHAINED spec, the id a bound parameter
        let sql = format!("SELECT {} FROM {} WHERE {filter} = $1 ORDER BY id", columns_sql(t), t.name); // ok: constant spec, no value
        for row in x.rows(&sql, &[Val::I(eval_id)], t.columns)? {
            out.push((t, row.int("id")?, chained_values(t, &row)?));
        }
    }
    Ok(out)
}

/// One link as stored.
#[derive(Debug, Clone)]
struct Link {
    seq: i64,
    tbl: String,
    row_id: i64,
    fields: String,
    hash: String,
}

const LINK_COLUMNS: &[(&str, Kind)] =
    &[("seq", Kind::I), ("tbl", Kind::T), ("row_id", Kind::I), ("fields", Kind::T), ("hash", Kind::T)];

fn link_of(r: &Row) -> Result<Link, DbError> {
    Ok(Link {
        seq: r.int("seq")?,
        tbl: r.string("tbl")?,
        row_id: r.int("row_id")?,
        fields: r.string("fields")?,
        hash: r.string("hash")?,
    })
}

fn head(x: &mut dyn Exec) -> Result<(i64, [u8; 32]), DbError> {
    let rows =
        x.rows("SELECT seq, hash FROM chain ORDER BY seq DESC LIMIT 1", &[], &[("seq", Kind::I), ("hash", Kind::T)])?;
    match rows.first() {
        None => Ok((0, [0u8; 32])),
        Some(r) => {
            let seq = r.int("seq")?;
            let h = unhex(&r.string("hash")?).ok_or_else(|| format!("chain link {seq} holds no valid hash"))?;
            Ok((seq, h))
        }
    }
}

/// Appends the links of evaluation `eval_id` and its rows (inside the transaction that inserted
/// them); the new head.
pub fn append_evaluation(x: &mut dyn Exec, eval_id: i64) -> Result<String, DbError> {
    append_evaluation_tables(x, eval_id, EVALUATION_TABLES)
}

/// The evaluation tables a store had when migration 3 built its chain (`input_content` came
/// with version 6).
const TABLES_AT_VERSION_3: usize = 4;

fn append_evaluation_tables(x: &mut dyn Exec, eval_id: i64, tables: usize) -> Result<String, DbError> {
    let (mut seq, mut prev) = head(x)?;
    let rows = evaluation_rows(x, eval_id, tables)?;
    let (mut seqs, mut tbls, mut ids, mut fields, mut hashes) = (vec![], vec![], vec![], vec![], vec![]);
    for (t, id, row) in &rows {
        seq += 1;
        prev = link_hash(&prev, seq, &row_digest(t, row));
        seqs.push(seq);
        tbls.push(Some(t.name.to_string()));
        ids.push(*id);
        fields.push(Some(field_digests(t, row)));
        hashes.push(Some(hex(&prev)));
    }
    x.insert_columns(
        "INSERT INTO chain (seq, tbl, row_id, fields, hash) VALUES ($1, $2, $3, $4, $5)",
        "INSERT INTO chain (seq, tbl, row_id, fields, hash) SELECT * FROM unnest($1::bigint[], $2::text[], $3::bigint[], \
         $4::text[], $5::text[])",
        &[Column::I(seqs), Column::T(tbls), Column::I(ids), Column::T(fields), Column::T(hashes)],
    )?;
    Ok(hex(&prev))
}

/// Appends the link of one row of `table` (inside the transaction that inserted it: an account,
/// an account change, an audit event, a signing key, an issue); the new head.
pub fn append_row(x: &mut dyn Exec, table_name: &str, id: i64) -> Result<String, DbError> {
    let t = table(table_name).ok_or_else(|| format!("'{table_name}' is not a chained table"))?;
    let row = read_row(x, t, id)?.ok_or_else(|| format!("{table_name} row {id} is not there to be chained"))?;
    let row = chained_values(t, &row)?;
    let (seq, prev) = head(x)?;
    let seq = seq + 1;
    let hash = link_hash(&prev, seq, &row_digest(t, &row));
    x.exec(
        "INSERT INTO chain (seq, tbl, row_id, fields, hash) VALUES ($1, $2, $3, $4, $5)",
        &[
            Val::I(seq),
            Val::T(Some(t.name.to_string())),
            Val::I(id),
            Val::T(Some(field_digests(t, &row))),
            Val::T(Some(hex(&hash))),
        ],
    )?;
    Ok(hex(&hash))
}

/// The chain head (hex) as it is now, none for an empty chain.
pub fn current_head(x: &mut dyn Exec) -> Result<Option<String>, DbError> {
    let (n, h) = head(x)?;
    Ok((n > 0).then(|| hex(&h)))
}

/// Builds the chain over every row of a store that had none (migration 3): evaluations by id,
/// each followed by its files and figures (see the module's documentation).
pub fn build_existing(x: &mut dyn Exec) -> Result<(), DbError> {
    let ids = x.rows("SELECT id FROM evaluation ORDER BY id", &[], &[("id", Kind::I)])?;
    for r in ids {
        append_evaluation_tables(x, r.int("id")?, TABLES_AT_VERSION_3)?;
    }
    Ok(())
}

/// One thing found wrong by a check.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Problem {
    /// The table concerned (`chain` for a link, `sqlite_master`/`pg_trigger` for a trigger).
    pub table: String,
    /// The row's id, when one is concerned.
    pub row_id: Option<i64>,
    /// The chain link concerned, when one is.
    pub link: Option<i64>,
    /// What differs.
    pub what: String,
}

impl std::fmt::Display for Problem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.table)?;
        if let Some(id) = self.row_id {
            write!(f, " row {id}")?;
        }
        if let Some(l) = self.link {
            write!(f, " (chain link {l})")?;
        }
        write!(f, ": {}", self.what)
    }
}

/// What a check covered and what it found.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct CheckReport {
    /// True for the quick check (triggers, row counts, the last [`QUICK_LINKS`] links), false
    /// for the full one.
    pub quick: bool,
    /// Triggers found present and unaltered (names), out of [`CheckReport::triggers_expected`].
    pub triggers_ok: Vec<String>,
    /// Triggers the schema has.
    pub triggers_expected: usize,
    /// Links in the chain.
    pub links: i64,
    /// Links re-verified against their rows.
    pub links_checked: i64,
    /// Rows per chained table (table, rows); full check only.
    pub rows: Vec<(String, i64)>,
    /// Report files and raw records whose stored bytes were re-hashed and found equal to their
    /// SHA-256 and size.
    pub files_checked: i64,
    /// Report files stored as hashes only (no bytes to check: schema version 1, over 64 MiB).
    pub files_hash_only: i64,
    /// The chain head (hex), none for an empty store.
    pub head: Option<String>,
    /// Everything found wrong, the first broken link first.
    pub problems: Vec<Problem>,
}

impl CheckReport {
    /// True when nothing was found wrong.
    pub fn is_whole(&self) -> bool {
        self.problems.is_empty()
    }
}

/// The protecting triggers of a back end: (table, trigger name, its SQL as written in the
/// migrations), from the migration scripts themselves.
pub fn expected_triggers(postgres: bool) -> Vec<(String, String, String)> {
    let mut out: Vec<(String, String, String)> = Vec::new();
    for m in schema::migrations(postgres) {
        for line in m.sql.lines().filter(|l| l.starts_with("CREATE TRIGGER ")) {
            let words: Vec<&str> = line.split_whitespace().collect();
            let name = words[2].to_string();
            let on = words.iter().position(|w| *w == "ON").map(|i| words[i + 1].to_string()).unwrap_or_default();
            out.retain(|(_, n, _)| *n != name); // a later migration re-creates it
            out.push((on, name, line.trim_end_matches(';').trim().to_string()));
        }
    }
    out
}

/// SQLite only: the database file's own structure, every page read (issue 53: a file with 4 KiB
/// of flipped bytes past its header accepted new evaluations). The quick check runs SQLite's
/// `PRAGMA quick_check` (b-tree pages, their order and free lists: linear in the file's size,
/// 0.21 s for a 275 MB file, warm); the full one `PRAGMA integrity_check` (indexes
/// against their tables too). PostgreSQL's pages are its server's to check (data checksums).
fn check_pages(x: &mut dyn Exec, postgres: bool, full: bool, report: &mut CheckReport) -> Result<(), DbError> {
    if postgres {
        return Ok(());
    }
    let (sql, column) = if full {
        ("PRAGMA integrity_check(20)", "integrity_check")
    } else {
        ("PRAGMA quick_check(20)", "quick_check")
    };
    let rows = match x.rows(sql, &[], &[(column, Kind::T)]) {
        Ok(r) => r,
        Err(e) => {
            report.problems.push(damaged(&e.to_string()));
            return Ok(());
        }
    };
    let lines: Vec<String> = rows.iter().map(|r| r.string(column)).collect::<Result<_, DbError>>()?;
    if lines.len() != 1 || lines[0] != "ok" {
        report.problems.push(damaged(&lines.join("; ").replace('\n', "; ")));
    }
    Ok(())
}

fn damaged(what: &str) -> Problem {
    Problem {
        table: "sqlite file".into(),
        row_id: None,
        link: None,
        what: format!("the database file is damaged ({what}): restore it from a backup"),
    }
}

fn check_triggers(x: &mut dyn Exec, postgres: bool, report: &mut CheckReport) -> Result<(), DbError> {
    let expected = expected_triggers(postgres);
    report.triggers_expected = expected.len();
    if postgres {
        let mut found: HashMap<(String, String), (String, String)> = HashMap::new();
        for t in CHAINED.iter().map(|t| t.name).chain(["chain"]) {
            let rows = x.rows(
                "SELECT t.tgname::text AS name, t.tgenabled::text AS enabled, p.prosrc AS source FROM pg_trigger t \
                 JOIN pg_proc p ON p.oid = t.tgfoid WHERE t.tgrelid = to_regclass($1::text) AND NOT t.tgisinternal",
                &[Val::T(Some(t.to_string()))],
                &[("name", Kind::T), ("enabled", Kind::T), ("source", Kind::T)],
            )?;
            for r in rows {
                found.insert((t.to_string(), r.string("name")?), (r.string("enabled")?, r.string("source")?));
            }
        }
        for (table, name, _) in expected {
            let what = match found.get(&(table.clone(), name.clone())) {
                None => Some("missing (dropped)".to_string()),
                Some((enabled, _)) if enabled == "D" => Some("disabled (ALTER TABLE ... DISABLE TRIGGER)".into()),
                Some((enabled, _)) if enabled == "R" => Some("set to fire on replicas only".into()),
                Some((_, src)) if !src.contains("RAISE EXCEPTION") => {
                    Some("its function no longer refuses (gyrolab_records_are_kept replaced)".into())
                }
                Some(_) => None,
            };
            match what {
                None => report.triggers_ok.push(name),
                Some(w) => report.problems.push(Problem {
                    table: "pg_trigger".into(),
                    row_id: None,
                    link: None,
                    what: format!("trigger {name} on {table}: {w}"),
                }),
            }
        }
    } else {
        let rows = x.rows(
            "SELECT name, sql FROM sqlite_master WHERE type = 'trigger'",
            &[],
            &[("name", Kind::T), ("sql", Kind::T)],
        )?;
        let found: HashMap<String, String> =
            rows.iter().map(|r| Ok((r.string("name")?, r.string("sql")?))).collect::<Result<_, DbError>>()?;
        for (table, name, sql) in expected {
            match found.get(&name) {
                Some(s) if s.trim().trim_end_matches(';') == sql => report.triggers_ok.push(name),
                Some(_) => report.problems.push(Problem {
                    table: "sqlite_master".into(),
                    row_id: None,
                    link: None,
                    what: format!("trigger {name} on {table}: altered (its SQL differs from the schema's)"),
                }),
                None => report.problems.push(Problem {
                    table: "sqlite_master".into(),
                    row_id: None,
                    link: None,
                    what: format!("trigger {name} on {table}: missing (dropped)"),
                }),
            }
        }
    }
    Ok(())
}

fn read_row(x: &mut dyn Exec, t: &ChainedTable, id: i64) -> Result<Option<Row>, DbError> {
    // ok: table and column names from the constant CHAINED spec, the id a bound parameter
    let sql = format!("SELECT {} FROM {} WHERE id = $1", columns_sql(t), t.name); // ok: constant spec, no value
    Ok(x.rows(&sql, &[Val::I(id)], t.columns)?.into_iter().next())
}

/// Verifies link `l` against the stored hash before it (`prev`) and the row's digest (`None`:
/// the row is gone); the problem found, if any. `prev_link`: the link before, to name it when
/// the row still matches what was chained (then that link was rewritten).
fn verify_link(
    x: &mut dyn Exec,
    l: &Link,
    prev: &[u8; 32],
    digest: Option<[u8; 32]>,
    prev_link: Option<&Link>,
) -> Result<Option<Problem>, DbError> {
    let Some(t) = table(&l.tbl) else {
        return Ok(Some(Problem {
            table: "chain".into(),
            row_id: Some(l.row_id),
            link: Some(l.seq),
            what: format!("names table '{}', which is not a record table", l.tbl),
        }));
    };
    let Some(digest) = digest else {
        return Ok(Some(Problem {
            table: t.name.into(),
            row_id: Some(l.row_id),
            link: Some(l.seq),
            what: "the row is gone (deleted, replaced under another id, or the table emptied)".into(),
        }));
    };
    if unhex(&l.hash).is_some_and(|h| h == link_hash(prev, l.seq, &digest)) {
        return Ok(None);
    }
    let row = match read_row(x, t, l.row_id) {
        Ok(Some(r)) => chained_values(t, &r)?,
        Ok(None) => Vec::new(),
        Err(e) => return Ok(Some(unreadable(t, l.row_id, Some(l.seq), &e))),
    };
    let now = field_digests(t, &row);
    let differ: Vec<&str> = t
        .columns
        .iter()
        .zip(now.split(' ').zip(l.fields.split(' ')))
        .filter(|(_, (a, b))| a != b)
        .map(|((name, _), _)| *name)
        .collect();
    if differ.is_empty() {
        if let Some(p) = prev_link {
            return Ok(Some(Problem {
                table: p.tbl.clone(),
                row_id: Some(p.row_id),
                link: Some(p.seq),
                what: format!(
                    "its link was rewritten: link {} ({} row {}) no longer follows from it (a row changed and its hash \
                     recomputed)",
                    l.seq, l.tbl, l.row_id
                ),
            }));
        }
        return Ok(Some(Problem {
            table: t.name.into(),
            row_id: Some(l.row_id),
            link: Some(l.seq),
            what: "its link's hash was rewritten".into(),
        }));
    }
    Ok(Some(Problem {
        table: t.name.into(),
        row_id: Some(l.row_id),
        link: Some(l.seq),
        what: format!("changed since it was stored (column(s) {} differ from the chained row)", differ.join(", ")),
    }))
}

/// A row that cannot be read as its columns' types (SQLite keeps any value in any column: a text
/// written into a REAL column behind the store's back).
fn unreadable(t: &ChainedTable, row_id: i64, link: Option<i64>, e: &DbError) -> Problem {
    Problem {
        table: t.name.into(),
        row_id: Some(row_id),
        link,
        what: format!("cannot be read as its columns' types ({e}): a value of another type was written into it"),
    }
}

/// The digest of one row for the checks: `None` when it is gone, a digest of nothing (which
/// matches no link) with a problem when it cannot be read.
fn digest_of(
    x: &mut dyn Exec,
    t: &ChainedTable,
    id: i64,
    problems: &mut Vec<Problem>,
) -> Result<Option<[u8; 32]>, DbError> {
    match read_row(x, t, id) {
        Ok(r) => Ok(r.map(|r| chained_values(t, &r)).transpose()?.map(|r| row_digest(t, &r))),
        Err(e) => {
            problems.push(unreadable(t, id, None, &e));
            Ok(Some([0u8; 32]))
        }
    }
}

/// The count of a `SELECT COUNT(*) AS n ...`.
fn count(x: &mut dyn Exec, sql: &str, params: &[Val]) -> Result<i64, DbError> {
    first_int(&x.rows(sql, params, &[("n", Kind::I)])?, "n", 0)
}

/// Rows past the end of the chain: per table, a row whose id is above the last chained one, or a
/// row without an id (index look-ups only, whatever the size of the store).
fn check_tails(x: &mut dyn Exec, report: &mut CheckReport) -> Result<(), DbError> {
    for t in &CHAINED {
        let max = |x: &mut dyn Exec, sql: &str, p: &[Val]| -> Result<Option<i64>, DbError> {
            Ok(x.rows(sql, p, &[("last", Kind::IOpt)])?.first().map(|r| r.int_opt("last")).transpose()?.flatten())
        };
        // ok: the table name from the constant CHAINED spec; no value in the text
        let last_row = max(x, &format!("SELECT MAX(id) AS last FROM {}", t.name), &[])?; // ok: constant spec, no value
        let last_link =
            max(x, "SELECT MAX(row_id) AS last FROM chain WHERE tbl = $1", &[Val::T(Some(t.name.to_string()))])?;
        if let Some(id) = last_row.filter(|id| last_link.is_none_or(|l| id > &l)) {
            report.problems.push(Problem {
                table: t.name.into(),
                row_id: Some(id),
                link: None,
                what: "not in the chain (past its last row of this table): inserted outside the store".into(),
            });
        }
        // ok: the table name from the constant CHAINED spec; no value in the text
        let no_id =
            x.rows(&format!("SELECT 1 AS one FROM {} WHERE id IS NULL LIMIT 1", t.name), &[], &[("one", Kind::I)])?; // ok: constant spec, no value
        if !no_id.is_empty() {
            report.problems.push(Problem {
                table: t.name.into(),
                row_id: None,
                link: None,
                what: "row(s) without an id: inserted outside the store".into(),
            });
        }
    }
    Ok(())
}

/// The quick check run before every write, in index look-ups and [`QUICK_LINKS`] row reads
/// whatever the size of the store: triggers present, no row past the chain's end or without an
/// id, and the last [`QUICK_LINKS`] links, without gaps, against their rows. A row changed,
/// deleted or inserted deeper in the store is found by [`full_check`] only.
/// `pages`: SQLite's page check first (`check_pages`; once per opening for writing, not again
/// inside each write).
pub fn quick_check(x: &mut dyn Exec, postgres: bool, pages: bool) -> Result<CheckReport, DbError> {
    let mut report = CheckReport { quick: true, ..CheckReport::default() };
    if pages {
        check_pages(x, postgres, false, &mut report)?;
    }
    if !report.problems.is_empty() {
        return Ok(report); // a damaged file: its rows cannot be trusted to be read
    }
    check_triggers(x, postgres, &mut report)?;
    check_tails(x, &mut report)?;
    let (n, h) = head(x)?;
    report.links = n;
    report.head = (n > 0).then(|| hex(&h));
    let from = (n - QUICK_LINKS).max(0);
    let links: Vec<Link> = x
        .rows(
            "SELECT seq, tbl, row_id, fields, hash FROM chain WHERE seq >= $1 ORDER BY seq",
            &[Val::I(from)],
            LINK_COLUMNS,
        )?
        .iter()
        .map(link_of)
        .collect::<Result<_, DbError>>()?;
    let mut prev: Option<Link> = None;
    for (i, l) in links.into_iter().enumerate() {
        let expected = from.max(1) + i as i64;
        if l.seq != expected {
            report.problems.push(Problem {
                table: "chain".into(),
                row_id: None,
                link: Some(expected),
                what: format!("link {expected} is missing (the next stored link is {})", l.seq),
            });
        }
        if l.seq == from && from > 0 {
            prev = Some(l);
            continue;
        }
        let prev_hash = match &prev {
            Some(p) => unhex(&p.hash).unwrap_or_default(),
            None => [0u8; 32],
        };
        let mut unread = Vec::new();
        let digest = match table(&l.tbl) {
            Some(t) => digest_of(x, t, l.row_id, &mut unread)?,
            None => Some([0u8; 32]),
        };
        report.links_checked += 1;
        if let Some(p) = verify_link(x, &l, &prev_hash, digest, prev.as_ref())? {
            report.problems.push(p);
        }
        report.problems.extend(unread);
        prev = Some(l);
    }
    Ok(report)
}

/// The full check: triggers, every link against its row (rows changed, deleted or inserted
/// outside the store), and every stored report file's bytes against its SHA-256 and size.
pub fn full_check(x: &mut dyn Exec, postgres: bool) -> Result<CheckReport, DbError> {
    let mut report = CheckReport::default();
    check_pages(x, postgres, true, &mut report)?;
    if !report.problems.is_empty() {
        return Ok(report); // a damaged file: its rows cannot be trusted to be read
    }
    check_triggers(x, postgres, &mut report)?;
    // Every row's digest by (table, id), read in pages; report files re-hashed on the way.
    let mut digests: HashMap<(&'static str, i64), [u8; 32]> = HashMap::new();
    let mut file_problems = Vec::new();
    for t in &CHAINED {
        // ok: the table name from the constant CHAINED spec; no value in the text
        let total = count(x, &format!("SELECT COUNT(*) AS n FROM {}", t.name), &[])?; // ok: constant spec, no value
        report.rows.push((t.name.to_string(), total));
        // Pages of rows (report files hold up to 64 MiB each: a few at a time).
        let page_rows = match t.name {
            "report_file" => 8,
            "input_content" => 1, // a raw record each (up to MAX_KEPT_INPUT_BYTES before compression)
            _ => 256,
        };
        let (cols, name) = (columns_sql(t), t.name);
        let sql = format!("SELECT {cols} FROM {name} WHERE id > $1 ORDER BY id LIMIT {page_rows}"); // ok: constants
        let mut last = i64::MIN;
        let mut seen = 0;
        let ids_sql = format!("SELECT id FROM {name} WHERE id > $1 ORDER BY id LIMIT {page_rows}"); // ok: constants
        loop {
            // (id, the row or why it cannot be read as its columns' types)
            let page: Vec<(i64, Result<Row, DbError>)> = match x.rows(&sql, &[Val::I(last)], t.columns) {
                Ok(p) => p.into_iter().map(|r| Ok((r.int("id")?, Ok(r)))).collect::<Result<_, DbError>>()?,
                Err(_) => {
                    // A row of this page cannot be read (SQLite keeps any value in any column):
                    // the page row by row.
                    let ids = x.rows(&ids_sql, &[Val::I(last)], &[("id", Kind::I)])?;
                    let mut rows = Vec::new();
                    for id in ids.iter().map(|r| r.int("id")).collect::<Result<Vec<_>, DbError>>()? {
                        match read_row(x, t, id) {
                            Ok(Some(r)) => rows.push((id, Ok(r))),
                            Ok(None) => {}
                            Err(e) => rows.push((id, Err(e))),
                        }
                    }
                    rows
                }
            };
            if page.is_empty() {
                break;
            }
            for (id, row) in &page {
                last = last.max(*id);
                seen += 1;
                match row {
                    Ok(row) => {
                        digests.insert((t.name, *id), row_digest(t, &chained_values(t, row)?));
                        if t.name == "report_file" || t.name == "input_content" {
                            check_file(t.name, row, &mut report, &mut file_problems)?;
                        }
                    }
                    Err(e) => {
                        report.problems.push(unreadable(t, *id, None, e));
                        digests.insert((t.name, *id), [0u8; 32]);
                    }
                }
            }
        }
        if seen != total {
            report.problems.push(Problem {
                table: t.name.into(),
                row_id: None,
                link: None,
                what: format!("{} row(s) without an id or sharing one: inserted outside the store", total - seen),
            });
        }
    }
    let links: Vec<Link> = x
        .rows("SELECT seq, tbl, row_id, fields, hash FROM chain ORDER BY seq", &[], LINK_COLUMNS)?
        .iter()
        .map(link_of)
        .collect::<Result<_, DbError>>()?;
    let mut prev: Option<&Link> = None;
    let mut chained: std::collections::HashSet<(String, i64)> = Default::default();
    for (i, l) in links.iter().enumerate() {
        let expected_seq = i as i64 + 1;
        if l.seq != expected_seq {
            report.problems.push(Problem {
                table: "chain".into(),
                row_id: None,
                link: Some(expected_seq),
                what: format!("link {expected_seq} is missing (the next stored link is {})", l.seq),
            });
        }
        let prev_hash = prev.and_then(|p| unhex(&p.hash)).unwrap_or([0u8; 32]);
        let digest = match table(&l.tbl) {
            Some(t) => digests.get(&(t.name, l.row_id)).copied(),
            None => Some([0u8; 32]),
        };
        chained.insert((l.tbl.clone(), l.row_id));
        report.links_checked += 1;
        if let Some(p) = verify_link(x, l, &prev_hash, digest, prev)? {
            report.problems.push(p);
        }
        prev = Some(l);
    }
    report.links = links.len() as i64;
    report.head = links.last().map(|l| l.hash.clone());
    let mut unchained: Vec<(&str, i64)> =
        digests.keys().filter(|(t, id)| !chained.contains(&(t.to_string(), *id))).map(|(t, id)| (*t, *id)).collect();
    unchained.sort_by_key(|(t, id)| (CHAINED.iter().position(|c| c.name == *t), *id));
    for (t, id) in unchained {
        report.problems.push(Problem {
            table: t.into(),
            row_id: Some(id),
            link: None,
            what: "not in the chain: inserted outside the store".into(),
        });
    }
    report.problems.extend(file_problems);
    Ok(report)
}

/// Re-hashes one stored file (a `report_file` or `input_content` row as read for the chain).
fn check_file(table: &str, row: &Row, report: &mut CheckReport, problems: &mut Vec<Problem>) -> Result<(), DbError> {
    let Some(packed) = row.bytes("content_zstd")? else {
        report.files_hash_only += 1;
        return Ok(());
    };
    let (id, sha256) = (row.int("id")?, row.string("sha256")?);
    let name = match table {
        "report_file" => row.string("name")?,
        _ => format!("raw record {}", &sha256[..sha256.len().min(16)]),
    };
    let size = row.int("size_bytes")?;
    let problem = |what: String| Problem { table: table.into(), row_id: Some(id), link: None, what };
    match zstd::stream::decode_all(packed) {
        Err(e) => problems.push(problem(format!("{name}: its stored bytes cannot be decompressed ({e})"))),
        Ok(bytes) => {
            let sha = hex(&Sha256::digest(&bytes));
            if sha != sha256 || bytes.len() as i64 != size {
                problems.push(problem(format!(
                    "{name}: its stored bytes ({} bytes, SHA-256 {sha}) differ from its recorded SHA-256 {sha256} ({size} bytes)",
                    bytes.len(),
                )));
            } else {
                report.files_checked += 1;
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn encoding_is_length_prefixed_and_typed() {
        let t = &CHAINED[1];
        let a = canonical(
            t,
            &[
                Val::IOpt(Some(1)),
                Val::IOpt(Some(2)),
                Val::T(Some("ab".into())),
                Val::T(Some("c".into())),
                Val::IOpt(Some(3)),
            ],
        );
        let b = canonical(
            t,
            &[
                Val::IOpt(Some(1)),
                Val::IOpt(Some(2)),
                Val::T(Some("a".into())),
                Val::T(Some("bc".into())),
                Val::IOpt(Some(3)),
            ],
        );
        assert_ne!(a, b, "moving a byte between fields changes the encoding");
        let n = canonical(
            t,
            &[Val::IOpt(Some(1)), Val::IOpt(None), Val::T(Some("a".into())), Val::T(None), Val::IOpt(Some(0))],
        );
        let z = canonical(
            t,
            &[
                Val::IOpt(Some(1)),
                Val::IOpt(Some(0)),
                Val::T(Some("a".into())),
                Val::T(Some(String::new())),
                Val::IOpt(Some(0)),
            ],
        );
        assert_ne!(n, z, "null differs from 0 and from the empty text");
        assert_eq!(&a[..8], &10u64.to_be_bytes(), "the table name comes first, length-prefixed");
        let d = row_digest(
            t,
            &[
                Val::IOpt(Some(1)),
                Val::IOpt(Some(2)),
                Val::T(Some("ab".into())),
                Val::T(Some("c".into())),
                Val::IOpt(Some(3)),
            ],
        );
        assert_ne!(link_hash(&[0; 32], 1, &d), link_hash(&[0; 32], 2, &d), "the position is hashed");
    }

    #[test]
    fn triggers_parsed_from_the_migrations() {
        let s = expected_triggers(false);
        assert!(s.iter().any(|(t, n, _)| t == "figure" && n == "figure_kept_r"));
        assert_eq!(s.iter().filter(|(_, n, _)| n == "figure_kept").count(), 1);
        let p = expected_triggers(true);
        assert!(p.iter().any(|(t, n, _)| t == "figure" && n == "figure_not_truncated"));
        assert_eq!(p.len(), 22);
    }
}
