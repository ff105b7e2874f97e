//! Speed of simulating and writing a static record.
//!
//! Usage: `cargo run --release -p gyrolab-io --example sim_speed -- [SAMPLES] [PRESET] [MODE] [pipelined] > /dev/null`
//! SAMPLES defaults to 10 000 000, PRESET to adxrs646; MODE is `shortest` (default), `fixedN`
//! (N decimals, such as `fixed7`) or `generate` (simulate only, write nothing); a 4th argument `pipelined` simulates
//! on a second thread while the first formats. The record (100 Hz) goes to stdout; the timing goes
//! to stderr.

use std::io::Write;
use std::time::Instant;

use gyrolab::sim::{Preset, SensorModel, StaticBlock, StaticGenerator, StaticSpec};
use gyrolab_io::sim_csv::{write_static_csv, NumberFormat, SimCsvOptions};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let samples: u64 = args.first().map_or(Ok(10_000_000), |s| s.parse())?;
    let preset_name = args.get(1).map_or("adxrs646", String::as_str);
    let preset = Preset::parse(preset_name).ok_or_else(|| format!("unknown preset {preset_name}"))?;
    let mode = args.get(2).map_or("shortest", String::as_str);
    let model = SensorModel::preset(preset);
    let spec = StaticSpec { sample_rate_hz: 100.0, duration_s: samples as f64 / 100.0, ..StaticSpec::default() };
    let start = Instant::now();
    let (rows, bytes) = if mode == "generate" {
        let mut generator = StaticGenerator::new(&model, &spec, 1)?;
        let mut block = StaticBlock::default();
        let mut n = 0u64;
        while generator.next_block(&mut block, 8192) > 0 {
            std::hint::black_box(&block);
            n += block.len() as u64;
        }
        (n, 0)
    } else {
        let number_format = match mode.strip_prefix("fixed").map(str::parse::<u8>) {
            Some(Ok(decimals)) => NumberFormat::Fixed { decimals },
            _ => NumberFormat::Shortest,
        };
        let pipelined = args.get(3).is_some_and(|s| s == "pipelined");
        let options = SimCsvOptions { number_format, comments: vec![format!("preset = {preset_name}")], pipelined };
        let stdout = std::io::stdout();
        let sum = write_static_csv(stdout, &model, &spec, 1, &options)?;
        (sum.rows, sum.bytes)
    };
    let secs = start.elapsed().as_secs_f64();
    let mut err = std::io::stderr().lock();
    writeln!(
        err,
        "{preset_name} {mode}: {rows} samples, {:.1} MB in {secs:.3} s: {:.2} M samples/s, {:.1} MB/s",
        bytes as f64 / 1e6,
        rows as f64 / secs / 1e6,
        bytes as f64 / secs / 1e6
    )?;
    Ok(())
}
