//! The report renders in a real browser: `gyrolab demo --out DIR`, then headless Chromium takes
//! a screenshot of report.html and the test checks that the SVG plots are drawn (pixels in the
//! plot colours across several horizontal bands of the page, and those bands are not blank).
//!
//! Needs /usr/bin/chromium (Debian package `chromium`; `scripts/install-test-deps.sh` installs
//! it, CI runs that script). Without it the test fails, unless GYROLAB_SKIP_BROWSER=1.

use crate::common;
use common::gyrolab;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const CHROMIUM: &str = "/usr/bin/chromium";
const WIDTH: u32 = 1200;
/// Tall enough for the header (with the ISO/IEC 17025 7.8.2.1 rows a printed report can be
/// completed in, issue 53), the summary (which lists the Allan terms known only as upper
/// bounds, "at most ...", since issue 33) and the first axis's plots.
const HEIGHT: u32 = 3400;

/// Runs headless Chromium on `html`, writing a screenshot `height` pixels tall to `png`; at
/// most 180 s.
fn screenshot(html: &Path, png: &Path, profile: &Path, height: u32) {
    let url = format!("file://{}", html.display());
    let mut child = Command::new(CHROMIUM)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--hide-scrollbars",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg(format!("--screenshot={}", png.display()))
        .arg(format!("--window-size={WIDTH},{height}"))
        .arg(url)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("cannot start chromium");
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            assert!(status.success(), "chromium exited with {status}");
            return;
        }
        if start.elapsed() > Duration::from_secs(180) {
            let _ = child.kill();
            panic!("chromium did not finish within 180 s");
        }
        std::thread::sleep(Duration::from_millis(200));
    }
}

/// RGB pixels of a PNG, row by row.
fn load_rgb(png: &Path) -> (u32, u32, Vec<[u8; 3]>) {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(png).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    let channels = info.color_type.samples();
    assert!(info.bit_depth == png::BitDepth::Eight && channels >= 3, "unexpected PNG format {info:?}");
    let px = buf[..info.buffer_size()].chunks(channels).map(|c| [c[0], c[1], c[2]]).collect();
    (info.width, info.height, px)
}

/// Colours the plots draw their series in (gyrolab_report::plot::PALETTE, first three).
const PLOT_COLOURS: [[u8; 3]; 3] = [[0, 114, 178], [213, 94, 0], [0, 158, 115]];

fn is_plot_colour(p: [u8; 3]) -> bool {
    PLOT_COLOURS.iter().any(|c| c.iter().zip(p).all(|(a, b)| (i32::from(*a) - i32::from(b)).abs() <= 30))
}

/// Whether Chromium is there; `false` (with a loud SKIPPED line) only when GYROLAB_SKIP_BROWSER=1,
/// else a missing browser fails the test.
fn browser_available() -> bool {
    if std::env::var("GYROLAB_SKIP_BROWSER").is_ok_and(|v| v == "1") {
        eprintln!("\n*** SKIPPED: GYROLAB_SKIP_BROWSER=1: browser test skipped ***\n");
        return false;
    }
    assert!(
        Path::new(CHROMIUM).exists(),
        "{CHROMIUM} not found: the browser test needs Chromium. Install it with \
         `bash scripts/install-test-deps.sh` (or `apt-get install -y chromium`), \
         or set GYROLAB_SKIP_BROWSER=1 to skip this test."
    );
    true
}

/// Bands of 200 px of a screenshot: (bands holding plot colours, plot-coloured pixels).
fn plot_bands(w: u32, h: u32, px: &[[u8; 3]]) -> (u32, usize) {
    let band = 200;
    let mut plot_bands = 0;
    let mut total_plot_px = 0;
    for b in 0..h / band {
        let rows = &px[(b * band * w) as usize..((b + 1) * band * w) as usize];
        let coloured = rows.iter().filter(|p| is_plot_colour(**p)).count();
        let non_white = rows.iter().filter(|p| p.iter().any(|c| *c < 235)).count();
        total_plot_px += coloured;
        if coloured > 150 {
            plot_bands += 1;
            assert!(non_white > coloured, "band {b}: plot colours but nothing else drawn");
        }
    }
    (plot_bands, total_plot_px)
}

/// The example plan with every test of a lab's program (examples/test_program/plan.toml, its
/// SIMULATED records written here by the example's generator), evaluated by `gyrolab eval` and
/// looked at in headless Chromium: the page holds the plots of every section that draws one.
#[test]
fn the_test_program_report_renders_in_headless_chromium() {
    if !browser_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("program");
    std::fs::create_dir_all(&data).unwrap();
    gyrolab_eval::program_sim::write_test_program(&data, 2026).unwrap();
    let out = dir.path().join("report");
    gyrolab().arg("eval").arg(data.join("plan.toml")).arg("--out").arg(&out).arg("--quiet").assert().code(0);
    let png = dir.path().join("shot.png");
    let tall = 24_000;
    screenshot(&out.join("report.html"), &png, &dir.path().join("profile"), tall);
    if let Ok(keep) = std::env::var("GYROLAB_KEEP_SCREENSHOT") {
        let _ = std::fs::copy(&png, format!("{keep}-program.png"));
    }
    let (w, h, px) = load_rgb(&png);
    assert_eq!((w, h), (WIDTH, tall), "screenshot size");
    let (bands, total) = plot_bands(w, h, &px);
    eprintln!("test program report: plot-coloured pixels {total} in {bands} bands");
    // Rate-table plots, bias and Allan plots, warm-up, K(T) and B(T): plots across many bands.
    assert!(bands >= 10 && total > 10_000, "plots found in only {bands} bands ({total} pixels)");
}

#[test]
fn report_renders_with_plots_in_headless_chromium() {
    if !browser_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let out: PathBuf = dir.path().join("report");
    // Shorter simulated static tests than the default keep the debug-build test fast; the Allan
    // record keeps its default length (7200 s), which shows the minimum (bias instability read-off).
    gyrolab().arg("demo").arg("--out").arg(&out).args(["--sim-static-s", "600", "--quiet"]).assert().code(0);
    if let Ok(keep) = std::env::var("GYROLAB_KEEP_SCREENSHOT") {
        let _ = std::fs::copy(out.join("report.html"), format!("{keep}.html"));
    }
    let png = dir.path().join("shot.png");
    screenshot(&out.join("report.html"), &png, &dir.path().join("profile"), HEIGHT);
    if let Ok(keep) = std::env::var("GYROLAB_KEEP_SCREENSHOT") {
        let _ = std::fs::copy(&png, format!("{keep}.png"));
    }
    let (w, h, px) = load_rgb(&png);
    assert_eq!((w, h), (WIDTH, HEIGHT), "screenshot size");

    // Bands of 200 px: how many hold plot-coloured pixels, and how non-blank they are.
    let band = 200;
    let (plot_bands, total_plot_px) = plot_bands(w, h, &px);
    eprintln!("plot-coloured pixels: {total_plot_px} in {plot_bands} bands");
    assert!(total_plot_px > 2_000, "too few plot-coloured pixels ({total_plot_px}): are the SVGs drawn?");
    assert!(plot_bands >= 4, "plots found in only {plot_bands} bands of {band} px");
    // The top of the page (header, summary) is text, not blank.
    let top = &px[..(200 * w) as usize];
    assert!(top.iter().filter(|p| p.iter().any(|c| *c < 128)).count() > 1_000, "the header is blank");
}
