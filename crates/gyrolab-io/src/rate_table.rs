//! Reader of rate-table test records, in two layouts:
//! - long: one row per sample, columns rate, run, stroke, output (`rate_dps,run,stroke,output_v`);
//!   rows with stroke `rest_start` / `rest_end` (rate 0) are the rest records of paper eq. 5;
//! - wide (the paper's Table 1): one row per rate, one column per run and stroke, with either a
//!   single header row (`rate_dps,run1_fwd_v,run1_rev_v,...`) or two header rows as a
//!   spreadsheet exports merged cells (run labels over stroke labels).
//!
//! Units come from the column-name suffix (`_dps`, `_rad_s` for rates; `_v`, `_mv`, `_lsb`,
//! `_dps`, `_rad_s` for outputs) or from options.

use crate::text::{parse_number, parse_text_table, TextTable};
use crate::DataError;
use gyrolab::rate_test::{RateObservation, RateTable, RateTestError, RestRecord, Stroke};
use gyrolab::units::{split_unit_suffix, OutputUnit, RateUnit};
use std::path::Path;

/// Most distinct table rates in one record (a real test has 10 to 100).
pub const MAX_RATES: usize = 10_000;
/// Most runs in one record (a real test has 1 to 20).
pub const MAX_RUNS: usize = 1_000;
/// Most cells (distinct rates times runs) of a record's grid: the grid is allocated whole.
pub const MAX_GRID_CELLS: usize = 1_000_000;

/// The error of a record with more rates, runs or grid cells than a real one has.
fn too_large(path: &Path, what: String) -> DataError {
    DataError::new(path, format!("{what}: expected a rate-table test (is this the right file or column?)"))
}

/// Which columns and units to use; `None` means "find it from the header".
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RateColumns {
    /// Name of the rate column.
    pub rate: Option<String>,
    /// Name of the run column.
    pub run: Option<String>,
    /// Name of the stroke column.
    pub stroke: Option<String>,
    /// Name of the output column.
    pub output: Option<String>,
    /// Unit of the rates, overriding any suffix.
    pub rate_unit: Option<RateUnit>,
    /// Unit of the outputs, overriding any suffix.
    pub output_unit: Option<OutputUnit>,
}

/// The layout a record was read in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RateLayout {
    /// One row per sample.
    Long,
    /// One row per rate, one column per run and stroke.
    Wide,
    /// A raw log (time, table rate, outputs) segmented into plateaus.
    Raw,
}

/// A rate-table record read from a file.
#[derive(Debug, Clone, PartialEq)]
pub struct RateTableFile {
    /// The grid of mean outputs, rates converted to deg/s.
    pub table: RateTable,
    /// Unit of the outputs.
    pub output_unit: OutputUnit,
    /// Unit the rates were given in.
    pub rate_unit: RateUnit,
    /// Layout found.
    pub layout: RateLayout,
    /// Number of output samples read (rest samples excluded).
    pub samples: usize,
}

/// Reads a rate-table record from a file.
pub fn read_rate_table(path: &Path, columns: &RateColumns) -> Result<RateTableFile, DataError> {
    let text = crate::text::read_text_file(
        path,
        crate::text::MAX_TABLE_BYTES,
        "a rate-table record (CSV, TSV or whitespace-separated text)",
    )?;
    parse_rate_table(path, &text, columns)
}

/// Parses a rate-table record from text; `path` names it in errors.
pub fn parse_rate_table(path: &Path, text: &str, columns: &RateColumns) -> Result<RateTableFile, DataError> {
    let table = parse_text_table(path, text)?;
    let stroke_name = columns.stroke.as_deref().unwrap_or("stroke");
    if table.column(stroke_name).is_some() {
        read_long(path, &table, columns, stroke_name)
    } else {
        read_wide(path, &table, columns)
    }
}

pub(crate) fn find_column(table: &TextTable, explicit: Option<&str>, base: &str) -> Option<usize> {
    match explicit {
        Some(n) => table.column(n),
        None => table.header.iter().position(|h| split_unit_suffix(h).0 == base || h.eq_ignore_ascii_case(base)),
    }
}

pub(crate) fn rate_unit_of(
    path: &Path,
    table: &TextTable,
    col: usize,
    given: Option<RateUnit>,
) -> Result<RateUnit, DataError> {
    if let Some(u) = given {
        return Ok(u);
    }
    let name = &table.header[col];
    let err = |m: String| DataError::new(path, m).at_line(table.header_line).at_column(col + 1, Some(name));
    // Bracketed units as in the paper's header, e.g. "转台速率 (°/sec)" or "rate (deg/s)".
    if let Some(u) = bracketed_unit(name).and_then(|b| RateUnit::parse(&b.replace("sec", "s"))) {
        return Ok(u);
    }
    match split_unit_suffix(name).1 {
        Some(s) => RateUnit::parse(&s).ok_or_else(|| {
            err(format!(
                "unknown rate unit suffix '_{}': expected one of _dps, _rad_s, _dph (or give --rate-unit)",
                crate::text::excerpt(&s)
            ))
        }),
        None => Err(err("the rate column has no unit: name it rate_dps or rate_rad_s, or give --rate-unit".into())),
    }
}

fn bracketed_unit(name: &str) -> Option<String> {
    let open = name.rfind(['(', '（'])?;
    let rest = &name[open..];
    let inner = rest.trim_start_matches(['(', '（']).trim_end_matches([')', '）']).trim();
    Some(inner.replace('°', "deg").replace("deg/sec", "deg/s"))
}

pub(crate) fn output_unit_of_name(name: &str) -> Result<Option<OutputUnit>, String> {
    if let Some(b) = bracketed_unit(name) {
        if let Some(u) = OutputUnit::parse_gyro_output(&b) {
            return Ok(Some(u));
        }
    }
    match split_unit_suffix(name).1 {
        Some(s) => OutputUnit::parse_gyro_output(&s).map(Some).ok_or_else(|| {
            format!(
                "unknown output unit suffix '_{}': expected one of _v, _mv, _lsb, _dps, _rad_s",
                crate::text::excerpt(&s)
            )
        }),
        None => Ok(None),
    }
}

fn data_error_from_grid(path: &Path, e: RateTestError, first_line_of_rate: impl Fn(f64) -> Option<u64>) -> DataError {
    match e {
        RateTestError::Empty => DataError::new(path, "no data rows after the header: expected one row per sample"),
        RateTestError::TooFewRates(n) => DataError::new(
            path,
            format!("{n} distinct rate(s) in the record: a scale factor needs at least two different table rates"),
        ),
        RateTestError::MissingCell { rate_dps, run, stroke } => {
            let mut d = DataError::new(
                path,
                format!(
                    "no data for rate {rate_dps} deg/s in run {run}, stroke {stroke}: every rate needs an output in every run and stroke"
                ),
            );
            if let Some(l) = first_line_of_rate(rate_dps) {
                d.message.push_str(&format!(" (rate first seen at line {l})"));
            }
            d
        }
        other => DataError::new(path, other.to_string()),
    }
}

/// The unit of an output column: `given`, else its name's suffix; an error located at the header
/// names the option (`give`) that sets it.
pub(crate) fn output_unit_of_column(
    path: &Path,
    table: &TextTable,
    output_col: usize,
    given: Option<OutputUnit>,
    give: &str,
) -> Result<OutputUnit, DataError> {
    let hl = table.header_line;
    let out_name = &table.header[output_col];
    match given {
        Some(u) => Ok(u),
        None => output_unit_of_name(out_name)
            .map_err(|m| DataError::new(path, m).at_line(hl).at_column(output_col + 1, Some(out_name)))?
            .ok_or_else(|| {
                DataError::new(
                    path,
                    format!(
                        "the output column has no unit: name it output_v, output_mv, output_lsb or output_dps, or \
                         give {give}"
                    ),
                )
                .at_line(hl)
                .at_column(output_col + 1, Some(out_name))
            }),
    }
}

fn read_long(
    path: &Path,
    table: &TextTable,
    columns: &RateColumns,
    stroke_name: &str,
) -> Result<RateTableFile, DataError> {
    let hl = table.header_line;
    let missing = |what: &str, expect: &str| {
        DataError::new(path, format!("no {what} column in the header: expected {expect}")).at_line(hl)
    };
    let rate_col = find_column(table, columns.rate.as_deref(), "rate")
        .ok_or_else(|| missing("rate", "a column named rate_dps or rate_rad_s (or name it with --rate-column)"))?;
    let stroke_col = table.column(stroke_name).ok_or_else(|| missing("stroke", "a column named stroke"))?;
    let run_col = find_column(table, columns.run.as_deref(), "run").ok_or_else(|| {
        missing(
            "run",
            &format!("a column named '{}' (or name it with --run-column)", columns.run.as_deref().unwrap_or("run")),
        )
    })?;
    let output_col = match find_column(table, columns.output.as_deref(), "output") {
        Some(c) => c,
        None => {
            let others: Vec<usize> =
                (0..table.header.len()).filter(|&c| c != rate_col && c != stroke_col && c != run_col).collect();
            match (columns.output.as_deref(), others.as_slice()) {
                (None, [one]) => *one,
                _ => {
                    return Err(missing(
                        "output",
                        "a column named output_<unit> such as output_v (or name it with --output-column)",
                    ))
                }
            }
        }
    };
    let rate_unit = rate_unit_of(path, table, rate_col, columns.rate_unit)?;
    let output_unit = output_unit_of_column(path, table, output_col, columns.output_unit, "--output-unit")?;
    let width = table.header.len();
    let mut obs = Vec::with_capacity(table.rows.len());
    let mut first_lines: Vec<(f64, u64)> = Vec::new();
    let mut runs: Vec<u32> = Vec::new();
    let (mut rest_start, mut rest_end) = (Vec::new(), Vec::new());
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
        let field = |c: usize| row.fields[c].as_str();
        let name = |c: usize| table.header[c].as_str();
        let rate = rate_unit.to_dps(parse_number(path, line, rate_col + 1, name(rate_col), field(rate_col))?);
        let output = parse_number(path, line, output_col + 1, name(output_col), field(output_col))?;
        let run = parse_run(field(run_col)).ok_or_else(|| {
            DataError::new(
                path,
                format!("found '{}', expected a whole run number such as 1", crate::text::excerpt(field(run_col))),
            )
            .at_line(line)
            .at_column(run_col + 1, Some(name(run_col)))
        })?;
        let label = field(stroke_col);
        let stroke = match label.to_ascii_lowercase().as_str() {
            "rest_start" | "start" => {
                rest_start.push(output);
                continue;
            }
            "rest_end" | "end" => {
                rest_end.push(output);
                continue;
            }
            _ => Stroke::from_label(label).ok_or_else(|| {
                DataError::new(
                    path,
                    format!(
                        "unknown stroke label '{}': expected one of {}, or rest_start/rest_end",
                        crate::text::excerpt(label),
                        Stroke::ACCEPTED
                    ),
                )
                .at_line(line)
                .at_column(stroke_col + 1, Some(name(stroke_col)))
            })?,
        };
        if !first_lines.iter().any(|(r, _)| *r == rate) {
            if first_lines.len() == MAX_RATES {
                return Err(too_large(path, format!("more than {MAX_RATES} distinct table rates")).at_line(line));
            }
            first_lines.push((rate, line));
        }
        if let Err(at) = runs.binary_search(&run) {
            if runs.len() == MAX_RUNS {
                return Err(too_large(path, format!("more than {MAX_RUNS} runs")).at_line(line));
            }
            runs.insert(at, run);
        }
        if first_lines.len() * runs.len() > MAX_GRID_CELLS {
            return Err(too_large(
                path,
                format!(
                    "{} distinct rates in {} runs, more than {MAX_GRID_CELLS} rate-run cells",
                    first_lines.len(),
                    runs.len()
                ),
            )
            .at_line(line));
        }
        obs.push(RateObservation { rate_dps: rate, run, stroke, output });
    }
    let rest = match (rest_start.is_empty(), rest_end.is_empty()) {
        (true, true) => None,
        (false, false) => Some(RestRecord {
            start: rest_start.iter().sum::<f64>() / rest_start.len() as f64,
            end: rest_end.iter().sum::<f64>() / rest_end.len() as f64,
        }),
        _ => return Err(DataError::new(
            path,
            "rest records found at only one end of the test: expected both rest_start and rest_end rows (paper eq. 5)",
        )),
    };
    let samples = obs.len();
    let grid = RateTable::from_observations(&obs, rest).map_err(|e| {
        data_error_from_grid(path, e, |r| first_lines.iter().find(|(x, _)| (x - r).abs() < 1e-9).map(|p| p.1))
    })?;
    Ok(RateTableFile { table: grid, output_unit, rate_unit, layout: RateLayout::Long, samples })
}

/// Parses a run label: digits anywhere ("1", "run1", "r1"), or a Chinese ordinal ("第一次").
/// A column name without its bracketed unit (`Run 1 (V)` -> `Run 1`), and that unit.
fn strip_bracketed_unit(name: &str) -> (String, Option<String>) {
    let t = name.trim();
    if t.ends_with([')', '）', ']']) {
        if let Some(open) = t.rfind(['(', '（', '[']) {
            let inner = t[open..].trim_start_matches(['(', '（', '[']).trim_end_matches([')', '）', ']']).trim();
            return (t[..open].trim().to_string(), Some(inner.replace('°', "deg").replace("deg/sec", "deg/s")));
        }
    }
    (t.to_string(), None)
}

fn parse_run(label: &str) -> Option<u32> {
    let (label, _) = strip_bracketed_unit(label);
    let label = label.as_str();
    let digits: String = label.chars().filter(|c| c.is_ascii_digit()).collect();
    if !digits.is_empty() {
        let rest_ok = label.chars().all(|c| c.is_ascii_digit() || c.is_alphabetic() || c == ' ' || c == '_');
        if label.contains('.') || !rest_ok {
            return None;
        }
        return digits.parse().ok();
    }
    const NUMERALS: [char; 10] = ['一', '二', '三', '四', '五', '六', '七', '八', '九', '十'];
    label.chars().find_map(|c| NUMERALS.iter().position(|&n| n == c)).map(|i| i as u32 + 1)
}

/// Splits a wide-layout column name like `run1_fwd_v` or `1 rev` into (run, stroke, unit text).
fn parse_wide_column(name: &str) -> Option<(u32, Stroke, Option<String>)> {
    let (base, bracketed) = strip_bracketed_unit(name);
    let lower = base.to_lowercase();
    let tokens: Vec<&str> = lower.split(['_', ' ']).filter(|t| !t.is_empty()).collect();
    let mut run = None;
    let mut stroke = None;
    let mut unit = bracketed.map(|u| u.to_lowercase());
    for t in &tokens {
        if let Some(s) = Stroke::from_label(t) {
            if stroke.is_none() {
                stroke = Some(s);
                continue;
            }
        }
        if run.is_none() && (t.chars().any(|c| c.is_ascii_digit()) || t.contains('次')) {
            run = parse_run(t);
            if run.is_some() {
                continue;
            }
        }
        if *t == "run" || *t == "r" {
            continue;
        }
        unit = Some(t.to_string());
    }
    Some((run?, stroke?, unit))
}

fn read_wide(path: &Path, table: &TextTable, columns: &RateColumns) -> Result<RateTableFile, DataError> {
    let hl = table.header_line;
    let rate_col = match columns.rate.as_deref() {
        Some(n) => table.column(n).ok_or_else(|| {
            DataError::new(path, format!("no column named '{}': expected it in the header", crate::text::excerpt(n)))
                .at_line(hl)
        })?,
        None => 0,
    };
    // Two header rows: the first data row holds stroke labels instead of numbers.
    let two_rows = table.rows.first().is_some_and(|r| {
        r.fields
            .iter()
            .enumerate()
            .filter(|(c, _)| *c != rate_col)
            .all(|(_, f)| f.is_empty() || Stroke::from_label(f).is_some())
            && r.fields.iter().any(|f| Stroke::from_label(f).is_some())
    });
    let mut cols: Vec<(usize, u32, Stroke)> = Vec::new();
    let mut unit_seen: Option<(OutputUnit, usize)> = None;
    let mut note_unit = |u: Option<OutputUnit>, c: usize| -> Result<(), DataError> {
        if let Some(u) = u {
            match unit_seen {
                Some((prev, pc)) if prev != u => {
                    return Err(DataError::new(
                        path,
                        format!(
                            "column {} says {u} but column {} says {prev}: expected one output unit",
                            c + 1,
                            pc + 1
                        ),
                    )
                    .at_line(hl)
                    .at_column(c + 1, Some(&table.header[c])))
                }
                None => unit_seen = Some((u, c)),
                _ => {}
            }
        }
        Ok(())
    };
    let data_rows: &[crate::text::TextRow];
    if two_rows {
        let strokes = &table.rows[0];
        let mut current_run = None;
        for c in 0..table.header.len().max(strokes.fields.len()) {
            if c == rate_col {
                continue;
            }
            let top = table.header.get(c).map(String::as_str).unwrap_or("");
            if !top.is_empty() {
                current_run = parse_run(top);
                if current_run.is_none() {
                    return Err(DataError::new(
                        path,
                        format!(
                            "found '{}', expected a run label such as 'run 1' or '第一次' over the stroke columns",
                            crate::text::excerpt(top)
                        ),
                    )
                    .at_line(hl)
                    .at_column(c + 1, Some(top)));
                }
                let u = output_unit_of_name(top).ok().flatten();
                note_unit(u, c)?;
            }
            let label = strokes.fields.get(c).map(String::as_str).unwrap_or("");
            let stroke = Stroke::from_label(label).ok_or_else(|| {
                DataError::new(
                    path,
                    format!("found '{}', expected a stroke label ({})", crate::text::excerpt(label), Stroke::ACCEPTED),
                )
                .at_line(strokes.line)
                .at_column(c + 1, None)
            })?;
            let run = current_run.ok_or_else(|| {
                DataError::new(
                    path,
                    "a stroke column without a run label above it: expected run labels in the first header row",
                )
                .at_line(hl)
                .at_column(c + 1, None)
            })?;
            cols.push((c, run, stroke));
        }
        data_rows = &table.rows[1..];
    } else {
        for (c, name) in table.header.iter().enumerate() {
            if c == rate_col {
                continue;
            }
            let (run, stroke, unit) = parse_wide_column(name).ok_or_else(|| {
                DataError::new(
                    path,
                    format!(
                        "cannot read run and stroke from column name '{}': expected names like run1_fwd_v, run1_rev_v (long layout needs a 'stroke' column)",
                        crate::text::excerpt(name)
                    ),
                )
                .at_line(hl)
                .at_column(c + 1, Some(name))
            })?;
            let u = match unit {
                Some(s) => Some(OutputUnit::parse_gyro_output(&s).ok_or_else(|| {
                    DataError::new(
                        path,
                        format!(
                            "unknown output unit suffix '_{}': expected one of _v, _mv, _lsb, _dps, _rad_s",
                            crate::text::excerpt(&s)
                        ),
                    )
                    .at_line(hl)
                    .at_column(c + 1, Some(name))
                })?),
                None => None,
            };
            note_unit(u, c)?;
            cols.push((c, run, stroke));
        }
        data_rows = &table.rows;
    }
    let output_unit = match (columns.output_unit, unit_seen) {
        (Some(u), _) => u,
        (None, Some((u, _))) => u,
        (None, None) => {
            return Err(DataError::new(
                path,
                "no output unit in the header: name the columns like run1_fwd_v (or _mv, _lsb, _dps), or give --output-unit",
            )
            .at_line(hl))
        }
    };
    let rate_unit = if two_rows && columns.rate_unit.is_none() && bracketed_unit(&table.header[rate_col]).is_none() {
        rate_unit_of(path, table, rate_col, None)?
    } else {
        rate_unit_of(path, table, rate_col, columns.rate_unit)?
    };
    let width = table.header.len().max(cols.iter().map(|c| c.0 + 1).max().unwrap_or(0));
    let mut obs = Vec::new();
    let mut first_lines = Vec::new();
    for row in data_rows {
        if row.fields.len() != width {
            return Err(DataError::new(
                path,
                format!(
                    "this row has {} fields but the header has {width}: expected one value per run and stroke",
                    row.fields.len()
                ),
            )
            .at_line(row.line));
        }
        let rate_name = table.header[rate_col].as_str();
        let rate = rate_unit.to_dps(parse_number(path, row.line, rate_col + 1, rate_name, &row.fields[rate_col])?);
        if cols.iter().all(|(c, _, _)| row.fields[*c].is_empty()) {
            return Err(DataError::new(
                path,
                format!("rate {rate} deg/s has no data: expected an output for every run and stroke"),
            )
            .at_line(row.line));
        }
        if first_lines.len() == MAX_RATES {
            return Err(too_large(path, format!("more than {MAX_RATES} rate rows")).at_line(row.line));
        }
        first_lines.push((rate, row.line));
        for &(c, run, stroke) in &cols {
            let name = table.header.get(c).map(String::as_str).unwrap_or("");
            let output = parse_number(path, row.line, c + 1, name, &row.fields[c])?;
            obs.push(RateObservation { rate_dps: rate, run, stroke, output });
        }
    }
    let samples = obs.len();
    let grid = RateTable::from_observations(&obs, None).map_err(|e| {
        data_error_from_grid(path, e, |r| first_lines.iter().find(|(x, _)| (x - r).abs() < 1e-9).map(|p| p.1))
    })?;
    Ok(RateTableFile { table: grid, output_unit, rate_unit, layout: RateLayout::Wide, samples })
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    const PAPER_X: &str = include_str!("../../../data/paper/paper_rate_table_x.csv");

    fn read(text: &str) -> Result<RateTableFile, DataError> {
        parse_rate_table(Path::new("t.csv"), text, &RateColumns::default())
    }

    #[test]
    fn paper_long_layout() {
        let f = read(PAPER_X).unwrap();
        assert_eq!(f.layout, RateLayout::Long);
        assert_eq!(f.output_unit, OutputUnit::Volt);
        assert_eq!(f.table.rates_dps.len(), 14);
        assert_eq!(f.table.runs, vec![1, 2, 3, 4]);
        assert_eq!(f.samples, 112);
        // Table 1, rate -300, run 1: fwd 0.251348, rev 0.248927.
        assert_eq!(f.table.forward[0][0], 0.251348);
        assert_eq!(f.table.reverse[0][0], 0.248927);
    }

    /// Builds the paper's Table 1 in the wide layout from the long file.
    fn paper_wide(two_rows: bool, sep: &str) -> String {
        let f = read(PAPER_X).unwrap();
        let mut s = String::new();
        if two_rows {
            s += &format!("rate (deg/s){sep}第一次 (V){sep}{sep}第二次{sep}{sep}第三次{sep}{sep}第四次{sep}\n");
            s += &format!("{sep}正行程{sep}反行程{sep}正行程{sep}反行程{sep}正行程{sep}反行程{sep}正行程{sep}反行程\n");
        } else {
            let names: Vec<String> = (1..=4).flat_map(|r| [format!("run{r}_fwd_v"), format!("run{r}_rev_v")]).collect();
            s += &format!("rate_dps{sep}{}\n", names.join(sep));
        }
        for (j, w) in f.table.rates_dps.iter().enumerate() {
            let cells: Vec<String> =
                (0..4).flat_map(|r| [f.table.forward[j][r].to_string(), f.table.reverse[j][r].to_string()]).collect();
            s += &format!("{w}{sep}{}\n", cells.join(sep));
        }
        s
    }

    #[test]
    fn wide_layouts_give_the_same_grid() {
        let long = read(PAPER_X).unwrap();
        for (two, sep) in [(false, ","), (false, "\t"), (true, ","), (true, "\t")] {
            let w = read(&paper_wide(two, sep)).unwrap_or_else(|e| panic!("{two} {sep:?}: {e}"));
            assert_eq!(w.layout, RateLayout::Wide);
            assert_eq!(w.table, long.table, "two rows {two}, sep {sep:?}");
            assert_eq!(w.output_unit, OutputUnit::Volt);
        }
        let ws = paper_wide(false, " ");
        assert_eq!(read(&ws).unwrap().table, long.table);
    }

    #[test]
    fn units_from_suffix_and_options() {
        let text = "rate_rad_s,run,stroke,output_mv\n-1,1,fwd,10\n1,1,fwd,20\n-1,1,rev,11\n1,1,rev,21\n";
        let f = read(text).unwrap();
        assert_eq!(f.output_unit, OutputUnit::Millivolt);
        assert_relative_eq!(f.table.rates_dps[1], 57.29577951308232);
        let o = RateColumns { output_unit: Some(OutputUnit::Lsb), ..Default::default() };
        let g = parse_rate_table(Path::new("t.csv"), text, &o).unwrap();
        assert_eq!(g.output_unit, OutputUnit::Lsb);
    }

    #[test]
    fn rest_records() {
        let text = "rate_dps,run,stroke,output_v\n0,1,rest_start,2.0\n-1,1,fwd,1\n1,1,fwd,3\n-1,1,rev,1\n1,1,rev,3\n0,1,rest_end,2.2\n";
        let f = read(text).unwrap();
        assert_eq!(f.table.rest, Some(RestRecord { start: 2.0, end: 2.2 }));
    }

    fn err(text: &str) -> DataError {
        read(text).unwrap_err()
    }

    #[test]
    fn bad_inputs_name_line_and_column() {
        let e = err("");
        assert!(e.message.contains("empty"), "{e}");
        let e = err("rate_dps,run,stroke\n1,1,fwd\n2,1,fwd\n");
        assert!(e.message.contains("no output column"), "{e}");
        let e = err("rate_dps,run,stroke,output_v\n1,1,fwd,abc\n");
        assert_eq!((e.line, e.column.as_ref().map(|c| c.index)), (Some(2), Some(4)), "{e}");
        let e = err("rate_dps,run,stroke,output_v\n1,1,fwd,NaN\n");
        assert!(e.message.contains("finite"), "{e}");
        let e = err("rate_dps,run,stroke,output_v\n1,1,fwd,1\n1,1,rev,1\n");
        assert!(e.message.contains("at least two"), "{e}");
        let e = err("rate_dps,run,stroke,output_v\n1,1,fwd,1\n2,1,fwd,1\n1,1,rev,1\n2,1,rev,1\n1,2,fwd,1\n2,2,fwd,1\n");
        assert!(e.message.contains("run 2, stroke rev"), "{e}");
        let e = err("rate_dps,run,stroke,output_v\n1,1,sideways,1\n");
        assert_eq!((e.line, e.column.as_ref().map(|c| c.index)), (Some(2), Some(3)));
        assert!(e.message.contains("unknown stroke label 'sideways'"), "{e}");
        let e = err("rate_dps,run,stroke,output_v,run\n");
        assert!(e.message.contains("duplicate"), "{e}");
        let e = err("rate_dps,run,stroke,output_amps\n1,1,fwd,1\n");
        assert!(e.message.contains("unknown output unit suffix '_amps'"), "{e}");
        assert_eq!(e.column.as_ref().map(|c| c.index), Some(4));
        let e = err("rate_xyz,run,stroke,output_v\n1,1,fwd,1\n");
        assert!(e.message.contains("unknown rate unit suffix"), "{e}");
        let e = err("rate_dps,run,stroke,output_v\n1,1,fwd\n");
        assert_eq!(e.line, Some(2));
        assert!(e.message.contains("3 fields"), "{e}");
        let e = err("rate_dps,run1_fwd_v,run1_rev_v\n1,1,2\n5,,\n");
        assert!(e.message.contains("rate 5 deg/s has no data"), "{e}");
        assert_eq!(e.line, Some(3));
        let e = err("rate_dps,run,stroke,output_v\n");
        assert!(e.message.contains("no data rows"), "{e}");
        let e = err("rate_dps,run,stroke,output_v\n1,1.5,fwd,1\n");
        assert!(e.message.contains("whole run number"), "{e}");
    }

    #[test]
    fn run_labels() {
        assert_eq!(parse_run("3"), Some(3));
        assert_eq!(parse_run("run12"), Some(12));
        assert_eq!(parse_run("第二次"), Some(2));
        assert_eq!(parse_run("1.5"), None);
        assert_eq!(parse_wide_column("run2_rev_mv").map(|c| (c.0, c.1)), Some((2, Stroke::Reverse)));
    }
}
