//! The ROS 1 bag reader (header, index, chunks bz2/lz4, connections, messages) on arbitrary bytes: `recording_input.rs`.
#![no_main]
use libfuzzer_sys::fuzz_target;

#[path = "recording_input.rs"]
mod recording_input;

fuzz_target!(|data: &[u8]| recording_input::read_recording("bag", b"#ROSBAG V2.0\n", data));
