//! `gyrolab eval --store` and `gyrolab store ...` as processes (SQLite; the PostgreSQL half of
//! the store is tested in crates/gyrolab-store/tests): the evaluation lands also when a limit
//! fails; two processes storing at once both land; a process killed while storing leaves only
//! whole evaluations; bad stores exit 2 naming the store, never printing a password.

use assert_cmd::Command;
use std::path::{Path, PathBuf};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn gyrolab() -> Command {
    let mut c = Command::cargo_bin("gyrolab").unwrap();
    c.env_remove("GYROLAB_STORE");
    c
}

/// The paper plan with `lot` and `serial` set, its inputs beside it, in `dir`.
fn plan(dir: &Path, serial: &str, lot: &str) -> PathBuf {
    let text = std::fs::read_to_string(repo().join("examples/paper_plan.toml"))
        .unwrap()
        .replace("../data/paper/", "")
        .replace("serial = \"paper-2014\"", &format!("serial = \"{serial}\"\nlot = \"{lot}\""));
    for axis in ["x", "y", "z"] {
        let name = format!("paper_rate_table_{axis}.csv");
        std::fs::copy(repo().join("data/paper").join(&name), dir.join(&name)).unwrap();
    }
    let p = dir.join(format!("{serial}.toml"));
    std::fs::write(&p, text).unwrap();
    p
}

fn history_rows(db: &Path, serial: &str) -> Vec<serde_json::Value> {
    let out = gyrolab().args(["store", "history", serial, "--json", "--store", db.to_str().unwrap()]).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice::<Vec<serde_json::Value>>(&out.stdout).unwrap()
}

#[test]
fn eval_store_keeps_the_evaluation_beside_the_plan_and_queries_read_it() {
    let dir = tempfile::tempdir().unwrap();
    let p = plan(dir.path(), "SN-1", "L1");
    // The paper plan fails its linearity limit: exit 3, everything written and stored.
    gyrolab()
        .args(["eval", p.to_str().unwrap(), "--out", dir.path().join("r1").to_str().unwrap(), "--store", "-q"])
        .assert()
        .code(3);
    let db = dir.path().join("gyrolab.db");
    assert!(db.is_file(), "default store beside the plan");
    let rows = history_rows(&db, "SN-1");
    let summary = std::fs::read_to_string(dir.path().join("r1/summary.csv")).unwrap();
    assert_eq!(rows.len(), summary.lines().count() - 1);
    assert!(rows.iter().any(|r| r["verdict"] == "FAIL"));
    // The same folder through `store add` into another store, and a lot query with CSV and an SVG.
    let other = dir.path().join("other.db");
    gyrolab()
        .args([
            "store",
            "add",
            dir.path().join("r1").to_str().unwrap(),
            "--plan",
            p.to_str().unwrap(),
            "--store",
            other.to_str().unwrap(),
        ])
        .assert()
        .success()
        .stdout(predicates::str::contains("as evaluation 1"));
    let out = gyrolab().args(["store", "lot", "L1", "--csv", "--store", db.to_str().unwrap()]).output().unwrap();
    let csv = String::from_utf8(out.stdout).unwrap();
    assert!(csv.starts_with("axis,figure,unit,n,mean,sd,"), "{csv}");
    let svg = dir.path().join("h.svg");
    gyrolab()
        .args([
            "store",
            "history",
            "SN-1",
            "--figure",
            "scale_factor",
            "--svg",
            svg.to_str().unwrap(),
            "--store",
            db.to_str().unwrap(),
        ])
        .assert()
        .success();
    assert!(std::fs::read_to_string(&svg).unwrap().contains("<svg"));
    // A correction and an approval, then history shows three revisions of each figure.
    for args in [
        vec![
            "store",
            "revise",
            "1",
            "--kind",
            "correction",
            "--by",
            "QA",
            "--reason",
            "operator",
            "--operator",
            "B. Tester",
        ],
        vec!["store", "revise", "2", "--kind", "approval", "--by", "Dr. A", "--reason", "reviewed"],
    ] {
        gyrolab().args(&args).args(["--store", db.to_str().unwrap()]).assert().success();
    }
    let rows = history_rows(&db, "SN-1");
    let ids: std::collections::BTreeSet<i64> = rows.iter().map(|r| r["evaluation"].as_i64().unwrap()).collect();
    assert_eq!(ids.into_iter().collect::<Vec<_>>(), vec![1, 2, 3]);
    gyrolab()
        .args([
            "store",
            "revise",
            "1",
            "--kind",
            "approval",
            "--by",
            "X",
            "--reason",
            "y",
            "--store",
            db.to_str().unwrap(),
        ])
        .assert()
        .code(2);
}

#[test]
fn two_processes_storing_at_once_both_land() {
    let dir = tempfile::tempdir().unwrap();
    let db = dir.path().join("shared.db");
    let mut dirs = Vec::new();
    for serial in ["A", "B"] {
        let p = plan(dir.path(), serial, "L");
        let out = dir.path().join(format!("r-{serial}"));
        gyrolab().args(["eval", p.to_str().unwrap(), "--out", out.to_str().unwrap(), "-q"]).assert().code(3);
        dirs.push((p, out));
    }
    let children: Vec<_> = dirs
        .iter()
        .map(|(p, out)| {
            let mut c = std::process::Command::new(assert_cmd::cargo::cargo_bin("gyrolab"));
            c.args(["store", "add", "--plan", p.to_str().unwrap(), "--store", db.to_str().unwrap()]);
            for _ in 0..10 {
                c.arg(out);
            }
            c.spawn().unwrap()
        })
        .collect();
    for mut c in children {
        assert!(c.wait().unwrap().success());
    }
    for serial in ["A", "B"] {
        let ids: std::collections::BTreeSet<i64> =
            history_rows(&db, serial).iter().map(|r| r["evaluation"].as_i64().unwrap()).collect();
        assert_eq!(ids.len(), 10, "{serial}");
    }
}

#[test]
fn a_process_killed_while_storing_leaves_only_whole_evaluations() {
    let dir = tempfile::tempdir().unwrap();
    let db = dir.path().join("kill.db");
    let p = plan(dir.path(), "K", "L");
    let out = dir.path().join("r");
    gyrolab().args(["eval", p.to_str().unwrap(), "--out", out.to_str().unwrap(), "-q"]).assert().code(3);
    let per_eval = std::fs::read_to_string(out.join("summary.csv")).unwrap().lines().count() - 1;
    for delay_ms in [150u64, 400, 900] {
        let mut c = std::process::Command::new(assert_cmd::cargo::cargo_bin("gyrolab"));
        c.args(["store", "add", "--plan", p.to_str().unwrap(), "--store", db.to_str().unwrap()]);
        for _ in 0..400 {
            c.arg(&out);
        }
        let mut child = c.stdout(std::process::Stdio::null()).spawn().unwrap();
        std::thread::sleep(std::time::Duration::from_millis(delay_ms));
        child.kill().unwrap(); // SIGKILL: no handler runs
        child.wait().unwrap();
        if !db.exists() {
            continue;
        }
        let rows = history_rows(&db, "K");
        let mut per: std::collections::BTreeMap<i64, usize> = std::collections::BTreeMap::new();
        for r in &rows {
            *per.entry(r["evaluation"].as_i64().unwrap()).or_default() += 1;
        }
        assert!(per.values().all(|n| *n == per_eval), "after a kill at {delay_ms} ms: {per:?}");
    }
    // The store still takes evaluations.
    gyrolab()
        .args(["store", "add", out.to_str().unwrap(), "--plan", p.to_str().unwrap(), "--store", db.to_str().unwrap()])
        .assert()
        .success();
}

#[test]
fn bad_stores_exit_2_naming_the_store_without_the_password() {
    let dir = tempfile::tempdir().unwrap();
    let junk = dir.path().join("junk.db");
    std::fs::write(&junk, "not sqlite").unwrap();
    let out = gyrolab().args(["store", "lot", "L", "--store", junk.to_str().unwrap()]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("junk.db") && err.contains("not an SQLite database"), "{err}");
    assert_eq!(std::fs::read_to_string(&junk).unwrap(), "not sqlite");
    let out = gyrolab()
        .args(["store", "history", "SN", "--store", "postgres://lab:hunter2-secret@127.0.0.1:1/db"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let all = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(all.contains("postgres://lab:***@127.0.0.1:1/db") && !all.contains("hunter2"), "{all}");
    // A query on a missing store does not create it.
    let missing = dir.path().join("none.db");
    gyrolab().args(["store", "lot", "L", "--store", missing.to_str().unwrap()]).assert().code(2);
    assert!(!missing.exists());
    // GYROLAB_STORE is the default.
    let out = gyrolab().env("GYROLAB_STORE", junk.to_str().unwrap()).args(["store", "lot", "L"]).output().unwrap();
    assert!(String::from_utf8_lossy(&out.stderr).contains("junk.db"));
}
