//! Parquet tables (the `parquet` crate, without Arrow): numeric columns read as a time series
//! by the header rules of a delimited file (units from the column names, as for CSV), and IMU
//! channels written for other tools (`gyrolab convert --out imu.parquet`).

use crate::error::DataError;
use crate::series::{series_from_columns, RowKind, SeriesData, SeriesOptions, SkipReason, SkippedColumn};
use parquet::basic::{Compression, Type as PhysicalType, ZstdLevel};
use parquet::column::reader::ColumnReader;
use parquet::data_type::{DoubleType, Int64Type};
use parquet::file::properties::WriterProperties;
use parquet::file::reader::{ChunkReader, FileReader, Length, SerializedFileReader};
use parquet::file::writer::SerializedFileWriter;
use std::path::Path;
use std::sync::Arc;

/// Rows read from a column at once.
const BATCH: usize = 64 * 1024;

/// A `parquet` crate error in words: without the crate's variant names (`External: `,
/// `Parquet error: `, `EOF: `).
fn perr(path: &Path, e: impl std::fmt::Display) -> DataError {
    let text = e.to_string();
    let mut t = text.as_str();
    for prefix in ["External: ", "Parquet error: ", "EOF: ", "General: ", "NYI: ", "Index out of bound: "] {
        t = t.strip_prefix(prefix).unwrap_or(t);
    }
    DataError::new(path, format!("not a readable Parquet file: {}", crate::text::short_message(t)))
}

/// Reads the numeric columns (INT32, INT64, FLOAT, DOUBLE; nulls as missing cells) of a
/// Parquet file as a time series; other columns are skipped with a note.
pub fn read_parquet(path: &Path, options: &SeriesOptions) -> Result<SeriesData, DataError> {
    let (file, _, _) = crate::sniff::open_sniffed(path)?;
    read_parquet_file(path, file, options)
}

/// [`read_parquet`] of a file already opened (once, by [`crate::sniff::open_sniffed`]).
/// The footer's schema is checked first (`check_footer`): the `parquet` crate reserves room
/// for a group's declared children before reading them.
pub fn read_parquet_file(
    path: &Path,
    mut file: std::fs::File,
    options: &SeriesOptions,
) -> Result<SeriesData, DataError> {
    check_footer(path, &mut file)?;
    // The `parquet` crate panics on some damaged pages (a dictionary-encoded page without its
    // dictionary, found by fuzzing): contained, as a message in words.
    crate::contained::contain(|| read_checked_parquet(path, file, options)).unwrap_or_else(|panic| {
        Err(DataError::new(path, format!("not a readable Parquet file: the Parquet reader failed on it ({panic})")))
    })
}

/// [`read_parquet_file`] after its footer is checked.
fn read_checked_parquet(path: &Path, file: std::fs::File, options: &SeriesOptions) -> Result<SeriesData, DataError> {
    let len = file.metadata().map_err(|e| DataError::io(path, &e))?.len();
    let reader = SerializedFileReader::new(BoundedFile { file, len }).map_err(|e| perr(path, e))?;
    let meta = reader.metadata();
    let schema = meta.file_metadata().schema_descr();
    let rows = meta.file_metadata().num_rows().max(0) as u64;
    let limit = options.max_rows.unwrap_or(crate::raw_log::MAX_RAW_LOG_ROWS);
    if rows > limit {
        return Err(DataError::new(path, format!("{rows} rows: more than the {limit} this reader accepts")));
    }
    let (names, leaves, skipped) = numeric_columns(&reader);
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

/// The numeric columns of a Parquet file (named and chosen as [`read_parquet`] does) and its
/// rows, from its footer alone.
#[derive(Debug, Clone, PartialEq)]
pub struct ParquetLayout {
    /// Rows in the file.
    pub rows: u64,
    /// Names of the numeric columns, in file order.
    pub names: Vec<String>,
    /// The other columns, skipped.
    pub skipped: Vec<SkippedColumn>,
}

/// Reads a Parquet file's layout ([`ParquetLayout`]) from its footer, the file opened once.
pub fn parquet_layout(path: &Path, mut file: std::fs::File) -> Result<ParquetLayout, DataError> {
    check_footer(path, &mut file)?;
    crate::contained::contain(|| {
        let len = file.metadata().map_err(|e| DataError::io(path, &e))?.len();
        let reader = SerializedFileReader::new(BoundedFile { file, len }).map_err(|e| perr(path, e))?;
        let (names, _, skipped) = numeric_columns(&reader);
        let rows = reader.metadata().file_metadata().num_rows().max(0) as u64;
        Ok(ParquetLayout { rows, names, skipped })
    })
    .unwrap_or_else(|panic| {
        Err(DataError::new(path, format!("not a readable Parquet file: the Parquet reader failed on it ({panic})")))
    })
}

/// The numeric leaf columns (INT32, INT64, FLOAT, DOUBLE, not repeated): names, leaf indices,
/// and the other columns as skipped.
fn numeric_columns<R: ChunkReader + 'static>(
    reader: &SerializedFileReader<R>,
) -> (Vec<String>, Vec<usize>, Vec<SkippedColumn>) {
    let schema = reader.metadata().file_metadata().schema_descr();
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
    (names, leaves, skipped)
}

/// The numeric columns of a Parquet file handed to `sink` in blocks of at most `block_rows`
/// rows, in file order (row group by row group, every column read `block_rows` records at a
/// time; nulls as NaN): memory bounded by the block whatever the file's length, and no limit on
/// its rows. `sink` gets the columns in the order of [`ParquetLayout::names`].
pub fn stream_parquet_file(
    path: &Path,
    mut file: std::fs::File,
    block_rows: usize,
    sink: &mut dyn FnMut(Vec<Vec<f64>>) -> Result<(), DataError>,
) -> Result<(), DataError> {
    check_footer(path, &mut file)?;
    crate::contained::contain(|| stream_checked_parquet(path, file, block_rows.max(1), sink)).unwrap_or_else(|panic| {
        Err(DataError::new(path, format!("not a readable Parquet file: the Parquet reader failed on it ({panic})")))
    })
}

/// [`stream_parquet_file`] after its footer is checked.
fn stream_checked_parquet(
    path: &Path,
    file: std::fs::File,
    block_rows: usize,
    sink: &mut dyn FnMut(Vec<Vec<f64>>) -> Result<(), DataError>,
) -> Result<(), DataError> {
    let len = file.metadata().map_err(|e| DataError::io(path, &e))?.len();
    let reader = SerializedFileReader::new(BoundedFile { file, len }).map_err(|e| perr(path, e))?;
    let (_, leaves, _) = numeric_columns(&reader);
    let schema = reader.metadata().file_metadata().schema_descr_ptr();
    for g in 0..reader.num_row_groups() {
        let group = reader.get_row_group(g).map_err(|e| perr(path, e))?;
        let mut readers = leaves
            .iter()
            .map(|&leaf| group.get_column_reader(leaf).map(|r| (r, schema.column(leaf).max_def_level())))
            .collect::<parquet::errors::Result<Vec<_>>>()
            .map_err(|e| perr(path, e))?;
        loop {
            let mut block: Vec<Vec<f64>> = Vec::with_capacity(readers.len());
            for (r, max_def) in &mut readers {
                let mut out = Vec::with_capacity(block_rows);
                while out.len() < block_rows {
                    let got = read_some(r, *max_def, block_rows - out.len(), &mut out).map_err(|e| perr(path, e))?;
                    if got == 0 {
                        break;
                    }
                }
                block.push(out);
            }
            let n = block.first().map_or(0, Vec::len);
            if block.iter().any(|c| c.len() != n) {
                return Err(DataError::new(
                    path,
                    format!("not a readable Parquet file: the columns of row group {} differ in length", g + 1),
                ));
            }
            if n == 0 {
                break;
            }
            sink(block)?;
        }
    }
    Ok(())
}

/// Reads up to `n` records of a column into `out` (nulls as NaN); the records read.
fn read_some(col: &mut ColumnReader, max_def: i16, n: usize, out: &mut Vec<f64>) -> parquet::errors::Result<usize> {
    macro_rules! some {
        ($r:expr, $conv:expr) => {{
            let mut values = Vec::new();
            let mut defs = Vec::new();
            let (records, _, _) =
                $r.read_records(n, if max_def > 0 { Some(&mut defs) } else { None }, None, &mut values)?;
            if max_def > 0 {
                let mut it = values.iter();
                for &d in &defs {
                    out.push(if d == max_def { it.next().map_or(f64::NAN, $conv) } else { f64::NAN });
                }
            } else {
                out.extend(values.iter().map($conv));
            }
            records
        }};
    }
    Ok(match col {
        ColumnReader::Int32ColumnReader(r) => some!(r, |v: &i32| f64::from(*v)),
        ColumnReader::Int64ColumnReader(r) => some!(r, |v: &i64| *v as f64),
        ColumnReader::FloatColumnReader(r) => some!(r, |v: &f32| f64::from(*v)),
        ColumnReader::DoubleColumnReader(r) => some!(r, |v: &f64| *v),
        _ => 0,
    })
}

/// The file as the `parquet` crate reads it, bounded by its length. The crate's own reader of a
/// `File` reserves a byte range's declared length before reading it, and returns nothing (not
/// an error) past the end of the file, so a damaged page header whose Thrift list declares
/// 2^31 elements was skipped element by element with a read each (over 20 s, found by fuzzing).
/// Here a range beyond the file is an error before any allocation, and reading at the end of
/// the file is an error.
struct BoundedFile {
    file: std::fs::File,
    len: u64,
}

impl Length for BoundedFile {
    fn len(&self) -> u64 {
        self.len
    }
}

impl ChunkReader for BoundedFile {
    type T = EndIsError<std::io::BufReader<std::fs::File>>;

    fn get_read(&self, start: u64) -> parquet::errors::Result<Self::T> {
        use std::io::{Seek, SeekFrom};
        if start > self.len {
            return Err(beyond_end(start, 0, self.len));
        }
        let mut f = self.file.try_clone()?;
        f.seek(SeekFrom::Start(start))?;
        Ok(EndIsError { inner: std::io::BufReader::new(f), left: self.len - start })
    }

    fn get_bytes(&self, start: u64, length: usize) -> parquet::errors::Result<bytes::Bytes> {
        use std::io::{Read, Seek, SeekFrom};
        if start.checked_add(length as u64).is_none_or(|end| end > self.len) {
            return Err(beyond_end(start, length, self.len));
        }
        let mut f = self.file.try_clone()?;
        f.seek(SeekFrom::Start(start))?;
        let mut buf = vec![0u8; length];
        f.read_exact(&mut buf)?;
        Ok(buf.into())
    }
}

fn beyond_end(start: u64, length: usize, len: u64) -> parquet::errors::ParquetError {
    parquet::errors::ParquetError::EOF(format!(
        "{length} bytes at byte {start} declared, beyond the end of the file ({len} bytes)"
    ))
}

/// A reader of the rest of a file (`left` bytes) for which reading at its end is an error.
struct EndIsError<R> {
    inner: R,
    left: u64,
}

impl<R: std::io::Read> std::io::Read for EndIsError<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        if buf.is_empty() {
            return Ok(0);
        }
        let want = buf.len().min(usize::try_from(self.left).unwrap_or(usize::MAX));
        let n = if want == 0 { 0 } else { self.inner.read(&mut buf[..want])? };
        if n == 0 {
            return Err(std::io::Error::new(std::io::ErrorKind::UnexpectedEof, "the file ends here"));
        }
        self.left -= n as u64;
        Ok(n)
    }
}

/// Longest footer (file metadata) read, bytes: 64 MiB.
pub const MAX_FOOTER_BYTES: u64 = 64 << 20;

/// Checks a Parquet footer before the `parquet` crate reads it: its length against the file
/// and [`MAX_FOOTER_BYTES`], and in its schema (Thrift compact protocol, parquet-format's
/// `FileMetaData` field 2, a list of `SchemaElement`, field 5 `num_children`) every group's
/// count of children against the elements that follow it. The crate reserves a vector of the
/// declared count first (2^30 children: 8 GiB) — refused here.
fn check_footer(path: &Path, file: &mut std::fs::File) -> Result<(), DataError> {
    use std::io::{Read, Seek, SeekFrom};
    let size = file.metadata().map_err(|e| DataError::io(path, &e))?.len();
    let bad = |what: String| DataError::new(path, format!("not a readable Parquet file: {what}"));
    if size < 12 {
        return Err(bad(format!("{size} bytes, too short for a Parquet file")));
    }
    let mut tail = [0u8; 8];
    file.seek(SeekFrom::End(-8)).map_err(|e| DataError::io(path, &e))?;
    file.read_exact(&mut tail).map_err(|e| DataError::io(path, &e))?;
    if &tail[4..] != b"PAR1" {
        return Err(bad("the file does not end with the PAR1 magic (cut off?)".into()));
    }
    let len = u64::from(u32::from_le_bytes([tail[0], tail[1], tail[2], tail[3]]));
    if len + 12 > size || len > MAX_FOOTER_BYTES {
        return Err(bad(format!(
            "the footer declares {len} bytes, more than the file's {size} bytes or the {MAX_FOOTER_BYTES} accepted"
        )));
    }
    let mut footer = Vec::new();
    file.seek(SeekFrom::Start(size - 8 - len)).map_err(|e| DataError::io(path, &e))?;
    file.by_ref().take(len).read_to_end(&mut footer).map_err(|e| DataError::io(path, &e))?;
    file.seek(SeekFrom::Start(0)).map_err(|e| DataError::io(path, &e))?;
    let at = size - 8 - len;
    let counts =
        thrift::schema_children(&footer).map_err(|why| bad(format!("the footer at byte {at} is damaged: {why}")))?;
    // The elements are the schema tree in pre-order: each takes one open slot and opens as
    // many as its declared children, which must fit in the elements that follow.
    let mut open: u64 = 1;
    for (i, c) in counts.iter().enumerate() {
        if open == 0 {
            return Err(bad(format!("the footer at byte {at}: schema element {} belongs to no group", i + 1)));
        }
        open -= 1;
        let n = match c {
            Some(n) if *n < 0 => {
                return Err(bad(format!("the footer at byte {at}: schema element {} declares {n} children", i + 1)))
            }
            Some(n) => *n as u64,
            None => 0,
        };
        let left = (counts.len() - i - 1) as u64;
        if open + n > left {
            return Err(bad(format!(
                "the footer at byte {at}: schema element {} declares {n} children, but only {left} elements follow",
                i + 1
            )));
        }
        open += n;
    }
    Ok(())
}

/// Just enough of the Thrift compact protocol to read the schema's children counts.
mod thrift {
    /// Deepest nesting of structs and lists walked.
    const MAX_DEPTH: u32 = 64;

    struct Cursor<'a> {
        b: &'a [u8],
    }

    impl Cursor<'_> {
        fn byte(&mut self) -> Result<u8, String> {
            let (&x, rest) = self.b.split_first().ok_or("it ends early")?;
            self.b = rest;
            Ok(x)
        }
        fn varint(&mut self) -> Result<u64, String> {
            let mut v = 0u64;
            for shift in (0..70).step_by(7) {
                let x = self.byte()?;
                if shift == 63 && x > 1 {
                    return Err("a number longer than 64 bits".into());
                }
                v |= u64::from(x & 0x7f) << shift;
                if x & 0x80 == 0 {
                    return Ok(v);
                }
            }
            Err("a number longer than 64 bits".into())
        }
        fn zigzag(&mut self) -> Result<i64, String> {
            let v = self.varint()?;
            Ok((v >> 1) as i64 ^ -((v & 1) as i64))
        }
        fn skip(&mut self, n: u64) -> Result<(), String> {
            if n > self.b.len() as u64 {
                return Err(format!("a field of {n} bytes where {} are left", self.b.len()));
            }
            self.b = &self.b[n as usize..];
            Ok(())
        }
        /// A list header: (element type, count), the count checked against the bytes left
        /// (every element takes at least one byte, except booleans packed in the header).
        fn list(&mut self) -> Result<(u8, u64), String> {
            let h = self.byte()?;
            let n = if h >> 4 == 15 { self.varint()? } else { u64::from(h >> 4) };
            if n > self.b.len() as u64 {
                return Err(format!("a list of {n} elements in {} bytes", self.b.len()));
            }
            Ok((h & 0x0f, n))
        }
        /// Skips a value of compact type `t`.
        fn skip_value(&mut self, t: u8, depth: u32) -> Result<(), String> {
            if depth > MAX_DEPTH {
                return Err("nested deeper than 64 levels".into());
            }
            match t {
                1 | 2 => Ok(()),
                3 => self.skip(1),
                4..=6 => self.varint().map(drop),
                7 => self.skip(8),
                8 => {
                    let n = self.varint()?;
                    self.skip(n)
                }
                9 | 10 => {
                    let (et, n) = self.list()?;
                    for _ in 0..n {
                        self.skip_value(et, depth + 1)?;
                    }
                    Ok(())
                }
                11 => {
                    let n = self.varint()?;
                    if n == 0 {
                        return Ok(());
                    }
                    let kv = self.byte()?;
                    if n > self.b.len() as u64 {
                        return Err(format!("a map of {n} entries in {} bytes", self.b.len()));
                    }
                    for _ in 0..n {
                        self.skip_value(kv >> 4, depth + 1)?;
                        self.skip_value(kv & 0x0f, depth + 1)?;
                    }
                    Ok(())
                }
                12 => self.walk_struct(depth + 1, &mut |_, _, _| Ok(false)),
                _ => Err(format!("an unknown Thrift type {t}")),
            }
        }
        /// Walks a struct's fields; `on(cursor, id, type)` reads a field itself (returns true)
        /// or leaves it to be skipped (false).
        fn walk_struct(
            &mut self,
            depth: u32,
            on: &mut dyn FnMut(&mut Self, i16, u8) -> Result<bool, String>,
        ) -> Result<(), String> {
            if depth > MAX_DEPTH {
                return Err("nested deeper than 64 levels".into());
            }
            let mut id: i16 = 0;
            loop {
                let h = self.byte()?;
                if h == 0 {
                    return Ok(());
                }
                let t = h & 0x0f;
                let delta = h >> 4;
                id = if delta == 0 {
                    i16::try_from(self.zigzag()?).map_err(|_| "a field id out of range".to_string())?
                } else {
                    id.wrapping_add(i16::from(delta))
                };
                if !on(self, id, t)? {
                    self.skip_value(t, depth)?;
                }
            }
        }
    }

    /// The `num_children` of every element of the schema (field 2 of FileMetaData), in order.
    pub fn schema_children(footer: &[u8]) -> Result<Vec<Option<i64>>, String> {
        let mut c = Cursor { b: footer };
        let mut counts = Vec::new();
        let mut found = false;
        c.walk_struct(0, &mut |c, id, t| {
            if id != 2 || t != 9 {
                return Ok(false);
            }
            let (et, n) = c.list()?;
            if et != 12 {
                return Err("the schema is not a list of elements".into());
            }
            found = true;
            for _ in 0..n {
                let mut children = None;
                c.walk_struct(1, &mut |c, id, t| {
                    if id == 5 && t == 5 {
                        children = Some(c.zigzag()?);
                        return Ok(true);
                    }
                    Ok(false)
                })?;
                counts.push(children);
            }
            Ok(true)
        })?;
        if !found || counts.is_empty() {
            return Err("no schema".into());
        }
        Ok(counts)
    }
}

/// Appends a column's values as f64, nulls as NaN.
fn read_column(mut col: ColumnReader, max_def: i16, out: &mut Vec<f64>) -> parquet::errors::Result<()> {
    while read_some(&mut col, max_def, BATCH, out)? > 0 {}
    Ok(())
}

/// The values of one column of a table written by [`write_table`]; `None` is a null cell.
#[derive(Debug, Clone, PartialEq)]
pub enum ColumnValues {
    /// UTF-8 text.
    Text(Vec<Option<String>>),
    /// 64-bit floats.
    Double(Vec<Option<f64>>),
    /// 64-bit integers.
    Int(Vec<Option<i64>>),
}

impl ColumnValues {
    fn len(&self) -> usize {
        match self {
            ColumnValues::Text(v) => v.len(),
            ColumnValues::Double(v) => v.len(),
            ColumnValues::Int(v) => v.len(),
        }
    }
}

/// Writes a table of named, optional columns (UTF-8, DOUBLE or INT64; `None` as null) as a
/// Parquet file in one row group, zstd-compressed (`schema` names its message), for the
/// results tables of `batch` and the store's query exports. Columns of different lengths are
/// an error.
///
/// ```
/// use gyrolab_io::parquet_table::{write_table, ColumnValues};
/// let bytes = write_table(
///     "t",
///     &[("serial".into(), ColumnValues::Text(vec![Some("SN-1".into()), None])),
///       ("value".into(), ColumnValues::Double(vec![Some(0.5), Some(1.5)]))],
/// )?;
/// assert!(bytes.starts_with(b"PAR1") && bytes.ends_with(b"PAR1"));
/// # Ok::<(), std::io::Error>(())
/// ```
pub fn write_table(schema: &str, columns: &[(String, ColumnValues)]) -> std::io::Result<Vec<u8>> {
    use parquet::basic::{ConvertedType, Repetition, Type as Physical};
    use parquet::data_type::{ByteArray, ByteArrayType};
    use parquet::schema::types::Type;
    let err = |e: parquet::errors::ParquetError| std::io::Error::other(e.to_string());
    let rows = columns.first().map_or(0, |(_, c)| c.len());
    if let Some((name, c)) = columns.iter().find(|(_, c)| c.len() != rows) {
        return Err(std::io::Error::other(format!("column '{name}' has {} rows, the first {rows}", c.len())));
    }
    let mut fields = Vec::with_capacity(columns.len());
    for (name, values) in columns {
        let b = match values {
            ColumnValues::Text(_) => {
                Type::primitive_type_builder(name, Physical::BYTE_ARRAY).with_converted_type(ConvertedType::UTF8)
            }
            ColumnValues::Double(_) => Type::primitive_type_builder(name, Physical::DOUBLE),
            ColumnValues::Int(_) => Type::primitive_type_builder(name, Physical::INT64),
        };
        fields.push(Arc::new(b.with_repetition(Repetition::OPTIONAL).build().map_err(err)?));
    }
    let schema = Arc::new(Type::group_type_builder(schema).with_fields(fields).build().map_err(err)?);
    let level = ZstdLevel::try_new(3).map_err(err)?;
    let props = Arc::new(WriterProperties::builder().set_compression(Compression::ZSTD(level)).build());
    let mut bytes = Vec::new();
    {
        let mut w = SerializedFileWriter::new(&mut bytes, schema, props).map_err(err)?;
        let mut g = w.next_row_group().map_err(err)?;
        for (_, values) in columns {
            let Some(mut c) = g.next_column().map_err(err)? else { break };
            fn defs<T>(v: &[Option<T>]) -> Vec<i16> {
                v.iter().map(|x| i16::from(x.is_some())).collect()
            }
            match values {
                ColumnValues::Text(v) => {
                    let present: Vec<ByteArray> = v.iter().flatten().map(|t| ByteArray::from(t.as_str())).collect();
                    c.typed::<ByteArrayType>().write_batch(&present, Some(&defs(v)), None).map_err(err)?;
                }
                ColumnValues::Double(v) => {
                    let present: Vec<f64> = v.iter().flatten().copied().collect();
                    c.typed::<DoubleType>().write_batch(&present, Some(&defs(v)), None).map_err(err)?;
                }
                ColumnValues::Int(v) => {
                    let present: Vec<i64> = v.iter().flatten().copied().collect();
                    c.typed::<Int64Type>().write_batch(&present, Some(&defs(v)), None).map_err(err)?;
                }
            }
            c.close().map_err(err)?;
        }
        g.close().map_err(err)?;
        w.close().map_err(err)?;
    }
    Ok(bytes)
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
