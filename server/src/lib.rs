//! kerf's HTTP service: axum routes per resource over SQLite or PostgreSQL (sqlx), problem+json errors, the
//! OpenAPI document with interactive docs, and the embedded web page. Geometry lives in
//! `kerf_solver`; handlers validate, resolve stored references and hand the work to the solver
//! on the blocking pool.

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

use tokio::net::TcpListener;

/// Serves `router` on `listener` until `shutdown` completes, then finishes the open requests.
///
/// # Errors
/// When the listener fails.
pub async fn serve(
    listener: TcpListener,
    router: axum::Router,
    shutdown: impl Future<Output = ()> + Send + 'static,
) -> std::io::Result<()> {
    axum::serve(listener, router).with_graceful_shutdown(shutdown).await
}
