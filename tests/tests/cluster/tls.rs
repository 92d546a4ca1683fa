//! PostgreSQL over TLS, as managed PostgreSQL services require: a throw-away server with `ssl=on`
//! that accepts only TLS connections (`hostssl`), its certificate signed by a certificate
//! authority made here with the `openssl` program. kerf connects with `sslmode=require` (encrypted,
//! the certificate not checked) and with `sslmode=verify-full&sslrootcert=CA` (the chain and the
//! host name checked); given another authority it refuses to start, with the reason on its error
//! output and no panic.

use std::path::Path;
use std::process::Command;

use kerf_server::db::{self, Database, Db};
use kerf_tests::external::{postgres_user, running_as_root};
use kerf_tests::{PgServer, ServerProcess, free_port};

/// Runs `openssl ARGUMENTS` in `folder`.
fn openssl(folder: &Path, arguments: &[&str]) {
    let output = Command::new("openssl").args(arguments).current_dir(folder).output().expect("openssl runs");
    assert!(output.status.success(), "openssl {arguments:?}: {}", String::from_utf8_lossy(&output.stderr));
}

/// A self-signed certificate authority `ca.crt` with its key `ca.key` in `folder`, named `name`.
fn certificate_authority(folder: &Path, name: &str) {
    let (key, certificate, subject) = ("ca.key", "ca.crt", format!("/CN={name}"));
    openssl(
        folder,
        &[
            "req",
            "-x509",
            "-newkey",
            "ec",
            "-pkeyopt",
            "ec_paramgen_curve:P-256",
            "-nodes",
            "-days",
            "2",
            "-subj",
            &subject,
            "-keyout",
            key,
            "-out",
            certificate,
            "-addext",
            "basicConstraints=critical,CA:TRUE",
            "-addext",
            "keyUsage=critical,keyCertSign,cRLSign",
        ],
    );
}

/// `server.crt` and `server.key` in `folder`, for 127.0.0.1 and localhost, signed by `ca`.
fn server_certificate(folder: &Path, ca: &Path) {
    openssl(
        folder,
        &[
            "req",
            "-newkey",
            "ec",
            "-pkeyopt",
            "ec_paramgen_curve:P-256",
            "-nodes",
            "-subj",
            "/CN=127.0.0.1",
            "-keyout",
            "server.key",
            "-out",
            "server.csr",
        ],
    );
    let extensions = folder.join("server.ext");
    std::fs::write(
        &extensions,
        "basicConstraints=CA:FALSE\nkeyUsage=critical,digitalSignature\nextendedKeyUsage=serverAuth\n\
         subjectAltName=IP:127.0.0.1,DNS:localhost\n",
    )
    .unwrap();
    openssl(
        folder,
        &[
            "x509",
            "-req",
            "-in",
            "server.csr",
            "-days",
            "2",
            "-CA",
            &ca.join("ca.crt").display().to_string(),
            "-CAkey",
            &ca.join("ca.key").display().to_string(),
            "-CAcreateserial",
            "-out",
            "server.crt",
            "-extfile",
            "server.ext",
        ],
    );
}

/// Restarts `postgres` with `ssl=on`, the certificate and key from `certificates`, and only TLS
/// connections over TCP.
fn serve_only_tls(postgres: &PgServer, certificates: &Path) {
    let folder = postgres.directory();
    for file in ["server.crt", "server.key"] {
        let copy = folder.join(file);
        std::fs::copy(certificates.join(file), &copy).unwrap();
        // PostgreSQL reads a key only its own user can read.
        std::fs::set_permissions(&copy, std::os::unix::fs::PermissionsExt::from_mode(0o600)).unwrap();
        if running_as_root() {
            let (uid, gid) = postgres_user().expect("the postgres user");
            std::os::unix::fs::chown(&copy, Some(uid), Some(gid)).unwrap();
        }
    }
    let data = folder.join("data");
    let mut configuration = std::fs::read_to_string(data.join("postgresql.conf")).unwrap();
    configuration.push_str(&format!(
        "\nssl = on\nssl_cert_file = '{}'\nssl_key_file = '{}'\n",
        folder.join("server.crt").display(),
        folder.join("server.key").display()
    ));
    std::fs::write(data.join("postgresql.conf"), configuration).unwrap();
    std::fs::write(data.join("pg_hba.conf"), "local all all trust\nhostssl all all 127.0.0.1/32 trust\n").unwrap();
    postgres.stop_fast();
    postgres.start_again();
}

/// Whether the connection `db` holds is encrypted, as the server sees it.
async fn encrypted(db: &Db) -> bool {
    let Db::Postgres(pool) = db else { panic!("a PostgreSQL store") };
    sqlx::query_scalar("SELECT ssl FROM pg_stat_ssl WHERE pid = pg_backend_pid()").fetch_one(pool).await.unwrap()
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(all(kerf_has_postgres, kerf_has_openssl)),
    ignore = "PostgreSQL or openssl not found: apt-get install postgresql openssl"
)]
async fn kerf_reaches_postgres_over_tls_and_refuses_an_unknown_authority() {
    let postgres = PgServer::start().expect("PostgreSQL starts");
    let (authority, other) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    certificate_authority(authority.path(), "kerf test authority");
    certificate_authority(other.path(), "another authority");
    server_certificate(authority.path(), authority.path());
    serve_only_tls(&postgres, authority.path());

    let url = |query: &str| format!("{}?{query}", postgres.url());
    let plain = db::open(&Database::Postgres(url("sslmode=disable"))).await;
    let refused = plain.expect_err("the server takes only TLS connections").to_string();
    assert!(refused.contains("connecting to"), "{refused}");

    let root = |folder: &Path| folder.join("ca.crt").display().to_string();
    let verified = url(&format!("sslmode=verify-full&sslrootcert={}", root(authority.path())));
    for database in [url("sslmode=require"), verified.clone()] {
        let db = db::open(&Database::Postgres(database.clone()))
            .await
            .unwrap_or_else(|error| panic!("{database}: {error:#}"));
        assert!(encrypted(&db).await, "{database}: not encrypted");
        db.close().await;
    }

    // The service itself on the verified connection: it starts, migrated, and is ready.
    let program = Path::new(env!("CARGO_BIN_EXE_kerf-under-test"));
    let server = ServerProcess::start_with(program, &["serve", "--database", &verified, "--job-workers", "0"]).await;
    let ready = reqwest::get(format!("{}/readyz", server.base)).await.unwrap();
    assert_eq!(ready.status(), 200);
    drop(server);

    // Another authority's root: the server's certificate is not trusted and kerf does not start.
    let wrong = url(&format!("sslmode=verify-full&sslrootcert={}", root(other.path())));
    let bind = format!("127.0.0.1:{}", free_port());
    let output = tokio::task::spawn_blocking(move || {
        Command::new(program).args(["serve", "--database", &wrong, "--bind", &bind]).env("RUST_LOG", "off").output()
    })
    .await
    .unwrap()
    .expect("kerf runs");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "kerf stops with an error: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(stderr.contains("connecting to postgres://") && stderr.contains("certificate"), "{stderr}");
}
