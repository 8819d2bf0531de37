//! A virtual serial-line CAN adapter (SLCAN) on a pty, with the served
//! modules on its CAN bus: python-can's `slcan` interface and PyTrinamic's
//! `slcan_tmcl` connection open it like a CANable or a Lawicel CANUSB.

use crate::SharedBus;
use crate::pty::Pty;
use std::sync::Arc;
use tmclsim_firmware::can::CanFrame;
use tmclsim_host::shared::EventSink;
use tmclsim_protocol::slcan::{self, SlcanCommand};
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::sync::{mpsc, watch};

/// Longest command line kept (an extended frame with 8 bytes is 26).
const MAX_LINE: usize = 64;

pub(crate) async fn run(pty: Pty, bus: Arc<SharedBus>, mut stop: watch::Receiver<bool>) {
    let (master, _slave) = match pty.into_stream() {
        Ok(v) => v,
        Err(e) => {
            eprintln!("tmclsim: slcan pty: {e}");
            return;
        }
    };
    let (mut reader, mut writer) = (master.clone(), master);
    let link = crate::link::next_link_id();
    let (events_tx, mut events) = mpsc::unbounded_channel::<[u8; 9]>();
    let sink: EventSink = Arc::new(move |event| {
        let _ = events_tx.send(event);
    });
    let mut open = false;
    let mut line = Vec::with_capacity(MAX_LINE);
    let mut buf = [0u8; 256];
    loop {
        let mut out = String::new();
        tokio::select! {
            read = reader.read(&mut buf) => {
                let n = match read {
                    Ok(0) | Err(_) => {
                        tokio::time::sleep(std::time::Duration::from_millis(20)).await;
                        continue;
                    }
                    Ok(n) => n,
                };
                for &b in &buf[..n] {
                    match b {
                        b'\r' => {
                            let text = String::from_utf8_lossy(&line).into_owned();
                            line.clear();
                            command(&text, &mut open, &bus, link, &sink, &mut out);
                        }
                        b'\n' => {}
                        _ if line.len() < MAX_LINE => line.push(b),
                        _ => {}
                    }
                }
            }
            Some(event) = events.recv() => {
                if open
                    && let Some(f) = bus.event_as_can(&event) {
                        out.push_str(&slcan::received(f.id, f.bytes()));
                    }
            }
            _ = stop.changed() => return,
        }
        if !out.is_empty() && writer.write_all(out.as_bytes()).await.is_err() {
            return;
        }
    }
}

/// One line from the host; the adapter's answer and any received frames
/// are appended to `out`.
fn command(text: &str, open: &mut bool, bus: &SharedBus, link: u64, events: &EventSink, out: &mut String) {
    const OK: &str = "\r";
    const ERROR: &str = "\x07";
    match slcan::parse(text) {
        Ok(SlcanCommand::Open { .. }) => {
            *open = true;
            out.push_str(OK);
        }
        Ok(SlcanCommand::Close) => {
            *open = false;
            out.push_str(OK);
        }
        Ok(SlcanCommand::Bitrate(_) | SlcanCommand::BitTiming | SlcanCommand::Setting) => out.push_str(OK),
        Ok(SlcanCommand::Version) => out.push_str("V1013\r"),
        Ok(SlcanCommand::SerialNumber) => out.push_str("NTMCL\r"),
        Ok(SlcanCommand::Status) => out.push_str("F00\r"),
        Ok(SlcanCommand::Transmit { id, extended, remote, data }) => {
            if !*open {
                out.push_str(ERROR);
                return;
            }
            out.push_str(if extended { "Z\r" } else { "z\r" });
            if extended || remote {
                return;
            }
            for reply in bus.handle_can(link, events, &CanFrame::new(id, &data)) {
                out.push_str(&slcan::received(reply.id, reply.bytes()));
            }
        }
        Err(_) => out.push_str(ERROR),
    }
}
