//! A small delimited-text parser for whole files that fit in memory (rate-table records,
//! test plans): comma, tab, semicolon or whitespace separated, `#` comment lines, one header
//! row. Every row keeps its 1-based line number for error messages.

use crate::DataError;
use std::io::Read;
use std::path::Path;

/// Longest line any reader accepts: 1 MiB. A real record's lines are well under 1 KiB; a longer
/// "line" is binary data or a file without line ends, and reading on would only fill memory.
pub const MAX_LINE_BYTES: usize = 1 << 20;

/// Largest configuration, calibration, test-plan or segment file: 4 MiB (real ones are a few KiB).
pub const MAX_CONFIG_BYTES: u64 = 4 << 20;

/// Largest rate-table record read whole into memory: 256 MiB (a long-layout record of a
/// thousand samples per plateau, 40 rates and 10 runs is about 20 MiB).
pub const MAX_TABLE_BYTES: u64 = 256 << 20;

/// Largest magnitude of a value read from a record: 1e150. Squares and sums of squares of such
/// values stay finite; a value beyond it is a corrupt cell, never a gyro output or a time.
pub const MAX_MAGNITUDE: f64 = 1e150;

pub use crate::error::{excerpt, MAX_EXCERPT_CHARS};

/// Most characters of a parser's message (a TOML error) quoted in an error.
pub const MAX_QUOTED_MESSAGE_CHARS: usize = 300;

/// A parser's message (which may quote the input) cut to [`MAX_QUOTED_MESSAGE_CHARS`]
/// characters, control characters escaped.
pub fn short_message(msg: &str) -> String {
    let mut out = String::new();
    for (n, c) in msg.trim_end().chars().enumerate() {
        if n == MAX_QUOTED_MESSAGE_CHARS {
            out.push_str("...");
            break;
        }
        if c.is_control() && c != '\n' {
            out.extend(c.escape_unicode());
        } else {
            out.push(c);
        }
    }
    out
}

/// Checks the bytes of a text file as they arrive: NUL bytes (binary data), lines longer than
/// [`MAX_LINE_BYTES`], lines that end with CR only. Keeps the line count across calls.
#[derive(Debug, Clone, Default)]
pub struct TextGuard {
    /// Lines ended so far.
    lines: u64,
    /// Bytes of the current line so far.
    line_bytes: usize,
    /// Whether the previous byte was a CR.
    after_cr: bool,
}

impl TextGuard {
    /// Checks the next bytes of `file`; the error names the line.
    pub fn check(&mut self, file: &Path, bytes: &[u8]) -> Result<(), DataError> {
        for &b in bytes {
            if self.after_cr && b != b'\n' {
                return Err(DataError::new(
                    file,
                    "lines end with CR only (a classic Mac OS text file): expected LF or CR LF line ends",
                )
                .at_line(self.lines + 1));
            }
            self.after_cr = b == b'\r';
            match b {
                b'\n' => {
                    self.lines += 1;
                    self.line_bytes = 0;
                }
                0 => {
                    return Err(
                        DataError::new(file, "binary data (a NUL byte): expected a text file").at_line(self.lines + 1)
                    )
                }
                _ => {
                    self.line_bytes += 1;
                    if self.line_bytes > MAX_LINE_BYTES {
                        return Err(long_line(file, self.lines + 1));
                    }
                }
            }
        }
        Ok(())
    }
}

/// The error of a line longer than [`MAX_LINE_BYTES`].
pub fn long_line(file: &Path, line: u64) -> DataError {
    DataError::new(
        file,
        format!(
            "line {line} is longer than {} MiB: expected text lines (is this a binary file?)",
            MAX_LINE_BYTES >> 20
        ),
    )
    .at_line(line)
}

/// Reads a whole text file of at most `max_bytes`, checking it as it arrives (see
/// [`TextGuard`]) so that binary data or an endless file (`/dev/zero`) ends the read early;
/// `what` names the expected kind of file in the size error.
pub fn read_text_file(path: &Path, max_bytes: u64, what: &str) -> Result<String, DataError> {
    let (f, _) = crate::input_file::open_regular(path)?;
    let mut src = f.take(max_bytes + 1);
    let mut bytes = Vec::new();
    let mut guard = TextGuard::default();
    let mut chunk = vec![0u8; 64 << 10];
    loop {
        let n = match src.read(&mut chunk) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(DataError::io(path, &e)),
        };
        guard.check(path, &chunk[..n])?;
        bytes.extend_from_slice(&chunk[..n]);
        if bytes.len() as u64 > max_bytes {
            return Err(DataError::new(
                path,
                format!("the file is larger than {}: expected {what}", size_text(max_bytes)),
            ));
        }
    }
    String::from_utf8(bytes).map_err(|e| {
        let upto = &e.as_bytes()[..e.utf8_error().valid_up_to()];
        let line = upto.iter().filter(|&&b| b == b'\n').count() as u64 + 1;
        DataError::new(path, "the file is not UTF-8 text: expected a text file").at_line(line)
    })
}

/// A byte count as text (`4 MiB`, `1.5 GiB`, `512 bytes`).
pub fn size_text(bytes: u64) -> String {
    const UNITS: [&str; 5] = ["bytes", "KiB", "MiB", "GiB", "TiB"];
    let mut v = bytes as f64;
    let mut u = 0;
    while v >= 1024.0 && u + 1 < UNITS.len() {
        v /= 1024.0;
        u += 1;
    }
    if u == 0 {
        format!("{bytes} bytes")
    } else if v.fract() == 0.0 {
        format!("{v} {}", UNITS[u])
    } else {
        format!("{v:.1} {}", UNITS[u])
    }
}

/// Field separator of a text file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Delimiter {
    /// `,`
    Comma,
    /// Tab.
    Tab,
    /// `;`
    Semicolon,
    /// One or more spaces or tabs.
    Whitespace,
}

impl Delimiter {
    /// The separator byte (a space for whitespace, which also matches tabs).
    pub(crate) fn byte(self) -> u8 {
        match self {
            Delimiter::Comma => b',',
            Delimiter::Tab => b'\t',
            Delimiter::Semicolon => b';',
            Delimiter::Whitespace => b' ',
        }
    }

    /// Guesses the separator from a header line: tab; then semicolon where the commas are decimal
    /// commas (`0,01;0,25`); then comma, then semicolon, else whitespace.
    pub fn sniff(header: &str) -> Delimiter {
        if header.contains('\t') {
            Delimiter::Tab
        } else if header.contains(';')
            && header.split(';').all(|f| !f.contains(',') || is_decimal_comma_number(f.trim().trim_matches('"')))
        {
            // `0,01;0,2515`: semicolons between numbers written with decimal commas (a European
            // spreadsheet's export without a header row).
            Delimiter::Semicolon
        } else if header.contains(',') {
            Delimiter::Comma
        } else if header.contains(';') {
            Delimiter::Semicolon
        } else {
            Delimiter::Whitespace
        }
    }

    /// Splits one line into trimmed fields (surrounding double quotes removed).
    pub fn split(self, line: &str) -> Vec<String> {
        let clean = |s: &str| s.trim().trim_matches('"').trim().to_string();
        match self {
            Delimiter::Comma => line.split(',').map(clean).collect(),
            Delimiter::Tab => line.split('\t').map(clean).collect(),
            Delimiter::Semicolon => line.split(';').map(clean).collect(),
            Delimiter::Whitespace => line.split_whitespace().map(clean).collect(),
        }
    }
}

/// One data row with its line number.
#[derive(Debug, Clone, PartialEq)]
pub struct TextRow {
    /// 1-based line number in the file.
    pub line: u64,
    /// Trimmed fields.
    pub fields: Vec<String>,
    /// The line as written (for re-splitting when the header turns out to be a title).
    pub raw_text: String,
}

/// A parsed text file: header, rows and comment lines.
#[derive(Debug, Clone, PartialEq)]
pub struct TextTable {
    /// The separator found.
    pub delimiter: Delimiter,
    /// 1-based line of the header.
    pub header_line: u64,
    /// Header fields.
    pub header: Vec<String>,
    /// Data rows (comment and blank lines removed); rows may have any number of fields.
    pub rows: Vec<TextRow>,
    /// Comment lines (without the `#`), with their line numbers.
    pub comments: Vec<(u64, String)>,
}

impl TextTable {
    /// Index of the header column named `name` (case-insensitive).
    pub fn column(&self, name: &str) -> Option<usize> {
        self.header.iter().position(|h| h.eq_ignore_ascii_case(name))
    }
}

/// Parses a whole file's text. Errors: binary data, overlong lines, CR-only line ends, empty
/// file, duplicate header names.
pub fn parse_text_table(file: &Path, text: &str) -> Result<TextTable, DataError> {
    TextGuard::default().check(file, text.as_bytes())?;
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut header: Option<(u64, Vec<String>, Delimiter)> = None;
    let mut header_raw = String::new();
    let mut rows = Vec::new();
    let mut comments = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = i as u64 + 1;
        let t = raw.trim();
        if t.is_empty() {
            continue;
        }
        if let Some(c) = t.strip_prefix('#') {
            comments.push((line, c.trim().to_string()));
            continue;
        }
        match &header {
            None => {
                let d = Delimiter::sniff(raw);
                header = Some((line, d.split(raw), d));
                header_raw = raw.to_string();
            }
            Some((_, _, d)) => rows.push(TextRow { line, fields: d.split(raw), raw_text: raw.to_string() }),
        }
    }
    // A title row above the header (as spreadsheets export a sheet with its caption): a first
    // line with one field, followed by a line with three or more.
    if let (Some((line, _, Delimiter::Whitespace)), Some(first)) = (&header, rows.first()) {
        let next_delim = Delimiter::sniff(&first.raw_text);
        let next_fields = next_delim.split(&first.raw_text);
        let names = next_fields.iter().filter(|f| !f.is_empty()).all(|f| f.chars().any(char::is_alphabetic));
        if next_delim != Delimiter::Whitespace && next_fields.len() >= 3 && names {
            comments.push((*line, header_raw.trim().to_string()));
            let first = rows.remove(0);
            header = Some((first.line, next_fields, next_delim));
            for r in &mut rows {
                r.fields = next_delim.split(&r.raw_text);
            }
        }
    }
    if let Some((_, _, d)) = &header {
        if *d != Delimiter::Comma {
            // Decimal commas (semicolon- or tab-separated files from a European spreadsheet).
            for r in &mut rows {
                for f in &mut r.fields {
                    if is_decimal_comma_number(f) {
                        *f = f.replace(',', ".");
                    }
                }
            }
        }
    }
    let Some((header_line, header, delimiter)) = header else {
        return Err(DataError::new(
            file,
            "the file is empty: expected a header line naming the columns, then data rows",
        ));
    };
    for (j, h) in header.iter().enumerate() {
        if h.is_empty() {
            continue;
        }
        if let Some(k) = header[..j].iter().position(|p| p.eq_ignore_ascii_case(h)) {
            return Err(DataError::new(
                file,
                format!(
                    "duplicate column name '{}' (columns {} and {}): expected every header name once",
                    excerpt(h),
                    k + 1,
                    j + 1
                ),
            )
            .at_line(header_line)
            .at_column(j + 1, Some(h)));
        }
    }
    Ok(TextTable { delimiter, header_line, header, rows, comments })
}

/// Whether a field is a number written with a decimal comma (`-0,25`, `1,5e-3`).
pub(crate) fn is_decimal_comma_number(f: &str) -> bool {
    let t = f.strip_prefix(['+', '-']).unwrap_or(f);
    let Some((a, b)) = t.split_once(',') else { return false };
    let (frac, exp) = match b.split_once(['e', 'E']) {
        Some((x, e)) => (x, Some(e)),
        None => (b, None),
    };
    !a.is_empty()
        && a.bytes().all(|c| c.is_ascii_digit())
        && !frac.is_empty()
        && frac.bytes().all(|c| c.is_ascii_digit())
        && exp.is_none_or(|e| {
            let e = e.strip_prefix(['+', '-']).unwrap_or(e);
            !e.is_empty() && e.bytes().all(|c| c.is_ascii_digit())
        })
}

/// Parses a finite number from a field, or explains what is wrong with it: not a number (one
/// sign at most: `+-2.5` is not read as -2.5), NaN or infinity, or a magnitude above
/// [`MAX_MAGNITUDE`].
pub fn parse_number(file: &Path, line: u64, column: usize, name: &str, field: &str) -> Result<f64, DataError> {
    let at = |msg: String| DataError::new(file, msg).at_line(line).at_column(column, Some(name));
    if field.is_empty() {
        return Err(at("empty cell: expected a number".into()));
    }
    let s = field.strip_prefix('+').unwrap_or(field);
    let shown = excerpt(field);
    if s.len() < field.len() && s.starts_with(['+', '-']) {
        return Err(at(format!("found '{shown}', expected a number with one sign at most")));
    }
    match fast_float2::parse::<f64, _>(s) {
        Ok(v) if v.is_finite() => check_magnitude(v).map_err(at),
        Ok(_) => Err(at(format!("found '{shown}', expected a finite number (NaN and infinity are not data)"))),
        Err(_) => Err(at(format!("found '{shown}', expected a number"))),
    }
}

/// `Ok(v)` when |v| is at most [`MAX_MAGNITUDE`], else the reason as a message.
pub fn check_magnitude(v: f64) -> Result<f64, String> {
    if v.abs() <= MAX_MAGNITUDE {
        Ok(v)
    } else {
        Err(format!(
            "found {v:e}, a magnitude above {MAX_MAGNITUDE:e}: such a value would overflow the figures \
             (sums of squares); expected a measured value"
        ))
    }
}

/// A path as text, exactly and reversibly ([`path_from_text`] gives it back): a name in UTF-8
/// as it is, except that a backslash is doubled; a byte that is not UTF-8 (a non-UTF-8 name
/// on Unix) as `\xNN`. Tables and journals hold this text, never a lossy one that would turn
/// two names into the same replacement character.
///
/// ```
/// use std::path::Path;
/// assert_eq!(gyrolab_io::text::path_text(Path::new("fleet/imu 1.csv")), "fleet/imu 1.csv");
/// assert_eq!(gyrolab_io::text::path_text(Path::new(r"a\b.csv")), r"a\\b.csv");
/// ```
pub fn path_text(path: &Path) -> String {
    #[cfg(unix)]
    let bytes: &[u8] = std::os::unix::ffi::OsStrExt::as_bytes(path.as_os_str());
    #[cfg(not(unix))]
    let owned = path.to_string_lossy().into_owned().into_bytes();
    #[cfg(not(unix))]
    let bytes: &[u8] = &owned;
    let mut out = String::with_capacity(bytes.len());
    for chunk in bytes.utf8_chunks() {
        for c in chunk.valid().chars() {
            if c == '\\' {
                out.push_str("\\\\");
            } else {
                out.push(c);
            }
        }
        for b in chunk.invalid() {
            out.push_str(&format!("\\x{b:02X}"));
        }
    }
    out
}

/// The path [`path_text`] wrote (`None` for text it cannot have written).
pub fn path_from_text(text: &str) -> Option<std::path::PathBuf> {
    let mut bytes = Vec::with_capacity(text.len());
    let mut rest = text.as_bytes();
    while let Some((&b, tail)) = rest.split_first() {
        if b != b'\\' {
            bytes.push(b);
            rest = tail;
            continue;
        }
        match tail {
            [b'\\', more @ ..] => {
                bytes.push(b'\\');
                rest = more;
            }
            [b'x', h, l, more @ ..] => {
                let hex = std::str::from_utf8(&[*h, *l]).ok().and_then(|s| u8::from_str_radix(s, 16).ok())?;
                bytes.push(hex);
                rest = more;
            }
            _ => return None,
        }
    }
    #[cfg(unix)]
    {
        Some(std::path::PathBuf::from(<std::ffi::OsString as std::os::unix::ffi::OsStringExt>::from_vec(bytes)))
    }
    #[cfg(not(unix))]
    {
        String::from_utf8(bytes).ok().map(std::path::PathBuf::from)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Non-UTF-8 names kept exactly (issue 55): every name reads back as written, two names
    /// that a lossy conversion would merge stay apart.
    #[cfg(unix)]
    #[test]
    fn path_text_is_exact_and_reversible() {
        use std::os::unix::ffi::OsStrExt;
        let names: [&[u8]; 6] =
            [b"plain.csv", b"caf\xc3\xa9.csv", b"bad\xff.csv", b"bad\xfe.csv", b"back\\slash\\x41.csv", b"\xff\\xff"];
        let mut texts = Vec::new();
        for n in names {
            let p = Path::new(std::ffi::OsStr::from_bytes(n));
            let t = path_text(p);
            assert_eq!(path_from_text(&t).as_deref(), Some(p), "{t}");
            texts.push(t);
        }
        assert_eq!(texts[1], "caf\u{e9}.csv");
        assert_eq!(texts[2], "bad\\xFF.csv");
        assert_ne!(texts[2], texts[3]);
        assert_eq!(path_from_text("a\\q"), None);
    }

    #[test]
    fn parses_comments_header_rows_and_sniffs() {
        let t = parse_text_table(Path::new("a.csv"), "\u{feff}# hello\n\na_x, b\n1, 2\n# mid\n3,4\n").unwrap();
        assert_eq!(t.delimiter, Delimiter::Comma);
        assert_eq!(t.header, vec!["a_x", "b"]);
        assert_eq!(t.header_line, 3);
        assert_eq!(t.rows[1].line, 6);
        assert_eq!(t.comments.len(), 2);
        let w = parse_text_table(Path::new("w.txt"), "a  b\n1   2\n").unwrap();
        assert_eq!(w.delimiter, Delimiter::Whitespace);
        assert_eq!(w.rows[0].fields, vec!["1", "2"]);
        assert_eq!(parse_text_table(Path::new("t.tsv"), "a\tb\n").unwrap().delimiter, Delimiter::Tab);
    }

    #[test]
    fn empty_and_duplicate_headers_are_errors() {
        let e = parse_text_table(Path::new("e.csv"), "# only a comment\n\n").unwrap_err();
        assert!(e.to_string().starts_with("e.csv: the file is empty"), "{e}");
        let d = parse_text_table(Path::new("d.csv"), "#c\nrate_dps,run,RUN\n").unwrap_err();
        assert_eq!(d.line, Some(2));
        assert_eq!(d.column.unwrap().index, 3);
    }

    #[test]
    fn numbers_and_their_errors() {
        let p = Path::new("n.csv");
        assert_eq!(parse_number(p, 1, 1, "x", "+1.5e3").unwrap(), 1500.0);
        let e = parse_number(p, 7, 2, "output_v", "abc").unwrap_err();
        assert_eq!(e.to_string(), "n.csv:7:2: column 'output_v': found 'abc', expected a number");
        assert!(parse_number(p, 1, 1, "x", "NaN").unwrap_err().message.contains("finite"));
        assert!(parse_number(p, 1, 1, "x", "").unwrap_err().message.contains("empty"));
    }

    #[test]
    fn guard_finds_nul_long_lines_and_cr_only() {
        let p = Path::new("g.csv");
        let e = TextGuard::default().check(p, b"a,b\n1,2\n\0\0").unwrap_err();
        assert_eq!((e.line, e.message.contains("binary data")), (Some(3), true), "{e}");
        let mut long = b"a\n".to_vec();
        long.extend(std::iter::repeat_n(b'x', MAX_LINE_BYTES + 1));
        let e = TextGuard::default().check(p, &long).unwrap_err();
        assert!(e.to_string().starts_with("g.csv:2: line 2 is longer than 1 MiB"), "{e}");
        let e = parse_text_table(p, "a,b\r1,2\r3,4\r").unwrap_err();
        assert!(e.message.contains("lines end with CR only"), "{e}");
        assert!(parse_text_table(p, "a,b\r\n1,2\r\n").is_ok());
    }

    #[test]
    fn files_over_their_limit_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let f = dir.path().join("big.toml");
        std::fs::write(&f, "x = 1\n".repeat(1000)).unwrap();
        let e = read_text_file(&f, 1024, "a test plan").unwrap_err();
        assert_eq!(e.message, "the file is larger than 1 KiB: expected a test plan");
        assert_eq!(read_text_file(&f, 1 << 20, "a plan").unwrap().len(), 6000);
        assert_eq!(size_text(4 << 20), "4 MiB");
        assert_eq!(excerpt(&"y".repeat(100)), format!("{}...", "y".repeat(60)));
        assert_eq!(excerpt("a\0b"), "a\\u{0}b");
    }
}
