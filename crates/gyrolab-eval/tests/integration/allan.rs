//! `analyse_file` on white rate noise written here from a seeded normal generator: the OADEV and
//! the slope-line ARW against the generating N, a gap in the time column, and the deviation at
//! m = 1 against a direct computation.

use gyrolab::allan::TauList;
use gyrolab_eval::allan::{analyse_file, AllanRequest, GapPolicy};
use gyrolab_eval::EvalError;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use std::fmt::Write as _;
use std::path::Path;

/// Writes `values` as `time_s,rate_dps` at 100 Hz (`{:?}`: the shortest text that reads back
/// to the same number); `gap_after` shifts every time stamp after that sample by 10 s.
fn write_rates(path: &Path, values: &[f64], gap_after: Option<usize>) {
    let mut s = String::from("time_s,rate_dps\n");
    for (i, v) in values.iter().enumerate() {
        let shift = if gap_after.is_some_and(|g| i > g) { 10.0 } else { 0.0 };
        writeln!(s, "{:?},{v:?}", i as f64 * 0.01 + shift).unwrap();
    }
    std::fs::write(path, s).unwrap();
}

fn white(n: usize, sigma: f64, seed: u64) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let d = Normal::new(0.0, sigma).unwrap();
    (0..n).map(|_| d.sample(&mut rng)).collect()
}

/// One hour at 100 Hz of white rate noise with ARW N = 0.5 deg/sqrt(h): per-sample sigma
/// (N / 60) / sqrt(0.01 s) deg/s, so the Allan deviation is (N / 60) / sqrt(tau), N/60 deg/s at
/// tau = 1 s. The OADEV at tau = 1 s (m = 100 of 360 000 samples) has about
/// 3 x 360 000 / (2 x 100) = 5400 degrees of freedom, a relative standard error of
/// 1 / sqrt(2 x 5400) = 1 %: 5 % is 5 sigma. The slope-line N reads the -1/2 line at 1 s, fitted
/// over several such points: 3 % is at least 3 sigma.
#[test]
fn white_noise_oadev_and_arw_match_the_generating_n() {
    const N_DEG_RT_H: f64 = 0.5;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("white.csv");
    let sigma = N_DEG_RT_H / 60.0 / 0.01f64.sqrt();
    write_rates(&path, &white(360_000, sigma, 2024), None);
    let request = AllanRequest { taus: TauList::Decade, ..AllanRequest::new(&path) };
    let outcome = analyse_file(&request).unwrap();
    assert_eq!(outcome.sample_interval_s, 0.01);
    let a = &outcome.analyses[0];
    assert_eq!(a.rate_unit, "deg/s");
    let p = a.curve.points.iter().find(|p| p.m == 100).expect("decade taus include m = 100");
    assert!((p.tau_s - 1.0).abs() < 1e-12);
    let want = N_DEG_RT_H / 60.0;
    assert!((p.deviation / want - 1.0).abs() < 0.05, "OADEV(1 s) = {}, N/60 = {want}", p.deviation);
    let n = a.slope_lines.as_ref().expect("slope lines for deg/s data").coefficients.arw_deg_rt_h.unwrap();
    assert!((n / N_DEG_RT_H - 1.0).abs() < 0.03, "slope-line N = {n}, truth {N_DEG_RT_H}");
}

/// A 10 s gap in the time column (1000 samples missing): computed over by default, with a note
/// naming the line of the first sample after the gap (the header is line 1, sample i is on line
/// i + 2); a data error naming that line under `GapPolicy::Error`.
#[test]
fn a_gap_is_computed_over_or_refused_naming_its_line() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("gap.csv");
    write_rates(&path, &white(2000, 0.1, 1), Some(999));
    let outcome = analyse_file(&AllanRequest::new(&path)).unwrap();
    let gaps = outcome.notes.iter().find_map(|n| match n {
        gyrolab_eval::allan::ReadNote::Gaps { count, missing, first, .. } => Some((*count, *missing, first.clone())),
        _ => None,
    });
    assert_eq!(gaps, Some((1, 1000, vec![(1002, 1000)])));
    // 3000 slots; at m = 1 every pair of neighbours but the one across the gap: 1998 terms.
    let a = &outcome.analyses[0];
    assert_eq!((a.curve.n_rate, a.curve.points[0].terms), (3000, 1998));
    let request = AllanRequest { gaps: GapPolicy::Error, ..AllanRequest::new(&path) };
    let e = analyse_file(&request).unwrap_err();
    match &e {
        EvalError::Data(d) => {
            assert_eq!(d.line, Some(1000 + 2), "{e}");
            assert!(d.message.contains("1000 sample(s) missing"), "{e}");
        }
        other => panic!("expected a data error, got {other:?}"),
    }
}

/// The deviation at m = 1 is sqrt(0.5 mean((y[i+1] - y[i])^2)), computed here from the
/// generated values (read back exactly), to 1e-12 relative.
#[test]
fn deviation_at_m1_is_the_direct_computation() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("short.csv");
    let y = white(20_000, 0.05, 77);
    write_rates(&path, &y, None);
    let outcome = analyse_file(&AllanRequest::new(&path)).unwrap();
    let p = &outcome.analyses[0].curve.points[0];
    assert_eq!(p.m, 1);
    let d2: f64 = y.windows(2).map(|w| (w[1] - w[0]).powi(2)).sum::<f64>() / (y.len() - 1) as f64;
    let direct = (0.5 * d2).sqrt();
    assert!((p.deviation - direct).abs() <= 1e-12 * direct, "{} vs {direct}", p.deviation);
}

/// `analyse_channel_borrowed` (the in-memory door of the Python package) against
/// `analyse_channel` (the owned samples of a file): the same curve and noise terms for samples
/// read where they are (deg/s) and for samples that need a conversion (rad/s); NaN read as a
/// missing sample or refused with its index, as asked.
#[test]
fn borrowed_samples_give_the_curve_of_owned_ones() {
    use gyrolab::allan::{AllanOptions, DeviationKind};
    use gyrolab::units::OutputUnit;
    use gyrolab_eval::allan::{analyse_channel, analyse_channel_borrowed, ChannelSetup};
    use gyrolab_eval::reference::ReferenceRequest;
    use gyrolab_io::series::{ChannelInfo, LineMap, UnitSource};
    let reference = ReferenceRequest::default().resolve().unwrap();
    let options = AllanOptions::new(DeviationKind::Oadev);
    let lines = LineMap::default();
    let setup = ChannelSetup {
        path: Path::new("<array>"),
        shown: "<array>".into(),
        topic: None,
        lines: &lines,
        tau0_s: 0.01,
        options: &options,
        reference: &reference,
        fit_range_s: None,
        uncalibrated_hint: "",
        allow_motion: false,
    };
    let mut x = white(60_000, 0.05, 11);
    for unit in [OutputUnit::DegPerSec, OutputUnit::RadPerSec] {
        let info = ChannelInfo { name: "x".into(), column: 1, unit, unit_source: UnitSource::Column };
        let owned = analyse_channel(&setup, &info, x.clone()).unwrap();
        for policy in [GapPolicy::Analyse, GapPolicy::Error] {
            let borrowed = analyse_channel_borrowed(&setup, &info, &x, Vec::new(), policy).unwrap();
            assert_eq!(borrowed.curve, owned.curve, "{unit:?}");
            assert_eq!(borrowed.slope_lines, owned.slope_lines, "{unit:?}");
        }
    }
    x[123] = f64::NAN;
    let info =
        ChannelInfo { name: "x".into(), column: 1, unit: OutputUnit::DegPerSec, unit_source: UnitSource::Column };
    let owned = analyse_channel(&setup, &info, x.clone()).unwrap();
    let borrowed = analyse_channel_borrowed(&setup, &info, &x, Vec::new(), GapPolicy::Analyse).unwrap();
    assert_eq!(borrowed.curve, owned.curve);
    // N - 1 terms at m = 1, less the two whose window (y_k, y_k+1) holds the missing sample
    assert_eq!(borrowed.curve.points[0].terms, 60_000 - 1 - 2);
    for unit in [OutputUnit::DegPerSec, OutputUnit::RadPerSec] {
        let info = ChannelInfo { name: "x".into(), column: 1, unit, unit_source: UnitSource::Column };
        let e = analyse_channel_borrowed(&setup, &info, &x, Vec::new(), GapPolicy::Error).unwrap_err().to_string();
        assert!(e.contains("x[123] = NaN is not a finite number"), "{unit:?}: {e}");
    }
}

/// Dropout rows need two or more channels: selecting one channel of a three-channel file that
/// has 40 all-zero rows leaves them as data, and a note says so and names the columns to read;
/// with two channels selected, they are found and treated as missing (the m = 1 term count
/// drops by the 41 intervals that touch them: 40 rows in one run). A one-channel file gets no note.
#[test]
fn a_one_channel_selection_says_dropouts_were_not_looked_for() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("three.csv");
    let (x, y, z) = (white(4000, 0.1, 7), white(4000, 0.1, 8), white(4000, 0.1, 9));
    let mut s = String::from("time_s,gx_dps,gy_dps,gz_dps\n");
    for i in 0..4000 {
        let zero = (2000..2040).contains(&i);
        let v = |c: &[f64]| if zero { 0.0 } else { c[i] };
        writeln!(s, "{:?},{:?},{:?},{:?}", i as f64 * 0.01, v(&x), v(&y), v(&z)).unwrap();
    }
    std::fs::write(&path, s).unwrap();
    let unchecked = |o: &gyrolab_eval::allan::AllanOutcome| {
        o.notes.iter().find_map(|n| match n {
            gyrolab_eval::allan::ReadNote::DropoutsUnchecked { read, not_read } => {
                Some((read.clone(), not_read.clone()))
            }
            _ => None,
        })
    };
    let dropouts = |o: &gyrolab_eval::allan::AllanOutcome| {
        o.notes.iter().any(|n| matches!(n, gyrolab_eval::allan::ReadNote::Dropouts { all_zero: 40, .. }))
    };
    let one = analyse_file(&AllanRequest { columns: vec!["gy_dps".into()], ..AllanRequest::new(&path) }).unwrap();
    assert_eq!(unchecked(&one), Some((vec!["gy_dps".to_string()], vec!["gx_dps".to_string(), "gz_dps".to_string()])));
    assert!(!dropouts(&one));
    assert_eq!(one.analyses[0].curve.points[0].terms, 3999, "the zeros are data");
    let two =
        analyse_file(&AllanRequest { columns: vec!["gy_dps".into(), "gz_dps".into()], ..AllanRequest::new(&path) })
            .unwrap();
    assert_eq!(unchecked(&two), None);
    assert!(dropouts(&two));
    assert_eq!(two.analyses[0].curve.points[0].terms, 3999 - 41, "the zero rows are missing samples");
    // A file with one channel column: nothing was selected out, no note.
    let single = dir.path().join("one.csv");
    write_rates(&single, &white(4000, 0.1, 3), None);
    assert_eq!(unchecked(&analyse_file(&AllanRequest::new(&single)).unwrap()), None);
}

/// Stamps in a column without a unit, read in seconds by assumption, that step by a whole
/// number of "seconds" (here 5: an Arduino's millis() at 200 Hz) give a warning naming the
/// column and the millisecond reading (200 Hz), in place of the plain "assumed" note; with the
/// unit given, or with stamps 0.01 s apart, there is none.
#[test]
fn whole_number_stamps_read_as_seconds_are_doubted() {
    use gyrolab_eval::allan::ReadNote;
    use gyrolab_eval::layout::LogLayout;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("millis.csv");
    let mut s = String::from("t,gx_dps\n");
    for (i, v) in white(3000, 0.1, 5).iter().enumerate() {
        writeln!(s, "{},{v:?}", 5 * i).unwrap();
    }
    std::fs::write(&path, s).unwrap();
    let doubt = |o: &gyrolab_eval::allan::AllanOutcome| {
        o.notes.iter().find_map(|n| match n {
            ReadNote::TimeUnitDoubt { column, step } => Some((column.clone(), *step, n.is_warning())),
            _ => None,
        })
    };
    let o = analyse_file(&AllanRequest::new(&path)).unwrap();
    assert_eq!(doubt(&o), Some(("t".to_string(), 5.0, true)));
    assert!(!o.notes.iter().any(|n| matches!(n, ReadNote::TimeUnit { .. })), "the warning replaces the note");
    assert!(o.notes.iter().any(|n| n.to_string().contains("then 200 Hz")));
    let layout = LogLayout { units: vec!["t=ms".into()], ..Default::default() };
    let o = analyse_file(&AllanRequest { layout, ..AllanRequest::new(&path) }).unwrap();
    assert_eq!(doubt(&o), None);
    assert!((o.sample_interval_s - 0.005).abs() < 1e-15);
    let plain = dir.path().join("plain.csv");
    write_rates(&plain, &white(3000, 0.1, 6), None);
    std::fs::write(&plain, std::fs::read_to_string(&plain).unwrap().replacen("time_s", "time", 1)).unwrap();
    assert_eq!(doubt(&analyse_file(&AllanRequest::new(&plain)).unwrap()), None);
}

/// A `rostopic echo -p` export: the message stamp is the time (not `%time`), `frame_id` (a name)
/// is skipped as text, and the orientation and covariance fields are one note, not one each.
#[test]
fn a_rostopic_export_reads_its_message_stamps_with_few_notes() {
    use gyrolab_eval::allan::ReadNote;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("imu.csv");
    let cov: Vec<String> = (0..9).map(|k| format!("field.angular_velocity_covariance{k}")).collect();
    let mut s = format!(
        "%time,field.header.seq,field.header.stamp,field.header.frame_id,field.orientation.x,field.orientation.w,{},field.angular_velocity.x\n",
        cov.join(",")
    );
    for (i, v) in white(3000, 0.01, 11).iter().enumerate() {
        let stamp = 1_700_000_000_000_000_000u64 + 5_000_000 * i as u64;
        // the receive time: late by 0 to 3 ms
        let recv = stamp + (i as u64 * 7919 % 3_000_000);
        writeln!(s, "{recv},{i},{stamp},imu_link,0,1,{},{v:?}", ["0"; 9].join(",")).unwrap();
    }
    std::fs::write(&path, s).unwrap();
    let o = analyse_file(&AllanRequest::new(&path)).unwrap();
    // (the receive times would give 0.005 + 0.9e-6 s: their last one is 2.7 ms late)
    assert!((o.sample_interval_s - 0.005).abs() < 1e-7, "{}", o.sample_interval_s);
    let text: Vec<String> = o.notes.iter().map(|n| n.to_string()).collect();
    assert!(text.iter().any(|t| t.contains("'%time' skipped: a second time column")), "{text:?}");
    assert!(text.iter().any(|t| t.contains("'field.header.frame_id' skipped: text")), "{text:?}");
    let grouped: Vec<&ReadNote> = o.notes.iter().filter(|n| matches!(n, ReadNote::RosFieldsSkipped { .. })).collect();
    assert_eq!(grouped.len(), 1, "{text:?}");
    assert!(matches!(grouped[0], ReadNote::RosFieldsSkipped { count: 11, .. }), "{text:?}");
    assert!(!text.iter().any(|t| t.contains("covariance3")), "one note for all: {text:?}");
}
