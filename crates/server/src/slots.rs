//! Connection slots of a listener (TMCL over TCP, the control socket): a
//! limit on connections at once, the idle rule that frees a slot for a new
//! client, and accepting with a back-off when the process runs out of
//! descriptors (docs/robustness.md, "Hostile links").

use std::collections::HashMap;
use std::future::Future;
use std::net::SocketAddr;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};
use tokio::net::{TcpListener, TcpStream};
use tokio::task::{AbortHandle, Id, JoinSet};

use crate::log_lines::Full;

/// How long the accept loop waits after a failed accept (out of file
/// descriptors, …) before it tries again.
pub const ACCEPT_BACKOFF: Duration = Duration::from_millis(100);

/// When a connection last completed a request (a frame, an ASCII line, a
/// control line); bytes that form none do not count.
pub(crate) struct Activity {
    start: Instant,
    last_ms: AtomicU64,
}

impl Activity {
    pub fn new() -> Activity {
        Activity { start: Instant::now(), last_ms: AtomicU64::new(0) }
    }

    /// A request was completed now.
    pub fn touch(&self) {
        self.last_ms.store(self.start.elapsed().as_millis() as u64, Ordering::Relaxed);
    }

    /// Time since the last request (or since the connection opened).
    pub fn idle(&self) -> Duration {
        self.start.elapsed().saturating_sub(Duration::from_millis(self.last_ms.load(Ordering::Relaxed)))
    }
}

struct Open {
    peer: SocketAddr,
    activity: Arc<Activity>,
    abort: AbortHandle,
}

/// The open connections of one listener.
pub(crate) struct Slots {
    what: &'static str,
    limit: usize,
    idle_timeout: Duration,
    open: HashMap<Id, Open>,
    tasks: JoinSet<()>,
}

impl Slots {
    pub fn new(what: &'static str, limit: usize, idle_timeout: Duration) -> Slots {
        Slots { what, limit, idle_timeout, open: HashMap::new(), tasks: JoinSet::new() }
    }

    /// Makes room for a new client. At the limit, the connection that has
    /// gone longest without a request is closed if that is `idle_timeout`
    /// or more; otherwise the new client is refused (`Err`: why).
    pub fn make_room(&mut self) -> Result<(), Full> {
        if self.open.len() < self.limit {
            return Ok(());
        }
        let idlest = self.open.iter().map(|(id, o)| (*id, o.activity.idle())).max_by_key(|(_, idle)| *idle);
        match idlest {
            Some((id, idle)) if idle >= self.idle_timeout => {
                if let Some(o) = self.open.remove(&id) {
                    o.abort.abort();
                    eprintln!("tmclsim: {}", crate::log_lines::idle_closed(self.what, o.peer, idle, self.limit));
                }
                Ok(())
            }
            _ => Err(Full { limit: self.limit, what: self.what }),
        }
    }

    /// Serves a connection in a slot of its own.
    pub fn spawn(&mut self, peer: SocketAddr, activity: Arc<Activity>, serve: impl Future<Output = ()> + Send + 'static) {
        let abort = self.tasks.spawn(serve);
        self.open.insert(abort.id(), Open { peer, activity, abort });
    }

    pub fn is_empty(&self) -> bool {
        self.tasks.is_empty()
    }

    /// Resolves when a connection ended; its slot is free again.
    pub async fn reap(&mut self) {
        match self.tasks.join_next_with_id().await {
            Some(Ok((id, ()))) => {
                self.open.remove(&id);
            }
            Some(Err(e)) => {
                self.open.remove(&e.id());
                if e.is_panic() {
                    // A connection that panicked takes its listener down
                    // with it, and the listener the server (lib.rs):
                    // nothing keeps listening with a broken module behind.
                    std::panic::resume_unwind(e.into_panic());
                }
            }
            None => std::future::pending().await,
        }
    }

    pub fn close_all(&mut self) {
        self.tasks.abort_all();
    }
}

/// Accepts the next client. A failed accept (EMFILE, ENFILE, …) is logged
/// once per run of failures and retried after [`ACCEPT_BACKOFF`], so the
/// loop never spins; `None` after such a wait.
pub(crate) async fn accept(listener: &TcpListener, failing: &mut bool, what: &str) -> Option<(TcpStream, SocketAddr)> {
    match listener.accept().await {
        Ok(accepted) => {
            *failing = false;
            Some(accepted)
        }
        Err(e) => {
            if !*failing {
                let at = listener.local_addr().map(|a| a.to_string()).unwrap_or_default();
                eprintln!("tmclsim: cannot accept {what} on {at}: {e}; trying again every {} ms", ACCEPT_BACKOFF.as_millis());
                *failing = true;
            }
            tokio::time::sleep(ACCEPT_BACKOFF).await;
            None
        }
    }
}
