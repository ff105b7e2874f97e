//! Gyro simulator with known truth: static records and rate-table tests from a stated error model.
//!
//! Sources: IEEE Std 952-1997 annex C (angle random walk N, bias instability B, rate random walk
//! K, rate ramp R, quantization, and the Allan variance of a first-order Gauss-Markov process);
//! Brown & Hwang, *Introduction to Random Signals and Applied Kalman Filtering* (Gauss-Markov
//! processes and their exact discretisation); the project's methods notes sections 1, 2 and 5
//! (test structure, indicator definitions, realistic parameters). `docs/METHODS.md` (section 4) gives the
//! model equation and every formula.
//!
//! Model, per sample k at time t (sensed rate w in deg/s, output F in the output unit):
//!   w = Omega_table + Omega_e sin(lat) + (+-h/2) + b0 + b_run + c_b (T - T_ref) + R t
//!       + n_white + sum_i x_i + b_rrw                     (then optional angle quantization)
//!   (static records in an orientation: + G · f, and u Omega_e sin(lat) with u the input axis's
//!   up component; `g_sensitivity_dph_per_g`, `StaticSpec::specific_force_g`, `input_axis_up`)
//!   F = clamp(null + K (1 + e_sf + e_run + c_k (T - T_ref)) (1 +- a/2) (w + k2 w^2 + k3 w^3),
//!             rail_low, rail_high)                        (then optional output quantization)
//!
//! Determinism and portability: one seed gives the same samples on every run and platform.
//! Random numbers come from ChaCha8 (`rand_chacha`, a fixed, endian-independent algorithm), seeded
//! by `seed_from_u64`, stream 0 for per-sample noise and stream 1 for run-to-run draws. Gaussian
//! draws are `rand_distr`'s `StandardNormal` (the core of its `Normal`): a ziggurat whose tables
//! are compiled-in constants, so a returned value is the product of a uniform and a table entry in
//! all but the tail case (per-sample draws are made in bulk by `normal`, value for value the same). Remaining risk: the ziggurat's wedge test calls `exp` (a last-bit
//! difference could flip an accept/reject decision only when the uniform falls within about one
//! ulp of the density, probability ~1e-16 per wedge draw) and its tail (|z| > 3.65, about 3 in
//! 10 000 draws) computes the value with `ln`, so a platform whose libm `ln` differs in the last
//! bit could change those values in the last bit. The value stream is also tied to the `rand` 0.8
//! / `rand_distr` 0.4 / `rand_chacha` 0.3 versions pinned in Cargo.lock. Everything else on the
//! sample path uses + - * / sqrt floor round only; set-up values that need `exp` (Gauss-Markov
//! coefficients) or `sin` (earth rate at a latitude) use the portable versions in `portable`.

mod flicker;
mod generate;
mod model;
mod normal;
mod portable;
mod raw_log;
#[cfg(test)]
mod tests;

pub use flicker::{FlickerDesign, FLICKER_ADEV_FACTOR, FLICKER_BAND, FLICKER_MIN_TAU_SAMPLES};
pub use generate::{
    collect_rate_test, RateTableGenerator, RateTableSample, SimStroke, SimulatedRateTest, StaticBlock, StaticGenerator,
    StaticSample,
};
pub use model::{
    ParameterText, Preset, RateTableSpec, SensorModel, SensorOverrides, SettlingRows, SimConfig, SimError, StaticSpec,
    TemperatureProfile, TemperatureStep, PAPER_RATES_DPS,
};
pub use raw_log::{
    gyro_output, raw_log_setpoints, simulate_raw_log, white_noise, RawLogHold, RawLogProfile, SimulatedRawLog,
};
