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
    assert_eq!(
        stdout.matches("unchanged").count() - stdout.matches("unchanged output").count(),
        5,
        "plan copy, plan, three inputs: {stdout}"
    );
    assert!(stdout.matches("unchanged output").count() >= 8, "every output of the manifest: {stdout}");

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
    // The plan copy is also an output of the manifest: found twice (as the plan's copy and as
    // an output), 4 of the 5 plan and input files and 9 outputs.
    assert!(stderr.starts_with("FAIL: 4 of 14 files of report LAB-2026-0042 changed, missing or added"), "{stderr}");
    assert!(stderr.contains("output plan_copy.toml"), "{stderr}");
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

/// `verify` checks the outputs too (issue 53): every file of the folder against manifest.json,
/// whose hashes equal coreutils' sha256sum; an edited report.html (PASS to FAIL), an edited
/// results.json, a deleted summary.csv and an added file each give exit 3 naming them; a
/// report.pdf printed afterwards is listed as not covered, not as a change; a folder without a
/// manifest has its outputs NOT CHECKED (exit 5), never passed.
#[test]
fn verify_checks_every_output_against_the_manifest() {
    let dir = tempfile::tempdir().unwrap();
    let p = plan(dir.path());
    let out = dir.path().join("report");
    gyrolab().arg("eval").arg(&p).arg("--out").arg(&out).arg("-q").assert().code(0);
    let manifest: serde_json::Value = serde_json::from_str(&read(&out.join("manifest.json"))).unwrap();
    let files = manifest["files"].as_array().unwrap();
    let mut names: Vec<&str> = files.iter().map(|f| f["name"].as_str().unwrap()).collect();
    names.sort();
    let mut on_disk: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n != "manifest.json")
        .collect();
    on_disk.sort();
    assert_eq!(names, on_disk);
    for f in files {
        if let Some(sum) = sha256sum(&out.join(f["name"].as_str().unwrap())) {
            assert_eq!(f["sha256"].as_str().unwrap(), sum, "{f}");
        }
    }
    let verify = || gyrolab().arg("verify").arg(&out).arg("--plan-dir").arg(dir.path()).output().unwrap();
    assert_eq!(verify().status.code(), Some(0));
    std::fs::write(out.join("report.pdf"), b"%PDF").unwrap();
    let o = verify();
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).contains("report.pdf (printed from report.html after the manifest"));
    let original = read(&out.join("report.html"));
    for (edit, word) in [("report.html", "output report.html"), ("results.json", "output results.json")] {
        let path = out.join(edit);
        let before = std::fs::read(&path).unwrap();
        let mut text = String::from_utf8(before.clone()).unwrap();
        text = if text.contains("PASS") { text.replacen("PASS", "FAIL", 1) } else { text.replacen('1', "2", 1) };
        std::fs::write(&path, text).unwrap();
        let o = verify();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(3), "{err}");
        assert!(err.contains(word), "{err}");
        std::fs::write(&path, before).unwrap();
    }
    assert_eq!(read(&out.join("report.html")), original);
    std::fs::remove_file(out.join("summary.csv")).unwrap();
    std::fs::write(out.join(".gyrolab-x.tmp"), b"leftover").unwrap();
    let o = verify();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(3), "{err}");
    assert!(err.contains("output summary.csv") && err.contains("added .gyrolab-x.tmp"), "{err}");
    std::fs::remove_file(out.join("manifest.json")).unwrap();
    std::fs::remove_file(out.join(".gyrolab-x.tmp")).unwrap();
    let o = verify();
    assert_eq!(o.status.code(), Some(5), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).contains("NOT CHECKED"));
}
