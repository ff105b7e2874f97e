//! Tamper evidence (issue 53): the forgeries reproduced on the store before schema version 3 are
//! refused by the schema or found by `Store::check` (and the quick check refuses to write), on
//! SQLite and on the PostgreSQL test server, with the table and row named.

use crate::common::{backends, record, Backend};
use gyrolab_store::chain::{self, ChainedTable, CHAINED};
use gyrolab_store::db::{Kind, Val};
use gyrolab_store::{query, Store, StoreError};

/// A raw connection to a store's database: what someone with SQL access (and the store's own
/// user on PostgreSQL, who owns the tables) can do behind the store's back.
enum Raw {
    S(rusqlite::Connection),
    P(Box<postgres::Client>),
}

impl Raw {
    fn open(b: &Backend) -> Raw {
        if b.name == "sqlite" {
            Raw::S(rusqlite::Connection::open(&b.location).unwrap())
        } else {
            Raw::P(Box::new(postgres::Client::connect(&b.location, postgres::NoTls).unwrap()))
        }
    }

    fn exec(&mut self, sql: &str) -> Result<(), String> {
        match self {
            Raw::S(c) => c.execute_batch(sql).map_err(|e| e.to_string()),
            Raw::P(c) => {
                c.batch_execute(sql).map_err(|e| e.as_db_error().map_or(e.to_string(), |d| d.message().into()))
            }
        }
    }

    fn int(&mut self, sql: &str) -> i64 {
        match self {
            Raw::S(c) => c.query_row(sql, [], |r| r.get(0)).unwrap(),
            Raw::P(c) => c.query_one(sql, &[]).unwrap().get(0),
        }
    }

    fn text(&mut self, sql: &str) -> String {
        match self {
            Raw::S(c) => c.query_row(sql, [], |r| r.get(0)).unwrap(),
            Raw::P(c) => c.query_one(sql, &[]).unwrap().get(0),
        }
    }

    /// One row of a chained table as the chain reads it.
    fn row(&mut self, t: &ChainedTable, id: i64) -> Vec<Val> {
        let cols: Vec<&str> = t.columns.iter().map(|c| c.0).collect();
        let sql = format!("SELECT {} FROM {} WHERE id = {id}", cols.join(", "), t.name);
        match self {
            Raw::S(c) => c
                .query_row(&sql, [], |r| {
                    Ok(t.columns
                        .iter()
                        .enumerate()
                        .map(|(i, (_, k))| match k {
                            Kind::F => Val::F(r.get(i).unwrap()),
                            Kind::T => Val::T(r.get(i).unwrap()),
                            Kind::B => Val::B(r.get(i).unwrap()),
                            _ => Val::IOpt(r.get(i).unwrap()),
                        })
                        .collect())
                })
                .unwrap(),
            Raw::P(c) => {
                let r = c.query_one(&sql, &[]).unwrap();
                t.columns
                    .iter()
                    .enumerate()
                    .map(|(i, (_, k))| match k {
                        Kind::F => Val::F(r.get(i)),
                        Kind::T => Val::T(r.get(i)),
                        Kind::B => Val::B(r.get(i)),
                        _ => Val::IOpt(r.get(i)),
                    })
                    .collect()
            }
        }
    }

    /// Turns the protecting triggers of `tables` off (SQLite: dropped; PostgreSQL: disabled by
    /// the owner), runs `sql`, and puts them back as they were, so that the trigger check passes.
    fn behind_the_triggers(&mut self, tables: &[&str], sql: &str) {
        let postgres = matches!(self, Raw::P(_));
        let triggers: Vec<(String, String, String)> =
            chain::expected_triggers(postgres).into_iter().filter(|(t, _, _)| tables.contains(&t.as_str())).collect();
        let mut off = String::new();
        let mut on = String::new();
        for (t, n, create) in &triggers {
            if postgres {
                off.push_str(&format!("ALTER TABLE {t} DISABLE TRIGGER {n};\n"));
                on.push_str(&format!("ALTER TABLE {t} ENABLE TRIGGER {n};\n"));
            } else {
                off.push_str(&format!("DROP TRIGGER {n};\n"));
                on.push_str(&format!("{create};\n"));
            }
        }
        self.exec(&format!("{off}{sql}\n{on}")).unwrap();
    }

    /// Rewrites chain link `seq` as the store would have written it for the row it names as
    /// that row is now (hash from the previous link, fields).
    fn recompute_link(&mut self, seq: i64) {
        let tbl = self.text(&format!("SELECT tbl FROM chain WHERE seq = {seq}"));
        let row_id = self.int(&format!("SELECT row_id FROM chain WHERE seq = {seq}"));
        let t = CHAINED.iter().find(|t| t.name == tbl).unwrap();
        let row = self.row(t, row_id);
        let prev = if seq == 1 {
            [0u8; 32]
        } else {
            let h = self.text(&format!("SELECT hash FROM chain WHERE seq = {}", seq - 1));
            let mut out = [0u8; 32];
            for (i, o) in out.iter_mut().enumerate() {
                *o = u8::from_str_radix(&h[2 * i..2 * i + 2], 16).unwrap();
            }
            out
        };
        let hash = chain::hex(&chain::link_hash(&prev, seq, &chain::row_digest(t, &row)));
        let fields = chain::field_digests(t, &row);
        self.behind_the_triggers(
            &["chain"],
            &format!("UPDATE chain SET hash = '{hash}', fields = '{fields}' WHERE seq = {seq};"),
        );
    }
}

/// A store with two evaluations (figures x bias 10.0 PASS and x scale 10.2 PASS each).
fn two_evaluations(b: &Backend) -> Store {
    let mut s = Store::open(&b.location, true).unwrap();
    s.add(&record("SN1", Some("L"), &[("x", "bias_dph", 10.0), ("x", "scale", 10.2)])).unwrap();
    s.add(&record("SN2", Some("L"), &[("x", "bias_dph", 10.1), ("x", "scale", 10.3)])).unwrap();
    let r = s.check().unwrap();
    assert!(r.is_whole(), "{}: {:?}", b.name, r.problems);
    s
}

fn first_figure_id(raw: &mut Raw) -> i64 {
    raw.int("SELECT MIN(id) FROM figure WHERE evaluation_id = 1")
}

/// The store refuses to write (quick check) naming the same table.
fn writing_is_refused(b: &Backend, table: &str) {
    let e = Store::open(&b.location, false).unwrap().add(&record("SN9", None, &[("x", "bias_dph", 10.0)])).unwrap_err();
    assert!(matches!(e, StoreError::Tampered { .. }), "{}: {e}", b.name);
    assert!(e.is_bad_input(), "exit 2");
    let m = e.to_string();
    assert!(m.contains(table) && m.contains("store check"), "{}: {m}", b.name);
    let e = Store::open_for_writing(&b.location, false).err().unwrap();
    assert!(matches!(e, StoreError::Tampered { .. }), "{}: {e}", b.name);
}

#[test]
fn replace_update_delete_and_truncate_are_refused() {
    for b in backends("tamper_refused") {
        let mut s = two_evaluations(&b);
        let mut raw = Raw::open(&b);
        let fid = first_figure_id(&mut raw);
        let refused = |sql: &str, raw: &mut Raw| {
            let e = raw.exec(sql).expect_err(sql);
            assert!(e.contains("gyrolab records are never"), "{}: {sql}: {e}", b.name);
        };
        refused(&format!("UPDATE figure SET verdict = 'FAIL' WHERE id = {fid}"), &mut raw);
        refused(&format!("DELETE FROM figure WHERE id = {fid}"), &mut raw);
        refused("DELETE FROM chain", &mut raw);
        refused("UPDATE chain SET hash = 'x'", &mut raw);
        if b.name == "sqlite" {
            // The forgery of issue 53: REPLACE by rowid turning PASS to FAIL.
            let replace = format!(
                "INSERT OR REPLACE INTO figure (rowid, id, evaluation_id, axis, figure, value, unit, basis, verdict, simulated) \
                 VALUES ({fid}, {fid}, 1, 'x', 'bias_dph', 12.0, 'deg/h', 'value', 'FAIL', 1)"
            );
            refused(&replace, &mut raw);
            refused("INSERT OR REPLACE INTO evaluation SELECT * FROM evaluation WHERE id = 1", &mut raw);
            refused("REPLACE INTO report_file SELECT * FROM report_file", &mut raw);
            refused("REPLACE INTO input_file SELECT * FROM input_file", &mut raw);
            refused("INSERT OR REPLACE INTO chain SELECT * FROM chain WHERE seq = 2", &mut raw);
            refused(&format!("UPDATE OR REPLACE figure SET verdict = 'FAIL' WHERE id = {fid}"), &mut raw);
            // With recursive triggers on (as the store's connections set them), the implicit
            // delete of a REPLACE fires the DELETE-refusing trigger even without the INSERT one.
            raw.exec("PRAGMA recursive_triggers = ON; DROP TRIGGER figure_kept_r;").unwrap();
            refused(&replace, &mut raw);
            let (_, _, create) =
                chain::expected_triggers(false).into_iter().find(|(_, n, _)| n == "figure_kept_r").unwrap();
            raw.exec(&create).unwrap();
        } else {
            refused("TRUNCATE figure", &mut raw);
            refused("TRUNCATE evaluation CASCADE", &mut raw);
            refused("TRUNCATE chain", &mut raw);
            refused("TRUNCATE input_file, report_file", &mut raw);
            refused(
                &format!(
                    "INSERT INTO figure (id, evaluation_id, axis, figure, unit, basis, verdict, simulated) OVERRIDING SYSTEM \
                     VALUE VALUES ({fid}, 1, 'x', 'bias_dph', 'deg/h', 'value', 'FAIL', 1) ON CONFLICT (id) DO UPDATE SET \
                     verdict = 'FAIL'"
                ),
                &mut raw,
            );
        }
        let r = s.check().unwrap();
        assert!(r.is_whole(), "{}: {:?}", b.name, r.problems);
        let h = query::history(&mut s, "SN1").unwrap();
        assert!(!h.is_empty() && h.iter().all(|r| r.figure.verdict.as_deref() == Some("PASS")), "{}", b.name);
        s.add(&record("SN3", None, &[("x", "bias_dph", 10.0)])).unwrap();
    }
}

#[test]
fn a_figure_changed_behind_the_triggers_is_found_by_table_row_and_column() {
    for b in backends("tamper_changed") {
        let mut s = two_evaluations(&b);
        let mut raw = Raw::open(&b);
        let fid = first_figure_id(&mut raw);
        raw.behind_the_triggers(&["figure"], &format!("UPDATE figure SET verdict = 'FAIL' WHERE id = {fid};"));
        let r = s.check().unwrap();
        let p = r.problems.first().unwrap_or_else(|| panic!("{}: not found", b.name));
        assert_eq!((p.table.as_str(), p.row_id), ("figure", Some(fid)), "{}: {p}", b.name);
        assert!(p.what.contains("verdict") && !p.what.contains("value"), "{}: {p}", b.name);
        assert_eq!(r.problems.len(), 1, "{}: {:?}", b.name, r.problems);
        assert_eq!(r.triggers_ok.len(), r.triggers_expected, "{}: the triggers were put back", b.name);
        writing_is_refused(&b, "figure");
    }
}

#[test]
fn a_row_changed_with_its_link_recomputed_breaks_the_next_link() {
    for b in backends("tamper_recomputed") {
        let mut s = two_evaluations(&b);
        let head_before = s.check().unwrap().head.unwrap();
        let mut raw = Raw::open(&b);
        let fid = first_figure_id(&mut raw);
        raw.behind_the_triggers(&["figure"], &format!("UPDATE figure SET verdict = 'FAIL' WHERE id = {fid};"));
        let seq = raw.int(&format!("SELECT seq FROM chain WHERE tbl = 'figure' AND row_id = {fid}"));
        raw.recompute_link(seq);
        let r = s.check().unwrap();
        let p = r.problems.first().unwrap_or_else(|| panic!("{}: not found", b.name));
        assert_eq!((p.table.as_str(), p.row_id, p.link), ("figure", Some(fid), Some(seq)), "{}: {p}", b.name);
        assert!(p.what.contains("rewritten"), "{}: {p}", b.name);
        writing_is_refused(&b, "figure");
        // Rewriting every later link too gives a whole chain with another head: only the head
        // kept elsewhere (and, to come, its signature) finds that (docs/STORE.md).
        let last = raw.int("SELECT MAX(seq) FROM chain");
        for l in seq + 1..=last {
            raw.recompute_link(l);
        }
        let r = s.check().unwrap();
        assert!(r.is_whole(), "{}: {:?}", b.name, r.problems);
        assert_ne!(r.head.unwrap(), head_before, "{}: the head changed", b.name);
    }
}

#[test]
fn an_extra_figure_row_is_found() {
    for b in backends("tamper_extra") {
        let mut s = two_evaluations(&b);
        let mut raw = Raw::open(&b);
        let id_sql = if b.name == "sqlite" { "(SELECT MAX(id) + 1 FROM figure), " } else { "" };
        let id_col = if b.name == "sqlite" { "id, " } else { "" };
        raw.exec(&format!(
            "INSERT INTO figure ({id_col}evaluation_id, axis, figure, value, unit, basis, verdict, simulated) VALUES \
             ({id_sql}1, 'x', 'forged', 1.0, 'deg/h', 'value', 'PASS', 0)"
        ))
        .unwrap();
        let extra = raw.int("SELECT MAX(id) FROM figure");
        let r = s.check().unwrap();
        assert!(
            r.problems
                .iter()
                .any(|p| p.table == "figure" && p.row_id == Some(extra) && p.what.contains("not in the chain")),
            "{}: {:?}",
            b.name,
            r.problems
        );
        writing_is_refused(&b, "figure");
        // A forged approval (an evaluation row) likewise.
        raw.exec(
            "INSERT INTO evaluation (supersedes, revision_kind, revision_by, revision_reason, stored_at, serial, model, \
             evaluated_at, software_version, plan_path, plan_text, plan_sha256, results_json, simulated) SELECT 1, \
             'approval', 'Boss', 'ok', stored_at, serial, model, evaluated_at, software_version, plan_path, plan_text, \
             plan_sha256, results_json, simulated FROM evaluation WHERE id = 1",
        )
        .unwrap();
        let r = s.check().unwrap();
        assert!(
            r.problems
                .iter()
                .any(|p| p.table == "evaluation" && p.row_id == Some(3) && p.what.contains("not in the chain")),
            "{}: {:?}",
            b.name,
            r.problems
        );
    }
}

#[test]
fn dropped_or_disabled_triggers_are_found() {
    for b in backends("tamper_triggers") {
        let mut s = two_evaluations(&b);
        let mut raw = Raw::open(&b);
        let (sql, name) = if b.name == "sqlite" {
            ("DROP TRIGGER figure_kept_r", "figure_kept_r")
        } else {
            ("DROP TRIGGER figure_not_truncated ON figure", "figure_not_truncated")
        };
        raw.exec(sql).unwrap();
        let r = s.check().unwrap();
        let p = r.problems.first().unwrap();
        assert!(p.what.contains(name) && p.what.contains("missing"), "{}: {p}", b.name);
        writing_is_refused(&b, name);
        if b.name == "postgres" {
            raw.exec("ALTER TABLE figure DISABLE TRIGGER figure_kept").unwrap();
            let r = s.check().unwrap();
            assert!(r.problems.iter().any(|p| p.what.contains("figure_kept") && p.what.contains("disabled")), "{r:?}");
            raw.exec(
                "CREATE OR REPLACE FUNCTION gyrolab_records_are_kept() RETURNS trigger LANGUAGE plpgsql AS $$ BEGIN \
                 RETURN NULL; END $$",
            )
            .unwrap();
            let r = s.check().unwrap();
            assert!(r.problems.iter().any(|p| p.what.contains("no longer refuses")), "{r:?}");
        } else {
            raw.exec(
                "DROP TRIGGER figure_kept; CREATE TRIGGER figure_kept BEFORE UPDATE ON figure BEGIN SELECT 1; END;",
            )
            .unwrap();
            let r = s.check().unwrap();
            assert!(r.problems.iter().any(|p| p.what.contains("figure_kept on figure: altered")), "{r:?}");
        }
    }
}

#[test]
fn a_report_file_replaced_is_found() {
    for b in backends("tamper_file") {
        let mut s = two_evaluations(&b);
        let mut raw = Raw::open(&b);
        let id = raw.int("SELECT MIN(id) FROM report_file");
        let forged = zstd::bulk::compress(b"{\"forged\":1}", 3).unwrap();
        let hex: String = forged.iter().map(|x| format!("{x:02x}")).collect();
        let blob = if b.name == "sqlite" { format!("X'{hex}'") } else { format!("'\\x{hex}'::bytea") };
        // The bytes replaced, the recorded SHA-256 kept: the file check and the chain find it.
        raw.behind_the_triggers(
            &["report_file"],
            &format!("UPDATE report_file SET content_zstd = {blob} WHERE id = {id};"),
        );
        let r = s.check().unwrap();
        assert_eq!(r.problems[0].table, "report_file", "{}: {:?}", b.name, r.problems);
        assert_eq!(r.problems[0].row_id, Some(id));
        assert!(r.problems[0].what.contains("content_zstd"), "{:?}", r.problems);
        assert!(
            r.problems.iter().any(|p| p.table == "report_file" && p.what.contains("differ from its recorded SHA-256")),
            "{}: {:?}",
            b.name,
            r.problems
        );
        // The SHA-256 and size replaced as well: the chain names the row and both columns.
        let sha = gyrolab_store::record::hash_bytes(b"{\"forged\":1}");
        raw.behind_the_triggers(
            &["report_file"],
            &format!("UPDATE report_file SET sha256 = '{sha}', size_bytes = 12 WHERE id = {id};"),
        );
        let r = s.check().unwrap();
        assert_eq!(r.problems.len(), 1, "{}: {:?}", b.name, r.problems);
        assert!(
            r.problems[0].what.contains("sha256") && r.problems[0].what.contains("content_zstd"),
            "{:?}",
            r.problems
        );
    }
}

#[test]
fn a_raw_record_replaced_is_found_and_refused_when_read() {
    for b in backends("tamper_raw_record") {
        let mut s = Store::open(&b.location, true).unwrap();
        let bytes = b"time_s,rate_dps\n0,0.1\n0.01,0.2\n".to_vec();
        let mut rec = record("SN1", Some("L"), &[("x", "bias_dph", 10.0)]);
        rec.inputs[0].sha256 = gyrolab_store::record::hash_bytes(&bytes);
        rec.inputs[0].size_bytes = bytes.len() as u64;
        rec.inputs[0].packed = Some(zstd::bulk::compress(&bytes, 3).unwrap());
        s.add(&rec).unwrap();
        // The same bytes again (another evaluation): kept once, content-addressed.
        let mut again = rec.clone();
        again.serial = "SN2".into();
        s.add(&again).unwrap();
        let mut raw = Raw::open(&b);
        assert_eq!(raw.int("SELECT COUNT(*) FROM input_content"), 1, "{}", b.name);
        let r = s.check().unwrap();
        assert!(r.is_whole(), "{}: {:?}", b.name, r.problems);
        assert_eq!(r.files_checked, 3, "{}: two report files and the raw record re-hashed", b.name);
        let mut out = Vec::new();
        assert!(query::write_input_content(&mut s, &rec.inputs[0].sha256, &mut out).unwrap());
        assert_eq!(out, bytes);
        // Refused by the schema...
        let e = raw.exec("UPDATE input_content SET size_bytes = 1").unwrap_err();
        assert!(e.contains("gyrolab records are never"), "{}: {e}", b.name);
        if b.name == "sqlite" {
            let e = raw.exec("REPLACE INTO input_content SELECT * FROM input_content").unwrap_err();
            assert!(e.contains("gyrolab records are never"), "{e}");
        } else {
            let e = raw.exec("TRUNCATE input_content").unwrap_err();
            assert!(e.contains("gyrolab records are never"), "{e}");
        }
        // ...and, behind the triggers, found by the check and refused when read.
        let forged = zstd::bulk::compress(b"time_s,rate_dps\n0,9.9\n0.01,9.9\n", 3).unwrap();
        let hex: String = forged.iter().map(|x| format!("{x:02x}")).collect();
        let blob = if b.name == "sqlite" { format!("X'{hex}'") } else { format!("'\\x{hex}'::bytea") };
        raw.behind_the_triggers(&["input_content"], &format!("UPDATE input_content SET content_zstd = {blob};"));
        let r = s.check().unwrap();
        assert_eq!(r.problems[0].table, "input_content", "{}: {:?}", b.name, r.problems);
        assert!(r.problems[0].what.contains("content_zstd"), "{:?}", r.problems);
        assert!(r.problems.iter().any(|p| p.what.contains("raw record")), "{}: {:?}", b.name, r.problems);
        let e = query::write_input_content(&mut s, &rec.inputs[0].sha256, &mut Vec::new()).unwrap_err();
        assert!(e.to_string().contains("does not match"), "{}: {e}", b.name);
    }
}

#[test]
fn rows_deleted_behind_the_triggers_are_found() {
    for b in backends("tamper_deleted") {
        let mut s = two_evaluations(&b);
        let mut raw = Raw::open(&b);
        let fid = first_figure_id(&mut raw);
        raw.behind_the_triggers(&["figure"], &format!("DELETE FROM figure WHERE id = {fid};"));
        let r = s.check().unwrap();
        let p = &r.problems.iter().find(|p| p.row_id.is_some()).unwrap();
        assert_eq!((p.table.as_str(), p.row_id), ("figure", Some(fid)), "{}: {p}", b.name);
        assert!(p.what.contains("gone"), "{p}");
        writing_is_refused(&b, "figure");
    }
}

#[test]
fn a_version_2_store_gets_its_chain_on_migration() {
    for b in backends("migrate_v2_chain") {
        // A store as schema version 2 made it, with one evaluation stored by that version.
        let sqlite = b.name == "sqlite";
        let m =
            if sqlite { gyrolab_store::schema::SQLITE_MIGRATIONS } else { gyrolab_store::schema::POSTGRES_MIGRATIONS };
        let mut raw = Raw::open(&b);
        raw.exec(&format!(
            "{};\n{}\n{}\nINSERT INTO gyrolab_schema VALUES (1, 'earlier', '0.0.1'); INSERT INTO gyrolab_schema VALUES (2, \
             'earlier', '0.0.2');",
            gyrolab_store::schema::VERSION_TABLE,
            m[0].sql,
            m[1].sql
        ))
        .unwrap();
        raw.exec(
            "INSERT INTO evaluation (revision_kind, stored_at, serial, model, evaluated_at, software_version, plan_path, \
             plan_text, plan_sha256, results_json, verdict, simulated) VALUES ('original', 't', 'OLD', 'M', 't', '0.0.2', \
             'p', 'x', 'h', '{}', 'PASS', 0);
             INSERT INTO figure (evaluation_id, axis, figure, value, unit, basis, verdict, simulated) VALUES (1, 'x', 'b', \
             1.5, 'u', 'value', 'PASS', 0);
             INSERT INTO figure (evaluation_id, axis, figure, value, unit, basis, verdict, simulated) VALUES (1, 'x', 'a', \
             NULL, 'u', 'value', NULL, 0);
             INSERT INTO input_file (evaluation_id, path, sha256, size_bytes) VALUES (1, '/x.csv', 'ab', 3);
             INSERT INTO report_file (evaluation_id, name, sha256, size_bytes) VALUES (1, 'results.json', 'cd', 2);",
        )
        .unwrap();
        let mut s = Store::open(&b.location, false).unwrap();
        assert_eq!(s.schema_version().unwrap(), gyrolab_store::schema::SCHEMA_VERSION);
        let r = s.check().unwrap();
        assert!(r.is_whole(), "{}: {:?}", b.name, r.problems);
        assert_eq!((r.links, r.files_hash_only), (5, 1), "{}", b.name);
        // The order: the evaluation, its input file, report file, figures by id.
        let order: Vec<String> = (1..=5).map(|i| raw.text(&format!("SELECT tbl FROM chain WHERE seq = {i}"))).collect();
        assert_eq!(order, ["evaluation", "input_file", "report_file", "figure", "figure"]);
        s.add(&record("NEW", None, &[("x", "bias_dph", 10.0)])).unwrap();
        let r = s.check().unwrap();
        // Four rows of the evaluation and its audit event (schema version 4).
        assert!(r.is_whole() && r.links == 10, "{}: {} {:?}", b.name, r.links, r.problems);
        assert_eq!(r.triggers_ok.len(), r.triggers_expected);
    }
}

#[test]
fn a_value_of_another_type_written_on_sqlite_is_named_not_a_failure() {
    // SQLite keeps any value in any column: a text in the REAL column `value`.
    let b = backends("tamper_types").into_iter().next().unwrap();
    let mut s = two_evaluations(&b);
    let mut raw = Raw::open(&b);
    let fid = first_figure_id(&mut raw);
    raw.behind_the_triggers(&["figure"], &format!("UPDATE figure SET value = 'ten' WHERE id = {fid};"));
    let r = s.check().unwrap();
    let p = r.problems.iter().find(|p| p.what.contains("another type")).unwrap_or_else(|| panic!("{:?}", r.problems));
    assert_eq!((p.table.as_str(), p.row_id), ("figure", Some(fid)));
    assert!(r.problems.iter().all(|p| p.row_id == Some(fid)), "{:?}", r.problems);
    assert!(matches!(Store::open_for_writing(&b.location, false), Err(StoreError::Tampered { .. })));
}

#[test]
fn a_version_2_sqlite_store_with_a_dropped_trigger_still_migrates() {
    let b = backends("migrate_v2_dropped").into_iter().next().unwrap();
    let m = gyrolab_store::schema::SQLITE_MIGRATIONS;
    let mut raw = Raw::open(&b);
    raw.exec(&format!(
        "{};\n{}\n{}\nINSERT INTO gyrolab_schema VALUES (1, 'earlier', '0.0.1'); INSERT INTO gyrolab_schema VALUES (2, \
         'earlier', '0.0.2'); DROP TRIGGER figure_kept;",
        gyrolab_store::schema::VERSION_TABLE,
        m[0].sql,
        m[1].sql
    ))
    .unwrap();
    let mut s = Store::open(&b.location, false).unwrap();
    let r = s.check().unwrap();
    assert!(r.is_whole() && r.triggers_ok.len() == r.triggers_expected, "{:?}", r.problems);
}

#[test]
fn an_account_changed_behind_the_triggers_is_found_and_replace_refused() {
    for b in backends("tamper_accounts") {
        let mut s = Store::open(&b.location, true).unwrap();
        let none = gyrolab_store::Actor::unauthenticated();
        s.add_account(&none, "admin", "A. Admin", gyrolab_store::Role::Admin, "password-admin").unwrap();
        let admin = s.authenticate("admin", "password-admin").unwrap();
        s.add_account(&admin, "op", "O. P.", gyrolab_store::Role::Operator, "password-op").unwrap();
        let mut raw = Raw::open(&b);
        // Plain statements are refused: UPDATE, DELETE, and REPLACE (SQLite) or TRUNCATE (PostgreSQL).
        assert!(raw.exec("UPDATE account SET role = 'admin' WHERE name = 'op'").is_err());
        assert!(raw.exec("DELETE FROM audit_event").is_err());
        if b.name == "sqlite" {
            assert!(raw
                .exec(
                    "INSERT OR REPLACE INTO account (id, name, display_name, role, password_hash, created_by) VALUES \
                     (2, 'op', 'O. P.', 'admin', 'x', 'admin')"
                )
                .is_err());
        } else {
            assert!(raw.exec("TRUNCATE account_change, account CASCADE").is_err());
        }
        assert!(s.check().unwrap().is_whole(), "{}", b.name);
        // Behind the triggers: the operator made an admin; found, naming the row and column.
        raw.behind_the_triggers(&["account"], "UPDATE account SET role = 'admin' WHERE name = 'op';");
        let r = s.check().unwrap();
        let p =
            r.problems.iter().find(|p| p.table == "account").unwrap_or_else(|| panic!("{}: {:?}", b.name, r.problems));
        assert!(p.what.contains("role"), "{}: {p}", b.name);
        writing_is_refused(&b, "account");
    }
}
