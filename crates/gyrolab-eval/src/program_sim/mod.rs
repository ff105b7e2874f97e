//! Simulated records with known truth for each test of a lab's test program (issue 19): one
//! module per test, each with `write_<topic>_records(dir, axis, seed)` that writes the records
//! and returns the TOML of its plan section (the truth stated in a comment).

pub mod g_sensitivity;
