//! Reader of threshold and resolution records: one row per sample, a rate column
//! (`rate_dps`, `rate_rad_s`, `rate_dph`: unit from the suffix, as in the rate-table long
//! layout) and an output column (`output_v`, `output_mv`, ...), rows grouped by commanded rate
//! (zero-rate rows included for a threshold record, base-rate rows for a resolution record).
//! Other columns (time, run, temperature) are ignored. Errors name file, line and column.

use crate::rate_table::{find_column, output_unit_of_column, rate_unit_of};
use crate::text::{parse_number, parse_text_table};
use crate::DataError;
use gyrolab::threshold::{group_by_rate, RateSamples};
use gyrolab::units::{OutputUnit, RateUnit};
use std::path::Path;

/// Most distinct commanded rates in one record (a real test has 5 to 50).
pub const MAX_RATES: usize = 1_000;

/// Which columns and units to use; `None` means "find it from the header".
#[derive(Debug, Clone, Default, PartialEq)]
pub struct StepColumns {
    /// Name of the rate column (default: the column named `rate_<unit>`).
    pub rate: Option<String>,
    /// Name of the output column (default: the column named `output_<unit>`, or the only other column).
    pub output: Option<String>,
    /// Unit of the outputs, overriding the column suffix.
    pub output_unit: Option<OutputUnit>,
}

/// A threshold or resolution record read from a file.
#[derive(Debug, Clone, PartialEq)]
pub struct StepRecord {
    /// The samples grouped by commanded rate (deg/s), in order of first appearance.
    pub groups: Vec<RateSamples>,
    /// The 1-based line where each group's rate first appears (same order as `groups`).
    pub first_lines: Vec<u64>,
    /// Unit of the outputs.
    pub output_unit: OutputUnit,
    /// Unit the rates were given in.
    pub rate_unit: RateUnit,
    /// The file's comment lines (without `#`), in order: a simulated record says so in its
    /// first (`gyrolab simulated ...`).
    pub comments: Vec<String>,
}

/// Reads a threshold or resolution record.
pub fn read_step_record(path: &Path, columns: &StepColumns) -> Result<StepRecord, DataError> {
    let text = crate::text::read_text_file(
        path,
        crate::text::MAX_TABLE_BYTES,
        "a threshold or resolution record (CSV: rate_dps, output_<unit>)",
    )?;
    parse_step_record(path, &text, columns)
}

/// Parses a threshold or resolution record from text; `path` names it in errors.
pub fn parse_step_record(path: &Path, text: &str, columns: &StepColumns) -> Result<StepRecord, DataError> {
    let table = parse_text_table(path, text)?;
    let hl = table.header_line;
    let missing = |what: &str, expect: &str| {
        DataError::new(path, format!("no {what} column in the header: expected {expect}")).at_line(hl)
    };
    let rate_col = find_column(&table, columns.rate.as_deref(), "rate").ok_or_else(|| {
        missing("rate", "a column named rate_dps, rate_rad_s or rate_dph (or name it with rate_column)")
    })?;
    let output_col = match find_column(&table, columns.output.as_deref(), "output") {
        Some(c) => c,
        None => {
            let others: Vec<usize> = (0..table.header.len()).filter(|&c| c != rate_col).collect();
            match (columns.output.as_deref(), others.as_slice()) {
                (None, [one]) => *one,
                _ => {
                    return Err(missing(
                        "output",
                        "a column named output_<unit> such as output_v (or name it with output_column)",
                    ))
                }
            }
        }
    };
    let rate_unit = rate_unit_of(path, &table, rate_col, None)?;
    let output_unit = output_unit_of_column(path, &table, output_col, columns.output_unit, "output_unit")?;
    let width = table.header.len();
    let mut rates = Vec::with_capacity(table.rows.len());
    let mut outputs = Vec::with_capacity(table.rows.len());
    let mut first_lines: Vec<(f64, u64)> = Vec::new();
    for row in &table.rows {
        let line = row.line;
        if row.fields.len() != width {
            return Err(DataError::new(
                path,
                format!(
                    "this row has {} fields but the header has {width}: expected one value per column",
                    row.fields.len()
                ),
            )
            .at_line(line));
        }
        let name = |c: usize| table.header[c].as_str();
        let rate = rate_unit.to_dps(parse_number(path, line, rate_col + 1, name(rate_col), &row.fields[rate_col])?);
        let output = parse_number(path, line, output_col + 1, name(output_col), &row.fields[output_col])?;
        if !first_lines.iter().any(|(r, _)| *r == rate) {
            if first_lines.len() == MAX_RATES {
                return Err(DataError::new(
                    path,
                    format!("more than {MAX_RATES} distinct rates: expected a threshold or resolution test"),
                )
                .at_line(line));
            }
            first_lines.push((rate, line));
        }
        rates.push(rate);
        outputs.push(output);
    }
    if rates.is_empty() {
        return Err(DataError::new(path, "no data rows after the header: expected one row per sample").at_line(hl));
    }
    let groups = group_by_rate(&rates, &outputs);
    let first_lines =
        groups.iter().map(|g| first_lines.iter().find(|(r, _)| *r == g.rate_dps).map_or(hl, |p| p.1)).collect();
    let comments = table.comments.iter().map(|(_, c)| c.trim().to_string()).collect();
    Ok(StepRecord { groups, first_lines, output_unit, rate_unit, comments })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<StepRecord, DataError> {
        parse_step_record(Path::new("t.csv"), text, &StepColumns::default())
    }

    #[test]
    fn groups_rows_by_rate_with_units_from_the_suffix() {
        let r = parse("time_s,rate_dph,output_mv\n0,0,1\n1,0,3\n2,36,5\n3,36,7\n4,-36,0\n5,-36,2\n").unwrap();
        assert_eq!(r.output_unit, OutputUnit::Millivolt);
        assert_eq!(r.groups.len(), 3);
        // 36 deg/h = 0.01 deg/s.
        assert!((r.groups[1].rate_dps - 0.01).abs() < 1e-15);
        assert_eq!(r.groups[1].outputs, [5.0, 7.0]);
        assert_eq!(r.first_lines, [2, 4, 6]);
    }

    #[test]
    fn errors_name_line_and_column() {
        let e = parse("rate_dps,output_v\n0,1\n0.1,x\n").unwrap_err();
        assert_eq!(e.line, Some(3), "{e}");
        assert!(e.to_string().contains("output_v"), "{e}");
        let e = parse("rate,output_v\n0,1\n").unwrap_err();
        assert!(e.to_string().contains("the rate column has no unit"), "{e}");
        let e = parse("rate_dps,a,b\n0,1,2\n").unwrap_err();
        assert!(e.to_string().contains("no output column"), "{e}");
        let e = parse("rate_dps,output_v\n").unwrap_err();
        assert!(e.to_string().contains("no data rows"), "{e}");
        let e = parse("rate_dps,output_v\n0,1,2\n").unwrap_err();
        assert_eq!(e.line, Some(2), "{e}");
    }
}
