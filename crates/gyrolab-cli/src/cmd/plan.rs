//! `gyrolab plan static`: how long a static record must be to measure bias instability (or
//! angle random walk) within plus or minus a precision at a confidence, before booking the table.

use crate::error::{CliError, CliResult};
use crate::output::{print, to_json};
use clap::{Args, Subcommand};
use gyrolab::plan::{bias_instability_tau_s, plan_static, PlanRequest, PlannedTerm};

/// What to plan.
#[derive(Debug, Subcommand)]
pub enum PlanCommand {
    /// A static (bias) record for an Allan-variance noise term.
    Static(StaticPlanArgs),
}

/// Options of `gyrolab plan static`.
#[derive(Debug, Args)]
pub struct StaticPlanArgs {
    /// Term to measure: bias-instability or arw.
    #[arg(long, default_value = "bias-instability", value_parser = parse_term)]
    pub term: PlannedTerm,
    /// Wanted precision: half-width of the interval, percent of the value.
    #[arg(long, value_name = "PCT")]
    pub precision_pct: f64,
    /// Two-sided confidence level.
    #[arg(long, default_value_t = 0.95, value_name = "C")]
    pub confidence: f64,
    /// Sample rate of the record, Hz.
    #[arg(long, value_name = "HZ")]
    pub sample_rate_hz: f64,
    /// Averaging time at which the term is read, s (default: 1 s for ARW; for bias instability
    /// derived from --arw-deg-rt-h and --bias-instability-dph).
    #[arg(long, value_name = "S")]
    pub tau_s: Option<f64>,
    /// Expected angle random walk, deg/sqrt(h) (datasheet), to place the bias-instability tau.
    #[arg(long, value_name = "N")]
    pub arw_deg_rt_h: Option<f64>,
    /// Expected bias instability, deg/h (datasheet), to place the bias-instability tau.
    #[arg(long, value_name = "B")]
    pub bias_instability_dph: Option<f64>,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
}

fn parse_term(s: &str) -> Result<PlannedTerm, String> {
    PlannedTerm::parse(s).ok_or_else(|| format!("unknown term '{s}': expected bias-instability or arw"))
}

/// Runs `gyrolab plan`.
pub fn run(cmd: &PlanCommand) -> CliResult {
    let PlanCommand::Static(a) = cmd;
    let tau_s = match (a.tau_s, a.term, a.arw_deg_rt_h, a.bias_instability_dph) {
        (Some(t), _, _, _) => t,
        (None, PlannedTerm::AngleRandomWalk, _, _) => 1.0,
        (None, PlannedTerm::BiasInstability, Some(n), Some(b)) if n > 0.0 && b > 0.0 => bias_instability_tau_s(n, b),
        (None, PlannedTerm::BiasInstability, _, _) => {
            return Err(CliError::Usage(
                "bias instability: give --tau-s, or --arw-deg-rt-h and --bias-instability-dph (positive) to place it"
                    .into(),
            ))
        }
    };
    let req = PlanRequest {
        term: a.term,
        relative_precision: a.precision_pct / 100.0,
        confidence: a.confidence,
        sample_rate_hz: a.sample_rate_hz,
        tau_s,
    };
    let plan = plan_static(&req).map_err(|e| CliError::Usage(format!("cannot plan: {e}")))?;
    if a.json {
        return print(&to_json(&plan)?);
    }
    let term = match a.term {
        PlannedTerm::BiasInstability => "bias instability (flicker rate noise, alpha = -1)",
        PlannedTerm::AngleRandomWalk => "angle random walk (white rate noise, alpha = 0)",
    };
    print(&format!(
        "To measure {term} from the overlapping Allan deviation at tau = {:.4} s (m = {}, {} Hz)\n\
         within +-{} % at {} % confidence, record at least {} samples: {:.0} s = {:.2} h.\n\
         Such a record gives {:.1} equivalent degrees of freedom and an interval of {:.3} to {:.3} times the value.\n\
         (EDF by Greenhall & Riley 2004; chi-squared bounds, NIST SP 1065 section 5.3.)\n",
        plan.request.tau_s,
        plan.m,
        plan.request.sample_rate_hz,
        a.precision_pct,
        100.0 * a.confidence,
        plan.samples,
        plan.duration_s,
        plan.duration_h,
        plan.required_edf,
        plan.relative_interval.0,
        plan.relative_interval.1
    ))
}
