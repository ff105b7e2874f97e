//! gyrolab core: the numerics and domain types of gyroscope test evaluation.
//!
//! This crate does no file, terminal or network I/O, so that it can be bound to other languages.
//! One module per concern:
//! - [`units`]: units of rates, outputs and noise coefficients, and every conversion;
//! - [`allan`]: the Allan-variance family with noise identification and confidence intervals;
//! - [`fit`]: least-squares lines and polynomials;
//! - [`g_sensitivity`]: g-sensitivity (acceleration-sensitive bias) from records in several orientations;
//! - [`gmwm`]: GMWM (wavelet-variance) estimation of composite noise models, and overbounding;
//! - [`noise`]: IEEE 952 noise terms (ARW, bias instability, RRW, ...) from an Allan curve;
//! - [`rate_test`]: rate-table (scale-factor) test figures;
//! - [`static_test`]: static (bias) test figures, accumulated block by block;
//! - [`record_length`]: test planning: record length for a noise term's precision;
//! - [`record_temperature`]: a static record's temperature: mean, range, drift, moved or not;
//! - [`published`]: comparison with figures printed in a publication;
//! - [`sim`]: gyro simulator with known truth (static records, rate-table tests);
//! - [`segment`]: plateaus, strokes and runs found in raw rate-table logs;
//! - [`sign_off`]: the facts of an issued report's sign-off (signer, meaning, key, amendment);
//! - [`triad`]: three-axis scale-factor, misalignment and bias calibration (12 parameters);
//! - [`apply`]: calibrations applied to output samples (output to rate);
//! - [`figures`]: the catalogue of reportable figures (limit names, units, formulas, sources) and
//!   the figures of an axis;
//! - [`limits`]: spec limits checked against the figures (PASS, FAIL, NOT EVALUATED);
//! - [`format`](mod@format): numbers to significant digits and to their uncertainty's digits;
//! - [`conformity`]: decision rules, guard bands, verdicts and rounding that never contradicts them;
//! - [`sampling`]: the sampling interval of a record from its time stamps (one estimator);
//! - [`validate`]: validators of option values (errors name the request field);
//! - [`thermal`]: temperature tests at soaked points: K(T), bias(T), sensitivities, compensation;
//! - [`threshold`]: threshold and resolution from small-rate plateaus and rate steps;
//! - [`stillness`]: whether a gyro or accelerometer channel moved during its record;
//! - [`window_means`]: streaming means of consecutive windows (bias time series).
//!
//! Formulas and their sources are listed in `docs/METHODS.md`.

#![deny(missing_docs)]

pub mod allan;
pub mod apply;
pub mod conformity;
pub mod control_chart;
pub mod dropout;
pub mod figures;
pub mod fit;
pub mod format;
pub mod g_sensitivity;
pub mod gmwm;
pub mod limits;
pub mod noise;
pub mod power_ups;
pub mod process_capability;
pub mod published;
pub mod rate_test;
pub mod record_length;
pub mod record_temperature;
pub mod sampling;
pub mod segment;
pub mod sign_off;
pub mod sim;
pub mod static_test;
pub mod stillness;
pub mod thermal;
pub mod threshold;
pub mod triad;
pub mod two_sample;
pub mod uncertainty;
pub mod units;
pub mod validate;
pub mod warmup;
pub mod window_means;
