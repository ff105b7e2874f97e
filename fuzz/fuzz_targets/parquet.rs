//! The Parquet reader (footer, schema, row groups, pages) on arbitrary bytes: `recording_input.rs`.
#![no_main]
use libfuzzer_sys::fuzz_target;

#[path = "recording_input.rs"]
mod recording_input;

fuzz_target!(|data: &[u8]| recording_input::read_recording("parquet", b"PAR1", data));
