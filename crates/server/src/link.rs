//! One byte-stream link (a TCP connection or the pty): framing, the
//! module's answer, replies and events written back in order.

use crate::shared::SharedBus;
use crate::slots::Activity;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};
use tmclsim_firmware::ascii::LineState;
use tmclsim_protocol::FRAME_LEN;
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
}

impl Options {
    pub fn of(config: &crate::ServerConfig, name: String) -> Options {
        Options { inter_byte_timeout: config.inter_byte_timeout, log_frames: config.log_frames, name }
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
    module: Arc<SharedBus>,
    options: &Options,
    lines: &mut LineState,
    activity: &Activity,
) -> std::io::Result<()>
where
    R: AsyncRead + Unpin,
    W: AsyncWrite + Unpin,
{
    let link = next_link_id();
    let (events_tx, mut events) = mpsc::unbounded_channel::<[u8; FRAME_LEN]>();
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
                let mut text = Vec::new();
                for &byte in &buf[..n] {
                    if module.ascii_active() {
                        // ASCII mode: text in, text out; the frame
                        // assembler starts afresh afterwards.
                        module.ascii_byte(lines, byte, &mut text);
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
                    activity.touch();
                    log(crate::frame_log::Direction::In, &frame);
                    let (replies, pause) = module.handle(link, &events_tx, &frame);
                    for reply in replies {
                        let (reply, fault_delay) = module.outgoing(reply);
                        let delay = pause + fault_delay;
                        if !delay.is_zero() {
                            tokio::time::sleep(delay).await;
                        }
                        if let Some(reply) = reply {
                            log(crate::frame_log::Direction::Out, &reply);
                            writer.write_all(&reply).await?;
                        }
                    }
                }
                if !text.is_empty() {
                    writer.write_all(&text).await?;
                }
                writer.flush().await?;
            }
            Some(event) = events.recv() => {
                if let (Some(event), _) = module.outgoing(event) {
                    log(crate::frame_log::Direction::Out, &event);
                    writer.write_all(&event).await?;
                    writer.flush().await?;
                }
            }
        }
    }
}
