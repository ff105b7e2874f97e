//! Every kind of bad input gives a clear error naming file, line and column, exit code 2.

use crate::common;
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
fn dev_zero_is_refused_before_it_is_opened() {
    let z = std::ffi::OsStr::new("/dev/zero");
    // Every reader refuses a device from its metadata, before opening it (issue 31): nothing
    // is read from an endless file.
    for cmd in ["rate", "bias", "allan", "inspect"] {
        let e = error_of(&[cmd.as_ref(), z]);
        assert!(e.contains("/dev/zero: a character device, not a regular file"), "{cmd}: {e}");
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

// ---- Issue 15: no silent NaN, inf or zero figure ----

#[test]
fn constant_output_is_no_scale_factor_and_writes_no_calibration() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(
        dir.path(),
        "flat.csv",
        "rate_dps,run,stroke,output_v\n-10,1,fwd,2.5\n10,1,fwd,2.5\n-10,1,rev,2.5\n10,1,rev,2.5\n",
    );
    let cal = dir.path().join("cal.toml");
    let e = error_of(&["rate".as_ref(), p.as_os_str(), "--cal-out".as_ref(), cal.as_os_str()]);
    assert!(e.contains("flat.csv: cannot evaluate: the output does not change with the rate: no scale factor"), "{e}");
    assert!(!cal.exists());
}

#[test]
fn overflowing_samples_are_refused_where_they_are() {
    let e = rate_error("rate_dps,run,stroke,output_v\n-10,1,fwd,1e308\n");
    assert!(e.contains("bad.csv:2:4: column 'output_v': found 1e308, a magnitude above 1e150"), "{e}");
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "s.csv", "time_s,output_dps\n0,1\n0.01,1e308\n0.02,1\n");
    for cmd in ["bias", "allan"] {
        let e = error_of(&[cmd.as_ref(), p.as_os_str()]);
        assert!(e.contains("s.csv:3:2: column 'output_dps': found 1e308, a magnitude above 1e150"), "{cmd}: {e}");
    }
}

#[test]
fn two_signs_are_not_a_number() {
    let e = rate_error("rate_dps,run,stroke,output_v\n-10,1,fwd,+-2.5\n");
    assert!(
        e.contains("bad.csv:2:4: column 'output_v': found '+-2.5', expected a number with one sign at most"),
        "{e}"
    );
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "s.csv", "time_s,output_dps\n0,1\n0.01,+-2.5\n0.02,1\n");
    let e = error_of(&["bias".as_ref(), p.as_os_str()]);
    assert!(e.contains("s.csv:3:2: column 'output_dps': found '+-2.5', expected a number"), "{e}");
}

#[test]
fn absurd_option_magnitudes_are_refused_with_the_flag() {
    let x = paper("paper_rate_table_x.csv");
    let e = error_of(&["rate".as_ref(), "--coverage".as_ref(), "1e308".as_ref(), x.as_os_str()]);
    assert!(e.contains("--coverage must have a magnitude from 1e-100 to 1e100"), "{e}");
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "v.csv", "time_s,output_v\n0,1\n0.01,2\n0.02,1\n0.03,1\n");
    let e = error_of(&["bias".as_ref(), "--scale-factor".as_ref(), "1e-320".as_ref(), p.as_os_str()]);
    assert!(e.contains("--scale-factor must have a magnitude") && e.contains("1e-320"), "{e}");
}

/// A calibration of the paper's axis x written by `gyrolab rate --cal-out`, edited by `edit`.
fn edited_calibration(dir: &std::path::Path, edit: impl Fn(&str) -> String) -> std::path::PathBuf {
    let cal = dir.join("cal.toml");
    gyrolab().arg("rate").arg(paper("paper_rate_table_x.csv")).arg("--cal-out").arg(&cal).assert().success();
    let text = edit(&std::fs::read_to_string(&cal).unwrap());
    std::fs::write(&cal, text).unwrap();
    cal
}

/// Replaces the value of `key = ...` by `value`.
fn set_key(text: &str, key: &str, value: &str) -> String {
    text.lines()
        .map(|l| if l.starts_with(&format!("{key} =")) { format!("{key} = {value}") } else { l.to_string() })
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn bad_calibration_values_name_the_calibration_file_line_and_key() {
    let dir = tempfile::tempdir().unwrap();
    let data = write(dir.path(), "data.csv", "time_s,output_v\n0,2.5\n0.01,2.6\n0.02,2.5\n0.03,2.4\n");
    for (key, value) in [("zero_offset", "nan"), ("zero_offset", "1e308"), ("scale_factor", "1.0")] {
        let cal = edited_calibration(dir.path(), |t| set_key(t, key, value));
        let text = std::fs::read_to_string(&cal).unwrap();
        let line = text.lines().position(|l| l.starts_with(&format!("{key} ="))).unwrap() + 1;
        for cmd in ["bias", "apply"] {
            let mut args: Vec<&std::ffi::OsStr> =
                vec![cmd.as_ref(), data.as_os_str(), "--cal".as_ref(), cal.as_os_str()];
            let out = dir.path().join("out.csv");
            if cmd == "apply" {
                args.extend(["--out".as_ref(), out.as_os_str()]);
            }
            let e = error_of(&args);
            assert!(
                e.contains(&format!("cal.toml:{line}: axis 'paper_rate_table_x', {key}")),
                "{cmd} {key}={value}: {e}"
            );
            assert!(!e.contains("data.csv"), "{e}");
        }
    }
}

#[test]
fn a_time_jump_inside_a_raw_log_plateau_is_reported_at_its_line() {
    let mut text = String::from("time_s,table_rate_dps,output_v\n");
    for i in 0..3000 {
        let t = i as f64 * 0.01 + if i >= 1500 { 1e6 } else { 0.0 };
        text.push_str(&format!("{t:.2},0,2.5\n"));
    }
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "raw.csv", &text);
    let e = error_of(&["rate".as_ref(), p.as_os_str()]);
    assert!(e.contains("raw.csv:1502: sample 1500") && e.contains("time jumps by"), "{e}");
}

// ---- Issue 15: contradictions ----

/// A 100 Hz static record of `n` samples (rate_dps, a small deterministic wobble).
fn record_100hz(n: usize) -> String {
    let mut text = String::from("time_s,rate_dps\n");
    for i in 0..n {
        text.push_str(&format!("{:.2},{:.6}\n", i as f64 * 0.01, ((i * 7919) % 1000) as f64 * 1e-4));
    }
    text
}

#[test]
fn a_given_rate_that_contradicts_the_time_stamps_is_used_with_a_warning() {
    // Issue 30: the user may know better than the stamps (a sensor clock read by a logger that
    // drops messages); the warning gives the stamps' reading.
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "r100.csv", &record_100hz(2000));
    let out = gyrolab().args(["allan", "--sample-rate-hz", "1000"]).arg(&p).assert().success().get_output().clone();
    let e = String::from_utf8(out.stderr).unwrap();
    assert!(e.contains("warning: sample rate 1000 Hz as given (--sample-rate-hz)"), "{e}");
    assert!(e.contains("the time stamps say 100.000000 Hz (+900.000 %): the given rate is used"), "{e}");
    // Within 1 %: a plain note.
    let out = gyrolab().args(["allan", "--sample-rate-hz", "100.5"]).arg(&p).assert().success().get_output().clone();
    let e = String::from_utf8(out.stderr).unwrap();
    assert!(e.contains("note: sample rate 100.5 Hz as given") && !e.contains("warning: sample rate"), "{e}");
}

#[test]
fn a_plan_rate_that_contradicts_the_time_stamps_names_the_key_and_file() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "a.csv", &record_100hz(3000));
    let plan = write(
        dir.path(),
        "plan.toml",
        "[device]\nmodel = \"m\"\nserial = \"1\"\naxes = [\"x\"]\n\n[static.x]\nfiles = [\"a.csv\"]\nsample_rate_hz = 1000\n",
    );
    let out = dir.path().join("o");
    let e = error_of(&["eval".as_ref(), plan.as_os_str(), "--out".as_ref(), out.as_os_str()]);
    assert!(
        e.contains("static.x.sample_rate_hz = 1000 Hz disagrees with the time column of") && e.contains("a.csv"),
        "{e}"
    );
}

// ---- Issue 15: messages ----

#[test]
fn cr_only_line_ends_are_named() {
    let e = rate_error("rate_dps,run,stroke,output_v\r-10,1,fwd,1\r10,1,fwd,2\r");
    assert!(e.contains("bad.csv:1: lines end with CR only"), "{e}");
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "mac.csv", "time_s,output_dps\r0,1\r0.01,2\r");
    for cmd in ["bias", "allan"] {
        let e = error_of(&[cmd.as_ref(), p.as_os_str()]);
        assert!(e.contains("mac.csv:1: lines end with CR only"), "{cmd}: {e}");
    }
}

#[test]
fn long_bad_fields_are_quoted_short() {
    let field = "z".repeat(500_000);
    let e = rate_error(&format!("rate_dps,run,stroke,output_v\n-10,1,fwd,{field}\n"));
    assert!(e.contains(&format!("found '{}...'", "z".repeat(60))), "{}", &e[..200.min(e.len())]);
    assert!(e.len() < 300, "{} chars", e.len());
    let e = rate_error(&format!("rate_dps,run,stroke,output_v\n-10,1,{field},1\n"));
    assert!(e.len() < 400, "{} chars", e.len());
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "s.csv", &format!("time_s,output_dps\n0,1\n0.01,{field}\n"));
    let e = error_of(&["bias".as_ref(), p.as_os_str()]);
    assert!(e.contains("s.csv:3:2") && e.len() < 300, "{} chars", e.len());
    let p = write(dir.path(), "h.csv", &format!("time_s,output_{field}\n0,1\n"));
    let e = error_of(&["bias".as_ref(), p.as_os_str()]);
    // The name is quoted three times, each cut at 60 characters.
    assert!(e.len() < 600 && !e.contains(&"z".repeat(61)), "{} chars", e.len());
}

/// A raw log of 3000 samples at 100 Hz at rest (table rate 0).
fn resting_raw_log(dir: &std::path::Path) -> std::path::PathBuf {
    let mut text = String::from("time_s,table_rate_dps,output_v\n");
    for i in 0..3000 {
        text.push_str(&format!("{:.2},0,2.5\n", i as f64 * 0.01));
    }
    write(dir, "raw.csv", &text)
}

#[test]
fn manual_segment_errors_point_at_the_segment_row_without_debug_text() {
    let dir = tempfile::tempdir().unwrap();
    let raw = resting_raw_log(dir.path());
    // Row 3 (line 4) asks for a window after the log's end.
    let segs = write(
        dir.path(),
        "segs.csv",
        "start_time_s,end_time_s,kind,run,stroke\n0,5,rest_start,,\n6,10,plateau,1,fwd\n100,200,plateau,1,rev\n",
    );
    let e = error_of(&["rate".as_ref(), raw.as_os_str(), "--segments".as_ref(), segs.as_os_str()]);
    assert!(e.contains("segs.csv:4:"), "{e}");
    let segs = write(
        dir.path(),
        "segs.csv",
        "start_time_s,end_time_s,kind,run,stroke\n0,5,rest_start,,\n6,10,sideways,1,fwd\n",
    );
    let e = error_of(&["rate".as_ref(), raw.as_os_str(), "--segments".as_ref(), segs.as_os_str()]);
    assert!(e.contains("segs.csv:3:3") && e.contains("with run 1 and stroke fwd"), "{e}");
    assert!(!e.contains("Some("), "{e}");
}

#[test]
fn simulate_config_value_errors_name_their_line() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = write(dir.path(), "sim.toml", "seed = 3\n\n[static_record]\nsample_rate_hz = 100\nduration_s = -5\n");
    let e = error_of(&["simulate".as_ref(), "static".as_ref(), "--config".as_ref(), cfg.as_os_str()]);
    assert!(e.contains("sim.toml:5: [static_record] parameter `duration_s` = -5 is invalid"), "{e}");
}

#[test]
fn a_plan_error_names_the_plan_not_its_folder() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "a.csv", &record_100hz(300));
    let plan = write(
        dir.path(),
        "plan.toml",
        "[device]\nmodel = \"m\"\nserial = \"1\"\naxes = [\"x\"]\n\n[static.x]\nfiles = [\"a.csv\"]\nsample_rate_hz = 100\noutput_unit = \"v\"\n",
    );
    let out = dir.path().join("o");
    let e = error_of(&["eval".as_ref(), plan.as_os_str(), "--out".as_ref(), out.as_os_str()]);
    assert!(e.contains("plan.toml:9:") && e.contains("static.x.output_unit: needs static.x.channel"), "{e}");
}

/// A cubic calibration (`--order 3`) reads back as written; its `scale_factor` edited by 10 %
/// disagrees with the least-squares slope of its polynomial over the calibrated range.
#[test]
fn a_hand_edited_scale_factor_of_a_cubic_calibration_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let cal = dir.path().join("cal.toml");
    gyrolab()
        .arg("rate")
        .arg(paper("paper_rate_table_x.csv"))
        .args(["--order", "3", "--cal-out"])
        .arg(&cal)
        .assert()
        .success();
    let data = write(dir.path(), "data.csv", "time_s,output_v\n0,2.5\n0.01,2.6\n0.02,2.5\n0.03,2.4\n");
    let out = dir.path().join("out.csv");
    gyrolab().arg("apply").arg(&data).arg("--cal").arg(&cal).arg("--out").arg(&out).assert().success();
    let text = std::fs::read_to_string(&cal).unwrap();
    let k: f64 = text.lines().find_map(|l| l.strip_prefix("scale_factor = ")).unwrap().trim().parse().unwrap();
    std::fs::write(&cal, set_key(&text, "scale_factor", &format!("{}", k * 1.1))).unwrap();
    let e = error_of(&[
        "apply".as_ref(),
        data.as_os_str(),
        "--cal".as_ref(),
        cal.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    assert!(e.contains("order-3 polynomial") && e.contains("scale_factor"), "{e}");
}

/// Ctrl-C during a long `simulate --out` leaves no temporary file, and the file it was to replace
/// as it was.
#[cfg(unix)]
#[test]
fn ctrl_c_during_simulate_leaves_no_temporary() {
    let dir = tempfile::tempdir().unwrap();
    let out = write(dir.path(), "s.csv", "old contents\n");
    let bin = assert_cmd::cargo::cargo_bin("gyrolab");
    let mut child = std::process::Command::new(bin)
        .args([
            "simulate",
            "static",
            "--duration-s",
            "1e6",
            "--sample-rate-hz",
            "1000",
            "--max-samples",
            "2e9",
            "--out",
        ])
        .arg(&out)
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    // Wait until the temporary file exists (the simulation is writing), at most 20 s.
    let tmp_exists = || {
        std::fs::read_dir(dir.path())
            .unwrap()
            .any(|e| e.unwrap().file_name().to_string_lossy().starts_with(".gyrolab-"))
    };
    let start = std::time::Instant::now();
    while !tmp_exists() && start.elapsed().as_secs() < 20 {
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    assert!(tmp_exists(), "the simulation never started writing");
    std::thread::sleep(std::time::Duration::from_millis(300));
    let ok = std::process::Command::new("kill").args(["-INT", &child.id().to_string()]).status().unwrap();
    assert!(ok.success());
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130), "{status:?}");
    assert!(!tmp_exists(), "a temporary file was left behind");
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "old contents\n");
}
