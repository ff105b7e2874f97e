//! The schema and its migrations, one list per back end (the same tables; only the column types
//! of keys and the immutability triggers are written differently). Migration N brings a store
//! from version N - 1 to N; `gyrolab_schema` keeps one row per applied version (docs/STORE.md).

/// The schema version this build writes and reads.
pub const SCHEMA_VERSION: i64 = 5;

/// SQLite migrations, by version (index 0 = version 1).
pub const SQLITE_MIGRATIONS: &[&str] = &[
    r#"
CREATE TABLE evaluation (
    id INTEGER PRIMARY KEY AUTOINCREMENT,
    supersedes INTEGER UNIQUE REFERENCES evaluation(id),
    revision_kind TEXT NOT NULL,
    revision_by TEXT,
    revision_reason TEXT,
    stored_at TEXT NOT NULL,
    serial TEXT NOT NULL,
    model TEXT NOT NULL,
    lot TEXT,
    operator TEXT,
    approver TEXT,
    test_date TEXT,
    evaluated_at TEXT NOT NULL,
    software_version TEXT NOT NULL,
    plan_path TEXT NOT NULL,
    plan_text TEXT NOT NULL,
    plan_sha256 TEXT NOT NULL,
    results_json TEXT NOT NULL,
    verdict TEXT,
    simulated INTEGER NOT NULL
);
CREATE INDEX evaluation_serial ON evaluation(serial);
CREATE INDEX evaluation_lot ON evaluation(lot);
CREATE TABLE input_file (
    evaluation_id INTEGER NOT NULL REFERENCES evaluation(id),
    path TEXT NOT NULL,
    sha256 TEXT NOT NULL,
    size_bytes INTEGER NOT NULL
);
CREATE INDEX input_file_evaluation ON input_file(evaluation_id);
CREATE TABLE report_file (
    evaluation_id INTEGER NOT NULL REFERENCES evaluation(id),
    name TEXT NOT NULL,
    sha256 TEXT NOT NULL,
    size_bytes INTEGER NOT NULL
);
CREATE INDEX report_file_evaluation ON report_file(evaluation_id);
CREATE TABLE figure (
    evaluation_id INTEGER NOT NULL REFERENCES evaluation(id),
    axis TEXT NOT NULL,
    figure TEXT NOT NULL,
    value REAL,
    unit TEXT NOT NULL,
    basis TEXT NOT NULL,
    expanded_uncertainty REAL,
    coverage_factor REAL,
    limit_min REAL,
    limit_max REAL,
    verdict TEXT,
    simulated INTEGER NOT NULL
);
CREATE INDEX figure_evaluation ON figure(evaluation_id);
CREATE TRIGGER evaluation_kept BEFORE UPDATE ON evaluation BEGIN SELECT RAISE(ABORT, 'gyrolab records are never changed: store a revision'); END;
CREATE TRIGGER evaluation_kept_d BEFORE DELETE ON evaluation BEGIN SELECT RAISE(ABORT, 'gyrolab records are never deleted'); END;
CREATE TRIGGER figure_kept BEFORE UPDATE ON figure BEGIN SELECT RAISE(ABORT, 'gyrolab records are never changed: store a revision'); END;
CREATE TRIGGER figure_kept_d BEFORE DELETE ON figure BEGIN SELECT RAISE(ABORT, 'gyrolab records are never deleted'); END;
"#,
    // 2: the report files themselves (zstd-compressed), so that a stored report can be written
    // back; rows stored under version 1 keep a null (their files were hashed only).
    // Input and report file rows are kept like evaluations and figures.
    r#"
ALTER TABLE report_file ADD COLUMN content_zstd BLOB;
CREATE TRIGGER input_file_kept BEFORE UPDATE ON input_file BEGIN SELECT RAISE(ABORT, 'gyrolab records are never changed: store a revision'); END;
CREATE TRIGGER input_file_kept_d BEFORE DELETE ON input_file BEGIN SELECT RAISE(ABORT, 'gyrolab records are never deleted'); END;
CREATE TRIGGER report_file_kept BEFORE UPDATE ON report_file BEGIN SELECT RAISE(ABORT, 'gyrolab records are never changed: store a revision'); END;
CREATE TRIGGER report_file_kept_d BEFORE DELETE ON report_file BEGIN SELECT RAISE(ABORT, 'gyrolab records are never deleted'); END;
"#,
    // 3 (issue 53): tamper evidence. Every file and figure row gets a stable `id` (its rowid at
    // migration; new rows: the next id, given by the store), the hash chain `chain` (one link
    // per stored row, appended by the store: crate::chain), INSERT refused over an existing key
    // (INSERT OR REPLACE deletes the old row without firing the DELETE triggers), and the chain
    // kept like the records. The chain over the rows already stored is built by the store right
    // after this script (crate::chain::build_existing), in the same transaction.
    r#"
ALTER TABLE input_file ADD COLUMN id INTEGER;
ALTER TABLE report_file ADD COLUMN id INTEGER;
ALTER TABLE figure ADD COLUMN id INTEGER;
DROP TRIGGER IF EXISTS input_file_kept;
DROP TRIGGER IF EXISTS report_file_kept;
DROP TRIGGER IF EXISTS figure_kept;
UPDATE input_file SET id = rowid;
UPDATE report_file SET id = rowid;
UPDATE figure SET id = rowid;
CREATE TRIGGER input_file_kept BEFORE UPDATE ON input_file BEGIN SELECT RAISE(ABORT, 'gyrolab records are never changed: store a revision'); END;
CREATE TRIGGER report_file_kept BEFORE UPDATE ON report_file BEGIN SELECT RAISE(ABORT, 'gyrolab records are never changed: store a revision'); END;
CREATE TRIGGER figure_kept BEFORE UPDATE ON figure BEGIN SELECT RAISE(ABORT, 'gyrolab records are never changed: store a revision'); END;
CREATE UNIQUE INDEX input_file_id ON input_file(id);
CREATE UNIQUE INDEX report_file_id ON report_file(id);
CREATE UNIQUE INDEX figure_id ON figure(id);
CREATE TABLE chain (
    seq INTEGER PRIMARY KEY,
    tbl TEXT NOT NULL,
    row_id INTEGER NOT NULL,
    fields TEXT NOT NULL,
    hash TEXT NOT NULL,
    UNIQUE (tbl, row_id)
);
CREATE TRIGGER chain_kept BEFORE UPDATE ON chain BEGIN SELECT RAISE(ABORT, 'gyrolab records are never changed: store a revision'); END;
CREATE TRIGGER chain_kept_d BEFORE DELETE ON chain BEGIN SELECT RAISE(ABORT, 'gyrolab records are never deleted'); END;
CREATE TRIGGER evaluation_kept_r BEFORE INSERT ON evaluation WHEN EXISTS (SELECT 1 FROM evaluation WHERE id = NEW.id OR supersedes = NEW.supersedes) BEGIN SELECT RAISE(ABORT, 'gyrolab records are never replaced'); END;
CREATE TRIGGER input_file_kept_r BEFORE INSERT ON input_file WHEN EXISTS (SELECT 1 FROM input_file WHERE rowid = NEW.rowid OR id = NEW.id) BEGIN SELECT RAISE(ABORT, 'gyrolab records are never replaced'); END;
CREATE TRIGGER report_file_kept_r BEFORE INSERT ON report_file WHEN EXISTS (SELECT 1 FROM report_file WHERE rowid = NEW.rowid OR id = NEW.id) BEGIN SELECT RAISE(ABORT, 'gyrolab records are never replaced'); END;
CREATE TRIGGER figure_kept_r BEFORE INSERT ON figure WHEN EXISTS (SELECT 1 FROM figure WHERE rowid = NEW.rowid OR id = NEW.id) BEGIN SELECT RAISE(ABORT, 'gyrolab records are never replaced'); END;
CREATE TRIGGER chain_kept_r BEFORE INSERT ON chain WHEN EXISTS (SELECT 1 FROM chain WHERE seq = NEW.seq OR (tbl = NEW.tbl AND row_id = NEW.row_id)) BEGIN SELECT RAISE(ABORT, 'gyrolab records are never replaced'); END;
"#,
    // 4 (issue 53): accounts, the audit trail, the lab's public keys and issued reports. Every
    // row is a record (chained, never changed: a disabled account or a new password is a new
    // `account_change` row). Times come from the database's clock (the column defaults).
    r#"
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
"#,
    // 5 (issue 53): no change on SQLite, whose indexes take a text of any length (the serial
    // and lot indexes are made hash indexes on PostgreSQL, whose B-tree rows stop at 2.7 KB).
    "CREATE INDEX IF NOT EXISTS evaluation_serial ON evaluation(serial);",
];

/// PostgreSQL migrations, by version (index 0 = version 1).
pub const POSTGRES_MIGRATIONS: &[&str] = &[
    r#"
CREATE TABLE evaluation (
    id BIGINT GENERATED ALWAYS AS IDENTITY PRIMARY KEY,
    supersedes BIGINT UNIQUE REFERENCES evaluation(id),
    revision_kind TEXT NOT NULL,
    revision_by TEXT,
    revision_reason TEXT,
    stored_at TEXT NOT NULL,
    serial TEXT NOT NULL,
    model TEXT NOT NULL,
    lot TEXT,
    operator TEXT,
    approver TEXT,
    test_date TEXT,
    evaluated_at TEXT NOT NULL,
    software_version TEXT NOT NULL,
    plan_path TEXT NOT NULL,
    plan_text TEXT NOT NULL,
    plan_sha256 TEXT NOT NULL,
    results_json TEXT NOT NULL,
    verdict TEXT,
    simulated BIGINT NOT NULL
);
CREATE INDEX evaluation_serial ON evaluation(serial);
CREATE INDEX evaluation_lot ON evaluation(lot);
CREATE TABLE input_file (
    evaluation_id BIGINT NOT NULL REFERENCES evaluation(id),
    path TEXT NOT NULL,
    sha256 TEXT NOT NULL,
    size_bytes BIGINT NOT NULL
);
CREATE INDEX input_file_evaluation ON input_file(evaluation_id);
CREATE TABLE report_file (
    evaluation_id BIGINT NOT NULL REFERENCES evaluation(id),
    name TEXT NOT NULL,
    sha256 TEXT NOT NULL,
    size_bytes BIGINT NOT NULL
);
CREATE INDEX report_file_evaluation ON report_file(evaluation_id);
CREATE TABLE figure (
    evaluation_id BIGINT NOT NULL REFERENCES evaluation(id),
    axis TEXT NOT NULL,
    figure TEXT NOT NULL,
    value DOUBLE PRECISION,
    unit TEXT NOT NULL,
    basis TEXT NOT NULL,
    expanded_uncertainty DOUBLE PRECISION,
    coverage_factor DOUBLE PRECISION,
    limit_min DOUBLE PRECISION,
    limit_max DOUBLE PRECISION,
    verdict TEXT,
    simulated BIGINT NOT NULL
);
CREATE INDEX figure_evaluation ON figure(evaluation_id);
CREATE FUNCTION gyrolab_records_are_kept() RETURNS trigger LANGUAGE plpgsql AS $$
BEGIN
    RAISE EXCEPTION 'gyrolab records are never changed or deleted: store a revision';
END $$;
CREATE TRIGGER evaluation_kept BEFORE UPDATE OR DELETE ON evaluation FOR EACH ROW EXECUTE FUNCTION gyrolab_records_are_kept();
CREATE TRIGGER figure_kept BEFORE UPDATE OR DELETE ON figure FOR EACH ROW EXECUTE FUNCTION gyrolab_records_are_kept();
"#,
    // 2: the report files themselves (zstd-compressed; see SQLITE_MIGRATIONS); input and report
    // file rows kept like evaluations and figures.
    r#"
ALTER TABLE report_file ADD COLUMN content_zstd BYTEA;
CREATE TRIGGER input_file_kept BEFORE UPDATE OR DELETE ON input_file FOR EACH ROW EXECUTE FUNCTION gyrolab_records_are_kept();
CREATE TRIGGER report_file_kept BEFORE UPDATE OR DELETE ON report_file FOR EACH ROW EXECUTE FUNCTION gyrolab_records_are_kept();
"#,
    // 3 (issue 53): tamper evidence (see SQLITE_MIGRATIONS): a stable `id` for file and figure
    // rows (rows already stored are numbered in the order PostgreSQL reads them), the hash chain,
    // and TRUNCATE refused on every table (it fires no row trigger).
    r#"
ALTER TABLE input_file ADD COLUMN id BIGINT GENERATED ALWAYS AS IDENTITY UNIQUE;
ALTER TABLE report_file ADD COLUMN id BIGINT GENERATED ALWAYS AS IDENTITY UNIQUE;
ALTER TABLE figure ADD COLUMN id BIGINT GENERATED ALWAYS AS IDENTITY UNIQUE;
CREATE TABLE chain (
    seq BIGINT PRIMARY KEY,
    tbl TEXT NOT NULL,
    row_id BIGINT NOT NULL,
    fields TEXT NOT NULL,
    hash TEXT NOT NULL,
    UNIQUE (tbl, row_id)
);
CREATE TRIGGER chain_kept BEFORE UPDATE OR DELETE ON chain FOR EACH ROW EXECUTE FUNCTION gyrolab_records_are_kept();
CREATE TRIGGER evaluation_not_truncated BEFORE TRUNCATE ON evaluation FOR EACH STATEMENT EXECUTE FUNCTION gyrolab_records_are_kept();
CREATE TRIGGER input_file_not_truncated BEFORE TRUNCATE ON input_file FOR EACH STATEMENT EXECUTE FUNCTION gyrolab_records_are_kept();
CREATE TRIGGER report_file_not_truncated BEFORE TRUNCATE ON report_file FOR EACH STATEMENT EXECUTE FUNCTION gyrolab_records_are_kept();
CREATE TRIGGER figure_not_truncated BEFORE TRUNCATE ON figure FOR EACH STATEMENT EXECUTE FUNCTION gyrolab_records_are_kept();
CREATE TRIGGER chain_not_truncated BEFORE TRUNCATE ON chain FOR EACH STATEMENT EXECUTE FUNCTION gyrolab_records_are_kept();
"#,
    // 4 (issue 53): accounts, the audit trail, the lab's public keys and issued reports (see
    // SQLITE_MIGRATIONS); times from the server's clock.
    r#"
CREATE TABLE account (
    id BIGINT GENERATED ALWAYS AS IDENTITY PRIMARY KEY,
    name TEXT NOT NULL UNIQUE,
    display_name TEXT NOT NULL,
    role TEXT NOT NULL CHECK (role IN ('viewer', 'operator', 'approver', 'admin')),
    password_hash TEXT NOT NULL,
    created_at TEXT NOT NULL DEFAULT (to_char(clock_timestamp() AT TIME ZONE 'UTC', 'YYYY-MM-DD"T"HH24:MI:SS.MS"Z"')),
    created_by TEXT NOT NULL
);
CREATE TABLE account_change (
    id BIGINT GENERATED ALWAYS AS IDENTITY PRIMARY KEY,
    account_id BIGINT NOT NULL REFERENCES account(id),
    change TEXT NOT NULL CHECK (change IN ('disable', 'password')),
    password_hash TEXT,
    changed_at TEXT NOT NULL DEFAULT (to_char(clock_timestamp() AT TIME ZONE 'UTC', 'YYYY-MM-DD"T"HH24:MI:SS.MS"Z"')),
    changed_by BIGINT NOT NULL REFERENCES account(id)
);
CREATE INDEX account_change_account ON account_change(account_id);
CREATE TABLE audit_event (
    id BIGINT GENERATED ALWAYS AS IDENTITY PRIMARY KEY,
    at TEXT NOT NULL DEFAULT (to_char(clock_timestamp() AT TIME ZONE 'UTC', 'YYYY-MM-DD"T"HH24:MI:SS.MS"Z"')),
    account_id BIGINT REFERENCES account(id),
    actor TEXT NOT NULL,
    action TEXT NOT NULL,
    evaluation_id BIGINT REFERENCES evaluation(id),
    detail TEXT
);
CREATE INDEX audit_event_evaluation ON audit_event(evaluation_id);
CREATE TABLE signing_key (
    id BIGINT GENERATED ALWAYS AS IDENTITY PRIMARY KEY,
    public_key TEXT NOT NULL UNIQUE,
    fingerprint TEXT NOT NULL,
    added_at TEXT NOT NULL DEFAULT (to_char(clock_timestamp() AT TIME ZONE 'UTC', 'YYYY-MM-DD"T"HH24:MI:SS.MS"Z"')),
    added_by TEXT NOT NULL
);
CREATE TABLE issue (
    id BIGINT GENERATED ALWAYS AS IDENTITY PRIMARY KEY,
    evaluation_id BIGINT NOT NULL UNIQUE REFERENCES evaluation(id),
    report_number TEXT NOT NULL UNIQUE,
    issued_at TEXT NOT NULL,
    signer_account_id BIGINT NOT NULL REFERENCES account(id),
    signer_name TEXT NOT NULL,
    signer_display_name TEXT NOT NULL,
    signer_role TEXT NOT NULL,
    meaning TEXT NOT NULL CHECK (meaning IN ('approved', 'reviewed')),
    key_fingerprint TEXT NOT NULL,
    chain_head TEXT NOT NULL,
    issue_json TEXT NOT NULL,
    report_html_zstd BYTEA NOT NULL,
    manifest TEXT NOT NULL,
    signature TEXT NOT NULL,
    amends BIGINT UNIQUE REFERENCES issue(id),
    amendment_no BIGINT,
    amend_reason TEXT,
    superseded_issue_json TEXT,
    superseded_manifest TEXT,
    superseded_signature TEXT
);
CREATE TRIGGER account_kept BEFORE UPDATE OR DELETE ON account FOR EACH ROW EXECUTE FUNCTION gyrolab_records_are_kept();
CREATE TRIGGER account_not_truncated BEFORE TRUNCATE ON account FOR EACH STATEMENT EXECUTE FUNCTION gyrolab_records_are_kept();
CREATE TRIGGER account_change_kept BEFORE UPDATE OR DELETE ON account_change FOR EACH ROW EXECUTE FUNCTION gyrolab_records_are_kept();
CREATE TRIGGER account_change_not_truncated BEFORE TRUNCATE ON account_change FOR EACH STATEMENT EXECUTE FUNCTION gyrolab_records_are_kept();
CREATE TRIGGER audit_event_kept BEFORE UPDATE OR DELETE ON audit_event FOR EACH ROW EXECUTE FUNCTION gyrolab_records_are_kept();
CREATE TRIGGER audit_event_not_truncated BEFORE TRUNCATE ON audit_event FOR EACH STATEMENT EXECUTE FUNCTION gyrolab_records_are_kept();
CREATE TRIGGER signing_key_kept BEFORE UPDATE OR DELETE ON signing_key FOR EACH ROW EXECUTE FUNCTION gyrolab_records_are_kept();
CREATE TRIGGER signing_key_not_truncated BEFORE TRUNCATE ON signing_key FOR EACH STATEMENT EXECUTE FUNCTION gyrolab_records_are_kept();
CREATE TRIGGER issue_kept BEFORE UPDATE OR DELETE ON issue FOR EACH ROW EXECUTE FUNCTION gyrolab_records_are_kept();
CREATE TRIGGER issue_not_truncated BEFORE TRUNCATE ON issue FOR EACH STATEMENT EXECUTE FUNCTION gyrolab_records_are_kept();
"#,
    // 5 (issue 53): the serial and lot indexes as hash indexes: a B-tree index row stops at
    // about 2.7 KB, so a longer serial (SQLite takes 16 MiB) was refused; every query of them is
    // an equality.
    r#"
DROP INDEX evaluation_serial;
CREATE INDEX evaluation_serial ON evaluation USING hash (serial);
DROP INDEX evaluation_lot;
CREATE INDEX evaluation_lot ON evaluation USING hash (lot);
"#,
];

/// The version table (both back ends).
pub const VERSION_TABLE: &str =
    "CREATE TABLE IF NOT EXISTS gyrolab_schema (version BIGINT NOT NULL PRIMARY KEY, applied_at TEXT NOT NULL, software_version TEXT NOT NULL)";

/// The database's clock as RFC 3339 UTC text to the millisecond (the column defaults of
/// migration 4 use the same expression): the time every account, audit event and issue records.
pub fn clock_sql(postgres: bool) -> &'static str {
    if postgres {
        "SELECT to_char(clock_timestamp() AT TIME ZONE 'UTC', 'YYYY-MM-DD\"T\"HH24:MI:SS.MS\"Z\"')"
    } else {
        "SELECT strftime('%Y-%m-%dT%H:%M:%fZ', 'now')"
    }
}
