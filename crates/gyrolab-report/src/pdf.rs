//! Printing a report folder's report.html to report.pdf with headless Chromium (`--pdf` of
//! `gyrolab eval` and `gyrolab demo --out`), the last rendering of a report folder. File output
//! only, no domain logic: finds the browser,
//! runs it with a time limit, and renames the PDF into place only when it is complete, so that
//! report.pdf is either a whole new PDF or left as it was.
//!
//! The browser: the path in the environment variable `GYROLAB_CHROMIUM` when it is set (and only
//! that), else `/usr/bin/chromium`, else the first of `chromium`, `chromium-browser`,
//! `google-chrome` found on `PATH`. The page layout (A4, margins, page breaks) comes from the
//! report's print CSS ([`crate::html`]).

use std::io::{Read, Seek};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The environment variable naming the browser to print with.
pub const BROWSER_ENV: &str = "GYROLAB_CHROMIUM";

/// The browser looked for when `GYROLAB_CHROMIUM` is not set, before `PATH`.
const DEFAULT_BROWSER: &str = "/usr/bin/chromium";

/// Names looked for on `PATH`, in order.
const PATH_NAMES: [&str; 3] = ["chromium", "chromium-browser", "google-chrome"];

/// Longest time the browser may take to print; it is killed after that.
pub const TIME_LIMIT: Duration = Duration::from_secs(120);

/// Temporary files and folders being used (the PDF being written, the browser profile), removed
/// by [`remove_temporaries`] when the program is interrupted.
static TEMPORARIES: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

/// Why report.pdf was not written.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum PdfError {
    /// No browser to print with: where it was looked for.
    NoBrowser(String),
    /// The browser was found but did not produce a PDF: what happened.
    Failed(String),
}

impl PdfError {
    /// The message for the user: what went wrong, that the rest of the folder is complete, and
    /// how to get a PDF anyway.
    pub fn message(&self, dir: &Path) -> String {
        let html = dir.join("report.html");
        let how = format!(
            "To get a PDF: install Chromium (Debian/Ubuntu: `apt-get install chromium`), or set {BROWSER_ENV} to the \
             path of a Chromium or Chrome browser and run again, or open {} in a browser and print it to PDF (A4)",
            html.display()
        );
        match self {
            PdfError::NoBrowser(looked) => format!(
                "report.pdf not written: no Chromium found ({looked}). The other files of {} are written and complete. {how}.",
                dir.display()
            ),
            PdfError::Failed(what) => format!(
                "report.pdf not written: {what}. The other files of {} are written and complete. {how}.",
                dir.display()
            ),
        }
    }
}

/// The browser to print with, or where it was looked for.
pub fn find_browser() -> Result<PathBuf, PdfError> {
    if let Some(v) = std::env::var_os(BROWSER_ENV).filter(|v| !v.is_empty()) {
        let p = PathBuf::from(&v);
        return if is_executable(&p) {
            Ok(p)
        } else {
            Err(PdfError::NoBrowser(format!("{BROWSER_ENV} is {}, which is not an executable file", p.display())))
        };
    }
    if is_executable(Path::new(DEFAULT_BROWSER)) {
        return Ok(PathBuf::from(DEFAULT_BROWSER));
    }
    if let Some(path) = std::env::var_os("PATH") {
        for name in PATH_NAMES {
            if let Some(p) = std::env::split_paths(&path).map(|d| d.join(name)).find(|p| is_executable(p)) {
                return Ok(p);
            }
        }
    }
    Err(PdfError::NoBrowser(format!(
        "looked for {DEFAULT_BROWSER}, then {} on PATH; {BROWSER_ENV} is not set",
        PATH_NAMES.join(", ")
    )))
}

fn is_executable(p: &Path) -> bool {
    match std::fs::metadata(p) {
        #[cfg(unix)]
        Ok(m) => {
            use std::os::unix::fs::PermissionsExt;
            m.is_file() && m.permissions().mode() & 0o111 != 0
        }
        #[cfg(not(unix))]
        Ok(m) => m.is_file(),
        Err(_) => false,
    }
}

/// Prints `dir/report.html` to `dir/report.pdf` with the browser found by [`find_browser`].
/// Returns the PDF's path and size in bytes. On failure report.pdf is left as it was.
pub fn print_report(dir: &Path) -> Result<(PathBuf, u64), PdfError> {
    let browser = find_browser()?;
    let html = dir.join("report.html");
    let html =
        std::fs::canonicalize(&html).map_err(|e| PdfError::Failed(format!("cannot find {}: {e}", html.display())))?;
    let io = |what: &str, e: std::io::Error| PdfError::Failed(format!("{what}: {e}"));
    let tmp = tempfile::Builder::new()
        .prefix(".gyrolab-")
        .suffix(".pdf.tmp")
        .tempfile_in(dir)
        .map_err(|e| io(&format!("cannot create a temporary file in {}", dir.display()), e))?;
    let profile = tempfile::Builder::new()
        .prefix("gyrolab-chromium-")
        .tempdir()
        .map_err(|e| io("cannot create a temporary browser profile folder", e))?;
    let registered = [tmp.path().to_path_buf(), profile.path().to_path_buf()];
    register(&registered);
    let result = run_browser(&browser, &html, tmp.path(), profile.path()).and_then(|()| {
        check_pdf(tmp.path())?;
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            std::fs::set_permissions(tmp.path(), std::fs::Permissions::from_mode(0o644))
                .map_err(|e| io("cannot set the permissions of the PDF", e))?;
        }
        let size = std::fs::metadata(tmp.path()).map_err(|e| io("cannot read the PDF", e))?.len();
        let target = dir.join("report.pdf");
        tmp.persist(&target).map_err(|e| io(&format!("cannot rename the PDF to {}", target.display()), e.error))?;
        Ok((target, size))
    });
    unregister(&registered);
    result
}

/// Runs the browser to print `html` to `pdf`, within [`TIME_LIMIT`].
fn run_browser(browser: &Path, html: &Path, pdf: &Path, profile: &Path) -> Result<(), PdfError> {
    let mut log = tempfile::tempfile().map_err(|e| PdfError::Failed(format!("cannot create a temporary file: {e}")))?;
    let stderr = log.try_clone().map_err(|e| PdfError::Failed(format!("cannot create a temporary file: {e}")))?;
    let mut child = Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--no-pdf-header-footer",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg(format!("--print-to-pdf={}", pdf.display()))
        .arg(file_url(html))
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::from(stderr))
        .spawn()
        .map_err(|e| PdfError::Failed(format!("cannot start {}: {e}", browser.display())))?;
    let start = Instant::now();
    let status = loop {
        match child.try_wait() {
            Ok(Some(status)) => break status,
            Ok(None) if start.elapsed() > TIME_LIMIT => {
                let _ = child.kill();
                let _ = child.wait();
                return Err(PdfError::Failed(format!(
                    "{} did not finish printing within {} s and was stopped",
                    browser.display(),
                    TIME_LIMIT.as_secs()
                )));
            }
            Ok(None) => std::thread::sleep(Duration::from_millis(100)),
            Err(e) => return Err(PdfError::Failed(format!("cannot wait for {}: {e}", browser.display()))),
        }
    };
    if status.success() {
        return Ok(());
    }
    let mut text = String::new();
    let _ = log.rewind().and_then(|()| log.read_to_string(&mut text));
    let tail: Vec<&str> = text.lines().filter(|l| !l.trim().is_empty()).collect();
    let tail = tail[tail.len().saturating_sub(3)..].join(" | ");
    let said = if tail.is_empty() { String::new() } else { format!("; it said: {tail}") };
    Err(PdfError::Failed(format!("{} exited with {status}{said}", browser.display())))
}

/// Checks that the browser wrote a PDF (not an empty or other file).
fn check_pdf(pdf: &Path) -> Result<(), PdfError> {
    let mut head = [0u8; 5];
    let n = std::fs::File::open(pdf).and_then(|mut f| f.read(&mut head)).unwrap_or(0);
    if n == 5 && &head == b"%PDF-" {
        Ok(())
    } else {
        Err(PdfError::Failed("the browser exited without writing a PDF".to_string()))
    }
}

/// The `file://` URL of an absolute path, with every byte other than letters, digits, `/` and
/// `-._~` percent-encoded (so that spaces, `#` and `?` in folder names stay part of the path).
fn file_url(path: &Path) -> String {
    #[cfg(unix)]
    let bytes = {
        use std::os::unix::ffi::OsStrExt;
        path.as_os_str().as_bytes().to_vec()
    };
    #[cfg(not(unix))]
    let bytes = path.to_string_lossy().replace('\\', "/").into_bytes();
    let mut url = String::from("file://");
    for b in bytes {
        if b.is_ascii_alphanumeric() || b"/-._~".contains(&b) {
            url.push(char::from(b));
        } else {
            url.push_str(&format!("%{b:02X}"));
        }
    }
    url
}

fn register(paths: &[PathBuf]) {
    if let Ok(mut t) = TEMPORARIES.lock() {
        t.extend_from_slice(paths);
    }
}

fn unregister(paths: &[PathBuf]) {
    if let Ok(mut t) = TEMPORARIES.lock() {
        t.retain(|p| !paths.contains(p));
    }
}

/// Removes the temporary PDF and browser profile of a print in progress (for the Ctrl-C
/// handler; an existing report.pdf stays as it was).
pub fn remove_temporaries() {
    let list = match TEMPORARIES.lock() {
        Ok(mut t) => std::mem::take(&mut *t),
        Err(_) => return,
    };
    for p in list {
        if p.is_dir() {
            let _ = std::fs::remove_dir_all(&p);
        } else {
            let _ = std::fs::remove_file(&p);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn file_urls_encode_what_is_not_a_plain_path_character() {
        assert_eq!(file_url(Path::new("/tmp/a b/r#1?.html")), "file:///tmp/a%20b/r%231%3F.html");
        assert_eq!(file_url(Path::new("/tmp/x-y_z.~/report.html")), "file:///tmp/x-y_z.~/report.html");
    }
}
