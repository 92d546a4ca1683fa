//! Test harness: starts the real service on `127.0.0.1:0` with a temporary SQLite file (or a
//! throw-away PostgreSQL server, [`postgres`]) and talks HTTP to it, and helpers for the external
//! checks (LinuxCNC's `rs274`, headless Chromium, PostgreSQL, schemathesis; [`external`]).

pub mod external;
pub mod postgres;

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;

use kerf_server::app::Config;
use kerf_server::db::Database;
use kerf_server::state::Limits;
use reqwest::{Client, Response};
use serde_json::Value;
use tokio::net::TcpListener;
use tokio::sync::oneshot;
use tokio::task::JoinHandle;

pub use postgres::PgServer;

/// Which store a test runs the service on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Store {
    /// A temporary SQLite file (the default).
    Sqlite,
    /// A throw-away PostgreSQL server of the test's own.
    Postgres,
}

/// Runs each `async fn NAME(store: Store)` test body on both stores: a module `NAME` with the
/// tests `sqlite` and `postgres` (ignored when PostgreSQL is not installed, see [`external`]).
#[macro_export]
macro_rules! on_both_stores {
    ($($test:ident),+ $(,)?) => {
        $(
            mod $test {
                #[tokio::test(flavor = "multi_thread")]
                async fn sqlite() {
                    super::$test($crate::Store::Sqlite).await;
                }

                #[tokio::test(flavor = "multi_thread")]
                #[cfg_attr(not(kerf_has_postgres), ignore = "PostgreSQL not found: apt-get install postgresql")]
                async fn postgres() {
                    super::$test($crate::Store::Postgres).await;
                }
            }
        )+
    };
}

/// A running service with its own database in a temporary directory or PostgreSQL server.
pub struct TestApp {
    /// `http://127.0.0.1:PORT`.
    pub base: String,
    /// HTTP client.
    pub client: Client,
    /// The SQLite database file (unused on PostgreSQL).
    pub database: PathBuf,
    /// The configuration it was started with.
    pub config: Config,
    /// The PostgreSQL server it uses, if any (kept running while the app is).
    pub postgres: Option<Arc<PgServer>>,
    directory: tempfile::TempDir,
    stop: Option<oneshot::Sender<()>>,
    task: Option<JoinHandle<std::io::Result<()>>>,
}

impl TestApp {
    /// Starts a service with default limits.
    pub async fn spawn() -> Self {
        Self::spawn_with(Limits::default()).await
    }

    /// Starts a service with `limits`.
    pub async fn spawn_with(limits: Limits) -> Self {
        Self::spawn_configured(|config| config.limits = limits).await
    }

    /// Starts a service with the default configuration changed by `adjust`.
    pub async fn spawn_configured(adjust: impl FnOnce(&mut Config)) -> Self {
        Self::spawn_at(None, adjust).await
    }

    /// Starts a service on `store` with the default configuration changed by `adjust`. Always
    /// `Some`: a missing PostgreSQL fails the test (see [`PgServer::start`]).
    pub async fn spawn_on(store: Store, adjust: impl FnOnce(&mut Config)) -> Option<Self> {
        let postgres = match store {
            Store::Sqlite => None,
            Store::Postgres => Some(Arc::new(PgServer::start()?)),
        };
        Some(Self::spawn_at(postgres, adjust).await)
    }

    /// Starts a second API node on this one's database (PostgreSQL: the same server).
    pub async fn spawn_beside(&self, adjust: impl FnOnce(&mut Config)) -> Self {
        let mut config = self.config.clone();
        adjust(&mut config);
        let postgres = self.postgres.clone();
        Self::spawn_at(postgres, |c| *c = config).await
    }

    async fn spawn_at(postgres: Option<Arc<PgServer>>, adjust: impl FnOnce(&mut Config)) -> Self {
        let directory = tempfile::tempdir().expect("temporary directory");
        let database = directory.path().join("kerf.db");
        let mut config = Config {
            database: postgres.as_ref().map_or_else(|| Database::Sqlite(database.clone()), |pg| pg.database()),
            limits: Limits::default(),
            solver_slots: 2,
            job_workers: 2,
            job_lease: Duration::from_secs(15),
            auth: kerf_server::auth::Auth::default(),
            job_storage: kerf_server::store::jobs::JobStorage::default(),
            cors_origins: Vec::new(),
        };
        adjust(&mut config);
        let mut app = Self {
            base: String::new(),
            client: Client::builder().timeout(Duration::from_secs(60)).build().expect("client"),
            database,
            config,
            postgres,
            directory,
            stop: None,
            task: None,
        };
        app.start().await;
        app
    }

    async fn start(&mut self) {
        let (router, _state) = kerf_server::app::build(&self.config).await.expect("service builds");
        let listener = TcpListener::bind("127.0.0.1:0").await.expect("bind");
        self.base = format!("http://{}", listener.local_addr().expect("address"));
        let (stop, stopped) = oneshot::channel::<()>();
        self.stop = Some(stop);
        self.task = Some(tokio::spawn(kerf_server::serve(listener, router, self.config.limits.clone(), async {
            let _ = stopped.await;
        })));
    }

    /// Stops the service gracefully and starts it again on the same database file.
    pub async fn restart(&mut self) {
        self.shutdown().await;
        self.start().await;
    }

    /// Stops the service and waits for it.
    pub async fn shutdown(&mut self) {
        if let Some(stop) = self.stop.take() {
            let _ = stop.send(());
        }
        if let Some(task) = self.task.take() {
            task.await.expect("server task").expect("server ran");
        }
    }

    /// The temporary directory (for files a test writes).
    pub fn directory(&self) -> &Path {
        self.directory.path()
    }

    /// `base` + `path`.
    pub fn url(&self, path: &str) -> String {
        format!("{}{path}", self.base)
    }

    /// GET.
    pub async fn get(&self, path: &str) -> Response {
        self.client.get(self.url(path)).send().await.expect("request")
    }

    /// POST a JSON value.
    pub async fn post_json(&self, path: &str, body: &Value) -> Response {
        self.client.post(self.url(path)).json(body).send().await.expect("request")
    }

    /// PUT a JSON value.
    pub async fn put_json(&self, path: &str, body: &Value) -> Response {
        self.client.put(self.url(path)).json(body).send().await.expect("request")
    }

    /// GET a text answer (G-code, HTML, a script), asserting its status first.
    pub async fn get_text(&self, path: &str, status: u16) -> String {
        text_with(path, self.get(path).await, status).await
    }

    /// POST a JSON value for a text answer (`?format=gcode`), asserting its status first.
    pub async fn post_text(&self, path: &str, body: &Value, status: u16) -> String {
        text_with(path, self.post_json(path, body).await, status).await
    }

    /// DELETE.
    pub async fn delete(&self, path: &str) -> Response {
        self.client.delete(self.url(path)).send().await.expect("request")
    }

    /// Registers `tool` under `number`, expecting success.
    pub async fn register_tool(&self, number: u32, tool: &Value) {
        let response = self.put_json(&format!("/api/v1/tools/{number}"), tool).await;
        assert!(response.status().is_success(), "registering tool {number}: {}", response.status());
    }
}

/// Reads the body of the answer to `path` as text, asserting the status first: the path and the
/// body are in the message when it differs.
async fn text_with(path: &str, response: Response, status: u16) -> String {
    let actual = response.status().as_u16();
    let text = response.text().await.expect("body");
    assert_eq!(actual, status, "{path}: unexpected status; body: {text}");
    text
}

/// Reads the body as JSON, asserting the status first.
pub async fn json_with(response: Response, status: u16) -> Value {
    let actual = response.status().as_u16();
    let text = response.text().await.expect("body");
    assert_eq!(actual, status, "unexpected status; body: {text}");
    serde_json::from_str(&text).unwrap_or_else(|error| panic!("not JSON ({error}): {text}"))
}

/// Asserts a problem+json answer with `status` and returns it.
pub async fn problem(response: Response, status: u16) -> Value {
    let content_type =
        response.headers().get("content-type").and_then(|v| v.to_str().ok()).unwrap_or_default().to_owned();
    let body = json_with(response, status).await;
    assert_eq!(content_type, "application/problem+json", "problem content type; body: {body}");
    assert_eq!(body["status"], status, "problem status field: {body}");
    assert!(body["detail"].as_str().is_some_and(|d| !d.is_empty()), "problem detail: {body}");
    body
}

/// Whether external programs are required (`KERF_REQUIRE_EXTERNAL=1`, set by `.ci/run`).
pub fn external_required() -> bool {
    external::required()
}

/// Finds `program` on the PATH, where the build script looks for it too (see [`external`]).
/// Always `Some`: a test that needs a program carries `#[cfg_attr(not(kerf_has_<name>), ignore =
/// "…")]` and is not run without it, so a program missing here (`KERF_REQUIRE_EXTERNAL=1`, a run
/// with `--ignored`, or a test without the attribute) fails the test instead of letting it pass
/// unrun.
pub fn external_program(program: &str, purpose: &str) -> Option<PathBuf> {
    let found = external::on_path(program);
    assert!(found.is_some(), "{}", missing_message(&format!("{program} not found on PATH"), purpose));
    found
}

/// Why a test that needs an external program fails without it.
pub fn missing_message(what: &str, purpose: &str) -> String {
    if external_required() {
        format!("{what}, needed for {purpose}, and KERF_REQUIRE_EXTERNAL=1 requires it")
    } else {
        format!(
            "{what}, needed for {purpose}; a test that needs it carries \
             #[cfg_attr(not(kerf_has_<name>), ignore = \"…\")] to be ignored without it (CONTRIBUTING.md)"
        )
    }
}

/// The real `kerf` program running as a child process on a database file, for tests that
/// kill it (SIGKILL) or restart it.
pub struct ServerProcess {
    /// `http://127.0.0.1:PORT`.
    pub base: String,
    child: std::process::Child,
}

impl ServerProcess {
    /// Starts `program serve` on `database` at a free loopback port and waits until it answers.
    pub async fn start(program: &Path, database: &Path) -> Self {
        Self::start_with(program, &["serve", "--database", &database.to_string_lossy()]).await
    }

    /// Starts `program` with `arguments` and `--bind` (`serve`) or `--metrics-bind` (`worker`)
    /// at a free loopback port, and waits until it answers `/healthz` there.
    pub async fn start_with(program: &Path, arguments: &[&str]) -> Self {
        Self::start_with_env(program, arguments, &[]).await
    }

    /// [`ServerProcess::start_with`] with these environment variables set.
    pub async fn start_with_env(program: &Path, arguments: &[&str], environment: &[(&str, &str)]) -> Self {
        let port = free_port();
        let bind = if arguments.first() == Some(&"worker") { "--metrics-bind" } else { "--bind" };
        let child = std::process::Command::new(program)
            .args(arguments)
            .envs(environment.iter().copied())
            .arg(bind)
            .arg(format!("127.0.0.1:{port}"))
            .env("RUST_LOG", std::env::var("KERF_TEST_LOG").unwrap_or_else(|_| "warn".to_owned()))
            .stdout(std::process::Stdio::null())
            .stderr(if std::env::var_os("KERF_TEST_LOG").is_some() {
                std::process::Stdio::inherit()
            } else {
                std::process::Stdio::null()
            })
            .spawn()
            .expect("server starts");
        let mut server = Self { base: format!("http://127.0.0.1:{port}"), child };
        let client = Client::new();
        for _ in 0..400 {
            if client.get(format!("{}/healthz", server.base)).send().await.is_ok_and(|r| r.status().is_success()) {
                return server;
            }
            if let Ok(Some(status)) = server.child.try_wait() {
                panic!("{} {arguments:?} exited with {status} before answering", program.display());
            }
            tokio::time::sleep(Duration::from_millis(50)).await;
        }
        panic!("the server did not come up on port {port}");
    }

    /// The process id (to send it signals).
    pub fn id(&self) -> u32 {
        self.child.id()
    }

    /// Asks the process to stop (SIGTERM) and waits for it.
    pub fn terminate(mut self) {
        let _ = std::process::Command::new("kill").arg("-TERM").arg(self.child.id().to_string()).status();
        let _ = self.child.wait();
    }

    /// Kills the process at once (SIGKILL), as a power cut or `kill -9` would.
    pub fn kill(mut self) {
        self.child.kill().expect("kill");
        self.child.wait().expect("wait");
    }
}

impl Drop for ServerProcess {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// A loopback port free right now.
pub fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0").and_then(|l| l.local_addr()).expect("free port").port()
}

/// Polls job `id` at `base` until `done(job)` or `seconds` pass; returns the last state.
pub async fn poll_job(client: &Client, base: &str, id: i64, seconds: u64, done: impl Fn(&Value) -> bool) -> Value {
    let deadline = std::time::Instant::now() + Duration::from_secs(seconds);
    loop {
        let job: Value =
            client.get(format!("{base}/api/v1/jobs/{id}")).send().await.expect("poll").json().await.expect("job");
        if done(&job) || std::time::Instant::now() > deadline {
            return job;
        }
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
}

/// True once a job reached a final status.
pub fn finished(job: &Value) -> bool {
    matches!(job["status"].as_str(), Some("done" | "failed" | "cancelled"))
}

/// Tool table for `rs274`: every pocket 1–99 holds a tool, so any program's `T n M06` and
/// `G43 H n` resolve.
fn rs274_tool_table() -> String {
    (1..100).map(|n| format!("T{n} P{n} D6.0 Z0 ;test tool\n")).collect()
}

/// Asserts that the moves `rs274` interpreted are `expected` (is a feed move, end point), in
/// count, kind and end point within 1e-4 mm; `label` names the program in the messages.
pub fn assert_moves_match(label: &str, interpreted: &[(bool, [f64; 3])], expected: &[(bool, [f64; 3])]) {
    assert_eq!(interpreted.len(), expected.len(), "{label}: move count");
    for (index, (got, want)) in interpreted.iter().zip(expected).enumerate() {
        assert_eq!(got.0, want.0, "{label}: move {index} kind");
        for axis in 0..3 {
            assert!((got.1[axis] - want.1[axis]).abs() <= 1e-4, "{label}: move {index} {got:?} vs {want:?}");
        }
    }
}

/// Runs `program` through LinuxCNC's `rs274` (writing it to `folder/name.ngc`), asserts that the
/// interpreter accepts it to its end without complaint, and returns its canonical moves:
/// (is a feed move, end point). Arcs (`ARC_FEED`) count as feed moves to their end point, in the
/// plane the program selected. Coordinates are in the program's units. Always `Some` (see
/// [`external_program`]).
pub fn rs274_moves(program: &str, folder: &Path, name: &str) -> Option<Vec<(bool, [f64; 3])>> {
    let rs274 = external_program("rs274", "the LinuxCNC G-code check")?;
    let file = folder.join(format!("{name}.ngc"));
    std::fs::write(&file, program).expect("write program");
    let table = folder.join("rs274-tools.tbl");
    std::fs::write(&table, rs274_tool_table()).expect("write tool table");
    // rs274 instances running at once share LinuxCNC state and crash or lose the tool table (a
    // bus error, "tool not found"): one at a time on this machine, across test processes too.
    let lock = std::fs::File::create(std::env::temp_dir().join("kerf-rs274.lock")).expect("rs274 lock file");
    lock.lock().expect("rs274 lock");
    let output = std::process::Command::new(rs274)
        .arg("-t")
        .arg(&table)
        .arg("-g")
        .arg(&file)
        .stdin(std::process::Stdio::null())
        .output()
        .expect("rs274 runs");
    drop(lock);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "rs274 rejected {name}: {stderr}\n{program}");
    let complaints: Vec<&str> = stderr.lines().filter(|l| !l.trim().is_empty() && l.trim() != "executing").collect();
    assert!(complaints.is_empty(), "rs274 complained about {name}: {complaints:?}");
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(stdout.contains("PROGRAM_END"), "{name} runs to its end");
    // Axis indices (first, second, normal) of ARC_FEED's end point in the selected plane.
    let mut plane = [0, 1, 2];
    Some(
        stdout
            .lines()
            .filter_map(|line| {
                if line.contains("SELECT_PLANE(") {
                    plane = if line.contains("CANON_PLANE_XZ") {
                        [2, 0, 1]
                    } else if line.contains("CANON_PLANE_YZ") {
                        [1, 2, 0]
                    } else {
                        [0, 1, 2]
                    };
                    return None;
                }
                let inside = line.split('(').nth(1)?.split(')').next()?;
                let numbers: Vec<f64> = inside.split(',').take(6).filter_map(|n| n.trim().parse().ok()).collect();
                if line.contains("ARC_FEED(") && numbers.len() == 6 {
                    let mut end = [0.0; 3];
                    end[plane[0]] = numbers[0];
                    end[plane[1]] = numbers[1];
                    end[plane[2]] = numbers[5];
                    return Some((true, end));
                }
                let feed = line.contains("STRAIGHT_FEED(");
                if !feed && !line.contains("STRAIGHT_TRAVERSE(") {
                    return None;
                }
                (numbers.len() >= 3).then(|| (feed, [numbers[0], numbers[1], numbers[2]]))
            })
            .collect(),
    )
}
