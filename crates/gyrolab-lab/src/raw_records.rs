//! The raw records kept in the store (issue 53): an evaluation's plan and inputs laid out again,
//! from the store alone, as they stood relative to the plan when it was evaluated, so that an
//! audit (`gyrolab store inputs ID --out DIR`) or a re-evaluation reproduces the report without
//! the lab's original folders.

use gyrolab_io::test_plan::TestPlan;
use gyrolab_store::query::write_input_content;
use gyrolab_store::{Store, StoreError, StoreResult};
use std::path::{Component, Path, PathBuf};

/// An evaluation's plan and inputs written out of the store.
#[derive(Debug, Clone, PartialEq)]
pub struct RestoredInputs {
    /// The plan, under its own file name, as stored (the bytes its SHA-256 was taken of).
    pub plan: PathBuf,
    /// Each input: its path relative to the plan's folder (as results.json names it) and where
    /// it was written.
    pub inputs: Vec<(String, PathBuf)>,
    /// The inputs the plan names by an absolute path, which cannot sit where the plan names
    /// them: (the path the plan names, where it was written, under `_absolute/`).
    pub moved: Vec<(PathBuf, PathBuf)>,
}

impl RestoredInputs {
    /// The restored plan, parsed, reading the inputs it names by absolute path from where they
    /// were written ([`gyrolab_io::test_plan::parse_plan_reading_moved`]; the report still names
    /// them as the plan does).
    pub fn plan(&self) -> Result<TestPlan, gyrolab_io::DataError> {
        let text =
            gyrolab_io::text::read_text_file(&self.plan, gyrolab_io::text::MAX_CONFIG_BYTES, "a test plan (TOML)")?;
        gyrolab_io::test_plan::parse_plan_reading_moved(&self.plan, &text, &self.moved)
    }
}

/// One input as the evaluation's results.json names it: its path relative to the plan's folder
/// and its SHA-256.
fn named_inputs(results_json: &str) -> Result<Vec<(String, String)>, String> {
    let v: serde_json::Value = serde_json::from_str(results_json).map_err(|e| format!("results.json: {e}"))?;
    let list = v["integrity"]["inputs"].as_array().ok_or("results.json: integrity.inputs missing")?;
    list.iter()
        .map(|i| {
            let file = i["file"].as_str().ok_or("results.json: an input without `file`")?;
            let sha = i["sha256"].as_str().ok_or("results.json: an input without `sha256`")?;
            Ok((file.to_string(), sha.to_string()))
        })
        .collect()
}

/// How many folders above the plan's the inputs reach (`../data/x.csv`: 1); an error for a path
/// that cannot be laid out beside the plan (absolute, or reaching up after a folder name).
fn levels_up(file: &str) -> Result<usize, String> {
    let mut up = 0;
    let mut named = false;
    for c in Path::new(file).components() {
        match c {
            Component::ParentDir if !named => up += 1,
            Component::Normal(_) => named = true,
            Component::CurDir => {}
            _ => {
                return Err(format!(
                    "input {file:?} is not named relative to the plan's folder: it cannot be laid out from the store"
                ))
            }
        }
    }
    if !named {
        return Err(format!("input {file:?} names no file"));
    }
    Ok(up)
}

/// Writes the plan and every input of evaluation `id` from the store into `dir` (which must not
/// exist: it is written whole, by a rename of a staged folder beside it, or not at all), laid
/// out as they stood relative to the plan. Inputs reaching above the plan's folder (`../x.csv`)
/// put the plan in as many nested `_` folders; inputs named by an absolute path go under
/// `_absolute/` ([`RestoredInputs::plan`] reads them from there). Refused, naming the input,
/// when the store keeps no copy of one (larger than 256 MiB, or stored before schema version 6).
pub fn restore_inputs(store: &mut Store, id: i64, dir: &Path) -> StoreResult<RestoredInputs> {
    if std::fs::symlink_metadata(dir).is_ok() {
        return Err(StoreError::Input {
            path: dir.display().to_string(),
            message: "already exists: the raw records are written into a new folder".into(),
        });
    }
    let parent = dir.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    // Staged as `.gyrolab-<pid>-inputs-*.tmp`, so that the next run removes what a killed one
    // left (gyrolab_io::atomic::clean_leftovers).
    gyrolab_io::atomic::clean_leftovers(parent);
    let staged = tempfile::Builder::new()
        .prefix(&format!(".gyrolab-{}-inputs-", std::process::id()))
        .suffix(".tmp")
        .tempdir_in(parent)
        .map_err(|e| StoreError::Input { path: parent.display().to_string(), message: format!("cannot write: {e}") })?;
    let restored = restore_into(store, id, staged.path())?;
    let staged_path = staged.keep();
    std::fs::rename(&staged_path, dir).map_err(|e| {
        let _ = std::fs::remove_dir_all(&staged_path);
        StoreError::Input { path: dir.display().to_string(), message: format!("cannot write: {e}") }
    })?;
    let moved = |p: &Path| dir.join(p.strip_prefix(&staged_path).unwrap_or(p));
    Ok(RestoredInputs {
        plan: moved(&restored.plan),
        inputs: restored.inputs.iter().map(|(f, p)| (f.clone(), moved(p))).collect(),
        moved: restored.moved.iter().map(|(f, p)| (f.clone(), moved(p))).collect(),
    })
}

/// [`restore_inputs`] and what was written, as `gyrolab store report ID --inputs` prints it.
pub fn restored_text(store: &mut Store, id: i64, dir: &Path) -> StoreResult<String> {
    let r = restore_inputs(store, id, dir)?;
    let mut s = format!(
        "wrote the plan and the {} raw record(s) of evaluation {id} to {}, each equal to its stored SHA-256:\n  {}\n",
        r.inputs.len(),
        dir.display(),
        r.plan.display()
    );
    for (_, p) in &r.inputs {
        s.push_str(&format!("  {}\n", p.display()));
    }
    match r.moved.len() {
        0 => s.push_str(&format!("evaluate them again with: gyrolab eval {} --out DIR\n", r.plan.display())),
        n => s.push_str(&format!(
            "the plan names {n} of them by an absolute path: they are under {}, and gyrolab store reevaluate \
             reads them from the store\n",
            dir.join("_absolute").display()
        )),
    }
    Ok(s)
}

/// [`restore_inputs`] into the existing, empty folder `root` (a temporary one for a
/// re-evaluation).
pub fn restore_into(store: &mut Store, id: i64, root: &Path) -> StoreResult<RestoredInputs> {
    let e = store.evaluation(id)?;
    let rec = &e.record;
    let store_name = store.name().to_string();
    let refuse = |m: String| StoreError::Refused { store: store_name.clone(), message: m };
    let inputs = named_inputs(&rec.results_json).map_err(|m| refuse(format!("evaluation {id}: {m}")))?;
    let mut up = 0;
    for (file, _) in inputs.iter().filter(|(f, _)| !Path::new(f).is_absolute()) {
        up = up.max(levels_up(file).map_err(|m| refuse(format!("evaluation {id}: {m}")))?);
    }
    let mut plan_dir = root.to_path_buf();
    (0..up).for_each(|_| plan_dir.push("_"));
    let plan_name = Path::new(&rec.plan_path).file_name().map(PathBuf::from).unwrap_or_else(|| "plan.toml".into());
    let io = |p: &Path, e: std::io::Error| StoreError::Input {
        path: p.display().to_string(),
        message: format!("cannot write: {e}"),
    };
    std::fs::create_dir_all(&plan_dir).map_err(|e| io(&plan_dir, e))?;
    let plan = plan_dir.join(plan_name);
    std::fs::write(&plan, rec.plan_text.as_bytes()).map_err(|e| io(&plan, e))?;
    let mut written = Vec::new();
    let mut moved = Vec::new();
    for (file, sha) in inputs {
        // Lexically inside `root`: `levels_up` allowed `..` only before the first name, and
        // the plan sits that many folders down. An absolute path goes under `_absolute/`
        // (its root and prefix left out).
        let path = match Path::new(&file).is_absolute() {
            true => {
                let mut p = root.join("_absolute");
                p.extend(Path::new(&file).components().filter(|c| matches!(c, Component::Normal(_))));
                moved.push((PathBuf::from(&file), p.clone()));
                p
            }
            false => plan_dir.join(&file),
        };
        let path: PathBuf = path.components().fold(PathBuf::new(), |mut p, c| {
            match c {
                Component::ParentDir => {
                    p.pop();
                }
                Component::CurDir => {}
                c => p.push(c),
            }
            p
        });
        if let Some(d) = path.parent() {
            std::fs::create_dir_all(d).map_err(|e| io(d, e))?;
        }
        let mut out = std::fs::File::create(&path).map_err(|e| io(&path, e))?;
        if !write_input_content(store, &sha, &mut out)? {
            return Err(refuse(format!(
                "evaluation {id}: the store keeps no copy of input {file} (SHA-256 {sha}): inputs over 256 MiB, and those \
                 of evaluations stored before schema version 6, are kept as hashes only"
            )));
        }
        written.push((file, path));
    }
    Ok(RestoredInputs { plan, inputs: written, moved })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inputs_are_laid_out_below_the_plan_or_refused() {
        assert_eq!(levels_up("x.csv"), Ok(0));
        assert_eq!(levels_up("data/x.csv"), Ok(0));
        assert_eq!(levels_up("../data/x.csv"), Ok(1));
        assert_eq!(levels_up("../../x.csv"), Ok(2));
        assert!(levels_up("data/../../x.csv").is_err(), "up after a name could leave the folder");
        assert!(levels_up("..").is_err());
    }
}
