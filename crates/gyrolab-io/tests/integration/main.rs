//! gyrolab-io's integration tests, in one test binary (one link instead of one per file: issue 32,
//! docs/PERFORMANCE.md). Each file is a module; run one with
//! `cargo test -p gyrolab-io --test integration -- MODULE::`.

mod fuzz_props;
mod imu_logs;
mod paper;
mod series;
mod spreadsheet_layouts;
