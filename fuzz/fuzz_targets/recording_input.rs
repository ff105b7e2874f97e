//! Shared by the recording targets (`mcap`, `bag`, `ulog`, `parquet`): the input written to a
//! file (the readers open paths) that starts with the format's magic (prepended when the input
//! lacks it, so every input reaches the reader), then read by `read_records`; an error's text
//! must stay short.

/// Writes `data` (behind `magic` when it lacks it) to a file named for `target` and reads it.
pub fn read_recording(target: &str, magic: &[u8], data: &[u8]) {
    let path = std::env::temp_dir().join(format!("gyrolab-fuzz-{}-{target}", std::process::id()));
    let bytes = if data.starts_with(magic) { data.to_vec() } else { [magic, data].concat() };
    if std::fs::write(&path, &bytes).is_err() {
        return;
    }
    let options = gyrolab_io::series::SeriesOptions::default();
    if let Err(e) = gyrolab_io::recording::read_records(&path, &options, &[]) {
        let text = e.to_string();
        assert!(text.len() < 2000, "error text of {} bytes", text.len());
    }
}
