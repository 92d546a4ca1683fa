//! The conventions every answer follows (docs/spec/api.md, Conventions): CORS for the configured
//! origins, gzip above 1 KiB, `X-Request-Id` echoed or made and logged with one line per request,
//! JSON or plain-text log lines, 413 before the body with `Connection: close`, liveness apart from
//! the database, and paged registry lists.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::Duration;

use kerf_server::state::Limits;
use kerf_tests::{Store, TestApp, free_port, json_with, problem};
use reqwest::Client;
use serde_json::{Value, json};
use tokio::io::{AsyncReadExt, AsyncWriteExt};

const ORIGIN: &str = "https://cam.example.com";

fn header<'a>(response: &'a reqwest::Response, name: &str) -> &'a str {
    response.headers().get(name).and_then(|v| v.to_str().ok()).unwrap_or_default()
}

/// The items of every `name` header line of `response`, lower case.
fn listed_in(response: &reqwest::Response, name: &str) -> Vec<String> {
    response
        .headers()
        .get_all(name)
        .iter()
        .filter_map(|v| v.to_str().ok())
        .flat_map(|list| list.split(','))
        .map(|item| item.trim().to_ascii_lowercase())
        .collect()
}

#[tokio::test(flavor = "multi_thread")]
async fn cors_answers_preflights_for_the_configured_origins_only() {
    let app = TestApp::spawn_configured(|config| config.cors_origins = vec![ORIGIN.to_owned()]).await;
    let preflight = |origin: &str| {
        app.client
            .request(reqwest::Method::OPTIONS, app.url("/api/v1/tools/7"))
            .header("origin", origin)
            .header("access-control-request-method", "PUT")
            .header("access-control-request-headers", "content-type, if-match, authorization")
            .send()
    };
    let answer = preflight(ORIGIN).await.unwrap();
    assert_eq!(answer.status(), 200, "preflight: {:?}", answer.headers());
    assert_eq!(header(&answer, "access-control-allow-origin"), ORIGIN);
    assert!(listed_in(&answer, "access-control-allow-methods").contains(&"put".to_owned()), "{answer:?}");
    let allowed = listed_in(&answer, "access-control-allow-headers");
    for name in ["content-type", "if-match", "authorization"] {
        assert!(allowed.contains(&name.to_owned()), "{name} in {allowed:?}");
    }
    // Another origin's page is not allowed.
    let other = preflight("https://elsewhere.example").await.unwrap();
    assert!(other.headers().get("access-control-allow-origin").is_none(), "{other:?}");
    // An answer names the headers a page may read.
    let listing = app.client.get(app.url("/api/v1/tools")).header("origin", ORIGIN).send().await.unwrap();
    assert_eq!(header(&listing, "access-control-allow-origin"), ORIGIN);
    let exposed = listed_in(&listing, "access-control-expose-headers");
    for name in ["etag", "x-request-id", "retry-after", "location"] {
        assert!(exposed.contains(&name.to_owned()), "{name} in {exposed:?}");
    }
    // Without origins (the default) nothing changes: no CORS headers, a preflight is 405.
    let closed = TestApp::spawn().await;
    let answer = closed
        .client
        .request(reqwest::Method::OPTIONS, closed.url("/api/v1/tools/7"))
        .header("origin", ORIGIN)
        .header("access-control-request-method", "PUT")
        .send()
        .await
        .unwrap();
    assert_eq!(answer.status(), 405);
    assert!(answer.headers().get("access-control-allow-origin").is_none());
}

fn gunzip(bytes: &[u8]) -> Vec<u8> {
    let mut plain = Vec::new();
    flate2::read::GzDecoder::new(bytes).read_to_end(&mut plain).expect("a gzip stream");
    plain
}

/// The answer to `request` as sent (`Accept-Encoding: identity`) and gzipped: the gzipped one
/// says so, varies by `Accept-Encoding`, and unpacks to the same bytes.
async fn same_when_gzipped(what: &str, request: impl Fn() -> reqwest::RequestBuilder) -> usize {
    let plain = request().header("accept-encoding", "identity").send().await.unwrap();
    assert_eq!(plain.status(), 200, "{what}");
    assert!(plain.headers().get("content-encoding").is_none(), "{what}: {plain:?}");
    let plain = plain.bytes().await.unwrap();
    let packed = request().header("accept-encoding", "br;q=1, gzip;q=0.8").send().await.unwrap();
    assert_eq!(packed.status(), 200, "{what}");
    assert_eq!(header(&packed, "content-encoding"), "gzip", "{what}: {packed:?}");
    assert!(listed_in(&packed, "vary").contains(&"accept-encoding".to_owned()), "{what}: {packed:?}");
    let packed = packed.bytes().await.unwrap();
    assert!(packed.len() < plain.len() / 2, "{what}: {} gzipped of {}", packed.len(), plain.len());
    assert_eq!(gunzip(&packed), plain, "{what}");
    plain.len()
}

#[tokio::test(flavor = "multi_thread")]
async fn answers_above_a_kibibyte_are_gzipped_when_the_client_accepts_it() {
    let app = TestApp::spawn().await;
    let segment = json!({"curve": {"kind": "circle", "centre": [0, 0], "radius": 20},
        "feed": 6000, "block_time_ms": 4, "margin": 1.1});
    let listing = same_when_gzipped("materials", || app.client.get(app.url("/api/v1/materials"))).await;
    assert!(listing > 1024);
    let json = same_when_gzipped("segment JSON", || app.client.post(app.url("/api/v1/segment")).json(&segment)).await;
    assert!(json > 1024);
    let program =
        same_when_gzipped("segment G-code", || app.client.post(app.url("/api/v1/segment?format=gcode")).json(&segment))
            .await;
    assert!(program > 1024);
    // Refused by q=0, or small: as it is.
    let refused = app
        .client
        .get(app.url("/api/v1/materials"))
        .header("accept-encoding", "gzip;q=0, identity")
        .send()
        .await
        .unwrap();
    assert!(refused.headers().get("content-encoding").is_none(), "{refused:?}");
    let small = app.client.get(app.url("/healthz")).header("accept-encoding", "gzip").send().await.unwrap();
    assert!(small.headers().get("content-encoding").is_none(), "{small:?}");
    json_with(small, 200).await;
    // A stored item is sent with its strong ETag as it is, never gzipped under that tag.
    // 500 characters, the most a description may have, of two bytes each: over the size.
    let description = "ü".repeat(500);
    let material = json!({"kc11": 1700, "mc": 0.25, "description": description});
    let put = app.client.put(app.url("/api/v1/materials/long")).json(&material).send().await.unwrap();
    assert!(put.status().is_success(), "{put:?}");
    let stored =
        app.client.get(app.url("/api/v1/materials/long")).header("accept-encoding", "gzip").send().await.unwrap();
    assert!(stored.headers().get("etag").is_some(), "{stored:?}");
    assert!(stored.headers().get("content-encoding").is_none(), "{stored:?}");
    assert!(stored.bytes().await.unwrap().len() as u64 > kerf_server::app::COMPRESS_ABOVE_BYTES);
    // A problem above the size is gzipped too, and still reads as one.
    let mut body = segment.clone();
    body["padding"] = json!("x".repeat(4000));
    let answer =
        app.client.post(app.url("/api/v1/segment")).header("accept-encoding", "gzip").json(&body).send().await.unwrap();
    assert_eq!(answer.status(), 400);
    let packed = header(&answer, "content-encoding") == "gzip";
    let bytes = answer.bytes().await.unwrap();
    let text = if packed { gunzip(&bytes) } else { bytes.to_vec() };
    let problem: Value = serde_json::from_slice(&text).unwrap();
    assert_eq!(problem["errors"][0]["path"], "padding", "{problem}");
}

fn is_made_id(id: &str) -> bool {
    id.len() == 32 && id.bytes().all(|b| b.is_ascii_hexdigit())
}

#[tokio::test(flavor = "multi_thread")]
async fn every_answer_carries_a_request_id() {
    let app = TestApp::spawn().await;
    let with_id = |method: reqwest::Method, path: &str, id: Option<&str>| {
        let mut request = app.client.request(method, app.url(path));
        if let Some(id) = id {
            request = request.header("x-request-id", id);
        }
        request.send()
    };
    // The client's own is echoed, on success and on every kind of problem.
    for (method, path, status) in [
        (reqwest::Method::GET, "/api/v1/tools", 200),
        (reqwest::Method::GET, "/api/v1/tools/77", 404),
        (reqwest::Method::GET, "/api/v1/tools/0", 422),
        (reqwest::Method::GET, "/api/v1/tools?limit=0", 400),
        (reqwest::Method::PATCH, "/api/v1/tools/7", 405),
        (reqwest::Method::GET, "/no/such/thing", 404),
    ] {
        let answer = with_id(method.clone(), path, Some("shop-42/a.b_c")).await.unwrap();
        assert_eq!(answer.status(), status, "{method} {path}");
        assert_eq!(header(&answer, "x-request-id"), "shop-42/a.b_c", "{method} {path}");
    }
    // Without one, or with one too long or not printable, one is made: a new one each time.
    let first = with_id(reqwest::Method::GET, "/healthz", None).await.unwrap();
    let second = with_id(reqwest::Method::GET, "/healthz", None).await.unwrap();
    let (first, second) = (header(&first, "x-request-id").to_owned(), header(&second, "x-request-id").to_owned());
    assert!(is_made_id(&first) && is_made_id(&second), "{first} {second}");
    assert_ne!(first, second);
    for unusable in ["x".repeat(129), "two words".to_owned(), String::new()] {
        let answer = with_id(reqwest::Method::GET, "/api/v1/tools/77", Some(&unusable)).await.unwrap();
        assert_eq!(answer.status(), 404);
        assert!(is_made_id(header(&answer, "x-request-id")), "{unusable:?}: {answer:?}");
    }
    let longest = "y".repeat(128);
    let answer = with_id(reqwest::Method::GET, "/healthz", Some(&longest)).await.unwrap();
    assert_eq!(header(&answer, "x-request-id"), longest);
}

/// The `kerf` program serving on a fresh database with `arguments` and `environment`, its log
/// (standard error, and standard output) written to files of `folder`.
struct LoggingServer {
    base: String,
    child: Child,
    log: PathBuf,
}

impl LoggingServer {
    async fn start(folder: &Path, arguments: &[&str], environment: &[(&str, &str)]) -> Self {
        let port = free_port();
        let log = folder.join("stderr.log");
        let child = Command::new(env!("CARGO_BIN_EXE_kerf-under-test"))
            .arg("serve")
            .arg("--database")
            .arg(folder.join("kerf.db"))
            .arg("--bind")
            .arg(format!("127.0.0.1:{port}"))
            .args(arguments)
            .env_remove("RUST_LOG")
            .env_remove("KERF_LOG_FORMAT")
            .env_remove("KERF_CORS_ORIGINS")
            .envs(environment.iter().copied())
            .stdout(std::fs::File::create(folder.join("stdout.log")).unwrap())
            .stderr(std::fs::File::create(&log).unwrap())
            .stdin(Stdio::null())
            .spawn()
            .expect("kerf starts");
        let mut server = Self { base: format!("http://127.0.0.1:{port}"), child, log };
        let client = Client::new();
        for _ in 0..400 {
            if client.get(format!("{}/healthz", server.base)).send().await.is_ok_and(|r| r.status().is_success()) {
                return server;
            }
            if let Ok(Some(status)) = server.child.try_wait() {
                panic!("kerf exited with {status}: {}", std::fs::read_to_string(&server.log).unwrap_or_default());
            }
            tokio::time::sleep(Duration::from_millis(50)).await;
        }
        panic!("kerf did not come up on port {port}");
    }

    /// The log so far, once it holds `wanted` (waiting up to 10 s for the line to be written).
    async fn log_with(&self, wanted: &str) -> String {
        for _ in 0..200 {
            let log = std::fs::read_to_string(&self.log).unwrap_or_default();
            if log.contains(wanted) {
                return log;
            }
            tokio::time::sleep(Duration::from_millis(50)).await;
        }
        panic!("no log line with {wanted:?}: {}", std::fs::read_to_string(&self.log).unwrap_or_default());
    }
}

impl Drop for LoggingServer {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

#[tokio::test(flavor = "multi_thread")]
async fn json_log_lines_name_each_request_with_its_id() {
    let folder = tempfile::tempdir().unwrap();
    let server = LoggingServer::start(folder.path(), &["--log-format", "json", "--cors-origin", ORIGIN], &[]).await;
    let client = Client::new();
    let answer = client
        .get(format!("{}/api/v1/tools/5", server.base))
        .header("x-request-id", "json-line-check-1")
        .header("origin", ORIGIN)
        .send()
        .await
        .unwrap();
    assert_eq!(answer.status(), 404);
    assert_eq!(header(&answer, "access-control-allow-origin"), ORIGIN, "--cors-origin reaches the service");
    let log = server.log_with("json-line-check-1").await;
    let lines: Vec<Value> = log
        .lines()
        .map(|line| serde_json::from_str(line).unwrap_or_else(|error| panic!("not a JSON line ({error}): {line}")))
        .collect();
    let ours: Vec<&Value> = lines.iter().filter(|line| line["span"]["request_id"] == "json-line-check-1").collect();
    assert_eq!(ours.len(), 1, "one line for the request: {ours:?}");
    let line = ours[0];
    assert_eq!(line["level"], "INFO", "{line}");
    assert_eq!(line["span"]["method"], "GET", "{line}");
    assert_eq!(line["span"]["route"], "/api/v1/tools/{number}", "{line}");
    assert_eq!(line["fields"]["status"], 404, "{line}");
    assert!(line["fields"]["duration_ms"].as_f64().is_some_and(|ms| ms >= 0.0), "{line}");
    assert!(line["timestamp"].is_string(), "{line}");
    // Nothing on standard output.
    assert_eq!(std::fs::read_to_string(folder.path().join("stdout.log")).unwrap(), "");
}

#[tokio::test(flavor = "multi_thread")]
async fn text_log_lines_have_no_colour_codes_off_a_terminal() {
    let folder = tempfile::tempdir().unwrap();
    let server = LoggingServer::start(
        folder.path(),
        &[],
        &[("KERF_LOG_FORMAT", "text"), ("KERF_CORS_ORIGINS", &format!("https://a.example,{ORIGIN}"))],
    )
    .await;
    let client = Client::new();
    let answer = client
        .get(format!("{}/api/v1/materials", server.base))
        .header("x-request-id", "text-line-check-2")
        .header("origin", ORIGIN)
        .send()
        .await
        .unwrap();
    assert_eq!(answer.status(), 200);
    assert_eq!(header(&answer, "access-control-allow-origin"), ORIGIN, "KERF_CORS_ORIGINS, comma-separated");
    let log = server.log_with("text-line-check-2").await;
    assert!(!log.contains('\u{1b}'), "ANSI escapes in a log file: {log:?}");
    let line = log.lines().find(|line| line.contains("text-line-check-2")).unwrap();
    for part in
        ["INFO", "request_id=text-line-check-2", "route=/api/v1/materials", "method=GET", "status=200", "duration_ms="]
    {
        assert!(line.contains(part), "{part} in {line}");
    }
}

/// Reads `stream` until the server closes it (or 20 s pass, which fails the test).
async fn read_to_close(stream: &mut tokio::net::TcpStream) -> String {
    let mut received = Vec::new();
    let closed = tokio::time::timeout(Duration::from_secs(20), async {
        let mut buffer = [0_u8; 4096];
        loop {
            match stream.read(&mut buffer).await {
                Ok(0) => return Ok(()),
                Ok(n) => received.extend_from_slice(&buffer[..n]),
                Err(error) => return Err(error),
            }
        }
    })
    .await;
    let text = String::from_utf8_lossy(&received).into_owned();
    match closed {
        Ok(Ok(())) => text,
        Ok(Err(error)) => panic!("the connection broke ({error}) instead of closing; received: {text}"),
        Err(_) => panic!("no 413 and close within 20 s; received: {text}"),
    }
}

#[tokio::test(flavor = "multi_thread")]
async fn a_body_declared_over_the_limit_gets_413_and_close_before_it_is_sent() {
    let app = TestApp::spawn_with(Limits { max_body_bytes: 1024, ..Limits::default() }).await;
    let address = app.base.trim_start_matches("http://").to_owned();
    for (route, media_type) in [
        ("PUT /api/v1/tools/7", "application/json"),
        ("POST /api/v1/segment", "application/json"),
        ("POST /api/v1/jobs", "application/toml"),
    ] {
        // The headers alone: the 413 comes without waiting for the body.
        let mut stream = tokio::net::TcpStream::connect(&address).await.unwrap();
        let head =
            format!("{route} HTTP/1.1\r\nHost: kerf\r\nContent-Type: {media_type}\r\nContent-Length: 5000000\r\n\r\n");
        stream.write_all(head.as_bytes()).await.unwrap();
        let answer = read_to_close(&mut stream).await;
        assert!(answer.starts_with("HTTP/1.1 413"), "{route}: {answer}");
        assert!(answer.to_ascii_lowercase().contains("\r\nconnection: close\r\n"), "{route}: {answer}");
        assert!(answer.contains("E_TOO_LARGE"), "{route}: {answer}");
    }
    // A client that sends its body at once still reads the 413 (not a reset) and the close.
    let mut stream = tokio::net::TcpStream::connect(&address).await.unwrap();
    let body = vec![b' '; 4_000_000];
    let head = format!(
        "PUT /api/v1/tools/7 HTTP/1.1\r\nHost: kerf\r\nContent-Type: application/json\r\nContent-Length: {}\r\n\r\n",
        body.len()
    );
    let (mut reading, mut writing) = stream.split();
    let send = async {
        let _ = writing.write_all(head.as_bytes()).await;
        let _ = writing.write_all(&body).await;
    };
    let receive = async {
        let mut received = Vec::new();
        let mut buffer = [0_u8; 4096];
        loop {
            match reading.read(&mut buffer).await {
                Ok(0) => return Ok(received),
                Ok(n) => received.extend_from_slice(&buffer[..n]),
                Err(error) => return Err((error, received)),
            }
        }
    };
    let (_, received) = tokio::time::timeout(Duration::from_secs(20), async { tokio::join!(send, receive) })
        .await
        .expect("an answer within 20 s");
    let received = received.unwrap_or_else(|(error, received)| {
        panic!("the connection broke ({error}); received: {}", String::from_utf8_lossy(&received))
    });
    let answer = String::from_utf8_lossy(&received);
    assert!(answer.starts_with("HTTP/1.1 413"), "{answer}");
    assert!(answer.to_ascii_lowercase().contains("\r\nconnection: close\r\n"), "{answer}");
    assert_eq!(app.get("/api/v1/tools/7").await.status(), 404);
}

#[tokio::test(flavor = "multi_thread")]
async fn liveness_does_not_need_the_database_readiness_does() {
    let app = TestApp::spawn().await;
    // A second service on the same file whose database pool this test holds and closes.
    let (router, state) = kerf_server::app::build(&app.config).await.expect("service builds");
    let listener = tokio::net::TcpListener::bind("127.0.0.1:0").await.unwrap();
    let base = format!("http://{}", listener.local_addr().unwrap());
    let limits = app.config.limits.clone();
    let served = tokio::spawn(kerf_server::serve(listener, router, limits, std::future::pending()));
    let client = Client::new();
    assert_eq!(client.get(format!("{base}/readyz")).send().await.unwrap().status(), 200);
    assert_eq!(client.get(format!("{base}/healthz")).send().await.unwrap().status(), 200);
    state.db.close().await;
    let ready = client.get(format!("{base}/readyz")).send().await.unwrap();
    assert!(ready.headers().get("retry-after").is_some(), "{ready:?}");
    assert_eq!(problem(ready, 503).await["code"], "E_UNAVAILABLE");
    let live = client.get(format!("{base}/healthz")).send().await.unwrap();
    assert_eq!(json_with(live, 200).await["status"], "ok", "liveness holds while the database is gone");
    served.abort();
}

async fn names(app: &TestApp, path: &str, key: &str) -> Vec<Value> {
    let list = json_with(app.get(path).await, 200).await;
    list.as_array().unwrap_or_else(|| panic!("{path}: {list}")).iter().map(|item| item[key].clone()).collect()
}

kerf_tests::on_both_stores!(registry_lists_page_with_limit_and_after);

async fn registry_lists_page_with_limit_and_after(store: Store) {
    let app = TestApp::spawn_on(store, |_| {}).await.expect("a service on the store");
    for number in [3, 1, 9, 4, 7] {
        app.register_tool(number, &json!({"kind": "flat", "radius": 2})).await;
    }
    assert_eq!(names(&app, "/api/v1/tools", "number").await, [1, 3, 4, 7, 9]);
    assert_eq!(names(&app, "/api/v1/tools?limit=2", "number").await, [1, 3]);
    assert_eq!(names(&app, "/api/v1/tools?limit=2&after=3", "number").await, [4, 7]);
    assert_eq!(names(&app, "/api/v1/tools?after=7&limit=2", "number").await, [9]);
    assert_eq!(names(&app, "/api/v1/tools?after=9", "number").await, Vec::<Value>::new());
    for name in ["mill-b", "lathe", "mill-a"] {
        let response =
            app.put_json(&format!("/api/v1/machines/{name}"), &json!({"block_time_ms": 4, "max_feed": 12000})).await;
        json_with(response, 201).await;
    }
    assert_eq!(names(&app, "/api/v1/machines?limit=2", "name").await, ["lathe", "mill-a"]);
    assert_eq!(names(&app, "/api/v1/machines?limit=2&after=mill-a", "name").await, ["mill-b"]);
    // The seeded materials, a page at a time, give the whole list in order.
    let all = names(&app, "/api/v1/materials", "name").await;
    assert!(all.len() > 3, "{all:?}");
    let mut paged: Vec<Value> = Vec::new();
    loop {
        let after = paged.last().and_then(Value::as_str).map(|name| format!("&after={name}")).unwrap_or_default();
        let page = names(&app, &format!("/api/v1/materials?limit=3{after}"), "name").await;
        assert!(page.len() <= 3);
        let last = page.len() < 3;
        paged.extend(page);
        if last {
            break;
        }
    }
    assert_eq!(paged, all);
    // Out of range or not a number: 400 naming the parameter.
    for (query, field) in [
        ("/api/v1/tools?limit=0", "limit"),
        ("/api/v1/tools?limit=1001", "limit"),
        ("/api/v1/tools?limit=ten", "limit"),
        ("/api/v1/tools?after=-1", "after"),
        ("/api/v1/tools?after=10000", "after"),
        ("/api/v1/machines?limit=-5", "limit"),
        ("/api/v1/materials?limit=100000", "limit"),
        ("/api/v1/materials?page=2", "page"),
    ] {
        let answer = problem(app.get(query).await, 400).await;
        assert_eq!(answer["code"], "E_QUERY", "{query}: {answer}");
        assert_eq!(answer["errors"][0]["path"], field, "{query}: {answer}");
    }
}
