//! `gyrolab demo`: the paper's worked example from data built into the binary.

use crate::error::CliResult;
use crate::folder::write_and_finish;
use crate::output::{print, to_json};
use crate::progress::Bar;
use clap::Args;
use gyrolab_eval::outcome::rate::AxisReport;
use gyrolab_eval::rate::EvaluatedAxis;
use gyrolab_lab::demo::{evaluate_paper, paper_report_folder, PaperReportRequest};
use gyrolab_report::paper::{demo_text, DemoJson};
use gyrolab_report::rate::{rate_json, rate_summary_table};
use std::path::PathBuf;

/// Options of `gyrolab demo`.
#[derive(Debug, Args)]
pub struct DemoArgs {
    /// Print the demo's figures and comparisons as JSON.
    #[arg(long)]
    pub json: bool,
    /// Write the paper's report folder (report.html, results.json, calibration.toml, CSV) here.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// With --out: no progress bar and no summary on standard output.
    #[arg(long, short, requires = "out")]
    pub quiet: bool,
    /// With --out: length of each simulated static test, s (4 per axis, 100 Hz).
    #[arg(long, value_name = "S", default_value_t = 1200.0, requires = "out")]
    pub sim_static_s: f64,
    /// With --out: length of the simulated record of each axis's Allan section, s (100 Hz);
    /// shorter records run faster but end the Allan curve at a quarter of their length.
    #[arg(long, value_name = "S", default_value_t = 7200.0, requires = "out")]
    pub sim_allan_s: f64,
    /// With --out: also print report.html to report.pdf with headless Chromium (/usr/bin/chromium, or
    /// chromium, chromium-browser or google-chrome on PATH, or the path in GYROLAB_CHROMIUM; at
    /// most 120 s). Without a browser, or when printing fails, the other files are still written
    /// and the exit code is 1 with a message saying how to get the PDF.
    #[arg(long, requires = "out")]
    pub pdf: bool,
}

/// Runs `gyrolab demo`.
pub fn run(args: &DemoArgs) -> CliResult {
    if let Some(out) = &args.out {
        let bar = Bar::new(args.quiet);
        let request = PaperReportRequest { sim_static_s: args.sim_static_s, sim_allan_s: args.sim_allan_s };
        let folder = paper_report_folder(&request, &bar);
        bar.finish();
        return write_and_finish(out, &folder?, args.quiet, args.pdf);
    }
    let demo = evaluate_paper()?;
    let reports: Vec<AxisReport<'_>> = demo.axes.iter().map(EvaluatedAxis::report).collect();
    if args.json {
        return print(&to_json(&DemoJson {
            rate: rate_json(&reports),
            table2_x: demo.table2.clone(),
            table6: demo.table6.clone(),
        })?);
    }
    print(&demo_text(
        &demo.table2,
        &demo.table5,
        &rate_summary_table(&reports),
        &demo.table6,
        &demo.table6_claims,
        &demo.evaluations(),
    ))
}
