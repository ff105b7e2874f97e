//! The ROS 1 bag reader (`read_records`: header, index, chunks bz2/lz4, connections, messages) on arbitrary bytes, written to a file (the readers open paths) that starts with
//! the format's magic (prepended when the input lacks it, so every input reaches the reader).
#![no_main]
use libfuzzer_sys::fuzz_target;

const MAGIC: &[u8] = b"#ROSBAG V2.0\n";

fuzz_target!(|data: &[u8]| {
    let path = std::env::temp_dir().join(format!("gyrolab-fuzz-{}-bag", std::process::id()));
    let bytes = if data.starts_with(MAGIC) { data.to_vec() } else { [MAGIC, data].concat() };
    if std::fs::write(&path, &bytes).is_err() {
        return;
    }
    let options = gyrolab_io::series::SeriesOptions::default();
    if let Err(e) = gyrolab_io::recording::read_records(&path, &options, &[]) {
        let text = e.to_string();
        assert!(text.len() < 2000, "error text of {} bytes", text.len());
    }
});
