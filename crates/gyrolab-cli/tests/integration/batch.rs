//! `gyrolab batch` end to end: a broken file among good ones, the results against single
//! `gyrolab allan --json` runs, resuming after a kill, and a journal of other options refused.

use crate::common;
use common::{gyrolab, write};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn simulate(dir: &Path, name: &str, seed: u64) -> PathBuf {
    let p = dir.join(name);
    gyrolab()
        .args(["simulate", "static", "--duration-s", "300", "--sample-rate-hz", "50", "--arw-deg-rt-h", "0.3"])
        .args(["--bias-instability-dph", "5", "--seed", &seed.to_string()])
        .arg("--out")
        .arg(&p)
        .assert()
        .success();
    p
}

/// The results CSV as rows of column name -> text (no quoted commas in these records).
fn results(out: &Path) -> Vec<BTreeMap<String, String>> {
    let text = std::fs::read_to_string(out.join("results.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    lines.map(|l| header.iter().cloned().zip(l.split(',').map(String::from)).collect()).collect()
}

fn num(row: &BTreeMap<String, String>, key: &str) -> Option<f64> {
    row.get(key).filter(|t| !t.is_empty()).map(|t| t.parse().unwrap())
}

/// Equal to the last bit, but for the one unit in the last place serde_json's float parser
/// (without its float_roundtrip feature) may differ by.
fn same(a: Option<f64>, b: Option<f64>) -> bool {
    match (a, b) {
        (Some(a), Some(b)) => (a - b).abs() <= 2.0 * f64::EPSILON * a.abs().max(b.abs()),
        (a, b) => a == b,
    }
}

#[test]
fn a_broken_file_among_good_ones_is_named_and_the_rest_are_evaluated() {
    let dir = tempfile::tempdir().unwrap();
    let fleet = dir.path().join("fleet");
    std::fs::create_dir_all(fleet.join("unit2")).unwrap();
    let good = [simulate(&fleet, "unit1.csv", 1), simulate(&fleet.join("unit2"), "static.csv", 2)];
    write(&fleet, "broken.csv", "time_s,rate_dps\n0,0.1\n0.02,zero point one\n0.04,0.1\n");
    write(&fleet, "notes.md", "not a record: passed over by its name");
    let out = dir.path().join("out");
    let run = gyrolab().arg("batch").arg(&fleet).arg("--out").arg(&out).assert().code(4);
    let stderr = String::from_utf8_lossy(&run.get_output().stderr).to_string();
    let stdout = String::from_utf8_lossy(&run.get_output().stdout).to_string();
    // One line naming the file and the line of the bad value, then the count.
    let failed: Vec<&str> = stderr.lines().filter(|l| l.starts_with("failed: ")).collect();
    assert_eq!(failed.len(), 1, "{stderr}");
    assert!(failed[0].contains("broken.csv") && failed[0].contains('3'), "{stderr}");
    assert!(stderr.contains("1 of 3 inputs failed"), "{stderr}");
    assert!(stdout.contains("3 inputs: 2 evaluated now, 0 already done"), "{stdout}");
    assert!(stdout.contains("arw_deg_rt_h"), "{stdout}");
    assert!(stdout.contains("SIMULATED: 2 of 2 rows"), "{stdout}");
    let rows = results(&out);
    let files: BTreeSet<String> = rows.iter().map(|r| r["file"].clone()).collect();
    let expected: BTreeSet<String> = good.iter().map(|p| p.display().to_string()).collect();
    assert_eq!(files, expected);
    assert!(rows.iter().all(|r| r["simulated"].starts_with("SIMULATED: gyrolab simulated static record")));
    let failures = std::fs::read_to_string(out.join("failures.csv")).unwrap();
    assert!(failures.contains("broken.csv") && failures.lines().count() == 2, "{failures}");
    assert!(std::fs::metadata(out.join("results.parquet")).unwrap().len() > 100);

    // Started again: the good ones are passed over by their hash, the broken one tried again.
    let run = gyrolab().arg("batch").arg(&fleet).arg("--out").arg(&out).assert().code(4);
    let stdout = String::from_utf8_lossy(&run.get_output().stdout).to_string();
    assert!(stdout.contains("3 inputs: 0 evaluated now, 2 already done (journal)"), "{stdout}");
    assert_eq!(results(&out), rows);

    // Fixed: exit 0 and the list of failures gone.
    write(&fleet, "broken.csv", "time_s,rate_dps\n0,0.1\n0.02,0.2\n0.04,0.1\n0.06,0.3\n");
    let run = gyrolab().arg("batch").arg(&fleet).arg("--out").arg(&out).assert().success();
    let stdout = String::from_utf8_lossy(&run.get_output().stdout).to_string();
    assert!(stdout.contains("3 inputs: 1 evaluated now, 2 already done"), "{stdout}");
    assert!(!out.join("failures.csv").exists());
    assert_eq!(results(&out).len(), 3);
}

#[test]
fn results_equal_those_of_single_allan_runs() {
    let dir = tempfile::tempdir().unwrap();
    let records: Vec<PathBuf> = (0..3).map(|i| simulate(dir.path(), &format!("r{i}.csv"), 10 + i)).collect();
    // A copy under another name: the same bytes, evaluated once.
    std::fs::copy(&records[0], dir.path().join("copy.csv")).unwrap();
    let out = dir.path().join("out");
    let run =
        gyrolab().arg("batch").arg(dir.path().join("*.csv")).arg("--out").arg(&out).arg("--jobs").arg("2").assert();
    let stdout = String::from_utf8_lossy(&run.success().get_output().stdout).to_string();
    assert!(stdout.contains("4 inputs: 3 evaluated now, 0 already done (journal), 1 same bytes"), "{stdout}");
    let rows = results(&out);
    assert_eq!(rows.len(), 3);
    for r in &records {
        let single = gyrolab().arg("allan").arg(r).arg("--json").assert().success().get_output().stdout.clone();
        let j: serde_json::Value = serde_json::from_slice(&single).unwrap();
        // r0 and its copy have the same bytes: whichever a worker reached first was evaluated.
        let copy = dir.path().join("copy.csv").display().to_string();
        let row = rows
            .iter()
            .find(|x| x["file"] == r.display().to_string() || (*r == records[0] && x["file"] == copy))
            .unwrap();
        assert_eq!(row["channel"], j["channel"].as_str().unwrap());
        assert_eq!(row["dev_unit"], j["dev_unit"].as_str().unwrap());
        assert_eq!(num(row, "samples"), j["samples"].as_f64());
        assert_eq!(num(row, "tau0_s"), j["tau0_s"].as_f64());
        let dev_min = j["dev"].as_array().unwrap().iter().filter_map(|v| v.as_f64()).fold(f64::INFINITY, f64::min);
        assert!(same(num(row, "dev_min"), Some(dev_min)));
        for key in ["allan_minimum_dph", "quantization_deg"] {
            assert!(same(num(row, key), j["noise"][key].as_f64()), "{key} of {}", r.display());
        }
        // A term with a basis: the reading's value or upper bound (issue 55: a bound is never a
        // blank cell), and its basis.
        for (key, term) in
            [("arw_deg_rt_h", "arw"), ("bias_instability_dph", "bias_instability"), ("rrw_deg_h_rt_h", "rrw")]
        {
            let reading = j["noise"]["readings"].as_array().unwrap().iter().find(|x| x["term"] == term).unwrap();
            assert!(same(num(row, key), reading["value"].as_f64()), "{key} of {}", r.display());
            assert_eq!(row[&format!("{term}_basis")], reading["basis"].as_str().unwrap());
            if reading["basis"] != "absent" {
                assert!(num(row, key).is_some(), "{key} of {}: a bound is written", r.display());
            }
        }
        assert!(same(num(row, "fit_arw_deg_rt_h"), j["noise"]["fit"]["arw_deg_rt_h"].as_f64()));
        assert!(num(row, "arw_deg_rt_h").is_some(), "ARW resolved on 300 s at 50 Hz");
        // The independent check of the hash: sha256sum's value of the same bytes.
        if let Ok(o) = std::process::Command::new("sha256sum").arg(r).output() {
            let text = String::from_utf8_lossy(&o.stdout).to_string();
            assert_eq!(row["sha256"], text.split_whitespace().next().unwrap_or(""));
        }
    }
}

/// Rows of a journal that are whole entries.
fn journal_entries(out: &Path) -> Vec<serde_json::Value> {
    let text = std::fs::read_to_string(out.join("batch-journal.jsonl")).unwrap_or_default();
    text.lines().skip(1).filter_map(|l| serde_json::from_str(l).ok()).collect()
}

#[test]
fn a_batch_killed_midway_resumes_without_doing_a_record_twice() {
    let dir = tempfile::tempdir().unwrap();
    let fleet = dir.path().join("fleet");
    std::fs::create_dir_all(&fleet).unwrap();
    const N: usize = 120;
    for i in 0..N {
        let mut text = String::from("time_s,rate_dps\n");
        let mut x: u64 = 0x9E37_79B9_7F4A_7C15 ^ i as u64;
        for k in 0..20_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            text.push_str(&format!("{},{}\n", k as f64 * 0.01, (x >> 11) as f64 / (1u64 << 53) as f64 - 0.5));
        }
        std::fs::write(fleet.join(format!("r{i:03}.csv")), text).unwrap();
    }
    let out = dir.path().join("out");
    let mut child = std::process::Command::new(assert_cmd::cargo::cargo_bin("gyrolab"))
        .arg("batch")
        .arg(&fleet)
        .arg("--out")
        .arg(&out)
        .args(["--jobs", "1", "--quiet"])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    while journal_entries(&out).len() < 3 && start.elapsed().as_secs() < 120 {
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    child.kill().unwrap(); // SIGKILL: no chance to tidy up
    child.wait().unwrap();
    let before = journal_entries(&out).len();
    assert!((3..N).contains(&before), "the kill came when {before} of {N} records were done");
    assert!(!out.join("results.csv").exists(), "results are written at the end only");

    let run = gyrolab().arg("batch").arg(&fleet).arg("--out").arg(&out).assert().success();
    let stdout = String::from_utf8_lossy(&run.get_output().stdout).to_string();
    assert!(stdout.contains(&format!("{N} inputs: {} evaluated now, {before} already done", N - before)), "{stdout}");
    let entries = journal_entries(&out);
    assert_eq!(entries.len(), N, "each record journaled exactly once");
    let hashes: BTreeSet<&str> = entries.iter().map(|e| e["sha256"].as_str().unwrap()).collect();
    assert_eq!(hashes.len(), N);
    let rows = results(&out);
    let files: BTreeSet<String> = rows.iter().map(|r| r["file"].clone()).collect();
    assert_eq!(rows.len(), N);
    assert_eq!(files.len(), N);
    assert!(rows.iter().all(|r| r["simulated"].is_empty()), "these records are not simulated");
}

#[test]
fn a_journal_of_other_options_is_not_resumed() {
    let dir = tempfile::tempdir().unwrap();
    let r = write(dir.path(), "a.csv", "time_s,rate_dps\n0,0.1\n0.01,0.2\n0.02,0.1\n0.03,0.3\n0.04,0.2\n");
    let out = dir.path().join("out");
    gyrolab().arg("batch").arg(&r).arg("--out").arg(&out).assert().success();
    let run = gyrolab().arg("batch").arg(&r).arg("--out").arg(&out).args(["--kind", "mdev"]).assert().code(2);
    let stderr = String::from_utf8_lossy(&run.get_output().stderr).to_string();
    assert!(stderr.contains("other options") && stderr.contains("batch-journal.jsonl"), "{stderr}");
    let run = gyrolab().arg("batch").arg(dir.path().join("nothing")).arg("--out").arg(&out).assert().code(2);
    assert!(String::from_utf8_lossy(&run.get_output().stderr).contains("no such file or folder"));
}

/// `batch` on a real folder (issue 55): a FIFO and a socket named with the record extension, a
/// link cycle (`loop -> .`), a link out of the folder (`up -> ..`), a link to nothing, two
/// byte-identical records and a non-UTF-8 name. The walk ends (within the test's own time: a
/// FIFO used to block, the cycle to walk without end), every entry is accounted for (evaluated,
/// a duplicate naming both files, or passed over with its reason), and the non-UTF-8 name is
/// written exactly (`\xFF`, reversible). A FIFO named on the command line is passed over too.
/// (An unreadable file is not tried: the tests run as root, whom permissions do not stop.)
#[cfg(unix)]
#[test]
fn a_folder_as_it_comes_is_walked_to_its_end_with_every_entry_accounted_for() {
    use std::os::unix::ffi::OsStrExt;
    let dir = tempfile::tempdir().unwrap();
    let fleet = dir.path().join("fleet");
    std::fs::create_dir(&fleet).unwrap();
    let a = simulate(&fleet, "a.csv", 1);
    std::fs::copy(&a, fleet.join("b.csv")).unwrap();
    let odd = fleet.join(std::ffi::OsStr::from_bytes(b"imu\xff.csv"));
    std::fs::copy(simulate(dir.path(), "c.csv", 2), &odd).unwrap();
    let fifo = fleet.join("pipe.csv");
    assert!(std::process::Command::new("mkfifo").arg(&fifo).status().unwrap().success());
    let _socket = std::os::unix::net::UnixListener::bind(fleet.join("sock.csv")).unwrap();
    std::os::unix::fs::symlink(".", fleet.join("loop")).unwrap();
    std::os::unix::fs::symlink("..", fleet.join("up")).unwrap();
    std::os::unix::fs::symlink("nowhere.csv", fleet.join("dangling.csv")).unwrap();
    let out = dir.path().join("out");
    let run = gyrolab()
        .arg("batch")
        .arg(&fleet)
        .arg(&fifo)
        .arg("--out")
        .arg(&out)
        .timeout(std::time::Duration::from_secs(120))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&run.stderr).into_owned();
    assert!(run.status.success(), "{err}");
    for said in [
        "pipe.csv: passed over: a FIFO (named pipe)",
        "sock.csv: passed over: a socket",
        "up: passed over: a link out of the folder",
        "--follow-links follows it",
        "dangling.csv: passed over: a link to nothing",
        "loop: passed over: a folder already walked (a link cycle)",
    ] {
        assert!(err.contains(said), "{said}: {err}");
    }
    // a.csv and b.csv have the same bytes: whichever a worker reached first is evaluated, and
    // the note names both.
    let b = fleet.join("b.csv");
    let (a_text, b_text) = (a.display().to_string(), b.display().to_string());
    let same =
        err.lines().find(|l| l.contains("the same bytes as")).unwrap_or_else(|| panic!("no duplicate note: {err}"));
    assert!(same.contains(&a_text) && same.contains(&b_text), "{same}");
    let rows = results(&out);
    let files: BTreeSet<&str> = rows.iter().map(|r| r["file"].as_str()).collect();
    let odd_text = format!("{}/imu\\xFF.csv", fleet.display());
    let evaluated = if files.contains(a_text.as_str()) { &a_text } else { &b_text };
    let want: BTreeSet<&str> = [evaluated.as_str(), odd_text.as_str()].into();
    assert_eq!(files, want);
    assert_eq!(
        gyrolab_io::text::path_from_text(&format!("{}/imu\\xFF.csv", fleet.display())).as_deref(),
        Some(odd.as_path())
    );
}
