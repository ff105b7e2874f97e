//! The test-plan parser on arbitrary bytes (relative to the examples folder, so file names in
//! mutated plans can resolve).
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let plan = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/paper_plan.toml");
    if let Err(e) = gyrolab_io::test_plan::parse_plan(&plan, &text, &|n| n.ends_with("_pct")) {
        assert!(e.to_string().len() < 2000);
    }
});
