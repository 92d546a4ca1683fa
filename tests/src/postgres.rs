//! A throw-away PostgreSQL server for one test: `initdb` into a temporary directory, `pg_ctl
//! start` on a free port of 127.0.0.1 (its socket in the same directory), stopped and removed
//! when dropped. PostgreSQL refuses to run as root, so as root (CI) every command runs as the
//! `postgres` system user through `runuser`, and the directory is handed to that user.
//!
//! The tests that use it carry `#[cfg_attr(not(kerf_has_postgres), ignore = …)]`, set by the build
//! script when it finds PostgreSQL where [`crate::external::postgres`] looks, so they are ignored
//! without it; [`PgServer::start`] fails a test that runs all the same (`KERF_REQUIRE_EXTERNAL=1`
//! sets every flag).

use std::path::{Path, PathBuf};
use std::process::Command;

use kerf_server::db::Database;

use crate::external::{self, postgres_user};
use crate::{free_port, missing_message};

/// A running PostgreSQL server with a database `postgres` that the user `postgres` may use
/// without a password.
pub struct PgServer {
    /// The server's folder (data, socket, log).
    directory: tempfile::TempDir,
    bin: PathBuf,
    /// `runuser -u postgres --` when running as root.
    as_postgres: bool,
    port: u16,
}

fn missing(reason: &str) -> ! {
    panic!("{}", missing_message(reason, "the PostgreSQL test"))
}

impl PgServer {
    /// Starts a server. Always `Some` (see the module).
    ///
    /// # Panics
    /// When PostgreSQL is missing, or installed but does not start.
    pub fn start() -> Option<Self> {
        let (bin, root) = match external::postgres() {
            Ok(found) => found,
            Err(reason) => missing(reason),
        };
        let directory = tempfile::Builder::new().prefix("kerf-pg-").tempdir().expect("temporary directory");
        if root {
            let (uid, gid) = postgres_user().expect("the postgres user, found by external::postgres");
            std::os::unix::fs::chown(directory.path(), Some(uid), Some(gid)).expect("hand the folder to postgres");
        }
        let server = Self { directory, bin, as_postgres: root, port: free_port() };
        let data = server.data();
        server.run(
            "initdb",
            &["-D", &data, "-U", "postgres", "--auth=trust", "-E", "UTF8", "--no-sync", "--no-instructions"],
        );
        server.start_again();
        Some(server)
    }

    /// Starts the server (again, after [`PgServer::stop`]) on its data and port, and waits until
    /// it accepts connections.
    ///
    /// # Panics
    /// When it does not start.
    pub fn start_again(&self) {
        let options = format!(
            "-p {} -k {} -c listen_addresses=127.0.0.1 -c fsync=off -c synchronous_commit=off \
             -c full_page_writes=off -c max_connections=300 -c shared_buffers=32MB",
            self.port,
            self.directory.path().display()
        );
        let log = self.directory.path().join("log").display().to_string();
        self.run("pg_ctl", &["-D", &self.data(), "-l", &log, "-o", &options, "-w", "-t", "60", "start"]);
    }

    fn data(&self) -> String {
        self.directory.path().join("data").display().to_string()
    }

    fn command(&self, program: &str) -> Command {
        let program = self.bin.join(program);
        if self.as_postgres {
            let mut command = Command::new("runuser");
            command.args(["-u", "postgres", "--"]).arg(program);
            command
        } else {
            Command::new(program)
        }
    }

    fn run(&self, program: &str, arguments: &[&str]) {
        let output = self.command(program).args(arguments).output().unwrap_or_else(|e| panic!("{program}: {e}"));
        let log = std::fs::read_to_string(self.directory.path().join("log")).unwrap_or_default();
        assert!(
            output.status.success(),
            "{program} {arguments:?} failed: {}{}\n{log}",
            String::from_utf8_lossy(&output.stdout),
            String::from_utf8_lossy(&output.stderr)
        );
    }

    /// `postgres://postgres@127.0.0.1:PORT/postgres`.
    pub fn url(&self) -> String {
        format!("postgres://postgres@127.0.0.1:{}/postgres", self.port)
    }

    /// The URL as a `--database` value.
    pub fn database(&self) -> Database {
        Database::Postgres(self.url())
    }

    /// The server's folder.
    pub fn directory(&self) -> &Path {
        self.directory.path()
    }

    /// Stops the server as an operator would (`pg_ctl stop -m fast`: every connection cut, every
    /// commit kept; the immediate [`PgServer::stop`] may lose the last commits, which this
    /// throw-away server does not flush).
    pub fn stop_fast(&self) {
        self.run("pg_ctl", &["-D", &self.data(), "-m", "fast", "-w", "stop"]);
    }

    /// Stops the server at once (as a crash would); dropping it stops it too.
    pub fn stop(&self) {
        let data = self.data();
        let _ = self.command("pg_ctl").args(["-D", &data, "-m", "immediate", "-w", "stop"]).output();
    }
}

impl Drop for PgServer {
    fn drop(&mut self) {
        self.stop();
    }
}
