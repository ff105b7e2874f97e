//! `--pdf`: the report printed to report.pdf by headless Chromium beside report.html, and the
//! clear failure (exit 1, the rest of the folder written) when there is no browser or it fails.
//!
//! The printing test needs /usr/bin/chromium (Debian package `chromium`;
//! `scripts/install-test-deps.sh` installs it, CI runs that script). Without it that test fails,
//! unless GYROLAB_SKIP_BROWSER=1, when it prints a SKIPPED line. The other tests need no browser.

use crate::common;
use common::gyrolab;
use std::path::Path;

const CHROMIUM: &str = "/usr/bin/chromium";

/// Page objects of a PDF (`/Type /Page`, not `/Type /Pages`), counted in its bytes: Chromium
/// (Skia) writes page dictionaries uncompressed.
fn page_count(pdf: &[u8]) -> usize {
    let key = b"/Type /Page";
    pdf.windows(key.len() + 1).filter(|w| &w[..key.len()] == key && !w[key.len()].is_ascii_alphanumeric()).count()
}

#[test]
fn page_count_counts_pages_not_the_page_tree() {
    let pdf = b"1 0 obj << /Type /Pages /Kids [2 0 R 3 0 R] >> 2 0 obj << /Type /Page >> 3 0 obj <</Type /Page/Parent 1 0 R>>";
    assert_eq!(page_count(pdf), 2);
}

/// The text of each page of a PDF, extracted by pypdf in the test venv; `None` (said loudly) only
/// with GYROLAB_SKIP_PYTHON=1 when the venv lacks it.
fn page_texts(pdf: &Path) -> Option<Vec<String>> {
    let py = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../.venv/bin/python");
    let script = "import json, sys, pypdf\nr = pypdf.PdfReader(sys.argv[1])\n\
                  print(json.dumps([p.extract_text() for p in r.pages]))\n";
    let out = std::process::Command::new(&py).args(["-c", script]).arg(pdf).output();
    match out {
        Ok(o) if o.status.success() => Some(serde_json::from_slice(&o.stdout).unwrap()),
        _ if std::env::var("GYROLAB_SKIP_PYTHON").as_deref() == Ok("1") => {
            eprintln!(
                "\n*** SKIPPED: the PDF page texts were not checked: .venv has no pypdf (GYROLAB_SKIP_PYTHON=1) ***\n"
            );
            None
        }
        other => panic!(
            "the PDF test reads the pages with pypdf from .venv: run scripts/install-test-deps.sh (or set \
             GYROLAB_SKIP_PYTHON=1 to skip that check loudly): {other:?}"
        ),
    }
}

/// The files of a folder, sorted.
fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    v.sort();
    v
}

#[test]
fn demo_report_prints_to_a_paginated_pdf() {
    if std::env::var("GYROLAB_SKIP_BROWSER").is_ok_and(|v| v == "1") {
        eprintln!("SKIPPED: GYROLAB_SKIP_BROWSER=1: the PDF printing test did not run (no report.pdf checked)");
        return;
    }
    assert!(
        Path::new(CHROMIUM).exists(),
        "{CHROMIUM} not found: the PDF test needs Chromium. Install it with \
         `bash scripts/install-test-deps.sh` (or `apt-get install -y chromium`), \
         or set GYROLAB_SKIP_BROWSER=1 to skip this test."
    );
    let dir = tempfile::tempdir().unwrap();
    // A space and a '#' in the folder name: the file URL given to the browser must encode them.
    let out = dir.path().join("report #1");
    gyrolab()
        .env_remove("GYROLAB_CHROMIUM")
        .arg("demo")
        .arg("--out")
        .arg(&out)
        .args(["--pdf", "--sim-static-s", "600", "--quiet"])
        .assert()
        .code(0);
    let pdf = std::fs::read(out.join("report.pdf")).unwrap();
    if let Ok(keep) = std::env::var("GYROLAB_KEEP_PDF") {
        let _ = std::fs::write(&keep, &pdf);
    }
    assert!(pdf.starts_with(b"%PDF-"), "not a PDF: {:?}", &pdf[..pdf.len().min(16)]);
    assert!(pdf.ends_with(b"%%EOF\n") || pdf.ends_with(b"%%EOF"), "the PDF is not complete");
    // The report has three rate-table axis sections, three static and three Allan sections,
    // each starting on a new page, plus the summary, the sign-off and the methods appendix.
    let pages = page_count(&pdf);
    assert!(pages >= 10, "{pages} pages: is the report paginated (page breaks, A4)?");
    // Sixteen SVG plots and the tables: far more than an empty page's few kB.
    assert!(pdf.len() > 100_000, "report.pdf is only {} bytes", pdf.len());
    // A4, 210 mm x 297 mm = 595.3 x 841.9 points (the report's `@page { size: A4 }`), on every
    // page, within a point (Chromium rounds to whole CSS pixels).
    let text = String::from_utf8_lossy(&pdf);
    let boxes: Vec<Vec<f64>> = text
        .split("/MediaBox [")
        .skip(1)
        .map(|s| s.split(']').next().unwrap().split_whitespace().map(|v| v.parse().unwrap()).collect())
        .collect();
    let (a4_w, a4_h) = (210.0 / 25.4 * 72.0, 297.0 / 25.4 * 72.0);
    assert!(!boxes.is_empty(), "no /MediaBox");
    for b in &boxes {
        assert!(b.len() == 4 && (b[2] - b[0] - a4_w).abs() < 1.0 && (b[3] - b[1] - a4_h).abs() < 1.0, "not A4: {b:?}");
    }
    // Every printed page has the report number and "page i of N" in its margin (CSS @page margin
    // boxes), read back from the PDF's text by pypdf, an independent PDF reader.
    let results: serde_json::Value = serde_json::from_slice(&std::fs::read(out.join("results.json")).unwrap()).unwrap();
    let number = results["report_number"].as_str().unwrap().to_string();
    if let Some(texts) = page_texts(&out.join("report.pdf")) {
        assert_eq!(texts.len(), pages, "pypdf and the page count disagree");
        for (i, t) in texts.iter().enumerate() {
            let want = format!("page {} of {pages}", i + 1);
            assert!(t.contains(&want), "page {}: no {want:?} in {:?}", i + 1, t.chars().take(200).collect::<String>());
            assert!(
                t.contains(&format!("Report {number}")),
                "page {}: no report number {number} in {:?}",
                i + 1,
                t.chars().skip(t.chars().count().saturating_sub(200)).collect::<String>()
            );
            assert!(t.contains("SIMULATED DATA"), "page {}: no SIMULATED mark", i + 1);
        }
        assert!(texts.last().unwrap().contains(&format!("End of report {number}")), "no end-of-report mark");
    }
    // Nothing temporary is left beside the outputs.
    let files = names(&out);
    assert!(files.iter().all(|n| !n.starts_with(".gyrolab-")), "{files:?}");
    assert!(files.contains(&"report.html".to_string()), "{files:?}");
    eprintln!("report.pdf: {} bytes, {pages} pages", pdf.len());
}

#[test]
fn without_a_browser_the_folder_is_written_and_the_message_says_how_to_get_a_pdf() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("report");
    // An older PDF in the folder shows an earlier report: it must not stay beside the new one.
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("report.pdf"), b"%PDF-1.4 an earlier report").unwrap();
    let assert = gyrolab()
        .env("GYROLAB_CHROMIUM", "/nonexistent")
        .arg("demo")
        .arg("--out")
        .arg(&out)
        .args(["--pdf", "--sim-static-s", "600", "--sim-allan-s", "1200", "--quiet"])
        .assert()
        .code(1);
    let stderr = String::from_utf8_lossy(&assert.get_output().stderr).into_owned();
    eprintln!("{stderr}");
    for want in [
        "report.pdf not written",
        "no Chromium found",
        "GYROLAB_CHROMIUM is /nonexistent",
        "are written and complete",
        "apt-get install chromium",
        "report.html in a browser and print it",
        "older report.pdf",
    ] {
        assert!(stderr.contains(want), "stderr lacks {want:?}: {stderr}");
    }
    let files = names(&out);
    for want in ["report.html", "results.json", "calibration.toml", "summary.csv"] {
        assert!(files.contains(&want.to_string()), "{want} missing: {files:?}");
    }
    assert!(!files.contains(&"report.pdf".to_string()), "{files:?}");
    assert!(files.iter().all(|n| !n.starts_with(".gyrolab-")), "{files:?}");
}

/// A stand-in browser: a shell script with `body`.
#[cfg(unix)]
fn fake_browser(dir: &Path, body: &str) -> std::path::PathBuf {
    use std::os::unix::fs::PermissionsExt;
    let p = dir.join("fake-chromium");
    std::fs::write(&p, format!("#!/bin/sh\n{body}\n")).unwrap();
    std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o755)).unwrap();
    p
}

#[cfg(unix)]
#[test]
fn a_failing_browser_leaves_report_pdf_unwritten_with_its_error() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        ("echo 'cannot open display' >&2; exit 3", "exited with exit status: 3", "cannot open display"),
        // Exits 0 without writing: the temporary (empty) file must not become report.pdf.
        ("exit 0", "without writing a PDF", ""),
    ];
    for (i, (body, want, said)) in cases.into_iter().enumerate() {
        let browser = fake_browser(dir.path(), body);
        let out = dir.path().join(format!("report{i}"));
        let assert = gyrolab()
            .env("GYROLAB_CHROMIUM", &browser)
            .arg("demo")
            .arg("--out")
            .arg(&out)
            .args(["--pdf", "--sim-static-s", "600", "--sim-allan-s", "1200", "--quiet"])
            .assert()
            .code(1);
        let stderr = String::from_utf8_lossy(&assert.get_output().stderr).into_owned();
        assert!(stderr.contains(want) && stderr.contains(said), "{body}: {stderr}");
        assert!(stderr.contains("are written and complete"), "{stderr}");
        let files = names(&out);
        assert!(files.contains(&"report.html".to_string()), "{files:?}");
        assert!(!files.iter().any(|n| n.contains("pdf")), "{body}: {files:?}");
    }
}

#[cfg(unix)]
#[test]
fn the_browser_gets_the_print_flags_and_the_pdf_is_renamed_into_place() {
    let dir = tempfile::tempdir().unwrap();
    let args_file = dir.path().join("args.txt");
    // Records its arguments and writes a minimal PDF where --print-to-pdf says.
    let body = format!(
        "printf '%s\\n' \"$@\" > '{}'\nfor a in \"$@\"; do case \"$a\" in --print-to-pdf=*) printf '%%PDF-1.4 fake\\n%%%%EOF\\n' > \"${{a#--print-to-pdf=}}\";; esac; done",
        args_file.display()
    );
    let browser = fake_browser(dir.path(), &body);
    let out = dir.path().join("report");
    gyrolab()
        .env("GYROLAB_CHROMIUM", &browser)
        .arg("demo")
        .arg("--out")
        .arg(&out)
        .args(["--pdf", "--sim-static-s", "600", "--sim-allan-s", "1200"])
        .assert()
        .code(0)
        .stdout(predicates::str::contains("Printed report.html to"));
    assert_eq!(std::fs::read(out.join("report.pdf")).unwrap(), b"%PDF-1.4 fake\n%%EOF\n");
    let args = std::fs::read_to_string(&args_file).unwrap();
    let args: Vec<&str> = args.lines().collect();
    for flag in [
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-quic",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--no-pdf-header-footer",
    ] {
        assert!(args.contains(&flag), "{flag} missing: {args:?}");
    }
    assert!(args.iter().any(|a| a.starts_with("--user-data-dir=")), "{args:?}");
    let tmp = args.iter().find_map(|a| a.strip_prefix("--print-to-pdf=")).unwrap();
    assert!(
        Path::new(tmp).parent() == Some(out.canonicalize().unwrap().as_path())
            || Path::new(tmp).parent() == Some(out.as_path()),
        "{tmp}"
    );
    assert!(!Path::new(tmp).exists(), "the temporary {tmp} was left");
    let url = args.last().unwrap();
    assert!(url.starts_with("file:///") && url.ends_with("/report/report.html"), "{url}");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(out.join("report.pdf")).unwrap().permissions().mode();
        assert_eq!(mode & 0o777, 0o644);
    }
}

#[test]
fn pdf_is_in_the_help_of_eval_and_demo() {
    for cmd in ["eval", "demo"] {
        let assert = gyrolab().args([cmd, "--help"]).assert().code(0);
        let help =
            String::from_utf8_lossy(&assert.get_output().stdout).split_whitespace().collect::<Vec<_>>().join(" ");
        assert!(
            help.contains("--pdf") && help.contains("GYROLAB_CHROMIUM") && help.contains("exit code is 1"),
            "{help}"
        );
    }
}
