//! Issuing and amending a stored evaluation (docs/STORE.md "Issued reports and signatures"): the
//! store numbers, signs and persists; the report crate draws the issued report.html's signature
//! block. This module joins the two for every front end.

use gyrolab_store::issue::{IssueRequest, IssuedReport, Meaning};
use gyrolab_store::sign::SigningKey;
use gyrolab_store::{sign, Actor, Role, Store, StoreError, StoreResult};

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

/// What `gyrolab store issue` and `amend` print: the report issued (an amendment's number and
/// the report it supersedes), by whom, with which key, and how to write and check the folder.
pub fn issued_text(r: &IssuedReport) -> String {
    let what = match (&r.amends_report, r.amendment_no) {
        (Some(old), Some(n)) => format!("amendment {n} to report {old} (now SUPERSEDED), "),
        _ => String::new(),
    };
    format!(
        "issued evaluation {} as report {} ({what}{} by {} ({}), {} UTC), signed with key {}\nstore chain head at \
         issue: {}\nwrite the issued folder: gyrolab store report {} --out DIR; check it: gyrolab verify DIR \
         --public-key LAB.pub\n",
        r.evaluation_id,
        r.report_number,
        r.meaning,
        r.signer_display_name,
        r.signer,
        r.issued_at,
        r.key_fingerprint,
        r.chain_head,
        r.evaluation_id
    )
}

/// `gyrolab store key init`: the lab's Ed25519 key pair written to `out` (private, mode 0600)
/// and `out`.pub, and its public key recorded in the store, by an admin (or anyone in a store
/// without accounts); the actor is checked before any file is written. What was done, as text.
pub fn init_key(store: &mut Store, actor: &Actor, out: &std::path::Path) -> StoreResult<String> {
    let allowed = match actor.account() {
        Some(acc) => acc.role == Role::Admin,
        None => !store.has_accounts()?,
    };
    if !allowed {
        return Err(StoreError::Refused {
            store: store.name().to_string(),
            message: "the lab key is recorded by an admin: --user NAME of an admin account, with its password".into(),
        });
    }
    let key = sign::create_key_files(out)
        .map_err(|message| StoreError::Input { path: out.display().to_string(), message })?;
    let fingerprint = store.add_signing_key(actor, &key)?;
    Ok(format!(
        "wrote the private key {} (mode 0600: keep it secret, outside the store) and the public key {}\nrecorded \
         public key {fingerprint} in {}\n",
        out.display(),
        sign::public_path_for(out).display(),
        store.name()
    ))
}

/// `gyrolab store grant ROLE`: the PostgreSQL `role` given SELECT and INSERT only on the store's
/// tables (and nothing else: UPDATE, DELETE, TRUNCATE and TRIGGER revoked), run by the owner;
/// what was granted, as text.
pub fn grant_text(store: &mut Store, role: &str) -> StoreResult<String> {
    let tables = store.grant_least_privilege(role)?;
    Ok(format!(
        "granted {role:?} SELECT and INSERT on {} table(s) of {} ({}), SELECT on gyrolab_schema; UPDATE, DELETE, \
         TRUNCATE, REFERENCES and TRIGGER revoked. Run gyrolab as {role:?} from now on; the owner role applies \
         the migrations of a newer gyrolab (docs/STORE.md, \"Least privilege\").\n",
        tables.len(),
        store.name(),
        tables.join(", ")
    ))
}
