//! Prints chi-squared quantiles for the grid that `scripts/check_chi2_scipy.py` compares with
//! scipy's `chi2.ppf`: one line `p dof quantile` per point, values in shortest round-trip form.
//!
//! Usage: `cargo run -p gyrolab --example chi2_quantiles` (or the built binary
//! `target/debug/examples/chi2_quantiles`).

use gyrolab::allan::chi_squared_quantile;

const PS: [f64; 7] = [0.0005, 0.025, 0.1587, 0.5, 0.8413, 0.975, 0.9995];
const DOFS: [f64; 12] = [1.0, 2.0, 3.7, 10.0, 100.0, 1e3, 1e4, 2.709e5, 1e6, 1e7, 1e8, 1e9];

fn main() {
    for &dof in &DOFS {
        for &p in &PS {
            match chi_squared_quantile(p, dof) {
                Some(q) => println!("{p:?} {dof:?} {q:?}"),
                None => println!("{p:?} {dof:?} nan"),
            }
        }
    }
}
