//! Parquet tables analysed within a memory ceiling (issue 37; docs/METHODS.md section 3.2): a
//! table whose rows (from its footer) would not fit the ceiling in memory is read row group by
//! row group in blocks by [`gyrolab_io::parquet_table::stream_parquet_file`] into the streamed
//! OADEV of its channels; the rules of a streamed text file apply (octave OADEV only, complete
//! records only).

use super::{
    allan_options, conversions_of, finish_streamed, pushed_error, stillness_footprint, streaming_summary,
    ChannelStreams, StreamedRecord, StreamingSummary, MIN_MEMORY_BYTES,
};
use crate::allan::{refuse_motion, AllanOutcome, AllanRequest};
use crate::error::{EvalError, EvalResult};
use gyrolab::allan::streaming::StreamingPlan;
use gyrolab::allan::AllanError;
use gyrolab::dropout::DropoutTally;
use gyrolab::sampling::CompactStamps;
use gyrolab_io::parquet_table::ParquetLayout;
use gyrolab_io::series::{series_from_columns, LineMap, ReaderQuality, RowKind, SeriesHeader, SeriesOptions};
use gyrolab_io::DataError;

/// Rows handed over per block.
pub const BLOCK_ROWS: usize = 1 << 16;

/// Rows of the first block whose stamps give the stillness check's interval.
const START_ROWS: usize = 10_000;

/// The in-memory size of a table, bytes: 8 bytes a numeric column and row (the time column
/// included).
pub fn table_size(layout: &ParquetLayout) -> u64 {
    layout.rows.saturating_mul(8 * layout.names.len().max(1) as u64)
}

/// What the reader side keeps: the header (from the first block), the time column's index and
/// unit factor, the channels' columns, stamps, lines and dropout tally.
struct TableKeep {
    header: SeriesHeader,
    time: Option<(usize, f64)>,
    columns: Vec<usize>,
    stamps: CompactStamps,
    lines: LineMap,
    tally: DropoutTally,
}

/// Streams a Parquet table (`layout`: its rows and columns) through the estimators of its
/// channels within `memory_bytes`: the reader on this thread, the estimators on another
/// (channels in parallel).
pub fn analyse_parquet_streaming(
    request: &AllanRequest,
    memory_bytes: u64,
    estimate: u64,
    layout: &ParquetLayout,
) -> EvalResult<(AllanOutcome, StreamingSummary)> {
    let path = request.file.as_path();
    let reference = request.reference.resolve()?;
    let options = allan_options(request);
    let series_options = request.layout.apply(SeriesOptions {
        sample_rate_hz: request.sample_rate_hz,
        channels: if request.columns.is_empty() { None } else { Some(request.columns.clone()) },
        tolerant: true,
        ..SeriesOptions::default()
    })?;
    let rows = layout.rows;
    // Off the ceiling before the plan shares it among the channels (known from the first
    // block's header): the blocks in flight (one read, two queued, one taken), the stamps
    // (about a byte a row) and the stillness checks (at the interval of the table's start).
    let block_bytes = BLOCK_ROWS as u64 * 8 * layout.names.len() as u64;
    let plan_for = |channels: usize, tau0: Option<f64>| {
        let stillness = tau0.map_or(0, |t| stillness_footprint(rows, channels, t));
        let overhead = 4 * block_bytes + rows + stillness;
        let budget = memory_bytes.saturating_sub(overhead).max(MIN_MEMORY_BYTES / 2);
        StreamingPlan::for_memory(
            usize::try_from(rows).unwrap_or(usize::MAX),
            channels.max(1),
            usize::try_from(budget).unwrap_or(usize::MAX),
        )
    };
    let mut plan = plan_for(layout.names.len(), None);
    let mut keep: Option<TableKeep> = None;
    let mut failure: Option<EvalError> = None;
    let pushed = std::thread::scope(|scope| {
        let (tx, rx) = std::sync::mpsc::sync_channel::<Result<ChannelStreams, Vec<Vec<f64>>>>(2);
        let consumer = scope.spawn(move || -> Result<Option<ChannelStreams>, (usize, AllanError)> {
            let mut streams: Option<ChannelStreams> = None;
            for work in rx {
                match (work, streams.as_mut()) {
                    (Ok(s), _) => streams = Some(s),
                    (Err(mut block), Some(s)) => s.push(&mut block)?,
                    (Err(_), None) => {}
                }
            }
            Ok(streams)
        });
        let stopped = || DataError::new(path, "the streamed analysis stopped");
        let mut sink = |block: Vec<Vec<f64>>| -> Result<(), DataError> {
            if keep.is_none() {
                let data = series_from_columns(path, &layout.names, block.clone(), RowKind::Row, &series_options)?;
                let header = data.header;
                let time = header.time_column.map(|c| (c - 1, header.time_unit.map_or(1.0, |u| u.seconds())));
                let start = match request.sample_rate_hz {
                    Some(r) => Some(1.0 / r),
                    None => data.time.as_deref().and_then(|t| {
                        gyrolab::sampling::estimate_interval(&t[..t.len().min(START_ROWS)]).ok().map(|e| e.interval_s)
                    }),
                }
                .filter(|x| x.is_finite() && *x > 0.0);
                plan = plan_for(header.channels.len(), start);
                let streams = conversions_of(path, &header.channels, &options, &reference)
                    .and_then(|c| ChannelStreams::new(path, c, &options, plan, start));
                match streams {
                    Ok(s) => tx.send(Ok(s)).map_err(|_| stopped())?,
                    Err(e) => {
                        failure = Some(e);
                        return Err(stopped());
                    }
                }
                keep = Some(TableKeep {
                    columns: header.channels.iter().map(|c| c.column - 1).collect(),
                    tally: DropoutTally::new(header.channels.len()),
                    header,
                    time,
                    stamps: CompactStamps::default(),
                    lines: LineMap::default(),
                });
            }
            let Some(k) = keep.as_mut() else { return Err(stopped()) };
            let rows = block.first().map_or(0, Vec::len);
            if let Some((c, factor)) = k.time {
                let t: Vec<f64> = block[c].iter().map(|v| v * factor).collect();
                k.stamps.extend_from_slice(&t);
            }
            k.lines.extend_numbered(rows);
            let mut block = block;
            let channels: Vec<Vec<f64>> = k.columns.iter().map(|&c| std::mem::take(&mut block[c])).collect();
            k.tally.push_block(&channels.iter().map(|c| &c[..]).collect::<Vec<_>>());
            tx.send(Err(channels)).map_err(|_| stopped())
        };
        let read = gyrolab_io::recording::open_sniffed(path)
            .and_then(|(file, _, _)| gyrolab_io::parquet_table::stream_parquet_file(path, file, BLOCK_ROWS, &mut sink));
        drop(tx);
        (read, consumer.join())
    });
    let (read, pushed) = pushed;
    // The sink's own error (a unit the reference cannot convert) first: it stopped the reader.
    if let Some(e) = failure {
        return Err(e);
    }
    let located = |e: EvalError| crate::allan::located_in(e, RowKind::Row, None);
    let streams = match pushed {
        Ok(Ok(Some(s))) => s,
        Ok(Ok(None)) => {
            read?;
            return Err(EvalError::Data(DataError::new(path, "no rows to analyse")));
        }
        Ok(Err((c, e))) => {
            let k = keep.as_ref().ok_or_else(|| EvalError::conflict(format!("{}: no header", path.display())))?;
            return Err(located(pushed_error(path, &k.header.channels[c], &k.lines, e, estimate)));
        }
        Err(_) => return Err(EvalError::conflict(format!("{}: the streamed analysis failed", path.display()))),
    };
    read?;
    let Some(k) = keep else { return Err(EvalError::Data(DataError::new(path, "no rows to analyse"))) };
    let mut header = k.header;
    header.skipped.extend(layout.skipped.iter().cloned());
    let record = StreamedRecord {
        stamps: k.time.map(|_| k.stamps),
        header,
        quality: ReaderQuality::default(),
        lines: k.lines,
        tally: k.tally,
        topic: None,
    };
    let (outcome, channels) = finish_streamed(request, &reference, &options, record, streams, estimate)?;
    refuse_motion(&outcome.analyses, path, request.allow_motion)?;
    Ok((outcome, streaming_summary(memory_bytes, estimate, &[plan], channels)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_table_takes_8_bytes_a_cell() {
        let layout = ParquetLayout { rows: 1000, names: vec!["t".into(), "x".into(), "y".into()], skipped: Vec::new() };
        assert_eq!(table_size(&layout), 24_000);
    }
}
