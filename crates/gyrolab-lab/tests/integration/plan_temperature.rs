//! Temperature tests in a plan (`[temperature.<axis>]`) on SIMULATED records with known
//! temperature coefficients and a known thermal hysteresis (program_sim::temperature): the
//! sensitivities against the truth's own least-squares slopes, the hysteresis against the step
//! put in, the compensation written into calibration.toml and applied by `apply` to a record
//! whose temperature steps through the range, and bad plans named by key and line.

use gyrolab::sim::{SensorModel, StaticSpec, TemperatureProfile, TemperatureStep};
use gyrolab_eval::apply::{apply_to, prepare_apply, ApplyRequest};
use gyrolab_eval::program_sim::temperature::{sensor, write_temperature_records, POINTS, TRUTH};
use gyrolab_eval::progress::Silent;
use gyrolab_io::sim_csv::{write_static_csv, SimCsvOptions};
use gyrolab_lab::report_folder::ReportFolder;
use gyrolab_lab::test_plan::{evaluate_test_plan, read_test_plan};
use serde_json::Value;
use std::path::Path;

const HEAD: &str = "[device]\nmodel = \"simulated\"\nserial = \"TC-1\"\naxes = [\"x\"]\n\n";

fn output<'a>(folder: &'a ReportFolder, name: &str) -> &'a [u8] {
    &folder.outputs.iter().find(|o| o.name == name).unwrap_or_else(|| panic!("no {name}")).bytes
}

/// Least-squares slope of y on x, computed here from the textbook formula.
fn slope(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = x.iter().map(|a| (a - mx) * (a - mx)).sum();
    sxy / sxx
}

fn evaluate(dir: &Path) -> (ReportFolder, Value) {
    let plan_text = format!("{HEAD}{}", write_temperature_records(dir, "x", 11).unwrap());
    let plan = dir.join("plan.toml");
    std::fs::write(&plan, plan_text).unwrap();
    let folder = evaluate_test_plan(&read_test_plan(&plan).unwrap(), "plan.toml", &Silent).unwrap();
    let json: Value = serde_json::from_slice(output(&folder, "results.json")).unwrap();
    (folder, json)
}

#[test]
fn sensitivities_and_hysteresis_recover_the_simulated_truth() {
    let dir = tempfile::tempdir().unwrap();
    let (folder, json) = evaluate(dir.path());
    let t = &json["sections"]["temperature"]["x"];
    assert_eq!(t["points"].as_array().unwrap().len(), POINTS.len());
    // Scale factor: the truth is K(T) = K25 (1 + 150e-6 (T - 25)), 150 ppm/degC of K(25)
    // exactly; the fitted K_i carry a few ppm of noise.
    let k = t["scale_factor_temp_sensitivity_ppm_per_c"]["value"].as_f64().unwrap();
    assert!((k - TRUTH.scale_factor_temp_coeff_ppm_per_c).abs() < 1.0, "{k} ppm/degC");
    // Bias: the truth at each point is 0.5 (T - 25) plus the 6 deg/h step on the cooling branch;
    // its least-squares slope over the same points (computed here) is what the figure estimates.
    let temps: Vec<f64> = POINTS.iter().map(|p| p.0).collect();
    let truth: Vec<f64> = POINTS
        .iter()
        .map(|(t, ph)| {
            TRUTH.bias_temp_coeff_dph_per_c * (t - 25.0)
                + if *ph == "cooling" { TRUTH.bias_hysteresis_dph } else { 0.0 }
        })
        .collect();
    let want = slope(&temps, &truth);
    let b = &t["bias_temp_sensitivity_dph_per_c"];
    let (got, se) = (b["value"].as_f64().unwrap(), b["standard_error"].as_f64().unwrap());
    // Noise of a 300-s point mean at ARW 0.3 deg/sqrt(h): 0.3 * 60 / sqrt(300) = 1.04 deg/h.
    assert!(se > 0.002 && se < 0.05, "standard error {se}");
    assert!((got - want).abs() < 4.0 * se.max(0.01), "bias sensitivity {got}, truth's slope {want}, se {se}");
    // Thermal hysteresis: the 6 deg/h step, within the noise of two point means (3 sigma).
    let h = t["bias_thermal_hysteresis_dph"]["value"].as_f64().unwrap();
    assert!((h - TRUTH.bias_hysteresis_dph).abs() < 4.5, "bias hysteresis {h}");
    assert_eq!(t["bias_thermal_hysteresis_dph"]["pairs"], 2);
    let hk = t["scale_factor_thermal_hysteresis_ppm"]["value"].as_f64().unwrap();
    assert!(hk < 40.0, "scale-factor hysteresis {hk} ppm where none was simulated");
    // The recorded temperature column agrees with the chamber temperature.
    for (p, (temp, _)) in t["points"].as_array().unwrap().iter().zip(POINTS) {
        assert!((p["recorded_temperature_c"].as_f64().unwrap() - temp).abs() < 1e-9);
    }
    // Summary figures, report section and CSV.
    let html = String::from_utf8(output(&folder, "report.html").to_vec()).unwrap();
    assert!(html.contains("Temperature tests, axis x"), "section");
    assert!(html.contains("scale_factor_temp_sensitivity_ppm_per_c"), "summary row");
    let csv = String::from_utf8(output(&folder, "temperature_points.csv").to_vec()).unwrap();
    // One header row per point plus the header; the records are the simulator's, so the table
    // starts with its SIMULATED line (issue 53: marked from the records themselves).
    assert!(csv.starts_with("# SIMULATED"), "{csv}");
    assert_eq!(csv.lines().filter(|l| !l.starts_with('#')).count(), POINTS.len() + 1);
    // The compensation is in calibration.toml.
    let cal = String::from_utf8(output(&folder, "calibration.toml").to_vec()).unwrap();
    assert!(cal.contains("[axis.temperature]"), "{cal}");
}

#[test]
fn apply_compensates_a_record_whose_temperature_steps_through_the_range() {
    let dir = tempfile::tempdir().unwrap();
    let (folder, _) = evaluate(dir.path());
    let cal = dir.path().join("cal.toml");
    std::fs::write(&cal, output(&folder, "calibration.toml")).unwrap();
    // The same sensor at rest, almost noiseless, 60 s at each of -30, 0, 40, 80 degC.
    let model = SensorModel { arw_deg_rt_h: 0.01, ..sensor(0.0) };
    let steps = [(60.0, 0.0), (120.0, 40.0), (180.0, 80.0)].map(|(at_s, temp_c)| TemperatureStep { at_s, temp_c });
    let spec = StaticSpec {
        sample_rate_hz: 10.0,
        duration_s: 240.0,
        temperature: TemperatureProfile::Steps { start_c: -30.0, steps: steps.to_vec() },
        latitude_deg: None,
        record_temperature: true,
        ..StaticSpec::default()
    };
    let input = dir.path().join("steps.csv");
    let f = std::fs::File::create(&input).unwrap();
    write_static_csv(std::io::BufWriter::new(f), &model, &spec, 5, &SimCsvOptions::default()).unwrap();
    let rates_by_step = |cal: &Path| -> Vec<f64> {
        let request = ApplyRequest {
            calibration: cal.to_path_buf(),
            input: input.clone(),
            calibration_axis: None,
            columns: vec![],
        };
        let plan = prepare_apply(&request).unwrap();
        let mut out = Vec::new();
        apply_to(&input, &plan, &mut out, &mut |_| {}).unwrap();
        let text = String::from_utf8(out).unwrap();
        let rates: Vec<f64> = text.lines().skip(1).map(|l| l.split(',').nth(1).unwrap().parse().unwrap()).collect();
        rates.chunks(600).map(|c| c.iter().sum::<f64>() / c.len() as f64).collect()
    };
    let compensated = rates_by_step(&cal);
    // The same calibration without its temperature model.
    let text = std::fs::read_to_string(&cal).unwrap();
    let plain = dir.path().join("plain.toml");
    let cut = text.find("[axis.temperature]").unwrap();
    std::fs::write(&plain, &text[..cut]).unwrap();
    let uncompensated = rates_by_step(&plain);
    let spread = |v: &[f64]| v.iter().cloned().fold(f64::MIN, f64::max) - v.iter().cloned().fold(f64::MAX, f64::min);
    // Uncompensated: 0.5 (deg/h)/degC over 110 degC is 55 deg/h = 0.0153 deg/s of spread.
    assert!(spread(&uncompensated) > 0.012, "{uncompensated:?}");
    assert!(spread(&compensated) < 0.1 * spread(&uncompensated), "{compensated:?} vs {uncompensated:?}");
    // A file without a temperature column is refused by a compensating calibration.
    let bare = dir.path().join("bare.csv");
    std::fs::write(&bare, "time_s,output_v\n0,2.5\n0.1,2.5\n").unwrap();
    let request =
        ApplyRequest { calibration: cal.clone(), input: bare.clone(), calibration_axis: None, columns: vec![] };
    let plan = prepare_apply(&request).unwrap();
    let err = apply_to(&bare, &plan, &mut Vec::new(), &mut |_| {}).unwrap_err();
    let msg = match err {
        gyrolab_io::apply_csv::StreamError::Data(d) => d.to_string(),
        other => panic!("{other:?}"),
    };
    assert!(msg.contains("no temperature column") && msg.contains("bare.csv"), "{msg}");
}

#[test]
fn tiny_spans_and_missing_records_are_said_not_computed() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_temperature_records(d, "x", 3).unwrap();
    // Two points 0.04 degC apart: no sensitivity, with the span named.
    let plan = format!(
        "{HEAD}[rate.x]\nfile = \"rate_x.csv\"\n\n[temperature.x]\n\
         [[temperature.x.points]]\ntemperature_c = 25.0\nrate = \"tc_x_2_rate.csv\"\nstatic = \"tc_x_2_static.csv\"\n\
         [[temperature.x.points]]\ntemperature_c = 25.04\nrate = \"tc_x_5_rate.csv\"\nstatic = \"tc_x_5_static.csv\"\n"
    );
    std::fs::write(d.join("tiny.toml"), plan).unwrap();
    let folder = evaluate_test_plan(&read_test_plan(&d.join("tiny.toml")).unwrap(), "tiny.toml", &Silent).unwrap();
    let json: Value = serde_json::from_slice(output(&folder, "results.json")).unwrap();
    let t = &json["sections"]["temperature"]["x"];
    assert_eq!(t["bias_temp_sensitivity_dph_per_c"]["reason"], "span_too_small", "{t}");
    assert!(t["bias_temp_sensitivity_dph_per_c"]["value"].is_null());
    let html = String::from_utf8(output(&folder, "report.html").to_vec()).unwrap();
    assert!(html.contains("Bias temperature sensitivity: no value (the points span 0.040 degC"), "reason shown");
}

#[test]
fn bad_temperature_plans_name_the_key_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_temperature_records(d, "x", 3).unwrap();
    let err = |body: &str| {
        std::fs::write(d.join("bad.toml"), format!("{HEAD}{body}")).unwrap();
        read_test_plan(&d.join("bad.toml")).unwrap_err().to_string()
    };
    // A point without records (line 8 of the plan).
    let e = err("[temperature.x]\n[[temperature.x.points]]\ntemperature_c = 25.0\n");
    assert!(e.contains("bad.toml:7") && e.contains("temperature.x.points[0]") && e.contains("has no record"), "{e}");
    let e = err("[temperature.x]\n[[temperature.x.points]]\ntemperature_c = 25.0\nrate = \"nope.csv\"\n");
    assert!(e.contains("temperature.x.points[0].rate") && e.contains("nope.csv") && e.contains(":9"), "{e}");
    let e =
        err("[temperature.x]\norder = 2\n[[temperature.x.points]]\ntemperature_c = 25.0\nrate = \"tc_x_2_rate.csv\"\n\
         [[temperature.x.points]]\ntemperature_c = 60.0\nrate = \"tc_x_3_rate.csv\"\n");
    assert!(
        e.contains("temperature.x.order") && e.contains("needs 3 distinct temperatures") && e.contains(":7"),
        "{e}"
    );
    let e = err("[temperature.x]\n[[temperature.x.points]]\ntemperature_c = 25.0\nphase = \"warming\"\nrate = \"tc_x_2_rate.csv\"\n");
    assert!(e.contains("temperature.x.points[0].phase") && e.contains("'warming'"), "{e}");
    let e = err("[temperature.y]\n[[temperature.y.points]]\ntemperature_c = 25.0\nrate = \"tc_x_2_rate.csv\"\n");
    assert!(e.contains("temperature.y: axis 'y' is not in device.axes"), "{e}");
    let e = err("[temperature.x]\n");
    assert!(e.contains("temperature.x.points: no temperature point"), "{e}");
}
