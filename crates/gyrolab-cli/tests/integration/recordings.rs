//! Robotics recordings through `gyrolab allan`, `bias`, `inspect` and `convert` (issue 17).
//!
//! The recordings are written by independent writers, not by gyrolab: the PyPI packages
//! `rosbags` (rosbag2 with MCAP storage, ROS 1 bags with bz2/lz4 chunks), `mcap` (zstd and lz4
//! chunks), `pyarrow` (Parquet) and a ULog writer built from the published format
//! specification (scripts/write_recordings.py), all installed into the project's venv by
//! scripts/install-test-deps.sh. The samples come from gyrolab's simulator (known N, B, K per
//! channel); every figure read from a recording must equal, to the last digit for the
//! deviations, the figure of the same numbers read from CSV.

use crate::common;
use common::gyrolab;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// Samples per channel: 1200 s at 100 Hz.
const RATE_HZ: f64 = 100.0;
const SECONDS: f64 = 1200.0;
/// Truth of every channel (gyro in rad/s, accelerometer numbers read as m/s^2): N (deg/sqrt(h),
/// numerically the VRW in m/s/sqrt(h) for the accelerometer), B (deg/h), K (deg/h/sqrt(h)).
const ARW: f64 = 0.3;
const BIAS_INSTABILITY: f64 = 3.0;
const RRW: f64 = 2.0;
const T0_NS: i64 = 1_700_000_000_000_000_000;

struct Fixture {
    dir: PathBuf,
    /// The reference CSV (same numbers, channel names of the topics).
    reference: PathBuf,
    /// Path of the rosbag2 MCAP file.
    ros2_mcap: PathBuf,
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The venv's Python with the writers' packages, or `None` (then the test says loudly that it
/// is skipped, which only GYROLAB_SKIP_PYTHON=1 allows).
fn python() -> Option<PathBuf> {
    let py = root().join(".venv/bin/python");
    let ok = py.exists()
        && std::process::Command::new(&py)
            .args(["-c", "import rosbags, mcap, pyarrow, numpy"])
            .status()
            .is_ok_and(|s| s.success());
    if ok {
        return Some(py);
    }
    if std::env::var("GYROLAB_SKIP_PYTHON").as_deref() == Ok("1") {
        eprintln!(
            "\n*** SKIPPED: recordings test needs .venv with rosbags, mcap, pyarrow (scripts/install-test-deps.sh); GYROLAB_SKIP_PYTHON=1 ***\n"
        );
        return None;
    }
    panic!("the recordings tests need .venv with rosbags, mcap and pyarrow: run scripts/install-test-deps.sh (or set GYROLAB_SKIP_PYTHON=1 to skip them loudly)");
}

/// One simulated channel (the simulator's output numbers).
fn simulate(seed: u64, unit: &str) -> Vec<f64> {
    let out = gyrolab()
        .args(["simulate", "static", "--seed", &seed.to_string(), "--sample-rate-hz", &RATE_HZ.to_string()])
        .args(["--duration-s", &SECONDS.to_string(), "--output-unit", unit])
        .args(["--arw-deg-rt-h", &ARW.to_string(), "--bias-instability-dph", &BIAS_INSTABILITY.to_string()])
        .args(["--rrw-deg-h-rt-h", &RRW.to_string()])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("time"))
        .map(|l| l.split(',').nth(1).unwrap().parse::<f64>().unwrap())
        .collect()
}

fn fixture() -> Option<&'static Fixture> {
    static F: OnceLock<Option<Fixture>> = OnceLock::new();
    F.get_or_init(|| {
        let py = python()?;
        let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("recordings");
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        // Gyro channels in rad/s; accelerometer channels: deg/s numbers read as m/s^2.
        let channels: Vec<Vec<f64>> =
            (0..6).map(|k| simulate(100 + k as u64, if k < 3 { "rad_s" } else { "dps" })).collect();
        let n = channels[0].len();
        let names = "gyro_x_rad_s,gyro_y_rad_s,gyro_z_rad_s,accel_x_m_s2,accel_y_m_s2,accel_z_m_s2";
        let (mut input, mut reference) =
            (String::from("timestamp_ns,gx,gy,gz,ax,ay,az\n"), format!("timestamp_ns,{names}\n"));
        for i in 0..n {
            let row: Vec<String> = channels.iter().map(|c| format!("{:?}", c[i])).collect();
            let line = format!("{},{}\n", T0_NS + i as i64 * 10_000_000, row.join(","));
            input.push_str(&line);
            reference.push_str(&line);
        }
        std::fs::write(dir.join("in.csv"), input).unwrap();
        std::fs::write(dir.join("reference.csv"), reference).unwrap();
        let out = std::process::Command::new(&py)
            .arg(root().join("scripts/write_recordings.py"))
            .arg(dir.join("in.csv"))
            .arg(dir.join("rec"))
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout).to_string();
        assert!(out.status.success(), "write_recordings.py failed: {stdout}{}", String::from_utf8_lossy(&out.stderr));
        let ros2_mcap = stdout
            .lines()
            .find_map(|l| l.strip_prefix("ros2_mcap="))
            .map(|p| PathBuf::from(p.trim()))
            .expect("write_recordings.py names the rosbag2 MCAP file");
        Some(Fixture { reference: dir.join("reference.csv"), dir, ros2_mcap })
    })
    .as_ref()
}

/// `gyrolab allan ARGS --json`: (the document, stderr).
fn allan_json(args: &[&str]) -> (Value, String) {
    let out = gyrolab().arg("allan").args(args).arg("--json").output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(out.status.success(), "allan {args:?}: {err}");
    (serde_json::from_slice(&out.stdout).unwrap(), err)
}

/// The channels of a document, those of `topic` (any topic: `None`).
fn channels<'a>(doc: &'a Value, topic: Option<&str>) -> Vec<&'a Value> {
    doc["channels"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|c| topic.is_none_or(|t| c["topic"].as_str() == Some(t)))
        .collect()
}

fn devs(c: &Value) -> Vec<f64> {
    c["dev"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect()
}

/// The deviations of `got` equal those of `want` to the last digit (`factor` 1), or equal those
/// of `want` times `factor` to a few units in the last place (the deviations of doubled values:
/// the sums of the deviation are not formed in the same order of magnitudes), with the same
/// term counts.
fn assert_same_curves(got: &[&Value], want: &[&Value], factor: f64, what: &str) {
    assert_eq!(got.len(), want.len(), "{what}: channel count");
    for (g, w) in got.iter().zip(want) {
        let scaled: Vec<f64> = devs(w).iter().map(|d| d * factor).collect();
        if factor == 1.0 {
            assert_eq!(devs(g), scaled, "{what}: {} against {}", g["channel"], w["channel"]);
        } else {
            for (a, b) in devs(g).iter().zip(&scaled) {
                assert!((a / b - 1.0).abs() < 1e-14, "{what}: {} against {}: {a} vs {b}", g["channel"], w["channel"]);
            }
        }
        assert_eq!(g["n_terms"], w["n_terms"], "{what}: term counts of {}", g["channel"]);
    }
}

fn reference_doc(f: &Fixture) -> &'static Value {
    static R: OnceLock<Value> = OnceLock::new();
    R.get_or_init(|| allan_json(&[f.reference.to_str().unwrap()]).0)
}

#[test]
fn rosbag2_mcap_topics_equal_the_csv_to_the_last_digit() {
    let Some(f) = fixture() else { return };
    let want = channels(reference_doc(f), None);
    let (doc, err) = allan_json(&[f.ros2_mcap.to_str().unwrap()]);
    assert_same_curves(&channels(&doc, Some("/imu0")), &want, 1.0, "/imu0");
    // /imu1 carries every value times 2: every deviation doubles exactly.
    assert_same_curves(&channels(&doc, Some("/imu1")), &want, 2.0, "/imu1");
    // The temperature topic is no IMU topic: not analysed.
    assert!(channels(&doc, Some("/temperature")).is_empty());
    // Every 50th message of /imu0 was written after its successor: put in order, said so.
    assert!(err.contains("topic /imu0 (sensor_msgs/msg/Imu)"), "{err}");
    assert!(err.contains("out of stamp order in the file and were put in order"), "{err}");
    // The noise terms too (tau0 from exact ns stamps here, from f64 seconds of epoch stamps in
    // the CSV: equal to 1e-6).
    for (g, w) in channels(&doc, Some("/imu0")).iter().zip(&want) {
        for key in ["arw_deg_rt_h", "bias_instability_dph"] {
            let (a, b) = (&g["noise"][key], &w["noise"][key]);
            if let (Some(a), Some(b)) = (a.as_f64(), b.as_f64()) {
                assert!((a / b - 1.0).abs() < 1e-6, "{key}: {a} vs {b}");
            } else {
                assert_eq!(a, b, "{key}");
            }
        }
    }
}

#[test]
fn the_simulated_noise_is_recovered_from_the_recording() {
    let Some(f) = fixture() else { return };
    let (doc, _) = allan_json(&[f.ros2_mcap.to_str().unwrap(), "--topic", "/imu0"]);
    let chans = channels(&doc, Some("/imu0"));
    for c in &chans[..3] {
        let n = c["noise"]["arw_deg_rt_h"].as_f64().unwrap();
        assert!((n / ARW - 1.0).abs() < 0.08, "{}: N = {n}, truth {ARW}", c["channel"]);
    }
    for c in &chans[3..] {
        let vrw = c["accel_noise"]["vrw_m_s_rt_h"].as_f64().unwrap();
        assert!((vrw / ARW - 1.0).abs() < 0.08, "{}: VRW = {vrw}, truth {ARW}", c["channel"]);
    }
}

#[test]
fn mcap_chunks_ros1_bags_and_parquet_equal_the_csv() {
    let Some(f) = fixture() else { return };
    let want = channels(reference_doc(f), None);
    let rec = f.dir.join("rec");
    for file in ["plain_zstd.mcap", "plain_lz4.mcap", "imu_bz2.bag", "imu_lz4.bag", "imu.bag"] {
        let (doc, _) = allan_json(&[rec.join(file).to_str().unwrap(), "--topic", "/imu0"]);
        assert_same_curves(&channels(&doc, Some("/imu0")), &want, 1.0, file);
    }
    let (doc, err) = allan_json(&[rec.join("imu.parquet").to_str().unwrap()]);
    assert_same_curves(&channels(&doc, None), &want, 1.0, "imu.parquet");
    assert!(err.contains("estimated from the time stamps"), "{err}");
    // A null cell: a missing sample, said so with its row.
    let (_, err) = allan_json(&[rec.join("imu_zstd.parquet").to_str().unwrap()]);
    assert!(err.contains("1 NaN or empty cell(s), first at row 11"), "{err}");
}

#[test]
fn ulog_topics_equal_their_csv() {
    let Some(f) = fixture() else { return };
    let rec = f.dir.join("rec");
    // The ULog holds float32 values: compare with the same values widened, read from CSV.
    let text = std::fs::read_to_string(rec.join("imu_f32.csv")).unwrap();
    let names = "timestamp_ns,gyro_x_rad_s,gyro_y_rad_s,gyro_z_rad_s,accel_x_m_s2,accel_y_m_s2,accel_z_m_s2";
    let body = text.split_once('\n').unwrap().1;
    let csv = common::write(&f.dir, "ulog_reference.csv", &format!("{names}\n{body}"));
    let (want_doc, _) = allan_json(&[csv.to_str().unwrap()]);
    let want = channels(&want_doc, None);
    let (doc, err) = allan_json(&[rec.join("imu.ulg").to_str().unwrap()]);
    assert_same_curves(&channels(&doc, Some("sensor_combined")), &want, 1.0, "sensor_combined");
    assert_same_curves(&channels(&doc, Some("sensor_gyro")), &want[..3], 1.0, "sensor_gyro");
    assert!(err.contains("timestamp_sample"), "{err}");
    let out = gyrolab().args(["inspect", rec.join("imu.ulg").to_str().unwrap(), "--json"]).output().unwrap();
    assert!(out.status.success());
    let inv: Value = serde_json::from_slice(&out.stdout).unwrap();
    let topics = inv["topics"].as_array().unwrap();
    let status = topics.iter().find(|t| t["topic"] == "vehicle_status").expect("vehicle_status listed");
    assert_eq!(status["imu"], false);
    let combined = topics.iter().find(|t| t["topic"] == "sensor_combined").unwrap();
    assert_eq!(
        combined["messages"].as_u64().unwrap() as usize,
        want_doc["channels"][0]["samples"].as_u64().unwrap() as usize
    );
}

#[test]
fn kalibr_yaml_per_topic_names_its_rostopic() {
    let Some(f) = fixture() else { return };
    let out_dir = tempfile::tempdir().unwrap();
    let yaml = out_dir.path().join("imu.yaml");
    let out = gyrolab()
        .args(["allan", f.ros2_mcap.to_str().unwrap(), "--kalibr-yaml", yaml.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    for topic in ["imu0", "imu1"] {
        let y = std::fs::read_to_string(out_dir.path().join(format!("imu_{topic}.yaml"))).unwrap();
        assert!(y.contains(&format!("rostopic: /{topic}\n")), "{y}");
        assert!(y.contains("update_rate: 100"), "{y}");
        assert!(y.contains("gyroscope_noise_density:") && y.contains("accelerometer_noise_density:"), "{y}");
    }
    assert!(!yaml.exists(), "one file per topic when there are several");
}

#[test]
fn wrong_topics_and_files_without_imu_data_are_clear_errors() {
    let Some(f) = fixture() else { return };
    let out = gyrolab().args(["allan", f.ros2_mcap.to_str().unwrap(), "--topic", "/imu9"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("topic '/imu9' is not in the file; it has: /imu0 (sensor_msgs/msg/Imu"), "{err}");
    assert!(err.contains("/temperature (sensor_msgs/msg/Temperature"), "{err}");
    let zstd = f.dir.join("rec/plain_zstd.mcap");
    let out = gyrolab().args(["allan", zstd.to_str().unwrap(), "--topic", "/camera/info"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("holds std_msgs/msg/String messages, not IMU data"), "{err}");
    // A recording without IMU topics: the error lists what it has; inspect lists it.
    let py = python().unwrap();
    let no_imu = f.dir.join("no_imu.mcap");
    let script = "import sys\nfrom mcap.writer import Writer\nw = Writer(open(sys.argv[1], 'wb'))\nw.start()\ns = w.register_schema(name='std_msgs/msg/String', encoding='ros2msg', data=b'string data')\nc = w.register_channel(topic='/chatter', message_encoding='cdr', schema_id=s)\nfor i in range(3):\n    w.add_message(channel_id=c, log_time=i, publish_time=i, data=b'\\x00\\x01\\x00\\x00\\x02\\x00\\x00\\x00a\\x00')\nw.finish()\n";
    let st = std::process::Command::new(&py).args(["-c", script, no_imu.to_str().unwrap()]).status().unwrap();
    assert!(st.success());
    let out = gyrolab().args(["allan", no_imu.to_str().unwrap()]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("no IMU messages") && err.contains("/chatter (std_msgs/msg/String, 3 messages)"), "{err}");
    let out = gyrolab().args(["inspect", no_imu.to_str().unwrap()]).output().unwrap();
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).contains("no IMU topic"));
    // A ROS 2 bag in the older SQLite3 storage: recognised and refused with the way out.
    let db3 = f.dir.join("old_bag.db3");
    let script = "import sqlite3, sys\nc = sqlite3.connect(sys.argv[1])\nc.execute('create table messages (id integer)')\nc.commit()\n";
    let st = std::process::Command::new(&py).args(["-c", script, db3.to_str().unwrap()]).status().unwrap();
    assert!(st.success());
    let out = gyrolab().args(["allan", db3.to_str().unwrap()]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("older .db3 storage") && err.contains("ros2 bag convert"), "{err}");
}

#[test]
fn truncated_recordings_warn_or_fail_clearly_and_never_panic() {
    let Some(f) = fixture() else { return };
    let work = tempfile::tempdir().unwrap();
    // Half of the MCAP: the first half of the messages analysed, with a warning.
    let bytes = std::fs::read(&f.ros2_mcap).unwrap();
    let half = common::write(work.path(), "half.mcap", "");
    std::fs::write(&half, &bytes[..bytes.len() / 2]).unwrap();
    let out = gyrolab().args(["allan", half.to_str().unwrap(), "--topic", "/imu0"]).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("warning: the file ends early or is damaged at byte"), "{err}");
    // Cuts anywhere in every format: a result with a warning, or exit 2 with a message.
    for file in
        [f.ros2_mcap.clone(), f.dir.join("rec/imu_lz4.bag"), f.dir.join("rec/imu.ulg"), f.dir.join("rec/imu.parquet")]
    {
        let bytes = std::fs::read(&file).unwrap();
        for k in 1..12 {
            let cut = work.path().join(format!("cut{k}.{}", file.extension().unwrap().to_string_lossy()));
            std::fs::write(&cut, &bytes[..bytes.len() * k / 12]).unwrap();
            let out = gyrolab().args(["allan", cut.to_str().unwrap()]).output().unwrap();
            let err = String::from_utf8_lossy(&out.stderr);
            assert!(!err.contains("panicked"), "{}: {err}", cut.display());
            match out.status.code() {
                Some(0) => assert!(err.contains("warning:"), "{} analysed without a warning: {err}", cut.display()),
                Some(2) => assert!(err.contains("error:") && err.len() < 2000, "{}: {err}", cut.display()),
                other => panic!("{}: exit {other:?}: {err}", cut.display()),
            }
        }
    }
}

#[test]
fn convert_writes_the_channels_as_recorded() {
    let Some(f) = fixture() else { return };
    let work = tempfile::tempdir().unwrap();
    let csv = work.path().join("imu0.csv");
    let out = gyrolab()
        .args(["convert", f.ros2_mcap.to_str().unwrap(), "--topic", "/imu0", "--out", csv.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let parse = |text: &str| -> Vec<Vec<f64>> {
        text.lines().skip(1).map(|l| l.split(',').map(|x| x.parse::<f64>().unwrap()).collect()).collect()
    };
    let got = std::fs::read_to_string(&csv).unwrap();
    let want = std::fs::read_to_string(&f.reference).unwrap();
    assert_eq!(got.lines().next(), want.lines().next(), "same header: timestamp_ns and the channels with units");
    assert_eq!(parse(&got), parse(&want), "the values as recorded, in stamp order");
    // Parquet: read back by gyrolab with the same figures.
    let pq = work.path().join("imu.parquet");
    let out =
        gyrolab().args(["convert", f.ros2_mcap.to_str().unwrap(), "--out", pq.to_str().unwrap()]).output().unwrap();
    assert!(out.status.success());
    let (doc, _) = allan_json(&[work.path().join("imu_imu0.parquet").to_str().unwrap()]);
    assert_same_curves(&channels(&doc, None), &channels(reference_doc(f), None), 1.0, "converted parquet");
    let out = gyrolab().args(["convert", f.ros2_mcap.to_str().unwrap(), "--out", "x.txt"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn bias_and_inspect_read_recordings_per_topic() {
    let Some(f) = fixture() else { return };
    let out = gyrolab().args(["bias", f.dir.join("rec/imu_lz4.bag").to_str().unwrap(), "--json"]).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("/imu0/gyro_x_rad_s") && text.contains("/imu1/gyro_x_rad_s"), "{text}");
    let out = gyrolab().args(["inspect", f.ros2_mcap.to_str().unwrap(), "--json"]).output().unwrap();
    assert!(out.status.success());
    let inv: Value = serde_json::from_slice(&out.stdout).unwrap();
    let n = (RATE_HZ * SECONDS) as u64;
    let imu0 = inv["topics"].as_array().unwrap().iter().find(|t| t["topic"] == "/imu0").unwrap();
    assert_eq!(imu0["messages"].as_u64(), Some(n));
    assert!((imu0["rate_hz"].as_f64().unwrap() - RATE_HZ).abs() < 1e-6);
    assert_eq!(imu0["gaps"], 0);
    assert!(imu0["out_of_order"].as_u64().unwrap() > 0);
    let temp = inv["topics"].as_array().unwrap().iter().find(|t| t["topic"] == "/temperature").unwrap();
    assert_eq!(temp["imu"], false);
}

#[test]
fn apply_calibrates_a_recording_topic_as_it_does_the_csv() {
    let Some(f) = fixture() else { return };
    let work = tempfile::tempdir().unwrap();
    // A calibration of an axis whose output is in rad/s, from a simulated rate-table test.
    let rt = work.path().join("rt.csv");
    let out = gyrolab()
        .args(["simulate", "rate-table", "--output-unit", "rad_s", "--runs", "2", "--out", rt.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let cal = work.path().join("cal.toml");
    let out = gyrolab().args(["rate", rt.to_str().unwrap(), "--cal-out", cal.to_str().unwrap()]).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let run = |input: &Path, topic: Option<&str>| {
        let mut c = gyrolab();
        c.args(["apply", "--cal", cal.to_str().unwrap(), input.to_str().unwrap(), "--column", "gyro_x_rad_s"]);
        if let Some(t) = topic {
            c.args(["--topic", t]);
        }
        let out = c.output().unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        (String::from_utf8(out.stdout).unwrap(), String::from_utf8_lossy(&out.stderr).to_string())
    };
    let (want, _) = run(&f.reference, None);
    let (got, err) = run(&f.dir.join("rec/imu_lz4.bag"), Some("/imu0"));
    assert!(err.contains("topic /imu0 (sensor_msgs/Imu)"), "{err}");
    let rates =
        |t: &str| -> Vec<String> { t.lines().map(|l| l.split(',').skip(1).collect::<Vec<_>>().join(",")).collect() };
    assert_eq!(rates(&got), rates(&want), "the same rates as from the CSV of the same numbers");
    // Several topics and none chosen: the error names them.
    let out = gyrolab()
        .args(["apply", "--cal", cal.to_str().unwrap(), f.dir.join("rec/imu_lz4.bag").to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("2 IMU topics (/imu0, /imu1): choose one with --topic"), "{err}");
}

/// Recordings beyond the memory ceiling are streamed (issue 37): every format, under 1 MiB
/// (the 1200 s records need about 6.4 MiB a topic in memory), against the same file in memory:
/// the same channels, samples and taus; every tau at full resolution equal to 1e-12 relative
/// (deviation, terms), every longer one inside the in-memory 68.3 % interval with
/// ceil(terms / stride) terms; the stillness check the same. Under 1 MiB a topic's messages
/// come in blocks of 1024, so the 120,000 cross many blocks; out-of-order messages (the bags
/// hold 2400) are put in order as in memory; a ULog's two IMU topics streamed at once come in
/// the in-memory order. The Parquet table of the same numbers likewise.
#[test]
fn recordings_beyond_the_ceiling_are_streamed_and_agree_with_memory() {
    let Some(f) = fixture() else { return };
    let rec = f.dir.join("rec");
    let nums =
        |v: &Value, key: &str| -> Vec<f64> { v[key].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect() };
    let cases = [
        ("plain_zstd.mcap", "/imu0"),
        ("plain_lz4.mcap", "/imu0"),
        ("imu_bz2.bag", "/imu0"),
        ("imu_lz4.bag", "/imu0"),
        ("imu.bag", "/imu0"),
        ("imu.ulg", "sensor_combined"),
        // every IMU topic at once (sensor_combined and sensor_gyro), and a table
        ("imu.ulg", ""),
        ("imu.parquet", ""),
    ];
    let ros2 = f.ros2_mcap.to_str().unwrap().to_string();
    let files: Vec<(String, &str)> = cases
        .iter()
        .map(|(file, topic)| (rec.join(file).to_str().unwrap().to_string(), *topic))
        .chain(std::iter::once((ros2, "/imu0")))
        .collect();
    for (file, topic) in &files {
        // a table has no topic
        let (args, topic): (Vec<&str>, Option<&str>) =
            if topic.is_empty() { (vec![file], None) } else { (vec![file, "--topic", topic], Some(*topic)) };
        let (memory, _) = allan_json(&args);
        assert_eq!(memory["memory"]["path"], "in_memory", "{file}");
        let streamed_args: Vec<&str> = args.iter().copied().chain(["--memory", "1MiB"]).collect();
        let (streamed, err) = allan_json(&streamed_args);
        let info = &streamed["memory"];
        assert_eq!(info["path"], "streaming", "{file}: {info}");
        assert!(err.contains("streamed"), "{file}: {err}");
        assert!(info["stride"].as_u64().unwrap() > 1, "{file}: {info}");
        let (a, b) = (channels(&memory, topic), channels(&streamed, topic));
        assert_eq!(a.len(), if file.ends_with(".ulg") && topic.is_none() { 9 } else { 6 }, "{file}");
        assert_eq!(a.len(), b.len(), "{file}");
        for (x, y) in a.iter().zip(&b) {
            assert_eq!((&x["topic"], &x["channel"]), (&y["topic"], &y["channel"]), "{file}: the same order");
            assert_eq!(x["samples"], y["samples"], "{file}");
            let (mx, my) = (nums(x, "m"), nums(y, "m"));
            assert_eq!(mx, my, "{file}: the same taus");
            let (dx, dy) = (nums(x, "dev"), nums(y, "dev"));
            let (lo, hi) = (nums(x, "ci_low"), nums(x, "ci_high"));
            let (tx, ty) = (nums(x, "n_terms"), nums(y, "n_terms"));
            // each topic has its own plan: the stride of each tau from the summary
            let taus = info["channels"]
                .as_array()
                .unwrap()
                .iter()
                .find(|c| c["topic"] == y["topic"] && c["channel"] == y["channel"])
                .unwrap_or_else(|| panic!("{file}: {} in the summary", y["channel"]))["taus"]
                .as_array()
                .unwrap()
                .clone();
            assert_eq!(taus.len(), mx.len(), "{file}");
            for i in 0..mx.len() {
                let m = mx[i] as usize;
                let stride = taus[i]["stride"].as_u64().unwrap() as usize;
                assert_eq!(taus[i]["m"].as_u64().unwrap() as usize, m, "{file}");
                if stride == 1 {
                    assert!(
                        (dy[i] / dx[i] - 1.0).abs() < 1e-12,
                        "{file} {} m {m}: {} vs {}",
                        x["channel"],
                        dy[i],
                        dx[i]
                    );
                    assert_eq!(tx[i], ty[i], "{file} m {m}");
                } else {
                    assert!(
                        dy[i] > lo[i] && dy[i] < hi[i],
                        "{file} {} m {m}: {} outside [{}, {}]",
                        x["channel"],
                        dy[i],
                        lo[i],
                        hi[i]
                    );
                    assert_eq!(ty[i] as usize, (tx[i] as usize).div_ceil(stride), "{file} m {m}");
                }
            }
            let (sx, sy) = (&x["stillness"], &y["stillness"]);
            for key in ["evaluated", "moved", "windows", "window_samples", "moved_windows"] {
                assert_eq!(sx[key], sy[key], "{file} {}: stillness {key}", x["channel"]);
            }
        }
    }
    // Another estimator beyond the ceiling is refused, naming the options.
    let out = gyrolab()
        .args(["allan", rec.join("imu.ulg").to_str().unwrap(), "--memory", "1MiB", "--kind", "mdev"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("octave OADEV only") && err.contains("--memory"), "{err}");
}

/// Snapshot topics skipped (issue 54): on pyulog's sample_log_small.ulg (BSD-3-Clause) the
/// default analysis takes sensor_combined only (250 Hz sensor samples); the three vehicle_imu
/// (2 Hz, integrated) and six sensor_gyro / sensor_accel copies (1 Hz, 6 messages) are named
/// with their reason, the Kalibr file is one file, exit 0; named with --topic, a snapshot is
/// analysed as asked.
#[test]
fn snapshot_topics_are_skipped_unless_named() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let ulg = root.join("examples/recordings/px4_sample_log_small.ulg");
    let dir = tempfile::tempdir().unwrap();
    let out = gyrolab()
        .current_dir(dir.path())
        .arg("allan")
        .arg(&ulg)
        .args(["--kalibr-yaml", "imu.yaml", "--json"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let channels = doc["channels"].as_array().unwrap();
    assert_eq!(channels.len(), 6, "sensor_combined's six channels only");
    assert!(
        channels
            .iter()
            .all(|c| c["topic"] == "sensor_combined" || c["file"].as_str().unwrap().contains("sensor_combined")),
        "{channels:?}"
    );
    for t in ["vehicle_imu", "vehicle_imu.1", "vehicle_imu.2"] {
        assert!(err.contains(&format!("topic {t} skipped: PX4's vehicle_imu")), "{t}: {err}");
    }
    for t in ["sensor_gyro", "sensor_gyro.2", "sensor_accel.1"] {
        assert!(err.contains(&format!("topic {t} skipped: 6 messages at 1.000 Hz")), "{t}: {err}");
    }
    assert!(err.contains("name it with --topic to analyse it anyway"), "{err}");
    let names: Vec<String> =
        std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    assert_eq!(names, ["imu.yaml"]);
    // Named, a snapshot is analysed (its curve as short as its record).
    let out = gyrolab().arg("allan").arg(&ulg).args(["--topic", "vehicle_imu", "--json"]).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(doc["channels"].as_array().unwrap().len(), 6);
}

/// `convert --start --end` (issue 54): cutting a flight log to a part keeps exactly the
/// messages stamped in `[start, end)` seconds after the topic's first one, the same rows as the
/// whole conversion holds there (pyulog's sample_flight.ulg, BSD-3-Clause); a window past the
/// end is a usage error naming the topic's length, and nothing is written.
#[test]
fn convert_start_and_end_keep_the_rows_of_the_window() {
    let ulg = root().join("examples/recordings/px4_sample_flight.ulg");
    let dir = tempfile::tempdir().unwrap();
    let (whole, part) = (dir.path().join("whole.csv"), dir.path().join("part.csv"));
    gyrolab().arg("convert").arg(&ulg).args(["--topic", "sensor_combined", "--out"]).arg(&whole).assert().success();
    gyrolab()
        .arg("convert")
        .arg(&ulg)
        .args(["--topic", "sensor_combined", "--start", "5", "--end", "15", "--out"])
        .arg(&part)
        .assert()
        .success();
    let whole = std::fs::read_to_string(&whole).unwrap();
    let mut lines = whole.lines();
    let header = lines.next().unwrap();
    let rows: Vec<&str> = lines.collect();
    let stamp = |l: &str| l.split(',').next().unwrap().parse::<i64>().unwrap();
    let first = stamp(rows[0]);
    let expected: Vec<&str> =
        rows.iter().copied().filter(|l| (5_000_000_000..15_000_000_000).contains(&(stamp(l) - first))).collect();
    let part = std::fs::read_to_string(&part).unwrap();
    let mut got = part.lines();
    assert_eq!(got.next(), Some(header));
    let got: Vec<&str> = got.collect();
    assert!(expected.len() > 2000, "{}", expected.len());
    assert_eq!(got, expected);
    let out = gyrolab()
        .arg("convert")
        .arg(&ulg)
        .args(["--topic", "sensor_combined", "--start", "500", "--out"])
        .arg(dir.path().join("none.csv"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("fewer than two messages between --start and --end: the topic is 68.8"), "{err}");
    assert!(!dir.path().join("none.csv").exists());
}

/// One clock model in every command, on a real log (issue 54): pyulog's
/// sample_logging_tagged_and_default_params.ulg (BSD-3-Clause) steps 4 and 8 ms; `inspect`,
/// `allan` and `bias` all read sensor_combined at 250 Hz with its 665 dropped samples (2,028
/// messages on a grid of 2,693), and skip the 1-2 Hz snapshot topics (Python's reading is
/// checked in python/tests/test_imu_logs.py).
#[test]
fn every_command_reads_the_clock_of_a_real_log_alike() {
    let ulg = root().join("examples/recordings/px4_sample_logging_tagged_and_default_params.ulg");
    let json = |args: &[&str]| -> Value {
        let out = gyrolab().args(args).arg(&ulg).arg("--json").output().unwrap();
        assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
        serde_json::from_slice(&out.stdout).unwrap()
    };
    let inv = json(&["inspect"]);
    let topic = inv["topics"].as_array().unwrap().iter().find(|t| t["topic"] == "sensor_combined").unwrap();
    assert_eq!((topic["messages"].as_u64(), topic["missing"].as_u64()), (Some(2028), Some(665)), "{topic}");
    assert_eq!(topic["rate_hz"], 250.0, "{topic}");
    let allan = json(&["allan"]);
    for c in allan["channels"].as_array().unwrap() {
        assert_eq!((c["tau0_s"].as_f64(), c["samples"].as_u64()), (Some(0.004), Some(2693)), "{}", c["channel"]);
    }
    let bias = json(&["bias"]);
    let tests = bias["tests"].as_array().unwrap();
    assert_eq!(tests.len(), 6, "sensor_combined's six channels only");
    for t in tests {
        assert_eq!(
            (t["sample_rate_hz"].as_f64(), t["samples"].as_u64()),
            (Some(250.0), Some(2028)),
            "{}",
            t["channel"]
        );
    }
}

/// A ROS 1 bag cut after its version line (issue 55) is refused by every command that reads
/// it, naming where it ends, instead of listed as a bag with no topics (exit 0); cut inside its
/// first record, likewise. The whole bag reads.
#[test]
fn a_bag_cut_after_its_version_line_is_refused() {
    let bag = std::fs::read(root().join("examples/recordings/simulated_imu_ros1.bag")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    for (cut, said) in
        [(13usize, "at byte 13: the file ends after its version line: no bag header"), (200, "more than the 110 left")]
    {
        let p = dir.path().join(format!("cut{cut}.bag"));
        std::fs::write(&p, &bag[..cut]).unwrap();
        for cmd in ["inspect", "allan", "bias"] {
            let out = gyrolab().arg(cmd).arg(&p).output().unwrap();
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(2), "{cmd} {cut}: {err}");
            assert!(err.contains(said), "{cmd} {cut}: {err}");
        }
    }
    gyrolab().arg("inspect").arg(root().join("examples/recordings/simulated_imu_ros1.bag")).assert().success();
}
