//! `[uncertainty]` in a test plan: the K and F0 budgets of the paper's rate table against a direct
//! computation here (the textbook standard errors of the slope and intercept of the point means,
//! the type-B parts from the plan's numbers, expanded = k combined); the bias, bias-stability and
//! noise-term budgets of simulated static records (the record-mean part against the simulated
//! white noise); bad values name the key and line.

mod common;
use gyrolab::sim::{SensorModel, StaticSpec};
use gyrolab::units::OutputUnit;
use gyrolab_eval::program_sim::uncertainty::write_uncertainty_section;
use gyrolab_eval::progress::Silent;
use gyrolab_eval::report_folder::ReportFolder;
use gyrolab_eval::test_plan::{evaluate_test_plan, read_test_plan};
use gyrolab_io::sim_csv::{write_static_csv, SimCsvOptions};
use serde_json::Value;

fn output<'a>(folder: &'a ReportFolder, name: &str) -> &'a [u8] {
    &folder.outputs.iter().find(|o| o.name == name).unwrap_or_else(|| panic!("no {name}")).bytes
}

fn close(got: f64, want: f64, rel: f64) {
    assert!((got - want).abs() <= rel * want.abs(), "got {got}, want {want}");
}

/// The paper's axis-x point means, the line and its textbook standard errors, computed here.
struct Line {
    k: f64,
    s: f64,
    u_k: f64,
    u_f0: f64,
}

fn paper_line() -> Line {
    let rows = common::read_long(&common::paper_file("paper_rate_table_x.csv"));
    let m = common::rate_means(&rows);
    let (k, f0) = common::lsq_line(&m.rates, &m.mean);
    let n = m.rates.len() as f64;
    let ss: f64 = m.rates.iter().zip(&m.mean).map(|(x, y)| (y - k * x - f0).powi(2)).sum();
    let s2 = ss / (n - 2.0);
    let sxx = common::sxx(&m.rates);
    let xbar = m.rates.iter().sum::<f64>() / n;
    Line { k, s: s2.sqrt(), u_k: (s2 / sxx).sqrt(), u_f0: (s2 * (1.0 / n + xbar * xbar / sxx)).sqrt() }
}

fn evaluate(dir: &std::path::Path, plan_text: &str) -> Value {
    let plan = dir.join("plan.toml");
    std::fs::write(&plan, plan_text).unwrap();
    let folder = evaluate_test_plan(&read_test_plan(&plan).unwrap(), "plan.toml", &Silent).unwrap();
    let html = String::from_utf8(output(&folder, "report.html").to_vec()).unwrap();
    assert!(html.contains("Measurement uncertainty"));
    serde_json::from_slice(output(&folder, "results.json")).unwrap()
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

#[test]
fn paper_rate_table_k_and_f0_budgets_equal_a_direct_computation() {
    let dir = tempfile::tempdir().unwrap();
    let x = common::paper_file("paper_rate_table_x.csv");
    let (rate_ppm, out_acc, k_cov) = (50.0, 0.001, 2.0);
    let text = format!(
        "[device]\nmodel = \"m\"\nserial = \"s\"\naxes = [\"x\"]\n[rate.x]\nfile = \"{}\"\n{}\
         [limits]\nscale_factor_expanded_uncertainty_ppm = {{ max = 1e6 }}\n",
        x.display(),
        write_uncertainty_section(k_cov, Some(rate_ppm), Some(out_acc))
    );
    let v = evaluate(dir.path(), &text);
    let u = &v["sections"]["uncertainty"]["x"];
    let l = paper_line();
    // Type A: the slope's and intercept's standard errors.
    let kb = &u["budgets"]["scale_factor"];
    close(f(&kb["value"]), l.k, 1e-12);
    close(f(&kb["components"][0]["standard_uncertainty"]), l.u_k, 1e-9);
    assert_eq!(kb["components"][0]["kind"], "A");
    // Type B: 50 ppm rectangular -> u_rel = 50e-6 / sqrt(3), u_B(K) = |K| u_rel.
    let ub_k = l.k.abs() * rate_ppm * 1e-6 / 3f64.sqrt();
    assert_eq!(kb["components"][1]["kind"], "B");
    close(f(&kb["components"][1]["contribution"]), ub_k, 1e-9);
    let uc_k = (l.u_k.powi(2) + ub_k.powi(2)).sqrt();
    close(f(&u["scale_factor_u"]), uc_k, 1e-9);
    close(f(&u["scale_factor_expanded"]), k_cov * uc_k, 1e-9);
    close(f(&u["scale_factor_u_ppm"]), uc_k / l.k.abs() * 1e6, 1e-9);
    close(f(&u["scale_factor_expanded_ppm"]), k_cov * uc_k / l.k.abs() * 1e6, 1e-9);
    // F0: intercept standard error and the output accuracy 0.001 V rectangular.
    let uc_f0 = (l.u_f0.powi(2) + (out_acc / 3f64.sqrt()).powi(2)).sqrt();
    close(f(&u["zero_offset_u"]), uc_f0, 1e-9);
    close(f(&u["zero_offset_expanded"]), k_cov * uc_f0, 1e-9);
    assert_eq!(f(&u["coverage_factor"]), k_cov);
    // The summary figure reaches [limits].
    let check = v["limit_checks"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["figure"] == "scale_factor_expanded_uncertainty_ppm")
        .unwrap();
    close(f(&check["value"]), k_cov * uc_k / l.k.abs() * 1e6, 1e-9);
    assert_eq!(check["verdict"], "PASS");
    // No static records: the static budgets are absent with their reason, never zero.
    assert!(u.get("bias_u_dph").is_none());
}

#[test]
fn no_uncertainty_table_no_section() {
    let dir = tempfile::tempdir().unwrap();
    let x = common::paper_file("paper_rate_table_x.csv");
    let plan = dir.path().join("plan.toml");
    std::fs::write(
        &plan,
        format!("[device]\nmodel = \"m\"\nserial = \"s\"\naxes = [\"x\"]\n[rate.x]\nfile = \"{}\"\n", x.display()),
    )
    .unwrap();
    let folder = evaluate_test_plan(&read_test_plan(&plan).unwrap(), "plan.toml", &Silent).unwrap();
    let v: Value = serde_json::from_slice(output(&folder, "results.json")).unwrap();
    assert!(v["sections"].get("uncertainty").is_none());
}

/// Two simulated static records (white rate noise of ARW 0.3 deg/√h, 1200 s at 100 Hz) against
/// the paper's K and F_r: the bias budget's record-mean part is the simulated white noise's
/// standard error ARW/60/√T per test (in deg/h, times 3600), divided by √2 for the mean of two
/// tests; the null and K parts follow from the line's numbers computed here.
#[test]
fn static_budgets_follow_the_simulated_noise_and_the_line() {
    let dir = tempfile::tempdir().unwrap();
    let x = common::paper_file("paper_rate_table_x.csv");
    let rows = common::read_long(&x);
    let zero: Vec<f64> = rows.iter().filter(|r| r.0 == 0.0).map(|r| r.3).collect();
    let f_r = zero.iter().sum::<f64>() / zero.len() as f64;
    let l = paper_line();
    let (arw, duration_s, bias) = (0.3, 1200.0, 50.0);
    for j in 0..2 {
        let model = SensorModel {
            output_unit: OutputUnit::Volt,
            scale_factor_per_dps: l.k,
            null: f_r,
            arw_deg_rt_h: arw,
            bias_dph: bias,
            ..SensorModel::default()
        };
        let spec = StaticSpec { sample_rate_hz: 100.0, duration_s, ..StaticSpec::default() };
        let file = std::fs::File::create(dir.path().join(format!("s{j}.csv"))).unwrap();
        write_static_csv(std::io::BufWriter::new(file), &model, &spec, 70 + j, &SimCsvOptions::default()).unwrap();
    }
    let (rate_ppm, out_acc) = (100.0, 0.0005);
    let text = format!(
        "[device]\nmodel = \"m\"\nserial = \"s\"\naxes = [\"x\"]\n[rate.x]\nfile = \"{}\"\n[static.x]\n\
         files = [\"s0.csv\", \"s1.csv\"]\nsample_rate_hz = 100.0\n{}",
        x.display(),
        write_uncertainty_section(2.0, Some(rate_ppm), Some(out_acc))
    );
    let v = evaluate(dir.path(), &text);
    let u = &v["sections"]["uncertainty"]["x"];
    let b = &u["budgets"]["bias"];
    // The record-mean part: recomputed here from the Allan curve of results.json (deg/s): the
    // longest tau <= T/4, sigma(tau) sqrt(tau/T) in deg/h, for each of the two equal tests,
    // root-sum-square / 2.
    let allan = &v["sections"]["allan"]["x"];
    let taus: Vec<f64> = allan["taus_s"].as_array().unwrap().iter().map(f).collect();
    let devs: Vec<f64> = allan["dev"].as_array().unwrap().iter().map(f).collect();
    let j = taus.iter().rposition(|t| *t <= duration_s / 4.0).unwrap();
    let per_test = devs[j] * 3600.0 * (taus[j] / duration_s).sqrt();
    let u_mean = f(&b["components"][0]["standard_uncertainty"]);
    close(u_mean, (2.0 * per_test * per_test).sqrt() / 2.0, 1e-9);
    // Against the simulated truth (white noise: sigma/sqrt(n)): one curve at tau near T/8 has
    // about ten degrees of freedom, so only a factor of two is asserted here; the estimator is
    // checked over many seeds in gyrolab::uncertainty's tests.
    let se_dph = arw / 60.0 / duration_s.sqrt() * 3600.0 / 2f64.sqrt();
    assert!(u_mean > 0.5 * se_dph && u_mean < 2.0 * se_dph, "record mean u {u_mean} deg/h, simulated {se_dph}");
    // The null is F_r (the 0 deg/s point): u = the residual std of the line, c = -3600/K.
    let per_output = 3600.0 / l.k;
    close(f(&b["components"][1]["standard_uncertainty"]), l.s, 1e-9);
    close(f(&b["components"][1]["sensitivity"]), -per_output, 1e-9);
    // Output accuracy: 0.0005 V / sqrt(3) with c = 3600/K.
    close(f(&b["components"][2]["contribution"]), out_acc / 3f64.sqrt() * per_output.abs(), 1e-9);
    // K: relative u(K)/K times the bias (no earth rate subtracted here).
    let b0 = f(&b["value"]);
    assert!((b0 - bias).abs() < 5.0 * se_dph * 2f64.sqrt(), "bias {b0}");
    let ub_k = l.k.abs() * rate_ppm * 1e-6 / 3f64.sqrt();
    close(f(&b["components"][3]["contribution"]), b0.abs() * l.u_k / l.k.abs(), 1e-6);
    close(f(&b["components"][4]["contribution"]), b0.abs() * ub_k / l.k.abs(), 1e-6);
    let want = (u_mean.powi(2)
        + (l.s * per_output).powi(2)
        + (out_acc / 3f64.sqrt() * per_output).powi(2)
        + (b0 / l.k).powi(2) * (l.u_k.powi(2) + ub_k.powi(2)))
    .sqrt();
    close(f(&u["bias_u_dph"]), want, 1e-6);
    close(f(&u["bias_expanded_dph"]), 2.0 * want, 1e-6);
    // Bias stability at 10 s: 120 windows per test, u = s / sqrt(2 * 119).
    let bs = &u["budgets"]["bias_stability"];
    assert_eq!(f(&u["bias_stability_smoothing_s"]), 10.0);
    close(f(&bs["components"][0]["standard_uncertainty"]), f(&bs["value"]) / (2.0 * 119.0f64).sqrt(), 1e-9);
    // The white noise of 10-s means: sigma_10 = ARW/60/sqrt(10) deg/h per sqrt(s)... in deg/h.
    let truth_bs = arw / 60.0 / 10f64.sqrt() * 3600.0;
    assert!((f(&bs["value"]) / truth_bs - 1.0).abs() < 0.25);
    // ARW: resolved on this white record; its relative u is the Allan interval's wider side, a
    // few percent on 120 000 samples, and the value is the simulated 0.3 deg/sqrt(h).
    let n = &u["budgets"]["arw"];
    close(f(&n["value"]), arw, 0.1);
    let rel = f(&n["components"][0]["standard_uncertainty"]) / f(&n["value"]);
    assert!(rel > 0.0 && rel < 0.05, "relative u of N {rel}");
    // Every noise term has either a budget or a stated reason, never both or neither.
    let not: Vec<&str> = u["not_given"].as_array().unwrap().iter().filter_map(|x| x["budget"].as_str()).collect();
    for term in ["arw", "bias_instability", "rrw"] {
        assert_ne!(u["budgets"].get(term).is_some(), not.contains(&term), "{term}: {u}");
    }
}

#[test]
fn bad_values_name_the_key_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let x = common::paper_file("paper_rate_table_x.csv");
    for (section, key, line) in [
        ("[uncertainty]\ncoverage_factor = 0\n", "uncertainty.coverage_factor", 8),
        ("[uncertainty]\nrate_accuracy_ppm = 10\noutput_accuracy = -0.1\n", "uncertainty.output_accuracy", 9),
        ("[uncertainty]\nrate_accuracy_ppm = -5\n", "uncertainty.rate_accuracy_ppm", 8),
        ("[uncertainty]\nrate_accuracy_distribution = \"uniform\"\n", "uncertainty.rate_accuracy_distribution", 8),
    ] {
        let plan = dir.path().join("plan.toml");
        std::fs::write(
            &plan,
            format!(
                "[device]\nmodel = \"m\"\nserial = \"s\"\naxes = [\"x\"]\n[rate.x]\nfile = \"{}\"\n{section}",
                x.display()
            ),
        )
        .unwrap();
        let e = read_test_plan(&plan).unwrap_err().to_string();
        assert!(e.contains(key), "{e}");
        assert!(e.contains(&format!("plan.toml:{line}:")), "{e}");
    }
}
