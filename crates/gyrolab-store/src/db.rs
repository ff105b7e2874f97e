//! The two back ends behind one small interface: SQLite (rusqlite, bundled) and PostgreSQL (the
//! synchronous `postgres` client). Every statement is a constant string with `$1, $2, ...`
//! parameters, numbered in order of first appearance (SQLite reads `$N` as a named parameter
//! whose index is its first appearance, so the same text binds the same way on both).

use rusqlite::types::{ToSql as SqliteToSql, ToSqlOutput};

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

/// The number of rows of equal-length columns, or why not.
fn rows_of(columns: &[Column]) -> Result<usize, String> {
    let n = columns.first().map_or(0, Column::len);
    if columns.iter().any(|c| c.len() != n) {
        return Err("columns of unequal length in one insert".into());
    }
    Ok(n)
}

/// Something that runs statements: a connection or a transaction of either back end.
pub trait Exec {
    /// Runs a statement; the number of rows changed.
    fn exec(&mut self, sql: &str, params: &[Val]) -> Result<u64, String>;
    /// Runs a query; every row read as `kinds`.
    fn query(&mut self, sql: &str, params: &[Val], kinds: &[Kind]) -> Result<Vec<Vec<Val>>, String>;
    /// Runs several statements without parameters (schema changes).
    fn batch(&mut self, sql: &str) -> Result<(), String>;
    /// Inserts rows given as columns: SQLite runs `row_sql` (one row's `$1..$n`) once per row
    /// (prepared once, in process); PostgreSQL runs `array_sql` once, with each column as one
    /// array parameter (`INSERT ... SELECT * FROM unnest($1::bigint[], ...)`), one round trip
    /// whatever the number of rows. The number of rows inserted.
    fn insert_columns(&mut self, row_sql: &str, array_sql: &str, columns: &[Column]) -> Result<u64, String>;
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
    fn exec(&mut self, sql: &str, params: &[Val]) -> Result<u64, String> {
        let mut st = self.0.prepare_cached(sql).map_err(|e| e.to_string())?;
        st.execute(rusqlite::params_from_iter(params.iter())).map(|n| n as u64).map_err(|e| e.to_string())
    }
    fn query(&mut self, sql: &str, params: &[Val], kinds: &[Kind]) -> Result<Vec<Vec<Val>>, String> {
        let mut st = self.0.prepare_cached(sql).map_err(|e| e.to_string())?;
        let rows = st
            .query_map(rusqlite::params_from_iter(params.iter()), |r| sqlite_row(r, kinds))
            .map_err(|e| e.to_string())?;
        rows.collect::<rusqlite::Result<Vec<_>>>().map_err(|e| e.to_string())
    }
    fn batch(&mut self, sql: &str) -> Result<(), String> {
        self.0.execute_batch(sql).map_err(|e| e.to_string())
    }
    fn insert_columns(&mut self, row_sql: &str, _array_sql: &str, columns: &[Column]) -> Result<u64, String> {
        let n = rows_of(columns)?;
        let mut st = self.0.prepare_cached(row_sql).map_err(|e| e.to_string())?;
        for row in 0..n {
            let params: Vec<Val> = columns.iter().map(|c| c.value(row)).collect();
            st.execute(rusqlite::params_from_iter(params.iter())).map_err(|e| e.to_string())?;
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

fn pg_error(e: postgres::Error) -> String {
    match e.as_db_error() {
        Some(db) => db.message().to_string(),
        None => e.to_string(),
    }
}

/// Prepared statements of one PostgreSQL connection, by their SQL text (a statement is prepared
/// once per connection, then each use is one round trip instead of two; prepared statements are
/// not undone by a rollback).
pub type PgStatements = std::collections::HashMap<String, postgres::Statement>;

/// PostgreSQL statements on a client or a transaction, with the connection's prepared statements.
pub struct PgExec<'a, C: postgres::GenericClient>(pub &'a mut C, pub &'a mut PgStatements);

impl<C: postgres::GenericClient> PgExec<'_, C> {
    fn statement(&mut self, sql: &str) -> Result<postgres::Statement, String> {
        if let Some(st) = self.1.get(sql) {
            return Ok(st.clone());
        }
        let st = self.0.prepare(sql).map_err(pg_error)?;
        self.1.insert(sql.to_string(), st.clone());
        Ok(st)
    }
}

impl<C: postgres::GenericClient> Exec for PgExec<'_, C> {
    fn exec(&mut self, sql: &str, params: &[Val]) -> Result<u64, String> {
        let st = self.statement(sql)?;
        let p = pg_params(params);
        let refs: Vec<&(dyn postgres::types::ToSql + Sync)> = p.iter().map(|b| b.as_ref()).collect();
        self.0.execute(&st, &refs).map_err(pg_error)
    }
    fn query(&mut self, sql: &str, params: &[Val], kinds: &[Kind]) -> Result<Vec<Vec<Val>>, String> {
        let st = self.statement(sql)?;
        let p = pg_params(params);
        let refs: Vec<&(dyn postgres::types::ToSql + Sync)> = p.iter().map(|b| b.as_ref()).collect();
        let rows = self.0.query(&st, &refs).map_err(pg_error)?;
        rows.iter()
            .map(|r| {
                kinds
                    .iter()
                    .enumerate()
                    .map(|(i, k)| {
                        Ok(match k {
                            Kind::I => Val::I(r.try_get::<_, Option<i64>>(i).map_err(pg_error)?.unwrap_or(0)),
                            Kind::IOpt => Val::IOpt(r.try_get(i).map_err(pg_error)?),
                            Kind::F => Val::F(r.try_get(i).map_err(pg_error)?),
                            Kind::T => Val::T(r.try_get(i).map_err(pg_error)?),
                            Kind::B => Val::B(r.try_get(i).map_err(pg_error)?),
                        })
                    })
                    .collect()
            })
            .collect()
    }
    fn batch(&mut self, sql: &str) -> Result<(), String> {
        self.0.batch_execute(sql).map_err(pg_error)
    }
    fn insert_columns(&mut self, _row_sql: &str, array_sql: &str, columns: &[Column]) -> Result<u64, String> {
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
        self.0.execute(&st, &refs).map_err(pg_error)
    }
}
