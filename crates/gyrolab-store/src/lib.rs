//! The records store of gyrolab: every evaluation kept per device, lot and software version, in
//! an embedded SQLite file by default or on a shared PostgreSQL server; revisions instead of
//! changes; history of a serial, lot statistics, lot comparison, control charts. The only crate
//! with SQL; every statement is a constant with parameters (docs/STORE.md).
//!
//! Layout: [`db`] the two back ends behind one interface; [`schema`] tables and migrations;
//! [`record`] what is kept of one evaluation, read from a finished report folder; [`query`] the
//! queries and their statistics (computed by the core crate: `gyrolab::process_capability`,
//! `gyrolab::control_chart`, `gyrolab::two_sample`); [`chain`] the hash chain and the checks; [`account`]
//! accounts, roles, authentication and the audit trail; [`sign`] the lab's Ed25519 key files and
//! signatures; [`issue`] issued reports and amendments (issue 53). It evaluates and renders
//! nothing: gyrolab-lab turns query results into tables and plots (gyrolab-report draws them)
//! and draws an issued report's signature block.

#![deny(missing_docs)]

pub mod account;
pub mod chain;
pub mod db;
pub mod issue;
pub mod location;
pub mod query;
pub mod record;
pub mod schema;
pub mod sign;

pub use account::{Account, Actor, AuditEvent, Role};
pub use chain::{CheckReport, Problem};
use db::{Column, DbError, Exec, Kind, PgExec, PgStatements, Row, SqliteExec, Val};
pub use location::{parse_location, Location, LocationError};
use record::EvaluationRecord;
use std::path::{Path, PathBuf};
use std::time::Duration;
use thiserror::Error;

/// Errors of the store; each names the store (password masked).
#[derive(Debug, Error)]
pub enum StoreError {
    /// The report folder is stored already, as evaluation `id` (the same results.json of the
    /// same serial, current): nothing was added. Not a failure: `store add` says so, exit 0.
    #[error("store {store}: already stored as evaluation {id} (the same results.json): nothing added")]
    AlreadyStored {
        /// The store, password masked.
        store: String,
        /// The evaluation that holds it.
        id: i64,
    },
    /// The store cannot be opened or is not a gyrolab store (exit code 2).
    #[error("store {store}: {message}")]
    Open {
        /// The store, password masked.
        store: String,
        /// What is wrong.
        message: String,
    },
    /// The store was written by a newer gyrolab (exit code 2).
    #[error(
        "store {store}: schema version {found} is newer than this gyrolab {software} knows (up to {known}); use a newer gyrolab"
    )]
    NewerSchema {
        /// The store, password masked.
        store: String,
        /// Version in the store.
        found: i64,
        /// Newest version this build knows.
        known: i64,
        /// This build's version.
        software: String,
    },
    /// A value was refused before anything was written (exit code 2).
    #[error("store {store}: refused: {message}")]
    Refused {
        /// The store, password masked.
        store: String,
        /// What was refused and why.
        message: String,
    },
    /// A report folder or an input could not be read (exit code 2).
    #[error("{path}: {message}")]
    Input {
        /// The file.
        path: String,
        /// What is wrong.
        message: String,
    },
    /// Nothing found for a query (exit code 2).
    #[error("store {store}: {message}")]
    NotFound {
        /// The store, password masked.
        store: String,
        /// What was not found.
        message: String,
    },
    /// The quick check run before every write found the store tampered with: nothing written
    /// (exit code 2; `gyrolab store check` names every broken link).
    #[error(
        "store {store}: refused to write: the store fails its quick check: {first}{more}; run `gyrolab store check`"
    )]
    Tampered {
        /// The store, password masked.
        store: String,
        /// The first problem found.
        first: String,
        /// How many more, as text (empty when none).
        more: String,
    },
    /// Authentication refused: an unknown name, a wrong password or a disabled account, never
    /// saying which (exit code 2).
    #[error("store {store}: {}", account::AUTH_FAILED)]
    Auth {
        /// The store, password masked.
        store: String,
    },
    /// A migration recorded in the store differs from the one this build embeds: the SQL that
    /// made the store is not the SQL of this build's migration file (exit code 2; nothing
    /// written). Names the version, the file and both SHA-256 checksums.
    #[error(
        "store {store}: schema version {version} was applied from SQL with SHA-256 {recorded}, but this gyrolab's \
         migration {file} has SHA-256 {embedded}: refused (a migration file changed after release, or the store's \
         version table was altered)"
    )]
    MigrationChecksum {
        /// The store, password masked.
        store: String,
        /// The migration's version.
        version: i64,
        /// Its file, relative to the store crate (`migrations/sqlite/0001_records.sql`).
        file: String,
        /// The checksum recorded in the store.
        recorded: String,
        /// The checksum of this build's migration.
        embedded: String,
    },
    /// The database failed during an operation (exit code 1; the transaction was rolled back).
    #[error("store {store}: {message}")]
    Database {
        /// The store, password masked.
        store: String,
        /// The database's message.
        message: String,
    },
}

/// How long an SQLite connection waits for another writer before "database is locked".
const BUSY_TIMEOUT: Duration = Duration::from_secs(30);

/// Puts an SQLite store into WAL mode. WAL is a property of the file, so it is read first and
/// nothing is locked once a store has been converted. The conversion itself needs the file to
/// itself and SQLite does not run the busy handler for it, so two processes opening a new store
/// at once (tests/integration/store.rs `two_processes_storing_at_once_both_land`) retry here, with backoff,
/// within the busy timeout.
fn set_wal(c: &rusqlite::Connection, budget: Duration) -> Result<(), DbError> {
    let start = std::time::Instant::now();
    let mut pause = Duration::from_millis(5);
    loop {
        let attempt = c.query_row("PRAGMA journal_mode", [], |r| r.get::<_, String>(0)).and_then(|mode| {
            if mode.eq_ignore_ascii_case("wal") {
                Ok(mode)
            } else {
                c.query_row("PRAGMA journal_mode = WAL", [], |r| r.get::<_, String>(0))
            }
        });
        match attempt {
            Ok(mode) if mode.eq_ignore_ascii_case("wal") => return Ok(()),
            Ok(mode) => return Err(DbError::JournalMode { mode }),
            Err(rusqlite::Error::SqliteFailure(e, _))
                if matches!(e.code, rusqlite::ErrorCode::DatabaseBusy | rusqlite::ErrorCode::DatabaseLocked)
                    && start.elapsed() < budget =>
            {
                std::thread::sleep(pause);
                pause = (pause * 2).min(Duration::from_millis(200));
            }
            Err(e) => return Err(e.into()),
        }
    }
}

impl StoreError {
    /// True for errors of the user's data or store (exit code 2), false for failures (exit code 1).
    /// A damaged SQLite file (SQLite's "malformed" and "not a database") is the store's fault,
    /// not a failure of this run: exit code 2, as for any unusable store (issue 53).
    pub fn is_bad_input(&self) -> bool {
        match self {
            StoreError::Database { message, .. } => {
                message.contains("database disk image is malformed") || message.contains("file is not a database")
            }
            _ => true,
        }
    }
}

/// Result of store operations.
pub type StoreResult<T> = Result<T, StoreError>;

/// The version of this build (written into every record).
pub const SOFTWARE_VERSION: &str = env!("CARGO_PKG_VERSION");

/// The environment variable naming the default store.
pub const STORE_ENV: &str = "GYROLAB_STORE";

/// The default store's file name, in the current folder.
pub const DEFAULT_FILE: &str = "gyrolab.db";

/// Where the store is, the same for every command and front end (issue 53: `eval --store` wrote
/// beside the plan while the queries looked in the current folder): `explicit` (a path or a
/// `postgres://` URL), else `GYROLAB_STORE`, else `gyrolab.db` in the current folder.
pub fn resolve_location(explicit: Option<&str>) -> String {
    if let Some(e) = explicit.filter(|e| !e.is_empty()) {
        return e.to_string();
    }
    if let Ok(env) = std::env::var(STORE_ENV) {
        if !env.is_empty() {
            return env;
        }
    }
    DEFAULT_FILE.to_string()
}

/// True when `location` names a PostgreSQL server (a `postgres://`/`postgresql://` URL in any
/// case, or a libpq keyword string; see [`parse_location`]).
pub fn is_postgres(location: &str) -> bool {
    parse_location(location).is_ok_and(|l| l.is_postgres())
}

/// The location as messages show it: the URL's whole user information replaced by `***`, its
/// query by `?***`, a keyword string's password by `***` (see [`location::shown_name`]).
pub fn mask_location(location: &str) -> String {
    location::shown_name(location)
}

enum Conn {
    Sqlite(rusqlite::Connection),
    Postgres(Box<postgres::Client>),
}

/// An open store with its schema up to date.
pub struct Store {
    conn: Conn,
    name: String,
    location: Location,
    statements: PgStatements,
}

const SQLITE_HEADER: &[u8; 16] = b"SQLite format 3\0";

impl Store {
    /// Opens the store at `location` (a file path, `sqlite://PATH`, a `postgres://` URL or a
    /// libpq keyword string, read by [`parse_location`]; a refused location is an
    /// [`StoreError::Open`] naming only what may be shown). `create`: a missing
    /// SQLite file is created (else it is an error). The schema is created or migrated on first
    /// use; a store of a newer schema, a file that is not SQLite, or an SQLite file with tables
    /// but no gyrolab schema is refused with nothing written.
    pub fn open(location: &str, create: bool) -> StoreResult<Store> {
        let parsed = parse_location(location)
            .map_err(|e| StoreError::Open { store: e.shown.clone(), message: e.message.clone() })?;
        let name = parsed.shown().to_string();
        let mut store = match &parsed {
            Location::Postgres { connect, .. } => {
                let mask = |m: String| parsed.mask(&m);
                let mut config: postgres::Config = connect.parse().map_err(|e: postgres::Error| StoreError::Open {
                    store: name.clone(),
                    message: mask(e.to_string()),
                })?;
                config.connect_timeout(Duration::from_secs(10));
                let client = config.connect(postgres::NoTls).map_err(|e| StoreError::Open {
                    store: name.clone(),
                    message: mask(format!(
                        "cannot connect: {}",
                        e.as_db_error().map_or_else(|| e.to_string(), |d| d.message().to_string())
                    )),
                })?;
                Store {
                    conn: Conn::Postgres(Box::new(client)),
                    name,
                    location: parsed.clone(),
                    statements: PgStatements::new(),
                }
            }
            Location::Sqlite { path } => {
                let path = Path::new(path);
                let open_err = |m: String| StoreError::Open { store: name.clone(), message: m };
                // Only a regular file is opened: opening a FIFO would wait for a writer forever,
                // and a folder or a device is no store.
                if let Ok(m) = std::fs::metadata(path) {
                    if !m.is_file() {
                        return Err(open_err(
                            "not a regular file (a folder, a FIFO or a device): not a gyrolab store".into(),
                        ));
                    }
                }
                match std::fs::File::open(path) {
                    Ok(mut f) => {
                        use std::io::Read;
                        let mut head = [0u8; 16];
                        let mut got = 0;
                        while got < 16 {
                            match f.read(&mut head[got..]) {
                                Ok(0) => break,
                                Ok(n) => got += n,
                                Err(e) => return Err(open_err(format!("cannot read: {e}"))),
                            }
                        }
                        if got > 0 && (got < 16 || head != *SQLITE_HEADER) {
                            return Err(open_err("not an SQLite database (wrong header): not a gyrolab store".into()));
                        }
                    }
                    Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                        if !create {
                            return Err(StoreError::NotFound {
                                store: name.clone(),
                                message:
                                    "no store here (it is created by `gyrolab store add` or `gyrolab eval --store`)"
                                        .into(),
                            });
                        }
                    }
                    Err(e) => return Err(open_err(format!("cannot open: {e}"))),
                }
                let conn = rusqlite::Connection::open(path).map_err(|e| open_err(e.to_string()))?;
                conn.busy_timeout(BUSY_TIMEOUT).map_err(|e| open_err(e.to_string()))?;
                let mut store =
                    Store { conn: Conn::Sqlite(conn), name, location: parsed.clone(), statements: PgStatements::new() };
                store.check_foreign_sqlite()?;
                if let Conn::Sqlite(c) = &store.conn {
                    set_wal(c, BUSY_TIMEOUT).map_err(|e| store.open_error(e.to_string()))?;
                    c.pragma_update(None, "foreign_keys", "ON").map_err(|e| store.open_error(e.to_string()))?;
                    // INSERT OR REPLACE deletes the row it replaces; with recursive triggers that
                    // delete fires the DELETE-refusing triggers (the schema's BEFORE INSERT triggers
                    // refuse it too, for connections that do not set this).
                    c.pragma_update(None, "recursive_triggers", "ON").map_err(|e| store.open_error(e.to_string()))?;
                }
                store
            }
        };
        store.migrate()?;
        Ok(store)
    }

    /// The store's name for messages (password masked).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// True on PostgreSQL.
    pub fn is_postgres(&self) -> bool {
        matches!(self.conn, Conn::Postgres(_))
    }

    fn mask(&self, m: String) -> String {
        self.location.mask(&m)
    }

    fn open_error(&self, m: String) -> StoreError {
        StoreError::Open { store: self.name.clone(), message: self.mask(m) }
    }

    pub(crate) fn db_error(&self, m: String) -> StoreError {
        StoreError::Database { store: self.name.clone(), message: self.mask(m) }
    }

    /// An SQLite file with tables but no `gyrolab_schema` is someone else's database.
    fn check_foreign_sqlite(&mut self) -> StoreResult<()> {
        let Conn::Sqlite(c) = &self.conn else { return Ok(()) };
        let rows = SqliteExec(c)
            .rows("SELECT name FROM sqlite_master WHERE type = 'table'", &[], &[("name", Kind::T)])
            .and_then(|rows| rows.iter().map(|r| r.string("name")).collect::<Result<Vec<String>, DbError>>())
            .map_err(|e| self.open_error(format!("not a usable SQLite database: {e}")))?;
        let names = rows;
        if !names.is_empty() && !names.iter().any(|n| n == "gyrolab_schema") {
            return Err(self.open_error(format!(
                "an SQLite database without a gyrolab schema (tables: {}): not a gyrolab store",
                names.join(", ")
            )));
        }
        Ok(())
    }

    /// Runs `f` in one transaction (SQLite: BEGIN IMMEDIATE, so concurrent writers queue on the
    /// busy timeout); rolled back on any error.
    pub(crate) fn transaction<T>(&mut self, f: impl FnOnce(&mut dyn Exec) -> Result<T, StoreError>) -> StoreResult<T> {
        let name = self.name.clone();
        let location = self.location.clone();
        let dberr = move |m: String| StoreError::Database { store: name.clone(), message: location.mask(&m) };
        match &mut self.conn {
            Conn::Sqlite(c) => {
                let tx = c
                    .transaction_with_behavior(rusqlite::TransactionBehavior::Immediate)
                    .map_err(|e| dberr(e.to_string()))?;
                let out = f(&mut SqliteExec(&tx))?;
                tx.commit().map_err(|e| dberr(e.to_string()))?;
                Ok(out)
            }
            Conn::Postgres(c) => {
                let mut tx = c.transaction().map_err(|e| dberr(e.to_string()))?;
                let out = f(&mut PgExec(&mut tx, &mut self.statements))?;
                tx.commit().map_err(|e| dberr(e.to_string()))?;
                Ok(out)
            }
        }
    }

    /// Runs a read-only query, its columns read by name (see [`db::Exec::rows`]).
    pub(crate) fn rows(&mut self, sql: &str, params: &[Val], columns: db::Columns<'_>) -> StoreResult<Vec<Row>> {
        let r = match &mut self.conn {
            Conn::Sqlite(c) => SqliteExec(c).rows(sql, params, columns),
            Conn::Postgres(c) => PgExec(c.as_mut(), &mut self.statements).rows(sql, params, columns),
        };
        r.map_err(|e| self.row_error(e))
    }

    /// A failure of the executor or of reading a row, as a [`StoreError::Database`].
    pub(crate) fn row_error(&self, e: DbError) -> StoreError {
        self.db_error(e.to_string())
    }

    /// The schema version in the store (0 for a new store).
    pub fn schema_version(&mut self) -> StoreResult<i64> {
        let rows =
            self.rows("SELECT COALESCE(MAX(version), 0) AS version FROM gyrolab_schema", &[], &[("version", Kind::I)])?;
        db::first_int(&rows, "version", 0).map_err(|e| self.row_error(e))
    }

    /// The migrations recorded in the store's `gyrolab_schema`, oldest first (their name and
    /// checksum are null only in a store no build with checksums has opened yet).
    pub fn recorded_migrations(&mut self) -> StoreResult<Vec<schema::RecordedMigration>> {
        let rows = self.rows(
            "SELECT version, name, sha256 FROM gyrolab_schema ORDER BY version",
            &[],
            &[("version", Kind::I), ("name", Kind::T), ("sha256", Kind::T)],
        )?;
        rows.iter()
            .map(|r| {
                Ok(schema::RecordedMigration {
                    version: r.int("version")?,
                    name: r.string_opt("name")?,
                    sha256: r.string_opt("sha256")?,
                })
            })
            .collect::<Result<Vec<_>, DbError>>()
            .map_err(|e| self.row_error(e))
    }

    fn migrate(&mut self) -> StoreResult<()> {
        let postgres = self.is_postgres();
        let migrations = schema::migrations(postgres);
        let store = self.name.clone();
        let now = now_rfc3339();
        let dberr = |m: DbError| StoreError::Open { store: store.clone(), message: m.to_string() };
        self.transaction(|x| {
            if postgres {
                // One migrating client at a time; others wait here and then find it done.
                x.exec("SELECT pg_advisory_xact_lock(7291835)", &[]).map_err(&dberr)?;
            }
            // A store already made is read without any DDL, so that a role with SELECT and
            // INSERT only (docs/STORE.md, "Least privilege") opens it; the owner migrates it.
            let exists = !x
                .rows(schema::version_table_exists_sql(postgres), &[], &[("one", Kind::I)])
                .map_err(&dberr)?
                .is_empty();
            if !exists {
                x.batch(schema::VERSION_TABLE).map_err(&dberr)?;
            }
            // A version table of a build before checksums lacks their columns: added here, in
            // this transaction, and filled below (adoption).
            let has: Vec<String> = x
                .rows(
                    schema::version_table_columns_sql(postgres),
                    &[Val::T(Some("gyrolab_schema".into()))],
                    &[("name", Kind::T)],
                )
                .and_then(|rows| rows.iter().map(|r| r.string("name")).collect())
                .map_err(&dberr)?;
            for (column, add) in schema::VERSION_TABLE_COLUMNS {
                if !has.iter().any(|h| h == column) {
                    x.batch(add).map_err(&dberr)?;
                }
            }
            let recorded = x
                .rows(
                    "SELECT version, sha256 FROM gyrolab_schema ORDER BY version",
                    &[],
                    &[("version", Kind::I), ("sha256", Kind::T)],
                )
                .map_err(&dberr)?;
            let found = match recorded.last() {
                Some(r) => r.int("version").map_err(&dberr)?,
                None => 0,
            };
            if found > schema::SCHEMA_VERSION {
                return Err(StoreError::NewerSchema {
                    store: store.clone(),
                    found,
                    known: schema::SCHEMA_VERSION,
                    software: SOFTWARE_VERSION.to_string(),
                });
            }
            for r in &recorded {
                let version = r.int("version").map_err(&dberr)?;
                let Some(m) = usize::try_from(version - 1).ok().and_then(|i| migrations.get(i)) else {
                    return Err(dberr(DbError::Invalid(format!("gyrolab_schema records an unknown version {version}"))));
                };
                let embedded = m.sha256();
                match r.text("sha256").map_err(&dberr)? {
                    // Applied by a build before checksums: adopted, recorded from this build.
                    None => {
                        x.exec(
                            "UPDATE gyrolab_schema SET name = $1, sha256 = $2 WHERE version = $3",
                            &[Val::T(Some(m.name.to_string())), Val::T(Some(embedded)), Val::I(version)],
                        )
                        .map_err(&dberr)?;
                    }
                    Some(recorded) if recorded != embedded => {
                        return Err(StoreError::MigrationChecksum {
                            store: store.clone(),
                            version,
                            file: m.file.to_string(),
                            recorded: recorded.to_string(),
                            embedded,
                        });
                    }
                    Some(_) => {}
                }
            }
            for m in migrations.iter().skip(found as usize) {
                x.batch(m.sql).map_err(|e| match e {
                    DbError::Postgres(m) if m.contains("permission denied") => dberr(DbError::Postgres(format!(
                        "{m}: this role may not migrate the store's schema (version {found} to {}); let the owner role \
                         open it once with this gyrolab (docs/STORE.md, \"Least privilege\")",
                        schema::SCHEMA_VERSION
                    ))),
                    e => dberr(e),
                })?;
                if m.version == 3 {
                    // Migration 3: the hash chain over the rows already stored.
                    chain::build_existing(x).map_err(&dberr)?;
                }
                x.exec(
                    "INSERT INTO gyrolab_schema (version, applied_at, software_version, name, sha256) VALUES ($1, $2, $3, $4, $5)",
                    &[
                        Val::I(m.version),
                        Val::T(Some(now.clone())),
                        Val::T(Some(SOFTWARE_VERSION.to_string())),
                        Val::T(Some(m.name.to_string())),
                        Val::T(Some(m.sha256())),
                    ],
                )
                .map_err(&dberr)?;
            }
            Ok(())
        })
        .map_err(|e| match e {
            StoreError::Database { store, message } => StoreError::Open { store, message },
            other => other,
        })
    }

    /// Stores one evaluation (a new original record) in one transaction, without an account (a
    /// store that has accounts refuses it: see [`Store::add_as`]); its id.
    pub fn add(&mut self, record: &EvaluationRecord) -> StoreResult<i64> {
        self.insert(record, None, &Actor::unauthenticated())
    }

    /// Stores one evaluation as `actor` (an account that may store, or no account in a store
    /// that has none), recording who and the database's time in the audit trail; its id.
    pub fn add_as(&mut self, record: &EvaluationRecord, actor: &Actor) -> StoreResult<i64> {
        self.insert(record, None, actor)
    }

    /// Authenticates `name` with `password` (Argon2id against the stored hash): the actor for
    /// later writes, or [`StoreError::Auth`] whatever was wrong (unknown name, wrong password,
    /// disabled account).
    pub fn authenticate(&mut self, name: &str, password: &str) -> StoreResult<Actor> {
        let store = self.name.clone();
        let found = self.transaction(|x| {
            account::authenticate(x, name, password)
                .map_err(|m| StoreError::Database { store: store.clone(), message: m.to_string() })
        })?;
        found.map(|(a, hash)| Actor::of(a, hash)).map_err(|()| StoreError::Auth { store: self.name.clone() })
    }

    /// The current evaluation of `serial` whose results.json is exactly `results_json`, if
    /// one is stored (a report folder added before).
    pub fn current_with_results(&mut self, serial: &str, results_json: &str) -> StoreResult<Option<i64>> {
        let store = self.name.clone();
        self.transaction(|x| {
            let rows = x
                .rows(
                    "SELECT id FROM evaluation WHERE serial = $1 AND results_json = $2 \
                     AND NOT EXISTS (SELECT 1 FROM evaluation later WHERE later.supersedes = evaluation.id) ORDER BY id",
                    &[Val::T(Some(serial.to_string())), Val::T(Some(results_json.to_string()))],
                    &[("id", Kind::I)],
                )
                .map_err(|m| StoreError::Database { store: store.clone(), message: m.to_string() })?;
            rows.first()
                .map(|r| r.int("id"))
                .transpose()
                .map_err(|m| StoreError::Database { store: store.clone(), message: m.to_string() })
        })
    }

    /// Which of the raw records `sha256s` the store keeps already (schema 6, `input_content`):
    /// those need not be read and compressed again.
    pub fn kept_contents(&mut self, sha256s: &[String]) -> StoreResult<std::collections::HashSet<String>> {
        let mut kept = std::collections::HashSet::new();
        for sha in sha256s {
            let rows = self.rows(
                "SELECT id FROM input_content WHERE sha256 = $1",
                &[Val::T(Some(sha.clone()))],
                &[("id", Kind::I)],
            )?;
            if !rows.is_empty() {
                kept.insert(sha.clone());
            }
        }
        Ok(kept)
    }

    /// The current evaluation of `record`'s serial made from the same plan (its SHA-256) and the
    /// same inputs (each path and SHA-256), if one is stored: running the same `eval --store`
    /// again is then its re-evaluation, not a second current original.
    pub fn current_of_same_inputs(&mut self, record: &EvaluationRecord) -> StoreResult<Option<i64>> {
        // A record the store refuses (a NUL in a text) is refused as storing it would be.
        if let Err(m) = record.check() {
            return Err(StoreError::Refused { store: self.name.clone(), message: m });
        }
        let store = self.name.clone();
        let dberr = |m: DbError| StoreError::Database { store: store.clone(), message: m.to_string() };
        let mut want: Vec<(String, String)> =
            record.inputs.iter().map(|f| (f.path.clone(), f.sha256.clone())).collect();
        want.sort();
        self.transaction(|x| {
            let ids = x
                .rows(
                    "SELECT id FROM evaluation WHERE serial = $1 AND plan_sha256 = $2 \
                     AND NOT EXISTS (SELECT 1 FROM evaluation later WHERE later.supersedes = evaluation.id) ORDER BY id",
                    &[Val::T(Some(record.serial.clone())), Val::T(Some(record.plan_sha256.clone()))],
                    &[("id", Kind::I)],
                )
                .map_err(&dberr)?;
            for r in ids {
                let id = r.int("id").map_err(&dberr)?;
                let files = x
                    .rows(
                        "SELECT path, sha256 FROM input_file WHERE evaluation_id = $1",
                        &[Val::I(id)],
                        &[("path", Kind::T), ("sha256", Kind::T)],
                    )
                    .map_err(&dberr)?;
                let mut have: Vec<(String, String)> = files
                    .iter()
                    .map(|f| Ok((f.string("path")?, f.string("sha256")?)))
                    .collect::<Result<_, DbError>>()
                    .map_err(&dberr)?;
                have.sort();
                if have == want {
                    return Ok(Some(id));
                }
            }
            Ok(None)
        })
    }

    /// Whether the store has any account (then every write needs one).
    pub fn has_accounts(&mut self) -> StoreResult<bool> {
        let store = self.name.clone();
        self.transaction(|x| {
            account::any(x).map_err(|m| StoreError::Database { store: store.clone(), message: m.to_string() })
        })
    }

    /// Every account as it stands now (no password hashes).
    pub fn accounts(&mut self) -> StoreResult<Vec<Account>> {
        let store = self.name.clone();
        self.transaction(|x| {
            account::accounts(x)
                .map(|v| v.into_iter().map(|(a, _)| a).collect())
                .map_err(|m| StoreError::Database { store: store.clone(), message: m.to_string() })
        })
    }

    /// The audit trail of evaluation `id` (every event with `None`), oldest first.
    pub fn audit_events(&mut self, id: Option<i64>) -> StoreResult<Vec<AuditEvent>> {
        let store = self.name.clone();
        self.transaction(|x| {
            account::events(x, id).map_err(|m| StoreError::Database { store: store.clone(), message: m.to_string() })
        })
    }

    /// Runs `f` in a write transaction: the chain's lock (PostgreSQL), the quick check, then `f`.
    pub(crate) fn write<T>(&mut self, f: impl FnOnce(&mut dyn Exec, &str) -> StoreResult<T>) -> StoreResult<T> {
        let store = self.name.clone();
        let postgres = self.is_postgres();
        let dberr = |m: DbError| StoreError::Database { store: store.clone(), message: m.to_string() };
        let out = self.transaction(|x| {
            if postgres {
                x.exec("SELECT pg_advisory_xact_lock(7291836)", &[]).map_err(&dberr)?;
            }
            let quick = chain::quick_check(x, postgres, false).map_err(&dberr)?;
            if let Some(first) = quick.problems.first() {
                let more = match quick.problems.len() - 1 {
                    0 => String::new(),
                    n => format!(" (and {n} more)"),
                };
                return Err(StoreError::Tampered { store: store.clone(), first: first.to_string(), more });
            }
            f(x, &store)
        });
        out.map_err(|e| match e {
            StoreError::Database { store, message } => StoreError::Database { store, message: self.mask(message) },
            other => other,
        })
    }

    /// Adds an account. The first account of a store must be an admin and needs no actor
    /// (`actor` unauthenticated); every later one is added by an authenticated admin. Its id.
    pub fn add_account(
        &mut self,
        actor: &Actor,
        name: &str,
        display_name: &str,
        role: Role,
        password: &str,
    ) -> StoreResult<i64> {
        account::check_new(name, display_name, password)
            .map_err(|m| StoreError::Refused { store: self.name.clone(), message: m })?;
        let hash = account::hash_password(password).map_err(|m| self.db_error(m))?;
        self.write(|x, store| {
            let dberr = |m: DbError| StoreError::Database { store: store.to_string(), message: m.to_string() };
            let refused = |m: String| StoreError::Refused { store: store.to_string(), message: m };
            let first = !account::any(x).map_err(dberr)?;
            let (by_id, by) = if first {
                if role != Role::Admin {
                    return Err(refused(format!(
                        "the first account of a store must be an admin (--role admin), not {}",
                        role.as_str()
                    )));
                }
                (None, UNAUTHENTICATED_FIRST.to_string())
            } else {
                account::check_actor(x, store, actor, account::Need::Admin)?
            };
            if account::by_name(x, name).map_err(dberr)?.is_some() {
                return Err(refused(format!("an account named {name:?} exists already")));
            }
            let rows = x
                .rows(
                    "INSERT INTO account (name, display_name, role, password_hash, created_by) VALUES ($1, $2, $3, $4, $5) RETURNING id",
                    &[
                        Val::T(Some(name.to_string())),
                        Val::T(Some(display_name.to_string())),
                        Val::T(Some(role.as_str().to_string())),
                        Val::T(Some(hash.clone())),
                        Val::T(Some(by.clone())),
                    ],
                    &[("id", Kind::I)],
                )
                .map_err(dberr)?;
            let id = db::returned_id(&rows).map_err(dberr)?;
            chain::append_row(x, "account", id).map_err(dberr)?;
            account::audit(x, by_id, &by, "user add", None, Some(&format!("{name} ({})", role.as_str())))
                .map_err(dberr)?;
            Ok(id)
        })
    }

    /// Disables an account (an admin; a new `account_change` row: it can no longer authenticate).
    pub fn disable_account(&mut self, actor: &Actor, name: &str) -> StoreResult<()> {
        self.change_account(actor, name, None)
    }

    /// Sets a new password of an account (an admin; a new `account_change` row).
    pub fn reset_password(&mut self, actor: &Actor, name: &str, password: &str) -> StoreResult<()> {
        account::check_password(password).map_err(|m| StoreError::Refused { store: self.name.clone(), message: m })?;
        let hash = account::hash_password(password).map_err(|m| self.db_error(m))?;
        self.change_account(actor, name, Some(hash))
    }

    fn change_account(&mut self, actor: &Actor, name: &str, password_hash: Option<String>) -> StoreResult<()> {
        self.write(|x, store| {
            let dberr = |m: DbError| StoreError::Database { store: store.to_string(), message: m.to_string() };
            let (by_id, by) = account::check_actor(x, store, actor, account::Need::Admin)?;
            let by_id = by_id.ok_or_else(|| StoreError::Auth { store: store.to_string() })?;
            let Some((target, _)) = account::by_name(x, name).map_err(dberr)? else {
                return Err(StoreError::NotFound { store: store.to_string(), message: format!("no account {name:?}") });
            };
            let change = if password_hash.is_some() { "password" } else { "disable" };
            if change == "disable" && target.disabled {
                return Err(StoreError::Refused {
                    store: store.to_string(),
                    message: format!("account {name:?} is disabled already"),
                });
            }
            let rows = x
                .rows(
                    "INSERT INTO account_change (account_id, change, password_hash, changed_by) VALUES ($1, $2, $3, $4) RETURNING id",
                    &[Val::I(target.id), Val::T(Some(change.into())), Val::T(password_hash.clone()), Val::I(by_id)],
                    &[("id", Kind::I)],
                )
                .map_err(dberr)?;
            let id = db::returned_id(&rows).map_err(dberr)?;
            chain::append_row(x, "account_change", id).map_err(dberr)?;
            let action = if change == "disable" { "user disable" } else { "user reset" };
            account::audit(x, Some(by_id), &by, action, None, Some(name)).map_err(dberr)?;
            Ok(())
        })
    }

    /// Records the lab's public key (an admin, or no account in the store), so that issues can be
    /// signed with its private key; its fingerprint.
    pub fn add_signing_key(&mut self, actor: &Actor, key: &ed25519_dalek::VerifyingKey) -> StoreResult<String> {
        let fingerprint = sign::fingerprint(key);
        let public = sign::public_hex(key);
        self.write(|x, store| {
            let dberr = |m: DbError| StoreError::Database { store: store.to_string(), message: m.to_string() };
            let (by_id, by) = account::check_actor(x, store, actor, account::Need::Admin)?;
            let rows = x
                .rows(
                    "INSERT INTO signing_key (public_key, fingerprint, added_by) VALUES ($1, $2, $3) RETURNING id",
                    &[Val::T(Some(public.clone())), Val::T(Some(fingerprint.clone())), Val::T(Some(by.clone()))],
                    &[("id", Kind::I)],
                )
                .map_err(dberr)?;
            let id = db::returned_id(&rows).map_err(dberr)?;
            chain::append_row(x, "signing_key", id).map_err(dberr)?;
            account::audit(x, by_id, &by, "key add", None, Some(&fingerprint)).map_err(dberr)?;
            Ok(fingerprint.clone())
        })
    }

    pub(crate) fn insert(
        &mut self,
        record: &EvaluationRecord,
        revision: Option<&Revision>,
        actor: &Actor,
    ) -> StoreResult<i64> {
        if let Err(m) = record.check() {
            return Err(StoreError::Refused { store: self.name.clone(), message: m });
        }
        if let Some(r) = revision {
            if let Err(m) = r.check() {
                return Err(StoreError::Refused { store: self.name.clone(), message: m });
            }
        }
        let now = now_rfc3339();
        // The chain's lock and the quick check first ([`Store::write`]).
        self.write(|x, store| {
            let dberr = |m: DbError| StoreError::Database { store: store.to_string(), message: m.to_string() };
            let need = match revision.map(|r| r.kind) {
                Some(RevisionKind::Approval) => account::Need::Approver,
                _ => account::Need::Store,
            };
            // A store without accounts keeps its free-text approvals (no account to check).
            let need = if need == account::Need::Approver && actor.account().is_none() {
                account::Need::Store
            } else {
                need
            };
            let (account_id, actor_name) = account::check_actor(x, store, actor, need)?;
            if let (Some(r), Some(me)) = (revision, account_id) {
                if r.kind == RevisionKind::Approval && issue::stored_by(x, r.supersedes).map_err(&dberr)?.contains(&me) {
                    return Err(StoreError::Refused {
                        store: store.to_string(),
                        message: format!(
                            "self-approval refused: account {actor_name:?} stored evaluation {} or a revision of it; \
                             another approver must approve it",
                            r.supersedes
                        ),
                    });
                }
            }
            let t = |s: &str| Val::T(Some(s.to_string()));
            let o = |s: &Option<String>| Val::T(s.clone());
            let (supersedes, kind, by, why) = match revision {
                Some(r) => (Val::I(r.supersedes), t(r.kind.as_str()), Val::T(Some(r.by.clone())), Val::T(Some(r.reason.clone()))),
                None => (Val::IOpt(None), t("original"), Val::T(None), Val::T(None)),
            };
            if let Some(r) = revision {
                let taken = x
                    .rows("SELECT id FROM evaluation WHERE supersedes = $1", &[Val::I(r.supersedes)], &[("id", Kind::I)])
                    .map_err(&dberr)?;
                if let Some(row) = taken.first() {
                    return Err(StoreError::Refused {
                        store: store.to_string(),
                        message: format!(
                            "evaluation {} is already superseded by {}: revise the current revision",
                            r.supersedes,
                            row.int("id").map_err(&dberr)?
                        ),
                    });
                }
            }
            let rows = x
                .rows(
                    "INSERT INTO evaluation (supersedes, revision_kind, revision_by, revision_reason, stored_at, serial, model, lot, \
                     operator, approver, test_date, evaluated_at, software_version, plan_path, plan_text, plan_sha256, results_json, \
                     verdict, simulated) VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11, $12, $13, $14, $15, $16, $17, $18, $19) \
                     RETURNING id",
                    &[
                        supersedes,
                        kind,
                        by,
                        why,
                        t(&now),
                        t(&record.serial),
                        t(&record.model),
                        o(&record.lot),
                        o(&record.operator),
                        o(&record.approver),
                        o(&record.test_date),
                        t(&record.evaluated_at),
                        t(&record.software_version),
                        t(&record.plan_path),
                        t(&record.plan_text),
                        t(&record.plan_sha256),
                        t(&record.results_json),
                        o(&record.verdict),
                        Val::I(record.simulated as i64),
                    ],
                    &[("id", Kind::I)],
                )
                .map_err(&dberr)?;
            let id = db::returned_id(&rows).map_err(&dberr)?;
            // One statement per table (PostgreSQL: one round trip each, the rows as arrays).
            let files = &record.inputs;
            let columns = [
                Column::I(vec![id; files.len()]),
                Column::T(files.iter().map(|f| Some(f.path.clone())).collect()),
                Column::T(files.iter().map(|f| Some(f.sha256.clone())).collect()),
                Column::I(files.iter().map(|f| f.size_bytes as i64).collect()),
            ];
            x.insert_columns(
                "INSERT INTO input_file (id, evaluation_id, path, sha256, size_bytes) VALUES ((SELECT COALESCE(MAX(id), 0) + 1 FROM input_file), $1, $2, $3, $4)",
                "INSERT INTO input_file (evaluation_id, path, sha256, size_bytes) \
                 SELECT * FROM unnest($1::bigint[], $2::text[], $3::text[], $4::bigint[])",
                &columns,
            )
            .map_err(&dberr)?;
            // The raw records (schema 6): one compressed copy per SHA-256 in the whole store.
            let mut kept: Vec<&str> = Vec::new();
            for f in record.inputs.iter().filter(|f| f.packed.is_some()) {
                if kept.contains(&f.sha256.as_str())
                    || !x
                        .rows("SELECT id FROM input_content WHERE sha256 = $1", &[t(&f.sha256)], &[("id", Kind::I)])
                        .map_err(&dberr)?
                        .is_empty()
                {
                    continue;
                }
                kept.push(&f.sha256);
                x.insert_columns(
                    "INSERT INTO input_content (id, evaluation_id, sha256, size_bytes, content_zstd) VALUES ((SELECT COALESCE(MAX(id), 0) + 1 FROM input_content), $1, $2, $3, $4)",
                    "INSERT INTO input_content (evaluation_id, sha256, size_bytes, content_zstd) \
                     SELECT * FROM unnest($1::bigint[], $2::text[], $3::bigint[], $4::bytea[])",
                    &[
                        Column::I(vec![id]),
                        Column::T(vec![Some(f.sha256.clone())]),
                        Column::I(vec![f.size_bytes as i64]),
                        Column::B(vec![f.packed.clone()]),
                    ],
                )
                .map_err(&dberr)?;
            }
            let files = &record.report_files;
            let packed = files
                .iter()
                .map(|f| f.content.as_deref().map(|b| zstd::bulk::compress(b, 3)).transpose())
                .collect::<Result<Vec<_>, _>>()
                .map_err(|e| dberr(format!("cannot compress a report file: {e}").into()))?;
            let columns = [
                Column::I(vec![id; files.len()]),
                Column::T(files.iter().map(|f| Some(f.path.clone())).collect()),
                Column::T(files.iter().map(|f| Some(f.sha256.clone())).collect()),
                Column::I(files.iter().map(|f| f.size_bytes as i64).collect()),
                Column::B(packed),
            ];
            x.insert_columns(
                "INSERT INTO report_file (id, evaluation_id, name, sha256, size_bytes, content_zstd) VALUES ((SELECT COALESCE(MAX(id), 0) + 1 FROM report_file), $1, $2, $3, $4, $5)",
                "INSERT INTO report_file (evaluation_id, name, sha256, size_bytes, content_zstd) \
                 SELECT * FROM unnest($1::bigint[], $2::text[], $3::text[], $4::bigint[], $5::bytea[])",
                &columns,
            )
            .map_err(&dberr)?;
            let figs = &record.figures;
            let text = |g: fn(&record::FigureRecord) -> &str| Column::T(figs.iter().map(|f| Some(g(f).to_string())).collect());
            let number = |g: fn(&record::FigureRecord) -> Option<f64>| Column::F(figs.iter().map(g).collect());
            let columns = [
                Column::I(vec![id; figs.len()]),
                text(|f| &f.axis),
                text(|f| &f.figure),
                number(|f| f.value),
                text(|f| &f.unit),
                text(|f| &f.basis),
                number(|f| f.expanded_uncertainty),
                number(|f| f.coverage_factor),
                number(|f| f.limit_min),
                number(|f| f.limit_max),
                Column::T(figs.iter().map(|f| f.verdict.clone()).collect()),
                Column::I(figs.iter().map(|f| f.simulated as i64).collect()),
            ];
            x.insert_columns(
                "INSERT INTO figure (id, evaluation_id, axis, figure, value, unit, basis, expanded_uncertainty, \
                 coverage_factor, limit_min, limit_max, verdict, simulated) VALUES ((SELECT COALESCE(MAX(id), 0) + 1 FROM \
                 figure), $1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11, $12)",
                "INSERT INTO figure (evaluation_id, axis, figure, value, unit, basis, expanded_uncertainty, coverage_factor, \
                 limit_min, limit_max, verdict, simulated) SELECT * FROM unnest($1::bigint[], $2::text[], $3::text[], \
                 $4::float8[], $5::text[], $6::text[], $7::float8[], $8::float8[], $9::float8[], $10::float8[], $11::text[], \
                 $12::bigint[])",
                &columns,
            )
            .map_err(&dberr)?;
            chain::append_evaluation(x, id).map_err(&dberr)?;
            let (action, detail) = match revision {
                Some(r) => (r.kind.as_str(), Some(format!("supersedes {}: {}", r.supersedes, r.reason))),
                None => ("store", None),
            };
            account::audit(x, account_id, &actor_name, action, Some(id), detail.as_deref()).map_err(&dberr)?;
            pause_for_test();
            Ok(id)
        })
    }

    /// Stores a revision of evaluation `revision.supersedes`: a copy of it with `changes`
    /// applied (a correction or an approval), or `record` (a re-evaluation). The superseded
    /// record stays as it was. Its id.
    pub fn revise(
        &mut self,
        revision: &Revision,
        changes: &Changes,
        record: Option<&EvaluationRecord>,
    ) -> StoreResult<i64> {
        self.revise_as(revision, changes, record, &Actor::unauthenticated())
    }

    /// [`Store::revise`] as `actor` (an approval needs an approver who did not store the
    /// evaluation or a revision of it, once the store has accounts).
    pub fn revise_as(
        &mut self,
        revision: &Revision,
        changes: &Changes,
        record: Option<&EvaluationRecord>,
        actor: &Actor,
    ) -> StoreResult<i64> {
        let mut rec = match record {
            Some(r) => r.clone(),
            None => self.evaluation(revision.supersedes)?.record,
        };
        if let Some(v) = &changes.serial {
            rec.serial = v.clone();
        }
        if let Some(v) = &changes.model {
            rec.model = v.clone();
        }
        if let Some(v) = &changes.lot {
            rec.lot = Some(v.clone());
        }
        if let Some(v) = &changes.operator {
            rec.operator = Some(v.clone());
        }
        if let Some(v) = &changes.test_date {
            rec.test_date = Some(v.clone());
        }
        if revision.kind == RevisionKind::Approval {
            rec.approver = Some(revision.by.clone());
        } else if let Some(v) = &changes.approver {
            rec.approver = Some(v.clone());
        }
        self.insert(&rec, Some(revision), actor)
    }

    /// Writes the stored report folder of evaluation `id` to `out` (see [`query::write_report`]).
    pub fn write_report(&mut self, id: i64, out: &Path) -> StoreResult<Vec<PathBuf>> {
        query::write_report(self, id, out)
    }

    /// PostgreSQL only, run as the owner of the store's tables: gives the existing login `role`
    /// USAGE on the store's schema, SELECT and INSERT on every record table and the chain,
    /// SELECT on `gyrolab_schema`, and revokes UPDATE, DELETE, TRUNCATE, REFERENCES and TRIGGER
    /// on them, so that gyrolab run as `role` can store and read but neither change, empty nor
    /// disable a trigger (only the owner can). The tables granted, in order. The statements are
    /// made by the server's `format()` with `%I` (the role and table names quoted as
    /// identifiers), never spliced here.
    pub fn grant_least_privilege(&mut self, role: &str) -> StoreResult<Vec<String>> {
        let store = self.name.clone();
        if !self.is_postgres() {
            return Err(StoreError::Refused {
                store,
                message: "an SQLite store is a file: its file permissions are its access control (grant is for \
                          PostgreSQL)"
                    .into(),
            });
        }
        let refused = |m: String| StoreError::Refused { store: store.clone(), message: m };
        let dberr = |m: DbError| StoreError::Database { store: store.clone(), message: m.to_string() };
        let r = Val::T(Some(role.to_string()));
        self.transaction(|x| {
            let found = x
                .rows(
                    "SELECT (CASE WHEN rolsuper THEN 1 ELSE 0 END)::int8 AS superuser FROM pg_roles WHERE rolname = $1",
                    std::slice::from_ref(&r),
                    &[("superuser", Kind::I)],
                )
                .map_err(&dberr)?;
            match found.first().map(|f| f.int("superuser")).transpose().map_err(&dberr)? {
                None => return Err(refused(format!("no PostgreSQL role {role:?}: create it first (CREATE ROLE ... LOGIN)"))),
                Some(1) => {
                    return Err(refused(format!("{role:?} is a superuser, whom no privilege limits: use an ordinary role")))
                }
                Some(_) => {}
            }
            // Only the owner grants: PostgreSQL turns another role's GRANT into a warning.
            let owner = x
                .rows(
                    "SELECT 1::int8 AS one FROM pg_tables WHERE schemaname = current_schema() AND tablename = 'evaluation' \
                     AND pg_has_role(tableowner, 'MEMBER')",
                    &[],
                    &[("one", Kind::I)],
                )
                .map_err(&dberr)?;
            if owner.is_empty() {
                return Err(refused("grant is run as the owner of the store's tables, which this role is not".into()));
            }
            let mut tables: Vec<&str> = chain::CHAINED.iter().map(|t| t.name).collect();
            tables.push("chain");
            let statement = |x: &mut dyn Exec, sql: &str, params: &[Val]| -> StoreResult<()> {
                let rows = x.rows(sql, params, &[("sql", Kind::T)]).map_err(&dberr)?;
                let text = rows.first().map(|r| r.string("sql")).transpose().map_err(&dberr)?.unwrap_or_default();
                x.batch(&text).map_err(|e| match e {
                    DbError::Postgres(m) if m.contains("must be owner") || m.contains("permission denied") => {
                        refused(format!("{m}: grant is run as the owner of the store's tables"))
                    }
                    e => dberr(e),
                })
            };
            statement(x, "SELECT format('GRANT USAGE ON SCHEMA %I TO %I', current_schema(), $1::text) AS sql", std::slice::from_ref(&r))?;
            for t in &tables {
                let t = Val::T(Some(t.to_string()));
                statement(
                    x,
                    "SELECT format('REVOKE UPDATE, DELETE, TRUNCATE, REFERENCES, TRIGGER ON %I FROM %I', $1::text, $2::text) AS sql",
                    &[t.clone(), r.clone()],
                )?;
                statement(x, "SELECT format('GRANT SELECT, INSERT ON %I TO %I', $1::text, $2::text) AS sql", &[t, r.clone()])?;
            }
            statement(x, "SELECT format('REVOKE ALL ON gyrolab_schema FROM %I', $1::text) AS sql", std::slice::from_ref(&r))?;
            statement(x, "SELECT format('GRANT SELECT ON gyrolab_schema TO %I', $1::text) AS sql", std::slice::from_ref(&r))?;
            Ok(tables.iter().map(|t| t.to_string()).collect())
        })
    }

    /// The full check (`gyrolab store check`): the protecting triggers, every chain link against
    /// its row, every stored report file against its SHA-256 ([`chain::full_check`]). A store
    /// found tampered with is a report with problems, not an error.
    pub fn check(&mut self) -> StoreResult<CheckReport> {
        let postgres = self.is_postgres();
        let store = self.name.clone();
        self.transaction(|x| {
            chain::full_check(x, postgres)
                .map_err(|m| StoreError::Database { store: store.clone(), message: m.to_string() })
        })
    }

    /// The quick check run before every write ([`chain::quick_check`]; SQLite's page check too,
    /// which the check inside each write leaves out): the triggers, row counts
    /// against link counts and the last links. `gyrolab eval --store` runs it before the report
    /// folder is written.
    pub fn quick_check(&mut self) -> StoreResult<CheckReport> {
        let postgres = self.is_postgres();
        let store = self.name.clone();
        self.transaction(|x| {
            chain::quick_check(x, postgres, true)
                .map_err(|m| StoreError::Database { store: store.clone(), message: m.to_string() })
        })
    }

    /// Opens the store at `location` for writing (see [`Store::open`]) and runs the quick check,
    /// refusing a store that fails it ([`StoreError::Tampered`], exit code 2).
    pub fn open_for_writing(location: &str, create: bool) -> StoreResult<Store> {
        let mut s = Store::open(location, create)?;
        let report = s.quick_check()?;
        if let Some(first) = report.problems.first() {
            let more = match report.problems.len() - 1 {
                0 => String::new(),
                n => format!(" (and {n} more)"),
            };
            return Err(StoreError::Tampered { store: s.name.clone(), first: first.to_string(), more });
        }
        Ok(s)
    }

    /// One stored evaluation with its files and figures.
    pub fn evaluation(&mut self, id: i64) -> StoreResult<query::StoredEvaluation> {
        query::evaluation(self, id)
    }
}

/// Recorded as the creator of a store's first account (made without authentication).
const UNAUTHENTICATED_FIRST: &str = "local (the store's first account)";

/// Kinds of revision.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RevisionKind {
    /// The stored plan and inputs evaluated again (another software version).
    Reevaluation,
    /// Recorded facts corrected (serial, lot, operator, date...).
    Correction,
    /// Approved by someone (who = the approver).
    Approval,
}

impl RevisionKind {
    /// The stored text.
    pub fn as_str(self) -> &'static str {
        match self {
            RevisionKind::Reevaluation => "reevaluation",
            RevisionKind::Correction => "correction",
            RevisionKind::Approval => "approval",
        }
    }
}

/// Who revises which evaluation, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct Revision {
    /// The evaluation superseded (must be a current revision).
    pub supersedes: i64,
    /// Kind of revision.
    pub kind: RevisionKind,
    /// Who.
    pub by: String,
    /// Why.
    pub reason: String,
}

impl Revision {
    fn check(&self) -> Result<(), String> {
        if self.by.trim().is_empty() {
            return Err("a revision needs who made it (--by)".into());
        }
        if self.reason.trim().is_empty() {
            return Err("a revision needs a reason (--reason)".into());
        }
        record::check_text("--by", &self.by)?;
        record::check_text("--reason", &self.reason)
    }
}

/// Fields a correction changes (unset: kept).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Changes {
    /// New serial.
    pub serial: Option<String>,
    /// New model.
    pub model: Option<String>,
    /// New lot.
    pub lot: Option<String>,
    /// New operator.
    pub operator: Option<String>,
    /// New approver.
    pub approver: Option<String>,
    /// New test date.
    pub test_date: Option<String>,
}

/// The environment variable of the kill test (crates/gyrolab-cli/tests/integration/store.rs): milliseconds
/// to pause inside the transaction of every stored evaluation, after all its rows are written and
/// before the commit, so that a test can kill the process there. Unset in normal use.
pub const TEST_PAUSE_ENV: &str = "GYROLAB_STORE_TEST_PAUSE_MS";

fn pause_for_test() {
    if let Some(ms) = std::env::var(TEST_PAUSE_ENV).ok().and_then(|v| v.parse::<u64>().ok()) {
        eprintln!("store: pausing {ms} ms inside the transaction ({TEST_PAUSE_ENV})");
        std::thread::sleep(Duration::from_millis(ms));
    }
}

/// Now, RFC 3339 UTC to the microsecond (sortable as text).
pub fn now_rfc3339() -> String {
    humantime::format_rfc3339_micros(std::time::SystemTime::now()).to_string()
}
