//! Writes the example plan with every test of a lab's program and its SIMULATED records
//! (`gyrolab_eval::program_sim::write_test_program`) into a folder (default
//! `examples/test_program`): `plan.toml` and the CSV records it names.
//!
//! `cargo run -p gyrolab-eval --example example_test_program -- examples/test_program`
//! then `gyrolab eval examples/test_program/plan.toml --out report/`.

/// Seed of the example's records.
const SEED: u64 = 2026;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::path::PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| "examples/test_program".into()));
    std::fs::create_dir_all(&dir)?;
    gyrolab_eval::program_sim::write_test_program(&dir, SEED)?;
    eprintln!("wrote {} (plan.toml and its SIMULATED records)", dir.display());
    Ok(())
}
