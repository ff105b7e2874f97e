//! SIMULATED records with known truth for the tests of a lab's test program (issue 19): each
//! module writes one test's records and returns the plan tables that evaluate them, for the
//! tests, the example plan with every test and `gyrolab demo --out`.

pub mod g_sensitivity;
pub mod power_ups;
pub mod temperature;
pub mod threshold;
pub mod uncertainty;
