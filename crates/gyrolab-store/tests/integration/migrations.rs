//! Migrations as files with checksums (issue 52): every applied migration's SHA-256 is recorded
//! in `gyrolab_schema` and checked on every open; a store made by a build before checksums (a
//! version table without the columns) is adopted; on SQLite and on the PostgreSQL test server.

use crate::common::{backends, make_version_1_store, Backend};
use gyrolab_store::schema::{self, Migration, RecordedMigration, SCHEMA_VERSION};
use gyrolab_store::{Store, StoreError};
use sha2::{Digest, Sha256};

fn migrations(b: &Backend) -> &'static [Migration] {
    schema::migrations(b.name == "postgres")
}

/// SHA-256 (hex) of a migration's file as it is on disk.
fn file_sha256(m: &Migration) -> String {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(m.file);
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    Sha256::digest(&bytes).iter().map(|b| format!("{b:02x}")).collect()
}

/// Runs `sql` (several statements) on the store's database directly.
fn raw(b: &Backend, sql: &str) {
    if b.name == "sqlite" {
        rusqlite::Connection::open(&b.location).unwrap().execute_batch(sql).unwrap();
    } else {
        postgres::Client::connect(&b.location, postgres::NoTls).unwrap().batch_execute(sql).unwrap();
    }
}

/// The recorded checksums, expected: one per migration, equal to its file's SHA-256.
fn assert_recorded(b: &Backend, s: &mut Store) {
    let recorded = s.recorded_migrations().unwrap();
    let expected: Vec<RecordedMigration> = migrations(b)
        .iter()
        .map(|m| RecordedMigration { version: m.version, name: Some(m.name.to_string()), sha256: Some(file_sha256(m)) })
        .collect();
    assert_eq!(recorded, expected, "{}", b.name);
    assert_eq!(s.schema_version().unwrap(), SCHEMA_VERSION, "{}", b.name);
}

#[test]
fn the_version_is_the_number_of_migration_files() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("migrations");
    for (back_end, list) in [("sqlite", schema::SQLITE_MIGRATIONS), ("postgres", schema::POSTGRES_MIGRATIONS)] {
        let mut files: Vec<String> = std::fs::read_dir(dir.join(back_end))
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".sql"))
            .collect();
        files.sort();
        assert_eq!(files.len() as i64, SCHEMA_VERSION, "{back_end}: {files:?}");
        let embedded: Vec<String> = list.iter().map(|m| m.file.rsplit('/').next().unwrap().to_string()).collect();
        assert_eq!(files, embedded, "{back_end}: every file embedded, in order");
        for (i, m) in list.iter().enumerate() {
            assert_eq!(m.version, i as i64 + 1);
            assert_eq!(m.file, format!("migrations/{back_end}/{:04}_{}.sql", m.version, m.name));
            assert_eq!(m.sha256(), file_sha256(m), "{}: the embedded SQL is the file's text", m.file);
        }
    }
}

#[test]
fn a_fresh_store_records_one_checksum_per_migration() {
    for b in backends("mig_fresh") {
        let mut s = Store::open(&b.location, true).unwrap();
        assert_recorded(&b, &mut s);
        drop(s);
        // Opened again: checked, nothing changed.
        let mut s = Store::open(&b.location, false).unwrap();
        assert_recorded(&b, &mut s);
    }
}

#[test]
fn a_store_whose_recorded_checksum_was_altered_is_refused() {
    for b in backends("mig_altered") {
        drop(Store::open(&b.location, true).unwrap());
        let forged = "ab".repeat(32);
        raw(&b, &format!("UPDATE gyrolab_schema SET sha256 = '{forged}' WHERE version = 2"));
        let m = &migrations(&b)[1];
        for attempt in [Store::open(&b.location, false), Store::open_for_writing(&b.location, false)] {
            let e = attempt.err().unwrap_or_else(|| panic!("{}: opened", b.name));
            let text = e.to_string();
            match &e {
                StoreError::MigrationChecksum { version, file, recorded, embedded, .. } => {
                    assert_eq!(*version, 2, "{}", b.name);
                    assert_eq!(file, &format!("migrations/{}/0002_report_contents.sql", b.name));
                    assert_eq!(recorded, &forged);
                    assert_eq!(embedded, &file_sha256(m));
                }
                other => panic!("{}: {other:?}", b.name),
            }
            assert!(e.is_bad_input());
            for part in ["version 2", m.file, &forged, &file_sha256(m)] {
                assert!(text.contains(part), "{}: {text} lacks {part}", b.name);
            }
            // The store is shown masked: no user information of the URL in the message.
            if let Some(userinfo) = b.location.split("://").nth(1).and_then(|r| r.split_once('@')).map(|(u, _)| u) {
                assert!(!text.contains(userinfo), "{}: {text}", b.name);
                assert!(text.contains(&gyrolab_store::mask_location(&b.location)), "{text}");
            }
        }
        // Nothing was written: the forged checksum is still there, and refused again.
        assert!(matches!(Store::open(&b.location, false), Err(StoreError::MigrationChecksum { version: 2, .. })));
    }
}

/// A store as the builds before checksums made it at schema version `upto`: the version table
/// without the `name` and `sha256` columns, the embedded migrations up to `upto`.
fn make_old_layout_store(b: &Backend, upto: usize) {
    let mut script = format!("{};\n", schema::VERSION_TABLE);
    for m in &migrations(b)[..upto] {
        script.push_str(m.sql);
        script.push('\n');
        script
            .push_str(&format!("INSERT INTO gyrolab_schema VALUES ({}, 'earlier', '0.0.{}');\n", m.version, m.version));
    }
    raw(b, &script);
}

#[test]
fn a_store_of_the_old_layout_is_adopted_and_its_checksums_recorded() {
    for b in backends("mig_adopt") {
        make_old_layout_store(&b, SCHEMA_VERSION as usize);
        let mut s = Store::open(&b.location, false).unwrap();
        assert_recorded(&b, &mut s);
        let r = s.check().unwrap();
        assert!(r.is_whole(), "{}: {:?}", b.name, r.problems);
        s.add(&crate::common::record("ADOPTED", Some("L"), &[("x", "bias_dph", 10.0)])).unwrap();
        drop(s);
        let mut s = Store::open_for_writing(&b.location, false).unwrap();
        assert_recorded(&b, &mut s);
    }
}

#[test]
fn an_old_store_behind_is_adopted_and_migrated_with_checksums() {
    for b in backends("mig_adopt_v1") {
        make_version_1_store(&b);
        let mut s = Store::open(&b.location, false).unwrap();
        assert_recorded(&b, &mut s);
    }
}

#[test]
fn a_newer_store_is_refused_before_its_checksums_are_looked_at() {
    for b in backends("mig_newer") {
        drop(Store::open(&b.location, true).unwrap());
        crate::common::mark_newer_schema(&b, SCHEMA_VERSION + 1);
        assert!(matches!(Store::open(&b.location, false), Err(StoreError::NewerSchema { .. })), "{}", b.name);
    }
}
