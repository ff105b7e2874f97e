//! The records store's integration tests, in one test binary (one link instead of one per file: issue 32,
//! docs/PERFORMANCE.md). Each file is a module; run one with
//! `cargo test -p gyrolab-store --test integration -- MODULE::`.

mod accounts;
mod common;
mod least_privilege;
mod migrations;
mod store;
mod tamper;
