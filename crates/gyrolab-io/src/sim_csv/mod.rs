//! Fast CSV writer for simulated records: the static layout (`time_s,output_<unit>` or
//! `time_s,rate_<unit>`, optional `temp_c`) and the rate-table long layout
//! (`rate_dps,run,stroke,output_<unit>`, optional `settling`), each after `# ` comment lines that
//! record the simulator's parameters and seed.
//!
//! Numbers are written either in the shortest form that reads back to the same f64 (Ryu
//! algorithm, `ryu` crate) or with a fixed number of decimals (one correctly rounded multiply by an
//! exact power of ten, round half away from zero, then integer digits: a value within half an ulp
//! of a rounding tie may round up where exact decimal rounding would round down); both are
//! byte-identical on every platform. Rows are
//! formatted into a 64 KiB buffer and handed to the writer in large blocks, so the caller need not
//! wrap it in a `BufWriter`.

use std::io::Write;

use gyrolab::sim::{
    FlickerDesign, RateTableGenerator, RateTableSpec, SensorModel, SimError, StaticGenerator, StaticSample, StaticSpec,
    FLICKER_BAND,
};
use gyrolab::units::OutputUnit;
use thiserror::Error;

/// How numbers are written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum NumberFormat {
    /// Shortest text that reads back to the same f64 (Ryu); exact, up to 17 significant digits.
    #[default]
    Shortest,
    /// A fixed number of decimals (0..=15); values too large for it fall back to `Shortest`.
    Fixed {
        /// Digits after the decimal point.
        decimals: u8,
    },
}

/// Options of the simulated-record writers.
#[derive(Debug, Clone, PartialEq)]
pub struct SimCsvOptions {
    /// Number formatting of the value columns.
    pub number_format: NumberFormat,
    /// Extra comment lines written after the title (such as the preset name or the command line).
    pub comments: Vec<String>,
    /// Simulate static records on a second thread while this one formats (same bytes either way;
    /// helps only when a second core is free).
    pub pipelined: bool,
}

impl Default for SimCsvOptions {
    /// Shortest number form, no extra comments, one thread.
    fn default() -> Self {
        SimCsvOptions { number_format: NumberFormat::Shortest, comments: Vec::new(), pipelined: false }
    }
}

/// Samples per block handed from the simulating thread to the formatting thread.
const BLOCK_SAMPLES: usize = 8192;
/// Buffer size at which rows are handed to the writer.
const FLUSH_AT: usize = 1 << 16;

mod pipeline;
mod text;

use text::{with_number_text, Fixed, IntegerText, NumberText, Shortest, TextBuf};

/// Why a simulated record could not be written.
#[derive(Debug, Error)]
pub enum SimCsvError {
    /// The simulation parameters are invalid.
    #[error(transparent)]
    Sim(#[from] SimError),
    /// Writing failed.
    #[error("cannot write the simulated record: {0}")]
    Io(#[from] std::io::Error),
    /// A writer option is out of range.
    #[error("invalid option: {0}")]
    InvalidOption(String),
}

/// What a writer wrote.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WriteSummary {
    /// Data rows written (comment and header lines not counted).
    pub rows: u64,
    /// Bytes written in all.
    pub bytes: u64,
}

/// Row formatter over a block buffer.
struct RowWriter<W: Write> {
    out: W,
    text: TextBuf,
    bytes: u64,
}

impl<W: Write> RowWriter<W> {
    fn new(out: W) -> Self {
        RowWriter::with_text(out, TextBuf::new(FLUSH_AT))
    }

    /// A row writer that starts with `text` (such as a preamble).
    fn with_text(out: W, text: TextBuf) -> Self {
        RowWriter { out, text, bytes: 0 }
    }

    /// Hands the text to the writer once it has reached [`FLUSH_AT`] bytes.
    #[inline]
    fn flush_when_full(&mut self) -> std::io::Result<()> {
        if self.text.end >= FLUSH_AT {
            self.flush_buffer()?;
        }
        Ok(())
    }

    fn flush_buffer(&mut self) -> std::io::Result<()> {
        self.out.write_all(&self.text.bytes[..self.text.end])?;
        self.bytes += self.text.end as u64;
        self.text.end = 0;
        Ok(())
    }

    fn finish(mut self) -> std::io::Result<u64> {
        self.flush_buffer()?;
        self.out.flush()?;
        Ok(self.bytes)
    }
}

/// Column name of a static record's output: `rate_<suffix>` for rate units, else `output_<suffix>`.
pub fn static_output_column(unit: OutputUnit) -> String {
    match unit {
        OutputUnit::DegPerSec | OutputUnit::RadPerSec => format!("rate_{}", unit.suffix()),
        _ => format!("output_{}", unit.suffix()),
    }
}

/// Header line of the static layout, such as `time_s,output_v,temp_c`.
pub fn static_header(unit: OutputUnit, with_temperature: bool) -> String {
    let mut h = format!("time_s,{}", static_output_column(unit));
    if with_temperature {
        h.push_str(",temp_c");
    }
    h
}

/// Header line of the rate-table long layout, such as `rate_dps,run,stroke,output_v[,settling]`.
pub fn rate_table_header(unit: OutputUnit, with_settling_flag: bool) -> String {
    let mut h = format!("rate_dps,run,stroke,output_{}", unit.suffix());
    if with_settling_flag {
        h.push_str(",settling");
    }
    h
}

fn flicker_comment(d: &FlickerDesign) -> String {
    let times: Vec<String> = d.correlation_times_s.iter().map(|t| format!("{t:?}")).collect();
    format!(
        "truth.flicker = sum of {} Gauss-Markov processes, correlation times {} s, sigma each {:?} deg/s; \
         Allan deviation within +-{:?} % of 0.6643 B for tau in [{:?}, {:?}] s",
        times.len(),
        times.join(" "),
        d.sigma_each_dps,
        FLICKER_BAND * 100.0,
        d.tau_min_s,
        d.tau_max_s
    )
}

fn write_preamble(
    text: &mut TextBuf,
    title: &str,
    seed: u64,
    options: &SimCsvOptions,
    model: &SensorModel,
    record: Vec<(&'static str, String)>,
    truth: Vec<String>,
) {
    text.comment(title);
    text.comment(&format!("seed = {seed}"));
    for c in &options.comments {
        text.comment(c);
    }
    for (k, v) in model.parameter_lines() {
        text.comment(&format!("sensor.{k} = {v}"));
    }
    for (k, v) in record {
        text.comment(&format!("record.{k} = {v}"));
    }
    for t in truth {
        text.comment(&t);
    }
}

/// Simulates a static record and writes it in the static layout; returns rows and bytes written.
/// With `options.pipelined`, three threads share the work: one simulates (and formats when the
/// second is busy), one formats, one writes (same bytes as with one thread; see `pipeline`).
pub fn write_static_csv<W: Write + Send>(
    out: W,
    model: &SensorModel,
    spec: &StaticSpec,
    seed: u64,
    options: &SimCsvOptions,
) -> Result<WriteSummary, SimCsvError> {
    with_number_text!(options.number_format, write_static_csv_as(out, model, spec, seed, options))
}

/// [`write_static_csv`] with the number columns written as `N`.
fn write_static_csv_as<N: NumberText, W: Write + Send>(
    out: W,
    model: &SensorModel,
    spec: &StaticSpec,
    seed: u64,
    options: &SimCsvOptions,
) -> Result<WriteSummary, SimCsvError> {
    let generator = StaticGenerator::new(model, spec, seed)?;
    let mut preamble = TextBuf::new(4096);
    let mut truth = vec![format!("truth.earth_rate_dps = {:?}", generator.earth_rate_dps())];
    truth.extend(generator.flicker_design().map(flicker_comment));
    let title = "gyrolab simulated static record";
    write_preamble(&mut preamble, title, seed, options, model, spec.parameter_lines(), truth);
    preamble.text(static_header(model.output_unit, generator.records_temperature()).as_bytes());
    preamble.byte(b'\n');
    if options.pipelined {
        return Ok(pipeline::write_static_parallel::<N, W>(out, generator, preamble)?);
    }
    let mut w = RowWriter::with_text(out, preamble);
    let mut rows = 0u64;
    let mut time_integer = IntegerText::default();
    for s in generator {
        static_row::<N>(&mut w.text, &s, &mut time_integer);
        w.flush_when_full()?;
        rows += 1;
    }
    let bytes = w.finish()?;
    Ok(WriteSummary { rows, bytes })
}

/// Appends one row of the static layout (with its newline).
#[inline]
fn static_row<N: NumberText>(text: &mut TextBuf, s: &StaticSample, time_integer: &mut IntegerText) {
    N::put_repeating(text, s.time_s, time_integer);
    text.byte(b',');
    N::put(text, s.output);
    if let Some(t) = s.temp_c {
        text.byte(b',');
        N::put(text, t);
    }
    text.byte(b'\n');
}

/// Simulates a rate-table test and writes it in the long layout; returns rows and bytes written.
pub fn write_rate_table_csv<W: Write>(
    out: W,
    model: &SensorModel,
    spec: &RateTableSpec,
    seed: u64,
    options: &SimCsvOptions,
) -> Result<WriteSummary, SimCsvError> {
    with_number_text!(options.number_format, write_rate_table_csv_as(out, model, spec, seed, options))
}

/// [`write_rate_table_csv`] with the number columns written as `N`.
fn write_rate_table_csv_as<N: NumberText, W: Write>(
    out: W,
    model: &SensorModel,
    spec: &RateTableSpec,
    seed: u64,
    options: &SimCsvOptions,
) -> Result<WriteSummary, SimCsvError> {
    let generator = RateTableGenerator::new(model, spec, seed)?;
    let mut w = RowWriter::new(out);
    let mut truth = vec![format!("truth.earth_rate_dps = {:?}", generator.earth_rate_dps())];
    truth.extend(generator.flicker_design().map(flicker_comment));
    let title = "gyrolab simulated rate-table test: runs of a forward stroke (rates rising) then a reverse \
                 stroke (rates falling)";
    write_preamble(&mut w.text, title, seed, options, model, spec.parameter_lines(), truth);
    let flagged = generator.flags_settling();
    w.text.text(rate_table_header(model.output_unit, flagged).as_bytes());
    w.text.byte(b'\n');
    let mut rows = 0u64;
    for s in generator {
        N::put(&mut w.text, s.rate_dps);
        w.text.byte(b',');
        w.text.unsigned(u64::from(s.run));
        w.text.byte(b',');
        w.text.text(s.stroke.label().as_bytes());
        w.text.byte(b',');
        N::put(&mut w.text, s.output);
        if flagged {
            w.text.text(if s.settling { b",1" } else { b",0" });
        }
        w.text.byte(b'\n');
        w.flush_when_full()?;
        rows += 1;
    }
    let bytes = w.finish()?;
    Ok(WriteSummary { rows, bytes })
}

/// Reads a simulation set-up (TOML: `seed`, `preset`, `[sensor]`, `[static_record]`,
/// `[rate_table]`); errors name the line and column.
pub fn read_sim_config(path: &std::path::Path) -> Result<gyrolab::sim::SimConfig, crate::DataError> {
    let text = std::fs::read_to_string(path).map_err(|e| crate::DataError::io(path, &e))?;
    toml::from_str(&text).map_err(|e| {
        let mut d = crate::DataError::new(path, format!("not a valid simulation set-up: {}", e.message()));
        if let Some(span) = e.span() {
            let (line, col) = crate::calibration::line_col(&text, span.start);
            d = d.at_line(line).at_column(col, None);
        }
        d
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use gyrolab::sim::{Preset, SettlingRows, SimConfig};

    fn static_bytes(seed: u64, options: &SimCsvOptions) -> Vec<u8> {
        let model = SensorModel { rrw_deg_h_rt_h: 3.0, ..SensorModel::preset(Preset::Adxrs646) };
        let spec =
            StaticSpec { sample_rate_hz: 100.0, duration_s: 30.0, record_temperature: true, ..StaticSpec::default() };
        let mut out = Vec::new();
        let sum = write_static_csv(&mut out, &model, &spec, seed, options).unwrap();
        assert_eq!(sum.rows, 3000);
        assert_eq!(sum.bytes, out.len() as u64);
        out
    }

    /// A writer that fails once it has taken `limit` bytes.
    struct FailingWriter {
        taken: usize,
        limit: usize,
    }

    impl Write for FailingWriter {
        fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
            if self.taken + bytes.len() > self.limit {
                return Err(std::io::Error::other("disk full (test)"));
            }
            self.taken += bytes.len();
            Ok(bytes.len())
        }

        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }

    #[test]
    fn output_errors_are_returned_with_one_or_three_threads() {
        let model = SensorModel::preset(Preset::Adxrs646);
        let spec = StaticSpec { sample_rate_hz: 100.0, duration_s: 2000.0, ..StaticSpec::default() };
        for pipelined in [false, true] {
            for limit in [0, 100, 300_000] {
                let o = SimCsvOptions { pipelined, ..SimCsvOptions::default() };
                let e = write_static_csv(FailingWriter { taken: 0, limit }, &model, &spec, 1, &o).unwrap_err();
                assert!(e.to_string().contains("disk full (test)"), "pipelined {pipelined}, limit {limit}: {e}");
            }
        }
    }

    #[test]
    fn same_seed_same_bytes_different_seed_different_bytes() {
        let o = SimCsvOptions::default();
        assert_eq!(static_bytes(42, &o), static_bytes(42, &o));
        let pipelined = SimCsvOptions { pipelined: true, ..SimCsvOptions::default() };
        assert_eq!(static_bytes(42, &o), static_bytes(42, &pipelined));
        assert_ne!(static_bytes(42, &o), static_bytes(43, &o));
        let spec = RateTableSpec { runs: 2, samples_per_plateau: 10, ..RateTableSpec::default() };
        let model = SensorModel::preset(Preset::Adxrs646);
        let bytes = |seed| {
            let mut out = Vec::new();
            write_rate_table_csv(&mut out, &model, &spec, seed, &o).unwrap();
            out
        };
        assert_eq!(bytes(5), bytes(5));
        assert_ne!(bytes(5), bytes(6));
    }

    #[test]
    fn three_threads_write_the_same_bytes_as_one_over_many_blocks() {
        // 40 blocks: the formatting is shared between two threads and written back in order.
        let model = SensorModel::preset(Preset::Adxrs646);
        let spec = StaticSpec { sample_rate_hz: 100.0, duration_s: 40.0 * 81.92, ..StaticSpec::default() };
        for number_format in [NumberFormat::Fixed { decimals: 7 }, NumberFormat::Shortest] {
            let bytes = |pipelined| {
                let mut out = Vec::new();
                let o = SimCsvOptions { number_format, pipelined, ..SimCsvOptions::default() };
                let sum = write_static_csv(&mut out, &model, &spec, 9, &o).unwrap();
                assert_eq!((sum.rows, sum.bytes), (spec.samples(), out.len() as u64));
                out
            };
            assert!(bytes(true) == bytes(false), "{number_format:?}");
        }
    }

    #[test]
    fn static_layout_has_comments_header_and_parsable_rows() {
        let o = SimCsvOptions { comments: vec!["preset = adxrs646".into()], ..SimCsvOptions::default() };
        let text = String::from_utf8(static_bytes(1, &o)).unwrap();
        let mut lines = text.lines();
        assert_eq!(lines.next(), Some("# gyrolab simulated static record"));
        assert_eq!(lines.next(), Some("# seed = 1"));
        assert_eq!(lines.next(), Some("# preset = adxrs646"));
        assert!(text.contains("# sensor.arw_deg_rt_h = 0.6\n"));
        assert!(text.contains("# truth.flicker = sum of "));
        let body: Vec<&str> = text.lines().filter(|l| !l.starts_with('#')).collect();
        assert_eq!(body[0], "time_s,output_v,temp_c");
        assert_eq!(body.len(), 3001);
        assert!(body[1].starts_with("0.0,2.") && body[1].ends_with(",25.0"), "{}", body[1]);
        let last: Vec<f64> = body[3000].split(',').map(|f| f.parse().unwrap()).collect();
        assert_eq!(last[0], 29.99);
        assert_eq!(last[2], 25.0);
    }

    #[test]
    fn more_than_15_decimals_are_refused() {
        let options = SimCsvOptions { number_format: NumberFormat::Fixed { decimals: 16 }, ..SimCsvOptions::default() };
        let e = write_static_csv(Vec::new(), &SensorModel::default(), &StaticSpec::default(), 0, &options).unwrap_err();
        assert!(matches!(e, SimCsvError::InvalidOption(_)), "{e}");
    }

    #[test]
    fn rate_table_layout_matches_the_reader_layout() {
        let spec = RateTableSpec {
            rates_dps: vec![-10.0, 10.0],
            runs: 1,
            samples_per_plateau: 2,
            settling_s: 0.01,
            settling: SettlingRows::Flag,
            rest_samples: 1,
            ..RateTableSpec::default()
        };
        let model = SensorModel {
            output_unit: OutputUnit::Volt,
            scale_factor_per_dps: 0.01,
            null: 2.5,
            ..SensorModel::default()
        };
        let o = SimCsvOptions { number_format: NumberFormat::Fixed { decimals: 6 }, ..SimCsvOptions::default() };
        let mut out = Vec::new();
        let sum = write_rate_table_csv(&mut out, &model, &spec, 0, &o).unwrap();
        let text = String::from_utf8(out).unwrap();
        let body: Vec<&str> = text.lines().filter(|l| !l.starts_with('#')).collect();
        assert_eq!(body[0], "rate_dps,run,stroke,output_v,settling");
        assert_eq!(body[1], "0.000000,1,rest_start,2.500000,0");
        assert_eq!(body[2], "-10.000000,1,fwd,2.400000,1");
        assert_eq!(body[3], "-10.000000,1,fwd,2.400000,0");
        assert_eq!(body.last(), Some(&"0.000000,1,rest_end,2.500000,0"));
        assert_eq!(sum.rows as usize, body.len() - 1);
    }

    #[test]
    fn bad_parameters_surface_as_sim_errors() {
        let spec = StaticSpec { sample_rate_hz: 0.0, ..StaticSpec::default() };
        let e = write_static_csv(Vec::new(), &SensorModel::default(), &spec, 0, &SimCsvOptions::default()).unwrap_err();
        assert!(matches!(e, SimCsvError::Sim(_)) && e.to_string().contains("sample_rate_hz"), "{e}");
    }

    #[test]
    fn a_toml_configuration_sets_preset_overrides_and_records() {
        let cfg: SimConfig = toml::from_str(
            r#"
            seed = 7
            preset = "adxrs646"
            [sensor]
            arw_deg_rt_h = 0.5
            output_rail_high = 4.9
            [static_record]
            sample_rate_hz = 1.0
            duration_s = 1200.0
            latitude_deg = 34.2
            temperature = { kind = "ramp", start_c = 20.0, rate_c_per_h = 5.0 }
            [rate_table]
            rates_dps = [-100.0, 0.0, 100.0]
            settling = "flag"
            "#,
        )
        .unwrap();
        let m = cfg.sensor_model();
        assert_eq!((m.arw_deg_rt_h, m.output_rail_high, m.null), (0.5, Some(4.9), 2.5));
        assert_eq!(cfg.static_record.samples(), 1200);
        assert_eq!(cfg.rate_table.runs, 4);
        assert!(toml::from_str::<SimConfig>("seed = 1\n[sensor]\narw = 0.5\n").is_err());
        assert!(toml::from_str::<SimConfig>(
            "[static_record]\ntemperature = { kind = \"constant\", temp_c = 1.0, x = 2 }\n"
        )
        .is_err());
    }
}
