//! `gyrolab store ...`: the records store (crate gyrolab-store, docs/STORE.md): add report
//! folders, show one evaluation, the history of a serial (table, JSON, CSV, SVG trend plot), lot
//! statistics, lot comparison, control charts, revisions (correction, approval) and
//! re-evaluation. Arguments to requests and printing only.

use crate::args::{prompt_password, stdin_line, AuthArgs, QueryOutput, StoreLocation};
use crate::error::{CliError, CliResult};
use crate::output::{print, to_json, write_file};
use clap::{Args, Subcommand, ValueEnum};
use gyrolab_lab::issue::Issue;
use gyrolab_lab::records::{
    accounts_text, chart_notes, chart_table, check_text, compare_table, evaluation_json, evaluation_text,
    history_table, lot_table, lot_text, reevaluation_text, revision_author,
};
use gyrolab_lab::reevaluate;
use gyrolab_report::table::{to_csv, to_parquet, to_text, Table};
use gyrolab_store::issue::Meaning;
use gyrolab_store::{query, resolve_location, sign, Actor, Changes, Revision, RevisionKind, Role, Store};
use std::path::PathBuf;

/// Kinds of manual revision.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum ReviseKind {
    /// Correct recorded facts (serial, model, lot, operator, test date).
    Correction,
    /// Approve the evaluation (--by is the approver).
    Approval,
}

/// `gyrolab store` subcommands.
#[derive(Debug, Subcommand)]
pub enum StoreCommand {
    /// Store finished report folders (results.json, summary.csv; the plan they name and its inputs are hashed).
    Add(AddArgs),
    /// One stored evaluation: device, plan hash, inputs, revisions, figures.
    Show(ShowArgs),
    /// Write a stored evaluation's report folder back, every file checked against its SHA-256.
    Report(ReportArgs),
    /// Every figure of a serial over time and revisions, with limits (`--plot` SVG trend plot).
    History(HistoryArgs),
    /// Lot statistics per figure: n of n_devices, bounds and devices not evaluated counted apart, mean,
    /// sd, min, max, yield, Cp/Cpk, Pp/Ppk with intervals, outliers, notes.
    Lot(LotArgs),
    /// Compare two lots per figure: Welch's t-test of the means, F-test of the spreads.
    Compare(CompareArgs),
    /// Control charts of one figure: individuals/moving range and X-bar/S over lots, Nelson rules.
    Chart(ChartArgs),
    /// Store a correction or an approval as a new revision of an evaluation.
    Revise(ReviseArgs),
    /// Re-run a stored evaluation's plan and inputs (where they are when unchanged, else the store's copies) under this version: new revision and diff.
    Reevaluate(ReevaluateArgs),
    /// Re-verify the store: its hash chain link by link against the rows, every stored file against its SHA-256, the protecting triggers (exit 3 when broken).
    Check(CheckArgs),
    /// PostgreSQL, run as the owner: give ROLE SELECT and INSERT only, to run gyrolab as (least privilege).
    Grant(GrantArgs),
    /// Accounts: add, list, disable, reset a password (the first account is an admin; then an admin manages them).
    #[command(subcommand)]
    User(UserCommand),
    /// The lab's Ed25519 signing key: `key init --out lab.key` makes one and records its public key.
    #[command(subcommand)]
    Key(KeyCommand),
    /// Issue a draft evaluation: report number, issue date, signature (an approver who did not store it), signed manifest.
    Issue(IssueArgs),
    /// Issue a later revision of an issued evaluation as "Amendment N to report R"; the replaced report is marked superseded.
    Amend(AmendArgs),
}

/// Meanings of an issuing signature.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum MeaningArg {
    /// The signer approves the results for issue.
    Approved,
    /// The signer reviewed the report.
    Reviewed,
}

/// Roles of an account.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum RoleArg {
    /// Reads only.
    Viewer,
    /// Stores evaluations, corrections and re-evaluations.
    Operator,
    /// Also issues and amends reports (never their own work).
    Approver,
    /// Manages accounts and the lab key.
    Admin,
}

/// `gyrolab store user` subcommands.
#[derive(Debug, Subcommand)]
pub enum UserCommand {
    /// Add an account (the store's first must be an admin and needs no authentication).
    Add(UserAddArgs),
    /// List the accounts: name, display name, role, disabled, created.
    List(UserListArgs),
    /// Disable an account (an admin): it can no longer authenticate.
    Disable(UserNameArgs),
    /// Set a new password of an account (an admin).
    Reset(UserNameArgs),
}

/// The authenticating admin of a user command: `--user` (or GYROLAB_USER), the password from
/// GYROLAB_PASSWORD or a prompt (standard input carries the new password).
#[derive(Debug, Args)]
pub struct AdminArgs {
    /// The admin making the change (default: GYROLAB_USER); password from GYROLAB_PASSWORD or a prompt.
    #[arg(long = "user", value_name = "NAME")]
    pub user: Option<String>,
}

/// Options of `gyrolab store user add`.
#[derive(Debug, Args)]
pub struct UserAddArgs {
    /// Login name (letters, digits, . _ - @).
    pub name: String,
    /// Role.
    #[arg(long, value_enum)]
    pub role: RoleArg,
    /// Name printed on reports and signatures (default: the login name).
    #[arg(long, value_name = "TEXT")]
    pub display_name: Option<String>,
    /// Read the new account's password from the first line of standard input (else
    /// GYROLAB_NEW_PASSWORD, else a prompt, twice).
    #[arg(long)]
    pub password_stdin: bool,
    #[command(flatten)]
    pub admin: AdminArgs,
    #[command(flatten)]
    pub location: StoreLocation,
}

/// Options of `gyrolab store user disable` and `reset`.
#[derive(Debug, Args)]
pub struct UserNameArgs {
    /// The account.
    pub name: String,
    /// `reset`: read the new password from the first line of standard input (else
    /// GYROLAB_NEW_PASSWORD, else a prompt, twice).
    #[arg(long)]
    pub password_stdin: bool,
    #[command(flatten)]
    pub admin: AdminArgs,
    #[command(flatten)]
    pub location: StoreLocation,
}

/// Options of `gyrolab store user list`.
#[derive(Debug, Args)]
pub struct UserListArgs {
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub location: StoreLocation,
}

/// `gyrolab store key` subcommands.
#[derive(Debug, Subcommand)]
pub enum KeyCommand {
    /// Make the lab's Ed25519 key pair: the private key in --out (mode 0600, never overwritten), the public key beside it (.pub), recorded in the store.
    Init(KeyInitArgs),
}

/// Options of `gyrolab store key init`.
#[derive(Debug, Args)]
pub struct KeyInitArgs {
    /// The private key file to write (the public key goes beside it, `.pub`).
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
    #[command(flatten)]
    pub auth: AuthArgs,
    #[command(flatten)]
    pub location: StoreLocation,
}

/// Options of `gyrolab store issue`.
#[derive(Debug, Args)]
pub struct IssueArgs {
    /// The evaluation to issue (a current, never issued revision).
    pub id: i64,
    /// The meaning of the signature.
    #[arg(long, value_enum)]
    pub meaning: MeaningArg,
    #[command(flatten)]
    pub signing: SigningArgs,
}

/// Options of `gyrolab store amend`.
#[derive(Debug, Args)]
pub struct AmendArgs {
    /// The issued evaluation (its current revision is issued) or that later revision.
    pub id: i64,
    /// Why the report is amended (printed in the amendment).
    #[arg(long, value_name = "TEXT")]
    pub reason: String,
    /// The meaning of the signature.
    #[arg(long, value_enum, default_value = "approved")]
    pub meaning: MeaningArg,
    #[command(flatten)]
    pub signing: SigningArgs,
}

/// What `store issue` and `store amend` share: the key, the number, who signs, the store.
#[derive(Debug, Args)]
pub struct SigningArgs {
    /// The lab's private key file (`gyrolab store key init`).
    #[arg(long, value_name = "FILE")]
    pub signing_key: PathBuf,
    /// The report number (default: the store's next GL-YYYY-NNNN); unique in the store.
    #[arg(long, value_name = "TEXT")]
    pub report_number: Option<String>,
    #[command(flatten)]
    pub auth: AuthArgs,
    #[command(flatten)]
    pub location: StoreLocation,
}

/// Options of `gyrolab store check`.
#[derive(Debug, Args)]
pub struct CheckArgs {
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub location: StoreLocation,
}

/// Options of `gyrolab store grant`.
#[derive(Debug, Args)]
pub struct GrantArgs {
    /// The PostgreSQL role (an existing login role) gyrolab will run as.
    pub role: String,
    #[command(flatten)]
    pub location: StoreLocation,
}

/// Options of `gyrolab store add`.
#[derive(Debug, Args)]
pub struct AddArgs {
    /// Report folders written by `gyrolab eval`.
    #[arg(value_name = "DIR", required = true)]
    pub dirs: Vec<PathBuf>,
    /// The plan of the folders (default: the plan_file each results.json names).
    #[arg(long, value_name = "PLAN.toml")]
    pub plan: Option<PathBuf>,
    #[command(flatten)]
    pub auth: AuthArgs,
    #[command(flatten)]
    pub location: StoreLocation,
}

/// Options of `gyrolab store show`.
#[derive(Debug, Args)]
pub struct ShowArgs {
    /// Evaluation id.
    pub id: i64,
    /// Print JSON (with the plan text and results.json).
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub location: StoreLocation,
}

/// Options of `gyrolab store history`.
#[derive(Debug, Args)]
pub struct HistoryArgs {
    /// Serial number.
    pub serial: String,
    /// Only this figure key.
    #[arg(long, value_name = "KEY")]
    pub figure: Option<String>,
    /// Also write an SVG trend plot (one panel per axis and figure, limits as lines).
    #[arg(long = "plot", visible_alias = "svg", value_name = "FILE.svg")]
    pub svg: Option<PathBuf>,
    #[command(flatten)]
    pub format: QueryOutput,
    #[command(flatten)]
    pub location: StoreLocation,
}

/// Options of `gyrolab store lot`.
#[derive(Debug, Args)]
pub struct LotArgs {
    /// Lot name.
    pub lot: String,
    /// Confidence level of the capability intervals.
    #[arg(long, default_value_t = 0.95)]
    pub confidence: f64,
    #[command(flatten)]
    pub format: QueryOutput,
    #[command(flatten)]
    pub location: StoreLocation,
}

/// Options of `gyrolab store compare`.
#[derive(Debug, Args)]
pub struct CompareArgs {
    /// First lot.
    pub lot1: String,
    /// Second lot.
    pub lot2: String,
    #[command(flatten)]
    pub format: QueryOutput,
    #[command(flatten)]
    pub location: StoreLocation,
}

/// Options of `gyrolab store chart`.
#[derive(Debug, Args)]
pub struct ChartArgs {
    /// Figure key.
    #[arg(long, value_name = "KEY")]
    pub figure: String,
    /// Axis name.
    #[arg(long, value_name = "AXIS")]
    pub axis: String,
    /// Individuals chart over this lot only (default: every device).
    #[arg(long, value_name = "LOT")]
    pub lot: Option<String>,
    #[command(flatten)]
    pub format: QueryOutput,
    #[command(flatten)]
    pub location: StoreLocation,
}

/// Options of `gyrolab store revise`.
#[derive(Debug, Args)]
pub struct ReviseArgs {
    /// The evaluation to supersede (a current revision).
    pub id: i64,
    /// correction or approval.
    #[arg(long, value_enum)]
    pub kind: ReviseKind,
    /// Who makes the revision (the approver of an approval); with --user, the account (default).
    #[arg(long, value_name = "NAME")]
    pub by: Option<String>,
    /// Why.
    #[arg(long, value_name = "TEXT")]
    pub reason: String,
    #[command(flatten)]
    pub auth: AuthArgs,
    /// Corrected serial.
    #[arg(long)]
    pub serial: Option<String>,
    /// Corrected model.
    #[arg(long)]
    pub model: Option<String>,
    /// Corrected lot.
    #[arg(long)]
    pub lot: Option<String>,
    /// Corrected operator.
    #[arg(long)]
    pub operator: Option<String>,
    /// Corrected test date.
    #[arg(long)]
    pub test_date: Option<String>,
    #[command(flatten)]
    pub location: StoreLocation,
}

/// Options of `gyrolab store report`.
#[derive(Debug, Args)]
pub struct ReportArgs {
    /// Evaluation id.
    pub id: i64,
    /// Folder to write the report files into (all of them or none).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Write the evaluation's plan and raw records instead, as the store keeps them, laid out as
    /// they stood relative to the plan (a new folder; each checked against its SHA-256).
    #[arg(long)]
    pub inputs: bool,
    #[command(flatten)]
    pub location: StoreLocation,
}

/// Options of `gyrolab store reevaluate`.
#[derive(Debug, Args)]
pub struct ReevaluateArgs {
    /// The evaluation to re-run (a current revision).
    pub id: i64,
    /// Folder for the new report.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Who re-evaluates; with --user, the account (default).
    #[arg(long, value_name = "NAME")]
    pub by: Option<String>,
    #[command(flatten)]
    pub auth: AuthArgs,
    /// Why.
    #[arg(long, value_name = "TEXT")]
    pub reason: String,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub location: StoreLocation,
}

fn open(location: &StoreLocation, create: bool) -> CliResult<Store> {
    Ok(Store::open(&resolve_location(location.store.as_deref()), create)?)
}

/// Opens a store to write to: the quick check first (exit 2 when it fails).
fn open_for_writing(location: &StoreLocation) -> CliResult<Store> {
    Ok(Store::open_for_writing(&resolve_location(location.store.as_deref()), false)?)
}

/// The actor of a write: the account `auth` names, authenticated, else no account (which a
/// store with accounts refuses).
fn actor(s: &mut Store, auth: &AuthArgs) -> CliResult<Actor> {
    Ok(match auth.credentials(true)? {
        Some((user, password)) => s.authenticate(&user, &password)?,
        None => Actor::unauthenticated(),
    })
}

fn meaning(m: MeaningArg) -> Meaning {
    match m {
        MeaningArg::Approved => Meaning::Approved,
        MeaningArg::Reviewed => Meaning::Reviewed,
    }
}

fn read_key(path: &std::path::Path) -> CliResult<gyrolab_store::sign::SigningKey> {
    sign::read_signing_key(path).map_err(CliError::Usage)
}

/// `gyrolab store issue` and `amend`.
/// `store issue` (no reason) or `store amend` (its reason) of evaluation `id`.
fn signed(id: i64, m: MeaningArg, amend_reason: Option<&str>, a: &SigningArgs) -> CliResult {
    let req = Issue {
        evaluation: id,
        meaning: meaning(m),
        key: &read_key(&a.signing_key)?,
        report_number: a.report_number.as_deref(),
        amend_reason,
    };
    issue(&a.location, &a.auth, &req)
}

fn issue(location: &StoreLocation, auth: &AuthArgs, req: &Issue) -> CliResult {
    let mut s = open_for_writing(location)?;
    let Some((user, password)) = auth.credentials(true)? else {
        return Err(CliError::Usage(
            "issuing needs an approver's account: --user NAME (or GYROLAB_USER) with its password (GYROLAB_PASSWORD, \
             --password-stdin or a prompt)"
                .into(),
        ));
    };
    let actor = s.authenticate(&user, &password)?;
    let r = gyrolab_lab::issue::issue(&mut s, &actor, req)?;
    print(&gyrolab_lab::issue::issued_text(&r))
}

/// The new password of `store user add` and `reset`: standard input, GYROLAB_NEW_PASSWORD, or
/// typed twice at the terminal.
fn new_password(from_stdin: bool, name: &str) -> CliResult<String> {
    if from_stdin {
        return stdin_line();
    }
    if let Ok(p) = std::env::var("GYROLAB_NEW_PASSWORD") {
        return Ok(p);
    }
    let alternatives = "--password-stdin or GYROLAB_NEW_PASSWORD";
    let first = prompt_password(&format!("New password of {name}: "), alternatives)?;
    let second = prompt_password("The same again: ", alternatives)?;
    if first != second {
        return Err(CliError::Usage("the two passwords typed differ; nothing was changed".into()));
    }
    Ok(first)
}

/// The admin of a user or key command, authenticated (the password from GYROLAB_PASSWORD or a
/// prompt); no account when none is named.
fn admin(s: &mut Store, a: &AdminArgs) -> CliResult<Actor> {
    let auth = AuthArgs { user: a.user.clone(), password_stdin: false };
    Ok(match auth.credentials(false)? {
        Some((user, password)) => s.authenticate(&user, &password)?,
        None => Actor::unauthenticated(),
    })
}

fn user(cmd: &UserCommand) -> CliResult {
    match cmd {
        UserCommand::Add(a) => {
            let mut s = Store::open_for_writing(&resolve_location(a.location.store.as_deref()), true)?;
            let actor = admin(&mut s, &a.admin)?;
            let password = new_password(a.password_stdin, &a.name)?;
            let role = match a.role {
                RoleArg::Viewer => Role::Viewer,
                RoleArg::Operator => Role::Operator,
                RoleArg::Approver => Role::Approver,
                RoleArg::Admin => Role::Admin,
            };
            let display = a.display_name.as_deref().unwrap_or(&a.name);
            print(&gyrolab_lab::records::add_account(&mut s, &actor, &a.name, display, role, &password)?)
        }
        UserCommand::List(a) => {
            let mut s = open(&a.location, false)?;
            let accounts = s.accounts()?;
            if a.json {
                return print(&to_json(&accounts)?);
            }
            print(&accounts_text(&accounts))
        }
        UserCommand::Disable(a) => {
            let mut s = open_for_writing(&a.location)?;
            let actor = admin(&mut s, &a.admin)?;
            print(&gyrolab_lab::records::disable_account(&mut s, &actor, &a.name)?)
        }
        UserCommand::Reset(a) => {
            let mut s = open_for_writing(&a.location)?;
            let actor = admin(&mut s, &a.admin)?;
            let password = new_password(a.password_stdin, &a.name)?;
            print(&gyrolab_lab::records::reset_password(&mut s, &actor, &a.name, &password)?)
        }
    }
}

/// `gyrolab store key init`: the actor checked before any file is written.
fn key_init(a: &KeyInitArgs) -> CliResult {
    let mut s = Store::open_for_writing(&resolve_location(a.location.store.as_deref()), true)?;
    let actor = actor(&mut s, &a.auth)?;
    print(&gyrolab_lab::issue::init_key(&mut s, &actor, &a.out)?)
}

/// Runs `gyrolab store`.
pub fn run(cmd: &StoreCommand) -> CliResult {
    match cmd {
        StoreCommand::Add(a) => {
            let credentials = a.auth.credentials(true)?;
            let credentials = credentials.as_ref().map(|(u, p)| (u.as_str(), p.as_str()));
            print(&gyrolab_lab::records::add_folders(
                &a.dirs,
                a.plan.as_deref(),
                a.location.store.as_deref(),
                credentials,
            )?)
        }
        StoreCommand::Show(a) => {
            let mut s = open(&a.location, false)?;
            let e = s.evaluation(a.id)?;
            let issued = s.issue_of(a.id)?;
            let events = s.audit_events(Some(a.id))?;
            if a.json {
                let v = evaluation_json(&e, issued.as_ref(), &events).map_err(|e| CliError::Output(e.to_string()))?;
                return print(&to_json(&v)?);
            }
            print(&evaluation_text(&e, issued.as_ref(), &events))
        }
        StoreCommand::Report(a) => {
            let mut s = open(&a.location, false)?;
            if a.inputs {
                return print(&gyrolab_lab::raw_records::restored_text(&mut s, a.id, &a.out)?);
            }
            let written = s.write_report(a.id, &a.out)?;
            print(&gyrolab_lab::records::written_report_text(&mut s, a.id, written.len(), &a.out)?)
        }
        StoreCommand::History(a) => history(a),
        StoreCommand::Lot(a) => {
            if !(a.confidence > 0.0 && a.confidence < 1.0) {
                return Err(CliError::Usage(format!("--confidence {}: must be between 0 and 1", a.confidence)));
            }
            let mut s = open(&a.location, false)?;
            let rows = query::lot(&mut s, &a.lot, a.confidence)?;
            emit(&lot_table(&rows), &a.format, || to_json(&rows), Some(lot_text(&rows)))
        }
        StoreCommand::Compare(a) => {
            let mut s = open(&a.location, false)?;
            let rows = query::compare(&mut s, &a.lot1, &a.lot2)?;
            emit(&compare_table(&rows), &a.format, || to_json(&rows), None)
        }
        StoreCommand::Chart(a) => {
            let mut s = open(&a.location, false)?;
            let c = query::control_charts(&mut s, a.lot.as_deref(), &a.axis, &a.figure)?;
            if !a.format.json {
                chart_notes(&c).iter().for_each(|n| eprintln!("note: {n}"));
            }
            emit(&chart_table(&c), &a.format, || to_json(&c), None)
        }
        StoreCommand::Revise(a) => {
            let mut s = open_for_writing(&a.location)?;
            let kind = match a.kind {
                ReviseKind::Correction => RevisionKind::Correction,
                ReviseKind::Approval => RevisionKind::Approval,
            };
            let changes = Changes {
                serial: a.serial.clone(),
                model: a.model.clone(),
                lot: a.lot.clone(),
                operator: a.operator.clone(),
                approver: None,
                test_date: a.test_date.clone(),
            };
            let actor = actor(&mut s, &a.auth)?;
            let by = revision_author(&actor, a.by.as_deref()).map_err(CliError::Usage)?;
            let r = Revision { supersedes: a.id, kind, by, reason: a.reason.clone() };
            print(&gyrolab_lab::records::revise(&mut s, &r, &changes, &actor)?)
        }
        StoreCommand::Check(a) => check(a),
        StoreCommand::Grant(a) => print(&gyrolab_lab::issue::grant_text(&mut open(&a.location, false)?, &a.role)?),
        StoreCommand::User(u) => user(u),
        StoreCommand::Key(KeyCommand::Init(a)) => key_init(a),
        StoreCommand::Issue(a) => signed(a.id, a.meaning, None, &a.signing),
        StoreCommand::Amend(a) => signed(a.id, a.meaning, Some(&a.reason), &a.signing),
        StoreCommand::Reevaluate(a) => {
            let mut s = open_for_writing(&a.location)?;
            let actor = actor(&mut s, &a.auth)?;
            let who = revision_author(&actor, a.by.as_deref()).map_err(CliError::Usage)?;
            let r = reevaluate::reevaluate_as(&mut s, a.id, &who, &a.reason, &a.out, &actor)?;
            let note = gyrolab_lab::records::draft_note(&mut s, a.id, r.revision)?;
            if !note.is_empty() {
                eprint!("{note}");
            }
            if a.json {
                return print(&to_json(&r)?);
            }
            print(&reevaluation_text(&r, &a.out))
        }
    }
}

/// `gyrolab store check`: the report printed; exit 3 naming the first problem when broken.
fn check(a: &CheckArgs) -> CliResult {
    let mut s = open(&a.location, false)?;
    let r = s.check()?;
    print(&if a.json { to_json(&r)? } else { check_text(&r, s.name()) })?;
    // The first broken link (a row named) first, else the first problem (a trigger).
    match r.problems.iter().find(|p| p.row_id.is_some()).or(r.problems.first()) {
        None => Ok(()),
        Some(p) => Err(CliError::Changed(format!(
            "store {}: BROKEN: {} problem(s); the first broken link: {p}",
            s.name(),
            r.problems.len()
        ))),
    }
}

/// Prints a query's table as text (`text`, else the table's), CSV or JSON (`json` makes the
/// JSON), and writes the Parquet file of `--parquet` first (whole or not at all).
fn emit(
    table: &Table,
    output: &QueryOutput,
    json: impl FnOnce() -> CliResult<String>,
    text: Option<String>,
) -> CliResult {
    if let Some(path) = &output.parquet {
        write_file(path, &to_parquet(table).map_err(|e| CliError::Usage(e.to_string()))?, &[])?;
    }
    if output.json {
        print(&json()?)
    } else if output.csv {
        print(&to_csv(table))
    } else {
        print(&text.unwrap_or_else(|| to_text(table)))
    }
}

fn history(a: &HistoryArgs) -> CliResult {
    let mut s = open(&a.location, false)?;
    let rows = gyrolab_lab::records::history(&mut s, &a.serial, a.figure.as_deref())?;
    if let Some(path) = &a.svg {
        let svg = gyrolab_lab::records::history_svg(&a.serial, &rows)
            .map_err(|e| CliError::Output(e.to_string()))?
            .ok_or_else(|| CliError::Usage(format!("serial {:?}: no values to plot", a.serial)))?;
        write_file(path, svg.as_bytes(), &[])?;
    }
    emit(&history_table(&rows), &a.format, || to_json(&rows), None)
}
