//! Streaming a file in parallel batches: the reader of a record too large to hold, parsed on
//! every core (issue 37: the streamed Allan analysis within a memory ceiling).
//!
//! [`BatchReader`] reads `batch_bytes` of the source at a time (the last line completed, as
//! [`SeriesReader::next_block`] reads its chunks), splits them at line ends into one piece per
//! thread, parses the pieces at once with the same row parser as [`SeriesReader::next_block`]
//! (each piece's lines counted from the lines before it) and hands the batch's rows over in file
//! order, owned. The values, lines, findings and errors are those of the sequential reader:
//! when a piece fails, the rows of the pieces before it are handed over first and the error
//! (the first in file order) on the next call, as a sequential reader stops at the failing row.
//! Memory: one batch of bytes, its copy split among the pieces, and the rows of one batch.

use super::*;
use rayon::prelude::*;

/// The rows of one batch, owned (all columns have the same length).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SeriesBatch {
    /// Source line of each row.
    pub lines: Vec<u64>,
    /// Time stamps, seconds.
    pub time: Option<Vec<f64>>,
    /// Temperature, degC.
    pub temperature: Option<Vec<f64>>,
    /// Table rate, deg/s.
    pub table_rate: Option<Vec<f64>>,
    /// One column per output channel, in the order of [`SeriesHeader::channels`].
    pub channels: Vec<Vec<f64>>,
}

impl SeriesBatch {
    /// Rows in the batch.
    pub fn len(&self) -> usize {
        self.lines.len()
    }

    /// Whether the batch has no rows.
    pub fn is_empty(&self) -> bool {
        self.lines.is_empty()
    }
}

/// A reader handing over a file's rows in batches parsed on several threads (module docs).
pub struct BatchReader<R: Read> {
    reader: SeriesReader<R>,
    threads: usize,
    batch_bytes: usize,
    /// The error of a piece whose earlier pieces' rows were handed over first.
    pending: Option<DataError>,
    /// Spent: the end was reached or an error was returned.
    done: bool,
    /// The pieces' byte buffers, reused from batch to batch.
    pool: Vec<Vec<u8>>,
}

impl<R: Read> BatchReader<R> {
    /// A batch reader over `reader` (its header read, no block taken yet): batches of about
    /// `batch_bytes` (at least 16; the reader's chunk, [`SeriesOptions::chunk_bytes`], if
    /// larger, and longer when a line is), each parsed in `threads` pieces (at least 1). A reader
    /// marking repeated rows as dropouts compares each row with the one before: it is read
    /// sequentially, in blocks of the reader's size.
    pub fn new(mut reader: SeriesReader<R>, threads: usize, batch_bytes: usize) -> Self {
        let batch_bytes = batch_bytes.max(16).max(reader.buf.len());
        reader.buf.resize(batch_bytes, 0);
        let threads = threads.max(1);
        BatchReader { reader, threads, batch_bytes, pending: None, done: false, pool: vec![Vec::new(); threads] }
    }

    /// The header.
    pub fn header(&self) -> &SeriesHeader {
        &self.reader.header
    }

    /// NaN and empty cells passed on and dropout rows, so far.
    pub fn quality(&self) -> &ReaderQuality {
        &self.reader.quality
    }

    /// Data rows handed over so far.
    pub fn rows(&self) -> u64 {
        self.reader.rows
    }

    /// Bytes of each batch (of a batch ending inside a line: up to its end).
    pub fn batch_bytes(&self) -> usize {
        self.batch_bytes
    }

    /// The next batch of rows, or `None` at the end of the file. After an error the reader is
    /// spent.
    pub fn next_batch(&mut self) -> Result<Option<SeriesBatch>, DataError> {
        if let Some(e) = self.pending.take() {
            self.done = true;
            return Err(e);
        }
        if self.done {
            return Ok(None);
        }
        loop {
            let result = if self.reader.dropouts.as_ref().is_some_and(|m| m.verdict().repeated) {
                self.next_sequential()
            } else {
                self.next_parallel()
            };
            match result {
                // A batch of blank and comment lines only: on to the next.
                Ok(Some(b)) if b.is_empty() => {
                    if let Some(e) = self.pending.take() {
                        self.done = true;
                        return Err(e);
                    }
                }
                Ok(Some(b)) => return Ok(Some(b)),
                Ok(None) => {
                    self.done = true;
                    if self.reader.rows == 0 {
                        return Err(no_data_rows(&self.reader.header));
                    }
                    return Ok(None);
                }
                Err(e) => {
                    self.done = true;
                    return Err(e);
                }
            }
        }
    }

    /// One block of the sequential reader, copied.
    fn next_sequential(&mut self) -> Result<Option<SeriesBatch>, DataError> {
        Ok(self.reader.next_block()?.map(|b| SeriesBatch {
            lines: b.lines.to_vec(),
            time: b.time.map(<[f64]>::to_vec),
            temperature: b.temp.map(<[f64]>::to_vec),
            table_rate: b.table_rate.map(<[f64]>::to_vec),
            channels: b.channels.to_vec(),
        }))
    }

    /// One batch of bytes parsed in pieces on `threads` threads.
    fn next_parallel(&mut self) -> Result<Option<SeriesBatch>, DataError> {
        let r = &mut self.reader;
        if r.pos >= r.complete && !r.fill()? {
            return Ok(None);
        }
        let nslots = r.cols.len();
        let batch = &r.buf[r.pos..r.complete];
        // Split at line ends into one piece per thread; count the lines of each piece.
        let threads = self.threads;
        let bounds = super::line_bounds(batch, threads);
        let mut line_no = r.line_no;
        let mut parsers = Vec::with_capacity(threads);
        for (k, w) in bounds.windows(2).enumerate() {
            let piece = &batch[w[0]..w[1]];
            let count = memchr::memchr_iter(b'\n', piece).count();
            let mut buf = std::mem::take(&mut self.pool[k]);
            buf.clear();
            buf.extend_from_slice(piece);
            let cols = vec![Vec::with_capacity(count); nslots];
            parsers.push(r.piece_parser(buf, line_no, count, cols, Vec::with_capacity(count)));
            line_no += count as u64;
        }
        let pieces: Vec<Result<Piece, DataError>> = parsers.into_par_iter().map(parse_piece).collect();
        r.line_no = line_no;
        r.pos = r.complete;
        // In file order, up to the first failing piece.
        let mut out: Option<Piece> = None;
        for (k, p) in pieces.into_iter().enumerate() {
            let mut p = match p {
                Ok(p) => p,
                Err(e) => {
                    self.pending = Some(e);
                    break;
                }
            };
            r.rows += p.lines.len() as u64;
            r.quality.append(std::mem::take(&mut p.quality), 0);
            match out.as_mut() {
                None => {
                    self.pool[k] = std::mem::take(&mut p.buf);
                    out = Some(p);
                }
                Some(o) => {
                    o.lines.extend_from_slice(&p.lines);
                    for (a, b) in o.cols.iter_mut().zip(&p.cols) {
                        a.extend_from_slice(b);
                    }
                    self.pool[k] = p.buf;
                }
            }
        }
        if let Some(limit) = r.max_rows {
            if r.rows > limit {
                let lines = out.as_ref().map_or(&[][..], |o| &o.lines[..]);
                let over = lines.len().saturating_sub((r.rows - limit) as usize);
                let line = lines.get(over).copied().unwrap_or(r.line_no);
                self.pending = None;
                return Err(too_many_rows(&r.header, limit, line));
            }
        }
        let Some(piece) = out else {
            // The first piece failed: its error now.
            return self.pending.take().map_or(Ok(Some(SeriesBatch::default())), Err);
        };
        let header = &r.header;
        let nch = header.channels.len();
        let mut it = piece.cols.into_iter();
        let channels: Vec<Vec<f64>> = it.by_ref().take(nch).collect();
        let mut slot = |used: bool| if used { it.next() } else { None };
        let time = slot(header.time_column.is_some());
        let temperature = slot(header.temperature_column.is_some());
        let table_rate = slot(header.table_rate_column.is_some());
        Ok(Some(SeriesBatch { lines: piece.lines, time, temperature, table_rate, channels }))
    }
}
