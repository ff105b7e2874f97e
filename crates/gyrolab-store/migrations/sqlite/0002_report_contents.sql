
ALTER TABLE report_file ADD COLUMN content_zstd BLOB;
CREATE TRIGGER input_file_kept BEFORE UPDATE ON input_file BEGIN SELECT RAISE(ABORT, 'gyrolab records are never changed: store a revision'); END;
CREATE TRIGGER input_file_kept_d BEFORE DELETE ON input_file BEGIN SELECT RAISE(ABORT, 'gyrolab records are never deleted'); END;
CREATE TRIGGER report_file_kept BEFORE UPDATE ON report_file BEGIN SELECT RAISE(ABORT, 'gyrolab records are never changed: store a revision'); END;
CREATE TRIGGER report_file_kept_d BEFORE DELETE ON report_file BEGIN SELECT RAISE(ABORT, 'gyrolab records are never deleted'); END;
