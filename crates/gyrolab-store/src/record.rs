//! What the store keeps of one evaluation, read from a finished report folder (results.json,
//! summary.csv, the other report files) and the plan it names (its text and every input file
//! it names, hashed), so that `gyrolab store add DIR` and `gyrolab eval --store` take one path.

use crate::{StoreError, StoreResult};
use gyrolab_io::test_plan::read_plan as read_test_plan;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Longest text accepted in one field (a plan, a serial...): 16 MiB.
pub const MAX_TEXT_BYTES: usize = 16 << 20;

/// Largest report file whose bytes the store keeps (larger ones are hashed only): 64 MiB.
pub const MAX_KEPT_FILE_BYTES: u64 = 64 << 20;

/// Largest input record whose bytes the store keeps (larger ones are hashed only, and
/// `store reevaluate` needs them on disk): 256 MiB.
pub const MAX_KEPT_INPUT_BYTES: u64 = 256 << 20;

/// A file of an evaluation: an input record or a report file.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FileRecord {
    /// Path (inputs: as resolved from the plan) or name (report files).
    pub path: String,
    /// SHA-256, lower-case hex.
    pub sha256: String,
    /// Size, bytes.
    pub size_bytes: u64,
    /// The file's bytes, kept for report files up to [`MAX_KEPT_FILE_BYTES`] (`None`: inputs,
    /// which are hashed only, and larger report files).
    #[serde(skip)]
    pub content: Option<Vec<u8>>,
    /// An input's bytes, zstd-compressed, read when the evaluation is stored and checked
    /// against [`FileRecord::sha256`] (the bytes evaluated); `None`: report files, inputs over
    /// [`MAX_KEPT_INPUT_BYTES`], and inputs of a revision (already in the store).
    #[serde(skip)]
    pub packed: Option<Vec<u8>>,
}

/// One figure of one axis.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FigureRecord {
    /// Axis name.
    pub axis: String,
    /// Figure key (docs/JSON.md).
    pub figure: String,
    /// Value (`None`: not computed).
    pub value: Option<f64>,
    /// Unit.
    pub unit: String,
    /// `value`, or `upper_bound` when the figure is a bound (an Allan term read off a curve
    /// too short to show its minimum).
    pub basis: String,
    /// Expanded uncertainty U of the figure, in its unit, when the evaluation gives one.
    pub expanded_uncertainty: Option<f64>,
    /// Coverage factor k of U.
    pub coverage_factor: Option<f64>,
    /// Lower limit.
    pub limit_min: Option<f64>,
    /// Upper limit.
    pub limit_max: Option<f64>,
    /// PASS, FAIL, CONDITIONAL, NOT EVALUATED (`None`: no limit on this figure).
    pub verdict: Option<String>,
    /// The figure comes from SIMULATED records.
    pub simulated: bool,
}

/// Everything kept of one evaluation.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EvaluationRecord {
    /// Serial number.
    pub serial: String,
    /// Model.
    pub model: String,
    /// Lot (the plan's `[device] lot`).
    pub lot: Option<String>,
    /// Operator (the plan's `[test] operator`).
    pub operator: Option<String>,
    /// Approver.
    pub approver: Option<String>,
    /// Test date (the plan's `[test] date`).
    pub test_date: Option<String>,
    /// When the evaluation ran (results.json `created`).
    pub evaluated_at: String,
    /// gyrolab version of the evaluation.
    pub software_version: String,
    /// The plan's path.
    pub plan_path: String,
    /// The plan's text.
    pub plan_text: String,
    /// SHA-256 of the plan's bytes.
    pub plan_sha256: String,
    /// results.json as written.
    pub results_json: String,
    /// Overall verdict (`None`: no limits).
    pub verdict: Option<String>,
    /// Any input SIMULATED.
    pub simulated: bool,
    /// Input files named by the plan.
    pub inputs: Vec<FileRecord>,
    /// The report folder's files.
    pub report_files: Vec<FileRecord>,
    /// Every figure of every axis.
    pub figures: Vec<FigureRecord>,
}

/// Checks a text field: no NUL character (PostgreSQL text cannot hold one, so neither back end
/// takes it) and at most [`MAX_TEXT_BYTES`].
pub fn check_text(field: &str, text: &str) -> Result<(), String> {
    if let Some(i) = text.find('\0') {
        return Err(format!("{field} holds a NUL character (byte {i}); texts with NUL are not stored"));
    }
    if text.len() > MAX_TEXT_BYTES {
        return Err(format!("{field} is {} bytes, more than the {} accepted", text.len(), MAX_TEXT_BYTES));
    }
    Ok(())
}

impl EvaluationRecord {
    /// Checks every text before anything is written.
    pub fn check(&self) -> Result<(), String> {
        let fields = [
            ("serial", Some(&self.serial)),
            ("model", Some(&self.model)),
            ("lot", self.lot.as_ref()),
            ("operator", self.operator.as_ref()),
            ("approver", self.approver.as_ref()),
            ("test date", self.test_date.as_ref()),
            ("plan path", Some(&self.plan_path)),
            ("plan text", Some(&self.plan_text)),
            ("results.json", Some(&self.results_json)),
        ];
        for (name, v) in fields {
            if let Some(v) = v {
                check_text(name, v)?;
            }
        }
        if self.serial.trim().is_empty() {
            return Err("the serial number is empty".into());
        }
        for f in self.inputs.iter().chain(&self.report_files) {
            check_text("file path", &f.path)?;
        }
        for f in &self.figures {
            check_text("figure axis", &f.axis)?;
            check_text("figure key", &f.figure)?;
            check_text("figure unit", &f.unit)?;
        }
        Ok(())
    }
}

/// SHA-256 (hex) and size of a file, read in blocks ([`gyrolab_io::input_file::sha256_file`]).
pub fn hash_file(path: &Path) -> StoreResult<(String, u64)> {
    gyrolab_io::input_file::sha256_file(path)
        .map_err(|e| StoreError::Input { path: path.display().to_string(), message: e.message })
}

/// SHA-256 (hex) of bytes.
pub fn hash_bytes(bytes: &[u8]) -> String {
    gyrolab_io::input_file::sha256_hex(bytes)
}

/// Every input file a plan names, resolved against its folder, in plan order, without repeats
/// ([`gyrolab_io::test_plan::TestPlan::input_files`]).
pub fn plan_inputs(plan: &gyrolab_io_plan::TestPlan) -> Vec<PathBuf> {
    plan.input_files()
}

/// The plan types (gyrolab-io's plan reader).
pub mod gyrolab_io_plan {
    pub use gyrolab_io::test_plan::TestPlan;
}

/// Splits one CSV line (RFC 4180 quoting, as summary.csv writes it).
fn csv_fields(line: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                cur.push('"');
                chars.next();
            }
            ('"', _) => quoted = !quoted,
            (',', false) => out.push(std::mem::take(&mut cur)),
            _ => cur.push(c),
        }
    }
    out.push(cur);
    out
}

/// Splits CSV text into records (a quoted field may hold a line break).
fn csv_records(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    let mut quotes = 0usize;
    for line in text.split_inclusive('\n') {
        cur.push_str(line);
        quotes += line.matches('"').count();
        if quotes.is_multiple_of(2) {
            let rec = cur.trim_end_matches(['\n', '\r']).to_string();
            if !rec.is_empty() {
                out.push(rec);
            }
            cur.clear();
            quotes = 0;
        }
    }
    out
}

fn number(text: &str, path: &Path, line: usize, column: &str) -> StoreResult<Option<f64>> {
    if text.is_empty() {
        return Ok(None);
    }
    text.parse::<f64>().map(Some).map_err(|_| StoreError::Input {
        path: path.display().to_string(),
        message: format!("line {line}, column {column}: {text:?} is not a number"),
    })
}

/// The figures of summary.csv, with each `*_expanded_uncertainty*` figure's value attached as U
/// to the figure of the same name without `_expanded_uncertainty` and the same unit, k =
/// `coverage`. Two layouts are read: gyrolab 0.2 and later (axis, figure, unit, value, basis,
/// limit_min, limit_max, rule, verdict, simulated) and the earlier seven columns (axis, figure,
/// unit, value, limit_min, limit_max, verdict), so report folders written before stay storable.
pub fn figures_from_summary(text: &str, path: &Path, coverage: f64, simulated: bool) -> StoreResult<Vec<FigureRecord>> {
    let records = csv_records(text);
    let bad = |line: usize, m: String| StoreError::Input {
        path: path.display().to_string(),
        message: format!("line {line}: {m}"),
    };
    let Some(header) = records.first() else {
        return Err(bad(1, "empty file".into()));
    };
    let cols = csv_fields(header);
    let old = ["axis", "figure", "unit", "value", "limit_min", "limit_max", "verdict"];
    let new = ["axis", "figure", "unit", "value", "basis", "limit_min", "limit_max", "rule", "verdict", "simulated"];
    // Positions of value, basis, limit_min, limit_max, verdict, simulated.
    let (width, at): (usize, [Option<usize>; 6]) = if cols == new {
        (new.len(), [Some(3), Some(4), Some(5), Some(6), Some(8), Some(9)])
    } else if cols == old {
        (old.len(), [Some(3), None, Some(4), Some(5), Some(6), None])
    } else {
        return Err(bad(1, format!("header {cols:?}, expected {new:?} (or the earlier {old:?})")));
    };
    let mut out = Vec::new();
    for (i, rec) in records.iter().enumerate().skip(1) {
        let line = i + 1;
        let f = csv_fields(rec);
        if f.len() != width {
            return Err(bad(line, format!("{} fields, expected {width}", f.len())));
        }
        let field = |j: Option<usize>| j.map_or("", |j| f[j].as_str());
        let basis = match field(at[1]) {
            "" | "value" => "value",
            "upper_bound" => "upper_bound",
            "lower_bound" => "lower_bound",
            other => return Err(bad(line, format!("basis {other:?}: expected value, upper_bound or lower_bound"))),
        };
        out.push(FigureRecord {
            axis: f[0].clone(),
            figure: f[1].clone(),
            unit: f[2].clone(),
            value: number(field(at[0]), path, line, "value")?,
            basis: basis.into(),
            expanded_uncertainty: None,
            coverage_factor: None,
            limit_min: number(field(at[2]), path, line, "limit_min")?,
            limit_max: number(field(at[3]), path, line, "limit_max")?,
            verdict: Some(field(at[4]).to_string()).filter(|v| !v.is_empty()),
            simulated: simulated || field(at[5]) == "SIMULATED",
        });
    }
    let uncertainties: Vec<(String, String, String, Option<f64>)> = out
        .iter()
        .filter(|f| f.figure.contains("_expanded_uncertainty"))
        .map(|f| (f.axis.clone(), f.figure.replacen("_expanded_uncertainty", "", 1), f.unit.clone(), f.value))
        .collect();
    for f in &mut out {
        if f.figure.contains("_expanded_uncertainty") {
            f.coverage_factor = f.value.map(|_| coverage);
            continue;
        }
        if let Some((_, _, _, u)) =
            uncertainties.iter().find(|(a, n, unit, _)| *a == f.axis && *n == f.figure && *unit == f.unit)
        {
            f.expanded_uncertainty = *u;
            f.coverage_factor = u.map(|_| coverage);
        }
    }
    Ok(out)
}

/// The expanded uncertainty U and coverage factor k of every figure as the report computed
/// them (results.json `sections.uncertainty.<axis>`): `<figure>_expanded_uncertainty`, and for K,
/// F0, B0, B_s(T) (the quoted smoothing time) and N their budgets' `expanded` with the budget's
/// own k; the axis's `coverage_factor` for the others. Replaces what summary.csv's rows gave
/// (issue 53: k was stored as the plan's repeatability factor 3 for a U computed with k = 2, and
/// U was empty for K, B_s and K_a).
fn attach_uncertainties(results: &serde_json::Value, figures: &mut [FigureRecord]) {
    let Some(axes) = results.pointer("/sections/uncertainty").and_then(|u| u.as_object()) else { return };
    for f in figures.iter_mut() {
        let Some(u) = axes.get(&f.axis) else { continue };
        let num = |key: &str| u.get(key).and_then(serde_json::Value::as_f64);
        let axis_k = num("coverage_factor");
        let budget_k = |name: &str| u.pointer(&format!("/budgets/{name}/coverage_factor")).and_then(|k| k.as_f64());
        let quoted = num("bias_stability_smoothing_s").map(|t| format!("bias_stability_dph_{}s", short_seconds(t)));
        let (expanded, k) = if f.figure.contains("_expanded_uncertainty") {
            // The U rows themselves: their k.
            (f.value, axis_k)
        } else {
            match f.figure.as_str() {
                "scale_factor" => (num("scale_factor_expanded"), budget_k("scale_factor").or(axis_k)),
                "zero_offset" => (num("zero_offset_expanded"), budget_k("zero_offset").or(axis_k)),
                "bias_dph" => (num("bias_expanded_dph"), budget_k("bias").or(axis_k)),
                "arw_deg_rt_h" => (num("arw_expanded_deg_rt_h"), budget_k("arw").or(axis_k)),
                name if quoted.as_deref() == Some(name) => {
                    (num("bias_stability_expanded_dph"), budget_k("bias_stability").or(axis_k))
                }
                name => (num(&format!("{name}_expanded_uncertainty")), axis_k),
            }
        };
        if let Some(x) = expanded {
            if !f.figure.contains("_expanded_uncertainty") {
                f.expanded_uncertainty = Some(x);
            }
            f.coverage_factor = k;
        }
    }
}

/// Seconds as a figure key writes them (`10`, `0.01`).
fn short_seconds(t: f64) -> String {
    let s = format!("{t}");
    s.strip_suffix(".0").map_or(s.clone(), str::to_string)
}

/// Marks the figures that are upper bounds: results.json objects naming a figure key with a
/// `basis` of `upper_bound` (the Allan noise terms), matched by key and axis where given.
fn mark_bounds(results: &serde_json::Value, figures: &mut [FigureRecord]) {
    fn walk(v: &serde_json::Value, axis: Option<&str>, out: &mut Vec<(Option<String>, String)>) {
        match v {
            serde_json::Value::Object(m) => {
                let axis = m.get("axis").and_then(|a| a.as_str()).or(axis);
                if m.get("basis").and_then(|b| b.as_str()) == Some("upper_bound") {
                    if let Some(k) = m.get("figure").or_else(|| m.get("key")).and_then(|k| k.as_str()) {
                        out.push((axis.map(str::to_string), k.to_string()));
                    }
                }
                m.values().for_each(|x| walk(x, axis, out));
            }
            serde_json::Value::Array(a) => a.iter().for_each(|x| walk(x, axis, out)),
            _ => {}
        }
    }
    let mut bounds = Vec::new();
    walk(results, None, &mut bounds);
    for f in figures.iter_mut() {
        if bounds.iter().any(|(a, k)| *k == f.figure && a.as_deref().is_none_or(|a| a == f.axis)) {
            f.basis = "upper_bound".into();
        }
    }
}

fn read_text(path: &Path) -> StoreResult<String> {
    let bytes = std::fs::read(path)
        .map_err(|e| StoreError::Input { path: path.display().to_string(), message: format!("cannot read: {e}") })?;
    String::from_utf8(bytes).map_err(|e| StoreError::Input {
        path: path.display().to_string(),
        message: format!("not UTF-8 text (byte {})", e.utf8_error().valid_up_to()),
    })
}

fn json_text(v: &serde_json::Value, keys: &[&str]) -> Option<String> {
    let mut cur = v;
    for k in keys {
        cur = cur.get(k)?;
    }
    cur.as_str().map(str::to_string)
}

/// `path` made absolute against the current folder, lexically (links are not resolved: the
/// path stays the one the lab named), or as it is when the current folder cannot be read.
pub fn absolute(path: &Path) -> PathBuf {
    std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf())
}

/// Reads the record of a finished report folder. `plan`: the plan file (default: the
/// `plan_file` results.json names, as written, relative to the current folder).
pub fn from_report_folder(dir: &Path, plan: Option<&Path>) -> StoreResult<EvaluationRecord> {
    from_report_folder_with(dir, plan, None, true, &[])
}

/// SHA-256 and size of every input file the plan at `plan_path` names, in plan order.
pub fn hash_plan_inputs(plan_path: &Path) -> StoreResult<Vec<FileRecord>> {
    let plan_path = &absolute(plan_path);
    let parsed = read_test_plan(plan_path)
        .map_err(|e| StoreError::Input { path: plan_path.display().to_string(), message: e.to_string() })?;
    hash_inputs(&parsed)
}

fn hash_inputs(parsed: &gyrolab_io_plan::TestPlan) -> StoreResult<Vec<FileRecord>> {
    let mut inputs = Vec::new();
    for p in plan_inputs(parsed) {
        let (sha256, size_bytes) = hash_file(&p)?;
        inputs.push(FileRecord { path: p.display().to_string(), sha256, size_bytes, content: None, packed: None });
    }
    Ok(inputs)
}

/// Reads every input of `inputs` (up to [`MAX_KEPT_INPUT_BYTES`]) into [`FileRecord::packed`],
/// compressed on the way (the file read once, in blocks: the memory held is the compressed
/// copy), and checks it is still the bytes hashed when it was evaluated: an input changed since
/// is refused, naming it, and nothing is stored.
pub fn pack_inputs(inputs: &mut [FileRecord]) -> StoreResult<()> {
    use sha2::Digest;
    use std::io::{Read, Write};
    for f in inputs.iter_mut().filter(|f| f.size_bytes <= MAX_KEPT_INPUT_BYTES) {
        let input = |m: String| StoreError::Input { path: f.path.clone(), message: m };
        let mut file = std::fs::File::open(&f.path).map_err(|e| input(format!("cannot read: {e}")))?;
        let mut encoder =
            zstd::stream::Encoder::new(Vec::new(), 3).map_err(|e| input(format!("cannot compress: {e}")))?;
        let mut hasher = sha2::Sha256::new();
        let mut block = vec![0u8; 1 << 20];
        let mut size = 0u64;
        loop {
            let n = file.read(&mut block).map_err(|e| input(format!("cannot read: {e}")))?;
            if n == 0 {
                break;
            }
            size += n as u64;
            if size > MAX_KEPT_INPUT_BYTES {
                break;
            }
            hasher.update(&block[..n]);
            encoder.write_all(&block[..n]).map_err(|e| input(format!("cannot compress: {e}")))?;
        }
        let sha: String = hasher.finalize().iter().map(|b| format!("{b:02x}")).collect();
        if sha != f.sha256 || size != f.size_bytes {
            return Err(input(format!(
                "changed since it was evaluated (SHA-256 {}, {} bytes then; {sha}, {size} bytes now): not stored",
                f.sha256, f.size_bytes
            )));
        }
        f.packed = Some(encoder.finish().map_err(|e| input(format!("cannot compress: {e}")))?);
    }
    Ok(())
}

/// The report folder's manifest, when it has one (a folder written before 0.3 has none).
fn read_manifest(dir: &Path) -> StoreResult<Option<gyrolab_io::provenance::Manifest>> {
    let path = dir.join(gyrolab_io::provenance::MANIFEST);
    if !path.is_file() {
        return Ok(None);
    }
    let text = read_text(&path)?;
    serde_json::from_str(&text).map(Some).map_err(|e| StoreError::Input {
        path: path.display().to_string(),
        message: format!("not a gyrolab manifest: {e}"),
    })
}

/// [`from_report_folder`] with the inputs' hashes already made by [`hash_plan_inputs`] of the
/// same plan (`gyrolab eval --store` makes them on a second thread while it evaluates); `None`:
/// hashed here. `pack`: the inputs' bytes read into [`FileRecord::packed`] ([`pack_inputs`]);
/// false for a re-evaluation of raw records the store keeps already. `moved`: inputs the plan
/// names read from elsewhere (the store's copies; see
/// [`gyrolab_io::test_plan::parse_plan_reading_moved`]).
pub fn from_report_folder_with(
    dir: &Path,
    plan: Option<&Path>,
    inputs: Option<Vec<FileRecord>>,
    pack: bool,
    moved: &[(PathBuf, PathBuf)],
) -> StoreResult<EvaluationRecord> {
    let results_path = dir.join("results.json");
    let results_json = read_text(&results_path)?;
    let bad = |m: String| StoreError::Input { path: results_path.display().to_string(), message: m };
    let results: serde_json::Value = serde_json::from_str(&results_json)
        .map_err(|e| bad(format!("line {}, column {}: {e}", e.line(), e.column())))?;
    let need = |keys: &[&str]| {
        json_text(&results, keys).ok_or_else(|| bad(format!("key {} missing or not text", keys.join("."))))
    };
    let serial = need(&["device", "serial"])?;
    let model = need(&["device", "model"])?;
    let software_version = need(&["gyrolab_version"])?;
    let evaluated_at = need(&["created"])?;
    let plan_file = need(&["plan_file"])?;
    let plan_path = plan.map(Path::to_path_buf).unwrap_or_else(|| PathBuf::from(&plan_file));
    if !plan_path.is_file() {
        return Err(bad(format!(
            "the plan it names, {plan_file}, is not found from here ({}): give it with --plan",
            plan_path.display()
        )));
    }
    // Kept as an absolute path, so that `store reevaluate` finds it from any folder (issue 53).
    let plan_path = absolute(&plan_path);
    let plan_text = read_text(&plan_path)?;
    // The text read once: parsed as it was read (never the file again).
    let parsed = gyrolab_io::test_plan::parse_plan_reading_moved(&plan_path, &plan_text, moved)
        .map_err(|e| StoreError::Input { path: plan_path.display().to_string(), message: e.to_string() })?;
    let mut inputs = match inputs {
        Some(i) => i,
        None => hash_inputs(&parsed)?,
    };
    // The raw records kept with the evaluation (issue 53), the bytes evaluated.
    if pack {
        pack_inputs(&mut inputs)?;
    }
    let mut report_files = Vec::new();
    let mut names: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| StoreError::Input { path: dir.display().to_string(), message: format!("cannot list: {e}") })?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_file())
        .collect();
    names.sort();
    // A folder with a manifest: only its files (and the manifest, and a report.pdf printed
    // after it) are the report; a leftover of a killed run or a file added by hand is not
    // stored, and an output that differs from its manifest hash refuses the folder.
    let manifest = read_manifest(dir)?;
    if let Some(m) = &manifest {
        names.retain(|p| {
            let name = p.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
            name == gyrolab_io::provenance::MANIFEST || name == "report.pdf" || m.files.iter().any(|f| f.name == name)
        });
        for f in &m.files {
            if !names.iter().any(|p| p.file_name().is_some_and(|n| n.to_string_lossy() == f.name)) {
                return Err(StoreError::Input {
                    path: dir.join(&f.name).display().to_string(),
                    message: "missing: the folder's manifest lists it (gyrolab verify checks the folder); not stored"
                        .into(),
                });
            }
        }
    }
    for p in names {
        let name = p.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let size = std::fs::metadata(&p).map(|m| m.len()).unwrap_or(u64::MAX);
        if size <= MAX_KEPT_FILE_BYTES {
            let bytes = std::fs::read(&p).map_err(|e| StoreError::Input {
                path: p.display().to_string(),
                message: format!("cannot read: {e}"),
            })?;
            if let Some(f) = manifest.as_ref().and_then(|m| m.files.iter().find(|f| f.name == name)) {
                let sha = hash_bytes(&bytes);
                if sha != f.sha256 {
                    return Err(StoreError::Input {
                        path: p.display().to_string(),
                        message: format!(
                            "changed since the report was written (SHA-256 {sha}, manifest {}): an edited folder is not stored (gyrolab verify names every change)",
                            f.sha256
                        ),
                    });
                }
            }
            report_files.push(FileRecord {
                path: name,
                sha256: hash_bytes(&bytes),
                size_bytes: bytes.len() as u64,
                content: Some(bytes),
                packed: None,
            });
        } else {
            let (sha256, size_bytes) = hash_file(&p)?;
            report_files.push(FileRecord { path: name, sha256, size_bytes, content: None, packed: None });
        }
    }
    let simulated = parsed.device.simulated.is_some();
    let summary_path = dir.join("summary.csv");
    let mut figures =
        figures_from_summary(&read_text(&summary_path)?, &summary_path, parsed.options.coverage, simulated)?;
    mark_bounds(&results, &mut figures);
    attach_uncertainties(&results, &mut figures);
    let verdict = json_text(&results, &["verdict"]);
    Ok(EvaluationRecord {
        serial,
        model,
        lot: parsed.device.lot.clone(),
        operator: json_text(&results, &["test", "operator"]).or(parsed.test.operator.clone()),
        approver: json_text(&results, &["test", "approver"]).or(parsed.test.approver.clone()),
        test_date: json_text(&results, &["test", "date"]).or(parsed.test.date.clone()),
        evaluated_at,
        software_version,
        plan_path: plan_path.display().to_string(),
        plan_sha256: hash_bytes(plan_text.as_bytes()),
        plan_text,
        results_json,
        verdict,
        simulated,
        inputs,
        report_files,
        figures,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_quoting_as_summary_csv_writes_it() {
        assert_eq!(csv_fields(r#"a,"b,c","d""e",,"#), vec!["a", "b,c", "d\"e", "", ""]);
        assert_eq!(csv_records("h\n\"x\ny\",1\nz,2\n"), vec!["h", "\"x\ny\",1", "z,2"]);
    }

    #[test]
    fn uncertainty_attached_to_its_figure() {
        let text = "axis,figure,unit,value,limit_min,limit_max,verdict\n\
                    x,bias_dph,deg/h,1.5,,2,PASS\n\
                    x,bias_expanded_uncertainty_dph,deg/h,0.25,,,\n";
        let f = figures_from_summary(text, Path::new("s.csv"), 2.0, false).unwrap();
        assert_eq!(f[0].expanded_uncertainty, Some(0.25));
        assert_eq!(f[0].coverage_factor, Some(2.0));
        assert_eq!(f[0].limit_max, Some(2.0));
        assert_eq!(f[0].verdict.as_deref(), Some("PASS"));
        assert_eq!(f[1].coverage_factor, Some(2.0));
        let e = figures_from_summary("axis,figure\n", Path::new("s.csv"), 2.0, false).unwrap_err();
        assert!(e.to_string().contains("s.csv: line 1"), "{e}");
    }

    #[test]
    fn the_current_summary_layout_carries_basis_rule_and_simulated() {
        let text = "axis,figure,unit,value,basis,limit_min,limit_max,rule,verdict,simulated\n\
                    x,threshold_dps,deg/s,0.5,lower_bound,,0.2,simple_acceptance,FAIL,SIMULATED\n\
                    x,bias_dph,deg/h,1.5,value,,2,guarded_acceptance,CONDITIONAL,\n";
        let f = figures_from_summary(text, Path::new("s.csv"), 2.0, false).unwrap();
        assert_eq!((f[0].basis.as_str(), f[0].verdict.as_deref(), f[0].simulated), ("lower_bound", Some("FAIL"), true));
        assert_eq!((f[1].basis.as_str(), f[1].limit_max, f[1].simulated), ("value", Some(2.0), false));
        let bad = text.replace("lower_bound", "sideways");
        let e = figures_from_summary(&bad, Path::new("s.csv"), 2.0, false).unwrap_err();
        assert!(e.to_string().contains("s.csv: line 2: basis \"sideways\""), "{e}");
    }

    #[test]
    fn nul_and_huge_texts_are_refused_by_name() {
        assert!(check_text("serial", "a\0b").unwrap_err().contains("serial holds a NUL"));
        assert!(check_text("plan text", &"x".repeat(MAX_TEXT_BYTES + 1)).is_err());
        assert!(check_text("serial", "'; DROP TABLE evaluation; --").is_ok());
    }
}
