//! The two back ends behind one small interface: SQLite (rusqlite, bundled) and PostgreSQL (the
//! synchronous `postgres` client). Every statement is a constant string with `$1, $2, ...`
//! parameters, numbered in order of first appearance (SQLite reads `$N` as a named parameter
//! whose index is its first appearance, so the same text binds the same way on both).
//!
//! Rows come back as [`Row`]s that carry their column names: a query declares the kind of each
//! column it reads by name ([`Exec::rows`]), and the caller reads a value by name
//! ([`Row::int`], [`Row::text`], ...), a missing column or a value of another kind being a
//! [`DbError`] that names the column. Every failure of the executor is a [`DbError`].

use rusqlite::types::{ToSql as SqliteToSql, ToSqlOutput};
use std::sync::Arc;
use thiserror::Error;

/// Why a statement or the reading of a row failed. Messages are the database's own (never the
/// location, so never a password) or name a column.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum DbError {
    /// SQLite refused or failed (its message).
    #[error("{0}")]
    Sqlite(String),
    /// PostgreSQL refused or failed (the server's message, else the client's).
    #[error("{0}")]
    Postgres(String),
    /// SQLite kept another journal mode than write-ahead logging.
    #[error("cannot use write-ahead logging (journal mode stays '{mode}')")]
    JournalMode {
        /// The journal mode SQLite reported.
        mode: String,
    },
    /// Columns of one insert have different lengths.
    #[error("columns of unequal length in one insert")]
    UnequalColumns,
    /// A column declared or read is not in the result.
    #[error("column {column:?} is not in the result (it has: {found})")]
    MissingColumn {
        /// The column asked for.
        column: String,
        /// The result's columns, comma-separated.
        found: String,
    },
    /// The result has a column whose kind was not declared.
    #[error("column {column:?} of the result has no declared kind")]
    UndeclaredColumn {
        /// The column.
        column: String,
    },
    /// A column was read as another kind than it holds.
    #[error("column {column:?} holds {found}, read as {wanted}")]
    WrongKind {
        /// The column.
        column: String,
        /// The kind asked for.
        wanted: &'static str,
        /// The kind it holds.
        found: &'static str,
    },
    /// A row read is not what the store wrote (a value out of its range, an unknown name).
    #[error("{0}")]
    Invalid(String),
}

impl From<rusqlite::Error> for DbError {
    fn from(e: rusqlite::Error) -> Self {
        DbError::Sqlite(e.to_string())
    }
}

impl From<postgres::Error> for DbError {
    fn from(e: postgres::Error) -> Self {
        DbError::Postgres(match e.as_db_error() {
            Some(db) => db.message().to_string(),
            None => e.to_string(),
        })
    }
}

impl From<DbError> for String {
    fn from(e: DbError) -> Self {
        e.to_string()
    }
}

/// A parameter or a column value.
#[derive(Debug, Clone, PartialEq)]
pub enum Val {
    /// 64-bit integer (INTEGER / BIGINT).
    I(i64),
    /// Optional 64-bit integer (a null reference).
    IOpt(Option<i64>),
    /// Optional double (REAL / DOUBLE PRECISION).
    F(Option<f64>),
    /// Optional text (TEXT).
    T(Option<String>),
    /// Optional bytes (BLOB / BYTEA).
    B(Option<Vec<u8>>),
}

impl Val {
    /// Text of a value (`None` for null or a number).
    pub fn text(&self) -> Option<&str> {
        match self {
            Val::T(t) => t.as_deref(),
            _ => None,
        }
    }
    /// Integer of a value (0 for anything else).
    pub fn int(&self) -> i64 {
        match self {
            Val::I(i) => *i,
            Val::IOpt(i) => i.unwrap_or(0),
            _ => 0,
        }
    }
    /// Double of a value.
    pub fn float(&self) -> Option<f64> {
        match self {
            Val::F(f) => *f,
            Val::I(i) => Some(*i as f64),
            Val::IOpt(i) => i.map(|i| i as f64),
            _ => None,
        }
    }
    /// Owned text (empty for null).
    pub fn string(&self) -> String {
        self.text().unwrap_or_default().to_string()
    }
    /// Bytes of a value (`None` for null or anything else).
    pub fn bytes(&self) -> Option<&[u8]> {
        match self {
            Val::B(b) => b.as_deref(),
            _ => None,
        }
    }
}

/// The kind of a result column, to read it on either back end.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// 64-bit integer.
    I,
    /// Optional 64-bit integer (null kept as null).
    IOpt,
    /// Optional double.
    F,
    /// Optional text.
    T,
    /// Optional bytes.
    B,
}

/// One column of rows inserted together: a typed array (PostgreSQL receives it as one array
/// parameter).
#[derive(Debug, Clone, PartialEq)]
pub enum Column {
    /// 64-bit integers (BIGINT[]).
    I(Vec<i64>),
    /// Optional doubles (DOUBLE PRECISION[]).
    F(Vec<Option<f64>>),
    /// Optional texts (TEXT[]).
    T(Vec<Option<String>>),
    /// Optional bytes (BYTEA[]).
    B(Vec<Option<Vec<u8>>>),
}

impl Column {
    fn len(&self) -> usize {
        match self {
            Column::I(v) => v.len(),
            Column::F(v) => v.len(),
            Column::T(v) => v.len(),
            Column::B(v) => v.len(),
        }
    }

    fn value(&self, row: usize) -> Val {
        match self {
            Column::I(v) => Val::I(v[row]),
            Column::F(v) => Val::F(v[row]),
            Column::T(v) => Val::T(v[row].clone()),
            Column::B(v) => Val::B(v[row].clone()),
        }
    }
}

impl Kind {
    /// The kind's name in messages.
    pub fn as_str(self) -> &'static str {
        match self {
            Kind::I => "an integer",
            Kind::IOpt => "an optional integer",
            Kind::F => "a number",
            Kind::T => "a text",
            Kind::B => "bytes",
        }
    }
}

impl Val {
    /// The kind of a value (as a column of that kind reads it).
    pub fn kind(&self) -> Kind {
        match self {
            Val::I(_) => Kind::I,
            Val::IOpt(_) => Kind::IOpt,
            Val::F(_) => Kind::F,
            Val::T(_) => Kind::T,
            Val::B(_) => Kind::B,
        }
    }
}

/// The columns a query reads, each by its name in the result (`SELECT ... AS name`) with the
/// kind it is read as.
pub type Columns<'a> = &'a [(&'a str, Kind)];

/// One row of a result, with the names of its columns (shared by every row of the result).
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    names: Arc<[String]>,
    vals: Vec<Val>,
}

impl Row {
    /// A row of `vals` under `names` (the same length).
    pub fn new(names: Arc<[String]>, vals: Vec<Val>) -> Row {
        Row { names, vals }
    }

    /// The names of its columns, in the result's order.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// Its values, in the result's order.
    pub fn values(&self) -> &[Val] {
        &self.vals
    }

    /// The value of column `name`, or [`DbError::MissingColumn`].
    pub fn get(&self, name: &str) -> Result<&Val, DbError> {
        match self.names.iter().position(|n| n == name) {
            Some(i) => Ok(&self.vals[i]),
            None => Err(DbError::MissingColumn { column: name.to_string(), found: self.names.join(", ") }),
        }
    }

    fn wrong(&self, name: &str, wanted: Kind, v: &Val) -> DbError {
        DbError::WrongKind { column: name.to_string(), wanted: wanted.as_str(), found: v.kind().as_str() }
    }

    /// Integer column `name` (read as [`Kind::I`], null read as 0, or a non-null [`Kind::IOpt`]).
    pub fn int(&self, name: &str) -> Result<i64, DbError> {
        match self.get(name)? {
            Val::I(i) | Val::IOpt(Some(i)) => Ok(*i),
            v => Err(self.wrong(name, Kind::I, v)),
        }
    }

    /// Optional integer column `name` ([`Kind::IOpt`] or [`Kind::I`]).
    pub fn int_opt(&self, name: &str) -> Result<Option<i64>, DbError> {
        match self.get(name)? {
            Val::I(i) => Ok(Some(*i)),
            Val::IOpt(i) => Ok(*i),
            v => Err(self.wrong(name, Kind::IOpt, v)),
        }
    }

    /// Optional double column `name` ([`Kind::F`]).
    pub fn float(&self, name: &str) -> Result<Option<f64>, DbError> {
        match self.get(name)? {
            Val::F(f) => Ok(*f),
            v => Err(self.wrong(name, Kind::F, v)),
        }
    }

    /// Optional text column `name` ([`Kind::T`]).
    pub fn text(&self, name: &str) -> Result<Option<&str>, DbError> {
        match self.get(name)? {
            Val::T(t) => Ok(t.as_deref()),
            v => Err(self.wrong(name, Kind::T, v)),
        }
    }

    /// Text column `name` as an owned string, null read as empty ([`Kind::T`]).
    pub fn string(&self, name: &str) -> Result<String, DbError> {
        Ok(self.text(name)?.unwrap_or_default().to_string())
    }

    /// Optional text column `name` as an owned string ([`Kind::T`]).
    pub fn string_opt(&self, name: &str) -> Result<Option<String>, DbError> {
        Ok(self.text(name)?.map(str::to_string))
    }

    /// Optional bytes column `name` ([`Kind::B`]).
    pub fn bytes(&self, name: &str) -> Result<Option<&[u8]>, DbError> {
        match self.get(name)? {
            Val::B(b) => Ok(b.as_deref()),
            v => Err(self.wrong(name, Kind::B, v)),
        }
    }
}

/// A result as fetched: the names of its columns and every row's values in that order.
pub type Fetched = (Arc<[String]>, Vec<Vec<Val>>);

/// How the columns of a result are read: by name (every column of the result declared, every
/// declared column present) or by position.
#[derive(Debug, Clone, Copy)]
pub enum Decode<'a> {
    /// Each column of the result by its name.
    ByName(Columns<'a>),
    /// The result's columns in order (tools and tests that build their own statements).
    ByPosition(&'a [Kind]),
}

impl Decode<'_> {
    /// The kind of each of the result's columns `names`, or why not.
    fn kinds(&self, names: &[String]) -> Result<Vec<Kind>, DbError> {
        match self {
            Decode::ByPosition(kinds) => Ok(kinds.to_vec()),
            Decode::ByName(columns) => {
                if let Some((missing, _)) = columns.iter().find(|(c, _)| !names.iter().any(|n| n == c)) {
                    return Err(DbError::MissingColumn { column: missing.to_string(), found: names.join(", ") });
                }
                names
                    .iter()
                    .map(|n| {
                        columns
                            .iter()
                            .find(|(c, _)| c == n)
                            .map(|(_, k)| *k)
                            .ok_or_else(|| DbError::UndeclaredColumn { column: n.clone() })
                    })
                    .collect()
            }
        }
    }
}

/// The number of rows of equal-length columns, or why not.
fn rows_of(columns: &[Column]) -> Result<usize, DbError> {
    let n = columns.first().map_or(0, Column::len);
    if columns.iter().any(|c| c.len() != n) {
        return Err(DbError::UnequalColumns);
    }
    Ok(n)
}

/// Something that runs statements: a connection or a transaction of either back end.
pub trait Exec {
    /// Runs a statement; the number of rows changed.
    fn exec(&mut self, sql: &str, params: &[Val]) -> Result<u64, DbError>;
    /// Runs a query; the names of the result's columns and every row's values, read as `decode`
    /// says.
    fn fetch(&mut self, sql: &str, params: &[Val], decode: Decode<'_>) -> Result<Fetched, DbError>;
    /// Runs several statements without parameters (schema changes).
    fn batch(&mut self, sql: &str) -> Result<(), DbError>;
    /// Inserts rows given as columns: SQLite runs `row_sql` (one row's `$1..$n`) once per row
    /// (prepared once, in process); PostgreSQL runs `array_sql` once, with each column as one
    /// array parameter (`INSERT ... SELECT * FROM unnest($1::bigint[], ...)`), one round trip
    /// whatever the number of rows. The number of rows inserted.
    fn insert_columns(&mut self, row_sql: &str, array_sql: &str, columns: &[Column]) -> Result<u64, DbError>;

    /// Runs a query whose columns are read by name: `columns` names every column of the result
    /// with its kind; each row carries the names ([`Row::get`]).
    fn rows(&mut self, sql: &str, params: &[Val], columns: Columns<'_>) -> Result<Vec<Row>, DbError> {
        let (names, rows) = self.fetch(sql, params, Decode::ByName(columns))?;
        Ok(rows.into_iter().map(|vals| Row { names: names.clone(), vals }).collect())
    }

    /// Runs a query whose columns are read by position as `kinds` (for tools and tests that
    /// build their own statements; the store reads its rows by name, [`Exec::rows`]).
    fn query(&mut self, sql: &str, params: &[Val], kinds: &[Kind]) -> Result<Vec<Vec<Val>>, DbError> {
        Ok(self.fetch(sql, params, Decode::ByPosition(kinds))?.1)
    }
}

impl SqliteToSql for Val {
    fn to_sql(&self) -> rusqlite::Result<ToSqlOutput<'_>> {
        match self {
            Val::I(i) => i.to_sql(),
            Val::IOpt(i) => i.to_sql(),
            Val::F(f) => f.to_sql(),
            Val::T(t) => t.to_sql(),
            Val::B(b) => b.to_sql(),
        }
    }
}

fn sqlite_row(row: &rusqlite::Row<'_>, kinds: &[Kind]) -> rusqlite::Result<Vec<Val>> {
    kinds
        .iter()
        .enumerate()
        .map(|(i, k)| {
            Ok(match k {
                Kind::I => Val::I(row.get::<_, Option<i64>>(i)?.unwrap_or(0)),
                Kind::IOpt => Val::IOpt(row.get(i)?),
                Kind::F => Val::F(row.get(i)?),
                Kind::T => Val::T(row.get(i)?),
                Kind::B => Val::B(row.get(i)?),
            })
        })
        .collect()
}

/// SQLite statements on a connection or a transaction (which derefs to one).
pub struct SqliteExec<'a>(pub &'a rusqlite::Connection);

impl Exec for SqliteExec<'_> {
    fn exec(&mut self, sql: &str, params: &[Val]) -> Result<u64, DbError> {
        let mut st = self.0.prepare_cached(sql)?;
        Ok(st.execute(rusqlite::params_from_iter(params.iter()))? as u64)
    }
    fn fetch(&mut self, sql: &str, params: &[Val], decode: Decode<'_>) -> Result<Fetched, DbError> {
        let mut st = self.0.prepare_cached(sql)?;
        let names: Arc<[String]> = st.column_names().into_iter().map(str::to_string).collect();
        let kinds = decode.kinds(&names)?;
        let rows = st.query_map(rusqlite::params_from_iter(params.iter()), |r| sqlite_row(r, &kinds))?;
        Ok((names, rows.collect::<rusqlite::Result<Vec<_>>>()?))
    }
    fn batch(&mut self, sql: &str) -> Result<(), DbError> {
        Ok(self.0.execute_batch(sql)?)
    }
    fn insert_columns(&mut self, row_sql: &str, _array_sql: &str, columns: &[Column]) -> Result<u64, DbError> {
        let n = rows_of(columns)?;
        let mut st = self.0.prepare_cached(row_sql)?;
        for row in 0..n {
            let params: Vec<Val> = columns.iter().map(|c| c.value(row)).collect();
            st.execute(rusqlite::params_from_iter(params.iter()))?;
        }
        Ok(n as u64)
    }
}

fn pg_params(params: &[Val]) -> Vec<Box<dyn postgres::types::ToSql + Sync>> {
    params
        .iter()
        .map(|p| -> Box<dyn postgres::types::ToSql + Sync> {
            match p {
                Val::I(i) => Box::new(*i),
                Val::IOpt(i) => Box::new(*i),
                Val::F(f) => Box::new(*f),
                Val::T(t) => Box::new(t.clone()),
                Val::B(b) => Box::new(b.clone()),
            }
        })
        .collect()
}

/// Prepared statements of one PostgreSQL connection, by their SQL text (a statement is prepared
/// once per connection, then each use is one round trip instead of two; prepared statements are
/// not undone by a rollback).
pub type PgStatements = std::collections::HashMap<String, postgres::Statement>;

/// PostgreSQL statements on a client or a transaction, with the connection's prepared statements.
pub struct PgExec<'a, C: postgres::GenericClient>(pub &'a mut C, pub &'a mut PgStatements);

impl<C: postgres::GenericClient> PgExec<'_, C> {
    fn statement(&mut self, sql: &str) -> Result<postgres::Statement, DbError> {
        if let Some(st) = self.1.get(sql) {
            return Ok(st.clone());
        }
        let st = self.0.prepare(sql)?;
        self.1.insert(sql.to_string(), st.clone());
        Ok(st)
    }
}

fn pg_value(r: &postgres::Row, i: usize, k: Kind) -> Result<Val, DbError> {
    Ok(match k {
        Kind::I => Val::I(r.try_get::<_, Option<i64>>(i)?.unwrap_or(0)),
        Kind::IOpt => Val::IOpt(r.try_get(i)?),
        Kind::F => Val::F(r.try_get(i)?),
        Kind::T => Val::T(r.try_get(i)?),
        Kind::B => Val::B(r.try_get(i)?),
    })
}

impl<C: postgres::GenericClient> Exec for PgExec<'_, C> {
    fn exec(&mut self, sql: &str, params: &[Val]) -> Result<u64, DbError> {
        let st = self.statement(sql)?;
        let p = pg_params(params);
        let refs: Vec<&(dyn postgres::types::ToSql + Sync)> = p.iter().map(|b| b.as_ref()).collect();
        Ok(self.0.execute(&st, &refs)?)
    }
    fn fetch(&mut self, sql: &str, params: &[Val], decode: Decode<'_>) -> Result<Fetched, DbError> {
        let st = self.statement(sql)?;
        let names: Arc<[String]> = st.columns().iter().map(|c| c.name().to_string()).collect();
        let kinds = decode.kinds(&names)?;
        let p = pg_params(params);
        let refs: Vec<&(dyn postgres::types::ToSql + Sync)> = p.iter().map(|b| b.as_ref()).collect();
        let rows = self.0.query(&st, &refs)?;
        let vals = rows
            .iter()
            .map(|r| kinds.iter().enumerate().map(|(i, k)| pg_value(r, i, *k)).collect())
            .collect::<Result<Vec<Vec<Val>>, DbError>>()?;
        Ok((names, vals))
    }
    fn batch(&mut self, sql: &str) -> Result<(), DbError> {
        Ok(self.0.batch_execute(sql)?)
    }
    fn insert_columns(&mut self, _row_sql: &str, array_sql: &str, columns: &[Column]) -> Result<u64, DbError> {
        if rows_of(columns)? == 0 {
            return Ok(0);
        }
        let st = self.statement(array_sql)?;
        let p: Vec<Box<dyn postgres::types::ToSql + Sync>> = columns
            .iter()
            .map(|c| -> Box<dyn postgres::types::ToSql + Sync> {
                match c {
                    Column::I(v) => Box::new(v.clone()),
                    Column::F(v) => Box::new(v.clone()),
                    Column::T(v) => Box::new(v.clone()),
                    Column::B(v) => Box::new(v.clone()),
                }
            })
            .collect();
        let refs: Vec<&(dyn postgres::types::ToSql + Sync)> = p.iter().map(|b| b.as_ref()).collect();
        Ok(self.0.execute(&st, &refs)?)
    }
}

impl From<String> for DbError {
    fn from(m: String) -> Self {
        DbError::Invalid(m)
    }
}

impl From<&str> for DbError {
    fn from(m: &str) -> Self {
        DbError::Invalid(m.to_string())
    }
}

/// The `id` of the first row of an `INSERT ... RETURNING id`, or why not.
pub fn returned_id(rows: &[Row]) -> Result<i64, DbError> {
    rows.first().ok_or(DbError::Invalid("no id returned".into()))?.int("id")
}

/// The integer column `name` of the first row, or `default` without a row (`SELECT COUNT(*)`,
/// `SELECT COALESCE(MAX(...), 0)`).
pub fn first_int(rows: &[Row], name: &str, default: i64) -> Result<i64, DbError> {
    rows.first().map_or(Ok(default), |r| r.int(name))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn conn() -> rusqlite::Connection {
        let c = rusqlite::Connection::open_in_memory().expect("in-memory SQLite"); // ok: test
        c.execute_batch("CREATE TABLE t (id INTEGER, serial TEXT, value REAL); INSERT INTO t VALUES (7, 'SN-1', 1.5);")
            .expect("table"); // ok: test
        c
    }

    #[test]
    fn rows_are_read_by_name_whatever_the_order() {
        let c = conn();
        let cols: Columns<'_> = &[("value", Kind::F), ("id", Kind::I), ("serial", Kind::T)];
        let rows = SqliteExec(&c).rows("SELECT serial, id, value FROM t", &[], cols).expect("rows"); // ok: test
        let r = &rows[0];
        assert_eq!(r.names(), ["serial", "id", "value"]);
        assert_eq!(r.int("id"), Ok(7));
        assert_eq!(r.string("serial").as_deref(), Ok("SN-1"));
        assert_eq!(r.float("value"), Ok(Some(1.5)));
    }

    #[test]
    fn a_missing_or_undeclared_column_or_another_kind_is_an_error_naming_the_column() {
        let c = conn();
        let rows = SqliteExec(&c).rows("SELECT id, serial FROM t", &[], &[("id", Kind::I), ("serial", Kind::T)]);
        let r = &rows.expect("rows")[0]; // ok: test
        let e = r.int("lot").unwrap_err();
        assert!(matches!(&e, DbError::MissingColumn { column, .. } if column == "lot"), "{e:?}");
        assert!(e.to_string().contains("\"lot\"") && e.to_string().contains("id, serial"), "{e}");
        let e = r.int("serial").unwrap_err();
        assert!(matches!(&e, DbError::WrongKind { column, .. } if column == "serial"), "{e:?}");
        assert!(e.to_string().contains("\"serial\" holds a text, read as an integer"), "{e}");
        let e = SqliteExec(&c).rows("SELECT id FROM t", &[], &[("id", Kind::I), ("lot", Kind::T)]).unwrap_err();
        assert!(matches!(&e, DbError::MissingColumn { column, .. } if column == "lot"), "{e:?}");
        let e = SqliteExec(&c).rows("SELECT id, serial FROM t", &[], &[("id", Kind::I)]).unwrap_err();
        assert_eq!(e, DbError::UndeclaredColumn { column: "serial".into() });
    }

    #[test]
    fn failures_are_typed() {
        let c = conn();
        let e = SqliteExec(&c).exec("INSERT INTO nowhere VALUES (1)", &[]).unwrap_err();
        assert!(matches!(&e, DbError::Sqlite(m) if m.contains("nowhere")), "{e:?}");
        let e = SqliteExec(&c).insert_columns("", "", &[Column::I(vec![1]), Column::T(vec![])]).unwrap_err();
        assert_eq!(e, DbError::UnequalColumns);
    }
}
