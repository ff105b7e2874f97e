
CREATE TABLE account (
    id INTEGER PRIMARY KEY AUTOINCREMENT,
    name TEXT NOT NULL UNIQUE,
    display_name TEXT NOT NULL,
    role TEXT NOT NULL CHECK (role IN ('viewer', 'operator', 'approver', 'admin')),
    password_hash TEXT NOT NULL,
    created_at TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now')),
    created_by TEXT NOT NULL
);
CREATE TABLE account_change (
    id INTEGER PRIMARY KEY AUTOINCREMENT,
    account_id INTEGER NOT NULL REFERENCES account(id),
    change TEXT NOT NULL CHECK (change IN ('disable', 'password')),
    password_hash TEXT,
    changed_at TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now')),
    changed_by INTEGER NOT NULL REFERENCES account(id)
);
CREATE INDEX account_change_account ON account_change(account_id);
CREATE TABLE audit_event (
    id INTEGER PRIMARY KEY AUTOINCREMENT,
    at TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now')),
    account_id INTEGER REFERENCES account(id),
    actor TEXT NOT NULL,
    action TEXT NOT NULL,
    evaluation_id INTEGER REFERENCES evaluation(id),
    detail TEXT
);
CREATE INDEX audit_event_evaluation ON audit_event(evaluation_id);
CREATE TABLE signing_key (
    id INTEGER PRIMARY KEY AUTOINCREMENT,
    public_key TEXT NOT NULL UNIQUE,
    fingerprint TEXT NOT NULL,
    added_at TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now')),
    added_by TEXT NOT NULL
);
CREATE TABLE issue (
    id INTEGER PRIMARY KEY AUTOINCREMENT,
    evaluation_id INTEGER NOT NULL UNIQUE REFERENCES evaluation(id),
    report_number TEXT NOT NULL UNIQUE,
    issued_at TEXT NOT NULL,
    signer_account_id INTEGER NOT NULL REFERENCES account(id),
    signer_name TEXT NOT NULL,
    signer_display_name TEXT NOT NULL,
    signer_role TEXT NOT NULL,
    meaning TEXT NOT NULL CHECK (meaning IN ('approved', 'reviewed')),
    key_fingerprint TEXT NOT NULL,
    chain_head TEXT NOT NULL,
    issue_json TEXT NOT NULL,
    report_html_zstd BLOB NOT NULL,
    manifest TEXT NOT NULL,
    signature TEXT NOT NULL,
    amends INTEGER UNIQUE REFERENCES issue(id),
    amendment_no INTEGER,
    amend_reason TEXT,
    superseded_issue_json TEXT,
    superseded_manifest TEXT,
    superseded_signature TEXT
);
CREATE TRIGGER account_kept BEFORE UPDATE ON account BEGIN SELECT RAISE(ABORT, 'gyrolab records are never changed: store a revision'); END;
CREATE TRIGGER account_kept_d BEFORE DELETE ON account BEGIN SELECT RAISE(ABORT, 'gyrolab records are never deleted'); END;
CREATE TRIGGER account_kept_r BEFORE INSERT ON account WHEN EXISTS (SELECT 1 FROM account WHERE id = NEW.id OR name = NEW.name) BEGIN SELECT RAISE(ABORT, 'gyrolab records are never replaced'); END;
CREATE TRIGGER account_change_kept BEFORE UPDATE ON account_change BEGIN SELECT RAISE(ABORT, 'gyrolab records are never changed: store a revision'); END;
CREATE TRIGGER account_change_kept_d BEFORE DELETE ON account_change BEGIN SELECT RAISE(ABORT, 'gyrolab records are never deleted'); END;
CREATE TRIGGER account_change_kept_r BEFORE INSERT ON account_change WHEN EXISTS (SELECT 1 FROM account_change WHERE id = NEW.id) BEGIN SELECT RAISE(ABORT, 'gyrolab records are never replaced'); END;
CREATE TRIGGER audit_event_kept BEFORE UPDATE ON audit_event BEGIN SELECT RAISE(ABORT, 'gyrolab records are never changed: store a revision'); END;
CREATE TRIGGER audit_event_kept_d BEFORE DELETE ON audit_event BEGIN SELECT RAISE(ABORT, 'gyrolab records are never deleted'); END;
CREATE TRIGGER audit_event_kept_r BEFORE INSERT ON audit_event WHEN EXISTS (SELECT 1 FROM audit_event WHERE id = NEW.id) BEGIN SELECT RAISE(ABORT, 'gyrolab records are never replaced'); END;
CREATE TRIGGER signing_key_kept BEFORE UPDATE ON signing_key BEGIN SELECT RAISE(ABORT, 'gyrolab records are never changed: store a revision'); END;
CREATE TRIGGER signing_key_kept_d BEFORE DELETE ON signing_key BEGIN SELECT RAISE(ABORT, 'gyrolab records are never deleted'); END;
CREATE TRIGGER signing_key_kept_r BEFORE INSERT ON signing_key WHEN EXISTS (SELECT 1 FROM signing_key WHERE id = NEW.id OR public_key = NEW.public_key) BEGIN SELECT RAISE(ABORT, 'gyrolab records are never replaced'); END;
CREATE TRIGGER issue_kept BEFORE UPDATE ON issue BEGIN SELECT RAISE(ABORT, 'gyrolab records are never changed: store a revision'); END;
CREATE TRIGGER issue_kept_d BEFORE DELETE ON issue BEGIN SELECT RAISE(ABORT, 'gyrolab records are never deleted'); END;
CREATE TRIGGER issue_kept_r BEFORE INSERT ON issue WHEN EXISTS (SELECT 1 FROM issue WHERE id = NEW.id OR evaluation_id = NEW.evaluation_id OR report_number = NEW.report_number OR amends = NEW.amends) BEGIN SELECT RAISE(ABORT, 'gyrolab records are never replaced (a report number, an evaluation and a report amended are issued once)'); END;
