
CREATE TABLE input_content (
    id INTEGER PRIMARY KEY,
    evaluation_id INTEGER NOT NULL REFERENCES evaluation(id),
    sha256 TEXT NOT NULL UNIQUE,
    size_bytes INTEGER NOT NULL,
    content_zstd BLOB NOT NULL
);
CREATE INDEX input_content_evaluation ON input_content(evaluation_id);
CREATE TRIGGER input_content_kept BEFORE UPDATE ON input_content BEGIN SELECT RAISE(ABORT, 'gyrolab records are never changed: store a revision'); END;
CREATE TRIGGER input_content_kept_d BEFORE DELETE ON input_content BEGIN SELECT RAISE(ABORT, 'gyrolab records are never deleted'); END;
CREATE TRIGGER input_content_kept_r BEFORE INSERT ON input_content WHEN EXISTS (SELECT 1 FROM input_content WHERE id = NEW.id OR sha256 = NEW.sha256) BEGIN SELECT RAISE(ABORT, 'gyrolab records are never replaced'); END;
