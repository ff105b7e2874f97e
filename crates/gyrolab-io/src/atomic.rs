//! Writing output files whole or not at all: write to a temporary file beside the target, then
//! rename it into place.
//!
//! A long output also asks the kernel to start writing each finished 32 MiB to disk while the
//! program goes on producing the rest (Linux `sync_file_range(2)` with `SYNC_FILE_RANGE_WRITE`, a
//! hint that does not wait for the data to reach the disk). Without it the whole file waits in
//! the page cache until the final `fsync`, which then writes it all with nothing left to overlap.

use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Temporary files being written (their paths), removed by [`remove_temporaries`] when the
/// program is interrupted (the front end's Ctrl-C handler calls it).
static TEMPORARIES: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

fn register(path: &Path) {
    if let Ok(mut t) = TEMPORARIES.lock() {
        t.push(path.to_path_buf());
    }
}

fn unregister(path: &Path) {
    if let Ok(mut t) = TEMPORARIES.lock() {
        t.retain(|p| p != path);
    }
}

/// Removes every temporary file still being written (for an interrupt handler; the outputs
/// they were to replace stay untouched). Returns how many were removed.
pub fn remove_temporaries() -> usize {
    let list = match TEMPORARIES.lock() {
        Ok(mut t) => std::mem::take(&mut *t),
        Err(_) => return 0,
    };
    list.iter().filter(|p| std::fs::remove_file(p).is_ok()).count()
}

/// Bytes written between two requests to start write-back.
const WRITEBACK_CHUNK: u64 = 32 << 20;

/// The name prefix of this process's staged files: `.gyrolab-<pid>-` (then random, `.tmp`), so
/// that a later run can tell a killed run's leftovers from a running one's.
fn staging_prefix() -> String {
    format!(".gyrolab-{}-", std::process::id())
}

/// Removes the staged files and folders a killed run left in `dir` (`.gyrolab-<pid>-*.tmp` whose process
/// no longer exists; never another live process's, never the `.gyrolab-old-*` copies a
/// replacement keeps, which may be the only copy of a file a run was replacing when killed).
/// Returns the files removed. Errors are ignored: cleaning is a courtesy, never a failure.
pub fn clean_leftovers(dir: &Path) -> Vec<PathBuf> {
    let mut removed = Vec::new();
    let Ok(entries) = std::fs::read_dir(dir) else { return removed };
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(name) = name.to_str() else { continue };
        let Some(rest) = name.strip_prefix(".gyrolab-").filter(|_| name.ends_with(".tmp")) else { continue };
        let Some(pid) = rest.split('-').next().and_then(|p| p.parse::<u32>().ok()) else { continue };
        if pid == std::process::id() || process_alive(pid) {
            continue;
        }
        // A staged file, or a staged folder (a folder written whole, then renamed into place).
        let gone = match entry.file_type() {
            Ok(t) if t.is_file() => std::fs::remove_file(entry.path()).is_ok(),
            Ok(t) if t.is_dir() => std::fs::remove_dir_all(entry.path()).is_ok(),
            _ => false,
        };
        if gone {
            removed.push(entry.path());
        }
    }
    removed
}

/// Whether process `pid` exists (signal 0: no signal sent, only the check).
fn process_alive(pid: u32) -> bool {
    #[cfg(unix)]
    {
        let Ok(pid) = libc::pid_t::try_from(pid) else { return true };
        // SAFETY: kill with signal 0 sends nothing; it only checks the process exists.
        let r = unsafe { libc::kill(pid, 0) };
        r == 0 || std::io::Error::last_os_error().raw_os_error() != Some(libc::ESRCH)
    }
    #[cfg(not(unix))]
    {
        let _ = pid;
        true
    }
}

/// Writes `bytes` to `path` atomically (temporary file in the same folder, then rename).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    write_atomic_with(path, |w| w.write_all(bytes))
}

/// Streams output into `path` atomically: `fill` writes into a buffered temporary file that
/// replaces `path` only when `fill` and the final flush succeed.
pub fn write_atomic_with(
    path: &Path,
    fill: impl FnOnce(&mut (dyn Write + Send)) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    clean_leftovers(dir);
    let tmp = tempfile::Builder::new().prefix(&staging_prefix()).suffix(".tmp").tempfile_in(dir)?;
    let tmp_path = tmp.path().to_path_buf();
    register(&tmp_path);
    let result = write_and_persist(tmp, path, fill);
    unregister(&tmp_path);
    result
}

fn write_and_persist(
    tmp: tempfile::NamedTempFile,
    path: &Path,
    fill: impl FnOnce(&mut (dyn Write + Send)) -> std::io::Result<()>,
) -> std::io::Result<()> {
    // Temporary files are private (0600); an output file is an ordinary file (0644).
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        tmp.as_file().set_permissions(std::fs::Permissions::from_mode(0o644))?;
    }
    {
        let file = EarlyWriteback::new(tmp.as_file(), WRITEBACK_CHUNK, start_writeback);
        let mut w = std::io::BufWriter::with_capacity(1 << 16, file);
        fill(&mut w)?;
        w.flush()?;
    }
    tmp.as_file().sync_all()?;
    tmp.persist(path).map_err(|e| e.error)?;
    Ok(())
}

/// One file of a set of outputs ([`write_outputs`]): its target and its bytes, given whole or
/// written by a function into the temporary file (for outputs too large to hold in memory).
pub struct OutputFile<'a> {
    /// Where the file goes.
    pub path: PathBuf,
    /// Its content.
    content: Content<'a>,
}

/// A function that writes a file's bytes into the writer it is given.
type Fill<'a> = Box<dyn FnOnce(&mut (dyn Write + Send)) -> std::io::Result<()> + 'a>;

/// The content of an [`OutputFile`].
enum Content<'a> {
    /// The bytes, whole.
    Bytes(std::borrow::Cow<'a, [u8]>),
    /// A function that writes them.
    Stream(Fill<'a>),
}

impl<'a> OutputFile<'a> {
    /// A file of these bytes.
    pub fn bytes(path: impl Into<PathBuf>, bytes: impl Into<std::borrow::Cow<'a, [u8]>>) -> OutputFile<'a> {
        OutputFile { path: path.into(), content: Content::Bytes(bytes.into()) }
    }

    /// A file whose bytes `fill` writes (into a buffered temporary file).
    pub fn stream(
        path: impl Into<PathBuf>,
        fill: impl FnOnce(&mut (dyn Write + Send)) -> std::io::Result<()> + 'a,
    ) -> OutputFile<'a> {
        OutputFile { path: path.into(), content: Content::Stream(Box::new(fill)) }
    }
}

/// Why a set of outputs was not written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputRefusal {
    /// The target is a file the run reads (an output never overwrites an input).
    IsAnInput,
    /// Two outputs of the run name one file.
    NamedTwice,
    /// A folder (or something else that is not a file) is where the file goes.
    NotAFile,
    /// A file name with a folder in it where a plain name is needed.
    NotAPlainName,
    /// Writing or renaming failed (a full disk, a missing folder, no permission).
    Io,
}

/// A set of outputs not written: which target, why, and what is on disk afterwards. Every
/// target is then as it was before the run (see [`write_outputs`]).
#[derive(Debug)]
pub struct OutputError {
    /// The target the failure is about.
    pub path: PathBuf,
    /// Why.
    pub refusal: OutputRefusal,
    /// The system's error, for [`OutputRefusal::Io`].
    pub source: Option<std::io::Error>,
    /// Every target of the run, with whether a file is there afterwards (as it was before).
    pub targets: Vec<(PathBuf, bool)>,
}

impl OutputError {
    /// Whether the failure is the request's (an input or a folder in the way, a file named
    /// twice, a bad name): bad usage, not a failure of the system.
    pub fn is_usage(&self) -> bool {
        self.refusal != OutputRefusal::Io
    }

    /// What is on disk afterwards, in words: "no file of this run was written; k.yaml is as it
    /// was, v.yaml does not exist".
    pub fn aftermath(&self) -> String {
        let (kept, absent): (Vec<_>, Vec<_>) = self.targets.iter().partition(|(_, there)| *there);
        let names =
            |v: &[&(PathBuf, bool)]| v.iter().map(|(p, _)| p.display().to_string()).collect::<Vec<_>>().join(", ");
        let mut s = String::from("no file of this run was written");
        if !kept.is_empty() {
            s.push_str(&format!("; left as they were: {}", names(&kept)));
        }
        if !absent.is_empty() {
            s.push_str(&format!("; not there: {}", names(&absent)));
        }
        s
    }
}

impl std::fmt::Display for OutputError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let why = match (self.refusal, &self.source) {
            (OutputRefusal::IsAnInput, _) => {
                "this file is an input of the run, and an output never overwrites an input: choose another output path or folder".to_string()
            }
            (OutputRefusal::NamedTwice, _) => "two outputs of the run name this file: each output needs its own file".to_string(),
            (OutputRefusal::NotAFile, _) => "a folder (or something else that is not a file) is in the way".to_string(),
            (OutputRefusal::NotAPlainName, _) => "not a plain file name".to_string(),
            (OutputRefusal::Io, Some(e)) => format!("cannot write the file: {e}"),
            (OutputRefusal::Io, None) => "cannot write the file".to_string(),
        };
        write!(f, "{}: {why} ({})", self.path.display(), self.aftermath())
    }
}

impl std::error::Error for OutputError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        self.source.as_ref().map(|e| e as _)
    }
}

/// Whether `target`, written by rename, would replace `input`: the same directory entry (the
/// same folder, canonically, and name) or, both existing, the same file (a hard link: the output
/// would take the input's name away from it).
fn replaces(target: &Path, input: &Path) -> bool {
    let entry = |p: &Path| -> Option<(PathBuf, std::ffi::OsString)> {
        let dir = match p.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        Some((std::fs::canonicalize(dir).ok()?, p.file_name()?.to_os_string()))
    };
    if let (Some(a), Some(b)) = (entry(target), entry(input)) {
        if a == b {
            return true;
        }
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if let (Ok(t), Ok(i)) = (std::fs::symlink_metadata(target), std::fs::metadata(input)) {
            return t.is_file() && t.dev() == i.dev() && t.ino() == i.ino();
        }
    }
    false
}

/// Writes a set of files, each anywhere, all or none as far as a file system allows, and never
/// over one of `inputs`:
/// 1. every target is checked first: not an input (nor a hard link of one), not named twice,
///    not a folder;
/// 2. every file is written to a temporary file beside its target (mode 0644, fsynced);
/// 3. only when all are written are they renamed into place, in order; the files being replaced
///    are kept as hard links until then, so that should a rename still fail, the ones already
///    replaced are put back (and new ones removed): the targets never mix files of two runs.
///
/// A failure leaves every target as it was; the error names the file it is about and what is
/// on disk afterwards ([`OutputError::aftermath`]). No temporary file is left behind.
pub fn write_outputs(files: Vec<OutputFile<'_>>, inputs: &[&Path]) -> Result<Vec<PathBuf>, OutputError> {
    let targets: Vec<PathBuf> = files.iter().map(|f| f.path.clone()).collect();
    let fail = |path: &Path, refusal: OutputRefusal, source: Option<std::io::Error>| OutputError {
        path: path.to_path_buf(),
        refusal,
        source,
        targets: targets.iter().map(|t| (t.clone(), std::fs::symlink_metadata(t).is_ok())).collect(),
    };
    for (i, path) in targets.iter().enumerate() {
        if inputs.iter().any(|input| replaces(path, input)) {
            return Err(fail(path, OutputRefusal::IsAnInput, None));
        }
        if targets[..i].iter().any(|other| replaces(path, other) || same_written_path(path, other)) {
            return Err(fail(path, OutputRefusal::NamedTwice, None));
        }
        if std::fs::symlink_metadata(path).is_ok_and(|m| !m.is_file() && !m.file_type().is_symlink()) {
            return Err(fail(path, OutputRefusal::NotAFile, None));
        }
    }
    let mut staged: Vec<(tempfile::NamedTempFile, PathBuf)> = Vec::with_capacity(files.len());
    let release = |staged: &[(tempfile::NamedTempFile, PathBuf)]| staged.iter().for_each(|(t, _)| unregister(t.path()));
    for file in files {
        let dir = match file.path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        match stage_in(&dir, file.content) {
            Ok(tmp) => staged.push((tmp, file.path)),
            Err(e) => {
                release(&staged);
                drop(staged);
                return Err(fail(&file.path, OutputRefusal::Io, Some(e)));
            }
        }
    }
    let temporaries: Vec<PathBuf> = staged.iter().map(|(t, _)| t.path().to_path_buf()).collect();
    let unregister_all = || temporaries.iter().for_each(|t| unregister(t));
    // The files being replaced, kept as hard links beside them until every rename is done.
    let mut kept: Vec<(PathBuf, PathBuf)> = Vec::new();
    for (n, (_, path)) in staged.iter().enumerate() {
        if std::fs::symlink_metadata(path).is_ok_and(|m| m.is_file() || m.file_type().is_symlink()) {
            let dir = match path.parent() {
                Some(p) if !p.as_os_str().is_empty() => p,
                _ => Path::new("."),
            };
            let keep = dir.join(format!(".gyrolab-old-{}-{n}.tmp", std::process::id()));
            let _ = std::fs::remove_file(&keep);
            if let Err(e) = std::fs::hard_link(path, &keep) {
                kept.iter().for_each(|(k, _)| drop(std::fs::remove_file(k)));
                unregister_all();
                let path = path.clone();
                drop(staged);
                return Err(fail(&path, OutputRefusal::Io, Some(e)));
            }
            register(&keep);
            kept.push((keep, path.clone()));
        }
    }
    let (written, result) = persist_in_order(staged);
    if result.is_err() {
        // Put every target back as it was: the new files out, the old ones in.
        for path in &written {
            match kept.iter().find(|(_, p)| p == path) {
                Some((keep, _)) => drop(std::fs::rename(keep, path)),
                None => drop(std::fs::remove_file(path)),
            }
        }
    }
    for (keep, _) in &kept {
        let _ = std::fs::remove_file(keep);
        unregister(keep);
    }
    unregister_all();
    match result {
        Ok(()) => Ok(written),
        Err((path, e)) => Err(fail(&path, OutputRefusal::Io, Some(e))),
    }
}

/// Whether two output paths name one file as written (relative to the working folder, `.`
/// components dropped; symbolic links and `..` are not resolved), for targets that may not
/// exist yet.
pub fn same_written_path(a: &Path, b: &Path) -> bool {
    let norm = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    norm(a) == norm(b)
}

/// Writes a folder of files all or none ([`write_outputs`]): creates `dir`, then writes every
/// `(name, bytes)` into it; `inputs` are never overwritten. Other files in `dir` are not touched.
pub fn write_folder(dir: &Path, files: &[(&str, &[u8])], inputs: &[&Path]) -> Result<Vec<PathBuf>, OutputError> {
    let targets = || files.iter().map(|(n, _)| (dir.join(n), false)).collect::<Vec<_>>();
    for (name, _) in files {
        if Path::new(name).file_name() != Some(std::ffi::OsStr::new(name)) {
            let mut targets = targets();
            targets.iter_mut().for_each(|(p, there)| *there = std::fs::symlink_metadata(p).is_ok());
            return Err(OutputError {
                path: dir.join(name),
                refusal: OutputRefusal::NotAPlainName,
                source: None,
                targets,
            });
        }
    }
    if let Err(e) = std::fs::create_dir_all(dir) {
        return Err(OutputError {
            path: dir.to_path_buf(),
            refusal: OutputRefusal::Io,
            source: Some(e),
            targets: targets(),
        });
    }
    write_outputs(files.iter().map(|(name, bytes)| OutputFile::bytes(dir.join(name), *bytes)).collect(), inputs)
}

/// Renames each staged file onto its target, in order, stopping at the first failure: (the
/// targets written, the failure naming its file).
#[allow(clippy::type_complexity)]
fn persist_in_order(
    staged: Vec<(tempfile::NamedTempFile, PathBuf)>,
) -> (Vec<PathBuf>, Result<(), (PathBuf, std::io::Error)>) {
    let mut written = Vec::with_capacity(staged.len());
    for (tmp, path) in staged {
        if let Err(e) = tmp.persist(&path) {
            return (written, Err((path, e.error)));
        }
        written.push(path);
    }
    (written, Ok(()))
}

/// A temporary file in `dir` holding `content` (mode 0644, synced to disk), registered for
/// removal on a signal until it is persisted or dropped.
fn stage_in(dir: &Path, content: Content<'_>) -> std::io::Result<tempfile::NamedTempFile> {
    clean_leftovers(dir);
    let tmp = tempfile::Builder::new().prefix(&staging_prefix()).suffix(".tmp").tempfile_in(dir)?;
    register(tmp.path());
    let filled = (|| {
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            tmp.as_file().set_permissions(std::fs::Permissions::from_mode(0o644))?;
        }
        {
            let file = EarlyWriteback::new(tmp.as_file(), WRITEBACK_CHUNK, start_writeback);
            let mut w = std::io::BufWriter::with_capacity(1 << 16, file);
            match content {
                Content::Bytes(b) => w.write_all(&b)?,
                Content::Stream(fill) => fill(&mut w)?,
            }
            w.flush()?;
        }
        tmp.as_file().sync_all()
    })();
    if let Err(e) = filled {
        unregister(tmp.path());
        return Err(e);
    }
    Ok(tmp)
}

/// A file written from its start that asks for write-back of every finished `chunk` bytes by
/// `request(file, offset, len)` (see the module documentation): each request covers the bytes
/// written since the last one, once they are at least `chunk`.
struct EarlyWriteback<'a, R: FnMut(&File, u64, u64)> {
    /// The file, empty when this starts.
    file: &'a File,
    /// Bytes between two requests, at the least.
    chunk: u64,
    /// Asks for write-back of a range of the file.
    request: R,
    /// Bytes written.
    written: u64,
    /// Bytes for which write-back has been requested.
    requested: u64,
}

impl<'a, R: FnMut(&File, u64, u64)> EarlyWriteback<'a, R> {
    /// The writer of the empty `file`, asking for write-back every `chunk` bytes by `request`.
    fn new(file: &'a File, chunk: u64, request: R) -> EarlyWriteback<'a, R> {
        EarlyWriteback { file, chunk, request, written: 0, requested: 0 }
    }
}

impl<R: FnMut(&File, u64, u64)> Write for EarlyWriteback<'_, R> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.file.write(buf)?;
        self.written += n as u64;
        if self.written - self.requested >= self.chunk {
            (self.request)(self.file, self.requested, self.written - self.requested);
            self.requested = self.written;
        }
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.file.flush()
    }
}

/// Asks the kernel to start writing `len` bytes from `offset` of `file` to disk, without waiting
/// for them to get there. A hint: if the file system declines, the final `fsync` does the work
/// (and reports any write error), so the result is ignored.
#[cfg(target_os = "linux")]
fn start_writeback(file: &File, offset: u64, len: u64) {
    use std::os::fd::AsRawFd;
    let (Ok(offset), Ok(len)) = (i64::try_from(offset), i64::try_from(len)) else { return };
    // SAFETY: `file` keeps the descriptor open for the call, which reads no memory of ours.
    unsafe {
        libc::sync_file_range(file.as_raw_fd(), offset, len, libc::SYNC_FILE_RANGE_WRITE);
    }
}

/// Elsewhere the final `fsync` writes everything.
#[cfg(not(target_os = "linux"))]
fn start_writeback(_file: &File, _offset: u64, _len: u64) {}

#[cfg(test)]
mod tests {
    use super::*;

    /// A killed run's staged files (issue 53: after a kill -9, `.gyrolab-*.tmp` stayed in
    /// `--out`) are removed by the next write into the folder; a live process's staged file,
    /// the `.gyrolab-old-*` copy of a file being replaced, and other files stay.
    #[test]
    fn the_next_write_removes_a_killed_runs_staged_files() {
        let dir = tempfile::tempdir().unwrap();
        // A process that has exited: its pid is free (reused only after wrapping around).
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let dead = child.id();
        child.wait().unwrap();
        let parent = std::os::unix::process::parent_id();
        let names = [
            format!(".gyrolab-{dead}-AbC123.tmp"),
            format!(".gyrolab-{parent}-XyZ789.tmp"),
            format!(".gyrolab-old-{dead}-0.tmp"),
            "keep.csv".to_string(),
        ];
        for n in &names {
            std::fs::write(dir.path().join(n), b"x").unwrap();
        }
        // A staged folder of the dead run (`store report --inputs`), with a file in it.
        let staged_dir = dir.path().join(format!(".gyrolab-{dead}-inputs-Q1.tmp"));
        std::fs::create_dir_all(staged_dir.join("data")).unwrap();
        std::fs::write(staged_dir.join("data/x.csv"), b"1,2\n").unwrap();
        write_outputs(vec![OutputFile::bytes(dir.path().join("out.csv"), b"a,b\n".to_vec())], &[]).unwrap();
        let mut left: Vec<String> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        left.sort();
        let mut want = vec![names[1].clone(), names[2].clone(), names[3].clone(), "out.csv".to_string()];
        want.sort();
        assert_eq!(left, want);
    }

    /// Writes `pieces` through an [`EarlyWriteback`] asking every `chunk` bytes (through a
    /// `BufWriter` of `buffer` bytes when given); returns the file's bytes and the requests.
    fn write_recording(pieces: &[Vec<u8>], chunk: u64, buffer: Option<usize>) -> (Vec<u8>, Vec<(u64, u64)>) {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("out.txt");
        let file = File::create(&p).unwrap();
        let mut requests = Vec::new();
        {
            let w = EarlyWriteback::new(&file, chunk, |_: &File, offset, len| requests.push((offset, len)));
            let mut w: Box<dyn Write> = match buffer {
                Some(b) => Box::new(std::io::BufWriter::with_capacity(b, w)),
                None => Box::new(w),
            };
            for piece in pieces {
                w.write_all(piece).unwrap();
            }
            w.flush().unwrap();
        }
        drop(file);
        (std::fs::read(&p).unwrap(), requests)
    }

    #[test]
    fn early_writeback_writes_every_byte_and_asks_for_each_finished_chunk() {
        // Pieces of 0 to 6 bytes, and (for the buffered case) some longer than the buffer.
        let pieces: Vec<Vec<u8>> =
            (0u8..60).map(|i| vec![b'a' + i % 26; usize::from(i % 7) * (1 + usize::from(i % 5 == 4) * 9)]).collect();
        let want: Vec<u8> = pieces.concat();
        for buffer in [None, Some(8)] {
            let (written, requests) = write_recording(&pieces, 10, buffer);
            assert_eq!(written, want, "buffer {buffer:?}");
            // The requests follow each other from the start, each at least a chunk long, and
            // leave less than a chunk unrequested at the end.
            let mut next = 0;
            for &(offset, len) in &requests {
                assert_eq!(offset, next, "{requests:?}");
                assert!(len >= 10, "{requests:?}");
                next = offset + len;
            }
            assert!(want.len() as u64 - next < 10, "{requests:?} of {}", want.len());
        }
        // Without a buffer each request ends at the first piece boundary that completes a chunk.
        let (_, requests) = write_recording(&pieces, 10, None);
        let mut ends = Vec::new();
        let (mut end, mut last) = (0u64, 0u64);
        for piece in &pieces {
            end += piece.len() as u64;
            if end - last >= 10 {
                ends.push(end);
                last = end;
            }
        }
        assert_eq!(requests.iter().map(|r| r.0 + r.1).collect::<Vec<_>>(), ends);
    }

    #[test]
    fn failed_write_leaves_no_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("out.txt");
        let r = write_atomic_with(&p, |w| {
            w.write_all(b"partial")?;
            Err(std::io::Error::other("boom"))
        });
        assert!(r.is_err());
        assert!(!p.exists());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
        write_atomic(&p, b"whole").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"whole");
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            assert_eq!(std::fs::metadata(&p).unwrap().permissions().mode() & 0o777, 0o644);
        }
    }

    #[test]
    fn a_folder_is_written_whole_or_left_as_it_was() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("report");
        let written = super::write_folder(&out, &[("a.txt", b"one"), ("b.txt", b"two")], &[]).unwrap();
        assert_eq!(written, [out.join("a.txt"), out.join("b.txt")]);
        assert_eq!(std::fs::read(out.join("b.txt")).unwrap(), b"two");
        // A bad name among the files: nothing is replaced, no temporary is left.
        let e = super::write_folder(&out, &[("a.txt", b"new"), ("x/y.txt", b"bad")], &[]).unwrap_err();
        assert_eq!(e.path, out.join("x/y.txt"));
        assert_eq!(std::fs::read(out.join("a.txt")).unwrap(), b"one");
        let names: Vec<_> = std::fs::read_dir(&out).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(names.len(), 2, "{names:?}");
        // A folder where a file goes (the third of three): refused before any rename, the
        // first two keep the earlier run's content; nothing else is left in the folder.
        std::fs::create_dir(out.join("c.txt")).unwrap();
        std::fs::write(out.join("mine.txt"), b"user").unwrap();
        let e = super::write_folder(&out, &[("a.txt", b"new"), ("b.txt", b"new"), ("c.txt", b"new")], &[]).unwrap_err();
        assert_eq!(e.path, out.join("c.txt"));
        assert_eq!(e.refusal, OutputRefusal::NotAFile);
        assert_eq!(std::fs::read(out.join("a.txt")).unwrap(), b"one");
        assert_eq!(std::fs::read(out.join("b.txt")).unwrap(), b"two");
        let mut names: Vec<_> =
            std::fs::read_dir(&out).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
        names.sort();
        assert_eq!(names, ["a.txt", "b.txt", "c.txt", "mine.txt"]);
        // Replaced whole: the old content is gone, the user's file stays, no link is left.
        std::fs::remove_dir(out.join("c.txt")).unwrap();
        super::write_folder(&out, &[("a.txt", b"new"), ("b.txt", b"new"), ("c.txt", b"new")], &[]).unwrap();
        for f in ["a.txt", "b.txt", "c.txt"] {
            assert_eq!(std::fs::read(out.join(f)).unwrap(), b"new");
        }
        assert_eq!(std::fs::read(out.join("mine.txt")).unwrap(), b"user");
        assert_eq!(std::fs::read_dir(&out).unwrap().count(), 4);
    }

    /// An input is never overwritten: named as it is, through another spelling of its folder, or
    /// as a hard link of it; nothing of the set is written and the message says what is there.
    #[test]
    fn an_input_is_never_overwritten() {
        let dir = tempfile::tempdir().unwrap();
        let input = dir.path().join("allan_x.csv");
        std::fs::write(&input, b"time_s,rate_dps\n").unwrap();
        let out = dir.path().join("table.csv");
        for target in [input.clone(), dir.path().join("sub/../allan_x.csv"), dir.path().join("link.csv")] {
            if target.ends_with("link.csv") {
                std::fs::hard_link(&input, &target).unwrap();
            } else {
                std::fs::create_dir_all(dir.path().join("sub")).unwrap();
            }
            let e = write_outputs(
                vec![OutputFile::bytes(&out, &b"a"[..]), OutputFile::bytes(&target, &b"b"[..])],
                &[&input],
            )
            .unwrap_err();
            assert_eq!(e.refusal, OutputRefusal::IsAnInput, "{target:?}");
            assert!(e.is_usage());
            assert_eq!(std::fs::read(&input).unwrap(), b"time_s,rate_dps\n");
            assert!(!out.exists());
            let text = e.to_string();
            assert!(text.contains("never overwrites an input") && text.contains("not there: "), "{text}");
        }
        // A file named twice in one set.
        let e = write_outputs(
            vec![OutputFile::bytes(&out, &b"a"[..]), OutputFile::bytes(dir.path().join("./table.csv"), &b"b"[..])],
            &[],
        )
        .unwrap_err();
        assert_eq!(e.refusal, OutputRefusal::NamedTwice);
        assert!(!out.exists());
    }

    /// A rename that fails after others succeeded (the third target's folder made read-only
    /// between staging and renaming cannot be arranged portably, so a staged file's folder is
    /// removed): the files already replaced get their old content back, new ones are removed.
    #[test]
    fn a_failed_write_part_way_leaves_every_target_as_it_was() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a.yaml");
        let b = dir.path().join("b.yaml");
        std::fs::write(&a, b"old a").unwrap();
        // The last output streams and fails: nothing is renamed, every target as it was.
        let e = write_outputs(
            vec![
                OutputFile::bytes(&a, &b"new a"[..]),
                OutputFile::bytes(&b, &b"new b"[..]),
                OutputFile::stream(dir.path().join("c.yaml"), |w| {
                    w.write_all(b"partial")?;
                    Err(std::io::Error::other("disk full"))
                }),
            ],
            &[],
        )
        .unwrap_err();
        assert_eq!(e.refusal, OutputRefusal::Io);
        assert_eq!(std::fs::read(&a).unwrap(), b"old a");
        assert!(!b.exists());
        assert_eq!(e.targets.iter().filter(|(_, there)| *there).count(), 1);
        let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(names, ["a.yaml"], "no temporary left");
        // A folder whose parent does not exist: refused at staging, before any rename.
        let e = write_outputs(
            vec![OutputFile::bytes(&a, &b"new a"[..]), OutputFile::bytes(dir.path().join("no/such/c.yaml"), &b"c"[..])],
            &[],
        )
        .unwrap_err();
        assert_eq!(e.path, dir.path().join("no/such/c.yaml"));
        assert_eq!(std::fs::read(&a).unwrap(), b"old a");
        // The rollback itself: the renames stop at a target that became a folder after the
        // checks (simulated by persisting onto a folder), earlier targets get their old bytes.
        let staged = vec![
            (stage_in(dir.path(), Content::Bytes(b"new a"[..].into())).unwrap(), a.clone()),
            (stage_in(dir.path(), Content::Bytes(b"x"[..].into())).unwrap(), dir.path().to_path_buf()),
        ];
        let (written, result) = persist_in_order(staged);
        assert_eq!(written, std::slice::from_ref(&a));
        assert!(result.is_err());
    }
}
