//! TCP: every connection is a link of its own to the same module.

use crate::ServerConfig;
use crate::shared::SharedBus;
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};
use tokio::net::TcpListener;
use tokio::sync::watch;

pub(crate) async fn run(listener: TcpListener, module: Arc<SharedBus>, config: ServerConfig, mut stop: watch::Receiver<bool>) {
    let open = Arc::new(AtomicUsize::new(0));
    let mut connections = tokio::task::JoinSet::new();
    loop {
        tokio::select! {
            accepted = listener.accept() => {
                let Ok((stream, peer)) = accepted else { continue };
                if open.load(Ordering::Relaxed) >= config.max_connections {
                    eprintln!("tmclsim: refusing connection from {peer}: {} connections open (the limit)", config.max_connections);
                    drop(stream);
                    continue;
                }
                let _ = stream.set_nodelay(true);
                open.fetch_add(1, Ordering::Relaxed);
                let module = module.clone();
                let open = open.clone();
                let timeout = config.inter_byte_timeout;
                connections.spawn(async move {
                    let (r, w) = stream.into_split();
                    let _ = crate::link::serve(r, w, module, timeout).await;
                    open.fetch_sub(1, Ordering::Relaxed);
                });
            }
            Some(_) = connections.join_next(), if !connections.is_empty() => {}
            _ = stop.changed() => break,
        }
    }
    connections.abort_all();
}
