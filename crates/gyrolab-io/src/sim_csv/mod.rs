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
    FlickerDesign, RateTableGenerator, RateTableSpec, SensorModel, SimError, StaticBlock, StaticGenerator, StaticSpec,
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

use text::{with_number_text, CountedTime, Cursor, Fixed, IntegerText, NumberText, Shortest, TextBuf, NUMBER_ROOM};

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
    mut out: W,
    model: &SensorModel,
    spec: &StaticSpec,
    seed: u64,
    options: &SimCsvOptions,
) -> Result<WriteSummary, SimCsvError> {
    write_static_csv_to(&mut out, model, spec, seed, options)
}

/// [`write_static_csv`] to a writer behind a reference: the row loops, compiled once per number
/// format (17 of them), are compiled here once, not again for each writer type in each calling
/// crate (51 copies in gyrolab-eval's release build, about a third of its LLVM IR; docs/PERFORMANCE.md).
/// The writer is called once per filled buffer, so the dynamic call costs nothing measurable.
fn write_static_csv_to(
    out: &mut (dyn Write + Send),
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
    let mut generator = StaticGenerator::new(model, spec, seed)?;
    let mut preamble = TextBuf::new(4096);
    let mut truth = vec![format!("truth.earth_rate_dps = {:?}", generator.earth_rate_dps())];
    truth.extend(generator.flicker_design().map(flicker_comment));
    let title = STATIC_RECORD_TITLE;
    write_preamble(&mut preamble, title, seed, options, model, spec.parameter_lines(), truth);
    preamble.text(static_header(model.output_unit, generator.records_temperature()).as_bytes());
    preamble.byte(b'\n');
    if options.pipelined {
        return Ok(pipeline::write_static_parallel::<N, W>(out, generator, preamble)?);
    }
    let mut w = RowWriter::with_text(out, preamble);
    let mut time = TimeColumn::new::<N>(&generator);
    let mut block = StaticBlock::default();
    let mut rows = 0u64;
    while generator.next_block(&mut block, BLOCK_SAMPLES) > 0 {
        static_rows::<N>(&mut w.text, &block, &mut time);
        w.flush_when_full()?;
        rows += block.len() as u64;
    }
    let bytes = w.finish()?;
    Ok(WriteSummary { rows, bytes })
}

/// How the time column of a static record is written: from each sample's index when that gives
/// exactly the text of its time (see [`CountedTime`]), else from the time itself.
#[derive(Debug, Clone)]
enum TimeColumn {
    /// From the sample index.
    Counted(CountedTime),
    /// From `time_s`, the text of its integer part kept while it repeats.
    Converted(IntegerText),
}

impl TimeColumn {
    /// The time column of `generator`'s record (before its first sample) written as `N`.
    fn new<N: NumberText>(generator: &StaticGenerator) -> TimeColumn {
        match CountedTime::new(generator.sample_rate_hz(), generator.remaining(), N::DECIMALS) {
            Some(counted) => TimeColumn::Counted(counted),
            None => TimeColumn::Converted(IntegerText::default()),
        }
    }
}

/// Room a static row needs: three numbers and their separators.
const STATIC_ROW_ROOM: usize = 3 * (NUMBER_ROOM + 1);
/// Rows written per room made.
const ROWS_PER_ROOM: usize = 256;

/// Appends the rows of `block` in the static layout (each with its newline).
fn static_rows<N: NumberText>(text: &mut TextBuf, block: &StaticBlock, time: &mut TimeColumn) {
    match time {
        TimeColumn::Counted(counted) => {
            counted.start_at(block.first_index);
            static_rows_timed::<N>(text, block, |text, _| counted.put_and_advance(text));
        }
        TimeColumn::Converted(repeat) => {
            static_rows_timed::<N>(text, block, |text, i| N::put_repeating(text, block.time_s[i], repeat));
        }
    }
}

/// [`static_rows`] with the time column of row i written by `time(text, i)`: the row loop
/// compiled with or without the temperature column.
#[inline(always)]
fn static_rows_timed<N: NumberText>(text: &mut TextBuf, block: &StaticBlock, time: impl FnMut(&mut Cursor<'_>, usize)) {
    if block.records_temperature {
        static_rows_with::<N, true>(text, block, time);
    } else {
        static_rows_with::<N, false>(text, block, time);
    }
}

/// [`static_rows_timed`] for one layout: the temperature column when `TEMPERATURE`.
#[inline(always)]
fn static_rows_with<N: NumberText, const TEMPERATURE: bool>(
    text: &mut TextBuf,
    block: &StaticBlock,
    mut time: impl FnMut(&mut Cursor<'_>, usize),
) {
    let mut start = 0;
    while start < block.len() {
        let stop = (start + ROWS_PER_ROOM).min(block.len());
        text.with_room((stop - start) * STATIC_ROW_ROOM, |text| {
            for (i, &output) in block.output.iter().enumerate().take(stop).skip(start) {
                time(text, i);
                text.byte(b',');
                N::put(text, output);
                if TEMPERATURE {
                    text.byte(b',');
                    N::put(text, block.temp_c[i]);
                }
                text.byte(b'\n');
            }
        });
        start = stop;
    }
}

/// Room a rate-table row needs: three numbers (the run too), the stroke label (at most 10 bytes)
/// and the separators.
const RATE_TABLE_ROW_ROOM: usize = 3 * NUMBER_ROOM + 16;

/// Simulates a rate-table test and writes it in the long layout; returns rows and bytes written.
pub fn write_rate_table_csv<W: Write>(
    mut out: W,
    model: &SensorModel,
    spec: &RateTableSpec,
    seed: u64,
    options: &SimCsvOptions,
) -> Result<WriteSummary, SimCsvError> {
    write_rate_table_csv_to(&mut out, model, spec, seed, options)
}

/// [`write_rate_table_csv`] to a writer behind a reference (compiled once; see
/// [`write_static_csv_to`]).
fn write_rate_table_csv_to(
    out: &mut dyn Write,
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
        w.text.with_room(RATE_TABLE_ROW_ROOM, |text| {
            N::put(text, s.rate_dps);
            text.byte(b',');
            text.integer(u64::from(s.run));
            text.byte(b',');
            text.text(s.stroke.label().as_bytes());
            text.byte(b',');
            N::put(text, s.output);
            if flagged {
                text.text(if s.settling { b",1" } else { b",0" });
            }
            text.byte(b'\n');
        });
        w.flush_when_full()?;
        rows += 1;
    }
    let bytes = w.finish()?;
    Ok(WriteSummary { rows, bytes })
}

/// The title line of a static record written by [`write_static_csv`].
pub const STATIC_RECORD_TITLE: &str = "gyrolab simulated static record";

/// The output-to-rate reference a simulated static record states in its comment lines
/// (`# sensor.output_unit = V`, `# sensor.scale_factor_per_dps = 0.0075`, `# sensor.null = 2.5`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StatedReference {
    /// The output unit of the record.
    pub output_unit: OutputUnit,
    /// Nominal scale factor K, output units per deg/s.
    pub scale_factor_per_dps: f64,
    /// Null (zero-rate output), output units.
    pub null: f64,
}

/// Reads the scale factor, null and output unit that gyrolab's simulator writes into the
/// comment lines at the top of a static record; `None` for any other file (first line not
/// [`STATIC_RECORD_TITLE`], a key missing or unreadable, or an I/O error: the file's reader
/// reports those). Reads at most the first 64 KiB, comment lines only.
///
/// ```
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// let dir = tempfile::tempdir()?;
/// let p = dir.path().join("s.csv");
/// let lines = ["# gyrolab simulated static record", "# sensor.output_unit = V"];
/// let more = ["# sensor.scale_factor_per_dps = 0.0075", "# sensor.null = 2.5", "time_s,output_v", "0,2.5"];
/// std::fs::write(&p, [&lines[..], &more[..]].concat().join("\n"))?;
/// let r = gyrolab_io::sim_csv::read_stated_reference(&p).ok_or("no reference")?;
/// assert_eq!((r.scale_factor_per_dps, r.null), (0.0075, 2.5));
/// # Ok(())
/// # }
/// ```
pub fn read_stated_reference(path: &std::path::Path) -> Option<StatedReference> {
    use std::io::{BufRead, Read};
    let (file, _) = crate::input_file::open_regular(path).ok()?;
    let reader = std::io::BufReader::new(file.take(64 * 1024));
    let mut lines = reader.lines();
    let first = lines.next()?.ok()?;
    if first.trim_start_matches('\u{feff}').trim_start_matches('#').trim() != STATIC_RECORD_TITLE {
        return None;
    }
    let (mut unit, mut k, mut null) = (None, None, None);
    for line in lines {
        let line = line.ok()?;
        let Some(comment) = line.strip_prefix('#') else { break };
        let Some((key, value)) = comment.split_once('=') else { continue };
        let value = value.trim();
        match key.trim() {
            "sensor.output_unit" => unit = OutputUnit::parse(value),
            "sensor.scale_factor_per_dps" => k = value.parse::<f64>().ok().filter(|k| k.is_finite() && *k != 0.0),
            "sensor.null" => null = value.parse::<f64>().ok().filter(|n| n.is_finite()),
            _ => {}
        }
    }
    Some(StatedReference { output_unit: unit?, scale_factor_per_dps: k?, null: null? })
}

/// Reads a simulation set-up (TOML: `seed`, `preset`, `[sensor]`, `[static_record]`,
/// `[rate_table]`); errors name the line and column.
pub fn read_sim_config(path: &std::path::Path) -> Result<gyrolab::sim::SimConfig, crate::DataError> {
    let text = crate::text::read_text_file(path, crate::text::MAX_CONFIG_BYTES, "a simulation set-up (TOML)")?;
    parse_sim_config(path, &text)
}

/// Parses a simulation set-up from TOML text and checks its values as written; `path` names it in
/// errors, which give the line of a bad value (`[sensor]`, `[static_record]`, `[rate_table]`).
pub fn parse_sim_config(path: &std::path::Path, text: &str) -> Result<gyrolab::sim::SimConfig, crate::DataError> {
    let cfg: gyrolab::sim::SimConfig = toml::from_str(text).map_err(|e| {
        let mut d = crate::DataError::new(
            path,
            format!("not a valid simulation set-up: {}", crate::text::short_message(e.message())),
        );
        if let Some(span) = e.span() {
            let (line, col) = crate::calibration::line_col(text, span.start);
            d = d.at_line(line).at_column(col, None);
        }
        d
    })?;
    let checks: [(&str, Result<(), gyrolab::sim::SimError>); 3] = [
        ("sensor", cfg.sensor_model().validate()),
        ("static_record", cfg.static_record.validate()),
        ("rate_table", cfg.rate_table.validate()),
    ];
    for (section, r) in checks {
        let Err(e) = r else { continue };
        use crate::calibration::{value_line, TomlStep};
        let place_of = |parameter: &'static str| {
            let mut place = vec![TomlStep::Key(section)];
            for k in parameter.split('.') {
                place.push(TomlStep::Key(k));
                // `temperature.steps.at_s`: the step at fault, then its key.
                if let (Some(i), "steps") = (e.step(), k) {
                    place.push(TomlStep::Index(i));
                }
            }
            place
        };
        let parameters = e.parameters();
        // The first key at fault the file writes; else the table's line, and the value said to
        // be a preset's or the default.
        let written = parameters.iter().find_map(|p| value_line(text, &place_of(p)));
        let mut d = match written {
            Some(_) => crate::DataError::new(path, format!("[{section}] {e}")),
            None => {
                let (table, key) = match parameters[0].rsplit_once('.') {
                    Some((sub, key)) => (format!("[{section}.{sub}]"), key),
                    None => (format!("[{section}]"), parameters[0]),
                };
                crate::DataError::new(
                    path,
                    format!(
                        "[{section}] {e} (`{key}` is not written in {table}: the value is the preset's or the default)"
                    ),
                )
            }
        };
        let table_line = || {
            let place = place_of(parameters[0]);
            (1..place.len()).rev().find_map(|n| value_line(text, &place[..n]))
        };
        if let Some(l) = written.or_else(table_line) {
            d = d.at_line(l);
        }
        return Err(d);
    }
    Ok(cfg)
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

#[cfg(test)]
mod time_column_tests {
    use super::*;
    use gyrolab::sim::Preset;

    /// The rows of a whole record, its time column written as `time` gives.
    fn rows<N: NumberText>(spec: &StaticSpec, block_samples: usize, counted: bool) -> (String, bool) {
        let model = SensorModel::preset(Preset::Adxrs646);
        let mut generator = StaticGenerator::new(&model, spec, 4).unwrap();
        let mut time = TimeColumn::new::<N>(&generator);
        let was_counted = matches!(time, TimeColumn::Counted(_));
        if !counted {
            time = TimeColumn::Converted(IntegerText::default());
        }
        let mut text = TextBuf::new(0);
        let mut block = StaticBlock::default();
        while generator.next_block(&mut block, block_samples) > 0 {
            static_rows::<N>(&mut text, &block, &mut time);
        }
        (String::from_utf8(text.bytes[..text.end].to_vec()).unwrap(), was_counted)
    }

    fn counted_equals_converted<N: NumberText>(sample_rate_hz: f64, duration_s: f64, counts: bool) {
        let spec = StaticSpec { sample_rate_hz, duration_s, ..StaticSpec::default() };
        for block_samples in [1, 7, 4096] {
            let (counted, was_counted) = rows::<N>(&spec, block_samples, true);
            let (converted, _) = rows::<N>(&spec, block_samples, false);
            assert_eq!(was_counted, counts, "{sample_rate_hz} Hz, {:?} decimals", N::DECIMALS);
            assert_eq!(counted, converted, "{sample_rate_hz} Hz, {:?} decimals", N::DECIMALS);
        }
    }

    #[test]
    fn time_counted_from_the_index_has_the_text_of_the_time_itself() {
        // Rates that divide 10^D: counted; crossing many whole seconds and block ends.
        counted_equals_converted::<Fixed<7>>(100.0, 130.0, true);
        counted_equals_converted::<Fixed<2>>(100.0, 130.0, true);
        counted_equals_converted::<Fixed<3>>(125.0, 100.0, true);
        counted_equals_converted::<Fixed<4>>(2000.0, 8.0, true);
        counted_equals_converted::<Fixed<8>>(256.0, 50.0, true);
        counted_equals_converted::<Fixed<15>>(1000.0, 1.0, true);
        // 10^15 x 1.2 s is past 2^50: written from the time itself.
        counted_equals_converted::<Fixed<15>>(1000.0, 1.2, false);
        counted_equals_converted::<Fixed<0>>(1.0, 5000.0, true);
        // Rates that do not: the time itself, written as before.
        counted_equals_converted::<Fixed<1>>(100.0, 50.0, false);
        counted_equals_converted::<Fixed<3>>(33.0, 50.0, false);
        counted_equals_converted::<Fixed<6>>(33.3, 50.0, false);
        counted_equals_converted::<Shortest>(100.0, 50.0, false);
    }

    #[test]
    fn time_is_counted_only_where_exactness_is_proven() {
        // M = k 10^D / f below 2^50 for the last sample k, and under 10^8 whole seconds.
        let limit = 1u64 << 50;
        // q = floor(2^50 / 10^7): q samples end at (q - 1) 10^7, q + 1 at q 10^7 < 2^50, q + 2 past it.
        assert!(CountedTime::new(100.0, limit / 10_000_000 + 1, Some(9)).is_some());
        assert!(CountedTime::new(100.0, limit / 10_000_000 + 2, Some(9)).is_none());
        assert!(CountedTime::new(100.0, 10_000_000_000, Some(2)).is_some());
        assert!(CountedTime::new(100.0, 10_000_000_001, Some(2)).is_none());
        assert!(CountedTime::new(1.0, 100_000_000, Some(0)).is_some());
        assert!(CountedTime::new(1.0, 100_000_001, Some(0)).is_none());
        assert!(CountedTime::new(200_000.0, 10, Some(7)).is_none());
        assert!(CountedTime::new(0.5, 10, Some(7)).is_none());
        assert!(CountedTime::new(100.0, 10, None).is_none());
    }

    /// The malformed-input campaign's simulator set-ups (issue 55), each located to the line of
    /// the key at fault: rails that do not enclose the null, an inverted flicker range, a
    /// temperature step going back in time (the step's own line, in an array of tables and in an
    /// inline array), a repeated rate; a value the file does not write is said to be so.
    #[test]
    fn every_simulator_set_up_error_names_its_line_and_key() {
        let p = std::path::Path::new("sim.toml");
        let head = "seed = 3\n\n[sensor]\narw_deg_rt_h = 0.5\n";
        let cases: Vec<(String, u64, &str)> = vec![
            (format!("{head}null = 2.5\noutput_rail_low = 3.0\noutput_rail_high = 5.0\n"), 6, "output_rail_low"),
            (format!("{head}flicker_tau_min_s = 100.0\nflicker_tau_max_s = 10.0\n"), 6, "flicker_tau_max_s"),
            (
                format!(
                    "{head}\n[static_record]\nduration_s = 60\n\n[static_record.temperature]\nkind = \"steps\"\nstart_c = 20.0\n\n\
                     [[static_record.temperature.steps]]\nat_s = 10.0\ntemp_c = 30.0\n\n\
                     [[static_record.temperature.steps]]\nat_s = 5.0\ntemp_c = 40.0\n"
                ),
                18,
                "step 2",
            ),
            (
                format!(
                    "{head}\n[static_record.temperature]\nkind = \"steps\"\nstart_c = 20.0\nsteps = [\n  {{ at_s = 10.0, temp_c = 30.0 }},\n  {{ at_s = 20.0, temp_c = nan }},\n]\n"
                ),
                11,
                "temp_c",
            ),
            (format!("{head}\n[rate_table]\nruns = 2\nrates_dps = [-10.0, 10.0, 10.0]\n"), 8, "rates_dps"),
        ];
        for (text, line, says) in &cases {
            let e = parse_sim_config(p, text).unwrap_err();
            assert_eq!(e.line, Some(*line), "{e}\n{text}");
            assert!(e.message.contains(says), "{e}");
        }
        // A preset's value the file does not write: said so, at its table's line.
        let text = "seed = 3\npreset = \"adxrs646\"\n\n[sensor]\noutput_rail_high = -100.0\n";
        let e = parse_sim_config(p, text).unwrap_err();
        assert_eq!(e.line, Some(5), "{e}");
    }
}
