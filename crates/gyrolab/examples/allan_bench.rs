//! Benchmark driver for `bench/allan_vs_allantools.sh`: writes a synthetic rate record, or times
//! one deviation computation on a record read from a little-endian f64 file (loading excluded).
//!
//! `allan_bench gen FILE N SEED` writes N samples of white plus random-walk rate noise.
//! `allan_bench run FILE KIND TAUS [ci] [OUT]` prints `compute_s`, `peak_mb` (VmHWM) and `taus`,
//! and writes "m deviation" lines to OUT when given (tau0 = 0.01 s).
use gyrolab::allan::{deviation_from_rate, AllanOptions, DeviationKind, TauList};
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use std::io::{Read, Write};
use std::time::Instant;

fn peak_rss_mb() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| s.lines().find(|l| l.starts_with("VmHWM")).map(|l| l.to_string()))
        .and_then(|l| l.split_whitespace().nth(1).and_then(|v| v.parse::<f64>().ok()))
        .map_or(f64::NAN, |kb| kb / 1024.0)
}

fn generate(path: &str, n: usize, seed: u64) -> std::io::Result<()> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut out = std::io::BufWriter::new(std::fs::File::create(path)?);
    let mut walk = 0.0f64;
    for _ in 0..n {
        let w: f64 = StandardNormal.sample(&mut rng);
        let r: f64 = StandardNormal.sample(&mut rng);
        // 0.5 deg/s offset, white noise 1e-2 deg/s per sample, rate random walk 3e-6 deg/s per sample
        walk += 3e-6 * r;
        out.write_all(&(0.5 + 1e-2 * w + walk).to_le_bytes())?;
    }
    out.flush()
}

/// Reads the record straight into a vector of capacity N + 1 (one copy of the record in memory).
fn load(path: &str) -> std::io::Result<Vec<f64>> {
    let mut file = std::fs::File::open(path)?;
    let n = file.metadata()?.len() as usize / 8;
    let mut v = Vec::with_capacity(n + 1);
    let mut buf = vec![0u8; 1 << 16];
    loop {
        let got = file.read(&mut buf)?;
        if got == 0 {
            break;
        }
        v.extend(buf[..got - got % 8].chunks_exact(8).map(|c| {
            let mut b = [0u8; 8];
            b.copy_from_slice(c);
            f64::from_le_bytes(b)
        }));
        if got % 8 != 0 {
            return Err(std::io::Error::other("unaligned read"));
        }
    }
    Ok(v)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        Some("gen") if args.len() == 4 => generate(&args[1], args[2].parse()?, args[3].parse()?)?,
        Some("run") if args.len() >= 4 => {
            let data = load(&args[1])?;
            let mut opts = AllanOptions::new(DeviationKind::parse(&args[2])?).with_taus(TauList::parse(&args[3])?);
            let ci = args.get(4).is_some_and(|a| a == "ci");
            opts = opts.with_confidence(ci.then_some(0.683));
            let out = args.get(if ci { 5 } else { 4 });
            let t = Instant::now();
            let curve = deviation_from_rate(data, 0.01, &opts)?;
            let dt = t.elapsed().as_secs_f64();
            println!("compute_s {dt:.4}\npeak_mb {:.1}\ntaus {}", peak_rss_mb(), curve.points.len());
            if let Some(path) = out {
                let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
                for p in &curve.points {
                    writeln!(f, "{} {:.17e}", p.m, p.deviation)?;
                }
            }
        }
        _ => {
            eprintln!("usage: allan_bench gen FILE N SEED | allan_bench run FILE KIND TAUS [ci] [OUT]");
            std::process::exit(2);
        }
    }
    Ok(())
}
