//! `gyrolab rate` on raw logs, `gyrolab rate --triad`, and `gyrolab apply`, end to end on
//! simulated logs with known plateaus, scale factors and misalignment angles.
//!
//! Logs: 100 Hz, holds of 10 s (rests 8 s), ramps at 50 deg/s^2 with a 0.5 deg/s overshoot
//! decaying in 0.1 s, table-rate noise 0.01 deg/s, output noise 2 mV (1 sigma) per sample.
//! Tolerances come from the noise: a plateau mean keeps n >= 850 samples (10 s less 1 s settling
//! and the overshoot's margin), so its standard error is 2 mV / sqrt(850) = 69 uV.

use crate::common;
use common::rawsim::csv;
use common::{gyrolab, write};
use gyrolab::rate_test::Stroke;
use gyrolab::segment::SegmentKind;
use gyrolab::sim::{raw_log_setpoints, simulate_raw_log, white_noise, RawLogHold, RawLogProfile, SimulatedRawLog};
use predicates::str::contains;
use std::path::{Path, PathBuf};

const RATES: [f64; 7] = [-300.0, -100.0, -30.0, 0.0, 30.0, 100.0, 300.0];
const SIGMA_U: f64 = 0.002; // V
const K: f64 = 0.0075; // V/(deg/s)
const F0: f64 = 2.5; // V
const SETTLING_S: f64 = 1.0;

/// First data line of a file written by `csv` (a comment, then the header).
const FIRST_DATA_LINE: u64 = 3;

fn single_axis_log(dir: &Path, name: &str, seq: &[(f64, Vec<SegmentKind>)], seed: u64) -> (PathBuf, SimulatedRawLog) {
    let sim = simulate_raw_log(seq, &RawLogProfile::default(), seed).unwrap();
    let e1 = white_noise(sim.time.len(), SIGMA_U, seed + 1).unwrap();
    let e2 = white_noise(sim.time.len(), SIGMA_U * 1e3, seed + 2).unwrap();
    let gx: Vec<f64> = sim.true_rate.iter().zip(&e1).map(|(w, e)| F0 + K * w + e).collect();
    // A second channel in mV with another scale factor and offset.
    let gy: Vec<f64> = sim.true_rate.iter().zip(&e2).map(|(w, e)| 1200.0 + 9.0 * w + e).collect();
    let p = write(dir, name, &csv(&sim, &["gx_v", "gy_mv"], &[gx, gy]));
    (p, sim)
}

fn json(out: &[u8]) -> serde_json::Value {
    serde_json::from_slice(out).unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(out)))
}

fn label_of(row: &[&str]) -> SegmentKind {
    match row[1] {
        "rest_start" => SegmentKind::RestStart,
        "rest_end" => SegmentKind::RestEnd,
        "plateau" => SegmentKind::Plateau {
            run: row[2].parse().unwrap(),
            stroke: if row[3] == "fwd" { Stroke::Forward } else { Stroke::Reverse },
        },
        k => panic!("kind {k}"),
    }
}

/// Segmentation exact: the segments, in order, carry the truth's labels (a turning hold gives
/// two segments, arriving and leaving stroke), each lies inside its hold after the settling
/// time, and the lines point at the samples of its times. K, F0 and F_r of both channels
/// within 5 standard errors.
#[test]
fn raw_log_segmentation_is_exact_and_the_scale_factor_recovered() {
    let dir = tempfile::tempdir().unwrap();
    let (log, sim) = single_axis_log(dir.path(), "sweep.csv", &raw_log_setpoints(&RATES, 2, true, true), 11);
    let seg = dir.path().join("seg.csv");
    let out = gyrolab().arg("rate").arg(&log).arg("--segments-out").arg(&seg).arg("--json").assert().success();
    let v = json(&out.get_output().stdout);

    let text = std::fs::read_to_string(&seg).unwrap();
    let mut rows = text.lines();
    assert_eq!(
        rows.next().unwrap(),
        "index,kind,run,stroke,start_line,end_line,start_time_s,end_time_s,samples,rate_dps"
    );
    let rows: Vec<Vec<&str>> = rows.map(|l| l.split(',').collect()).collect();
    let truth: Vec<(SegmentKind, &RawLogHold)> =
        sim.holds.iter().flat_map(|h| h.labels.iter().map(move |l| (*l, h))).collect();
    assert_eq!(rows.len(), truth.len(), "{text}");
    assert_eq!(rows.len(), 1 + 4 * 7 + 1); // rests + 2 runs x 2 strokes x 7 rates
    for (row, (label, hold)) in rows.iter().zip(&truth) {
        assert_eq!(label_of(row), *label, "{row:?}");
        let (t0, t1): (f64, f64) = (row[6].parse().unwrap(), row[7].parse().unwrap());
        assert!(t0 >= hold.t_start + SETTLING_S - 1e-9 && t1 <= hold.t_end + 0.02, "{row:?} vs {hold:?}");
        // Lines: the time t = i * 0.01 s is on data line i + FIRST_DATA_LINE.
        let l0: u64 = row[4].parse().unwrap();
        assert_eq!(l0, (t0 / 0.01).round() as u64 + FIRST_DATA_LINE, "{row:?}");
        let rate: f64 = row[9].parse().unwrap();
        assert!((rate - hold.rate).abs() < 0.01, "{row:?}");
    }
    let segj = &v["segmentation"][0];
    assert_eq!(segj["runs"], 2);
    assert_eq!(segj["plateaus"], 28);
    assert_eq!(segj["mode"], "automatic");
    assert!(segj["settling_samples_dropped"].as_u64().unwrap() > 0);

    let axes = v["axes"].as_array().unwrap();
    assert_eq!(axes.len(), 2);
    assert_eq!(axes[0]["name"], "gx");
    assert_eq!(axes[0]["layout"], "raw");
    assert_eq!(axes[1]["output_unit"], "mV");
    // K: slope through 7 point means, each of 4 strokes-runs of >= 850 samples:
    // se = 69 uV / 2 / sqrt(sum (rate - mean)^2 = 201800) = 7.7e-8 V/(deg/s).
    let se_k = SIGMA_U / 850f64.sqrt() / 2.0 / 201_800f64.sqrt();
    let k = axes[0]["scale_factor"].as_f64().unwrap();
    assert!((k - K).abs() < 5.0 * se_k, "K = {k}, tolerance {}", 5.0 * se_k);
    let f0 = axes[0]["zero_offset"].as_f64().unwrap();
    assert!((f0 - F0).abs() < 5.0 * SIGMA_U / (28.0f64 * 850.0).sqrt(), "F0 = {f0}");
    assert_eq!(axes[0]["rest_reference_source"], "rest_records");
    let fr = axes[0]["rest_reference"].as_f64().unwrap();
    assert!((fr - F0).abs() < 5.0 * SIGMA_U / 1400f64.sqrt(), "F_r = {fr}");
    let k2 = axes[1]["scale_factor"].as_f64().unwrap();
    // Noise 2 mV on the mV channel: the same standard error in mV.
    assert!((k2 - 9.0).abs() < 5.0 * se_k * 1e3, "K2 = {k2}");

    // The text output carries the segmentation summary.
    gyrolab()
        .arg("rate")
        .arg(&log)
        .assert()
        .success()
        .stdout(contains("Segmentation of"))
        .stdout(contains("run 2 rev: 7 plateaus"));

    // The segment file read back as a manual segmentation gives the same samples, so the same K
    // (to 1e-7: a turning plateau's halves take the whole plateau's mean rate automatically, their
    // own mean rate as manual segments; the two differ by the table-rate noise only).
    let out = gyrolab().arg("rate").arg(&log).arg("--segments").arg(&seg).arg("--json").assert().success();
    let w = json(&out.get_output().stdout);
    assert_eq!(w["segmentation"][0]["mode"], "manual");
    let km = w["axes"][0]["scale_factor"].as_f64().unwrap();
    assert!((km - k).abs() <= 1e-7 * k.abs(), "{km} vs {k}");
}

/// Per-sample rates of an `apply` output: (time, columns by name).
fn read_applied(text: &str) -> (Vec<String>, Vec<Vec<String>>) {
    let mut lines = text.lines();
    let header: Vec<String> = lines.next().unwrap().split(',').map(str::to_string).collect();
    (header, lines.map(|l| l.split(',').map(str::to_string).collect()).collect())
}

/// Calibrate on a raw log, apply the calibration to the same log: on every plateau (after
/// settling) the calibrated rate's mean is the table rate within 5 standard errors (noise 2 mV /
/// K = 0.27 deg/s per sample, / sqrt(n)), plus K's own uncertainty times the rate; the
/// per-sample scatter is the output noise over K. The same output in mV gives the same rates.
#[test]
fn apply_on_the_calibration_record_gives_the_table_rates_back() {
    let dir = tempfile::tempdir().unwrap();
    let (log, sim) = single_axis_log(dir.path(), "cal.csv", &raw_log_setpoints(&RATES, 2, true, true), 31);
    let cal = dir.path().join("cal.toml");
    gyrolab().arg("rate").arg(&log).arg("--cal-out").arg(&cal).assert().success();
    let out = gyrolab()
        .arg("apply")
        .arg("--cal")
        .arg(&cal)
        .arg("--cal-axis")
        .arg("gx")
        .arg(&log)
        .arg("--column")
        .arg("gx_v")
        .assert()
        .success();
    let text = String::from_utf8(out.get_output().stdout.clone()).unwrap();
    let (header, rows) = read_applied(&text);
    assert_eq!(header, ["time_s", "table_rate_dps", "rate_dps", "flag"]);
    assert_eq!(rows.len(), sim.time.len());
    let sigma_rate = SIGMA_U / K;
    let se_k_rel = 5.0 * SIGMA_U / 850f64.sqrt() / 2.0 / 201_800f64.sqrt() / K;
    let mut sq = (0.0, 0usize);
    for h in &sim.holds {
        let idx: Vec<usize> =
            (0..sim.time.len()).filter(|&i| sim.time[i] >= h.t_start + SETTLING_S && sim.time[i] < h.t_end).collect();
        let rates: Vec<f64> = idx.iter().map(|&i| rows[i][2].parse::<f64>().unwrap()).collect();
        let mean = rates.iter().sum::<f64>() / rates.len() as f64;
        let tol = 5.0 * sigma_rate / (rates.len() as f64).sqrt()
            + se_k_rel * h.rate.abs()
            + 5.0 * sigma_rate / 1400f64.sqrt();
        assert!((mean - h.rate).abs() < tol, "hold at {} deg/s: mean {mean}, tolerance {tol}", h.rate);
        for (&i, r) in idx.iter().zip(&rates) {
            sq.0 += (r - sim.true_rate[i]).powi(2);
            sq.1 += 1;
            assert!(rows[i][3] == "ok" || h.rate.abs() == 300.0, "{:?}", rows[i]);
        }
    }
    let rms = (sq.0 / sq.1 as f64).sqrt();
    assert!((rms / sigma_rate - 1.0).abs() < 0.05, "per-sample scatter {rms} deg/s vs noise {sigma_rate}");

    // The same outputs in mV convert; in LSB they do not (exit 2, naming file, line, column).
    let mv: String = std::fs::read_to_string(&log)
        .unwrap()
        .lines()
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            if l.starts_with('#') {
                return format!("{l}\n");
            }
            if f[0] == "time_s" {
                return "time_s,gx_mv\n".into();
            }
            format!("{},{}\n", f[0], f[2].parse::<f64>().unwrap() * 1e3)
        })
        .collect();
    let mv = write(dir.path(), "mv.csv", &mv);
    let out = gyrolab().args(["apply", "--cal-axis", "gx", "--cal"]).arg(&cal).arg(&mv).assert().success();
    let (h2, rows2) = read_applied(&String::from_utf8(out.get_output().stdout.clone()).unwrap());
    assert_eq!(h2, ["time_s", "rate_dps", "flag"]);
    for (a, b) in rows.iter().zip(&rows2).step_by(97) {
        let (x, y): (f64, f64) = (a[2].parse().unwrap(), b[1].parse().unwrap());
        assert!((x - y).abs() < 1e-9, "{x} vs {y}");
    }
    let lsb = write(dir.path(), "lsb.csv", "time_s,gx_lsb\n0,1\n");
    gyrolab()
        .args(["apply", "--cal-axis", "gx", "--cal"])
        .arg(&cal)
        .arg(&lsb)
        .assert()
        .code(2)
        .stderr(contains("lsb.csv:1:2: column 'gx_lsb'"))
        .stderr(contains("do not convert"));

    // --out writes atomically; a bad cell is flagged, not an error.
    let bad = write(dir.path(), "nan.csv", "time_s,gx_v\n0,2.5\n0.01,\n0.02,5.0\n");
    let dest = dir.path().join("out.csv");
    gyrolab()
        .args(["apply", "--cal-axis", "gx", "--cal"])
        .arg(&cal)
        .arg(&bad)
        .arg("--out")
        .arg(&dest)
        .assert()
        .success();
    let (_, r) = read_applied(&std::fs::read_to_string(&dest).unwrap());
    assert_eq!(r[0][2], "ok");
    assert_eq!(r[1][1..], ["NaN", "not_finite"]);
    assert_eq!(r[2][2], "above");
}

/// Misalignment of gyro i towards table axis j, rad, and the triad's scale factors and biases.
const ANGLE: [[f64; 3]; 3] = [[0.0, 3e-3, -2e-3], [4e-3, 0.0, 2.5e-3], [-5e-3, 3.5e-3, 0.0]];
const KT: [f64; 3] = [0.0075, 0.0076, 0.0074];
const BT: [f64; 3] = [2.50, 2.51, 2.49];
const TRIAD_RATES: [f64; 6] = [-300.0, -100.0, -30.0, 30.0, 100.0, 300.0];

fn s_true() -> [[f64; 3]; 3] {
    let mut s = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            s[i][j] = if i == j { KT[i] } else { KT[i] * ANGLE[i][j].tan() };
        }
    }
    s
}

fn triad_log(dir: &Path, axis: usize, seq: &[(f64, Vec<SegmentKind>)], seed: u64) -> (PathBuf, SimulatedRawLog) {
    let sim = simulate_raw_log(seq, &RawLogProfile::default(), seed).unwrap();
    let s = s_true();
    let outs: Vec<Vec<f64>> = (0..3)
        .map(|i| {
            let e = white_noise(sim.time.len(), SIGMA_U, seed * 10 + i as u64).unwrap();
            sim.true_rate.iter().zip(&e).map(|(w, e)| BT[i] + s[i][axis] * w + e).collect()
        })
        .collect();
    let name = format!("turn_{}.csv", ["x", "y", "z"][axis]);
    (write(dir, &name, &csv(&sim, &["gx_v", "gy_v", "gz_v"], &outs)), sim)
}

/// The 3x3 matrix, misalignment angles and biases from three simulated logs (one per table
/// axis, +-30, 100, 300 deg/s, rests at both ends) within 5 standard errors from the noise
/// (S_ij: 69 uV / sqrt(sum of rate_j^2 = 2 x 100900) = 1.5e-7 V/(deg/s); angles: that / K_i =
/// 0.02 mrad, so 0.1 mrad is a 5-sigma bound), then `apply` with the [triad] calibration gives
/// the table rate vector back.
#[test]
fn triad_matrix_angles_recovered_and_applied() {
    let dir = tempfile::tempdir().unwrap();
    let logs: Vec<(PathBuf, SimulatedRawLog)> = (0..3)
        .map(|a| triad_log(dir.path(), a, &raw_log_setpoints(&TRIAD_RATES, 1, true, true), 40 + a as u64))
        .collect();
    let cal = dir.path().join("triad.toml");
    let mut cmd = gyrolab();
    cmd.arg("rate").arg("--json").arg("--cal-out").arg(&cal);
    for (a, (p, _)) in logs.iter().enumerate() {
        cmd.arg("--triad").arg(format!("{}={}", ["x", "y", "z"][a], p.display()));
    }
    let v = json(&cmd.assert().success().get_output().stdout);
    let s = s_true();
    let se_s = SIGMA_U / 850f64.sqrt() / (2.0 * (300f64.powi(2) + 100f64.powi(2) + 30f64.powi(2))).sqrt();
    for i in 0..3 {
        for j in 0..3 {
            let got = v["matrix"][i][j].as_f64().unwrap();
            assert!((got - s[i][j]).abs() < 5.0 * se_s, "S[{i}][{j}] = {got} vs {}", s[i][j]);
            if i != j {
                let mrad = v["misalignment_mrad"][i][j].as_f64().unwrap();
                assert!((mrad - ANGLE[i][j] * 1e3).abs() < 0.1, "angle {i}{j} = {mrad} mrad");
                let pct = v["cross_axis_sensitivity_pct"][i][j].as_f64().unwrap();
                assert!((pct - ANGLE[i][j].tan() * 100.0).abs() < 0.01, "cross-axis {i}{j} = {pct} %");
            }
        }
        let b = v["bias"][i].as_f64().unwrap();
        assert!((b - BT[i]).abs() < 5.0 * SIGMA_U / (39.0f64 * 850.0).sqrt(), "b[{i}] = {b}");
        assert!(v["rms_rate_error_dps"][i].as_f64().unwrap() < 0.05);
    }
    assert_eq!(v["plateaus"], 39);
    assert_eq!(v["output_unit"], "V");
    assert!(std::fs::read_to_string(&cal).unwrap().contains("[triad]"));

    // Text output names the figures.
    let mut cmd = gyrolab();
    cmd.arg("rate");
    for (a, (p, _)) in logs.iter().enumerate() {
        cmd.arg("--triad").arg(format!("{}={}", ["x", "y", "z"][a], p.display()));
    }
    cmd.assert().success().stdout(contains("misalignment mrad")).stdout(contains("cross-axis sensitivity %"));

    // Apply to the y log: rate_y is the table rate, rate_x and rate_z stay at zero, plateau by
    // plateau, within 5 standard errors of the noise (0.27 deg/s / sqrt(n)) plus the matrix's.
    let (ylog, sim) = &logs[1];
    let out = gyrolab().arg("apply").arg("--cal").arg(&cal).arg(ylog).assert().success();
    let (header, rows) = read_applied(&String::from_utf8(out.get_output().stdout.clone()).unwrap());
    assert_eq!(header, ["time_s", "table_rate_dps", "rate_x_dps", "rate_y_dps", "rate_z_dps", "flag"]);
    for h in &sim.holds {
        let idx: Vec<usize> =
            (0..sim.time.len()).filter(|&i| sim.time[i] >= h.t_start + SETTLING_S && sim.time[i] < h.t_end).collect();
        for (c, want) in [(2, 0.0), (3, h.rate), (4, 0.0)] {
            let mean = idx.iter().map(|&i| rows[i][c].parse::<f64>().unwrap()).sum::<f64>() / idx.len() as f64;
            let tol = 5.0 * SIGMA_U / K / (idx.len() as f64).sqrt() + 5.0 * se_s / K * h.rate.abs() + 0.01;
            assert!((mean - want).abs() < tol, "{} at {} deg/s: {mean} vs {want} (tol {tol})", header[c], h.rate);
        }
    }
}

fn assert_exit2(cmd: &mut assert_cmd::Command, needles: &[&str]) {
    let out = cmd.assert().code(2).get_output().stderr.clone();
    let msg = String::from_utf8(out).unwrap();
    for n in needles {
        assert!(msg.contains(n), "missing '{n}' in: {msg}");
    }
    assert!(!msg.contains("panicked"), "{msg}");
}

/// Bad input: each case exits 2 with a message naming the file and, where it is about a
/// sample, its line.
#[test]
fn bad_raw_logs_exit_2_naming_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();

    // A log where the table never holds a rate: a slow continuous ramp.
    let mut s = String::from("time_s,table_rate_dps,gx_v\n");
    for i in 0..3000 {
        let t = i as f64 * 0.01;
        s.push_str(&format!("{t:.2},{:.4},{:.6}\n", 10.0 * t - 100.0, 2.5 + 0.0075 * (10.0 * t - 100.0)));
    }
    let ramp = write(d, "ramp.csv", &s);
    // The longest steady stretch starts at sample 2499 (t = 24.99 s), on line 2501.
    assert_exit2(gyrolab().arg("rate").arg(&ramp), &["ramp.csv:2501:", "no steady plateau"]);

    // Starts at rest, never returns to it.
    let (p, _) = single_axis_log(d, "norest.csv", &raw_log_setpoints(&RATES, 1, true, false), 5);
    assert_exit2(gyrolab().arg("rate").arg(&p), &["norest.csv:", "never returns to rest"]);

    // The second run stops midway: its reverse stroke has 4 of the 7 rates.
    let mut seq = raw_log_setpoints(&RATES, 2, true, false);
    seq.truncate(seq.len() - 3);
    seq.push((0.0, vec![SegmentKind::RestEnd]));
    let (p, _) = single_axis_log(d, "midway.csv", &seq, 6);
    assert_exit2(gyrolab().arg("rate").arg(&p), &["midway.csv:", "run 2 rev stroke stops midway"]);

    // Manual segments that overlap: out of order in the file (the reader), and sharing a sample
    // (the segmentation).
    let (p, _) = single_axis_log(d, "ok.csv", &raw_log_setpoints(&RATES, 1, true, true), 7);
    let seg = write(
        d,
        "seg.csv",
        "start_time_s,end_time_s,kind,run,stroke\n1,5,rest_start,,\n20,28,plateau,1,fwd\n25,30,plateau,1,fwd\n",
    );
    assert_exit2(gyrolab().arg("rate").arg(&p).arg("--segments").arg(&seg), &["seg.csv:4:", "must not overlap"]);
    let seg = write(
        d,
        "seg2.csv",
        "start_time_s,end_time_s,kind,run,stroke\n1,5,rest_start,,\n20,28,plateau,1,fwd\n28,30,plateau,1,fwd\n",
    );
    assert_exit2(gyrolab().arg("rate").arg(&p).arg("--segments").arg(&seg), &["seg2.csv:4:", "overlaps", "ok.csv:"]);

    // A three-axis set without z, and one whose z log turns in one sense only.
    let (x, _) = triad_log(d, 0, &raw_log_setpoints(&TRIAD_RATES, 1, true, true), 1);
    let (y, _) = triad_log(d, 1, &raw_log_setpoints(&TRIAD_RATES, 1, true, true), 2);
    let mut cmd = gyrolab();
    cmd.arg("rate").arg("--triad").arg(format!("x={}", x.display())).arg("--triad").arg(format!("y={}", y.display()));
    assert_exit2(&mut cmd, &["misses the z axis", "turn_x.csv", "turn_y.csv"]);
    let (z, _) = triad_log(d, 2, &raw_log_setpoints(&[30.0, 100.0, 300.0], 1, true, true), 3);
    let mut cmd = gyrolab();
    cmd.arg("rate");
    for (a, p) in [("x", &x), ("y", &y), ("z", &z)] {
        cmd.arg("--triad").arg(format!("{a}={}", p.display()));
    }
    assert_exit2(&mut cmd, &["turn_z.csv", "both senses"]);

    // The malformed-input campaign's triad case (issue 55): a time stamp of the y log that goes
    // back, located at its line of that file.
    let (z, _) = triad_log(d, 2, &raw_log_setpoints(&TRIAD_RATES, 1, true, true), 3);
    let text = std::fs::read_to_string(&y).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let header = lines.iter().position(|l| l.starts_with("time_s")).unwrap();
    let bad = header + 301;
    let mut fields: Vec<String> = lines[bad].split(',').map(String::from).collect();
    fields[0] = "0.5".into();
    lines[bad] = fields.join(",");
    let back = write(d, "back_y.csv", &(lines.join("\n") + "\n"));
    let mut cmd = gyrolab();
    cmd.arg("rate");
    for (a, p) in [("x", &x), ("y", &back), ("z", &z)] {
        cmd.arg("--triad").arg(format!("{a}={}", p.display()));
    }
    assert_exit2(&mut cmd, &[&format!("back_y.csv:{}:", bad + 1), "time"]);
}
