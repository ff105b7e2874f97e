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

/// Exact powers of ten 10^0 ..= 10^15 (all exactly representable in f64).
const POW10: [f64; 16] = [1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15];
/// Largest magnitude written through the integer path (2^53).
const EXACT_INT_LIMIT: f64 = 9_007_199_254_740_992.0;
/// Buffer size at which rows are handed to the writer.
const FLUSH_AT: usize = 1 << 16;

/// The eight decimal digits of `n` < 10^8 as ASCII, zero-padded, the first digit in the lowest
/// byte (SWAR: both four-digit halves, then both digit pairs of each, then both digits of each
/// pair, are split at once with multiplications by reciprocals that are exact in these ranges).
#[inline(always)]
fn eight_digits(n: u64) -> u64 {
    // Lanes of 32 bits: the first four digits (n / 10^4) in the low lane.
    let quads = (n / 10_000) | ((n % 10_000) << 32);
    // In each lane, abcd / 100 = (abcd * 5243) >> 19 for abcd < 10^4; pairs in 16-bit lanes.
    let hundreds = ((quads * 5243) >> 19) & 0x0000_007f_0000_007f;
    let pairs = hundreds | ((quads - hundreds * 100) << 16);
    // In each 16-bit lane, ab / 10 = (ab * 103) >> 10 for ab < 100; digits in bytes.
    let tens = ((pairs * 103) >> 10) & 0x000f_000f_000f_000f;
    let digits = tens | ((pairs - tens * 10) << 8);
    digits + 0x3030_3030_3030_3030
}

/// Appends `v` / 10^decimals in fixed notation (`decimals` digits after the point, at least one
/// before it), with a minus sign when `negative`. `v` must be below 10^16, `decimals` at most 15.
#[inline]
fn push_fixed(out: &mut Vec<u8>, v: u64, decimals: usize, negative: bool) {
    // Sixteen digits, the first in the lowest byte.
    let text = u128::from(eight_digits(v / 100_000_000)) | (u128::from(eight_digits(v % 100_000_000)) << 64);
    let leading_zeros = ((text - u128::from_le_bytes([b'0'; 16])).trailing_zeros() / 8) as usize;
    let width = (16 - leading_zeros).max(decimals + 1);
    if negative {
        out.push(b'-');
    }
    if width >= 16 {
        // No room for the point in 16 bytes: in two parts.
        let digits = text.to_le_bytes();
        let (int, frac) = digits[16 - width..].split_at(width - decimals);
        out.extend_from_slice(int);
        if decimals > 0 {
            out.push(b'.');
            out.extend_from_slice(frac);
        }
        return;
    }
    // The `width` significant digits from byte 0, then the point put in after the integer part.
    let digits = text >> (8 * (16 - width));
    let int_bytes = 8 * (width - decimals) as u32;
    let (line, len) = if decimals > 0 {
        let int_mask = (1u128 << int_bytes) - 1;
        ((digits & int_mask) | (u128::from(b'.') << int_bytes) | ((digits & !int_mask) << 8), width + 1)
    } else {
        (digits, width)
    };
    // Sixteen bytes at once, then cut back to the length.
    let start = out.len();
    out.extend_from_slice(&line.to_le_bytes());
    out.truncate(start + len);
}

/// `x` rounded half away from zero, as `f64::round` (sign of zero included), for |x| < 2^53 (the truncation by an
/// integer conversion and the difference x - trunc(x) are exact there).
#[inline(always)]
fn round_half_away(x: f64) -> f64 {
    let t = (x as i64 as f64).copysign(x);
    let d = x - t;
    if d >= 0.5 {
        t + 1.0
    } else if d <= -0.5 {
        t - 1.0
    } else {
        t
    }
}

/// Row formatter over a block buffer.
struct RowWriter<W: Write> {
    out: W,
    buf: Vec<u8>,
    ryu: ryu::Buffer,
    format: NumberFormat,
    bytes: u64,
}

impl<W: Write> RowWriter<W> {
    fn new(out: W, format: NumberFormat) -> Result<Self, SimCsvError> {
        if let NumberFormat::Fixed { decimals } = format {
            if decimals > 15 {
                return Err(SimCsvError::InvalidOption(format!("fixed decimals = {decimals}: must be within 0..=15")));
            }
        }
        Ok(RowWriter { out, buf: Vec::with_capacity(FLUSH_AT + 1024), ryu: ryu::Buffer::new(), format, bytes: 0 })
    }

    fn text(&mut self, s: &str) {
        self.buf.extend_from_slice(s.as_bytes());
    }

    fn comment(&mut self, line: &str) {
        // One comment line per text line, so that no text can end the comment block early.
        for part in line.split('\n') {
            self.buf.extend_from_slice(b"# ");
            self.buf.extend_from_slice(part.trim_end_matches('\r').as_bytes());
            self.buf.push(b'\n');
        }
    }

    fn unsigned(&mut self, v: u64) {
        if v < 10_000_000_000_000_000 {
            push_fixed(&mut self.buf, v, 0, false);
        } else {
            self.buf.extend_from_slice(v.to_string().as_bytes());
        }
    }

    fn shortest(&mut self, v: f64) {
        let s = self.ryu.format(v);
        self.buf.extend_from_slice(s.as_bytes());
    }

    #[inline]
    fn number(&mut self, v: f64) {
        match self.format {
            NumberFormat::Shortest => self.shortest(v),
            NumberFormat::Fixed { decimals } => {
                let d = usize::from(decimals);
                let unrounded = v * POW10[d];
                if unrounded.is_nan() || unrounded.abs() >= EXACT_INT_LIMIT {
                    self.shortest(v);
                    return;
                }
                let scaled = round_half_away(unrounded);
                if scaled.abs() >= EXACT_INT_LIMIT {
                    // Too large for the integer path (or not finite).
                    self.shortest(v);
                    return;
                }
                // ok: |scaled| < 2^53, so the conversion to u64 is exact.
                push_fixed(&mut self.buf, scaled.abs() as u64, d, scaled < 0.0);
            }
        }
    }

    #[inline]
    fn end_row(&mut self) -> std::io::Result<()> {
        self.buf.push(b'\n');
        if self.buf.len() >= FLUSH_AT {
            self.flush_buffer()?;
        }
        Ok(())
    }

    fn flush_buffer(&mut self) -> std::io::Result<()> {
        self.out.write_all(&self.buf)?;
        self.bytes += self.buf.len() as u64;
        self.buf.clear();
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

fn write_preamble<W: Write>(
    w: &mut RowWriter<W>,
    title: &str,
    seed: u64,
    options: &SimCsvOptions,
    model: &SensorModel,
    record: Vec<(&'static str, String)>,
    truth: Vec<String>,
) {
    w.comment(title);
    w.comment(&format!("seed = {seed}"));
    for c in &options.comments {
        w.comment(c);
    }
    for (k, v) in model.parameter_lines() {
        w.comment(&format!("sensor.{k} = {v}"));
    }
    for (k, v) in record {
        w.comment(&format!("record.{k} = {v}"));
    }
    for t in truth {
        w.comment(&t);
    }
}

/// Simulates a static record and writes it in the static layout; returns rows and bytes written.
/// With `options.pipelined`, three threads share the work: one simulates, one formats, one
/// writes (same bytes as with one thread).
pub fn write_static_csv<W: Write + Send>(
    out: W,
    model: &SensorModel,
    spec: &StaticSpec,
    seed: u64,
    options: &SimCsvOptions,
) -> Result<WriteSummary, SimCsvError> {
    let generator = StaticGenerator::new(model, spec, seed)?;
    if !options.pipelined {
        return write_static_rows(RowWriter::new(out, options.number_format)?, generator, seed, model, spec, options);
    }
    let (to_output, from_formatter) = std::sync::mpsc::sync_channel::<Vec<u8>>(4);
    let (to_formatter, spare_buffers) = std::sync::mpsc::channel::<Vec<u8>>();
    std::thread::scope(|scope| {
        let output = scope.spawn(move || -> std::io::Result<()> {
            let mut out = out;
            for text in from_formatter {
                out.write_all(&text)?;
                // The formatter may have finished: a failed return of the buffer is harmless.
                let _ = to_formatter.send(text);
            }
            out.flush()
        });
        let sink = ThreadedSink { to_output, spare_buffers };
        let formatted = RowWriter::new(sink, options.number_format)
            .map_err(|e| (e, false))
            .and_then(|w| write_static_rows(w, generator, seed, model, spec, options).map_err(|e| (e, true)));
        // The sink is dropped by now, so the output thread ends once it has written everything.
        let written = output.join().unwrap_or_else(|_| Err(std::io::Error::other("the output thread failed")));
        match (formatted, written) {
            (Ok(summary), Ok(())) => Ok(summary),
            // An output error stops the formatter too: report the output's own error.
            (Err((_, true)), Err(e)) | (Ok(_), Err(e)) => Err(SimCsvError::Io(e)),
            (Err((e, _)), _) => Err(e),
        }
    })
}

/// A [`Write`] that hands its bytes to the output thread (copies into recycled buffers).
struct ThreadedSink {
    to_output: std::sync::mpsc::SyncSender<Vec<u8>>,
    spare_buffers: std::sync::mpsc::Receiver<Vec<u8>>,
}

impl Write for ThreadedSink {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        let mut text = self.spare_buffers.try_recv().unwrap_or_default();
        text.clear();
        text.extend_from_slice(bytes);
        self.to_output.send(text).map_err(|_| std::io::Error::other("the output stopped"))?;
        Ok(bytes.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// The preamble and rows of a static record (simulated on a second thread with
/// `options.pipelined`).
fn write_static_rows<W: Write>(
    mut w: RowWriter<W>,
    generator: StaticGenerator,
    seed: u64,
    model: &SensorModel,
    spec: &StaticSpec,
    options: &SimCsvOptions,
) -> Result<WriteSummary, SimCsvError> {
    let mut truth = vec![format!("truth.earth_rate_dps = {:?}", generator.earth_rate_dps())];
    truth.extend(generator.flicker_design().map(flicker_comment));
    write_preamble(&mut w, "gyrolab simulated static record", seed, options, model, spec.parameter_lines(), truth);
    let with_temp = generator.records_temperature();
    w.text(&static_header(model.output_unit, with_temp));
    w.end_row()?;
    let mut rows = 0u64;
    if options.pipelined {
        let (to_writer, from_generator) = std::sync::mpsc::sync_channel::<Vec<StaticSample>>(4);
        let (to_generator, from_writer) = std::sync::mpsc::channel::<Vec<StaticSample>>();
        let written = std::thread::scope(|scope| {
            scope.spawn(move || {
                let mut generator = generator;
                loop {
                    let mut block = from_writer.try_recv().unwrap_or_else(|_| Vec::with_capacity(BLOCK_SAMPLES));
                    block.clear();
                    block.extend(generator.by_ref().take(BLOCK_SAMPLES));
                    // A send error means the writer stopped (an I/O error): stop too.
                    if block.is_empty() || to_writer.send(block).is_err() {
                        break;
                    }
                }
            });
            for block in from_generator {
                for s in &block {
                    write_static_row(&mut w, s)?;
                }
                rows += block.len() as u64;
                // The generator may have finished: a failed return of the buffer is harmless.
                let _ = to_generator.send(block);
            }
            Ok::<(), std::io::Error>(())
        });
        written?;
    } else {
        for s in generator {
            write_static_row(&mut w, &s)?;
            rows += 1;
        }
    }
    let bytes = w.finish()?;
    Ok(WriteSummary { rows, bytes })
}

#[inline]
fn write_static_row<W: Write>(w: &mut RowWriter<W>, s: &StaticSample) -> std::io::Result<()> {
    w.number(s.time_s);
    w.buf.push(b',');
    w.number(s.output);
    if let Some(t) = s.temp_c {
        w.buf.push(b',');
        w.number(t);
    }
    w.end_row()
}

/// Simulates a rate-table test and writes it in the long layout; returns rows and bytes written.
pub fn write_rate_table_csv<W: Write>(
    out: W,
    model: &SensorModel,
    spec: &RateTableSpec,
    seed: u64,
    options: &SimCsvOptions,
) -> Result<WriteSummary, SimCsvError> {
    let generator = RateTableGenerator::new(model, spec, seed)?;
    let mut w = RowWriter::new(out, options.number_format)?;
    let mut truth = vec![format!("truth.earth_rate_dps = {:?}", generator.earth_rate_dps())];
    truth.extend(generator.flicker_design().map(flicker_comment));
    let title = "gyrolab simulated rate-table test: runs of a forward stroke (rates rising) then a reverse \
                 stroke (rates falling)";
    write_preamble(&mut w, title, seed, options, model, spec.parameter_lines(), truth);
    let flagged = generator.flags_settling();
    w.text(&rate_table_header(model.output_unit, flagged));
    w.end_row()?;
    let mut rows = 0u64;
    for s in generator {
        w.number(s.rate_dps);
        w.buf.push(b',');
        w.unsigned(u64::from(s.run));
        w.buf.push(b',');
        w.text(s.stroke.label());
        w.buf.push(b',');
        w.number(s.output);
        if flagged {
            w.text(if s.settling { ",1" } else { ",0" });
        }
        w.end_row()?;
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

    proptest::proptest! {
        /// Fixed notation by SWAR digits equals the plain integer formatting of the same value.
        #[test]
        fn push_fixed_equals_integer_formatting(v in 0u64..10_000_000_000_000_000, decimals in 0usize..16, negative: bool) {
            let mut out = Vec::new();
            push_fixed(&mut out, v, decimals, negative);
            let unit = 10u64.pow(decimals as u32);
            let sign = if negative { "-" } else { "" };
            let want = if decimals == 0 {
                format!("{sign}{v}")
            } else {
                format!("{sign}{}.{:0decimals$}", v / unit, v % unit)
            };
            proptest::prop_assert_eq!(String::from_utf8(out).unwrap(), want);
        }
    }

    proptest::proptest! {
        /// Rounding by truncation equals `f64::round` below 2^53.
        #[test]
        fn round_half_away_equals_round(x in -9.0e15f64..9.0e15, k in 0i32..6) {
            let x = x / 10f64.powi(k * 3);
            proptest::prop_assert_eq!(round_half_away(x).to_bits(), x.round().to_bits(), "{}", x);
        }
    }

    #[test]
    fn round_half_away_at_halves() {
        for x in [0.5, -0.5, 1.5, -2.5, 0.49999999999999994, -0.49999999999999994, 4503599627370495.5, 0.0, -0.0] {
            assert_eq!(round_half_away(x).to_bits(), x.round().to_bits(), "{x}");
        }
    }

    #[test]
    fn eight_digits_of_edge_values() {
        for n in [0u64, 1, 9, 10, 99, 100, 999, 1_000, 9_999, 10_000, 12_345_678, 99_999_999] {
            assert_eq!(eight_digits(n).to_le_bytes(), *format!("{n:08}").as_bytes(), "{n}");
        }
        // The two four-digit lanes are computed apart (masked): n = k * 10^4 + k gives every
        // value 0..=9999 in both, so this covers every lane value exhaustively.
        for n in (0u64..10_000).map(|k| k * 10_000 + k) {
            assert_eq!(eight_digits(n).to_le_bytes(), *format!("{n:08}").as_bytes(), "{n}");
        }
    }

    #[test]
    fn fixed_decimals_are_rounded_and_padded() {
        let mut out = Vec::new();
        let mut w = RowWriter::new(&mut out, NumberFormat::Fixed { decimals: 4 }).unwrap();
        for v in [2.5, -0.00004, -0.00006, 1.23456, 0.0, 12345.25, 1e300] {
            w.number(v);
            w.buf.push(b' ');
        }
        w.finish().unwrap();
        // A negative value that rounds to zero is written without its sign.
        assert_eq!(String::from_utf8(out).unwrap(), "2.5000 0.0000 -0.0001 1.2346 0.0000 12345.2500 1e300 ");
        assert!(RowWriter::new(Vec::new(), NumberFormat::Fixed { decimals: 16 }).is_err());
        let mut out = Vec::new();
        let mut w = RowWriter::new(&mut out, NumberFormat::Fixed { decimals: 3 }).unwrap();
        for v in [0.005, -0.005, 9.9996, 1234567.0, 99.0] {
            w.number(v);
            w.buf.push(b' ');
        }
        w.unsigned(0);
        w.buf.push(b' ');
        w.unsigned(18_446_744_073_709_551_615);
        w.finish().unwrap();
        assert_eq!(String::from_utf8(out).unwrap(), "0.005 -0.005 10.000 1234567.000 99.000 0 18446744073709551615");
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
