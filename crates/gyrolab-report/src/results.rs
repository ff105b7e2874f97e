//! The `results.json` document of `gyrolab eval` and `gyrolab demo --out`: device, every
//! rate-table figure per axis (the `gyrolab rate --json` axis objects), the limits and their
//! verdicts. The static (bias) and Allan sections (and the demo's `paper`) go under their own key in `sections`.

use crate::limits::{LimitCheck, Verdict};
use crate::rate::AxisJson;
use serde::Serialize;
use std::collections::BTreeMap;

/// The device block of results.json.
#[derive(Debug, Clone, Serialize)]
pub struct DeviceJson {
    /// Model.
    pub model: String,
    /// Serial number.
    pub serial: String,
    /// Axis names.
    pub axes: Vec<String>,
    /// Free description.
    pub description: Option<String>,
}

/// A limit as given in the plan.
#[derive(Debug, Clone, Serialize)]
pub struct LimitJson {
    /// Figure key.
    pub figure: String,
    /// Lower bound.
    pub min: Option<f64>,
    /// Upper bound.
    pub max: Option<f64>,
}

/// The whole results.json document.
#[derive(Debug, Clone, Serialize)]
pub struct ResultsJson {
    /// Program version.
    pub gyrolab_version: String,
    /// Time of evaluation (RFC 3339, UTC).
    pub created: String,
    /// The plan file as given (or a description of built-in data).
    pub plan_file: String,
    /// The device.
    pub device: DeviceJson,
    /// Who, where, when, under which conditions (the plan's `[test]`).
    pub test: crate::html::TestConditions,
    /// The equipment used, with its calibration status on the test date.
    pub equipment: Vec<crate::html::EquipmentRow>,
    /// Rate-table figures per axis (keys in docs/JSON.md).
    pub rate_axes: Vec<AxisJson>,
    /// Further sections by name (`static`, `allan`, `paper`), keys in docs/JSON.md.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub sections: BTreeMap<String, serde_json::Value>,
    /// The plan's limits.
    pub limits: Vec<LimitJson>,
    /// Every limit checked on every axis.
    pub limit_checks: Vec<LimitCheck>,
    /// FAIL if any check failed, PASS if any passed, NOT_EVALUATED otherwise; null without limits.
    pub verdict: Option<Verdict>,
}
