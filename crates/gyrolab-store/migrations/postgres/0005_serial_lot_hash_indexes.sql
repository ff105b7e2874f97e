
DROP INDEX evaluation_serial;
CREATE INDEX evaluation_serial ON evaluation USING hash (serial);
DROP INDEX evaluation_lot;
CREATE INDEX evaluation_lot ON evaluation USING hash (lot);
