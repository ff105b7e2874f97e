//! Reading a whole file in parallel by byte ranges: the parallel path of
//! [`super::read_series_all`] for regular files.
//!
//! The data bytes after the header are cut into one range per thread; a line belongs to the
//! range that holds its first byte. The file is opened once; each thread reads its range by position in chunks into
//! its own buffer, parses them with the same row parser as [`SeriesReader::next_block`] and
//! copies the values, still in cache, into its region of each column. A column is one
//! allocation for the whole file, sized from the bytes per line of the header's chunk with a
//! tenth to spare; it is allocated zeroed, so its pages cost memory only once written (not on
//! huge pages: their first fault may wait for the kernel to compact memory, measured here at
//! 0.2 s for 88 MB, against 0.03 s for ordinary pages). The
//! regions are then closed up in order (one move of each later range's rows), and the time
//! stamps, line maps and findings of the ranges are joined, their lines shifted by the lines
//! before. The values, lines, findings and errors are those of the sequential reader; the
//! first error in file order is returned. A range whose rows outrun its region keeps the rest
//! apart, and the columns are then built by concatenation (more memory, same values).

use super::*;
use rayon::prelude::*;

/// Bytes a range's thread reads at once (its buffer stays in the core's cache).
pub const RANGE_CHUNK_BYTES: usize = 512 << 10;

/// Spare rows of each range's region beyond its estimate.
const SPARE_ROWS: usize = 4096;

/// What one range's thread read.
struct RangeOutput {
    /// Rows written into the range's regions.
    in_region: usize,
    /// Per slot (empty for the compact time slot), the rows past the region.
    overflow: Vec<Vec<f64>>,
    /// Lines of the range (blank and comment lines too), for the line numbers of the next.
    lines_read: u64,
    /// Each row's line, counted from the range's first line (1).
    lines: LineMap,
    /// The time stamps, when kept compactly.
    stamps: Option<CompactStamps>,
    /// Findings, with lines counted from the range's first line.
    quality: ReaderQuality,
}

/// Why a range stopped, with lines counted from the range's first line (shifted to the file's
/// lines by the caller).
enum RangeFailure {
    /// An error located at a line of the range.
    Data(DataError),
    /// A line longer than [`MAX_LINE_BYTES`] (its message names the line, so it is made once
    /// the line is known).
    LongLine(u64),
}

impl From<DataError> for RangeFailure {
    fn from(e: DataError) -> Self {
        RangeFailure::Data(e)
    }
}

/// One range of the file: its bytes, whether it starts at a line start (the first range), and
/// its region of each slot (`None` for the compact time slot).
struct Range<'a> {
    start: u64,
    end: u64,
    at_line_start: bool,
    regions: Vec<Option<&'a mut [f64]>>,
}

/// Reads a whole file in `ranges` parallel ranges of chunks of `chunk_bytes` (the parallel
/// path of [`read_series_all`], exposed to test it against [`collect_series`] on any input).
pub fn read_series_in_ranges(
    path: impl AsRef<Path>,
    options: &SeriesOptions,
    ranges: usize,
    chunk_bytes: usize,
) -> Result<SeriesData, DataError> {
    let path = path.as_ref();
    let (file, size) = crate::input_file::open_regular(path)?;
    let shared = file.try_clone().map_err(|e| DataError::io(path, &e))?;
    let r = SeriesReader::from_reader(path, Box::new(file) as Source, options)?;
    collect_series_ranges(r, &shared, size, ranges.max(1), chunk_bytes.max(64))
}

/// A reader of one byte range of a file shared by the threads: positional reads, which leave
/// the file's offset alone (the file is opened once for all ranges).
struct RangeReader<'a> {
    file: &'a File,
    pos: u64,
}

impl Read for RangeReader<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        #[cfg(unix)]
        let n = std::os::unix::fs::FileExt::read_at(self.file, buf, self.pos)?;
        #[cfg(windows)]
        let n = std::os::windows::fs::FileExt::seek_read(self.file, buf, self.pos)?;
        self.pos += n as u64;
        Ok(n)
    }
}

/// Reads every row of `r` (reading the regular file `file` of `size` bytes, its header read)
/// in `ranges` parallel byte ranges, each read from `file` by position.
pub(super) fn collect_series_ranges(
    r: SeriesReader<Source>,
    file: &File,
    size: u64,
    ranges: usize,
    chunk_bytes: usize,
) -> Result<SeriesData, DataError> {
    if r.eof || r.dropouts.as_ref().is_some_and(|m| m.verdict().repeated) {
        // The whole file is in the buffer already; or repeated rows compare each row with the
        // one before, across ranges: read in order.
        return collect_series(r);
    }
    let header = r.header.clone();
    let nch = header.channels.len();
    let nslots = r.cols.len();
    let compact_slot = if r.compact_time { r.time_slot } else { None };
    // The file offset of the first data byte, and the bytes per line of the chunk in hand.
    let data_start = r.consumed - (r.filled - r.pos) as u64;
    let data_bytes = size.saturating_sub(data_start);
    let sample = &r.buf[r.pos..r.complete];
    let sample_lines = memchr::memchr_iter(b'\n', sample).count().max(1);
    let per_line = (sample.len() as f64 / sample_lines as f64).max(2.0);
    let bounds: Vec<u64> =
        (0..=ranges).map(|k| data_start + (u128::from(data_bytes) * k as u128 / ranges as u128) as u64).collect();
    let caps: Vec<usize> = bounds
        .windows(2)
        .map(|w| (((w[1] - w[0]) as f64 / per_line * 1.1) as usize + SPARE_ROWS).min(MAX_RESERVE_ROWS))
        .collect();
    let total_cap: usize = caps.iter().sum();
    // One zeroed allocation per slot: pages are mapped as the ranges write them.
    let mut columns: Vec<Vec<f64>> =
        (0..nslots).map(|s| if Some(s) == compact_slot { Vec::new() } else { vec![0.0; total_cap] }).collect();
    let outputs: Vec<Result<RangeOutput, RangeFailure>> = {
        let mut per_range: Vec<Vec<Option<&mut [f64]>>> = (0..ranges).map(|_| Vec::with_capacity(nslots)).collect();
        for (s, col) in columns.iter_mut().enumerate() {
            let mut rest: &mut [f64] = col;
            for (k, cap) in caps.iter().enumerate() {
                if Some(s) == compact_slot {
                    per_range[k].push(None);
                } else {
                    let (mine, after) = std::mem::take(&mut rest).split_at_mut(*cap);
                    per_range[k].push(Some(mine));
                    rest = after;
                }
            }
        }
        let jobs: Vec<(Range<'_>, SeriesReader<std::io::Empty>)> = per_range
            .into_iter()
            .enumerate()
            .map(|(k, regions)| {
                let range = Range { start: bounds[k], end: bounds[k + 1], at_line_start: k == 0, regions };
                let parser = r.piece_parser(Vec::new(), 0, usize::MAX, vec![Vec::new(); nslots], Vec::new());
                (range, parser)
            })
            .collect();
        jobs.into_par_iter().map(|(range, parser)| read_range(file, parser, range, compact_slot, chunk_bytes)).collect()
    };
    // In file order: the first error, else each range's lines, findings and stamps joined.
    let mut base = r.line_no;
    let mut lines = LineMap::default();
    let mut quality = ReaderQuality::default();
    let mut stamps = compact_slot.map(|_| CompactStamps::default());
    let mut done = Vec::with_capacity(ranges);
    for out in outputs {
        let mut out = out.map_err(|f| match f {
            RangeFailure::Data(mut e) => {
                e.line = e.line.map(|l| l + base);
                e
            }
            RangeFailure::LongLine(l) => crate::text::long_line(&header.file, l + base),
        })?;
        lines.append(&out.lines, base);
        quality.append(std::mem::take(&mut out.quality), base);
        if let (Some(all), Some(part)) = (stamps.as_mut(), out.stamps.take()) {
            all.append(part);
        }
        base += out.lines_read;
        done.push(out);
    }
    if lines.is_empty() {
        return Err(no_data_rows(&header));
    }
    check_row_limit(&header, &lines, r.max_rows)?;
    // Close up the regions (each range's rows move down to follow the ranges before), the
    // columns in parallel. (The stamps are joined before, not meanwhile: the moves and the
    // join's growing codes at once raised the 10 M-line case's peak by 6 MB, for no time.)
    let offsets: Vec<usize> = caps.iter().scan(0usize, |at, c| Some(std::mem::replace(at, *at + c))).collect();
    let spilled = done.iter().any(|o| o.overflow.iter().any(|v| !v.is_empty()));
    let close_up = |(s, col): (usize, &mut Vec<f64>)| {
        if Some(s) == compact_slot {
            return;
        }
        if spilled {
            let mut joined = Vec::with_capacity(lines.len());
            for (o, &at) in done.iter().zip(&offsets) {
                joined.extend_from_slice(&col[at..at + o.in_region]);
                joined.extend_from_slice(&o.overflow[s]);
            }
            *col = joined;
        } else {
            let mut to = 0;
            for (o, &at) in done.iter().zip(&offsets) {
                col.copy_within(at..at + o.in_region, to);
                to += o.in_region;
            }
            col.truncate(to);
            col.shrink_to_fit();
        }
    };
    columns.par_iter_mut().enumerate().for_each(close_up);
    let mut it = columns.into_iter();
    let channels: Vec<Vec<f64>> = it.by_ref().take(nch).collect();
    let mut slot = |used: bool| if used { it.next() } else { None };
    let time = slot(header.time_column.is_some()).filter(|_| stamps.is_none());
    let temperature = slot(header.temperature_column.is_some());
    let table_rate = slot(header.table_rate_column.is_some());
    Ok(SeriesData { header, lines, time, time_compact: stamps, temperature, table_rate, channels, quality })
}

/// Reads one range: its lines (those whose first byte is in `start..end`) in chunks, parsed by
/// `parser` and copied into the range's regions. Errors name lines counted from the range's
/// first line.
fn read_range(
    source: &File,
    mut parser: SeriesReader<std::io::Empty>,
    mut range: Range<'_>,
    compact_slot: Option<usize>,
    chunk_bytes: usize,
) -> Result<RangeOutput, RangeFailure> {
    let file = parser.header.file.clone();
    let io = |e: std::io::Error| DataError::io(&file, &e);
    let nslots = range.regions.len();
    let mut out = RangeOutput {
        in_region: 0,
        overflow: vec![Vec::new(); nslots],
        lines_read: 0,
        lines: LineMap::default(),
        stamps: compact_slot.map(|_| CompactStamps::default()),
        quality: ReaderQuality::default(),
    };
    // A range after the first starts one byte early: its first line starts after the first
    // line end from there.
    let from = if range.at_line_start { range.start } else { range.start - 1 };
    let mut f = RangeReader { file: source, pos: from };
    let mut buf = vec![0u8; chunk_bytes.min(MAX_LINE_BYTES)];
    let (mut filled, mut pos, mut buf_at) = (0usize, 0usize, from);
    let mut started = range.at_line_start;
    let mut eof = false;
    let room = range.regions.iter().flatten().map(|r| r.len()).next().unwrap_or(usize::MAX);
    loop {
        while !eof && filled < buf.len() {
            match f.read(&mut buf[filled..]) {
                Ok(0) => eof = true,
                Ok(n) => filled += n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => return Err(io(e).into()),
            }
        }
        if !started {
            match memchr::memchr(b'\n', &buf[..filled]) {
                Some(i) => {
                    pos = i + 1;
                    started = true;
                }
                None if eof => break,
                None => {
                    // Still inside the previous range's last line.
                    buf_at += filled as u64;
                    filled = 0;
                    continue;
                }
            }
        }
        // Complete lines from `pos` that start before the range's end.
        let limit = usize::try_from(range.end.saturating_sub(buf_at)).unwrap_or(usize::MAX);
        let whole_lines = |buf: &[u8]| memchr::memrchr(b'\n', &buf[pos..filled]).map_or(pos, |i| pos + i + 1);
        // The range's last line ends at the first line end at or after its last byte.
        let last_end = (pos < limit && limit <= filled)
            .then(|| memchr::memchr(b'\n', &buf[limit - 1..filled]).map(|i| limit + i))
            .flatten();
        let (cut, done) = match last_end {
            _ if limit <= pos => (pos, true),
            Some(end) => (end, true),
            None if eof => (filled, true),
            None => (whole_lines(&buf), false),
        };
        // A last line without its line end gets one, as the sequential reader gives it.
        let cut = if done && cut == filled && cut > pos && buf[cut - 1] != b'\n' {
            if filled == buf.len() {
                buf.push(b'\n');
            } else {
                buf[filled] = b'\n';
            }
            filled += 1;
            filled
        } else {
            cut
        };
        if cut > pos {
            if let Some(i) = memchr::memchr(0, &buf[pos..cut]) {
                let line = out.lines_read + memchr::memchr_iter(b'\n', &buf[pos..pos + i]).count() as u64 + 1;
                return Err(DataError::new(&file, "binary data (a NUL byte): expected a text file of numbers")
                    .at_line(line)
                    .into());
            }
            buf = parse_chunk(&mut parser, buf, pos, cut, &mut out, &mut range, compact_slot, room)?;
            pos = cut;
        }
        if done {
            break;
        }
        // Keep the unfinished line; a line longer than the buffer grows it, up to the limit.
        if pos > 0 {
            buf.copy_within(pos..filled, 0);
            filled -= pos;
            buf_at += pos as u64;
            pos = 0;
        } else if filled == buf.len() {
            if buf.len() > MAX_LINE_BYTES {
                return Err(RangeFailure::LongLine(out.lines_read + 1));
            }
            buf.resize((buf.len() * 2).min(MAX_LINE_BYTES + 1), 0);
        }
    }
    out.quality = std::mem::take(&mut parser.quality);
    Ok(out)
}

/// Parses `buf[pos..cut]` (whole lines) with `parser` and moves its rows into the range's
/// regions (or its overflow), stamps and line map; gives the buffer back.
#[allow(clippy::too_many_arguments)]
fn parse_chunk(
    parser: &mut SeriesReader<std::io::Empty>,
    buf: Vec<u8>,
    pos: usize,
    cut: usize,
    out: &mut RangeOutput,
    range: &mut Range<'_>,
    compact_slot: Option<usize>,
    room: usize,
) -> Result<Vec<u8>, DataError> {
    parser.buf = buf;
    parser.pos = pos;
    parser.filled = cut;
    parser.complete = cut;
    parser.eof = true;
    parser.line_no = out.lines_read;
    let parsed = parser.next_block().map(|b| b.is_some());
    out.lines_read = parser.line_no;
    let buf = std::mem::take(&mut parser.buf);
    if !parsed? {
        return Ok(buf);
    }
    let rows = parser.lines.len();
    out.lines.extend_from_slice(&parser.lines);
    let take = rows.min(room - out.in_region);
    for (s, col) in parser.cols.iter().enumerate() {
        if Some(s) == compact_slot {
            if let Some(st) = out.stamps.as_mut() {
                st.extend_from_slice(col);
            }
        } else if let Some(region) = range.regions[s].as_deref_mut() {
            region[out.in_region..out.in_region + take].copy_from_slice(&col[..take]);
            out.overflow[s].extend_from_slice(&col[take..]);
        }
    }
    out.in_region += take;
    Ok(buf)
}
