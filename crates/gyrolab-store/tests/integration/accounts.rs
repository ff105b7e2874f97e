//! Accounts and attribution (issue 53, schema version 4) through the library, on SQLite and on
//! the PostgreSQL test server: the first account an admin, later ones by an admin only; one
//! refusal for a wrong password, an unknown name and a disabled account; a new password; roles;
//! every write in the audit trail with its account (or none in a store without accounts), all of
//! it chained and `check` whole.

use crate::common::{backends, record};
use gyrolab_store::{Actor, Changes, Revision, RevisionKind, Role, Store, StoreError};

#[test]
fn accounts_roles_and_the_audit_trail() {
    for b in backends("accounts") {
        let mut s = Store::open(&b.location, true).unwrap();
        // Without accounts: writes as before, recorded as such.
        let first = s.add(&record("SN1", None, &[("x", "bias_dph", 10.0)])).unwrap();
        let ev = s.audit_events(Some(first)).unwrap();
        assert_eq!(
            (ev.len(), ev[0].actor.as_str(), ev[0].action.as_str()),
            (1, "local (no accounts in this store)", "store")
        );
        assert!(ev[0].at.ends_with('Z') && ev[0].at.len() == 24, "{}: the database's clock: {}", b.name, ev[0].at);

        let none = Actor::unauthenticated();
        let e = s.add_account(&none, "op", "O. P.", Role::Operator, "password-1").unwrap_err();
        assert!(e.to_string().contains("must be an admin"), "{}: {e}", b.name);
        s.add_account(&none, "admin", "A. Admin", Role::Admin, "password-admin").unwrap();
        let e = s.add_account(&none, "op", "O. P.", Role::Operator, "password-1").unwrap_err();
        assert!(matches!(e, StoreError::Refused { .. }), "{}: only an admin adds accounts: {e}", b.name);
        let admin = s.authenticate("admin", "password-admin").unwrap();
        s.add_account(&admin, "op", "O. Perator", Role::Operator, "password-op").unwrap();
        s.add_account(&admin, "appr", "A. Prover", Role::Approver, "password-appr").unwrap();
        s.add_account(&admin, "view", "V. Iewer", Role::Viewer, "password-view").unwrap();
        assert!(s.add_account(&admin, "op", "Again", Role::Operator, "password-x").is_err(), "names are unique");
        assert!(s.add_account(&admin, "bad name", "B", Role::Operator, "password-x").is_err());
        assert!(s.add_account(&admin, "short", "S", Role::Operator, "short").is_err());

        // One refusal, whatever was wrong.
        let wrong = s.authenticate("op", "password-OP").unwrap_err();
        let unknown = s.authenticate("nobody", "password-op").unwrap_err();
        assert!(matches!(wrong, StoreError::Auth { .. }) && wrong.is_bad_input());
        assert_eq!(wrong.to_string(), unknown.to_string(), "{}", b.name);
        assert!(!wrong.to_string().contains("password-"), "no password in the message");

        // Writes need an account now; a viewer may not store.
        let e = s.add(&record("SN2", None, &[("x", "bias_dph", 10.0)])).unwrap_err();
        assert!(e.to_string().contains("this store has accounts"), "{}: {e}", b.name);
        let viewer = s.authenticate("view", "password-view").unwrap();
        assert!(s.add_as(&record("SN2", None, &[("x", "bias_dph", 10.0)]), &viewer).is_err());
        let op = s.authenticate("op", "password-op").unwrap();
        let id = s.add_as(&record("SN2", None, &[("x", "bias_dph", 10.0)]), &op).unwrap();
        let ev = s.audit_events(Some(id)).unwrap();
        assert_eq!((ev[0].actor.as_str(), ev[0].action.as_str()), ("op", "store"));

        // An approval by an account: an approver, not the one who stored it.
        let approval = |by: &str| Revision {
            supersedes: id,
            kind: RevisionKind::Approval,
            by: by.to_string(),
            reason: "reviewed".into(),
        };
        assert!(s.revise_as(&approval("op"), &Changes::default(), None, &op).is_err(), "an operator approves nothing");
        let appr = s.authenticate("appr", "password-appr").unwrap();
        let approved = s.revise_as(&approval("appr"), &Changes::default(), None, &appr).unwrap();
        let fix =
            Revision { supersedes: approved, kind: RevisionKind::Correction, by: "appr".into(), reason: "lot".into() };
        let corrected =
            s.revise_as(&fix, &Changes { lot: Some("L9".into()), ..Default::default() }, None, &appr).unwrap();
        let again = Revision { supersedes: corrected, ..approval("appr") };
        let e = s.revise_as(&again, &Changes::default(), None, &appr).unwrap_err();
        assert!(e.to_string().contains("self-approval refused"), "{}: {e}", b.name);

        // An actor of another store (the same name and id, another salt) is refused here.
        let other_dir = tempfile::tempdir().unwrap();
        let mut other = Store::open(other_dir.path().join("other.db").to_str().unwrap(), true).unwrap();
        other.add_account(&none, "admin", "Other", Role::Admin, "password-other").unwrap();
        let foreign = other.authenticate("admin", "password-other").unwrap();
        assert!(matches!(s.add_account(&foreign, "x", "X", Role::Admin, "password-x"), Err(StoreError::Auth { .. })));

        // Disabled, and a new password: each a new record.
        s.reset_password(&admin, "op", "password-op-2").unwrap();
        assert!(s.authenticate("op", "password-op").is_err());
        assert!(
            matches!(s.add_as(&record("SN4", None, &[("x", "bias_dph", 10.0)]), &op), Err(StoreError::Auth { .. })),
            "an actor authenticated with the old password is refused after a reset"
        );
        let op2 = s.authenticate("op", "password-op-2").unwrap();
        s.disable_account(&admin, "op").unwrap();
        let disabled = s.authenticate("op", "password-op-2").unwrap_err();
        assert_eq!(disabled.to_string(), wrong.to_string(), "{}", b.name);
        assert!(
            matches!(s.add_as(&record("SN3", None, &[("x", "bias_dph", 10.0)]), &op2), Err(StoreError::Auth { .. })),
            "an actor authenticated before the account was disabled is refused at the write"
        );
        assert!(s.disable_account(&appr, "view").is_err(), "only an admin");
        let accounts = s.accounts().unwrap();
        assert!(accounts.iter().any(|a| a.name == "op" && a.disabled));
        assert_eq!(
            accounts.iter().find(|a| a.name == "admin").unwrap().created_by,
            "local (the store's first account)"
        );

        let all = s.audit_events(None).unwrap();
        for action in ["user add", "user reset", "user disable", "approval", "correction"] {
            assert!(all.iter().any(|e| e.action == action), "{}: no {action} in {all:?}", b.name);
        }
        let r = s.check().unwrap();
        assert!(r.is_whole(), "{}: {:?}", b.name, r.problems);
        let chained: i64 = ["account", "account_change", "audit_event"]
            .iter()
            .map(|t| r.rows.iter().find(|(n, _)| n == t).unwrap().1)
            .sum();
        assert!(chained >= 4 + 2 + 9, "{}: {:?}", b.name, r.rows);
    }
}
