//! Batches: many records (anything [`gyrolab_eval::allan`] reads: delimited text, Parquet, MCAP, ROS 1
//! bags, ULog) evaluated on every core, each named by the SHA-256 of its bytes so that a batch
//! started again skips what it finished before; one result row per record and channel (the
//! noise terms of `gyrolab allan --json`, their units in the column names), as CSV or Parquet.
//!
//! The figures are those of [`gyrolab_eval::allan::analyse_records`] and
//! [`gyrolab_report::allan::allan_json_with`] without the GMWM, which the table does not hold
//! (docs/METHODS.md section 3); this module adds no formula, only the bookkeeping
//! (docs/METHODS.md, "Batches").
//!
//! Nothing is written here: the front end receives each finished input through [`BatchSink`]
//! (to append it to its journal, [`journal_line`]) and renders the combined table with
//! [`results_csv`] and [`results_parquet`].

use gyrolab_eval::allan::{analyse_records, AllanRequest};
use gyrolab_eval::error::{EvalError, EvalResult};
use gyrolab_eval::progress::Progress;
use gyrolab_io::DataError;
use gyrolab_report::allan::{allan_json_with, AllanJson};
use gyrolab_report::table::csv_field;
use rayon::prelude::*;
use sha2::{Digest, Sha256};
use std::collections::{BTreeMap, HashMap};
use std::io::Read;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// File name extensions a folder or a glob contributes as records (other files are passed
/// over); a file named on its own or in a list is taken whatever its name.
pub const RECORD_EXTENSIONS: [&str; 9] = ["csv", "tsv", "txt", "dat", "parquet", "mcap", "bag", "ulg", "log"];

/// The type of a result column.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ColumnType {
    /// Text (UTF-8).
    Text,
    /// A real number (f64).
    Number,
    /// A count (u64).
    Count,
}

/// The result columns, in order: name (units in the name, as the JSON keys of
/// docs/JSON.md) and type. Noise terms are the slope-line values of `gyrolab allan --json`
/// (empty unless the term is resolved as a value; `*_basis` says `value`, `upper_bound` or
/// `absent`), gyro terms for channels in deg/s, accelerometer terms for channels in m/s^2.
pub const COLUMNS: [(&str, ColumnType); 34] = [
    ("file", ColumnType::Text),
    ("sha256", ColumnType::Text),
    ("simulated", ColumnType::Text),
    ("topic", ColumnType::Text),
    ("channel", ColumnType::Text),
    ("quantity", ColumnType::Text),
    ("kind", ColumnType::Text),
    ("dev_unit", ColumnType::Text),
    ("tau0_s", ColumnType::Number),
    ("samples", ColumnType::Count),
    ("record_length_s", ColumnType::Number),
    ("dev_min", ColumnType::Number),
    ("dev_min_tau_s", ColumnType::Number),
    ("arw_deg_rt_h", ColumnType::Number),
    ("arw_basis", ColumnType::Text),
    ("bias_instability_dph", ColumnType::Number),
    ("bias_instability_basis", ColumnType::Text),
    ("allan_minimum_dph", ColumnType::Number),
    ("allan_minimum_tau_s", ColumnType::Number),
    ("rrw_deg_h_rt_h", ColumnType::Number),
    ("rrw_basis", ColumnType::Text),
    ("quantization_deg", ColumnType::Number),
    ("rate_ramp_dph_per_h", ColumnType::Number),
    ("fit_arw_deg_rt_h", ColumnType::Number),
    ("fit_bias_instability_dph", ColumnType::Number),
    ("fit_rrw_deg_h_rt_h", ColumnType::Number),
    ("fit_quality", ColumnType::Text),
    ("vrw_m_s_rt_h", ColumnType::Number),
    ("vrw_basis", ColumnType::Text),
    ("bias_instability_ug", ColumnType::Number),
    ("allan_minimum_ug", ColumnType::Number),
    ("accel_random_walk_m_s2_rt_h", ColumnType::Number),
    ("accel_random_walk_basis", ColumnType::Text),
    ("noise_note", ColumnType::Text),
];

/// One cell of a result row.
#[derive(Debug, Clone, PartialEq)]
pub enum Cell {
    /// No value.
    Empty,
    /// Text.
    Text(String),
    /// A real number.
    Number(f64),
    /// A count.
    Count(u64),
}

impl Cell {
    /// The cell as CSV field text (unquoted): numbers in the shortest form that reads back to
    /// the same f64 (ryu), empty for [`Cell::Empty`].
    pub fn text(&self) -> String {
        match self {
            Cell::Empty => String::new(),
            Cell::Text(t) => t.clone(),
            Cell::Number(x) if x.is_finite() => ryu::Buffer::new().format_finite(*x).to_string(),
            Cell::Number(x) => format!("{x}"),
            Cell::Count(n) => n.to_string(),
        }
    }

    /// Reads a cell of type `ty` back from [`Cell::text`]; `None` when the text is not of the type.
    pub fn parse(text: &str, ty: ColumnType) -> Option<Cell> {
        if text.is_empty() {
            return Some(Cell::Empty);
        }
        match ty {
            ColumnType::Text => Some(Cell::Text(text.to_string())),
            ColumnType::Number => text.parse().ok().map(Cell::Number),
            ColumnType::Count => text.parse().ok().map(Cell::Count),
        }
    }

    /// The number, if the cell holds one.
    pub fn number(&self) -> Option<f64> {
        match self {
            Cell::Number(x) => Some(*x),
            Cell::Count(n) => Some(*n as f64),
            _ => None,
        }
    }
}

/// One row of the results: a record's channel, one cell per [`COLUMNS`] entry.
#[derive(Debug, Clone, PartialEq)]
pub struct ResultRow(pub Vec<Cell>);

impl ResultRow {
    /// The cell of the column `name`, if there is such a column.
    pub fn get(&self, name: &str) -> Option<&Cell> {
        COLUMNS.iter().position(|(n, _)| *n == name).and_then(|i| self.0.get(i))
    }
}

/// What a batch evaluates: its inputs and the Allan options every record is analysed with.
#[derive(Debug, Clone)]
pub struct BatchRequest {
    /// The records, in order (see [`collect_inputs`]).
    pub inputs: Vec<PathBuf>,
    /// The options of each analysis (its `file` is replaced by each input).
    pub allan: AllanRequest,
    /// Worker threads (default: one per core).
    pub jobs: Option<usize>,
}

/// An input evaluated: its rows, to be journaled by the front end.
#[derive(Debug, Clone)]
pub struct DoneInput {
    /// The file as given.
    pub file: PathBuf,
    /// SHA-256 of its bytes, lower-case hex.
    pub sha256: String,
    /// One row per record (topic) and channel.
    pub rows: Vec<ResultRow>,
}

/// An input that could not be evaluated.
#[derive(Debug)]
pub struct FailedInput {
    /// The file as given.
    pub file: PathBuf,
    /// Why.
    pub error: EvalError,
}

/// An input passed over.
#[derive(Debug, Clone, PartialEq)]
pub enum Skipped {
    /// Its bytes were evaluated in an earlier run of the same batch (the journal holds them).
    AlreadyDone {
        /// The file as given.
        file: PathBuf,
    },
    /// The same bytes as another input of this run (evaluated once).
    SameAs {
        /// The file as given.
        file: PathBuf,
        /// The input evaluated in its place.
        original: PathBuf,
    },
}

/// Where the front end keeps what a batch has done: called from the worker threads as each
/// input ends.
pub trait BatchSink: Sync {
    /// An input was evaluated: keep it (the journal). An error makes the input a failure.
    fn done(&self, input: &DoneInput) -> Result<(), String>;
    /// An input failed (after `done` failed too, or without it); shown to the user at once.
    fn failed(&self, input: &FailedInput);
}

/// What a run of a batch did.
#[derive(Debug, Default)]
pub struct BatchOutcome {
    /// Inputs evaluated in this run, in input order.
    pub evaluated: Vec<DoneInput>,
    /// Inputs passed over (done before, or duplicates), in input order.
    pub skipped: Vec<Skipped>,
    /// Inputs that failed, in input order.
    pub failures: Vec<FailedInput>,
}

/// The journal of a batch: the inputs done by earlier runs, keyed by the SHA-256 of their bytes.
#[derive(Debug, Clone, Default)]
pub struct Journal {
    /// The fingerprint of the options the batch was run with ([`options_fingerprint`]).
    pub options: Option<String>,
    /// Inputs done, by SHA-256.
    pub entries: BTreeMap<String, DoneInput>,
    /// Lines that could not be read (a line cut short when a run was killed while writing it):
    /// their inputs are evaluated again.
    pub unreadable_lines: usize,
}

/// The first line of a journal written with options of fingerprint `options`.
pub fn journal_header(options: &str) -> String {
    format!("# gyrolab batch journal 1; options {options}\n")
}

/// One journal line (JSON, newline-terminated) for an input done: its SHA-256, file and rows
/// (cells as their CSV text, so that numbers read back bit for bit).
pub fn journal_line(input: &DoneInput) -> String {
    let rows: Vec<Vec<String>> = input.rows.iter().map(|r| r.0.iter().map(Cell::text).collect()).collect();
    let value = serde_json::json!({
        "sha256": input.sha256,
        "file": gyrolab_io::text::path_text(&input.file),
        "rows": rows,
    });
    value.to_string() + "\n"
}

impl Journal {
    /// Reads a journal's text (`path` names it in errors). A line that is not a whole entry
    /// (cut short by a kill) is counted in [`Journal::unreadable_lines`], not an error.
    pub fn parse(text: &str, path: &Path) -> EvalResult<Journal> {
        let mut journal = Journal::default();
        for (i, line) in text.split_inclusive('\n').enumerate() {
            if i == 0 {
                let options = line
                    .strip_prefix("# gyrolab batch journal 1; options ")
                    .map(|s| s.trim_end().to_string())
                    .filter(|_| line.ends_with('\n'));
                match options {
                    Some(o) => journal.options = Some(o),
                    None => return Err(DataError::new(
                        path,
                        "not a gyrolab batch journal (its first line is not `# gyrolab batch journal 1; options ...`)",
                    )
                    .at_line(1)
                    .into()),
                }
                continue;
            }
            match line.strip_suffix('\n').and_then(parse_entry) {
                Some(entry) => {
                    journal.entries.insert(entry.sha256.clone(), entry);
                }
                None => journal.unreadable_lines += 1,
            }
        }
        Ok(journal)
    }
}

fn parse_entry(line: &str) -> Option<DoneInput> {
    let v: serde_json::Value = serde_json::from_str(line).ok()?;
    let sha256 = v.get("sha256")?.as_str()?.to_string();
    let file = gyrolab_io::text::path_from_text(v.get("file")?.as_str()?)?;
    let mut rows = Vec::new();
    for r in v.get("rows")?.as_array()? {
        let cells = r.as_array()?;
        if cells.len() != COLUMNS.len() {
            return None;
        }
        let row: Option<Vec<Cell>> =
            cells.iter().zip(COLUMNS).map(|(c, (_, ty))| c.as_str().and_then(|t| Cell::parse(t, ty))).collect();
        rows.push(ResultRow(row?));
    }
    Some(DoneInput { file, sha256, rows })
}

/// The fingerprint of the options of a batch: SHA-256 of the program version and of every
/// Allan option but the file. A journal of other options is not resumed (its results would
/// not be comparable).
pub fn options_fingerprint(allan: &AllanRequest) -> String {
    let mut a = allan.clone();
    a.file = PathBuf::new();
    let text = format!("gyrolab {} {:?}", env!("CARGO_PKG_VERSION"), a);
    hex(&Sha256::digest(text.as_bytes()))
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// SHA-256 of a file's bytes (lower-case hex) and whether it is a SIMULATED record (its first
/// line says the simulator wrote it: then that line, without `# `;
/// [`gyrolab_io::provenance::simulator_title`]).
pub fn hash_file(path: &Path) -> Result<(String, Option<String>), DataError> {
    let err = |e: std::io::Error| DataError::new(path, format!("cannot read the file: {e}"));
    // A regular file only (a FIFO named among the inputs would block).
    let (mut f, _) = gyrolab_io::input_file::open_regular(path)?;
    let mut hasher = Sha256::new();
    let mut buf = vec![0u8; 1 << 20];
    let mut first: Vec<u8> = Vec::new();
    loop {
        let n = f.read(&mut buf).map_err(err)?;
        if n == 0 {
            break;
        }
        if first.len() < 256 {
            first.extend_from_slice(&buf[..n.min(256 - first.len())]);
        }
        hasher.update(&buf[..n]);
    }
    Ok((hex(&hasher.finalize()), gyrolab_io::provenance::simulator_title(&first)))
}

/// The inputs a batch found, and the entries it passed over with the reason.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CollectedInputs {
    /// The record files, in order.
    pub files: Vec<PathBuf>,
    /// Entries not taken, each with why: a FIFO, socket or device; a link out of the folder
    /// (without `follow_links`); a link back into a folder already walked (a cycle).
    pub passed_over: Vec<(PathBuf, String)>,
}

/// The inputs of a batch: each spec a file, a folder (its record files, see
/// [`RECORD_EXTENSIONS`], at any depth, in name order; hidden entries and `exclude` passed
/// over) or a glob pattern (`*`, `?`, `[...]`, `**`); each list file one spec a line (blank
/// lines and `#` comments passed over). A path given twice is taken once.
///
/// Only regular files are read: a FIFO, socket or device (named, or met in a folder) is passed
/// over with its kind, never opened (a FIFO would block). In a folder, a symbolic link is
/// followed when its target lies inside the folder given (or anywhere with `follow_links`),
/// and every folder is walked once (a link back to a folder already walked, a cycle such as
/// `a -> .`, is passed over), so a walk always ends.
pub fn collect_inputs(
    specs: &[String],
    lists: &[PathBuf],
    exclude: Option<&Path>,
    follow_links: bool,
) -> EvalResult<CollectedInputs> {
    let mut all: Vec<String> = specs.to_vec();
    for list in lists {
        gyrolab_io::input_file::check_regular(list)?;
        let text = std::fs::read_to_string(list)
            .map_err(|e| DataError::new(list, format!("cannot read the list of inputs: {e}")))?;
        all.extend(text.lines().map(str::trim).filter(|l| !l.is_empty() && !l.starts_with('#')).map(String::from));
    }
    let exclude = exclude.and_then(|p| p.canonicalize().ok());
    let mut found = CollectedInputs::default();
    for spec in &all {
        let path = Path::new(spec);
        if path.is_dir() {
            let mut walk = Walk {
                root: path.canonicalize().map_err(|e| DataError::io(path, &e))?,
                exclude: exclude.as_deref(),
                follow_links,
                visited: std::collections::HashSet::new(),
                found: &mut found,
            };
            walk.folder(path)?;
        } else if std::fs::symlink_metadata(path).is_ok() {
            match not_regular(path) {
                Some(kind) => found.passed_over.push((path.to_path_buf(), kind)),
                None => found.files.push(path.to_path_buf()),
            }
        } else if spec.contains(['*', '?', '[']) {
            let paths = glob::glob(spec).map_err(|e| {
                EvalError::conflict_on(&["inputs"], format!("'{spec}': not a usable pattern for {{inputs}}: {e}"))
            })?;
            let mut matched: Vec<PathBuf> = paths.filter_map(Result::ok).filter(|p| is_record(p)).collect();
            matched.sort();
            for p in matched {
                if p.is_dir() {
                    continue;
                }
                match not_regular(&p) {
                    Some(kind) => found.passed_over.push((p, kind)),
                    None => found.files.push(p),
                }
            }
        } else {
            return Err(DataError::new(path, "no such file or folder").into());
        }
    }
    let mut seen = std::collections::HashSet::new();
    found.files.retain(|p| seen.insert(p.clone()));
    Ok(found)
}

/// What a path is when it is not a regular file (following links): "a FIFO (named pipe)",
/// "a socket", ...; `None` for a regular file.
fn not_regular(path: &Path) -> Option<String> {
    match gyrolab_io::input_file::check_regular(path) {
        Ok(_) => None,
        Err(e) => Some(e.message.split(", not a regular file").next().unwrap_or("not a regular file").to_string()),
    }
}

fn is_record(p: &Path) -> bool {
    p.extension().and_then(|e| e.to_str()).is_some_and(|e| RECORD_EXTENSIONS.contains(&e.to_ascii_lowercase().as_str()))
}

/// One folder walk of [`collect_inputs`].
struct Walk<'a> {
    /// The folder given, canonical: links are followed only to targets inside it (unless
    /// `follow_links`).
    root: PathBuf,
    exclude: Option<&'a Path>,
    follow_links: bool,
    /// Canonical folders walked (a folder reached twice, through a link, is walked once).
    visited: std::collections::HashSet<PathBuf>,
    found: &'a mut CollectedInputs,
}

impl Walk<'_> {
    fn folder(&mut self, dir: &Path) -> EvalResult<()> {
        let canonical = dir.canonicalize().map_err(|e| DataError::io(dir, &e))?;
        if self.exclude == Some(canonical.as_path()) {
            return Ok(());
        }
        if !self.visited.insert(canonical) {
            self.found.passed_over.push((dir.to_path_buf(), "a folder already walked (a link cycle)".into()));
            return Ok(());
        }
        let read = std::fs::read_dir(dir).map_err(|e| DataError::new(dir, format!("cannot read the folder: {e}")))?;
        let mut entries: Vec<PathBuf> = read.filter_map(Result::ok).map(|e| e.path()).collect();
        entries.sort();
        for p in entries {
            if p.file_name().and_then(|n| n.to_str()).is_some_and(|n| n.starts_with('.')) {
                continue;
            }
            let Ok(meta) = std::fs::symlink_metadata(&p) else { continue };
            if meta.file_type().is_symlink() {
                let Ok(target) = p.canonicalize() else {
                    if is_record(&p) {
                        self.found.passed_over.push((p, "a link to nothing".into()));
                    }
                    continue;
                };
                if !self.follow_links && !target.starts_with(&self.root) {
                    if target.is_dir() || is_record(&p) {
                        self.found.passed_over.push((
                            p,
                            format!("a link out of the folder (to {}; --follow-links follows it)", target.display()),
                        ));
                    }
                    continue;
                }
            }
            if p.is_dir() {
                self.folder(&p)?;
            } else if is_record(&p) {
                match not_regular(&p) {
                    Some(kind) => self.found.passed_over.push((p, kind)),
                    None => self.found.files.push(p),
                }
            }
        }
        Ok(())
    }
}

/// The rows of one input: every channel of every record (topic) it holds.
pub fn evaluate_input(
    allan: &AllanRequest,
    file: &Path,
    sha256: &str,
    simulated: Option<&str>,
) -> EvalResult<Vec<ResultRow>> {
    let mut request = allan.clone();
    request.file = file.to_path_buf();
    let outcomes = analyse_records(&request)?;
    let mut rows = Vec::new();
    for outcome in &outcomes {
        for a in &outcome.analyses {
            rows.push(result_row(&allan_json_with(a, false), file, sha256, simulated));
        }
    }
    if rows.is_empty() {
        return Err(EvalError::conflict(format!("{}: no channel to analyse", file.display())));
    }
    Ok(rows)
}

/// The result row of one channel's JSON result.
pub fn result_row(j: &AllanJson, file: &Path, sha256: &str, simulated: Option<&str>) -> ResultRow {
    let text = |s: &str| Cell::Text(s.to_string());
    let num = |x: Option<f64>| x.map_or(Cell::Empty, Cell::Number);
    let opt_text = |s: Option<&str>| s.map_or(Cell::Empty, text);
    let basis = |readings: &[gyrolab_report::allan::ReadingJson], term: &str| {
        opt_text(readings.iter().find(|r| r.term == term).map(|r| r.basis))
    };
    // A term with a basis column: its value, or its upper bound (the basis beside it says
    // which), as the text prints `< 9.17`; empty only when absent.
    let reading = |readings: &[gyrolab_report::allan::ReadingJson], term: &str| {
        num(readings.iter().find(|r| r.term == term).and_then(|r| r.value))
    };
    let quantity = serde_json::to_value(j.quantity).ok().and_then(|v| v.as_str().map(String::from));
    let min = j.dev.iter().zip(&j.taus_s).filter(|(d, _)| d.is_finite()).min_by(|a, b| a.0.total_cmp(b.0));
    let noise = j.noise.as_ref();
    let gyro = |f: fn(&gyrolab_report::allan::NoiseJson) -> Option<f64>| num(noise.and_then(f));
    let fit = noise.and_then(|n| n.fit.as_ref());
    let readings = noise.map_or(&[][..], |n| &n.readings[..]);
    let accel = j.accel_noise.as_ref();
    let acc = |f: fn(&gyrolab_report::allan::AccelNoiseJson) -> Option<f64>| num(accel.and_then(f));
    let accel_readings = accel.map_or(&[][..], |n| &n.readings[..]);
    let fit_quality = fit.and_then(|f| serde_json::to_value(f.quality).ok()).and_then(|v| v.as_str().map(String::from));
    ResultRow(vec![
        text(&gyrolab_io::text::path_text(file)),
        text(sha256),
        opt_text(simulated.map(|s| format!("SIMULATED: {s}")).as_deref()),
        opt_text(j.topic.as_deref()),
        text(&j.channel),
        opt_text(quantity.as_deref()),
        text(&j.kind),
        text(&j.dev_unit),
        Cell::Number(j.tau0_s),
        Cell::Count(j.samples as u64),
        Cell::Number(j.samples as f64 * j.tau0_s),
        num(min.map(|m| *m.0)),
        num(min.map(|m| *m.1)),
        reading(readings, "arw"),
        if noise.is_some() { basis(readings, "arw") } else { Cell::Empty },
        reading(readings, "bias_instability"),
        if noise.is_some() { basis(readings, "bias_instability") } else { Cell::Empty },
        gyro(|n| n.allan_minimum_dph),
        gyro(|n| n.allan_minimum_tau_s),
        reading(readings, "rrw"),
        if noise.is_some() { basis(readings, "rrw") } else { Cell::Empty },
        gyro(|n| n.quantization_deg),
        gyro(|n| n.rate_ramp_dph_per_h),
        num(fit.and_then(|f| f.arw_deg_rt_h)),
        num(fit.and_then(|f| f.bias_instability_dph)),
        num(fit.and_then(|f| f.rrw_deg_h_rt_h)),
        opt_text(fit_quality.as_deref()),
        reading(accel_readings, "vrw"),
        if accel.is_some() { basis(accel_readings, "vrw") } else { Cell::Empty },
        acc(|n| n.bias_instability_ug),
        acc(|n| n.allan_minimum_ug),
        reading(accel_readings, "accel_random_walk"),
        if accel.is_some() { basis(accel_readings, "accel_random_walk") } else { Cell::Empty },
        opt_text(j.noise_note.as_deref()),
    ])
}

/// Runs a batch: each input hashed, passed over when `journal` holds its bytes (or another
/// input of this run has the same bytes), else analysed; inputs in parallel on `request.jobs`
/// threads (default: every core), each reported to `sink` and `progress` as it ends. A failing
/// input does not stop the others.
pub fn run_batch(
    request: &BatchRequest,
    journal: &Journal,
    sink: &dyn BatchSink,
    progress: &dyn Progress,
) -> EvalResult<BatchOutcome> {
    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(n) = request.jobs {
        gyrolab::validate::positive("jobs", n as f64)?;
        builder = builder.num_threads(n);
    }
    let pool = builder.build().map_err(|e| EvalError::Output(format!("cannot start the worker threads: {e}")))?;
    progress.begin(request.inputs.len() as u64);
    let claimed: Arc<Mutex<HashMap<String, PathBuf>>> = Arc::default();
    enum Ended {
        Done(DoneInput),
        Skipped(Skipped),
        Failed(FailedInput),
    }
    let one = |file: &PathBuf| -> Ended {
        let fail = |error: EvalError| {
            let f = FailedInput { file: file.clone(), error };
            sink.failed(&f);
            Ended::Failed(f)
        };
        let (sha256, simulated) = match hash_file(file) {
            Ok(h) => h,
            Err(e) => return fail(e.into()),
        };
        if journal.entries.contains_key(&sha256) {
            return Ended::Skipped(Skipped::AlreadyDone { file: file.clone() });
        }
        {
            let mut claimed = claimed.lock().unwrap_or_else(|p| p.into_inner());
            if let Some(original) = claimed.get(&sha256) {
                return Ended::Skipped(Skipped::SameAs { file: file.clone(), original: original.clone() });
            }
            claimed.insert(sha256.clone(), file.clone());
        }
        match evaluate_input(&request.allan, file, &sha256, simulated.as_deref()) {
            Ok(rows) => {
                let done = DoneInput { file: file.clone(), sha256, rows };
                match sink.done(&done) {
                    Ok(()) => Ended::Done(done),
                    Err(e) => fail(EvalError::Output(format!(
                        "{}: evaluated, but cannot keep the result: {e}",
                        file.display()
                    ))),
                }
            }
            Err(e) => fail(e),
        }
    };
    let ended: Vec<Ended> = pool.install(|| {
        request
            .inputs
            .par_iter()
            .map(|f| {
                let e = one(f);
                progress.advance(1);
                e
            })
            .collect()
    });
    let mut outcome = BatchOutcome::default();
    for e in ended {
        match e {
            Ended::Done(d) => outcome.evaluated.push(d),
            Ended::Skipped(s) => outcome.skipped.push(s),
            Ended::Failed(f) => outcome.failures.push(f),
        }
    }
    Ok(outcome)
}

/// Every row of a batch's journal, ordered by file and then by the record's own channel order
/// (the same order whatever order the inputs ended in).
pub fn journal_rows(journal: &Journal) -> Vec<ResultRow> {
    let mut entries: Vec<&DoneInput> = journal.entries.values().collect();
    entries.sort_by(|a, b| a.file.cmp(&b.file).then_with(|| a.sha256.cmp(&b.sha256)));
    entries.into_iter().flat_map(|e| e.rows.iter().cloned()).collect()
}

/// The results as CSV: a header of [`COLUMNS`] names, one line per row; text fields quoted
/// when they hold a comma, quote or line break (RFC 4180).
pub fn results_csv(rows: &[ResultRow]) -> String {
    let mut s = COLUMNS.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(",");
    s.push('\n');
    for r in rows {
        let fields: Vec<String> = r.0.iter().map(|c| csv_field(&c.text())).collect();
        s.push_str(&fields.join(","));
        s.push('\n');
    }
    s
}

/// The results as a Parquet file (one row group, zstd): the [`COLUMNS`] as optional UTF-8,
/// DOUBLE or INT64 columns of the same names, empty cells null.
pub fn results_parquet(rows: &[ResultRow]) -> EvalResult<Vec<u8>> {
    use gyrolab_io::parquet_table::{write_table, ColumnValues};
    let cells = |i: usize| rows.iter().map(move |r| r.0.get(i).unwrap_or(&Cell::Empty));
    let columns: Vec<(String, ColumnValues)> = COLUMNS
        .iter()
        .enumerate()
        .map(|(i, (name, ty))| {
            let values = match ty {
                ColumnType::Text => ColumnValues::Text(
                    cells(i).map(|c| if *c == Cell::Empty { None } else { Some(c.text()) }).collect(),
                ),
                ColumnType::Number => ColumnValues::Double(cells(i).map(Cell::number).collect()),
                ColumnType::Count => ColumnValues::Int(
                    cells(i)
                        .map(|c| match c {
                            Cell::Count(n) => Some(i64::try_from(*n).unwrap_or(i64::MAX)),
                            _ => None,
                        })
                        .collect(),
                ),
            };
            (name.to_string(), values)
        })
        .collect();
    write_table("batch_results", &columns)
        .map_err(|e| EvalError::Output(format!("cannot write the Parquet results: {e}")))
}

/// `FILE: reason`, the file named once (`flag` spells a request field as the front end does).
pub fn failure_text(input: &FailedInput, flag: &dyn Fn(&str) -> String) -> String {
    let reason = input.error.render(flag);
    let file = input.file.display().to_string();
    if reason.starts_with(&file) {
        reason
    } else {
        format!("{file}: {reason}")
    }
}

/// failures.csv of a batch with failures (`file,reason`, both quoted), `None` without any.
pub fn failures_csv(failures: &[FailedInput], flag: &dyn Fn(&str) -> String) -> Option<String> {
    (!failures.is_empty()).then(|| {
        let mut s = String::from("file,reason\n");
        for f in failures {
            let reason = f.error.render(flag).replace('"', "\"\"");
            s.push_str(&format!("\"{}\",\"{reason}\"\n", gyrolab_io::text::path_text(&f.file).replace('"', "\"\"")));
        }
        s
    })
}

/// Opens (or starts) the journal `name` of the output folder `out`: the entries of earlier runs
/// and the file to append to; a journal of other options is refused (a conflict).
pub fn open_journal(out: &Path, name: &str, options: &str) -> EvalResult<(Journal, std::fs::File)> {
    use std::io::Write;
    let path = out.join(name);
    let io = |e: std::io::Error| EvalError::Output(format!("{}: {e}", path.display()));
    std::fs::create_dir_all(out)
        .map_err(|e| EvalError::Output(format!("{}: cannot create the folder: {e}", out.display())))?;
    let journal = match std::fs::read(&path) {
        Ok(bytes) => {
            let text = String::from_utf8_lossy(&bytes);
            let journal = Journal::parse(&text, &path)?;
            if journal.options.as_deref() != Some(options) {
                return Err(EvalError::conflict(format!(
                    "{}: this folder holds a batch run with other options or by another gyrolab version; give another --out, or delete {} to start the batch over",
                    out.display(),
                    path.display()
                )));
            }
            let mut f = std::fs::OpenOptions::new().append(true).open(&path).map_err(io)?;
            if !text.ends_with('\n') {
                // The last line was cut short by a killed run: end it, so the next entry starts
                // on a line of its own (the cut line is passed over when read).
                f.write_all(b"\n").map_err(io)?;
            }
            journal
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            gyrolab_io::atomic::write_atomic(&path, journal_header(options).as_bytes()).map_err(io)?;
            Journal { options: Some(options.to_string()), ..Journal::default() }
        }
        Err(e) => return Err(io(e)),
    };
    let file = std::fs::OpenOptions::new().append(true).open(&path).map_err(io)?;
    Ok((journal, file))
}

/// The fleet at a glance: per channel name and noise term, how many records resolved it and
/// the median, smallest and largest value.
pub fn summary_text(rows: &[ResultRow]) -> String {
    const TERMS: [&str; 6] = [
        "arw_deg_rt_h",
        "bias_instability_dph",
        "rrw_deg_h_rt_h",
        "vrw_m_s_rt_h",
        "bias_instability_ug",
        "accel_random_walk_m_s2_rt_h",
    ];
    let simulated = rows.iter().filter(|r| matches!(r.get("simulated"), Some(Cell::Text(_)))).count();
    let mut groups: BTreeMap<(String, &str), (usize, Vec<f64>)> = BTreeMap::new();
    for r in rows {
        let channel = match (r.get("topic"), r.get("channel")) {
            (Some(Cell::Text(t)), Some(Cell::Text(c))) => format!("{t}/{c}"),
            (_, Some(Cell::Text(c))) => c.clone(),
            _ => String::new(),
        };
        for term in TERMS {
            let applies = match term {
                "vrw_m_s_rt_h" | "bias_instability_ug" | "accel_random_walk_m_s2_rt_h" => {
                    matches!(r.get("vrw_basis"), Some(Cell::Text(_)))
                }
                _ => matches!(r.get("arw_basis"), Some(Cell::Text(_))),
            };
            if !applies {
                continue;
            }
            let g = groups.entry((channel.clone(), term)).or_default();
            g.0 += 1;
            if let Some(x) = r.get(term).and_then(Cell::number) {
                g.1.push(x);
            }
        }
    }
    if groups.is_empty() {
        return "No noise terms (no channel in deg/s or m/s^2; give --unit or a calibration).\n".into();
    }
    let mut lines =
        vec![["channel".to_string(), "term".into(), "resolved".into(), "median".into(), "min".into(), "max".into()]];
    let g4 = |x: f64| format!("{x:.4e}");
    for ((channel, term), (n, mut v)) in groups {
        v.sort_by(f64::total_cmp);
        let median = match v.len() {
            0 => None,
            k if k % 2 == 1 => Some(v[k / 2]),
            k => Some(0.5 * (v[k / 2 - 1] + v[k / 2])),
        };
        lines.push([
            channel,
            term.to_string(),
            format!("{}/{n}", v.len()),
            median.map_or("-".into(), g4),
            v.first().map_or("-".into(), |x| g4(*x)),
            v.last().map_or("-".into(), |x| g4(*x)),
        ]);
    }
    let widths: Vec<usize> = (0..6).map(|i| lines.iter().map(|l| l[i].chars().count()).max().unwrap_or(0)).collect();
    let mut s = String::new();
    for l in &lines {
        let cells: Vec<String> = l.iter().zip(&widths).map(|(c, w)| format!("{c:<w$}")).collect();
        s.push_str(cells.join("  ").trim_end());
        s.push('\n');
    }
    if simulated > 0 {
        s.push_str(&format!(
            "SIMULATED: {simulated} of {} rows come from simulated records (column `simulated`)\n",
            rows.len()
        ));
    }
    s
}

/// A batch written into a folder (`gyrolab batch`): the inputs (files, folders, glob patterns,
/// and list files), the output folder and its journal's name, the analysis and the workers.
pub struct BatchFolderRequest<'a> {
    /// Files, folders or glob patterns.
    pub inputs: &'a [String],
    /// Files listing inputs, one per line.
    pub lists: &'a [PathBuf],
    /// The output folder (results.csv, results.parquet, failures.csv, the journal).
    pub out: &'a Path,
    /// Follow symbolic links in folders.
    pub follow_links: bool,
    /// The analysis of each record.
    pub allan: AllanRequest,
    /// Workers (default: every core).
    pub jobs: Option<usize>,
    /// The journal's file name in `out`.
    pub journal: &'a str,
}

/// What a batch into a folder did: the summary to print (counts, the fleet table, the files
/// written) and, when inputs failed, the message saying so (the others are written).
pub struct BatchFolderOutcome {
    /// The summary.
    pub summary: String,
    /// `Some(message)` when some inputs failed.
    pub failed: Option<String>,
}

/// Appends each input done to the journal (one line, one write, under a lock) and shows each
/// failure.
struct JournalSink<'a> {
    file: Mutex<std::fs::File>,
    show: &'a (dyn Fn(&str) + Sync),
    flag: &'a (dyn Fn(&str) -> String + Sync),
}

impl BatchSink for JournalSink<'_> {
    fn done(&self, input: &DoneInput) -> Result<(), String> {
        let line = journal_line(input);
        let mut f = self.file.lock().unwrap_or_else(|p| p.into_inner());
        std::io::Write::write_all(&mut *f, line.as_bytes()).map_err(|e| format!("cannot append to the journal: {e}"))
    }
    fn failed(&self, input: &FailedInput) {
        (self.show)(&format!("failed: {}", failure_text(input, self.flag)));
    }
}

/// Runs a batch into its folder: inputs collected, the journal opened (a batch started again
/// passes over what it finished), every record evaluated on the workers, the union of this run
/// and earlier ones written whole (results.csv, results.parquet, failures.csv when inputs
/// failed). `show` prints notes and failure lines as they come; `flag` spells request fields.
pub fn batch_folder(
    request: &BatchFolderRequest<'_>,
    progress: &dyn Progress,
    show: &(dyn Fn(&str) + Sync),
    flag: &(dyn Fn(&str) -> String + Sync),
) -> EvalResult<BatchFolderOutcome> {
    let collected = collect_inputs(request.inputs, request.lists, Some(request.out), request.follow_links)?;
    for (path, why) in &collected.passed_over {
        show(&format!("note: {}: passed over: {why}", gyrolab_io::text::path_text(path)));
    }
    let inputs = collected.files;
    if inputs.is_empty() {
        return Err(EvalError::conflict("no record to evaluate: give files, folders, glob patterns or --list FILE"));
    }
    let options = options_fingerprint(&request.allan);
    let (mut journal, file) = open_journal(request.out, request.journal, &options)?;
    if journal.unreadable_lines > 0 {
        show(&format!(
            "note: {} line(s) of {} were cut short by an interrupted run; their records are evaluated again",
            journal.unreadable_lines,
            request.out.join(request.journal).display()
        ));
    }
    let sink = JournalSink { file: Mutex::new(file), show, flag };
    let batch = BatchRequest { inputs, allan: request.allan.clone(), jobs: request.jobs };
    let outcome = run_batch(&batch, &journal, &sink, progress)?;
    let file = sink.file.into_inner().unwrap_or_else(|p| p.into_inner());
    file.sync_data().map_err(|e| EvalError::Output(format!("{}: {e}", request.out.join(request.journal).display())))?;
    let now = outcome.evaluated.len();
    // The batch's inputs, which no table may overwrite (`--out .` among the records).
    let input_files: Vec<PathBuf> = outcome
        .evaluated
        .iter()
        .map(|d| d.file.clone())
        .chain(outcome.failures.iter().map(|f| f.file.clone()))
        .chain(outcome.skipped.iter().map(|s| match s {
            Skipped::AlreadyDone { file } | Skipped::SameAs { file, .. } => file.clone(),
        }))
        .collect();
    for d in outcome.evaluated {
        journal.entries.insert(d.sha256.clone(), d);
    }
    // The union of this run and the earlier ones, in file order: complete or untouched.
    let rows = journal_rows(&journal);
    let csv = results_csv(&rows);
    let parquet = results_parquet(&rows)?;
    let failures_csv = failures_csv(&outcome.failures, flag);
    let mut files: Vec<(&str, &[u8])> = vec![("results.csv", csv.as_bytes()), ("results.parquet", &parquet)];
    if let Some(f) = &failures_csv {
        files.push(("failures.csv", f.as_bytes()));
    }
    let inputs: Vec<&std::path::Path> = input_files.iter().map(PathBuf::as_path).collect();
    gyrolab_io::atomic::write_folder(request.out, &files, &inputs)?;
    if failures_csv.is_none() {
        // A list of failures from an earlier run would no longer be true.
        let _ = std::fs::remove_file(request.out.join("failures.csv"));
    }
    // Byte-identical inputs: one row, both names said.
    for s in &outcome.skipped {
        if let Skipped::SameAs { file, original } = s {
            show(&format!(
                "note: {}: the same bytes as {}: evaluated once, its rows are {}'s",
                gyrolab_io::text::path_text(file),
                gyrolab_io::text::path_text(original),
                gyrolab_io::text::path_text(original)
            ));
        }
    }
    let done_before = outcome.skipped.iter().filter(|s| matches!(s, Skipped::AlreadyDone { .. })).count();
    let duplicates = outcome.skipped.len() - done_before;
    let summary = {
        let mut s = format!(
            "{} inputs: {now} evaluated now, {done_before} already done (journal), {duplicates} same bytes as another input, {} failed\n",
            batch.inputs.len(),
            outcome.failures.len()
        );
        s.push_str(&summary_text(&rows));
        s.push_str(&format!(
            "Wrote {} ({} rows), {}{}\n",
            request.out.join("results.csv").display(),
            rows.len(),
            request.out.join("results.parquet").display(),
            if failures_csv.is_some() {
                format!(", {}", request.out.join("failures.csv").display())
            } else {
                String::new()
            }
        ));
        s
    };
    let failed = (!outcome.failures.is_empty()).then(|| {
        format!(
            "{} of {} inputs failed (listed above and in {}); the others are in {}",
            outcome.failures.len(),
            batch.inputs.len(),
            request.out.join("failures.csv").display(),
            request.out.join("results.csv").display()
        )
    });
    Ok(BatchFolderOutcome { summary, failed })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(file: &str, x: f64) -> ResultRow {
        let mut cells = vec![Cell::Empty; COLUMNS.len()];
        cells[0] = Cell::Text(file.into());
        cells[1] = Cell::Text("ab".into());
        cells[4] = Cell::Text("rate, \"x\"".into());
        cells[8] = Cell::Number(x);
        cells[9] = Cell::Count(60_000);
        ResultRow(cells)
    }

    #[test]
    fn a_journal_reads_back_bit_for_bit_and_passes_over_a_line_cut_short() {
        let x = 0.1 + 0.2; // not a short decimal
        let done = DoneInput { file: "a/b.csv".into(), sha256: "ab".into(), rows: vec![row("a/b.csv", x)] };
        let line = journal_line(&done);
        let mut text = journal_header("f00") + &line;
        text.push_str(&line[..line.len() / 2]); // a run killed while writing its next line
        let j = Journal::parse(&text, Path::new("j")).unwrap();
        assert_eq!(j.options.as_deref(), Some("f00"));
        assert_eq!(j.entries.len(), 1);
        assert_eq!(j.unreadable_lines, 1);
        assert_eq!(j.entries["ab"].rows, done.rows);
        assert_eq!(j.entries["ab"].rows[0].get("tau0_s").and_then(Cell::number), Some(x));
    }

    #[test]
    fn a_file_that_is_not_a_journal_is_an_error_naming_it() {
        let e = Journal::parse("time_s,rate\n", Path::new("out/journal")).unwrap_err().to_string();
        assert!(e.contains("out/journal") && e.contains("not a gyrolab batch journal"), "{e}");
    }

    #[test]
    fn the_csv_quotes_text_and_the_parquet_reads_back_the_same_cells() {
        use parquet::file::reader::{FileReader, SerializedFileReader};
        let rows = vec![row("a.csv", 0.01), row("b.csv", 1.0 / 3.0)];
        let csv = results_csv(&rows);
        assert!(csv.lines().nth(1).unwrap().contains(",\"rate, \"\"x\"\"\","), "{csv}");
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("results.parquet");
        std::fs::write(&p, results_parquet(&rows).unwrap()).unwrap();
        let reader = SerializedFileReader::new(std::fs::File::open(&p).unwrap()).unwrap();
        assert_eq!(reader.metadata().file_metadata().num_rows(), 2);
        let read: Vec<_> = reader.get_row_iter(None).unwrap().map(|r| r.unwrap().to_string()).collect();
        assert!(read[1].contains("tau0_s: 0.3333333333333333"), "{}", read[1]);
        assert!(read[0].contains("file: \"a.csv\"") && read[0].contains("samples: 60000"), "{}", read[0]);
        assert!(read[0].contains("topic: null"), "{}", read[0]);
    }

    #[test]
    fn a_simulated_record_is_recognised_by_its_first_line() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("s.csv");
        std::fs::write(&p, "# gyrolab simulated static record\n# seed = 3\ntime_s,rate_dps\n0,1\n").unwrap();
        let (sha, sim) = hash_file(&p).unwrap();
        assert_eq!(sim.as_deref(), Some("gyrolab simulated static record"));
        // SHA-256 of the bytes, checked against sha256sum's value of the same text.
        assert_eq!(sha.len(), 64);
        let q = dir.path().join("t.csv");
        std::fs::write(&q, "abc").unwrap();
        assert_eq!(
            hash_file(&q).unwrap(),
            ("ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad".into(), None)
        );
    }
}
