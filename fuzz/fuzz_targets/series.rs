//! The streaming time-series reader on arbitrary bytes, in strict, tolerant and raw-log modes,
//! with a small chunk so lines cross chunk ends.
#![no_main]
use gyrolab_io::series::{SeriesOptions, SeriesReader};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let chunk_bytes = 16 + usize::from(data.first().copied().unwrap_or(0));
    let modes = [
        SeriesOptions { chunk_bytes, block_rows: 3, ..SeriesOptions::default() },
        SeriesOptions { chunk_bytes, tolerant: true, sample_rate_hz: Some(100.0), ..SeriesOptions::default() },
        SeriesOptions {
            chunk_bytes,
            table_rate_column: Some("table_rate_dps".into()),
            fast_rows: false,
            ..SeriesOptions::default()
        },
    ];
    for o in modes {
        let r = SeriesReader::from_reader("f.csv", std::io::Cursor::new(data), &o).and_then(|mut r| {
            while let Some(b) = r.next_block()? {
                assert!(b.channels.iter().all(|c| c.len() == b.len()));
            }
            Ok(())
        });
        if let Err(e) = r {
            assert!(e.to_string().len() < 2000);
        }
    }
});
