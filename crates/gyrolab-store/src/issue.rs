//! Issued reports and amendments (issue 53; docs/STORE.md "Issued reports and signatures").
//!
//! A stored evaluation is a draft. [`crate::Store::issue`] (an approver who did not store the
//! evaluation or a revision of it, password checked) gives it a report number unique in the
//! store and an issue date from the database's clock, and signs its report folder's manifest with
//! the lab's Ed25519 key: the issued folder is the stored report files with report.html's
//! sign-off block replaced by the signature block, plus `issue.json` (the issue record), a new
//! `manifest.json` over all of them and `manifest.sig`. The `issue` row keeps the signed manifest,
//! the signature, issue.json and the issued report.html; it is a record like every other (never
//! changed, chained). `Store::amend` issues a later revision of an issued evaluation as
//! "Amendment N to report R" (ISO/IEC 17025 7.8.8), naming what changed, and re-signs the
//! replaced report's folder with its issue.json marked superseded; the replaced report stays
//! retrievable (`gyrolab store report`).

use crate::account::{self, Need};
use crate::db::{returned_id, Columns, DbError, Exec, Kind, Row, Val};
use crate::{chain, schema, sign, Actor, Store, StoreError, StoreResult};
use ed25519_dalek::SigningKey;
use gyrolab_io::provenance::{manifest_json, Manifest, NamedOutput, MANIFEST};
use serde::Serialize;

/// The meaning of an issuing signature.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Meaning {
    /// The signer approves the report's results for issue.
    Approved,
    /// The signer reviewed the report.
    Reviewed,
}

impl Meaning {
    /// The stored word.
    pub fn as_str(self) -> &'static str {
        match self {
            Meaning::Approved => "approved",
            Meaning::Reviewed => "reviewed",
        }
    }
}

/// One issued report as the store holds it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct IssuedReport {
    /// The issue's id.
    pub id: i64,
    /// The evaluation issued.
    pub evaluation_id: i64,
    /// The report number (unique in the store).
    pub report_number: String,
    /// When it was issued (the database's clock, RFC 3339 UTC).
    pub issued_at: String,
    /// The signer's account name.
    pub signer: String,
    /// The signer's display name.
    pub signer_display_name: String,
    /// The signer's role.
    pub signer_role: String,
    /// approved or reviewed.
    pub meaning: String,
    /// The fingerprint of the lab key that signed.
    pub key_fingerprint: String,
    /// The store's chain head just before the issue.
    pub chain_head: String,
    /// The report this one amends (its number), if it is an amendment.
    pub amends_report: Option<String>,
    /// The amendment's number (1, 2, ...), if it is one.
    pub amendment_no: Option<i64>,
    /// Why it was amended.
    pub amend_reason: Option<String>,
    /// The report that supersedes this one (its number), when amended.
    pub superseded_by: Option<String>,
}

impl IssuedReport {
    /// `ISSUED` or `SUPERSEDED by N`.
    pub fn status(&self) -> String {
        match &self.superseded_by {
            Some(n) => format!("SUPERSEDED by report {n}"),
            None => "ISSUED".into(),
        }
    }
}

const ISSUE_COLUMNS: &str = "i.id AS id, i.evaluation_id AS evaluation_id, i.report_number AS report_number, \
     i.issued_at AS issued_at, i.signer_name AS signer_name, i.signer_display_name AS signer_display_name, \
     i.signer_role AS signer_role, i.meaning AS meaning, i.key_fingerprint AS key_fingerprint, i.chain_head AS chain_head, \
     (SELECT a.report_number FROM issue a WHERE a.id = i.amends) AS amends_report, i.amendment_no AS amendment_no, \
     i.amend_reason AS amend_reason, (SELECT s.report_number FROM issue s WHERE s.amends = i.id) AS superseded_by";
const ISSUE_KINDS: Columns<'static> = &[
    ("id", Kind::I),
    ("evaluation_id", Kind::I),
    ("report_number", Kind::T),
    ("issued_at", Kind::T),
    ("signer_name", Kind::T),
    ("signer_display_name", Kind::T),
    ("signer_role", Kind::T),
    ("meaning", Kind::T),
    ("key_fingerprint", Kind::T),
    ("chain_head", Kind::T),
    ("amends_report", Kind::T),
    ("amendment_no", Kind::IOpt),
    ("amend_reason", Kind::T),
    ("superseded_by", Kind::T),
];

fn issued_of(r: &Row) -> Result<IssuedReport, DbError> {
    Ok(IssuedReport {
        id: r.int("id")?,
        evaluation_id: r.int("evaluation_id")?,
        report_number: r.string("report_number")?,
        issued_at: r.string("issued_at")?,
        signer: r.string("signer_name")?,
        signer_display_name: r.string("signer_display_name")?,
        signer_role: r.string("signer_role")?,
        meaning: r.string("meaning")?,
        key_fingerprint: r.string("key_fingerprint")?,
        chain_head: r.string("chain_head")?,
        amends_report: r.string_opt("amends_report")?,
        amendment_no: r.int_opt("amendment_no")?,
        amend_reason: r.string_opt("amend_reason")?,
        superseded_by: r.string_opt("superseded_by")?,
    })
}

/// The issue of evaluation `id`, if it was issued.
pub(crate) fn issue_of(x: &mut dyn Exec, id: i64) -> Result<Option<IssuedReport>, DbError> {
    // ok: SQL from the module's constant column list; every value is a parameter.
    let sql = format!("SELECT {ISSUE_COLUMNS} FROM issue i WHERE i.evaluation_id = $1");
    x.rows(&sql, &[Val::I(id)], ISSUE_KINDS)?.first().map(issued_of).transpose()
}

/// Every issued report, oldest first.
pub(crate) fn all(x: &mut dyn Exec) -> Result<Vec<IssuedReport>, DbError> {
    // ok: SQL from the module's constant column list; every value is a parameter.
    let sql = format!("SELECT {ISSUE_COLUMNS} FROM issue i ORDER BY i.id");
    x.rows(&sql, &[], ISSUE_KINDS)?.iter().map(issued_of).collect()
}

/// Evaluation `id` and the revisions it supersedes, newest first (`id`, its predecessor, ...).
pub(crate) fn lineage(x: &mut dyn Exec, id: i64) -> Result<Vec<i64>, DbError> {
    let mut out = vec![id];
    let mut at = id;
    while let Some(prev) = x
        .rows("SELECT supersedes FROM evaluation WHERE id = $1", &[Val::I(at)], &[("supersedes", Kind::IOpt)])?
        .first()
        .map(|r| r.int_opt("supersedes"))
        .transpose()?
        .flatten()
    {
        if out.contains(&prev) || out.len() > 100_000 {
            break;
        }
        out.push(prev);
        at = prev;
    }
    Ok(out)
}

/// The accounts that stored evaluation `id` or any revision it supersedes (the audit trail:
/// stores, corrections and re-evaluations; not approvals, issues and amendments).
pub(crate) fn stored_by(x: &mut dyn Exec, id: i64) -> Result<Vec<i64>, DbError> {
    let mut out = Vec::new();
    for e in lineage(x, id)? {
        for r in x.rows(
            "SELECT account_id FROM audit_event WHERE evaluation_id = $1 AND account_id IS NOT NULL AND action NOT IN ('issue', 'amend', 'approval')",
            &[Val::I(e)],
            &[("account_id", Kind::I)],
        )? {
            out.push(r.int("account_id")?);
        }
    }
    Ok(out)
}

/// The current revision of evaluation `id` (following `supersedes` forward).
fn current_of(x: &mut dyn Exec, id: i64) -> Result<i64, DbError> {
    let mut at = id;
    for _ in 0..100_000 {
        match x.rows("SELECT id FROM evaluation WHERE supersedes = $1", &[Val::I(at)], &[("id", Kind::I)])?.first() {
            Some(r) => at = r.int("id")?,
            None => break,
        }
    }
    Ok(at)
}

/// What the issued report's HTML and issue.json say about the issue.
struct IssueText<'a> {
    number: &'a str,
    issued_at: &'a str,
    signer: &'a crate::Account,
    meaning: Meaning,
    fingerprint: &'a str,
    head: &'a str,
    evaluation_id: i64,
    stored_by: Vec<String>,
    record: &'a crate::record::EvaluationRecord,
    amendment: Option<(i64, &'a str, &'a str, &'a [String])>,
}

/// issue.json of an issued report; `superseded_by`: (number, date, reason) once amended.
fn issue_json(t: &IssueText, superseded_by: Option<(&str, &str, &str)>) -> String {
    let v = serde_json::json!({
        "about": "the issue record of this gyrolab report (gyrolab store issue): covered by manifest.json, whose exact \
                  bytes manifest.sig signs with the lab's Ed25519 key; `gyrolab verify DIR --public-key LAB.pub` checks both",
        "status": if superseded_by.is_some() { "superseded" } else { "issued" },
        "report_number": t.number,
        "issued_at": t.issued_at,
        "evaluation": t.evaluation_id,
        "serial": t.record.serial,
        "model": t.record.model,
        "lot": t.record.lot,
        "verdict": t.record.verdict,
        "stored_by": t.stored_by,
        "signature": {
            "signer": t.signer.name,
            "display_name": t.signer.display_name,
            "role": t.signer.role.as_str(),
            "meaning": t.meaning.as_str(),
            "signed_at": t.issued_at,
            "algorithm": "Ed25519",
            "key_fingerprint": t.fingerprint,
        },
        "store_chain_head_at_issue": t.head,
        "amendment": t.amendment.map(|(n, replaces, reason, changes)| serde_json::json!({
            "number": n,
            "replaces_report": replaces,
            "title": format!("Amendment {n} to report {replaces}"),
            "reason": reason,
            "changes": changes,
        })),
        "superseded_by": superseded_by.map(|(n, at, reason)| serde_json::json!({
            "report_number": n,
            "issued_at": at,
            "reason": reason,
        })),
    });
    serde_json::to_string_pretty(&v).map(|s| s + "\n").unwrap_or_default()
}

/// The report.html of the issued report, drawn by the caller's renderer (the report crate's
/// `signature::issued_html`) from the issue's facts.
fn issued_html(
    render: IssuedHtml<'_>,
    draft: &str,
    t: &IssueText,
    draft_number: &str,
    draft_issue_date: &str,
) -> String {
    let block = gyrolab::sign_off::SignOff {
        number: t.number,
        issued_at: t.issued_at,
        amendment: t.amendment,
        tested_by: t.record.operator.clone().unwrap_or_else(|| "(not named in the plan)".into()),
        stored_by: &t.stored_by,
        tested_on: t.record.test_date.as_deref().unwrap_or(&t.record.evaluated_at),
        meaning: t.meaning.as_str(),
        signer: (&t.signer.display_name, &t.signer.name, t.signer.role.as_str()),
        fingerprint: t.fingerprint,
        head: t.head,
    };
    render(draft, &block, draft_number, draft_issue_date)
}

/// The files of an issued folder (the stored ones but their manifest and any earlier issue
/// files, report.html replaced, issue.json added) and the manifest.json over them.
fn issued_outputs(
    files: &[(String, Vec<u8>)],
    html: &[u8],
    issue_json: &str,
) -> StoreResult<(Vec<NamedOutput>, String)> {
    let mut outputs: Vec<NamedOutput> = files
        .iter()
        .filter(|(n, _)| n != MANIFEST && n != sign::SIGNATURE_FILE && n != sign::ISSUE_FILE)
        .map(|(n, b)| NamedOutput {
            name: n.clone(),
            bytes: if n == "report.html" { html.to_vec() } else { b.clone() },
        })
        .collect();
    outputs.push(NamedOutput { name: sign::ISSUE_FILE.into(), bytes: issue_json.as_bytes().to_vec() });
    let manifest = manifest_json(&outputs)
        .map_err(|e| StoreError::Input { path: MANIFEST.into(), message: format!("cannot write the manifest: {e}") })?;
    Ok((outputs, manifest))
}

/// A file of a report folder: its name and bytes.
pub type NamedFile = (String, Vec<u8>);

/// Draws the issued report.html from the draft's, the sign-off's facts, the draft's report
/// number and its issue date (the report crate's `signature::issued_html`; the store persists
/// and draws nothing).
pub type IssuedHtml<'a> = &'a dyn Fn(&str, &gyrolab::sign_off::SignOff<'_>, &str, &str) -> String;

/// What an issue or an amendment asks for.
pub struct IssueRequest<'a> {
    /// Draws the issued report.html ([`IssuedHtml`]).
    pub render: IssuedHtml<'a>,
    /// The evaluation to issue (for an amendment: the issued evaluation or its later revision).
    pub evaluation: i64,
    /// The meaning of the signature.
    pub meaning: Meaning,
    /// The lab's private key (its public part recorded in the store).
    pub key: &'a SigningKey,
    /// The report number (default: the store's next `GL-YYYY-NNNN`).
    pub report_number: Option<&'a str>,
    /// An amendment: why (required for one; `None` issues a first report).
    pub amend_reason: Option<&'a str>,
}

/// What one draft evaluation holds for issuing: its record and files, the draft's number and date.
struct Draft {
    record: crate::record::EvaluationRecord,
    files: Vec<(String, Vec<u8>)>,
    number: String,
    issue_date: String,
}

fn draft(store: &mut Store, id: i64) -> StoreResult<Draft> {
    let record = store.evaluation(id)?.record;
    let files = crate::query::report_files(store, id)?;
    let results: serde_json::Value = serde_json::from_str(&record.results_json).unwrap_or_default();
    Ok(Draft {
        number: results["report_number"].as_str().unwrap_or_default().to_string(),
        issue_date: results["issue_date"].as_str().unwrap_or_default().to_string(),
        record,
        files,
    })
}

/// What changed from the replaced report's evaluation to the amending one (fields and figures).
fn changes(before: &crate::record::EvaluationRecord, after: &crate::record::EvaluationRecord) -> Vec<String> {
    let mut out = Vec::new();
    let o = |v: &Option<String>| v.clone().unwrap_or_else(|| "-".into());
    for (what, a, b) in [
        ("serial", before.serial.clone(), after.serial.clone()),
        ("model", before.model.clone(), after.model.clone()),
        ("lot", o(&before.lot), o(&after.lot)),
        ("operator", o(&before.operator), o(&after.operator)),
        ("test date", o(&before.test_date), o(&after.test_date)),
        ("overall verdict", o(&before.verdict), o(&after.verdict)),
        ("gyrolab version", before.software_version.clone(), after.software_version.clone()),
    ] {
        if a != b {
            out.push(format!("{what}: {a} -> {b}"));
        }
    }
    for c in crate::query::diff_figures(&before.figures, &after.figures) {
        let v = |x: Option<f64>| x.map_or_else(|| "-".into(), |x| format!("{x}"));
        out.push(format!(
            "{} {}: {} -> {} {} ({} -> {})",
            c.axis,
            c.figure,
            v(c.before),
            v(c.after),
            c.unit,
            o(&c.verdict_before),
            o(&c.verdict_after)
        ));
    }
    if out.is_empty() {
        out.push("no recorded field or figure changed (the report is re-issued)".into());
    }
    out
}

impl Store {
    /// Issues evaluation `req.evaluation` (see the module's documentation), or with
    /// `req.amend_reason` amends the report issued for it or for a revision it supersedes. The
    /// actor must be an approver who did not store the evaluation or any revision of it.
    pub fn issue(&mut self, actor: &Actor, req: &IssueRequest) -> StoreResult<IssuedReport> {
        let refused = |s: &Store, m: String| StoreError::Refused { store: s.name().to_string(), message: m };
        if let Some(n) = req.report_number {
            if n.trim().is_empty() || n.chars().count() > 64 || n.chars().any(char::is_control) {
                return Err(refused(self, "--report-number: expected 1 to 64 printable characters".into()));
            }
        }
        if let Some(r) = req.amend_reason {
            if r.trim().is_empty() {
                return Err(refused(self, "an amendment needs a reason (--reason)".into()));
            }
            crate::record::check_text("--reason", r).map_err(|m| refused(self, m))?;
        }
        let signer = actor.account().cloned().ok_or_else(|| {
            refused(self, "issuing needs an approver's account (--user NAME with its password)".into())
        })?;
        // What to issue, read before the transaction (records never change; the checks that
        // decide are repeated inside it).
        let store_name = self.name().to_string();
        let dberr = |m: DbError| StoreError::Database { store: store_name.clone(), message: m.to_string() };
        let (target, prior) = self.transaction(|x| {
            let target = if req.amend_reason.is_some() { current_of(x, req.evaluation) } else { Ok(req.evaluation) }
                .map_err(&dberr)?;
            let mut prior = None;
            for e in lineage(x, target).map_err(&dberr)?.into_iter().skip(1) {
                if let Some(i) = issue_of(x, e).map_err(&dberr)? {
                    prior = Some(i);
                    break;
                }
            }
            Ok((target, prior))
        })?;
        let new = draft(self, target)?;
        let old = match (&prior, req.amend_reason) {
            (Some(p), Some(_)) => Some(draft(self, p.evaluation_id)?),
            _ => None,
        };
        let verifying = req.key.verifying_key();
        let fingerprint = sign::fingerprint(&verifying);
        let public = sign::public_hex(&verifying);
        let postgres = self.is_postgres();
        self.write(|x, store| {
            let dberr = |m: DbError| StoreError::Database { store: store.to_string(), message: m.to_string() };
            let refused = |m: String| StoreError::Refused { store: store.to_string(), message: m };
            let (account_id, _) = account::check_actor(x, store, actor, Need::Approver)?;
            let account_id = account_id.ok_or_else(|| StoreError::Auth { store: store.to_string() })?;
            if x
                .rows("SELECT id FROM signing_key WHERE public_key = $1", &[Val::T(Some(public.clone()))], &[("id", Kind::I)])
                .map_err(dberr)?
                .is_empty()
            {
                return Err(refused(format!(
                    "the signing key ({fingerprint}) is not one of this store's lab keys: `gyrolab store key init` makes \
                     one and records its public key"
                )));
            }
            if let Some(r) = x
                .rows("SELECT id FROM evaluation WHERE supersedes = $1", &[Val::I(target)], &[("id", Kind::I)])
                .map_err(dberr)?
                .first()
            {
                return Err(refused(format!(
                    "evaluation {target} is superseded by evaluation {}: only a current revision is issued",
                    r.int("id").map_err(dberr)?
                )));
            }
            if let Some(i) = issue_of(x, target).map_err(dberr)? {
                return Err(refused(match req.amend_reason {
                    Some(_) => format!(
                        "evaluation {target} is issued as report {} and has no later revision: store a correction \
                         (gyrolab store revise) or a re-evaluation (gyrolab store reevaluate) first, then amend",
                        i.report_number
                    ),
                    None => format!("evaluation {target} is issued already, as report {}", i.report_number),
                }));
            }
            let amendment = match (req.amend_reason, &prior) {
                (None, Some(p)) => {
                    return Err(refused(format!(
                        "evaluation {target} revises issued report {}: it is issued as an amendment (gyrolab store amend \
                         {target} --reason ...)",
                        p.report_number
                    )))
                }
                (Some(_), None) => {
                    return Err(refused(format!(
                        "evaluation {target} and the revisions it supersedes were never issued: nothing to amend (gyrolab \
                         store issue issues it)"
                    )))
                }
                (Some(reason), Some(p)) => {
                    // Read again inside the transaction: another amendment may have landed since.
                    let now = issue_of(x, p.evaluation_id).map_err(dberr)?;
                    if let Some(s) = now.as_ref().and_then(|n| n.superseded_by.as_ref()) {
                        return Err(refused(format!(
                            "report {} is superseded already by report {s}: amend that one",
                            p.report_number
                        )));
                    }
                    Some((p, reason))
                }
                (None, None) => None,
            };
            if stored_by(x, target).map_err(dberr)?.contains(&account_id) {
                return Err(refused(format!(
                    "self-approval refused: account {:?} stored evaluation {target} or a revision of it; another \
                     approver must issue it",
                    signer.name
                )));
            }
            let issued_at = x
                .rows(schema::clock_sql(postgres), &[], &[("now", Kind::T)])
                .map_err(dberr)?
                .first()
                .map(|r| r.string("now"))
                .ok_or_else(|| dberr("the database gave no time".into()))?
                .map_err(dberr)?;
            let number = match req.report_number {
                Some(n) => n.to_string(),
                None => {
                    let year = issued_at.get(..4).unwrap_or("0000").to_string();
                    let mut n = crate::db::first_int(
                        &x.rows("SELECT COUNT(*) AS n FROM issue", &[], &[("n", Kind::I)]).map_err(dberr)?,
                        "n",
                        0,
                    )
                    .map_err(dberr)?
                        + 1;
                    loop {
                        let candidate = format!("GL-{year}-{n:04}");
                        if x
                            .rows("SELECT id FROM issue WHERE report_number = $1", &[Val::T(Some(candidate.clone()))], &[
                                ("id", Kind::I),
                            ])
                            .map_err(dberr)?
                            .is_empty()
                        {
                            break candidate;
                        }
                        n += 1;
                    }
                }
            };
            let head = chain::current_head(x).map_err(dberr)?.unwrap_or_default();
            let names = |x: &mut dyn Exec, id: i64| -> StoreResult<Vec<String>> {
                let mut out: Vec<String> = Vec::new();
                for e in lineage(x, id).map_err(dberr)?.into_iter().rev() {
                    for ev in account::events(x, Some(e)).map_err(dberr)? {
                        if matches!(ev.action.as_str(), "issue" | "amend" | "approval") {
                            continue;
                        }
                        let shown = match account::by_name(x, &ev.actor).map_err(dberr)? {
                            Some((a, _)) => format!("{} ({})", a.display_name, a.name),
                            None => ev.actor,
                        };
                        if !out.contains(&shown) {
                            out.push(shown);
                        }
                    }
                }
                Ok(out)
            };
            let stored_names = names(x, target)?;
            let change_list = match (&amendment, &old) {
                (Some(_), Some(o)) => changes(&o.record, &new.record),
                _ => Vec::new(),
            };
            let amendment_no = amendment.as_ref().map(|(p, _)| p.amendment_no.unwrap_or(0) + 1);
            let text = IssueText {
                number: &number,
                issued_at: &issued_at,
                signer: &signer,
                meaning: req.meaning,
                fingerprint: &fingerprint,
                head: &head,
                evaluation_id: target,
                stored_by: stored_names,
                record: &new.record,
                amendment: amendment
                    .as_ref()
                    .zip(amendment_no)
                    .map(|((p, reason), n)| (n, p.report_number.as_str(), *reason, change_list.as_slice())),
            };
            let json = issue_json(&text, None);
            let draft_html = new.files.iter().find(|(n, _)| n == "report.html").map(|(_, b)| b.clone());
            let html = match draft_html {
                Some(b) => issued_html(req.render, &String::from_utf8_lossy(&b), &text, &new.number, &new.issue_date)
                    .into_bytes(),
                None => return Err(refused(format!("evaluation {target} has no stored report.html to issue"))),
            };
            let (_, manifest) = issued_outputs(&new.files, &html, &json)?;
            let signature = sign::sign_manifest(req.key, manifest.as_bytes());
            // The replaced report, re-signed with its issue.json marked superseded.
            let superseded = match (&amendment, &old) {
                (Some((p, reason)), Some(o)) => {
                    let (old_json, old_html) = x
                        .rows(
                            "SELECT issue_json, report_html_zstd FROM issue WHERE id = $1",
                            &[Val::I(p.id)],
                            &[("issue_json", Kind::T), ("report_html_zstd", Kind::B)],
                        )
                        .map_err(dberr)?
                        .first()
                        .map(|r| -> Result<_, DbError> {
                            Ok((r.string("issue_json")?, r.bytes("report_html_zstd")?.map(<[u8]>::to_vec).unwrap_or_default()))
                        })
                        .ok_or_else(|| dberr("the replaced issue is gone".into()))?
                        .map_err(dberr)?;
                    let mut v: serde_json::Value =
                        serde_json::from_str(&old_json).map_err(|e| dberr(format!("the replaced issue.json: {e}").into()))?;
                    v["status"] = "superseded".into();
                    v["superseded_by"] =
                        serde_json::json!({ "report_number": number, "issued_at": issued_at, "reason": reason });
                    let old_json = serde_json::to_string_pretty(&v).map(|s| s + "\n").unwrap_or_default();
                    let old_html = zstd::stream::decode_all(old_html.as_slice())
                        .map_err(|e| dberr(format!("the replaced report.html: {e}").into()))?;
                    let (_, old_manifest) = issued_outputs(&o.files, &old_html, &old_json)?;
                    let old_signature = sign::sign_manifest(req.key, old_manifest.as_bytes());
                    Some((old_json, old_manifest, old_signature))
                }
                _ => None,
            };
            let packed = zstd::bulk::compress(&html, 3).map_err(|e| dberr(format!("cannot compress: {e}").into()))?;
            let t = |s: &str| Val::T(Some(s.to_string()));
            let rows = x
                .rows(
                    "INSERT INTO issue (evaluation_id, report_number, issued_at, signer_account_id, signer_name, \
                     signer_display_name, signer_role, meaning, key_fingerprint, chain_head, issue_json, report_html_zstd, \
                     manifest, signature, amends, amendment_no, amend_reason, superseded_issue_json, superseded_manifest, \
                     superseded_signature) VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11, $12, $13, $14, $15, $16, \
                     $17, $18, $19, $20) RETURNING id",
                    &[
                        Val::I(target),
                        t(&number),
                        t(&issued_at),
                        Val::I(account_id),
                        t(&signer.name),
                        t(&signer.display_name),
                        t(signer.role.as_str()),
                        t(req.meaning.as_str()),
                        t(&fingerprint),
                        t(&head),
                        t(&json),
                        Val::B(Some(packed)),
                        t(&manifest),
                        t(&signature),
                        Val::IOpt(amendment.as_ref().map(|(p, _)| p.id)),
                        Val::IOpt(amendment_no),
                        Val::T(amendment.as_ref().map(|(_, r)| r.to_string())),
                        Val::T(superseded.as_ref().map(|s| s.0.clone())),
                        Val::T(superseded.as_ref().map(|s| s.1.clone())),
                        Val::T(superseded.as_ref().map(|s| s.2.clone())),
                    ],
                    &[("id", Kind::I)],
                )
                .map_err(|e| {
                    let m = e.to_string();
                    if m.contains("UNIQUE") || m.contains("unique") || m.contains("duplicate") || m.contains("replaced") {
                        refused(format!(
                            "report number {number:?} or evaluation {target} is issued already, or the report it amends \
                             is amended already (the store refuses a second issue of any of them)"
                        ))
                    } else {
                        dberr(e)
                    }
                })?;
            let id = returned_id(&rows).map_err(dberr)?;
            chain::append_row(x, "issue", id).map_err(dberr)?;
            let (action, detail) = match &amendment {
                Some((p, reason)) => ("amend", format!("report {number} amends report {}: {reason}", p.report_number)),
                None => ("issue", format!("report {number}, {}", req.meaning.as_str())),
            };
            account::audit(x, Some(account_id), &signer.name, action, Some(target), Some(&detail)).map_err(dberr)?;
            issue_of(x, target).map_err(dberr)?.ok_or_else(|| dberr("the issue is not there".into()))
        })
    }

    /// The issue of evaluation `id`, if it was issued.
    pub fn issue_of(&mut self, id: i64) -> StoreResult<Option<IssuedReport>> {
        let store = self.name().to_string();
        self.transaction(|x| {
            issue_of(x, id).map_err(|m| StoreError::Database { store: store.clone(), message: m.to_string() })
        })
    }

    /// Every issued report, oldest first.
    pub fn issued_reports(&mut self) -> StoreResult<Vec<IssuedReport>> {
        let store = self.name().to_string();
        self.transaction(|x| all(x).map_err(|m| StoreError::Database { store: store.clone(), message: m.to_string() }))
    }

    /// The issued folder of evaluation `id` (its files, manifest.json and manifest.sig; the
    /// superseded version when amended), each file checked against the signed manifest and the
    /// signature against the lab key recorded in the store; `None` for a draft.
    pub fn issued_files(&mut self, id: i64) -> StoreResult<Option<Vec<NamedFile>>> {
        let store = self.name().to_string();
        let dberr = |m: DbError| StoreError::Database { store: store.clone(), message: m.to_string() };
        let row = self.transaction(|x| {
            let rows = x
                .rows(
                    "SELECT i.issue_json AS issue_json, i.report_html_zstd AS report_html_zstd, i.manifest AS manifest, \
                     i.signature AS signature, s.superseded_issue_json AS superseded_issue_json, \
                     s.superseded_manifest AS superseded_manifest, s.superseded_signature AS superseded_signature, \
                     i.key_fingerprint AS key_fingerprint, k.public_key AS public_key, i.report_number AS report_number FROM issue i \
                     LEFT JOIN issue s ON s.amends = i.id LEFT JOIN signing_key k ON k.fingerprint = i.key_fingerprint \
                     WHERE i.evaluation_id = $1",
                    &[Val::I(id)],
                    &[
                        ("issue_json", Kind::T),
                        ("report_html_zstd", Kind::B),
                        ("manifest", Kind::T),
                        ("signature", Kind::T),
                        ("superseded_issue_json", Kind::T),
                        ("superseded_manifest", Kind::T),
                        ("superseded_signature", Kind::T),
                        ("key_fingerprint", Kind::T),
                        ("public_key", Kind::T),
                        ("report_number", Kind::T),
                    ],
                )
                .map_err(&dberr)?;
            Ok(rows.into_iter().next())
        })?;
        let Some(r) = row else { return Ok(None) };
        let files = crate::query::report_files(self, id)?;
        let html =
            zstd::stream::decode_all(r.bytes("report_html_zstd").map_err(dberr)?.unwrap_or_default()).map_err(|e| {
                dberr(format!("evaluation {id}: the issued report.html cannot be decompressed: {e}").into())
            })?;
        let (json, manifest, signature) = match r.text("superseded_issue_json").map_err(dberr)? {
            Some(j) => (
                j.to_string(),
                r.string("superseded_manifest").map_err(dberr)?,
                r.string("superseded_signature").map_err(dberr)?,
            ),
            None => (
                r.string("issue_json").map_err(dberr)?,
                r.string("manifest").map_err(dberr)?,
                r.string("signature").map_err(dberr)?,
            ),
        };
        let number = r.string("report_number").map_err(dberr)?;
        let tampered = |what: String| StoreError::Tampered {
            store: store.clone(),
            first: format!("issued report {number} (evaluation {id}): {what}"),
            more: String::new(),
        };
        let (outputs, _) = issued_outputs(&files, &html, &json)?;
        let signed: Manifest = serde_json::from_str(&manifest)
            .map_err(|e| tampered(format!("its signed manifest cannot be read: {e}")))?;
        for o in &outputs {
            let sha = crate::record::hash_bytes(&o.bytes);
            if !signed.files.iter().any(|f| f.name == o.name && f.sha256 == sha) {
                return Err(tampered(format!("{} differs from its signed manifest", o.name)));
            }
        }
        if signed.files.len() != outputs.len() {
            return Err(tampered("its signed manifest lists files the store does not hold".into()));
        }
        let (public, fingerprint) =
            (r.string("public_key").map_err(dberr)?, r.string("key_fingerprint").map_err(dberr)?);
        let key = sign::public_from_hex(&public)
            .ok_or_else(|| tampered(format!("the lab key {fingerprint} is not recorded in the store")))?;
        if !sign::verify_manifest(&key, manifest.as_bytes(), &signature) {
            return Err(tampered("its signature does not verify with the lab key recorded in the store".into()));
        }
        let mut out: Vec<(String, Vec<u8>)> = outputs.into_iter().map(|o| (o.name, o.bytes)).collect();
        out.push((MANIFEST.into(), manifest.into_bytes()));
        out.push((sign::SIGNATURE_FILE.into(), sign::signature_file(&key, &signature).into_bytes()));
        Ok(Some(out))
    }
}
