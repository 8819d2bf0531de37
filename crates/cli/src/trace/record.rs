//! `tmclsim trace record`: a transparent TMCL proxy that writes a trace.
//!
//! The listening port is a TMCL port and has its defences (docs/behaviour.md
//! rule 90, docs/robustness.md): loopback by default; a connection is
//! screened before anything of it is forwarded (one that opens with an
//! HTTP request line or a TLS client hello is closed); one that sends
//! `--bad-frame-limit` frames in a row with a wrong checksum is closed; one
//! host at a time, a new one taking the place of a host idle for
//! `--idle-timeout`, else refused. Every refusal is a line on standard
//! error, in the words of `tmclsim serve`, and none ends the recording.
//!
//! A host's bytes are assembled into 9-byte frames (a gap longer than the
//! inter-byte timeout drops a partial frame, as a module does); each frame
//! is recorded and sent to the module, and the host's next frame waits
//! until the module has answered or the reply timeout has passed. A
//! request that gets no reply is recorded without one (and said on
//! standard error). Frames the module sends on its own (138 events, a reply
//! that came too late) are recorded and forwarded to the host when they
//! come; with no host connected they are recorded only.
//!
//! Threads: one reads the module's link, one accepts hosts, one per
//! connection screens it and then serves it as the host, one waits for
//! Ctrl-C (SIGTERM, SIGHUP); the calling thread waits for that or a
//! failure. Every line of the trace is flushed as it is written.

use crate::client::Link;
use std::io::{Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::mpsc::{self, RecvTimeoutError, Sender};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};
use tmclsim_host::client::RawLink;
use tmclsim_host::hex;
use tmclsim_host::trace::{Dir, MAX_ENTRIES, Writer, is_event};
use tmclsim_protocol::preamble::{MAX_PREAMBLE, Preamble, Verdict};
use tmclsim_protocol::serial::FrameAssembler;
use tmclsim_protocol::{FRAME_LEN, checksum};
use tmclsim_server::log_lines;

#[derive(clap::Args)]
pub struct RecordArgs {
    /// Where the host connects: TCP HOST:PORT (loopback by default; a
    /// non-loopback address is warned about). One host at a time.
    #[arg(long, value_name = "HOST:PORT", value_parser = crate::socket_address, default_value = "127.0.0.1:1200")]
    pub listen: SocketAddr,
    #[command(flatten)]
    pub link: Link,
    /// The trace to write (JSON Lines; replaced if it exists).
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
    /// How long to wait for the module's reply to a request, in milliseconds.
    #[arg(long, value_name = "MS", default_value_t = 1000)]
    pub timeout: u64,
    /// Drop a partial frame after this many milliseconds without a byte.
    #[arg(long, value_name = "MS", default_value_t = 5)]
    pub inter_byte_timeout: u64,
    /// Close a host's connection after this many frames in a row with a
    /// wrong checksum (0: never), as `tmclsim serve` does (docs/behaviour.md
    /// rule 90).
    #[arg(long, value_name = "N", default_value_t = tmclsim_server::BAD_FRAME_LIMIT)]
    pub bad_frame_limit: u32,
    /// A new host takes the place of the connected one when that has sent
    /// no frame for this many seconds; before, the new one is refused.
    #[arg(long, value_name = "S", default_value_t = 30, value_parser = clap::value_parser!(u64).range(1..=86_400))]
    pub idle_timeout: u64,
}

/// Connections at once that have sent too little to tell what they speak;
/// more are refused.
const MAX_SCREENING: usize = 16;

/// Why the recording ends.
enum Stop {
    Signal,
    Failed(String),
}

/// The trace file, closed for good when the recording stops.
struct Trace {
    writer: Writer<std::fs::File>,
    closed: bool,
    full_said: bool,
}

/// The connected host.
struct Host {
    /// Which connection it is (a host that was replaced may still be
    /// finishing an exchange).
    id: u64,
    peer: SocketAddr,
    /// Its writing half.
    writer: TcpStream,
    /// When it last completed a frame (or connected).
    last_request: Instant,
}

/// What the threads share.
struct Proxy {
    start: Instant,
    trace: Mutex<Trace>,
    host: Mutex<Option<Host>>,
    next_host: AtomicU64,
    /// Connections being screened (their first bytes).
    screening: AtomicUsize,
    /// Held while a request waits for its reply: one exchange at a time.
    exchanging: Mutex<()>,
    /// Set while a request waits for its reply: where the reply goes.
    awaiting: Mutex<Option<Sender<[u8; FRAME_LEN]>>>,
    module: Mutex<Box<dyn Write + Send>>,
    stop: Mutex<Sender<Stop>>,
    timeout: Duration,
    inter_byte_ns: u64,
    bad_frame_limit: u32,
    idle_timeout: Duration,
}

/// A lock whose holder may have panicked: the data is still usable (a
/// panic ends the process anyway, see `main`).
fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

impl Proxy {
    fn now_ns(&self) -> u64 {
        self.start.elapsed().as_nanos() as u64
    }

    fn stop(&self, why: Stop) {
        let _ = lock(&self.stop).send(why);
    }

    fn record(&self, t_ns: u64, dir: Dir, frame: &[u8; FRAME_LEN]) {
        let mut trace = lock(&self.trace);
        if trace.closed {
            return;
        }
        match trace.writer.write(t_ns, dir, frame) {
            Ok(true) => {}
            Ok(false) => {
                if !std::mem::replace(&mut trace.full_said, true) {
                    eprintln!(
                        "tmclsim: the trace holds {MAX_ENTRIES} frames, the limit of a trace; frames are forwarded but no longer recorded"
                    );
                }
            }
            Err(e) => {
                trace.closed = true;
                self.stop(Stop::Failed(format!("cannot write the trace: {e}")));
            }
        }
    }

    /// Sends a frame to the connected host, if there is one (and, with
    /// `only`, if it is that host).
    fn to_host(&self, only: Option<u64>, frame: &[u8; FRAME_LEN]) {
        let mut host = lock(&self.host);
        if let Some(h) = host.as_mut().filter(|h| only.is_none_or(|id| id == h.id))
            && let Err(e) = h.writer.write_all(frame)
        {
            eprintln!("tmclsim: cannot send to the host: {e}");
            let _ = h.writer.shutdown(std::net::Shutdown::Both);
        }
    }

    /// One request of host `id`: recorded, sent to the module, its reply
    /// (if it comes in time) sent back.
    fn exchange(&self, id: u64, t_ns: u64, frame: &[u8; FRAME_LEN]) {
        let _one_at_a_time = lock(&self.exchanging);
        self.record(t_ns, Dir::Host, frame);
        let (tx, rx) = mpsc::channel();
        *lock(&self.awaiting) = Some(tx);
        let sent = {
            let mut module = lock(&self.module);
            module.write_all(frame).and_then(|_| module.flush())
        };
        if let Err(e) = sent {
            self.stop(Stop::Failed(format!("cannot send to the module: {e}")));
            return;
        }
        let reply = match rx.recv_timeout(self.timeout) {
            Ok(reply) => Some(reply),
            Err(RecvTimeoutError::Timeout) => {
                // The module's reader hands a reply over while it holds
                // `awaiting`: if it is gone, the reply is in the channel.
                if lock(&self.awaiting).take().is_some() { None } else { rx.try_recv().ok() }
            }
            Err(RecvTimeoutError::Disconnected) => None,
        };
        match reply {
            Some(r) => self.to_host(Some(id), &r),
            None => eprintln!("tmclsim: no reply to {} within {} ms; nothing recorded for it", hex(frame), self.timeout.as_millis()),
        }
    }

    /// Reads the module's link for good: replies go to the request that
    /// waits, everything else to the host.
    fn read_module(&self, mut reader: Box<dyn Read + Send>) {
        let mut assembler = FrameAssembler::new(self.inter_byte_ns);
        let mut buf = [0u8; 512];
        loop {
            let n = match reader.read(&mut buf) {
                Ok(0) => return self.stop(Stop::Failed("the link to the module closed".into())),
                Ok(n) => n,
                Err(e)
                    if matches!(
                        e.kind(),
                        std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut | std::io::ErrorKind::Interrupted
                    ) =>
                {
                    continue;
                }
                Err(e) => return self.stop(Stop::Failed(format!("cannot read from the module: {e}"))),
            };
            let now = self.now_ns();
            let mut frames = Vec::new();
            assembler.push_all(&buf[..n], now, |f| frames.push(f));
            for frame in frames {
                self.record(now, Dir::Module, &frame);
                if !is_event(&frame) {
                    let mut awaiting = lock(&self.awaiting);
                    if let Some(tx) = awaiting.take() {
                        let _ = tx.send(frame);
                        continue;
                    }
                }
                self.to_host(None, &frame);
            }
        }
    }

    /// Reads a connection's first bytes until they tell what it speaks:
    /// the bytes read, when TMCL; `None` (the connection closed, with a
    /// line on standard error) for another protocol.
    fn screen(&self, stream: &mut TcpStream, name: &str) -> Option<Vec<u8>> {
        let mut preamble = Preamble::new();
        let mut buf = [0u8; MAX_PREAMBLE];
        loop {
            let n = match stream.read(&mut buf) {
                Ok(0) | Err(_) => return None,
                Ok(n) => n,
            };
            for (i, &b) in buf[..n].iter().enumerate() {
                match preamble.push(b) {
                    Verdict::Undecided => {}
                    Verdict::Tmcl => return Some([preamble.held(), &buf[i + 1..n]].concat()),
                    foreign => {
                        eprintln!("tmclsim: {}", log_lines::foreign(name, foreign));
                        return None;
                    }
                }
            }
        }
    }

    /// Makes `stream` the host, in place of one idle for the idle timeout;
    /// its id, or `None` (refused, with a line on standard error).
    fn admit(&self, stream: &TcpStream, peer: SocketAddr) -> Option<u64> {
        let writer = stream.try_clone().ok()?;
        let mut host = lock(&self.host);
        if let Some(h) = host.as_ref() {
            let idle = h.last_request.elapsed();
            if idle < self.idle_timeout {
                eprintln!("tmclsim: {}", log_lines::refused("connection", peer, log_lines::Full { limit: 1, what: "connection" }));
                return None;
            }
            eprintln!("tmclsim: {}", log_lines::idle_closed("connection", h.peer, idle, 1));
            let _ = h.writer.shutdown(std::net::Shutdown::Both);
        }
        stream.set_nodelay(true).ok();
        writer.set_write_timeout(Some(Duration::from_secs(5))).ok();
        let id = self.next_host.fetch_add(1, Ordering::Relaxed);
        *host = Some(Host { id, peer, writer, last_request: Instant::now() });
        Some(id)
    }

    /// A connection: screened, then served as the host until it closes.
    fn connection(&self, mut stream: TcpStream, peer: SocketAddr) {
        let name = format!("tcp {peer}");
        let first = self.screen(&mut stream, &name);
        self.screening.fetch_sub(1, Ordering::Relaxed);
        let Some(first) = first else { return };
        let Some(id) = self.admit(&stream, peer) else { return };
        eprintln!("tmclsim: host {peer} connected");
        let mut assembler = FrameAssembler::new(self.inter_byte_ns);
        let mut bad_frames = 0u32;
        let mut bytes = first;
        let mut buf = [0u8; 512];
        'serving: loop {
            let now = self.now_ns();
            let mut frames = Vec::new();
            assembler.push_all(&bytes, now, |f| frames.push(f));
            for frame in frames {
                if let Some(h) = lock(&self.host).as_mut().filter(|h| h.id == id) {
                    h.last_request = Instant::now();
                }
                bad_frames = if checksum(&frame[..FRAME_LEN - 1]) == frame[FRAME_LEN - 1] { 0 } else { bad_frames + 1 };
                self.exchange(id, now, &frame);
                if self.bad_frame_limit > 0 && bad_frames >= self.bad_frame_limit {
                    eprintln!("tmclsim: {}", log_lines::bad_frames(&name, bad_frames));
                    break 'serving;
                }
            }
            bytes = match stream.read(&mut buf) {
                Ok(0) | Err(_) => break,
                Ok(n) => buf[..n].to_vec(),
            };
        }
        let _ = stream.shutdown(std::net::Shutdown::Both);
        let mut host = lock(&self.host);
        if host.as_ref().is_some_and(|h| h.id == id) {
            *host = None;
        }
        drop(host);
        eprintln!("tmclsim: host {peer} disconnected");
    }
}

/// Accepts connections; each is screened and served on a thread of its
/// own, at most [`MAX_SCREENING`] screened at once.
fn accept(proxy: Arc<Proxy>, listener: TcpListener) {
    for stream in listener.incoming() {
        let stream = match stream {
            Ok(s) => s,
            Err(e) => {
                eprintln!("tmclsim: cannot accept a host: {e}");
                std::thread::sleep(tmclsim_server::ACCEPT_BACKOFF);
                continue;
            }
        };
        let Ok(peer) = stream.peer_addr() else { continue };
        if proxy.screening.fetch_add(1, Ordering::Relaxed) >= MAX_SCREENING {
            proxy.screening.fetch_sub(1, Ordering::Relaxed);
            eprintln!(
                "tmclsim: refusing connection from {peer}: {MAX_SCREENING} connections have not yet said what they speak (the limit)"
            );
            continue;
        }
        let p = proxy.clone();
        std::thread::spawn(move || p.connection(stream, peer));
    }
}

/// Takes Ctrl-C, SIGTERM and SIGHUP from now on, and returns what waits
/// for one of them: a signal that comes early (before the banner is read,
/// say) waits for the waiter instead of ending the process unrecorded.
fn take_stop_signals() -> Result<impl FnOnce() + Send, String> {
    // A server's signals (on Windows: Ctrl-C, Ctrl-Break, the console
    // closing).
    let signals = crate::signal::Signals::install()?;
    Ok(move || signals.wait())
}

pub fn run(args: RecordArgs) -> Result<ExitCode, String> {
    let wait_for_signal = take_stop_signals()?;
    let link = args.link.tcp.as_deref().or(args.link.port.as_deref()).unwrap_or("");
    let listener = TcpListener::bind(args.listen).map_err(|e| format!("cannot listen on {}: {e}", args.listen))?;
    let listening = listener.local_addr().map_err(|e| e.to_string())?;
    let raw = RawLink::open(args.link.tcp.as_deref(), args.link.port.as_deref(), args.link.baud, Duration::from_millis(50))?;
    let file = std::fs::File::create(&args.out).map_err(|e| format!("{}: {e}", args.out.display()))?;
    let endpoints = tmclsim_server::Endpoints { tcp: Some(listening), pty: None, control: None, slcan: None, serial: Vec::new() };
    for w in tmclsim_server::exposure_warnings(&[endpoints]) {
        eprintln!("tmclsim: warning: {w}");
    }
    let (stop_tx, stop_rx) = mpsc::channel();
    let proxy = Arc::new(Proxy {
        start: Instant::now(),
        trace: Mutex::new(Trace { writer: Writer::new(file), closed: false, full_said: false }),
        host: Mutex::new(None),
        next_host: AtomicU64::new(1),
        screening: AtomicUsize::new(0),
        exchanging: Mutex::new(()),
        awaiting: Mutex::new(None),
        module: Mutex::new(raw.writer),
        stop: Mutex::new(stop_tx.clone()),
        timeout: crate::millis(args.timeout.max(1)),
        inter_byte_ns: args.inter_byte_timeout.saturating_mul(1_000_000),
        bad_frame_limit: args.bad_frame_limit,
        idle_timeout: Duration::from_secs(args.idle_timeout),
    });
    let p = proxy.clone();
    std::thread::spawn(move || p.read_module(raw.reader));
    let p = proxy.clone();
    std::thread::spawn(move || accept(p, listener));
    std::thread::spawn(move || {
        wait_for_signal();
        let _ = stop_tx.send(Stop::Signal);
    });
    println!("tmclsim: recording a host's session with the module on {link}");
    println!("  listen: {listening}  (one host at a time)");
    println!("  trace: {}", args.out.display());
    println!(
        "connect with: pytrinamic ConnectionManager(\"--interface socket_serial_tmcl --port {listening}\")  (Ctrl-C ends the recording)"
    );
    let _ = std::io::stdout().flush();
    let why = stop_rx.recv().unwrap_or(Stop::Signal);
    let frames = {
        let mut trace = lock(&proxy.trace);
        trace.closed = true;
        trace.writer.entries()
    };
    let summary = format!("{frames} frame(s) in {}", args.out.display());
    match why {
        Stop::Signal => {
            println!("tmclsim: stopping; {summary}");
            Ok(ExitCode::SUCCESS)
        }
        Stop::Failed(e) => Err(format!("{e}; {summary}")),
    }
}
