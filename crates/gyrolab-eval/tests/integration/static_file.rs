//! The static test of a file, streamed (moved from gyrolab-io with `evaluate_static_file`, issue
//! 52): gaps and unsorted time located to their lines, tolerant missing cells, and results that do
//! not depend on the reader's chunk and block sizes.

use gyrolab::static_test::{Position, StaticTestConfig};
use gyrolab_eval::static_test::evaluate_static_file;
use gyrolab_io::series::SeriesOptions;

fn write_temp(text: &str) -> (tempfile::TempDir, std::path::PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("rec.csv");
    std::fs::write(&p, text).unwrap();
    (dir, p)
}

fn tolerant() -> SeriesOptions {
    SeriesOptions { tolerant: true, ..SeriesOptions::default() }
}

#[test]
fn static_test_of_a_file_reports_gaps_and_unsorted_time_with_lines() {
    // 1 Hz; line 2 is the header, sample i on line 3 + i. Gap before sample 5 (t 4 -> 7),
    // t repeats at sample 8, decreases at sample 9.
    let times = [0.0, 1.0, 2.0, 3.0, 4.0, 7.0, 8.0, 9.0, 9.0, 8.5, 10.0, 11.0];
    let mut text = String::from("# rec\ntime_s,output_v\n");
    for (i, t) in times.iter().enumerate() {
        text.push_str(&format!("{t},{}\n", 2.5 + 0.001 * (i % 3) as f64));
    }
    let (_d, p) = write_temp(&text);
    let (res, summary) = evaluate_static_file(&p, &SeriesOptions::default(), |_| StaticTestConfig {
        sample_rate_hz: Some(1.0),
        ..StaticTestConfig::default()
    })
    .unwrap();
    assert_eq!(summary.rows, 12);
    let q = &res[0].quality;
    let pos = |s: u64| Position { sample: s, line: Some(3 + s) };
    // Sample 10 follows 8.5 by 1.5 s: not above 1.5 x 1 s, so not a gap.
    assert_eq!(q.time_gaps.first, vec![pos(5)]);
    assert_eq!(q.repeated_time.first, vec![pos(8)]);
    assert_eq!(q.decreasing_time.first, vec![pos(9)]);
    // Short record: 12 samples fit 1 window of 10 s, none of 100 s: both skipped with reasons.
    let skipped: Vec<f64> = res[0].bias_stability_skipped.iter().map(|s| s.smoothing_s).collect();
    assert_eq!(skipped, vec![10.0, 100.0]);
    assert!(res[0].bias_stability_skipped[0].reason.contains("1 whole windows"));
    assert_eq!(res[0].channel, "output_v");
}

#[test]
fn tolerant_missing_cells_reach_the_static_test_with_lines() {
    let (_d, p) = write_temp("time_s,output_v,gyro_y_v\n0,1,1\n1,nan,2\n2,3,\n3,4,4\n");
    let (res, summary) = evaluate_static_file(&p, &tolerant(), |_| StaticTestConfig::default()).unwrap();
    assert_eq!(summary.quality.missing_cells, 2);
    assert_eq!(res[0].quality.missing.first, vec![Position { sample: 1, line: Some(3) }]);
    assert_eq!(res[1].quality.missing.first, vec![Position { sample: 2, line: Some(4) }]);
    assert_eq!(res[0].valid_samples, 3);
    assert!((res[0].mean_output - 8.0 / 3.0).abs() < 1e-15);
}

#[test]
fn chunk_and_block_sizes_do_not_change_static_results() {
    let mut text = String::from("time_s,temp_c,output_v\n");
    for i in 0..3000 {
        let x = 2.5 + 1e-3 * (((i * 7919) % 101) as f64 / 101.0 - 0.5) + 1e-7 * i as f64;
        text.push_str(&format!("{:.2},{:.3},{x:.9}\n", i as f64 * 0.1, 20.0 + i as f64 * 0.001));
    }
    let (_d, p) = write_temp(&text);
    let base = evaluate_static_file(&p, &SeriesOptions::default(), |_| StaticTestConfig::default()).unwrap().0;
    for (chunk, rows) in [(16, 1), (64, 7), (1000, 333), (5000, 4096)] {
        let o = SeriesOptions { chunk_bytes: chunk, block_rows: rows, ..SeriesOptions::default() };
        let r = evaluate_static_file(&p, &o, |_| StaticTestConfig::default()).unwrap().0;
        let (a, b) = (&base[0], &r[0]);
        assert_eq!(a.samples, b.samples);
        assert!((a.mean_output - b.mean_output).abs() < 1e-14);
        assert_eq!(a.bias_stability.len(), b.bias_stability.len());
        for (x, y) in a.bias_stability.iter().zip(&b.bias_stability) {
            assert_eq!(x.smoothing_s, y.smoothing_s);
            assert!((y.output - x.output).abs() < 1e-12 * x.output.abs(), "{} s", x.smoothing_s);
        }
        assert!((a.drift_output_per_h.unwrap() - b.drift_output_per_h.unwrap()).abs() < 1e-10);
        let (ta, tb) = (a.temperature.as_ref().unwrap(), b.temperature.as_ref().unwrap());
        assert!((ta.slope_output_per_c - tb.slope_output_per_c).abs() < 1e-9 * ta.slope_output_per_c.abs());
    }
}
