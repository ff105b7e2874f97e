//! `gyrolab plan static` (the record-length planner): how long a static record must be to measure bias instability (or
//! angle random walk) within plus or minus a precision at a confidence, before booking the table.

use crate::error::CliResult;
use crate::output::{print, to_json};
use clap::{Args, Subcommand};
use gyrolab::record_length::NoiseTerm;
use gyrolab_eval::record_length::{plan_record_length, RecordLengthQuery};

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
    pub term: NoiseTerm,
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

fn parse_term(s: &str) -> Result<NoiseTerm, String> {
    NoiseTerm::parse(s).ok_or_else(|| format!("unknown term '{s}': expected bias-instability or arw"))
}

/// Runs `gyrolab plan`.
pub fn run(cmd: &PlanCommand) -> CliResult {
    let PlanCommand::Static(a) = cmd;
    let plan = plan_record_length(&RecordLengthQuery {
        term: a.term,
        precision_pct: a.precision_pct,
        confidence: a.confidence,
        sample_rate_hz: a.sample_rate_hz,
        tau_s: a.tau_s,
        arw_deg_rt_h: a.arw_deg_rt_h,
        bias_instability_dph: a.bias_instability_dph,
    })?;
    if a.json {
        return print(&to_json(&plan)?);
    }
    print(&gyrolab_report::allan::record_length_text(&plan, a.precision_pct, a.confidence))
}
