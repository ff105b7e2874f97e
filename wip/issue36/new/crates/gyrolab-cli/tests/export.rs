//! `gyrolab allan --export`: the SIMULATED mark, the basis and factors in the header, GMWM as the
//! basis, the stack names, all-or-none writes (the files' readers: scripts/check_exports.py).

mod common;
use common::gyrolab;

fn simulate(dir: &std::path::Path) -> std::path::PathBuf {
    let p = dir.join("sim.csv");
    gyrolab()
        .args(["simulate", "static", "--duration-s", "2000", "--sample-rate-hz", "50", "--arw-deg-rt-h", "0.3"])
        .args(["--rrw-deg-h-rt-h", "20", "--seed", "36", "--out"])
        .arg(&p)
        .assert()
        .success();
    p
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
    let f = dir.path().join("vins.yaml");
    gyrolab()
        .arg("allan")
        .arg(&sim)
        .args(["--estimator", "gmwm", "--export"])
        .arg(format!("vins={}", f.display()))
        .assert()
        .success();
    let text = std::fs::read_to_string(&f).unwrap();
    assert!(text.contains("estimator: gmwm") && text.contains("gmwm: GMWM estimate"), "{text}");
    // N = 0.3 deg/sqrt(h) = 0.005 deg/sqrt(s) = 8.727e-5 rad/s/sqrt(Hz): within 10 %.
    let n = value(&text, "gyr_n");
    assert!((n / (0.005f64.to_radians()) - 1.0).abs() < 0.1, "{n}");
    let json = gyrolab().arg("allan").arg(&sim).arg("--json").assert().success().get_output().stdout.clone();
    let v: serde_json::Value = serde_json::from_slice(&json).unwrap();
    assert_eq!(v["channels"][0]["gmwm"]["sided"], "two-sided");
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
