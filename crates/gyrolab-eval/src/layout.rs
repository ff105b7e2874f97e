//! How a log file is laid out, as the user describes it: units for columns (`gx=rad/s`) or for
//! every column without one (`rad/s`, `m/s^2`), the time column and its unit, the names of a
//! file without a header row. The one place where these requests become reader options, for
//! every front end (CLI `--unit`, `--time-column`, `--names`; plan keys; Python arguments).

use crate::error::EvalResult;
use gyrolab::units::{OutputUnit, TimeUnit};
use gyrolab::validate::InvalidOption;
use gyrolab_io::series::SeriesOptions;

/// The layout of a log file, as requested.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LogLayout {
    /// Units: `COLUMN=UNIT` for one column (a time unit s, ms, us, ns for the time column), or
    /// `UNIT` for every output column without one (one per quantity: an angular-rate or output
    /// unit, and an acceleration unit for columns named as accelerometers).
    pub units: Vec<String>,
    /// The time column (default: the first column named as a time).
    pub time_column: Option<String>,
    /// Column names of a file without a header row (default `c1..cN`).
    pub names: Vec<String>,
}

impl LogLayout {
    /// Applies the layout to reader options (field `units`, `time_column`, `names` in errors).
    ///
    /// ```
    /// use gyrolab_eval::layout::LogLayout;
    /// use gyrolab::units::{OutputUnit, TimeUnit};
    /// let l = LogLayout { units: vec!["gx=rad/s".into(), "m/s^2".into(), "stamp=ns".into()], ..Default::default() };
    /// let o = l.apply(Default::default())?;
    /// assert_eq!(o.column_units, vec![("gx".to_string(), OutputUnit::RadPerSec)]);
    /// assert_eq!(o.default_units, vec![OutputUnit::MeterPerSec2]);
    /// assert_eq!((o.time_column.as_deref(), o.time_unit), (Some("stamp"), Some(TimeUnit::Nanosecond)));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn apply(&self, mut options: SeriesOptions) -> EvalResult<SeriesOptions> {
        let accepted = || {
            format!(
                "expected COLUMN=UNIT or UNIT, with UNIT one of {} (or deg/s, rad/s, m/s^2 ...), or s, ms, us, ns for the time column",
                OutputUnit::accepted_channel_suffixes()
            )
        };
        for u in &self.units {
            let bad = |what: String| InvalidOption::new("units", format!("'{u}': {what}; {}", accepted()));
            match u.split_once('=') {
                Some((col, unit)) => {
                    let col = col.trim();
                    if col.is_empty() {
                        return Err(bad("no column name before '='".into()).into());
                    }
                    if let Some(t) = TimeUnit::parse(unit) {
                        if options.time_column.as_deref().is_some_and(|c| !c.eq_ignore_ascii_case(col)) {
                            return Err(bad("a time unit for a second time column".into()).into());
                        }
                        options.time_column = Some(col.to_string());
                        options.time_unit = Some(t);
                    } else if let Some(o) = OutputUnit::parse(unit) {
                        options.column_units.push((col.to_string(), o));
                    } else {
                        return Err(bad(format!("unknown unit '{}'", unit.trim())).into());
                    }
                }
                None => {
                    let Some(o) = OutputUnit::parse(u) else {
                        return Err(bad("unknown unit".into()).into());
                    };
                    let accel = |x: &OutputUnit| x.per_m_s2().is_some();
                    if options.default_units.iter().any(|d| accel(d) == accel(&o)) {
                        return Err(bad(format!(
                            "a second default {} unit",
                            if accel(&o) { "acceleration" } else { "rate or output" }
                        ))
                        .into());
                    }
                    options.default_units.push(o);
                }
            }
        }
        if let Some(t) = &self.time_column {
            if options.time_column.as_deref().is_some_and(|c| !c.eq_ignore_ascii_case(t)) {
                return Err(InvalidOption::new(
                    "time_column",
                    format!(
                        "'{t}' and a time unit for column '{}': name one time column",
                        options.time_column.unwrap_or_default()
                    ),
                )
                .into());
            }
            options.time_column = Some(t.clone());
        }
        if !self.names.is_empty() {
            options.names = Some(self.names.clone());
        }
        Ok(options)
    }
}
