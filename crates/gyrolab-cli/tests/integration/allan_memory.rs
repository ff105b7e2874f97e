//! `gyrolab allan --memory` (issue 37 part 2): a CSV streamed under a small ceiling against the
//! same CSV analysed in memory, at every tau of every channel; incomplete records refused when
//! streamed, naming --memory.

use crate::common;
use common::{gyrolab, write};
use serde_json::Value;
use std::path::Path;

/// A 200 Hz, three-channel CSV of `n` rows (time_s, deg/s): white noise on every channel, a
/// random walk and a large offset on the first (xorshift64*; a fixed seed per record).
fn record(n: usize, seed: u64) -> String {
    let mut x = seed | 1;
    let mut next = move || {
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        (x.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let mut walk = 0.0;
    let mut s = String::with_capacity(n * 48);
    s.push_str("time_s,gx_dps,gy_dps,gz_dps\n");
    for i in 0..n {
        walk += 2e-4 * next();
        let (a, b, c) = (250.0 + 0.02 * next() + walk, 0.05 * next(), 0.01 * next());
        s.push_str(&format!("{:.3},{a:.9e},{b:.6e},{c:.6e}\n", i as f64 * 0.005));
    }
    s
}

fn json(file: &Path, args: &[&str]) -> (Value, String) {
    let out = gyrolab().arg("allan").arg(file).args(args).arg("--json").assert().success().get_output().clone();
    (serde_json::from_slice(&out.stdout).unwrap(), String::from_utf8(out.stderr).unwrap())
}

fn nums(v: &Value, key: &str) -> Vec<f64> {
    v[key].as_array().unwrap_or_else(|| panic!("{key}")).iter().map(|x| x.as_f64().unwrap()).collect()
}

/// Streamed under 1 MiB (stride > 1) against in memory, on two seeds: every tau below the
/// full-resolution limit equal to 1e-12 relative (deviation, terms, EDF, bounds) where the head's
/// noise type is the record's; every longer tau inside the in-memory 68.3 % interval, with
/// ceil((N - 2m) / stride) terms and its EDF loss reported, at most stride / m.
#[test]
fn a_streamed_csv_agrees_with_the_in_memory_analysis_at_every_tau() {
    let dir = tempfile::tempdir().unwrap();
    for seed in [1, 2] {
        let p = write(dir.path(), &format!("r{seed}.csv"), &record(300_000, seed));
        let (memory, _) = json(&p, &[]);
        assert_eq!(memory["memory"]["path"], "in_memory");
        let (streamed, stderr) = json(&p, &["--memory", "1MiB"]);
        let info = &streamed["memory"];
        assert_eq!(info["path"], "streaming", "{info}");
        assert!(stderr.contains("streamed") && stderr.contains("--memory"), "{stderr}");
        let stride = info["stride"].as_u64().unwrap() as usize;
        let limit = info["full_resolution_below_m"].as_u64().unwrap() as usize;
        assert!(stride > 1 && limit == 16 * stride, "{info}");
        let (a, b) = (memory["channels"].as_array().unwrap(), streamed["channels"].as_array().unwrap());
        assert_eq!(a.len(), 3);
        assert_eq!(b.len(), 3);
        let mut strided = 0;
        for (c, (x, y)) in a.iter().zip(b).enumerate() {
            let taus = info["channels"][c]["taus"].as_array().unwrap();
            let (mx, my) = (nums(x, "m"), nums(y, "m"));
            assert_eq!(mx, my, "channel {c}: the same taus");
            assert_eq!(x["samples"], y["samples"]);
            let (dx, dy) = (nums(x, "dev"), nums(y, "dev"));
            let (lo, hi) = (nums(x, "ci_low"), nums(x, "ci_high"));
            let (tx, ty) = (nums(x, "n_terms"), nums(y, "n_terms"));
            for i in 0..mx.len() {
                let m = mx[i] as usize;
                let t = &taus[i];
                assert_eq!(t["m"].as_u64().unwrap() as usize, m);
                if m < limit {
                    assert_eq!(t["stride"], 1);
                    assert!(
                        (dy[i] / dx[i] - 1.0).abs() < 1e-12,
                        "seed {seed} channel {c} m {m}: {} vs {}",
                        dy[i],
                        dx[i]
                    );
                    assert_eq!(tx[i], ty[i]);
                    if x["alpha"][i] == y["alpha"][i] {
                        let (ex, ey) = (x["edf"][i].as_f64().unwrap(), y["edf"][i].as_f64().unwrap());
                        assert!((ey / ex - 1.0).abs() < 1e-12, "m {m}");
                        let (hy, ly) = (nums(y, "ci_high")[i], nums(y, "ci_low")[i]);
                        assert!((hy / hi[i] - 1.0).abs() < 1e-12 && (ly / lo[i] - 1.0).abs() < 1e-12, "m {m}");
                    }
                } else {
                    strided += 1;
                    assert_eq!(t["stride"].as_u64().unwrap() as usize, stride);
                    assert!(
                        dy[i] > lo[i] && dy[i] < hi[i],
                        "seed {seed} channel {c} m {m}: {} outside [{}, {}]",
                        dy[i],
                        lo[i],
                        hi[i]
                    );
                    assert_eq!(ty[i] as usize, (tx[i] as usize).div_ceil(stride), "m {m}");
                    // The loss reported is the strided estimator's EDF against the in-memory one
                    // (same noise type): at most stride / m for FM noises (alpha <= 0); angle
                    // (PM) noises, whose overlapping terms are nearly independent, lose more.
                    let loss = t["edf_loss"].as_f64().unwrap();
                    let (ex, ey) = (x["edf"][i].as_f64().unwrap(), y["edf"][i].as_f64().unwrap());
                    let alpha = y["alpha"][i].as_i64().unwrap();
                    assert_eq!(x["alpha"][i], y["alpha"][i], "m {m}");
                    assert!((t["edf_full"].as_f64().unwrap() / ex - 1.0).abs() < 1e-12, "m {m}");
                    assert!((loss - (1.0 - ey / ex)).abs() < 1e-12, "m {m}");
                    let bound = if alpha <= 0 { stride as f64 / m as f64 } else { 1.0 };
                    assert!((-1e-3..=bound).contains(&loss), "seed {seed} channel {c} m {m}: EDF loss {loss} ({t})");
                }
            }
        }
        assert!(strided >= 6, "{strided} strided taus");
        // The text output says which path.
        let out = gyrolab().arg("allan").arg(&p).args(["--memory", "1MiB"]).assert().success().get_output().clone();
        assert!(String::from_utf8(out.stdout).unwrap().contains("memory: "), "text output names the path");
    }
}

/// What the streamed path cannot analyse exactly is refused (exit 2), naming the line and the
/// option that lets the in-memory path take it.
#[test]
fn an_incomplete_record_or_another_estimator_is_refused_when_streamed() {
    let dir = tempfile::tempdir().unwrap();
    let text = record(100_000, 3);
    let mut rows: Vec<&str> = text.lines().collect();
    // A gap: rows 50,000 to 50,009 (lines 50,002 to 50,011) removed.
    rows.drain(50_001..50_011);
    let p = write(dir.path(), "gap.csv", &(rows.join("\n") + "\n"));
    gyrolab().arg("allan").arg(&p).assert().success();
    let e = gyrolab().arg("allan").arg(&p).args(["--memory", "1MiB"]).assert().code(2).get_output().stderr.clone();
    let e = String::from_utf8(e).unwrap();
    assert!(e.contains("gap") && e.contains("--memory") && e.contains(":50002:"), "{e}");
    // An empty cell.
    let mut rows: Vec<String> = text.lines().map(String::from).collect();
    let cells: Vec<&str> = rows[70_000].split(',').collect();
    rows[70_000] = format!("{},,{},{}", cells[0], cells[2], cells[3]);
    let p = write(dir.path(), "cell.csv", &(rows.join("\n") + "\n"));
    let e = gyrolab().arg("allan").arg(&p).args(["--memory", "1MiB"]).assert().code(2).get_output().stderr.clone();
    let e = String::from_utf8(e).unwrap();
    assert!(e.contains(":70001:") && e.contains("--memory"), "{e}");
    // A reset: the stamps of the last 10,000 rows start again from 0 (in memory the record
    // ends before them, with a note; streamed, the estimators took them: refused).
    let mut rows: Vec<String> = text.lines().map(String::from).collect();
    for (k, row) in rows[90_001..].iter_mut().enumerate() {
        let rest = row.split_once(',').unwrap().1.to_string();
        *row = format!("{:.3},{rest}", k as f64 * 0.005);
    }
    let p = write(dir.path(), "reset.csv", &(rows.join("\n") + "\n"));
    let (in_memory, _) = json(&p, &[]);
    assert_eq!(in_memory["samples"], 90_000, "the in-memory record ends before the reset");
    let e = gyrolab().arg("allan").arg(&p).args(["--memory", "1MiB"]).assert().code(2).get_output().stderr.clone();
    let e = String::from_utf8(e).unwrap();
    assert!(e.contains("time stamps go back") && e.contains(":90002:") && e.contains("--memory"), "{e}");
    // MDEV beyond the ceiling; a ceiling that is no size.
    let p = write(dir.path(), "ok.csv", &text);
    let e = gyrolab().arg("allan").arg(&p).args(["--memory", "1MiB", "--kind", "mdev"]).assert().code(2);
    let e = String::from_utf8(e.get_output().stderr.clone()).unwrap();
    assert!(e.contains("octave OADEV only") && e.contains("--memory"), "{e}");
    let e = gyrolab().arg("allan").arg(&p).args(["--memory", "lots"]).assert().code(2);
    let e = String::from_utf8(e.get_output().stderr.clone()).unwrap();
    assert!(e.contains("--memory") && e.contains("1GiB"), "{e}");
}
