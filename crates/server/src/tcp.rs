//! TCP: every connection is a link of its own to the same module.

use crate::ServerConfig;
use crate::SharedBus;
use crate::slots::{Activity, Slots, accept};
use std::sync::Arc;
use tokio::net::TcpListener;
use tokio::sync::watch;

pub(crate) async fn run(listener: TcpListener, bus: Arc<SharedBus>, config: ServerConfig, mut stop: watch::Receiver<bool>) {
    let mut slots = Slots::new("connection", config.max_connections, config.idle_timeout);
    let mut failing = false;
    loop {
        tokio::select! {
            accepted = accept(&listener, &mut failing, "a TCP connection") => {
                let Some((stream, peer)) = accepted else { continue };
                if let Err(why) = slots.make_room() {
                    eprintln!("tmclsim: {}", crate::log_lines::refused("connection", peer, why));
                    drop(stream);
                    continue;
                }
                let _ = stream.set_nodelay(true);
                let bus = bus.clone();
                let options = crate::link::Options::network(&config, format!("tcp {peer}"));
                let activity = Arc::new(Activity::new());
                let seen = activity.clone();
                slots.spawn(peer, activity, async move {
                    let (r, w) = stream.into_split();
                    let mut lines = Default::default();
                    let _ = crate::link::serve(r, w, bus, &options, &mut lines, &seen).await;
                });
            }
            _ = slots.reap(), if !slots.is_empty() => {}
            _ = stop.changed() => break,
        }
    }
    slots.close_all();
}
