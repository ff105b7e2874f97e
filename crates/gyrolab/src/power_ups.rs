//! Repeatability across power-ups: the spread of one figure (scale factor K_i, bias B0_i) over
//! records taken at separate power-ups under the same conditions.
//!
//! Sources: GJB 2426A-2004 (零偏重复性, bias repeatability, and 标度因数重复性, scale-factor
//! repeatability, between power-ups: the standard deviation (n - 1) of the per-power-up values,
//! relative to their mean for the scale factor); IEEE Std 952-1997 and IEEE Std 1431-2004
//! ("turn-on to turn-on" bias and scale-factor repeatability). docs/METHODS.md, "Repeatability
//! across power-ups".
//!
//! With n values: mean m = sum x_i / n, s = sqrt(sum (x_i - m)^2 / (n - 1)), deviations
//! x_i - m; the relative spread s / |m| in ppm (scale factor). Two values give a value that is
//! flagged (`few`): a standard deviation from fewer than three power-ups has fewer than two
//! degrees of freedom.

use crate::units;

/// Fewest power-ups for a value.
pub const MIN_POWER_UPS: usize = 2;
/// Fewest power-ups for a value that is not flagged.
pub const SUPPORTED_POWER_UPS: usize = 3;

/// The spread of one figure across power-ups.
#[derive(Debug, Clone, PartialEq)]
pub struct PowerUpSpread {
    /// Number of power-ups n.
    pub n: usize,
    /// Mean of the values.
    pub mean: f64,
    /// Standard deviation (n - 1) of the values.
    pub std: f64,
    /// Each value's deviation from the mean, in input order.
    pub deviations: Vec<f64>,
    /// Fewer than [`SUPPORTED_POWER_UPS`] power-ups: the value has little support.
    pub few: bool,
}

impl PowerUpSpread {
    /// The relative spread std / |mean| in ppm; `None` when the mean is 0.
    pub fn relative_ppm(&self) -> Option<f64> {
        (self.mean != 0.0).then(|| units::ratio_to_ppm(self.std / self.mean.abs()))
    }
}

/// Why there is no spread.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SpreadError {
    /// Fewer than [`MIN_POWER_UPS`] values.
    #[error("{n} power-up(s): a repeatability across power-ups needs at least {MIN_POWER_UPS}")]
    TooFew {
        /// How many there were.
        n: usize,
    },
    /// A value is not finite.
    #[error("the value of power-up {index} is not a finite number")]
    NonFinite {
        /// Its index (0-based).
        index: usize,
    },
}

/// Mean, standard deviation (n - 1) and deviations of per-power-up values.
pub fn spread(values: &[f64]) -> Result<PowerUpSpread, SpreadError> {
    if let Some(index) = values.iter().position(|v| !v.is_finite()) {
        return Err(SpreadError::NonFinite { index });
    }
    let n = values.len();
    if n < MIN_POWER_UPS {
        return Err(SpreadError::TooFew { n });
    }
    let mean = values.iter().sum::<f64>() / n as f64;
    let deviations: Vec<f64> = values.iter().map(|v| v - mean).collect();
    let std = (deviations.iter().map(|d| d * d).sum::<f64>() / (n - 1) as f64).sqrt();
    Ok(PowerUpSpread { n, mean, std, deviations, few: n < SUPPORTED_POWER_UPS })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hand_worked_spread() {
        // 0.0075, 0.0076, 0.0077: mean 0.0076, deviations -1e-4, 0, 1e-4, s = sqrt(2e-8 / 2) = 1e-4,
        // s / m = 1e-4 / 0.0076 = 13157.89 ppm.
        let s = spread(&[0.0075, 0.0076, 0.0077]).unwrap();
        assert_eq!(s.n, 3);
        assert!((s.mean - 0.0076).abs() < 1e-15);
        assert!((s.std - 1e-4).abs() < 1e-15);
        assert!((s.relative_ppm().unwrap() - 1e6 / 76.0).abs() < 1e-6);
        assert!(!s.few);
        assert!((s.deviations[0] + 1e-4).abs() < 1e-15);
    }

    #[test]
    fn two_are_flagged_one_is_refused() {
        // 10 and 14 deg/h: s = |14 - 10| / sqrt(2).
        let s = spread(&[10.0, 14.0]).unwrap();
        assert!(s.few && (s.std - 4.0 / 2f64.sqrt()).abs() < 1e-12);
        assert_eq!(spread(&[1.0]), Err(SpreadError::TooFew { n: 1 }));
        assert_eq!(spread(&[1.0, f64::NAN]), Err(SpreadError::NonFinite { index: 1 }));
        assert_eq!(spread(&[0.0, 0.0]).unwrap().relative_ppm(), None);
    }
}
