use super::*;

fn term(v: f64, basis: &'static str) -> ExportTerm {
    ExportTerm {
        value: v,
        estimate: v,
        overbound_factor: None,
        source: TermSource { basis: basis.into(), detail: "test".into() },
    }
}

/// N = 1e-3 rad/s/sqrt(Hz), K = 2e-5 rad/s^2/sqrt(Hz), accel 4e-3, 6e-4 at 400 Hz.
pub(super) fn sample() -> NoiseExport {
    NoiseExport {
        record: "imu.csv".into(),
        rate_hz: 400.0,
        simulated: true,
        estimator: "slopes".into(),
        inflation: 1.0,
        gyro_noise: Some(term(1e-3, "value")),
        gyro_walk: Some(term(2e-5, "upper_bound")),
        accel_noise: Some(term(4e-3, "value")),
        accel_walk: Some(term(6e-4, "fit_value")),
        rostopic: None,
        motion: Vec::new(),
        unrepresented: Vec::new(),
        writer: "test".into(),
        per_axis: [None; 4],
    }
}

/// The value of `key` in `key: value` or `param set key value` or tab-separated lines.
pub(super) fn value_of(text: &str, key: &str) -> Option<f64> {
    for line in text.lines() {
        let l = line.trim();
        if l.starts_with('#') {
            continue;
        }
        if let Some(rest) = l.strip_prefix(&format!("{key}:")) {
            return rest.split('#').next()?.trim().parse().ok();
        }
        if let Some(rest) = l.strip_prefix(&format!("param set {key} ")) {
            return rest.trim().parse().ok();
        }
        let cells: Vec<&str> = l.split('\t').collect();
        if cells.len() == 5 && cells[2] == key {
            return cells[3].parse().ok();
        }
    }
    None
}

#[test]
fn real_text_reads_back_and_is_a_yaml_1_1_float() {
    for v in [1e-3, 2e-5, 1.6968e-4, 123.456, 0.1 + 0.2, 5e300, 1.0] {
        let t = real_text(v);
        assert_eq!(t.parse::<f64>().unwrap(), v, "{t}");
        // PyYAML's float: digits '.' digits [eE][-+]digits
        let (m, e) = t.split_once('e').unwrap();
        assert!(m.contains('.'), "{t}");
        assert!(e.starts_with('-') || e.starts_with('+'), "{t}");
    }
}

#[test]
fn continuous_stacks_write_the_densities_under_their_keys() {
    let n = sample();
    for (stack, keys) in [
        (
            Stack::Kalibr,
            [
                "gyroscope_noise_density",
                "gyroscope_random_walk",
                "accelerometer_noise_density",
                "accelerometer_random_walk",
            ],
        ),
        (Stack::Orbslam3, ["IMU.NoiseGyro", "IMU.GyroWalk", "IMU.NoiseAcc", "IMU.AccWalk"]),
    ] {
        let text = n.render(stack);
        for (k, want) in keys.iter().zip([1e-3, 2e-5, 4e-3, 6e-4]) {
            assert_eq!(value_of(&text, k), Some(want), "{stack:?} {k}\n{text}");
        }
        assert!(text.contains("SIMULATED"), "{text}");
        assert!(text.contains("upper_bound"), "{text}");
    }
    assert!(n.render(Stack::Orbslam3).contains("\nIMU.Frequency: 400\n"));
    assert!(n.render(Stack::Kalibr).contains("\nupdate_rate: 400\n"));
}

/// VINS-Fusion's values per sample at 400 Hz, by hand: gyr_n = 1e-3 x sqrt(800) =
/// 2.8284271e-2 rad/s, gyr_w = 2e-5 x sqrt(400) = 4e-4 rad/s^2, acc_n = 4e-3 x sqrt(800) =
/// 1.1313708e-1 m/s^2, acc_w = 6e-4 x 20 = 1.2e-2 m/s^3 (the propagation test proves the rule).
#[test]
fn vins_values_are_per_sample() {
    let text = sample().render(Stack::Vins);
    for (k, want) in
        [("gyr_n", 2.828_427_124_746_19e-2), ("gyr_w", 4e-4), ("acc_n", 1.131_370_849_898_476e-1), ("acc_w", 1.2e-2)]
    {
        let got = value_of(&text, k).unwrap();
        assert!((got / want - 1.0).abs() < 1e-12, "{k}: {got}\n{text}");
    }
    assert!(text.contains("SIMULATED") && text.contains("per IMU sample at 400 Hz"), "{text}");
}

/// A rate whole to 1e-9 is written as an integer everywhere (Kalibr, OpenVINS, ORB-SLAM3,
/// Basalt); another rate as its shortest decimal, and ORB-SLAM3's IMU.Frequency as the nearest
/// integer with a comment giving the rate.
#[test]
fn whole_rates_are_integers() {
    let mut n = sample();
    n.rate_hz = 200.00000000635782;
    for stack in [Stack::Kalibr, Stack::Openvins, Stack::Orbslam3, Stack::Basalt] {
        let text = n.render(stack);
        assert!(!text.contains("200.0000"), "{stack:?}\n{text}");
    }
    assert!(n.render(Stack::Kalibr).contains("\nupdate_rate: 200\n"));
    assert!(n.render(Stack::Basalt).contains("\"imu_update_rate\": 200,"));
    n.rate_hz = 204.58265139116196;
    assert!(n.render(Stack::Kalibr).contains("\nupdate_rate: 204.58265139116196\n"));
    let orb = n.render(Stack::Orbslam3);
    assert!(
        orb.contains("\nIMU.Frequency: 205\n") && orb.contains("the record's rate is 204.58265139116196 Hz"),
        "{orb}"
    );
    assert_eq!(whole_rate(199.9999), None);
    assert_eq!(whole_rate(199.99999999), Some(200));
    assert_eq!(whole_rate(0.2), None);
}

#[test]
fn px4_values_are_per_step_at_the_ekf2_default_rate() {
    let n = sample();
    for stack in [Stack::Px4, Stack::Px4Qgc] {
        let text = n.render(stack);
        // hand, at EKF2's 100 Hz step (not the record's 400 Hz): 1e-3 x sqrt(100) = 0.01 rad/s;
        // 2e-5 x 10 = 2e-4 rad/s^2; 4e-3 x 10 = 0.04 m/s^2; 6e-4 x 10 = 0.006 m/s^3
        for (k, want) in [
            ("EKF2_GYR_NOISE", 0.01),
            ("EKF2_GYR_B_NOISE", 2e-4),
            ("EKF2_ACC_NOISE", 0.04),
            ("EKF2_ACC_B_NOISE", 0.006),
        ] {
            let got = value_of(&text, k).unwrap_or(f64::NAN);
            assert!((got / want - 1.0).abs() < 1e-12, "{stack:?} {k}: {got}\n{text}");
        }
    }
}

#[test]
fn ros_covariance_holds_per_sample_variances() {
    let text = sample().render(Stack::RosCovariance);
    let line = text.lines().find(|l| l.starts_with("angular_velocity_covariance:")).unwrap();
    let inner = line.split('[').nth(1).unwrap().split(']').next().unwrap();
    let v: Vec<f64> = inner.split(',').map(|x| x.trim().parse().unwrap()).collect();
    // (1e-3 x sqrt(400))^2 = 4e-4 (rad/s)^2
    assert!((v[0] / 4e-4 - 1.0).abs() < 1e-12 && v[4] == v[0] && v[8] == v[0] && v[1] == 0.0, "{v:?}");
    assert!(text.contains("orientation_covariance: [-1.0"));
}

#[test]
fn a_missing_term_is_named_not_invented() {
    let mut n = sample();
    n.accel_noise = None;
    n.accel_walk = None;
    for stack in STACKS {
        let text = n.render(stack);
        assert!(text.contains("not written") || text.contains("not estimated"), "{stack:?}\n{text}");
        assert_eq!(value_of(&text, "acc_n"), None);
    }
    assert!(!n.render(Stack::Basalt).contains("accel_noise_std"));
}

#[test]
fn stack_names_parse() {
    for s in STACKS {
        assert_eq!(Stack::parse(s.name()), Some(s));
    }
    assert_eq!(Stack::parse("ORBSLAM3"), Some(Stack::Orbslam3));
    assert_eq!(Stack::parse("gtsam"), None);
}

/// Terms the values do not model are one `NOT REPRESENTED:` header line each, in every stack's file.
#[test]
fn unrepresented_terms_are_header_lines() {
    let mut e = sample();
    e.unrepresented = vec!["gyro_x: the GMWM model holds a flicker floor (bias instability B = 1.0e-05 rad/s)".into()];
    for stack in STACKS {
        let lines = e.header_lines(stack);
        let hit =
            lines.iter().filter(|l| l.starts_with("NOT REPRESENTED: gyro_x: the GMWM model holds a flicker")).count();
        assert_eq!(hit, 1, "{}: {lines:?}", stack.name());
    }
    assert!(!sample().header_lines(Stack::Kalibr).iter().any(|l| l.contains("NOT REPRESENTED")));
}

/// Simulated marks read from a file's first line (issue 53): the simulator's records and
/// gyrolab's outputs made from simulated records (calibration.toml, a report's CSV tables);
/// a measured file, a FIFO (refused without blocking) and a missing file are not.
#[test]
fn simulated_marks_are_read_from_the_first_line() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        ("sim.csv", "# gyrolab simulated static record\ntime_s,rate_dps\n", true),
        ("cal.toml", "# SIMULATED DATA: this calibration comes from simulated records (x).\n", true),
        ("bom.csv", "\u{feff}# SIMULATED DATA\nrate_dps\n", true),
        ("measured.csv", "time_s,rate_dps\n0,1\n", false),
        ("later.csv", "time_s,rate_dps\n# gyrolab simulated\n", false),
    ];
    for (name, text, want) in cases {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        assert_eq!(crate::provenance::is_gyrolab_simulation(&p), want, "{name}");
    }
    assert!(!crate::provenance::is_gyrolab_simulation(&dir.path().join("missing.csv")));
    let fifo = dir.path().join("fifo.csv");
    let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    // SAFETY: a valid NUL-terminated path; mkfifo only creates the node.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    assert!(!crate::provenance::is_gyrolab_simulation(&fifo));
}
