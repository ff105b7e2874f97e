//! Simulated records of a whole gyro test program, with known truth: one module per test, each
//! with a `write_<topic>_records(dir, axis, seed)` that writes the CSV files into `dir` and
//! returns the TOML of its plan section (relative paths; the simulated truth in a TOML comment).

pub mod threshold;
