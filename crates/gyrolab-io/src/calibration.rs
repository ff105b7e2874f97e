//! Calibration files (TOML): written by `gyrolab rate --cal-out`, read by commands that turn
//! outputs into rates (`bias --cal`, `allan --cal`, `apply`).
//!
//! Model per axis: output = sum_k c_k * rate_dps^k (polynomial, ascending powers), with the
//! straight line output = K * rate_dps + F0 always present.

use crate::DataError;
use gyrolab::units::OutputUnit;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Format tag of the current calibration file version.
pub const CALIBRATION_FORMAT: &str = "gyrolab-calibration-1";

/// A calibration file: one or more axes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CalibrationFile {
    /// Format tag, `gyrolab-calibration-1`.
    pub format: String,
    /// Program and version that wrote it.
    pub generator: String,
    /// Time of evaluation (RFC 3339, UTC).
    pub created: String,
    /// One entry per axis.
    #[serde(rename = "axis")]
    pub axes: Vec<AxisCalibration>,
}

/// The calibration of one axis.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AxisCalibration {
    /// Axis name.
    pub name: String,
    /// The record it was computed from.
    pub source_file: String,
    /// Unit of the gyro output.
    pub output_unit: OutputUnit,
    /// Scale factor K, output units per deg/s.
    pub scale_factor: f64,
    /// Zero offset F0 of the fitted line, output units.
    pub zero_offset: f64,
    /// Rest reference F_r, output units.
    pub rest_reference: f64,
    /// Tested rate range, deg/s: the model is valid inside it.
    pub rate_min_dps: f64,
    /// Upper end of the tested rate range, deg/s.
    pub rate_max_dps: f64,
    /// Polynomial model.
    pub polynomial: PolynomialModel,
}

/// A polynomial output model in the input rate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PolynomialModel {
    /// Polynomial order.
    pub order: usize,
    /// Coefficients c_0..c_order: output = sum_k c_k * rate_dps^k (units: output / (deg/s)^k).
    pub coefficients: Vec<f64>,
}

impl CalibrationFile {
    /// The axis named `name`, or the only axis when `name` is `None`.
    pub fn axis(&self, name: Option<&str>) -> Result<&AxisCalibration, String> {
        match name {
            Some(n) => self.axes.iter().find(|a| a.name == n).ok_or_else(|| {
                let names: Vec<&str> = self.axes.iter().map(|a| a.name.as_str()).collect();
                format!("no axis '{n}' in the calibration: it has {}", names.join(", "))
            }),
            None if self.axes.len() == 1 => Ok(&self.axes[0]),
            None => {
                let names: Vec<&str> = self.axes.iter().map(|a| a.name.as_str()).collect();
                Err(format!("the calibration has several axes ({}): choose one with --axis", names.join(", ")))
            }
        }
    }

    /// Serialises to TOML text with a comment header.
    pub fn to_toml(&self) -> Result<String, toml::ser::Error> {
        let body = toml::to_string_pretty(self)?;
        Ok(format!(
            "# gyrolab calibration. Model per axis: output = sum_k coefficients[k] * rate_dps^k;\n\
             # scale_factor is in output units per deg/s, offsets in output units.\n{body}"
        ))
    }
}

/// Reads a calibration file; errors name the line and column of a TOML problem.
pub fn read_calibration(path: &Path) -> Result<CalibrationFile, DataError> {
    let text = std::fs::read_to_string(path).map_err(|e| DataError::io(path, &e))?;
    parse_calibration(path, &text)
}

/// Parses calibration TOML text; `path` names it in errors.
pub fn parse_calibration(path: &Path, text: &str) -> Result<CalibrationFile, DataError> {
    let cal: CalibrationFile = toml::from_str(text).map_err(|e| {
        let mut d = DataError::new(path, format!("not a valid calibration file: {}", e.message()));
        if let Some(span) = e.span() {
            let (line, col) = line_col(text, span.start);
            d = d.at_line(line).at_column(col, None);
        }
        d
    })?;
    if cal.format != CALIBRATION_FORMAT {
        return Err(DataError::new(
            path,
            format!("format '{}' is not supported: expected '{CALIBRATION_FORMAT}'", cal.format),
        ));
    }
    for a in &cal.axes {
        if !(a.scale_factor.is_finite() && a.scale_factor != 0.0) {
            return Err(DataError::new(path, format!("axis '{}': scale_factor must be a non-zero number", a.name)));
        }
        if a.polynomial.coefficients.len() != a.polynomial.order + 1 {
            return Err(DataError::new(
                path,
                format!(
                    "axis '{}': polynomial of order {} needs {} coefficients",
                    a.name,
                    a.polynomial.order,
                    a.polynomial.order + 1
                ),
            ));
        }
    }
    if cal.axes.is_empty() {
        return Err(DataError::new(path, "the calibration has no [[axis]] entry"));
    }
    Ok(cal)
}

/// 1-based line and column of a byte offset.
pub fn line_col(text: &str, offset: usize) -> (u64, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() as u64 + 1;
    let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, col)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> CalibrationFile {
        CalibrationFile {
            format: CALIBRATION_FORMAT.into(),
            generator: "gyrolab test".into(),
            created: "2026-01-01T00:00:00Z".into(),
            axes: vec![AxisCalibration {
                name: "x".into(),
                source_file: "x.csv".into(),
                output_unit: OutputUnit::Volt,
                scale_factor: 0.0075,
                zero_offset: 2.5,
                rest_reference: 2.51,
                rate_min_dps: -300.0,
                rate_max_dps: 300.0,
                polynomial: PolynomialModel { order: 1, coefficients: vec![2.5, 0.0075] },
            }],
        }
    }

    #[test]
    fn round_trip() {
        let c = sample();
        let text = c.to_toml().unwrap();
        assert!(text.contains("output_unit = \"V\""), "{text}");
        assert_eq!(parse_calibration(Path::new("c.toml"), &text).unwrap(), c);
        assert_eq!(c.axis(None).unwrap().name, "x");
        assert!(c.axis(Some("y")).is_err());
    }

    #[test]
    fn errors_name_line() {
        let text = sample().to_toml().unwrap().replace("scale_factor = 0.0075", "scale_factr = 0.0075");
        let e = parse_calibration(Path::new("c.toml"), &text).unwrap_err();
        assert!(e.line.is_some(), "{e}");
        assert!(e.to_string().contains("scale_factr"), "{e}");
    }
}
