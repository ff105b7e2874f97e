//! `[g_sensitivity.<axis>]` in a test plan: simulated records in six orientations
//! (`program_sim::g_sensitivity`) with a rate-table record of the same sensor; the fitted G
//! against the simulated truth within 3 standard errors, the zero-g bias against the truth seen
//! through the reference null, unresolved components absent with their reason, a limit on
//! `g_sensitivity_dph_per_g`, and bad plans naming the key and line.

use gyrolab::limits::Overall;
use gyrolab::units::EARTH_RATE_DPH;
use gyrolab_eval::program_sim::g_sensitivity::{
    write_g_sensitivity_records, write_rate_table_record, BIAS_DPH, LATITUDE_DEG, TRUTH_G_DPH_PER_G,
};
use gyrolab_eval::progress::Silent;
use gyrolab_eval::EvalError;
use gyrolab_lab::report_folder::ReportFolder;
use gyrolab_lab::test_plan::{evaluate_test_plan, read_test_plan};
use std::path::Path;

fn output<'a>(folder: &'a ReportFolder, name: &str) -> &'a [u8] {
    &folder.outputs.iter().find(|o| o.name == name).unwrap_or_else(|| panic!("no {name}")).bytes
}

const HEAD: &str =
    "[device]\nmodel = \"simulated ADXRS646\"\nserial = \"G-1\"\naxes = [\"x\"]\n\n[rate.x]\nfile = \"rate_x.csv\"\n\n";

/// Writes the records once; returns the folder and the section's TOML.
fn setup() -> (tempfile::TempDir, String) {
    let dir = tempfile::tempdir().unwrap();
    assert_eq!(write_rate_table_record(dir.path(), "x", 5).unwrap(), "rate_x.csv");
    let section = write_g_sensitivity_records(dir.path(), "x", 100).unwrap();
    (dir, section)
}

fn evaluate(dir: &Path, plan: &str) -> Result<serde_json::Value, EvalError> {
    let p = dir.join("plan.toml");
    std::fs::write(&p, plan).unwrap();
    let plan = read_test_plan(&p)?;
    let folder = evaluate_test_plan(&plan, "plan.toml", &Silent)?;
    let mut v: serde_json::Value = serde_json::from_slice(output(&folder, "results.json")).unwrap();
    let html = String::from_utf8(output(&folder, "report.html").to_vec()).unwrap_or_default();
    v["html_has_section"] = serde_json::json!(html.contains("g-sensitivity, axis x"));
    v["html_unresolved_y"] =
        serde_json::json!(html.contains("not resolved: no record has a specific force along this axis"));
    v["verdict"] = serde_json::json!(folder.verdict.map(|v| v == Overall::Pass));
    v["csv_lines"] =
        // Data rows and header; a `# SIMULATED` line first (the simulator's records mark it).
        serde_json::json!(std::str::from_utf8(output(&folder, "g_sensitivity.csv"))
            .unwrap()
            .lines()
            .filter(|l| !l.starts_with('#'))
            .count());
    Ok(v)
}

/// The 1-based line of the first occurrence of `needle` in `text` (computed here, not by gyrolab).
fn line_of(text: &str, needle: &str) -> u64 {
    let at = text.find(needle).unwrap_or_else(|| panic!("{needle} not in the plan"));
    text[..at].matches('\n').count() as u64 + 1
}

fn f(v: &serde_json::Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

#[test]
fn simulated_truth_is_recovered_within_three_standard_errors() {
    let (dir, section) = setup();
    let plan = format!("{HEAD}{section}\n[limits]\ng_sensitivity_dph_per_g = {{ max = 100 }}\n");
    let v = evaluate(dir.path(), &plan).unwrap();
    let g = &v["sections"]["g_sensitivity"]["x"];
    assert_eq!(g["input_axis"], "x");
    assert_eq!(g["records"].as_array().unwrap().len(), 12);
    assert_eq!(g["residual_dof"], 8);
    assert_eq!(g["reference"]["source"], "rate_table");
    for (i, n) in ["x", "y", "z"].iter().enumerate() {
        let value = f(&g[format!("g_sensitivity_{n}_dph_per_g")]);
        let se = f(&g[format!("g_sensitivity_{n}_std_error_dph_per_g")]);
        // ARW 0.6 deg/sqrt(h) over 120 s: 3.29 deg/h per record mean; four records at +-1 g per
        // axis: 1.64 (deg/h)/g, plus the 1 deg/h bias instability; the estimate itself has 8
        // degrees of freedom, so a factor 3 either way.
        let arw_se = 0.6 / (120.0f64 / 3600.0).sqrt() / 2.0;
        assert!(se > arw_se / 3.0 && se < 3.0 * arw_se, "G_{n} standard error {se}, ARW alone {arw_se}");
        let truth = TRUTH_G_DPH_PER_G[i];
        assert!((value - truth).abs() < 3.0 * se, "G_{n} = {value} ± {se}, truth {truth}");
    }
    let truth_m = TRUTH_G_DPH_PER_G.iter().map(|v| v * v).sum::<f64>().sqrt();
    let m = f(&g["g_sensitivity_dph_per_g"]);
    assert!((m - truth_m).abs() < 3.0 * f(&g["g_sensitivity_std_error_dph_per_g"]), "|G| = {m}, truth {truth_m}");
    assert_eq!(g["g_sensitivity_kind"], "magnitude");
    assert_eq!(g["unresolved_components"], serde_json::json!({}));
    // Zero-g bias relative to the rate-table null (measured at rest, input axis up, so holding
    // bias + earth rate, and no g-sensitive bias in the simulator's rate-table records):
    // B_0 = bias + Omega_e sin(30 deg) - (null - 2.5 V) / K, in deg/h.
    let null = f(&g["reference"]["null_output"]);
    let k = f(&g["reference"]["scale_factor"]);
    let earth = EARTH_RATE_DPH * 0.5;
    let want_b0 = BIAS_DPH + earth - (null - 2.5) / k * 3600.0;
    let b0 = f(&g["bias_at_zero_g_dph"]);
    assert!((b0 - want_b0).abs() < 3.0 * f(&g["bias_at_zero_g_std_error_dph"]), "B0 {b0}, expected {want_b0}");
    // Earth rate removed: Omega_e sin(lat) (u - 1) with u = +1 (+x up), -1 (-x up), 0 otherwise.
    assert!((f(&g["earth_rate_vertical_dph"]) - earth).abs() < 1e-9);
    for r in g["records"].as_array().unwrap() {
        let u = f(&r["specific_force_g"][0]);
        assert!((f(&r["earth_rate_removed_dph"]) - earth * (u - 1.0)).abs() < 1e-9, "{r}");
    }
    assert_eq!(g["latitude_deg"], LATITUDE_DEG);
    // The summary figure takes the limit; the report has the section and the CSV 12 rows.
    assert_eq!(v["verdict"], true);
    assert_eq!(v["html_has_section"], true);
    assert_eq!(v["csv_lines"], 13);
}

#[test]
fn two_orientations_resolve_one_component_and_report_the_others_absent() {
    let (dir, section) = setup();
    // Keep the +x up and -x up records only (the first four).
    let kept: Vec<&str> = section
        .lines()
        .filter(|l| {
            !l.contains("orientation = \"+y") && !l.contains("\"-y") && !l.contains("\"+z") && !l.contains("\"-z")
        })
        .collect();
    let v = evaluate(dir.path(), &format!("{HEAD}{}\n", kept.join("\n"))).unwrap();
    let g = &v["sections"]["g_sensitivity"]["x"];
    assert_eq!(g["records"].as_array().unwrap().len(), 4);
    let gx = f(&g["g_sensitivity_x_dph_per_g"]);
    let se = f(&g["g_sensitivity_x_std_error_dph_per_g"]);
    assert!((gx - TRUTH_G_DPH_PER_G[0]).abs() < 3.0 * se, "G_x = {gx} ± {se}");
    assert!(g.get("g_sensitivity_y_dph_per_g").is_none() && g.get("g_sensitivity_z_dph_per_g").is_none());
    assert_eq!(g["unresolved_components"]["y"]["reason"], "no_specific_force");
    assert_eq!(g["unresolved_components"]["z"]["reason"], "no_specific_force");
    assert_eq!(g["g_sensitivity_kind"], "single_component");
    // The report shows the absent components with the reason, not as 0.
    assert_eq!(v["html_unresolved_y"], true);
    assert!((f(&g["g_sensitivity_dph_per_g"]) - gx.abs()).abs() < 1e-12);
}

#[test]
fn axis_with_only_a_g_sensitivity_table_is_accepted_but_needs_k() {
    let (dir, section) = setup();
    let plan = format!(
        "{}{section}\n{}",
        HEAD.replace("axes = [\"x\"]", "axes = [\"x\", \"y\"]"),
        section.replace("[g_sensitivity.x]", "[g_sensitivity.y]").replace("input_axis = \"x\"", "input_axis = \"y\"")
    );
    let e = evaluate(dir.path(), &plan).unwrap_err().to_string();
    assert!(e.contains("g_sensitivity.y: no scale factor K") && e.contains("[rate.y]"), "{e}");
    assert!(e.contains(&format!("plan.toml:{}:", line_of(&plan, "[g_sensitivity.y]"))), "{e}");
}

fn plan_error(dir: &Path, plan: &str) -> String {
    let p = dir.join("plan.toml");
    std::fs::write(&p, plan).unwrap();
    read_test_plan(&p).unwrap_err().to_string()
}

#[test]
fn bad_plans_name_the_key_and_line() {
    let (dir, section) = setup();
    let d = dir.path();
    // Every record in one orientation: no component is spanned.
    let one =
        section.replace("-x up", "+x up").replace("y up", "x up").replace("z up", "x up").replace("-x up", "+x up");
    let plan = format!("{HEAD}{one}");
    let e = plan_error(d, &plan);
    assert!(e.contains("g_sensitivity.x.records") && e.contains("span no g-sensitivity component"), "{e}");
    assert!(e.contains(&format!("plan.toml:{}:", line_of(&plan, "records = ["))), "{e}");
    // An unknown orientation name: the record's key and line.
    let plan = format!("{HEAD}{}", section.replacen("\"-x up\"", "\"-x upward\"", 1));
    let e = plan_error(d, &plan);
    assert!(e.contains("g_sensitivity.x.records[2].orientation: unknown orientation '-x upward'"), "{e}");
    assert!(e.contains(&format!("plan.toml:{}:", line_of(&plan, "-x upward"))), "{e}");
    // A missing file.
    let plan = format!("{HEAD}{}", section.replace("g_x_mx_1.csv", "nope.csv"));
    let e = plan_error(d, &plan);
    assert!(e.contains("g_sensitivity.x.records[2].file") && e.contains("nope.csv") && e.contains("not found"), "{e}");
    assert!(e.contains(&format!("plan.toml:{}:", line_of(&plan, "nope.csv"))), "{e}");
    // A vector of the wrong length; both orientation and vector; an axis not named x/y/z without input_axis.
    let plan = format!("{HEAD}{}", section.replacen("orientation = \"+x up\"", "specific_force_g = [1, 0]", 1));
    let e = plan_error(d, &plan);
    assert!(e.contains("g_sensitivity.x.records[0].specific_force_g: expected three numbers"), "{e}");
    let plan = format!(
        "{}{}",
        HEAD.replace("[\"x\"]", "[\"gx\"]").replace("[rate.x]", "[rate.gx]"),
        section.replace("[g_sensitivity.x]", "[g_sensitivity.gx]").replace("input_axis = \"x\"\n", "")
    );
    let e = plan_error(d, &plan);
    assert!(e.contains("g_sensitivity.gx.input_axis: missing"), "{e}");
    assert!(e.contains(&format!("plan.toml:{}:", line_of(&plan, "[g_sensitivity.gx]"))), "{e}");
    // An axis not in device.axes.
    let plan = format!("{HEAD}{}", section.replace("[g_sensitivity.x]", "[g_sensitivity.q]"));
    let e = plan_error(d, &plan);
    assert!(e.contains("g_sensitivity.q: axis 'q' is not in device.axes"), "{e}");
}
