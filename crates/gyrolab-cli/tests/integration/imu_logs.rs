//! Real IMU logs through `gyrolab allan` (issue 16): ROS-style exports, Kalibr's imu0.csv,
//! headerless files, standard input, accelerometer channels, Kalibr and imu_utils YAML.
//! Truth is simulated white noise of known density; hand conversions are in the comments.

use crate::common;
use common::{gyrolab, write};
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};

/// Gyro white noise N = 0.3 deg/sqrt(h) = 0.005 deg/sqrt(s) = 8.7266e-5 rad/s/sqrt(Hz).
const GYRO_ND: f64 = 0.005 * std::f64::consts::PI / 180.0;
/// Accelerometer white noise VRW = 0.05 m/s/sqrt(h) = 8.3333e-4 m/s^2/sqrt(Hz).
const ACCEL_ND: f64 = 0.05 / 60.0;

/// Rows of a six-channel IMU at `rate_hz` for `seconds`: stamps in ns (jittered by up to
/// +-`jitter` of the interval), gyro in rad/s, accel in m/s^2 (z carries 9.81), rows in `drop`
/// left out.
fn imu_rows(seed: u64, rate_hz: f64, seconds: f64, jitter: f64, drop: &[usize]) -> Vec<(i64, [f64; 6])> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let n = (rate_hz * seconds) as usize;
    let (sg, sa) = (GYRO_ND * rate_hz.sqrt(), ACCEL_ND * rate_hz.sqrt());
    let mut rows = Vec::with_capacity(n);
    for i in 0..n {
        let u: f64 = StandardNormal.sample(&mut rng);
        let j = (u.clamp(-1.0, 1.0)) * jitter / rate_hz;
        let t = 1_700_000_000_000_000_000i64 + ((i as f64 / rate_hz + j) * 1e9).round() as i64;
        let mut v = [0.0; 6];
        for (k, x) in v.iter_mut().enumerate() {
            let z: f64 = StandardNormal.sample(&mut rng);
            *x = z * if k < 3 { sg } else { sa } + if k == 5 { 9.81 } else { 0.0 };
        }
        if !drop.contains(&i) {
            rows.push((t, v));
        }
    }
    rows
}

fn kalibr_csv(rows: &[(i64, [f64; 6])]) -> String {
    let mut s = String::from(
        "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n",
    );
    for (t, v) in rows {
        s.push_str(&format!("{t},{:.7e},{:.7e},{:.7e},{:.7e},{:.7e},{:.7e}\n", v[0], v[1], v[2], v[3], v[4], v[5]));
    }
    s
}

fn yaml_entry(y: &str, key: &str) -> f64 {
    let line = y.lines().find(|l| l.starts_with(&format!("{key}:"))).unwrap_or_else(|| panic!("no {key} in {y}"));
    line.split(':').nth(1).unwrap().split('#').next().unwrap().trim().parse().unwrap()
}

fn rel(a: f64, b: f64) -> f64 {
    (a / b - 1.0).abs()
}

#[test]
fn kalibr_imu0_csv_gives_a_complete_kalibr_and_imu_utils_yaml() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "imu0.csv", &kalibr_csv(&imu_rows(7, 200.0, 1200.0, 0.0, &[])));
    let (ky, iy) = (dir.path().join("imu.yaml"), dir.path().join("iu.yaml"));
    let out = gyrolab()
        .arg("allan")
        .arg(&p)
        .arg("--kalibr-yaml")
        .arg(&ky)
        .arg("--imu-utils-yaml")
        .arg(&iy)
        .arg("--json")
        .assert()
        .success()
        .get_output()
        .clone();
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let ch = v["channels"].as_array().unwrap();
    assert_eq!(ch.len(), 6);
    assert_eq!(ch[0]["quantity"], "angular_rate");
    assert_eq!(ch[3]["quantity"], "acceleration");
    assert_eq!(ch[3]["dev_unit"], "m/s^2");
    // VRW in m/s/sqrt(h) = 60 x the density in m/s/sqrt(s).
    let vrw = ch[4]["accel_noise"]["vrw_m_s_rt_h"].as_f64().unwrap();
    assert!(rel(vrw, 0.05) < 0.05, "{vrw}");
    assert!(ch[4]["noise"].is_null());
    let y = std::fs::read_to_string(&ky).unwrap();
    assert!(rel(yaml_entry(&y, "gyroscope_noise_density"), GYRO_ND) < 0.05, "{y}");
    assert!(rel(yaml_entry(&y, "accelerometer_noise_density"), ACCEL_ND) < 0.05, "{y}");
    assert!(yaml_entry(&y, "gyroscope_random_walk") > 0.0 && yaml_entry(&y, "accelerometer_random_walk") > 0.0);
    assert_eq!(yaml_entry(&y, "update_rate"), 200.0);
    assert!(y.contains("rostopic: "), "{y}");
    let u = std::fs::read_to_string(&iy).unwrap();
    assert!(u.starts_with("%YAML:1.0"), "{u}");
    for k in ["gyr_n", "gyr_w", "acc_n", "acc_w"] {
        assert!(yaml_entry(&u, k) > 0.0, "{k}: {u}");
    }
    assert_eq!(yaml_entry(&u, "acc_n"), yaml_entry(&y, "accelerometer_noise_density"));
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(stderr.contains("warning: Kalibr gyroscope_random_walk is upper_bound"), "{stderr}");
}

#[test]
fn ros_export_needs_units_and_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let rows = imu_rows(3, 100.0, 200.0, 0.0, &[]);
    let mut text = String::from("time,gx,gy,gz,ax,ay,az\n");
    for (t, v) in &rows {
        let ts = (*t - 1_700_000_000_000_000_000) as f64 * 1e-9;
        text.push_str(&format!("{ts:.5},{},{},{},{},{},{}\n", v[0], v[1], v[2], v[3], v[4], v[5]));
    }
    let p = write(dir.path(), "ros.csv", &text);
    let out = gyrolab().arg("allan").arg(&p).arg("--json").assert().success().get_output().clone();
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(stderr.contains("note: no unit for gx, gy, gz, ax, ay, az"), "{stderr}");
    assert!(stderr.contains("--unit gx=rad/s"), "{stderr}");
    assert!(stderr.contains("note: time column 'time' read in s"), "{stderr}");
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["channels"][0]["quantity"], "unitless");
    assert!(v["channels"][0]["noise"].is_null());
    // With a default unit per quantity: gyro terms in deg units, accelerometer terms in m/s.
    let out = gyrolab()
        .arg("allan")
        .arg(&p)
        .args(["--unit", "rad/s", "--unit", "m/s^2", "--json"])
        .assert()
        .success()
        .get_output()
        .stdout
        .clone();
    let v: serde_json::Value = serde_json::from_slice(&out).unwrap();
    let ch = v["channels"].as_array().unwrap();
    let n = ch[1]["noise"]["arw_deg_rt_h"].as_f64().unwrap();
    assert!(rel(n, 0.3) < 0.1, "{n}");
    assert!(ch[5]["accel_noise"]["vrw_m_s_rt_h"].as_f64().is_some());
    // The same accelerometer column in g: deviations scale by 1/9.80665 on reading, and are
    // reported back in m/s^2, so they are the same.
    let dev_ms2 = ch[3]["dev"][0].as_f64().unwrap();
    let g_text: String = text
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i == 0 {
                "time,gx,gy,gz,ax_g,ay,az\n".to_string()
            } else {
                let mut f: Vec<String> = l.split(',').map(str::to_string).collect();
                f[4] = format!("{:e}", f[4].parse::<f64>().unwrap() / 9.806_65);
                f.join(",") + "\n"
            }
        })
        .collect();
    let pg = write(dir.path(), "ros_g.csv", &g_text);
    let out = gyrolab()
        .arg("allan")
        .arg(&pg)
        .args(["--column", "ax", "--json"])
        .assert()
        .success()
        .get_output()
        .stdout
        .clone();
    let v: serde_json::Value = serde_json::from_slice(&out).unwrap();
    assert!(rel(v["dev"][0].as_f64().unwrap(), dev_ms2) < 1e-6);
}

#[test]
fn headerless_file_and_standard_input() {
    let dir = tempfile::tempdir().unwrap();
    let rows = imu_rows(5, 100.0, 100.0, 0.0, &[]);
    let text: String = rows.iter().map(|(_, v)| format!("{:e}\n", v[0])).collect();
    let p = write(dir.path(), "one.txt", &text);
    let a = gyrolab()
        .arg("allan")
        .arg(&p)
        .args(["--sample-rate-hz", "100", "--unit", "rad/s", "--json"])
        .assert()
        .success()
        .get_output()
        .stdout
        .clone();
    let b = gyrolab()
        .arg("allan")
        .arg("-")
        .args(["--sample-rate-hz", "100", "--unit", "rad/s", "--json"])
        .write_stdin(text.clone())
        .assert()
        .success()
        .get_output()
        .stdout
        .clone();
    let (va, vb): (serde_json::Value, serde_json::Value) =
        (serde_json::from_slice(&a).unwrap(), serde_json::from_slice(&b).unwrap());
    assert_eq!(va["channel"], "c1");
    assert_eq!(va["dev"], vb["dev"]);
    // Named columns of a headerless file, one of them the time.
    let text: String = rows.iter().map(|(t, v)| format!("{} {:e}\n", *t as f64 * 1e-9, v[1])).collect();
    let p = write(dir.path(), "two.txt", &text);
    gyrolab().arg("allan").arg(&p).args(["--names", "t,gy", "--unit", "gy=rad/s"]).assert().success();
}

/// The case: 2 h at 200 Hz, six channels, jittered stamps, a dozen dropped samples,
/// through `gyrolab allan FILE --kalibr-yaml imu.yaml` with no other option.
#[test]
fn two_hours_with_jitter_and_dropped_samples_give_truth_and_a_complete_yaml() {
    let dir = tempfile::tempdir().unwrap();
    let drops: Vec<usize> = (0..12).map(|k| 40_000 + k * 117_000).collect();
    let rows = imu_rows(21, 200.0, 7200.0, 0.3, &drops);
    let p = write(dir.path(), "imu0.csv", &kalibr_csv(&rows));
    let yaml = dir.path().join("imu.yaml");
    let out = gyrolab()
        .arg("allan")
        .arg(&p)
        .arg("--kalibr-yaml")
        .arg(&yaml)
        .arg("--json")
        .assert()
        .success()
        .get_output()
        .clone();
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(stderr.contains("note: 12 gap(s) in the time stamps, 12 sample(s) missing"), "{stderr}");
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let ch = v["channels"].as_array().unwrap();
    for c in &ch[..3] {
        let n = c["noise"]["arw_deg_rt_h"].as_f64().unwrap();
        assert!(rel(n, 0.3) < 0.03, "N {n}");
        // 1 440 000 slots, 12 missing, each filled by the default --gaps fill: m = 1 has every
        // pair of neighbours.
        assert_eq!(c["samples"], 1_440_000);
        assert_eq!(c["n_terms"][0], 1_440_000 - 1);
    }
    for c in &ch[3..] {
        let vrw = c["accel_noise"]["vrw_m_s_rt_h"].as_f64().unwrap();
        assert!(rel(vrw, 0.05) < 0.03, "VRW {vrw}");
    }
    let y = std::fs::read_to_string(&yaml).unwrap();
    for k in [
        "gyroscope_noise_density",
        "gyroscope_random_walk",
        "accelerometer_noise_density",
        "accelerometer_random_walk",
        "update_rate",
    ] {
        assert!(yaml_entry(&y, k) > 0.0, "{k}\n{y}");
    }
    assert!((yaml_entry(&y, "update_rate") - 200.0).abs() < 0.01, "{y}");
    // The same file with --gaps error is refused at the first gap's line (header on line 1).
    let e = gyrolab().arg("allan").arg(&p).args(["--gaps", "error"]).assert().code(2).get_output().stderr.clone();
    let e = String::from_utf8(e).unwrap();
    assert!(e.contains(&format!(":{}:", drops[0] + 2)) && e.contains("gap"), "{e}");
}

/// Dropout rows and NaN cells are missing samples: the deviations equal those of the record
/// with those rows left out of every term (computed here directly for m = 1).
#[test]
fn dropouts_and_nan_cells_are_missing_samples() {
    let dir = tempfile::tempdir().unwrap();
    let mut rows = imu_rows(8, 100.0, 300.0, 0.0, &[]);
    let zero_rows: Vec<usize> = (0..30).map(|k| 1_000 + k).chain((0..30).map(|k| 9_000 + k)).collect();
    for &r in &zero_rows {
        rows[r].1 = [0.0; 6];
    }
    let mut text = kalibr_csv(&rows);
    // A NaN cell in the gyro x column of row 20 000 (line 20 002).
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let mut f: Vec<String> = lines[20_001].split(',').map(str::to_string).collect();
    f[1] = "nan".into();
    lines[20_001] = f.join(",");
    text = lines.join("\n") + "\n";
    let p = write(dir.path(), "drop.csv", &text);
    let out = gyrolab()
        .arg("allan")
        .arg(&p)
        .args(["--json", "--taus", "0.01", "--confidence", "none", "--gaps", "analyse"])
        .assert()
        .success()
        .get_output()
        .clone();
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(stderr.contains("60 dropout row(s) (60 with every channel zero"), "{stderr}");
    assert!(stderr.contains("1 NaN or empty cell(s), first at line 20002"), "{stderr}");
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    // Direct OADEV at m = 1 of gyro x in deg/s over neighbours that are both present.
    let x: Vec<Option<f64>> = rows
        .iter()
        .enumerate()
        .map(|(i, r)| if zero_rows.contains(&i) || i == 20_000 { None } else { Some(r.1[0].to_degrees()) })
        .collect();
    let (mut sum, mut terms) = (0.0, 0usize);
    for w in x.windows(2) {
        if let (Some(a), Some(b)) = (w[0], w[1]) {
            sum += (b - a) * (b - a);
            terms += 1;
        }
    }
    let direct = (sum / (2.0 * terms as f64)).sqrt();
    assert_eq!(v["channels"][0]["n_terms"][0], terms);
    assert!(
        rel(v["channels"][0]["dev"][0].as_f64().unwrap(), direct) < 1e-6,
        "{} vs {direct}",
        v["channels"][0]["dev"][0]
    );
}

/// An MPU6050 log as a PC records it: host stamps in USB bursts (about 100.3 Hz on average,
/// 0.9 ms apart inside a burst), six LSB channels, 720 all-zero dropout rows. `gyrolab bias`
/// finds the true rate (its 1 s and 10 s stabilities are there) and leaves the dropouts out of
/// the mean: the bias equals the mean of the other rows (computed here).
#[test]
fn mpu6050_bursty_log_with_dropouts() {
    use rand::Rng;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let (rate, n) = (100.3, 60_000usize);
    let mut text = String::from("time_s,gx_lsb,gy_lsb,gz_lsb,ax_lsb,ay_lsb,az_lsb\n");
    let mut last = f64::NEG_INFINITY;
    let mut gx_sum = 0.0;
    let mut kept = 0usize;
    for i in 0..n {
        let frame = (i as f64 / rate / 0.02).ceil() * 0.02 + 0.005 * rng.gen::<f64>();
        let t = frame.max(last + 0.0009);
        last = t;
        let dropout = (10_000..10_720).contains(&i);
        let v: [i64; 6] =
            if dropout { [0; 6] } else { [-40, 12, 7, 120, -300, 16_384].map(|b| b + rng.gen_range(-20..=20)) };
        if !dropout {
            gx_sum += v[0] as f64;
            kept += 1;
        }
        text.push_str(&format!("{t:.4},{},{},{},{},{},{}\n", v[0], v[1], v[2], v[3], v[4], v[5]));
    }
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "mpu.csv", &text);
    let out = gyrolab().arg("bias").arg(&p).arg("--json").assert().success().get_output().clone();
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(stderr.contains("720 dropout row(s)") && stderr.contains("mpu.csv:10002"), "{stderr}");
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let t = &v["tests"][0];
    let hz = t["sample_rate_hz"].as_f64().unwrap();
    assert!((hz / rate - 1.0).abs() < 0.005, "{hz} Hz");
    let mean = t["mean_output"].as_f64().unwrap();
    assert!((mean - gx_sum / kept as f64).abs() < 1e-9, "{mean} vs {}", gx_sum / kept as f64);
}

/// One clock model in every command (issue 54): an MPU6050 logger's CSV (millisecond stamps,
/// 100 Hz, 6,280 rows) ending with 720 rows of zeros, the stamps included. `inspect`, `allan`
/// and `bias` each end the record before the trailer with the same words, read 100 Hz and
/// 6,280 samples; none refuses it.
#[test]
fn a_zero_trailer_ends_the_record_in_every_command() {
    let dir = tempfile::tempdir().unwrap();
    let mut text = String::from("timestamp_ms,gx_dps,gy_dps,gz_dps,ax_g,ay_g,az_g\n");
    let mut x: u64 = 11;
    let mut noise = || {
        x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (x >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    for i in 0..6280 {
        let t = 1010 + 10 * i;
        text.push_str(&format!(
            "{t},{:.4},{:.4},{:.4},{:.5},{:.5},{:.5}\n",
            0.1 + 0.1 * noise(),
            -0.2 + 0.1 * noise(),
            0.05 + 0.1 * noise(),
            0.004 * noise(),
            0.004 * noise(),
            1.0 + 0.004 * noise()
        ));
    }
    for _ in 0..720 {
        text.push_str("0,0,0,0,0,0,0\n");
    }
    let p = common::write(dir.path(), "mpu.csv", &text);
    let said = "the time stamps go back at line 6282 (from";
    let out = gyrolab().arg("inspect").arg(&p).arg("--json").output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(out.status.success(), "{err}");
    let inv: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(inv["topics"][0]["messages"], 6280, "{inv}");
    assert!((inv["topics"][0]["rate_hz"].as_f64().unwrap() - 100.0).abs() < 1e-6, "{inv}");
    assert!(inv["truncated"].as_str().unwrap().contains(said), "{inv}");
    let out = gyrolab().arg("allan").arg(&p).arg("--json").output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(out.status.success() && err.contains(said), "{err}");
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!((doc["channels"][0]["tau0_s"].as_f64().unwrap() - 0.01).abs() < 1e-12, "{}", doc["channels"][0]["tau0_s"]);
    let out = gyrolab().arg("bias").arg(&p).arg("--json").output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(out.status.success() && err.contains(said), "{err}");
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let test = &doc["tests"][0];
    assert_eq!(test["samples"], 6280, "{test}");
    assert_eq!(test["sample_rate_hz"], 100.0, "{test}");
}

/// Host stamps with single drops (issue 54; the ArDrone bag's pattern): a 50 Hz stream stamped
/// on arrival 0 to 6 ms late, 1.5 % of the samples dropped one at a time, each drop a single
/// 40 ms interval followed by regular ones. `allan`, `bias` and `inspect` all read 50 Hz (to
/// 0.05 %) and count every drop (the samples over the span would say 49.3 Hz); with
/// `--sample-rate-hz 50` the grid is that rate's, the same drops on it.
#[test]
fn single_drops_in_host_stamps_are_counted_by_every_command() {
    use rand::Rng;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(54);
    let (rate, n) = (50.0, 4_600usize);
    let mut text = String::from("time_s,gx_rad_s,gy_rad_s,gz_rad_s\n");
    let (mut dropped, mut last_drop, mut rows) = (0usize, 0usize, 0usize);
    let mut stamps = Vec::new();
    for i in 0..n {
        if i > 40 && i + 40 < n && i - last_drop > 10 && rng.gen::<f64>() < 0.016 {
            dropped += 1;
            last_drop = i;
            continue;
        }
        let t = 1.7e9 + i as f64 / rate + 0.006 * rng.gen::<f64>();
        stamps.push(t);
        let v: [f64; 3] = [rng.gen_range(-0.02..0.02), rng.gen_range(-0.02..0.02), rng.gen_range(-0.02..0.02)];
        text.push_str(&format!("{t:.6},{:.6},{:.6},{:.6}\n", v[0], v[1], v[2]));
        rows += 1;
    }
    assert!(dropped > 40, "{dropped}");
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "host.csv", &text);
    let said = format!("{dropped} sample(s) missing");
    for given in [None, Some("50")] {
        let mut cmd = gyrolab();
        cmd.arg("allan").arg(&p).arg("--json");
        if let Some(f) = given {
            cmd.args(["--sample-rate-hz", f]);
        }
        let out = cmd.output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr).to_string();
        assert!(out.status.success() && err.contains(&said), "{given:?}: {err}");
        let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let tau0 = doc["channels"][0]["tau0_s"].as_f64().unwrap();
        assert!((tau0 * rate - 1.0).abs() < 5e-4, "{given:?}: tau0 {tau0}");
        assert_eq!(doc["channels"][0]["samples"], rows + dropped, "{given:?}");
    }
    let out = gyrolab().arg("bias").arg(&p).arg("--json").output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let hz = doc["tests"][0]["sample_rate_hz"].as_f64().unwrap();
    assert!((hz / rate - 1.0).abs() < 5e-4, "bias: {hz} Hz");
    let out = gyrolab().arg("inspect").arg(&p).arg("--json").output().unwrap();
    let inv: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let hz = inv["topics"][0]["rate_hz"].as_f64().unwrap();
    assert!((hz / rate - 1.0).abs() < 5e-4, "inspect: {hz} Hz");
    assert_eq!(inv["topics"][0]["missing"], dropped, "{inv}");
    let plain = (rows - 1) as f64 / (stamps[rows - 1] - stamps[0]);
    assert!(plain / rate < 0.995, "the samples over the span, {plain} Hz, should show the drops");
}
