//! Raw-log test files: the log itself comes from the simulator (`gyrolab::sim::simulate_raw_log`,
//! with the truth of every hold); this writes it as a CSV file the way a rate table's logger does.
#![allow(dead_code)]

use gyrolab::sim::SimulatedRawLog;

/// The log as CSV: `time_s,table_rate_dps,<names...>` with one output column per entry.
pub fn csv(sim: &SimulatedRawLog, names: &[&str], outputs: &[Vec<f64>]) -> String {
    let mut s = format!("# simulated raw log\ntime_s,table_rate_dps,{}\n", names.join(","));
    for i in 0..sim.time.len() {
        s.push_str(&format!("{:.3},{:.6}", sim.time[i], sim.logged_rate[i]));
        for o in outputs {
            s.push_str(&format!(",{:.8}", o[i]));
        }
        s.push('\n');
    }
    s
}
