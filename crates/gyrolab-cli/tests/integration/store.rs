//! `gyrolab eval --store` and `gyrolab store ...` as processes, every test body on a temporary
//! SQLite file AND on the real PostgreSQL server of GYROLAB_TEST_PG_URL (one schema per test;
//! scripts/pg-test-server.sh starts it; without the URL the PostgreSQL half prints `SKIPPED:`,
//! and fails under CI=true). Checked: the evaluation lands also when a limit fails and queries
//! read it back (history rows = the report's summary.csv rows; export CSV/Parquet); revisions and
//! re-evaluation; two processes storing at once both land; a process killed inside the store's
//! transaction leaves nothing of its evaluation; bad stores exit 2 naming the store, never
//! printing a password, writing nothing; hostile texts come back verbatim or are refused.

use assert_cmd::Command;
use std::collections::{BTreeMap, BTreeSet};
use std::io::BufRead;
use std::path::{Path, PathBuf};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn gyrolab() -> Command {
    let mut c = Command::cargo_bin("gyrolab").unwrap();
    c.env_remove("GYROLAB_STORE").env_remove("GYROLAB_STORE_TEST_PAUSE_MS");
    c
}

fn gyrolab_process() -> std::process::Command {
    let mut c = std::process::Command::new(assert_cmd::cargo::cargo_bin("gyrolab"));
    c.env_remove("GYROLAB_STORE").env_remove("GYROLAB_STORE_TEST_PAUSE_MS");
    c
}

// The back ends of the store's own tests (an SQLite file in a new folder, a new schema of the
// PostgreSQL test server): one implementation, and the SQL that makes the schema stays in the
// gyrolab-store crate.
#[path = "../../../gyrolab-store/tests/integration/common/mod.rs"]
pub(crate) mod store_backends;
use store_backends::{backends, mark_newer_schema};

/// A TOML basic string holding `s` exactly.
fn toml_str(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if c.is_control() => out.push_str(&format!("\\u{:04X}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// The paper plan (its inputs by absolute path) with `serial`, `lot`, `operator` set, in `dir`
/// as `name`, with `extra` appended (comments).
fn plan_with(dir: &Path, name: &str, serial: &str, lot: &str, operator: &str, extra: &str) -> PathBuf {
    let data = repo().join("data/paper/");
    let text = std::fs::read_to_string(repo().join("examples/paper_plan.toml"))
        .unwrap()
        .replace("../data/paper/", &format!("{}/", data.display()))
        .replace("serial = \"paper-2014\"", &format!("serial = {}\nlot = {}", toml_str(serial), toml_str(lot)))
        .replace("[test]\n", &format!("[test]\noperator = {}\n", toml_str(operator)));
    let p = dir.join(name);
    std::fs::write(&p, text + extra).unwrap();
    p
}

fn plan(dir: &Path, serial: &str, lot: &str) -> PathBuf {
    plan_with(dir, &format!("{serial}.toml"), serial, lot, "A. Operator", "")
}

/// `gyrolab eval PLAN --out OUT -q` (exit 3: the paper fails its linearity limit), with
/// `--store LOCATION` when given.
fn eval(plan: &Path, out: &Path, store: Option<&str>) {
    let mut c = gyrolab();
    c.args(["eval", plan.to_str().unwrap(), "--out", out.to_str().unwrap(), "-q"]);
    if let Some(s) = store {
        c.args(["--store", s]);
    }
    c.assert().code(3);
}

fn json_of(args: &[&str], store: &str) -> serde_json::Value {
    let out = gyrolab().args(args).args(["--json", "--store", store]).output().unwrap();
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

fn history_ids(store: &str, serial: &str) -> BTreeMap<i64, usize> {
    let rows = json_of(&["store", "history", serial], store);
    let mut per = BTreeMap::new();
    for r in rows.as_array().unwrap() {
        *per.entry(r["evaluation"].as_i64().unwrap()).or_insert(0) += 1;
    }
    per
}

fn summary_rows(out: &Path) -> usize {
    std::fs::read_to_string(out.join("summary.csv")).unwrap().lines().count() - 1
}

#[test]
fn eval_store_then_queries_revisions_and_reevaluation() {
    for b in backends("queries") {
        let dir = tempfile::tempdir().unwrap();
        let loc = b.location.as_str();
        // Three devices in lot L1, two in L2: evaluated with --store (exit 3 still stores).
        for (serial, lot) in [("S1", "L1"), ("S2", "L1"), ("S3", "L1"), ("T1", "L2"), ("T2", "L2")] {
            let p = plan(dir.path(), serial, lot);
            eval(&p, &dir.path().join(format!("r-{serial}")), Some(loc));
        }
        let n = summary_rows(&dir.path().join("r-S1"));
        let rows = json_of(&["store", "history", "S1"], loc);
        let rows = rows.as_array().unwrap();
        assert_eq!(rows.len(), n, "{}: one history row per summary.csv row", b.name);
        assert!(rows.iter().any(|r| r["verdict"] == "FAIL" && r["figure"] == "linearity_pct"), "{}", b.name);
        // The stored value equals the report's results.json value, bit for bit.
        let summary = std::fs::read_to_string(dir.path().join("r-S1/summary.csv")).unwrap();
        let head: Vec<&str> = summary.lines().next().unwrap().split(',').collect();
        let col = |k: &str| head.iter().position(|h| *h == k).unwrap();
        let line = summary.lines().find(|l| l.contains(",scale_factor,")).expect("a scale_factor row");
        let f: Vec<&str> = line.split(',').collect();
        let stored = rows
            .iter()
            .find(|r| r["figure"] == "scale_factor" && r["axis"] == f[col("axis")])
            .and_then(|r| r["value"].as_f64())
            .unwrap();
        assert_eq!(stored, f[col("value")].parse::<f64>().unwrap(), "{}", b.name);

        // Lot statistics: n = 3 devices, as text, CSV and Parquet.
        let lot = json_of(&["store", "lot", "L1"], loc);
        let sf = lot.as_array().unwrap().iter().find(|r| r["figure"] == "scale_factor").unwrap().clone();
        assert_eq!(sf["statistics"]["n"], 3, "{}", b.name);
        assert_eq!(sf["statistics"]["mean"].as_f64(), Some(stored), "{}: identical devices", b.name);
        let pq = dir.path().join("lot.parquet");
        let out = gyrolab()
            .args(["store", "lot", "L1", "--csv", "--parquet", pq.to_str().unwrap(), "--store", loc])
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let csv = String::from_utf8(out.stdout).unwrap();
        assert!(
            csv.starts_with(
                "axis,figure,unit,n,n_devices,n_bounds,n_not_evaluated,mean,sd,min,max,limit_min,limit_max,yield,\
                 yield_evaluated,Cp,"
            ),
            "{csv}"
        );
        assert!(csv.lines().next().unwrap().ends_with(",outliers,simulated,notes"), "{csv}");
        // Three devices: every index carries the few-values warning (n = 3 < 25).
        assert_eq!(sf["n_devices"], 3, "{}", b.name);
        let warned = sf["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .any(|w| w.as_str().unwrap().starts_with("capability from n = 3 values, fewer than 25"));
        assert!(warned || sf["statistics"]["ppk"].is_null(), "{}: {sf}", b.name);
        assert_eq!(csv.lines().count(), lot.as_array().unwrap().len() + 1);
        assert_eq!(&std::fs::read(&pq).unwrap()[..4], b"PAR1");
        let text =
            String::from_utf8(gyrolab().args(["store", "lot", "L1", "--store", loc]).output().unwrap().stdout).unwrap();
        assert!(text.lines().next().unwrap().starts_with("axis  figure"), "{text}");

        // Compare and control charts run on the stored lots.
        let cmp = json_of(&["store", "compare", "L1", "L2"], loc);
        let row = cmp.as_array().unwrap().iter().find(|r| r["figure"] == "scale_factor").unwrap().clone();
        assert_eq!((row["n1"].as_i64(), row["n2"].as_i64()), (Some(3), Some(2)), "{}", b.name);
        let chart = json_of(&["store", "chart", "--axis", "x", "--figure", "scale_factor"], loc);
        assert_eq!(chart["serials"].as_array().unwrap().len(), 5, "{}", b.name);
        assert_eq!(chart["lots"], serde_json::json!(["L1", "L2"]), "{}", b.name);

        // History as an SVG trend plot.
        let svg = dir.path().join("h.svg");
        gyrolab()
            .args(["store", "history", "S1", "--figure", "scale_factor", "--plot", svg.to_str().unwrap()])
            .args(["--store", loc])
            .assert()
            .success();
        let svg = std::fs::read_to_string(&svg).unwrap();
        assert!(svg.contains("<svg") && svg.contains("History of serial S1"), "{}", b.name);

        // A correction, an approval, a re-evaluation: four revisions of S1, the last current.
        let id = rows[0]["evaluation"].as_i64().unwrap().to_string();
        let out = gyrolab()
            .args(["store", "revise", &id, "--kind", "correction", "--by", "QA", "--reason", "operator misspelt"])
            .args(["--operator", "B. Tester", "--store", loc])
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let corrected = String::from_utf8(out.stdout).unwrap();
        let corrected = corrected.split("as evaluation ").nth(1).unwrap().split(' ').next().unwrap().to_string();
        let shown = json_of(&["store", "show", &corrected], loc);
        assert_eq!(shown["record"]["operator"], "B. Tester");
        assert_eq!(shown["supersedes"].as_i64().unwrap().to_string(), id);
        // The superseded one cannot be revised again (exit 2, nothing stored).
        gyrolab()
            .args(["store", "revise", &id, "--kind", "approval", "--by", "X", "--reason", "y", "--store", loc])
            .assert()
            .code(2)
            .stderr(predicates::str::contains("already superseded"));
        gyrolab()
            .args(["store", "revise", &corrected, "--kind", "approval", "--by", "Dr. A", "--reason", "reviewed"])
            .args(["--store", loc])
            .assert()
            .success();
        let re = dir.path().join("re");
        let latest = *history_ids(loc, "S1").keys().last().unwrap();
        let diff = json_of(
            &[
                "store",
                "reevaluate",
                &latest.to_string(),
                "--out",
                re.to_str().unwrap(),
                "--by",
                "CI",
                "--reason",
                "new version",
            ],
            loc,
        );
        assert_eq!(diff["changes"].as_array().unwrap().len(), 0, "{}: same build, same figures", b.name);
        assert!(re.join("results.json").is_file());
        let ids = history_ids(loc, "S1");
        assert_eq!(ids.len(), 4, "{}: {ids:?}", b.name);
        assert!(ids.values().all(|c| *c == n), "{}: every revision has every figure", b.name);
        let rows = json_of(&["store", "history", "S1"], loc);
        let current: BTreeSet<i64> = rows
            .as_array()
            .unwrap()
            .iter()
            .filter(|r| r["current"] == true)
            .map(|r| r["evaluation"].as_i64().unwrap())
            .collect();
        assert_eq!(current.len(), 1, "{}", b.name);
        assert_eq!(current.first(), ids.keys().last(), "{}", b.name);
        // The lot still counts S1 once.
        let lot = json_of(&["store", "lot", "L1"], loc);
        let sf = lot.as_array().unwrap().iter().find(|r| r["figure"] == "scale_factor").unwrap().clone();
        assert_eq!(sf["statistics"]["n"], 3, "{}", b.name);
    }
}

#[test]
fn every_command_defaults_to_gyrolab_db_in_the_current_folder_or_gyrolab_store() {
    // Issue 53: `eval --store` wrote gyrolab.db beside the plan while `store history` looked in
    // the current folder, so a newcomer's first query said "no store here".
    let dir = tempfile::tempdir().unwrap();
    let plans = dir.path().join("plans");
    let work = dir.path().join("work");
    std::fs::create_dir_all(&plans).unwrap();
    std::fs::create_dir_all(&work).unwrap();
    let p = plan(&plans, "D1", "L");
    for out in ["r", "r2"] {
        gyrolab()
            .current_dir(&work)
            .args(["eval", p.to_str().unwrap(), "--out", dir.path().join(out).to_str().unwrap(), "-q", "--store"])
            .assert()
            .code(3);
    }
    assert!(work.join("gyrolab.db").is_file(), "gyrolab.db in the current folder");
    assert!(!plans.join("gyrolab.db").exists(), "nothing beside the plan");
    // The queries find it without --store, from the same folder.
    let out = gyrolab().current_dir(&work).args(["store", "history", "D1", "--json"]).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let rows: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let ids: std::collections::BTreeSet<i64> =
        rows.as_array().unwrap().iter().map(|r| r["evaluation"].as_i64().unwrap()).collect();
    assert_eq!(ids.len(), 2, "{rows}");
    // store add, without --store, into the same default (a folder of another serial).
    let p3 = plan(&plans, "D3", "L");
    eval(&p3, &dir.path().join("r3"), None);
    gyrolab()
        .current_dir(&work)
        .args(["store", "add", dir.path().join("r3").to_str().unwrap()])
        .assert()
        .success()
        .stdout(predicates::str::contains("in gyrolab.db"));
    gyrolab().current_dir(&work).args(["store", "history", "D3"]).assert().success();
    // GYROLAB_STORE is the default of eval --store and of the queries.
    let env_db = dir.path().join("env.db");
    gyrolab()
        .env("GYROLAB_STORE", &env_db)
        .args(["eval", p.to_str().unwrap(), "--out", dir.path().join("r4").to_str().unwrap(), "-q", "--store"])
        .assert()
        .code(3);
    gyrolab().env("GYROLAB_STORE", &env_db).args(["store", "history", "D1"]).assert().success();
    // store add of an existing folder (the plan named in results.json), into a new store.
    let other = dir.path().join("other.db");
    gyrolab()
        .args(["store", "add", dir.path().join("r").to_str().unwrap(), "--store", other.to_str().unwrap()])
        .assert()
        .success()
        .stdout(predicates::str::contains("as evaluation 1 in"));
}

#[test]
fn two_processes_storing_at_once_both_land() {
    for b in backends("concurrent") {
        let dir = tempfile::tempdir().unwrap();
        // Ten report folders of each serial, each of its own plan (a comment apart), so each its
        // own results.json: the same folder added twice is stored once.
        let mut outs = Vec::new();
        for serial in ["A", "B"] {
            let folders: Vec<PathBuf> = (0..10)
                .map(|i| {
                    let p = plan_with(
                        dir.path(),
                        &format!("{serial}-{i}.toml"),
                        serial,
                        "L",
                        "A. Operator",
                        &format!("# copy {i}\n"),
                    );
                    let out = dir.path().join(format!("r-{serial}-{i}"));
                    eval(&p, &out, None);
                    out
                })
                .collect();
            outs.push(folders);
        }
        // Create the store first for SQLite, so both writers meet an existing file.
        let children: Vec<_> = outs
            .iter()
            .map(|folders| {
                let mut c = gyrolab_process();
                c.args(["store", "add", "--store", &b.location]);
                c.args(folders);
                c.stdout(std::process::Stdio::null()).spawn().unwrap()
            })
            .collect();
        for mut c in children {
            assert!(c.wait().unwrap().success(), "{}", b.name);
        }
        let n = summary_rows(&outs[0][0]);
        for serial in ["A", "B"] {
            let ids = history_ids(&b.location, serial);
            assert_eq!(ids.len(), 10, "{} {serial}", b.name);
            assert!(ids.values().all(|c| *c == n), "{} {serial}: {ids:?}", b.name);
        }
    }
}

#[test]
fn a_process_killed_inside_the_transaction_leaves_nothing_of_its_evaluation() {
    for b in backends("kill") {
        let dir = tempfile::tempdir().unwrap();
        let p = plan(dir.path(), "K", "L");
        // One evaluation stored (of the plan with a comment more: its own results.json); the
        // killed adds try to store the other.
        let other = plan_with(dir.path(), "K-stored.toml", "K", "L", "A. Operator", "# stored first\n");
        eval(&other, &dir.path().join("stored"), Some(&b.location));
        let out = dir.path().join("r");
        eval(&p, &out, None);
        let n = summary_rows(&out);
        for round in 0..2 {
            // The store pauses after writing every row of the evaluation, before the commit.
            let mut child = gyrolab_process()
                .args(["store", "add", out.to_str().unwrap(), "--store", &b.location])
                .env("GYROLAB_STORE_TEST_PAUSE_MS", "60000")
                .stdout(std::process::Stdio::null())
                .stderr(std::process::Stdio::piped())
                .spawn()
                .unwrap();
            let mut err = std::io::BufReader::new(child.stderr.take().unwrap());
            let mut line = String::new();
            err.read_line(&mut line).unwrap();
            assert!(line.contains("pausing 60000 ms inside the transaction"), "{}: {line}", b.name);
            child.kill().unwrap(); // SIGKILL: no handler, no rollback by the process
            child.wait().unwrap();
            let ids = history_ids(&b.location, "K");
            assert_eq!(ids.len(), 1, "{} round {round}: the killed evaluation is not visible: {ids:?}", b.name);
            assert!(ids.values().all(|c| *c == n));
        }
        // The store still takes evaluations (no lock left behind).
        gyrolab().args(["store", "add", out.to_str().unwrap(), "--store", &b.location]).assert().success();
        assert_eq!(history_ids(&b.location, "K").len(), 2, "{}", b.name);
    }
}

#[test]
fn hostile_texts_come_back_verbatim_or_are_refused_clearly() {
    // A plan of over 1 MB (1,100 comment lines of 1,000 characters; a plan line may not exceed 1 MiB).
    let big = format!("# {}\n", "x".repeat(998)).repeat(1100);
    let texts = [
        "'; DROP TABLE evaluation; --",
        "\"quoted\" and 'single' and \\ backslash",
        "Robert'); DELETE FROM figure WHERE (''='",
        "Ünïcødé ∮ 漢字 🚀 \u{202e}rtl\u{202c}",
        "tab\tand newline\nin it",
    ];
    for b in backends("hostile") {
        let dir = tempfile::tempdir().unwrap();
        for (i, t) in texts.iter().enumerate() {
            let p = plan_with(dir.path(), &format!("h{i}.toml"), t, t, t, &format!("\n{big}"));
            let out = dir.path().join(format!("r{i}"));
            let o = gyrolab()
                .args(["eval", p.to_str().unwrap(), "--out", out.to_str().unwrap(), "-q", "--store", &b.location])
                .output()
                .unwrap();
            assert_eq!(o.status.code(), Some(3), "{} {t:?}: {}", b.name, String::from_utf8_lossy(&o.stderr));
            let ids = history_ids(&b.location, t);
            assert_eq!(ids.len(), 1, "{} {t:?}", b.name);
            let id = ids.keys().next().unwrap().to_string();
            let shown = json_of(&["store", "show", &id], &b.location);
            let r = &shown["record"];
            assert_eq!(
                (r["serial"].as_str(), r["lot"].as_str(), r["operator"].as_str()),
                (Some(*t), Some(*t), Some(*t))
            );
            assert!(r["plan_text"].as_str().unwrap().ends_with(&big), "{}: the 1 MB plan comes back", b.name);
            let lot = json_of(&["store", "lot", t], &b.location);
            assert!(!lot.as_array().unwrap().is_empty(), "{} {t:?}", b.name);
        }
        // Every table is still there and holds every evaluation.
        assert_eq!(history_ids(&b.location, texts[0]).len(), 1);
        // A NUL character is refused, naming the field, and nothing is stored.
        let p = plan_with(dir.path(), "nul.toml", "NUL\u{0}SN", "L", "op", "");
        let o = gyrolab()
            .args(["eval", p.to_str().unwrap(), "--out", dir.path().join("rn").to_str().unwrap(), "-q"])
            .args(["--store", &b.location])
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "{}", b.name);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains("NUL"), "{}: {err}", b.name);
        gyrolab().args(["store", "history", "NULSN", "--store", &b.location]).assert().code(2);
    }
}

#[test]
fn bad_stores_exit_2_naming_the_store_without_the_password_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let p = plan(dir.path(), "B1", "L");
    let report = dir.path().join("r");
    // Not SQLite: refused before evaluating, the file and the report folder untouched.
    let junk = dir.path().join("junk.db");
    std::fs::write(&junk, "not sqlite at all").unwrap();
    let o = gyrolab()
        .args(["eval", p.to_str().unwrap(), "--out", report.to_str().unwrap(), "-q", "--store", junk.to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("junk.db") && err.contains("not an SQLite database"), "{err}");
    assert_eq!(std::fs::read_to_string(&junk).unwrap(), "not sqlite at all");
    assert!(!report.exists(), "nothing written");
    for args in [vec!["store", "lot", "L"], vec!["store", "history", "B1"]] {
        gyrolab().args(&args).args(["--store", junk.to_str().unwrap()]).assert().code(2);
    }
    gyrolab()
        .env("GYROLAB_STORE", &junk)
        .args(["store", "lot", "L"])
        .assert()
        .code(2)
        .stderr(predicates::str::contains("junk.db"));
    // A query on a missing store does not create it.
    let missing = dir.path().join("none.db");
    gyrolab().args(["store", "lot", "L", "--store", missing.to_str().unwrap()]).assert().code(2);
    assert!(!missing.exists());
    // A server that is down: exit 2, the URL named with its password masked.
    let o = gyrolab()
        .args(["eval", p.to_str().unwrap(), "--out", report.to_str().unwrap(), "--store"])
        .arg("postgres://lab:hunter2-secret@127.0.0.1:1/db")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let all = format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    assert!(all.contains("postgres://***@127.0.0.1:1/db") && !all.contains("hunter2"), "{all}");
    assert!(!report.exists(), "nothing written");
    // The real server with a wrong password, and with the right one: never printed.
    if let Some(pg) = backends("bad_stores").into_iter().find(|b| b.name == "postgres") {
        let url = pg.location.clone();
        let right = url.split("://").nth(1).unwrap().split('@').next().unwrap().split(':').nth(1).unwrap().to_string();
        let wrong = url.replacen(&format!(":{right}@"), ":wrong-Pa55word@", 1);
        let o = gyrolab().args(["store", "lot", "L", "--store", &wrong]).output().unwrap();
        assert_eq!(o.status.code(), Some(2));
        let all = format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
        assert!(all.contains("://***@") && !all.contains("wrong-Pa55word") && !all.contains(&right), "{all}");
        assert!(all.contains("password"), "{all}");
        let o = gyrolab()
            .args(["eval", p.to_str().unwrap(), "--out", report.to_str().unwrap(), "--store", &url])
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(3));
        let all = format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
        assert!(all.contains("Stored as evaluation") && all.contains("://***@") && !all.contains(&right), "{all}");
    }
}

#[test]
fn a_store_of_a_newer_schema_exits_2_naming_both_versions_and_writes_nothing() {
    for b in backends("cli_newer_schema") {
        let dir = tempfile::tempdir().unwrap();
        let p = plan(dir.path(), "N1", "L");
        eval(&p, &dir.path().join("first"), Some(&b.location));
        mark_newer_schema(&b, 9);
        let report = dir.path().join("second");
        let o = gyrolab()
            .args(["eval", p.to_str().unwrap(), "--out", report.to_str().unwrap(), "-q", "--store", &b.location])
            .output()
            .unwrap_or_else(|e| panic!("{}: {e}", b.name));
        assert_eq!(o.status.code(), Some(2), "{}", b.name);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            err.contains("schema version 9")
                && err.contains(&format!("up to {}", gyrolab_store::schema::SCHEMA_VERSION)),
            "{}: {err}",
            b.name
        );
        assert!(!report.exists(), "{}: nothing written", b.name);
        for args in [vec!["store", "lot", "L"], vec!["store", "history", "N1"]] {
            gyrolab()
                .args(&args)
                .args(["--store", &b.location])
                .assert()
                .code(2)
                .stderr(predicates::str::contains("schema version 9"));
        }
    }
}

/// Every file of folder `a` has the same bytes in folder `b`, and `b` has no other file.
fn same_folder(a: &Path, b: &Path) {
    let names = |d: &Path| -> BTreeSet<String> {
        std::fs::read_dir(d).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect()
    };
    assert_eq!(names(a), names(b), "{} vs {}", a.display(), b.display());
    for n in names(a) {
        assert!(std::fs::read(a.join(&n)).unwrap() == std::fs::read(b.join(&n)).unwrap(), "{n} differs");
    }
}

#[test]
fn the_stored_report_folder_is_written_back_byte_for_byte_also_from_a_revision() {
    for b in backends("cli_report_back") {
        let dir = tempfile::tempdir().unwrap();
        let p = plan(dir.path(), "R1", "L");
        let report = dir.path().join("report");
        eval(&p, &report, Some(&b.location));
        let id = *history_ids(&b.location, "R1").keys().next().unwrap();
        let back = dir.path().join("back");
        gyrolab()
            .args(["store", "report", &id.to_string(), "--out", back.to_str().unwrap(), "--store", &b.location])
            .assert()
            .success();
        same_folder(&report, &back);
        // An approval is a new revision that keeps the same report.
        gyrolab()
            .args(["store", "revise", &id.to_string(), "--kind", "approval", "--by", "Q. Manager"])
            .args(["--reason", "reviewed", "--store", &b.location])
            .assert()
            .success();
        let approved = *history_ids(&b.location, "R1").keys().last().unwrap();
        assert_ne!(approved, id);
        let back2 = dir.path().join("back2");
        gyrolab()
            .args(["store", "report", &approved.to_string(), "--out", back2.to_str().unwrap(), "--store", &b.location])
            .assert()
            .success();
        same_folder(&report, &back2);
        // No such evaluation: exit 2, nothing written.
        let none = dir.path().join("none");
        gyrolab()
            .args(["store", "report", "999999", "--out", none.to_str().unwrap(), "--store", &b.location])
            .assert()
            .code(2)
            .stderr(predicates::str::contains("no evaluation 999999"));
        assert!(!none.exists());
    }
}

/// A store that cannot be made (its folder missing) ends `eval --store` with exit 2 before the
/// report folder is written (issue 53: exit 2 means nothing written), the password of a
/// mistyped URL not echoed.
#[test]
fn an_unusable_store_is_refused_before_the_folder_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let plan = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/paper_plan.toml");
    let out = dir.path().join("report");
    for store in [dir.path().join("no/such/folder/g.db").display().to_string(), "postgress://u:s3cr3t@h/db".to_string()]
    {
        let o = gyrolab().arg("eval").arg(&plan).arg("--out").arg(&out).arg("--store").arg(&store).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(!out.exists(), "{err}");
        assert!(!err.contains("s3cr3t"), "{err}");
    }
}

/// Runs raw SQL on a store behind its back (the store's own user on PostgreSQL, who owns the
/// tables and may disable their triggers).
fn raw_sql(b: &store_backends::Backend, sql: &str) {
    if b.name == "sqlite" {
        rusqlite::Connection::open(&b.location).unwrap().execute_batch(sql).unwrap();
    } else {
        postgres::Client::connect(&b.location, postgres::NoTls).unwrap().batch_execute(sql).unwrap();
    }
}

#[test]
fn store_check_exits_0_when_whole_3_when_tampered_and_writing_is_refused() {
    for b in backends("cli_store_check") {
        let dir = tempfile::tempdir().unwrap();
        let p = plan(dir.path(), "C1", "L");
        eval(&p, &dir.path().join("first"), Some(&b.location));
        let o = gyrolab().args(["store", "check", "--store", &b.location]).output().unwrap();
        let out = String::from_utf8_lossy(&o.stdout).to_string();
        assert_eq!(o.status.code(), Some(0), "{}: {out}{}", b.name, String::from_utf8_lossy(&o.stderr));
        assert!(out.contains("chain head: ") && out.contains("whole") && out.contains("re-hashed equal"), "{out}");
        // A figure turned to FAIL behind the triggers, the triggers put back: the last one stored,
        // so that the quick check (the last links) finds it as well as the full one.
        let forge = "UPDATE figure SET verdict = 'FAIL' WHERE id = (SELECT MAX(id) FROM figure);";
        if b.name == "sqlite" {
            let (_, _, create) = gyrolab_store::chain::expected_triggers(false)
                .into_iter()
                .find(|(_, n, _)| n == "figure_kept")
                .unwrap();
            raw_sql(&b, &format!("DROP TRIGGER figure_kept; {forge} {create};"));
        } else {
            raw_sql(
                &b,
                &format!("ALTER TABLE figure DISABLE TRIGGER figure_kept; {forge} ALTER TABLE figure ENABLE TRIGGER figure_kept;"),
            );
        }
        let o = gyrolab().args(["store", "check", "--store", &b.location]).output().unwrap();
        let all = format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
        assert_eq!(o.status.code(), Some(3), "{}: {all}", b.name);
        assert!(all.contains("BROKEN: figure row ") && all.contains("verdict"), "{}: {all}", b.name);
        // Writing is refused before anything is written (the quick check): exit 2.
        let out = dir.path().join("second");
        let o = gyrolab()
            .args(["eval", p.to_str().unwrap(), "--out", out.to_str().unwrap(), "--store", &b.location])
            .output()
            .unwrap();
        let all = format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
        assert_eq!(o.status.code(), Some(2), "{}: {all}", b.name);
        assert!(all.contains("quick check") && all.contains("figure"), "{}: {all}", b.name);
        assert!(!out.exists(), "{}: nothing written", b.name);
        let o = gyrolab()
            .args(["store", "add", dir.path().join("first").to_str().unwrap(), "--store", &b.location])
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "{}", b.name);
    }
}

#[test]
fn store_urls_never_show_a_password_nor_become_files() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (
            "postgres://odd:p@ss:w/rd?x#y%@127.0.0.1:1/db",
            &["p@ss", "ss:w", "w/rd", "rd?x", "x#y"][..],
            "postgres://***@127.0.0.1:1/db",
        ),
        ("POSTGRES://lab:Secr3tPw@127.0.0.1:1/db", &["Secr3tPw"][..], "postgres://***@127.0.0.1:1/db"),
        ("postgress://lab:Secr3tPw@127.0.0.1:1/db", &["Secr3tPw"][..], "'postgress'"),
        ("postgre://lab:Secr3tPw@127.0.0.1:1/db", &["Secr3tPw"][..], "'postgre'"),
        ("host=127.0.0.1 port=1 dbname=db user=lab password=Secr3tPw", &["Secr3tPw"][..], "password=***"),
        ("lab.db password=Secr3tPw", &["Secr3tPw"][..], "not taken as a file name"),
    ];
    for (location, secrets, shown) in cases {
        for args in [&["store", "lot", "L"][..], &["store", "check"][..]] {
            let o = gyrolab().current_dir(dir.path()).args(args).args(["--store", location]).output().unwrap();
            let all = format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
            assert_eq!(o.status.code(), Some(2), "{location}: {all}");
            assert!(all.contains(shown), "{location}: {all}");
            for s in secrets {
                assert!(!all.contains(s), "{location}: {s} in {all}");
            }
        }
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0, "{location}: no file made");
    }
}

/// `store add` takes the report as its manifest lists it (issue 53): a leftover `.gyrolab-*.tmp`
/// of a killed run is not stored, and an output edited after the folder was written refuses
/// the folder (exit 2, the file named), nothing stored.
#[test]
fn store_add_takes_the_manifest_files_and_refuses_an_edited_folder() {
    let dir = tempfile::tempdir().unwrap();
    let plan = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/paper_plan.toml");
    let out = dir.path().join("report");
    gyrolab().arg("eval").arg(&plan).arg("--out").arg(&out).arg("-q").assert().code(3);
    std::fs::write(out.join(".gyrolab-leftover.tmp"), b"half a file").unwrap();
    let db = dir.path().join("g.db");
    gyrolab().args(["store", "add"]).arg(&out).arg("--plan").arg(&plan).arg("--store").arg(&db).assert().success();
    let back = dir.path().join("back");
    gyrolab().args(["store", "report", "1", "--out"]).arg(&back).arg("--store").arg(&db).assert().success();
    assert!(back.join("manifest.json").exists() && !back.join(".gyrolab-leftover.tmp").exists());
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    std::fs::write(out.join("report.html"), html.replacen("FAIL", "PASS", 1)).unwrap();
    let db2 = dir.path().join("g2.db");
    let o =
        gyrolab().args(["store", "add"]).arg(&out).arg("--plan").arg(&plan).arg("--store").arg(&db2).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("report.html") && err.contains("changed since the report was written"), "{err}");
}

/// A FIFO or a folder given as the store is refused at once (issue 53: a FIFO hung `eval`,
/// `store history` and `store add`), exit 2, nothing written.
#[cfg(unix)]
#[test]
fn a_fifo_or_a_folder_as_the_store_is_refused_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("store.db");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status().map(|s| s.success()).unwrap_or(false);
    let mut stores = vec![dir.path().to_path_buf()];
    if made {
        stores.push(fifo);
    } else {
        eprintln!("SKIPPED: the FIFO case of a_fifo_or_a_folder_as_the_store_is_refused_at_once: mkfifo failed");
    }
    for store in stores {
        let started = std::time::Instant::now();
        let o = gyrolab()
            .args(["store", "history", "SN1", "--store"])
            .arg(&store)
            .timeout(std::time::Duration::from_secs(20))
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{}: {err}", store.display());
        assert!(err.contains("not a regular file"), "{err}");
        assert!(started.elapsed() < std::time::Duration::from_secs(5), "{:?}", started.elapsed());
    }
}

/// Control characters in stored text (issue 53: an escape sequence in a lot or operator name
/// reached the terminal raw through `store show`): the text tables print them as `\u{1b}`,
/// the JSON keeps them exactly (escaped by JSON itself).
#[test]
fn control_characters_in_stored_text_never_reach_the_terminal_raw() {
    let dir = tempfile::tempdir().unwrap();
    let store = dir.path().join("s.db").display().to_string();
    let evil = "L7\u{1b}[2J\u{1b}[31mRED\u{7}";
    let p = plan_with(dir.path(), "c.toml", "SN-C", evil, evil, "");
    let out = dir.path().join("r");
    let o = gyrolab()
        .args(["eval", p.to_str().unwrap(), "--out", out.to_str().unwrap(), "-q", "--store", &store])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(3), "{}", String::from_utf8_lossy(&o.stderr));
    let id = history_ids(&store, "SN-C").keys().next().unwrap().to_string();
    for args in [vec!["store", "show", id.as_str()], vec!["store", "history", "SN-C"], vec!["store", "lot", evil]] {
        let o = gyrolab().args(&args).args(["--store", &store]).output().unwrap();
        let text = String::from_utf8_lossy(&o.stdout);
        assert!(o.status.success(), "{args:?}: {}", String::from_utf8_lossy(&o.stderr));
        assert!(!text.contains('\u{1b}') && !text.contains('\u{7}'), "{args:?}: a raw control character");
        if args[1] == "show" {
            assert!(text.contains("L7\\u{1b}[2J\\u{1b}[31mRED\\u{7}"), "{text}");
        }
    }
    let shown = json_of(&["store", "show", &id], &store);
    assert_eq!(shown["record"]["lot"].as_str(), Some(evil), "JSON keeps the text exactly");
}

/// Re-adding a report folder is idempotent (issue 53: it made a second current original): the
/// second `store add` says where it is stored already, exit 0, and the serial still has one
/// evaluation; on SQLite and PostgreSQL.
#[test]
fn adding_the_same_folder_again_adds_nothing() {
    for b in backends("readd") {
        let dir = tempfile::tempdir().unwrap();
        let p = plan(dir.path(), "RE-ADD", "L1");
        let out = dir.path().join("r");
        eval(&p, &out, None);
        let first = gyrolab().args(["store", "add", out.to_str().unwrap(), "--store", &b.location]).output().unwrap();
        assert!(first.status.success(), "{}: {}", b.name, String::from_utf8_lossy(&first.stderr));
        let again = gyrolab().args(["store", "add", out.to_str().unwrap(), "--store", &b.location]).output().unwrap();
        let said = String::from_utf8_lossy(&again.stdout);
        assert!(again.status.success(), "{}: {}", b.name, String::from_utf8_lossy(&again.stderr));
        assert!(
            said.contains("is stored already as evaluation") && said.contains("nothing added"),
            "{}: {said}",
            b.name
        );
        assert_eq!(history_ids(&b.location, "RE-ADD").len(), 1, "{}", b.name);
    }
}

/// The stored U and k are the report's (issue 53: k was stored as 3, the repeatability factor,
/// for a U computed with k = 2, and U was empty for K, B_s and K_a): on the example test
/// program, every figure the uncertainty section gives a U carries it with its budget's k.
#[test]
fn the_stored_uncertainties_are_the_reports() {
    let dir = tempfile::tempdir().unwrap();
    let prog = dir.path().join("prog");
    gyrolab().args(["simulate", "test-program"]).arg(&prog).assert().success();
    let out = dir.path().join("r");
    let store = dir.path().join("s.db").display().to_string();
    let o = gyrolab()
        .args(["eval", prog.join("plan.toml").to_str().unwrap(), "--out", out.to_str().unwrap(), "-q"])
        .args(["--store", &store])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let results: serde_json::Value = serde_json::from_slice(&std::fs::read(out.join("results.json")).unwrap()).unwrap();
    let u = &results["sections"]["uncertainty"]["x"];
    let id = history_ids(&store, "SIM-0001").keys().next().copied().unwrap_or(1).to_string();
    let shown = json_of(&["store", "show", &id], &store);
    let figures = shown["record"]["figures"].as_array().unwrap();
    let find = |name: &str| {
        figures.iter().find(|f| f["axis"] == "x" && f["figure"] == name).unwrap_or_else(|| panic!("{name}"))
    };
    for (figure, key, budget) in [
        ("scale_factor", "scale_factor_expanded", Some("scale_factor")),
        ("bias_stability_dph_10s", "bias_stability_expanded_dph", Some("bias_stability")),
        ("nonlinearity_pct", "nonlinearity_pct_expanded_uncertainty", None),
        ("bias_thermal_hysteresis_dph", "bias_thermal_hysteresis_dph_expanded_uncertainty", None),
    ] {
        let f = find(figure);
        assert_eq!(f["expanded_uncertainty"].as_f64(), u[key].as_f64(), "{figure}: {f}");
        let k = budget.map_or(&u["coverage_factor"], |b| &u["budgets"][b]["coverage_factor"]);
        assert_eq!(f["coverage_factor"].as_f64(), k.as_f64(), "{figure}: {f}");
        assert_eq!(f["coverage_factor"].as_f64(), Some(2.0), "{figure}");
    }
}

/// A long serial is stored on both back ends (issue 53: PostgreSQL refused a serial over about
/// 2.7 KB, the row limit of a B-tree index, where SQLite takes it; schema 5 makes the serial and
/// lot indexes hash indexes there): a 100,000-character serial and lot come back exactly.
#[test]
fn a_long_serial_is_stored_on_both_back_ends() {
    let serial = format!("SN-{}", "7".repeat(100_000));
    for b in backends("longserial") {
        let dir = tempfile::tempdir().unwrap();
        let p = plan_with(dir.path(), "long.toml", &serial, &serial, "A. Operator", "");
        let out = dir.path().join("r");
        let o = gyrolab()
            .args(["eval", p.to_str().unwrap(), "--out", out.to_str().unwrap(), "-q", "--store", &b.location])
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(3), "{}: {}", b.name, String::from_utf8_lossy(&o.stderr));
        let ids = history_ids(&b.location, &serial);
        assert_eq!(ids.len(), 1, "{}", b.name);
        let id = ids.keys().next().unwrap().to_string();
        let shown = json_of(&["store", "show", &id], &b.location);
        assert_eq!(shown["record"]["serial"].as_str(), Some(serial.as_str()), "{}", b.name);
        let lot = json_of(&["store", "lot", &serial], &b.location);
        assert!(!lot.as_array().unwrap().is_empty(), "{}", b.name);
    }
}

/// The paper's three rate-table records copied into `data` (which exists).
fn copy_paper_records(data: &Path) {
    for axis in ["x", "y", "z"] {
        let name = format!("paper_rate_table_{axis}.csv");
        std::fs::copy(repo().join("data/paper").join(&name), data.join(&name)).unwrap();
    }
}

#[test]
fn the_raw_records_are_kept_and_a_report_is_reproduced_from_the_store_alone() {
    // Issue 53: "Raw records are hashed, not kept"; "paths are stored relative to the working
    // folder, so store reevaluate fails from another folder".
    let dir = tempfile::tempdir().unwrap();
    let lab = dir.path().join("lab");
    let data = lab.join("data");
    std::fs::create_dir_all(&data).unwrap();
    copy_paper_records(&data);
    let plans = lab.join("plans");
    std::fs::create_dir_all(&plans).unwrap();
    let text = std::fs::read_to_string(repo().join("examples/paper_plan.toml")).unwrap();
    std::fs::write(plans.join("plan.toml"), text.replace("../data/paper/", "../data/")).unwrap();
    let db = dir.path().join("lab.db");
    gyrolab()
        .current_dir(&lab)
        .args(["eval", "plans/plan.toml", "--out", "report", "-q", "--store", db.to_str().unwrap()])
        .assert()
        .code(3);
    // The plan and its raw records out of the store, as they stood relative to the plan.
    let audit = dir.path().join("audit");
    gyrolab()
        .args(["store", "report", "1", "--inputs", "--out", audit.to_str().unwrap(), "--store", db.to_str().unwrap()])
        .assert()
        .success()
        .stdout(predicates::str::contains("3 raw record(s)"));
    assert_eq!(std::fs::read(audit.join("_/plan.toml")).unwrap(), std::fs::read(plans.join("plan.toml")).unwrap());
    for axis in ["x", "y", "z"] {
        let name = format!("paper_rate_table_{axis}.csv");
        assert_eq!(std::fs::read(audit.join("data").join(&name)).unwrap(), std::fs::read(data.join(&name)).unwrap());
    }
    // The restored plan evaluates to the same figures.
    gyrolab()
        .args([
            "eval",
            audit.join("_/plan.toml").to_str().unwrap(),
            "--out",
            dir.path().join("again").to_str().unwrap(),
        ])
        .arg("-q")
        .assert()
        .code(3);
    assert_eq!(
        std::fs::read_to_string(dir.path().join("again/summary.csv")).unwrap(),
        std::fs::read_to_string(lab.join("report/summary.csv")).unwrap()
    );
    // The lab's folders gone: re-evaluated from another folder, from the store alone.
    std::fs::remove_dir_all(&lab).unwrap();
    let out = gyrolab()
        .current_dir(dir.path())
        .args(["store", "reevaluate", "1", "--out", "re", "--by", "CI", "--reason", "audit", "--json"])
        .args(["--store", db.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let r: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(r["changes"].as_array().unwrap().len(), 0, "{r}");
    assert_eq!(r["revision"], 2);
}

#[test]
fn store_grant_gives_a_postgres_role_select_and_insert_and_refuses_an_sqlite_file() {
    for b in backends("cli_grant") {
        let dir = tempfile::tempdir().unwrap();
        eval(&plan(dir.path(), "G1", "L"), &dir.path().join("r"), Some(&b.location));
        let out = gyrolab().args(["store", "grant", "gyrolab_app", "--store", &b.location]).output().unwrap();
        let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
        if b.name == "sqlite" {
            assert_eq!(out.status.code(), Some(2), "{stderr}");
            assert!(stderr.contains("file permissions"), "{stderr}");
        } else {
            assert!(out.status.success(), "{stderr}");
            assert!(stdout.contains("SELECT and INSERT") && !stdout.contains("gyrolab-test-"), "{stdout}");
        }
    }
}

/// Lot Q of the store's own test (issue 53), stored through the store crate: D1-D5 values of
/// bias_dph 9.8, 10.1, 10.0, 9.9, 10.2 and D6 NOT EVALUATED (limits 9 .. 11); resolution_dps
/// upper bounds 0.0125, 0.02 on D1, D2, a value 0.03 on D3 and no row on D4-D6 (upper limit 0.0625).
fn store_lot_q(location: &str) {
    use gyrolab_store::record::FigureRecord;
    let row = |key: &str, unit: &str, value: Option<f64>, basis: &str, lo: Option<f64>, hi: f64, verdict: &str| {
        FigureRecord {
            axis: "x".into(),
            figure: key.into(),
            value,
            unit: unit.into(),
            basis: basis.into(),
            expanded_uncertainty: None,
            coverage_factor: None,
            limit_min: lo,
            limit_max: Some(hi),
            verdict: Some(verdict.into()),
            simulated: false,
        }
    };
    let mut s = gyrolab_store::Store::open(location, true).unwrap();
    let bias = [Some(9.8), Some(10.1), Some(10.0), Some(9.9), Some(10.2), None];
    for (i, v) in bias.into_iter().enumerate() {
        let mut r = store_backends::record(&format!("D{}", i + 1), Some("Q"), &[]);
        r.test_date = Some(format!("2026-11-{:02}", i + 1));
        let verdict = if v.is_some() { "PASS" } else { "NOT EVALUATED" };
        r.figures.push(row("bias_dph", "deg/h", v, "value", Some(9.0), 11.0, verdict));
        match i {
            0 => r.figures.push(row("resolution_dps", "deg/s", Some(0.0125), "upper_bound", None, 0.0625, "PASS")),
            1 => r.figures.push(row("resolution_dps", "deg/s", Some(0.02), "upper_bound", None, 0.0625, "PASS")),
            2 => r.figures.push(row("resolution_dps", "deg/s", Some(0.03), "value", None, 0.0625, "PASS")),
            _ => {}
        }
        s.add(&r).unwrap();
    }
}

#[test]
fn a_store_file_damaged_past_its_header_is_refused_and_nothing_written() {
    // Issue 53: "A corrupt SQLite file (4 KiB of flipped bytes) accepts new evaluations (only its
    // 16-byte header is checked)". Every page is now read by SQLite's quick check before a write.
    let dir = tempfile::tempdir().unwrap();
    let db = dir.path().join("s.db");
    for i in 0..4 {
        eval(&plan(dir.path(), &format!("C{i}"), "L"), &dir.path().join(format!("r{i}")), Some(db.to_str().unwrap()));
    }
    let bytes = std::fs::read(&db).unwrap();
    let pages = bytes.len() / 4096;
    assert!(pages >= 8, "{pages} pages");
    // 4 KiB of flipped bytes at the second page, the middle and the last page but one.
    for page in [1, pages / 2, pages - 2] {
        let mut b = bytes.clone();
        b[page * 4096..(page + 1) * 4096].iter_mut().enumerate().for_each(|(i, x)| *x ^= 1 + (i % 255) as u8);
        let damaged = dir.path().join(format!("damaged-{page}.db"));
        std::fs::write(&damaged, &b).unwrap();
        let out = dir.path().join(format!("out-{page}"));
        let started = std::time::Instant::now();
        let o = gyrolab()
            .args(["eval", plan(dir.path(), "C9", "L").to_str().unwrap(), "--out", out.to_str().unwrap(), "-q"])
            .args(["--store", damaged.to_str().unwrap()])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "page {page}: {err}");
        assert!(err.contains("damaged") || err.contains("malformed"), "page {page}: {err}");
        assert!(!out.exists(), "page {page}: nothing written");
        eprintln!("page {page}: refused in {:?}", started.elapsed());
        // store check says so: exit 3 (named) or 2 (not even openable), never 0.
        let c = gyrolab().args(["store", "check", "--store", damaged.to_str().unwrap()]).output().unwrap();
        assert!(matches!(c.status.code(), Some(2) | Some(3)), "page {page}: {:?}", c.status);
        assert_eq!(std::fs::read(&damaged).unwrap(), b, "page {page}: the damaged file left as it was");
    }
}

#[test]
fn two_revisions_of_one_evaluation_at_once_one_lands_the_other_is_refused_clearly() {
    // Issue 53: "Two concurrent store revise of one evaluation on PostgreSQL give a raw
    // duplicate key error, exit 1." Both processes hold their transaction open 300 ms
    // (GYROLAB_STORE_TEST_PAUSE_MS), so the second meets the first's revision inside its lock.
    for b in backends("concurrent_revise") {
        let dir = tempfile::tempdir().unwrap();
        eval(&plan(dir.path(), "R1", "L"), &dir.path().join("r"), Some(&b.location));
        let children: Vec<_> = ["LOT-A", "LOT-B"]
            .iter()
            .map(|lot| {
                let mut c = gyrolab_process();
                c.env("GYROLAB_STORE_TEST_PAUSE_MS", "300");
                c.args(["store", "revise", "1", "--kind", "correction", "--by", "QA", "--reason", "lot", "--lot", lot]);
                c.args(["--store", &b.location]);
                c.stdout(std::process::Stdio::piped()).stderr(std::process::Stdio::piped()).spawn().unwrap()
            })
            .collect();
        let outs: Vec<_> = children.into_iter().map(|c| c.wait_with_output().unwrap()).collect();
        let codes: Vec<Option<i32>> = outs.iter().map(|o| o.status.code()).collect();
        let errs: Vec<String> = outs.iter().map(|o| String::from_utf8_lossy(&o.stderr).into_owned()).collect();
        assert!(codes.contains(&Some(0)) && codes.contains(&Some(2)), "{}: {codes:?} {errs:?}", b.name);
        let refused = &errs[codes.iter().position(|c| *c == Some(2)).unwrap()];
        assert!(refused.contains("already superseded by 2"), "{}: {refused}", b.name);
        assert!(!refused.contains("duplicate key") && !refused.contains("UNIQUE"), "{}: {refused}", b.name);
        let ids = history_ids(&b.location, "R1");
        assert_eq!(ids.keys().copied().collect::<Vec<_>>(), [1, 2], "{}: one revision landed", b.name);
    }
}

#[test]
fn inputs_named_by_absolute_paths_are_reevaluated_from_the_store_and_still_named_so() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("data");
    std::fs::create_dir_all(&data).unwrap();
    copy_paper_records(&data);
    let text = std::fs::read_to_string(repo().join("examples/paper_plan.toml")).unwrap();
    // The plan in a folder of its own: its inputs are outside it, named absolutely.
    std::fs::create_dir_all(dir.path().join("plans")).unwrap();
    let plan = dir.path().join("plans/plan.toml");
    std::fs::write(&plan, text.replace("../data/paper/", &format!("{}/", data.display()))).unwrap();
    let db = dir.path().join("lab.db");
    eval(&plan, &dir.path().join("r"), Some(db.to_str().unwrap()));
    let audit = dir.path().join("audit");
    gyrolab()
        .args(["store", "report", "1", "--inputs", "--out", audit.to_str().unwrap(), "--store", db.to_str().unwrap()])
        .assert()
        .success()
        .stdout(predicates::str::contains("by an absolute path"));
    std::fs::remove_dir_all(&data).unwrap();
    let re = dir.path().join("re");
    let out = gyrolab()
        .args(["store", "reevaluate", "1", "--out", re.to_str().unwrap(), "--by", "CI", "--reason", "audit", "--json"])
        .args(["--store", db.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let r: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(r["changes"].as_array().unwrap().len(), 0, "{r}");
    let results: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(re.join("results.json")).unwrap()).unwrap();
    let named: Vec<&str> =
        results["integrity"]["inputs"].as_array().unwrap().iter().map(|i| i["file"].as_str().unwrap()).collect();
    assert_eq!(named, ["x", "y", "z"].map(|a| format!("{}/paper_rate_table_{a}.csv", data.display())), "{named:?}");
}

#[test]
fn store_lot_shows_devices_bounds_not_evaluated_and_the_few_values_warning() {
    for b in backends("lot_output") {
        let loc = b.location.as_str();
        store_lot_q(loc);
        // JSON: the counts, the yield over every device, the notes.
        let lot = json_of(&["store", "lot", "Q"], loc);
        let rows = lot.as_array().unwrap();
        let by = |k: &str| rows.iter().find(|r| r["figure"] == k).unwrap().clone();
        let bias = by("bias_dph");
        assert_eq!(
            (&bias["n_devices"], &bias["n_evaluated"], &bias["n_bounds"], &bias["n_not_evaluated"]),
            (&serde_json::json!(6), &serde_json::json!(5), &serde_json::json!(0), &serde_json::json!(1)),
            "{}: {bias}",
            b.name
        );
        assert_eq!(bias["statistics"]["n"], 5);
        assert_eq!(bias["statistics"]["yield_fraction"], 1.0, "among the values");
        assert_eq!(bias["yield_devices"].as_f64(), Some(5.0 / 6.0), "over every device");
        let notes: Vec<&str> = bias["warnings"].as_array().unwrap().iter().map(|w| w.as_str().unwrap()).collect();
        assert!(notes.iter().any(|w| w.starts_with("capability from n = 5 values, fewer than 25")), "{notes:?}");
        assert!(notes.contains(&"1 device NOT EVALUATED (no value, or the verdict NOT EVALUATED): D6"), "{notes:?}");
        let res = by("resolution_dps");
        assert_eq!(
            (res["n_devices"].as_i64(), res["n_bounds"].as_i64(), res["n_missing"].as_i64()),
            (Some(6), Some(2), Some(3))
        );
        assert_eq!(res["statistics"]["mean"], 0.03, "{}: the bounds are not averaged", b.name);
        assert_eq!(res["largest_upper_bound"], 0.02);
        assert!(res["statistics"]["ppk"].is_null() && res["statistics"]["sd"].is_null());

        // CSV: the count columns and the notes, one row per figure.
        let out = gyrolab().args(["store", "lot", "Q", "--csv", "--store", loc]).output().unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let csv = String::from_utf8(out.stdout).unwrap();
        let head: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
        let line = csv.lines().find(|l| l.starts_with("x,bias_dph,")).unwrap();
        let col = |k: &str| head.iter().position(|h| *h == k).unwrap();
        let f: Vec<&str> = line.splitn(head.len(), ',').collect();
        assert_eq!((f[col("n")], f[col("n_devices")], f[col("n_not_evaluated")]), ("5", "6", "1"), "{csv}");
        assert_eq!(f[col("yield")].parse::<f64>().unwrap(), 5.0 / 6.0, "{csv}");
        assert_eq!(f[col("yield_evaluated")], "1", "{csv}");
        let notes = line.rsplit_once(",\"").map(|(_, n)| n).unwrap_or_default();
        assert!(notes.contains("fewer than 25") && notes.contains("D6"), "{csv}");
        let res = csv.lines().find(|l| l.starts_with("x,resolution_dps,")).unwrap();
        assert!(res.contains("2 devices give only an upper bound (each at most 0.02 deg/s"), "{csv}");

        // Text: the table without the notes column, then the notes and what n and yield mean.
        let out = gyrolab().args(["store", "lot", "Q", "--store", loc]).output().unwrap();
        let text = String::from_utf8(out.stdout).unwrap();
        let header = text.lines().next().unwrap();
        assert!(
            header.contains("n_devices") && header.contains("n_not_evaluated") && !header.contains("notes"),
            "{text}"
        );
        assert!(text.contains("\nnotes:\n"), "{text}");
        assert!(text.contains("  x bias_dph: capability from n = 5 values, fewer than 25"), "{text}");
        assert!(text.contains("  x resolution_dps: 3 devices without this figure"), "{text}");
        assert!(text.contains("yield: conforming devices / n_devices"), "{text}");

        // A chart says on standard error what it leaves out; its JSON has the counts.
        let out = gyrolab()
            .args(["store", "chart", "--axis", "x", "--figure", "bias_dph", "--lot", "Q"])
            .args(["--store", loc])
            .output()
            .unwrap();
        assert!(out.status.success());
        let err = String::from_utf8(out.stderr).unwrap();
        assert!(err.contains("note: 1 device NOT EVALUATED") && err.contains("no point"), "{err}");
        let chart = json_of(&["store", "chart", "--axis", "x", "--figure", "bias_dph", "--lot", "Q"], loc);
        assert_eq!((chart["n_devices"].as_i64(), chart["n_not_evaluated"].as_i64()), (Some(6), Some(1)));
        assert_eq!(chart["serials"].as_array().unwrap().len(), 5);
    }
}

#[test]
fn the_same_eval_store_run_twice_is_stored_as_a_reevaluation_and_said_so() {
    // Issue 53: "running the same eval --store twice stores a second current evaluation without a
    // word". The second run supersedes the first (kind reevaluation) and says so, even with -q.
    let dir = tempfile::tempdir().unwrap();
    let p = plan(dir.path(), "T1", "L");
    let db = dir.path().join("s.db");
    eval(&p, &dir.path().join("r1"), Some(db.to_str().unwrap()));
    let o = gyrolab()
        .args(["eval", p.to_str().unwrap(), "--out", dir.path().join("r2").to_str().unwrap(), "-q"])
        .args(["--store", db.to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(3));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("a re-evaluation of evaluation 1"), "{err}");
    let rows = json_of(&["store", "history", "T1"], db.to_str().unwrap());
    let current: BTreeSet<i64> = rows
        .as_array()
        .unwrap()
        .iter()
        .filter(|r| r["current"] == true)
        .map(|r| r["evaluation"].as_i64().unwrap())
        .collect();
    assert_eq!(current.into_iter().collect::<Vec<_>>(), [2], "one current evaluation");
    let e = json_of(&["store", "show", "2"], db.to_str().unwrap());
    assert_eq!(e["revision_kind"], "reevaluation", "{e}");
    // Another plan of the same serial (a comment apart: another SHA-256) is a new original.
    let p2 = plan_with(dir.path(), "T1b.toml", "T1", "L", "A. Operator", "# another plan\n");
    eval(&p2, &dir.path().join("r3"), Some(db.to_str().unwrap()));
    let e = json_of(&["store", "show", "3"], db.to_str().unwrap());
    assert_eq!((e["revision_kind"].as_str(), e["supersedes"].as_i64()), (Some("original"), None), "{e}");
    // store add of another folder of the first plan (evaluated again without --store): the
    // re-evaluation of evaluation 2, said so.
    std::thread::sleep(std::time::Duration::from_millis(1100)); // another `created` second
    eval(&p, &dir.path().join("r4"), None);
    gyrolab()
        .args(["store", "add", dir.path().join("r4").to_str().unwrap(), "--store", db.to_str().unwrap()])
        .assert()
        .success()
        .stdout(predicates::str::contains("a re-evaluation of evaluation 2"));
}
