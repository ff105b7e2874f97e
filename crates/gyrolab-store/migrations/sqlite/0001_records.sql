
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
