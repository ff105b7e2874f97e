//! Least privilege on PostgreSQL (issue 53: "a least-privilege PostgreSQL role (SELECT/INSERT)
//! is refused because the store wants CREATE"; "PostgreSQL refuses TRUNCATE, and the
//! application runs as a role with INSERT and SELECT only (the owner role applies
//! migrations)"): the owner makes the store and grants the test server's `gyrolab_app` role;
//! gyrolab run as that role opens, stores, queries and checks, and the role can neither change,
//! empty nor disable anything. On the real server only (SQLite has no roles: refused clearly).

use crate::common::{backends, record};
use gyrolab_store::{query, Store, StoreError};

/// The app role's URL with the same search_path as the owner's test schema.
fn app_location(owner_location: &str) -> Option<String> {
    let app = std::env::var("GYROLAB_TEST_PG_APP_URL").ok().filter(|u| !u.is_empty())?;
    let options = &owner_location[owner_location.find("?options=")?..];
    Some(format!("{app}{options}"))
}

#[test]
fn a_select_insert_role_stores_and_reads_but_cannot_change_empty_or_disable() {
    for b in backends("least_privilege") {
        if b.name == "sqlite" {
            let mut s = Store::open(&b.location, true).unwrap();
            let e = s.grant_least_privilege("anyone").unwrap_err();
            assert!(matches!(e, StoreError::Refused { .. }) && e.to_string().contains("file permissions"), "{e}");
            continue;
        }
        let app = app_location(&b.location)
            .unwrap_or_else(|| panic!("GYROLAB_TEST_PG_APP_URL is not set: scripts/pg-test-server.sh makes it"));
        // The owner makes the store (schema 1..6) and stores one evaluation.
        let mut owner = Store::open(&b.location, true).unwrap();
        owner.add(&record("SN1", Some("L"), &[("x", "bias_dph", 10.0)])).unwrap();
        // Before the grant the role cannot even read it.
        assert!(Store::open(&app, false).is_err());
        // Errors name the role, never the password; a superuser and an unknown role are refused.
        let e = owner.grant_least_privilege("no_such_role").unwrap_err();
        assert!(e.to_string().contains("no PostgreSQL role"), "{e}");
        let e = owner.grant_least_privilege("postgres").unwrap_err();
        assert!(e.to_string().contains("superuser"), "{e}");
        let tables = owner.grant_least_privilege("gyrolab_app").unwrap();
        assert!(tables.iter().any(|t| t == "figure") && tables.iter().any(|t| t == "chain"), "{tables:?}");
        // gyrolab as the app role: opens without DDL, stores, queries, checks.
        let mut s = Store::open_for_writing(&app, false).unwrap();
        let id = s.add(&record("SN2", Some("L"), &[("x", "bias_dph", 10.5)])).unwrap();
        assert_eq!(id, 2);
        assert_eq!(query::history(&mut s, "SN2").unwrap().len(), 1);
        let r = s.check().unwrap();
        assert!(r.is_whole(), "{:?}", r.problems);
        // What the role cannot do, whatever it tries.
        let mut raw = postgres::Client::connect(&app, postgres::NoTls).unwrap();
        for sql in [
            "UPDATE figure SET verdict = 'FAIL'",
            "DELETE FROM figure",
            "TRUNCATE figure",
            "ALTER TABLE figure DISABLE TRIGGER figure_kept",
            "DROP TRIGGER figure_kept ON figure",
            "CREATE TABLE forged (x int)",
            "UPDATE gyrolab_schema SET sha256 = 'x'",
        ] {
            let e = raw.batch_execute(sql).expect_err(sql);
            let m = e.as_db_error().map_or(e.to_string(), |d| d.message().to_string());
            assert!(m.contains("permission denied") || m.contains("must be owner"), "{sql}: {m}");
        }
        // The app role cannot widen its own rights.
        let e = s.grant_least_privilege("gyrolab_app").unwrap_err();
        assert!(e.to_string().contains("owner"), "{e}");
        assert!(owner.check().unwrap().is_whole());
    }
}
