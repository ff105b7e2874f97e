//! The delimited-text parser on arbitrary bytes: never a panic, errors bounded.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    if let Err(e) = gyrolab_io::text::parse_text_table(std::path::Path::new("f.csv"), &text) {
        assert!(e.to_string().len() < 2000);
    }
});
