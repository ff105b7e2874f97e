//! The scale factor and null that turn outputs into rates: from a calibration file (`--cal`,
//! written by `gyrolab rate --cal-out`) or given (`--scale-factor`, `--null`). Shared by the
//! commands that read time series (`bias`, `allan`, `apply`).

use crate::error::{CliError, CliResult};
use clap::Args;
use gyrolab::static_test::StaticTestConfig;
use gyrolab::units::OutputUnit;
use gyrolab_io::calibration::read_calibration;
use std::path::PathBuf;

/// Options naming the output-to-rate reference.
#[derive(Debug, Clone, Args)]
pub struct ReferenceArgs {
    /// Calibration file written by `gyrolab rate --cal-out` (scale factor K and null F0).
    #[arg(long, value_name = "FILE.toml", conflicts_with = "scale_factor")]
    pub cal: Option<PathBuf>,
    /// Axis of the calibration file to use (needed when it has several).
    #[arg(long = "cal-axis", value_name = "NAME", requires = "cal")]
    pub cal_axis: Option<String>,
    /// Scale factor K in output units per deg/s (e.g. 0.0075 for V, 7.5 for mV outputs).
    #[arg(long, value_name = "K", allow_hyphen_values = true)]
    pub scale_factor: Option<f64>,
    /// Zero-rate output (null) in output units, with --scale-factor.
    #[arg(long, value_name = "F", allow_hyphen_values = true, requires = "scale_factor")]
    pub null: Option<f64>,
}

/// A resolved reference.
#[derive(Debug, Clone, PartialEq)]
pub enum Reference {
    /// Nothing given: figures in output units only.
    None,
    /// Given on the command line, in the unit of whatever output it is applied to.
    Given {
        /// K, output units per deg/s.
        scale_factor: f64,
        /// Null, output units.
        null: Option<f64>,
    },
    /// From a calibration file, in its output unit.
    Calibrated {
        /// K, `unit` per deg/s.
        scale_factor: f64,
        /// F0, `unit`.
        null: f64,
        /// The calibration's output unit.
        unit: OutputUnit,
    },
}

impl Reference {
    /// Resolves the options (reads the calibration file).
    pub fn from_args(a: &ReferenceArgs) -> CliResult<Reference> {
        if let Some(path) = &a.cal {
            let cal = read_calibration(path)?;
            let axis =
                cal.axis(a.cal_axis.as_deref()).map_err(|m| CliError::Usage(format!("{}: {m}", path.display())))?;
            return Ok(Reference::Calibrated {
                scale_factor: axis.scale_factor,
                null: axis.zero_offset,
                unit: axis.output_unit,
            });
        }
        match a.scale_factor {
            Some(k) if k.is_finite() && k != 0.0 => {
                if let Some(n) = a.null {
                    if !n.is_finite() {
                        return Err(CliError::Usage(format!("--null must be a number, got {n}")));
                    }
                }
                Ok(Reference::Given { scale_factor: k, null: a.null })
            }
            Some(k) => Err(CliError::Usage(format!("--scale-factor must be a non-zero number, got {k}"))),
            None => Ok(Reference::None),
        }
    }

    /// Whether no reference was given.
    pub fn is_none(&self) -> bool {
        matches!(self, Reference::None)
    }

    /// (K, null) in the unit of an output channel; `None` when no reference was given.
    /// A calibration in V applies to mV channels (and deg/s to rad/s) after conversion; other
    /// unit pairs are an error.
    pub fn for_unit(&self, unit: OutputUnit) -> Result<Option<(f64, Option<f64>)>, String> {
        match *self {
            Reference::None => Ok(None),
            Reference::Given { scale_factor, null } => Ok(Some((scale_factor, null))),
            Reference::Calibrated { scale_factor, null, unit: cal_unit } => match cal_unit.factor_to(unit) {
                Some(f) => Ok(Some((scale_factor * f, Some(null * f)))),
                None => Err(format!("the calibration is for {cal_unit} outputs but this channel is in {unit}")),
            },
        }
    }

    /// Sets the scale factor and null of a static-test configuration for a channel in `unit`
    /// (nothing when no reference was given); the message of an error names the channel.
    pub fn configure(&self, cfg: &mut StaticTestConfig, channel: &str, unit: OutputUnit) -> Result<(), String> {
        match self.for_unit(unit) {
            Ok(Some((k, null))) => {
                cfg.scale_factor = Some(k);
                cfg.null_output = null;
                Ok(())
            }
            Ok(None) => Ok(()),
            Err(m) => Err(format!("channel '{channel}': {m}")),
        }
    }
}
