//! Units of rates, outputs and noise coefficients. Every unit conversion in gyrolab lives here.
//!
//! Sources: SI definitions; IEEE Std 952-1997 annex C for the noise-coefficient units
//! (angle random walk in deg/sqrt(h), bias instability in deg/h, rate random walk in deg/h/sqrt(h)).

use serde::{Deserialize, Serialize};
use std::fmt;

/// Degrees per radian.
pub const DEG_PER_RAD: f64 = 180.0 / std::f64::consts::PI;
/// Seconds per hour.
pub const SECONDS_PER_HOUR: f64 = 3600.0;
/// Earth rotation rate relative to the stars, in deg/h (IERS: 7.292115e-5 rad/s).
pub const EARTH_RATE_DPH: f64 = 7.292_115e-5 * DEG_PER_RAD * SECONDS_PER_HOUR;

/// Converts a rate in deg/s to deg/h.
pub fn dps_to_dph(v: f64) -> f64 {
    v * SECONDS_PER_HOUR
}

/// Converts a rate in deg/h to deg/s.
pub fn dph_to_dps(v: f64) -> f64 {
    v / SECONDS_PER_HOUR
}

/// Converts an angle random walk from deg/sqrt(s) (equal to deg/s/sqrt(Hz)) to deg/sqrt(h).
pub fn arw_deg_rt_s_to_deg_rt_h(v: f64) -> f64 {
    v * SECONDS_PER_HOUR.sqrt()
}

/// Converts an angle random walk from deg/sqrt(h) to deg/sqrt(s).
pub fn arw_deg_rt_h_to_deg_rt_s(v: f64) -> f64 {
    v / SECONDS_PER_HOUR.sqrt()
}

/// Converts a rate random walk from deg/s/sqrt(s) to deg/h/sqrt(h) (factor 3600^1.5 = 216000).
pub fn rrw_dps_rt_s_to_dph_rt_h(v: f64) -> f64 {
    v * SECONDS_PER_HOUR * SECONDS_PER_HOUR.sqrt()
}

/// Converts a rate random walk from deg/h/sqrt(h) to deg/s/sqrt(s).
pub fn rrw_dph_rt_h_to_dps_rt_s(v: f64) -> f64 {
    v / (SECONDS_PER_HOUR * SECONDS_PER_HOUR.sqrt())
}

/// Converts a bias instability (or any rate) from deg/s to deg/h; alias of [`dps_to_dph`] for noise terms.
pub fn bias_dps_to_dph(v: f64) -> f64 {
    dps_to_dph(v)
}

/// Converts a rate ramp from deg/s per s (deg/s^2) to deg/h per h (factor 3600^2).
pub fn rate_ramp_dps_per_s_to_dph_per_h(v: f64) -> f64 {
    v * SECONDS_PER_HOUR * SECONDS_PER_HOUR
}

/// Converts an angle random walk in deg/sqrt(s) to a Kalibr noise density in rad/s/sqrt(Hz).
pub fn arw_deg_rt_s_to_rad_s_rt_hz(v: f64) -> f64 {
    deg_to_rad(v)
}

/// Converts a rate random walk in deg/s/sqrt(s) to a Kalibr random walk in rad/s^2/sqrt(Hz).
pub fn rrw_dps_rt_s_to_rad_s2_rt_hz(v: f64) -> f64 {
    deg_to_rad(v)
}

/// Converts degrees (or deg/s, deg/s/sqrt(Hz), ...) to radians (rad/s, ...).
pub fn deg_to_rad(v: f64) -> f64 {
    v / DEG_PER_RAD
}

/// Converts radians (or rad/s, ...) to degrees (deg/s, ...).
pub fn rad_to_deg(v: f64) -> f64 {
    v * DEG_PER_RAD
}

/// Converts an angle in radians to milliradians.
pub fn rad_to_mrad(v: f64) -> f64 {
    v * 1e3
}

/// Converts an angle in milliradians to radians.
pub fn mrad_to_rad(v: f64) -> f64 {
    v * 1e-3
}

/// Converts a dimensionless ratio to percent.
pub fn ratio_to_pct(v: f64) -> f64 {
    v * 100.0
}

/// Converts parts per million to a dimensionless ratio.
pub fn ppm_to_ratio(v: f64) -> f64 {
    v * 1e-6
}

/// Converts a rate ramp from deg/h per hour (deg/h^2) to deg/s per second (deg/s^2).
pub fn rate_ramp_dph_per_h_to_dps_per_s(v: f64) -> f64 {
    v / (SECONDS_PER_HOUR * SECONDS_PER_HOUR)
}

/// Converts a temperature rate from degC per hour to degC per second.
pub fn per_hour_to_per_second(v: f64) -> f64 {
    v / SECONDS_PER_HOUR
}

/// Per-sample standard deviation (deg/s) of white rate noise from an angle random walk N in
/// deg/sqrt(h) at sample interval dt in s: sigma = N[deg/sqrt(s)] / sqrt(dt) (IEEE Std 952 annex C).
pub fn arw_deg_rt_h_to_sample_sigma_dps(arw_deg_rt_h: f64, dt_s: f64) -> f64 {
    arw_deg_rt_h_to_deg_rt_s(arw_deg_rt_h) / dt_s.sqrt()
}

/// Standard deviation (deg/s) of one rate-random-walk increment over dt in s from K in
/// deg/h/sqrt(h): sigma = K[deg/s/sqrt(s)] * sqrt(dt) (IEEE Std 952 annex C).
pub fn rrw_dph_rt_h_to_increment_sigma_dps(rrw_deg_h_rt_h: f64, dt_s: f64) -> f64 {
    rrw_dph_rt_h_to_dps_rt_s(rrw_deg_h_rt_h) * dt_s.sqrt()
}

/// Converts a dimensionless ratio to parts per million.
pub fn ratio_to_ppm(v: f64) -> f64 {
    v * 1e6
}

/// Converts a quantity per second (such as a drift slope in V/s) to the same quantity per hour.
pub fn per_s_to_per_h(v: f64) -> f64 {
    v * SECONDS_PER_HOUR
}

/// Converts a rate change in (deg/s)/s to (deg/h)/h (factor 3600 * 3600).
pub fn dps_per_s_to_dph_per_h(v: f64) -> f64 {
    v * SECONDS_PER_HOUR * SECONDS_PER_HOUR
}

/// Converts a temperature sensitivity in (deg/s)/degC to (deg/h)/degC.
pub fn dps_per_c_to_dph_per_c(v: f64) -> f64 {
    v * SECONDS_PER_HOUR
}

/// Earth-rate component along a vertical (upward) input axis at a latitude in degrees:
/// Omega_e * sin(latitude), in deg/h. For a downward axis pass the negated latitude.
pub fn earth_rate_vertical_dph(latitude_deg: f64) -> f64 {
    EARTH_RATE_DPH * deg_to_rad(latitude_deg).sin()
}

/// Unit of an input (table) rate.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum RateUnit {
    /// Degrees per second.
    #[serde(rename = "deg/s")]
    DegPerSec,
    /// Radians per second.
    #[serde(rename = "rad/s")]
    RadPerSec,
    /// Degrees per hour.
    #[serde(rename = "deg/h")]
    DegPerHour,
}

impl RateUnit {
    /// All rate units, for listing in messages.
    pub const ALL: [RateUnit; 3] = [RateUnit::DegPerSec, RateUnit::RadPerSec, RateUnit::DegPerHour];

    /// Converts a value in this unit to deg/s.
    pub fn to_dps(self, v: f64) -> f64 {
        match self {
            RateUnit::DegPerSec => v,
            RateUnit::RadPerSec => rad_to_deg(v),
            RateUnit::DegPerHour => dph_to_dps(v),
        }
    }

    /// Converts a value in deg/s to this unit.
    pub fn from_dps(self, v: f64) -> f64 {
        match self {
            RateUnit::DegPerSec => v,
            RateUnit::RadPerSec => deg_to_rad(v),
            RateUnit::DegPerHour => dps_to_dph(v),
        }
    }

    /// The unit's symbol, such as `deg/s`.
    pub fn symbol(self) -> &'static str {
        match self {
            RateUnit::DegPerSec => "deg/s",
            RateUnit::RadPerSec => "rad/s",
            RateUnit::DegPerHour => "deg/h",
        }
    }

    /// The column-name suffix that declares this unit, such as `dps` in `rate_dps`.
    pub fn suffix(self) -> &'static str {
        match self {
            RateUnit::DegPerSec => "dps",
            RateUnit::RadPerSec => "rad_s",
            RateUnit::DegPerHour => "dph",
        }
    }

    /// Parses a suffix or symbol (`dps`, `deg/s`, `rad_s`, `rad/s`, `dph`, `deg/h`).
    pub fn parse(s: &str) -> Option<RateUnit> {
        match s.trim().to_ascii_lowercase().as_str() {
            "dps" | "deg/s" | "deg_s" | "°/s" => Some(RateUnit::DegPerSec),
            "rad_s" | "rad/s" | "rps" => Some(RateUnit::RadPerSec),
            "dph" | "deg/h" | "deg_h" => Some(RateUnit::DegPerHour),
            _ => None,
        }
    }
}

impl fmt::Display for RateUnit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.symbol())
    }
}

/// Unit of a gyro's output signal.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum OutputUnit {
    /// Volts (analog output).
    #[serde(rename = "V")]
    Volt,
    /// Millivolts (analog output).
    #[serde(rename = "mV")]
    Millivolt,
    /// Least significant bits (digital output counts).
    #[serde(rename = "LSB")]
    Lsb,
    /// Degrees per second (an already scaled digital output).
    #[serde(rename = "deg/s")]
    DegPerSec,
    /// Radians per second (an already scaled digital output).
    #[serde(rename = "rad/s")]
    RadPerSec,
}

impl OutputUnit {
    /// All output units, for listing in messages.
    pub const ALL: [OutputUnit; 5] =
        [OutputUnit::Volt, OutputUnit::Millivolt, OutputUnit::Lsb, OutputUnit::DegPerSec, OutputUnit::RadPerSec];

    /// The unit's symbol, such as `mV`.
    pub fn symbol(self) -> &'static str {
        match self {
            OutputUnit::Volt => "V",
            OutputUnit::Millivolt => "mV",
            OutputUnit::Lsb => "LSB",
            OutputUnit::DegPerSec => "deg/s",
            OutputUnit::RadPerSec => "rad/s",
        }
    }

    /// The column-name suffix that declares this unit, such as `v` in `output_v`.
    pub fn suffix(self) -> &'static str {
        match self {
            OutputUnit::Volt => "v",
            OutputUnit::Millivolt => "mv",
            OutputUnit::Lsb => "lsb",
            OutputUnit::DegPerSec => "dps",
            OutputUnit::RadPerSec => "rad_s",
        }
    }

    /// Parses a suffix or symbol (`v`, `mv`, `lsb`, `dps`, `rad_s`, `deg/s`, `rad/s`).
    pub fn parse(s: &str) -> Option<OutputUnit> {
        match s.trim().to_ascii_lowercase().as_str() {
            "v" | "volt" | "volts" => Some(OutputUnit::Volt),
            "mv" => Some(OutputUnit::Millivolt),
            "lsb" | "counts" => Some(OutputUnit::Lsb),
            "dps" | "deg/s" | "deg_s" => Some(OutputUnit::DegPerSec),
            "rad_s" | "rad/s" => Some(OutputUnit::RadPerSec),
            _ => None,
        }
    }

    /// The scale factor, in this unit per deg/s, of an output that is already a rate
    /// (1 for deg/s, pi/180 for rad/s); `None` for V, mV and LSB, which need a calibration.
    pub fn native_scale_factor_per_dps(self) -> Option<f64> {
        match self {
            OutputUnit::DegPerSec => Some(1.0),
            OutputUnit::RadPerSec => Some(deg_to_rad(1.0)),
            _ => None,
        }
    }

    /// The accepted column-name suffixes, for messages: `v, mv, lsb, dps, rad_s`.
    pub fn accepted_suffixes() -> String {
        OutputUnit::ALL.iter().map(|u| u.suffix()).collect::<Vec<_>>().join(", ")
    }

    /// The unit in which people usually quote a scale factor for this output, with the factor
    /// that converts a value in this unit to it (volts are quoted in mV per deg/s).
    pub fn scale_factor_display(self) -> (OutputUnit, f64) {
        match self {
            OutputUnit::Volt => (OutputUnit::Millivolt, 1e3),
            other => (other, 1.0),
        }
    }

    /// The factor that converts a value in this unit to `other`, when both are the same
    /// physical quantity (V and mV; deg/s and rad/s).
    pub fn factor_to(self, other: OutputUnit) -> Option<f64> {
        use OutputUnit::*;
        match (self, other) {
            (a, b) if a == b => Some(1.0),
            (Volt, Millivolt) => Some(1e3),
            (Millivolt, Volt) => Some(1e-3),
            (DegPerSec, RadPerSec) => Some(1.0 / DEG_PER_RAD),
            (RadPerSec, DegPerSec) => Some(DEG_PER_RAD),
            _ => None,
        }
    }
}

impl fmt::Display for OutputUnit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.symbol())
    }
}

/// Splits a column name such as `output_mv` or `rate_rad_s` into its base name and unit suffix.
///
/// Returns the base and the suffix text (lower case) after the first underscore that starts a
/// recognised suffix, or the whole name and `None` when there is no underscore.
pub fn split_unit_suffix(name: &str) -> (String, Option<String>) {
    let lower = name.trim().to_ascii_lowercase();
    // Two-part suffixes first (rad_s).
    if let Some(base) = lower.strip_suffix("_rad_s") {
        return (base.to_string(), Some("rad_s".to_string()));
    }
    match lower.rfind('_') {
        Some(i) if i > 0 => (lower[..i].to_string(), Some(lower[i + 1..].to_string())),
        _ => (lower, None),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn noise_unit_factors_match_hand_values() {
        // 1 deg/sqrt(s) = 60 deg/sqrt(h); 1 deg/s/sqrt(s) = 3600 * 60 deg/h/sqrt(h).
        assert_relative_eq!(arw_deg_rt_s_to_deg_rt_h(1.0), 60.0);
        assert_relative_eq!(rrw_dps_rt_s_to_dph_rt_h(1.0), 216_000.0);
        assert_relative_eq!(rrw_dph_rt_h_to_dps_rt_s(216_000.0), 1.0);
        assert_relative_eq!(dps_to_dph(1.0), 3600.0);
        assert_relative_eq!(EARTH_RATE_DPH, 15.041_07, epsilon = 1e-4);
        // 1 (deg/s)/s = 3600 (deg/h)/s = 12 960 000 (deg/h)/h; sin(30 deg) = 1/2.
        assert_relative_eq!(dps_per_s_to_dph_per_h(1.0), 12_960_000.0);
        assert_relative_eq!(earth_rate_vertical_dph(30.0), 0.5 * EARTH_RATE_DPH, epsilon = 1e-12);
        assert_relative_eq!(OutputUnit::RadPerSec.native_scale_factor_per_dps().unwrap(), 0.017_453_292_519_943_295);
    }

    #[test]
    fn rate_units_round_trip() {
        for u in RateUnit::ALL {
            assert_relative_eq!(u.to_dps(u.from_dps(12.5)), 12.5, epsilon = 1e-12);
        }
        assert_relative_eq!(RateUnit::RadPerSec.to_dps(std::f64::consts::PI), 180.0);
    }

    #[test]
    fn suffixes_split() {
        assert_eq!(split_unit_suffix("rate_rad_s"), ("rate".into(), Some("rad_s".into())));
        assert_eq!(split_unit_suffix("Output_mV"), ("output".into(), Some("mv".into())));
        assert_eq!(split_unit_suffix("run"), ("run".into(), None));
        for u in OutputUnit::ALL {
            assert_eq!(OutputUnit::parse(u.suffix()), Some(u));
        }
        for u in RateUnit::ALL {
            assert_eq!(RateUnit::parse(u.suffix()), Some(u));
        }
    }
}
