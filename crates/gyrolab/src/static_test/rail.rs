//! Runs of identical samples at the record's min or max (stuck at a rail).

use super::accumulator::StaticTestAccumulator;
use super::config::FIRST_POSITIONS;
use super::result::{Position, RailRuns};

/// Candidate runs at the running min or max.
#[derive(Debug, Clone, Default)]
pub(super) struct RailTracker {
    pub(super) run_value: f64,
    pub(super) run_len: u64,
    pub(super) run_start: Option<Position>,
    pub(super) at_min: RailRuns,
    pub(super) at_max: RailRuns,
}

impl StaticTestAccumulator {
    /// One sample of the rail-run tracking: it continues the current run or ends it (the running
    /// min and max, as of this sample, decide whether the ending run is at a rail).
    #[inline]
    pub(super) fn rail_step(&mut self, v: f64, p: Position) {
        if self.rail.run_len > 0 && v == self.rail.run_value {
            self.rail.run_len += 1;
        } else {
            self.min = self.min.min(v);
            self.max = self.max.max(v);
            self.end_run();
            self.rail.run_value = v;
            self.rail.run_len = 1;
            self.rail.run_start = Some(p);
        }
    }

    pub(super) fn end_run(&mut self) {
        let r = &mut self.rail;
        if r.run_len >= self.config.rail_run_samples {
            let v = r.run_value;
            for (rails, at) in [(&mut r.at_min, v == self.min), (&mut r.at_max, v == self.max)] {
                if !at {
                    continue;
                }
                if rails.value != Some(v) {
                    *rails = RailRuns { value: Some(v), ..RailRuns::default() };
                }
                rails.runs += 1;
                rails.samples += r.run_len;
                if rails.first.len() < FIRST_POSITIONS {
                    if let Some(p) = r.run_start {
                        rails.first.push(p);
                    }
                }
            }
        }
        r.run_len = 0;
    }
}
