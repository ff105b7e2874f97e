//! A real report folder (the paper's plan, evaluated by the lab layer) stored on both back ends:
//! every figure of summary.csv, the plan's hash and every input's hash and size kept; a
//! re-evaluation under this build writes a revision and lists exactly the figures that changed;
//! the raw records are kept and laid out again from the store alone; a changed input is
//! re-evaluated from the store's copy, and refused when the store keeps none.

use crate::store_common::backends;
use gyrolab_lab::evaluate::add_report_folder;
use gyrolab_lab::raw_records::restore_inputs;
use gyrolab_lab::reevaluate::reevaluate;
use gyrolab_store::record::{from_report_folder, hash_file};
use gyrolab_store::{Store, StoreError};
use std::path::{Path, PathBuf};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The paper plan (with a lot) and its inputs copied into `dir`, evaluated into `dir/report`.
fn evaluated_copy(dir: &Path) -> (PathBuf, PathBuf) {
    let plan_text = std::fs::read_to_string(repo().join("examples/paper_plan.toml"))
        .unwrap()
        .replace("../data/paper/", "")
        .replace("serial = \"paper-2014\"", "serial = \"paper-2014\"\nlot = \"LOT-'quoted'\"");
    for axis in ["x", "y", "z"] {
        let name = format!("paper_rate_table_{axis}.csv");
        std::fs::copy(repo().join("data/paper").join(&name), dir.join(&name)).unwrap();
    }
    let plan = dir.join("plan.toml");
    std::fs::write(&plan, plan_text).unwrap();
    let parsed = gyrolab_lab::test_plan::read_test_plan(&plan).unwrap();
    let folder =
        gyrolab_lab::test_plan::evaluate_test_plan(&parsed, &plan.display().to_string(), &gyrolab_eval::Silent)
            .unwrap();
    let out = dir.join("report");
    let files: Vec<(&str, &[u8])> = folder.outputs.iter().map(|o| (o.name.as_str(), o.bytes.as_slice())).collect();
    gyrolab_io::atomic::write_folder(&out, &files, &[]).unwrap();
    (plan, out)
}

#[test]
fn a_report_folder_is_kept_whole_and_reevaluated_with_a_diff() {
    let dir = tempfile::tempdir().unwrap();
    let (plan, out) = evaluated_copy(dir.path());
    let rec = from_report_folder(&out, Some(&plan)).unwrap();
    assert_eq!(rec.serial, "paper-2014");
    assert_eq!(rec.lot.as_deref(), Some("LOT-'quoted'"));
    assert_eq!(rec.inputs.len(), 3);
    let (sha, size) = hash_file(&dir.path().join("paper_rate_table_x.csv")).unwrap();
    assert!(rec.inputs.iter().any(|f| f.sha256 == sha && f.size_bytes == size));
    assert_eq!(rec.plan_sha256, gyrolab_store::record::hash_bytes(&std::fs::read(&plan).unwrap()));
    let summary = std::fs::read_to_string(out.join("summary.csv")).unwrap();
    assert_eq!(rec.figures.len(), summary.lines().count() - 1, "every summary row kept");
    assert!(
        rec.figures.iter().any(|f| f.verdict.as_deref() == Some("FAIL")),
        "the paper plan fails its linearity limit"
    );
    assert!(rec.report_files.iter().any(|f| f.path == "report.html"));

    for b in backends("reevaluate") {
        // An evaluation "made by an older version": one figure's value and verdict differ.
        let mut s = Store::open(&b.location, true).unwrap();
        let mut old = rec.clone();
        old.software_version = "0.0.9".into();
        let i = old.figures.iter().position(|f| f.value.is_some() && f.verdict.as_deref() == Some("FAIL")).unwrap();
        let true_value = old.figures[i].value.unwrap();
        old.figures[i].value = Some(true_value * 0.5);
        old.figures[i].verdict = Some("PASS".into());
        let id = s.add(&old).unwrap();
        let r = reevaluate(&mut s, id, "lab", "new version", &dir.path().join(format!("re-{}", b.name))).unwrap();
        assert_eq!((r.software_before.as_str(), r.software_after.as_str()), ("0.0.9", gyrolab_store::SOFTWARE_VERSION));
        assert_eq!(r.changes.len(), 1, "{}: {:?}", b.name, r.changes);
        let c = &r.changes[0];
        assert_eq!((c.before, c.after), (Some(true_value * 0.5), Some(true_value)));
        assert_eq!((c.verdict_before.as_deref(), c.verdict_after.as_deref()), (Some("PASS"), Some("FAIL")));
        let e = s.evaluation(r.revision).unwrap();
        assert_eq!((e.supersedes, e.revision_kind.as_str()), (Some(id), "reevaluation"));
        assert_eq!(e.record.lot.as_deref(), Some("LOT-'quoted'"));
        // Re-evaluating the superseded one is refused.
        assert!(matches!(
            reevaluate(&mut s, id, "lab", "again", &dir.path().join("x")),
            Err(StoreError::Refused { .. })
        ));
    }

    // The one path shared with `eval --store`: a store named explicitly.
    let stored =
        add_report_folder(&out, Some(&plan), Some(dir.path().join("shared.db").to_str().unwrap()), None).unwrap();
    assert_eq!(stored.id, 1);
    assert!(stored.line.contains("shared.db"), "{}", stored.line);

    // The raw records are kept: laid out again from the store alone, byte for byte, beside
    // their plan (issue 53).
    let mut s = Store::open(dir.path().join("shared.db").to_str().unwrap(), false).unwrap();
    let restored = restore_inputs(&mut s, 1, &dir.path().join("audit")).unwrap();
    assert_eq!(restored.plan, dir.path().join("audit/plan.toml"));
    assert_eq!(std::fs::read(&restored.plan).unwrap(), std::fs::read(&plan).unwrap());
    assert_eq!(restored.inputs.len(), 3);
    for (file, path) in &restored.inputs {
        assert_eq!(std::fs::read(path).unwrap(), std::fs::read(dir.path().join(file)).unwrap(), "{file}");
    }
    assert!(restore_inputs(&mut s, 1, &dir.path().join("audit")).is_err(), "an existing folder is not written into");

    // A changed input: the re-evaluation runs on the store's copy, the bytes first evaluated,
    // and finds the same figures (before schema 6 it was refused).
    let x = dir.path().join("paper_rate_table_x.csv");
    let mut text = std::fs::read_to_string(&x).unwrap();
    text.push_str("1,2,3\n");
    std::fs::write(&x, text).unwrap();
    std::fs::remove_file(&plan).unwrap();
    let r = reevaluate(&mut s, 1, "lab", "r", &dir.path().join("re-changed")).unwrap();
    assert!(r.changes.is_empty(), "{:?}", r.changes);
    let e = s.evaluation(r.revision).unwrap();
    let first = s.evaluation(1).unwrap();
    assert_eq!(e.record.plan_path, first.record.plan_path, "the report names the original plan");
    let hashes = |r: &gyrolab_store::record::EvaluationRecord| {
        let mut v: Vec<(String, String)> = r.inputs.iter().map(|f| (f.path.clone(), f.sha256.clone())).collect();
        v.sort();
        v
    };
    assert_eq!(hashes(&e.record), hashes(&first.record));

    // A store that keeps no copy (an evaluation stored before schema 6, here one without the
    // bytes): refused, naming the input and why, and nothing is stored.
    let mut bare = rec.clone();
    bare.serial = "no-copy".into();
    bare.inputs.iter_mut().for_each(|f| f.packed = None);
    let mut t = Store::open(dir.path().join("bare.db").to_str().unwrap(), true).unwrap();
    let id = t.add(&bare).unwrap();
    let e = reevaluate(&mut t, id, "lab", "r", &dir.path().join("re-bare")).unwrap_err();
    let text = e.to_string();
    assert!(text.contains("plan.toml") && text.contains("keeps no copy of input"), "{text}");
    assert!(t.evaluation(id + 1).is_err());
}
