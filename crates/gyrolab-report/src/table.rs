//! Tables of results and their renderings: aligned text, CSV (RFC 4180 quoting) and Parquet
//! files (one row group, zstd, through gyrolab-io's writer). The records store's queries become
//! [`Table`]s in the lab layer; the command line prints or exports them and Python turns them
//! into DataFrames, all through this module (no front end imports a table or Parquet crate).

use gyrolab::format::sig_opt;

/// A table that cannot be written as Parquet (cells of the wrong kind or count, or the writer's
/// error).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("Parquet export: {message}")]
pub struct TableError {
    /// What is wrong, naming the row and column.
    pub message: String,
}

/// One cell of a table.
#[derive(Debug, Clone, PartialEq)]
pub enum Cell {
    /// No value (empty in CSV, null in Parquet).
    Empty,
    /// Text.
    Text(String),
    /// A real number (shortest text that reads back to the same `f64` in CSV; DOUBLE in Parquet).
    Number(f64),
    /// A whole number (INT64 in Parquet).
    Count(i64),
}

impl Cell {
    /// A number or empty.
    pub fn number(v: Option<f64>) -> Cell {
        v.map_or(Cell::Empty, Cell::Number)
    }

    /// A text or empty.
    pub fn text(v: Option<&str>) -> Cell {
        v.map_or(Cell::Empty, |s| Cell::Text(s.to_string()))
    }

    /// The cell as CSV text before quoting (numbers exactly, `f64` shortest round trip).
    pub fn raw(&self) -> String {
        match self {
            Cell::Empty => String::new(),
            Cell::Text(t) => t.clone(),
            Cell::Number(x) => format!("{x}"),
            Cell::Count(n) => n.to_string(),
        }
    }
}

/// What a column holds, declared by the query that makes the table (so that a column whose cells
/// are all empty still has its type in Parquet and in a DataFrame).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ColumnKind {
    /// Text (UTF-8 in Parquet, object in a DataFrame).
    Text,
    /// Real numbers (DOUBLE, float64).
    Number,
    /// Whole numbers (INT64, nullable Int64).
    Count,
}

impl ColumnKind {
    /// The kind's name: `text`, `number` or `count`.
    pub fn as_str(self) -> &'static str {
        match self {
            ColumnKind::Text => "text",
            ColumnKind::Number => "number",
            ColumnKind::Count => "count",
        }
    }
}

/// A query result: named columns (units in the names or in a `unit` column) of declared kinds,
/// and rows.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Table {
    /// Column names.
    pub columns: Vec<String>,
    /// The kind of each column, in column order.
    pub kinds: Vec<ColumnKind>,
    /// Rows, each with one cell per column.
    pub rows: Vec<Vec<Cell>>,
}

/// A CSV field (RFC 4180): quoted when it holds a comma, a quote or a line break (CR or LF),
/// quotes doubled. The one quoting of every CSV gyrolab writes.
pub fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// The table as CSV: a header row, then one line per row; fields holding a comma, quote or line
/// break quoted, quotes doubled.
pub fn to_csv(table: &Table) -> String {
    let mut out = String::new();
    let head: Vec<String> = table.columns.iter().map(|c| csv_field(c)).collect();
    out.push_str(&head.join(","));
    out.push('\n');
    for r in &table.rows {
        let fields: Vec<String> = r.iter().map(|c| csv_field(&c.raw())).collect();
        out.push_str(&fields.join(","));
        out.push('\n');
    }
    out
}

/// The table as a Parquet file (bytes): one optional column per table column, of the same name,
/// typed by its [`ColumnKind`] (text UTF-8, numbers DOUBLE, counts INT64; a text cell in a
/// number column is an error), empty cells null; one row group, zstd.
pub fn to_parquet(table: &Table) -> Result<Vec<u8>, TableError> {
    use gyrolab_io::parquet_table::{write_table, ColumnValues};
    let failed = |message: String| TableError { message };
    if table.kinds.len() != table.columns.len() {
        return Err(failed(format!("{} column kinds for {} columns", table.kinds.len(), table.columns.len())));
    }
    if let Some(bad) = table.rows.iter().position(|r| r.len() != table.columns.len()) {
        return Err(failed(format!(
            "row {} has {} cells for {} columns",
            bad + 1,
            table.rows[bad].len(),
            table.columns.len()
        )));
    }
    for (r, row) in table.rows.iter().enumerate() {
        for (i, (cell, kind)) in row.iter().zip(&table.kinds).enumerate() {
            let fits = matches!(
                (kind, cell),
                (ColumnKind::Text, _)
                    | (_, Cell::Empty)
                    | (ColumnKind::Number, Cell::Number(_) | Cell::Count(_))
                    | (ColumnKind::Count, Cell::Count(_))
            );
            if !fits {
                return Err(failed(format!(
                    "row {}, column {:?}: {:?} in a {} column",
                    r + 1,
                    table.columns[i],
                    cell,
                    kind.as_str()
                )));
            }
        }
    }
    let columns: Vec<(String, ColumnValues)> = table
        .columns
        .iter()
        .enumerate()
        .map(|(i, name)| {
            let cells = table.rows.iter().map(|r| &r[i]);
            let values = match table.kinds[i] {
                ColumnKind::Text => {
                    ColumnValues::Text(cells.map(|c| if *c == Cell::Empty { None } else { Some(c.raw()) }).collect())
                }
                ColumnKind::Number => ColumnValues::Double(
                    cells
                        .map(|c| match c {
                            Cell::Number(x) => Some(*x),
                            Cell::Count(n) => Some(*n as f64),
                            _ => None,
                        })
                        .collect(),
                ),
                ColumnKind::Count => ColumnValues::Int(
                    cells
                        .map(|c| match c {
                            Cell::Count(n) => Some(*n),
                            _ => None,
                        })
                        .collect(),
                ),
            };
            (name.clone(), values)
        })
        .collect();
    write_table("gyrolab_store_query", &columns).map_err(|e| failed(format!("cannot write the Parquet table: {e}")))
}

/// The table as aligned text: numbers with 6 significant digits, control characters escaped,
/// columns two spaces apart, trailing spaces trimmed.
pub fn to_text(table: &Table) -> String {
    let shown: Vec<Vec<String>> = table
        .rows
        .iter()
        .map(|r| {
            r.iter()
                .map(|c| match c {
                    Cell::Number(x) => sig_opt(Some(*x), 6),
                    Cell::Text(t) => t
                        .chars()
                        .flat_map(|c| if c.is_control() { c.escape_default().collect::<Vec<_>>() } else { vec![c] })
                        .collect(),
                    other => other.raw(),
                })
                .collect()
        })
        .collect();
    let mut width: Vec<usize> = table.columns.iter().map(|h| h.chars().count()).collect();
    for r in &shown {
        for (i, f) in r.iter().enumerate() {
            if let Some(w) = width.get_mut(i) {
                *w = (*w).max(f.chars().count());
            }
        }
    }
    let mut out = String::new();
    for r in std::iter::once(&table.columns).chain(shown.iter()) {
        let line: Vec<String> =
            r.iter().enumerate().map(|(i, f)| format!("{f:<w$}", w = width.get(i).copied().unwrap_or(0))).collect();
        out.push_str(line.join("  ").trim_end());
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use parquet::file::reader::{FileReader, SerializedFileReader};
    use parquet::record::Field;

    fn table() -> Table {
        Table {
            columns: vec!["serial".into(), "value".into(), "n".into(), "note".into()],
            kinds: vec![ColumnKind::Text, ColumnKind::Number, ColumnKind::Count, ColumnKind::Text],
            rows: vec![
                vec![
                    Cell::Text("SN-1, \"a\"".into()),
                    Cell::Number(0.1 + 0.2),
                    Cell::Count(3),
                    Cell::Text("'; DROP TABLE figure; --".into()),
                ],
                vec![Cell::Text("SN-2 ∮ \u{202e}".into()), Cell::Empty, Cell::Empty, Cell::Empty],
            ],
        }
    }

    #[test]
    fn csv_quotes_and_keeps_numbers_exact() {
        let csv = to_csv(&table());
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines[0], "serial,value,n,note");
        assert_eq!(lines[1], "\"SN-1, \"\"a\"\"\",0.30000000000000004,3,'; DROP TABLE figure; --");
        assert_eq!(lines[2], "SN-2 ∮ \u{202e},,,");
        assert_eq!(lines[1].split(',').nth(2).map(|v| v.parse::<f64>().ok()), Some(Some(0.1 + 0.2)));
    }

    #[test]
    fn parquet_reads_back_the_same_cells_with_types_and_nulls() {
        let t = table();
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.parquet");
        std::fs::write(&p, to_parquet(&t).unwrap()).unwrap();
        let r = SerializedFileReader::new(std::fs::File::open(&p).unwrap()).unwrap();
        assert_eq!(r.metadata().file_metadata().num_rows(), 2);
        let rows: Vec<_> = r.get_row_iter(None).unwrap().map(|x| x.unwrap()).collect();
        let cols: Vec<Vec<(String, Field)>> =
            rows.iter().map(|row| row.get_column_iter().map(|(n, f)| (n.clone(), f.clone())).collect()).collect();
        assert_eq!(cols[0][0], ("serial".into(), Field::Str("SN-1, \"a\"".into())));
        assert_eq!(cols[0][1], ("value".into(), Field::Double(0.1 + 0.2)));
        assert_eq!(cols[0][2], ("n".into(), Field::Long(3)));
        assert_eq!(cols[0][3].1, Field::Str("'; DROP TABLE figure; --".into()));
        assert_eq!(cols[1][0].1, Field::Str("SN-2 ∮ \u{202e}".into()));
        assert_eq!(cols[1][1].1, Field::Null);
        assert_eq!(cols[1][2].1, Field::Null);
    }

    #[test]
    fn a_cell_of_the_wrong_kind_is_an_error_and_an_empty_column_keeps_its_type() {
        let mut t = table();
        t.rows[0][2] = Cell::Text("three".into());
        let e = to_parquet(&t).unwrap_err().to_string();
        assert!(e.contains("row 1, column \"n\""), "{e}");
        let mut t = table();
        t.rows[0][1] = Cell::Empty;
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.parquet");
        std::fs::write(&p, to_parquet(&t).unwrap()).unwrap();
        let r = SerializedFileReader::new(std::fs::File::open(&p).unwrap()).unwrap();
        let col = r.metadata().file_metadata().schema_descr().column(1);
        assert_eq!(col.physical_type(), parquet::basic::Type::DOUBLE);
    }

    #[test]
    fn text_aligns_columns_rounds_numbers_and_escapes_control_characters() {
        let mut t = table();
        t.rows[1][0] = Cell::Text("SN-2\x1b[31m".into());
        let text = to_text(&t);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 3, "{text}");
        assert_eq!(lines[0], "serial          value     n  note");
        assert_eq!(lines[1], "SN-1, \"a\"       0.300000  3  '; DROP TABLE figure; --");
        assert_eq!(lines[2], "SN-2\\u{1b}[31m");
    }

    #[test]
    fn a_row_of_the_wrong_width_is_an_error() {
        let mut t = table();
        t.rows[1].pop();
        let e = to_parquet(&t).unwrap_err().to_string();
        assert!(e.contains("row 2 has 3 cells for 4 columns"), "{e}");
    }
}
