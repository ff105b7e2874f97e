//! Simulated records with known truth for the test-plan sections (one module per section): each
//! `write_<topic>_records(dir, axis, seed)` writes CSV files into `dir` and returns the TOML of
//! its plan section referring to them, the simulated truth stated in a TOML comment.

pub mod power_ups;
