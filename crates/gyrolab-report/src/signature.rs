//! The signature block of an issued report: the draft's sign-off section (between
//! [`crate::html::SIGNATURE_BLOCK_BEGIN`] and [`crate::html::SIGNATURE_BLOCK_END`]) replaced by
//! who issued it, when, with what meaning and key, and the amendment it is, if one (ISO/IEC
//! 17025:2017 7.8.2.1 o, 7.8.8). The records store supplies the facts ([`gyrolab::sign_off::SignOff`]); this crate draws.

use crate::html::{escape, SIGNATURE_BLOCK_BEGIN, SIGNATURE_BLOCK_END};
pub use gyrolab::sign_off::SignOff as SignatureBlock;

/// The report.html of the issued report: the draft's sign-off block (between its markers, else
/// the `sign-off` section) replaced by the signature block, and the draft's report number and
/// issue date replaced by the issued ones.
pub fn issued_html(draft: &str, t: &SignatureBlock<'_>, draft_number: &str, draft_issue_date: &str) -> String {
    let mut block = format!("{SIGNATURE_BLOCK_BEGIN}\n<section class=\"sign-off\">\n<h2>Sign-off</h2>\n");
    block.push_str(&format!(
        "<p class=\"note\"><b>ISSUED</b>: report {} issued {} (UTC, the records store's clock).</p>\n",
        escape(t.number),
        escape(t.issued_at)
    ));
    if let Some((n, replaces, reason, changes)) = t.amendment {
        block.push_str(&format!(
            "<p class=\"note\"><b>Amendment {n} to report {}</b>, which it replaces. Reason: {}</p>\n<ul>\n",
            escape(replaces),
            escape(reason)
        ));
        for c in changes {
            block.push_str(&format!("<li>{}</li>\n", escape(c)));
        }
        block.push_str("</ul>\n");
    }
    block.push_str(
        "<table class=\"sign-off\"><thead><tr><th class=\"name\">role</th><th class=\"name\">name</th><th class=\"name\">\
         signature</th><th class=\"name\">date</th></tr></thead><tbody>\n",
    );
    block.push_str(&format!(
        "<tr><td class=\"name\">tested by</td><td class=\"name\">{}</td><td class=\"name\">stored by {}</td><td \
         class=\"name\">{}</td></tr>\n",
        escape(&t.tested_by),
        escape(&t.stored_by.join(", ")),
        escape(t.tested_on)
    ));
    let (display, name, role) = t.signer;
    block.push_str(&format!(
        "<tr><td class=\"name\">{} by</td><td class=\"name\">{} ({}, {})</td><td class=\"name\">signed electronically \
         (Ed25519, key {})</td><td class=\"name\">{}</td></tr>\n",
        escape(t.meaning),
        escape(display),
        escape(name),
        escape(role),
        escape(t.fingerprint),
        escape(t.issued_at)
    ));
    block.push_str(&format!(
        "</tbody></table>\n<p class=\"note\">manifest.json (every file of this folder with its SHA-256) is signed in \
         manifest.sig; <code>gyrolab verify DIR --public-key LAB.pub</code> checks the signature and every file. The \
         records store's chain head at issue: <code>{}</code>.</p>\n</section>\n{SIGNATURE_BLOCK_END}",
        escape(t.head)
    ));
    let mut html = match (draft.find(SIGNATURE_BLOCK_BEGIN), draft.find(SIGNATURE_BLOCK_END)) {
        (Some(a), Some(b)) if b > a => format!("{}{block}{}", &draft[..a], &draft[b + SIGNATURE_BLOCK_END.len()..]),
        _ => match draft.find("<section class=\"sign-off\">") {
            Some(a) => {
                let end = draft[a..].find("</section>").map_or(a, |e| a + e + "</section>".len());
                format!("{}{block}{}", &draft[..a], &draft[end..])
            }
            None => match draft.find("<p class=\"end\">") {
                Some(a) => format!("{}{block}\n{}", &draft[..a], &draft[a..]),
                None => format!("{draft}{block}\n"),
            },
        },
    };
    if !draft_issue_date.is_empty() {
        html = html.replace(
            &format!("<tr><td><b>issued</b></td><td>{}</td></tr>", escape(draft_issue_date)),
            &format!("<tr><td><b>issued</b></td><td>{}</td></tr>", escape(t.issued_at)),
        );
    }
    if draft_number.len() >= 4 {
        html = html.replace(&escape(draft_number), &escape(t.number));
    }
    html
}
