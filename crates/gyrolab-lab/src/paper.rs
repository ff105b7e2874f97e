//! The paper's data (Cheng et al. 2014), built in so that the demo needs no files: the one place
//! that holds them (`data/paper/*.csv`: Tables 1, 3, 4 in the long layout; Tables 2, 5, 6 as
//! printed), for the demo, the tests and every front end.

use gyrolab::published::PrintedValue;
use gyrolab_io::text::parse_text_table;
use gyrolab_io::DataError;
use gyrolab_report::paper::{ClaimedTable6, PrintedTable2Row, PrintedTable5Row};
use std::path::Path;

/// Rate-table records of the three axes (Tables 1, 3, 4): (axis, built-in name, CSV text).
pub const RATE_TABLES: [(&str, &str, &str); 3] = [
    ("x", "<built-in paper_rate_table_x.csv>", include_str!("../../../data/paper/paper_rate_table_x.csv")),
    ("y", "<built-in paper_rate_table_y.csv>", include_str!("../../../data/paper/paper_rate_table_y.csv")),
    ("z", "<built-in paper_rate_table_z.csv>", include_str!("../../../data/paper/paper_rate_table_z.csv")),
];
const TABLE2: &str = include_str!("../../../data/paper/paper_table2_means_x.csv");
const TABLE5: &str = include_str!("../../../data/paper/paper_table5_bias.csv");
const TABLE6: &str = include_str!("../../../data/paper/paper_table6_claimed.csv");

fn printed(file: &Path, line: u64, col: usize, text: &str) -> Result<PrintedValue, DataError> {
    PrintedValue::parse(text).ok_or_else(|| {
        DataError::new(file, format!("found '{text}', expected a printed decimal number"))
            .at_line(line)
            .at_column(col, None)
    })
}

fn field<'a>(file: &Path, row: &'a gyrolab_io::text::TextRow, col: usize) -> Result<&'a str, DataError> {
    row.fields
        .get(col)
        .map(String::as_str)
        .ok_or_else(|| DataError::new(file, format!("expected at least {} fields", col + 1)).at_line(row.line))
}

/// Table 2 as printed (axis x).
pub fn table2() -> Result<Vec<PrintedTable2Row>, DataError> {
    let file = Path::new("<built-in paper_table2_means_x.csv>");
    let t = parse_text_table(file, TABLE2)?;
    t.rows
        .iter()
        .map(|r| {
            let num = |c: usize| printed(file, r.line, c + 1, field(file, r, c)?);
            Ok(PrintedTable2Row {
                point: num(0)?.value as usize,
                rate_dps: num(1)?.value,
                fwd: num(2)?,
                rev: num(3)?,
                mean: num(4)?,
            })
        })
        .collect()
}

/// Table 5 as printed: four zero-rate outputs per axis and the printed mean.
pub fn table5() -> Result<Vec<PrintedTable5Row>, DataError> {
    let file = Path::new("<built-in paper_table5_bias.csv>");
    let t = parse_text_table(file, TABLE5)?;
    t.rows
        .iter()
        .map(|r| {
            let n = r.fields.len();
            let tests = (1..n - 1)
                .map(|c| Ok(printed(file, r.line, c + 1, field(file, r, c)?)?.value))
                .collect::<Result<_, DataError>>()?;
            Ok(PrintedTable5Row {
                axis: field(file, r, 0)?.to_string(),
                tests_v: tests,
                mean: printed(file, r.line, n, field(file, r, n - 1)?)?,
            })
        })
        .collect()
}

/// Table 6 as printed (the paper's claims).
pub fn table6() -> Result<Vec<ClaimedTable6>, DataError> {
    let file = Path::new("<built-in paper_table6_claimed.csv>");
    let t = parse_text_table(file, TABLE6)?;
    t.rows
        .iter()
        .map(|r| {
            let num = |c: usize| printed(file, r.line, c + 1, field(file, r, c)?);
            Ok(ClaimedTable6 {
                axis: field(file, r, 0)?.to_string(),
                scale_factor_mv_per_dps: num(1)?,
                zero_bias_v: num(2)?,
                linearity_pct: num(3)?,
                hysteresis_pct: num(4)?,
                repeatability_pct: num(5)?,
                accuracy_pct: num(6)?,
            })
        })
        .collect()
}
