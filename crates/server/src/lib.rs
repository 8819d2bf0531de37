//! Serving virtual modules on real links: TCP, a pty that host software
//! opens like the module's serial port, and real serial devices.
//!
//! A server is request → response: bytes arrive on a link, the serial
//! framing turns them into frames, the module answers, the reply goes back
//! on the same link. Virtual time is paced by the wall clock; a clock task
//! wakes only when the module has something to do on its own (a 138 event,
//! a heartbeat stop), so an idle server uses no CPU.
//!
//! The files tmclsim reads and writes are here too, since the firmware
//! and the assembler do no I/O: the crash-safe EEPROM file
//! ([`eeprom_file`]), world, fleet and symbol files and program binaries
//! with their size limits ([`files`]), and TMCL source files with their
//! includes ([`sources`]).

mod clock;
pub mod control;
// EtherCAT needs raw Ethernet (AF_PACKET), which is Linux's; elsewhere
// serving it is refused (no_ethercat.rs).
#[cfg(target_os = "linux")]
pub mod ethercat;
#[cfg(not(target_os = "linux"))]
#[path = "no_ethercat.rs"]
pub mod ethercat;
pub mod files;
pub mod frame_log;
mod link;
pub mod log_lines;
// A pty and the SLCAN adapter on one are Unix's; on Windows both are
// refused (no_pty.rs).
#[cfg(unix)]
mod pty;
#[cfg(not(unix))]
#[path = "no_pty.rs"]
mod pty;
mod serial;
#[cfg(unix)]
mod slcan;
#[cfg(not(unix))]
#[path = "no_slcan.rs"]
mod slcan;
mod slots;
pub mod sources;
mod tcp;

// The bus a link serves and its EEPROM files are the host crate's (the
// Python package drives them without a server).
pub use slots::ACCEPT_BACKOFF;
pub use tmclsim_host::eeprom_file;
pub use tmclsim_host::{LinkFaults, SharedBus, Stats};

use eeprom_file::EepromFile;
use std::net::SocketAddr;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;
use tmclsim_firmware::{Module, Speed};
use tokio::sync::watch;
use tokio::task::JoinSet;

/// What to serve and where.
#[derive(Clone, Debug)]
pub struct ServerConfig {
    /// TCP address to listen on (loopback by default).
    pub tcp: Option<SocketAddr>,
    /// Path of the symlink to the pty's serial device.
    pub pty: Option<PathBuf>,
    /// Real serial devices the modules answer on (`--serial`).
    pub serial: Vec<SerialLine>,
    /// EEPROM file, held (locked) by the caller; written atomically on
    /// every EEPROM change.
    pub eeprom: Option<Arc<EepromFile>>,
    /// A partial frame is dropped after this gap between two bytes.
    pub inter_byte_timeout: Duration,
    /// Most TCP clients at once (at least 1); more are refused with a log
    /// line unless the idle rule frees a slot (`idle_timeout`).
    pub max_connections: usize,
    /// When every slot (TCP or control) is taken, a new client takes the
    /// slot of the connection that has gone longest without a complete
    /// request, if that is this long or longer (docs/robustness.md).
    pub idle_timeout: Duration,
    /// TCP address of the control socket (world and link faults). A
    /// non-loopback address needs `control_token`.
    pub control: Option<SocketAddr>,
    /// Most control clients at once; more get an error line.
    pub control_max_connections: usize,
    /// Longest control line in bytes; a longer one is answered with an
    /// error and dropped.
    pub control_max_line: usize,
    /// Control clients must send `auth TOKEN` as their first line.
    pub control_token: Option<String>,
    /// Print a warning on stderr for every endpoint that listens on a
    /// non-loopback address ([`exposure_warnings`]).
    pub warn_exposure: bool,
    /// Deliver bytes at the modules' baud rate (GP 65), as a real RS485 bus.
    pub wire_timing: bool,
    /// How fast the link's virtual time runs against the wall clock
    /// (`tmclsim serve --speed`): everything the modules time follows it.
    pub speed: Speed,
    /// Path of the symlink to a pty that is a serial-line CAN adapter
    /// (SLCAN) with the modules on its CAN bus.
    pub slcan: Option<PathBuf>,
    /// Print every frame in and out on stderr, decoded, with the time and
    /// the link it came on.
    pub log_frames: bool,
    /// A TCP connection that sends this many frames with a wrong checksum
    /// in a row is closed (docs/behaviour.md rule 90; 0: never).
    pub bad_frame_limit: u32,
}

/// A serial device the modules answer on.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SerialLine {
    /// The device: `/dev/ttyUSB0`, `/dev/pts/7`, `COM5`.
    pub device: String,
    /// A fixed baud rate; `None`: the rate of the first module's GP 65 at
    /// power-up, as on the module (its manual: interface bit rates take
    /// effect after a power cycle).
    pub baud: Option<u32>,
}

/// Frames with a wrong checksum in a row after which a TCP connection is
/// closed: far more than a host that lost a byte sends before it
/// resynchronises, far fewer than a stream of another protocol makes.
pub const BAD_FRAME_LIMIT: u32 = 16;

impl Default for ServerConfig {
    fn default() -> Self {
        ServerConfig {
            tcp: None,
            pty: None,
            serial: Vec::new(),
            eeprom: None,
            inter_byte_timeout: Duration::from_millis(5),
            max_connections: 64,
            idle_timeout: Duration::from_secs(30),
            control: None,
            control_max_connections: 16,
            control_max_line: 4096,
            control_token: None,
            warn_exposure: true,
            wire_timing: false,
            speed: Speed::REAL_TIME,
            slcan: None,
            log_frames: false,
            bad_frame_limit: BAD_FRAME_LIMIT,
        }
    }
}

/// The endpoints a running server listens on.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Endpoints {
    /// The TCP listener's address (the port the system chose for port 0).
    pub tcp: Option<SocketAddr>,
    /// The symlink a host opens, and the pty device it points to.
    pub pty: Option<(PathBuf, PathBuf)>,
    /// The control socket.
    pub control: Option<SocketAddr>,
    /// The SLCAN adapter's symlink and device.
    pub slcan: Option<(PathBuf, PathBuf)>,
    /// The serial devices served, each with the baud rate it was opened at.
    pub serial: Vec<(String, u32)>,
}

impl Endpoints {
    /// A PyTrinamic `ConnectionManager` argument string for the first
    /// endpoint (TCP preferred).
    pub fn pytrinamic_args(&self) -> Option<String> {
        if let Some(addr) = self.tcp {
            return Some(format!("--interface socket_serial_tmcl --port {addr}"));
        }
        self.pty.as_ref().map(|(link, _)| format!("--interface serial_tmcl --port {}", link.display()))
    }

    /// How a host reaches modules served on serial devices: through the
    /// other end of the (first) line.
    pub fn serial_hint(&self) -> Option<String> {
        let (device, baud) = self.serial.first()?;
        Some(format!("pytrinamic ConnectionManager(\"--interface serial_tmcl --port <the other end of {device}> --data-rate {baud}\")"))
    }
}

/// One served link: its endpoints and the bus of its module(s).
#[derive(Clone)]
pub struct LinkHandle {
    /// Where the link is served.
    pub endpoints: Endpoints,
    /// The bus of the link's modules, shared with its tasks.
    pub bus: Arc<SharedBus>,
}

/// A server running on its own thread; dropping it stops it.
pub struct ServerHandle {
    links: Vec<LinkHandle>,
    /// The pty symlinks this server created, removed when it stops.
    claims: Vec<pty::LinkClaim>,
    stop: watch::Sender<bool>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl ServerHandle {
    /// The endpoints of the (first) link.
    pub fn endpoints(&self) -> &Endpoints {
        &self.links[0].endpoints
    }

    /// The bus of the served module(s) of the (first) link.
    pub fn bus(&self) -> &Arc<SharedBus> {
        &self.links[0].bus
    }

    /// Every link of a fleet.
    pub fn links(&self) -> &[LinkHandle] {
        &self.links
    }

    /// Frames handled and real-time deadlines missed, over all links.
    pub fn stats(&self) -> Stats {
        self.links.iter().fold(Stats::default(), |acc, l| acc.merged(l.bus.stats()))
    }

    /// Stops serving, closes the links and removes the pty symlinks.
    pub fn stop(mut self) {
        self.shutdown();
    }

    fn shutdown(&mut self) {
        let _ = self.stop.send(true);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
        // Each link goes only if it still points to our pty.
        self.claims.clear();
    }

    /// Blocks until the server stops (it runs until stopped).
    pub fn wait(mut self) {
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

impl Drop for ServerHandle {
    fn drop(&mut self) {
        self.shutdown();
    }
}

/// A line for each module that starts in its bootloader (a firmware
/// update left no valid firmware, docs/behaviour.md rule 100).
pub fn bootloader_lines(links: &[LinkHandle]) -> Vec<String> {
    let mut out = Vec::new();
    for link in links {
        link.bus.with_bus(|b| {
            for m in b.modules().iter().filter(|m| m.in_bootloader()) {
                let text = m.profile().bootloader.as_ref().map_or(String::new(), |f| format!("{}, at address {}", f.version_text, f.address));
                out.push(format!(
                    "firmware: the {} is in its bootloader ({text}): a firmware update did not complete; it answers only the bootloader's commands until one does",
                    m.profile().module.name
                ));
            }
        });
    }
    out
}

/// What one link serves and how.
pub struct LinkSpec {
    /// The modules on the link, each with the file its EEPROM is saved in.
    pub modules: Vec<(Module, Option<Arc<EepromFile>>)>,
    /// The link's endpoints and options.
    pub config: ServerConfig,
}

/// Starts serving `module` in a background thread.
pub fn start(module: Module, config: ServerConfig) -> std::io::Result<ServerHandle> {
    let eeprom = config.eeprom.clone();
    start_bus_with_eeproms(vec![(module, eeprom)], config)
}

/// Starts serving several modules on one link (an RS485-style multi-drop
/// bus: every module sees every frame, the addressed one answers).
/// `config.eeprom` is used when there is a single module.
pub fn start_bus(modules: Vec<Module>, config: ServerConfig) -> std::io::Result<ServerHandle> {
    let single = modules.len() == 1;
    let nodes = modules.into_iter().map(|m| (m, if single { config.eeprom.clone() } else { None })).collect();
    start_bus_with_eeproms(nodes, config)
}

/// Starts serving modules, each with its own EEPROM file, on one link.
pub fn start_bus_with_eeproms(modules: Vec<(Module, Option<Arc<EepromFile>>)>, config: ServerConfig) -> std::io::Result<ServerHandle> {
    start_fleet(vec![LinkSpec { modules, config }])
}

/// The listeners and ptys of one link, opened.
struct Opened {
    tcp: Option<tokio::net::TcpListener>,
    pty: Option<pty::Pty>,
    control: Option<tokio::net::TcpListener>,
    slcan: Option<pty::Pty>,
    serial: Vec<(SerialLine, Box<dyn serialport::SerialPort>)>,
}

impl Opened {
    /// Where this link is served, as its handle reports it.
    fn endpoints(&self) -> Endpoints {
        Endpoints {
            tcp: self.tcp.as_ref().and_then(|l| l.local_addr().ok()),
            pty: self.pty.as_ref().map(|p| (p.link.clone(), p.device.clone())),
            control: self.control.as_ref().and_then(|l| l.local_addr().ok()),
            slcan: self.slcan.as_ref().map(|p| (p.link.clone(), p.device.clone())),
            serial: self.serial.iter().map(|(line, port)| (line.device.clone(), port.baud_rate().unwrap_or(0))).collect(),
        }
    }
}

async fn open(config: &ServerConfig, bus: &SharedBus) -> std::io::Result<Opened> {
    let tcp = match config.tcp {
        Some(addr) => Some(listen(addr, "TCP").await?),
        None => None,
    };
    let pty = match &config.pty {
        Some(path) => Some(open_pty(path, "pty")?),
        None => None,
    };
    let control = match config.control {
        Some(addr) => Some(listen(addr, "control").await?),
        None => None,
    };
    let slcan = match &config.slcan {
        Some(path) => Some(open_pty(path, "SLCAN pty")?),
        None => None,
    };
    let serial = config.serial.iter().map(|line| Ok((line.clone(), serial::open(line, bus)?))).collect::<std::io::Result<_>>()?;
    Ok(Opened { tcp, pty, control, slcan, serial })
}

/// Binds a listener; an error names the address and what to do.
async fn listen(addr: SocketAddr, what: &str) -> std::io::Result<tokio::net::TcpListener> {
    tokio::net::TcpListener::bind(addr).await.map_err(|e| {
        let hint = match e.kind() {
            std::io::ErrorKind::AddrInUse => " (another program listens there: stop it, or choose another port; port 0 takes a free one)",
            std::io::ErrorKind::AddrNotAvailable => " (no interface of this machine has that address)",
            std::io::ErrorKind::PermissionDenied => " (ports below 1024 need privileges: choose a port above 1023)",
            _ => "",
        };
        std::io::Error::new(e.kind(), format!("cannot listen on {addr} ({what}): {e}{hint}"))
    })
}

fn open_pty(path: &std::path::Path, what: &str) -> std::io::Result<pty::Pty> {
    pty::Pty::open(path).map_err(|e| {
        if e.kind() == std::io::ErrorKind::AddrInUse || e.kind() == std::io::ErrorKind::AlreadyExists {
            e
        } else {
            std::io::Error::new(e.kind(), format!("cannot create the {what} at {}: {e}", path.display()))
        }
    })
}

/// What is wrong with a configuration before anything is opened.
fn check(config: &ServerConfig) -> std::io::Result<()> {
    let invalid = |m: String| Err(std::io::Error::new(std::io::ErrorKind::InvalidInput, m));
    if config.tcp.is_some() && config.max_connections == 0 {
        return invalid("max_connections is 0: the TCP link would serve no client".into());
    }
    if config.control.is_some() && config.control_max_connections == 0 {
        return invalid("control_max_connections is 0: the control socket would serve no client".into());
    }
    if let Some(addr) = config.control
        && !addr.ip().is_loopback()
        && config.control_token.as_deref().is_none_or(str::is_empty)
    {
        return invalid(format!(
            "the control socket on {addr} would be open to other machines without a token (it can mute links and inject faults)"
        ));
    }
    Ok(())
}

/// One warning per kind of endpoint that listens on a non-loopback
/// address (docs/robustness.md, "Exposure: who can reach what").
pub fn exposure_warnings(endpoints: &[Endpoints]) -> Vec<String> {
    let public = |addrs: Vec<SocketAddr>| -> Option<String> {
        let addrs: Vec<SocketAddr> = addrs.into_iter().filter(|a| !a.ip().is_loopback()).collect();
        let first = addrs.first()?;
        Some(if addrs.len() == 1 { first.to_string() } else { format!("{first} and {} more addresses", addrs.len() - 1) })
    };
    let mut out = Vec::new();
    if let Some(at) = public(endpoints.iter().filter_map(|e| e.tcp).collect()) {
        out.push(format!(
            "TMCL on {at} is open to other machines: anyone who reaches it can drive the motors (TMCL has no authentication); listen on 127.0.0.1 to keep it local"
        ));
    }
    if let Some(at) = public(endpoints.iter().filter_map(|e| e.control).collect()) {
        out.push(format!(
            "the control socket on {at} is open to other machines: whoever has its token can change the world, mute links and inject faults"
        ));
    }
    out
}

/// A link of a kind the modules on it do not have is refused
/// (docs/behaviour.md rule 92): a CAN adapter needs modules with a CAN
/// interface, a multi-drop bus of two or more modules needs RS-485.
fn check_interfaces(bus: &SharedBus, config: &ServerConfig) -> std::io::Result<()> {
    use tmclsim_firmware::profile::Interface;
    let modules: Vec<(String, Vec<Interface>)> =
        bus.with_bus(|b| b.modules().iter().map(|m| (m.profile().module.name.clone(), m.profile().module.interfaces.clone())).collect());
    let lacking = |needed: Interface, what: &str| -> std::io::Result<()> {
        match modules.iter().find(|(_, has)| !has.contains(&needed)) {
            None => Ok(()),
            Some((name, has)) => {
                let has: Vec<&str> = has.iter().map(|i| i.name()).collect();
                Err(std::io::Error::other(format!(
                    "{name} has no {} interface (its interfaces: {}), so it cannot be served {what}",
                    needed.name(),
                    has.join(", ")
                )))
            }
        }
    };
    if config.slcan.is_some() {
        lacking(Interface::Can, "behind a CAN adapter (--slcan)")?;
    }
    if modules.len() > 1 {
        lacking(Interface::Rs485, "on a multi-drop bus with other modules")?;
    }
    Ok(())
}

/// Starts serving many links (a fleet) from one thread: one event loop,
/// a task per connection and per clock, nothing that polls.
pub fn start_fleet(links: Vec<LinkSpec>) -> std::io::Result<ServerHandle> {
    if links.is_empty() || links.iter().any(|l| l.modules.is_empty()) {
        return Err(std::io::Error::other("every link needs at least one module"));
    }
    serve_buses(links.into_iter().map(|l| (Arc::new(SharedBus::wall(l.modules, l.config.wire_timing, l.config.speed)), l.config)).collect())
}

/// Serves a bus that already exists (e.g. one the Python package holds):
/// its clock stays what it is (stepped or wall).
pub fn start_shared(bus: Arc<SharedBus>, config: ServerConfig) -> std::io::Result<ServerHandle> {
    serve_buses(vec![(bus, config)])
}

/// What the server thread hands back once its links are open: their
/// endpoints and the pty links' claims, or why a link did not open.
type Ready = std::io::Result<(Vec<Endpoints>, Vec<pty::LinkClaim>)>;

fn serve_buses(specs: Vec<(Arc<SharedBus>, ServerConfig)>) -> std::io::Result<ServerHandle> {
    for (bus, config) in &specs {
        check(config)?;
        check_interfaces(bus, config)?;
    }
    if specs.iter().any(|(_, c)| c.log_frames) {
        frame_log::started();
    }
    let warn = specs.iter().any(|(_, c)| c.warn_exposure);
    let shared: Vec<Arc<SharedBus>> = specs.iter().map(|(m, _)| m.clone()).collect();
    let (stop_tx, stop_rx) = watch::channel(false);
    let (ready_tx, ready_rx) = std::sync::mpsc::channel::<Ready>();
    let thread = std::thread::Builder::new().name("tmclsim-server".into()).spawn(move || {
        let rt = match tokio::runtime::Builder::new_current_thread().enable_all().build() {
            Ok(rt) => rt,
            Err(e) => {
                let _ = ready_tx.send(Err(e));
                return;
            }
        };
        rt.block_on(serve_opened(specs, &ready_tx, stop_rx));
    })?;
    let ready = ready_rx.recv().map_err(|_| std::io::Error::other("server thread ended early")).and_then(|r| r);
    let (endpoints, claims) = match ready {
        Ok(v) => v,
        Err(e) => {
            let _ = thread.join();
            return Err(e);
        }
    };
    if warn {
        for w in exposure_warnings(&endpoints) {
            eprintln!("tmclsim: warning: {w}");
        }
    }
    let links = endpoints.into_iter().zip(shared).map(|(endpoints, bus)| LinkHandle { endpoints, bus }).collect();
    Ok(ServerHandle { links, claims, stop: stop_tx, thread: Some(thread) })
}

/// The server thread's work: opens every link, reports them ready, serves
/// them until asked to stop. On an error, what was opened so far is
/// dropped: listeners close, pty links and their locks are removed.
async fn serve_opened(
    specs: Vec<(Arc<SharedBus>, ServerConfig)>,
    ready_tx: &std::sync::mpsc::Sender<Ready>,
    stop_rx: watch::Receiver<bool>,
) {
    let mut opened = Vec::with_capacity(specs.len());
    for (bus, config) in &specs {
        match open(config, bus).await {
            Ok(o) => opened.push(o),
            Err(e) => {
                drop(opened);
                let _ = ready_tx.send(Err(e));
                return;
            }
        }
    }
    let claims = opened.iter_mut().flat_map(|o| [o.pty.as_mut(), o.slcan.as_mut()]).flatten().filter_map(|p| p.claim.take()).collect();
    let endpoints = opened.iter().map(Opened::endpoints).collect();
    let _ = ready_tx.send(Ok((endpoints, claims)));
    let mut tasks = tokio::task::JoinSet::new();
    for ((bus, config), o) in specs.into_iter().zip(opened) {
        spawn_link(&mut tasks, o, &bus, &config, &stop_rx);
    }
    until_stopped(tasks, stop_rx).await;
}

/// The tasks of one link: its clock and whichever of TCP, pty, control
/// port, slcan and serial devices it serves.
fn spawn_link(tasks: &mut JoinSet<()>, o: Opened, bus: &Arc<SharedBus>, config: &ServerConfig, stop_rx: &watch::Receiver<bool>) {
    tasks.spawn(clock::run(bus.clone(), stop_rx.clone()));
    if let Some(listener) = o.tcp {
        tasks.spawn(tcp::run(listener, bus.clone(), config.clone(), stop_rx.clone()));
    }
    if let Some(p) = o.pty {
        tasks.spawn(pty::run(p, bus.clone(), config.clone(), stop_rx.clone()));
    }
    if let Some(listener) = o.control {
        tasks.spawn(control::run(listener, bus.clone(), config.clone(), stop_rx.clone()));
    }
    if let Some(p) = o.slcan {
        tasks.spawn(slcan::run(p, bus.clone(), stop_rx.clone()));
    }
    for (line, port) in o.serial {
        tasks.spawn(serial::run(port, line, bus.clone(), config.clone(), stop_rx.clone()));
    }
}

/// Runs the tasks until the server is asked to stop, or until one of them
/// panics: then every link closes rather than a listener staying open in
/// front of a task that is gone.
async fn until_stopped(mut tasks: JoinSet<()>, mut stop: watch::Receiver<bool>) {
    let failed = async {
        loop {
            match tasks.join_next().await {
                Some(Err(e)) if e.is_panic() => return e,
                Some(_) => {}
                None => std::future::pending::<()>().await,
            }
        }
    };
    tokio::select! {
        _ = stop.wait_for(|s| *s) => {}
        e = failed => eprintln!("tmclsim: a server task failed ({e}); every link of this server is closed"),
    }
    tasks.abort_all();
    while tasks.join_next().await.is_some() {}
}
