//! The simulation set-up parser (`simulate --config`) on arbitrary bytes.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    if let Err(e) = gyrolab_io::sim_csv::parse_sim_config(std::path::Path::new("s.toml"), &text) {
        assert!(e.to_string().len() < 2000);
    }
});
