//! Every kind of bad input gives a clear error naming file, line and column, exit code 2.

mod common;
use common::{gyrolab, paper, write};

/// Runs `gyrolab rate` on `text` and returns stderr, asserting exit code 2.
fn rate_error(text: &str) -> String {
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "bad.csv", text);
    let out = gyrolab().arg("rate").arg(&p).assert().code(2).get_output().clone();
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(err.starts_with("error: "), "{err}");
    assert!(err.contains("bad.csv"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    err
}

#[test]
fn empty_file() {
    assert!(rate_error("").contains("bad.csv: the file is empty"));
}

#[test]
fn missing_column() {
    let e = rate_error("rate_dps,stroke,output_v\n1,fwd,2\n");
    assert!(e.contains("bad.csv:1: no run column in the header: expected a column named 'run'"), "{e}");
    let e = rate_error("rate_dps,run,stroke,value,extra\n1,1,fwd,2,3\n");
    assert!(e.contains("bad.csv:1: no output column in the header"), "{e}");
}

#[test]
fn non_numeric_cell() {
    let e = rate_error("rate_dps,run,stroke,output_v\n1,1,fwd,2.5\n2,1,fwd,2.x\n");
    assert!(e.contains("bad.csv:3:4: column 'output_v': found '2.x', expected a number"), "{e}");
}

#[test]
fn nan_cell() {
    let e = rate_error("rate_dps,run,stroke,output_v\n1,1,fwd,NaN\n");
    assert!(e.contains("bad.csv:2:4"), "{e}");
    assert!(e.contains("finite"), "{e}");
}

#[test]
fn rate_with_no_data() {
    let e = rate_error("rate_dps,run1_fwd_v,run1_rev_v\n-10,1.0,1.1\n0,,\n10,3.0,3.1\n");
    assert!(e.contains("bad.csv:3: rate 0 deg/s has no data"), "{e}");
}

#[test]
fn single_distinct_rate() {
    let e = rate_error("rate_dps,run,stroke,output_v\n5,1,fwd,1\n5,1,rev,1\n");
    assert!(e.contains("1 distinct rate(s)"), "{e}");
}

#[test]
fn run_missing_a_stroke() {
    let e =
        rate_error("rate_dps,run,stroke,output_v\n1,1,fwd,1\n2,1,fwd,2\n1,1,rev,1\n2,1,rev,2\n1,2,fwd,1\n2,2,fwd,2\n");
    assert!(e.contains("no data for rate 1 deg/s in run 2, stroke rev"), "{e}");
}

#[test]
fn unknown_stroke_label() {
    let e = rate_error("rate_dps,run,stroke,output_v\n1,1,sideways,1\n");
    assert!(e.contains("bad.csv:2:3: column 'stroke': unknown stroke label 'sideways'"), "{e}");
}

#[test]
fn duplicate_headers() {
    let e = rate_error("rate_dps,run,stroke,output_v,output_v\n");
    assert!(e.contains("bad.csv:1:5"), "{e}");
    assert!(e.contains("duplicate column name 'output_v'"), "{e}");
}

#[test]
fn unknown_unit_suffix() {
    let e = rate_error("rate_dps,run,stroke,output_amps\n1,1,fwd,1\n");
    assert!(e.contains("bad.csv:1:4: column 'output_amps': unknown output unit suffix '_amps'"), "{e}");
}

#[test]
fn wrong_field_count() {
    let e = rate_error("rate_dps,run,stroke,output_v\n1,1,fwd\n");
    assert!(e.contains("bad.csv:2: this row has 3 fields but the header has 4"), "{e}");
}

#[test]
fn missing_file_and_bad_options() {
    let out = gyrolab().args(["rate", "/nonexistent/x.csv"]).assert().code(2).get_output().clone();
    assert!(String::from_utf8_lossy(&out.stderr).contains("/nonexistent/x.csv: cannot read the file"));
    gyrolab().args(["rate", "--coverage", "-1"]).arg(paper("paper_rate_table_x.csv")).assert().code(2);
    gyrolab().args(["rate", "--order", "0"]).arg(paper("paper_rate_table_x.csv")).assert().code(2);
    gyrolab().args(["rate", "--axis", "a", "--axis", "b"]).arg(paper("paper_rate_table_x.csv")).assert().code(2);
    gyrolab().args(["rate", "--output-unit", "furlongs"]).arg(paper("paper_rate_table_x.csv")).assert().code(2);
    gyrolab().args(["nonsense"]).assert().code(2);
    gyrolab().args(["rate"]).assert().code(2);
}
