//! Plan sections with simulated records (or only plan inputs) for each part of a lab's test
//! program: each module writes its records into a folder and returns its TOML section.

pub mod uncertainty;
