//! Planning a static record: how long it must be to measure a noise term from the overlapping
//! Allan deviation to a stated precision ([`gyrolab::record_length`]: Greenhall & Riley EDF,
//! NIST SP 1065 chi-squared bounds).

use crate::error::{EvalError, EvalResult};
use gyrolab::record_length::{
    bias_instability_tau_s, static_record_length, NoiseTerm, RecordLength, RecordLengthRequest,
};

/// What to plan for, as a front end gives it.
///
/// ```
/// use gyrolab_eval::record_length::{plan_record_length, RecordLengthQuery};
/// use gyrolab::record_length::NoiseTerm;
/// let q = RecordLengthQuery {
///     term: NoiseTerm::AngleRandomWalk,
///     precision_pct: 10.0,
///     confidence: 0.95,
///     sample_rate_hz: 100.0,
///     tau_s: None,
///     arw_deg_rt_h: None,
///     bias_instability_dph: None,
/// };
/// let plan = plan_record_length(&q)?;
/// assert!(plan.samples > 100 && plan.request.tau_s == 1.0);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct RecordLengthQuery {
    /// The noise term.
    pub term: NoiseTerm,
    /// Wanted precision: half-width of the interval, percent of the value.
    pub precision_pct: f64,
    /// Two-sided confidence level.
    pub confidence: f64,
    /// Sample rate of the record, Hz.
    pub sample_rate_hz: f64,
    /// Averaging time of the reading, s (default: 1 s for ARW; for bias instability placed from
    /// the expected N and B).
    pub tau_s: Option<f64>,
    /// Expected angle random walk, deg/sqrt(h).
    pub arw_deg_rt_h: Option<f64>,
    /// Expected bias instability, deg/h.
    pub bias_instability_dph: Option<f64>,
}

/// The record length the query needs.
pub fn plan_record_length(q: &RecordLengthQuery) -> EvalResult<RecordLength> {
    let tau_s =
        match (q.tau_s, q.term, q.arw_deg_rt_h, q.bias_instability_dph) {
            (Some(t), _, _, _) => t,
            (None, NoiseTerm::AngleRandomWalk, _, _) => 1.0,
            (None, NoiseTerm::BiasInstability, Some(n), Some(b)) if n > 0.0 && b > 0.0 => bias_instability_tau_s(n, b),
            (None, NoiseTerm::BiasInstability, _, _) => return Err(EvalError::conflict_on(
                &["tau_s", "arw_deg_rt_h", "bias_instability_dph"],
                "bias instability: give {tau_s}, or {arw_deg_rt_h} and {bias_instability_dph} (positive) to place it",
            )),
        };
    let req = RecordLengthRequest {
        term: q.term,
        relative_precision: q.precision_pct / 100.0,
        confidence: q.confidence,
        sample_rate_hz: q.sample_rate_hz,
        tau_s,
    };
    static_record_length(&req).map_err(|e| EvalError::conflict(format!("cannot plan: {e}")))
}
