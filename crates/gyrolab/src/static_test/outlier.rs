//! The second pass: outliers about the first pass's drift line, and the report when the pass
//! can be skipped.

use super::accumulator::{OutlierRule, StaticTestAccumulator};
use super::config::*;
use super::result::*;

/// Second pass over the same record: finds outliers by the rule |x - drift line| > k sigma
/// (sigma the residual std about the first pass's drift line) and, with `drop_outliers`,
/// recomputes every figure without them.
#[derive(Debug, Clone)]
pub struct OutlierScan {
    inner: StaticTestAccumulator,
    line: DriftLine,
}

impl OutlierScan {
    /// Prepares the second pass from the first pass's result.
    pub fn new(first: &FirstPass, config: &StaticTestConfig) -> Result<Self, StaticTestError> {
        let first = &first.result;
        let mut cfg = config.clone();
        // The second pass reuses the rate the first pass used, so windows line up.
        cfg.sample_rate_hz = Some(first.sample_rate_hz);
        let mut inner = StaticTestAccumulator::new(cfg)?;
        inner.fs_given = config.sample_rate_hz.is_some();
        let line = first.drift_line.unwrap_or(DriftLine {
            t0_s: 0.0,
            output_at_t0: first.mean_output,
            slope_output_per_s: 0.0,
            residual_std_output: first.std_output,
        });
        // A record that lies exactly on its drift line has sigma 0: no sample is an outlier by this rule.
        if line.residual_std_output > 0.0 {
            inner.rule = Some(OutlierRule { line, limit: config.outlier_k_sigma * line.residual_std_output });
        }
        Ok(OutlierScan { inner, line })
    }

    /// Adds a block of the same record, in the same order as the first pass.
    pub fn push(&mut self, block: &SampleBlock) -> Result<(), StaticTestError> {
        self.inner.push(block)
    }

    /// The final result: the first pass's figures with the outlier report, or, with
    /// `drop_outliers`, the figures recomputed without the outliers.
    pub fn finish(mut self, first: FirstPass) -> Result<StaticTestResult, StaticTestError> {
        let drop = self.inner.config.drop_outliers;
        let report = OutlierReport {
            k_sigma: self.inner.config.outlier_k_sigma,
            residual_std_output: self.line.residual_std_output,
            outliers: std::mem::take(&mut self.inner.outliers),
            dropped: drop,
        };
        let mut out = if drop && report.outliers.count > 0 { self.inner.finish()?.result } else { first.result };
        out.quality.outliers = Some(report);
        Ok(out)
    }
}

impl FirstPass {
    /// The result of an outlier pass that found nothing, for a first pass whose extremes prove
    /// that none exists (`outlier_scan_needed` is false): the same report the pass would give.
    pub fn with_no_outliers(self, config: &StaticTestConfig) -> StaticTestResult {
        let mut out = self.result;
        let sigma = out.drift_line.map_or(out.std_output, |l| l.residual_std_output);
        out.quality.outliers = Some(OutlierReport {
            k_sigma: config.outlier_k_sigma,
            residual_std_output: sigma,
            outliers: QualityIssue::default(),
            dropped: config.drop_outliers,
        });
        out
    }
}
