//! The MCAP reader (chunks, schemas, channels, CDR and ROS 1 messages) on arbitrary bytes: `recording_input.rs`.
#![no_main]
use libfuzzer_sys::fuzz_target;

#[path = "recording_input.rs"]
mod recording_input;

fuzz_target!(|data: &[u8]| recording_input::read_recording("mcap", b"\x89MCAP0\r\n", data));
