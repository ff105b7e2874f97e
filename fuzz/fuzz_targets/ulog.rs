//! The PX4 ULog reader (definitions, formats, data messages) on arbitrary bytes: `recording_input.rs`.
#![no_main]
use libfuzzer_sys::fuzz_target;

#[path = "recording_input.rs"]
mod recording_input;

fuzz_target!(|data: &[u8]| recording_input::read_recording("ulog", b"ULog\x01\x12\x35\x01", data));
