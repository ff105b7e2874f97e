//! Shared by the store tests: the back ends to run every test on (SQLite always; PostgreSQL at
//! GYROLAB_TEST_PG_URL, started by scripts/pg-test-server.sh; a missing URL fails under CI=true
//! and prints SKIPPED: otherwise) and synthetic records.

#![allow(dead_code)]

use gyrolab_store::record::{EvaluationRecord, FigureRecord, FileRecord};
use std::sync::atomic::{AtomicUsize, Ordering};

/// A back end for one test: its location and, for SQLite, the folder that holds the file.
pub struct Backend {
    /// Location (a file path or a URL).
    pub location: String,
    /// Short name for messages.
    pub name: &'static str,
    _dir: Option<tempfile::TempDir>,
}

static COUNTER: AtomicUsize = AtomicUsize::new(0);

/// The PostgreSQL URL of the test server, or `None` (with SKIPPED: printed) outside CI.
pub fn pg_url(test: &str) -> Option<String> {
    match std::env::var("GYROLAB_TEST_PG_URL") {
        Ok(u) if !u.is_empty() => Some(u),
        _ => {
            if std::env::var("CI").is_ok_and(|v| v == "true") {
                panic!("GYROLAB_TEST_PG_URL is not set under CI=true: the PostgreSQL store tests must run (scripts/pg-test-server.sh)");
            }
            eprintln!(
                "SKIPPED: {test} on PostgreSQL: GYROLAB_TEST_PG_URL is not set (run under scripts/pg-test-server.sh)"
            );
            None
        }
    }
}

/// A fresh, empty store location on each back end: an SQLite file in a new folder, and a new
/// schema of the test server (its URL with `search_path` set to it).
pub fn backends(test: &str) -> Vec<Backend> {
    let dir = tempfile::tempdir().expect("temp dir");
    let mut out = vec![Backend {
        location: dir.path().join("gyrolab.db").display().to_string(),
        name: "sqlite",
        _dir: Some(dir),
    }];
    if let Some(url) = pg_url(test) {
        let schema = format!(
            "t_{}_{}_{}",
            test.replace(|c: char| !c.is_ascii_alphanumeric(), "_"),
            std::process::id(),
            COUNTER.fetch_add(1, Ordering::SeqCst)
        );
        let mut c = postgres::Client::connect(&url, postgres::NoTls).expect("connect to the test server");
        c.batch_execute(&format!("CREATE SCHEMA {schema}")).expect("create schema");
        let sep = if url.contains('?') { '&' } else { '?' };
        out.push(Backend {
            location: format!("{url}{sep}options=-c%20search_path%3D{schema}"),
            name: "postgres",
            _dir: None,
        });
    }
    out
}

/// Makes the store at `b` look written by a later gyrolab: a row of schema `version` in its
/// `gyrolab_schema` table (test set-up only).
pub fn mark_newer_schema(b: &Backend, version: i64) {
    let row = format!(
        "INSERT INTO gyrolab_schema (version, applied_at, software_version) VALUES ({version}, 'later', '9.9.9')"
    );
    if b.name == "sqlite" {
        let c = rusqlite::Connection::open(&b.location).expect("open the SQLite store");
        c.execute(&row, []).expect("insert the schema row");
    } else {
        let mut c = postgres::Client::connect(&b.location, postgres::NoTls).expect("connect to the test server");
        c.batch_execute(&row).expect("insert the schema row");
    }
}

/// Makes an empty store at `b` as a gyrolab of schema version 1 made it: its migration 1 only
/// (test set-up for the migration test).
pub fn make_version_1_store(b: &Backend) {
    let sqlite = b.name == "sqlite";
    let migration = if sqlite {
        gyrolab_store::schema::SQLITE_MIGRATIONS[0].sql
    } else {
        gyrolab_store::schema::POSTGRES_MIGRATIONS[0].sql
    };
    let script = format!(
        "{};\n{migration}\nINSERT INTO gyrolab_schema VALUES (1, 'earlier', '0.0.1');",
        gyrolab_store::schema::VERSION_TABLE
    );
    if sqlite {
        let c = rusqlite::Connection::open(&b.location).expect("create the SQLite store");
        c.execute_batch(&script).expect("schema version 1");
    } else {
        let mut c = postgres::Client::connect(&b.location, postgres::NoTls).expect("connect to the test server");
        c.batch_execute(&script).expect("schema version 1");
    }
}

/// A synthetic record of `serial` in `lot` with figures `(axis, key, value)`, limits 9 .. 11.
pub fn record(serial: &str, lot: Option<&str>, figures: &[(&str, &str, f64)]) -> EvaluationRecord {
    EvaluationRecord {
        serial: serial.into(),
        model: "ADXRS-test".into(),
        lot: lot.map(str::to_string),
        operator: Some("A. Operator".into()),
        approver: None,
        test_date: Some("2026-11-27".into()),
        evaluated_at: "2026-11-27T10:00:00Z".into(),
        software_version: "0.1.0".into(),
        plan_path: "/lab/plan.toml".into(),
        plan_text: "[device]\nmodel = \"ADXRS-test\"\n".into(),
        plan_sha256: "00".repeat(32),
        results_json: "{}".into(),
        verdict: Some("PASS".into()),
        simulated: true,
        inputs: vec![FileRecord {
            path: "/lab/x.csv".into(),
            sha256: "ab".repeat(32),
            size_bytes: 1234,
            content: None,
            packed: None,
        }],
        report_files: vec![FileRecord {
            path: "results.json".into(),
            sha256: gyrolab_store::record::hash_bytes(b"{}"),
            size_bytes: 2,
            content: Some(b"{}".to_vec()),
            packed: None,
        }],
        figures: figures
            .iter()
            .map(|(axis, key, v)| FigureRecord {
                axis: axis.to_string(),
                figure: key.to_string(),
                value: Some(*v),
                unit: "deg/h".into(),
                basis: "value".into(),
                expanded_uncertainty: Some(0.01),
                coverage_factor: Some(2.0),
                limit_min: Some(9.0),
                limit_max: Some(11.0),
                verdict: Some(if (9.0..=11.0).contains(v) { "PASS" } else { "FAIL" }.into()),
                simulated: true,
            })
            .collect(),
    }
}
