//! A static record on three threads. The simulation is sequential (one noise stream), the
//! formatting is not: blocks of samples can be turned into text in any order and written in
//! order.
//!
//! - The simulating thread (the caller's) simulates blocks of samples and queues them for the
//!   formatting thread. When the queue is full and one of its own text buffers is free, it
//!   formats the block itself instead of waiting, so the two share the formatting by how busy
//!   they are (no fixed split, which would suit only one machine and one number format).
//! - The formatting thread formats queued blocks.
//! - The output thread writes text blocks in sequence order (holding early arrivals) and gives
//!   each buffer back to the thread that owns it.
//!
//! Memory is bounded: each formatter owns at most [`TEXT_BUFFERS`] buffers (the simulating thread
//! also gets the preamble's back). No deadlock: the
//! output thread always takes what it is sent; the formatting thread formats in queue order, so
//! every block before the one at the head of the queue has been formatted (by it, or by the
//! simulating thread, which formats without waiting on anything but the output thread) and the
//! formatting thread's buffers all come back; the simulating thread waits on the queue only when
//! it has no free buffer.
//! An output error ends the output thread; the other two then find their channels closed and stop.

use std::collections::BTreeMap;
use std::io::Write;
use std::sync::mpsc::{channel, sync_channel, Receiver, Sender, TrySendError};

use gyrolab::sim::{StaticBlock, StaticGenerator};

use super::text::{NumberText, TextBuf};
use super::{static_rows, TimeColumn, WriteSummary, BLOCK_SAMPLES};

/// Text buffers each formatting thread owns at most.
const TEXT_BUFFERS: usize = 3;
/// Sample blocks queued for the formatting thread.
const QUEUED_BLOCKS: usize = 2;
/// Text bytes a block usually needs (grows when needed).
const BLOCK_TEXT: usize = BLOCK_SAMPLES * 32;

/// Who formatted a text block (and gets its buffer back).
#[derive(Debug, Clone, Copy)]
enum Owner {
    Simulator,
    Formatter,
}

/// A formatted block: its place in the record and its text `bytes[..len]`.
struct TextBlock {
    seq: u64,
    bytes: Vec<u8>,
    len: usize,
    owner: Owner,
}

/// A formatting thread's text buffers: taken back from the output thread, or new while fewer
/// than [`TEXT_BUFFERS`] exist.
struct BufferPool {
    returned: Receiver<Vec<u8>>,
    created: usize,
}

impl BufferPool {
    /// A free buffer now, if there is one.
    fn try_take(&mut self) -> Option<Vec<u8>> {
        if let Ok(b) = self.returned.try_recv() {
            return Some(b);
        }
        (self.created < TEXT_BUFFERS).then(|| {
            self.created += 1;
            vec![0; BLOCK_TEXT]
        })
    }

    /// A free buffer, waiting for one to come back; none when the output thread has stopped.
    fn take(&mut self) -> Option<Vec<u8>> {
        self.try_take().or_else(|| self.returned.recv().ok())
    }
}

/// Formats `samples` as rows into a fresh text in `buffer`; returns the text block.
fn format_block<N: NumberText>(
    text: &mut TextBuf,
    buffer: Vec<u8>,
    samples: &StaticBlock,
    time: &mut TimeColumn,
    seq: u64,
    owner: Owner,
) -> TextBlock {
    text.bytes = buffer;
    text.end = 0;
    static_rows::<N>(text, samples, time);
    TextBlock { seq, bytes: std::mem::take(&mut text.bytes), len: text.end, owner }
}

/// Writes `preamble` then the rows of `generator` to `out` on three threads (see the module
/// documentation); returns rows and bytes written, or the first output error.
pub(super) fn write_static_parallel<N: NumberText, W: Write + Send>(
    out: W,
    mut generator: StaticGenerator,
    preamble: TextBuf,
) -> std::io::Result<WriteSummary> {
    let (to_formatter, queued) = sync_channel::<(u64, StaticBlock)>(QUEUED_BLOCKS);
    let (samples_back, spare_samples) = channel::<StaticBlock>();
    let time = TimeColumn::new::<N>(&generator);
    let formatter_time = time.clone();
    let (to_output, formatted) = sync_channel::<TextBlock>(2 * TEXT_BUFFERS + 2);
    let (back_to_simulator, simulator_returned) = channel::<Vec<u8>>();
    let (back_to_formatter, formatter_returned) = channel::<Vec<u8>>();
    std::thread::scope(|scope| {
        let output = scope.spawn(move || write_in_order(out, formatted, back_to_simulator, back_to_formatter));
        let formatter_output = to_output.clone();
        scope.spawn(move || {
            let mut pool = BufferPool { returned: formatter_returned, created: 0 };
            let mut text = TextBuf::new(0);
            let mut time = formatter_time;
            for (seq, samples) in queued {
                // None: the output thread stopped (it reports why).
                let Some(buffer) = pool.take() else { break };
                let block = format_block::<N>(&mut text, buffer, &samples, &mut time, seq, Owner::Formatter);
                if formatter_output.send(block).is_err() {
                    break;
                }
                // The simulating thread may have finished: a failed return is harmless.
                let _ = samples_back.send(samples);
            }
        });
        let mut pool = BufferPool { returned: simulator_returned, created: 0 };
        let mut text = TextBuf::new(0);
        let mut time = time;
        let mut rows = 0u64;
        let first = TextBlock { seq: 0, len: preamble.end, bytes: preamble.bytes, owner: Owner::Simulator };
        let mut sending = to_output.send(first).is_ok();
        let mut seq = 1;
        // A sample block this thread formatted itself, for reuse.
        let mut own_spare: Option<StaticBlock> = None;
        while sending {
            let mut samples = own_spare.take().or_else(|| spare_samples.try_recv().ok()).unwrap_or_default();
            if generator.next_block(&mut samples, BLOCK_SAMPLES) == 0 {
                break;
            }
            rows += samples.len() as u64;
            sending = match to_formatter.try_send((seq, samples)) {
                Ok(()) => true,
                Err(TrySendError::Full((seq, samples))) => match pool.try_take() {
                    // The formatter is busy and a buffer is free: format here.
                    Some(buffer) => {
                        let block = format_block::<N>(&mut text, buffer, &samples, &mut time, seq, Owner::Simulator);
                        own_spare = Some(samples);
                        to_output.send(block).is_ok()
                    }
                    None => to_formatter.send((seq, samples)).is_ok(),
                },
                // The formatting thread stopped: the output thread stopped first (it says why).
                Err(TrySendError::Disconnected(_)) => false,
            };
            seq += 1;
        }
        // Closing the queue and this thread's sender lets the other two finish.
        drop(to_formatter);
        drop(to_output);
        let bytes = output.join().unwrap_or_else(|_| Err(std::io::Error::other("the output thread failed")))?;
        Ok(WriteSummary { rows, bytes })
    })
}

/// The output thread: writes text blocks in sequence order and returns each buffer to its owner;
/// returns the bytes written.
fn write_in_order<W: Write>(
    mut out: W,
    formatted: Receiver<TextBlock>,
    back_to_simulator: Sender<Vec<u8>>,
    back_to_formatter: Sender<Vec<u8>>,
) -> std::io::Result<u64> {
    let mut next = 0u64;
    let mut early = BTreeMap::new();
    let mut bytes = 0u64;
    for block in formatted {
        early.insert(block.seq, block);
        while let Some(block) = early.remove(&next) {
            out.write_all(&block.bytes[..block.len])?;
            bytes += block.len as u64;
            next += 1;
            // An owner that has finished no longer takes buffers back: harmless.
            let _ = match block.owner {
                Owner::Simulator => back_to_simulator.send(block.bytes),
                Owner::Formatter => back_to_formatter.send(block.bytes),
            };
        }
    }
    if !early.is_empty() {
        // Only when a formatter stopped early, which only an output error causes.
        return Err(std::io::Error::other("the simulated record ended with blocks missing"));
    }
    out.flush()?;
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_are_written_in_sequence_and_buffers_go_back_to_their_owners() {
        let (to_output, formatted) = sync_channel::<TextBlock>(8);
        let (back_to_simulator, simulator_returned) = channel::<Vec<u8>>();
        let (back_to_formatter, formatter_returned) = channel::<Vec<u8>>();
        let block = |seq: u64, text: &str, owner| {
            let mut bytes = text.as_bytes().to_vec();
            bytes.extend_from_slice(b"unused room");
            TextBlock { seq, bytes, len: text.len(), owner }
        };
        for b in [block(2, "c", Owner::Formatter), block(0, "a", Owner::Simulator), block(3, "d", Owner::Simulator)] {
            to_output.send(b).unwrap();
        }
        to_output.send(block(1, "b", Owner::Formatter)).unwrap();
        drop(to_output);
        let mut out = Vec::new();
        let bytes = write_in_order(&mut out, formatted, back_to_simulator, back_to_formatter).unwrap();
        assert_eq!((out.as_slice(), bytes), (&b"abcd"[..], 4));
        let starts = |r: Receiver<Vec<u8>>| r.try_iter().map(|b| b[0]).collect::<Vec<u8>>();
        assert_eq!(starts(simulator_returned), b"ad");
        assert_eq!(starts(formatter_returned), b"bc");
    }

    #[test]
    fn a_missing_block_is_an_error_not_a_silent_gap() {
        let (to_output, formatted) = sync_channel::<TextBlock>(8);
        let (back_to_simulator, _a) = channel::<Vec<u8>>();
        let (back_to_formatter, _b) = channel::<Vec<u8>>();
        to_output.send(TextBlock { seq: 1, bytes: b"b".to_vec(), len: 1, owner: Owner::Formatter }).unwrap();
        drop(to_output);
        let e = write_in_order(Vec::new(), formatted, back_to_simulator, back_to_formatter).unwrap_err();
        assert!(e.to_string().contains("blocks missing"), "{e}");
    }
}
