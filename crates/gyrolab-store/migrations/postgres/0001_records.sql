
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
