//! `gyrolab verify DIR` (issue 33): the integrity record `gyrolab eval` writes (the plan's
//! SHA-256 and its copy, every input with its SHA-256) checked against the files as they are
//! now; the report's identity (number, issue date, page numbering, end mark) in report.html.

use crate::common;
use common::{gyrolab, paper, write};
use std::path::Path;

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// A plan over copies of the paper's three records in `dir`, with a report number and the
/// identity keys of `[test]`.
fn plan(dir: &Path) -> std::path::PathBuf {
    for a in ["x", "y", "z"] {
        let name = format!("paper_rate_table_{a}.csv");
        std::fs::copy(paper(&name), dir.join(&name)).unwrap();
    }
    write(
        dir,
        "plan.toml",
        "[device]\nmodel = \"m\"\nserial = \"S1\"\naxes = [\"x\", \"y\", \"z\"]\n\n\
         [test]\nreport_number = \"LAB-2026-0042\"\nissue_date = \"2026-11-30\"\ncustomer = \"ACME Navigation\"\n\
         item_condition = \"sealed, no visible damage\"\nreceipt_date = \"2026-11-20\"\n\
         deviations = \"rate table at 23.5 degC instead of 23 degC\"\n\n\
         [rate.x]\nfile = \"paper_rate_table_x.csv\"\n[rate.y]\nfile = \"paper_rate_table_y.csv\"\n\
         [rate.z]\nfile = \"paper_rate_table_z.csv\"\n",
    )
}

/// SHA-256 by an independent tool (coreutils sha256sum), when present.
fn sha256sum(p: &Path) -> Option<String> {
    let o = std::process::Command::new("sha256sum").arg(p).output().ok()?;
    o.status.success().then(|| String::from_utf8_lossy(&o.stdout).split_whitespace().next().unwrap_or("").to_string())
}

#[test]
fn verify_names_every_changed_or_missing_input_and_the_report_has_an_identity() {
    let dir = tempfile::tempdir().unwrap();
    let plan = plan(dir.path());
    let out = dir.path().join("report");
    gyrolab().arg("eval").arg(&plan).arg("--out").arg(&out).arg("-q").assert().code(0);

    // The record: plan hash and copy, the inputs relative to the plan's folder, hashes equal to
    // sha256sum's.
    let v: serde_json::Value = serde_json::from_str(&read(&out.join("results.json"))).unwrap();
    assert_eq!((v["report_number"].as_str(), v["issue_date"].as_str()), (Some("LAB-2026-0042"), Some("2026-11-30")));
    assert_eq!(v["test"]["customer"], "ACME Navigation");
    let integrity = &v["integrity"];
    assert_eq!(integrity["plan_copy"], "plan_copy.toml");
    assert_eq!(read(&out.join("plan_copy.toml")), read(&plan));
    let inputs = integrity["inputs"].as_array().unwrap();
    assert_eq!(inputs.len(), 3);
    assert_eq!(inputs[0]["file"], "paper_rate_table_x.csv");
    if let Some(want) = sha256sum(&dir.path().join("paper_rate_table_x.csv")) {
        assert_eq!(inputs[0]["sha256"].as_str(), Some(want.as_str()));
        assert_eq!(integrity["plan_sha256"].as_str(), Some(sha256sum(&plan).unwrap().as_str()));
    } else {
        eprintln!("\n*** SKIPPED: sha256sum not found: the hashes are not compared with an independent tool ***\n");
    }

    // The report's identity.
    let html = read(&out.join("report.html"));
    for want in [
        "<td><b>report number</b></td><td>LAB-2026-0042</td>",
        "<td><b>issued</b></td><td>2026-11-30</td>",
        "@bottom-left { content: \"Report LAB-2026-0042\"",
        "counter(page) \" of \" counter(pages)",
        "End of report LAB-2026-0042",
        "The results relate only to the items tested",
        "ACME Navigation",
        "sealed, no visible damage",
        "rate table at 23.5 degC instead of 23 degC",
        "Inputs and their SHA-256",
    ] {
        assert!(html.contains(want), "report.html lacks {want:?}");
    }

    // Unchanged: exit 0, every file named.
    let a = gyrolab().arg("verify").arg(&out).current_dir(dir.path()).assert().code(0);
    let stdout = String::from_utf8_lossy(&a.get_output().stdout).into_owned();
    assert!(stdout.starts_with("Report LAB-2026-0042"), "{stdout}");
    assert_eq!(stdout.matches("unchanged").count(), 5, "plan copy, plan, three inputs: {stdout}");

    // One byte of an input changed, another input gone, the plan copy edited: exit 3, each named.
    let y = dir.path().join("paper_rate_table_y.csv");
    let mut bytes = std::fs::read(&y).unwrap();
    let last = bytes.len() - 2;
    bytes[last] = if bytes[last] == b'1' { b'2' } else { b'1' };
    std::fs::write(&y, bytes).unwrap();
    std::fs::remove_file(dir.path().join("paper_rate_table_z.csv")).unwrap();
    let copy = out.join("plan_copy.toml");
    std::fs::write(&copy, read(&copy).replace("S1", "S2")).unwrap();
    let a = gyrolab().arg("verify").arg(&out).arg("--plan-dir").arg(dir.path()).assert().code(3);
    let o = a.get_output();
    let stdout = String::from_utf8_lossy(&o.stdout).into_owned();
    let stderr = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(stdout.contains("CHANGED   input") && stdout.contains("paper_rate_table_y.csv (SHA-256 now"), "{stdout}");
    assert!(stdout.contains("MISSING   input") && stdout.contains("paper_rate_table_z.csv"), "{stdout}");
    assert!(stdout.contains("CHANGED   plan copy"), "{stdout}");
    assert!(stdout.contains("unchanged input") && stdout.contains("paper_rate_table_x.csv"), "{stdout}");
    assert!(stderr.starts_with("FAIL: 3 of 5 files of report LAB-2026-0042 changed or missing"), "{stderr}");
}

#[test]
fn verify_refuses_folders_without_an_integrity_record() {
    let dir = tempfile::tempdir().unwrap();
    // No results.json.
    let a = gyrolab().arg("verify").arg(dir.path()).assert().code(2);
    assert!(String::from_utf8_lossy(&a.get_output().stderr).contains("results.json"));
    // The demo's built-in data name no plan.
    let out = dir.path().join("demo");
    gyrolab()
        .arg("demo")
        .arg("--out")
        .arg(&out)
        .args(["--sim-static-s", "60", "--sim-allan-s", "600", "-q"])
        .assert()
        .code(0);
    let a = gyrolab().arg("verify").arg(&out).assert().code(2);
    let err = String::from_utf8_lossy(&a.get_output().stderr).into_owned();
    assert!(err.contains("nothing to verify") && !err.contains("panicked"), "{err}");
    // A results.json of an earlier gyrolab (no integrity key).
    std::fs::write(out.join("results.json"), "{\"gyrolab_version\": \"0.1.0\"}").unwrap();
    let a = gyrolab().arg("verify").arg(&out).assert().code(2);
    assert!(String::from_utf8_lossy(&a.get_output().stderr).contains("no integrity record"));
}
