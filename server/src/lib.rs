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
use std::io;
use std::pin::Pin;
use std::task::{Context, Poll};
use std::time::Duration;

use hyper_util::rt::{TokioExecutor, TokioIo, TokioTimer};
use hyper_util::server::conn::auto;
use hyper_util::server::graceful::GracefulShutdown;
use hyper_util::service::TowerToHyperService;
use tokio::io::{AsyncRead, AsyncReadExt, AsyncWrite, AsyncWriteExt, ReadBuf};
use tokio::net::{TcpListener, TcpStream};

use crate::state::Limits;

/// Serves `router` on `listener` until `shutdown` completes, then lets the open requests finish
/// for at most `limits.shutdown_grace` and drops what is left, so a slow or hostile client cannot
/// keep a stopped server alive. A client that takes longer than `limits.header_read_timeout` to
/// send its headers is disconnected. Each connection closes lingering (`Lingering`).
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
                let connection = builder
                    .serve_connection_with_upgrades(TokioIo::new(Lingering(Some(stream))), service)
                    .into_owned();
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

/// How long a closed connection still reads what its client sends (`Lingering`).
const LINGER: Duration = Duration::from_secs(2);

/// The most a closed connection reads and discards (`Lingering`).
const LINGER_BYTES: usize = 64 * 1024 * 1024;

/// A client connection that closes lingering: once the server is done with it, it sends its end
/// (FIN) and reads and discards what the client still sends, for at most [`LINGER`] and
/// [`LINGER_BYTES`], before it closes. Closed with unread bytes waiting, the socket would send a
/// reset instead, which can destroy an answer the client has not read yet: the 413 sent for a
/// body declared over the limit before it was read.
struct Lingering(Option<TcpStream>);

impl Lingering {
    fn stream(&mut self) -> io::Result<Pin<&mut TcpStream>> {
        self.0.as_mut().map(Pin::new).ok_or_else(|| io::Error::from(io::ErrorKind::NotConnected))
    }
}

impl AsyncRead for Lingering {
    fn poll_read(self: Pin<&mut Self>, cx: &mut Context<'_>, buf: &mut ReadBuf<'_>) -> Poll<io::Result<()>> {
        match self.get_mut().stream() {
            Ok(stream) => stream.poll_read(cx, buf),
            Err(error) => Poll::Ready(Err(error)),
        }
    }
}

impl AsyncWrite for Lingering {
    fn poll_write(self: Pin<&mut Self>, cx: &mut Context<'_>, buf: &[u8]) -> Poll<io::Result<usize>> {
        match self.get_mut().stream() {
            Ok(stream) => stream.poll_write(cx, buf),
            Err(error) => Poll::Ready(Err(error)),
        }
    }

    fn poll_write_vectored(
        self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        bufs: &[io::IoSlice<'_>],
    ) -> Poll<io::Result<usize>> {
        match self.get_mut().stream() {
            Ok(stream) => stream.poll_write_vectored(cx, bufs),
            Err(error) => Poll::Ready(Err(error)),
        }
    }

    fn is_write_vectored(&self) -> bool {
        true
    }

    fn poll_flush(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        match self.get_mut().stream() {
            Ok(stream) => stream.poll_flush(cx),
            Err(error) => Poll::Ready(Err(error)),
        }
    }

    fn poll_shutdown(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        match self.get_mut().stream() {
            Ok(stream) => stream.poll_shutdown(cx),
            Err(error) => Poll::Ready(Err(error)),
        }
    }
}

impl Drop for Lingering {
    fn drop(&mut self) {
        let Some(mut stream) = self.0.take() else { return };
        // Outside a runtime (the process is ending) the socket just closes.
        let Ok(runtime) = tokio::runtime::Handle::try_current() else { return };
        runtime.spawn(async move {
            let _ = stream.shutdown().await;
            let mut buffer = vec![0_u8; 16 * 1024];
            let mut discarded = 0;
            let _ = tokio::time::timeout(LINGER, async {
                while discarded < LINGER_BYTES {
                    match stream.read(&mut buffer).await {
                        Ok(0) | Err(_) => break,
                        Ok(read) => discarded += read,
                    }
                }
            })
            .await;
        });
    }
}
