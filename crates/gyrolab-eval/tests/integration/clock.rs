//! The clock model, resets and gap policies through `analyse_file` (issue 30), on files written
//! here for each clock pattern of real recordings: a PX4-style sample clock with drops
//! (intervals of 4.000, 8.000, ... ms), a host stamping samples in bursts, a trailer of zeros,
//! a clock reset, sparse drops over 20 minutes of host stamps. Each has its true rate; the
//! records are white rate noise of known N (deg/sqrt(h)) from a seeded generator, and the
//! slope-line N must come within 3 % of it (a rate read 18 % off moves N by 9 %).

use gyrolab::allan::TauList;
use gyrolab::sampling::ClockKind;
use gyrolab_eval::allan::{analyse_file, AllanOutcome, AllanRequest, GapPolicy, ReadNote};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use std::fmt::Write as _;
use std::path::Path;

/// ARW of every record, deg/sqrt(h).
const N_DEG_RT_H: f64 = 0.5;

/// White rate noise of ARW [`N_DEG_RT_H`] sampled every `dt` s: per-sample sigma
/// (N / 60) / sqrt(dt) deg/s.
fn white(n: usize, dt: f64, rng: &mut ChaCha8Rng) -> Vec<f64> {
    let d = Normal::new(0.0, N_DEG_RT_H / 60.0 / dt.sqrt()).unwrap();
    (0..n).map(|_| d.sample(rng)).collect()
}

/// Writes `time_s,rate_dps` rows.
fn write(path: &Path, t: &[f64], y: &[f64]) {
    let mut s = String::from("time_s,rate_dps\n");
    for (a, b) in t.iter().zip(y) {
        writeln!(s, "{a:?},{b:?}").unwrap();
    }
    std::fs::write(path, s).unwrap();
}

fn clock_of(o: &AllanOutcome) -> ClockKind {
    o.notes.iter().find_map(|n| if let ReadNote::Clock(c) = n { Some(c.kind) } else { None }).expect("a clock note")
}

fn gaps_of(o: &AllanOutcome) -> Option<(usize, usize)> {
    o.notes
        .iter()
        .find_map(|n| if let ReadNote::Gaps { count, missing, .. } = n { Some((*count, *missing)) } else { None })
}

fn arw(o: &AllanOutcome) -> f64 {
    o.analyses[0].slope_lines.as_ref().expect("slope lines").coefficients.arw_deg_rt_h.expect("N read")
}

/// PX4 `sensor_combined`: 250 Hz on the sensor's clock, stamps in whole microseconds, a run of
/// 1 to 3 messages dropped after about one in eight (the logger): 250 Hz with every drop
/// counted, not the 211 Hz of samples over span; N within 3 %.
#[test]
fn a_sample_clock_with_drops_reads_250_hz_and_its_drops() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("px4.csv");
    let mut rng = ChaCha8Rng::seed_from_u64(30);
    let n_grid = 100_000;
    let all = white(n_grid, 0.004, &mut rng);
    let (mut t, mut y, mut dropped, mut runs, mut pending) = (Vec::new(), Vec::new(), 0usize, 0usize, 0usize);
    let mut i = 0usize;
    while i < n_grid {
        t.push((1_000_000 + i as u64 * 4000) as f64 * 1e-6);
        y.push(all[i]);
        // A run of drops counts once a message follows it (the stamps cannot show a run at the end).
        dropped += pending;
        runs += usize::from(pending > 0);
        pending = 0;
        i += 1;
        if rng.gen::<f64>() < 0.125 {
            pending = rng.gen_range(1..=3);
            i += pending;
        }
    }
    let samples_over_span = (t.len() - 1) as f64 / (t[t.len() - 1] - t[0]);
    assert!(samples_over_span < 0.85 * 250.0, "the naive reading is far off: {samples_over_span}");
    write(&path, &t, &y);
    // Analyse (drops left out) and fill (runs of up to 3 filled): both at 250 Hz.
    for gaps in [GapPolicy::Analyse, GapPolicy::Fill] {
        let o = analyse_file(&AllanRequest { gaps, taus: TauList::Decade, ..AllanRequest::new(&path) }).unwrap();
        assert_eq!(clock_of(&o), ClockKind::SampleClock);
        assert!((1.0 / o.sample_interval_s - 250.0).abs() < 1e-6, "{}", 1.0 / o.sample_interval_s);
        assert_eq!(gaps_of(&o), Some((runs, dropped)));
        let n = arw(&o);
        assert!((n / N_DEG_RT_H - 1.0).abs() < 0.03, "{gaps:?}: N = {n}");
        if gaps == GapPolicy::Fill {
            // About 20 % of the grid missing: beyond the 1 % the fill rule is checked for, so
            // nothing is filled and the note says why.
            let declined = o.notes.iter().find(|n| matches!(n, ReadNote::FillDeclined { .. })).expect("declined");
            assert!(declined.to_string().contains("more than the 1 %"), "{declined}");
            assert!(!o.notes.iter().any(|n| matches!(n, ReadNote::Filled { .. })));
        }
    }
    // A given rate of 250 Hz agrees with the stamps: no warning about it.
    let o = analyse_file(&AllanRequest { sample_rate_hz: Some(250.0), ..AllanRequest::new(&path) }).unwrap();
    let given = o.notes.iter().find(|n| matches!(n, ReadNote::SampleRateGiven { .. })).expect("a note on the rate");
    assert!(!given.is_warning(), "{given}");
}

/// A host stamping a 100.22 Hz sensor when the driver hands samples over: bursts every 30 to
/// 70 ms, 0.5 to 1 ms apart inside one. Rate = samples / span, no gap invented, the curve to a
/// quarter of the record, N within 3 %.
#[test]
fn bursts_of_host_stamps_read_samples_over_span_and_keep_the_long_taus() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bursts.csv");
    let mut rng = ChaCha8Rng::seed_from_u64(31);
    let (rate, n) = (100.22, 40_000usize);
    let y = white(n, 1.0 / rate, &mut rng);
    let (mut t, mut next, mut last, mut i) = (Vec::with_capacity(n), 0.0f64, f64::NEG_INFINITY, 0usize);
    while t.len() < n {
        next += rng.gen_range(0.030..0.070);
        while t.len() < n && i as f64 / rate <= next {
            let stamp = next.max(last + rng.gen_range(0.0005..0.001));
            t.push(stamp);
            last = stamp;
            i += 1;
        }
    }
    write(&path, &t, &y);
    let o = analyse_file(&AllanRequest { taus: TauList::Decade, ..AllanRequest::new(&path) }).unwrap();
    assert_eq!(clock_of(&o), ClockKind::ArrivalStamps);
    assert_eq!(
        gaps_of(&o),
        None,
        "{:?} {}",
        o.notes,
        o.notes.iter().map(|n| n.to_string()).collect::<Vec<_>>().join(" | ")
    );
    let span = t[n - 1] - t[0];
    assert_eq!(o.sample_interval_s, span / (n - 1) as f64);
    assert!((1.0 / o.sample_interval_s / rate - 1.0).abs() < 2e-3);
    let longest = o.analyses[0].curve.points.last().unwrap().tau_s;
    assert!(longest >= span / 4.0 / 2.0, "the curve stops at {longest} s of {span} s");
    let n_read = arw(&o);
    assert!((n_read / N_DEG_RT_H - 1.0).abs() < 0.03, "N = {n_read}");
}

/// 6280 clean rows then 720 rows of zeros, the time stamp included (the logger's unused
/// buffer): the clean part is analysed, a warning names the row where the stamps go back.
#[test]
fn a_zero_trailer_ends_the_record_with_a_located_warning() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("trailer.csv");
    let mut rng = ChaCha8Rng::seed_from_u64(32);
    let mut t: Vec<f64> = (0..6280).map(|i| 3.0 + i as f64 * 0.01).collect();
    let mut y = white(6280, 0.01, &mut rng);
    t.extend(std::iter::repeat_n(0.0, 720));
    y.extend(std::iter::repeat_n(0.0, 720));
    write(&path, &t, &y);
    let o = analyse_file(&AllanRequest::new(&path)).unwrap();
    assert!((o.sample_interval_s - 0.01).abs() < 1e-12);
    let (row, left_out) = o
        .notes
        .iter()
        .find_map(|n| if let ReadNote::Reset { row, reset, .. } = n { Some((*row, reset.left_out)) } else { None })
        .expect("a reset note");
    // Header on line 1: sample 6280 (the first zero row) is on line 6282.
    assert_eq!((row, left_out), (6282, 720));
    assert!(o.notes.iter().any(|n| matches!(n, ReadNote::Reset { .. }) && n.is_warning()));
    let first = &o.analyses[0].curve.points[0];
    assert_eq!((first.m, first.terms), (1, 6279), "OADEV at m = 1 over the 6280 clean samples");
}

/// A clock reset to zero after 5000 samples: the record ends there, with the note.
#[test]
fn a_clock_reset_ends_the_record() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("reset.csv");
    let mut rng = ChaCha8Rng::seed_from_u64(33);
    let mut t: Vec<f64> = (0..5000).map(|i| 60.0 + i as f64 * 0.005).collect();
    t.extend((0..3000).map(|i| i as f64 * 0.005));
    let y = white(8000, 0.005, &mut rng);
    write(&path, &t, &y);
    let o = analyse_file(&AllanRequest::new(&path)).unwrap();
    assert!((o.sample_interval_s - 0.005).abs() < 1e-12);
    assert!(o.notes.iter().any(|n| matches!(n, ReadNote::Reset { row: 5002, .. })), "{:?}", o.notes);
    assert_eq!(o.analyses[0].curve.points[0].terms, 4999);
}

/// A rate given beside stamps that say otherwise is used, with a warning giving the stamps'.
#[test]
fn a_given_rate_beside_the_stamps_is_used_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("given.csv");
    let mut rng = ChaCha8Rng::seed_from_u64(34);
    let t: Vec<f64> = (0..4000).map(|i| i as f64 * 0.01).collect();
    write(&path, &t, &white(4000, 0.01, &mut rng));
    let o = analyse_file(&AllanRequest { sample_rate_hz: Some(125.0), ..AllanRequest::new(&path) }).unwrap();
    assert_eq!(o.sample_interval_s, 1.0 / 125.0);
    let note = o.notes.iter().find(|n| matches!(n, ReadNote::SampleRateGiven { .. })).unwrap();
    assert!(note.is_warning());
    let text = note.to_string();
    assert!(text.contains("the time stamps say 100.000000 Hz") && text.contains("+25.000 %"), "{text}");
}

/// 20 minutes at 250 Hz of host stamps (+-10 % jitter) with one message in about 150 dropped:
/// the default policy (fill) keeps the taus to a quarter of the record and says what it filled;
/// `analyse` loses them and says so; `contiguous` closes the gaps up. N within 3 % by fill.
#[test]
fn sparse_drops_over_twenty_minutes_keep_the_long_taus() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bag.csv");
    let mut rng = ChaCha8Rng::seed_from_u64(35);
    let (rate, grid) = (250.0, 300_000usize);
    let all = white(grid, 1.0 / rate, &mut rng);
    let (mut t, mut y, mut dropped) = (Vec::new(), Vec::new(), 0usize);
    let mut i = 0usize;
    let mut since = 0usize;
    while i < grid {
        if since > 40 && rng.gen::<f64>() < 1.0 / 150.0 {
            i += 1;
            dropped += 1;
            since = 0;
            continue;
        }
        t.push((i as f64 + rng.gen_range(-0.1..0.1)) / rate);
        y.push(all[i]);
        i += 1;
        since += 1;
    }
    write(&path, &t, &y);
    let quarter = grid as f64 / rate / 4.0;
    let fill = analyse_file(&AllanRequest::new(&path)).unwrap();
    assert_eq!(gaps_of(&fill), Some((dropped, dropped)));
    assert!((1.0 / fill.sample_interval_s / rate - 1.0).abs() < 1e-5);
    assert!(fill.notes.iter().any(|n| matches!(n, ReadNote::Filled { filled, left: 0, .. } if *filled == dropped)));
    // Octave taus: the last factor is the largest power of two within a quarter of the record.
    let last = fill.analyses[0].curve.points.last().unwrap().tau_s;
    assert!(last > quarter / 2.0, "{last} of {quarter}");
    assert!(!fill.notes.iter().any(|n| matches!(n, ReadNote::LongTausLost { .. })));
    let n = arw(&fill);
    assert!((n / N_DEG_RT_H - 1.0).abs() < 0.03, "N = {n}");
    let analyse = analyse_file(&AllanRequest { gaps: GapPolicy::Analyse, ..AllanRequest::new(&path) }).unwrap();
    assert!(analyse.analyses[0].curve.points.last().unwrap().tau_s < quarter / 8.0);
    assert!(analyse.notes.iter().any(|n| matches!(n, ReadNote::LongTausLost { .. }) && n.is_warning()));
    let contiguous = analyse_file(&AllanRequest { gaps: GapPolicy::Contiguous, ..AllanRequest::new(&path) }).unwrap();
    assert_eq!(contiguous.analyses[0].curve.points[0].terms, t.len() - 1);
    // The curve reaches a quarter of the closed-up record (floor((n - 1) / 4) samples).
    let contiguous_quarter = ((t.len() - 1) / 4) as f64 / rate;
    let last = contiguous.analyses[0].curve.points.last().unwrap().tau_s;
    assert!(last > contiguous_quarter / 2.0, "{last} of {contiguous_quarter}");
}

/// The REAL PX4 log of examples/recordings (PX4/pyulog's test log, BSD-3-Clause): topic
/// `sensor_combined` read by gyrolab against pyulog + numpy on the same messages
/// (tests/data/px4_clock_reference.json, written and checked by scripts/px4_clock_reference.py):
/// a sample clock of 4.888 ms with 32 samples missing after the first message, the rate
/// (n - 1 + missing) / span, and the OADEV of each gyro axis with the gap rule at m = 1 to 64,
/// term counts equal and deviations to 1e-12.
#[test]
fn px4_log_matches_pyulog_and_numpy() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let ulg = root.join("examples/recordings/px4_sample_log_small.ulg");
    if !ulg.exists() {
        eprintln!("SKIPPED: px4_log_matches_pyulog_and_numpy: {} is missing", ulg.display());
        return;
    }
    let text = std::fs::read_to_string(root.join("crates/gyrolab-eval/tests/data/px4_clock_reference.json")).unwrap();
    let want: serde_json::Value = serde_json::from_str(&text).unwrap();
    let request = AllanRequest {
        topics: vec!["sensor_combined".into()],
        gaps: GapPolicy::Analyse,
        confidence: None,
        ..AllanRequest::new(&ulg)
    };
    let o = analyse_file(&request).unwrap();
    assert_eq!(clock_of(&o), ClockKind::SampleClock);
    let rate = 1.0 / o.sample_interval_s;
    assert!((rate / want["rate_hz"].as_f64().unwrap() - 1.0).abs() < 1e-12, "{rate} Hz");
    let (count, missing) = gaps_of(&o).unwrap();
    assert_eq!(count, want["gaps"].as_array().unwrap().len());
    assert_eq!(missing as u64, want["missing"].as_u64().unwrap());
    let mut compared = 0;
    for (name, points) in want["oadev_dps"].as_object().unwrap() {
        let a = o.analyses.iter().find(|a| &a.channel == name).unwrap_or_else(|| panic!("channel {name}"));
        for p in points.as_array().unwrap() {
            let (m, terms, dev) =
                (p[0].as_u64().unwrap() as usize, p[1].as_u64().unwrap() as usize, p[2].as_f64().unwrap());
            let Some(q) = a.curve.points.iter().find(|q| q.m == m) else { continue };
            assert_eq!(q.terms, terms, "{name} m = {m}");
            assert!((q.deviation / dev - 1.0).abs() < 1e-12, "{name} m = {m}: {} vs {dev}", q.deviation);
            compared += 1;
        }
    }
    assert!(compared >= 18, "{compared} points compared");
}

/// Dense drops of a REAL PX4 log (issue 54): pyulog's sample_logging_tagged_and_default_params.ulg
/// steps 4 and 8 ms on `sensor_combined`, 665 of 2,693 samples missing (24.7 %), too many to
/// fill. The default policy's present-sample estimator keeps the long taus: the curve passes
/// 1 s (the gap rule's stopped at 0.032 s), N is a value, and every deviation from m = 16 to 512
/// has the term count of pyulog + numpy's time-binned reading of the same messages
/// (tests/data/px4_dense_drops_reference.json, scripts/px4_dense_drops_reference.py) and lies
/// within 5 % below it (gyrolab removes the white excess of the missing samples, which the
/// time-binned means keep).
#[test]
fn dense_drops_keep_the_long_taus_of_a_real_px4_log() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let ulg = root.join("examples/recordings/px4_sample_logging_tagged_and_default_params.ulg");
    let text =
        std::fs::read_to_string(root.join("crates/gyrolab-eval/tests/data/px4_dense_drops_reference.json")).unwrap();
    let want: serde_json::Value = serde_json::from_str(&text).unwrap();
    let o = analyse_file(&AllanRequest { topics: vec!["sensor_combined".into()], ..AllanRequest::new(&ulg) }).unwrap();
    assert!(o.notes.iter().any(|n| matches!(n, ReadNote::FillDeclined { missing: 665, samples: 2693 })));
    let mut compared = 0;
    for (name, points) in want["oadev_dps"].as_object().unwrap() {
        let a = o.analyses.iter().find(|a| &a.channel == name).unwrap_or_else(|| panic!("channel {name}"));
        assert!(
            a.curve.points.last().unwrap().tau_s > 1.0,
            "{name}: the curve stops at {}",
            a.curve.points.last().unwrap().tau_s
        );
        let n = a.slope_lines.as_ref().and_then(|s| s.coefficients.arw_deg_rt_h);
        assert!(n.is_some_and(|n| n > 0.5 && n < 5.0), "{name}: N = {n:?}");
        for p in points.as_array().unwrap() {
            let (m, terms, dev) =
                (p[0].as_u64().unwrap() as usize, p[1].as_u64().unwrap() as usize, p[2].as_f64().unwrap());
            let q = a.curve.points.iter().find(|q| q.m == m).unwrap_or_else(|| panic!("{name}: no point at m = {m}"));
            assert_eq!(q.terms, terms, "{name} m = {m}");
            let r = q.deviation / dev;
            assert!(r <= 1.0 + 1e-12 && r > 0.95, "{name} m = {m}: {} vs time-binned {dev}", q.deviation);
            compared += 1;
        }
    }
    assert!(compared >= 18, "{compared} points compared");
    // The gap rule (`--gaps analyse`) on the same record: the long taus are lost.
    let gaps = analyse_file(&AllanRequest {
        topics: vec!["sensor_combined".into()],
        gaps: GapPolicy::Analyse,
        ..AllanRequest::new(&ulg)
    })
    .unwrap();
    assert!(gaps.analyses[0].curve.points.last().unwrap().tau_s < 0.1);
}
