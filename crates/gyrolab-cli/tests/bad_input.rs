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

// ---- Issue 15: bounded memory and time ----

/// Runs `gyrolab ARGS` and returns stderr, asserting exit code 2 and no panic.
fn error_of(args: &[&std::ffi::OsStr]) -> String {
    let out = gyrolab().args(args).timeout(std::time::Duration::from_secs(60)).assert().code(2).get_output().clone();
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(err.starts_with("error: "), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    err
}

#[test]
fn dev_zero_ends_quickly_as_binary_data() {
    let z = std::ffi::OsStr::new("/dev/zero");
    for cmd in ["rate", "bias", "allan"] {
        let e = error_of(&[cmd.as_ref(), z]);
        assert!(e.contains("/dev/zero:1: binary data"), "{cmd}: {e}");
    }
}

#[test]
fn nul_file_and_overlong_line_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let nul = dir.path().join("nul.csv");
    std::fs::write(&nul, vec![0u8; 3 << 20]).unwrap();
    for cmd in ["rate", "bias"] {
        let e = error_of(&[cmd.as_ref(), nul.as_os_str()]);
        assert!(e.contains("nul.csv:1: binary data"), "{e}");
        assert!(e.len() < 300, "{e}");
    }
    let long = dir.path().join("long.csv");
    let mut text = b"rate_dps,run,stroke,output_v\n".to_vec();
    text.extend(std::iter::repeat_n(b'7', 2 << 20));
    std::fs::write(&long, &text).unwrap();
    for cmd in ["rate", "bias"] {
        let e = error_of(&[cmd.as_ref(), long.as_os_str()]);
        assert!(e.contains("line 2 is longer than 1 MiB: expected text lines (is this a binary file?)"), "{cmd}: {e}");
        assert!(e.len() < 300, "{e}");
    }
}

#[test]
fn many_distinct_rates_and_runs_are_refused() {
    let mut text = String::from("rate_dps,run,stroke,output_v\n");
    for i in 0..8000 {
        text.push_str(&format!("{i},{i},fwd,1\n"));
    }
    let e = rate_error(&text);
    assert!(e.contains("more than 1000 runs"), "{e}");
    let mut text = String::from("rate_dps,run,stroke,output_v\n");
    for i in 0..2000 {
        text.push_str(&format!("{i},{},fwd,1\n", i % 900 + 1));
    }
    let e = rate_error(&text);
    assert!(e.contains("more than 1000000 rate-run cells"), "{e}");
}

#[test]
fn huge_simulations_are_refused_up_front_with_their_size() {
    for args in [
        &["simulate", "static", "--duration-s", "1e10"][..],
        &["simulate", "static", "--sample-rate-hz", "1e12"][..],
        &["simulate", "rate-table", "--samples-per-plateau", "4294967295", "--runs", "1000"][..],
    ] {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("o.csv");
        let out_arg = out.as_os_str();
        let mut all: Vec<&std::ffi::OsStr> = args.iter().map(|s| s.as_ref()).collect();
        all.extend(["--out".as_ref(), out_arg]);
        let e = error_of(&all);
        assert!(e.contains("samples (about") && e.contains("--max-samples"), "{e}");
        assert!(!out.exists());
    }
    // The bound is explicit and can be lowered (or raised).
    let e = error_of(&[
        "simulate".as_ref(),
        "static".as_ref(),
        "--duration-s".as_ref(),
        "10".as_ref(),
        "--max-samples".as_ref(),
        "100".as_ref(),
    ]);
    assert!(e.contains("1e3 samples"), "{e}");
    gyrolab().args(["simulate", "static", "--duration-s", "10", "--max-samples", "1000"]).assert().success();
}
