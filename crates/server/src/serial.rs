//! A real serial device (a USB–RS485 adapter, a COM port, one end of a
//! virtual null-modem pair): the modules answer on it as on their own
//! UART/RS485 port (docs/behaviour.md rule 98).
//!
//! The device is driven by the `serialport` crate, which is blocking and
//! portable (Unix and Windows alike): a reader thread hands the bytes that
//! arrive to the link's task, a writer thread puts the replies on the
//! line. Both end when the link's task lets go of them. A device that
//! vanishes (a USB adapter unplugged, the other end of a pair closed for
//! good) is reported and opened again when it is back; it never ends the
//! other links.

use crate::SerialLine;
use crate::ServerConfig;
use crate::SharedBus;
use std::io;
use std::pin::Pin;
use std::sync::Arc;
use std::task::{Context, Poll};
use std::time::Duration;
use tokio::io::{AsyncRead, AsyncWrite, ReadBuf};
use tokio::sync::{mpsc, watch};

/// How long a read waits before the reader thread looks whether its link
/// is still wanted and whether the module was power-cycled.
const READ_POLL: Duration = Duration::from_millis(100);

/// How often a vanished device is looked for.
const REOPEN_EVERY: Duration = Duration::from_millis(250);

/// The baud rate a line runs at now: its fixed rate, or the one of the
/// first module's GP 65 (its bootloader's while that runs), with the number
/// of resets that it was read at.
fn rate(bus: &SharedBus, line: &SerialLine) -> (u32, u32) {
    bus.with_module(0, |m| {
        // The bootloader has a rate of its own (docs/behaviour.md rule 99).
        let rate = line.baud.unwrap_or_else(|| match m.profile().bootloader.as_ref().filter(|_| m.in_bootloader()) {
            Some(boot) => boot.baud,
            None => m.profile().baud_rate(m.baud_rate_code()),
        });
        (rate, m.resets())
    })
}

/// Opens `line` at `baud` for the reader thread (which waits at most
/// [`READ_POLL`] per read).
fn open_port(line: &SerialLine, baud: u32) -> io::Result<Box<dyn serialport::SerialPort>> {
    serialport::new(&line.device, baud).timeout(READ_POLL).open().map_err(io::Error::from)
}

/// Opens a line as the server starts: an error names the device.
pub(crate) fn open(line: &SerialLine, bus: &SharedBus) -> io::Result<Box<dyn serialport::SerialPort>> {
    let (baud, _) = rate(bus, line);
    open_port(line, baud).map_err(|e| io::Error::new(e.kind(), format!("cannot open the serial device {}: {e}", line.device)))
}

/// The link's side of the reader thread: the bytes it read, in order.
struct Reader {
    rx: mpsc::Receiver<io::Result<Vec<u8>>>,
    pending: Vec<u8>,
}

impl AsyncRead for Reader {
    fn poll_read(mut self: Pin<&mut Self>, cx: &mut Context<'_>, buf: &mut ReadBuf<'_>) -> Poll<io::Result<()>> {
        if self.pending.is_empty() {
            match std::task::ready!(self.rx.poll_recv(cx)) {
                Some(Ok(bytes)) => self.pending = bytes,
                Some(Err(e)) => return Poll::Ready(Err(e)),
                // The thread is gone without a word: the device is.
                None => return Poll::Ready(Err(io::Error::new(io::ErrorKind::BrokenPipe, "the reader stopped"))),
            }
        }
        let n = self.pending.len().min(buf.remaining());
        buf.put_slice(&self.pending[..n]);
        self.pending.drain(..n);
        Poll::Ready(Ok(()))
    }
}

/// The link's side of the writer thread: a write is queued and counts as
/// done; the thread writes it on the line in order.
struct Writer {
    tx: std::sync::mpsc::Sender<Vec<u8>>,
}

impl AsyncWrite for Writer {
    fn poll_write(self: Pin<&mut Self>, _: &mut Context<'_>, data: &[u8]) -> Poll<io::Result<usize>> {
        match self.tx.send(data.to_vec()) {
            Ok(()) => Poll::Ready(Ok(data.len())),
            Err(_) => Poll::Ready(Err(io::Error::new(io::ErrorKind::BrokenPipe, "the device cannot be written"))),
        }
    }

    fn poll_flush(self: Pin<&mut Self>, _: &mut Context<'_>) -> Poll<io::Result<()>> {
        Poll::Ready(Ok(()))
    }

    fn poll_shutdown(self: Pin<&mut Self>, _: &mut Context<'_>) -> Poll<io::Result<()>> {
        Poll::Ready(Ok(()))
    }
}

/// Starts the threads of an open port: the stream halves the link serves.
fn streams(port: Box<dyn serialport::SerialPort>, line: &SerialLine, bus: Arc<SharedBus>) -> io::Result<(Reader, Writer)> {
    let mut out = port.try_clone().map_err(io::Error::from)?;
    let (wtx, wrx) = std::sync::mpsc::channel::<Vec<u8>>();
    std::thread::Builder::new().name(format!("serial writer {}", line.device)).spawn(move || {
        for data in wrx {
            if out.write_all(&data).and_then(|()| out.flush()).is_err() {
                return;
            }
        }
    })?;
    let (rtx, rrx) = mpsc::channel(64);
    let line = line.clone();
    std::thread::Builder::new().name(format!("serial reader {}", line.device)).spawn(move || read_loop(port, &line, &bus, &rtx))?;
    Ok((Reader { rx: rrx, pending: Vec::new() }, Writer { tx: wtx }))
}

/// The reader thread: bytes to the link until the device fails or the
/// link lets go; a power cycle of the module sets the line to GP 65's rate
/// again (when no fixed rate is given).
fn read_loop(mut port: Box<dyn serialport::SerialPort>, line: &SerialLine, bus: &SharedBus, tx: &mpsc::Sender<io::Result<Vec<u8>>>) {
    let mut buf = [0u8; 512];
    let (mut baud, mut resets) = rate(bus, line);
    while !tx.is_closed() {
        let got = match port.read(&mut buf) {
            Ok(0) => Err(io::Error::new(io::ErrorKind::UnexpectedEof, "the device was closed")),
            Ok(n) => Ok(buf[..n].to_vec()),
            // Nothing came: a device that is gone says so when asked how
            // many bytes wait (Windows reads of a removed device may
            // just time out).
            Err(e) if matches!(e.kind(), io::ErrorKind::TimedOut | io::ErrorKind::Interrupted | io::ErrorKind::WouldBlock) => {
                port.bytes_to_read().map(|_| Vec::new()).map_err(io::Error::from)
            }
            Err(e) => Err(e),
        };
        match got {
            Ok(bytes) if bytes.is_empty() => {}
            Ok(bytes) => {
                if tx.blocking_send(Ok(bytes)).is_err() {
                    return;
                }
            }
            Err(e) => {
                let _ = tx.blocking_send(Err(e));
                return;
            }
        }
        let (now, count) = rate(bus, line);
        if count != resets {
            resets = count;
            if now != baud && port.set_baud_rate(now).is_ok() {
                baud = now;
            }
        }
    }
}

/// Serves one serial device until the server stops: as the pty, one ASCII
/// line state and one link for the whole life of the device; when it
/// vanishes, a line on stderr, and the device is looked for again.
pub(crate) async fn run(
    port: Box<dyn serialport::SerialPort>,
    line: SerialLine,
    bus: Arc<SharedBus>,
    config: ServerConfig,
    mut stop: watch::Receiver<bool>,
) {
    let mut lines = Default::default();
    let activity = crate::slots::Activity::new();
    let options = crate::link::Options::local(&config, format!("serial {}", line.device));
    let mut port = Some(port);
    loop {
        let p = match port.take() {
            Some(p) => p,
            None => match reopen(&line, &bus, &mut stop).await {
                Some(p) => p,
                None => return,
            },
        };
        let why = match streams(p, &line, bus.clone()) {
            Ok((reader, writer)) => tokio::select! {
                r = crate::link::serve(reader, writer, bus.clone(), &options, &mut lines, &activity) => match r {
                    Ok(()) => "the device was closed".to_string(),
                    Err(e) => e.to_string(),
                },
                _ = stop.changed() => return,
            },
            Err(e) => e.to_string(),
        };
        eprintln!("tmclsim: serial {}: lost ({why}); serving it again when it is back", line.device);
    }
}

/// Looks for a vanished device until it opens (said once, then) or the
/// server stops (`None`).
async fn reopen(line: &SerialLine, bus: &SharedBus, stop: &mut watch::Receiver<bool>) -> Option<Box<dyn serialport::SerialPort>> {
    loop {
        tokio::select! {
            () = tokio::time::sleep(REOPEN_EVERY) => {}
            _ = stop.changed() => return None,
        }
        let (baud, _) = rate(bus, line);
        if let Ok(p) = open_port(line, baud) {
            eprintln!("tmclsim: serial {}: back, serving it again", line.device);
            return Some(p);
        }
    }
}
