//! A throw-away PostgreSQL server for one test: `initdb` into a temporary directory, `pg_ctl
//! start` on a free port of 127.0.0.1 (its socket in the same directory), stopped and removed
//! when dropped. PostgreSQL refuses to run as root, so as root (CI) every command runs as the
//! `postgres` system user through `runuser`, and the directory is handed to that user.
//!
//! Without PostgreSQL's programs (Debian's `postgresql` package) [`PgServer::start`] prints why
//! the test skips and returns `None`, or panics under `KERF_REQUIRE_EXTERNAL=1`.

use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};
use std::process::Command;

use kerf_server::db::Database;

use crate::{external_required, free_port};

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

fn skip(reason: &str) -> Option<PgServer> {
    let message = format!("{reason}: skipping the PostgreSQL test");
    assert!(!external_required(), "{message}, but KERF_REQUIRE_EXTERNAL=1");
    eprintln!("SKIP: {message}");
    None
}

/// The folder with `initdb` and `pg_ctl`: on the PATH, else Debian's newest
/// `/usr/lib/postgresql/N/bin`.
fn bin_folder() -> Option<PathBuf> {
    let on_path = std::env::var_os("PATH").and_then(|paths| {
        std::env::split_paths(&paths).find(|dir| dir.join("initdb").is_file() && dir.join("pg_ctl").is_file())
    });
    if on_path.is_some() {
        return on_path;
    }
    let mut versions: Vec<(u32, PathBuf)> = std::fs::read_dir("/usr/lib/postgresql")
        .ok()?
        .filter_map(|entry| {
            let entry = entry.ok()?;
            let version = entry.file_name().to_str()?.parse().ok()?;
            let bin = entry.path().join("bin");
            bin.join("initdb").is_file().then_some((version, bin))
        })
        .collect();
    versions.sort();
    versions.pop().map(|(_, bin)| bin)
}

/// The uid and gid of the `postgres` system user, from `/etc/passwd`.
fn postgres_user() -> Option<(u32, u32)> {
    let passwd = std::fs::read_to_string("/etc/passwd").ok()?;
    let line = passwd.lines().find(|line| line.starts_with("postgres:"))?;
    let fields: Vec<&str> = line.split(':').collect();
    Some((fields.get(2)?.parse().ok()?, fields.get(3)?.parse().ok()?))
}

impl PgServer {
    /// Starts a server, or `None` when PostgreSQL is not installed (see the module).
    ///
    /// # Panics
    /// When it is installed but does not start.
    pub fn start() -> Option<Self> {
        let Some(bin) = bin_folder() else { return skip("PostgreSQL (initdb, pg_ctl) is not installed") };
        let root = std::fs::metadata("/proc/self").is_ok_and(|m| m.uid() == 0);
        let directory = tempfile::Builder::new().prefix("kerf-pg-").tempdir().expect("temporary directory");
        if root {
            let Some((uid, gid)) = postgres_user() else {
                return skip("running as root and there is no postgres user to run PostgreSQL as");
            };
            std::os::unix::fs::chown(directory.path(), Some(uid), Some(gid)).expect("hand the folder to postgres");
            if Command::new("runuser").arg("--help").output().is_err() {
                return skip("running as root and runuser is missing");
            }
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
