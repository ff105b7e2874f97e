//! A small delimited-text parser for whole files that fit in memory (rate-table records,
//! test plans): comma, tab, semicolon or whitespace separated, `#` comment lines, one header
//! row. Every row keeps its 1-based line number for error messages.

use crate::DataError;
use std::path::Path;

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

    /// Guesses the separator from a header line: tab, then comma, then semicolon, else whitespace.
    pub fn sniff(header: &str) -> Delimiter {
        if header.contains('\t') {
            Delimiter::Tab
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

/// Parses a whole file's text. Errors: empty file, duplicate header names.
pub fn parse_text_table(file: &Path, text: &str) -> Result<TextTable, DataError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut header: Option<(u64, Vec<String>, Delimiter)> = None;
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
            }
            Some((_, _, d)) => rows.push(TextRow { line, fields: d.split(raw) }),
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
                    "duplicate column name '{h}' (columns {} and {}): expected every header name once",
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

/// Parses a finite number from a field, or explains what is wrong with it.
pub fn parse_number(file: &Path, line: u64, column: usize, name: &str, field: &str) -> Result<f64, DataError> {
    let at = |msg: String| DataError::new(file, msg).at_line(line).at_column(column, Some(name));
    if field.is_empty() {
        return Err(at("empty cell: expected a number".into()));
    }
    let s = field.strip_prefix('+').unwrap_or(field);
    match fast_float2::parse::<f64, _>(s) {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(at(format!("found '{field}', expected a finite number (NaN and infinity are not data)"))),
        Err(_) => Err(at(format!("found '{field}', expected a number"))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
