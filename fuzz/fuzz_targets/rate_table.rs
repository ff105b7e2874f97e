//! The rate-table reader (long and wide layouts) on arbitrary bytes.
#![no_main]
use gyrolab_io::rate_table::{parse_rate_table, RateColumns};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    if let Err(e) = parse_rate_table(std::path::Path::new("f.csv"), &text, &RateColumns::default()) {
        assert!(e.to_string().len() < 2000);
    }
});
