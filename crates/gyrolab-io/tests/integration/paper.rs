//! The paper's own data read from `data/paper/` and evaluated: the figures checked here were
//! computed independently (docs: ../shared/docs/methods-notes.md section 1, "What reproduces").

use approx::assert_relative_eq;
use gyrolab::published::PrintedValue;
use gyrolab::rate_test::{evaluate, RateEvaluation, RateTestOptions};
use gyrolab_io::rate_table::{read_rate_table, RateColumns};
use gyrolab_io::text::parse_text_table;
use std::path::{Path, PathBuf};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/paper").join(name)
}

fn axis(a: &str) -> RateEvaluation {
    let f = read_rate_table(&data(&format!("paper_rate_table_{a}.csv")), &RateColumns::default()).unwrap();
    evaluate(&f.table, &RateTestOptions::default()).unwrap()
}

#[test]
fn table2_rows_reproduce_except_11_and_14() {
    let e = axis("x");
    let text = std::fs::read_to_string(data("paper_table2_means_x.csv")).unwrap();
    let t = parse_text_table(Path::new("t2"), &text).unwrap();
    assert_eq!(t.rows.len(), 14);
    let mut differing = Vec::new();
    for (row, p) in t.rows.iter().zip(&e.points) {
        let printed: Vec<PrintedValue> = row.fields[2..5].iter().map(|f| PrintedValue::parse(f).unwrap()).collect();
        let ok = printed[0].agrees_with(p.forward_mean)
            && printed[1].agrees_with(p.reverse_mean)
            && printed[2].agrees_with(p.mean);
        if !ok {
            differing.push(row.fields[0].clone());
        }
    }
    assert_eq!(differing, vec!["11", "14"]);
    // The forward means the data give at those rows (methods-notes, checked independently).
    assert_relative_eq!(e.points[10].forward_mean, 3.53280075, epsilon = 1e-9);
    assert_relative_eq!(e.points[13].forward_mean, 4.67490275, epsilon = 1e-9);
}

#[test]
fn scale_factors_of_the_three_axes() {
    // Least squares on the overall means: x 7.5616, y 7.5756, z 7.5759 mV/(deg/s).
    for (a, k) in [("x", 7.5616), ("y", 7.5756), ("z", 7.5759)] {
        assert_relative_eq!(axis(a).scale_factor() * 1e3, k, epsilon = 5e-5);
    }
}

#[test]
fn figures_of_axis_x() {
    // methods-notes section 1: linearity 5.54 %, hysteresis 0.66 %, repeatability 2.26 %,
    // nonlinearity about 11.1 %.
    let e = axis("x");
    assert_relative_eq!(e.linearity * 100.0, 5.54, epsilon = 0.005);
    assert_relative_eq!(e.hysteresis * 100.0, 0.66, epsilon = 0.005);
    assert_relative_eq!(e.repeatability.unwrap() * 100.0, 2.26, epsilon = 0.005);
    assert_relative_eq!(e.nonlinearity * 100.0, 11.1, epsilon = 0.05);
}

#[test]
fn table5_means_reproduce() {
    let text = std::fs::read_to_string(data("paper_table5_bias.csv")).unwrap();
    let t = parse_text_table(Path::new("t5"), &text).unwrap();
    for row in &t.rows {
        let v: Vec<f64> = row.fields[1..5].iter().map(|f| f.parse().unwrap()).collect();
        let m = v.iter().sum::<f64>() / 4.0;
        assert!(PrintedValue::parse(&row.fields[5]).unwrap().agrees_with(m), "{row:?}");
    }
}
