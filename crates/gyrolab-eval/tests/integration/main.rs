//! gyrolab-eval's integration tests, in one test binary (one link instead of one per file: issue 32,
//! docs/PERFORMANCE.md). Each file is a module; run one with
//! `cargo test -p gyrolab-eval --test integration -- MODULE::`.

mod allan;
mod clock;
mod common;
mod rate;
mod raw_log;
mod static_file;
mod static_test;
mod triad;
