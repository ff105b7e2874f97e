//! Three-axis calibration from raw logs of rotations about each table axis in both senses:
//! scale factors, misalignments and biases (12 parameters, [`gyrolab::triad`]; docs/METHODS.md).

use crate::error::{EvalError, EvalResult};
use crate::outcome::triad::TriadReport;
use crate::rate::raw_log::{rate_column, SegmentationRequest};
use gyrolab::segment::find_steady_segments;
use gyrolab::triad::{fit_triad, plateaus_from_segments, TableAxis, TriadError, TriadFit, TriadOptions, TriadPlateau};
use gyrolab::units::OutputUnit;
use gyrolab_io::calibration::{CalibrationFile, TriadSection, CALIBRATION_FORMAT};
use gyrolab_io::raw_log::read_raw_log;
use gyrolab_io::DataError;
use std::path::PathBuf;

/// A three-axis calibration set.
///
/// Each table axis needs a log; a missing one is a conflict naming its field (`triad_x`,
/// `triad_y`, `triad_z`), which the front end spells its own way:
///
/// ```
/// use gyrolab::triad::TableAxis;
/// use gyrolab_eval::triad::{evaluate_triad, TriadRequest};
/// let request = TriadRequest {
///     files: vec![(TableAxis::X, "turn_x.csv".into()), (TableAxis::Y, "turn_y.csv".into())],
///     ..Default::default()
/// };
/// let e = evaluate_triad(&request).unwrap_err();
/// let text = e.render(&|f| format!("--{}", f.replace('_', "-")));
/// assert!(text.contains("misses the z axis") && text.contains("give --triad-z"), "{text}");
/// // Gyro columns, when named, are three.
/// let request = TriadRequest { gyro_columns: vec!["gx_v".into()], ..request };
/// let files = vec![(TableAxis::Z, "turn_z.csv".into())];
/// let e = evaluate_triad(&TriadRequest { files: [request.files.clone(), files].concat(), ..request }).unwrap_err();
/// assert!(e.render(&|f| f.to_string()).contains("gyro_columns needs three names"), "{e}");
/// ```
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriadRequest {
    /// The logs, (table axis, file); x, y and z each at least once.
    pub files: Vec<(TableAxis, PathBuf)>,
    /// The gyro output columns x, y, z (default: the file's three outputs).
    pub gyro_columns: Vec<String>,
    /// Segmentation (table-rate column, tolerances).
    pub segmentation: SegmentationRequest,
}

/// A finished three-axis fit with its inputs.
#[derive(Debug, Clone)]
pub struct TriadResult {
    /// The records, (axis, file as given).
    pub files: Vec<(TableAxis, String)>,
    /// Gyro output columns x, y, z (as in the first file).
    pub gyro_columns: [String; 3],
    /// Output unit.
    pub output_unit: OutputUnit,
    /// The fit.
    pub fit: TriadFit,
}

impl TriadResult {
    /// The report view of this fit.
    pub fn report(&self) -> TriadReport<'_> {
        TriadReport {
            files: self.files.clone(),
            gyro_columns: self.gyro_columns.clone(),
            output_unit: self.output_unit,
            fit: &self.fit,
        }
    }

    /// The calibration file of this fit (a `[triad]` section), stamped with the time now.
    pub fn calibration_file(&self) -> CalibrationFile {
        CalibrationFile {
            format: CALIBRATION_FORMAT.into(),
            generator: format!("gyrolab {}", env!("CARGO_PKG_VERSION")),
            created: humantime::format_rfc3339_seconds(std::time::SystemTime::now()).to_string(),
            simulated: None,
            axes: Vec::new(),
            triad: Some(TriadSection::from_calibration(
                &self.fit.calibration,
                ["x".into(), "y".into(), "z".into()],
                self.files.iter().map(|(_, f)| f.clone()).collect(),
                self.output_unit,
            )),
        }
    }
}

/// Reads the three-axis set, segments each log and fits the 12-parameter model.
pub fn evaluate_triad(request: &TriadRequest) -> EvalResult<TriadResult> {
    let options = request.segmentation.options()?;
    let files = &request.files;
    let listed = || files.iter().map(|(a, f)| format!("{a}={}", f.display())).collect::<Vec<_>>().join(", ");
    for axis in TableAxis::ALL {
        if !files.iter().any(|(a, _)| *a == axis) {
            let field = match axis {
                TableAxis::X => "triad_x",
                TableAxis::Y => "triad_y",
                TableAxis::Z => "triad_z",
            };
            return Err(EvalError::conflict_on(
                &[field],
                format!(
                    "the three-axis set misses the {axis} axis (given: {}): give {{{field}}}, a log of rotations \
                 about {axis} in both senses",
                    listed()
                ),
            ));
        }
    }
    if !request.gyro_columns.is_empty() && request.gyro_columns.len() != 3 {
        return Err(EvalError::conflict_on(
            &["gyro_columns"],
            format!("{{gyro_columns}} needs three names (gyros x, y, z), got {}", request.gyro_columns.len()),
        ));
    }
    let mut plateaus: Vec<TriadPlateau> = Vec::new();
    let mut unit: Option<OutputUnit> = None;
    let mut gyro_columns: Option<[String; 3]> = None;
    let mut described = Vec::new();
    for (axis, path) in files {
        let rate = rate_column(path, request.segmentation.table_rate_column.as_deref())?;
        let select = (!request.gyro_columns.is_empty()).then(|| request.gyro_columns.clone());
        let log = read_raw_log(path, &rate, select)?;
        let chans = &log.header.channels;
        let order: Vec<usize> = if request.gyro_columns.is_empty() {
            if chans.len() != 3 {
                let names: Vec<&str> = chans.iter().map(|c| c.name.as_str()).collect();
                return Err(EvalError::conflict_on(
                    &["gyro_columns"],
                    format!(
                        "{}:{}: {} output column(s) ({}): a three-axis log needs three; name them with \
                         {{gyro_columns}} GX,GY,GZ",
                        path.display(),
                        log.header.header_line,
                        chans.len(),
                        names.join(", ")
                    ),
                ));
            }
            vec![0, 1, 2]
        } else {
            // ok: read_raw_log selected exactly these columns, so each is present.
            request.gyro_columns.iter().map(|n| log.channel(n).unwrap_or(0)).collect()
        };
        let u0 = *unit.get_or_insert(chans[order[0]].unit);
        let mut outputs: Vec<Vec<f64>> = Vec::with_capacity(3);
        for &k in &order {
            let c = &chans[k];
            let f = c.unit.factor_to(u0).ok_or_else(|| {
                DataError::new(
                    path,
                    format!("output in {}, but the set's outputs are in {u0}: the units do not convert", c.unit),
                )
                .at_line(log.header.header_line)
                .at_column(c.column, Some(&c.name))
            })?;
            outputs.push(log.channels[k].iter().map(|v| v * f).collect());
        }
        gyro_columns.get_or_insert_with(|| [0, 1, 2].map(|i| chans[order[i]].name.clone()));
        let steady =
            find_steady_segments(&log.time_s, &log.table_rate_dps, &options).map_err(|e| log.segment_error(&e))?;
        let o = [&outputs[0][..], &outputs[1][..], &outputs[2][..]];
        plateaus.extend(plateaus_from_segments(*axis, &steady, &log.time_s, o).map_err(|e| log.segment_error(&e))?);
        described.push((*axis, path.display().to_string()));
    }
    let topts = TriadOptions { rest_tolerance_dps: options.rest_tolerance_dps, ..TriadOptions::default() };
    let fit = fit_triad(&plateaus, &topts).map_err(|e| {
        // Name the file(s) of the axis the problem is about, else every file of the set.
        let axis = match &e {
            TriadError::MissingAxis { axis, .. } | TriadError::MissingSense { axis, .. } => Some(*axis),
            TriadError::NonFinite { axis, .. } => Some(*axis),
            _ => None,
        };
        let names: Vec<String> =
            files.iter().filter(|(a, _)| axis.is_none_or(|x| x == *a)).map(|(_, f)| f.display().to_string()).collect();
        EvalError::Data(DataError::new(names.join(", "), format!("three-axis calibration: {e}")))
    })?;
    Ok(TriadResult {
        files: described,
        gyro_columns: gyro_columns.unwrap_or_else(|| ["x".into(), "y".into(), "z".into()]),
        output_unit: unit.unwrap_or(OutputUnit::Volt),
        fit,
    })
}
