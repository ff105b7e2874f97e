//! Bench helper of bench/store_speed.sh (not a test, not part of the library): fills a store
//! with N evaluations made from one finished report folder, each a device of its own (serials
//! `BENCH-00000`, ...; lot `BENCH`), its figure values scattered by up to ±1 % (a fixed
//! xorshift sequence, so every run stores the same values), each stored by `Store::add` in its
//! own transaction as `gyrolab eval --store` does. Every 20th device also gets two corrections,
//! so that histories have revisions.
//!
//!   cargo run --release -p gyrolab-store --example store_fill -- STORE N REPORT_DIR PLAN

use gyrolab_store::record::from_report_folder;
use gyrolab_store::{Changes, Revision, RevisionKind, Store};
use std::io::IsTerminal;
use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 5 {
        eprintln!("usage: store_fill STORE N REPORT_DIR PLAN");
        std::process::exit(2);
    }
    let n: usize = args[2].parse()?;
    let base = from_report_folder(Path::new(&args[3]), Some(Path::new(&args[4])))?;
    let mut store = Store::open(&args[1], true)?;
    let progress = std::io::stderr().is_terminal();
    let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
    let started = std::time::Instant::now();
    for i in 0..n {
        let mut r = base.clone();
        r.serial = format!("BENCH-{i:05}");
        r.lot = Some("BENCH".into());
        r.test_date = Some(format!("2026-{:02}-{:02}", 1 + i % 12, 1 + i % 28));
        for f in &mut r.figures {
            if let Some(v) = f.value.as_mut() {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                let u = (state >> 11) as f64 / (1u64 << 53) as f64;
                *v *= 1.0 + 0.02 * (u - 0.5);
            }
        }
        let mut id = store.add(&r)?;
        if i % 20 == 0 {
            for k in 0..2 {
                let rev = Revision {
                    supersedes: id,
                    kind: RevisionKind::Correction,
                    by: "bench".into(),
                    reason: format!("correction {k}"),
                };
                let changes = Changes { operator: Some(format!("operator {k}")), ..Changes::default() };
                id = store.revise(&rev, &changes, None)?;
            }
        }
        if progress && (i + 1) % 500 == 0 {
            eprint!("\rstore_fill: {} of {n} evaluations", i + 1);
        }
    }
    if progress {
        eprintln!();
    }
    eprintln!("store_fill: {n} evaluations in {:.1} s into {}", started.elapsed().as_secs_f64(), store.name());
    Ok(())
}
