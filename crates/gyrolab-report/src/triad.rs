//! Reports of three-axis (triad) calibrations (`gyrolab rate --triad`): text and JSON. Keys name
//! their unit; output-valued keys are in `output_unit`.

use comfy_table::{presets::UTF8_FULL_CONDENSED, CellAlignment, Table};
use gyrolab::format::sig;
use gyrolab::triad::TableAxis;
use gyrolab_eval::outcome::triad::TriadReport;
use serde::Serialize;

/// A record of the set in JSON.
#[derive(Debug, Clone, Serialize)]
pub struct TriadFileJson {
    /// Table axis the unit turned about.
    pub axis: TableAxis,
    /// Source file.
    pub file: String,
}

/// One plateau's residual in JSON.
#[derive(Debug, Clone, Serialize)]
pub struct TriadResidualJson {
    /// Table axis.
    pub axis: TableAxis,
    /// Table rate, deg/s.
    pub rate_dps: f64,
    /// u - (S omega + b) per gyro, output units.
    pub output_residual: [f64; 3],
    /// S^-1 (u - b) - omega per axis, deg/s.
    pub rate_error_dps: [f64; 3],
}

/// JSON document of `gyrolab rate --triad ... --json`.
#[derive(Debug, Clone, Serialize)]
pub struct TriadJson {
    /// Program version.
    pub gyrolab_version: String,
    /// The records.
    pub files: Vec<TriadFileJson>,
    /// Gyro output columns, x, y, z.
    pub gyro_columns: [String; 3],
    /// Unit of every output-valued field.
    pub output_unit: String,
    /// S (rows = gyros, columns = table axes), output units per deg/s.
    pub matrix: [[f64; 3]; 3],
    /// b, output units.
    pub bias: [f64; 3],
    /// S^-1, deg/s per output unit.
    pub inverse_dps_per_output: [[f64; 3]; 3],
    /// S_ii, output units per deg/s.
    pub scale_factors: [f64; 3],
    /// S_ij / S_ii in percent (0 on the diagonal).
    pub cross_axis_sensitivity_pct: [[f64; 3]; 3],
    /// atan(S_ij / S_ii), mrad (0 on the diagonal).
    pub misalignment_mrad: [[f64; 3]; 3],
    /// RMS output residual per gyro, output units.
    pub rms_output_residual: [f64; 3],
    /// RMS rate error per axis, deg/s.
    pub rms_rate_error_dps: [f64; 3],
    /// Largest |table rate| calibrated, deg/s.
    pub rate_limit_dps: f64,
    /// Condition number of the equilibrated design matrix.
    pub design_condition: f64,
    /// Condition number of S.
    pub matrix_condition: f64,
    /// Plateaus used (rests included).
    pub plateaus: usize,
    /// Every plateau's residual.
    pub residuals: Vec<TriadResidualJson>,
}

/// Builds the JSON document of a three-axis fit.
pub fn triad_json(r: &TriadReport<'_>) -> TriadJson {
    let f = r.fit;
    TriadJson {
        gyrolab_version: env!("CARGO_PKG_VERSION").into(),
        files: r.files.iter().map(|(axis, file)| TriadFileJson { axis: *axis, file: file.clone() }).collect(),
        gyro_columns: r.gyro_columns.clone(),
        output_unit: r.output_unit.symbol().into(),
        matrix: f.calibration.matrix,
        bias: f.calibration.bias,
        inverse_dps_per_output: f.inverse,
        scale_factors: f.scale_factors,
        cross_axis_sensitivity_pct: f.cross_axis_sensitivity_pct,
        misalignment_mrad: f.misalignment_mrad,
        rms_output_residual: f.rms_output_residual,
        rms_rate_error_dps: f.rms_rate_error_dps,
        rate_limit_dps: f.calibration.rate_limit_dps,
        design_condition: f.design_condition,
        matrix_condition: f.matrix_condition,
        plateaus: f.plateaus,
        residuals: f
            .residuals
            .iter()
            .map(|q| TriadResidualJson {
                axis: q.axis,
                rate_dps: q.rate_dps,
                output_residual: q.output_residual,
                rate_error_dps: q.rate_error_dps,
            })
            .collect(),
    }
}

fn matrix_table(title: &str, rows: &[String; 3], m: &[[f64; 3]; 3], digits: usize, diag: bool) -> String {
    let mut t = Table::new();
    t.load_preset(UTF8_FULL_CONDENSED);
    t.set_header(vec![title.to_string(), "axis x".into(), "axis y".into(), "axis z".into()]);
    for (i, row) in m.iter().enumerate() {
        let mut cells = vec![format!("gyro {} ({})", TableAxis::ALL[i], rows[i])];
        cells.extend(row.iter().enumerate().map(|(j, v)| if i == j && !diag { "-".into() } else { sig(*v, digits) }));
        t.add_row(cells);
    }
    for c in 1..4 {
        if let Some(col) = t.column_mut(c) {
            col.set_cell_alignment(CellAlignment::Right);
        }
    }
    t.to_string()
}

/// The three-axis calibration as text: S, b, scale factors, cross-axis %, misalignment mrad,
/// residual RMS and condition numbers; and where the calibration was written (`cal_out`).
pub fn triad_text(r: &TriadReport<'_>, cal_out: Option<&std::path::Path>) -> String {
    let f = r.fit;
    let u = r.output_unit.symbol();
    let mut s = String::from("Three-axis calibration u = S omega + b (12 parameters)\n");
    for (axis, file) in &r.files {
        s.push_str(&format!("  rotations about {axis}: {file}\n"));
    }
    s.push('\n');
    s.push_str(&matrix_table(&format!("S {u}/(deg/s)"), &r.gyro_columns, &f.calibration.matrix, 6, true));
    s.push_str("\n\n");
    let mut t = Table::new();
    t.load_preset(UTF8_FULL_CONDENSED);
    t.set_header(vec![
        "gyro".to_string(),
        format!("bias b {u}"),
        format!("scale factor {u}/(deg/s)"),
        format!("RMS output residual {u}"),
        "RMS rate error deg/s".into(),
    ]);
    for i in 0..3 {
        t.add_row(vec![
            format!("{} ({})", TableAxis::ALL[i], r.gyro_columns[i]),
            sig(f.calibration.bias[i], 7),
            sig(f.scale_factors[i], 6),
            sig(f.rms_output_residual[i], 3),
            sig(f.rms_rate_error_dps[i], 3),
        ]);
    }
    for c in 1..5 {
        if let Some(col) = t.column_mut(c) {
            col.set_cell_alignment(CellAlignment::Right);
        }
    }
    s.push_str(&t.to_string());
    s.push_str("\n\n");
    s.push_str(&matrix_table("cross-axis sensitivity %", &r.gyro_columns, &f.cross_axis_sensitivity_pct, 4, false));
    s.push_str("\n\n");
    s.push_str(&matrix_table("misalignment mrad", &r.gyro_columns, &f.misalignment_mrad, 4, false));
    s.push_str(&format!(
        "\n\n{} plateaus; rate limit {} deg/s; condition number of the design {}, of S {}\n",
        f.plateaus,
        sig(f.calibration.rate_limit_dps, 4),
        sig(f.design_condition, 3),
        sig(f.matrix_condition, 4)
    ));
    if let Some(cal) = cal_out {
        s.push_str(&format!("\nCalibration ([triad]) written to {}\n", cal.display()));
    }
    s
}
