//! gyrolab-lab's integration tests, in one test binary. Each file is a module; run one with
//! `cargo test -p gyrolab-lab --test integration -- MODULE::`.

// The independent side of every comparison is shared with gyrolab-eval's tests (one file).
#[path = "../../../gyrolab-eval/tests/integration/common/mod.rs"]
mod common;
mod demo;
mod plan_g_sensitivity;
mod plan_power_ups;
mod plan_temperature;
mod plan_threshold;
mod plan_uncertainty;
// The store's back ends (SQLite always; PostgreSQL at GYROLAB_TEST_PG_URL), shared with its tests.
#[path = "../../../gyrolab-store/tests/integration/common/mod.rs"]
mod store_common;
mod store_folder;
mod test_plan;
mod test_program;
