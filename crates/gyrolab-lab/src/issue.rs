//! Issuing and amending a stored evaluation (docs/STORE.md "Issued reports and signatures"): the
//! store numbers, signs and persists; the report crate draws the issued report.html's signature
//! block. This module joins the two for every front end.

use gyrolab_store::issue::{IssueRequest, IssuedReport, Meaning};
use gyrolab_store::sign::SigningKey;
use gyrolab_store::{Actor, Store, StoreResult};

/// What to issue: the evaluation, the signature's meaning, the lab key, an optional report
/// number (default: the store's next `GL-YYYY-NNNN`) and, for an amendment, its reason.
pub struct Issue<'a> {
    /// The evaluation to issue (for an amendment: the issued evaluation or its later revision).
    pub evaluation: i64,
    /// The meaning of the signature.
    pub meaning: Meaning,
    /// The lab's private key.
    pub key: &'a SigningKey,
    /// The report number.
    pub report_number: Option<&'a str>,
    /// An amendment's reason (`None`: a first issue).
    pub amend_reason: Option<&'a str>,
}

/// Issues (or amends) as `actor`, the issued report.html drawn by
/// [`gyrolab_report::signature::issued_html`].
pub fn issue(store: &mut Store, actor: &Actor, what: &Issue<'_>) -> StoreResult<IssuedReport> {
    let req = IssueRequest {
        render: &gyrolab_report::signature::issued_html,
        evaluation: what.evaluation,
        meaning: what.meaning,
        key: what.key,
        report_number: what.report_number,
        amend_reason: what.amend_reason,
    };
    store.issue(actor, &req)
}
