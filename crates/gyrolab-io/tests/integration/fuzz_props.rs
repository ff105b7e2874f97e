//! Every reader and configuration parser survives arbitrary bytes (issue 15): random inputs and
//! mutations of valid files (truncated, random bytes inserted or overwritten, lines duplicated
//! or dropped) never panic, and every error is a `DataError` with a message of bounded length.
//! The cargo-fuzz targets in `fuzz/` run the same readers for longer (docs/FUZZING.md); inputs
//! they found are kept in `regressions` below.

use gyrolab_io::calibration::parse_calibration;
use gyrolab_io::rate_table::{parse_rate_table, RateColumns};
use gyrolab_io::raw_log::parse_manual_segments;
use gyrolab_io::series::{SeriesOptions, SeriesReader};
use gyrolab_io::sim_csv::parse_sim_config;
use gyrolab_io::test_plan::parse_plan;
use gyrolab_io::text::parse_text_table;
use gyrolab_io::DataError;
use proptest::prelude::*;
use std::path::Path;

/// Cases per property: 300, or `GYROLAB_PROP_CASES` for a longer hunt.
fn cases() -> u32 {
    std::env::var("GYROLAB_PROP_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(300)
}

/// Longest error text accepted: the message cap plus the file, line and column.
const MAX_ERROR_CHARS: usize = gyrolab_io::error::MAX_MESSAGE_CHARS + 200;

const RATE_LONG: &str = "rate_dps,run,stroke,output_v\n0,1,rest_start,2.5\n-10,1,fwd,2.42\n10,1,fwd,2.58\n10,1,rev,2.581\n-10,1,rev,2.421\n-10,2,fwd,2.42\n10,2,fwd,2.58\n10,2,rev,2.58\n-10,2,rev,2.42\n0,1,rest_end,2.5\n";
const RATE_WIDE: &str = include_str!("../../../../data/paper/paper_rate_table_x.csv");
const SERIES: &str = "# a comment\ntime_s,table_rate_dps,output_v,temp_c\n0.00,0,2.5,25.0\n0.01,0,2.51,25.0\n0.02,10,-2.49e0,25.1\n0.03,10,+2.5,25.1\n";
const SEGMENTS: &str = "start_time_s,end_time_s,kind,run,stroke\n0,5,rest_start,,\n6,10,plateau,1,fwd\n11,15,plateau,1,rev\n16,20,rest_end,,\n";
const SIM: &str = "seed = 3\npreset = \"adxrs646\"\n\n[sensor]\narw_deg_rt_h = 0.5\n\n[static_record]\nsample_rate_hz = 100\nduration_s = 60\n\n[rate_table]\nrates_dps = [-10.0, 10.0]\nruns = 2\n";
const PLAN: &str = include_str!("../../../../examples/paper_plan.toml");

/// The example plan's path: its folder holds the files it names, so mutated plans get past the
/// file checks.
fn plan_path() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/paper_plan.toml")
}

fn calibration_text() -> String {
    "format = \"gyrolab-calibration-1\"\ngenerator = \"t\"\ncreated = \"2026-01-01T00:00:00Z\"\n\n[[axis]]\nname = \"x\"\n\
     source_file = \"x.csv\"\noutput_unit = \"V\"\nscale_factor = 0.0075\nzero_offset = 2.5\nrest_reference = 2.51\n\
     rate_min_dps = -300.0\nrate_max_dps = 300.0\n\n[axis.polynomial]\norder = 1\ncoefficients = [2.5, 0.0075]\n\n\
     [triad]\naxes = [\"x\", \"y\", \"z\"]\nsource_files = [\"a\", \"b\", \"c\"]\noutput_unit = \"V\"\n\
     matrix = [[0.0075, 0.0, 0.0], [0.0, 0.0076, 0.0], [0.0, 0.0, 0.0074]]\nbias = [2.5, 2.51, 2.49]\nrate_limit_dps = 300.0\n"
        .to_string()
}

/// Checks a reader's result: any `Ok`, or an error whose text is bounded.
fn bounded<T>(r: Result<T, DataError>) -> Result<(), TestCaseError> {
    if let Err(e) = r {
        let text = e.to_string();
        // Bytes, not characters: a message of replacement characters is 3 bytes a character.
        prop_assert!(text.len() <= MAX_ERROR_CHARS, "{} bytes: {}", text.len(), text);
        prop_assert!(!e.message.is_empty());
    }
    Ok(())
}

/// Every reader on the same bytes.
fn all_readers(bytes: &[u8]) -> Result<(), TestCaseError> {
    let text = String::from_utf8_lossy(bytes);
    let p = Path::new("fuzz.txt");
    bounded(parse_text_table(p, &text))?;
    bounded(parse_rate_table(p, &text, &RateColumns::default()))?;
    bounded(parse_manual_segments(p, &text))?;
    bounded(parse_calibration(p, &text))?;
    bounded(parse_sim_config(p, &text))?;
    bounded(parse_plan(&plan_path(), &text))?;
    series(bytes, 16)?;
    series(bytes, 1 << 20)
}

/// The streaming series reader over `bytes`, chunk by chunk, in strict, tolerant and raw-log modes.
fn series(bytes: &[u8], chunk_bytes: usize) -> Result<(), TestCaseError> {
    let modes = [
        SeriesOptions { chunk_bytes, block_rows: 3, ..SeriesOptions::default() },
        SeriesOptions { chunk_bytes, tolerant: true, sample_rate_hz: Some(100.0), ..SeriesOptions::default() },
        SeriesOptions {
            chunk_bytes,
            table_rate_column: Some("table_rate_dps".into()),
            channels: Some(vec!["output_v".into()]),
            fast_rows: false,
            ..SeriesOptions::default()
        },
    ];
    for o in modes {
        let r = SeriesReader::from_reader("fuzz.csv", std::io::Cursor::new(bytes), &o).and_then(|mut r| {
            let mut rows = 0;
            while let Some(b) = r.next_block()? {
                rows += b.len();
                assert!(b.channels.iter().all(|c| c.len() == b.len()));
            }
            Ok(rows)
        });
        bounded(r)?;
    }
    Ok(())
}

/// One mutation of a file.
#[derive(Debug, Clone)]
enum Mutation {
    Truncate(prop::sample::Index),
    Insert(prop::sample::Index, Vec<u8>),
    Overwrite(prop::sample::Index, u8),
    DuplicateLine(prop::sample::Index),
    DropLine(prop::sample::Index),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let interesting = prop::sample::select(b"\0\r\n,;\t #\"+-.eE9[]=\xff\xc3".to_vec());
    prop_oneof![
        any::<prop::sample::Index>().prop_map(Mutation::Truncate),
        (any::<prop::sample::Index>(), prop::collection::vec(any::<u8>(), 1..12))
            .prop_map(|(i, b)| Mutation::Insert(i, b)),
        (any::<prop::sample::Index>(), interesting).prop_map(|(i, b)| Mutation::Overwrite(i, b)),
        any::<prop::sample::Index>().prop_map(Mutation::DuplicateLine),
        any::<prop::sample::Index>().prop_map(Mutation::DropLine),
    ]
}

fn mutate(seed: &str, ops: &[Mutation]) -> Vec<u8> {
    let mut b = seed.as_bytes().to_vec();
    for op in ops {
        if b.is_empty() {
            break;
        }
        match op {
            Mutation::Truncate(i) => b.truncate(i.index(b.len())),
            Mutation::Insert(i, bytes) => {
                let at = i.index(b.len() + 1);
                b.splice(at..at, bytes.iter().copied());
            }
            Mutation::Overwrite(i, c) => {
                let at = i.index(b.len());
                b[at] = *c;
            }
            Mutation::DuplicateLine(i) | Mutation::DropLine(i) => {
                let mut lines: Vec<Vec<u8>> = b.split_inclusive(|&c| c == b'\n').map(<[u8]>::to_vec).collect();
                let k = i.index(lines.len());
                if matches!(op, Mutation::DuplicateLine(_)) {
                    let l = lines[k].clone();
                    lines.insert(k, l);
                } else {
                    lines.remove(k);
                }
                b = lines.concat();
            }
        }
    }
    b
}

fn seeds() -> Vec<String> {
    vec![
        RATE_LONG.to_string(),
        RATE_WIDE.to_string(),
        SERIES.to_string(),
        SEGMENTS.to_string(),
        SIM.to_string(),
        PLAN.to_string(),
        calibration_text(),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), failure_persistence: None, ..ProptestConfig::default() })]

    /// Random bytes: never a panic, errors bounded.
    #[test]
    fn random_bytes(bytes in prop::collection::vec(any::<u8>(), 0..600)) {
        all_readers(&bytes)?;
    }

    /// Random text made of the characters the formats use.
    #[test]
    fn random_format_text(text in "[a-z_0-9,.;\t \n\r#=\"\\[\\]+-]{0,400}") {
        all_readers(text.as_bytes())?;
    }

    /// Valid files of every format, mutated: never a panic, errors bounded.
    #[test]
    fn mutated_valid_files(which in 0usize..7, ops in prop::collection::vec(mutation(), 1..6)) {
        let seed = &seeds()[which];
        all_readers(&mutate(seed, &ops))?;
    }
}

#[test]
fn the_seeds_are_valid() {
    let p = Path::new("seed");
    parse_rate_table(p, RATE_LONG, &RateColumns::default()).unwrap();
    parse_rate_table(p, RATE_WIDE, &RateColumns::default()).unwrap();
    parse_manual_segments(p, SEGMENTS).unwrap();
    parse_sim_config(p, SIM).unwrap();
    parse_calibration(p, &calibration_text()).unwrap();
    parse_plan(&plan_path(), PLAN).unwrap();
    let o = SeriesOptions { table_rate_column: Some("table_rate_dps".into()), ..SeriesOptions::default() };
    let mut r = SeriesReader::from_reader("s.csv", SERIES.as_bytes(), &o).unwrap();
    assert_eq!(r.next_block().unwrap().unwrap().len(), 4);
}

/// Inputs found by the fuzz targets and by these properties, kept as regression tests.
mod regressions {
    use super::*;

    fn check(bytes: &[u8]) {
        all_readers(bytes).unwrap();
    }

    /// Crash inputs of the cargo-fuzz runs: TOML errors that quoted a whole line of invalid UTF-8
    /// (replacement characters, 3 bytes each) gave messages of several KiB.
    #[test]
    fn fuzz_crashes() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz_regressions");
        for name in ["calibration-long-message.bin", "test_plan-long-message.bin"] {
            let bytes = std::fs::read(dir.join(name)).unwrap();
            let text = String::from_utf8_lossy(&bytes);
            let errors = [
                parse_calibration(Path::new("c.toml"), &text).map(|_| ()),
                parse_plan(&plan_path(), &text).map(|_| ()),
            ];
            for e in errors.into_iter().filter_map(Result::err) {
                let shown = e.to_string();
                assert!(shown.len() < 2000, "{name}: {} bytes: {shown}", shown.len());
            }
            check(&bytes);
        }
    }

    /// Crash and time-out inputs of the recording targets' runs (scripts/fuzz_recordings.sh): an
    /// `A` message of 2 bytes that the `px4-ulog` parser indexed past its end, a Parquet page in
    /// dictionary encoding without its dictionary (a panic inside the `parquet` crate), a
    /// Parquet page header declaring a list far beyond the end of the file. Each
    /// must end in a located error in words, without a panic message. The fuzz targets put the
    /// format's magic in front of an input that lacks it; so does this replay.
    #[test]
    fn recording_fuzz_crashes() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz_regressions");
        let tmp = tempfile::tempdir().unwrap();
        for (name, magic, words) in [
            ("ulog-short-add-message.bin", &b"ULog\x01\x12\x35"[..], "shorter than the 3 bytes of its fields"),
            ("parquet-dictionary-page-missing.bin", &b"PAR1"[..], "the Parquet reader failed on it"),
            // A page header whose Thrift list declares 2^31 elements past the end of the file:
            // skipped element by element with a read each (over 20 s) before reads at the end
            // of the file became errors.
            ("parquet-long-thrift-list.bin", &b"PAR1"[..], "not a readable Parquet file: the file ends here"),
        ] {
            let bytes = std::fs::read(dir.join(name)).unwrap();
            let bytes = if bytes.starts_with(magic) { bytes } else { [magic, &bytes[..]].concat() };
            let p = tmp.path().join(name);
            std::fs::write(&p, &bytes).unwrap();
            let e = gyrolab_io::recording::read_records(&p, &Default::default(), &[]).unwrap_err().to_string();
            assert!(e.contains(words), "{name}: {e}");
            assert!(!e.contains("panicked"), "{name}: {e}");
        }
    }

    #[test]
    fn known_inputs() {
        for input in [&b""[..], b"\n", b"\r", b"\xef\xbb\xbf", b"a\r\r\n", b"time_s,output_v\n0,+-1\n", b"#\0"] {
            check(input);
        }
    }
}
