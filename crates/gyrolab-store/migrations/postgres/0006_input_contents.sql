
CREATE TABLE input_content (
    id BIGINT GENERATED ALWAYS AS IDENTITY PRIMARY KEY,
    evaluation_id BIGINT NOT NULL REFERENCES evaluation(id),
    sha256 TEXT NOT NULL UNIQUE,
    size_bytes BIGINT NOT NULL,
    content_zstd BYTEA NOT NULL
);
CREATE INDEX input_content_evaluation ON input_content(evaluation_id);
CREATE TRIGGER input_content_kept BEFORE UPDATE OR DELETE ON input_content FOR EACH ROW EXECUTE FUNCTION gyrolab_records_are_kept();
CREATE TRIGGER input_content_not_truncated BEFORE TRUNCATE ON input_content FOR EACH STATEMENT EXECUTE FUNCTION gyrolab_records_are_kept();
