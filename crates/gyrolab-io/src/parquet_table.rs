//! Parquet tables (the `parquet` crate, without Arrow): numeric columns read as a time series
//! by the header rules of a delimited file (units from the column names, as for CSV), and IMU
//! channels written for other tools (`gyrolab convert --out imu.parquet`).

use crate::error::DataError;
use crate::series::{series_from_columns, RowKind, SeriesData, SeriesOptions, SkipReason, SkippedColumn};
use parquet::basic::{Compression, Type as PhysicalType, ZstdLevel};
use parquet::column::reader::ColumnReader;
use parquet::data_type::{DoubleType, Int64Type};
use parquet::file::properties::WriterProperties;
use parquet::file::reader::{FileReader, SerializedFileReader};
use parquet::file::writer::SerializedFileWriter;
use std::path::Path;
use std::sync::Arc;

/// Rows read from a column at once.
const BATCH: usize = 64 * 1024;

fn perr(path: &Path, e: impl std::fmt::Display) -> DataError {
    DataError::new(path, format!("not a readable Parquet file: {e}"))
}

/// Reads the numeric columns (INT32, INT64, FLOAT, DOUBLE; nulls as missing cells) of a
/// Parquet file as a time series; other columns are skipped with a note.
pub fn read_parquet(path: &Path, options: &SeriesOptions) -> Result<SeriesData, DataError> {
    let file = std::fs::File::open(path).map_err(|e| DataError::io(path, &e))?;
    let reader = SerializedFileReader::new(file).map_err(|e| perr(path, e))?;
    let meta = reader.metadata();
    let schema = meta.file_metadata().schema_descr();
    let rows = meta.file_metadata().num_rows().max(0) as u64;
    let limit = options.max_rows.unwrap_or(crate::raw_log::MAX_RAW_LOG_ROWS);
    if rows > limit {
        return Err(DataError::new(path, format!("{rows} rows: more than the {limit} this reader accepts")));
    }
    let mut names = Vec::new();
    let mut leaves = Vec::new();
    let mut skipped = Vec::new();
    for (i, col) in schema.columns().iter().enumerate() {
        let numeric = matches!(
            col.physical_type(),
            PhysicalType::INT32 | PhysicalType::INT64 | PhysicalType::FLOAT | PhysicalType::DOUBLE
        );
        let name = col.path().string();
        if numeric && col.max_rep_level() == 0 {
            names.push(name);
            leaves.push(i);
        } else {
            skipped.push(SkippedColumn { column: i + 1, name, reason: SkipReason::NotNumeric });
        }
    }
    let mut columns: Vec<Vec<f64>> = leaves.iter().map(|_| Vec::with_capacity(rows as usize)).collect();
    for g in 0..reader.num_row_groups() {
        let group = reader.get_row_group(g).map_err(|e| perr(path, e))?;
        for (k, &leaf) in leaves.iter().enumerate() {
            let max_def = schema.column(leaf).max_def_level();
            let col = group.get_column_reader(leaf).map_err(|e| perr(path, e))?;
            read_column(col, max_def, &mut columns[k]).map_err(|e| perr(path, e))?;
        }
    }
    let mut data = series_from_columns(path, &names, columns, RowKind::Row, options)?;
    data.header.skipped.extend(skipped);
    Ok(data)
}

/// Appends a column's values as f64, nulls as NaN.
fn read_column(col: ColumnReader, max_def: i16, out: &mut Vec<f64>) -> parquet::errors::Result<()> {
    macro_rules! drain {
        ($r:expr, $conv:expr) => {{
            let mut r = $r;
            let mut values = Vec::new();
            let mut defs = Vec::new();
            loop {
                values.clear();
                defs.clear();
                let (records, _, _) =
                    r.read_records(BATCH, if max_def > 0 { Some(&mut defs) } else { None }, None, &mut values)?;
                if records == 0 {
                    break;
                }
                if max_def > 0 {
                    let mut it = values.iter();
                    for &d in &defs {
                        out.push(if d == max_def { it.next().map_or(f64::NAN, $conv) } else { f64::NAN });
                    }
                } else {
                    out.extend(values.iter().map($conv));
                }
            }
        }};
    }
    match col {
        ColumnReader::Int32ColumnReader(r) => drain!(r, |v: &i32| f64::from(*v)),
        ColumnReader::Int64ColumnReader(r) => drain!(r, |v: &i64| *v as f64),
        ColumnReader::FloatColumnReader(r) => drain!(r, |v: &f32| f64::from(*v)),
        ColumnReader::DoubleColumnReader(r) => drain!(r, |v: &f64| *v),
        _ => {}
    }
    Ok(())
}

/// Writes a table: an INT64 time column (`time_name`, such as `timestamp_ns`) and DOUBLE
/// columns, zstd-compressed, in row groups of one million rows, to `out`.
pub fn write_parquet(
    out: &mut (dyn std::io::Write + Send),
    time_name: &str,
    time: &[i64],
    names: &[String],
    columns: &[&[f64]],
) -> std::io::Result<()> {
    let io = |e: parquet::errors::ParquetError| std::io::Error::other(e.to_string());
    let clean =
        |n: &str| n.chars().map(|c| if c.is_ascii_alphanumeric() || c == '_' { c } else { '_' }).collect::<String>();
    let mut schema = format!("message imu {{ required int64 {}; ", clean(time_name));
    for n in names {
        schema.push_str(&format!("required double {}; ", clean(n)));
    }
    schema.push('}');
    let schema = Arc::new(parquet::schema::parser::parse_message_type(&schema).map_err(io)?);
    let props = Arc::new(
        WriterProperties::builder().set_compression(Compression::ZSTD(ZstdLevel::try_new(3).map_err(io)?)).build(),
    );
    let mut w = SerializedFileWriter::new(out, schema, props).map_err(io)?;
    const GROUP: usize = 1 << 20;
    let mut start = 0;
    while start < time.len() || (start == 0 && time.is_empty()) {
        let end = (start + GROUP).min(time.len());
        let mut g = w.next_row_group().map_err(io)?;
        if let Some(mut c) = g.next_column().map_err(io)? {
            c.typed::<Int64Type>().write_batch(&time[start..end], None, None).map_err(io)?;
            c.close().map_err(io)?;
        }
        for col in columns {
            if let Some(mut c) = g.next_column().map_err(io)? {
                c.typed::<DoubleType>().write_batch(&col[start..end], None, None).map_err(io)?;
                c.close().map_err(io)?;
            }
        }
        g.close().map_err(io)?;
        if end == time.len() {
            break;
        }
        start = end;
    }
    w.close().map_err(io)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_written_table_reads_back_with_units_from_its_names() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("imu.parquet");
        let t: Vec<i64> = (0..1000).map(|i| 1_700_000_000_000_000_000 + i * 5_000_000).collect();
        let g: Vec<f64> = (0..1000).map(|i| (i as f64 * 0.37).sin() * 1e-3).collect();
        let a: Vec<f64> = (0..1000).map(|i| 9.81 + (i as f64 * 0.11).cos() * 1e-2).collect();
        let names = vec!["gyro_x_rad_s".to_string(), "accel_z_m_s2".to_string()];
        crate::atomic::write_atomic_with(&p, |w| write_parquet(w, "timestamp_ns", &t, &names, &[&g, &a])).unwrap();
        let s = read_parquet(&p, &SeriesOptions::default()).unwrap();
        assert_eq!(s.channels, vec![g, a]);
        let time = s.time.unwrap();
        assert!((time[1] - time[0] - 0.005).abs() < 1e-6, "{}", time[1] - time[0]);
        assert_eq!(s.header.channels[0].unit, gyrolab::units::OutputUnit::RadPerSec);
        assert_eq!(s.header.rows, RowKind::Row);
    }

    #[test]
    fn a_file_that_is_not_parquet_is_an_error_not_a_panic() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("bad.parquet");
        std::fs::write(&p, b"PAR1 this is not a parquet file PAR1").unwrap();
        let e = read_parquet(&p, &SeriesOptions::default()).unwrap_err().to_string();
        assert!(e.contains("not a readable Parquet file"), "{e}");
    }
}
