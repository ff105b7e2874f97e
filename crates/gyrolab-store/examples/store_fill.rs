//! Benchmark helper (bench/store_speed.sh): stores N evaluations into a store, each a copy of
//! one real report folder's record with its own serial (`BENCH-00001`...), lot `BENCH`, test
//! date and figure values scattered by a fixed pseudo-random sequence (relative 1e-3), one
//! transaction per evaluation as `gyrolab store add` does. Prints the wall time on stderr.
//!
//!   cargo run --release -p gyrolab-store --example store_fill -- STORE N REPORT_DIR PLAN

use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 5 {
        return Err("usage: store_fill STORE N REPORT_DIR PLAN".into());
    }
    let n: usize = args[2].parse()?;
    let base = gyrolab_store::record::from_report_folder(args[3].as_ref(), Some(args[4].as_ref()))?;
    let mut store = gyrolab_store::Store::open(&args[1], true)?;
    let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
    let start = Instant::now();
    for i in 0..n {
        let mut r = base.clone();
        r.serial = format!("BENCH-{i:05}");
        r.lot = Some("BENCH".into());
        r.test_date = Some(format!("2026-{:02}-{:02}", 1 + i % 12, 1 + i % 28));
        for f in &mut r.figures {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            let u = (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            f.value = f.value.map(|v| v * (1.0 + 2e-3 * u));
        }
        store.add(&r)?;
    }
    eprintln!("stored {n} evaluations ({} figures each) in {:.1} s", base.figures.len(), start.elapsed().as_secs_f64());
    Ok(())
}
