//! `gyrolab allan --export`: the SIMULATED mark, the basis and factors in the header, GMWM as the
//! basis, the stack names, all-or-none writes (the files' readers: scripts/check_exports.py).

use crate::common;
use common::gyrolab;

fn simulate(dir: &std::path::Path) -> std::path::PathBuf {
    simulate_walk(dir, "20", "36")
}

/// 2000 s at 50 Hz of N 0.3 deg/sqrt(h) and a random walk K `rrw` deg/h/sqrt(h), seed `seed`.
fn simulate_walk(dir: &std::path::Path, rrw: &str, seed: &str) -> std::path::PathBuf {
    let p = dir.join("sim.csv");
    gyrolab()
        .args(["simulate", "static", "--duration-s", "2000", "--sample-rate-hz", "50", "--arw-deg-rt-h", "0.3"])
        .args(["--rrw-deg-h-rt-h", rrw, "--seed", seed, "--out"])
        .arg(&p)
        .assert()
        .success();
    p
}

/// `gyrolab allan RECORD --estimator gmwm --export STACK=FILE`, asserted to succeed; the file's text.
fn gmwm_export(record: &std::path::Path, stack: &str, file: &std::path::Path) -> String {
    gmwm_export_and_stderr(record, stack, file).0
}

/// As [`gmwm_export`], with the run's stderr.
fn gmwm_export_and_stderr(record: &std::path::Path, stack: &str, file: &std::path::Path) -> (String, String) {
    let out = gyrolab()
        .arg("allan")
        .arg(record)
        .args(["--estimator", "gmwm", "--export"])
        .arg(format!("{stack}={}", file.display()))
        .assert()
        .success();
    let stderr = String::from_utf8_lossy(&out.get_output().stderr).to_string();
    (std::fs::read_to_string(file).unwrap(), stderr)
}

/// `gyrolab allan RECORD --json`, parsed.
fn allan_json(record: &std::path::Path) -> serde_json::Value {
    let json = gyrolab().arg("allan").arg(record).arg("--json").assert().success().get_output().stdout.clone();
    serde_json::from_slice(&json).unwrap()
}

fn value(text: &str, key: &str) -> f64 {
    let line = text.lines().find(|l| l.starts_with(&format!("{key}:"))).unwrap_or_else(|| panic!("{key}\n{text}"));
    line[key.len() + 1..].split('#').next().unwrap().trim().parse().unwrap()
}

#[test]
fn simulated_record_is_marked_and_factors_are_recorded() {
    let dir = tempfile::tempdir().unwrap();
    let sim = simulate(dir.path());
    let plain = dir.path().join("plain.yaml");
    let bounded = dir.path().join("bounded.yaml");
    gyrolab().arg("allan").arg(&sim).arg("--export").arg(format!("kalibr={}", plain.display())).assert().success();
    let out = gyrolab()
        .arg("allan")
        .arg(&sim)
        .args(["--overbound", "--inflate", "2", "--export"])
        .arg(format!("kalibr={}", bounded.display()))
        .assert()
        .success();
    let plain = std::fs::read_to_string(&plain).unwrap();
    let bounded = std::fs::read_to_string(&bounded).unwrap();
    assert!(plain.contains("# SIMULATED"), "{plain}");
    assert!(bounded.contains("overbound factor") && bounded.contains("x 2 (--inflate)"), "{bounded}");
    // value = estimate x factor x 2, the factor at least 1.
    let (a, b) = (value(&plain, "gyroscope_noise_density"), value(&bounded, "gyroscope_noise_density"));
    assert!(b >= 2.0 * a * (1.0 - 1e-12), "{a} {b}");
    let stderr = String::from_utf8_lossy(&out.get_output().stderr).to_string();
    assert!(!stderr.contains("panicked"), "{stderr}");
}

#[test]
fn gmwm_is_the_basis_when_asked() {
    let dir = tempfile::tempdir().unwrap();
    let sim = simulate(dir.path());
    let text = gmwm_export(&sim, "vins", &dir.path().join("vins.yaml"));
    assert!(text.contains("estimator: gmwm") && text.contains("gmwm: GMWM estimate"), "{text}");
    // N = 0.3 deg/sqrt(h) = 0.005 deg/sqrt(s) = 8.727e-5 rad/s/sqrt(Hz), and VINS's gyr_n per
    // sample at 50 Hz N sqrt(2 x 50): within 10 %.
    let n = value(&text, "gyr_n");
    assert!((n / (0.005f64.to_radians() * 100f64.sqrt()) - 1.0).abs() < 0.1, "{n}");
    assert_eq!(allan_json(&sim)["channels"][0]["gmwm"]["sided"], "two-sided");
}

#[test]
fn bad_exports_are_usage_errors_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let sim = simulate(dir.path());
    let good = dir.path().join("good.yaml");
    for bad in ["gtsam=x.yaml", "kalibr", "kalibr="] {
        let out = gyrolab()
            .arg("allan")
            .arg(&sim)
            .arg("--export")
            .arg(format!("kalibr={}", good.display()))
            .args(["--export", bad])
            .assert()
            .code(2);
        let err = String::from_utf8_lossy(&out.get_output().stderr).to_string();
        assert!(err.contains("export"), "{bad}: {err}");
        assert!(!good.exists());
    }
    gyrolab().arg("allan").arg(&sim).args(["--estimator", "median", "--export", "kalibr=k.yaml"]).assert().code(2);
    let missing = dir.path().join("no").join("x.yaml");
    gyrolab()
        .arg("allan")
        .arg(&sim)
        .arg("--export")
        .arg(format!("kalibr={}", good.display()))
        .arg("--export")
        .arg(format!("px4={}", missing.display()))
        .assert()
        .failure();
    assert!(!good.exists());
}

/// The values of `--export kalibr` and of `--kalibr-yaml` (two writers of the same rule) are the
/// same numbers on a recording with gyro and accelerometer channels.
#[test]
fn export_kalibr_equals_kalibr_yaml() {
    let dir = tempfile::tempdir().unwrap();
    let mcap =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/recordings/simulated_imu_ros2.mcap");
    let (a, b) = (dir.path().join("a.yaml"), dir.path().join("b.yaml"));
    gyrolab()
        .arg("allan")
        .arg(&mcap)
        .arg("--kalibr-yaml")
        .arg(&a)
        .arg("--export")
        .arg(format!("kalibr={}", b.display()))
        .assert()
        .success();
    let (a, b) = (std::fs::read_to_string(&a).unwrap(), std::fs::read_to_string(&b).unwrap());
    for key in [
        "gyroscope_noise_density",
        "gyroscope_random_walk",
        "accelerometer_noise_density",
        "accelerometer_random_walk",
        "update_rate",
    ] {
        let (x, y) = (value(&a, key), value(&b, key));
        assert!(x > 0.0 && x == y, "{key}: {x} vs {y}");
    }
}

/// The rate written into the filter files of real recordings, end to end (issue 30): the PX4 log's
/// `sensor_combined` at the rate pyulog + numpy give (the committed reference that
/// scripts/px4_clock_reference.py re-derives in the test script), and each topic of the ROS 1 bag
/// at its simulated 100 Hz.
#[test]
fn update_rate_of_real_recordings_end_to_end() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let reference: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(root.join("crates/gyrolab-eval/tests/data/px4_clock_reference.json")).unwrap(),
    )
    .unwrap();
    let want = reference["rate_hz"].as_f64().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let (k, ov) = (dir.path().join("k.yaml"), dir.path().join("ov.yaml"));
    gyrolab()
        .arg("allan")
        .arg(root.join("examples/recordings/px4_sample_log_small.ulg"))
        .args(["--topic", "sensor_combined", "--kalibr-yaml"])
        .arg(&k)
        .arg("--export")
        .arg(format!("openvins={}", ov.display()))
        .assert()
        .success();
    let kalibr = value(&std::fs::read_to_string(&k).unwrap(), "update_rate");
    assert!((kalibr / want - 1.0).abs() < 1e-8, "Kalibr update_rate {kalibr} vs pyulog {want}");
    let openvins = std::fs::read_to_string(&ov).unwrap();
    let line = openvins.lines().find_map(|l| l.trim().strip_prefix("update_rate:")).unwrap();
    let got: f64 = line.trim().parse().unwrap();
    assert!((got / want - 1.0).abs() < 1e-12, "OpenVINS update_rate {got} vs pyulog {want}");

    let bag = dir.path().join("bag.yaml");
    gyrolab()
        .arg("allan")
        .arg(root.join("examples/recordings/simulated_imu_ros1.bag"))
        .arg("--kalibr-yaml")
        .arg(&bag)
        .assert()
        .success();
    for topic in ["imu0", "imu1"] {
        let text = std::fs::read_to_string(dir.path().join(format!("bag_{topic}.yaml"))).unwrap();
        assert_eq!(value(&text, "update_rate"), 100.0, "{topic}\n{text}");
        assert!(text.contains(&format!("rostopic: /{topic}")), "{text}");
    }
}

/// White noise N 0.01 deg/sqrt(s) and a sampled Gauss-Markov process (sigma 0.02 deg/s, T 5 s)
/// at 100 Hz for 2^17 samples, as a CSV.
fn gauss_markov_record(dir: &std::path::Path) -> std::path::PathBuf {
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(36);
    let (n, sigma, t, tau0) = (0.01f64, 0.02f64, 5.0f64, 0.01f64);
    let phi = (-tau0 / t).exp();
    let mut x = 0.0;
    let mut text = String::from("time_s,rate_dps\n");
    for i in 0..(1 << 17) {
        let a: f64 = StandardNormal.sample(&mut rng);
        let b: f64 = StandardNormal.sample(&mut rng);
        x = phi * x + sigma * (1.0 - phi * phi).sqrt() * b;
        text.push_str(&format!("{},{}\n", i as f64 * tau0, n / tau0.sqrt() * a + x));
    }
    let p = dir.join("gm.csv");
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn a_gauss_markov_process_is_exported_as_the_random_walk_that_bounds_it() {
    let dir = tempfile::tempdir().unwrap();
    let rec = gauss_markov_record(dir.path());
    let text = gmwm_export(&rec, "kalibr", &dir.path().join("kalibr.yaml"));
    let v = allan_json(&rec);
    let g = &v["channels"][0]["gmwm"];
    let params = g["parameters"].as_array().unwrap();
    let markov: Vec<&serde_json::Value> = params.iter().filter(|p| p["process"] == "gauss_markov").collect();
    assert_eq!(markov.len(), 1, "{g}");
    let (sigma, t) = (markov[0]["value"].as_f64().unwrap(), markov[0]["correlation_time_s"].as_f64().unwrap());
    assert_eq!(markov[0]["unit"], "deg/s");
    assert!((sigma / 0.02 - 1.0).abs() < 0.2 && (t / 5.0 - 1.0).abs() < 0.35, "sigma {sigma} T {t}");
    assert_eq!(g["quality"], "acceptable", "{g}");
    // The hand conversion: K^2 = K_rw^2 + 2 sigma^2 / T, deg -> rad (over this curve's taus,
    // 0.01 to 164 s, the random walk is the tighter bound of T = 5 s: it exceeds the process by
    // about 380 at 164 s, white noise by about 7.5e5 at 0.01 s).
    let k_rw = params.iter().find(|p| p["process"] == "random_walk").map_or(0.0, |p| p["value"].as_f64().unwrap());
    let want = (k_rw * k_rw + 2.0 * sigma * sigma / t).sqrt().to_radians();
    let got = value(&text, "gyroscope_random_walk");
    assert!((got / want - 1.0).abs() < 1e-6, "{got} vs {want}\n{text}");
    assert!(text.contains("gmwm_gauss_markov_bound") && text.contains("gauss_markov(sigma"), "{text}");
}

/// A random walk the chosen GMWM model leaves out (white noise + a drift chosen for N 0.3
/// deg/sqrt(h), K 3 deg/h/sqrt(h), seed 6) is bounded given that it is there (the candidates
/// holding it): the text names it, the JSON lists it under `left_out` with the weight of those
/// candidates, and the Kalibr export writes that bound in rad with the basis `gmwm_upper_bound`.
#[test]
fn a_random_walk_left_out_by_the_chosen_model_is_exported_as_its_bound() {
    let dir = tempfile::tempdir().unwrap();
    let sim = simulate_walk(dir.path(), "3", "6");
    let v = allan_json(&sim);
    let g = &v["channels"][0]["gmwm"];
    assert!(g["parameters"].as_array().unwrap().iter().all(|p| p["process"] != "random_walk"), "{g}");
    let left = g["left_out"].as_array().unwrap();
    let k = left.iter().find(|b| b["process"] == "random_walk").unwrap_or_else(|| panic!("{g}"));
    assert_eq!(k["unit"], "deg/s/sqrt(s)");
    assert_eq!(k["confidence_one_sided"], 0.8415);
    let (upper, weight) = (k["upper"].as_f64().unwrap(), k["model_weight"].as_f64().unwrap());
    assert!(upper > 0.0 && weight > 0.0 && weight < 1.0, "{k}");
    let text = gyrolab().arg("allan").arg(&sim).assert().success().get_output().stdout.clone();
    let text = String::from_utf8_lossy(&text).to_string();
    assert!(
        text.contains("left out by the chosen model: random_walk <") && text.contains(" if present (one-sided 84.15 %"),
        "{text}"
    );
    let (yaml, stderr) = gmwm_export_and_stderr(&sim, "kalibr", &dir.path().join("kalibr.yaml"));
    assert!(stderr.contains("gyro random walk is a GMWM bound given that the term is there"), "{stderr}");
    let got = value(&yaml, "gyroscope_random_walk");
    assert!((got / upper.to_radians() - 1.0).abs() < 1e-6, "{got} vs {upper} deg\n{yaml}");
    assert!(yaml.contains("gmwm_upper_bound") && yaml.contains("84.2 % upper bound"), "{yaml}");
}

/// The export options without --export are usage errors (they would be silently ignored), as
/// are two outputs naming one file and a negative --inflate written as two arguments; nothing is
/// analysed or written.
#[test]
fn export_options_need_an_export_and_outputs_their_own_files() {
    let dir = tempfile::tempdir().unwrap();
    let sim = simulate(dir.path());
    let stderr = |args: &[&str]| {
        let out = gyrolab().arg("allan").arg(&sim).args(args).assert().code(2);
        String::from_utf8_lossy(&out.get_output().stderr).to_string()
    };
    for (args, named) in [
        (vec!["--inflate", "2"], "--inflate"),
        (vec!["--overbound"], "--overbound"),
        (vec!["--estimator", "gmwm"], "--estimator"),
    ] {
        let err = stderr(&args);
        assert!(err.contains(&format!("{named} applies to the --export files only")), "{args:?}: {err}");
    }
    let k = dir.path().join("k.yaml");
    let (k_kalibr, k_vins) = (format!("kalibr={}", k.display()), format!("vins={}", k.display()));
    let err = stderr(&["--export", &k_kalibr, "--export", &k_vins]);
    assert!(err.contains("--export kalibr= and --export vins= both name") && err.contains("its own file"), "{err}");
    let err = stderr(&["--export", &k_kalibr, "--kalibr-yaml", k.to_str().unwrap()]);
    assert!(err.contains("--export kalibr= and --kalibr-yaml both name"), "{err}");
    // The same file written two ways, from the record's folder: `k.yaml` and `./k.yaml`.
    let out = gyrolab()
        .current_dir(dir.path())
        .args(["allan", "sim.csv", "--export", "kalibr=k.yaml", "--export", "vins=./k.yaml"])
        .assert()
        .code(2);
    assert!(String::from_utf8_lossy(&out.get_output().stderr).contains("both name"));
    // A bad --inflate is refused before anything is analysed or written, --kalibr-yaml included.
    let y = dir.path().join("y.yaml");
    let err = stderr(&["--kalibr-yaml", y.to_str().unwrap(), "--export", &k_kalibr, "--inflate", "0"]);
    assert!(err.contains("inflate") && err.contains("not a positive number"), "{err}");
    assert!(!y.exists());
    assert!(!k.exists());
    // `--inflate -2` reaches gyrolab's own check, not clap's "use '-- -2'" hint.
    let err = stderr(&["--inflate", "-2", "--export", &k_kalibr]);
    assert!(err.contains("inflate") && !err.contains("-- -2"), "{err}");
    assert!(!k.exists());
}

/// A GMWM model with a flicker floor (white noise + bias instability, 2 h at 50 Hz): no stack
/// takes the floor, so every file's header and a `warning:` name it as not represented, with B in
/// rad/s; a bound of a left-out term is warned about as a bound too.
#[test]
fn a_gmwm_flicker_floor_is_named_as_not_represented() {
    let dir = tempfile::tempdir().unwrap();
    let sim = dir.path().join("flicker.csv");
    gyrolab()
        .args(["simulate", "static", "--duration-s", "7200", "--sample-rate-hz", "50", "--arw-deg-rt-h", "0.3"])
        .args(["--bias-instability-dph", "5", "--seed", "11", "--out"])
        .arg(&sim)
        .assert()
        .success();
    let v = allan_json(&sim);
    let g = &v["channels"][0]["gmwm"];
    let flicker = g["parameters"].as_array().unwrap().iter().find(|p| p["process"] == "flicker");
    let flicker = flicker.unwrap_or_else(|| panic!("the chosen model holds a flicker floor: {g}"));
    let b_rad = flicker["value"].as_f64().unwrap().to_radians();
    let file = dir.path().join("k.yaml");
    let (text, stderr) = gmwm_export_and_stderr(&sim, "kalibr", &file);
    let line = text.lines().find(|l| l.starts_with("# NOT REPRESENTED: ")).unwrap_or_else(|| panic!("{text}"));
    assert!(line.contains("flicker floor") && line.contains("rad/s"), "{line}");
    let written: f64 = line.split("B = ").nth(1).unwrap().split(' ').next().unwrap().parse().unwrap();
    assert!((written / b_rad - 1.0).abs() < 1e-9, "{written} vs {b_rad}");
    assert!(
        stderr.contains("warning: not represented in the exports: ") && stderr.contains("flicker floor"),
        "{stderr}"
    );
    // The slope readings' export has no such line: it does not come from the GMWM's model.
    gyrolab().arg("allan").arg(&sim).arg("--export").arg(format!("kalibr={}", file.display())).assert().success();
    assert!(!std::fs::read_to_string(&file).unwrap().contains("NOT REPRESENTED"));
}

/// A channel whose name carries no unit gyrolab knows (a typo, `gyro_y_dsp`) is analysed in
/// output units and left out of the exports, with a `warning:` naming it, not in silence.
#[test]
fn a_channel_without_a_unit_is_named_when_the_exports_leave_it_out() {
    let dir = tempfile::tempdir().unwrap();
    let sim = simulate(dir.path());
    let text = std::fs::read_to_string(&sim).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header = lines.next().unwrap();
    let rate_column = header.split(',').position(|c| c.starts_with("rate") || c.contains("dps")).unwrap();
    let mut csv = String::from("time_s,gyro_x_dps,gyro_y_dsp\n");
    for line in lines.take(50_000) {
        let cells: Vec<&str> = line.split(',').collect();
        csv.push_str(&format!("{},{},{}\n", cells[0], cells[rate_column], cells[rate_column]));
    }
    let typo = dir.path().join("typo.csv");
    std::fs::write(&typo, csv).unwrap();
    let file = dir.path().join("k.yaml");
    let out =
        gyrolab().arg("allan").arg(&typo).arg("--export").arg(format!("kalibr={}", file.display())).assert().success();
    let stderr = String::from_utf8_lossy(&out.get_output().stderr).to_string();
    assert!(
        stderr.contains(
            "warning: gyro_y_dsp: not a gyro or accelerometer channel, so the exports leave it out; it has no unit"
        ),
        "{stderr}"
    );
    assert!(!stderr.contains("warning: gyro_x_dps: not a gyro"), "{stderr}");
}

/// A simulated record is marked in the text reports of `allan` and `bias` (a first `SIMULATED:`
/// line); the same samples without the simulator's header are not.
#[test]
fn simulated_inputs_are_marked_in_the_text_reports() {
    let dir = tempfile::tempdir().unwrap();
    let sim = simulate(dir.path());
    let stdout = |args: &[&str], file: &std::path::Path| {
        let out = gyrolab().arg(args[0]).arg(file).args(&args[1..]).assert().success();
        String::from_utf8_lossy(&out.get_output().stdout).to_string()
    };
    assert!(stdout(&["allan"], &sim).starts_with("SIMULATED: "), "allan");
    assert!(stdout(&["bias"], &sim).starts_with("SIMULATED: "), "bias");
    // The same samples without the simulator's header lines read as a measured record.
    let measured = dir.path().join("measured.csv");
    let text = std::fs::read_to_string(&sim).unwrap();
    std::fs::write(&measured, text.lines().filter(|l| !l.starts_with('#')).collect::<Vec<_>>().join("\n")).unwrap();
    assert!(!stdout(&["allan"], &measured).contains("SIMULATED"), "allan, measured");
    assert!(!stdout(&["bias"], &measured).contains("SIMULATED"), "bias, measured");
}

/// The names of the files in `dir`, sorted.
fn names_in(dir: &std::path::Path) -> Vec<String> {
    let mut v: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    v.sort();
    v
}

/// Every output of `allan` all or none (issue 54): four exports with a folder where the px4 file
/// goes, the Kalibr and imu_utils files beside them, existing files of an earlier run. Nothing
/// is replaced, nothing new appears, no temporary is left, and the message says what is there.
#[test]
fn allan_outputs_are_written_all_or_none() {
    let dir = tempfile::tempdir().unwrap();
    let sim = simulate(dir.path());
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("k.yaml"), "earlier run\n").unwrap();
    std::fs::create_dir(out.join("px4.params")).unwrap();
    let run = |px4: &str| {
        let mut c = gyrolab();
        c.current_dir(&out).arg("allan").arg(&sim);
        for t in ["kalibr=k.yaml", "openvins=ov.yaml", px4, "vins=v.yaml"] {
            c.args(["--export", t]);
        }
        c.args(["--kalibr-yaml", "kalibr_plain.yaml", "--imu-utils-yaml", "imu_utils.yaml"]);
        c
    };
    let before = names_in(&out);
    let err = run("px4=px4.params").assert().code(2).get_output().stderr.clone();
    let err = String::from_utf8_lossy(&err);
    assert!(err.contains("px4.params") && err.contains("a folder"), "{err}");
    assert!(err.contains("no file of this run was written") && err.contains("left as they were: k.yaml"), "{err}");
    assert!(err.contains("not there: ") && err.contains("v.yaml"), "{err}");
    assert_eq!(names_in(&out), before);
    assert_eq!(std::fs::read_to_string(out.join("k.yaml")).unwrap(), "earlier run\n");
    // The same run with a file target: all six files, the earlier k.yaml replaced.
    run("px4=px4.txt").assert().success();
    assert_eq!(
        names_in(&out),
        ["imu_utils.yaml", "k.yaml", "kalibr_plain.yaml", "ov.yaml", "px4.params", "px4.txt", "v.yaml"]
    );
    assert!(std::fs::read_to_string(out.join("k.yaml")).unwrap().contains("gyroscope_noise_density"));
}

/// A full disk (a file-size limit of 1 KiB, below a Kalibr file's size, with SIGXFSZ ignored so
/// that a write fails with EFBIG as on a full file system): no output is left behind, the
/// earlier file stays, no temporary is left, exit 1 with the file named.
#[cfg(unix)]
#[test]
fn a_full_disk_leaves_every_output_as_it_was() {
    let dir = tempfile::tempdir().unwrap();
    let sim = simulate(dir.path());
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("k.yaml"), "earlier run\n").unwrap();
    let bin = assert_cmd::cargo::cargo_bin("gyrolab");
    let script = format!(
        "trap '' XFSZ; ulimit -f 1; exec '{}' allan '{}' --export kalibr=k.yaml --export openvins=ov.yaml --kalibr-yaml big.yaml",
        bin.display(),
        sim.display()
    );
    let o = std::process::Command::new("sh").arg("-c").arg(&script).current_dir(&out).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("cannot write the file") && err.contains("no file of this run was written"), "{err}");
    assert_eq!(names_in(&out), ["k.yaml"], "{err}");
    assert_eq!(std::fs::read_to_string(out.join("k.yaml")).unwrap(), "earlier run\n");
}

/// An output never overwrites an input: an export named as the record itself is refused (exit
/// 2) before anything is written, and the record is unchanged.
#[test]
fn an_export_never_overwrites_the_record() {
    let dir = tempfile::tempdir().unwrap();
    let sim = simulate(dir.path());
    let before = std::fs::read(&sim).unwrap();
    let err = gyrolab()
        .current_dir(dir.path())
        .args(["allan", "sim.csv", "--export", "kalibr=k.yaml", "--export", "vins=./sim.csv"])
        .assert()
        .code(2)
        .get_output()
        .stderr
        .clone();
    let err = String::from_utf8_lossy(&err);
    assert!(err.contains("never overwrites an input"), "{err}");
    assert_eq!(std::fs::read(&sim).unwrap(), before);
    assert!(!dir.path().join("k.yaml").exists());
}

/// A GMWM POOR FIT is not exported in silence (issue 54): a record whose curve no model
/// describes (white noise and a 0.2 Hz sine of 0.5 deg/s: a bump at 1 to 3 s) with
/// `--estimator gmwm --export` writes nothing and exits 7 naming `--allow-poor-fit`; with it
/// the file is written with a warning, exit 0.
#[test]
fn a_gmwm_poor_fit_export_exits_7_unless_allowed() {
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};
    let dir = tempfile::tempdir().unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    let mut text = String::from("time_s,gyro_x [deg/s]\n");
    for i in 0..60_000 {
        let t = i as f64 / 100.0;
        let w: f64 = StandardNormal.sample(&mut rng);
        text.push_str(&format!("{t:.2},{:.9e}\n", 0.05 * w + 0.5 * (2.0 * std::f64::consts::PI * 0.2 * t).sin()));
    }
    let record = common::write(dir.path(), "sine.csv", &text);
    let k = dir.path().join("k.yaml");
    let run = |allow: bool| {
        let mut c = gyrolab();
        c.arg("allan").arg(&record).args(["--estimator", "gmwm", "--export"]).arg(format!("kalibr={}", k.display()));
        if allow {
            c.arg("--allow-poor-fit");
        }
        c.output().unwrap()
    };
    let out = run(false);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(7), "{err}");
    assert!(
        err.contains("GMWM POOR FIT") && err.contains("--allow-poor-fit") && err.contains("no export file was written"),
        "{err}"
    );
    assert!(!k.exists());
    let out = run(true);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("is from a GMWM POOR FIT in the exports"), "{err}");
    assert!(std::fs::read_to_string(&k).unwrap().contains("GMWM POOR FIT"));
    // --allow-poor-fit without --export is a usage error, as the other export options.
    gyrolab().arg("allan").arg(&record).arg("--allow-poor-fit").assert().code(2);
}
