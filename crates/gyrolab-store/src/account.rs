//! Accounts, roles and authentication (issue 53; docs/STORE.md "Accounts and attribution").
//!
//! An account (`account` table) has a name, a display name, a role and an Argon2id password hash
//! (PHC string, default parameters, a random salt). Accounts are records like every other: never
//! changed; disabling one or setting a new password is a new `account_change` row. Every write to
//! the store records who made it (an authenticated [`Actor`]) and the database's time in
//! `audit_event`. A store with no account works without authentication (the actor recorded as
//! [`UNAUTHENTICATED`]); once it has one, every write needs an authenticated account.

use crate::db::{returned_id, Columns, DbError, Exec, Kind, Row, Val};
use crate::{chain, StoreError};
use argon2::password_hash::{PasswordHash, PasswordHasher, PasswordVerifier, SaltString};
use argon2::Argon2;

/// The actor recorded for writes to a store that has no account yet.
pub const UNAUTHENTICATED: &str = "local (no accounts in this store)";

/// The one message of every refused authentication: it never says whether the name, the
/// password or the account's state was the reason.
pub const AUTH_FAILED: &str =
    "authentication failed: the user name and password were not accepted (or the account is disabled)";

/// What an account may do.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Role {
    /// Reads only (queries need no account).
    Viewer,
    /// Stores evaluations, corrections and re-evaluations.
    Operator,
    /// As an operator, and issues and amends reports (never their own work).
    Approver,
    /// As an operator, and manages accounts and the lab's public keys.
    Admin,
}

impl Role {
    /// The stored word.
    pub fn as_str(self) -> &'static str {
        match self {
            Role::Viewer => "viewer",
            Role::Operator => "operator",
            Role::Approver => "approver",
            Role::Admin => "admin",
        }
    }

    /// The role of a stored or typed word.
    pub fn parse(s: &str) -> Option<Role> {
        match s {
            "viewer" => Some(Role::Viewer),
            "operator" => Some(Role::Operator),
            "approver" => Some(Role::Approver),
            "admin" => Some(Role::Admin),
            _ => None,
        }
    }

    /// Whether the role may store evaluations and revisions.
    pub fn may_store(self) -> bool {
        !matches!(self, Role::Viewer)
    }
}

/// One account as it stands now (its changes applied).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Account {
    /// Id.
    pub id: i64,
    /// Login name.
    pub name: String,
    /// Name printed on reports and signatures.
    pub display_name: String,
    /// Role.
    pub role: Role,
    /// Disabled accounts cannot authenticate.
    pub disabled: bool,
    /// When it was made (the database's clock).
    pub created_at: String,
    /// Who made it.
    pub created_by: String,
}

/// Who makes a write: an account authenticated by [`crate::Store::authenticate`], or nobody (a
/// store with no account). Made only by the store, so a holder of an `Actor` has authenticated.
/// It is bound to the password hash it was authenticated against: used with another store (whose
/// account of the same name has another salt) or after the password was reset, it is refused.
#[derive(Clone, PartialEq)]
pub struct Actor {
    account: Option<Account>,
    verified_hash: String,
}

impl std::fmt::Debug for Actor {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        // Never the hash.
        f.debug_struct("Actor").field("account", &self.account).finish_non_exhaustive()
    }
}

impl Actor {
    /// No account: accepted only by a store that has none ([`UNAUTHENTICATED`] is recorded).
    pub fn unauthenticated() -> Actor {
        Actor { account: None, verified_hash: String::new() }
    }

    pub(crate) fn of(account: Account, verified_hash: String) -> Actor {
        Actor { account: Some(account), verified_hash }
    }

    /// The authenticated account, if any.
    pub fn account(&self) -> Option<&Account> {
        self.account.as_ref()
    }

    /// The name recorded for it.
    pub fn label(&self) -> String {
        self.account.as_ref().map_or_else(|| UNAUTHENTICATED.to_string(), |a| a.name.clone())
    }
}

/// What a write needs of its actor.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Need {
    /// Store evaluations and revisions: operator, approver or admin (or no account in the store).
    Store,
    /// Issue or amend: an approver, always (also in a store without accounts: there is none).
    Approver,
    /// Manage accounts and keys: an admin (or no account in the store).
    Admin,
}

/// Argon2id (the crate's default parameters) of `password` with a fresh random salt, as a PHC
/// string.
pub fn hash_password(password: &str) -> Result<String, String> {
    let mut salt = [0u8; 16];
    getrandom::getrandom(&mut salt).map_err(|e| format!("no random numbers from the system: {e}"))?;
    let salt = SaltString::encode_b64(&salt).map_err(|e| e.to_string())?;
    Argon2::default().hash_password(password.as_bytes(), &salt).map(|h| h.to_string()).map_err(|e| e.to_string())
}

/// Whether `password` matches the PHC string `hash` (false for a hash that cannot be read).
pub fn verify_password(password: &str, hash: &str) -> bool {
    PasswordHash::new(hash).is_ok_and(|h| Argon2::default().verify_password(password.as_bytes(), &h).is_ok())
}

/// A valid hash of no one's password, verified against when the name is unknown so that an
/// unknown name takes as long to refuse as a wrong password.
fn decoy_hash() -> &'static str {
    static DECOY: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    DECOY.get_or_init(|| hash_password("gyrolab decoy password").unwrap_or_default())
}

/// Checks a new account's name, display name and password.
pub fn check_new(name: &str, display_name: &str, password: &str) -> Result<(), String> {
    if name.is_empty()
        || name.len() > 64
        || !name.chars().all(|c| c.is_ascii_alphanumeric() || matches!(c, '.' | '_' | '-' | '@'))
    {
        return Err(format!("account name {name:?}: expected 1 to 64 letters, digits or . _ - @ (no spaces)"));
    }
    if display_name.trim().is_empty()
        || display_name.chars().count() > 200
        || display_name.chars().any(char::is_control)
    {
        return Err("display name: expected 1 to 200 printable characters".into());
    }
    check_password(password)
}

/// Checks a new password: 8 to 1024 bytes, no NUL.
pub fn check_password(password: &str) -> Result<(), String> {
    if password.len() < 8 {
        return Err("the password is shorter than 8 characters".into());
    }
    if password.len() > 1024 || password.contains('\0') {
        return Err("the password is longer than 1024 bytes or holds a NUL".into());
    }
    Ok(())
}

const ACCOUNT_SQL: &str = "SELECT a.id AS id, a.name AS name, a.display_name AS display_name, a.role AS role, \
     a.created_at AS created_at, a.created_by AS created_by, \
     (SELECT COUNT(*) FROM account_change c WHERE c.account_id = a.id AND c.change = 'disable') AS disables, \
     COALESCE((SELECT c.password_hash FROM account_change c WHERE c.account_id = a.id AND c.change = 'password' \
     ORDER BY c.id DESC LIMIT 1), a.password_hash) AS password_hash FROM account a";

/// The columns of [`ACCOUNT_SQL`].
const ACCOUNT_COLUMNS: Columns<'static> = &[
    ("id", Kind::I),
    ("name", Kind::T),
    ("display_name", Kind::T),
    ("role", Kind::T),
    ("created_at", Kind::T),
    ("created_by", Kind::T),
    ("disables", Kind::I),
    ("password_hash", Kind::T),
];

fn account_of(r: &Row) -> Result<(Account, String), DbError> {
    Ok((
        Account {
            id: r.int("id")?,
            name: r.string("name")?,
            display_name: r.string("display_name")?,
            role: Role::parse(r.text("role")?.unwrap_or_default()).unwrap_or(Role::Viewer),
            created_at: r.string("created_at")?,
            created_by: r.string("created_by")?,
            disabled: r.int("disables")? > 0,
        },
        r.string("password_hash")?,
    ))
}

/// Every account, by id, with its current password hash.
pub(crate) fn accounts(x: &mut dyn Exec) -> Result<Vec<(Account, String)>, DbError> {
    // ok: SQL from the module's constant column list; every value is a parameter.
    let sql = format!("{ACCOUNT_SQL} ORDER BY a.id");
    x.rows(&sql, &[], ACCOUNT_COLUMNS)?.iter().map(account_of).collect()
}

/// The account named `name`, with its current password hash.
pub(crate) fn by_name(x: &mut dyn Exec, name: &str) -> Result<Option<(Account, String)>, DbError> {
    // ok: SQL from the module's constant column list; every value is a parameter.
    let sql = format!("{ACCOUNT_SQL} WHERE a.name = $1");
    x.rows(&sql, &[Val::T(Some(name.to_string()))], ACCOUNT_COLUMNS)?.first().map(account_of).transpose()
}

/// Whether the store has any account.
pub(crate) fn any(x: &mut dyn Exec) -> Result<bool, DbError> {
    Ok(!x.rows("SELECT id FROM account LIMIT 1", &[], &[("id", Kind::I)])?.is_empty())
}

/// Authenticates `name` with `password`: the account and the hash it was verified against, or
/// [`AUTH_FAILED`] whatever was wrong.
pub(crate) fn authenticate(
    x: &mut dyn Exec,
    name: &str,
    password: &str,
) -> Result<Result<(Account, String), ()>, DbError> {
    let found = by_name(x, name)?;
    let ok = match &found {
        Some((_, hash)) => verify_password(password, hash),
        None => {
            let _ = verify_password(password, decoy_hash());
            false
        }
    };
    Ok(match found {
        Some((a, hash)) if ok && !a.disabled => Ok((a, hash)),
        _ => Err(()),
    })
}

/// Checks inside a write's transaction that `actor` may do `need` now (its account still there,
/// not disabled, its role sufficient; no account given only while the store has none): the
/// account's id (none for an unauthenticated write) and the name recorded.
pub(crate) fn check_actor(
    x: &mut dyn Exec,
    store: &str,
    actor: &Actor,
    need: Need,
) -> Result<(Option<i64>, String), StoreError> {
    let dberr = |m: DbError| StoreError::Database { store: store.to_string(), message: m.to_string() };
    let refused = |m: String| StoreError::Refused { store: store.to_string(), message: m };
    match actor.account() {
        None => {
            if need == Need::Approver {
                return Err(refused(
                    "issuing needs an approver's account: add accounts first (gyrolab store user add)".into(),
                ));
            }
            if any(x).map_err(dberr)? {
                return Err(refused(
                    "this store has accounts: every write needs one (--user NAME or GYROLAB_USER, the password from \
                     GYROLAB_PASSWORD, --password-stdin or a prompt)"
                        .into(),
                ));
            }
            Ok((None, UNAUTHENTICATED.to_string()))
        }
        Some(a) => {
            let Some((now, hash)) = by_name(x, &a.name).map_err(dberr)? else {
                return Err(StoreError::Auth { store: store.to_string() });
            };
            if now.id != a.id || now.disabled || hash != actor.verified_hash {
                return Err(StoreError::Auth { store: store.to_string() });
            }
            let allowed = match need {
                Need::Store => now.role.may_store(),
                Need::Approver => now.role == Role::Approver,
                Need::Admin => now.role == Role::Admin,
            };
            if !allowed {
                let what = match need {
                    Need::Store => "store evaluations or revisions (an operator, approver or admin may)",
                    Need::Approver => "issue or amend reports (only an approver may)",
                    Need::Admin => "manage accounts or keys (only an admin may)",
                };
                return Err(refused(format!("account {:?} ({}) may not {what}", now.name, now.role.as_str())));
            }
            Ok((Some(now.id), now.name))
        }
    }
}

/// Records one audit event (inside the write's transaction) and chains it; its id.
pub(crate) fn audit(
    x: &mut dyn Exec,
    account_id: Option<i64>,
    actor: &str,
    action: &str,
    evaluation_id: Option<i64>,
    detail: Option<&str>,
) -> Result<i64, DbError> {
    let rows = x.rows(
        "INSERT INTO audit_event (account_id, actor, action, evaluation_id, detail) VALUES ($1, $2, $3, $4, $5) RETURNING id",
        &[
            Val::IOpt(account_id),
            Val::T(Some(actor.to_string())),
            Val::T(Some(action.to_string())),
            Val::IOpt(evaluation_id),
            Val::T(detail.map(str::to_string)),
        ],
        &[("id", Kind::I)],
    )?;
    let id = returned_id(&rows)?;
    chain::append_row(x, "audit_event", id)?;
    Ok(id)
}

/// One audit event as read back.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct AuditEvent {
    /// Id.
    pub id: i64,
    /// When (the database's clock).
    pub at: String,
    /// Who (an account name, or [`UNAUTHENTICATED`]).
    pub actor: String,
    /// What: store, correction, approval, reevaluation, issue, amend, user add, ...
    pub action: String,
    /// The evaluation concerned, if any.
    pub evaluation_id: Option<i64>,
    /// Details.
    pub detail: Option<String>,
}

/// The audit events of evaluation `id` (or every one with `None`), oldest first.
pub(crate) fn events(x: &mut dyn Exec, evaluation: Option<i64>) -> Result<Vec<AuditEvent>, DbError> {
    let kinds: Columns<'_> = &[
        ("id", Kind::I),
        ("at", Kind::T),
        ("actor", Kind::T),
        ("action", Kind::T),
        ("evaluation_id", Kind::IOpt),
        ("detail", Kind::T),
    ];
    let rows = match evaluation {
        Some(id) => x.rows(
            "SELECT id, at, actor, action, evaluation_id, detail FROM audit_event WHERE evaluation_id = $1 ORDER BY id",
            &[Val::I(id)],
            kinds,
        )?,
        None => {
            x.rows("SELECT id, at, actor, action, evaluation_id, detail FROM audit_event ORDER BY id", &[], kinds)?
        }
    };
    rows.iter()
        .map(|r| {
            Ok(AuditEvent {
                id: r.int("id")?,
                at: r.string("at")?,
                actor: r.string("actor")?,
                action: r.string("action")?,
                evaluation_id: r.int_opt("evaluation_id")?,
                detail: r.string_opt("detail")?,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn argon2id_hashes_verify_and_differ_by_salt() {
        let a = hash_password("correct horse").expect("hash"); // ok: test
        let b = hash_password("correct horse").expect("hash"); // ok: test
        assert!(a.starts_with("$argon2id$"), "{a}");
        assert_ne!(a, b, "a random salt each time");
        assert!(verify_password("correct horse", &a));
        assert!(!verify_password("correct horsE", &a));
        assert!(!verify_password("correct horse", "not a hash"));
    }

    #[test]
    fn names_and_passwords_are_checked() {
        assert!(check_new("alice", "Alice A.", "longenough").is_ok());
        assert!(check_new("al ice", "Alice", "longenough").is_err());
        assert!(check_new("alice", "", "longenough").is_err());
        assert!(check_new("alice", "Alice", "short").is_err());
    }
}
