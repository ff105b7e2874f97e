//! Provenance of a report folder: its outputs as named bytes and the manifest that lists each with
//! its SHA-256 and size (written last; `gyrolab verify` checks a folder against it, and an issued
//! report's signature is over it). One place for every crate that writes, stores or checks one.

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
