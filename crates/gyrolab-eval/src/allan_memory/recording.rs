//! Recordings (MCAP, ROS 1 bags, PX4 ULog) analysed within a memory ceiling (issue 37;
//! docs/METHODS.md section 3.2): a recording whose IMU topics would not fit the ceiling in
//! memory is read in one pass by [`gyrolab_io::recording::OpenedFile::stream_recording`], each
//! IMU topic's messages handed over in blocks in stamp order, into the streamed OADEV of its
//! channels; the rules of a streamed text file apply (octave OADEV only, complete records only).
//!
//! Whether a recording fits is decided without a pass when its size alone shows it (an IMU
//! message takes at least [`MIN_FILE_BYTES_PER_MESSAGE`] bytes of file and at most
//! [`IN_MEMORY_BYTES_PER_MESSAGE`] of memory), else from the message counts of a first pass
//! that decodes nothing (the same counts plan the streamed estimators). The analyses come in
//! the order the in-memory path gives them (the topics' order in the file).

use super::{
    allan_options, conversions_of, finish_streamed, incomplete, pushed_error, stillness_footprint, streaming_summary,
    ChannelStreams, StreamedChannel, StreamedRecord, StreamingSummary, MIN_MEMORY_BYTES,
};
use crate::allan::{located_in, refuse_motion, AllanOutcome, AllanRequest, ReadNote};
use crate::error::{EvalError, EvalResult};
use gyrolab::allan::streaming::StreamingPlan;
use gyrolab::allan::AllanError;
use gyrolab::dropout::DropoutTally;
use gyrolab::sampling::CompactStamps;
use gyrolab_io::recording::{RecordingOptions, TopicBlock, TopicInfo};
use gyrolab_io::series::{
    series_from_columns, ChannelInfo, LineMap, ReaderQuality, RowKind, SeriesHeader, SeriesOptions,
};
use gyrolab_io::DataError;

/// Most messages of a topic handed over per block (and put in stamp order over twice as many).
pub const MAX_BLOCK_MESSAGES: usize = 1 << 16;

/// Fewest messages of a topic handed over per block.
pub const MIN_BLOCK_MESSAGES: usize = 1 << 10;

/// Messages per block under a ceiling: a block of a topic in memory takes a 64th of the ceiling
/// (56 bytes a message), between [`MIN_BLOCK_MESSAGES`] and [`MAX_BLOCK_MESSAGES`].
pub fn block_messages(memory_bytes: u64) -> usize {
    let n = memory_bytes / 64 / IN_MEMORY_BYTES_PER_MESSAGE;
    usize::try_from(n).unwrap_or(MAX_BLOCK_MESSAGES).clamp(MIN_BLOCK_MESSAGES, MAX_BLOCK_MESSAGES)
}

/// In-memory bytes of one IMU message at most: six channels and its stamp, 8 bytes each.
pub const IN_MEMORY_BYTES_PER_MESSAGE: u64 = 56;

/// File bytes of one IMU message at least, in any recording format: a ULog data message of a
/// time stamp and three float32 values takes 25 (header 3, id 2, payload 20), an uncompressed
/// MCAP or bag message more (a record header of 31 or 8 bytes besides its payload); compressed
/// chunks of a sensor at rest (constant fields, quantised values, regular stamps) can take a
/// few bytes a message, so 2 is assumed.
pub const MIN_FILE_BYTES_PER_MESSAGE: u64 = 2;

/// Rows of a topic's first block whose stamps give the stillness check's interval.
const START_ROWS: usize = 10_000;

/// The in-memory size of a recording of `size` bytes at most, by its size alone.
pub fn size_bound(size: u64) -> u64 {
    (size / MIN_FILE_BYTES_PER_MESSAGE + 1).saturating_mul(IN_MEMORY_BYTES_PER_MESSAGE)
}

/// The IMU topics the request analyses, with their message counts: from an MCAP file's summary
/// when it has one that names every topic asked for, else from a pass over the file that
/// decodes nothing (the topics named are checked as the in-memory path checks them).
pub fn imu_topic_counts(request: &AllanRequest) -> EvalResult<Vec<TopicInfo>> {
    let selected = |t: &TopicInfo| t.imu && (request.topics.is_empty() || request.topics.contains(&t.topic));
    if let Some(topics) = gyrolab_io::recording::mcap_summary_topics(&request.file)? {
        let known = |name: &String| topics.iter().any(|t| &t.topic == name && t.imu);
        if request.topics.iter().all(known) && topics.iter().any(selected) {
            return Ok(topics.into_iter().filter(selected).collect());
        }
    }
    let options = RecordingOptions { topics: request.topics.clone(), inventory_only: true, ..Default::default() };
    let recording = gyrolab_io::recording::read_recording(&request.file, &options)?;
    Ok(recording.topics.into_iter().filter(selected).collect())
}

/// The in-memory size of the topics counted, bytes.
pub fn counted_size(topics: &[TopicInfo]) -> u64 {
    topics.iter().map(|t| t.messages).sum::<u64>().saturating_mul(IN_MEMORY_BYTES_PER_MESSAGE)
}

/// What the reader side keeps of one streamed topic.
struct TopicKeep {
    topic: String,
    message_type: String,
    header: SeriesHeader,
    /// For each analysed channel, its column in the topic's blocks.
    columns: Vec<usize>,
    first_ns: i64,
    stamps: CompactStamps,
    lines: LineMap,
    tally: DropoutTally,
    plan: StreamingPlan,
}

/// Work for the estimators' thread.
enum Work {
    /// A topic's first block comes: its streams.
    Start(ChannelStreams),
    /// A block of topic `0` (its index in order of first blocks), one column per channel.
    Block(usize, Vec<Vec<f64>>),
}

/// Seconds from `first_ns` of each stamp (in 128 bits, as the in-memory path computes them).
fn seconds(stamps_ns: &[i64], first_ns: i64) -> Vec<f64> {
    stamps_ns.iter().map(|&t| (i128::from(t) - i128::from(first_ns)) as f64 * 1e-9).collect()
}

/// Streams a recording's IMU topics (`counts`: their messages, from [`imu_topic_counts`])
/// through the estimators of their channels within `memory_bytes`: the reader decodes on this
/// thread, the estimators take the blocks on another (channels in parallel).
pub fn analyse_recording_streaming(
    request: &AllanRequest,
    memory_bytes: u64,
    estimate: u64,
    counts: &[TopicInfo],
) -> EvalResult<(Vec<AllanOutcome>, StreamingSummary)> {
    let path = request.file.as_path();
    let reference = request.reference.resolve()?;
    let options = allan_options(request);
    // As the in-memory path reads a topic (`ImuTopic::into_series`): the layout's time column,
    // time unit and names do not apply to messages.
    let series_options = SeriesOptions {
        time_column: None,
        time_unit: None,
        names: None,
        ..request.layout.apply(SeriesOptions {
            sample_rate_hz: request.sample_rate_hz,
            channels: if request.columns.is_empty() { None } else { Some(request.columns.clone()) },
            tolerant: true,
            compact_time: true,
            ..SeriesOptions::default()
        })?
    };
    let block_size = block_messages(memory_bytes);
    // Off the ceiling before the plans share it: each topic's reorder buffer (three blocks),
    // the blocks in flight (one decoded, two queued, one taken), the stamps (about a byte a
    // message) and the stillness checks (at the rate of the topic's span).
    let block_bytes = block_size as u64 * IN_MEMORY_BYTES_PER_MESSAGE;
    let messages: u64 = counts.iter().map(|t| t.messages).sum();
    let stillness_bytes: u64 = counts
        .iter()
        .filter_map(|t| {
            let (a, b) = t.span_ns?;
            let tau0 = (b - a) as f64 * 1e-9 / t.messages.saturating_sub(1).max(1) as f64;
            (tau0 > 0.0).then(|| stillness_footprint(t.messages, 6, tau0))
        })
        .sum();
    let overhead = counts.len() as u64 * 3 * block_bytes + 4 * block_bytes + messages + stillness_bytes;
    let budget = memory_bytes.saturating_sub(overhead).max(MIN_MEMORY_BYTES / 2);
    let plan_of = |topic: &str, channels: usize| {
        let n = counts.iter().find(|t| t.topic == topic).map_or(0, |t| t.messages);
        let share = (budget as f64 * n as f64 / messages.max(1) as f64) as u64;
        StreamingPlan::for_memory(
            usize::try_from(n).unwrap_or(usize::MAX),
            channels.max(1),
            usize::try_from(share.max(MIN_MEMORY_BYTES / 2)).unwrap_or(usize::MAX),
        )
    };

    let mut keeps: Vec<TopicKeep> = Vec::new();
    // An error of the sink that is not the reader's (a unit the reference cannot convert): the
    // pass is stopped with a placeholder and this error is reported.
    let mut failure: Option<EvalError> = None;
    let (streamed, pushed) = std::thread::scope(|scope| {
        let (tx, rx) = std::sync::mpsc::sync_channel::<Work>(2);
        let consumer = scope.spawn(move || -> Result<Vec<ChannelStreams>, (usize, usize, AllanError)> {
            let mut streams: Vec<ChannelStreams> = Vec::new();
            for work in rx {
                match work {
                    Work::Start(s) => streams.push(s),
                    Work::Block(t, mut block) => streams[t].push(&mut block).map_err(|(c, e)| (t, c, e))?,
                }
            }
            Ok(streams)
        });
        let stopped = || DataError::new(path, "the streamed analysis stopped");
        let mut sink = |b: TopicBlock<'_>| -> Result<(), DataError> {
            let index = match keeps.iter().position(|k| k.topic == b.topic && k.message_type == b.message_type) {
                Some(i) => i,
                None => {
                    let Some(&first_ns) = b.stamps_ns.first() else { return Ok(()) };
                    let time = seconds(b.stamps_ns, first_ns);
                    let mut names = vec!["time_s".to_string()];
                    names.extend(b.names.iter().cloned());
                    let mut columns = vec![time.clone()];
                    columns.extend(b.channels.iter().cloned());
                    let data = series_from_columns(path, &names, columns, RowKind::Message, &series_options).map_err(
                        |mut e| {
                            e.message = format!("topic '{}': {}", gyrolab_io::text::excerpt(b.topic), e.message);
                            e
                        },
                    )?;
                    let header = data.header;
                    let infos: Vec<ChannelInfo> = header.channels.clone();
                    let start = match request.sample_rate_hz {
                        Some(r) => Some(1.0 / r),
                        None => gyrolab::sampling::estimate_interval(&time[..time.len().min(START_ROWS)])
                            .ok()
                            .map(|e| e.interval_s),
                    }
                    .filter(|x| x.is_finite() && *x > 0.0);
                    let plan = plan_of(b.topic, infos.len());
                    // Each channel's column in the blocks: [time, channels...] is 1-based.
                    let columns: Option<Vec<usize>> =
                        infos.iter().map(|i| i.column.checked_sub(2).filter(|&c| c < b.channels.len())).collect();
                    let streams = match columns {
                        Some(_) => conversions_of(path, &infos, &options, &reference)
                            .and_then(|c| ChannelStreams::new(path, c, &options, plan, start)),
                        None => Err(EvalError::conflict(format!(
                            "{}: topic '{}': a channel is not among the message's values",
                            path.display(),
                            gyrolab_io::text::excerpt(b.topic)
                        ))),
                    };
                    let streams = match streams {
                        Ok(s) => s,
                        Err(e) => {
                            failure = Some(e);
                            return Err(stopped());
                        }
                    };
                    tx.send(Work::Start(streams)).map_err(|_| stopped())?;
                    keeps.push(TopicKeep {
                        topic: b.topic.to_string(),
                        message_type: b.message_type.to_string(),
                        columns: columns.unwrap_or_default(),
                        tally: DropoutTally::new(infos.len()),
                        header,
                        first_ns,
                        stamps: CompactStamps::default(),
                        lines: LineMap::default(),
                        plan,
                    });
                    keeps.len() - 1
                }
            };
            let k = &mut keeps[index];
            k.stamps.extend_from_slice(&seconds(b.stamps_ns, k.first_ns));
            k.lines.extend_numbered(b.stamps_ns.len());
            let Some(block) = k.columns.iter().map(|&c| b.channels.get(c).cloned()).collect::<Option<Vec<_>>>() else {
                return Err(DataError::new(path, format!("topic '{}': a block without a channel", b.topic)));
            };
            k.tally.push_block(&block.iter().map(|c| &c[..]).collect::<Vec<_>>());
            tx.send(Work::Block(index, block)).map_err(|_| stopped())
        };
        let streamed =
            gyrolab_io::recording::open(path).and_then(|f| f.stream_recording(&request.topics, block_size, &mut sink));
        drop(tx);
        (streamed, consumer.join())
    });
    // A sample the estimators refused comes first, then the sink's own error, then the reader's.
    let streams = match pushed {
        Ok(Ok(s)) => s,
        Ok(Err((t, c, e))) => {
            let k = &keeps[t];
            let e = pushed_error(path, &k.header.channels[c], &k.lines, e, estimate);
            let meta = gyrolab_io::recording::TopicMeta {
                topic: k.topic.clone(),
                message_type: k.message_type.clone(),
                stamp_source: gyrolab_io::recording::StampSource::Header,
                messages: k.lines.len() as u64,
                out_of_order: 0,
                first_stamp_ns: k.first_ns,
            };
            return Err(located_in(e, RowKind::Message, Some(&meta)));
        }
        Err(_) => return Err(EvalError::conflict(format!("{}: the streamed analysis failed", path.display()))),
    };
    if let Some(e) = failure {
        return Err(e);
    }
    let streamed = streamed.map_err(|e| {
        if e.message.contains("out of stamp order by more than") {
            EvalError::Data(incomplete(path, &e.message, estimate))
        } else {
            EvalError::Data(e)
        }
    })?;
    let mut outcomes = Vec::with_capacity(keeps.len());
    let mut channels: Vec<StreamedChannel> = Vec::new();
    let mut plans = Vec::with_capacity(keeps.len());
    for ((k, s), meta) in keeps.into_iter().zip(streams).zip(streamed.streamed) {
        plans.push(k.plan);
        let record = StreamedRecord {
            header: k.header,
            quality: ReaderQuality::default(),
            stamps: Some(k.stamps),
            lines: k.lines,
            tally: k.tally,
            topic: Some(meta.clone()),
        };
        let (mut outcome, mut c) = finish_streamed(request, &reference, &options, record, s, estimate)?;
        let mut notes = vec![ReadNote::Topic(meta)];
        if let Some(what) = &streamed.truncated {
            notes.push(ReadNote::Truncated(what.clone()));
        }
        notes.append(&mut outcome.notes);
        outcome.notes = notes;
        outcomes.push(outcome);
        channels.append(&mut c);
    }
    // In the file's order of topics, as in memory (the blocks came in the order of the topics'
    // first full blocks).
    let order = |o: &AllanOutcome| {
        o.topic.as_ref().and_then(|m| streamed.topics.iter().position(|t| t.topic == m.topic)).unwrap_or(usize::MAX)
    };
    outcomes.sort_by_key(order);
    let position = |topic: &Option<String>| {
        topic.as_ref().and_then(|n| streamed.topics.iter().position(|t| &t.topic == n)).unwrap_or(usize::MAX)
    };
    channels.sort_by_key(|c| position(&c.topic));
    refuse_motion(outcomes.iter().flat_map(|o| &o.analyses), path, request.allow_motion)?;
    Ok((outcomes, streaming_summary(memory_bytes, estimate, &plans, channels)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_size_bound_covers_the_densest_format() {
        // a ULog of 25-byte messages (3 float32 and a stamp) widened to 4 f64: 32 bytes a
        // message; a compressed chunk of 3 bytes a message read as six channels: 56; the bound
        // assumes 2 bytes of file and 56 of memory a message
        assert!(size_bound(25 * 1000) >= 1000 * 32);
        assert!(size_bound(3 * 1000) >= 1000 * 56);
        assert_eq!(size_bound(0), 56);
        assert_eq!(block_messages(1 << 20), MIN_BLOCK_MESSAGES);
        assert_eq!(block_messages(1 << 30), MAX_BLOCK_MESSAGES);
        assert_eq!(block_messages(64 << 20), (64 << 20) / 64 / 56);
    }

    #[test]
    fn seconds_count_from_the_first_stamp_in_128_bits() {
        assert_eq!(seconds(&[i64::MIN, i64::MIN + 1_000_000_000], i64::MIN), [0.0, 1.0]);
        assert_eq!(seconds(&[1_700_000_000_005_000_000], 1_700_000_000_000_000_000), [0.005]);
    }

    #[test]
    fn a_missing_file_is_an_error_naming_it() {
        // a path that does not exist is an error naming it, not a panic
        let request = AllanRequest::new("/nonexistent/x.mcap");
        let e = imu_topic_counts(&request).unwrap_err().to_string();
        assert!(e.contains("/nonexistent/x.mcap"), "{e}");
    }
}
