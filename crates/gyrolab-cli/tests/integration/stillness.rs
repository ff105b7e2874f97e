//! The stillness check through `gyrolab allan` (issue 30, "records that move"): a record whose
//! gyro moved is refused (exit 2, naming the channel, the episode and --allow-motion); with
//! --allow-motion every output is marked. Truth: records written here from white noise with a
//! rotation episode added at a known time; the bundled recordings (a simulated ROS 1 bag and
//! ROS 2 MCAP at rest, and a PX4 excerpt logged armed on the ground) are not flagged.

use crate::common;
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
    record_of(dir, name, seed, episode_dps, 12_000)
}

/// [`record`] of `rows` rows.
fn record_of(dir: &Path, name: &str, seed: u64, episode_dps: f64, rows: usize) -> PathBuf {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let noise = Normal::new(0.0, 0.05).unwrap();
    let mut text = String::from("time_s,gyro_x [deg/s],gyro_z [deg/s]\n");
    for i in 0..rows {
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

/// A test plan's static records that moved are refused like `allan`'s, naming the plan key that
/// allows it: a bias record (evaluated for bias, not for the Allan curve) and the Allan record;
/// with `allow_motion = true` they are evaluated and the section and the analysis say they moved.
#[test]
fn a_plan_refuses_a_static_record_that_moved_unless_the_plan_allows_it() {
    let dir = tempfile::tempdir().unwrap();
    record(dir.path(), "moved.csv", 3, 20.0);
    record(dir.path(), "still.csv", 6, 0.0);
    let plan = |files: &str, allan: &str, allow: &str| {
        write(
            dir.path(),
            "plan.toml",
            &format!(
                "[device]\nmodel = \"m\"\nserial = \"s\"\naxes = [\"x\"]\n[static.x]\nfiles = [{files}]\n\
                 allan_file = \"{allan}\"\nsample_rate_hz = 100.0\nchannel = \"gyro_x [deg/s]\"\n{allow}"
            ),
        )
    };
    let eval = |plan: PathBuf| {
        let _ = std::fs::remove_dir_all(dir.path().join("r"));
        gyrolab().arg("eval").arg(plan).arg("--out").arg(dir.path().join("r")).arg("-q").output().unwrap()
    };
    // a bias record that moved (the Allan record is still), with a gap of 0.5 s in its stamps
    // before the episode: the samples are placed on the grid, so the episode is where it was
    let moved = std::fs::read_to_string(dir.path().join("moved.csv")).unwrap();
    let kept: Vec<&str> =
        moved.lines().enumerate().filter(|(i, _)| !(2001..2051).contains(i)).map(|(_, l)| l).collect();
    write(dir.path(), "moved_gap.csv", &(kept.join("\n") + "\n"));
    let out = eval(plan("\"still.csv\", \"moved_gap.csv\"", "still.csv", ""));
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("moved_gap.csv: static.x.files[1]: the record is not static"), "{err}");
    assert!(err.contains("first episode 50.0 to 55.0 s"), "{err}");
    assert!(err.contains("static.x.allow_motion = true"), "{err}");
    assert!(!dir.path().join("r").exists(), "nothing written");
    // the Allan record that moved (the bias record is still)
    let out = eval(plan("\"still.csv\"", "moved.csv", ""));
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("static.x: the Allan record is not static"), "{err}");
    assert!(err.contains("first episode 50.0 to 55.0 s"), "{err}");
    assert!(err.contains("static.x.allow_motion = true"), "{err}");
    assert!(!dir.path().join("r").exists(), "nothing written");
    // allowed: both evaluated, both marked
    let out = eval(plan("\"still.csv\", \"moved.csv\"", "moved.csv", "allow_motion = true\n"));
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let v: Value = serde_json::from_slice(&std::fs::read(dir.path().join("r/results.json")).unwrap()).unwrap();
    let still = &v["sections"]["allan"]["x"]["stillness"];
    assert_eq!((still["moved"].as_bool(), still["allow_motion"].as_bool()), (Some(true), Some(true)), "{still}");
    assert!(still["motion"].as_str().is_some_and(|m| m.starts_with("MOTION:")), "{still}");
    let notes = v["sections"]["static"]["x"]["notes"].as_array().unwrap();
    let moved: Vec<&str> = notes.iter().filter_map(|n| n.as_str()).filter(|n| n.starts_with("MOTION: ")).collect();
    assert_eq!(moved.len(), 1, "{notes:?}");
    assert!(moved[0].contains("moved.csv: channel 'gyro_x [deg/s]' moved in 5 of 120 windows"), "{moved:?}");
    assert!(moved[0].contains("static.x.allow_motion = true"), "{moved:?}");
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

/// A record streamed within a memory ceiling (`--memory`) gets the same check as in memory:
/// refused when it moved, naming the episode; with --allow-motion the streamed check equals the
/// in-memory one (same windows, episodes and white-noise sigma).
#[test]
fn a_streamed_record_is_checked_as_in_memory() {
    let dir = tempfile::tempdir().unwrap();
    // 600 s at 100 Hz, two channels: about 1.4 MB in memory, above a 1 MiB ceiling
    let file = record_of(dir.path(), "long.csv", 4, 20.0, 60_000);
    let f = file.to_str().unwrap();
    let out = gyrolab().args(["allan", f, "--memory", "1MiB"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("channel 'gyro_x [deg/s]' moved in 5 of 600 windows of 1 s"), "{err}");
    assert!(err.contains("first episode 50.0 to 55.0 s"), "{err}");
    let streamed = json(&["allan", f, "--memory", "1MiB", "--allow-motion"]);
    assert_eq!(streamed["memory"]["path"], "streaming");
    let in_memory = json(&["allan", f, "--allow-motion"]);
    assert_eq!(in_memory["memory"]["path"], "in_memory");
    for c in 0..2 {
        let (a, b) = (&streamed["channels"][c]["stillness"], &in_memory["channels"][c]["stillness"]);
        assert_eq!(a["evaluated"], true, "{a}");
        for key in ["moved", "windows", "moved_windows", "window_samples", "first_episode", "largest_episode"] {
            assert_eq!(a[key], b[key], "channel {c}, {key}");
        }
        let (sa, sb) = (a["white_noise_sigma"].as_f64().unwrap(), b["white_noise_sigma"].as_f64().unwrap());
        assert!((sa / sb - 1.0).abs() < 1e-9, "{sa} vs {sb}");
    }
    assert_eq!(streamed["channels"][0]["stillness"]["moved"], true);
    assert_eq!(streamed["channels"][1]["stillness"]["moved"], false);
    // a still record streamed passes
    let still = record_of(dir.path(), "still.csv", 5, 0.0, 60_000);
    let j = json(&["allan", still.to_str().unwrap(), "--memory", "1MiB"]);
    assert_eq!(j["memory"]["path"], "streaming");
    for c in j["channels"].as_array().unwrap() {
        let s = &c["stillness"];
        assert_eq!((s["evaluated"].as_bool(), s["moved"].as_bool()), (Some(true), Some(false)), "{s}");
    }
}

/// A REAL moving record: PX4/pyulog's `test/sample.ulg` (BSD-3-Clause; bundled as
/// examples/recordings/px4_sample_flight.ulg) is a flight: its gyro turns at up to 12 deg/s in
/// 1 s window means. `allan` refuses it naming each gyro channel; with --allow-motion the
/// check's windows, still level and first episode agree with an independent reading by pyulog +
/// numpy (scripts/px4_motion_reference.py: 1 s windows by time stamp, which the test script
/// checks against the committed JSON), allowing for gyrolab's own window grid.
#[test]
fn a_real_px4_flight_is_found_moving() {
    let ulg = root().join("examples/recordings/px4_sample_flight.ulg");
    let reference: Value = serde_json::from_slice(
        &std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/px4_motion_reference.json")).unwrap(),
    )
    .unwrap();
    let f = ulg.to_str().unwrap();
    let out = gyrolab().args(["allan", f, "--topic", "sensor_combined"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("the record is not static"), "{err}");
    for axis in ["x", "y", "z"] {
        assert!(err.contains(&format!("channel 'gyro_{axis}_rad_s' moved in ")), "{axis}: {err}");
    }
    assert!(err.contains("--allow-motion"), "{err}");
    let j = json(&["allan", f, "--topic", "sensor_combined", "--allow-motion"]);
    let channels = j["channels"].as_array().unwrap();
    for axis in ["x", "y", "z"] {
        let c = channels.iter().find(|c| c["channel"] == format!("gyro_{axis}_rad_s")).unwrap();
        let s = &c["stillness"];
        let r = &reference["channels"][format!("gyro_{axis}")];
        assert_eq!((s["evaluated"].as_bool(), s["moved"].as_bool()), (Some(true), Some(true)), "{axis}: {s}");
        assert_eq!(s["windows"], r["windows"], "{axis}");
        let level = s["still_level"].as_f64().unwrap();
        let want = r["still_level_dps"].as_f64().unwrap();
        assert!((level - want).abs() < 0.01, "{axis}: still level {level} vs numpy {want}");
        // every window whose mean departs by more than the floor is moved in gyrolab too (its
        // spread test may add windows that shook without moving their mean)
        let moved = s["moved_windows"].as_u64().unwrap();
        let mean_moved = r["mean_moved_windows"].as_u64().unwrap();
        assert!(moved >= mean_moved && moved <= mean_moved + 2, "{axis}: {moved} vs numpy {mean_moved}");
        let start = s["first_episode"]["start_s"].as_f64().unwrap();
        let want = r["first_mean_moved_start_s"].as_f64().unwrap();
        assert!((start - want).abs() <= 1.0, "{axis}: first episode at {start} s, numpy's first moved window {want} s");
        let peak = s["first_episode"]["peak_departure"].as_f64().unwrap();
        let largest = s["largest_episode"]["peak_departure"].as_f64().unwrap_or(peak);
        assert!(peak.max(largest) >= r["largest_mean_departure_dps"].as_f64().unwrap() * 0.9, "{axis}");
        assert!(c["stillness"]["motion"].as_str().is_some_and(|m| m.starts_with("MOTION:")), "{axis}");
    }
}

/// The static records of `[power_ups.<axis>]` are checked too: refused naming the file and
/// `power_ups.<axis>.allow_motion`; allowed, evaluated with a MOTION note in the section's JSON.
#[test]
fn a_plan_refuses_a_power_up_record_that_moved_unless_the_plan_allows_it() {
    let dir = tempfile::tempdir().unwrap();
    record(dir.path(), "up1.csv", 7, 0.0);
    record(dir.path(), "up2.csv", 8, 15.0);
    record(dir.path(), "up3.csv", 9, 0.0);
    let plan = |allow: &str| {
        write(
            dir.path(),
            "plan.toml",
            &format!(
                "[device]\nmodel = \"m\"\nserial = \"s\"\naxes = [\"x\"]\n[power_ups.x]\n\
                 static_files = [\"up1.csv\", \"up2.csv\", \"up3.csv\"]\nsample_rate_hz = 100.0\n\
                 channel = \"gyro_x [deg/s]\"\n{allow}"
            ),
        )
    };
    let r = dir.path().join("r");
    let out = gyrolab().arg("eval").arg(plan("")).arg("--out").arg(&r).arg("-q").output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("up2.csv: power_ups.x.static_files[1]: the record is not static"), "{err}");
    assert!(err.contains("channel 'gyro_x [deg/s]' moved in 5 of 120 windows"), "{err}");
    assert!(err.contains("power_ups.x.allow_motion = true"), "{err}");
    assert!(!r.exists(), "nothing written");
    let out = gyrolab().arg("eval").arg(plan("allow_motion = true\n")).arg("--out").arg(&r).arg("-q").output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let v: Value = serde_json::from_slice(&std::fs::read(r.join("results.json")).unwrap()).unwrap();
    let notes = v["sections"]["power_ups"]["x"]["notes"].as_array().unwrap();
    assert_eq!(notes.len(), 1, "{notes:?}");
    let note = notes[0].as_str().unwrap();
    assert!(note.starts_with("MOTION: up2.csv: channel 'gyro_x [deg/s]' moved in 5 of 120 windows"), "{note}");
    assert!(note.contains("power_ups.x.allow_motion = true"), "{note}");
    let html = std::fs::read_to_string(r.join("report.html")).unwrap();
    assert!(html.contains("MOTION: up2.csv"), "the section prints the note");
}

/// The stillness text states the window it used (issue 54): at 100 Hz the rule's 1 s (100
/// samples); at 2 Hz a window holds the minimum of 10 samples, 5 s, and the text says 5 s.
#[test]
fn the_stillness_text_states_the_window_used() {
    let dir = tempfile::tempdir().unwrap();
    for (rate, want) in [(100.0, "no window of 1 s (100 samples)"), (2.0, "no window of 5 s (10 samples)")] {
        let mut text = String::from("time_s,gyro_x [deg/s]\n");
        let mut x: u64 = 7;
        for i in 0..2000 {
            x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            let u = (x >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            text.push_str(&format!("{},{}\n", i as f64 / rate, 0.01 * u));
        }
        let p = write(dir.path(), "r.csv", &text);
        let out = gyrolab().arg("allan").arg(&p).output().unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(stdout.contains(want), "{rate} Hz: {stdout}");
    }
}
