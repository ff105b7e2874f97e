//! The sign-off of an issued report: who issued it, when, with what meaning and key, and the
//! amendment it is, if one (ISO/IEC 17025:2017 7.8.2.1 o, 7.8.8). The records store supplies
//! these facts when it issues; the report crate draws them.

/// The facts of an issue, as an issued report's signature block prints them.
#[derive(Debug, Clone, PartialEq)]
pub struct SignOff<'a> {
    /// The report number assigned at issue.
    pub number: &'a str,
    /// The issue time (UTC, the store's clock).
    pub issued_at: &'a str,
    /// Amendment n, the report it replaces, the reason and what changed.
    pub amendment: Option<(i64, &'a str, &'a str, &'a [String])>,
    /// Who tested (the plan's operator, or a placeholder).
    pub tested_by: String,
    /// The accounts that stored the evaluation and its revisions.
    pub stored_by: &'a [String],
    /// The test date (else the evaluation time).
    pub tested_on: &'a str,
    /// The meaning of the signature (`approved`, `reviewed`).
    pub meaning: &'a str,
    /// The signer's display name, account name and role.
    pub signer: (&'a str, &'a str, &'a str),
    /// The fingerprint of the lab key that signed.
    pub fingerprint: &'a str,
    /// The store's chain head at issue.
    pub head: &'a str,
}
