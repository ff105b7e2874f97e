//! The error every reader returns: which file, which line and column, what was wrong and what
//! was expected.

use std::fmt;
use std::path::{Path, PathBuf};

/// Longest message kept in a [`DataError`], in bytes (cut at a character boundary, then "...").
pub const MAX_MESSAGE_CHARS: usize = 1000;

/// A column of a delimited file: its 1-based position and, when known, its header name.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ColumnRef {
    /// 1-based column position.
    pub index: usize,
    /// Header name, when the file has one.
    pub name: Option<String>,
}

/// A problem with input data, located as precisely as the reader could.
#[derive(Debug, Clone, PartialEq)]
pub struct DataError {
    /// The file (or `<stdin>`, `<built-in ...>`).
    pub file: PathBuf,
    /// 1-based line, when the problem is on one line.
    pub line: Option<u64>,
    /// Column, when the problem is in one column.
    pub column: Option<ColumnRef>,
    /// What was wrong and what was expected.
    pub message: String,
}

impl DataError {
    /// A problem with a file as a whole.
    ///
    /// A message longer than [`MAX_MESSAGE_CHARS`] is cut (a safety net: readers quote fields
    /// through [`excerpt`]).
    pub fn new(file: impl AsRef<Path>, message: impl Into<String>) -> Self {
        let mut message: String = message.into();
        if message.len() > MAX_MESSAGE_CHARS {
            // Bytes, cut at a character boundary: invalid UTF-8 shown as U+FFFD is 3 bytes each.
            let cut = (0..=MAX_MESSAGE_CHARS).rev().find(|&i| message.is_char_boundary(i)).unwrap_or(0);
            message.truncate(cut);
            message.push_str("...");
        }
        DataError { file: file.as_ref().to_path_buf(), line: None, column: None, message }
    }

    /// Locates the problem on a line (1-based). Line 0, which names no line (the header of a
    /// file without a header row), leaves the error unlocated rather than printed as `file:0:`.
    pub fn at_line(mut self, line: u64) -> Self {
        self.line = (line > 0).then_some(line);
        self
    }

    /// Locates the problem in a column (1-based index and optional header name).
    pub fn at_column(mut self, index: usize, name: Option<&str>) -> Self {
        self.column = Some(ColumnRef { index, name: name.map(excerpt) });
        self
    }

    /// An I/O failure while opening or reading a file.
    pub fn io(file: impl AsRef<Path>, err: &std::io::Error) -> Self {
        use std::io::ErrorKind as K;
        let what = match err.kind() {
            K::NotFound => "no such file".to_string(),
            K::PermissionDenied => "permission denied".to_string(),
            K::IsADirectory => "a directory, not a file".to_string(),
            K::InvalidInput => "the file cannot be read this way (invalid argument)".to_string(),
            K::UnexpectedEof => "the file ends early".to_string(),
            _ => {
                let t = err.to_string();
                t.split(" (os error").next().unwrap_or(&t).to_string()
            }
        };
        DataError::new(file, format!("cannot read the file: {what}"))
    }
}

impl fmt::Display for DataError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file.display())?;
        if let Some(l) = self.line {
            write!(f, ":{l}")?;
            if let Some(c) = &self.column {
                write!(f, ":{}", c.index)?;
            }
        }
        write!(f, ": ")?;
        if let Some(ColumnRef { name: Some(n), index }) = &self.column {
            if self.line.is_some() {
                write!(f, "column '{n}': ")?;
            } else {
                write!(f, "column {index} '{n}': ")?;
            }
        }
        f.write_str(&self.message)
    }
}

impl std::error::Error for DataError {}

/// Most characters of a field quoted in an error message (longer fields end in "...").
pub const MAX_EXCERPT_CHARS: usize = 60;

/// A field as quoted in messages: at most [`MAX_EXCERPT_CHARS`] characters, control characters
/// shown as `\u{..}`, "..." when cut.
pub fn excerpt(field: &str) -> String {
    let mut out = String::new();
    for (n, c) in field.chars().enumerate() {
        if n == MAX_EXCERPT_CHARS {
            out.push_str("...");
            break;
        }
        if c.is_control() {
            out.extend(c.escape_unicode());
        } else {
            out.push(c);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_names_file_line_column() {
        let e = DataError::new("x.csv", "found 'abc', expected a number").at_line(12).at_column(4, Some("output_v"));
        assert_eq!(e.to_string(), "x.csv:12:4: column 'output_v': found 'abc', expected a number");
        assert_eq!(DataError::new("x.csv", "the file is empty").to_string(), "x.csv: the file is empty");
    }
}
