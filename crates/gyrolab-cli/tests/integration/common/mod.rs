//! Helpers shared by the CLI tests.
#![allow(dead_code)]

use assert_cmd::Command;
use std::path::{Path, PathBuf};

/// The gyrolab binary.
pub fn gyrolab() -> Command {
    Command::cargo_bin("gyrolab").unwrap()
}

/// A file of the bundled paper data.
pub fn paper(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/paper").join(name)
}

/// Writes `text` to `name` inside `dir` and returns its path.
pub fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}
pub mod rawsim;
