//! The schema and its migrations, one list per back end (the same tables; only the column types
//! of keys and the immutability triggers are written differently). Migration N brings a store
//! from version N - 1 to N; `gyrolab_schema` keeps one row per applied version, with the name and
//! the SHA-256 of the migration's SQL, checked on every open (docs/STORE.md).
//!
//! The SQL of each migration is a file, `migrations/sqlite/NNNN_name.sql` and
//! `migrations/postgres/NNNN_name.sql`, embedded at build time. A migration's file is never
//! edited once released: a store that recorded its checksum would be refused.

/// One migration: its version, its name and its SQL (embedded from its file).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Migration {
    /// The version it brings a store to (1 for the first).
    pub version: i64,
    /// Its name, as in its file name after the version (`records` of `0001_records.sql`).
    pub name: &'static str,
    /// Its file, relative to the crate (`migrations/sqlite/0001_records.sql`).
    pub file: &'static str,
    /// Its SQL, the file's text exactly.
    pub sql: &'static str,
}

impl Migration {
    /// SHA-256 of its SQL text, lower-case hex (what `gyrolab_schema.sha256` records).
    pub fn sha256(&self) -> String {
        gyrolab_io::input_file::sha256_hex(self.sql.as_bytes())
    }
}

/// One row of `gyrolab_schema` as a store records it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RecordedMigration {
    /// The version applied.
    pub version: i64,
    /// The migration's name (null until a build with checksums opened the store).
    pub name: Option<String>,
    /// SHA-256 (hex) of the SQL applied (null until a build with checksums opened the store).
    pub sha256: Option<String>,
}

/// A migration of back end `$dir` from `migrations/$dir/$file`.
macro_rules! migration {
    ($dir:literal, $version:literal, $name:literal, $file:literal) => {
        Migration {
            version: $version,
            name: $name,
            file: concat!("migrations/", $dir, "/", $file),
            sql: include_str!(concat!("../migrations/", $dir, "/", $file)),
        }
    };
}

/// SQLite migrations, by version (index 0 = version 1).
pub const SQLITE_MIGRATIONS: &[Migration] = &[
    migration!("sqlite", 1, "records", "0001_records.sql"),
    // 2: the report files themselves (zstd-compressed), so that a stored report can be written
    // back; rows stored under version 1 keep a null (their files were hashed only).
    // Input and report file rows are kept like evaluations and figures.
    migration!("sqlite", 2, "report_contents", "0002_report_contents.sql"),
    // 3 (issue 53): tamper evidence. Every file and figure row gets a stable `id` (its rowid at
    // migration; new rows: the next id, given by the store), the hash chain `chain` (one link
    // per stored row, appended by the store: crate::chain), INSERT refused over an existing key
    // (INSERT OR REPLACE deletes the old row without firing the DELETE triggers), and the chain
    // kept like the records. The chain over the rows already stored is built by the store right
    // after this script (crate::chain::build_existing), in the same transaction.
    migration!("sqlite", 3, "tamper_evidence", "0003_tamper_evidence.sql"),
    // 4 (issue 53): accounts, the audit trail, the lab's public keys and issued reports. Every
    // row is a record (chained, never changed: a disabled account or a new password is a new
    // `account_change` row). Times come from the database's clock (the column defaults).
    migration!("sqlite", 4, "accounts_and_issues", "0004_accounts_and_issues.sql"),
    // 5 (issue 53): no change on SQLite, whose indexes take a text of any length (the serial
    // and lot indexes are made hash indexes on PostgreSQL, whose B-tree rows stop at 2.7 KB).
    migration!("sqlite", 5, "serial_lot_hash_indexes", "0005_serial_lot_hash_indexes.sql"),
    // 6 (issue 53): the raw records kept, content-addressed: one zstd-compressed copy per
    // SHA-256 (`input_content`, chained with the evaluation that first brought it), so that an
    // audit or `store reevaluate` reproduces a report from the store alone.
    migration!("sqlite", 6, "input_contents", "0006_input_contents.sql"),
];

/// PostgreSQL migrations, by version (index 0 = version 1).
pub const POSTGRES_MIGRATIONS: &[Migration] = &[
    migration!("postgres", 1, "records", "0001_records.sql"),
    // 2: the report files themselves (zstd-compressed; see SQLITE_MIGRATIONS); input and report
    // file rows kept like evaluations and figures.
    migration!("postgres", 2, "report_contents", "0002_report_contents.sql"),
    // 3 (issue 53): tamper evidence (see SQLITE_MIGRATIONS): a stable `id` for file and figure
    // rows (rows already stored are numbered in the order PostgreSQL reads them), the hash chain,
    // and TRUNCATE refused on every table (it fires no row trigger).
    migration!("postgres", 3, "tamper_evidence", "0003_tamper_evidence.sql"),
    // 4 (issue 53): accounts, the audit trail, the lab's public keys and issued reports (see
    // SQLITE_MIGRATIONS); times from the server's clock.
    migration!("postgres", 4, "accounts_and_issues", "0004_accounts_and_issues.sql"),
    // 5 (issue 53): the serial and lot indexes as hash indexes: a B-tree index row stops at
    // about 2.7 KB, so a longer serial (SQLite takes 16 MiB) was refused; every query of them is
    // an equality.
    migration!("postgres", 5, "serial_lot_hash_indexes", "0005_serial_lot_hash_indexes.sql"),
    // 6 (issue 53): the raw records kept, content-addressed (see SQLITE_MIGRATIONS).
    migration!("postgres", 6, "input_contents", "0006_input_contents.sql"),
];

/// The schema version this build writes and reads: the number of migrations.
pub const SCHEMA_VERSION: i64 = SQLITE_MIGRATIONS.len() as i64;

// Both back ends have the same migrations, numbered 1, 2, ... in order.
const _: () = {
    assert!(SQLITE_MIGRATIONS.len() == POSTGRES_MIGRATIONS.len(), "one migration per back end and version");
    let mut i = 0;
    while i < SQLITE_MIGRATIONS.len() {
        assert!(SQLITE_MIGRATIONS[i].version == i as i64 + 1, "SQLite migrations numbered 1, 2, ...");
        assert!(POSTGRES_MIGRATIONS[i].version == i as i64 + 1, "PostgreSQL migrations numbered 1, 2, ...");
        i += 1;
    }
};

/// The migrations of a back end.
pub fn migrations(postgres: bool) -> &'static [Migration] {
    if postgres {
        POSTGRES_MIGRATIONS
    } else {
        SQLITE_MIGRATIONS
    }
}

/// Columns added to [`VERSION_TABLE`] since the first builds, each with the statement that adds
/// it (run on open, in the migrating transaction, when the column is missing): the migration's
/// name and the SHA-256 of its SQL. Rows of versions applied before get them filled from the
/// embedded migrations (adoption).
pub const VERSION_TABLE_COLUMNS: &[(&str, &str)] = &[
    ("name", "ALTER TABLE gyrolab_schema ADD COLUMN name TEXT"),
    ("sha256", "ALTER TABLE gyrolab_schema ADD COLUMN sha256 TEXT"),
];

/// One row (`one` = 1) when the version table exists, none otherwise: a look-up that needs no
/// privilege beyond reading the catalogue.
pub fn version_table_exists_sql(postgres: bool) -> &'static str {
    if postgres {
        "SELECT 1::bigint AS one WHERE to_regclass('gyrolab_schema') IS NOT NULL"
    } else {
        "SELECT 1 AS one FROM sqlite_master WHERE type = 'table' AND name = 'gyrolab_schema'"
    }
}

/// The columns of `gyrolab_schema` as the store has them (parameter `$1`: the table's name).
pub fn version_table_columns_sql(postgres: bool) -> &'static str {
    if postgres {
        "SELECT column_name::text AS name FROM information_schema.columns WHERE table_schema = current_schema() \
         AND table_name = $1"
    } else {
        "SELECT name FROM pragma_table_info($1)"
    }
}

/// The version table (both back ends) as the first builds made it: one row per applied version.
/// A store of any build is opened through this statement, then given the columns of
/// [`VERSION_TABLE_COLUMNS`] that it lacks.
pub const VERSION_TABLE: &str =
    "CREATE TABLE IF NOT EXISTS gyrolab_schema (version BIGINT NOT NULL PRIMARY KEY, applied_at TEXT NOT NULL, software_version TEXT NOT NULL)";

/// The database's clock as RFC 3339 UTC text to the millisecond (the column defaults of
/// migration 4 use the same expression): the time every account, audit event and issue records,
/// as the column `now`.
pub fn clock_sql(postgres: bool) -> &'static str {
    if postgres {
        "SELECT to_char(clock_timestamp() AT TIME ZONE 'UTC', 'YYYY-MM-DD\"T\"HH24:MI:SS.MS\"Z\"') AS now"
    } else {
        "SELECT strftime('%Y-%m-%dT%H:%M:%fZ', 'now') AS now"
    }
}
