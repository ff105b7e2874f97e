//! Speed of gyrolab's file writer alone: the output side of `gyrolab simulate ... --out FILE`
//! with nothing to compute.
//!
//! Usage: `cargo run --release -p gyrolab-io --example write_speed -- SOURCE OUT BYTES`
//! Writes BYTES bytes into OUT through `write_atomic_with` (temporary file, write-back started
//! every 32 MiB, fsync, rename), in writes of 204 800 bytes (a block of 8192 rows of 25 bytes, as
//! the simulator writes), repeating the first 1.6 MB of SOURCE (read before the clock starts; as
//! many bytes as the simulator's text buffers, which it reuses).
//! The timing goes to stderr.

use std::io::Read;
use std::time::Instant;

/// Bytes per write.
const WRITE_BYTES: usize = 8192 * 25;
/// Bytes read from the source and repeated: eight writes.
const SOURCE_BYTES: u64 = 8 * WRITE_BYTES as u64;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [source, out, bytes] = args.as_slice() else {
        return Err("usage: write_speed SOURCE OUT BYTES".into());
    };
    let total: u64 = bytes.parse()?;
    let mut text = Vec::new();
    std::fs::File::open(source)?.take(SOURCE_BYTES).read_to_end(&mut text)?;
    if text.len() < WRITE_BYTES {
        return Err(format!("{source}: fewer than {WRITE_BYTES} bytes").into());
    }
    let start = Instant::now();
    gyrolab_io::atomic::write_atomic_with(std::path::Path::new(out), |w| {
        let mut left = total;
        while left > 0 {
            for block in text.chunks_exact(WRITE_BYTES) {
                let n = usize::try_from(left).map_or(block.len(), |l| l.min(block.len()));
                w.write_all(&block[..n])?;
                left -= n as u64;
                if left == 0 {
                    break;
                }
            }
        }
        Ok(())
    })?;
    let secs = start.elapsed().as_secs_f64();
    eprintln!("write_speed: {:.1} MB in {secs:.3} s: {:.1} MB/s", total as f64 / 1e6, total as f64 / secs / 1e6);
    Ok(())
}
