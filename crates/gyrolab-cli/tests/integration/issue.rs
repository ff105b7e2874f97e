//! Accounts, issue, signatures and amendments (issue 53) from the command line, every test body
//! on a temporary SQLite file AND on the PostgreSQL test server (GYROLAB_TEST_PG_URL; one schema
//! per test). Checked: the first account is an admin made without authentication, later ones
//! only by an admin; a wrong password, an unknown user and a disabled account get one message,
//! exit 2; an operator cannot issue; self-approval is refused; issue assigns a report number and
//! a date from the database; a duplicate report number is refused; `verify --public-key` passes
//! an issued folder, names an edited file and a rewritten manifest, and says NOT CHECKED without
//! the key (exit 5); an amendment names the report it replaces, which is marked SUPERSEDED; a
//! database administrator who rewrites an issued row, re-signs with their own key and recomputes
//! the whole chain passes `store check` but not `verify --public-key` with the lab's key; no
//! password appears in any output.

use assert_cmd::Command;
use std::path::{Path, PathBuf};

use crate::store::store_backends::backends;

const ADMIN_PW: &str = "Adm1n-pass-\u{e9}t\u{e9}";
const OPER_PW: &str = "0per-pass-word!";
const APPR_PW: &str = "Appr0ver-pass#1";
const APPR2_PW: &str = "Second-appr0ver%2";
const ALL_PW: [&str; 4] = [ADMIN_PW, OPER_PW, APPR_PW, APPR2_PW];

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Every command's output, kept to check that no password appears in any of them.
struct Run {
    store: String,
    outputs: Vec<String>,
}

impl Run {
    fn new(store: &str) -> Run {
        Run { store: store.to_string(), outputs: Vec::new() }
    }

    /// `gyrolab ARGS --store STORE` as `user` (password from GYROLAB_PASSWORD), with `stdin`:
    /// (exit code, stdout, stderr).
    fn run(&mut self, args: &[&str], user: Option<(&str, &str)>, stdin: Option<&str>) -> (i32, String, String) {
        let mut c = Command::cargo_bin("gyrolab").unwrap();
        c.env_remove("GYROLAB_STORE")
            .env_remove("GYROLAB_USER")
            .env_remove("GYROLAB_PASSWORD")
            .env_remove("GYROLAB_NEW_PASSWORD")
            .args(args)
            .args(["--store", &self.store]);
        if let Some((u, p)) = user {
            c.env("GYROLAB_USER", u).env("GYROLAB_PASSWORD", p);
        }
        c.write_stdin(stdin.unwrap_or("").to_string());
        let o = c.output().unwrap();
        let (out, err) =
            (String::from_utf8_lossy(&o.stdout).into_owned(), String::from_utf8_lossy(&o.stderr).into_owned());
        self.outputs.push(format!("{args:?}\n{out}\n{err}"));
        (o.status.code().unwrap_or(-1), out, err)
    }

    fn ok(&mut self, args: &[&str], user: Option<(&str, &str)>, stdin: Option<&str>) -> String {
        let (code, out, err) = self.run(args, user, stdin);
        assert_eq!(code, 0, "{args:?}: {out}{err}");
        out
    }

    fn no_password_anywhere(&self) {
        for o in &self.outputs {
            for p in ALL_PW {
                assert!(!o.contains(p), "a password in the output of {o}");
            }
        }
    }
}

/// The paper plan in `dir` (its inputs by absolute path) as `name`, with `serial`.
fn plan(dir: &Path, name: &str, serial: &str) -> PathBuf {
    let data = repo().join("data/paper/");
    let text = std::fs::read_to_string(repo().join("examples/paper_plan.toml"))
        .unwrap()
        .replace("../data/paper/", &format!("{}/", data.display()))
        .replace("serial = \"paper-2014\"", &format!("serial = \"{serial}\""));
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// A store with an admin, an operator, two approvers and the lab key (`lab.key`, `lab.pub` in
/// `dir`); checks the account rules on the way.
fn lab(r: &mut Run, dir: &Path) -> (PathBuf, PathBuf) {
    let admin = Some(("admin", ADMIN_PW));
    // The first account must be an admin.
    let (code, _, err) =
        r.run(&["store", "user", "add", "first", "--role", "operator", "--password-stdin"], None, Some("longenough\n"));
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("must be an admin"), "{err}");
    r.ok(
        &["store", "user", "add", "admin", "--role", "admin", "--display-name", "A. Admin", "--password-stdin"],
        None,
        Some(&format!("{ADMIN_PW}\n")),
    );
    // Then only an authenticated admin adds accounts.
    let (code, _, err) =
        r.run(&["store", "user", "add", "intruder", "--role", "admin", "--password-stdin"], None, Some("longenough\n"));
    assert_eq!(code, 2, "{err}");
    for (name, role, display, pw) in [
        ("op", "operator", "O. Perator", OPER_PW),
        ("appr", "approver", "A. Prover", APPR_PW),
        ("appr2", "approver", "B. Prover", APPR2_PW),
    ] {
        r.ok(
            &["store", "user", "add", name, "--role", role, "--display-name", display, "--password-stdin"],
            admin,
            Some(&format!("{pw}\n")),
        );
    }
    let (code, _, _) = r.run(
        &["store", "user", "add", "op2", "--role", "operator", "--password-stdin"],
        Some(("op", OPER_PW)),
        Some("longenough\n"),
    );
    assert_eq!(code, 2, "an operator adds no account");
    let key = dir.join("lab.key");
    let (code, _, _) = r.run(&["store", "key", "init", "--out", key.to_str().unwrap()], Some(("op", OPER_PW)), None);
    assert_eq!(code, 2, "an operator makes no lab key");
    assert!(!key.exists(), "nothing written when refused");
    r.ok(&["store", "key", "init", "--out", key.to_str().unwrap()], admin, None);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        assert_eq!(std::fs::metadata(&key).unwrap().permissions().mode() & 0o777, 0o600);
    }
    let (code, _, err) = r.run(&["store", "key", "init", "--out", key.to_str().unwrap()], admin, None);
    assert_eq!(code, 2, "a key file is never overwritten: {err}");
    let list = r.ok(&["store", "user", "list"], None, None);
    for n in ["admin", "op", "appr", "appr2"] {
        assert!(list.contains(n), "{list}");
    }
    (key.clone(), dir.join("lab.pub"))
}

fn eval(r: &mut Run, plan: &Path, out: &Path, user: Option<(&str, &str)>) -> (i32, String) {
    let (code, _, err) = r.run(&["eval", plan.to_str().unwrap(), "--out", out.to_str().unwrap()], user, None);
    (code, err)
}

fn stored_id(err: &str) -> String {
    let at = err.find("Stored as evaluation ").expect("stored") + "Stored as evaluation ".len();
    err[at..].split_whitespace().next().unwrap().to_string()
}

fn args(v: &[String]) -> Vec<&str> {
    v.iter().map(String::as_str).collect()
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}

#[test]
fn accounts_issue_verify_and_amend_from_the_command_line() {
    for b in backends("cli_issue") {
        let dir = tempfile::tempdir().unwrap();
        let mut r = Run::new(&b.location);
        let (key, public) = lab(&mut r, dir.path());
        let (k, p) = (key.to_str().unwrap(), public.to_str().unwrap());
        let op = Some(("op", OPER_PW));
        let appr = Some(("appr", APPR_PW));
        let appr2 = Some(("appr2", APPR2_PW));
        let plan1 = plan(dir.path(), "p1.toml", "SN-1");

        // Writes need an account now; a wrong password, an unknown user: one message, exit 2.
        let out = dir.path().join("r0");
        let (code, err) = eval(&mut r, &plan1, &out, None);
        assert_eq!(code, 2, "{}: {err}", b.name);
        assert!(err.contains("this store has accounts") && !out.exists(), "{}: {err}", b.name);
        let mut messages = Vec::new();
        for who in [("op", "wrong-password"), ("nobody", OPER_PW)] {
            let (code, err) = eval(&mut r, &plan1, &out, Some(who));
            assert_eq!(code, 2, "{}: {err}", b.name);
            assert!(!out.exists(), "{}: nothing written", b.name);
            messages.push(err.lines().find(|l| l.contains("authentication failed")).unwrap_or_default().to_string());
        }
        assert!(!messages[0].is_empty() && messages[0] == messages[1], "{}: {messages:?}", b.name);

        // The operator evaluates and stores; the operator cannot issue.
        let (code, err) = eval(&mut r, &plan1, &dir.path().join("r1"), op);
        assert_eq!(code, 3, "{}: {err}", b.name);
        let id1 = stored_id(&err);
        let show = r.ok(&["store", "show", &id1], None, None);
        assert!(show.contains("DRAFT") && show.contains("store by op"), "{}: {show}", b.name);
        let issue = |id: &str| ["store", "issue", id, "--meaning", "approved", "--signing-key", k].map(str::to_string);
        let (code, _, err) = r.run(&args(&issue(&id1)), op, None);
        assert_eq!(code, 2, "{}: {err}", b.name);
        assert!(err.contains("only an approver"), "{}: {err}", b.name);

        // Self-approval refused: an approver's own evaluation.
        let plan2 = plan(dir.path(), "p2.toml", "SN-2");
        let (_, err) = eval(&mut r, &plan2, &dir.path().join("r2"), appr);
        let id2 = stored_id(&err);
        let (code, _, err) = r.run(&args(&issue(&id2)), appr, None);
        assert_eq!(code, 2, "{}: {err}", b.name);
        assert!(err.contains("self-approval refused"), "{}: {err}", b.name);

        // The approver issues the operator's evaluation: number and date from the store.
        let said = r.ok(&args(&issue(&id1)), appr, None);
        assert!(said.contains("as report GL-"), "{}: {said}", b.name);
        let (code, _, err) = r.run(&args(&issue(&id1)), appr2, None);
        assert_eq!(code, 2, "{}: issued once: {err}", b.name);
        let issued = dir.path().join("issued");
        r.ok(&["store", "report", &id1, "--out", issued.to_str().unwrap()], None, None);
        let record = json(&issued.join("issue.json"));
        let number = record["report_number"].as_str().unwrap().to_string();
        assert!(number.starts_with("GL-") && number.len() == 12, "{}: {number}", b.name);
        let at = record["issued_at"].as_str().unwrap();
        assert!(at.len() == 24 && at.ends_with('Z') && at.as_bytes()[10] == b'T', "{}: {at}", b.name);
        assert_eq!(record["signature"]["signer"], "appr");
        assert_eq!(record["signature"]["meaning"], "approved");
        assert_eq!(record["status"], "issued");
        let html = std::fs::read_to_string(issued.join("report.html")).unwrap();
        assert!(html.contains("<b>ISSUED</b>") && html.contains(&number) && !html.contains("DRAFT: not issued"));
        assert!(html.contains("A. Prover"), "{}: the signer's name in the signature block", b.name);

        // A duplicate report number is refused (another approver, another evaluation).
        let plan3 = plan(dir.path(), "p3.toml", "SN-3");
        let (_, err) = eval(&mut r, &plan3, &dir.path().join("r3"), op);
        let id3 = stored_id(&err);
        let mut dup = issue(&id3).to_vec();
        dup.extend(["--report-number".to_string(), number.clone()]);
        let (code, _, err) = r.run(&args(&dup), appr2, None);
        assert_eq!(code, 2, "{}: {err}", b.name);
        assert!(err.contains("issued already"), "{}: {err}", b.name);

        // verify: with the key exit 0; without it NOT CHECKED, exit 5.
        let verify = |r: &mut Run, dir: &Path, key: bool| {
            let mut c = Command::cargo_bin("gyrolab").unwrap();
            c.args(["verify", dir.to_str().unwrap()]);
            if key {
                c.args(["--public-key", p]);
            }
            let o = c.output().unwrap();
            let text = format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
            r.outputs.push(text.clone());
            (o.status.code().unwrap_or(-1), text)
        };
        let (code, text) = verify(&mut r, &issued, true);
        assert_eq!(code, 0, "{}: {text}", b.name);
        assert!(text.contains("signature valid"), "{text}");
        let (code, text) = verify(&mut r, &issued, false);
        assert_eq!(code, 5, "{}: {text}", b.name);
        assert!(text.contains("NOT CHECKED"), "{text}");
        // An edited file of the issued folder is named.
        let edited = dir.path().join("edited");
        r.ok(&["store", "report", &id1, "--out", edited.to_str().unwrap()], None, None);
        let summary = edited.join("summary.csv");
        let t = std::fs::read_to_string(&summary).unwrap().replacen("FAIL", "PASS", 1);
        std::fs::write(&summary, &t).unwrap();
        let (code, text) = verify(&mut r, &edited, true);
        assert_eq!(code, 3, "{}: {text}", b.name);
        assert!(text.contains("CHANGED") && text.contains("summary.csv"), "{text}");
        // ... and so is the manifest rewritten with it: the signature no longer verifies.
        let mut m = json(&edited.join("manifest.json"));
        for f in m["files"].as_array_mut().unwrap() {
            if f["name"] == "summary.csv" {
                f["sha256"] = gyrolab_io::input_file::sha256_hex(t.as_bytes()).into();
                f["size_bytes"] = t.len().into();
            }
        }
        std::fs::write(edited.join("manifest.json"), serde_json::to_string_pretty(&m).unwrap() + "\n").unwrap();
        let (code, text) = verify(&mut r, &edited, true);
        assert_eq!(code, 3, "{}: {text}", b.name);
        assert!(text.contains("manifest.json: the signature does NOT verify"), "{text}");
        assert!(!text.contains("CHANGED   output    summary.csv"), "the files match the rewritten manifest");

        // No correction of an issued evaluation but a new revision, issued only as an amendment.
        let fixed = r.ok(
            &["store", "revise", &id1, "--kind", "correction", "--serial", "SN-1B", "--reason", "serial misread"],
            op,
            None,
        );
        let id4 = fixed.split_whitespace().nth(7).unwrap().to_string();
        // Its report drawn again with the corrected serial (issue 53: the body showed the old one).
        assert!(fixed.contains("drawn again with the corrected fields"), "{}: {fixed}", b.name);
        let (code, _, err) = r.run(&args(&issue(&id4)), appr, None);
        assert_eq!(code, 2, "{}: {err}", b.name);
        assert!(err.contains("amendment"), "{}: {err}", b.name);
        let said = r.ok(&["store", "amend", &id1, "--reason", "serial corrected", "--signing-key", k], appr, None);
        assert!(said.contains(&format!("amendment 1 to report {number}")), "{}: {said}", b.name);
        let amended = dir.path().join("amended");
        r.ok(&["store", "report", &id4, "--out", amended.to_str().unwrap()], None, None);
        let a = json(&amended.join("issue.json"));
        assert_eq!(a["amendment"]["replaces_report"], number.as_str());
        assert_eq!(a["amendment"]["title"], format!("Amendment 1 to report {number}").as_str());
        assert!(a["amendment"]["changes"].to_string().contains("SN-1 -> SN-1B"), "{a}");
        assert_eq!(json(&amended.join("results.json"))["device"]["serial"], "SN-1B", "{}", b.name);
        let html = std::fs::read_to_string(amended.join("report.html")).unwrap();
        assert!(html.contains("SN-1B") && !html.contains(">SN-1<"), "{}: the body names the corrected serial", b.name);
        let summary = |d: &std::path::Path| std::fs::read_to_string(d.join("summary.csv")).unwrap();
        let new_number = a["report_number"].as_str().unwrap().to_string();
        assert_ne!(new_number, number);
        assert_eq!(verify(&mut r, &amended, true).0, 0);
        // The replaced report stays retrievable, marked superseded, its folder re-signed.
        let old = dir.path().join("old");
        r.ok(&["store", "report", &id1, "--out", old.to_str().unwrap()], None, None);
        let o = json(&old.join("issue.json"));
        assert_eq!(
            (o["status"].as_str(), o["superseded_by"]["report_number"].as_str()),
            (Some("superseded"), Some(new_number.as_str()))
        );
        assert_eq!(verify(&mut r, &old, true).0, 0, "{}", b.name);
        assert_eq!(summary(&old), summary(&amended), "{}: the figures of the corrected report unchanged", b.name);
        let show = r.ok(&["store", "show", &id1], None, None);
        assert!(show.contains(&format!("SUPERSEDED by report {new_number}")), "{}: {show}", b.name);
        let history = r.ok(&["store", "history", "SN-1", "--csv"], None, None);
        assert!(history.contains(&format!("SUPERSEDED {number} by {new_number}")), "{}", b.name);
        let check = r.ok(&["store", "check"], None, None);
        assert!(check.contains("whole"), "{}: {check}", b.name);

        // A re-evaluation of the amended report, amended in turn: "Amendment 2 to report <the first
        // amendment>"; an approver's approval revision does not make the approver its author.
        let re = dir.path().join("re");
        let said =
            r.ok(&["store", "reevaluate", &id4, "--out", re.to_str().unwrap(), "--reason", "new version"], op, None);
        let id5 =
            said.split("evaluation ").nth(2).unwrap().split(|c: char| !c.is_ascii_digit()).next().unwrap().to_string();
        r.ok(&["store", "amend", &id5, "--reason", "re-evaluated", "--signing-key", k], appr2, None);
        let second = dir.path().join("second");
        r.ok(&["store", "report", &id5, "--out", second.to_str().unwrap()], None, None);
        let a2 = json(&second.join("issue.json"));
        assert_eq!(a2["amendment"]["number"], 2, "{}: {a2}", b.name);
        assert_eq!(a2["amendment"]["replaces_report"], new_number.as_str());
        assert_eq!(verify(&mut r, &second, true).0, 0, "{}", b.name);
        let (code, _, err) = r.run(&["store", "amend", &id1, "--reason", "again", "--signing-key", k], appr, None);
        assert_eq!(code, 2, "{}: nothing left to amend without a new revision: {err}", b.name);

        // A disabled account cannot authenticate (the same message).
        r.ok(&["store", "user", "disable", "appr2"], Some(("admin", ADMIN_PW)), None);
        let (code, _, err) = r.run(&args(&issue(&id3)), appr2, None);
        assert_eq!(code, 2);
        assert!(err.contains(&messages[0]), "{}: {err}", b.name);
        r.no_password_anywhere();
    }
}

/// A chain link recomputed from `from` to the head (what a database administrator can do).
fn rechain(x: &mut dyn gyrolab_store::db::Exec, from: i64) {
    use gyrolab_store::chain::{self, CHAINED};
    use gyrolab_store::db::{Kind, Val};
    let links = x
        .query(
            "SELECT seq, tbl, row_id FROM chain WHERE seq >= $1 ORDER BY seq",
            &[Val::I(from)],
            &[Kind::I, Kind::T, Kind::I],
        )
        .unwrap();
    for l in links {
        let (seq, tbl, id) = (l[0].int(), l[1].string(), l[2].int());
        let t = CHAINED.iter().find(|t| t.name == tbl).unwrap();
        let cols: Vec<&str> = t.columns.iter().map(|c| c.0).collect();
        let kinds: Vec<Kind> = t.columns.iter().map(|c| c.1).collect();
        let row = x
            .query(&format!("SELECT {} FROM {} WHERE id = $1", cols.join(", "), t.name), &[Val::I(id)], &kinds)
            .unwrap()
            .remove(0);
        let prev = x.query("SELECT hash FROM chain WHERE seq = $1", &[Val::I(seq - 1)], &[Kind::T]).unwrap();
        let mut p = [0u8; 32];
        if let Some(h) = prev.first() {
            let h = h[0].string();
            for (i, o) in p.iter_mut().enumerate() {
                *o = u8::from_str_radix(&h[2 * i..2 * i + 2], 16).unwrap();
            }
        }
        let hash = chain::hex(&chain::link_hash(&p, seq, &chain::row_digest(t, &row)));
        x.exec(
            "UPDATE chain SET hash = $1, fields = $2 WHERE seq = $3",
            &[Val::T(Some(hash)), Val::T(Some(chain::field_digests(t, &row))), Val::I(seq)],
        )
        .unwrap();
    }
}

#[test]
fn a_database_administrator_rewriting_an_issued_report_is_caught_by_the_signature() {
    use gyrolab_store::db::{Exec, Kind, Val};
    for b in backends("cli_forgery") {
        let dir = tempfile::tempdir().unwrap();
        let mut r = Run::new(&b.location);
        let (key, public) = lab(&mut r, dir.path());
        let plan1 = plan(dir.path(), "p1.toml", "SN-F");
        let (_, err) = eval(&mut r, &plan1, &dir.path().join("r1"), Some(("op", OPER_PW)));
        let id = stored_id(&err);
        r.ok(
            &["store", "issue", &id, "--meaning", "approved", "--signing-key", key.to_str().unwrap()],
            Some(("appr", APPR_PW)),
            None,
        );
        // The administrator: summary.csv's stored bytes and hash rewritten (FAIL -> PASS), the
        // issue's manifest rewritten with them and signed with a key of their own, recorded in
        // place of the lab's; triggers off, every chain link from the first changed row on
        // recomputed, triggers back on.
        let forger = gyrolab_store::sign::SigningKey::from_bytes(&[7u8; 32]);
        let forged_pub = forger.verifying_key();
        let tables = ["report_file", "issue", "signing_key", "chain"];
        let postgres = b.name == "postgres";
        let triggers: Vec<(String, String, String)> = gyrolab_store::chain::expected_triggers(postgres)
            .into_iter()
            .filter(|(t, _, _)| tables.contains(&t.as_str()))
            .collect();
        let (mut off, mut on) = (String::new(), String::new());
        for (t, n, create) in &triggers {
            if postgres {
                off.push_str(&format!("ALTER TABLE {t} DISABLE TRIGGER {n};"));
                on.push_str(&format!("ALTER TABLE {t} ENABLE TRIGGER {n};"));
            } else {
                off.push_str(&format!("DROP TRIGGER {n};"));
                on.push_str(&format!("{create};"));
            }
        }
        // Stage 1: summary.csv's row alone; stage 2: the issue and the key too.
        let forge = |x: &mut dyn Exec, stage: u8| {
            x.batch(&off).unwrap();
            let eid: i64 = id.parse().unwrap();
            let f = x
                .query(
                    "SELECT id, content_zstd FROM report_file WHERE evaluation_id = $1 AND name = 'summary.csv'",
                    &[Val::I(eid)],
                    &[Kind::I, Kind::B],
                )
                .unwrap()
                .remove(0);
            let bytes = zstd::stream::decode_all(f[1].bytes().unwrap()).unwrap();
            let forged = String::from_utf8(bytes).unwrap().replace("FAIL", "PASS");
            let sha = gyrolab_io::input_file::sha256_hex(forged.as_bytes());
            if stage == 1 {
                x.exec(
                    "UPDATE report_file SET content_zstd = $1, sha256 = $2, size_bytes = $3 WHERE id = $4",
                    &[
                        Val::B(Some(zstd::bulk::compress(forged.as_bytes(), 3).unwrap())),
                        Val::T(Some(sha.clone())),
                        Val::I(forged.len() as i64),
                        Val::I(f[0].int()),
                    ],
                )
                .unwrap();
                let first = x
                    .query(
                        "SELECT seq FROM chain WHERE tbl = 'report_file' AND row_id = $1",
                        &[Val::I(f[0].int())],
                        &[Kind::I],
                    )
                    .unwrap()[0][0]
                    .int();
                rechain(x, first);
                x.batch(&on).unwrap();
                return;
            }
            let manifest = x
                .query("SELECT manifest FROM issue WHERE evaluation_id = $1", &[Val::I(eid)], &[Kind::T])
                .unwrap()[0][0]
                .string();
            let mut m: serde_json::Value = serde_json::from_str(&manifest).unwrap();
            for e in m["files"].as_array_mut().unwrap() {
                if e["name"] == "summary.csv" {
                    e["sha256"] = sha.clone().into();
                    e["size_bytes"] = forged.len().into();
                }
            }
            let manifest = serde_json::to_string_pretty(&m).unwrap() + "\n";
            let signature = gyrolab_store::sign::sign_manifest(&forger, manifest.as_bytes());
            let fp = gyrolab_store::sign::fingerprint(&forged_pub);
            x.exec(
                "UPDATE issue SET manifest = $1, signature = $2, key_fingerprint = $3 WHERE evaluation_id = $4",
                &[Val::T(Some(manifest)), Val::T(Some(signature)), Val::T(Some(fp.clone())), Val::I(eid)],
            )
            .unwrap();
            x.exec(
                "UPDATE signing_key SET public_key = $1, fingerprint = $2",
                &[Val::T(Some(gyrolab_store::sign::public_hex(&forged_pub))), Val::T(Some(fp))],
            )
            .unwrap();
            let first = x
                .query(
                    "SELECT MIN(seq) FROM chain WHERE (tbl = 'report_file' AND row_id = $1) OR tbl = 'signing_key'",
                    &[Val::I(f[0].int())],
                    &[Kind::I],
                )
                .unwrap()[0][0]
                .int();
            rechain(x, first);
            x.batch(&on).unwrap();
        };
        let run = |stage: u8| {
            if postgres {
                let mut c = postgres::Client::connect(&b.location, postgres::NoTls).unwrap();
                let mut st = Default::default();
                forge(&mut gyrolab_store::db::PgExec(&mut c, &mut st), stage);
            } else {
                let c = rusqlite::Connection::open(&b.location).unwrap();
                forge(&mut gyrolab_store::db::SqliteExec(&c), stage);
            }
        };
        // The file's row alone, its chain recomputed: the store check is whole, but `store report`
        // refuses the folder, naming the file against the signed manifest.
        run(1);
        let check = r.ok(&["store", "check"], None, None);
        assert!(check.contains("whole"), "{}: {check}", b.name);
        let half = dir.path().join("half");
        let (code, _, err) = r.run(&["store", "report", &id, "--out", half.to_str().unwrap()], None, None);
        assert_eq!(code, 2, "{}: {err}", b.name);
        assert!(err.contains("summary.csv differs from its signed manifest"), "{}: {err}", b.name);
        assert!(!half.exists(), "{}: nothing written", b.name);
        run(2);
        // The store is whole again, with another head; its report folder is consistent.
        let check = r.ok(&["store", "check"], None, None);
        assert!(check.contains("whole"), "{}: {check}", b.name);
        let out = dir.path().join("forged");
        r.ok(&["store", "report", &id, "--out", out.to_str().unwrap()], None, None);
        assert!(std::fs::read_to_string(out.join("summary.csv")).unwrap().contains("PASS"));
        let o = Command::cargo_bin("gyrolab")
            .unwrap()
            .args(["verify", out.to_str().unwrap(), "--public-key", public.to_str().unwrap()])
            .output()
            .unwrap();
        let text = format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
        assert_eq!(o.status.code(), Some(3), "{}: {text}", b.name);
        assert!(text.contains("does NOT verify") && text.contains("manifest.json"), "{}: {text}", b.name);
        r.no_password_anywhere();
    }
}
