//! gyrolab-report: text tables, JSON documents, SVG plots and the HTML report of gyrolab results.
//!
//! - [`allan`]: Allan-deviation tables, CSV, JSON, noise terms and Kalibr YAML;
//! - [`bias`]: static (bias) test tables and JSON;
//! - [`rate`]: rate-table evaluation tables and JSON (keys in docs/JSON.md);
//! - [`plot`]: SVG plot building blocks; [`rate_plots`]: the rate-table plots;
//! - [`html`]: the self-contained HTML report (header, summary, sections, methods appendix);
//! - [`pdf`]: report.html printed to report.pdf with headless Chromium (whole or not at all);
//! - [`signature`]: the signature block of an issued report (who issued it, when, with what key);
//! - [`inventory`]: the topics of a recording (`gyrolab inspect`);
//! - [`results`]: the results.json document of `gyrolab eval`;
//! - [`segments`]: segmentation summaries of raw rate-table logs;
//! - [`thermal`]: the temperature-test section (soaked points, K(T), bias(T), sensitivities);
//! - [`triad`]: three-axis calibration tables and JSON;
//! - [`paper`]: the paper's printed tables beside the recomputation, for `gyrolab demo`;
//! - [`table`]: tables of results as aligned text, CSV and Parquet (batch, the store's queries);
//! - [`trend`]: trend plots of figures over evaluations (a serial's history);
//! - [`tables_csv`]: the CSV tables of a report folder (points, runs, summary);
//! - [`threshold`]: threshold and resolution tests (section, figures, JSON);

#![deny(missing_docs)]

pub mod allan;
pub mod bias;
pub mod html;
pub mod inventory;
pub mod paper;
pub mod pdf;
pub mod plot;
pub mod power_ups;
pub mod rate;
pub mod rate_plots;
pub mod results;
pub mod segments;
pub mod signature;
pub mod static_report;
pub mod table;
pub mod tables_csv;
pub mod thermal;
pub mod threshold;
pub mod trend;
pub mod triad;
