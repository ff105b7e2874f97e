//! Measures the time-series reader: writes a synthetic `time_s,output_v` file (10 M lines by
//! default, or the count given as the first argument) into a temporary folder, then reads it back
//! (parse only) and runs the static test on it (parse + figures + outlier pass), reporting MB/s
//! and rows/s per second of CPU time of the reading thread (wall time where that is unavailable). Run with `cargo run --release -p gyrolab-eval --example series_speed [-- LINES]`.

use gyrolab::static_test::StaticTestConfig;
use gyrolab_eval::static_test::evaluate_static_file;
use gyrolab_io::series::{read_series, SeriesOptions};
use std::io::Write;
use std::time::Instant;

/// On-CPU time of this thread in seconds (Linux `/proc/thread-self/schedstat`), so that the
/// figures are not diluted by other processes sharing the cores; `None` elsewhere.
fn cpu_seconds() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    s.split_whitespace().next()?.parse::<f64>().ok().map(|ns| ns * 1e-9)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let lines: u64 = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(10_000_000);
    let dir = tempfile::tempdir()?;
    let path = dir.path().join("static.csv");
    {
        let mut w = std::io::BufWriter::with_capacity(1 << 20, std::fs::File::create(&path)?);
        writeln!(w, "# synthetic static record, 100 Hz")?;
        writeln!(w, "time_s,output_v")?;
        // A cheap deterministic pseudo-noise (linear congruential), 1e-4 V around 2.5 V.
        let mut s: u64 = 12345;
        for i in 0..lines {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            let noise = ((s >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 3.4e-4;
            writeln!(w, "{:.2},{:.7}", i as f64 * 0.01, 2.5 + noise)?;
        }
        w.flush()?;
    }
    let bytes = std::fs::metadata(&path)?.len() as f64;
    let opts = SeriesOptions::default();

    let (t, c) = (Instant::now(), cpu_seconds());
    let mut sum = 0.0;
    let summary = read_series(&path, &opts, |_, b| {
        sum += b.channels[0].iter().sum::<f64>();
        Ok(())
    })?;
    let s = cpu_seconds().zip(c).map_or(t.elapsed().as_secs_f64(), |(b, a)| b - a);
    println!(
        "read only : {} rows, {:.1} MB in {:.3} s CPU: {:.0} MB/s, {:.1} M rows/s (checksum {:.3})",
        summary.rows,
        bytes / 1e6,
        s,
        bytes / 1e6 / s,
        summary.rows as f64 / 1e6 / s,
        sum / summary.rows as f64
    );

    let (t, c) = (Instant::now(), cpu_seconds());
    let (results, summary) = evaluate_static_file(&path, &opts, |_| StaticTestConfig::default())?;
    let s = cpu_seconds().zip(c).map_or(t.elapsed().as_secs_f64(), |(b, a)| b - a);
    println!(
        "bias (one pass unless outliers are possible): {:.3} s CPU: {:.0} MB/s, {:.1} M rows/s; mean {:.7} V, B_s(1 s) {:?} V",
        s,
        bytes / 1e6 / s,
        summary.rows as f64 / 1e6 / s,
        results[0].mean_output,
        results[0].stability_at(1.0).map(|b| b.output)
    );
    Ok(())
}
