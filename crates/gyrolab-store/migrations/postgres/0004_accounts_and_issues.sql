
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
