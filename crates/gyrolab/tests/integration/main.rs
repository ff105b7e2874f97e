//! The core's integration tests, in one test binary (one link instead of one per file: issue 32,
//! docs/PERFORMANCE.md). Each file is a module; run one with
//! `cargo test -p gyrolab --test integration -- MODULE::`.

mod determinism;
mod noise_support;
mod stable32_reference;
mod static_test;
