//! Input files, checked before they are opened and opened once.
//!
//! Every reader of `gyrolab-io` opens its file here: a path that is not a regular file (a FIFO,
//! socket, character or block device, or a directory) is refused from its metadata, before any
//! `open` that could block (a FIFO without a writer) or read forever (`/dev/zero`); the opened
//! file is checked again (it may have been replaced in between). Standard input is read only
//! where a reader says so, under the name `-`.

use crate::error::DataError;
use std::fs::File;
use std::path::Path;

/// Refuses a path that is not a regular file (a FIFO, socket, character or block device, or a
/// directory), from its metadata: nothing is opened, so a FIFO without a writer cannot block.
/// Returns the file's size in bytes.
///
/// ```
/// let e = gyrolab_io::input_file::check_regular(std::path::Path::new("/dev/null")).unwrap_err();
/// assert!(e.to_string().contains("a character device, not a regular file"));
/// ```
pub fn check_regular(path: &Path) -> Result<u64, DataError> {
    let meta = std::fs::metadata(path).map_err(|e| DataError::io(path, &e))?;
    let kind = meta.file_type();
    if kind.is_file() {
        return Ok(meta.len());
    }
    #[cfg(unix)]
    let what = {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_fifo() {
            "a FIFO (named pipe)"
        } else if kind.is_socket() {
            "a socket"
        } else if kind.is_char_device() {
            "a character device"
        } else if kind.is_block_device() {
            "a block device"
        } else if kind.is_dir() {
            "a directory"
        } else {
            "not a regular file"
        }
    };
    #[cfg(not(unix))]
    let what = if kind.is_dir() { "a directory" } else { "not a regular file" };
    Err(DataError::new(
        path,
        format!("{what}, not a regular file: give a file (standard input is read as `-`, for delimited text)"),
    ))
}

/// Opens a regular file ([`check_regular`] first, and again on the opened file): (the file,
/// its size in bytes).
pub fn open_regular(path: &Path) -> Result<(File, u64), DataError> {
    check_regular(path)?;
    let f = File::open(path).map_err(|e| DataError::io(path, &e))?;
    let meta = f.metadata().map_err(|e| DataError::io(path, &e))?;
    if !meta.is_file() {
        return Err(DataError::new(path, "not a regular file (it changed while being opened)"));
    }
    Ok((f, meta.len()))
}

/// SHA-256 (lower-case hex, FIPS 180-4) and size in bytes of a regular file, read in 64 KiB
/// blocks (the integrity record of a report folder's inputs; `gyrolab verify`).
pub fn sha256_file(path: &Path) -> Result<(String, u64), DataError> {
    sha256_file_identified(path).map(|(sha, size, _)| (sha, size))
}

/// What identifies a file's content without reading it: device, inode, size, and the times
/// of its last write and last status change (a rename over it, a write in place, a truncation
/// all change one of them).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FileIdentity {
    /// Device and inode (0 where the platform has none).
    pub device_inode: (u64, u64),
    /// Size in bytes.
    pub size: u64,
    /// Last modification and last status change, ns since the epoch (status change: 0 where
    /// the platform has none).
    pub times_ns: (i128, i128),
}

impl FileIdentity {
    /// The identity of a file from its metadata.
    pub fn of(meta: &std::fs::Metadata) -> FileIdentity {
        let modified = meta
            .modified()
            .ok()
            .and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok())
            .map_or(0, |d| d.as_nanos() as i128);
        #[cfg(unix)]
        {
            use std::os::unix::fs::MetadataExt;
            FileIdentity {
                device_inode: (meta.dev(), meta.ino()),
                size: meta.len(),
                times_ns: (modified, i128::from(meta.ctime()) * 1_000_000_000 + i128::from(meta.ctime_nsec())),
            }
        }
        #[cfg(not(unix))]
        {
            FileIdentity { device_inode: (0, 0), size: meta.len(), times_ns: (modified, 0) }
        }
    }

    /// The identity of the file at `path` now.
    pub fn at(path: &Path) -> Result<FileIdentity, DataError> {
        let meta = std::fs::metadata(path).map_err(|e| DataError::io(path, &e))?;
        Ok(FileIdentity::of(&meta))
    }
}

/// [`sha256_file`] with the identity of the file read (its metadata from the same open file).
pub fn sha256_file_identified(path: &Path) -> Result<(String, u64, FileIdentity), DataError> {
    use sha2::Digest;
    use std::io::Read;
    let (mut f, _) = open_regular(path)?;
    let identity = FileIdentity::of(&f.metadata().map_err(|e| DataError::io(path, &e))?);
    let mut h = sha2::Sha256::new();
    let mut buf = vec![0u8; 1 << 16];
    let mut size = 0u64;
    loop {
        let n = f.read(&mut buf).map_err(|e| DataError::io(path, &e))?;
        if n == 0 {
            break;
        }
        size += n as u64;
        h.update(&buf[..n]);
    }
    Ok((hex(&h.finalize()), size, identity))
}

/// SHA-256 (lower-case hex) of bytes.
///
/// ```
/// // FIPS 180-4 example "abc".
/// assert_eq!(
///     gyrolab_io::input_file::sha256_hex(b"abc"),
///     "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
/// );
/// ```
pub fn sha256_hex(bytes: &[u8]) -> String {
    use sha2::Digest;
    hex(&sha2::Sha256::digest(bytes))
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sha256_of_a_file_equals_that_of_its_bytes_across_blocks() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("big.bin");
        let bytes: Vec<u8> = (0..200_000u32).map(|i| (i * 7 % 251) as u8).collect();
        std::fs::write(&p, &bytes).unwrap();
        assert_eq!(sha256_file(&p).unwrap(), (sha256_hex(&bytes), 200_000));
        // FIPS 180-4: the empty message.
        assert_eq!(sha256_hex(b""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
    }

    #[test]
    fn regular_files_open_and_others_are_named() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.csv");
        std::fs::write(&p, "t,x\n0,1\n").unwrap();
        assert_eq!(open_regular(&p).unwrap().1, 8);
        let e = open_regular(dir.path()).unwrap_err().to_string();
        assert!(e.contains("a directory, not a regular file"), "{e}");
        let e = open_regular(&dir.path().join("none.csv")).unwrap_err().to_string();
        assert!(e.ends_with("cannot read the file: no such file"), "{e}");
        assert!(!e.contains("os error"), "{e}");
    }
}
