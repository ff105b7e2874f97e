//! The time-series reader: good layouts, every bad input (with line and column), block and chunk
//! boundaries, and the static test of a file.

use gyrolab::units::OutputUnit;
use gyrolab_io::series::*;
use gyrolab_io::DataError;
use proptest::prelude::*;

fn read_str(text: &str, opts: &SeriesOptions) -> Result<SeriesData, DataError> {
    collect_series(SeriesReader::from_reader("t.csv", text.as_bytes(), opts)?)
}

fn err(text: &str, opts: &SeriesOptions) -> DataError {
    read_str(text, opts).expect_err("expected an error")
}

fn at(e: &DataError) -> (Option<u64>, Option<usize>) {
    (e.line, e.column.as_ref().map(|c| c.index))
}

fn tolerant() -> SeriesOptions {
    SeriesOptions { tolerant: true, ..SeriesOptions::default() }
}

#[test]
fn csv_with_bom_comments_blank_lines_crlf() {
    let text = "\u{feff}# comment\r\n\r\ntime_s, temp_c ,gyro_x_mv,rate_rad_s\r\n0,20.5,+1.5e3,-2\r\n# mid comment\r\n  \r\n0.01,20.6,1500.25,3E-2\r\n";
    let d = read_str(text, &SeriesOptions::default()).unwrap();
    assert_eq!(d.header.header_line, 3);
    assert_eq!(d.header.delimiter, Delimiter::Comma);
    assert_eq!(d.header.time_column, Some(1));
    assert_eq!(d.header.temperature_column, Some(2));
    let units: Vec<OutputUnit> = d.header.channels.iter().map(|c| c.unit).collect();
    assert_eq!(units, vec![OutputUnit::Millivolt, OutputUnit::RadPerSec]);
    assert_eq!(d.lines.to_vec(), vec![4, 7]);
    assert_eq!(d.time.unwrap(), vec![0.0, 0.01]);
    assert_eq!(d.temperature.unwrap(), vec![20.5, 20.6]);
    assert_eq!(d.channels, vec![vec![1500.0, 1500.25], vec![-2.0, 0.03]]);
}

#[test]
fn tsv_whitespace_and_sample_rate_without_time() {
    let d = read_str("time_s\toutput_v\n1\t2.5\n2\t2.6", &SeriesOptions::default()).unwrap();
    assert_eq!(d.header.delimiter, Delimiter::Tab);
    assert_eq!(d.channels[0], vec![2.5, 2.6], "a last line without a line end is read");
    let o = SeriesOptions { sample_rate_hz: Some(100.0), ..SeriesOptions::default() };
    let d = read_str("  output_v   counts_lsb\n  2.5   12\n2.6 \t 13  \n", &o).unwrap();
    assert_eq!(d.header.delimiter, Delimiter::Whitespace);
    assert!(d.time.is_none());
    assert_eq!(d.channels, vec![vec![2.5, 2.6], vec![12.0, 13.0]]);
    assert_eq!(d.header.sample_rate_hz, Some(100.0));
}

#[test]
fn unit_override_and_channel_selection() {
    let o = SeriesOptions { column_units: vec![("sensor".into(), OutputUnit::Volt)], ..SeriesOptions::default() };
    let d = read_str("time_s,sensor\n0,1\n", &o).unwrap();
    assert_eq!(d.header.channels[0].unit, OutputUnit::Volt);
    let o = SeriesOptions { channels: Some(vec!["output_v".into()]), ..SeriesOptions::default() };
    let d = read_str("time_s,status_flag,output_v\n0,abc,1\n", &o).unwrap();
    assert_eq!(d.header.columns[1].role, ColumnRole::Ignored);
    assert_eq!(d.channels, vec![vec![1.0]]);
    let o = SeriesOptions { channels: Some(vec!["output_mv".into()]), ..SeriesOptions::default() };
    let e = err("time_s,output_v\n0,1\n", &o);
    assert!(e.message.contains("'output_mv' is not in the header"), "{e}");
}

#[test]
fn text_in_a_number_names_line_column_and_text() {
    let e = err("time_s,output_v\n0,1\n1,abc\n", &SeriesOptions::default());
    assert_eq!(at(&e), (Some(3), Some(2)));
    assert_eq!(e.column.as_ref().unwrap().name.as_deref(), Some("output_v"));
    assert!(e.message.contains("found 'abc', expected a number"), "{e}");
    let e = err("time_s,output_v\n0,1\n1.5x,2\n", &SeriesOptions::default());
    assert_eq!(at(&e), (Some(3), Some(1)));
    assert!(e.message.contains("'1.5x'"), "{e}");
    assert_eq!(e.to_string(), "t.csv:3:1: column 'time_s': found '1.5x', expected a number");
}

#[test]
fn wrong_field_counts() {
    let e = err("time_s,output_v,temp_c\n0,1,2\n1,2\n", &SeriesOptions::default());
    assert_eq!(at(&e), (Some(3), Some(3)));
    assert!(e.message.contains("found 2 fields, expected 3"), "{e}");
    let e = err("time_s,output_v\n0,1\n\n1,2,3\n", &SeriesOptions::default());
    assert_eq!(at(&e), (Some(4), Some(3)));
    assert!(e.message.contains("found 3 fields, expected 2"), "{e}");
    let o = SeriesOptions { sample_rate_hz: Some(1.0), ..SeriesOptions::default() };
    let e = err("output_v gyro_y_v\n1 2\n3\n", &o);
    assert_eq!(at(&e), (Some(3), Some(2)));
    assert!(e.message.contains("found 1 fields, expected 2"), "{e}");
}

#[test]
fn nan_and_empty_cells_are_errors_or_listed_when_tolerant() {
    let e = err("time_s,output_v\n0,1\n1,NaN\n", &SeriesOptions::default());
    assert_eq!(at(&e), (Some(3), Some(2)));
    assert!(e.message.contains("found 'NaN', expected a finite number"), "{e}");
    let e = err("time_s,output_v\n0,\n", &SeriesOptions::default());
    assert_eq!(at(&e), (Some(2), Some(2)));
    assert!(e.message.contains("found an empty cell"), "{e}");
    let e = err("time_s,output_v\n0,inf\n", &tolerant());
    assert_eq!(at(&e), (Some(2), Some(2)));
    let d = read_str("time_s,output_v\n0,1\n1,nan\n2,\n3,4\n", &tolerant()).unwrap();
    assert!(d.channels[0][1].is_nan() && d.channels[0][2].is_nan());
    assert_eq!(d.quality.missing_cells, 2);
    let first: Vec<(u64, usize, &str)> =
        d.quality.first_missing.iter().map(|m| (m.line, m.column, m.text.as_str())).collect();
    assert_eq!(first, vec![(3, 2, "nan"), (4, 2, "")]);
}

#[test]
fn empty_header_only_and_comment_only_files() {
    for text in ["", "\n\n", "# only a comment\n"] {
        let e = err(text, &SeriesOptions::default());
        assert!(e.message.contains("the file is empty"), "{e}");
        assert_eq!(at(&e), (None, None));
    }
    let e = err("# c\ntime_s,output_v\n# no data\n", &SeriesOptions::default());
    assert_eq!(at(&e), (Some(2), None));
    assert!(e.message.contains("no data rows"), "{e}");
}

#[test]
fn header_errors() {
    let e = err("time_s,output_v,Output_V\n0,1,2\n", &SeriesOptions::default());
    assert_eq!(at(&e), (Some(1), Some(3)));
    assert!(e.message.contains("column 2 'output_v' and column 3 'Output_V'"), "{e}");
    // A selected column whose bracketed unit is unknown is an error naming it and the units.
    let sel = SeriesOptions { channels: Some(vec!["output".into()]), ..SeriesOptions::default() };
    let e = err("# x\ntime_s,output [furlong]\n0,1\n", &sel);
    assert_eq!(at(&e), (Some(2), Some(2)));
    assert!(e.message.contains("unknown unit 'furlong'"), "{e}");
    assert!(e.message.contains("v, mv, lsb, dps, rad_s"), "{e}");
    // A time column whose unit is not a time.
    let e = err("time [v],output_v\n0,1\n", &SeriesOptions::default());
    assert_eq!(at(&e), (Some(1), Some(1)));
    assert!(e.message.contains("not a time unit"), "{e}");
    let e = err("temp_k,output_v\n0,1\n", &SeriesOptions { sample_rate_hz: Some(1.0), ..SeriesOptions::default() });
    assert_eq!(at(&e), (Some(1), Some(1)));
    let e = err("output_v\n1\n", &SeriesOptions::default());
    assert!(e.message.contains("no time column"), "{e}");
    let e = err("time_s,temp_c\n0,1\n", &SeriesOptions::default());
    assert!(e.message.contains("no output channel"), "{e}");
}

proptest! {
    #[test]
    fn values_round_trip_exactly_for_any_chunk_size(
        rows in prop::collection::vec((any::<f64>(), any::<f64>()), 1..60),
        chunk in 16usize..200,
        block_rows in 1usize..20,
        sep in prop::sample::select(vec![",", "\t", " ", ";"]),
        comments in any::<bool>(),
    ) {
        // Magnitudes above MAX_MAGNITUDE are refused by design (they would overflow the figures).
        let small = |v: &f64| v.abs() <= gyrolab_io::text::MAX_MAGNITUDE;
        let rows: Vec<(f64, f64)> = rows.into_iter().filter(|(a, b)| small(a) && small(b)).collect();
        prop_assume!(!rows.is_empty());
        let mut text = format!("time_s{sep}output_v\n");
        let mut lines = Vec::new();
        let mut line = 1u64;
        for (i, (t, x)) in rows.iter().enumerate() {
            if comments && i % 3 == 0 {
                text.push_str("# c\n\n");
                line += 2;
            }
            // Rust's Display gives the shortest text that parses back to the same f64; '+' and exponents too.
            let tt = if i % 2 == 0 { format!("{t:e}") } else { format!("{t}") };
            let xt = if x.is_sign_positive() && i % 4 == 1 { format!("+{x}") } else { format!("{x}") };
            text.push_str(&format!("{tt}{sep}{xt}\n"));
            line += 1;
            lines.push(line);
        }
        let o = SeriesOptions { chunk_bytes: chunk, block_rows, ..SeriesOptions::default() };
        let d = read_str(&text, &o).unwrap();
        let t: Vec<f64> = rows.iter().map(|r| r.0).collect();
        let x: Vec<f64> = rows.iter().map(|r| r.1).collect();
        prop_assert_eq!(d.time.unwrap(), t);
        prop_assert_eq!(&d.channels[0], &x);
        prop_assert_eq!(d.lines.to_vec(), lines);
    }
}

proptest! {
    /// The plain-decimal fast path returns exactly what the full parser returns.
    #[test]
    fn plain_decimal_fast_path_is_bit_exact(int in 0u64..10_000_000, frac in 0u64..100_000_000, width in 0usize..9, sign in 0u8..3) {
        let sign = ["", "-", "+"][sign as usize];
        let frac = format!("{frac:08}");
        let text = if width == 0 { format!("{sign}{int}") } else { format!("{sign}{int}.{}", &frac[..width]) };
        let full: f64 = text.trim_start_matches('+').parse().unwrap();
        // At most 7 + 8 = 15 digits: the fast path must take it, and agree to the bit.
        let fast = gyrolab_io::series::plain_decimal(text.as_bytes());
        prop_assert!(fast.is_some(), "{} declined", text);
        if let Some((v, n)) = fast {
            prop_assert_eq!(n, text.len());
            prop_assert_eq!(v.to_bits(), full.to_bits(), "{}", text);
        }
        // Followed by a delimiter and more text, the same value and length.
        let padded = format!("{text},12345678.9\n");
        prop_assert_eq!(gyrolab_io::series::plain_decimal(padded.as_bytes()), fast);
    }

    /// On any text made of number characters, whatever the fast path accepts is exactly what
    /// the full parser reads (value and length).
    #[test]
    fn plain_decimal_agrees_with_full_parser_on_any_text(text in "[-+0-9.eE,x]{0,40}") {
        if let Some((v, n)) = gyrolab_io::series::plain_decimal(text.as_bytes()) {
            let (full, m) = fast_float2::parse_partial::<f64, _>(text.as_bytes()).unwrap();
            prop_assert_eq!(n, m, "{}", text);
            prop_assert_eq!(v.to_bits(), full.to_bits(), "{}", text);
        }
    }

    /// Numbers with exponents, as `%e` writes them: read bit-identical to the full parser, or
    /// declined (exponents beyond Clinger's exact range).
    #[test]
    fn exponent_decimals_are_exact(neg in any::<bool>(), int in 0u64..10, frac in "[0-9]{0,14}", e in -40i32..40, big in any::<bool>()) {
        let text = format!("{}{int}.{frac}{}{e:+03}", if neg { "-" } else { "" }, if big { "E" } else { "e" });
        if let Some((v, n)) = gyrolab_io::series::plain_decimal(text.as_bytes()) {
            let (full, m) = fast_float2::parse_partial::<f64, _>(text.as_bytes()).unwrap();
            prop_assert_eq!(n, m, "{}", text);
            prop_assert_eq!(v.to_bits(), full.to_bits(), "{}", text);
        } else {
            prop_assert!((e - frac.len() as i32).abs() > 22, "{} declined", text);
        }
    }

    /// Long digit runs (across the eight-byte groups) are read exactly or declined.
    #[test]
    fn plain_decimal_long_runs(int in "[0-9]{1,20}", frac in "[0-9]{0,20}") {
        let text = if frac.is_empty() { int.clone() } else { format!("{int}.{frac}") };
        let full: f64 = text.parse().unwrap();
        match gyrolab_io::series::plain_decimal(text.as_bytes()) {
            Some((v, n)) => {
                prop_assert!(int.len() + frac.len() <= 15, "{} taken", text);
                prop_assert_eq!(n, text.len());
                prop_assert_eq!(v.to_bits(), full.to_bits(), "{}", text);
            }
            None => prop_assert!(int.len() + frac.len() > 15, "{} declined", text),
        }
    }
}

#[test]
fn plain_decimal_declines_what_it_cannot_do_exactly() {
    use gyrolab_io::series::plain_decimal;
    // Exponents within Clinger's exact range are read (correctly rounded), others declined.
    assert_eq!(plain_decimal(b"1e5"), Some((1e5, 3)));
    assert_eq!(plain_decimal(b"-1.2345670e-02,"), Some((-1.234567e-2, 14)));
    assert_eq!(plain_decimal(b"1e23"), None);
    assert_eq!(plain_decimal(b"1e-30"), None);
    assert_eq!(plain_decimal(b"1e"), None);
    assert_eq!(plain_decimal(b"1e1234"), None);
    assert_eq!(plain_decimal(b"1234567890.123456"), None); // 16 digits
    assert_eq!(plain_decimal(b"nan"), None);
    assert_eq!(plain_decimal(b"-"), None);
    assert_eq!(plain_decimal(b"1.2.3"), None);
    assert_eq!(plain_decimal(b"2.5,1"), Some((2.5, 3)));
    assert_eq!(plain_decimal(b"-0.001\n"), Some((-0.001, 6)));
    assert_eq!(plain_decimal(b".5"), Some((0.5, 2)));
}

/// A cell of a random row: mostly plain decimals (the fast path's), sometimes what only the
/// general path reads or reports.
fn cell() -> impl Strategy<Value = String> {
    prop_oneof![
        6 => (0u8..3, 0u64..100_000_000, 0usize..9, 0u64..100_000_000).prop_map(|(s, i, w, f)| {
            let sign = ["", "-", "+"][s as usize];
            if w == 0 { format!("{sign}{i}") } else { format!("{sign}{i}.{}", &format!("{f:08}")[..w]) }
        }),
        1 => prop::sample::select(vec!["1e3", "", "NaN", " 2.5", "2.5 ", "x", "1234567890.1234567", ".5", "5."])
            .prop_map(String::from),
    ]
}

/// A file of random rows (`time_s`, `output_v`, `other_v`): every delimiter, CRLF or LF, with
/// comment and blank lines when `comments`.
fn random_file(rows: &[Vec<String>], sep: &str, crlf: bool, comments: bool) -> String {
    let eol = if crlf { "\r\n" } else { "\n" };
    let mut text = format!("time_s{sep}output_v{sep}other_v{eol}");
    for (i, row) in rows.iter().enumerate() {
        if comments && i % 5 == 2 {
            text.push_str(&format!("# note{eol}{eol}"));
        }
        text.push_str(&row.join(sep));
        text.push_str(eol);
    }
    text
}

proptest! {
    /// The fast row path changes nothing: on random files (every delimiter, CRLF or LF, comments,
    /// blank lines, odd cells, tolerant or strict) the reader gives the same values (to the bit),
    /// line numbers and findings, or the same error, with it and without it.
    #[test]
    fn fast_rows_change_nothing(
        rows in prop::collection::vec(prop::collection::vec(cell(), 2..4), 1..40),
        sep in prop::sample::select(vec![",", "\t", " ", ";"]),
        crlf in any::<bool>(),
        comments in any::<bool>(),
        tolerant in any::<bool>(),
        chunk in 16usize..300,
        block_rows in 1usize..30,
    ) {
        let text = random_file(&rows, sep, crlf, comments);
        let with = SeriesOptions { tolerant, chunk_bytes: chunk, block_rows, ..SeriesOptions::default() };
        let without = SeriesOptions { fast_rows: false, ..with.clone() };
        match (read_str(&text, &with), read_str(&text, &without)) {
            (Ok(a), Ok(b)) => {
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                prop_assert_eq!(&a.lines, &b.lines);
                prop_assert_eq!(bits(&a.time.unwrap()), bits(&b.time.unwrap()));
                prop_assert_eq!(a.channels.len(), b.channels.len());
                for (ca, cb) in a.channels.iter().zip(&b.channels) {
                    prop_assert_eq!(bits(ca), bits(cb));
                }
                prop_assert_eq!(a.quality, b.quality);
            }
            (Err(a), Err(b)) => prop_assert_eq!(a.to_string(), b.to_string()),
            (a, b) => prop_assert!(false, "fast {:?} vs general {:?}\n{:?}", a.map(|d| d.lines.to_vec()), b.map(|d| d.lines.to_vec()), text),
        }
    }
}

proptest! {
    /// The parallel path of `read_series_all` changes nothing: on random files (as above) it
    /// gives the same values (to the bit), lines and findings as the sequential reader, or the
    /// same error, whatever the thread count and batch size.
    #[test]
    fn parallel_reading_changes_nothing(
        rows in prop::collection::vec(prop::collection::vec(cell(), 2..4), 1..60),
        sep in prop::sample::select(vec![",", "\t", " ", ";"]),
        crlf in any::<bool>(),
        comments in any::<bool>(),
        tolerant in any::<bool>(),
        threads in 1usize..5,
        batch in 16usize..400,
    ) {
        let text = random_file(&rows, sep, crlf, comments);
        let opts = SeriesOptions { tolerant, chunk_bytes: 64, ..SeriesOptions::default() };
        let parallel = SeriesReader::from_reader("t.csv", text.as_bytes(), &opts)
            .and_then(|r| collect_series_in_parallel(r, threads, batch));
        match (parallel, read_str(&text, &opts)) {
            (Ok(a), Ok(b)) => {
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                prop_assert_eq!(&a.lines, &b.lines);
                prop_assert_eq!(bits(&a.time.unwrap()), bits(&b.time.unwrap()));
                for (ca, cb) in a.channels.iter().zip(&b.channels) {
                    prop_assert_eq!(bits(ca), bits(cb));
                }
                prop_assert_eq!(a.quality, b.quality);
            }
            (Err(a), Err(b)) => prop_assert_eq!(a.to_string(), b.to_string()),
            (a, b) => prop_assert!(false, "parallel {:?} vs sequential {:?}\n{:?}", a.map(|d| d.lines.to_vec()), b.map(|d| d.lines.to_vec()), text),
        }
    }
}

proptest! {
    /// Reading a file in parallel byte ranges changes nothing: on random files (as above, with
    /// the time stamps kept plainly or compactly) it gives the same values (to the bit), lines
    /// and findings as the sequential reader, or the same error, whatever the number of ranges
    /// and the chunk size (small chunks: lines cross chunk and range bounds everywhere).
    #[test]
    fn reading_in_ranges_changes_nothing(
        rows in prop::collection::vec(prop::collection::vec(cell(), 2..4), 1..60),
        sep in prop::sample::select(vec![",", "\t", " ", ";"]),
        crlf in any::<bool>(),
        comments in any::<bool>(),
        tolerant in any::<bool>(),
        compact_time in any::<bool>(),
        zero_rows in any::<bool>(),
        no_last_eol in any::<bool>(),
        ranges in 1usize..6,
        chunk in 64usize..400,
    ) {
        let mut text = random_file(&rows, sep, crlf, comments);
        if no_last_eol {
            text = text.trim_end_matches(['\r', '\n']).to_string();
        }
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.csv");
        std::fs::write(&path, &text).unwrap();
        let opts = SeriesOptions { tolerant, compact_time, zero_rows_missing: zero_rows, chunk_bytes: 64, ..SeriesOptions::default() };
        let plain = SeriesOptions { compact_time: false, ..opts.clone() };
        let sequential = SeriesReader::open(&path, &plain).and_then(collect_series);
        match (read_series_in_ranges(&path, &opts, ranges, chunk), sequential) {
            (Ok(a), Ok(b)) => {
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                prop_assert_eq!(&a.lines, &b.lines);
                let time = match (a.time, a.time_compact) {
                    (Some(t), None) => t,
                    (None, Some(c)) => c.to_vec(),
                    other => panic!("time kept as {other:?}"),
                };
                prop_assert_eq!(bits(&time), bits(&b.time.unwrap()));
                prop_assert_eq!(a.channels.len(), b.channels.len());
                for (ca, cb) in a.channels.iter().zip(&b.channels) {
                    prop_assert_eq!(bits(ca), bits(cb));
                }
                prop_assert_eq!(a.quality, b.quality);
            }
            (Err(a), Err(b)) => prop_assert_eq!(a.to_string(), b.to_string()),
            (a, b) => prop_assert!(false, "ranges {:?} vs sequential {:?}\n{:?}", a.map(|d| d.lines.to_vec()), b.map(|d| d.lines.to_vec()), text),
        }
    }
}

/// A file larger than the reader's sample of bytes per line, whose later lines are much shorter
/// than its first ones: the ranges' rows outrun their regions and are kept apart, with the same
/// values as the sequential reader.
#[test]
fn ranges_whose_rows_outrun_their_regions() {
    let mut text = String::from("time_s,output_v\n");
    for i in 0..60_000 {
        text.push_str(&format!("{:.6},{:.12}\n", i as f64 * 0.01 + 1000.0, (i % 97) as f64 * 0.123456789));
    }
    for i in 60_000..400_000 {
        text.push_str(&format!("{},{}\n", i, i % 7));
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.csv");
    std::fs::write(&path, &text).unwrap();
    // The reader's first chunk (its sample of bytes per line) holds long lines only.
    let opts = SeriesOptions { chunk_bytes: 1 << 16, ..SeriesOptions::default() };
    let a = read_series_in_ranges(&path, &opts, 3, 4096).unwrap();
    let b = read_str(&text, &SeriesOptions::default()).unwrap();
    assert_eq!(a.lines, b.lines);
    assert_eq!(a.time, b.time);
    assert_eq!(a.channels, b.channels);
    assert_eq!(a.channels[0].len(), 400_000);
}

/// A line over the length limit and a NUL byte, each in a later range: the same error, at the
/// same line, as the sequential reader (the message names the file's line, not the range's).
#[test]
fn ranges_report_long_lines_and_nul_bytes_at_the_files_line() {
    let rows: Vec<String> =
        (0..120_000).map(|i| format!("{:.2},{:.6}", i as f64 * 0.01, (i % 13) as f64 * 0.1)).collect();
    let dir = tempfile::tempdir().unwrap();
    let mut long = rows.clone();
    long[90_000] = format!("1.0,{}", "9".repeat(MAX_LINE_BYTES + 5));
    let mut nul = rows.join("\n").into_bytes();
    let at = nul.len() * 4 / 5;
    nul[at] = 0;
    for (name, text) in [
        ("long.csv", format!("time_s,rate_dps\n{}\n", long.join("\n")).into_bytes()),
        ("nul.csv", {
            let mut t = b"time_s,rate_dps\n".to_vec();
            t.extend_from_slice(&nul);
            t
        }),
    ] {
        let path = dir.path().join(name);
        std::fs::write(&path, &text).unwrap();
        let ranges = read_series_in_ranges(&path, &SeriesOptions::default(), 3, 4096).unwrap_err();
        let sequential = SeriesReader::open(&path, &SeriesOptions::default()).and_then(collect_series).unwrap_err();
        assert_eq!(ranges.to_string(), sequential.to_string(), "{name}");
        assert!(ranges.line.unwrap() > 80_000, "{name}: {ranges}");
    }
}

/// Every batch of a [`BatchReader`] joined: lines, time, channels and findings, as
/// [`collect_series`] gives them (the time stamps plainly).
fn collect_batches<R: std::io::Read>(mut b: BatchReader<R>) -> Result<SeriesData, DataError> {
    let header = b.header().clone();
    let mut lines = LineMap::default();
    let mut time = header.time_column.map(|_| Vec::new());
    let mut channels = vec![Vec::new(); header.channels.len()];
    while let Some(batch) = b.next_batch()? {
        assert!(!batch.is_empty(), "a batch without rows is skipped, not handed over");
        assert!(batch.channels.iter().all(|c| c.len() == batch.len()));
        lines.extend_from_slice(&batch.lines);
        if let (Some(t), Some(bt)) = (time.as_mut(), batch.time) {
            t.extend_from_slice(&bt);
        }
        for (c, bc) in channels.iter_mut().zip(batch.channels) {
            c.extend_from_slice(&bc);
        }
    }
    assert!(b.next_batch().unwrap().is_none(), "spent after the end");
    let quality = b.quality().clone();
    Ok(SeriesData { header, lines, time, time_compact: None, temperature: None, table_rate: None, channels, quality })
}

proptest! {
    /// Streaming a file in parallel batches changes nothing: on random files (every delimiter,
    /// CRLF or LF, comments and blank lines, odd cells, tolerant or strict, dropout rows marked
    /// or not, with or without a last line end) the batches joined give the same values (to the
    /// bit), lines and findings as the sequential reader, or the same error at the same line,
    /// whatever the thread count and the batch size (small batches: lines cross batch and piece
    /// bounds everywhere, CRLF pairs split between batches too).
    #[test]
    fn reading_in_parallel_batches_changes_nothing(
        rows in prop::collection::vec(prop::collection::vec(cell(), 2..4), 1..60),
        sep in prop::sample::select(vec![",", "\t", " ", ";"]),
        crlf in any::<bool>(),
        comments in any::<bool>(),
        tolerant in any::<bool>(),
        zero_rows in any::<bool>(),
        repeated_rows in any::<bool>(),
        no_last_eol in any::<bool>(),
        threads in 1usize..5,
        batch in 16usize..400,
    ) {
        let mut text = random_file(&rows, sep, crlf, comments);
        if no_last_eol {
            text = text.trim_end_matches(['\r', '\n']).to_string();
        }
        let opts = SeriesOptions {
            tolerant,
            zero_rows_missing: zero_rows,
            repeated_rows_missing: repeated_rows,
            chunk_bytes: 64,
            ..SeriesOptions::default()
        };
        let batched = SeriesReader::from_reader("t.csv", text.as_bytes(), &opts)
            .and_then(|r| collect_batches(BatchReader::new(r, threads, batch)));
        match (batched, read_str(&text, &opts)) {
            (Ok(a), Ok(b)) => {
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                prop_assert_eq!(&a.lines, &b.lines);
                prop_assert_eq!(bits(&a.time.unwrap()), bits(&b.time.unwrap()));
                prop_assert_eq!(a.channels.len(), b.channels.len());
                for (ca, cb) in a.channels.iter().zip(&b.channels) {
                    prop_assert_eq!(bits(ca), bits(cb));
                }
                prop_assert_eq!(a.quality, b.quality);
            }
            (Err(a), Err(b)) => {
                prop_assert_eq!(a.to_string(), b.to_string());
                prop_assert_eq!(at(&a), at(&b));
            }
            (a, b) => prop_assert!(false, "batches {:?} vs sequential {:?}\n{:?}", a.map(|d| d.lines.to_vec()), b.map(|d| d.lines.to_vec()), text),
        }
    }
}

/// A larger CRLF file in batches of several sizes (1 KiB to 1 MiB, none a divisor of the line
/// length, so batch and piece bounds fall inside lines and between `\r` and `\n`) on 1 to 4
/// threads: the same rows as the sequential reader; then a bad cell, a NaN (strict) and a
/// NUL byte deep in the file: the same error at the same line (and column) as the
/// sequential reader, the rows before it handed over first.
#[test]
fn batches_of_several_sizes_equal_the_sequential_reader_and_locate_errors() {
    let mut text = String::from("# a comment\r\ntime_s,gx_dps,gy_dps\r\n");
    for i in 0..60_000u64 {
        if i % 10_007 == 5 {
            text.push_str("\r\n# mid comment\r\n");
        }
        text.push_str(&format!(
            "{}.{:03},{:.6},-{:.5}\r\n",
            i / 1000,
            i % 1000,
            (i % 97) as f64 * 0.0123,
            (i % 89) as f64 * 0.7
        ));
    }
    // Small chunks for the header: the batches are then of the size asked for.
    let opts = SeriesOptions { tolerant: true, chunk_bytes: 64, ..SeriesOptions::default() };
    let plain = read_str(&text, &opts).unwrap();
    assert_eq!(plain.lines.len(), 60_000);
    for batch in [1000, 4099, 65_537, 1 << 20] {
        for threads in 1..=4 {
            let r = SeriesReader::from_reader("t.csv", text.as_bytes(), &opts).unwrap();
            let b = BatchReader::new(r, threads, batch);
            assert_eq!(b.batch_bytes(), batch);
            let a = collect_batches(b).unwrap();
            assert_eq!(a.lines, plain.lines, "batch {batch}, {threads} threads");
            assert_eq!(a.time, plain.time);
            assert_eq!(a.channels, plain.channels);
            assert_eq!(a.quality, plain.quality);
        }
    }
    let lines: Vec<&str> = text.split_inclusive("\r\n").collect();
    let strict = SeriesOptions { chunk_bytes: 64, ..SeriesOptions::default() };
    for (what, line, cell) in [("bad", 41_234, "12.5x"), ("nan", 52_001, "NaN"), ("nul", 30_003, "1\0")] {
        let mut broken: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
        broken[line - 1] = format!("1.0,{cell},2.0\r\n");
        let broken = broken.concat();
        let sequential = read_str(&broken, &strict).unwrap_err();
        assert_eq!(sequential.line, Some(line as u64), "{what}: {sequential}");
        for batch in [4099, 1 << 20] {
            let r = SeriesReader::from_reader("t.csv", broken.as_bytes(), &strict).unwrap();
            let mut b = BatchReader::new(r, 2, batch);
            let mut last_line = 0;
            let e = loop {
                match b.next_batch() {
                    Ok(Some(rows)) => last_line = *rows.lines.last().unwrap(),
                    Ok(None) => panic!("{what}: no error"),
                    Err(e) => break e,
                }
            };
            assert_eq!(e.to_string(), sequential.to_string(), "{what}, batch {batch}");
            assert_eq!(at(&e), at(&sequential));
            // The rows before the error were handed over, up to the failing piece (lines of
            // about 27 bytes: fewer than batch / 20 lines a batch).
            assert!(
                last_line < line as u64 && last_line + (batch / 20) as u64 > line as u64,
                "{what}: rows up to {last_line}"
            );
            assert!(b.next_batch().unwrap().is_none(), "spent after the error");
        }
    }
}

/// `;`- and tab-separated files with decimal commas (issue 55), as a European spreadsheet
/// exports them, read as the same file with points by the sequential reader, the parallel
/// batches and the parallel ranges; a headerless one too; a field with two commas is located.
#[test]
fn decimal_commas_are_read_by_every_path_of_the_series_reader() {
    let mut dotted = String::from("time_s,gyro_x_dps,temp_c\n");
    let mut semicolon = String::from("time_s;gyro_x_dps;temp_c\n");
    let mut tabbed = String::from("time_s\tgyro_x_dps\ttemp_c\n");
    let mut headerless = String::new();
    for i in 0..5_000 {
        // The first row holds integers only: the commas come later.
        let (t, w, c) =
            (i as f64 * 0.01, if i == 0 { 1.0 } else { 0.25 + (i % 13) as f64 * 1.5e-3 }, 21.0 + (i % 7) as f64 * 0.1);
        dotted.push_str(&format!("{t},{w},{c}\n"));
        let dc = |x: f64| format!("{x}").replace('.', ",");
        semicolon.push_str(&format!("{};{};{}\n", dc(t), dc(w), dc(c)));
        tabbed.push_str(&format!("{}\t{}\t{}\n", dc(t), dc(w), dc(c)));
        if i > 0 {
            headerless.push_str(&format!("{};{}\n", dc(t), dc(w)));
        }
    }
    let plain = read_str(&dotted, &SeriesOptions::default()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    for (name, text) in [("semicolon", &semicolon), ("tab", &tabbed)] {
        let seq = read_str(text, &SeriesOptions::default()).unwrap_or_else(|e| panic!("{name}: {e}"));
        let path = dir.path().join(format!("{name}.csv"));
        std::fs::write(&path, text).unwrap();
        let opts = SeriesOptions { chunk_bytes: 4096, ..SeriesOptions::default() };
        let batches = SeriesReader::from_reader("t.csv", text.as_bytes(), &opts)
            .and_then(|r| collect_series_in_parallel(r, 2, 1000))
            .unwrap();
        let ranges = read_series_in_ranges(&path, &opts, 3, 4096).unwrap();
        for (how, d) in [("sequential", &seq), ("batches", &batches), ("ranges", &ranges)] {
            assert_eq!(d.channels, plain.channels, "{name} {how}");
            assert_eq!(d.time, plain.time, "{name} {how}");
            assert_eq!(d.temperature, plain.temperature, "{name} {how}");
            assert_eq!(d.lines, plain.lines, "{name} {how}");
        }
    }
    // A first data row with decimal commas: said in the header.
    let later = semicolon.replacen("0;1;21\n", "", 1);
    assert!(read_str(&later, &SeriesOptions::default()).unwrap().header.decimal_comma);
    assert!(!plain.header.decimal_comma);
    // Without a header row: the decimal commas are numbers, not column names.
    let d = read_str(&headerless, &SeriesOptions { sample_rate_hz: Some(100.0), ..SeriesOptions::default() }).unwrap();
    assert!(d.header.headerless && d.header.decimal_comma);
    assert_eq!(d.channels[0].len(), 4_999);
    assert_eq!((d.channels[0][0], d.channels[1][0]), (0.01, 0.2515));
    // Two commas in a number: located; in a comma-separated file a comma stays a delimiter.
    let e = err("time_s;gyro_x_dps\n0,01;0,25\n0,02;0,2,5\n", &SeriesOptions::default());
    assert_eq!(at(&e), (Some(3), Some(2)), "{e}");
    let e = err("time_s,gyro_x_dps\n0.01,0,25\n", &SeriesOptions::default());
    assert_eq!(e.line, Some(2), "{e}");
}
