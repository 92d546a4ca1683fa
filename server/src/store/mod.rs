//! Repositories: the only place with SQL. Handlers call these functions with the [`Db`] they
//! hold; each function runs its statement on whichever store that is. Where SQLite and
//! PostgreSQL accept the same text (`$1` placeholders work in both) it is written once; where
//! they differ (timestamps, upserts, the queue's leases) each store has its own static SQL.

pub mod jobs;
pub mod machines;
pub mod materials;
pub mod outputs;
pub mod packed;
pub mod tools;

use crate::db::Db;
use crate::error::{AppError, AppResult};

/// Runs one statement on the store `$db` is: `sqlx::$make` (`query` or `query_as`) over the
/// SQL for that store (`both:` one text, or `sqlite:` and `postgres:` each their own), with the
/// arguments bound in order, finished by `$run` (`fetch_one`, ..., or `execute`: the rows affected). Evaluates to the
/// `Result` of `$run`, known only once the statement (and with it its implicit commit) ended. Both stores take the same arguments; SQLite leaves those its text does not
/// name unused (the worker and lease of the queue's statements: it has one process, no leases).
macro_rules! on {
    // `execute` answers the number of rows affected, the same type for both stores.
    ($db:expr, query, sqlite: $sqlite:expr, postgres: $postgres:expr, [$($bind:expr),* $(,)?], execute) => {
        match $db {
            $crate::db::Db::Sqlite(pool) => {
                sqlx::query($sqlite)$(.bind($bind))*.execute(pool).await.map(|done| done.rows_affected())
            }
            $crate::db::Db::Postgres(pool) => {
                sqlx::query($postgres)$(.bind($bind))*.execute(pool).await.map(|done| done.rows_affected())
            }
        }
    };
    // A statement that answers rows is driven to its end (`fetch_all`) even when one row is
    // wanted: outside a transaction the store commits only at the statement's end, so an
    // `INSERT … RETURNING` read with `fetch_one` would hand back its row before a commit that may
    // still fail (a full disk), and that failure would be lost. Reads cost nothing more: every
    // `fetch_one`/`fetch_optional` here reads one row by key.
    ($db:expr, $make:ident, sqlite: $sqlite:expr, postgres: $postgres:expr, [$($bind:expr),* $(,)?], fetch_one) => {
        on!($db, $make, sqlite: $sqlite, postgres: $postgres, [$($bind),*], fetch_all)
            .and_then(|rows| rows.into_iter().next().ok_or(sqlx::Error::RowNotFound))
    };
    ($db:expr, $make:ident, sqlite: $sqlite:expr, postgres: $postgres:expr, [$($bind:expr),* $(,)?], fetch_optional) => {
        on!($db, $make, sqlite: $sqlite, postgres: $postgres, [$($bind),*], fetch_all).map(|rows| rows.into_iter().next())
    };
    ($db:expr, $make:ident, both: $sql:expr, [$($bind:expr),* $(,)?], $run:ident) => {
        on!($db, $make, sqlite: $sql, postgres: $sql, [$($bind),*], $run)
    };
    ($db:expr, $make:ident, sqlite: $sqlite:expr, postgres: $postgres:expr, [$($bind:expr),* $(,)?], $run:ident) => {
        match $db {
            $crate::db::Db::Sqlite(pool) => sqlx::$make($sqlite)$(.bind($bind))*.$run(pool).await,
            $crate::db::Db::Postgres(pool) => sqlx::$make($postgres)$(.bind($bind))*.$run(pool).await,
        }
    };
}
pub(crate) use on;

/// How often a guarded write reads again when a concurrent writer created the item between its
/// read and its insert (each time the guard sees the new item) before it answers 409.
pub const WRITE_ATTEMPTS: u32 = 3;

/// A value bound to a registry statement (the same on both stores).
#[derive(Debug, Clone, Copy)]
pub(crate) enum Bind<'a> {
    Integer(i64),
    Real(f64),
    OptionalReal(Option<f64>),
    Text(&'a str),
    OptionalText(Option<&'a str>),
}

/// `$query` with each of `$binds` ([`Bind`]) bound in order.
macro_rules! bound {
    ($query:expr, $binds:expr) => {{
        let mut query = $query;
        for value in $binds {
            query = match *value {
                $crate::store::Bind::Integer(v) => query.bind(v),
                $crate::store::Bind::Real(v) => query.bind(v),
                $crate::store::Bind::OptionalReal(v) => query.bind(v),
                $crate::store::Bind::Text(v) => query.bind(v),
                $crate::store::Bind::OptionalText(v) => query.bind(v),
            };
        }
        query
    }};
}

/// The statements of one registry table (tools, machines, materials) that its guarded writes run.
/// Each takes the item's key as `$1`; `update` and `insert` take the stored columns after it, in
/// the order the write's values are given. `insert` does nothing on a key already stored.
pub(crate) struct Registry {
    /// What an item is called in a conflict ("tool 7", "machine \"mill\"").
    pub item: String,
    /// The stored row of the key (SQLite).
    pub select_sqlite: &'static str,
    /// The stored row of the key, locked until the commit (PostgreSQL: `FOR UPDATE`).
    pub select_postgres: &'static str,
    /// Replaces the stored row, counting its revision (SQLite).
    pub update_sqlite: &'static str,
    /// Replaces the stored row, counting its revision (PostgreSQL).
    pub update_postgres: &'static str,
    /// Stores a new row (`ON CONFLICT DO NOTHING`).
    pub insert: &'static str,
    /// Removes the row.
    pub delete: &'static str,
}

/// Stores `values` under `key` if `guard` accepts the item stored under it now (`None`: none
/// is), and says whether it was new. The read, the guard and the write are one transaction
/// (SQLite: `BEGIN IMMEDIATE`, the write lock from the read on; PostgreSQL: the read holds the
/// row `FOR UPDATE`, and a key not stored yet is claimed by the insert, which waits for a
/// concurrent one and then does nothing), so no other write falls between what the guard saw and
/// what is written. A key created by another writer between the read and the insert is read and
/// guarded again, up to [`WRITE_ATTEMPTS`] times, then 409.
pub(crate) async fn guarded_put<R, T>(
    db: &Db,
    registry: &Registry,
    key: Bind<'_>,
    values: &[Bind<'_>],
    decode: impl Fn(R) -> AppResult<T>,
    guard: impl Fn(Option<&T>) -> AppResult<()>,
) -> AppResult<bool>
where
    R: for<'r> sqlx::FromRow<'r, sqlx::sqlite::SqliteRow> + for<'r> sqlx::FromRow<'r, sqlx::postgres::PgRow>,
    R: Send + Unpin,
{
    let row: Vec<Bind<'_>> = std::iter::once(key).chain(values.iter().copied()).collect();
    macro_rules! put_in {
        ($begin:expr, $select:expr, $update:expr) => {{
            let mut transaction = $begin.await?;
            let mut attempts = 0;
            let created = loop {
                let stored: Option<R> =
                    bound!(sqlx::query_as($select), &[key]).fetch_optional(&mut *transaction).await?;
                let current = stored.map(&decode).transpose()?;
                guard(current.as_ref())?;
                if current.is_some() {
                    bound!(sqlx::query($update), &row).execute(&mut *transaction).await?;
                    break false;
                }
                let inserted = bound!(sqlx::query(registry.insert), &row).execute(&mut *transaction).await?;
                if inserted.rows_affected() == 1 {
                    break true;
                }
                // Another writer stored the key after the read: read it again and guard that.
                attempts += 1;
                if attempts == WRITE_ATTEMPTS {
                    return Err(AppError::Conflict(format!("{} was written concurrently; try again", registry.item)));
                }
            };
            transaction.commit_checked().await?;
            Ok(created)
        }};
    }
    match db {
        Db::Sqlite(pool) => {
            put_in!(pool.begin_with("BEGIN IMMEDIATE"), registry.select_sqlite, registry.update_sqlite)
        }
        Db::Postgres(pool) => put_in!(pool.begin(), registry.select_postgres, registry.update_postgres),
    }
}

/// Deletes the item under `key` if `guard` accepts the item stored now (`None`: none is), in
/// one transaction as [`guarded_put`]; false if there was none.
pub(crate) async fn guarded_delete<R, T>(
    db: &Db,
    registry: &Registry,
    key: Bind<'_>,
    decode: impl Fn(R) -> AppResult<T>,
    guard: impl Fn(Option<&T>) -> AppResult<()>,
) -> AppResult<bool>
where
    R: for<'r> sqlx::FromRow<'r, sqlx::sqlite::SqliteRow> + for<'r> sqlx::FromRow<'r, sqlx::postgres::PgRow>,
    R: Send + Unpin,
{
    macro_rules! delete_in {
        ($begin:expr, $select:expr) => {{
            let mut transaction = $begin.await?;
            let stored: Option<R> = bound!(sqlx::query_as($select), &[key]).fetch_optional(&mut *transaction).await?;
            let current = stored.map(&decode).transpose()?;
            guard(current.as_ref())?;
            let deleted = bound!(sqlx::query(registry.delete), &[key]).execute(&mut *transaction).await?;
            transaction.commit_checked().await?;
            Ok(deleted.rows_affected() > 0)
        }};
    }
    match db {
        Db::Sqlite(pool) => delete_in!(pool.begin_with("BEGIN IMMEDIATE"), registry.select_sqlite),
        Db::Postgres(pool) => delete_in!(pool.begin(), registry.select_postgres),
    }
}

/// Whether the database's schema has `table`: a database an older kerf left may lack a library
/// (`machines` came with migration 0003, `materials` with 0006) until it is migrated.
pub async fn has_table(db: &Db, table: &str) -> AppResult<bool> {
    let (count,): (i64,) = on!(db, query_as,
        sqlite: "SELECT COUNT(*) FROM sqlite_master WHERE type = 'table' AND name = $1",
        postgres: "SELECT COUNT(*) FROM information_schema.tables WHERE table_schema = current_schema() AND table_name = $1",
        [table],
        fetch_one)?;
    Ok(count > 0)
}

/// Counts of jobs by status (for the `kerf_jobs` gauge).
pub async fn job_counts(db: &Db) -> AppResult<Vec<(String, i64)>> {
    Ok(on!(db, query_as, both: "SELECT status, COUNT(*) FROM jobs GROUP BY status", [], fetch_all)?)
}

/// Commits a transaction so that a failed commit is reported and leaves its connection fit for
/// the next request.
pub(crate) trait CommitChecked {
    /// Commits; the error of a failed commit (a full disk, a lost connection) is returned.
    async fn commit_checked(self) -> Result<(), sqlx::Error>;
}

impl CommitChecked for sqlx::Transaction<'_, sqlx::Postgres> {
    async fn commit_checked(self) -> Result<(), sqlx::Error> {
        self.commit().await
    }
}

impl CommitChecked for sqlx::Transaction<'_, sqlx::Sqlite> {
    /// SQLite rolls a transaction back by itself when its COMMIT fails on a full disk; sqlx's
    /// own COMMIT would then leave its count of open transactions at one and its ROLLBACK on drop
    /// fail, so the pooled connection would refuse every later `BEGIN IMMEDIATE` and nest every
    /// `BEGIN` as a savepoint that never commits. So the COMMIT is sent as plain SQL first, and
    /// sqlx then ends an empty transaction opened for it, whichever way the COMMIT went.
    async fn commit_checked(mut self) -> Result<(), sqlx::Error> {
        use sqlx::Executor;
        match self.execute(sqlx::raw_sql("COMMIT")).await {
            Ok(_) => {
                self.execute(sqlx::raw_sql("BEGIN")).await?;
                self.commit().await
            }
            Err(error) => {
                // Fails when SQLite kept the transaction open; the ROLLBACK then ends that one.
                let _ = self.execute(sqlx::raw_sql("BEGIN")).await;
                let _ = self.rollback().await;
                Err(error)
            }
        }
    }
}
