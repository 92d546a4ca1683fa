//! The `kerf` program: command line and environment configuration, `serve` (until SIGINT or
//! SIGTERM), `worker` (claims and runs jobs from PostgreSQL, no API), `run`, `migrate` and `jobs
//! prune`.

use std::io::IsTerminal;
use std::net::SocketAddr;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

use anyhow::Context;
use clap::{Args, Parser, Subcommand, ValueEnum};
use tokio::net::TcpListener;
use tracing_subscriber::EnvFilter;

use crate::app::Config;
use crate::auth::Auth;
use crate::db::{self, Database};
use crate::jobs::queue::{DEFAULT_LEASE, JobRunner};
use crate::state::Limits;
use crate::store::jobs::{self as storage, JobStorage, MIB, mib};

/// kerf: CAM web service (tool-centre paths as JSON or G-code).
#[derive(Debug, Parser)]
#[command(name = "kerf", version, about, args_conflicts_with_subcommands = true)]
pub struct Cli {
    /// What to do; without a subcommand kerf serves.
    #[command(subcommand)]
    pub command: Option<Command>,
    /// Options of `serve` when no subcommand is given.
    #[command(flatten)]
    pub serve: ServeArgs,
    /// How log lines are written to standard error: `text` (without colours unless standard
    /// error is a terminal) or `json` (one object per line, for a log collector).
    #[arg(long, global = true, env = "KERF_LOG_FORMAT", value_enum, default_value_t = LogFormat::Text)]
    pub log_format: LogFormat,
}

/// The form of log lines.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum LogFormat {
    /// Human-readable lines.
    Text,
    /// One JSON object per line: `timestamp`, `level`, `fields` (with `message`), `target`, and
    /// `span` (the request's `method`, `route` and `request_id`) where one is open.
    Json,
}

/// Subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run the HTTP service (the default).
    Serve(ServeArgs),
    /// Claim and run jobs from a PostgreSQL database shared with `kerf serve` nodes (no API).
    Worker(WorkerArgs),
    /// Run a job file locally, without the service, and write its results as files.
    Run(RunArgs),
    /// Bring an existing database to this version's schema and stop (what `serve` and `worker`
    /// do at start; `run` only reads a database as it is).
    Migrate(MigrateArgs),
    /// Manage the stored jobs.
    #[command(subcommand)]
    Jobs(JobsCommand),
}

/// `kerf jobs` subcommands.
#[derive(Debug, Subcommand)]
pub enum JobsCommand {
    /// Remove finished jobs (done, failed, cancelled) older than a number of days, with their
    /// results; queued and running jobs stay. Prints what it removed. On an SQLite file made
    /// before incremental vacuum it also converts the file (one full VACUUM: stop the service
    /// first), after which the file shrinks as jobs are pruned.
    Prune(PruneArgs),
}

/// Options of `kerf jobs prune`.
#[derive(Debug, Clone, Args)]
pub struct PruneArgs {
    /// Remove the jobs that finished more than this many days ago (0: every finished job). Not
    /// read from `KERF_JOB_RETENTION_DAYS`, where 0 means the opposite (keep forever).
    #[arg(long, default_value_t = 30.0)]
    pub older_than_days: f64,
    /// The database (an SQLite file or a `postgres://` URL).
    #[arg(long, env = "KERF_DATABASE", default_value = "kerf.db")]
    pub database: Database,
}

/// The job store's bounds, shared by `serve` and `worker`.
#[derive(Debug, Clone, Args)]
pub struct JobStorageArgs {
    /// MiB all stored jobs may take together (job files and compressed results); a submission
    /// beyond it gets 429 `E_JOB_STORE_FULL`. 0: no quota.
    #[arg(long, env = "KERF_JOB_STORE_QUOTA_MB", default_value_t = JobStorage::default().quota() / MIB)]
    pub job_store_quota_mb: u64,
    /// MiB one job's stored results may take (compressed); a job over it fails with
    /// `E_RESULT_TOO_LARGE` naming the operation.
    #[arg(long, env = "KERF_JOB_RESULT_MAX_MB", default_value_t = JobStorage::default().job_max_bytes / MIB)]
    pub job_result_max_mb: u64,
    /// Days a finished job is kept before it is pruned (0: forever).
    #[arg(long, env = "KERF_JOB_RETENTION_DAYS", default_value_t = 30.0)]
    pub job_retention_days: f64,
}

impl JobStorageArgs {
    /// The bounds these options describe.
    pub fn storage(&self) -> JobStorage {
        JobStorage {
            quota_bytes: (self.job_store_quota_mb > 0).then(|| self.job_store_quota_mb.saturating_mul(MIB)),
            job_max_bytes: self.job_result_max_mb.max(1).saturating_mul(MIB),
            retention: storage::days(self.job_retention_days),
            ..JobStorage::default()
        }
    }
}

/// Options of `kerf run`.
#[derive(Debug, Clone, Args)]
pub struct RunArgs {
    /// The job file (JSON or TOML).
    pub job_file: PathBuf,
    /// Folder for the results (created if missing).
    #[arg(short, long, default_value = "kerf-out")]
    pub out: PathBuf,
    /// Tool table, machines registry and materials library to resolve the tool numbers, machine
    /// and material names the job file does not define (read as it is, never migrated: `kerf
    /// migrate` upgrades an older one; an SQLite file is used if it exists, or a `postgres://`
    /// URL).
    #[arg(long, env = "KERF_DATABASE", default_value = "kerf.db")]
    pub database: Database,
}

/// Options of `kerf migrate`.
#[derive(Debug, Clone, Args)]
pub struct MigrateArgs {
    /// The database (an SQLite file, which must exist, or a `postgres://` URL).
    #[arg(long, env = "KERF_DATABASE", default_value = "kerf.db")]
    pub database: Database,
}

/// Options of `kerf worker`.
#[derive(Debug, Clone, Args)]
pub struct WorkerArgs {
    /// The PostgreSQL database the API nodes use (`postgres://user:password@host:port/name`).
    #[arg(long, env = "KERF_DATABASE")]
    pub database: Database,
    /// Jobs this process runs at once (default: the number of CPU cores).
    #[arg(long, env = "KERF_JOB_WORKERS")]
    pub job_workers: Option<usize>,
    /// Seconds a claimed job stays this worker's without a heartbeat; after that (the process
    /// died) another worker claims it again.
    #[arg(long, env = "KERF_JOB_LEASE_S", default_value_t = DEFAULT_LEASE.as_secs_f64())]
    pub job_lease_s: f64,
    /// Address for `/metrics`, `/readyz` and `/healthz` of this worker (none when absent).
    #[arg(long, env = "KERF_METRICS_BIND")]
    pub metrics_bind: Option<SocketAddr>,
    /// The job store's bounds.
    #[command(flatten)]
    pub storage: JobStorageArgs,
}

/// Options of the service.
#[derive(Debug, Clone, Args)]
pub struct ServeArgs {
    /// Address to listen on.
    #[arg(long, env = "KERF_BIND", default_value = "127.0.0.1:8080")]
    pub bind: SocketAddr,
    /// The database: an SQLite file (a path or `sqlite://PATH`, created with the schema if
    /// missing) or PostgreSQL (`postgres://user:password@host:port/name`, migrated at start).
    #[arg(long, env = "KERF_DATABASE", default_value = "kerf.db")]
    pub database: Database,
    /// Largest accepted request body, bytes.
    #[arg(long, env = "KERF_MAX_BODY_BYTES", default_value_t = Limits::default().max_body_bytes)]
    pub max_body_bytes: usize,
    /// Largest accepted body of upload routes (`POST /api/v1/predict`: STL stock, long programs), bytes.
    #[arg(long, env = "KERF_MAX_UPLOAD_BYTES", default_value_t = Limits::default().max_upload_bytes)]
    pub max_upload_bytes: usize,
    /// Longest synchronous solver call, seconds (a fraction allowed, 0.01 to 86 400), before the
    /// client is told to submit a job.
    #[arg(long, env = "KERF_SOLVER_TIME_LIMIT_S", default_value_t = Limits::default().solver_time_limit.as_secs_f64(), value_parser = time_limit_seconds)]
    pub solver_time_limit_s: f64,
    /// MiB of solver answers kept to answer the same question (request, stored tool, machine
    /// and material values, output options) again without solving; 0 keeps none.
    #[arg(long, env = "KERF_ANSWER_CACHE_MB", default_value_t = u64::try_from(Limits::default().answer_cache_bytes).unwrap_or(u64::MAX) / MIB)]
    pub answer_cache_mb: u64,
    /// MiB of solver answers and uploads held in memory at once; one answer (or a job's
    /// operation) larger than it is refused with `E_TOO_LARGE_ANSWER` before it is built whole.
    #[arg(long, env = "KERF_ANSWER_BUDGET_MB", default_value_t = u64::try_from(Limits::default().answer_budget_bytes).unwrap_or(u64::MAX) / MIB)]
    pub answer_budget_mb: u64,
    /// Slowest a request body may arrive, bytes per second averaged over `--body-rate-window-s`;
    /// a slower one ends with 408. 0: no minimum.
    #[arg(long, env = "KERF_MIN_BODY_RATE", default_value_t = Limits::default().min_body_rate)]
    pub min_body_rate: usize,
    /// Seconds the minimum body rate is averaged over.
    #[arg(long, env = "KERF_BODY_RATE_WINDOW_S", default_value_t = Limits::default().body_rate_window.as_secs_f64())]
    pub body_rate_window_s: f64,
    /// Solver calls allowed at once (default: the number of CPU cores).
    #[arg(long, env = "KERF_SOLVER_SLOTS")]
    pub solver_slots: Option<usize>,
    /// Job workers in this process (default: the number of CPU cores); 0 runs no jobs here
    /// (an API node in front of `kerf worker` processes on PostgreSQL).
    #[arg(long, env = "KERF_JOB_WORKERS")]
    pub job_workers: Option<usize>,
    /// Seconds a job claimed by this process stays its own without a heartbeat (PostgreSQL).
    #[arg(long, env = "KERF_JOB_LEASE_S", default_value_t = DEFAULT_LEASE.as_secs_f64())]
    pub job_lease_s: f64,
    /// API token: when set, requests that change state need `Authorization: Bearer <token>`.
    #[arg(long, env = "KERF_API_TOKEN", hide_env_values = true)]
    pub api_token: Option<String>,
    /// With a token, reads of the API need it too.
    #[arg(long, env = "KERF_PRIVATE")]
    pub private: bool,
    /// An origin whose pages may call the API from a browser (CORS), as `scheme://host[:port]`
    /// (`https://cam.example.com`), or `*` for any. Repeat it for several; from the environment,
    /// separated by commas. None by default: browsers then allow only pages served by kerf itself.
    #[arg(long = "cors-origin", env = "KERF_CORS_ORIGINS", value_delimiter = ',', value_parser = cors_origin)]
    pub cors_origins: Vec<String>,
    /// The job store's bounds.
    #[command(flatten)]
    pub storage: JobStorageArgs,
}

/// Reads `--solver-time-limit-s`: seconds from 0.01 to 86 400 (a day), a fraction allowed.
fn time_limit_seconds(text: &str) -> Result<f64, String> {
    let seconds: f64 = text.trim().parse().map_err(|_| format!("{text:?} is not a number of seconds"))?;
    if (0.01..=86_400.0).contains(&seconds) { Ok(seconds) } else { Err(format!("{text} s is outside 0.01 to 86400 s")) }
}

/// Reads one `--cors-origin`: `*`, or `scheme://host[:port]` with nothing after (an origin as a
/// browser sends it in `Origin`).
fn cors_origin(text: &str) -> Result<String, String> {
    let text = text.trim();
    if text == "*" {
        return Ok(text.to_owned());
    }
    let usage = || format!("{text:?} is not an origin: write scheme://host[:port], e.g. https://cam.example.com");
    let (scheme, rest) = text.split_once("://").ok_or_else(usage)?;
    let scheme_ok = scheme.starts_with(|c: char| c.is_ascii_alphabetic())
        && scheme.chars().all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c));
    let host_ok = !rest.is_empty()
        && rest.chars().all(|c| c.is_ascii_alphanumeric() || "-.:[]".contains(c))
        && !rest.starts_with(':');
    if scheme_ok && host_ok { Ok(text.to_owned()) } else { Err(usage()) }
}

impl ServeArgs {
    /// The service configuration these options describe.
    pub fn config(&self) -> Config {
        let cores = std::thread::available_parallelism().map_or(2, std::num::NonZero::get);
        Config {
            database: self.database.clone(),
            limits: Limits {
                max_body_bytes: self.max_body_bytes,
                max_upload_bytes: self.max_upload_bytes,
                solver_time_limit: Duration::from_secs_f64(self.solver_time_limit_s),
                answer_cache_bytes: usize::try_from(self.answer_cache_mb.saturating_mul(MIB)).unwrap_or(usize::MAX),
                answer_budget_bytes: usize::try_from(self.answer_budget_mb.max(1).saturating_mul(MIB))
                    .unwrap_or(usize::MAX),
                min_body_rate: self.min_body_rate,
                body_rate_window: Duration::try_from_secs_f64(self.body_rate_window_s)
                    .unwrap_or(Limits::default().body_rate_window),
                ..Limits::default()
            },
            solver_slots: self.solver_slots.unwrap_or(cores),
            job_workers: self.job_workers.unwrap_or(cores),
            job_lease: lease(self.job_lease_s),
            auth: Auth { token: self.api_token.clone().filter(|t| !t.is_empty()), private: self.private },
            job_storage: self.storage.storage(),
            cors_origins: self.cors_origins.clone(),
        }
    }
}

/// The `kerf` program: parses the command line, sets up logging and runs the command.
///
/// # Errors
/// Whatever the command fails with.
pub fn main() -> anyhow::Result<()> {
    let cli = Cli::parse();
    let filter = EnvFilter::try_from_default_env().unwrap_or_else(|_| EnvFilter::new("info"));
    // Standard error, so what `run`, `migrate` and `jobs prune` print on standard output stays
    // theirs alone.
    let lines = tracing_subscriber::fmt().with_env_filter(filter).with_writer(std::io::stderr);
    match cli.log_format {
        LogFormat::Text => lines.with_ansi(std::io::stderr().is_terminal()).init(),
        LogFormat::Json => lines.json().with_current_span(true).with_span_list(false).init(),
    }
    let runtime = tokio::runtime::Runtime::new().context("starting the async runtime")?;
    let result = match cli.command {
        Some(Command::Serve(args)) => runtime.block_on(serve(args)),
        Some(Command::Worker(args)) => runtime.block_on(worker(args)),
        Some(Command::Run(args)) => runtime.block_on(run(args)),
        Some(Command::Migrate(args)) => runtime.block_on(migrate(args)),
        Some(Command::Jobs(JobsCommand::Prune(args))) => runtime.block_on(prune(args)),
        None => runtime.block_on(serve(cli.serve)),
    };
    // Solver work was told to stop; whatever has not ended by now is not waited for, so the
    // process ends within its shutdown deadline.
    runtime.shutdown_timeout(BLOCKING_WORK_GRACE);
    result
}

/// How long the program waits, once it stopped, for solver work still running on blocking
/// threads (cancelled work ends within milliseconds).
const BLOCKING_WORK_GRACE: Duration = Duration::from_secs(2);

async fn run(args: RunArgs) -> anyhow::Result<()> {
    let report = crate::jobs::local::run(&args.job_file, &args.out, Some(&args.database)).await?;
    for file in report.files {
        println!("{}", file.display());
    }
    Ok(())
}

/// `kerf migrate`: applies the migrations an existing database lacks.
async fn migrate(args: MigrateArgs) -> anyhow::Result<()> {
    if args.database.sqlite_path().is_some_and(|path| !path.exists()) {
        anyhow::bail!("no database at {} (kerf serve creates a new one)", args.database);
    }
    let db = db::open(&args.database).await?;
    db.close().await;
    println!("{}: at this version's schema", args.database);
    Ok(())
}

/// `kerf jobs prune`: removes the finished jobs older than the given days and says what it removed.
async fn prune(args: PruneArgs) -> anyhow::Result<()> {
    if !(args.older_than_days.is_finite() && args.older_than_days >= 0.0) {
        anyhow::bail!("--older-than-days must be a number of days, 0 or more (got {})", args.older_than_days);
    }
    let file_size = |database: &Database| {
        database.sqlite_path().map(|path| {
            ["", "-wal"]
                .iter()
                .filter_map(|suffix| std::fs::metadata(format!("{}{suffix}", path.display())).ok())
                .map(|metadata| metadata.len())
                .sum::<u64>()
        })
    };
    if args.database.sqlite_path().is_some_and(|path| !path.exists()) {
        anyhow::bail!("no database at {}", args.database);
    }
    let before = file_size(&args.database);
    let db = db::open(&args.database).await?;
    let older_than = Duration::from_secs_f64(args.older_than_days * 86_400.0);
    let pruned = crate::store::jobs::prune(&db, older_than).await?;
    let Some(pruned) = pruned else {
        println!("another process is pruning this database right now; nothing removed");
        return Ok(());
    };
    // The ids, up to a screenful.
    const LISTED: usize = 50;
    let mut ids: Vec<String> = pruned.ids.iter().take(LISTED).map(i64::to_string).collect();
    if pruned.ids.len() > LISTED {
        ids.push(format!("… {} more", pruned.ids.len() - LISTED));
    }
    println!(
        "removed {} finished job(s) older than {} day(s){}: {} of job files and results",
        pruned.ids.len(),
        args.older_than_days,
        if ids.is_empty() { String::new() } else { format!(" (ids {})", ids.join(", ")) },
        mib(pruned.bytes.unsigned_abs())
    );
    if !crate::store::jobs::incremental_vacuum(&db).await? {
        println!("converting the SQLite file to incremental vacuum (one full VACUUM)");
        crate::store::jobs::convert_to_incremental_vacuum(&db).await?;
    }
    let (jobs, bytes) = crate::store::jobs::usage(&db).await?;
    println!("the store holds {jobs} job(s), {}", mib(bytes.unsigned_abs()));
    db.close().await;
    if let (Some(before), Some(after)) = (before, file_size(&args.database)) {
        println!("database file: {} before, {} after", mib(before), mib(after));
    }
    Ok(())
}

/// A lease of `seconds` (at least 1 s).
fn lease(seconds: f64) -> Duration {
    if seconds.is_finite() && seconds >= 1.0 { Duration::from_secs_f64(seconds) } else { Duration::from_secs(1) }
}

async fn serve(args: ServeArgs) -> anyhow::Result<()> {
    let config = args.config();
    let (router, state) = crate::app::build(&config).await?;
    let listener = TcpListener::bind(args.bind).await.with_context(|| format!("binding {}", args.bind))?;
    tracing::info!(address = %listener.local_addr()?, database = %config.database, "kerf listening");
    let stopping = Arc::clone(&state.solving);
    let stop = async move {
        shutdown_signal().await;
        stopping.stop();
    };
    crate::serve(listener, router, config.limits.clone(), stop).await?;
    state.jobs.release(&state.db).await;
    tracing::info!("kerf stopped");
    Ok(())
}

async fn worker(args: WorkerArgs) -> anyhow::Result<()> {
    if !matches!(args.database, Database::Postgres(_)) {
        anyhow::bail!(
            "kerf worker needs a PostgreSQL database (--database postgres://...); with SQLite, kerf serve runs the jobs"
        );
    }
    let cores = std::thread::available_parallelism().map_or(2, std::num::NonZero::get);
    let workers = args.job_workers.unwrap_or(cores).max(1);
    let db = db::open(&args.database).await?;
    let runner = Arc::new(
        JobRunner::new(lease(args.job_lease_s), args.storage.storage())
            .with_answer_limit(Limits::default().answer_budget_bytes),
    );
    runner.start(&db, &Arc::new(tokio::sync::Semaphore::new(workers)), workers).await?;
    if let Some(bind) = args.metrics_bind {
        let listener = TcpListener::bind(bind).await.with_context(|| format!("binding {bind}"))?;
        tracing::info!(address = %listener.local_addr()?, "worker metrics listening");
        let router = crate::metrics::worker_router(db.clone());
        tokio::spawn(async move {
            crate::serve(listener, router, crate::state::Limits::default(), std::future::pending()).await
        });
    }
    tracing::info!(database = %args.database, worker = runner.worker(), workers, "kerf worker running");
    shutdown_signal().await;
    runner.release(&db).await;
    tracing::info!("kerf worker stopped");
    Ok(())
}

/// Completes on SIGINT (Ctrl-C) or SIGTERM.
async fn shutdown_signal() {
    let interrupt = async {
        let _ = tokio::signal::ctrl_c().await;
    };
    #[cfg(unix)]
    let terminate = async {
        match tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate()) {
            Ok(mut signal) => {
                signal.recv().await;
            }
            Err(error) => {
                tracing::warn!(%error, "cannot listen for SIGTERM");
                std::future::pending::<()>().await;
            }
        }
    };
    #[cfg(not(unix))]
    let terminate = std::future::pending::<()>();
    tokio::select! {
        () = interrupt => {},
        () = terminate => {},
    }
    tracing::info!("shutting down");
}
