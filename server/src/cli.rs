//! Command line and environment configuration of the `kerf` binary.

use std::net::SocketAddr;
use std::path::PathBuf;
use std::time::Duration;

use clap::{Args, Parser, Subcommand};

use crate::app::Config;
use crate::state::Limits;

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
}

/// Subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run the HTTP service (the default).
    Serve(ServeArgs),
}

/// Options of the service.
#[derive(Debug, Clone, Args)]
pub struct ServeArgs {
    /// Address to listen on.
    #[arg(long, env = "KERF_BIND", default_value = "127.0.0.1:8080")]
    pub bind: SocketAddr,
    /// SQLite database file, created with the schema if missing.
    #[arg(long, env = "KERF_DATABASE", default_value = "kerf.db")]
    pub database: PathBuf,
    /// Largest accepted request body, bytes.
    #[arg(long, env = "KERF_MAX_BODY_BYTES", default_value_t = Limits::default().max_body_bytes)]
    pub max_body_bytes: usize,
    /// Longest synchronous solver call, seconds, before the client is told to submit a job.
    #[arg(long, env = "KERF_SOLVER_TIME_LIMIT_S", default_value_t = Limits::default().solver_time_limit.as_secs())]
    pub solver_time_limit_s: u64,
    /// Solver calls allowed at once (default: the number of CPU cores).
    #[arg(long, env = "KERF_SOLVER_SLOTS")]
    pub solver_slots: Option<usize>,
}

impl ServeArgs {
    /// The service configuration these options describe.
    pub fn config(&self) -> Config {
        let cores = std::thread::available_parallelism().map_or(2, std::num::NonZero::get);
        Config {
            database: self.database.clone(),
            limits: Limits {
                max_body_bytes: self.max_body_bytes,
                solver_time_limit: Duration::from_secs(self.solver_time_limit_s.max(1)),
                ..Limits::default()
            },
            solver_slots: self.solver_slots.unwrap_or(cores),
        }
    }
}
