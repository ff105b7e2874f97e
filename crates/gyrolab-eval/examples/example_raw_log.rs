//! Writes the bundled example raw log `examples/data/raw_log_x.csv` (SIMULATED): a rate table
//! stepping through +-10, 50, 100 deg/s in two runs with rests at both ends, logged at 50 Hz,
//! and one gyro output in V with K = 0.0075 V/(deg/s), null 2.5 V and 0.5 mV white noise.
//!
//! `cargo run -p gyrolab-eval --example example_raw_log -- examples/data/raw_log_x.csv`

use gyrolab::sim::{raw_log_setpoints, simulate_raw_log, RawLogProfile};
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use std::fmt::Write;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args().nth(1).ok_or("usage: example_raw_log OUT.csv")?;
    let rates = [-100.0, -50.0, -10.0, 10.0, 50.0, 100.0];
    let seq = raw_log_setpoints(&rates, 2, true, true);
    let profile = RawLogProfile { dt: 0.02, hold_s: 8.0, ..RawLogProfile::default() };
    let log = simulate_raw_log(&seq, &profile, 2014)?;
    let (k, null) = (0.0075, 2.5);
    let noise = Normal::new(0.0, 5e-4)?;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(2015);
    let mut text = String::from(
        "# SIMULATED raw rate-table log (gyrolab example, crates/gyrolab-eval/examples/example_raw_log.rs):\n\
         # K = 0.0075 V/(deg/s), null = 2.5 V, 0.5 mV white noise, 50 Hz, 2 runs of +-10/50/100 deg/s\n\
         time_s,table_rate_dps,gx_v\n",
    );
    for i in 0..log.time.len() {
        let v = null + k * log.true_rate[i] + noise.sample(&mut rng);
        writeln!(text, "{:.2},{:.4},{:.6}", log.time[i], log.logged_rate[i], v)?;
    }
    std::fs::write(&out, text)?;
    Ok(())
}
