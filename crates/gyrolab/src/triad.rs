//! Three-axis (triad) gyro calibration: the 3x3 scale-factor-and-misalignment matrix and the bias
//! vector (12 parameters) from rate-table plateaus about each table axis, both senses.
//!
//! Model: u = S omega + b, with u the three gyro outputs, omega the table rate vector in deg/s
//! (rate times the unit vector of the table axis), S (output units per deg/s) whose diagonal
//! holds the scale factors and whose off-diagonal terms are the cross-axis sensitivities, and b
//! the bias vector (output units). It is the forward form of the model omega = T K (u - b) of
//! Tedaldi, Pretto & Menegatti, "A robust and easy to implement method for IMU calibration
//! without external equipments", ICRA 2014 (imu_tk; also imucal), with S = (T K)^-1.
//! Terms (scale factor, cross-axis sensitivity, input-axis misalignment) after IEEE Std 528 and
//! IEEE Std 952-1997. Solution: each output row is an independent 4-parameter linear
//! least-squares problem [omega_x omega_y omega_z 1] [S_i1 S_i2 S_i3 b_i]^T = u_i, solved by
//! Householder QR on the column-equilibrated design (Golub & Van Loan, Matrix Computations,
//! section 5.3), never by normal equations; the condition number comes from its SVD.
//! `docs/METHODS.md` (section 5) gives every formula with its units.

use crate::segment::{SegmentError, SteadySegment};
use crate::units;
use nalgebra::{DMatrix, Matrix3};
use serde::{Deserialize, Serialize};
use std::fmt;
use thiserror::Error;

/// A table axis (equally, the index of a gyro in the triad: x, y, z).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TableAxis {
    /// x axis.
    X,
    /// y axis.
    Y,
    /// z axis.
    Z,
}

impl TableAxis {
    /// The three axes in order.
    pub const ALL: [TableAxis; 3] = [TableAxis::X, TableAxis::Y, TableAxis::Z];

    /// Index 0, 1, 2.
    pub fn index(self) -> usize {
        self as usize
    }

    /// Label `x`, `y` or `z`.
    pub fn label(self) -> &'static str {
        ["x", "y", "z"][self.index()]
    }

    /// Parses `x`, `y`, `z` (any case).
    pub fn parse(s: &str) -> Option<TableAxis> {
        match s.trim().to_ascii_lowercase().as_str() {
            "x" => Some(TableAxis::X),
            "y" => Some(TableAxis::Y),
            "z" => Some(TableAxis::Z),
            _ => None,
        }
    }
}

impl fmt::Display for TableAxis {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.label())
    }
}

/// One plateau of a three-axis test: table rate about one axis and the mean of the three outputs.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TriadPlateau {
    /// The table axis the unit turned about.
    pub axis: TableAxis,
    /// Table rate about it, deg/s (0 for rest).
    pub rate_dps: f64,
    /// Mean output of gyros x, y, z, output units.
    pub output: [f64; 3],
    /// Samples averaged.
    pub samples: usize,
    /// Time of the plateau's first sample, s (to locate it in its log).
    pub start_time_s: f64,
}

impl TriadPlateau {
    /// The table rate vector omega = rate * e_axis, deg/s.
    pub fn rate_vector(&self) -> [f64; 3] {
        let mut w = [0.0; 3];
        w[self.axis.index()] = self.rate_dps;
        w
    }
}

/// Means of the three outputs over each steady segment of a log turning about `axis` (rest
/// segments included: they carry the bias).
pub fn plateaus_from_segments(
    axis: TableAxis,
    segments: &[SteadySegment],
    time_s: &[f64],
    outputs: [&[f64]; 3],
) -> Result<Vec<TriadPlateau>, SegmentError> {
    for (c, o) in outputs.iter().enumerate() {
        if o.len() != time_s.len() {
            let what = ["output x", "output y", "output z"][c];
            return Err(SegmentError::LengthMismatch { what, found: o.len(), expected: time_s.len() });
        }
    }
    let mut out = Vec::with_capacity(segments.len());
    for s in segments {
        if s.start_index >= s.end_index || s.end_index > time_s.len() {
            return Err(SegmentError::EmptySegment {
                start_s: s.start_time_s,
                end_s: s.end_time_s,
                log_start_s: time_s.first().copied().unwrap_or(f64::NAN),
                log_end_s: time_s.last().copied().unwrap_or(f64::NAN),
            });
        }
        let mut mean = [0.0; 3];
        for (c, o) in outputs.iter().enumerate() {
            let v = &o[s.start_index..s.end_index];
            if let Some(k) = v.iter().position(|x| !x.is_finite()) {
                let index = s.start_index + k;
                return Err(SegmentError::NonFinite { index, time_s: time_s[index], what: "output" });
            }
            mean[c] = v.iter().sum::<f64>() / v.len() as f64;
        }
        out.push(TriadPlateau {
            axis,
            rate_dps: s.rate_dps,
            output: mean,
            samples: s.samples(),
            start_time_s: s.start_time_s,
        });
    }
    Ok(out)
}

/// Options of the three-axis fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TriadOptions {
    /// Require rotations in both senses (positive and negative rates) about every axis.
    pub require_both_senses: bool,
    /// A plateau with |rate| at most this counts as rest, not as a rotation, deg/s.
    pub rest_tolerance_dps: f64,
    /// Largest condition number of the equilibrated design matrix accepted.
    pub max_condition: f64,
}

impl Default for TriadOptions {
    fn default() -> Self {
        TriadOptions { require_both_senses: true, rest_tolerance_dps: 0.05, max_condition: 1e6 }
    }
}

/// Why a three-axis calibration cannot be computed.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum TriadError {
    /// No plateau at all.
    #[error("no plateaus: a three-axis calibration needs rotations about x, y and z")]
    Empty,
    /// A value is NaN or infinite.
    #[error("plateau {index} (axis {axis}, t = {start_time_s} s): a rate or output is not a finite number")]
    NonFinite {
        /// Position of the plateau in the input.
        index: usize,
        /// Its axis.
        axis: TableAxis,
        /// Its start time, s.
        start_time_s: f64,
    },
    /// An axis has no rotation plateau.
    #[error(
        "no rotation about the {axis} axis: the set has {found} plateau(s) about other axes; a three-axis \
         calibration needs rotations about x, y and z (both senses)"
    )]
    MissingAxis {
        /// The axis without data.
        axis: TableAxis,
        /// Plateaus found in total.
        found: usize,
    },
    /// An axis was turned in one sense only.
    #[error("rotations about the {axis} axis are all {present}: rotations in both senses are needed")]
    MissingSense {
        /// The axis.
        axis: TableAxis,
        /// `positive` or `negative`: the sense present.
        present: &'static str,
    },
    /// Fewer plateaus than parameters per row.
    #[error("only {found} plateaus: the fit of 4 parameters per gyro needs at least 4 (better 6 or more)")]
    TooFewPlateaus {
        /// Plateaus given.
        found: usize,
    },
    /// The design is singular or nearly so.
    #[error(
        "the plateaus do not determine the 12 parameters: the condition number of the (equilibrated) design is \
         {condition:.3e}, above the limit {limit:.1e}; add rest records or rotations in the other sense"
    )]
    IllConditioned {
        /// Condition number found.
        condition: f64,
        /// Limit.
        limit: f64,
    },
    /// The fitted S cannot be inverted.
    #[error("the fitted scale-factor matrix is singular (condition number {condition:.3e}): it cannot be applied")]
    SingularMatrix {
        /// Condition number of S.
        condition: f64,
    },
}

/// Largest condition number of S accepted for inversion (a gyro triad has about 1.0 to 1.1).
pub const MAX_MATRIX_CONDITION: f64 = 1e10;

/// A three-axis calibration: what must be stored to turn outputs into rates.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TriadCalibration {
    /// S: row i = gyro i, column j = table axis j; output units per deg/s.
    pub matrix: [[f64; 3]; 3],
    /// Bias vector b, output units.
    pub bias: [f64; 3],
    /// Largest |table rate| of the calibration plateaus, deg/s: the model is valid inside it.
    pub rate_limit_dps: f64,
}

impl TriadCalibration {
    /// S^-1 ((deg/s) per output unit), or `None` when S is singular (condition number above
    /// [`MAX_MATRIX_CONDITION`] or not finite).
    pub fn inverse_matrix(&self) -> Option<[[f64; 3]; 3]> {
        let acceptable = matrix_condition(&self.matrix) <= MAX_MATRIX_CONDITION; // false for NaN
        if !acceptable {
            return None;
        }
        let m = to_matrix3(&self.matrix);
        let inv = m.try_inverse()?;
        if inv.iter().all(|v| v.is_finite()) {
            Some(from_matrix3(&inv))
        } else {
            None
        }
    }

    /// Outputs predicted for a rate vector: S omega + b.
    pub fn output_of(&self, omega_dps: [f64; 3]) -> [f64; 3] {
        let mut u = self.bias;
        for (i, ui) in u.iter_mut().enumerate() {
            *ui += (0..3).map(|j| self.matrix[i][j] * omega_dps[j]).sum::<f64>();
        }
        u
    }
}

fn to_matrix3(m: &[[f64; 3]; 3]) -> Matrix3<f64> {
    Matrix3::from_fn(|i, j| m[i][j])
}

fn from_matrix3(m: &Matrix3<f64>) -> [[f64; 3]; 3] {
    let mut a = [[0.0; 3]; 3];
    for (i, row) in a.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = m[(i, j)];
        }
    }
    a
}

/// Condition number (largest over smallest singular value) of S.
pub fn matrix_condition(m: &[[f64; 3]; 3]) -> f64 {
    let sv = to_matrix3(m).singular_values();
    let (max, min) = (sv.max(), sv.min());
    if min > 0.0 {
        max / min
    } else {
        f64::INFINITY
    }
}

/// Residual of one plateau.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TriadResidual {
    /// Table axis.
    pub axis: TableAxis,
    /// Table rate, deg/s.
    pub rate_dps: f64,
    /// u - (S omega + b) per gyro, output units.
    pub output_residual: [f64; 3],
    /// S^-1 (u - b) - omega per axis, deg/s.
    pub rate_error_dps: [f64; 3],
}

/// The result of a three-axis fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TriadFit {
    /// S and b (what a calibration file stores).
    pub calibration: TriadCalibration,
    /// S^-1, (deg/s) per output unit: omega = S^-1 (u - b).
    pub inverse: [[f64; 3]; 3],
    /// Scale factor of each gyro, S_ii, output units per deg/s.
    pub scale_factors: [f64; 3],
    /// Cross-axis sensitivity S_ij / S_ii (i != j; 0 on the diagonal), ratio.
    pub cross_axis_sensitivity: [[f64; 3]; 3],
    /// The same in percent.
    pub cross_axis_sensitivity_pct: [[f64; 3]; 3],
    /// Misalignment angle of gyro i's input axis towards table axis j, atan(S_ij / S_ii), mrad.
    pub misalignment_mrad: [[f64; 3]; 3],
    /// Residual of every plateau, in input order.
    pub residuals: Vec<TriadResidual>,
    /// RMS of the output residuals per gyro, output units.
    pub rms_output_residual: [f64; 3],
    /// RMS of the rate errors per axis, deg/s.
    pub rms_rate_error_dps: [f64; 3],
    /// Condition number of the column-equilibrated design matrix [omega 1].
    pub design_condition: f64,
    /// Condition number of S.
    pub matrix_condition: f64,
    /// Plateaus used.
    pub plateaus: usize,
}

/// Fits the 12-parameter model u = S omega + b to plateaus about the three table axes.
pub fn fit_triad(plateaus: &[TriadPlateau], options: &TriadOptions) -> Result<TriadFit, TriadError> {
    if plateaus.is_empty() {
        return Err(TriadError::Empty);
    }
    for (index, p) in plateaus.iter().enumerate() {
        if !p.rate_dps.is_finite() || p.output.iter().any(|v| !v.is_finite()) {
            return Err(TriadError::NonFinite { index, axis: p.axis, start_time_s: p.start_time_s });
        }
    }
    for axis in TableAxis::ALL {
        let rot = || plateaus.iter().filter(|p| p.axis == axis && p.rate_dps.abs() > options.rest_tolerance_dps);
        let (pos, neg) = (rot().filter(|p| p.rate_dps > 0.0).count(), rot().filter(|p| p.rate_dps < 0.0).count());
        if pos + neg == 0 {
            return Err(TriadError::MissingAxis { axis, found: plateaus.len() });
        }
        if options.require_both_senses && (pos == 0 || neg == 0) {
            return Err(TriadError::MissingSense { axis, present: if pos > 0 { "positive" } else { "negative" } });
        }
    }
    let n = plateaus.len();
    if n < 4 {
        return Err(TriadError::TooFewPlateaus { found: n });
    }
    // Design [omega_x omega_y omega_z 1], columns scaled to unit norm.
    let design = DMatrix::from_fn(n, 4, |r, c| if c == 3 { 1.0 } else { plateaus[r].rate_vector()[c] });
    let norms: Vec<f64> = (0..4).map(|c| design.column(c).norm()).collect();
    let scaled = DMatrix::from_fn(n, 4, |r, c| design[(r, c)] / norms[c]);
    let sv = scaled.clone().singular_values();
    let design_condition = if sv.min() > 0.0 { sv.max() / sv.min() } else { f64::INFINITY };
    let acceptable = design_condition <= options.max_condition; // false for NaN
    if !acceptable {
        return Err(TriadError::IllConditioned { condition: design_condition, limit: options.max_condition });
    }
    let rhs = DMatrix::from_fn(n, 3, |r, c| plateaus[r].output[c]);
    let qr = scaled.qr();
    let qtb = qr.q().transpose() * rhs;
    let coef = qr
        .r()
        .solve_upper_triangular(&qtb)
        .ok_or(TriadError::IllConditioned { condition: design_condition, limit: options.max_condition })?;
    let mut matrix = [[0.0; 3]; 3];
    let mut bias = [0.0; 3];
    for i in 0..3 {
        for j in 0..3 {
            matrix[i][j] = coef[(j, i)] / norms[j];
        }
        bias[i] = coef[(3, i)] / norms[3];
    }
    let rate_limit_dps = plateaus.iter().map(|p| p.rate_dps.abs()).fold(0.0, f64::max);
    let calibration = TriadCalibration { matrix, bias, rate_limit_dps };
    let condition = matrix_condition(&matrix);
    let inverse = calibration.inverse_matrix().ok_or(TriadError::SingularMatrix { condition })?;
    let scale_factors = [matrix[0][0], matrix[1][1], matrix[2][2]];
    let mut cross = [[0.0; 3]; 3];
    let mut cross_pct = [[0.0; 3]; 3];
    let mut angles = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            if i != j {
                cross[i][j] = matrix[i][j] / matrix[i][i];
                cross_pct[i][j] = units::ratio_to_pct(cross[i][j]);
                angles[i][j] = units::rad_to_mrad(cross[i][j].atan());
            }
        }
    }
    let mut residuals = Vec::with_capacity(n);
    let (mut ss_out, mut ss_rate) = ([0.0; 3], [0.0; 3]);
    for p in plateaus {
        let w = p.rate_vector();
        let predicted = calibration.output_of(w);
        let mut output_residual = [0.0; 3];
        let mut rate_error_dps = [0.0; 3];
        for i in 0..3 {
            output_residual[i] = p.output[i] - predicted[i];
        }
        for i in 0..3 {
            let est: f64 = (0..3).map(|j| inverse[i][j] * (p.output[j] - bias[j])).sum();
            rate_error_dps[i] = est - w[i];
            ss_out[i] += output_residual[i] * output_residual[i];
            ss_rate[i] += rate_error_dps[i] * rate_error_dps[i];
        }
        residuals.push(TriadResidual { axis: p.axis, rate_dps: p.rate_dps, output_residual, rate_error_dps });
    }
    let rms = |ss: [f64; 3]| ss.map(|s| (s / n as f64).sqrt());
    Ok(TriadFit {
        calibration,
        inverse,
        scale_factors,
        cross_axis_sensitivity: cross,
        cross_axis_sensitivity_pct: cross_pct,
        misalignment_mrad: angles,
        residuals,
        rms_output_residual: rms(ss_out),
        rms_rate_error_dps: rms(ss_rate),
        design_condition,
        matrix_condition: condition,
        plateaus: n,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::apply::{RangeStatus, TriadApplier};
    use crate::segment::{find_steady_segments, SegmentOptions};
    use crate::sim::{raw_log_setpoints, simulate_raw_log, RawLogProfile, SimulatedRawLog};
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, Normal};

    const RATES: [f64; 6] = [-300.0, -100.0, -30.0, 30.0, 100.0, 300.0];
    const SIGMA_U: f64 = 0.002; // output noise per sample, V
    const K: [f64; 3] = [0.0075, 0.0076, 0.0074]; // V/(deg/s)
    const BIAS: [f64; 3] = [2.50, 2.51, 2.49]; // V
    /// Misalignment of gyro i's input axis towards table axis j, rad (2 to 5 mrad).
    const ANGLE: [[f64; 3]; 3] = [[0.0, 3e-3, -2e-3], [4e-3, 0.0, 2.5e-3], [-5e-3, 3.5e-3, 0.0]];

    /// True S: row i is K_i times gyro i's input-axis direction (unit along i, tan(angle) along j).
    fn true_matrix() -> [[f64; 3]; 3] {
        let mut s = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                s[i][j] = if i == j { K[i] } else { K[i] * ANGLE[i][j].tan() };
            }
        }
        s
    }

    struct AxisLog {
        sim: SimulatedRawLog,
        outputs: [Vec<f64>; 3],
    }

    fn axis_log(axis: TableAxis, seed: u64) -> AxisLog {
        let sim = simulate_raw_log(&raw_log_setpoints(&RATES, 1, true, true), &RawLogProfile::default(), seed).unwrap();
        let s = true_matrix();
        let mut rng = ChaCha8Rng::seed_from_u64(seed + 100);
        let noise = Normal::new(0.0, SIGMA_U).unwrap();
        let j = axis.index();
        let outputs = [0, 1, 2].map(|i| {
            sim.true_rate.iter().map(|w| BIAS[i] + s[i][j] * w + noise.sample(&mut rng)).collect::<Vec<f64>>()
        });
        AxisLog { sim, outputs }
    }

    fn plateaus_of(axis: TableAxis, log: &AxisLog) -> Vec<TriadPlateau> {
        let steady = find_steady_segments(&log.sim.time, &log.sim.logged_rate, &SegmentOptions::default()).unwrap();
        let o = [&log.outputs[0][..], &log.outputs[1][..], &log.outputs[2][..]];
        plateaus_from_segments(axis, &steady, &log.sim.time, o).unwrap()
    }

    fn all_plateaus() -> (Vec<TriadPlateau>, Vec<AxisLog>) {
        let logs: Vec<AxisLog> = TableAxis::ALL.iter().map(|&a| axis_log(a, 40 + a.index() as u64)).collect();
        let p = TableAxis::ALL.iter().flat_map(|&a| plateaus_of(a, &logs[a.index()])).collect();
        (p, logs)
    }

    /// Standard errors from the noise: each plateau mean has sigma_u / sqrt(n) with n >= 850 kept
    /// samples (10 s holds at 100 Hz less 1 s settling and <= 0.5 s overshoot); S_ij is the slope
    /// on omega_j, so its standard error is that over sqrt(sum of omega_j^2) (the design is
    /// nearly centred: rests and both senses); an angle's is that divided by K_i.
    fn standard_errors(p: &[TriadPlateau]) -> ([f64; 3], f64) {
        let sigma_mean = SIGMA_U / 850f64.sqrt();
        let se_s = TableAxis::ALL.map(|a| {
            let sxx: f64 = p.iter().filter(|q| q.axis == a).map(|q| q.rate_dps * q.rate_dps).sum();
            sigma_mean / sxx.sqrt()
        });
        (se_s, sigma_mean / (p.len() as f64).sqrt())
    }

    #[test]
    fn matrix_angles_and_biases_recovered_from_simulated_logs() {
        let (p, _) = all_plateaus();
        // rest + 11 plateaus + rest per axis.
        assert_eq!(p.len(), 3 * 13);
        let f = fit_triad(&p, &TriadOptions::default()).unwrap();
        let (se_s, se_b) = standard_errors(&p);
        let s = true_matrix();
        for i in 0..3 {
            for j in 0..3 {
                let got = f.calibration.matrix[i][j];
                assert!((got - s[i][j]).abs() < 5.0 * se_s[j], "S[{i}][{j}] = {got} vs {} (se {})", s[i][j], se_s[j]);
                if i != j {
                    let tol_mrad = 5.0 * se_s[j] / K[i] * 1e3 * 1.01;
                    assert!(tol_mrad < 0.1, "the test must resolve 0.1 mrad: {tol_mrad}");
                    let got = f.misalignment_mrad[i][j];
                    assert!((got - ANGLE[i][j] * 1e3).abs() < tol_mrad, "angle {i}{j}: {got} mrad");
                    let pct = f.cross_axis_sensitivity_pct[i][j];
                    assert!((pct - ANGLE[i][j].tan() * 100.0).abs() < tol_mrad / 10.0, "cross {i}{j}: {pct} %");
                }
            }
            assert!((f.scale_factors[i] - K[i]).abs() < 5.0 * se_s[i]);
            assert!((f.calibration.bias[i] - BIAS[i]).abs() < 5.0 * se_b, "b[{i}] = {}", f.calibration.bias[i]);
            // RMS output residual: about the noise of a plateau mean.
            assert!(f.rms_output_residual[i] < 2.0 * SIGMA_U / 850f64.sqrt(), "{:?}", f.rms_output_residual);
        }
        assert!(f.design_condition < 10.0, "{}", f.design_condition);
        assert_eq!(f.calibration.rate_limit_dps.round(), 300.0);
        assert_eq!(f.residuals.len(), p.len());
        // S S^-1 = I.
        for i in 0..3 {
            for j in 0..3 {
                let v: f64 = (0..3).map(|k| f.calibration.matrix[i][k] * f.inverse[k][j]).sum();
                assert!((v - if i == j { 1.0 } else { 0.0 }).abs() < 1e-12);
            }
        }
    }

    /// Applying the calibration to its own plateaus gives the table rates back within the noise:
    /// a plateau mean's rate error is sigma_u / sqrt(n) / K (about 0.01 deg/s), and on single
    /// samples the spread of the calibrated rate is sigma_u / K (0.27 deg/s).
    #[test]
    fn applying_the_calibration_returns_the_table_rates() {
        let (p, logs) = all_plateaus();
        let f = fit_triad(&p, &TriadOptions::default()).unwrap();
        let apply = TriadApplier::new(&f.calibration).unwrap();
        let tol = 5.0 * SIGMA_U / 850f64.sqrt() / 0.0074 + 5.0 * 0.01 / 850f64.sqrt();
        for q in &p {
            let got = apply.rates(q.output);
            assert_eq!(got.status, RangeStatus::Inside);
            let w = q.rate_vector();
            for (g, t) in got.rates_dps.iter().zip(w) {
                assert!((g - t).abs() < tol, "{q:?}: {:?}", got.rates_dps);
            }
        }
        // Sample by sample over one plateau of the y log (the +300 deg/s hold).
        let log = &logs[1];
        let steady = find_steady_segments(&log.sim.time, &log.sim.logged_rate, &SegmentOptions::default()).unwrap();
        let top = steady.iter().max_by(|a, b| a.rate_dps.total_cmp(&b.rate_dps)).unwrap();
        let r = top.start_index..top.end_index;
        let mut out = Vec::new();
        apply
            .apply_block(&log.outputs[0][r.clone()], &log.outputs[1][r.clone()], &log.outputs[2][r], &mut out)
            .unwrap();
        let n = out.len() as f64;
        let mean_y = out.iter().map(|a| a.rates_dps[1]).sum::<f64>() / n;
        let std_y = (out.iter().map(|a| (a.rates_dps[1] - mean_y).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        assert!((mean_y - top.rate_dps).abs() < tol, "{mean_y} vs {}", top.rate_dps);
        let expected_std = SIGMA_U / K[1];
        assert!((std_y / expected_std - 1.0).abs() < 0.1, "{std_y} vs {expected_std}");
    }

    #[test]
    fn a_set_missing_an_axis_or_a_sense_is_an_error() {
        let (p, _) = all_plateaus();
        let no_z: Vec<TriadPlateau> = p.iter().filter(|q| q.axis != TableAxis::Z).copied().collect();
        let e = fit_triad(&no_z, &TriadOptions::default()).unwrap_err();
        assert!(matches!(e, TriadError::MissingAxis { axis: TableAxis::Z, .. }), "{e}");
        assert!(e.to_string().contains("no rotation about the z axis"), "{e}");
        let y_positive: Vec<TriadPlateau> =
            p.iter().filter(|q| !(q.axis == TableAxis::Y && q.rate_dps < 0.0)).copied().collect();
        let e = fit_triad(&y_positive, &TriadOptions::default()).unwrap_err();
        assert!(matches!(e, TriadError::MissingSense { axis: TableAxis::Y, present: "positive" }), "{e}");
        // Accepted when one sense is allowed (rests pin the bias).
        let o = TriadOptions { require_both_senses: false, ..Default::default() };
        assert!(fit_triad(&y_positive, &o).is_ok());
        assert_eq!(fit_triad(&[], &o), Err(TriadError::Empty));
    }

    #[test]
    fn an_undetermined_set_is_ill_conditioned() {
        let plateau =
            |axis, rate_dps| TriadPlateau { axis, rate_dps, output: [1.0, 2.0, 3.0], samples: 1, start_time_s: 0.0 };
        let o = TriadOptions { require_both_senses: false, ..Default::default() };
        // One rate per axis and no rest: bias and scale factors cannot be told apart.
        let p = [
            plateau(TableAxis::X, 100.0),
            plateau(TableAxis::Y, 100.0),
            plateau(TableAxis::Z, 100.0),
            plateau(TableAxis::X, 100.0),
        ];
        let e = fit_triad(&p, &o).unwrap_err();
        assert!(matches!(e, TriadError::IllConditioned { .. }), "{e}");
        assert!(matches!(fit_triad(&p[..3], &o), Err(TriadError::TooFewPlateaus { found: 3 })));
        let mut bad = p;
        bad[1].output[2] = f64::NAN;
        assert!(matches!(fit_triad(&bad, &o), Err(TriadError::NonFinite { index: 1, .. })));
    }
}
