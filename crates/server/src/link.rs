//! One byte-stream link (a TCP connection or the pty): framing, the
//! module's answer, replies and events written back in order.

use crate::SharedBus;
use crate::slots::Activity;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};
use tmclsim_firmware::ascii::LineState;
use tmclsim_host::shared::EventSink;
use tmclsim_protocol::FRAME_LEN;
use tmclsim_protocol::preamble::{Preamble, Verdict};
use tmclsim_protocol::serial::FrameAssembler;
use tokio::io::{AsyncRead, AsyncReadExt, AsyncWrite, AsyncWriteExt};
use tokio::sync::mpsc;

static NEXT_LINK: AtomicU64 = AtomicU64::new(1);

/// A fresh identifier for a link (events go to the link that spoke last).
pub(crate) fn next_link_id() -> u64 {
    NEXT_LINK.fetch_add(1, Ordering::Relaxed)
}

/// How a link is served: from the server's configuration, and the link's
/// name for the frame log.
pub(crate) struct Options {
    pub inter_byte_timeout: Duration,
    pub log_frames: bool,
    pub name: String,
    /// A network link (TCP): a connection that opens with another
    /// protocol is closed unexecuted, and one that sends this many frames
    /// with a wrong checksum in a row is closed (docs/behaviour.md rule 90).
    /// `None`: a local link (the pty), which screens nothing; `Some(0)`:
    /// no limit on bad frames.
    pub network: Option<u32>,
}

impl Options {
    /// A local link (the pty).
    pub fn local(config: &crate::ServerConfig, name: String) -> Options {
        Options { inter_byte_timeout: config.inter_byte_timeout, log_frames: config.log_frames, name, network: None }
    }

    /// A connection from the network (TCP).
    pub fn network(config: &crate::ServerConfig, name: String) -> Options {
        Options { network: Some(config.bad_frame_limit), ..Options::local(config, name) }
    }
}

/// What a link's bytes are allowed to do while a connection's preamble is
/// looked at.
enum Screened<'a> {
    /// Not decided yet: nothing is executed.
    Hold,
    /// Another protocol: the connection is closed.
    Foreign(Verdict),
    /// TMCL: these bytes go on.
    Pass(std::borrow::Cow<'a, [u8]>),
}

/// Screens bytes through the preamble (while there is one): the bytes that
/// may go on, including those held back until the verdict.
fn screen<'a>(preamble: &mut Option<Preamble>, bytes: &'a [u8]) -> Screened<'a> {
    let Some(p) = preamble else { return Screened::Pass(bytes.into()) };
    for (i, &b) in bytes.iter().enumerate() {
        match p.push(b) {
            Verdict::Undecided => continue,
            Verdict::Tmcl => {
                let mut all = p.held().to_vec();
                all.extend_from_slice(&bytes[i + 1..]);
                *preamble = None;
                return Screened::Pass(all.into());
            }
            foreign => return Screened::Foreign(foreign),
        }
    }
    Screened::Hold
}

/// Tells the bus that a link is gone, however its task ends.
struct Closing<'a> {
    bus: &'a SharedBus,
    link: u64,
}

impl Drop for Closing<'_> {
    fn drop(&mut self) {
        self.bus.link_closed(self.link);
    }
}

/// Serves one stream until it closes or fails. Replies are written by this
/// task as soon as they exist; unsolicited events (138) reach it through a
/// channel, so one task writes and frames never interleave. `lines` is
/// the link's own ASCII line state (docs/behaviour.md rule 83); `activity`
/// learns of every complete request.
pub(crate) async fn serve<R, W>(
    mut reader: R,
    mut writer: W,
    bus: Arc<SharedBus>,
    options: &Options,
    lines: &mut LineState,
    activity: &Activity,
) -> std::io::Result<()>
where
    R: AsyncRead + Unpin,
    W: AsyncWrite + Unpin,
{
    let link = next_link_id();
    let _closing = Closing { bus: &bus, link };
    let (events_tx, mut events) = mpsc::unbounded_channel::<[u8; FRAME_LEN]>();
    let mut session = Session::new(&bus, options, link, events_tx);
    let mut buf = [0u8; 512];
    loop {
        tokio::select! {
            read = reader.read(&mut buf) => {
                let n = read?;
                if n == 0 || session.bytes_in(&mut writer, &buf[..n], lines, activity).await? == Flow::Close {
                    return Ok(());
                }
            }
            Some(event) = events.recv() => session.event_out(&mut writer, event).await?,
        }
    }
}

/// Whether a link stays open after what it sent.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Flow {
    Open,
    Close,
}

/// What one served link keeps between reads.
struct Session<'a> {
    bus: &'a SharedBus,
    options: &'a Options,
    link: u64,
    /// Where the bus sends the link's events (to the serving task).
    sink: EventSink,
    /// A network link's first bytes, until they are known to be TMCL.
    preamble: Option<Preamble>,
    /// Frames with a wrong checksum in a row.
    bad_frames: u32,
    assembler: FrameAssembler,
    start: Instant,
}

impl<'a> Session<'a> {
    fn new(bus: &'a SharedBus, options: &'a Options, link: u64, events: mpsc::UnboundedSender<[u8; FRAME_LEN]>) -> Session<'a> {
        let sink: EventSink = Arc::new(move |event| {
            let _ = events.send(event);
        });
        Session {
            bus,
            options,
            link,
            sink,
            preamble: options.network.map(|_| Preamble::new()),
            bad_frames: 0,
            assembler: FrameAssembler::new(options.inter_byte_timeout.as_nanos() as u64),
            start: Instant::now(),
        }
    }

    fn log(&self, direction: crate::frame_log::Direction, frame: &[u8; FRAME_LEN]) {
        if self.options.log_frames {
            crate::frame_log::print(&self.options.name, self.link, direction, frame);
        }
    }

    /// Bytes read from the link: screened, then taken as ASCII text or
    /// frames, and answered.
    async fn bytes_in<W: AsyncWrite + Unpin>(
        &mut self,
        writer: &mut W,
        read: &[u8],
        lines: &mut LineState,
        activity: &Activity,
    ) -> std::io::Result<Flow> {
        let now = self.start.elapsed().as_nanos() as u64;
        let bytes = match screen(&mut self.preamble, read) {
            Screened::Hold => return Ok(Flow::Open),
            Screened::Foreign(what) => {
                eprintln!("tmclsim: {}", crate::log_lines::foreign(&self.options.name, what));
                return Ok(Flow::Close);
            }
            Screened::Pass(bytes) => bytes,
        };
        let mut text = Vec::new();
        for &byte in bytes.iter() {
            if self.bus.ascii_active() {
                // ASCII mode: text in, text out; the frame
                // assembler starts afresh afterwards.
                self.bus.ascii_byte(lines, byte, &mut text);
                if byte == b'\r' {
                    activity.touch();
                }
                self.assembler.reset();
                continue;
            }
            if !text.is_empty() {
                writer.write_all(&std::mem::take(&mut text)).await?;
            }
            let Some(frame) = self.assembler.push(byte, now) else { continue };
            if self.frame_in(writer, &frame, activity).await? == Flow::Close {
                return Ok(Flow::Close);
            }
        }
        if !text.is_empty() {
            writer.write_all(&text).await?;
        }
        writer.flush().await?;
        Ok(Flow::Open)
    }

    /// A complete frame: the module's replies, each after its delay.
    /// `Close` when a network link sent too many bad frames in a row.
    async fn frame_in<W: AsyncWrite + Unpin>(
        &mut self,
        writer: &mut W,
        frame: &[u8; FRAME_LEN],
        activity: &Activity,
    ) -> std::io::Result<Flow> {
        let checksum_ok = tmclsim_protocol::checksum(&frame[..FRAME_LEN - 1]) == frame[FRAME_LEN - 1];
        self.bad_frames = if checksum_ok { 0 } else { self.bad_frames + 1 };
        activity.touch();
        self.log(crate::frame_log::Direction::In, frame);
        let (replies, pause) = self.bus.handle(self.link, &self.sink, frame);
        for reply in replies {
            let (reply, fault_delay) = self.bus.outgoing(reply);
            let delay = pause + fault_delay;
            if !delay.is_zero() {
                tokio::time::sleep(delay).await;
            }
            if let Some(reply) = reply {
                self.log(crate::frame_log::Direction::Out, &reply);
                writer.write_all(&reply).await?;
            }
        }
        if self.options.network.is_some_and(|limit| limit > 0 && self.bad_frames >= limit) {
            writer.flush().await?;
            eprintln!("tmclsim: {}", crate::log_lines::bad_frames(&self.options.name, self.bad_frames));
            return Ok(Flow::Close);
        }
        Ok(Flow::Open)
    }

    /// An event of the link's modules, written as it comes.
    async fn event_out<W: AsyncWrite + Unpin>(&self, writer: &mut W, event: [u8; FRAME_LEN]) -> std::io::Result<()> {
        if let (Some(event), _) = self.bus.outgoing(event) {
            self.log(crate::frame_log::Direction::Out, &event);
            writer.write_all(&event).await?;
            writer.flush().await?;
        }
        Ok(())
    }
}
