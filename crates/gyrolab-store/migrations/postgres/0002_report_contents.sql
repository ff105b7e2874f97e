
ALTER TABLE report_file ADD COLUMN content_zstd BYTEA;
CREATE TRIGGER input_file_kept BEFORE UPDATE OR DELETE ON input_file FOR EACH ROW EXECUTE FUNCTION gyrolab_records_are_kept();
CREATE TRIGGER report_file_kept BEFORE UPDATE OR DELETE ON report_file FOR EACH ROW EXECUTE FUNCTION gyrolab_records_are_kept();
