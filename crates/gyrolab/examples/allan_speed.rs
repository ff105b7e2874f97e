//! Speed of the Allan-variance family on synthetic white rate noise.
//! Run: `cargo run --release -p gyrolab --example allan_speed`
use gyrolab::allan::{deviation_from_rate, AllanOptions, DeviationKind, TauList};
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use std::time::Instant;

fn record(n: usize) -> Vec<f64> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    let mut v = Vec::with_capacity(n + 1);
    v.extend((0..n).map(|_| {
        let z: f64 = StandardNormal.sample(&mut rng);
        2.5 + 1e-3 * z
    }));
    v
}

fn peak_rss_mb() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| s.lines().find(|l| l.starts_with("VmHWM")).map(|l| l.to_string()))
        .and_then(|l| l.split_whitespace().nth(1).and_then(|v| v.parse::<f64>().ok()))
        .map_or(f64::NAN, |kb| kb / 1024.0)
}

fn time(label: &str, n: usize, opts: &AllanOptions) {
    let data = record(n);
    let t = Instant::now();
    let curve = deviation_from_rate(data, 0.01, opts).expect("synthetic record is valid");
    let dt = t.elapsed();
    println!(
        "{label}: {} taus in {:.1} ms (peak RSS so far {:.0} MB; record {:.0} MB)",
        curve.points.len(),
        dt.as_secs_f64() * 1e3,
        peak_rss_mb(),
        n as f64 * 8.0 / 1048576.0
    );
}

fn main() {
    let oct = AllanOptions::new(DeviationKind::Oadev).with_confidence(None);
    time("10M OADEV octave, no CI", 10_000_000, &oct);
    time("10M OADEV octave, no CI (again)", 10_000_000, &oct);
    time("10M OADEV octave, 68.3% CI", 10_000_000, &oct.clone().with_confidence(Some(0.683)));
    for kind in [DeviationKind::Mdev, DeviationKind::Ohdev, DeviationKind::Totdev] {
        time(&format!("10M {} octave, no CI", kind.name()), 10_000_000, &AllanOptions::new(kind).with_confidence(None));
    }
    time("1M OADEV all taus (m <= N/4), no CI", 1_000_000, &oct.clone().with_taus(TauList::All));
}
