//! `tmclsim trace record`: a transparent TMCL proxy that writes a trace.
//!
//! One host at a time connects to the listen address (a second is accepted
//! and closed at once, with a line on standard error). Its bytes are
//! assembled into 9-byte frames (a gap longer than the inter-byte timeout
//! drops a partial frame, as a module does); each frame is recorded and
//! sent to the module, and the host's next frame waits until the module
//! has answered or the reply timeout has passed. A request that gets no
//! reply is recorded without one (and said on standard error). Frames the
//! module sends on its own (138 events, a reply that came too late) are
//! recorded and forwarded to the host when they come; with no host
//! connected they are recorded only.
//!
//! Threads: one reads the module's link, one the connected host, one
//! accepts hosts, one waits for Ctrl-C (SIGTERM, SIGHUP); the calling
//! thread waits for that or a failure. Every line of the trace is flushed
//! as it is written.

use crate::client::Link;
use std::io::{Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::mpsc::{self, RecvTimeoutError, Sender};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};
use tmclsim_host::client::RawLink;
use tmclsim_host::hex;
use tmclsim_host::trace::{Dir, MAX_ENTRIES, Writer, is_event};
use tmclsim_protocol::FRAME_LEN;
use tmclsim_protocol::serial::FrameAssembler;

#[derive(clap::Args)]
pub struct RecordArgs {
    /// Where the host connects: TCP HOST:PORT (e.g. 127.0.0.1:1200; a
    /// non-loopback address is warned about). One host at a time.
    #[arg(long, value_name = "HOST:PORT", value_parser = crate::socket_address)]
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
}

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

/// What the threads share.
struct Proxy {
    start: Instant,
    trace: Mutex<Trace>,
    /// The connected host's writing half.
    host: Mutex<Option<TcpStream>>,
    /// Set while a request waits for its reply: where the reply goes.
    awaiting: Mutex<Option<Sender<[u8; FRAME_LEN]>>>,
    module: Mutex<Box<dyn Write + Send>>,
    stop: Mutex<Sender<Stop>>,
    timeout: Duration,
    inter_byte_ns: u64,
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

    /// Sends a frame to the connected host, if there is one.
    fn to_host(&self, frame: &[u8; FRAME_LEN]) {
        let mut host = lock(&self.host);
        if let Some(s) = host.as_mut()
            && let Err(e) = s.write_all(frame)
        {
            eprintln!("tmclsim: cannot send to the host: {e}");
            let _ = s.shutdown(std::net::Shutdown::Both);
        }
    }

    /// One request: recorded, sent to the module, its reply (if it comes
    /// in time) sent back.
    fn exchange(&self, t_ns: u64, frame: &[u8; FRAME_LEN]) {
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
            Some(r) => self.to_host(&r),
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
                self.to_host(&frame);
            }
        }
    }

    /// Serves one host until it disconnects.
    fn serve_host(&self, mut stream: TcpStream, peer: SocketAddr) {
        eprintln!("tmclsim: host {peer} connected");
        let mut assembler = FrameAssembler::new(self.inter_byte_ns);
        let mut buf = [0u8; 512];
        loop {
            let n = match stream.read(&mut buf) {
                Ok(0) | Err(_) => break,
                Ok(n) => n,
            };
            let now = self.now_ns();
            let mut frames = Vec::new();
            assembler.push_all(&buf[..n], now, |f| frames.push(f));
            for frame in frames {
                self.exchange(now, &frame);
            }
        }
        *lock(&self.host) = None;
        eprintln!("tmclsim: host {peer} disconnected");
    }
}

/// Accepts hosts one at a time.
fn accept(proxy: Arc<Proxy>, listener: TcpListener) {
    for stream in listener.incoming() {
        let stream = match stream {
            Ok(s) => s,
            Err(e) => {
                eprintln!("tmclsim: cannot accept a host: {e}");
                std::thread::sleep(Duration::from_millis(100));
                continue;
            }
        };
        let peer = stream.peer_addr().map_or_else(|_| "?".to_string(), |a| a.to_string());
        let mut host = lock(&proxy.host);
        if host.is_some() {
            eprintln!("tmclsim: refusing host {peer}: one host at a time, and another is connected");
            continue;
        }
        let (Ok(writer), Ok(peer_addr)) = (stream.try_clone(), stream.peer_addr()) else { continue };
        stream.set_nodelay(true).ok();
        writer.set_write_timeout(Some(Duration::from_secs(5))).ok();
        *host = Some(writer);
        drop(host);
        let p = proxy.clone();
        std::thread::spawn(move || p.serve_host(stream, peer_addr));
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
        awaiting: Mutex::new(None),
        module: Mutex::new(raw.writer),
        stop: Mutex::new(stop_tx.clone()),
        timeout: crate::millis(args.timeout.max(1)),
        inter_byte_ns: args.inter_byte_timeout.saturating_mul(1_000_000),
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
