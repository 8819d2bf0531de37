//! The app's HTTP server, with a limit on everything a client can hold:
//! connections at once, the time to send a request's head (which is also
//! how long an idle keep-alive connection stays), the size of that head
//! (docs/robustness.md, "The browser IDE").

use axum::Router;
use hyper_util::rt::{TokioIo, TokioTimer};
use hyper_util::service::TowerToHyperService;
use std::pin::Pin;
use std::sync::Arc;
use std::task::{Context, Poll};
use std::time::Duration;
use tokio::io::{AsyncRead, AsyncWrite, ReadBuf};
use tokio::net::{TcpListener, TcpStream};
use tokio::sync::{OwnedSemaphorePermit, Semaphore, watch};
use tokio::task::JoinSet;

/// The limits of the app's server.
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    /// Connections at once; one more is answered 503 and closed.
    pub connections: usize,
    /// Time a client has to send a request's head, counted from when the
    /// server waits for it (a new connection, or one idle between
    /// requests); then the connection is closed.
    pub head_timeout: Duration,
    /// Largest request head (request line and headers) in bytes.
    pub max_head: usize,
}

impl Default for Limits {
    fn default() -> Limits {
        Limits { connections: 256, head_timeout: Duration::from_secs(10), max_head: 16 * 1024 }
    }
}

/// The answer to a connection past the limit.
fn busy(limit: usize) -> Vec<u8> {
    let body = format!("{{\"error\": \"the IDE serves {limit} connections at once and has them all open; try again\"}}\n");
    format!(
        "HTTP/1.1 503 Service Unavailable\r\nContent-Type: application/json\r\nContent-Length: {}\r\nRetry-After: 1\r\nConnection: close\r\n\r\n{body}",
        body.len()
    )
    .into_bytes()
}

/// A connection with its slot: the slot is free again when the connection
/// is dropped, also after it became a WebSocket.
struct Held {
    stream: TcpStream,
    _slot: OwnedSemaphorePermit,
}

impl AsyncRead for Held {
    fn poll_read(self: Pin<&mut Self>, cx: &mut Context<'_>, buf: &mut ReadBuf<'_>) -> Poll<std::io::Result<()>> {
        Pin::new(&mut self.get_mut().stream).poll_read(cx, buf)
    }
}

impl AsyncWrite for Held {
    fn poll_write(self: Pin<&mut Self>, cx: &mut Context<'_>, data: &[u8]) -> Poll<std::io::Result<usize>> {
        Pin::new(&mut self.get_mut().stream).poll_write(cx, data)
    }

    fn poll_flush(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<std::io::Result<()>> {
        Pin::new(&mut self.get_mut().stream).poll_flush(cx)
    }

    fn poll_shutdown(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<std::io::Result<()>> {
        Pin::new(&mut self.get_mut().stream).poll_shutdown(cx)
    }
}

/// Serves `app` on `listener` until `stop` says so; then every connection
/// is dropped.
pub async fn serve(listener: TcpListener, app: Router, limits: Limits, mut stop: watch::Receiver<bool>) {
    let slots = Arc::new(Semaphore::new(limits.connections.max(1)));
    let mut connections = JoinSet::new();
    let mut failing = false;
    loop {
        tokio::select! {
            accepted = listener.accept() => {
                let stream = match accepted {
                    Ok((stream, _)) => stream,
                    Err(e) => {
                        // Out of descriptors: wait instead of spinning.
                        if !failing {
                            eprintln!("tmclsim: the IDE cannot accept a connection: {e}; trying again every 100 ms");
                        }
                        failing = true;
                        tokio::time::sleep(Duration::from_millis(100)).await;
                        continue;
                    }
                };
                failing = false;
                let Ok(slot) = slots.clone().try_acquire_owned() else {
                    // A fresh socket's send buffer is empty: the answer fits.
                    let _ = stream.try_write(&busy(limits.connections));
                    continue;
                };
                let _ = stream.set_nodelay(true);
                let service = TowerToHyperService::new(app.clone());
                let stream = Held { stream, _slot: slot };
                connections.spawn(async move {
                    let mut http = hyper::server::conn::http1::Builder::new();
                    http.timer(TokioTimer::new()).header_read_timeout(limits.head_timeout).max_buf_size(limits.max_head.max(8192));
                    let _ = http.serve_connection(TokioIo::new(stream), service).with_upgrades().await;
                });
            }
            Some(_) = connections.join_next(), if !connections.is_empty() => {}
            _ = stop.wait_for(|s| *s) => break,
        }
    }
    connections.abort_all();
}
