//! `gyrolab demo`: the paper's worked example from data built into the binary.

use crate::cmd::rate::{evaluate_record, EvaluatedAxis};
use crate::error::CliResult;
use crate::output::{print, to_json};
use crate::paper_data;
use clap::Args;
use gyrolab::rate_test::RateTestOptions;
use gyrolab_io::rate_table::{parse_rate_table, RateColumns};
use gyrolab_report::paper::{compare_table2, compare_table6, table2_text, table5_text, table6_text};
use gyrolab_report::rate::{rate_json, rate_summary_table, AxisReport};
use serde::Serialize;
use std::path::Path;

/// Options of `gyrolab demo`.
#[derive(Debug, Args)]
pub struct DemoArgs {
    /// Print the demo's figures and comparisons as JSON.
    #[arg(long)]
    pub json: bool,
}

#[derive(Serialize)]
struct DemoJson<'a> {
    rate: gyrolab_report::rate::RateJson,
    table2_x: Vec<gyrolab_report::paper::Table2Comparison>,
    table6: Vec<gyrolab_report::paper::ClaimVerdict>,
    #[serde(skip)]
    _p: std::marker::PhantomData<&'a ()>,
}

/// Runs `gyrolab demo`.
pub fn run(args: &DemoArgs) -> CliResult {
    let options = RateTestOptions::default();
    let mut axes: Vec<EvaluatedAxis> = Vec::new();
    for (axis, name, text) in paper_data::RATE_TABLES {
        let record = parse_rate_table(Path::new(name), text, &RateColumns::default())?;
        axes.push(evaluate_record(axis.into(), name.into(), record, &options)?);
    }
    let reports: Vec<AxisReport<'_>> = axes.iter().map(EvaluatedAxis::report).collect();
    let evals: Vec<(&str, &gyrolab::rate_test::RateEvaluation)> =
        axes.iter().map(|a| (a.name.as_str(), &a.evaluation)).collect();
    let t2 = paper_data::table2()?;
    let t5 = paper_data::table5()?;
    let t6 = paper_data::table6()?;
    let table2 = compare_table2(&t2, &axes[0].evaluation);
    let zero_bias: Vec<(&str, f64)> =
        t5.iter().map(|r| (r.axis.as_str(), gyrolab::fit::mean(&r.tests_v).unwrap_or(f64::NAN))).collect();
    let verdicts = compare_table6(&t6, &evals, &zero_bias);
    if args.json {
        return print(&to_json(&DemoJson {
            rate: rate_json(&reports),
            table2_x: table2,
            table6: verdicts,
            _p: std::marker::PhantomData,
        })?);
    }
    let mut s = String::new();
    s.push_str("gyrolab demo: the paper's worked example (Cheng et al. 2014, MEMS gyro of the ADXRS family,\n");
    s.push_str("three axes on a rate table, 14 rates, 4 runs of forward and reverse strokes). Data built in.\n\n");
    s.push_str("1. Table 2 (axis x): stroke means recomputed from Table 1 beside the printed values\n");
    s.push_str(&table2_text(&table2));
    let bad: Vec<String> = table2
        .iter()
        .filter(|r| !r.differs.is_empty())
        .map(|r| format!("{} ({} deg/s)", r.point, r.rate_dps))
        .collect();
    if bad.is_empty() {
        s.push_str("\nEvery row agrees with the printed values at their printed precision.\n");
    } else {
        s.push_str(&format!(
            "\nRows {} do not reproduce from Table 1: the printed value differs from the mean of the printed\n\
             Table 1 entries (a slip in the paper). gyrolab uses the means of Table 1.\n",
            bad.join(", ")
        ));
    }
    s.push_str("\n2. Table 5: zero-rate output of the four static tests per axis, means recomputed\n");
    let (t5_text, t5_ok) = table5_text(&t5);
    s.push_str(&t5_text);
    s.push_str(if t5_ok {
        "\nEvery printed mean agrees at its printed precision. (The raw static records were not published.)\n"
    } else {
        "\nSome printed means do not agree with the mean of the printed tests.\n"
    });
    s.push_str("\n3. Rate-table figures computed by gyrolab (definitions in docs/METHODS.md)\n");
    s.push_str(&rate_summary_table(&reports));
    s.push_str("\n\n4. Table 6: the paper's claims beside the figures computed from its own data\n");
    s.push_str(&table6_text(&verdicts, &t6, &evals));
    print(&s)
}
