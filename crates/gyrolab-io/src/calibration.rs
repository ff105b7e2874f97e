//! Calibration files (TOML): written by `gyrolab rate --cal-out`, read by commands that turn
//! outputs into rates (`bias --cal`, `allan --cal`, `apply`).
//!
//! Model per axis: output = sum_k c_k * rate_dps^k (polynomial, ascending powers), with the
//! straight line output = K * rate_dps + F0 always present. An optional `[triad]` table holds a
//! three-axis calibration: outputs u = S * omega + b (S 3x3, rows = gyros, columns = axes).

use crate::DataError;
use gyrolab::triad::TriadCalibration;
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
    /// The calibration comes from SIMULATED records: how (a comment line says so too).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub simulated: Option<String>,
    /// One entry per axis (may be empty when the file holds a `[triad]` only).
    #[serde(rename = "axis", default, skip_serializing_if = "Vec::is_empty")]
    pub axes: Vec<AxisCalibration>,
    /// Three-axis calibration, when the file holds one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub triad: Option<TriadSection>,
}

/// The `[triad]` table: a three-axis calibration u = S * omega + b.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TriadSection {
    /// Names of the three gyros / axes, in the order of the matrix rows and columns.
    pub axes: [String; 3],
    /// The records it was computed from.
    pub source_files: Vec<String>,
    /// Unit of the gyro outputs.
    pub output_unit: OutputUnit,
    /// S, row i = gyro i, column j = axis j, output units per deg/s.
    pub matrix: [[f64; 3]; 3],
    /// Bias vector b, output units.
    pub bias: [f64; 3],
    /// Largest |table rate| calibrated, deg/s: the model is valid inside it.
    pub rate_limit_dps: f64,
}

impl TriadSection {
    /// The core calibration (S, b, rate limit).
    pub fn calibration(&self) -> TriadCalibration {
        TriadCalibration { matrix: self.matrix, bias: self.bias, rate_limit_dps: self.rate_limit_dps }
    }

    /// A section from a core calibration and its description.
    pub fn from_calibration(
        cal: &TriadCalibration,
        axes: [String; 3],
        source_files: Vec<String>,
        output_unit: OutputUnit,
    ) -> TriadSection {
        TriadSection {
            axes,
            source_files,
            output_unit,
            matrix: cal.matrix,
            bias: cal.bias,
            rate_limit_dps: cal.rate_limit_dps,
        }
    }
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
    /// Temperature compensation (`[axis.temperature]`, from a plan's temperature points).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub temperature: Option<TemperatureSection>,
}

/// Temperature compensation of an axis: the output at temperature T is brought to the reference
/// temperature, u_ref = (u - F(T)) K(T_ref) / K(T) + F(T_ref), before the rate model
/// (`gyrolab::thermal::Compensation`). Written by `gyrolab eval` from `[temperature.<axis>]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TemperatureSection {
    /// Reference temperature T_ref, degC.
    pub reference_temp_c: f64,
    /// Lowest temperature of the model's points, degC (colder samples use the model there).
    pub temp_min_c: f64,
    /// Highest temperature of the model's points, degC.
    pub temp_max_c: f64,
    /// K(T) = sum_k c_k (T - T_ref)^k: output units per deg/s per degC^k.
    pub scale_factor_coefficients: Vec<f64>,
    /// Null F(T) = sum_k d_k (T - T_ref)^k: output units per degC^k.
    pub null_coefficients: Vec<f64>,
}

impl TemperatureSection {
    /// The core compensation model.
    pub fn compensation(&self) -> Result<gyrolab::thermal::Compensation, gyrolab::thermal::CompensationError> {
        let model = |c: &Vec<f64>| gyrolab::thermal::TemperatureModel {
            reference_temp_c: self.reference_temp_c,
            coefficients: c.clone(),
            temp_min_c: self.temp_min_c,
            temp_max_c: self.temp_max_c,
            rms_residual: 0.0,
            residual_dof: 0,
        };
        gyrolab::thermal::Compensation::new(model(&self.scale_factor_coefficients), model(&self.null_coefficients))
    }
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
            None if self.axes.is_empty() => Err("the calibration has no single-axis [[axis]] entry".to_string()),
            None => {
                let names: Vec<&str> = self.axes.iter().map(|a| a.name.as_str()).collect();
                Err(format!("the calibration has several axes ({}): choose one with --axis", names.join(", ")))
            }
        }
    }

    /// Serialises to TOML text with a comment header.
    pub fn to_toml(&self) -> Result<String, toml::ser::Error> {
        let body = toml::to_string_pretty(self)?;
        let mark = match &self.simulated {
            Some(how) => format!(
                "{}: this calibration comes from simulated records ({how}).\n",
                crate::provenance::SIMULATED_DATA_MARK
            ),
            None => String::new(),
        };
        Ok(format!(
            "{mark}# gyrolab calibration. Model per axis: output = sum_k coefficients[k] * rate_dps^k;\n\
             # scale_factor is in output units per deg/s, offsets in output units.\n\
             # [triad]: outputs u = matrix * omega + bias (rows = gyros, columns = axes, omega in deg/s).\n{body}"
        ))
    }
}

/// Reads a calibration file; errors name the line and column of a TOML problem.
pub fn read_calibration(path: &Path) -> Result<CalibrationFile, DataError> {
    let text = crate::text::read_text_file(path, crate::text::MAX_CONFIG_BYTES, "a calibration file (TOML)")?;
    parse_calibration(path, &text)
}

/// Parses calibration TOML text; `path` names it in errors.
pub fn parse_calibration(path: &Path, text: &str) -> Result<CalibrationFile, DataError> {
    let cal: CalibrationFile = toml::from_str(text).map_err(|e| {
        let mut d =
            DataError::new(path, format!("not a valid calibration file: {}", crate::text::short_message(e.message())));
        if let Some(span) = e.span() {
            let (line, col) = line_col(text, span.start);
            d = d.at_line(line).at_column(col, None);
        }
        d
    })?;
    if cal.format != CALIBRATION_FORMAT {
        let d = DataError::new(
            path,
            format!(
                "format: '{}' is not supported: expected '{CALIBRATION_FORMAT}'",
                crate::text::excerpt(&cal.format)
            ),
        );
        return Err(match value_line(text, &[TomlStep::Key("format")]) {
            Some(l) => d.at_line(l),
            None => d,
        });
    }
    for (i, a) in cal.axes.iter().enumerate() {
        let axis = crate::text::excerpt(&a.name);
        let at = |table: &str, key: &str, msg: String| {
            let d = DataError::new(path, format!("axis '{axis}', {key}: {msg}"));
            let mut place = vec![TomlStep::Key("axis"), TomlStep::Index(i)];
            if let Some(sub) = table.strip_prefix("[axis.").and_then(|t| t.strip_suffix(']')) {
                place.push(TomlStep::Key(sub));
            }
            place.push(TomlStep::Key(key));
            match value_line(text, &place) {
                Some(l) => d.at_line(l),
                None => d,
            }
        };
        let values = [
            ("scale_factor", a.scale_factor),
            ("zero_offset", a.zero_offset),
            ("rest_reference", a.rest_reference),
            ("rate_min_dps", a.rate_min_dps),
            ("rate_max_dps", a.rate_max_dps),
        ];
        for (key, v) in values {
            if !(v.is_finite() && v.abs() <= crate::text::MAX_MAGNITUDE) {
                return Err(at(
                    "[[axis]]",
                    key,
                    format!(
                        "found {v}, expected a finite number of magnitude at most {:e}",
                        crate::text::MAX_MAGNITUDE
                    ),
                ));
            }
        }
        if a.rate_min_dps >= a.rate_max_dps {
            return Err(at(
                "[[axis]]",
                "rate_max_dps",
                format!(
                    "{} is not above rate_min_dps = {}: expected the calibrated range as rate_min_dps < rate_max_dps",
                    a.rate_max_dps, a.rate_min_dps
                ),
            ));
        }
        if a.scale_factor.abs() < MIN_SCALE_FACTOR {
            return Err(at(
                "[[axis]]",
                "scale_factor",
                format!(
                    "found {:e}, expected a non-zero number of magnitude at least {MIN_SCALE_FACTOR:e}",
                    a.scale_factor
                ),
            ));
        }
        if a.polynomial.order > MAX_POLYNOMIAL_ORDER || a.polynomial.coefficients.len() != a.polynomial.order + 1 {
            return Err(at(
                "[axis.polynomial]",
                "coefficients",
                format!(
                    "a polynomial of order {} (at most {MAX_POLYNOMIAL_ORDER}) needs {} coefficients, found {}",
                    a.polynomial.order,
                    a.polynomial.order.saturating_add(1),
                    a.polynomial.coefficients.len()
                ),
            ));
        }
        if let Some(c) =
            a.polynomial.coefficients.iter().find(|c| !(c.is_finite() && c.abs() <= crate::text::MAX_MAGNITUDE))
        {
            return Err(at(
                "[axis.polynomial]",
                "coefficients",
                format!("found {c}, expected finite numbers of magnitude at most {:e}", crate::text::MAX_MAGNITUDE),
            ));
        }
        if a.polynomial.order >= 2 {
            // K is the least-squares line's slope over the calibration points; the polynomial's
            // least-squares slope over the calibrated range (1001 even points) must be close to it.
            let (lo, hi) = (a.rate_min_dps, a.rate_max_dps);
            if lo.is_finite() && hi.is_finite() && hi > lo {
                let xs: Vec<f64> = (0..=1000).map(|i| lo + (hi - lo) * i as f64 / 1000.0).collect();
                let p = |x: f64| a.polynomial.coefficients.iter().rev().fold(0.0, |acc, c| acc * x + c);
                let mx = xs.iter().sum::<f64>() / xs.len() as f64;
                let my = xs.iter().map(|&x| p(x)).sum::<f64>() / xs.len() as f64;
                let sxy: f64 = xs.iter().map(|&x| (x - mx) * (p(x) - my)).sum();
                let sxx: f64 = xs.iter().map(|&x| (x - mx) * (x - mx)).sum();
                let slope = sxy / sxx;
                if slope.is_finite()
                    && (slope - a.scale_factor).abs() > POLYNOMIAL_SLOPE_TOLERANCE * a.scale_factor.abs()
                {
                    return Err(at(
                        "[[axis]]",
                        "scale_factor",
                        format!(
                            "{} disagrees with the slope {slope} of the order-{} polynomial over {lo}..{hi} deg/s (its least-squares line): \
                             expected within {} %; the file was edited by hand?",
                            a.scale_factor,
                            a.polynomial.order,
                            POLYNOMIAL_SLOPE_TOLERANCE * 100.0
                        ),
                    ));
                }
            }
        }
        if let Some(t) = &a.temperature {
            let n_ok = |c: &Vec<f64>| (1..=MAX_POLYNOMIAL_ORDER + 1).contains(&c.len());
            if !(n_ok(&t.scale_factor_coefficients) && n_ok(&t.null_coefficients)) {
                return Err(at(
                    "[axis.temperature]",
                    "scale_factor_coefficients",
                    format!("expected 1 to {} coefficients in each model", MAX_POLYNOMIAL_ORDER + 1),
                ));
            }
            if let Err(e) = t.compensation() {
                return Err(at("[axis.temperature]", "scale_factor_coefficients", e.to_string()));
            }
        }
        if a.polynomial.order == 1 {
            let slope = a.polynomial.coefficients[1];
            if (slope - a.scale_factor).abs() > SLOPE_TOLERANCE * a.scale_factor.abs() {
                return Err(at(
                    "[[axis]]",
                    "scale_factor",
                    format!(
                        "{} disagrees with the slope {slope} of the straight-line polynomial (coefficients[1]): \
                         expected the same value (relative {SLOPE_TOLERANCE:e}); the file was edited by hand?",
                        a.scale_factor
                    ),
                ));
            }
        }
    }
    if let Some(t) = &cal.triad {
        let line = |key: &str| value_line(text, &[TomlStep::Key("triad"), TomlStep::Key(key)]);
        let with_line = |d: DataError, l: Option<u64>| match l {
            Some(l) => d.at_line(l),
            None => d,
        };
        let sane = |v: &f64| v.is_finite() && v.abs() <= crate::text::MAX_MAGNITUDE;
        if !t.matrix.iter().flatten().all(sane) || t.calibration().inverse_matrix().is_none() {
            return Err(with_line(
                DataError::new(path, "[triad] matrix: expected finite numbers and an invertible matrix"),
                line("matrix"),
            ));
        }
        if !t.bias.iter().all(sane) {
            return Err(with_line(DataError::new(path, "[triad] bias: expected finite numbers"), line("bias")));
        }
        if !(sane(&t.rate_limit_dps) && t.rate_limit_dps > 0.0) {
            return Err(with_line(
                DataError::new(path, "[triad] rate_limit_dps: expected a positive number"),
                line("rate_limit_dps"),
            ));
        }
    }
    if cal.axes.is_empty() && cal.triad.is_none() {
        return Err(DataError::new(path, "the calibration has no [[axis]] entry and no [triad] table"));
    }
    Ok(cal)
}

/// Relative tolerance between `scale_factor` and the slope of a straight-line polynomial.
pub const SLOPE_TOLERANCE: f64 = 1e-6;

/// Largest relative difference between `scale_factor` and the least-squares slope of a
/// polynomial of order 2 or more over the calibrated range: 2 % (the straight-line fit through
/// the calibration points and through the polynomial's curve differ by a fraction of the
/// nonlinearity; a hand edit of K is caught).
pub const POLYNOMIAL_SLOPE_TOLERANCE: f64 = 0.02;

/// Smallest magnitude of a scale factor (subnormal or absurd values make rates overflow).
pub const MIN_SCALE_FACTOR: f64 = 1e-100;

/// Highest polynomial order in a calibration file.
pub const MAX_POLYNOMIAL_ORDER: usize = 9;

/// One step of a path into a TOML document: a key, or a 0-based index into an array (of
/// tables).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TomlStep<'a> {
    /// A key of a table (a `[table]`, an inline table or a dotted key alike).
    Key(&'a str),
    /// An element of an array or of an array of tables (`[[axis]]`).
    Index(usize),
}

/// The 1-based line on which the value at `place` is written, from a parse that keeps where
/// each value stands (toml_edit): `key = value` lines, inline tables, dotted keys and the
/// sub-tables of an array of tables (`[axis.polynomial]` of the third `[[axis]]`) alike. A table
/// is placed at its header. `None` when the text does not write that value.
pub fn value_line(text: &str, place: &[TomlStep<'_>]) -> Option<u64> {
    let doc = toml_edit::ImDocument::parse(text).ok()?;
    let mut item = doc.as_item();
    for step in place {
        item = match *step {
            TomlStep::Key(k) => item.get(k)?,
            TomlStep::Index(i) => item.get(i)?,
        };
    }
    let span = item.span()?;
    Some(line_col(text, span.start).0)
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
            simulated: None,
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
                temperature: None,
            }],
            triad: None,
        }
    }

    fn triad() -> TriadSection {
        TriadSection {
            axes: ["x".into(), "y".into(), "z".into()],
            source_files: vec!["x.csv".into(), "y.csv".into(), "z.csv".into()],
            output_unit: OutputUnit::Volt,
            matrix: [[0.0075, 2.25e-5, -1.5e-5], [3.04e-5, 0.0076, 1.9e-5], [-3.7e-5, 2.59e-5, 0.0074]],
            bias: [2.5, 2.51, 2.49],
            rate_limit_dps: 300.0,
        }
    }

    #[test]
    fn triad_round_trip_and_old_files_still_read() {
        let mut c = sample();
        // A file without [triad] (as written before it existed) reads with triad = None.
        let old = c.to_toml().unwrap();
        assert!(!old.contains("\n[triad]"), "{old}");
        assert_eq!(parse_calibration(Path::new("c.toml"), &old).unwrap().triad, None);
        c.triad = Some(triad());
        let text = c.to_toml().unwrap();
        assert!(text.contains("\n[triad]"), "{text}");
        let back = parse_calibration(Path::new("c.toml"), &text).unwrap();
        assert_eq!(back, c);
        assert_eq!(back.triad.unwrap().calibration().matrix[1][0], 3.04e-5);
        // Triad only.
        c.axes.clear();
        let text = c.to_toml().unwrap();
        assert!(!text.contains("\n[[axis]]"), "{text}");
        let back = parse_calibration(Path::new("c.toml"), &text).unwrap();
        assert_eq!(back, c);
        assert!(back.axis(None).is_err());
        // Unknown keys are still refused, inside [triad] too.
        let bad = text.replace("rate_limit_dps", "rate_limt_dps");
        let e = parse_calibration(Path::new("c.toml"), &bad).unwrap_err();
        assert!(e.to_string().contains("rate_limt_dps"), "{e}");
        // A singular matrix is refused.
        let mut t = triad();
        t.matrix[2] = t.matrix[0];
        c.triad = Some(t);
        assert!(parse_calibration(Path::new("c.toml"), &c.to_toml().unwrap()).is_err());
        // Neither [[axis]] nor [triad].
        c.triad = None;
        assert!(parse_calibration(Path::new("c.toml"), &c.to_toml().unwrap()).is_err());
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

    #[test]
    fn value_errors_name_the_line_and_key() {
        let p = Path::new("cal.toml");
        let good = sample().to_toml().unwrap();
        let line_of = |text: &str, key: &str| text.lines().position(|l| l.starts_with(key)).unwrap() as u64 + 1;
        for (from, to, key) in [
            ("zero_offset = 2.5", "zero_offset = nan", "zero_offset"),
            ("zero_offset = 2.5", "zero_offset = 1e308", "zero_offset"),
            ("scale_factor = 0.0075", "scale_factor = 0.0076", "scale_factor"),
            ("scale_factor = 0.0075", "scale_factor = 1e-320", "scale_factor"),
            ("rest_reference = 2.51", "rest_reference = inf", "rest_reference"),
        ] {
            let text = good.replace(from, to);
            let e = parse_calibration(p, &text).unwrap_err();
            assert_eq!(e.line, Some(line_of(&text, key)), "{e}");
            assert!(e.to_string().starts_with("cal.toml:"), "{e}");
            assert!(e.message.contains(key), "{e}");
        }
        let text = good.replace("coefficients = [", "coefficients = [1e300, ");
        let e = parse_calibration(p, &text).unwrap_err();
        assert_eq!(e.line, Some(line_of(&text, "coefficients")), "{e}");
    }

    /// The malformed-input campaign's calibration cases (issue 55), each located to the line of
    /// its key: a wrong format, an inverted range, NaN coefficients, an order that does not match
    /// the coefficients, in the second of two axes (whose polynomial table follows a first axis
    /// without one written as a table), in an inline table, and in [triad].
    #[test]
    fn every_calibration_error_names_its_line_and_key() {
        let p = Path::new("cal.toml");
        let mut two = sample();
        let mut y = two.axes[0].clone();
        y.name = "y".into();
        y.polynomial = PolynomialModel { order: 2, coefficients: vec![2.5, 0.0075, 1e-8] };
        two.axes.push(y);
        let good = two.to_toml().unwrap();
        // The line of the n-th (0-based) line starting with `key`.
        let nth = |text: &str, key: &str, n: usize| {
            text.lines().enumerate().filter(|(_, l)| l.trim_start().starts_with(key)).nth(n).unwrap().0 as u64 + 1
        };
        let second = |text: &str, from: &str, to: &str| {
            let at = text.match_indices(from).nth(1).unwrap().0;
            format!("{}{to}{}", &text[..at], &text[at + from.len()..])
        };
        let cases: Vec<(String, &str, usize, &str)> = vec![
            (
                good.replace("format = \"gyrolab-calibration-1\"", "format = \"gyrolab-calibration-9\""),
                "format",
                0,
                "format",
            ),
            (
                second(&good, "rate_min_dps = -300.0", "rate_min_dps = 400.0"),
                "rate_max_dps",
                1,
                "rate_min_dps < rate_max_dps",
            ),
            (second(&good, "0.0075,", "nan,"), "coefficients", 1, "finite"),
            (good.replace("order = 2", "order = 3"), "coefficients", 1, "needs 4 coefficients"),
            (good.replace("order = 1", "order = 4"), "coefficients", 0, "needs 5 coefficients"),
        ];
        assert!(good.contains("format = \"gyrolab-calibration-1\""), "{good}");
        for (text, key, n, says) in &cases {
            let e = parse_calibration(p, text).unwrap_err();
            assert_eq!(e.line, Some(nth(text, key, *n)), "{key}: {e}\n{text}");
            assert!(e.message.contains(says) && e.message.contains(key), "{e}");
        }
        // An inline polynomial table: its line.
        let inline = "format = \"gyrolab-calibration-1\"\ngenerator = \"hand\"\ncreated = \"2026\"\n\n[[axis]]\nname = \"x\"\nsource_file = \"x.csv\"\noutput_unit = \"V\"\nscale_factor = 0.0075\nzero_offset = 2.5\nrest_reference = 2.5\nrate_min_dps = -300.0\nrate_max_dps = 300.0\npolynomial = { order = 1, coefficients = [2.5, nan] }\n";
        let e = parse_calibration(p, inline).unwrap_err();
        assert_eq!(e.line, Some(14), "{e}");
        // [triad]: a NaN bias and a negative rate limit, each at its line.
        let mut c = sample();
        c.triad = Some(triad());
        let text = c.to_toml().unwrap();
        for (from, to, key) in [
            ("bias = [", "bias = [nan, ", "bias"),
            ("rate_limit_dps = 300.0", "rate_limit_dps = -1.0", "rate_limit_dps"),
        ] {
            let bad = text.replace(from, to);
            let e = parse_calibration(p, &bad).unwrap_err();
            let triad_at = bad.find("[triad]").unwrap();
            let line = bad[..triad_at].matches('\n').count()
                + bad[triad_at..].lines().position(|l| l.starts_with(key)).unwrap()
                + 1;
            assert_eq!(e.line, Some(line as u64), "{e}\n{bad}");
        }
    }
}
