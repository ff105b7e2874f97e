//! A SIMULATED six-channel IMU record as CSV on standard output, fast (for
//! bench/long_recording.sh): `long_record HOURS RATE_HZ [SEED]`. Columns time_s, gx/gy/gz in
//! deg/s (white noise 0.01 deg/s a sample plus a random walk), ax/ay/az in m/s^2 (white noise
//! 0.002 m/s^2, 9.81 on z); values with six decimals, written by hand (no float formatting).
//! The first line says SIMULATED.

use std::io::Write;

fn main() -> std::io::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let usage = "usage: long_record HOURS RATE_HZ [SEED]";
    let hours: f64 = args.get(1).and_then(|a| a.parse().ok()).ok_or_else(|| std::io::Error::other(usage))?;
    let rate: u64 = args.get(2).and_then(|a| a.parse().ok()).ok_or_else(|| std::io::Error::other(usage))?;
    let seed: u64 = args.get(3).and_then(|a| a.parse().ok()).unwrap_or(1);
    if rate == 0 || rate > 1_000_000 || !(hours > 0.0 && hours <= 1000.0) {
        return Err(std::io::Error::other(usage));
    }
    let rows = (hours * 3600.0 * rate as f64).round() as u64;
    let mut out = std::io::BufWriter::with_capacity(1 << 20, std::io::stdout().lock());
    writeln!(out, "# SIMULATED by gyrolab-io/examples/long_record.rs: {hours} h at {rate} Hz, seed {seed}")?;
    writeln!(out, "time_s,gx_dps,gy_dps,gz_dps,ax_m_s2,ay_m_s2,az_m_s2")?;
    let mut x = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let mut uniform = move || {
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        (x.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let mut walk = [0.0f64; 3];
    let mut line = Vec::with_capacity(128);
    // Whole digits of the stamp's decimal fraction (3 for 1 kHz, up to 6).
    let decimals = (rate as f64).log10().ceil().clamp(0.0, 6.0) as u32;
    let per = 10u64.pow(decimals);
    for i in 0..rows {
        line.clear();
        // time_s = i / rate exactly in `decimals` decimals when rate divides 10^decimals.
        let t = i * per / rate;
        push_fixed(&mut line, t as i64, decimals);
        for (axis, w) in walk.iter_mut().enumerate() {
            *w += 2e-5 * uniform();
            let v = [0.05, -0.02, 0.01][axis] + 0.0346 * uniform() + *w;
            line.push(b',');
            push_fixed(&mut line, (v * 1e6).round() as i64, 6);
        }
        for axis in 0..3 {
            let v = [0.0, 0.0, 9.81][axis] + 0.0069 * uniform();
            line.push(b',');
            push_fixed(&mut line, (v * 1e6).round() as i64, 6);
        }
        line.push(b'\n');
        out.write_all(&line)?;
    }
    out.flush()
}

/// Appends `v / 10^decimals` with exactly `decimals` decimals.
fn push_fixed(line: &mut Vec<u8>, v: i64, decimals: u32) {
    if v < 0 {
        line.push(b'-');
    }
    let v = v.unsigned_abs();
    let scale = 10u64.pow(decimals);
    let (whole, frac) = (v / scale, v % scale);
    let mut digits = [0u8; 20];
    let mut n = 0;
    let mut w = whole;
    loop {
        digits[n] = b'0' + (w % 10) as u8;
        n += 1;
        w /= 10;
        if w == 0 {
            break;
        }
    }
    line.extend(digits[..n].iter().rev());
    if decimals > 0 {
        line.push(b'.');
        for k in (0..decimals).rev() {
            line.push(b'0' + ((frac / 10u64.pow(k)) % 10) as u8);
        }
    }
}
