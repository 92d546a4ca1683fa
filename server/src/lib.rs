//! kerf's HTTP service: axum routes per resource over SQLite or PostgreSQL (sqlx), problem+json errors, the
//! OpenAPI document with interactive docs, and the embedded web page. Geometry lives in
//! `kerf_solver`; handlers validate, resolve stored references and hand the work to the solver
//! on the blocking pool.

pub mod answer_cache;
pub mod app;
pub mod auth;
pub mod capabilities;
pub mod cli;
pub mod db;
pub mod error;
pub mod extract;
pub mod http;
pub mod jobs;
pub mod metrics;
pub mod openapi;
pub mod state;
pub mod store;
pub mod web;

use std::future::Future;

use hyper_util::rt::{TokioExecutor, TokioIo, TokioTimer};
use hyper_util::server::conn::auto;
use hyper_util::server::graceful::GracefulShutdown;
use hyper_util::service::TowerToHyperService;
use tokio::net::TcpListener;

use crate::state::Limits;

/// Serves `router` on `listener` until `shutdown` completes, then lets the open requests finish
/// for at most `limits.shutdown_grace` and drops what is left, so a slow or hostile client cannot
/// keep a stopped server alive. A client that takes longer than `limits.header_read_timeout` to
/// send its headers is disconnected.
///
/// # Errors
/// Never at present: a failed accept (for example out of file descriptors) is logged and retried.
pub async fn serve(
    listener: TcpListener,
    router: axum::Router,
    limits: Limits,
    shutdown: impl Future<Output = ()> + Send + 'static,
) -> std::io::Result<()> {
    let mut builder = auto::Builder::new(TokioExecutor::new());
    builder.http1().timer(TokioTimer::new()).header_read_timeout(limits.header_read_timeout);
    builder.http2().timer(TokioTimer::new());
    let graceful = GracefulShutdown::new();
    tokio::pin!(shutdown);
    loop {
        tokio::select! {
            accepted = listener.accept() => {
                let stream = match accepted {
                    Ok((stream, _)) => stream,
                    Err(error) => {
                        tracing::warn!(%error, "accepting a connection failed");
                        tokio::time::sleep(std::time::Duration::from_millis(50)).await;
                        continue;
                    }
                };
                let service = TowerToHyperService::new(router.clone());
                let connection = builder.serve_connection_with_upgrades(TokioIo::new(stream), service).into_owned();
                let connection = graceful.watch(connection);
                tokio::spawn(async move {
                    if let Err(error) = connection.await {
                        tracing::debug!(%error, "connection ended with an error");
                    }
                });
            }
            () = &mut shutdown => break,
        }
    }
    drop(listener);
    if tokio::time::timeout(limits.shutdown_grace, graceful.shutdown()).await.is_err() {
        tracing::warn!(
            grace_s = limits.shutdown_grace.as_secs_f64(),
            "open connections dropped at the shutdown deadline"
        );
    }
    Ok(())
}
