//! The browser IDE: an HTTP and WebSocket API over a [`Target`] (virtual
//! modules served by this process, or modules reached over a TMCL link),
//! and the app's assets, embedded in the binary. The API is described in
//! this crate's README.

mod api;
mod app;
mod assets;
pub mod link_target;
mod live;
mod program;
mod security;
mod serve;
pub mod virtual_target;

pub use link_target::{LinkTarget, Probe};
pub use serve::Limits;
pub use tmclsim_ide::target::{self, Found, ModuleEntry, Target, TargetError};
pub use virtual_target::VirtualTarget;

use std::net::SocketAddr;
use std::sync::Arc;
use tokio::sync::watch;

/// The address the app listens on unless told otherwise.
pub const DEFAULT_ADDR: &str = "127.0.0.1:8141";

/// Where and how the app is served.
#[derive(Clone, Debug)]
pub struct WebConfig {
    /// The address to listen on (port 0: the system picks one).
    pub addr: SocketAddr,
    /// Allow a non-loopback address; every request then needs the token.
    pub public: bool,
    /// What a client may hold of the server (docs/robustness.md).
    pub limits: Limits,
}

/// A running app; dropping it stops it.
pub struct WebHandle {
    addr: SocketAddr,
    token: Option<String>,
    stop: watch::Sender<bool>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl WebHandle {
    /// The address the app listens on, with the port it got.
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// The token requests must carry (non-loopback binds only).
    pub fn token(&self) -> Option<&str> {
        self.token.as_deref()
    }

    /// The URL to open in a browser, with the token where one is needed.
    pub fn url(&self) -> String {
        match &self.token {
            Some(t) => format!("http://{}/?token={t}", self.addr),
            None => format!("http://{}/", self.addr),
        }
    }

    /// Blocks until the app stops (never, unless stopped from elsewhere).
    pub fn wait(mut self) {
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

impl Drop for WebHandle {
    fn drop(&mut self) {
        let _ = self.stop.send(true);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// Starts the app on its own thread.
pub fn start(target: Arc<dyn Target>, config: WebConfig) -> std::io::Result<WebHandle> {
    if !config.addr.ip().is_loopback() && !config.public {
        return Err(std::io::Error::new(
            std::io::ErrorKind::PermissionDenied,
            format!(
                "{} is not a loopback address: the IDE controls motors, so binding it there needs --web-public (and then a token)",
                config.addr
            ),
        ));
    }
    let token = (!config.addr.ip().is_loopback()).then(security::new_token).transpose()?;
    let listener = std::net::TcpListener::bind(config.addr).map_err(|e| {
        let hint =
            if e.kind() == std::io::ErrorKind::AddrInUse { ": another program listens there; pick another with --web ADDR" } else { "" };
        std::io::Error::new(e.kind(), format!("cannot listen on {} for the IDE: {e}{hint}", config.addr))
    })?;
    listener.set_nonblocking(true)?;
    let addr = listener.local_addr()?;
    let (stop, stopped) = watch::channel(false);
    let state = app::App::new(target, token.clone());
    let thread = std::thread::Builder::new().name("tmclsim-web".into()).spawn(move || {
        // One thread: the app's requests are short; link targets' waits run
        // on the blocking pool.
        let rt = tokio::runtime::Builder::new_current_thread().enable_all().build().expect("a tokio runtime");
        rt.block_on(async move {
            let listener = tokio::net::TcpListener::from_std(listener).expect("a tokio listener");
            serve::serve(listener, api::router(state), config.limits, stopped).await;
        });
        // Open WebSockets end with the runtime.
        rt.shutdown_timeout(std::time::Duration::from_millis(200));
    })?;
    Ok(WebHandle { addr, token, stop, thread: Some(thread) })
}
