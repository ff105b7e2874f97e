//! The static (bias) test of a whole record: a file streamed twice (figures, then outliers, memory
//! per block), or a record already in memory (a Parquet table, a recording's topic); and the
//! window means of a file for the temperature and power-up parts of a plan. The figures are the
//! core's ([`gyrolab::static_test`], [`gyrolab::window_means`]); the reading is gyrolab-io's
//! ([`gyrolab_io::series`]). Moved here from gyrolab-io (issue 52: evaluation is eval's work, not
//! the reader's).

use gyrolab::dropout::{DropoutMarker, DropoutVerdict};
use gyrolab::static_test::{OutlierScan, StaticTestAccumulator, StaticTestConfig, StaticTestResult};
use gyrolab_io::series::{
    read_series, ChannelInfo, SeriesBlock, SeriesData, SeriesHeader, SeriesOptions, SeriesReader, SeriesSummary,
};
use gyrolab_io::DataError;
use std::path::Path;

/// Each channel's static-test options: `config_for`'s, with the channel's name, unit and the
/// header's sample rate when none is set.
fn channel_configs(
    header: &SeriesHeader,
    config_for: &mut impl FnMut(&ChannelInfo) -> StaticTestConfig,
) -> Vec<StaticTestConfig> {
    header
        .channels
        .iter()
        .map(|c| {
            let mut cfg = config_for(c);
            cfg.channel = c.name.clone();
            cfg.output_unit = c.unit;
            if cfg.sample_rate_hz.is_none() {
                cfg.sample_rate_hz = header.sample_rate_hz;
            }
            cfg
        })
        .collect()
}

/// Evaluates the static (bias) test of every channel of a file, streaming it twice (figures,
/// then outliers); `config_for` gives each channel's options (scale factor, null, latitude ...).
pub fn evaluate_static_file(
    path: impl AsRef<Path>,
    options: &SeriesOptions,
    mut config_for: impl FnMut(&ChannelInfo) -> StaticTestConfig,
) -> Result<(Vec<StaticTestResult>, SeriesSummary), DataError> {
    let path = path.as_ref();
    let mut r = SeriesReader::open(path, options)?;
    let header = r.header().clone();
    let configs = channel_configs(&header, &mut config_for);
    let wrap = |ch: &str, e: gyrolab::static_test::StaticTestError| {
        DataError::new(path, format!("channel '{}': {e}", gyrolab_io::text::excerpt(ch)))
    };
    let mut accs = Vec::with_capacity(configs.len());
    for cfg in &configs {
        accs.push(StaticTestAccumulator::new(cfg.clone()).map_err(|e| wrap(&cfg.channel, e))?);
    }
    while let Some(b) = r.next_block()? {
        for (k, acc) in accs.iter_mut().enumerate() {
            acc.push(&b.samples(k)).map_err(|e| wrap(&configs[k].channel, e))?;
        }
    }
    let summary = SeriesSummary { header: header.clone(), rows: r.rows(), quality: r.quality().clone() };
    let mut firsts = Vec::with_capacity(accs.len());
    let mut scans = Vec::with_capacity(accs.len());
    for (acc, cfg) in accs.into_iter().zip(&configs) {
        let first = acc.finish().map_err(|e| wrap(&cfg.channel, e))?;
        scans.push(OutlierScan::new(&first, cfg).map_err(|e| wrap(&cfg.channel, e))?);
        firsts.push(first);
    }
    // The second pass can only find outliers where the first pass's extremes allow them.
    if firsts.iter().all(|f| !f.outlier_scan_needed) {
        let results = firsts.into_iter().zip(&configs).map(|(f, cfg)| f.with_no_outliers(cfg)).collect();
        return Ok((results, summary));
    }
    let mut r = SeriesReader::open(path, options)?;
    while let Some(b) = r.next_block()? {
        for (k, scan) in scans.iter_mut().enumerate() {
            scan.push(&b.samples(k)).map_err(|e| wrap(&configs[k].channel, e))?;
        }
    }
    let mut results = Vec::with_capacity(scans.len());
    for ((scan, first), cfg) in scans.into_iter().zip(firsts).zip(&configs) {
        results.push(scan.finish(first).map_err(|e| wrap(&cfg.channel, e))?);
    }
    Ok((results, summary))
}

/// Evaluates the static (bias) test of every channel of a record held in memory (a Parquet
/// table, a recording's topic) as [`evaluate_static_file`] does for a file; the dropout rows of
/// the kinds `dropouts` names (all zero, repeated; [`gyrolab::dropout`]) are left out as missing
/// (counted in the summary's quality).
pub fn evaluate_static_data(
    data: &mut SeriesData,
    dropouts: DropoutVerdict,
    mut config_for: impl FnMut(&ChannelInfo) -> StaticTestConfig,
) -> Result<(Vec<StaticTestResult>, SeriesSummary), DataError> {
    let header = data.header.clone();
    let path = header.file.clone();
    let nch = data.channels.len();
    if dropouts.any() && nch > 0 {
        let mut rows = Vec::new();
        let refs: Vec<&[f64]> = data.channels.iter().map(|c| &c[..]).collect();
        DropoutMarker::new(dropouts).mark_block(&refs, |i, kind| rows.push((i, kind)));
        for (i, kind) in rows {
            data.channels.iter_mut().for_each(|c| c[i] = f64::NAN);
            data.quality.count_dropout(kind, data.lines.get(i).unwrap_or(0));
        }
    }
    let configs = channel_configs(&header, &mut config_for);
    let wrap = |ch: &str, e: gyrolab::static_test::StaticTestError| {
        DataError::new(&path, format!("channel '{}': {e}", gyrolab_io::text::excerpt(ch)))
    };
    let lines = data.lines.to_vec();
    let block = SeriesBlock {
        first_line: lines.first().copied().unwrap_or(0),
        lines: &lines,
        time: data.time.as_deref(),
        temp: data.temperature.as_deref(),
        table_rate: data.table_rate.as_deref(),
        channels: &data.channels,
    };
    let mut results = Vec::with_capacity(configs.len());
    for (k, cfg) in configs.iter().enumerate() {
        let mut acc = StaticTestAccumulator::new(cfg.clone()).map_err(|e| wrap(&cfg.channel, e))?;
        acc.push(&block.samples(k)).map_err(|e| wrap(&cfg.channel, e))?;
        let first = acc.finish().map_err(|e| wrap(&cfg.channel, e))?;
        if !first.outlier_scan_needed {
            results.push(first.with_no_outliers(cfg));
            continue;
        }
        let mut scan = OutlierScan::new(&first, cfg).map_err(|e| wrap(&cfg.channel, e))?;
        scan.push(&block.samples(k)).map_err(|e| wrap(&cfg.channel, e))?;
        results.push(scan.finish(first).map_err(|e| wrap(&cfg.channel, e))?);
    }
    let summary = SeriesSummary { header, rows: lines.len() as u64, quality: data.quality.clone() };
    Ok((results, summary))
}

/// Means of consecutive `window_s`-second windows of one output channel (index into the
/// header's channels) and the temperature, streaming the file once (memory per window, not
/// per sample). The sample rate is the options' one, else the mean interval of the time column.
pub fn window_means_file(
    path: impl AsRef<Path>,
    options: &SeriesOptions,
    channel: usize,
    window_s: f64,
) -> Result<Vec<gyrolab::window_means::WindowMean>, DataError> {
    let path = path.as_ref();
    let mut r = SeriesReader::open(path, options)?;
    let fs = match options.sample_rate_hz {
        Some(f) => f,
        None => {
            // The time column's mean interval, from a first pass over the time stamps.
            let (mut first, mut last, mut n) = (None, 0.0, 0u64);
            read_series(path, options, |_, b| {
                if let Some(t) = b.time {
                    if first.is_none() {
                        first = t.first().copied();
                    }
                    if let Some(&l) = t.last() {
                        last = l;
                    }
                    n += t.len() as u64;
                }
                Ok(())
            })?;
            match first {
                Some(f0) if n > 1 && last > f0 => (n - 1) as f64 / (last - f0),
                _ => return Err(DataError::new(path, "cannot tell the sample rate: give it (sample_rate_hz)")),
            }
        }
    };
    let mut acc = gyrolab::window_means::WindowMeanAccumulator::new(window_s, fs)
        .ok_or_else(|| DataError::new(path, format!("window of {window_s} s at {fs} Hz: expected positive numbers")))?;
    while let Some(b) = r.next_block()? {
        let Some(out) = b.channels.get(channel) else {
            return Err(DataError::new(path, format!("no output channel number {}", channel + 1)));
        };
        acc.push(out, b.temp);
    }
    Ok(acc.finish())
}
