//! `evaluate_triad` on three simulated raw logs, one per table axis, of a triad with known
//! scale factors, misalignment angles and biases (the truth in `common`).

use crate::common;
use common::{flag, s_true, triad_log, ANGLE, BT, SIGMA_U, TRIAD_RATES};
use gyrolab::triad::TableAxis;
use gyrolab_eval::triad::{evaluate_triad, TriadRequest};
use gyrolab_eval::EvalError;

/// The matrix S, the misalignment angles and the biases are recovered within 5 standard errors
/// of the noise. Each log is one run over +-30, 100, 300 deg/s in both senses with rests at
/// both ends; a plateau mean keeps >= 850 samples of 2 mV noise (69 uV standard error).
/// S_ij is a slope over the plateaus of rotations about axis j: its standard error is
/// 69 uV / sqrt(sum of rate^2 over both strokes = 2 x (300^2 + 100^2 + 30^2)). An angle is
/// S_ij / S_ii, so its error is that over K (about 0.02 mrad): 0.1 mrad is 5 sigma. A bias
/// is a mean over all 39 plateaus and rests: 2 mV / sqrt(39 x 850).
#[test]
fn triad_matrix_angles_and_biases_recovered() {
    let dir = tempfile::tempdir().unwrap();
    let files: Vec<(TableAxis, std::path::PathBuf)> = TableAxis::ALL
        .into_iter()
        .enumerate()
        .map(|(a, axis)| (axis, triad_log(dir.path(), a, 40 + a as u64)))
        .collect();
    let request = TriadRequest { files, ..Default::default() };
    let result = evaluate_triad(&request).unwrap();
    let fit = &result.fit;
    let s = s_true();
    let sum_r2: f64 = TRIAD_RATES.iter().map(|r| r * r).sum();
    let se_s = SIGMA_U / 850f64.sqrt() / sum_r2.sqrt();
    for i in 0..3 {
        for j in 0..3 {
            let got = fit.calibration.matrix[i][j];
            assert!((got - s[i][j]).abs() < 5.0 * se_s, "S[{i}][{j}] = {got}, truth {}", s[i][j]);
            if i != j {
                let mrad = fit.misalignment_mrad[i][j];
                assert!((mrad - ANGLE[i][j] * 1e3).abs() < 0.1, "angle {i}{j} = {mrad} mrad");
            }
        }
        let b = fit.calibration.bias[i];
        assert!((b - BT[i]).abs() < 5.0 * SIGMA_U / (39.0f64 * 850.0).sqrt(), "b[{i}] = {b}, truth {}", BT[i]);
    }
    // 13 plateaus per log (rest, 6 rates up, 5 down plus the shared turning hold, rest).
    assert_eq!(fit.plateaus, 39);
    assert_eq!(result.gyro_columns, ["gx_v", "gy_v", "gz_v"]);
    let cal = result.calibration_file().to_toml().unwrap();
    assert!(cal.contains("[triad]"), "{cal}");
}

/// A set without a log about z: a conflict naming the field `triad_z`, spelled by the caller.
#[test]
fn a_set_missing_z_is_a_conflict_naming_triad_z() {
    let dir = tempfile::tempdir().unwrap();
    let files = vec![(TableAxis::X, triad_log(dir.path(), 0, 1)), (TableAxis::Y, triad_log(dir.path(), 1, 2))];
    let e = evaluate_triad(&TriadRequest { files, ..Default::default() }).unwrap_err();
    match &e {
        EvalError::Conflict { fields, .. } => assert_eq!(fields, &["triad_z"]),
        other => panic!("expected a conflict, got {other:?}"),
    }
    let text = e.render(&flag);
    assert!(text.contains("--triad-z"), "{text}");
    assert!(text.contains("misses the z axis"), "{text}");
    assert!(e.to_string().contains("`triad_z`"), "{e}");
}
