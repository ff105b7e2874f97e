//! gyrolab core: the numerics and domain types of gyroscope test evaluation.
//!
//! This crate does no file, terminal or network I/O, so that it can be bound to other languages.
//! One module per concern:
//! - [`units`]: units of rates, outputs and noise coefficients, and every conversion;
//! - [`allan`]: the Allan-variance family with noise identification and confidence intervals;
//! - [`fit`]: least-squares lines and polynomials;
//! - [`noise`]: IEEE 952 noise terms (ARW, bias instability, RRW, ...) from an Allan curve;
//! - [`rate_test`]: rate-table (scale-factor) test figures;
//! - [`published`]: comparison with figures printed in a publication.
//!
//! Formulas and their sources are listed in `docs/METHODS.md`.

pub mod allan;
pub mod fit;
pub mod noise;
pub mod published;
pub mod rate_test;
pub mod units;
