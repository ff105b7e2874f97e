//! Typed outcomes of evaluations: what eval's requests return and the report crate renders (the
//! outcomes of a test plan's parts are assembled by the lab layer).
//!
//! - [`allan`]: an Allan-variance analysis of one channel ([`allan::ChannelAnalysis`]);
//! - [`static_test`]: static (bias) tests, repeatability across files, warm-ups;
//! - [`rate`]: a rate-table evaluation of one axis ([`rate::AxisReport`]);
//! - [`segments`]: a raw log's segmentation ([`segments::SegmentationReport`]);
//! - [`triad`]: a three-axis calibration ([`triad::TriadReport`]);
//! - [`inventory`]: the topics of a recording ([`inventory::Inventory`]).

pub mod allan;
pub mod inventory;
pub mod rate;
pub mod segments;
pub mod static_test;
pub mod triad;
