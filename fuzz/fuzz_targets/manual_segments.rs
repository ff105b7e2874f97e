//! The manual segment-file parser (`rate --segments`) on arbitrary bytes.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    if let Err(e) = gyrolab_io::raw_log::parse_manual_segments(std::path::Path::new("g.csv"), &text) {
        assert!(e.to_string().len() < 2000);
    }
});
