//! The two stores behind one handle: an embedded SQLite file (the default: created if missing,
//! WAL, foreign keys, busy timeout) or a PostgreSQL server shared by any number of API nodes and
//! worker processes. Each has its own migrations (`migrations/sqlite/`, `migrations/postgres/`),
//! applied at start; `store/` holds the SQL of both.

use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;
use std::time::Duration;

use anyhow::Context;
use sqlx::postgres::{PgConnectOptions, PgPoolOptions};
use sqlx::sqlite::{
    SqliteAutoVacuum, SqliteConnectOptions, SqliteJournalMode, SqliteLockingMode, SqlitePoolOptions, SqliteSynchronous,
};
use sqlx::{Connection, PgPool, SqlitePool};

/// Where the data lives, as `--database` names it: a file path or `sqlite://PATH` (SQLite), or
/// `postgres://…` / `postgresql://…` (PostgreSQL).
#[derive(Clone, PartialEq, Eq)]
pub enum Database {
    /// An SQLite file.
    Sqlite(PathBuf),
    /// A PostgreSQL connection URL.
    Postgres(String),
}

impl Database {
    /// Reads a `--database` value. Never fails: anything that is not a PostgreSQL URL is a path.
    pub fn parse(text: &str) -> Self {
        if text.starts_with("postgres://") || text.starts_with("postgresql://") {
            return Self::Postgres(text.to_owned());
        }
        let path = text.strip_prefix("sqlite://").or_else(|| text.strip_prefix("sqlite:")).unwrap_or(text);
        Self::Sqlite(PathBuf::from(path))
    }

    /// The SQLite file, if this is one.
    pub fn sqlite_path(&self) -> Option<&Path> {
        match self {
            Self::Sqlite(path) => Some(path),
            Self::Postgres(_) => None,
        }
    }
}

impl FromStr for Database {
    type Err = std::convert::Infallible;

    fn from_str(text: &str) -> Result<Self, Self::Err> {
        Ok(Self::parse(text))
    }
}

impl From<PathBuf> for Database {
    fn from(path: PathBuf) -> Self {
        Self::Sqlite(path)
    }
}

/// Shown in logs: the file, or the URL without its password.
impl fmt::Display for Database {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Sqlite(path) => write!(f, "{}", path.display()),
            Self::Postgres(url) => {
                let parts = url.split_once("://").and_then(|(scheme, rest)| Some((scheme, rest.rsplit_once('@')?)));
                match parts {
                    Some((scheme, (credentials, host))) => match credentials.split_once(':') {
                        Some((user, _password)) => write!(f, "{scheme}://{user}:***@{host}"),
                        None => write!(f, "{url}"),
                    },
                    None => write!(f, "{url}"),
                }
            }
        }
    }
}

impl fmt::Debug for Database {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Database({self})")
    }
}

/// An open store: a pool of either kind. Cheap to clone.
#[derive(Debug, Clone)]
pub enum Db {
    /// The embedded SQLite file.
    Sqlite(SqlitePool),
    /// A PostgreSQL server.
    Postgres(PgPool),
}

impl Db {
    /// Whether this is PostgreSQL (shared by several processes: leases, LISTEN/NOTIFY).
    pub fn is_postgres(&self) -> bool {
        matches!(self, Self::Postgres(_))
    }

    /// `sqlite` or `postgres`.
    pub fn kind(&self) -> &'static str {
        match self {
            Self::Sqlite(_) => "sqlite",
            Self::Postgres(_) => "postgres",
        }
    }

    /// Closes the pool (an SQLite file's write-ahead log is checkpointed and removed).
    pub async fn close(&self) {
        match self {
            Self::Sqlite(pool) => pool.close().await,
            Self::Postgres(pool) => pool.close().await,
        }
    }

    /// One round trip to the database.
    ///
    /// # Errors
    /// When the database does not answer.
    pub async fn ping(&self) -> Result<(), sqlx::Error> {
        match self {
            Self::Sqlite(pool) => sqlx::query("SELECT 1").execute(pool).await.map(|_| ()),
            Self::Postgres(pool) => sqlx::query("SELECT 1").execute(pool).await.map(|_| ()),
        }
    }
}

/// Opens (creating an SQLite file if needed) the database and migrates it to the current schema.
/// Several processes may start on one PostgreSQL database at once: sqlx takes an advisory lock
/// while it migrates.
///
/// # Errors
/// When the database cannot be opened or reached, or a migration fails.
pub async fn open(database: &Database) -> anyhow::Result<Db> {
    match database {
        Database::Sqlite(path) => open_sqlite(path).await.map(Db::Sqlite),
        Database::Postgres(url) => {
            let pool = connect_postgres(url, 16).await.with_context(|| format!("connecting to {database}"))?;
            sqlx::migrate!("../migrations/postgres").run(&pool).await.context("applying migrations")?;
            Ok(Db::Postgres(pool))
        }
    }
}

/// Opens an existing database to read the tool table and machines registry (`kerf run`):
/// `None` when it is an SQLite file that does not exist. Nothing is created or migrated.
///
/// # Errors
/// When the database cannot be opened.
pub async fn open_read_only(database: &Database) -> anyhow::Result<Option<Db>> {
    match database {
        Database::Sqlite(path) if !path.exists() => Ok(None),
        Database::Sqlite(path) => {
            let options = SqliteConnectOptions::from_str("sqlite:")?.filename(path).read_only(true);
            Ok(Some(Db::Sqlite(SqlitePoolOptions::new().max_connections(1).connect_with(options).await?)))
        }
        Database::Postgres(url) => {
            Ok(Some(Db::Postgres(connect_postgres(url, 2).await.with_context(|| format!("connecting to {database}"))?)))
        }
    }
}

async fn open_sqlite(path: &Path) -> anyhow::Result<SqlitePool> {
    let existed = path.exists();
    let mut options = SqliteConnectOptions::from_str("sqlite:")?.filename(path).create_if_missing(true);
    if !existed {
        // A new file gives pages freed by pruned jobs back to the file system (`PRAGMA
        // incremental_vacuum` after each prune). Set on a new file only: on an existing one it
        // changes nothing (`kerf jobs prune` converts an older file) but still writes, which
        // fails on a full disk, and the service must start there (read-only until space is
        // freed).
        options = options.auto_vacuum(SqliteAutoVacuum::Incremental);
    }
    let options = options
        .journal_mode(SqliteJournalMode::Wal)
        // The write-ahead log is cut back to 64 MiB after each checkpoint instead of keeping the
        // size of the largest transaction (a job's results) for good.
        .pragma("journal_size_limit", "67108864")
        .synchronous(SqliteSynchronous::Normal)
        .foreign_keys(true)
        // Concurrent writers wait for the lock instead of failing with "database is locked".
        .busy_timeout(Duration::from_secs(10));
    let pool = match sqlite_pool(8).connect_with(options.clone()).await {
        Ok(pool) => pool,
        Err(error) if existed && crate::error::disk_full(&error) => {
            // No room for the shared-memory index (`-shm`) the connections share: one connection
            // that holds the file alone keeps that index in its own memory instead. Reads work,
            // writes once space is freed; a restart then brings the pool back.
            tracing::warn!(%error, database = %path.display(), "the disk is full: one exclusive connection until a restart");
            let exclusive = options.locking_mode(SqliteLockingMode::Exclusive);
            sqlite_pool(1)
                .connect_with(exclusive)
                .await
                .map_err(|_| error)
                .with_context(|| format!("opening database {}", path.display()))?
        }
        Err(error) => return Err(error).with_context(|| format!("opening database {}", path.display())),
    };
    sqlx::migrate!("../migrations/sqlite").run(&pool).await.context("applying migrations")?;
    Ok(pool)
}

/// SQLite pool options: a connection that comes back still inside a transaction is closed, not
/// reused. A COMMIT that fails on a full disk makes SQLite roll the transaction back itself, so
/// sqlx's ROLLBACK on drop fails and its count of open transactions stays at one: reused, such a
/// connection would refuse every later `BEGIN IMMEDIATE` and nest every `BEGIN` as a savepoint
/// that never commits.
fn sqlite_pool(connections: u32) -> SqlitePoolOptions {
    SqlitePoolOptions::new()
        .max_connections(connections)
        .after_release(|connection, _| Box::pin(async move { Ok(!connection.is_in_transaction()) }))
}

/// How long a request waits for a database connection before it is answered 503 `E_UNAVAILABLE`
/// (with `Retry-After`): `KERF_DATABASE_TIMEOUT_S` seconds, by default [`DEFAULT_ACQUIRE_TIMEOUT`].
/// Short, so an outage is told to clients at once instead of holding their requests.
pub fn acquire_timeout() -> Duration {
    std::env::var("KERF_DATABASE_TIMEOUT_S")
        .ok()
        .and_then(|text| text.trim().parse::<f64>().ok())
        .filter(|seconds| seconds.is_finite() && *seconds > 0.0)
        .map_or(DEFAULT_ACQUIRE_TIMEOUT, |seconds| Duration::from_secs_f64(seconds.min(3600.0)))
}

/// The default of [`acquire_timeout`].
pub const DEFAULT_ACQUIRE_TIMEOUT: Duration = Duration::from_secs(3);

/// How long a starting process waits for its PostgreSQL server (which may be starting beside it).
const START_WAIT: Duration = Duration::from_secs(10);

async fn connect_postgres(url: &str, connections: u32) -> anyhow::Result<PgPool> {
    let options = PgConnectOptions::from_str(url)?.application_name("kerf");
    let started = std::time::Instant::now();
    loop {
        match PgPoolOptions::new()
            .max_connections(connections)
            .acquire_timeout(acquire_timeout())
            .connect_with(options.clone())
            .await
        {
            Ok(pool) => return Ok(pool),
            Err(error @ (sqlx::Error::Io(_) | sqlx::Error::PoolTimedOut)) if started.elapsed() < START_WAIT => {
                tracing::warn!(%error, "the database does not answer yet; trying again");
                tokio::time::sleep(Duration::from_millis(500)).await;
            }
            Err(error) => return Err(error.into()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn database_values() {
        assert_eq!(Database::parse("kerf.db"), Database::Sqlite("kerf.db".into()));
        assert_eq!(Database::parse("sqlite:///var/lib/kerf.db"), Database::Sqlite("/var/lib/kerf.db".into()));
        assert_eq!(Database::parse("sqlite:kerf.db"), Database::Sqlite("kerf.db".into()));
        let url = "postgres://kerf:s3cret@db:5432/kerf";
        assert_eq!(Database::parse(url), Database::Postgres(url.to_owned()));
        assert_eq!(Database::parse(url).to_string(), "postgres://kerf:***@db:5432/kerf");
        assert_eq!(Database::parse("postgresql://db/kerf").to_string(), "postgresql://db/kerf");
        // A user without a password is shown as it is.
        let url = "postgres://postgres@127.0.0.1:5432/kerf?sslmode=require";
        assert_eq!(Database::parse(url).to_string(), url);
    }
}
