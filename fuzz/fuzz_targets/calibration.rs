//! The calibration-file parser on arbitrary bytes.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    if let Err(e) = gyrolab_io::calibration::parse_calibration(std::path::Path::new("c.toml"), &text) {
        assert!(e.to_string().len() < 2000);
    }
});
