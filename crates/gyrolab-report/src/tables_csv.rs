//! The CSV tables of a report folder: per-point means of each rate-table axis, per-run scale
//! factors, and the summary of every figure with its unit, limit and verdict.

use crate::html::SummaryTable;
use crate::rate::AxisJson;
use crate::table::csv_field;
use gyrolab::figures::AxisFigures;
use gyrolab::limits::Limit;

fn opt(v: Option<f64>) -> String {
    v.map_or_else(String::new, |x| x.to_string())
}

/// The per-point CSV of one axis (Table 2 with residuals).
pub fn points_csv(a: &AxisJson) -> String {
    let u = &a.output_unit;
    let mut s = format!(
        "# gyrolab: axis {} rate-table points; output-valued columns in {u}\n\
         rate_dps,fwd_mean,rev_mean,mean,fwd_std,rev_std,line_output,line_residual,nonlinearity_pct,polynomial_residual\n",
        a.name
    );
    for p in &a.points {
        s.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{}\n",
            p.rate_dps,
            p.fwd_mean,
            p.rev_mean,
            p.mean,
            opt(p.fwd_std),
            opt(p.rev_std),
            p.line_output,
            p.line_residual,
            p.nonlinearity_pct,
            p.polynomial_residual
        ));
    }
    s
}

/// The per-run scale factors of every axis.
pub fn runs_csv(axes: &[AxisJson]) -> String {
    let mut s = String::from(
        "# gyrolab: scale factor K of each run (both strokes), output units per deg/s\naxis,run,scale_factor,unit\n",
    );
    for a in axes {
        for r in &a.scale_factor_per_run {
            s.push_str(&format!(
                "{},{},{},{}\n",
                csv_field(&a.name),
                r.run,
                r.scale_factor,
                csv_field(&a.scale_factor_unit)
            ));
        }
    }
    s
}

/// The summary CSV: every figure of every axis with its unit, what the value is (`basis`:
/// `value`, `upper_bound` or `lower_bound`), its limit, decision rule and verdict, and whether it
/// comes from SIMULATED records (`simulated`: `SIMULATED` or empty). docs/PLAN.md.
pub fn summary_csv(summary: &SummaryTable, figures: &[AxisFigures], limits: &[Limit]) -> String {
    let mut s = String::from("axis,figure,unit,value,basis,limit_min,limit_max,rule,verdict,simulated\n");
    for a in figures {
        for row in &summary.rows {
            let l = limits.iter().find(|l| l.figure == row.key);
            let verdict = summary
                .checks
                .iter()
                .find(|c| c.axis == a.axis && c.figure == row.key)
                .map_or("", |c| c.verdict.text());
            let known = a.known(&row.key);
            s.push_str(&format!(
                "{},{},{},{},{},{},{},{},{},{}\n",
                csv_field(&a.axis),
                row.key,
                csv_field(&a.unit_of(&row.key)),
                opt(known.map(|k| k.value)),
                known.map_or("", |k| k.support.key()),
                opt(l.and_then(|l| l.min)),
                opt(l.and_then(|l| l.max)),
                l.map_or("", |l| l.rule.key()),
                verdict,
                if a.simulated.contains(&row.key) { "SIMULATED" } else { "" }
            ));
        }
    }
    s
}
