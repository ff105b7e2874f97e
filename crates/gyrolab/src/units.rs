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

/// Converts a velocity random walk from m/s/sqrt(s) (= m/s^2/sqrt(Hz)) to m/s/sqrt(h).
pub fn vrw_m_s_rt_s_to_m_s_rt_h(v: f64) -> f64 {
    v * SECONDS_PER_HOUR.sqrt()
}

/// Converts an acceleration random walk from m/s^2/sqrt(s) (= m/s^3/sqrt(Hz)) to m/s^2/sqrt(h).
pub fn accel_rw_m_s2_rt_s_to_m_s2_rt_h(v: f64) -> f64 {
    v * SECONDS_PER_HOUR.sqrt()
}

/// Converts an acceleration in m/s^2 to micro-g (1 ug = 9.80665e-6 m/s^2).
pub fn m_s2_to_ug(v: f64) -> f64 {
    v / STANDARD_GRAVITY_M_S2 * 1e6
}

/// Converts an acceleration ramp from m/s^2 per second to m/s^2 per hour.
pub fn accel_ramp_per_s_to_per_h(v: f64) -> f64 {
    v * SECONDS_PER_HOUR
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

/// What a channel's values measure, by their unit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Quantity {
    /// A sensor output (V, mV, LSB) that needs a scale factor to become a rate.
    SensorOutput,
    /// An angular rate (deg/s, rad/s, deg/h, mrad/s): a gyro channel.
    AngularRate,
    /// A specific force (m/s^2, g, mg): an accelerometer channel.
    Acceleration,
    /// No unit known: deviations in the channel's own units, no noise terms in physical units.
    Unitless,
}

/// Standard gravity g_n in m/s^2 (CGPM 1901; ISO 80000-3).
pub const STANDARD_GRAVITY_M_S2: f64 = 9.806_65;

/// Unit of a sensor channel: a gyro's output signal, an angular rate, or an acceleration.
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
    /// Degrees per hour.
    #[serde(rename = "deg/h")]
    DegPerHour,
    /// Milliradians per second.
    #[serde(rename = "mrad/s")]
    MilliradPerSec,
    /// Metres per second squared (accelerometer).
    #[serde(rename = "m/s^2")]
    MeterPerSec2,
    /// Standard gravity, 9.80665 m/s^2 (accelerometer).
    #[serde(rename = "g")]
    StandardGravity,
    /// Thousandths of standard gravity (accelerometer).
    #[serde(rename = "mg")]
    MilliG,
    /// No unit: a dimensionless output.
    #[serde(rename = "1")]
    Unitless,
}

impl OutputUnit {
    /// The units a rate-table output can be in (sensor outputs and angular rates), for messages.
    pub const ALL: [OutputUnit; 7] = [
        OutputUnit::Volt,
        OutputUnit::Millivolt,
        OutputUnit::Lsb,
        OutputUnit::DegPerSec,
        OutputUnit::RadPerSec,
        OutputUnit::DegPerHour,
        OutputUnit::MilliradPerSec,
    ];

    /// Every unit a time-series channel can be in.
    pub const CHANNEL_UNITS: [OutputUnit; 10] = [
        OutputUnit::Volt,
        OutputUnit::Millivolt,
        OutputUnit::Lsb,
        OutputUnit::DegPerSec,
        OutputUnit::RadPerSec,
        OutputUnit::DegPerHour,
        OutputUnit::MilliradPerSec,
        OutputUnit::MeterPerSec2,
        OutputUnit::StandardGravity,
        OutputUnit::MilliG,
    ];

    /// The unit's symbol, such as `mV`.
    pub fn symbol(self) -> &'static str {
        match self {
            OutputUnit::Volt => "V",
            OutputUnit::Millivolt => "mV",
            OutputUnit::Lsb => "LSB",
            OutputUnit::DegPerSec => "deg/s",
            OutputUnit::RadPerSec => "rad/s",
            OutputUnit::DegPerHour => "deg/h",
            OutputUnit::MilliradPerSec => "mrad/s",
            OutputUnit::MeterPerSec2 => "m/s^2",
            OutputUnit::StandardGravity => "g",
            OutputUnit::MilliG => "mg",
            OutputUnit::Unitless => "1",
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
            OutputUnit::DegPerHour => "dph",
            OutputUnit::MilliradPerSec => "mrad_s",
            OutputUnit::MeterPerSec2 => "m_s2",
            OutputUnit::StandardGravity => "g",
            OutputUnit::MilliG => "mg",
            OutputUnit::Unitless => "",
        }
    }

    /// What the unit measures.
    pub fn quantity(self) -> Quantity {
        match self {
            OutputUnit::Volt | OutputUnit::Millivolt | OutputUnit::Lsb => Quantity::SensorOutput,
            OutputUnit::DegPerSec | OutputUnit::RadPerSec | OutputUnit::DegPerHour | OutputUnit::MilliradPerSec => {
                Quantity::AngularRate
            }
            OutputUnit::MeterPerSec2 | OutputUnit::StandardGravity | OutputUnit::MilliG => Quantity::Acceleration,
            OutputUnit::Unitless => Quantity::Unitless,
        }
    }

    /// Parses a suffix or symbol: `v`, `mv`, `lsb`, `dps`, `deg_s`, `deg/s`, `dph`, `deg/h`,
    /// `rad_s`, `rad/s`, `mrad_s`, `m_s2`, `m/s^2`, `g`, `mg` (and the spellings of
    /// [`normalise_unit_text`], such as `rad s^-1` or `°/s`).
    pub fn parse(s: &str) -> Option<OutputUnit> {
        let t = normalise_unit_text(s);
        match t.as_str() {
            "v" | "volt" | "volts" => Some(OutputUnit::Volt),
            "mv" => Some(OutputUnit::Millivolt),
            "lsb" | "counts" | "count" | "digits" => Some(OutputUnit::Lsb),
            "dps" | "deg/s" | "deg_s" | "degps" => Some(OutputUnit::DegPerSec),
            "rad_s" | "rad/s" | "rps" => Some(OutputUnit::RadPerSec),
            "dph" | "deg/h" | "deg_h" => Some(OutputUnit::DegPerHour),
            "mrad_s" | "mrad/s" => Some(OutputUnit::MilliradPerSec),
            "m_s2" | "m/s^2" | "m_s^2" | "mps2" | "m/s/s" | "m_s_2" => Some(OutputUnit::MeterPerSec2),
            "g" | "g0" | "gn" => Some(OutputUnit::StandardGravity),
            "mg" => Some(OutputUnit::MilliG),
            _ => None,
        }
    }

    /// Parses a unit a rate-table output can be in ([`OutputUnit::ALL`]: sensor outputs and
    /// angular rates); accelerations and unitless outputs are `None`.
    pub fn parse_gyro_output(s: &str) -> Option<OutputUnit> {
        OutputUnit::parse(s).filter(|u| OutputUnit::ALL.contains(u))
    }

    /// The scale factor, in this unit per deg/s, of an output that is already a rate
    /// (1 for deg/s, pi/180 for rad/s, 3600 for deg/h); `None` for V, mV and LSB, which need a
    /// calibration, and for accelerations and unitless outputs.
    pub fn native_scale_factor_per_dps(self) -> Option<f64> {
        match self {
            OutputUnit::DegPerSec => Some(1.0),
            OutputUnit::RadPerSec => Some(deg_to_rad(1.0)),
            OutputUnit::DegPerHour => Some(dps_to_dph(1.0)),
            OutputUnit::MilliradPerSec => Some(rad_to_mrad(deg_to_rad(1.0))),
            _ => None,
        }
    }

    /// The factor, in this unit per m/s^2, of an acceleration unit (1 for m/s^2, 1/9.80665 for
    /// g); `None` for other quantities.
    pub fn per_m_s2(self) -> Option<f64> {
        match self {
            OutputUnit::MeterPerSec2 => Some(1.0),
            OutputUnit::StandardGravity => Some(1.0 / STANDARD_GRAVITY_M_S2),
            OutputUnit::MilliG => Some(1e3 / STANDARD_GRAVITY_M_S2),
            _ => None,
        }
    }

    /// The accepted column-name suffixes of rate-table outputs, for messages.
    pub fn accepted_suffixes() -> String {
        OutputUnit::ALL.iter().map(|u| u.suffix()).collect::<Vec<_>>().join(", ")
    }

    /// The accepted column-name suffixes of time-series channels, for messages.
    pub fn accepted_channel_suffixes() -> String {
        OutputUnit::CHANNEL_UNITS.iter().map(|u| u.suffix()).collect::<Vec<_>>().join(", ")
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
    /// physical quantity (V and mV; any two angular rates; any two accelerations).
    pub fn factor_to(self, other: OutputUnit) -> Option<f64> {
        use OutputUnit::*;
        if self == other {
            return Some(1.0);
        }
        if let (Some(a), Some(b)) = (self.native_scale_factor_per_dps(), other.native_scale_factor_per_dps()) {
            return Some(b / a);
        }
        if let (Some(a), Some(b)) = (self.per_m_s2(), other.per_m_s2()) {
            return Some(b / a);
        }
        match (self, other) {
            (Volt, Millivolt) => Some(1e3),
            (Millivolt, Volt) => Some(1e-3),
            _ => None,
        }
    }
}

/// Unit of a time column.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum TimeUnit {
    /// Seconds.
    #[serde(rename = "s")]
    Second,
    /// Milliseconds.
    #[serde(rename = "ms")]
    Millisecond,
    /// Microseconds.
    #[serde(rename = "us")]
    Microsecond,
    /// Nanoseconds.
    #[serde(rename = "ns")]
    Nanosecond,
}

impl TimeUnit {
    /// Seconds per unit.
    pub fn seconds(self) -> f64 {
        match self {
            TimeUnit::Second => 1.0,
            TimeUnit::Millisecond => 1e-3,
            TimeUnit::Microsecond => 1e-6,
            TimeUnit::Nanosecond => 1e-9,
        }
    }

    /// The unit's symbol.
    pub fn symbol(self) -> &'static str {
        match self {
            TimeUnit::Second => "s",
            TimeUnit::Millisecond => "ms",
            TimeUnit::Microsecond => "us",
            TimeUnit::Nanosecond => "ns",
        }
    }

    /// Parses `s`, `sec`, `ms`, `us`, `µs`, `ns` (any case).
    pub fn parse(s: &str) -> Option<TimeUnit> {
        match normalise_unit_text(s).as_str() {
            "s" | "sec" | "secs" | "second" | "seconds" => Some(TimeUnit::Second),
            "ms" | "msec" => Some(TimeUnit::Millisecond),
            "us" | "usec" => Some(TimeUnit::Microsecond),
            "ns" | "nsec" => Some(TimeUnit::Nanosecond),
            _ => None,
        }
    }
}

/// Whether a unit text names a temperature in degC (`c`, `degc`, `°c`, `celsius`).
pub fn is_celsius(s: &str) -> bool {
    matches!(normalise_unit_text(s).as_str(), "c" | "degc" | "deg_c" | "celsius")
}

/// Normalises how a unit is written: lower case; `°` as `deg`, `µ` as `u`, `²` as `^2`;
/// `sec` as `s`; products with negative powers as a quotient (`rad s^-1` as `rad/s`,
/// `m s^-2` as `m/s^2`).
///
/// ```
/// use gyrolab::units::normalise_unit_text;
/// assert_eq!(normalise_unit_text("rad s^-1"), "rad/s");
/// assert_eq!(normalise_unit_text("m s^-2"), "m/s^2");
/// assert_eq!(normalise_unit_text("°/s"), "deg/s");
/// assert_eq!(normalise_unit_text("m/s²"), "m/s^2");
/// ```
pub fn normalise_unit_text(s: &str) -> String {
    let t = s.trim().to_lowercase().replace('°', "deg").replace(['µ', 'μ'], "u").replace('²', "^2");
    let t = t.replace("/sec", "/s").replace("deg/hr", "deg/h");
    let tokens: Vec<&str> =
        t.split(|c: char| c.is_whitespace() || c == '*' || c == '·').filter(|x| !x.is_empty()).collect();
    if tokens.len() < 2 {
        return tokens.first().map_or(String::new(), |x| x.to_string());
    }
    let (mut num, mut den) = (Vec::new(), Vec::new());
    for tok in tokens {
        match tok.split_once("^-").or_else(|| tok.split_once('-').filter(|(a, _)| !a.is_empty())) {
            Some((base, "1")) => den.push(base.to_string()),
            Some((base, p)) => den.push(format!("{base}^{p}")),
            None => num.push(tok.to_string()),
        }
    }
    let mut out = num.join(" ");
    for d in den {
        out.push('/');
        out.push_str(&d);
    }
    out
}

/// A column name split into its base name and its unit text: `GYRO_X[deg/s]`,
/// `w_RS_S_x [rad s^-1]`, `Rate (rad/s)`, `gyro_x_deg_s`, `output_mv`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ColumnName {
    /// The name without its unit, lower case, trimmed (a leading `#` or `%` removed).
    pub base: String,
    /// The unit as written (lower case): inside brackets, or the suffix after the base.
    pub unit: Option<String>,
    /// Whether the unit was written in brackets or parentheses (any text), rather than as a
    /// suffix (which is only taken when it is a known unit).
    pub bracketed: bool,
}

/// Two-part unit suffixes, tried before the last underscore.
const MULTI_PART_SUFFIXES: [&str; 7] = ["m_s2", "m_s_2", "mrad_s", "rad_s", "deg_s", "deg_h", "deg_c"];

/// Splits a column name into base and unit (see [`ColumnName`]). A suffix after the last
/// underscore counts as a unit only when it is one ([`OutputUnit::parse`], [`TimeUnit::parse`],
/// degC): `gyro_x` has no unit.
///
/// ```
/// use gyrolab::units::parse_column_name;
/// let c = parse_column_name("w_RS_S_x [rad s^-1]");
/// assert_eq!((c.base.as_str(), c.unit.as_deref()), ("w_rs_s_x", Some("rad s^-1")));
/// assert_eq!(parse_column_name("gyro_x_deg_s").unit.as_deref(), Some("deg_s"));
/// assert_eq!(parse_column_name("gyro_x").unit, None);
/// assert_eq!(parse_column_name("#timestamp [ns]").base, "timestamp");
/// ```
pub fn parse_column_name(name: &str) -> ColumnName {
    let lower = name.trim().trim_start_matches(['#', '%']).trim().to_lowercase();
    for (open, close) in [('[', ']'), ('(', ')'), ('{', '}')] {
        if lower.ends_with(close) {
            if let Some(i) = lower.rfind(open) {
                let unit = lower[i + 1..lower.len() - 1].trim().to_string();
                let base = lower[..i].trim().trim_end_matches(['_', '-', ' ']).to_string();
                if !base.is_empty() {
                    return ColumnName { base, unit: (!unit.is_empty()).then_some(unit), bracketed: true };
                }
            }
        }
    }
    let is_unit = |s: &str| OutputUnit::parse(s).is_some() || TimeUnit::parse(s).is_some() || is_celsius(s);
    for sfx in MULTI_PART_SUFFIXES {
        if let Some(base) = lower.strip_suffix(sfx).and_then(|b| b.strip_suffix('_')) {
            if !base.is_empty() {
                return ColumnName { base: base.to_string(), unit: Some(sfx.to_string()), bracketed: false };
            }
        }
    }
    if let Some(i) = lower.rfind('_') {
        if i > 0 && is_unit(&lower[i + 1..]) {
            return ColumnName {
                base: lower[..i].to_string(),
                unit: Some(lower[i + 1..].to_string()),
                bracketed: false,
            };
        }
    }
    ColumnName { base: lower, unit: None, bracketed: false }
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
    // Two-part suffixes first (rad_s, deg_s, m_s2, ...).
    for sfx in MULTI_PART_SUFFIXES {
        if let Some(base) = lower.strip_suffix(sfx).and_then(|b| b.strip_suffix('_')) {
            if !base.is_empty() {
                return (base.to_string(), Some(sfx.to_string()));
            }
        }
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
