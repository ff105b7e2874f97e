//! Real IMU log layouts, as loggers write them (issue 16): units from suffixes, brackets and
//! options; time columns in s, ms, us, ns; headerless files; Kalibr's imu0.csv; ROS exports;
//! columns that cannot be used are skipped with a reason. Expected values are the numbers the
//! test writes, converted by hand.

use gyrolab::units::{OutputUnit, TimeUnit};
use gyrolab_io::series::*;
use gyrolab_io::DataError;

fn read(text: &str, opts: &SeriesOptions) -> Result<SeriesData, DataError> {
    collect_series(SeriesReader::from_reader("log.csv", text.as_bytes(), opts)?)
}

fn units(d: &SeriesData) -> Vec<(String, OutputUnit, UnitSource)> {
    d.header.channels.iter().map(|c| (c.name.clone(), c.unit, c.unit_source)).collect()
}

#[test]
fn ros_export_without_units_reads_unitless_until_units_are_given() {
    let text = "time,gx,gy,gz,ax,ay,az\n0.000,0.01,0.02,0.03,0.1,0.2,9.8\n0.005,0.01,0.02,0.03,0.1,0.2,9.8\n";
    let d = read(text, &SeriesOptions::default()).unwrap();
    assert_eq!(d.header.time_unit, Some(TimeUnit::Second));
    assert_eq!(d.header.time_unit_source, Some(UnitSource::Assumed));
    assert!(d.header.channels.iter().all(|c| c.unit == OutputUnit::Unitless && c.unit_source == UnitSource::None));
    // One default per quantity: rad/s for the gyro columns, m/s^2 for those named as accelerometers.
    let o =
        SeriesOptions { default_units: vec![OutputUnit::RadPerSec, OutputUnit::MeterPerSec2], ..Default::default() };
    let d = read(text, &o).unwrap();
    let u = units(&d);
    assert_eq!(u[0].1, OutputUnit::RadPerSec);
    assert_eq!(u[2].1, OutputUnit::RadPerSec);
    assert_eq!(u[3].1, OutputUnit::MeterPerSec2);
    assert_eq!(u[5], ("az".into(), OutputUnit::MeterPerSec2, UnitSource::Default));
    // A unit named for one column wins over the default.
    let o = SeriesOptions {
        default_units: vec![OutputUnit::RadPerSec],
        column_units: vec![("gz".into(), OutputUnit::DegPerSec)],
        ..Default::default()
    };
    let d = read(text, &o).unwrap();
    assert_eq!(units(&d)[2], ("gz".into(), OutputUnit::DegPerSec, UnitSource::Column));
    assert_eq!(units(&d)[3].1, OutputUnit::Unitless, "no accel default given");
}

#[test]
fn kalibr_imu0_csv_reads_with_no_options() {
    let text = "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n\
                1403636579758555392,-0.099134701513277898,0.14032447186034408,0.023547760560897612,8.1476917083333333,-0.37592158333333331,-2.4026292499999999\n\
                1403636579763555584,-0.099134701513277898,0.14032447186034408,0.023547760560897612,8.033280791666666,-0.40861041666666664,-2.4026292499999999\n";
    let d = read(text, &SeriesOptions::default()).unwrap();
    assert_eq!(d.header.header_line, 1);
    assert_eq!(d.header.time_unit, Some(TimeUnit::Nanosecond));
    assert_eq!(d.header.time_unit_source, Some(UnitSource::Header));
    let u = units(&d);
    assert_eq!(u.len(), 6);
    assert!(u[..3].iter().all(|c| c.1 == OutputUnit::RadPerSec && c.2 == UnitSource::Header));
    assert!(u[3..].iter().all(|c| c.1 == OutputUnit::MeterPerSec2));
    let t = d.time.unwrap();
    // 5 000 192 ns between the stamps: to the f64 resolution of 1.4e9 s (2.4e-7 s).
    assert!((t[1] - t[0] - 0.005_000_192).abs() < 5e-7, "{}", t[1] - t[0]);
    assert_eq!(d.channels[3], vec!["8.1476917083333333".parse::<f64>().unwrap(), 8.033_280_791_666_666]);
}

#[test]
fn bracketed_and_suffixed_units() {
    let text = "T[s]\tGYRO_X[deg/s]\tGYRO_Y[°/s]\tRate (rad/s)\tgz_dph\tacc_x_g\tacc_y_mg\tw_mrad_s\ttemp [degC]\n\
                0\t1\t2\t3\t4\t5\t6\t7\t25\n0.002\t1\t2\t3\t4\t5\t6\t7\t25\n";
    let d = read(text, &SeriesOptions::default()).unwrap();
    assert_eq!(d.header.delimiter, Delimiter::Tab);
    assert_eq!(d.header.time_column, Some(1));
    assert_eq!(d.header.temperature_column, Some(9));
    let u: Vec<OutputUnit> = d.header.channels.iter().map(|c| c.unit).collect();
    assert_eq!(
        u,
        vec![
            OutputUnit::DegPerSec,
            OutputUnit::DegPerSec,
            OutputUnit::RadPerSec,
            OutputUnit::DegPerHour,
            OutputUnit::StandardGravity,
            OutputUnit::MilliG,
            OutputUnit::MilliradPerSec
        ]
    );
}

#[test]
fn time_units_are_converted_to_seconds() {
    for (name, scale) in [("time_ms", 1e-3), ("timestamp_us", 1e-6), ("t [ns]", 1e-9), ("time_s", 1.0)] {
        let text = format!("{name},gyro_x_dps\n1000,0.5\n3000,0.5\n");
        let d = read(&text, &SeriesOptions::default()).unwrap();
        let t = d.time.unwrap();
        assert!((t[1] - t[0] - 2000.0 * scale).abs() < 1e-12 * (2000.0 * scale), "{name}");
    }
    // Without a unit: epoch nanoseconds are recognised by their magnitude, and say so.
    let d =
        read("time,gyro_x_dps\n1700000000000000000,0.5\n1700000000010000000,0.5\n", &SeriesOptions::default()).unwrap();
    assert_eq!(d.header.time_unit, Some(TimeUnit::Nanosecond));
    assert_eq!(d.header.time_unit_source, Some(UnitSource::Magnitude));
    // An option names the time column and its unit.
    let o = SeriesOptions {
        time_column: Some("host".into()),
        time_unit: Some(TimeUnit::Millisecond),
        ..Default::default()
    };
    let d = read("host,gyro_x_dps\n0,1\n10,2\n", &o).unwrap();
    assert_eq!(d.time.unwrap(), vec![0.0, 0.01]);
    let e = read("host,gyro_x_dps\n0,1\n", &SeriesOptions { time_column: Some("clock".into()), ..Default::default() })
        .unwrap_err();
    assert!(e.message.contains("time column 'clock' is not in the header"), "{e}");
}

#[test]
fn headerless_files_get_numbered_or_given_names() {
    let d = read("-0.05\n0.02\n0.01\n", &SeriesOptions { sample_rate_hz: Some(10.0), ..Default::default() }).unwrap();
    assert!(d.header.headerless);
    assert_eq!(d.header.channels[0].name, "c1");
    assert_eq!(d.channels[0], vec![-0.05, 0.02, 0.01]);
    assert_eq!(d.lines.to_vec(), vec![1, 2, 3]);
    // Comments above, whitespace separated, names given, one of them the time.
    let o = SeriesOptions { names: Some(vec!["t".into(), "gx".into(), "gy".into()]), ..Default::default() };
    let d = read("# from np.savetxt\n0.00 1.5 2.5\n0.01 1.6 2.6\n", &o).unwrap();
    assert_eq!(d.header.time_column, Some(1));
    assert_eq!(d.channels[1], vec![2.5, 2.6]);
    assert_eq!(d.lines.to_vec(), vec![2, 3]);
    // A UTF-8 BOM before the first number.
    let d =
        read("\u{feff}1.0,2.0\n3.0,4.0\n", &SeriesOptions { sample_rate_hz: Some(1.0), ..Default::default() }).unwrap();
    assert_eq!(d.channels[0], vec![1.0, 3.0]);
    let e = read(
        "1,2\n",
        &SeriesOptions { names: Some(vec!["a".into()]), sample_rate_hz: Some(1.0), ..Default::default() },
    )
    .unwrap_err();
    assert!(e.message.contains("1 names given"), "{e}");
    // Without a time: the message names the numbered columns and no line (a headerless file's
    // header is no line of the file).
    let e = read("0.00 1.5 2.5\n0.01 1.6 2.6\n", &SeriesOptions::default()).unwrap_err();
    assert!(e.message.contains("no header row: its columns are c1, c2, c3"), "{e}");
    assert_eq!(e.line, None, "{e}");
    assert!(!e.to_string().contains(":0:"), "{e}");
}

#[test]
fn a_unit_for_a_column_not_in_the_header_is_an_error() {
    // A mistyped name is refused as a mistyped --column is, not silently ignored.
    let text = "time,gx,gy\n0.000,0.01,0.02\n0.005,0.01,0.02\n";
    let o = SeriesOptions { column_units: vec![("gq".into(), OutputUnit::RadPerSec)], ..Default::default() };
    let e = read(text, &o).unwrap_err();
    assert!(
        e.message.contains("a unit is given for column 'gq', which is not in the header: found time, gx, gy"),
        "{e}"
    );
    assert_eq!(e.line, Some(1));
    let o = SeriesOptions { column_units: vec![("GX".into(), OutputUnit::RadPerSec)], ..Default::default() };
    assert_eq!(read(text, &o).unwrap().header.channels[0].unit, OutputUnit::RadPerSec, "names match without case");
}

#[test]
fn unusable_columns_are_skipped_with_a_reason() {
    let text = "%time,field.header.seq,field.header.stamp,field.orientation.x,field.angular_velocity.x,field.linear_acceleration.z,status,pressure [hPa]\n\
                1700000000000000000,1,1700000000000000000,0.1,0.01,9.8,OK,1013\n\
                1700000005000000000,2,1700000005000000000,0.1,0.01,9.8,OK,1013\n";
    let d = read(text, &SeriesOptions::default()).unwrap();
    // The message stamp, not the receive time `%time` (which comes first).
    assert_eq!(d.header.time_column, Some(3));
    assert_eq!(d.header.time_unit, Some(TimeUnit::Nanosecond));
    let u = units(&d);
    assert_eq!(u[0], ("field.angular_velocity.x".into(), OutputUnit::RadPerSec, UnitSource::RosConvention));
    assert_eq!(u[1].1, OutputUnit::MeterPerSec2);
    let reasons: Vec<(usize, SkipReason)> = d.header.skipped.iter().map(|s| (s.column, s.reason.clone())).collect();
    assert_eq!(
        reasons,
        vec![
            (1, SkipReason::SecondTime),
            (2, SkipReason::Counter),
            (4, SkipReason::RosField),
            (7, SkipReason::Text),
            (8, SkipReason::UnknownUnit("hpa".into())),
        ]
    );
    assert!(d.header.skipped[4].to_string().contains("column 8 'pressure [hPa]' skipped: unit 'hpa'"));
    // A driver that leaves the message stamp unset (0): the receive time is the time.
    let unset = text.replace(",1,1700000000000000000,", ",1,0,").replace(",2,1700000005000000000,", ",2,0,");
    assert_eq!(read(&unset, &SeriesOptions::default()).unwrap().header.time_column, Some(1));
}
