//! Provenance, one place for every crate that writes, stores or checks it:
//! - the SIMULATED marks: the first line of every record gyrolab's simulator writes
//!   ([`SIMULATOR_MARK`]) and of every output made from simulated records
//!   ([`SIMULATED_DATA_MARK`]), read by [`is_gyrolab_simulation`] and [`simulator_title`];
//! - a report folder's outputs as named bytes and the manifest that lists each with its SHA-256
//!   and size (written last; `gyrolab verify` checks a folder against it, and an issued report's
//!   signature is over it). The hashes themselves: [`crate::input_file`].

/// The first line of every record gyrolab's simulator writes starts with this.
pub const SIMULATOR_MARK: &str = "# gyrolab simulated";

/// The first line of every gyrolab output made from simulated records (a calibration.toml, a
/// report's CSV table) starts with this.
pub const SIMULATED_DATA_MARK: &str = "# SIMULATED DATA";

/// The text of a file's first bytes, a byte-order mark left out.
fn head_text(head: &[u8]) -> std::borrow::Cow<'_, str> {
    let head = head.strip_prefix(b"\xef\xbb\xbf".as_slice()).unwrap_or(head);
    String::from_utf8_lossy(head)
}

/// Whether a file was written by gyrolab's simulator, or is a gyrolab output made from simulated
/// records (its first line says so); `false` when it cannot be read. A regular file only: a FIFO
/// among the inputs does not block here.
pub fn is_gyrolab_simulation(path: &std::path::Path) -> bool {
    use std::io::Read;
    let mut head = [0u8; 64];
    let Ok((mut f, _)) = crate::input_file::open_regular(path) else { return false };
    let n = f.read(&mut head).unwrap_or(0);
    let text = head_text(&head[..n]);
    text.starts_with(SIMULATOR_MARK) || text.starts_with(SIMULATED_DATA_MARK)
}

/// The simulator's title of a record whose first bytes are `head` (its first line without `# `,
/// such as `gyrolab simulated static record`), `None` when the simulator did not write it.
pub fn simulator_title(head: &[u8]) -> Option<String> {
    let text = head_text(head);
    let line = text.lines().next()?;
    line.starts_with(SIMULATOR_MARK).then(|| line[2..].trim_end().to_string())
}

/// One output of a report folder.
#[derive(Debug, Clone, PartialEq)]
pub struct NamedOutput {
    /// File name inside the folder.
    pub name: String,
    /// Its content.
    pub bytes: Vec<u8>,
}

/// The name of a report folder's manifest: every other file of the folder with its SHA-256 and
/// size, written last; `gyrolab verify` checks the folder against it.
pub const MANIFEST: &str = "manifest.json";

/// One file of a report folder's manifest.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct ManifestEntry {
    /// The file's name in the folder.
    pub name: String,
    /// SHA-256 of its bytes, lower-case hex.
    pub sha256: String,
    /// Its size, bytes.
    pub size_bytes: u64,
}

/// A report folder's manifest ([`MANIFEST`]).
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Manifest {
    /// What it is, for a reader who finds the file alone.
    pub about: String,
    /// The hash function: `SHA-256`.
    pub algorithm: String,
    /// Every file of the report but the manifest itself, in writing order.
    pub files: Vec<ManifestEntry>,
}

/// The manifest of `outputs` as pretty JSON followed by a blank line.
pub fn manifest_json(outputs: &[NamedOutput]) -> Result<String, serde_json::Error> {
    let manifest = Manifest {
        about: "the files of this gyrolab report folder with their SHA-256, written with them; `gyrolab verify` checks the folder against it (an edited, missing or added file is found; a manifest rewritten with the files is found only by the signature of an issued report)".into(),
        algorithm: "SHA-256".into(),
        files: outputs
            .iter()
            .map(|o| ManifestEntry {
                name: o.name.clone(),
                sha256: crate::input_file::sha256_hex(&o.bytes),
                size_bytes: o.bytes.len() as u64,
            })
            .collect(),
    };
    // Pretty JSON, a final newline, and the blank line every earlier build wrote after it.
    serde_json::to_string_pretty(&manifest).map(|s| s + "\n\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn simulator_title_reads_the_first_line_with_or_without_a_byte_order_mark() {
        let t = "gyrolab simulated static record";
        assert_eq!(simulator_title(b"# gyrolab simulated static record\n# seed = 3\n").as_deref(), Some(t));
        assert_eq!(simulator_title(b"\xef\xbb\xbf# gyrolab simulated static record\r\n").as_deref(), Some(t));
        assert_eq!(simulator_title(b"time_s,rate_dps\n# gyrolab simulated\n"), None);
        assert_eq!(simulator_title(b""), None);
    }
}
