//! The stillness check through `gyrolab allan` (issue 30, "records that move"): a record whose
//! gyro moved is refused (exit 2, naming the channel, the episode and --allow-motion); with
//! --allow-motion every output is marked. Truth: records written here from white noise with a
//! rotation episode added at a known time; the bundled recordings (a simulated ROS 1 bag and
//! ROS 2 MCAP at rest, and a PX4 excerpt logged armed on the ground) are not flagged.

mod common;
use common::{gyrolab, write};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// 100 Hz, 120 s; gyro x and z in deg/s with white noise 0.05 deg/s per sample (N = 0.3
/// deg/sqrt(h)) about biases 0.3 and -0.2 deg/s; a rate of `episode_dps` added to x from 50 s
/// to 55 s.
fn record(dir: &Path, name: &str, seed: u64, episode_dps: f64) -> PathBuf {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let noise = Normal::new(0.0, 0.05).unwrap();
    let mut text = String::from("time_s,gyro_x [deg/s],gyro_z [deg/s]\n");
    for i in 0..12_000 {
        let t = i as f64 / 100.0;
        let step = if (50.0..55.0).contains(&t) { episode_dps } else { 0.0 };
        let x = 0.3 + step + noise.sample(&mut rng);
        let z = -0.2 + noise.sample(&mut rng);
        text.push_str(&format!("{t:.2},{x:.6},{z:.6}\n"));
    }
    write(dir, name, &text)
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn json(args: &[&str]) -> Value {
    let out = gyrolab().args(args).arg("--json").output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn a_record_that_moved_is_refused_naming_the_channel_and_the_episode() {
    let dir = tempfile::tempdir().unwrap();
    let file = record(dir.path(), "moved.csv", 1, 20.0);
    let yaml = dir.path().join("imu.yaml");
    let out = gyrolab()
        .arg("allan")
        .arg(&file)
        .arg("--kalibr-yaml")
        .arg(&yaml)
        .arg("--export")
        .arg(format!("openvins={}", dir.path().join("ov.yaml").display()))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("the record is not static"), "{err}");
    assert!(err.contains("channel 'gyro_x [deg/s]' moved in 5 of 120 windows of 1 s"), "{err}");
    assert!(err.contains("first episode 50.0 to 55.0 s (peak departure 20."), "{err}");
    assert!(err.contains("--allow-motion"), "{err}");
    assert!(!err.contains("channel 'gyro_z"), "{err}");
    // nothing written
    assert!(!yaml.exists() && !dir.path().join("ov.yaml").exists());
}

#[test]
fn with_allow_motion_every_output_is_marked() {
    let dir = tempfile::tempdir().unwrap();
    let file = record(dir.path(), "moved.csv", 2, -8.0);
    let yaml = dir.path().join("imu.yaml");
    let ov = dir.path().join("ov.yaml");
    let f = file.to_str().unwrap();
    let out = gyrolab()
        .args(["allan", f, "--allow-motion", "--kalibr-yaml"])
        .arg(&yaml)
        .arg("--export")
        .arg(format!("openvins={}", ov.display()))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("warning: MOTION: the record is not static:"), "{text}");
    assert!(text.contains("(gyro_x [deg/s]) moved in 5 of 120 windows"), "{text}");
    assert!(text.contains("analysed because motion was allowed"), "{text}");
    let kalibr = std::fs::read_to_string(&yaml).unwrap();
    assert!(kalibr.contains("# MOTION: the record is not static:") && kalibr.contains("(gyro_x [deg/s])"), "{kalibr}");
    let export = std::fs::read_to_string(&ov).unwrap();
    assert!(export.contains("MOTION: the record is not static:") && export.contains("still sensor's"), "{export}");
    let j = json(&["allan", f, "--allow-motion"]);
    let channels = j["channels"].as_array().unwrap();
    let x = &channels[0]["stillness"];
    assert_eq!((x["moved"].as_bool(), x["allow_motion"].as_bool()), (Some(true), Some(true)));
    assert_eq!(x["rule"]["unit"], "deg/s");
    assert_eq!(x["rule"]["floor"], 1.0);
    assert_eq!(x["first_episode"]["start_s"], 50.0);
    assert_eq!(x["first_episode"]["end_s"], 55.0);
    let peak = x["first_episode"]["peak_departure"].as_f64().unwrap();
    assert!((peak - 8.0).abs() < 0.1, "{peak}");
    // the white noise from first differences is the simulated 0.05 deg/s
    let sigma = x["white_noise_sigma"].as_f64().unwrap();
    assert!((sigma / 0.05 - 1.0).abs() < 0.03, "{sigma}");
    let z = &channels[1]["stillness"];
    assert_eq!((z["evaluated"].as_bool(), z["moved"].as_bool()), (Some(true), Some(false)));
}

#[test]
fn still_records_of_several_seeds_pass() {
    let dir = tempfile::tempdir().unwrap();
    for seed in 10..13 {
        let file = record(dir.path(), &format!("still{seed}.csv"), seed, 0.0);
        let out = gyrolab().arg("allan").arg(&file).output().unwrap();
        assert!(out.status.success(), "seed {seed}: {}", String::from_utf8_lossy(&out.stderr));
        let text = String::from_utf8_lossy(&out.stdout);
        assert_eq!(text.matches("stillness: still:").count(), 2, "{text}");
    }
}

#[test]
fn bundled_recordings_at_rest_are_not_flagged() {
    let dir = root().join("examples/recordings");
    // The simulated bag and MCAP: records at rest. The PX4 excerpt (6.5 s of sensor_combined at
    // 200 Hz) was logged armed on the ground: its window means stay within 0.04 deg/s and
    // 0.01 m/s^2 (pyulog + numpy on the same messages), so it is not flagged either.
    for (file, topic) in [
        ("simulated_imu_ros1.bag", "/imu0"),
        ("simulated_imu_ros2.mcap", "/imu0"),
        ("px4_sample_log_small.ulg", "sensor_combined"),
    ] {
        let path = dir.join(file);
        let j = json(&["allan", path.to_str().unwrap(), "--topic", topic]);
        let channels = j["channels"].as_array().unwrap();
        assert_eq!(channels.len(), 6, "{file}");
        for c in channels {
            let s = &c["stillness"];
            assert_eq!((s["evaluated"].as_bool(), s["moved"].as_bool()), (Some(true), Some(false)), "{file}: {s}");
        }
    }
}

#[test]
fn snapshot_topics_too_short_for_the_check_say_so() {
    // PX4's sensor_gyro logged at 1 Hz: 6 samples, fewer than three windows of 10 samples.
    let path = root().join("examples/recordings/px4_sample_log_small.ulg");
    let out = gyrolab().args(["allan", path.to_str().unwrap(), "--topic", "sensor_gyro"]).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("stillness: not evaluated (the record holds 1 window(s) of 10 samples"), "{text}");
}

/// A test plan's static record that moved is refused like `allan`'s, naming the plan key that
/// allows it; with `allow_motion = true` it is evaluated and its analysis says it moved.
#[test]
fn a_plan_refuses_a_static_record_that_moved_unless_the_plan_allows_it() {
    let dir = tempfile::tempdir().unwrap();
    record(dir.path(), "moved.csv", 3, 20.0);
    let plan = |allow: &str| {
        write(
            dir.path(),
            "plan.toml",
            &format!(
                "[device]\nmodel = \"m\"\nserial = \"s\"\naxes = [\"x\"]\n[static.x]\nfiles = [\"moved.csv\"]\n\
                 sample_rate_hz = 100.0\nchannel = \"gyro_x [deg/s]\"\n{allow}"
            ),
        )
    };
    let out = gyrolab().arg("eval").arg(plan("")).arg("--out").arg(dir.path().join("r")).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("static.x: the Allan record is not static"), "{err}");
    assert!(err.contains("first episode 50.0 to 55.0 s"), "{err}");
    assert!(err.contains("static.x.allow_motion = true"), "{err}");
    assert!(!dir.path().join("r").exists(), "nothing written");
    let out = gyrolab()
        .arg("eval")
        .arg(plan("allow_motion = true\n"))
        .arg("--out")
        .arg(dir.path().join("r"))
        .arg("-q")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let v: Value = serde_json::from_slice(&std::fs::read(dir.path().join("r/results.json")).unwrap()).unwrap();
    let still = &v["sections"]["allan"]["x"]["stillness"];
    assert_eq!((still["moved"].as_bool(), still["allow_motion"].as_bool()), (Some(true), Some(true)), "{still}");
    assert!(still["motion"].as_str().is_some_and(|m| m.starts_with("MOTION:")), "{still}");
}

/// The gravity check of a three-axis accelerometer: the bundled ROS 1 bag's /imu0 holds gravity
/// (9.80665 m/s^2 on z) and is within 0.1 g in every 1 s window; its /imu1 carries every value
/// times 2 (recordings README), so its magnitude is 2 g: a warning naming the unit or scale, and
/// the check in each accelerometer channel's JSON (never in a gyro's).
#[test]
fn the_gravity_check_finds_an_accelerometer_that_is_not_1_g() {
    let bag = root().join("examples/recordings/simulated_imu_ros1.bag");
    let run = |topic: &str| {
        let out = gyrolab().arg("allan").arg(&bag).args(["--topic", topic, "--json"]).output().unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let v: Value = serde_json::from_slice(&out.stdout).unwrap();
        (v, String::from_utf8_lossy(&out.stderr).into_owned())
    };
    let (v, err) = run("/imu0");
    assert!(err.contains("note: gravity: the accelerometer's magnitude is 9.80"), "{err}");
    assert!(err.contains("in every window"), "{err}");
    for c in v["channels"].as_array().unwrap() {
        let name = c["channel"].as_str().unwrap();
        assert_eq!(c.get("gravity").is_some(), name.starts_with("accel"), "{name}");
    }
    let g = &v["channels"][3]["gravity"];
    assert_eq!(g["outside_windows"], 0);
    assert!((g["median_magnitude_m_s2"].as_f64().unwrap() - 9.80665).abs() < 0.01, "{g}");
    let (v, err) = run("/imu1");
    assert!(err.contains("warning: gravity: the accelerometer's magnitude is not 1 g"), "{err}");
    assert!(err.contains("unit or scale is wrong") && err.contains("--unit"), "{err}");
    let g = &v["channels"][3]["gravity"];
    assert_eq!(g["outside_windows"], g["windows"]);
    assert!((g["median_magnitude_m_s2"].as_f64().unwrap() - 2.0 * 9.80665).abs() < 0.02, "{g}");
}
