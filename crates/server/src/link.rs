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
    let mut preamble = options.network.map(|_| Preamble::new());
    let mut bad_frames = 0u32;
    let (events_tx, mut events) = mpsc::unbounded_channel::<[u8; FRAME_LEN]>();
    let sink: EventSink = Arc::new(move |event| {
        let _ = events_tx.send(event);
    });
    let start = Instant::now();
    let mut assembler = FrameAssembler::new(options.inter_byte_timeout.as_nanos() as u64);
    let log = |direction: crate::frame_log::Direction, frame: &[u8; FRAME_LEN]| {
        if options.log_frames {
            crate::frame_log::print(&options.name, link, direction, frame);
        }
    };
    let mut buf = [0u8; 512];
    loop {
        tokio::select! {
            read = reader.read(&mut buf) => {
                let n = match read {
                    Ok(0) => return Ok(()),
                    Ok(n) => n,
                    Err(e) => return Err(e),
                };
                let now = start.elapsed().as_nanos() as u64;
                let bytes = match screen(&mut preamble, &buf[..n]) {
                    Screened::Hold => continue,
                    Screened::Foreign(what) => {
                        eprintln!("tmclsim: closing connection {}: it opened with {}, not TMCL; nothing was executed", options.name, what.describe());
                        return Ok(());
                    }
                    Screened::Pass(bytes) => bytes,
                };
                let mut text = Vec::new();
                for &byte in bytes.iter() {
                    if bus.ascii_active() {
                        // ASCII mode: text in, text out; the frame
                        // assembler starts afresh afterwards.
                        bus.ascii_byte(lines, byte, &mut text);
                        if byte == b'\r' {
                            activity.touch();
                        }
                        assembler.reset();
                        continue;
                    }
                    if !text.is_empty() {
                        writer.write_all(&std::mem::take(&mut text)).await?;
                    }
                    let Some(frame) = assembler.push(byte, now) else { continue };
                    let checksum_ok = tmclsim_protocol::checksum(&frame[..FRAME_LEN - 1]) == frame[FRAME_LEN - 1];
                    bad_frames = if checksum_ok { 0 } else { bad_frames + 1 };
                    activity.touch();
                    log(crate::frame_log::Direction::In, &frame);
                    let (replies, pause) = bus.handle(link, &sink, &frame);
                    for reply in replies {
                        let (reply, fault_delay) = bus.outgoing(reply);
                        let delay = pause + fault_delay;
                        if !delay.is_zero() {
                            tokio::time::sleep(delay).await;
                        }
                        if let Some(reply) = reply {
                            log(crate::frame_log::Direction::Out, &reply);
                            writer.write_all(&reply).await?;
                        }
                    }
                    if options.network.is_some_and(|limit| limit > 0 && bad_frames >= limit) {
                        writer.flush().await?;
                        eprintln!("tmclsim: closing connection {}: {bad_frames} frames in a row with a wrong checksum", options.name);
                        return Ok(());
                    }
                }
                if !text.is_empty() {
                    writer.write_all(&text).await?;
                }
                writer.flush().await?;
            }
            Some(event) = events.recv() => {
                if let (Some(event), _) = bus.outgoing(event) {
                    log(crate::frame_log::Direction::Out, &event);
                    writer.write_all(&event).await?;
                    writer.flush().await?;
                }
            }
        }
    }
}
