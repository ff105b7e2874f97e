//! g-sensitivity (acceleration-sensitive bias) from static records in several orientations.
//!
//! Sources: IEEE Std 1431-2004 (Coriolis vibratory gyros) and IEEE Std 952-1997 (single-axis
//! optical gyros), model equations: the g-sensitive drift term D_g · a of the rate equation;
//! GJB 2426A-2004 lists the g-sensitivity (acceleration-sensitive drift) tests made from static
//! records in several orientations. Least squares by the singular value decomposition
//! (Golub & Van Loan, Matrix Computations, sections 5.5 and 2.5: the pseudo-inverse, rank and
//! estimable functions of a rank-deficient problem).
//!
//! Model of one gyro axis in record i (orientation i):
//!
//!   B_i = B_0 + G_x f_xi + G_y f_yi + G_z f_zi
//!
//! with f_i the specific force (the reaction to gravity, pointing up) along the sensor's x, y, z
//! axes in g: with the sensor axis `+x` up, f = (+1, 0, 0). B in deg/h, G in (deg/h)/g.
//!
//! Earth rate: with a latitude phi, the earth rate's projection on the input axis,
//! Omega_e sin(phi) u_i with u_i the input axis's up component (f_input / |f|), is removed from
//! each bias. Horizontal input-axis components are taken as pointing east-west, where the
//! earth-rate projection is zero. A null measured at rest on a rate table with the input axis up
//! already contains Omega_e sin(phi); then Omega_e sin(phi) (u_i - 1) is removed instead.
//!
//! Only the components of (B_0, G) that the orientations span can be estimated: a component is
//! resolved when its unit vector lies in the row space of the design matrix [1, f_x, f_y, f_z]
//! (it is then the same for every least-squares solution). Standard errors come from the
//! residual variance s^2 = sum r_i^2 / (n - rank) and need n > rank.

use crate::units;
use nalgebra::{DMatrix, DVector};
use thiserror::Error;

/// A sensor axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum SensorAxis {
    /// x.
    X,
    /// y.
    Y,
    /// z.
    Z,
}

impl SensorAxis {
    /// The three axes in order.
    pub const ALL: [SensorAxis; 3] = [SensorAxis::X, SensorAxis::Y, SensorAxis::Z];

    /// Index 0, 1, 2.
    pub fn index(self) -> usize {
        match self {
            SensorAxis::X => 0,
            SensorAxis::Y => 1,
            SensorAxis::Z => 2,
        }
    }

    /// Name: `x`, `y` or `z`.
    pub fn name(self) -> &'static str {
        ["x", "y", "z"][self.index()]
    }

    /// Parses `x`, `y` or `z` (case-insensitive).
    pub fn parse(s: &str) -> Option<SensorAxis> {
        match s.trim().to_ascii_lowercase().as_str() {
            "x" => Some(SensorAxis::X),
            "y" => Some(SensorAxis::Y),
            "z" => Some(SensorAxis::Z),
            _ => None,
        }
    }
}

/// A named orientation: one sensor axis pointing up or down.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct NamedOrientation {
    /// The sensor axis pointing vertically.
    pub axis: SensorAxis,
    /// Whether its positive end points up (`+x up`) rather than down (`-x up`).
    pub positive_up: bool,
}

impl NamedOrientation {
    /// The names accepted by [`NamedOrientation::parse`].
    pub const NAMES: [&'static str; 6] = ["+x up", "-x up", "+y up", "-y up", "+z up", "-z up"];

    /// Parses `+x up`, `-x up`, `+y up`, `-y up`, `+z up`, `-z up` (case and spaces ignored).
    pub fn parse(s: &str) -> Option<NamedOrientation> {
        let t: String = s.chars().filter(|c| !c.is_whitespace()).collect::<String>().to_ascii_lowercase();
        let rest = t.strip_suffix("up")?;
        let (sign, axis) = rest.split_at_checked(1)?;
        let positive_up = match sign {
            "+" => true,
            "-" => false,
            _ => return None,
        };
        Some(NamedOrientation { axis: SensorAxis::parse(axis)?, positive_up })
    }

    /// The name as written in plans (`+x up`).
    pub fn name(self) -> String {
        format!("{}{} up", if self.positive_up { "+" } else { "-" }, self.axis.name())
    }

    /// The specific force in this orientation, g: 1 g along the axis, signed.
    pub fn specific_force_g(self) -> [f64; 3] {
        let mut f = [0.0; 3];
        f[self.axis.index()] = if self.positive_up { 1.0 } else { -1.0 };
        f
    }
}

/// One static record: the specific force it saw and its mean bias.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GRecord {
    /// Specific force along sensor x, y, z, g (reaction to gravity: up is positive).
    pub specific_force_g: [f64; 3],
    /// Mean bias of the record, deg/h, before any earth-rate correction.
    pub bias_dph: f64,
}

/// How the records are to be corrected for the earth rate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GSensitivityConfig {
    /// The sensor axis that is this gyro's input axis.
    pub input_axis: SensorAxis,
    /// Latitude of the site, deg; none: no earth-rate correction.
    pub latitude_deg: Option<f64>,
    /// Whether the null used for the biases was measured at rest with the input axis up (it then
    /// contains Omega_e sin(latitude) already).
    pub null_contains_earth_rate: bool,
}

/// A resolved coefficient and its standard error.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// Value (deg/h for B_0, (deg/h)/g for G).
    pub value: f64,
    /// Standard error; `None` when the residual has no degrees of freedom (see
    /// [`GSensitivityFit::std_error_absent`]).
    pub std_error: Option<f64>,
}

/// Why a coefficient could not be estimated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UnresolvedReason {
    /// No record had a specific force along this axis.
    NoSpecificForce,
    /// The records excite it, but only in a fixed combination with B_0 or another component
    /// (e.g. `+x up` alone: only B_0 + G_x is known).
    Confounded,
}

impl UnresolvedReason {
    /// The reason in words.
    pub fn text(self) -> &'static str {
        match self {
            UnresolvedReason::NoSpecificForce => "no record has a specific force along this axis",
            UnresolvedReason::Confounded => {
                "the orientations give it only in a fixed combination with the zero-g bias or another component"
            }
        }
    }

    /// A short key for JSON (`no_specific_force`, `confounded`).
    pub fn key(self) -> &'static str {
        match self {
            UnresolvedReason::NoSpecificForce => "no_specific_force",
            UnresolvedReason::Confounded => "confounded",
        }
    }
}

/// A coefficient: estimated, or not with the reason.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Coefficient {
    /// Spanned by the orientations.
    Resolved(Estimate),
    /// Not spanned.
    Unresolved(UnresolvedReason),
}

impl Coefficient {
    /// The estimate, when resolved.
    pub fn estimate(&self) -> Option<Estimate> {
        match self {
            Coefficient::Resolved(e) => Some(*e),
            Coefficient::Unresolved(_) => None,
        }
    }
}

/// Why standard errors are absent.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NoStdError {
    /// As many independent records as resolved unknowns: the fit is exact.
    NoResidualDegreesOfFreedom,
}

/// What `g_sensitivity_dph_per_g` is.
#[derive(Debug, Clone, PartialEq)]
pub enum MagnitudeKind {
    /// The single resolved component (its absolute value).
    Single(SensorAxis),
    /// The magnitude of the vector of the resolved components.
    Vector(Vec<SensorAxis>),
}

/// The summary figure: the magnitude of the resolved G (for a single resolved component, its
/// absolute value).
#[derive(Debug, Clone, PartialEq)]
pub struct Magnitude {
    /// Value, (deg/h)/g.
    pub value: f64,
    /// Standard error (first-order propagation through the covariance of the resolved components;
    /// none without residual degrees of freedom, or when the magnitude is 0).
    pub std_error: Option<f64>,
    /// Which it is.
    pub kind: MagnitudeKind,
}

/// One record in the fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FittedRecord {
    /// Specific force, g.
    pub specific_force_g: [f64; 3],
    /// Bias as measured, deg/h.
    pub bias_dph: f64,
    /// Up component of the input axis, f_input / |f| (0 for zero specific force).
    pub input_axis_up: f64,
    /// Earth rate removed from the bias, deg/h (0 without latitude).
    pub earth_rate_removed_dph: f64,
    /// Bias after the earth-rate correction, deg/h.
    pub corrected_bias_dph: f64,
    /// Corrected bias minus the fitted model, deg/h.
    pub residual_dph: f64,
}

/// The fitted g-sensitivity of one gyro axis.
#[derive(Debug, Clone, PartialEq)]
pub struct GSensitivityFit {
    /// Bias at zero specific force B_0, deg/h.
    pub bias_at_zero_g: Coefficient,
    /// G_x, G_y, G_z, (deg/h)/g.
    pub g_dph_per_g: [Coefficient; 3],
    /// The summary figure; none when no component is resolved (never: that is an error).
    pub magnitude: Option<Magnitude>,
    /// Records with their corrections and residuals, in input order.
    pub records: Vec<FittedRecord>,
    /// Rank of the design matrix (independent combinations estimated).
    pub rank: usize,
    /// Residual degrees of freedom n - rank.
    pub residual_dof: usize,
    /// Residual standard deviation s, deg/h; none without degrees of freedom.
    pub residual_std_dph: Option<f64>,
    /// Why standard errors are absent, if they are.
    pub std_error_absent: Option<NoStdError>,
    /// Earth-rate component along a vertical-up input axis, Omega_e sin(latitude), deg/h.
    pub earth_rate_vertical_dph: Option<f64>,
}

/// Why no g-sensitivity can be fitted.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum GSensitivityError {
    /// No record.
    #[error("no record: g-sensitivity needs static records in at least two orientations")]
    NoRecords,
    /// A value is NaN or infinite.
    #[error("record {index}: a specific force or bias is not finite")]
    NonFinite {
        /// 0-based record index.
        index: usize,
    },
    /// The orientations span no component of G.
    #[error(
        "the orientations span no g-sensitivity component ({records} record(s), {orientations} distinct \
         orientation(s)): record at least two orientations that differ along a sensor axis, e.g. +x up and -x up"
    )]
    NoSpan {
        /// Records.
        records: usize,
        /// Distinct specific-force vectors.
        orientations: usize,
    },
}

/// Tolerance on singular values relative to the largest.
const RANK_TOL: f64 = 1e-9;
/// Tolerance on a parameter's projection on the null space.
const ESTIMABLE_TOL: f64 = 1e-7;

/// The up component of the input axis for a specific force (0 for zero force).
pub fn input_axis_up(specific_force_g: [f64; 3], input_axis: SensorAxis) -> f64 {
    let n = specific_force_g.iter().map(|v| v * v).sum::<f64>().sqrt();
    if n > 0.0 {
        specific_force_g[input_axis.index()] / n
    } else {
        0.0
    }
}

/// Fits B_0 and G by least squares (see the module doc).
pub fn fit_g_sensitivity(
    records: &[GRecord],
    config: &GSensitivityConfig,
) -> Result<GSensitivityFit, GSensitivityError> {
    if records.is_empty() {
        return Err(GSensitivityError::NoRecords);
    }
    for (index, r) in records.iter().enumerate() {
        if !r.bias_dph.is_finite() || r.specific_force_g.iter().any(|v| !v.is_finite()) {
            return Err(GSensitivityError::NonFinite { index });
        }
    }
    let earth = config.latitude_deg.map(units::earth_rate_vertical_dph);
    let mut fitted: Vec<FittedRecord> = records
        .iter()
        .map(|r| {
            let up = input_axis_up(r.specific_force_g, config.input_axis);
            let removed = match earth {
                Some(e) if config.null_contains_earth_rate => e * (up - 1.0),
                Some(e) => e * up,
                None => 0.0,
            };
            FittedRecord {
                specific_force_g: r.specific_force_g,
                bias_dph: r.bias_dph,
                input_axis_up: up,
                earth_rate_removed_dph: removed,
                corrected_bias_dph: r.bias_dph - removed,
                residual_dph: 0.0,
            }
        })
        .collect();
    let n = fitted.len();
    // Padded with zero rows to at least 4, so the SVD's V is the full 4 x 4 basis (zero rows do
    // not change the row space or the solution).
    let rows = n.max(4);
    let mut a = DMatrix::<f64>::zeros(rows, 4);
    let mut b = DVector::<f64>::zeros(rows);
    for (i, r) in fitted.iter().enumerate() {
        a[(i, 0)] = 1.0;
        for j in 0..3 {
            a[(i, j + 1)] = r.specific_force_g[j];
        }
        b[i] = r.corrected_bias_dph;
    }
    let svd = a.clone().svd(true, true);
    let (Some(u), Some(v_t)) = (svd.u.as_ref(), svd.v_t.as_ref()) else {
        unreachable!("the SVD was asked for U and V") // ok: svd(true, true) computes both
    };
    let s = &svd.singular_values;
    let s_max = s.iter().cloned().fold(0.0, f64::max);
    let tol = RANK_TOL * s_max.max(f64::MIN_POSITIVE);
    let kept: Vec<usize> = (0..s.len()).filter(|&k| s[k] > tol).collect();
    let rank = kept.len();
    // Estimable: e_j lies in the row space spanned by the kept right singular vectors.
    let estimable: Vec<bool> = (0..4)
        .map(|j| {
            let in_row_space: f64 = kept.iter().map(|&k| v_t[(k, j)] * v_t[(k, j)]).sum();
            (1.0 - in_row_space).abs() < ESTIMABLE_TOL
        })
        .collect();
    let distinct = {
        let mut v: Vec<[u64; 3]> = fitted.iter().map(|r| r.specific_force_g.map(f64::to_bits)).collect();
        v.sort_unstable();
        v.dedup();
        v.len()
    };
    if !estimable[1..].iter().any(|&e| e) {
        return Err(GSensitivityError::NoSpan { records: n, orientations: distinct });
    }
    // Minimum-norm solution x = V S^+ U^T b, and (V S^+)(V S^+)^T for the covariance.
    let mut x = [0.0; 4];
    let mut w = [[0.0; 4]; 4]; // w[j][k] = V_jk / s_k
    for &k in &kept {
        let ub: f64 = (0..rows).map(|i| u[(i, k)] * b[i]).sum();
        for j in 0..4 {
            x[j] += v_t[(k, j)] * ub / s[k];
            w[j][k] = v_t[(k, j)] / s[k];
        }
    }
    let mut ss = 0.0;
    for (i, r) in fitted.iter_mut().enumerate() {
        let model: f64 = (0..4).map(|j| a[(i, j)] * x[j]).sum();
        r.residual_dph = r.corrected_bias_dph - model;
        ss += r.residual_dph * r.residual_dph;
    }
    let dof = n - rank;
    let s2 = (dof > 0).then(|| ss / dof as f64);
    let cov = |p: usize, q: usize| s2.map(|s2| s2 * (0..4).map(|k| w[p][k] * w[q][k]).sum::<f64>());
    let coefficient = |j: usize| {
        if estimable[j] {
            Coefficient::Resolved(Estimate { value: x[j], std_error: cov(j, j).map(|v| v.max(0.0).sqrt()) })
        } else if j > 0 && fitted.iter().all(|r| r.specific_force_g[j - 1] == 0.0) {
            Coefficient::Unresolved(UnresolvedReason::NoSpecificForce)
        } else {
            Coefficient::Unresolved(UnresolvedReason::Confounded)
        }
    };
    let g = [coefficient(1), coefficient(2), coefficient(3)];
    let resolved: Vec<SensorAxis> = SensorAxis::ALL.into_iter().filter(|a| estimable[a.index() + 1]).collect();
    let magnitude = match resolved.as_slice() {
        [] => None,
        [one] => Some(Magnitude {
            value: x[one.index() + 1].abs(),
            std_error: cov(one.index() + 1, one.index() + 1).map(|v| v.max(0.0).sqrt()),
            kind: MagnitudeKind::Single(*one),
        }),
        many => {
            let m = many.iter().map(|a| x[a.index() + 1].powi(2)).sum::<f64>().sqrt();
            // d|G|/dG_j = G_j / |G|: var = g^T C g / |G|^2.
            let se = if m > 0.0 {
                let mut var = Some(0.0);
                for p in many {
                    for q in many {
                        let (ip, iq) = (p.index() + 1, q.index() + 1);
                        var = var.zip(cov(ip, iq)).map(|(v, c)| v + x[ip] * x[iq] * c);
                    }
                }
                var.map(|v| (v / (m * m)).max(0.0).sqrt())
            } else {
                None
            };
            Some(Magnitude { value: m, std_error: se, kind: MagnitudeKind::Vector(many.to_vec()) })
        }
    };
    Ok(GSensitivityFit {
        bias_at_zero_g: coefficient(0),
        g_dph_per_g: g,
        magnitude,
        records: fitted,
        rank,
        residual_dof: dof,
        residual_std_dph: s2.map(f64::sqrt),
        std_error_absent: (dof == 0).then_some(NoStdError::NoResidualDegreesOfFreedom),
        earth_rate_vertical_dph: earth,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn named(s: &str) -> [f64; 3] {
        NamedOrientation::parse(s).unwrap().specific_force_g()
    }

    fn cfg() -> GSensitivityConfig {
        GSensitivityConfig { input_axis: SensorAxis::X, latitude_deg: None, null_contains_earth_rate: false }
    }

    fn rec(o: &str, bias_dph: f64) -> GRecord {
        GRecord { specific_force_g: named(o), bias_dph }
    }

    #[test]
    fn names_parse() {
        for n in NamedOrientation::NAMES {
            assert_eq!(NamedOrientation::parse(n).unwrap().name(), n);
        }
        assert_eq!(named("+x up"), [1.0, 0.0, 0.0]);
        assert_eq!(named("-Z UP"), [0.0, 0.0, -1.0]);
        assert_eq!(named(" - y  up"), [0.0, -1.0, 0.0]);
        for bad in ["x up", "+w up", "+x down", "", "+x", "++x up"] {
            assert!(NamedOrientation::parse(bad).is_none(), "{bad}");
        }
    }

    #[test]
    fn two_opposite_orientations_give_one_component_exactly() {
        // Hand-worked: B(+x) = 13, B(-x) = 7 -> B0 = (13 + 7)/2 = 10, G_x = (13 - 7)/2 = 3.
        let f = fit_g_sensitivity(&[rec("+x up", 13.0), rec("-x up", 7.0)], &cfg()).unwrap();
        let b0 = f.bias_at_zero_g.estimate().unwrap();
        let gx = f.g_dph_per_g[0].estimate().unwrap();
        assert!((b0.value - 10.0).abs() < 1e-12 && (gx.value - 3.0).abs() < 1e-12);
        assert_eq!((b0.std_error, gx.std_error), (None, None));
        assert_eq!(f.std_error_absent, Some(NoStdError::NoResidualDegreesOfFreedom));
        assert_eq!(f.g_dph_per_g[1], Coefficient::Unresolved(UnresolvedReason::NoSpecificForce));
        assert_eq!(f.g_dph_per_g[2], Coefficient::Unresolved(UnresolvedReason::NoSpecificForce));
        let m = f.magnitude.unwrap();
        assert_eq!(m.kind, MagnitudeKind::Single(SensorAxis::X));
        assert!((m.value - 3.0).abs() < 1e-12);
        // Swapped: G_x = (7 - 13)/2 = -3, the summary figure its absolute value 3.
        let f = fit_g_sensitivity(&[rec("+x up", 7.0), rec("-x up", 13.0)], &cfg()).unwrap();
        assert!((f.g_dph_per_g[0].estimate().unwrap().value + 3.0).abs() < 1e-12);
        assert!((f.magnitude.unwrap().value - 3.0).abs() < 1e-12);
        assert_eq!((f.rank, f.residual_dof), (2, 0));
    }

    #[test]
    fn six_orientations_hand_worked_with_standard_errors() {
        // Biases: B0 = 10, G = (3, -2, 0.5), plus residual pattern e = (+1, +1, -1, -1, 0, 0).
        // Normal equations of the six-position design are diagonal: B0 = mean, G_j = (B+j - B-j)/2.
        let biases = [13.0 + 1.0, 7.0 + 1.0, 8.0 - 1.0, 12.0 - 1.0, 10.5, 9.5];
        let names = ["+x up", "-x up", "+y up", "-y up", "+z up", "-z up"];
        let recs: Vec<GRecord> = names.iter().zip(biases).map(|(n, b)| rec(n, b)).collect();
        let f = fit_g_sensitivity(&recs, &cfg()).unwrap();
        let b0 = f.bias_at_zero_g.estimate().unwrap();
        assert!((b0.value - 10.0).abs() < 1e-12, "{b0:?}");
        let g: Vec<f64> = f.g_dph_per_g.iter().map(|c| c.estimate().unwrap().value).collect();
        assert!((g[0] - 3.0).abs() < 1e-12 && (g[1] + 2.0).abs() < 1e-12 && (g[2] - 0.5).abs() < 1e-12, "{g:?}");
        // Residuals: the mean of e is 0 and e is orthogonal to every f column, so r = e.
        let r: Vec<f64> = f.records.iter().map(|r| r.residual_dph).collect();
        for (ri, ei) in r.iter().zip([1.0, 1.0, -1.0, -1.0, 0.0, 0.0]) {
            assert!((ri - ei).abs() < 1e-12, "{r:?}");
        }
        // s^2 = 4 / (6 - 4) = 2; var(B0) = s^2 / 6; var(G_j) = s^2 / 2.
        assert_eq!((f.rank, f.residual_dof), (4, 2));
        assert!((f.residual_std_dph.unwrap() - 2f64.sqrt()).abs() < 1e-12);
        assert!((b0.std_error.unwrap() - (2.0f64 / 6.0).sqrt()).abs() < 1e-12);
        for c in &f.g_dph_per_g {
            assert!((c.estimate().unwrap().std_error.unwrap() - 1.0).abs() < 1e-12);
        }
        // |G| = sqrt(9 + 4 + 0.25); se = sqrt(g^T (I s^2/2) g) / |G| = 1.
        let m = f.magnitude.unwrap();
        assert!((m.value - 13.25f64.sqrt()).abs() < 1e-12);
        assert!((m.std_error.unwrap() - 1.0).abs() < 1e-12);
        assert_eq!(m.kind, MagnitudeKind::Vector(SensorAxis::ALL.to_vec()));
    }

    #[test]
    fn one_orientation_or_confounded_sets_do_not_span() {
        let e = fit_g_sensitivity(&[rec("+x up", 1.0), rec("+x up", 2.0)], &cfg()).unwrap_err();
        assert_eq!(e, GSensitivityError::NoSpan { records: 2, orientations: 1 });
        // +x up and +y up: only B0 + G_x and B0 + G_y are known.
        let e = fit_g_sensitivity(&[rec("+x up", 1.0), rec("+y up", 2.0)], &cfg()).unwrap_err();
        assert!(matches!(e, GSensitivityError::NoSpan { orientations: 2, .. }), "{e}");
        assert_eq!(fit_g_sensitivity(&[], &cfg()).unwrap_err(), GSensitivityError::NoRecords);
        let nan = GRecord { specific_force_g: [f64::NAN, 0.0, 0.0], bias_dph: 1.0 };
        assert_eq!(fit_g_sensitivity(&[nan], &cfg()).unwrap_err(), GSensitivityError::NonFinite { index: 0 });
    }

    #[test]
    fn partly_confounded_components_are_absent_with_reason() {
        // +x up and -x up resolve B0 = 10 and G_x = 3; the tilted record (0, 0.6, 0.8) excites y and
        // z only in the one combination 0.6 G_y + 0.8 G_z, so neither is resolved on its own.
        let tilted = GRecord { specific_force_g: [0.0, 0.6, 0.8], bias_dph: 12.0 };
        let f = fit_g_sensitivity(&[rec("+x up", 13.0), rec("-x up", 7.0), tilted], &cfg()).unwrap();
        assert!((f.g_dph_per_g[0].estimate().unwrap().value - 3.0).abs() < 1e-12);
        assert_eq!(f.g_dph_per_g[1], Coefficient::Unresolved(UnresolvedReason::Confounded));
        assert_eq!(f.g_dph_per_g[2], Coefficient::Unresolved(UnresolvedReason::Confounded));
        assert!((f.bias_at_zero_g.estimate().unwrap().value - 10.0).abs() < 1e-12);
        // Its opposite (0, -0.6, -0.8) excites the same combination: still confounded.
        let opposite = GRecord { specific_force_g: [0.0, -0.6, -0.8], bias_dph: 8.0 };
        let f = fit_g_sensitivity(&[rec("+x up", 13.0), rec("-x up", 7.0), tilted, opposite], &cfg()).unwrap();
        assert_eq!(f.g_dph_per_g[1], Coefficient::Unresolved(UnresolvedReason::Confounded));
        assert_eq!(f.magnitude.unwrap().kind, MagnitudeKind::Single(SensorAxis::X));
    }

    #[test]
    fn earth_rate_projection_is_removed() {
        // Truth: B0 = 10, G_x = 3 (input axis x). At latitude 30 deg, E = 15.041 sin 30 = 7.52 deg/h:
        // +x up measures 13 + E, -x up measures 7 - E.
        let lat = 30.0;
        let e = units::EARTH_RATE_DPH * 0.5;
        let c = GSensitivityConfig { latitude_deg: Some(lat), ..cfg() };
        let f = fit_g_sensitivity(&[rec("+x up", 13.0 + e), rec("-x up", 7.0 - e), rec("+y up", 10.0)], &c).unwrap();
        assert!((f.g_dph_per_g[0].estimate().unwrap().value - 3.0).abs() < 1e-9);
        assert!((f.bias_at_zero_g.estimate().unwrap().value - 10.0).abs() < 1e-9);
        assert!((f.records[0].earth_rate_removed_dph - e).abs() < 1e-9);
        assert_eq!(f.records[2].earth_rate_removed_dph, 0.0);
        // With a null that contains E (measured with x up), the biases are measured relative to it:
        // +x up: 13 - 10 ... i.e. every bias is lower by E; removed = E (u - 1).
        let c = GSensitivityConfig { null_contains_earth_rate: true, ..c };
        let f =
            fit_g_sensitivity(&[rec("+x up", 13.0), rec("-x up", 7.0 - 2.0 * e), rec("+y up", 10.0 - e)], &c).unwrap();
        assert!((f.g_dph_per_g[0].estimate().unwrap().value - 3.0).abs() < 1e-9);
        assert!((f.bias_at_zero_g.estimate().unwrap().value - 10.0).abs() < 1e-9);
        assert!((f.records[1].earth_rate_removed_dph + 2.0 * e).abs() < 1e-9);
    }

    #[test]
    fn noisy_simulated_truth_is_recovered_within_standard_errors() {
        use rand::SeedableRng;
        use rand_distr::{Distribution, Normal};
        let truth_b0 = -4.0;
        let truth_g = [25.0, -12.0, 6.0];
        let sigma = 0.8;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let noise = Normal::new(0.0, sigma).unwrap();
        let mut recs = Vec::new();
        for _ in 0..3 {
            for n in NamedOrientation::NAMES {
                let f = named(n);
                let b = truth_b0 + (0..3).map(|j| truth_g[j] * f[j]).sum::<f64>() + noise.sample(&mut rng);
                recs.push(GRecord { specific_force_g: f, bias_dph: b });
            }
        }
        let fit = fit_g_sensitivity(&recs, &cfg()).unwrap();
        assert_eq!(fit.residual_dof, 18 - 4);
        for (j, (c, truth)) in fit.g_dph_per_g.iter().zip(truth_g).enumerate() {
            let e = c.estimate().unwrap();
            let se = e.std_error.unwrap();
            // The design's standard error is sigma / sqrt(6) (6 records at +-1 g per axis).
            assert!(se > 0.4 * sigma / 6f64.sqrt() && se < 2.0 * sigma / 6f64.sqrt(), "{se}");
            assert!((e.value - truth).abs() < 3.0 * se, "G_{j} = {} +- {se}, truth {truth}", e.value);
        }
        let b0 = fit.bias_at_zero_g.estimate().unwrap();
        assert!((b0.value - truth_b0).abs() < 3.0 * b0.std_error.unwrap());
        let m = fit.magnitude.unwrap();
        let truth_m = truth_g.iter().map(|v| v * v).sum::<f64>().sqrt();
        assert!((m.value - truth_m).abs() < 3.0 * m.std_error.unwrap());
    }

    #[test]
    fn simulated_static_records_carry_the_g_sensitive_bias_and_earth_rate_share() {
        use crate::sim::{SensorModel, StaticGenerator, StaticSpec};
        let model = SensorModel { g_sensitivity_dph_per_g: [30.0, -12.0, 5.0], bias_dph: 20.0, ..Default::default() };
        let base = StaticSpec { sample_rate_hz: 10.0, duration_s: 10.0, ..StaticSpec::default() };
        let mean_dph = |spec: &StaticSpec| {
            let g = StaticGenerator::new(&model, spec, 1).unwrap();
            let v: Vec<f64> = g.map(|s| s.output).collect();
            units::dps_to_dph(v.iter().sum::<f64>() / v.len() as f64)
        };
        // No orientation: the plain bias (existing behaviour).
        assert!((mean_dph(&base) - 20.0).abs() < 1e-9);
        // -y up: 20 + (-12)(-1) = 32; tilted (0.6, 0, 0.8): 20 + 18 + 4 = 42.
        let s = StaticSpec { specific_force_g: Some(named("-y up")), ..base.clone() };
        assert!((mean_dph(&s) - 32.0).abs() < 1e-9);
        let s = StaticSpec { specific_force_g: Some([0.6, 0.0, 0.8]), ..base.clone() };
        assert!((mean_dph(&s) - 42.0).abs() < 1e-9);
        // Input axis down at latitude 30: the earth rate enters with -1.
        let e = units::EARTH_RATE_DPH * 0.5;
        let s = StaticSpec { latitude_deg: Some(30.0), input_axis_up: -1.0, ..base.clone() };
        assert!((mean_dph(&s) - (20.0 - e)).abs() < 1e-6);
        let s = StaticSpec { input_axis_up: 1.5, ..base };
        assert!(StaticGenerator::new(&model, &s, 1).is_err());
    }
}
