//! The schema and its migrations, one list per back end (the same tables; only the column types
//! of keys and the immutability triggers are written differently). Migration N brings a store
//! from version N - 1 to N; `gyrolab_schema` keeps one row per applied version (docs/STORE.md).

/// The schema version this build writes and reads.
pub const SCHEMA_VERSION: i64 = 2;

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
];

/// The version table (both back ends).
pub const VERSION_TABLE: &str =
    "CREATE TABLE IF NOT EXISTS gyrolab_schema (version BIGINT NOT NULL PRIMARY KEY, applied_at TEXT NOT NULL, software_version TEXT NOT NULL)";
