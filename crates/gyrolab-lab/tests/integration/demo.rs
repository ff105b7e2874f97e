//! The paper's worked example: Table 2 as printed against the stroke means computed here from
//! the paper's Table 1 (`data/paper/paper_rate_table_x.csv`), and axis x's K against the LSQ
//! slope computed here.

use crate::common;
use common::{lsq_line, paper_file, rate_means, read_long};
use gyrolab_lab::demo::evaluate_paper;

/// The number of decimals of a printed number.
fn decimals(s: &str) -> i32 {
    s.split_once('.').map_or(0, |(_, d)| d.len() as i32)
}

/// Table 2 rows 11 and 14 do not reproduce from Table 1 and every other row does, both by the
/// demo's comparison and by the test's own: the forward, reverse and overall means computed
/// here from the CSV text, rounded to the printed number of decimals (half a unit in the last
/// printed place, plus 1e-12 for the binary representation), against the printed text of
/// `paper_table2_means_x.csv`.
#[test]
fn table2_rows_11_and_14_disagree_and_all_others_agree() {
    let demo = evaluate_paper().unwrap();
    let slips: Vec<usize> = demo.table2.iter().filter(|r| !r.differs.is_empty()).map(|r| r.point).collect();
    assert_eq!(slips, [11, 14]);
    assert_eq!(demo.table2.len(), 14);

    let m = rate_means(&read_long(&paper_file("paper_rate_table_x.csv")));
    let text = std::fs::read_to_string(paper_file("paper_table2_means_x.csv")).unwrap();
    let mut rows = text.lines().filter(|l| !l.starts_with('#'));
    assert_eq!(rows.next().unwrap(), "point,rate_dps,fwd_mean_v,rev_mean_v,mean_v");
    let mut disagree = Vec::new();
    let mut count = 0;
    for line in rows.filter(|l| !l.trim().is_empty()) {
        let c: Vec<&str> = line.split(',').collect();
        let point: usize = c[0].parse().unwrap();
        let rate: f64 = c[1].parse().unwrap();
        let j = m.rates.iter().position(|r| (r - rate).abs() < 1e-9).unwrap();
        let computed = [m.forward[j], m.reverse[j], m.mean[j]];
        let mut differs = false;
        for (k, printed) in c[2..5].iter().enumerate() {
            let p: f64 = printed.parse().unwrap();
            let half_ulp = 0.5 * 10f64.powi(-decimals(printed));
            if (computed[k] - p).abs() > half_ulp + 1e-12 {
                differs = true;
            }
        }
        if differs {
            disagree.push(point);
        }
        // The demo's computed means are the same stroke means.
        let row = demo.table2.iter().find(|r| r.point == point).unwrap();
        for (k, (got, want)) in row.computed_v.iter().zip(&computed).enumerate() {
            assert!((got - want).abs() < 1e-12, "point {point} column {k}");
        }
        count += 1;
    }
    assert_eq!(count, 14);
    assert_eq!(disagree, [11, 14], "independent comparison of Table 2 with Table 1");
}

/// K of axis x equals the LSQ slope through the per-rate means of the paper's Table 1,
/// computed here (1e-10 relative: only the order of operations differs).
#[test]
fn axis_x_scale_factor_is_the_independent_lsq_slope() {
    let demo = evaluate_paper().unwrap();
    let x = demo.axes.iter().find(|a| a.name == "x").unwrap();
    let m = rate_means(&read_long(&paper_file("paper_rate_table_x.csv")));
    let (k, _) = lsq_line(&m.rates, &m.mean);
    let got = x.evaluation.scale_factor();
    assert!((got - k).abs() <= 1e-10 * k.abs(), "K = {got}, LSQ {k}");
}

/// `gyrolab demo --out`: beside the paper's report, the whole test program of a lab on SIMULATED
/// records (program_report.html), every data section labelled so.
#[test]
fn demo_folder_shows_the_test_program_simulated() {
    use gyrolab_lab::demo::{paper_report_folder, PaperReportRequest};
    let request = PaperReportRequest { sim_static_s: 60.0, sim_allan_s: 600.0 };
    let folder = paper_report_folder(&request, &gyrolab_eval::progress::Silent).unwrap();
    let get = |name: &str| {
        let o = folder.outputs.iter().find(|o| o.name == name).unwrap_or_else(|| panic!("no {name}"));
        String::from_utf8(o.bytes.clone()).unwrap()
    };
    assert!(get("report.html").contains("program_report.html"), "the paper's report points to the program");
    let html = get("program_report.html");
    for title in ["Temperature tests, axis x", "Threshold and resolution", "g-sensitivity, axis x", "Warm-up"] {
        assert!(html.contains(title), "no section {title}");
    }
    assert_eq!(html.matches("<p class=\"simulated\">SIMULATED DATA").count(), 9, "every data section labelled");
    assert!(html.contains("<div class=\"sim-page\">SIMULATED DATA"), "and every printed page");
    let json: serde_json::Value = serde_json::from_str(&get("program_results.json")).unwrap();
    assert_eq!(json["simulated"], true, "program_results.json says SIMULATED at its top");
    assert!(get("program_summary.csv").lines().skip(1).all(|l| l.ends_with(",SIMULATED")));
    assert!(json["sections"]["power_ups"]["x"].is_object() && json["sections"]["uncertainty"]["x"].is_object());
    assert!(get("program_plan.toml").contains("[temperature.x]"));
}
