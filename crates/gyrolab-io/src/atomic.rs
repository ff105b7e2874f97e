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
    let tmp = tempfile::Builder::new().prefix(".gyrolab-").suffix(".tmp").tempfile_in(dir)?;
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

/// Writes a folder of files all or nothing as far as a file system allows: creates `dir`, writes
/// every file to a temporary file inside it (fsynced), and only when all are written renames
/// them into place, in order. A failure before the renames leaves the folder as it was (the
/// temporaries are removed); the error names the file it is about. A target that cannot be
/// replaced (a folder of that name) is found before any rename; should a rename still fail, the
/// files already replaced are put back from hard links kept of them (and the new ones removed),
/// so that the folder never mixes files of two runs. Other files in `dir` are not touched.
pub fn write_folder(dir: &Path, files: &[(&str, &[u8])]) -> Result<Vec<PathBuf>, (PathBuf, std::io::Error)> {
    std::fs::create_dir_all(dir).map_err(|e| (dir.to_path_buf(), e))?;
    let mut staged = Vec::with_capacity(files.len());
    for (name, bytes) in files {
        let path = dir.join(name);
        if Path::new(name).file_name() != Some(std::ffi::OsStr::new(name)) {
            return Err((path, std::io::Error::new(std::io::ErrorKind::InvalidInput, "not a plain file name")));
        }
        match stage_in(dir, bytes) {
            Ok(tmp) => staged.push((tmp, path)),
            Err(e) => {
                staged.iter().for_each(|(t, _)| unregister(t.path()));
                return Err((path, e));
            }
        }
    }
    let temporaries: Vec<PathBuf> = staged.iter().map(|(t, _)| t.path().to_path_buf()).collect();
    let unregister_all = || temporaries.iter().for_each(|t| unregister(t));
    // Targets that a rename could not replace, found before the first rename.
    for (_, path) in &staged {
        if std::fs::symlink_metadata(path).is_ok_and(|m| m.is_dir()) {
            unregister_all();
            return Err((
                path.clone(),
                std::io::Error::new(std::io::ErrorKind::IsADirectory, "a folder of this name is in the way"),
            ));
        }
    }
    // The files being replaced, kept as hard links until every rename is done.
    let mut kept: Vec<(PathBuf, PathBuf)> = Vec::new();
    for (_, path) in &staged {
        if std::fs::symlink_metadata(path).is_ok_and(|m| m.is_file()) {
            let keep = dir.join(format!(".gyrolab-old-{}-{}.tmp", std::process::id(), kept.len()));
            let _ = std::fs::remove_file(&keep);
            if let Err(e) = std::fs::hard_link(path, &keep) {
                kept.iter().for_each(|(k, _)| drop(std::fs::remove_file(k)));
                unregister_all();
                return Err((path.clone(), e));
            }
            register(&keep);
            kept.push((keep, path.clone()));
        }
    }
    let (written, result) = persist_in_order(staged);
    if result.is_err() {
        // Put the folder back as it was: the new files out, the old ones in.
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
    result.map(|()| written)
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

/// A temporary file in `dir` holding `bytes` (mode 0644, synced to disk), registered for
/// removal on a signal until it is persisted or dropped.
fn stage_in(dir: &Path, bytes: &[u8]) -> std::io::Result<tempfile::NamedTempFile> {
    let mut tmp = tempfile::Builder::new().prefix(".gyrolab-").suffix(".tmp").tempfile_in(dir)?;
    register(tmp.path());
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        tmp.as_file().set_permissions(std::fs::Permissions::from_mode(0o644))?;
    }
    tmp.write_all(bytes)?;
    tmp.as_file().sync_all()?;
    Ok(tmp)
}

/// Writes several files, each anywhere, all or nothing as far as a file system allows: every
/// file is first written to a temporary file beside its target (fsynced); only when all are
/// written are they renamed into place, in order. A failure before the renames leaves every
/// target as it was; the error names the file it is about.
pub fn write_files(files: &[(PathBuf, Vec<u8>)]) -> Result<Vec<PathBuf>, (PathBuf, std::io::Error)> {
    let mut staged: Vec<(tempfile::NamedTempFile, PathBuf)> = Vec::with_capacity(files.len());
    let release = |staged: &[(tempfile::NamedTempFile, PathBuf)]| staged.iter().for_each(|(t, _)| unregister(t.path()));
    for (path, bytes) in files {
        let dir = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        match stage_in(dir, bytes) {
            Ok(tmp) => staged.push((tmp, path.clone())),
            Err(e) => {
                release(&staged);
                return Err((path.clone(), e));
            }
        }
    }
    let temporaries: Vec<PathBuf> = staged.iter().map(|(t, _)| t.path().to_path_buf()).collect();
    let (written, result) = persist_in_order(staged);
    temporaries.iter().for_each(|t| unregister(t));
    result.map(|()| written)
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
        let written = super::write_folder(&out, &[("a.txt", b"one"), ("b.txt", b"two")]).unwrap();
        assert_eq!(written, [out.join("a.txt"), out.join("b.txt")]);
        assert_eq!(std::fs::read(out.join("b.txt")).unwrap(), b"two");
        // A bad name among the files: nothing is replaced, no temporary is left.
        let e = super::write_folder(&out, &[("a.txt", b"new"), ("x/y.txt", b"bad")]).unwrap_err();
        assert_eq!(e.0, out.join("x/y.txt"));
        assert_eq!(std::fs::read(out.join("a.txt")).unwrap(), b"one");
        let names: Vec<_> = std::fs::read_dir(&out).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(names.len(), 2, "{names:?}");
        // A folder where a file goes (the third of three): refused before any rename, the
        // first two keep the earlier run's content; nothing else is left in the folder.
        std::fs::create_dir(out.join("c.txt")).unwrap();
        std::fs::write(out.join("mine.txt"), b"user").unwrap();
        let e = super::write_folder(&out, &[("a.txt", b"new"), ("b.txt", b"new"), ("c.txt", b"new")]).unwrap_err();
        assert_eq!(e.0, out.join("c.txt"));
        assert_eq!(std::fs::read(out.join("a.txt")).unwrap(), b"one");
        assert_eq!(std::fs::read(out.join("b.txt")).unwrap(), b"two");
        let mut names: Vec<_> =
            std::fs::read_dir(&out).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
        names.sort();
        assert_eq!(names, ["a.txt", "b.txt", "c.txt", "mine.txt"]);
        // Replaced whole: the old content is gone, the user's file stays, no link is left.
        std::fs::remove_dir(out.join("c.txt")).unwrap();
        super::write_folder(&out, &[("a.txt", b"new"), ("b.txt", b"new"), ("c.txt", b"new")]).unwrap();
        for f in ["a.txt", "b.txt", "c.txt"] {
            assert_eq!(std::fs::read(out.join(f)).unwrap(), b"new");
        }
        assert_eq!(std::fs::read(out.join("mine.txt")).unwrap(), b"user");
        assert_eq!(std::fs::read_dir(&out).unwrap().count(), 4);
    }
}
