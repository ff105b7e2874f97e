//! The lab's Ed25519 key and the signature of an issued report's manifest (issue 53;
//! docs/STORE.md "Issued reports and signatures").
//!
//! Key files are text: a first line saying what the file is, then the key's 32 bytes in hex
//! (the private key file holds the seed, written with mode 0600 and never over an existing file;
//! the public key file the public key). A key's fingerprint is `sha256:` and the SHA-256 of its 32
//! public bytes in hex. `manifest.sig` is JSON: the algorithm, the key's fingerprint and the
//! Ed25519 signature (hex) over the exact bytes of `manifest.json`.

use ed25519_dalek::{Signature, Signer, Verifier};
/// The key types, re-exported for the front ends.
pub use ed25519_dalek::{SigningKey, VerifyingKey};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// The first line of a private key file.
pub const PRIVATE_HEADER: &str = "gyrolab Ed25519 signing key: keep it secret, outside the store";
/// The first line of a public key file.
pub const PUBLIC_HEADER: &str = "gyrolab Ed25519 public key";
/// The detached signature of an issued report folder.
pub const SIGNATURE_FILE: &str = "manifest.sig";
/// The issue record of an issued report folder (covered by its manifest).
pub const ISSUE_FILE: &str = "issue.json";

/// The fingerprint of a public key: `sha256:` and the SHA-256 of its bytes in hex.
pub fn fingerprint(key: &VerifyingKey) -> String {
    format!("sha256:{}", crate::chain::hex(&Sha256::digest(key.as_bytes())))
}

/// The public key as stored in the store and in a public key file: 64 hex digits.
pub fn public_hex(key: &VerifyingKey) -> String {
    crate::chain::hex(key.as_bytes())
}

fn unhex32(s: &str) -> Option<[u8; 32]> {
    let s = s.trim();
    if s.len() != 64 || !s.is_ascii() {
        return None;
    }
    let mut out = [0u8; 32];
    for (i, o) in out.iter_mut().enumerate() {
        *o = u8::from_str_radix(&s[2 * i..2 * i + 2], 16).ok()?;
    }
    Some(out)
}

fn unhex64(s: &str) -> Option<[u8; 64]> {
    let s = s.trim();
    if s.len() != 128 || !s.is_ascii() {
        return None;
    }
    let mut out = [0u8; 64];
    for (i, o) in out.iter_mut().enumerate() {
        *o = u8::from_str_radix(&s[2 * i..2 * i + 2], 16).ok()?;
    }
    Some(out)
}

/// The public key of 64 hex digits.
pub fn public_from_hex(s: &str) -> Option<VerifyingKey> {
    unhex32(s).and_then(|b| VerifyingKey::from_bytes(&b).ok())
}

/// The public key file beside a private key file: `lab.key` -> `lab.pub`.
pub fn public_path_for(private: &Path) -> PathBuf {
    private.with_extension("pub")
}

/// Makes a new key pair from the system's random numbers and writes the private key to `out`
/// (mode 0600, refusing an existing file) and the public key beside it ([`public_path_for`]);
/// the public key. Nothing is written when either file exists.
pub fn create_key_files(out: &Path) -> Result<VerifyingKey, String> {
    let public = public_path_for(out);
    for p in [out, public.as_path()] {
        if std::fs::symlink_metadata(p).is_ok() {
            return Err(format!("{}: exists; a key file is never overwritten", p.display()));
        }
    }
    let mut seed = [0u8; 32];
    getrandom::getrandom(&mut seed).map_err(|e| format!("no random numbers from the system: {e}"))?;
    let key = SigningKey::from_bytes(&seed);
    let verifying = key.verifying_key();
    let private_text = format!("{PRIVATE_HEADER}\n{}\n", crate::chain::hex(&seed));
    seed.fill(0);
    write_new(out, private_text.as_bytes(), true)?;
    if let Err(e) = write_new(&public, format!("{PUBLIC_HEADER}\n{}\n", public_hex(&verifying)).as_bytes(), false) {
        let _ = std::fs::remove_file(out);
        return Err(e);
    }
    Ok(verifying)
}

fn write_new(path: &Path, bytes: &[u8], secret: bool) -> Result<(), String> {
    use std::io::Write;
    let mut o = std::fs::OpenOptions::new();
    o.write(true).create_new(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        o.mode(if secret { 0o600 } else { 0o644 });
    }
    #[cfg(not(unix))]
    let _ = secret;
    let mut f = o.open(path).map_err(|e| format!("{}: cannot create: {e}", path.display()))?;
    f.write_all(bytes).and_then(|()| f.sync_all()).map_err(|e| format!("{}: cannot write: {e}", path.display()))
}

fn key_line(path: &Path, header: &str, what: &str) -> Result<[u8; 32], String> {
    let meta = std::fs::metadata(path).map_err(|e| format!("{}: cannot read the {what}: {e}", path.display()))?;
    if !meta.is_file() || meta.len() > 4096 {
        return Err(format!("{}: not a gyrolab {what} file", path.display()));
    }
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: cannot read the {what}: {e}", path.display()))?;
    let mut lines = text.lines().filter(|l| !l.trim().is_empty());
    if lines.next().map(str::trim) != Some(header) {
        return Err(format!("{}: not a gyrolab {what} file (its first line is not \"{header}\")", path.display()));
    }
    lines
        .next()
        .and_then(unhex32)
        .ok_or_else(|| format!("{}: not a gyrolab {what} file (no 64 hex digits on its second line)", path.display()))
}

/// Reads a private key file written by [`create_key_files`].
pub fn read_signing_key(path: &Path) -> Result<SigningKey, String> {
    let mut seed = key_line(path, PRIVATE_HEADER, "private key")?;
    let key = SigningKey::from_bytes(&seed);
    seed.fill(0);
    Ok(key)
}

/// Reads a public key file written by [`create_key_files`].
pub fn read_public_key(path: &Path) -> Result<VerifyingKey, String> {
    let b = key_line(path, PUBLIC_HEADER, "public key")?;
    VerifyingKey::from_bytes(&b).map_err(|_| format!("{}: not a valid Ed25519 public key", path.display()))
}

/// The detached signature file's content.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct DetachedSignature {
    /// What it is.
    pub about: String,
    /// `Ed25519`.
    pub algorithm: String,
    /// The signed file: `manifest.json`.
    pub signed_file: String,
    /// The fingerprint of the key that signed ([`fingerprint`]).
    pub key_fingerprint: String,
    /// The signature, 128 hex digits.
    pub signature: String,
}

/// Signs `manifest` (the exact bytes of manifest.json): the signature in hex.
pub fn sign_manifest(key: &SigningKey, manifest: &[u8]) -> String {
    crate::chain::hex(&key.sign(manifest).to_bytes())
}

/// The text of `manifest.sig` for a signature made by `key`.
pub fn signature_file(key: &VerifyingKey, signature_hex: &str) -> String {
    let d = DetachedSignature {
        about:
            "the Ed25519 signature of this folder's manifest.json (its exact bytes) by the lab's key; `gyrolab verify \
                DIR --public-key LAB.pub` checks it, then every file against the manifest"
                .into(),
        algorithm: "Ed25519".into(),
        signed_file: "manifest.json".into(),
        key_fingerprint: fingerprint(key),
        signature: signature_hex.to_string(),
    };
    serde_json::to_string_pretty(&d).map(|s| s + "\n").unwrap_or_default()
}

/// Whether `signature_hex` is `key`'s Ed25519 signature of `manifest`.
pub fn verify_manifest(key: &VerifyingKey, manifest: &[u8], signature_hex: &str) -> bool {
    unhex64(signature_hex).is_some_and(|b| key.verify(manifest, &Signature::from_bytes(&b)).is_ok())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn key_files_sign_and_verify_and_are_never_overwritten() {
        let dir = tempfile::tempdir().expect("temp dir"); // ok: test
        let out = dir.path().join("lab.key");
        let public = create_key_files(&out).expect("keys"); // ok: test
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let mode = std::fs::metadata(&out).expect("meta").permissions().mode(); // ok: test
            assert_eq!(mode & 0o777, 0o600);
        }
        assert!(create_key_files(&out).is_err(), "never over an existing key");
        let key = read_signing_key(&out).expect("read"); // ok: test
        let read_public = read_public_key(&dir.path().join("lab.pub")).expect("read pub"); // ok: test
        assert_eq!(read_public, public);
        let sig = sign_manifest(&key, b"{\"files\": []}\n");
        assert!(verify_manifest(&public, b"{\"files\": []}\n", &sig));
        assert!(!verify_manifest(&public, b"{\"files\": [1]}\n", &sig));
        assert!(read_public_key(&out).is_err(), "a private key is not read as a public one");
    }
}
