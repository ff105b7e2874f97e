//! The simulated gyro's error model, its presets, the record specifications and their validation.
//!
//! Sources: IEEE Std 952-1997 annex C (noise terms and their units); the presets follow the
//! datasheet classes listed in the project's methods notes, section 5 (ADXRS646, ADIS16470,
//! STIM300); `docs/METHODS.md` (section 4) gives the model equation.

use crate::units::OutputUnit;
use serde::{Deserialize, Serialize};
use thiserror::Error;

use super::flicker::FLICKER_MIN_TAU_SAMPLES;

/// Why a simulation cannot be set up: the parameter at fault and its valid range.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SimError {
    /// A parameter is outside its valid range (or not finite).
    #[error("parameter `{parameter}` = {value} is invalid: it must be {valid}")]
    OutOfRange {
        /// Parameter name, as in the configuration.
        parameter: &'static str,
        /// The value given.
        value: f64,
        /// The valid range, in words.
        valid: String,
    },
    /// The output rails do not enclose the null.
    #[error(
        "output rails [`output_rail_low` = {low}, `output_rail_high` = {high}] must enclose the null \
         (`null` = {null}): need output_rail_low < null < output_rail_high"
    )]
    RailsMustEncloseNull {
        /// Lower rail (or -inf when unset), output units.
        low: f64,
        /// Upper rail (or +inf when unset), output units.
        high: f64,
        /// Null, output units.
        null: f64,
    },
    /// The rate list has fewer than two distinct rates.
    #[error("parameter `rates_dps` has {found} distinct rate(s): it must list at least 2 distinct finite rates")]
    TooFewRates {
        /// Distinct rates found.
        found: usize,
    },
    /// The rate list repeats a rate.
    #[error("parameter `rates_dps` lists {rate_dps} deg/s more than once: each rate must appear once")]
    DuplicateRate {
        /// The repeated rate, deg/s.
        rate_dps: f64,
    },
    /// A step of a temperature profile is out of range.
    #[error("step {} of `temperature.steps`: {error}", index + 1)]
    InStep {
        /// 0-based index of the step.
        index: usize,
        /// What is wrong with it.
        error: Box<SimError>,
    },
}

impl SimError {
    /// The configuration keys at fault (`flicker_tau_max_s`; `output_rail_low`,
    /// `output_rail_high` and `null` for rails; `rates_dps`), which a reader of the file locates
    /// to the line of the first it writes.
    pub fn parameters(&self) -> Vec<&'static str> {
        match self {
            SimError::OutOfRange { parameter, .. } => vec![parameter],
            SimError::RailsMustEncloseNull { .. } => vec!["output_rail_low", "output_rail_high", "null"],
            SimError::TooFewRates { .. } | SimError::DuplicateRate { .. } => vec!["rates_dps"],
            SimError::InStep { error, .. } => error.parameters(),
        }
    }

    /// The 0-based index of the temperature step at fault, for an error in one.
    pub fn step(&self) -> Option<usize> {
        match self {
            SimError::InStep { index, .. } => Some(*index),
            _ => None,
        }
    }
}

fn check(parameter: &'static str, value: f64, ok: bool, valid: &str) -> Result<(), SimError> {
    if ok && value.is_finite() {
        Ok(())
    } else {
        Err(SimError::OutOfRange { parameter, value, valid: valid.to_string() })
    }
}

pub(crate) fn finite(parameter: &'static str, value: f64) -> Result<(), SimError> {
    check(parameter, value, true, "a finite number")
}

pub(crate) fn non_negative(parameter: &'static str, value: f64) -> Result<(), SimError> {
    check(parameter, value, value >= 0.0, "finite and >= 0")
}

pub(crate) fn positive(parameter: &'static str, value: f64) -> Result<(), SimError> {
    check(parameter, value, value > 0.0, "finite and > 0")
}

/// Formats a parameter value for a record's comment lines.
pub trait ParameterText {
    /// The value as text (shortest round-trip form for numbers).
    fn parameter_text(&self) -> String;
}

impl ParameterText for f64 {
    fn parameter_text(&self) -> String {
        format!("{self:?}")
    }
}

impl ParameterText for Option<f64> {
    fn parameter_text(&self) -> String {
        self.map_or_else(|| "none".to_string(), |v| format!("{v:?}"))
    }
}

impl ParameterText for [f64; 3] {
    fn parameter_text(&self) -> String {
        format!("{:?} {:?} {:?}", self[0], self[1], self[2])
    }
}

impl ParameterText for OutputUnit {
    fn parameter_text(&self) -> String {
        self.symbol().to_string()
    }
}

macro_rules! sensor_model {
    ($($(#[doc = $doc:literal])+ $field:ident: $ty:ty,)+) => {
        /// The error model of a single-axis gyro; every parameter carries its unit in its name
        /// (output units are those of `output_unit`). Missing TOML fields take the ideal-sensor default.
        #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
        #[serde(default, deny_unknown_fields)]
        pub struct SensorModel {
            $($(#[doc = $doc])+ pub $field: $ty,)+
        }

        /// Changes to a sensor model (typically a preset): every field that is set replaces the model's.
        #[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
        #[serde(default, deny_unknown_fields)]
        pub struct SensorOverrides {
            $($(#[doc = $doc])+ pub $field: Option<$ty>,)+
        }

        impl SensorModel {
            /// Returns the model with every parameter set in `overrides` replaced.
            pub fn with_overrides(mut self, overrides: &SensorOverrides) -> SensorModel {
                $(if let Some(v) = &overrides.$field {
                    self.$field = v.clone();
                })+
                self
            }

            /// Each parameter's name and value as text, for a record's comment lines.
            pub fn parameter_lines(&self) -> Vec<(&'static str, String)> {
                vec![$((stringify!($field), self.$field.parameter_text()),)+]
            }
        }
    };
}

sensor_model! {
    /// Unit of the output signal.
    output_unit: OutputUnit,
    /// Nominal scale factor K, output units per deg/s (non-zero).
    scale_factor_per_dps: f64,
    /// Null: the output at zero sensed rate, output units.
    null: f64,
    /// Systematic deviation of the true scale factor from the nominal, ppm.
    scale_factor_error_ppm: f64,
    /// Scale-factor asymmetry (K+ - K-) / K, ppm: K+ = K (1 + a/2) for sensed rate >= 0, K- = K (1 - a/2).
    scale_factor_asymmetry_ppm: f64,
    /// Quadratic nonlinearity k2, 1/(deg/s): output = null + K (w + k2 w^2 + k3 w^3).
    nonlinearity_quadratic_per_dps: f64,
    /// Cubic nonlinearity k3, 1/(deg/s)^2 (see `nonlinearity_quadratic_per_dps`).
    nonlinearity_cubic_per_dps2: f64,
    /// Lower output rail (saturation), output units; none for no rail.
    output_rail_low: Option<f64>,
    /// Upper output rail (saturation), output units; none for no rail.
    output_rail_high: Option<f64>,
    /// Dead zone (threshold), deg/s: an input rate (table rate plus earth rate plus the
    /// hysteresis offset, before bias and noise are added) of magnitude below it is not sensed
    /// (contributes no output change); at or above it, it is sensed in full (a gap dead zone,
    /// so the simulated threshold is exactly this value); 0 for none.
    dead_zone_dps: f64,
    /// Hysteresis: forward-minus-reverse stroke difference of the sensed rate, deg/s (+h/2 forward, -h/2 reverse).
    hysteresis_dps: f64,
    /// Constant bias (turn-on bias), deg/h.
    bias_dph: f64,
    /// Run-to-run bias change, standard deviation of a Gaussian drawn per run, deg/h.
    run_to_run_bias_sigma_dph: f64,
    /// Run-to-run scale-factor change, standard deviation of a Gaussian drawn per run, ppm.
    run_to_run_scale_factor_sigma_ppm: f64,
    /// Angle random walk N, deg/sqrt(h) (white rate noise).
    arw_deg_rt_h: f64,
    /// Bias instability B, deg/h (flicker rate noise; flat Allan deviation 0.6643 B).
    bias_instability_dph: f64,
    /// Lower end of the tau range over which the flicker Allan deviation is flat, s (>= 10 sample intervals).
    flicker_tau_min_s: f64,
    /// Upper end of that tau range, s.
    flicker_tau_max_s: f64,
    /// Rate random walk K, deg/h/sqrt(h).
    rrw_deg_h_rt_h: f64,
    /// Rate ramp R, deg/h per hour.
    rate_ramp_dph_per_h: f64,
    /// Warm-up transient amplitude A, deg/h: the bias at time t after power-on (the record's
    /// start) is B + A exp(-t / tau); 0 for none.
    warmup_amplitude_dph: f64,
    /// Warm-up time constant tau, s (positive when `warmup_amplitude_dph` is not 0).
    warmup_time_constant_s: f64,
    /// Output quantization step (ADC resolution), output units; 0 for none.
    output_quantization_step: f64,
    /// Angle quantization step of the sensed angle, deg; 0 for none.
    angle_quantization_deg: f64,
    /// Bias temperature coefficient, (deg/h)/degC.
    bias_temp_coeff_dph_per_c: f64,
    /// Scale-factor temperature coefficient, ppm/degC.
    scale_factor_temp_coeff_ppm_per_c: f64,
    /// Temperature at which bias and scale factor take their nominal values, degC.
    reference_temp_c: f64,
    /// g-sensitivity G along sensor x, y, z, (deg/h)/g: a static record with specific force f
    /// (`StaticSpec::specific_force_g`) has the added bias G · f (IEEE 1431 / 952 D_g · a).
    g_sensitivity_dph_per_g: [f64; 3],
}

impl Default for SensorModel {
    /// An ideal sensor: output in deg/s, K = 1, null 0, no error terms, flicker range 10..10000 s.
    fn default() -> Self {
        SensorModel {
            output_unit: OutputUnit::DegPerSec,
            scale_factor_per_dps: 1.0,
            null: 0.0,
            scale_factor_error_ppm: 0.0,
            scale_factor_asymmetry_ppm: 0.0,
            nonlinearity_quadratic_per_dps: 0.0,
            nonlinearity_cubic_per_dps2: 0.0,
            output_rail_low: None,
            output_rail_high: None,
            dead_zone_dps: 0.0,
            hysteresis_dps: 0.0,
            bias_dph: 0.0,
            run_to_run_bias_sigma_dph: 0.0,
            run_to_run_scale_factor_sigma_ppm: 0.0,
            arw_deg_rt_h: 0.0,
            bias_instability_dph: 0.0,
            flicker_tau_min_s: 10.0,
            flicker_tau_max_s: 10_000.0,
            rrw_deg_h_rt_h: 0.0,
            rate_ramp_dph_per_h: 0.0,
            warmup_amplitude_dph: 0.0,
            warmup_time_constant_s: 0.0,
            output_quantization_step: 0.0,
            angle_quantization_deg: 0.0,
            bias_temp_coeff_dph_per_c: 0.0,
            scale_factor_temp_coeff_ppm_per_c: 0.0,
            reference_temp_c: 25.0,
            g_sensitivity_dph_per_g: [0.0; 3],
        }
    }
}

/// A named set of realistic parameters (methods notes section 5; datasheet classes).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Preset {
    /// ADXRS646 class (the paper's family): analog volts, 7.5 mV/(deg/s), null 2.5 V, rails 0.25/4.75 V.
    Adxrs646,
    /// ADIS16470 class: digital deg/s output, +-2000 deg/s, ARW 0.34 deg/sqrt(h), BI 8 deg/h.
    Adis16470,
    /// STIM300 class: digital deg/s, +-400 deg/s, ARW 0.15, BI 0.5, SF 500 ppm, nonlinearity 25 ppm at 200 deg/s.
    Stim300,
}

impl Preset {
    /// All presets, for listing in messages.
    pub const ALL: [Preset; 3] = [Preset::Adxrs646, Preset::Adis16470, Preset::Stim300];

    /// The preset's name as typed (`adxrs646`, `adis16470`, `stim300`).
    pub fn name(self) -> &'static str {
        match self {
            Preset::Adxrs646 => "adxrs646",
            Preset::Adis16470 => "adis16470",
            Preset::Stim300 => "stim300",
        }
    }

    /// Parses a preset name (case-insensitive).
    pub fn parse(s: &str) -> Option<Preset> {
        let t = s.trim().to_ascii_lowercase();
        Preset::ALL.into_iter().find(|p| p.name() == t)
    }

    /// The convention of the datasheet's bias-instability figure: every preset's datasheet
    /// (ADI, Sensonor) quotes the Allan deviation minimum; the preset takes that number as the
    /// IEEE 952 B, so its simulated Allan minimum is 0.6643 times the datasheet figure. To
    /// simulate the datasheet's minimum itself, set `bias_instability_dph` to figure / 0.6643.
    pub fn bias_instability_convention(self) -> &'static str {
        match self {
            Preset::Adxrs646 | Preset::Adis16470 => {
                "datasheet figure: Allan minimum (ADI); preset value used as IEEE 952 B (Allan minimum = 0.6643 B)"
            }
            Preset::Stim300 => {
                "datasheet figure: Allan minimum (Sensonor); preset value used as IEEE 952 B (Allan minimum = 0.6643 B)"
            }
        }
    }

    /// Where the preset's figures come from, for a record's comment lines.
    pub fn source(self) -> &'static str {
        match self {
            Preset::Adxrs646 => {
                "ADXRS646 datasheet class (methods notes s.5): ARW 0.6 deg/sqrt(h), bias drift 12 deg/h (ADI quotes the \
                 Allan minimum; simulated as IEEE 952 B = 12, i.e. Allan minimum 0.6643 x 12 = 8.0 deg/h); \
                 K 7.5 mV/(deg/s) as measured in the paper; null 2.5 V; rails 0.25/4.75 V"
            }
            Preset::Adis16470 => {
                "ADIS16470 datasheet class (methods notes s.5): ARW 0.34 deg/sqrt(h), BI 8 deg/h (ADI's in-run bias \
                 stability, an Allan minimum; simulated as IEEE 952 B = 8, i.e. Allan minimum 5.3 deg/h), +-2000 deg/s, \
                 32-bit output LSB 0.1/65536 deg/s"
            }
            Preset::Stim300 => {
                "STIM300 datasheet class (methods notes s.5): ARW 0.15 deg/sqrt(h), BI 0.5 deg/h (Sensonor quotes the \
                 Allan minimum; simulated as IEEE 952 B = 0.5, i.e. Allan minimum 0.33 deg/h), SF 500 ppm, \
                 nonlinearity 25 ppm at +-200 deg/s, range +-400 deg/s"
            }
        }
    }
}

impl SensorModel {
    /// The model of a preset; terms a preset does not state are zero (ideal).
    pub fn preset(preset: Preset) -> SensorModel {
        let base = SensorModel::default();
        match preset {
            Preset::Adxrs646 => SensorModel {
                output_unit: OutputUnit::Volt,
                scale_factor_per_dps: 0.0075,
                null: 2.5,
                output_rail_low: Some(0.25),
                output_rail_high: Some(4.75),
                arw_deg_rt_h: 0.6,
                bias_instability_dph: 12.0,
                ..base
            },
            Preset::Adis16470 => SensorModel {
                output_unit: OutputUnit::DegPerSec,
                output_rail_low: Some(-2000.0),
                output_rail_high: Some(2000.0),
                arw_deg_rt_h: 0.34,
                bias_instability_dph: 8.0,
                // 32-bit output (GYRO_OUT:GYRO_LOW): 0.1 deg/s per 2^16 LSB = 2^-16 / 10 deg/s.
                output_quantization_step: 0.1 / 65_536.0,
                ..base
            },
            Preset::Stim300 => SensorModel {
                output_unit: OutputUnit::DegPerSec,
                output_rail_low: Some(-400.0),
                output_rail_high: Some(400.0),
                scale_factor_error_ppm: 500.0,
                // Cubic term equal to 25 ppm of the output at 200 deg/s: k3 * 200^3 = 25e-6 * 200.
                nonlinearity_cubic_per_dps2: 25e-6 / (200.0 * 200.0),
                arw_deg_rt_h: 0.15,
                bias_instability_dph: 0.5,
                ..base
            },
        }
    }

    /// Checks every parameter; the error names the parameter and its valid range.
    pub fn validate(&self) -> Result<(), SimError> {
        check(
            "scale_factor_per_dps",
            self.scale_factor_per_dps,
            self.scale_factor_per_dps != 0.0,
            "finite and non-zero",
        )?;
        finite("null", self.null)?;
        let e = self.scale_factor_error_ppm;
        check("scale_factor_error_ppm", e, e > -1e6, "finite and > -1e6 (the scale factor keeps its sign)")?;
        let a = self.scale_factor_asymmetry_ppm;
        check("scale_factor_asymmetry_ppm", a, a.abs() < 2e6, "finite and within (-2e6, 2e6)")?;
        finite("nonlinearity_quadratic_per_dps", self.nonlinearity_quadratic_per_dps)?;
        finite("nonlinearity_cubic_per_dps2", self.nonlinearity_cubic_per_dps2)?;
        if let Some(v) = self.output_rail_low {
            finite("output_rail_low", v)?;
        }
        if let Some(v) = self.output_rail_high {
            finite("output_rail_high", v)?;
        }
        let low = self.output_rail_low.unwrap_or(f64::NEG_INFINITY);
        let high = self.output_rail_high.unwrap_or(f64::INFINITY);
        if !(low < self.null && self.null < high) {
            return Err(SimError::RailsMustEncloseNull { low, high, null: self.null });
        }
        non_negative("dead_zone_dps", self.dead_zone_dps)?;
        finite("hysteresis_dps", self.hysteresis_dps)?;
        finite("bias_dph", self.bias_dph)?;
        non_negative("run_to_run_bias_sigma_dph", self.run_to_run_bias_sigma_dph)?;
        non_negative("run_to_run_scale_factor_sigma_ppm", self.run_to_run_scale_factor_sigma_ppm)?;
        non_negative("arw_deg_rt_h", self.arw_deg_rt_h)?;
        non_negative("bias_instability_dph", self.bias_instability_dph)?;
        positive("flicker_tau_min_s", self.flicker_tau_min_s)?;
        let (tmin, tmax) = (self.flicker_tau_min_s, self.flicker_tau_max_s);
        check(
            "flicker_tau_max_s",
            tmax,
            tmax >= 2.0 * tmin && tmax <= 1e9 * tmin,
            "finite, at least 2 x flicker_tau_min_s and at most 1e9 x flicker_tau_min_s",
        )?;
        non_negative("rrw_deg_h_rt_h", self.rrw_deg_h_rt_h)?;
        finite("rate_ramp_dph_per_h", self.rate_ramp_dph_per_h)?;
        finite("warmup_amplitude_dph", self.warmup_amplitude_dph)?;
        if self.warmup_amplitude_dph != 0.0 {
            positive("warmup_time_constant_s", self.warmup_time_constant_s)?;
        } else {
            non_negative("warmup_time_constant_s", self.warmup_time_constant_s)?;
        }
        non_negative("output_quantization_step", self.output_quantization_step)?;
        non_negative("angle_quantization_deg", self.angle_quantization_deg)?;
        finite("bias_temp_coeff_dph_per_c", self.bias_temp_coeff_dph_per_c)?;
        finite("scale_factor_temp_coeff_ppm_per_c", self.scale_factor_temp_coeff_ppm_per_c)?;
        finite("reference_temp_c", self.reference_temp_c)?;
        for g in self.g_sensitivity_dph_per_g {
            finite("g_sensitivity_dph_per_g", g)?;
        }
        Ok(())
    }

    /// Checks the parameters that depend on the sample rate (after [`SensorModel::validate`]).
    pub fn validate_for_sample_rate(&self, sample_rate_hz: f64) -> Result<(), SimError> {
        if self.bias_instability_dph > 0.0 {
            let min_s = FLICKER_MIN_TAU_SAMPLES / sample_rate_hz;
            let t = self.flicker_tau_min_s;
            if t < min_s {
                return Err(SimError::OutOfRange {
                    parameter: "flicker_tau_min_s",
                    value: t,
                    valid: format!(
                        "at least {FLICKER_MIN_TAU_SAMPLES} sample intervals ({min_s} s at {sample_rate_hz} Hz) \
                         when bias_instability_dph > 0"
                    ),
                });
            }
        }
        Ok(())
    }
}

/// A step of a temperature profile: from `at_s` on, the temperature is `temp_c`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TemperatureStep {
    /// Time of the step from the record start, s.
    pub at_s: f64,
    /// Temperature from then on, degC.
    pub temp_c: f64,
}

/// The sensor temperature over the record (drives the temperature coefficients).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum TemperatureProfile {
    /// Constant temperature, degC.
    Constant {
        /// Temperature, degC.
        temp_c: f64,
    },
    /// Linear ramp: start_c + rate_c_per_h * t.
    Ramp {
        /// Temperature at the record start, degC.
        start_c: f64,
        /// Ramp rate, degC per hour.
        rate_c_per_h: f64,
    },
    /// Steps: start_c, then each step's temperature from its time on (steps in increasing time).
    Steps {
        /// Temperature at the record start, degC.
        start_c: f64,
        /// The steps, in increasing time.
        steps: Vec<TemperatureStep>,
    },
}

impl Default for TemperatureProfile {
    /// Constant 25 degC.
    fn default() -> Self {
        TemperatureProfile::Constant { temp_c: 25.0 }
    }
}

impl TemperatureProfile {
    /// Temperature at time t_s from the record start, degC.
    pub fn temp_at(&self, t_s: f64) -> f64 {
        match self {
            TemperatureProfile::Constant { temp_c } => *temp_c,
            TemperatureProfile::Ramp { start_c, rate_c_per_h } => {
                start_c + crate::units::per_hour_to_per_second(*rate_c_per_h) * t_s
            }
            TemperatureProfile::Steps { start_c, steps } => {
                let i = steps.partition_point(|s| s.at_s <= t_s);
                if i == 0 {
                    *start_c
                } else {
                    steps[i - 1].temp_c
                }
            }
        }
    }

    /// Replaces `temps_c` with the temperature at each of `times_s` (the values of
    /// [`TemperatureProfile::temp_at`]), degC.
    pub fn temps_at(&self, times_s: &[f64], temps_c: &mut Vec<f64>) {
        temps_c.clear();
        match self {
            TemperatureProfile::Constant { temp_c } => temps_c.resize(times_s.len(), *temp_c),
            _ => temps_c.extend(times_s.iter().map(|&t| self.temp_at(t))),
        }
    }

    /// Checks the profile's values (finite; steps in strictly increasing time, at or after 0).
    pub fn validate(&self) -> Result<(), SimError> {
        match self {
            TemperatureProfile::Constant { temp_c } => finite("temperature.temp_c", *temp_c),
            TemperatureProfile::Ramp { start_c, rate_c_per_h } => {
                finite("temperature.start_c", *start_c)?;
                finite("temperature.rate_c_per_h", *rate_c_per_h)
            }
            TemperatureProfile::Steps { start_c, steps } => {
                finite("temperature.start_c", *start_c)?;
                let mut last = f64::NEG_INFINITY;
                for (index, s) in steps.iter().enumerate() {
                    let in_step = |e| SimError::InStep { index, error: Box::new(e) };
                    check(
                        "temperature.steps.at_s",
                        s.at_s,
                        s.at_s >= 0.0 && s.at_s > last,
                        "finite, >= 0 and increasing",
                    )
                    .map_err(in_step)?;
                    finite("temperature.steps.temp_c", s.temp_c).map_err(in_step)?;
                    last = s.at_s;
                }
                Ok(())
            }
        }
    }

    /// The profile as text, for a record's comment lines.
    pub fn describe(&self) -> String {
        match self {
            TemperatureProfile::Constant { temp_c } => format!("constant {temp_c:?} degC"),
            TemperatureProfile::Ramp { start_c, rate_c_per_h } => {
                format!("ramp from {start_c:?} degC at {rate_c_per_h:?} degC/h")
            }
            TemperatureProfile::Steps { start_c, steps } => {
                let mut s = format!("steps from {start_c:?} degC");
                for st in steps {
                    s.push_str(&format!("; {:?} degC at {:?} s", st.temp_c, st.at_s));
                }
                s
            }
        }
    }
}

fn validate_latitude(latitude_deg: Option<f64>) -> Result<(), SimError> {
    match latitude_deg {
        Some(l) => check("latitude_deg", l, (-90.0..=90.0).contains(&l), "finite and within [-90, 90]"),
        None => Ok(()),
    }
}

/// A static (zero table rate) record: input axis vertical, so the earth rate's vertical part is
/// sensed (scaled by `input_axis_up` when the sensor is turned to another orientation).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StaticSpec {
    /// Sample rate, Hz (> 0).
    pub sample_rate_hz: f64,
    /// Record length, s (at least one sample: samples = round(duration_s x sample_rate_hz)).
    pub duration_s: f64,
    /// Sensor temperature over the record.
    pub temperature: TemperatureProfile,
    /// Latitude, deg (north positive); none to leave the earth rate out.
    pub latitude_deg: Option<f64>,
    /// Whether samples carry the temperature (a `temp_c` column).
    pub record_temperature: bool,
    /// Specific force along sensor x, y, z in this record's orientation, g (the reaction to
    /// gravity: `[1, 0, 0]` with +x up); adds the bias G · f of `g_sensitivity_dph_per_g`.
    /// None: no g-sensitive bias (as before).
    pub specific_force_g: Option<[f64; 3]>,
    /// Up component of the input axis (cosine of its angle to the vertical), scaling the sensed
    /// vertical earth rate: 1 input axis up (the default), -1 down, 0 horizontal (pointing
    /// east-west, where the earth rate's projection is zero).
    pub input_axis_up: f64,
}

impl Default for StaticSpec {
    /// 100 Hz, 1200 s (the paper's static-test length), 25 degC, no earth rate, no temperature column.
    fn default() -> Self {
        StaticSpec {
            sample_rate_hz: 100.0,
            duration_s: 1200.0,
            temperature: TemperatureProfile::default(),
            latitude_deg: None,
            record_temperature: false,
            specific_force_g: None,
            input_axis_up: 1.0,
        }
    }
}

impl StaticSpec {
    /// Number of samples in the record.
    pub fn samples(&self) -> u64 {
        (self.duration_s * self.sample_rate_hz).round() as u64
    }

    /// Checks the specification; the error names the parameter and its valid range.
    pub fn validate(&self) -> Result<(), SimError> {
        positive("sample_rate_hz", self.sample_rate_hz)?;
        positive("duration_s", self.duration_s)?;
        let n = self.duration_s * self.sample_rate_hz;
        check("duration_s", self.duration_s, (0.5..9e18).contains(&n), "at least one sample interval long")?;
        self.temperature.validate()?;
        if let Some(f) = self.specific_force_g {
            for v in f {
                finite("specific_force_g", v)?;
            }
        }
        let u = self.input_axis_up;
        check("input_axis_up", u, (-1.0..=1.0).contains(&u), "finite and within [-1, 1]")?;
        validate_latitude(self.latitude_deg)
    }

    /// Each parameter's name and value as text, for a record's comment lines (the orientation
    /// lines only when an orientation is set).
    pub fn parameter_lines(&self) -> Vec<(&'static str, String)> {
        let mut lines = vec![
            ("sample_rate_hz", self.sample_rate_hz.parameter_text()),
            ("duration_s", self.duration_s.parameter_text()),
            ("samples", self.samples().to_string()),
            ("temperature", self.temperature.describe()),
            ("latitude_deg", self.latitude_deg.parameter_text()),
        ];
        if let Some(f) = self.specific_force_g {
            lines.push(("specific_force_g", f.parameter_text()));
        }
        if self.input_axis_up != 1.0 {
            lines.push(("input_axis_up", self.input_axis_up.parameter_text()));
        }
        lines
    }
}

/// What to do with the samples taken while the table settles on a new rate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SettlingRows {
    /// Simulate them (time and noise go on) but do not yield them.
    Drop,
    /// Yield them with `settling = true` (the CSV writer adds a `settling` column).
    Flag,
}

/// A rate-table (scale-factor) test: runs of a forward stroke (rates rising) then a reverse
/// stroke (rates falling), each plateau a number of samples after a settling time.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RateTableSpec {
    /// Table rates, deg/s (any order; at least 2 distinct; the strokes sort them).
    pub rates_dps: Vec<f64>,
    /// Number of runs (>= 1).
    pub runs: u32,
    /// Sample rate, Hz (> 0).
    pub sample_rate_hz: f64,
    /// Samples kept per plateau (>= 1).
    pub samples_per_plateau: u32,
    /// Settling time at the start of each plateau, s (the table rate ramps linearly to the new rate).
    pub settling_s: f64,
    /// Whether settling samples are dropped or yielded flagged.
    pub settling: SettlingRows,
    /// Samples of the rest records at start and end (rate 0, strokes `rest_start` / `rest_end`); 0 for none.
    pub rest_samples: u32,
    /// Sensor temperature over the test.
    pub temperature: TemperatureProfile,
    /// Latitude, deg (input axis vertical); none to leave the earth rate out.
    pub latitude_deg: Option<f64>,
}

/// The paper's 14 table rates, deg/s.
pub const PAPER_RATES_DPS: [f64; 14] =
    [-300.0, -240.0, -160.0, -120.0, -60.0, -40.0, 0.0, 25.0, 70.0, 100.0, 135.0, 185.0, 230.0, 300.0];

impl Default for RateTableSpec {
    /// The paper's test: 14 rates, 4 runs; 100 Hz, 100 samples per plateau, 2 s settling dropped, 100 rest samples.
    fn default() -> Self {
        RateTableSpec {
            rates_dps: PAPER_RATES_DPS.to_vec(),
            runs: 4,
            sample_rate_hz: 100.0,
            samples_per_plateau: 100,
            settling_s: 2.0,
            settling: SettlingRows::Drop,
            rest_samples: 100,
            temperature: TemperatureProfile::default(),
            latitude_deg: None,
        }
    }
}

impl RateTableSpec {
    /// The distinct rates in ascending order (the forward stroke), after validation.
    pub fn sorted_rates(&self) -> Result<Vec<f64>, SimError> {
        let mut rates = self.rates_dps.clone();
        for &r in &rates {
            finite("rates_dps", r)?;
        }
        rates.sort_by(f64::total_cmp);
        for w in rates.windows(2) {
            if w[0] == w[1] {
                return Err(SimError::DuplicateRate { rate_dps: w[0] });
            }
        }
        if rates.len() < 2 {
            return Err(SimError::TooFewRates { found: rates.len() });
        }
        Ok(rates)
    }

    /// Checks the specification; the error names the parameter and its valid range.
    pub fn validate(&self) -> Result<(), SimError> {
        self.sorted_rates()?;
        check("runs", self.runs as f64, self.runs >= 1, "an integer >= 1")?;
        positive("sample_rate_hz", self.sample_rate_hz)?;
        check(
            "samples_per_plateau",
            self.samples_per_plateau as f64,
            self.samples_per_plateau >= 1,
            "an integer >= 1",
        )?;
        non_negative("settling_s", self.settling_s)?;
        check("settling_s", self.settling_s, self.settling_s * self.sample_rate_hz < 4e9, "shorter than 4e9 samples")?;
        self.temperature.validate()?;
        validate_latitude(self.latitude_deg)
    }

    /// Samples in the settling part of each plateau.
    pub fn settling_samples(&self) -> u64 {
        (self.settling_s * self.sample_rate_hz).ceil() as u64
    }

    /// Each parameter's name and value as text, for a record's comment lines.
    pub fn parameter_lines(&self) -> Vec<(&'static str, String)> {
        let rates: Vec<String> = self.rates_dps.iter().map(|r| r.parameter_text()).collect();
        vec![
            ("rates_dps", rates.join(" ")),
            ("runs", self.runs.to_string()),
            ("sample_rate_hz", self.sample_rate_hz.parameter_text()),
            ("samples_per_plateau", self.samples_per_plateau.to_string()),
            ("settling_s", self.settling_s.parameter_text()),
            ("settling", format!("{:?}", self.settling).to_lowercase()),
            ("rest_samples", self.rest_samples.to_string()),
            ("temperature", self.temperature.describe()),
            ("latitude_deg", self.latitude_deg.parameter_text()),
        ]
    }
}

/// A whole simulation set-up, as a TOML file gives it: a seed, an optional preset with
/// overrides, and the two record specifications.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SimConfig {
    /// Seed of the random streams (the same seed gives the same samples everywhere).
    pub seed: u64,
    /// Preset to start from; none for the ideal sensor.
    pub preset: Option<Preset>,
    /// Parameters that replace the preset's.
    pub sensor: SensorOverrides,
    /// The static record.
    pub static_record: StaticSpec,
    /// The rate-table test.
    pub rate_table: RateTableSpec,
}

impl SimConfig {
    /// The sensor model: the preset (or the ideal sensor) with the overrides applied.
    pub fn sensor_model(&self) -> SensorModel {
        self.preset.map_or_else(SensorModel::default, SensorModel::preset).with_overrides(&self.sensor)
    }
}
