
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
