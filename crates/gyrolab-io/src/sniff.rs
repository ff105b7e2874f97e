//! What a file is, told by its first bytes (never its extension): delimited text, MCAP, ROS 1
//! bag, PX4 ULog, Parquet or an SQLite database; every reader that takes "any file" dispatches on
//! [`FileFormat`] after one [`open_sniffed`].

use crate::error::DataError;
use crate::input_file::open_regular;
use std::io::Read;
use std::path::Path;

/// The formats gyrolab reads, told apart by their first bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileFormat {
    /// Delimited text (CSV, TSV, whitespace).
    Text,
    /// MCAP (ROS 2's default bag storage, Foxglove).
    Mcap,
    /// ROS 1 bag (format 2.0).
    RosBag,
    /// PX4 ULog.
    ULog,
    /// Apache Parquet.
    Parquet,
    /// An SQLite database (a ROS 2 bag in the older `.db3` storage): recognised, not read.
    Sqlite,
}

impl FileFormat {
    /// The format's usual name.
    pub fn name(self) -> &'static str {
        match self {
            FileFormat::Text => "delimited text",
            FileFormat::Mcap => "MCAP",
            FileFormat::RosBag => "ROS 1 bag",
            FileFormat::ULog => "PX4 ULog",
            FileFormat::Parquet => "Parquet",
            FileFormat::Sqlite => "SQLite database",
        }
    }

    /// Whether the format is a recording of topics (MCAP, ROS 1 bag, ULog).
    pub fn is_recording(self) -> bool {
        matches!(self, FileFormat::Mcap | FileFormat::RosBag | FileFormat::ULog)
    }
}

/// The format of a file by its first bytes (`-`, standard input, is text). A FIFO, socket or
/// device is refused before it is opened ([`crate::input_file::check_regular`]).
pub fn sniff_format(path: &Path) -> Result<FileFormat, DataError> {
    if path.as_os_str() == "-" {
        return Ok(FileFormat::Text);
    }
    Ok(open_sniffed(path)?.1)
}

/// Opens a regular file once ([`crate::input_file::check_regular`] first), reads its first bytes for the format
/// and rewinds it: (the file, its format, its size in bytes).
pub fn open_sniffed(path: &Path) -> Result<(std::fs::File, FileFormat, u64), DataError> {
    use std::io::{Seek, SeekFrom};
    let (mut f, size) = open_regular(path)?;
    let mut head = [0u8; 16];
    let mut n = 0;
    while n < head.len() {
        match f.read(&mut head[n..]) {
            Ok(0) => break,
            Ok(k) => n += k,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(DataError::io(path, &e)),
        }
    }
    f.seek(SeekFrom::Start(0)).map_err(|e| DataError::io(path, &e))?;
    Ok((f, format_of(&head[..n]), size))
}

/// The format of a file that starts with `head`.
pub fn format_of(head: &[u8]) -> FileFormat {
    if head.starts_with(b"\x89MCAP") {
        FileFormat::Mcap
    } else if head.starts_with(b"#ROSBAG V2.0") {
        FileFormat::RosBag
    } else if head.starts_with(b"ULog\x01\x12\x35") {
        FileFormat::ULog
    } else if head.starts_with(b"PAR1") {
        FileFormat::Parquet
    } else if head.starts_with(b"SQLite format 3\0") {
        FileFormat::Sqlite
    } else {
        FileFormat::Text
    }
}
