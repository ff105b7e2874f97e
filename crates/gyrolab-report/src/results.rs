//! The `results.json` document of `gyrolab eval` and `gyrolab demo --out`: device, every
//! rate-table figure per axis (the `gyrolab rate --json` axis objects), the limits and their
//! verdicts. The static (bias) and Allan sections (and the demo's `paper`) go under their own key in `sections`.

use crate::rate::AxisJson;
use gyrolab::limits::{DecisionRule, Limit, LimitCheck, Overall};
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
    /// Its decision rule (`simple_acceptance`, `guarded_acceptance`, `guarded_rejection`).
    pub rule: DecisionRule,
    /// The axes it applies to; null: every axis.
    pub axes: Option<Vec<String>>,
}

impl LimitJson {
    /// The plan's limit as written to results.json.
    pub fn new(l: &Limit) -> LimitJson {
        LimitJson { figure: l.figure.clone(), min: l.min, max: l.max, rule: l.rule, axes: l.axes.clone() }
    }
}

/// One input file of a report, hashed when it was evaluated.
#[derive(Debug, Clone, Default, PartialEq, Serialize, serde::Deserialize)]
pub struct InputJson {
    /// The path, relative to the plan's folder when the file lies inside it (else absolute).
    pub file: String,
    /// SHA-256 of its bytes, lower-case hex.
    pub sha256: String,
    /// Its size in bytes.
    pub size_bytes: u64,
}

/// What a report folder was made from: the plan (its SHA-256 and the name of its copy in the
/// folder) and every input file with its SHA-256 (ISO/IEC 17025:2017 7.5, 7.11; `gyrolab
/// verify`).
#[derive(Debug, Clone, Default, PartialEq, Serialize, serde::Deserialize)]
pub struct IntegrityJson {
    /// SHA-256 of the plan file's bytes.
    pub plan_sha256: Option<String>,
    /// The plan's copy in the folder (`plan_copy.toml`).
    pub plan_copy: Option<String>,
    /// The inputs, in plan order.
    pub inputs: Vec<InputJson>,
}

/// A decision rule used by the limits, with the statement the report prints (ISO/IEC
/// 17025:2017 7.8.6.1: the rule is reported with the statement of conformity).
#[derive(Debug, Clone, Serialize)]
pub struct DecisionRuleJson {
    /// The rule's key.
    pub rule: DecisionRule,
    /// What it means, with its source.
    pub statement: &'static str,
}

impl DecisionRuleJson {
    /// The rules the limits use, each once, in [`DecisionRule::ALL`] order.
    pub fn used(limits: &[Limit]) -> Vec<DecisionRuleJson> {
        DecisionRule::ALL
            .into_iter()
            .filter(|r| limits.iter().any(|l| l.rule == *r))
            .map(|rule| DecisionRuleJson { rule, statement: rule.statement() })
            .collect()
    }
}

/// The whole results.json document.
#[derive(Debug, Clone, Serialize)]
pub struct ResultsJson {
    /// True when any input of the report is simulated (a section, a summary figure): the
    /// verdict is then one on SIMULATED data (each section and `summary.csv` row says which).
    pub simulated: bool,
    /// The report's number.
    pub report_number: String,
    /// The issue date, `YYYY-MM-DD`.
    pub issue_date: String,
    /// Program version.
    pub gyrolab_version: String,
    /// Time of evaluation (RFC 3339, UTC).
    pub created: String,
    /// The plan file as given (or a description of built-in data).
    pub plan_file: String,
    /// The device.
    pub device: DeviceJson,
    /// Who, where, when, under which conditions (the plan's `[test]`).
    pub test: TestConditions,
    /// The equipment used, with its calibration status on the test date.
    pub equipment: Vec<EquipmentRow>,
    /// Rate-table figures per axis (keys in docs/JSON.md).
    pub rate_axes: Vec<AxisJson>,
    /// Further sections by name (`static`, `allan`, `paper`), keys in docs/JSON.md.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub sections: BTreeMap<String, serde_json::Value>,
    /// The plan and the inputs with their SHA-256.
    pub integrity: IntegrityJson,
    /// The plan's limits.
    pub limits: Vec<LimitJson>,
    /// Every limit checked on every axis.
    pub limit_checks: Vec<LimitCheck>,
    /// The decision rules of the limits, with their statements.
    pub decision_rules: Vec<DecisionRuleJson>,
    /// Overall: FAIL if any check failed, else INCOMPLETE if any is NOT_EVALUATED, else
    /// CONDITIONAL if any is, else PASS; null without limits.
    pub verdict: Option<Overall>,
}

/// The conditions of a test, for the header and the sign-off block.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct TestConditions {
    /// Who ran the test.
    pub operator: Option<String>,
    /// Who approves the report.
    pub approver: Option<String>,
    /// Date of the test, `YYYY-MM-DD`.
    pub test_date: Option<String>,
    /// Laboratory or site.
    pub site: Option<String>,
    /// Procedure or standard followed.
    pub procedure: Option<String>,
    /// Ambient temperature, degC.
    pub ambient_temperature_c: Option<f64>,
    /// Ambient relative humidity, %.
    pub ambient_humidity_pct: Option<f64>,
    /// The customer.
    pub customer: Option<String>,
    /// The item's condition when received.
    pub item_condition: Option<String>,
    /// The date the item was received, `YYYY-MM-DD`.
    pub receipt_date: Option<String>,
    /// Deviations from, additions to or exclusions from the method.
    pub deviations: Option<String>,
    /// The last date of a test over several days, `YYYY-MM-DD`.
    pub test_date_end: Option<String>,
    /// The laboratory's name.
    pub laboratory: Option<String>,
    /// The laboratory's address.
    pub laboratory_address: Option<String>,
    /// The customer's contact information.
    pub customer_contact: Option<String>,
    /// Reference to the sampling plan and method.
    pub sampling: Option<String>,
}

/// Whether a piece of equipment was within its calibration on the test date.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CalibrationStatus {
    /// Due on or after the test date.
    Valid,
    /// Due before the test date.
    Expired,
    /// No due date given.
    NotStated,
}

/// One piece of test equipment.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct EquipmentRow {
    /// What it is.
    pub name: String,
    /// Make and model.
    pub model: Option<String>,
    /// Asset number or serial.
    pub id: String,
    /// Calibration due date, `YYYY-MM-DD`.
    pub calibration_due: Option<String>,
    /// Its status on the test date.
    pub status: CalibrationStatus,
}
