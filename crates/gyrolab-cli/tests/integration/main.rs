//! The command line's integration tests, in one test binary (one link instead of one per file: issue 32,
//! docs/PERFORMANCE.md). Each file is a module; run one with
//! `cargo test -p gyrolab-cli --test integration -- MODULE::`.

mod allan;
mod allan_memory;
mod bad_input;
mod batch;
mod bias;
mod browser;
mod common;
mod defaults;
mod eval;
mod export;
mod golden;
mod hostile;
mod imu_logs;
mod issue;
mod pdf;
mod rate;
mod raw_log;
mod recordings;
mod simulate;
mod stillness;
mod store;
mod verify;
