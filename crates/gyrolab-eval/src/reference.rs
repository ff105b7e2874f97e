//! The output-to-rate reference: the scale factor K and null that turn a gyro's outputs into
//! rates, from a calibration file (written by `gyrolab rate --cal-out`), given numbers, or this
//! plan's rate-table evaluation. The one place where outputs become deg/s.
//!
//! Rate = (output - null) / K (paper eq. 1 inverted); outputs already in deg/s or rad/s are rates
//! by their unit's native factor ([`OutputUnit::native_scale_factor_per_dps`]).

use crate::error::{EvalError, EvalResult};
use gyrolab::static_test::StaticTestConfig;
use gyrolab::units::{OutputUnit, Quantity};
use gyrolab::validate;
use gyrolab_io::calibration::read_calibration;
use std::path::PathBuf;

/// Where the reference comes from: a calibration file, or K (and a null) given.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ReferenceRequest {
    /// Calibration file (TOML written by `gyrolab rate --cal-out`).
    pub calibration: Option<PathBuf>,
    /// Axis of the calibration file (needed when it has several).
    pub calibration_axis: Option<String>,
    /// Scale factor K, output units per deg/s (instead of a file).
    pub scale_factor: Option<f64>,
    /// Null (zero-rate output), output units, with `scale_factor`.
    pub null: Option<f64>,
}

impl ReferenceRequest {
    /// Resolves the request (reads the calibration file).
    ///
    /// ```
    /// use gyrolab_eval::reference::{Reference, ReferenceRequest};
    /// use gyrolab::units::{OutputUnit, Quantity};
    /// let r = ReferenceRequest { scale_factor: Some(0.0075), null: Some(2.5), ..Default::default() };
    /// let reference = r.resolve()?;
    /// let mut v = vec![2.5075, 2.5];
    /// assert!(reference.to_rate(OutputUnit::Volt, &mut v)?);
    /// assert!((v[0] - 1.0).abs() < 1e-12 && v[1] == 0.0);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn resolve(&self) -> EvalResult<Reference> {
        if let Some(path) = &self.calibration {
            if self.scale_factor.is_some() {
                return Err(EvalError::conflict_on(
                    &["calibration", "scale_factor"],
                    "{calibration} and {scale_factor} exclude each other: give one",
                ));
            }
            let cal = read_calibration(path)?;
            let axis = cal
                .axis(self.calibration_axis.as_deref())
                .map_err(|m| EvalError::conflict(format!("{}: {m}", path.display())))?;
            return Ok(Reference::Calibrated {
                scale_factor: axis.scale_factor,
                null: axis.zero_offset,
                unit: axis.output_unit,
            });
        }
        if self.calibration_axis.is_some() {
            return Err(EvalError::conflict_on(
                &["calibration_axis", "calibration"],
                "{calibration_axis} needs {calibration}",
            ));
        }
        match self.scale_factor {
            Some(k) => {
                validate::scale_factor("scale_factor", k)?;
                if let Some(n) = self.null {
                    validate::finite("null", n)?;
                }
                Ok(Reference::Given { scale_factor: k, null: self.null })
            }
            None if self.null.is_some() => {
                Err(EvalError::conflict_on(&["null", "scale_factor"], "{null} needs {scale_factor}"))
            }
            None => Ok(Reference::None),
        }
    }
}

/// A resolved reference.
#[derive(Debug, Clone, PartialEq)]
pub enum Reference {
    /// Nothing given: figures in output units only.
    None,
    /// Given numbers, in the unit of whatever output they are applied to.
    Given {
        /// K, output units per deg/s.
        scale_factor: f64,
        /// Null, output units.
        null: Option<f64>,
    },
    /// From a calibration (a file or this plan's rate-table evaluation), in its output unit.
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
            Err(m) => Err(format!("channel '{}': {m}", gyrolab_io::text::excerpt(channel))),
        }
    }

    /// Turns samples in `unit` into physical units in place and says what they now are:
    /// accelerations become m/s^2 ([`Quantity::Acceleration`], whatever the reference);
    /// outputs and unitless samples with a reference, and angular rates, become deg/s
    /// ([`Quantity::AngularRate`], by [`Reference::to_rate`]); anything else is left as it is
    /// ([`Quantity::SensorOutput`] or [`Quantity::Unitless`]).
    pub fn to_physical(&self, unit: OutputUnit, values: &mut [f64]) -> Result<Quantity, String> {
        let (quantity, conversion) = self.physical_conversion(unit)?;
        conversion.apply(values);
        Ok(quantity)
    }

    /// What [`Reference::to_physical`] makes of samples in `unit`, and the conversion it
    /// applies, without touching any sample (so that a caller can skip a copy when the
    /// conversion is the identity).
    pub fn physical_conversion(&self, unit: OutputUnit) -> Result<(Quantity, Conversion), String> {
        if let Some(f) = unit.per_m_s2() {
            return Ok((Quantity::Acceleration, Conversion::affine(0.0, f)));
        }
        if unit == OutputUnit::Unitless && self.is_none() {
            return Ok((Quantity::Unitless, Conversion::Identity));
        }
        Ok(match self.rate_conversion(unit)? {
            Some(c) => (Quantity::AngularRate, c),
            None => (unit.quantity(), Conversion::Identity),
        })
    }

    /// The conversion of output samples in `unit` to deg/s: `(x - null) / K` with the
    /// reference (a missing null counts as 0: deviations do not depend on it), else the unit's
    /// native factor (deg/s, rad/s); `None` when the samples cannot be turned into rates.
    fn rate_conversion(&self, unit: OutputUnit) -> Result<Option<Conversion>, String> {
        let (k, null) = match self.for_unit(unit)? {
            Some((k, null)) => (Some(k), null.unwrap_or(0.0)),
            None => (unit.native_scale_factor_per_dps(), 0.0),
        };
        Ok(k.map(|k| Conversion::affine(null, k)))
    }

    /// Turns output samples in `unit` into rates in deg/s, in place: `(x - null) / K` with the
    /// reference (a missing null counts as 0: deviations do not depend on it), else by the
    /// unit's native factor (deg/s, rad/s). Returns whether the values are now rates; `false`
    /// leaves them in output units.
    pub fn to_rate(&self, unit: OutputUnit, values: &mut [f64]) -> Result<bool, String> {
        match self.rate_conversion(unit)? {
            Some(c) => {
                c.apply(values);
                Ok(true)
            }
            None => Ok(false),
        }
    }
}

/// A conversion of samples to physical units: (x - null) / k, or nothing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Conversion {
    /// The samples are already in the physical unit (x / 1 is x exactly: no pass over them).
    Identity,
    /// x / k.
    Scale(f64),
    /// (x - null) / k.
    Affine {
        /// Output at zero input, in the samples' unit.
        null: f64,
        /// Output units per physical unit.
        k: f64,
    },
}

impl Conversion {
    /// (x - null) / k, with the identity and the pure scale told apart.
    fn affine(null: f64, k: f64) -> Conversion {
        match (null == 0.0, k == 1.0) {
            (true, true) => Conversion::Identity,
            (true, false) => Conversion::Scale(k),
            _ => Conversion::Affine { null, k },
        }
    }

    /// Applies the conversion in place.
    pub fn apply(self, values: &mut [f64]) {
        match self {
            Conversion::Identity => {}
            Conversion::Scale(k) => values.iter_mut().for_each(|v| *v /= k),
            Conversion::Affine { null, k } => values.iter_mut().for_each(|v| *v = (*v - null) / k),
        }
    }
}
