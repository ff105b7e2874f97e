//! The same outputs before and after (issue 52): `scripts/golden_outputs.sh` runs the paper's
//! demo, the simulated test program's evaluation, the export files of every filter stack, a batch,
//! rate and bias JSON and a stored report's rows and trend plot with this build, and every output
//! (74 files) must have the SHA-256 recorded in `tests/data/golden_outputs.sha256`, byte for byte
//! once the parts that change from run to run are masked ([`normalise`]: times, dates, generated report numbers,
//! and the hashes in manifests and store listings of files that hold them).
//!
//! The digests were made by the build before the workspace was restructured (commit c9b9e47):
//! `GYROLAB_GOLDEN_BIN=/path/to/that/gyrolab GYROLAB_GOLDEN_WRITE=1 cargo test -p gyrolab-cli
//! --test integration -- golden::` rewrites them from any binary; a change of an output on purpose
//! is recorded that way, and the commit says why.

use regex::Regex;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The file of recorded digests.
fn digests_file() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/golden_outputs.sha256")
}

/// The bytes compared: Parquet as written; text with the run's times, dates, generated report
/// numbers masked, and in manifests and store listings every SHA-256 (the hashes of files that
/// hold a time) and the run's folder (the store keeps the plan's and inputs' absolute paths since
/// issue 53; the build before kept them relative to the run's folder, as they then read).
fn normalise(root: &Path, path: &Path, bytes: Vec<u8>) -> Vec<u8> {
    if path.extension().is_some_and(|e| e == "parquet") {
        return bytes;
    }
    let Ok(text) = String::from_utf8(bytes.clone()) else { return bytes };
    let number = Regex::new(r"GYR-\d{8}-[0-9a-f]{8}").unwrap(); // ok: a constant pattern
    let time = Regex::new(r"\d{4}-\d{2}-\d{2}[T ]\d{2}:\d{2}:\d{2}(\.\d+)?(Z|[+-]\d{2}:?\d{2})?").unwrap(); // ok: constant
    let date = Regex::new(r"\b\d{4}-\d{2}-\d{2}\b").unwrap(); // ok: a constant pattern
    let sha = Regex::new(r"\b[0-9a-f]{64}\b").unwrap(); // ok: a constant pattern
    let text = number.replace_all(&text, "<NUMBER>");
    let text = time.replace_all(&text, "<TIME>");
    let mut text = date.replace_all(&text, "<DATE>").into_owned();
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    if name.ends_with("manifest.json") || name == "store_show.stdout" || name == "store_add.stdout" {
        text = sha.replace_all(&text, "<SHA256>").into_owned();
        let run = format!("{}/", root.canonicalize().unwrap_or(root.to_path_buf()).display()); // ok: test
        text = text.replace(&run, "").replace(&format!("{}/", root.display()), "");
    }
    text.into_bytes()
}

/// `path  sha256` of every output under `dir` (the inputs the script copies or simulates left
/// out), sorted by path.
fn digests(dir: &Path) -> Vec<String> {
    fn walk(root: &Path, dir: &Path, out: &mut Vec<String>) {
        let mut entries: Vec<PathBuf> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()).collect(); // ok: test
        entries.sort();
        for p in entries {
            let rel = p.strip_prefix(root).unwrap().to_string_lossy().replace('\\', "/"); // ok: under root
            let input = rel.starts_with("program/")
                || ["static.csv", "simulated_imu_ros2.mcap", "paper_rate_table_x.csv"].contains(&rel.as_str());
            if p.is_dir() {
                walk(root, &p, out);
            } else if !input {
                let bytes = normalise(root, &p, std::fs::read(&p).unwrap()); // ok: test
                out.push(format!("{rel}  {}", gyrolab_io::input_file::sha256_hex(&bytes)));
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out
}

#[test]
fn every_output_equals_the_golden_outputs_of_the_build_before_the_restructuring() {
    let bin = std::env::var("GYROLAB_GOLDEN_BIN")
        .map(PathBuf::from)
        .unwrap_or_else(|_| assert_cmd::cargo::cargo_bin("gyrolab"));
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("run");
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scripts/golden_outputs.sh");
    let status = Command::new("bash").arg(&script).arg(&bin).arg(&out).status().unwrap();
    assert!(status.success(), "{} failed", script.display());
    let now = digests(&out);
    if std::env::var("GYROLAB_GOLDEN_WRITE").is_ok_and(|v| v == "1") {
        std::fs::write(digests_file(), now.join("\n") + "\n").unwrap();
        eprintln!("wrote {} from {}", digests_file().display(), bin.display());
        return;
    }
    let recorded: Vec<String> = std::fs::read_to_string(digests_file()).unwrap().lines().map(String::from).collect();
    let differ: Vec<String> = now.iter().filter(|l| !recorded.contains(l)).cloned().collect();
    let gone: Vec<String> = recorded.iter().filter(|l| !now.contains(l)).cloned().collect();
    assert!(recorded.len() >= 70, "the golden list holds every output: {}", recorded.len());
    assert!(
        differ.is_empty() && gone.is_empty(),
        "outputs differ from the golden outputs (left: now; right: recorded; run the script with both builds and diff the folders):\n  now:      {}\n  recorded: {}",
        differ.join("\n            "),
        gone.join("\n            ")
    );
}
