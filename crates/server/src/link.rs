//! One byte-stream link (a TCP connection or the pty): framing, the
//! module's answer, replies and events written back in order.

use crate::shared::SharedModule;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};
use tmclsim_protocol::serial::FrameAssembler;
use tmclsim_protocol::FRAME_LEN;
use tokio::io::{AsyncRead, AsyncReadExt, AsyncWrite, AsyncWriteExt};
use tokio::sync::mpsc;

static NEXT_LINK: AtomicU64 = AtomicU64::new(1);

/// Serves one stream until it closes or fails.
pub(crate) async fn serve<R, W>(mut reader: R, mut writer: W, module: Arc<SharedModule>, inter_byte_timeout: Duration) -> std::io::Result<()>
where
    R: AsyncRead + Unpin,
    W: AsyncWrite + Unpin + Send + 'static,
{
    let link = NEXT_LINK.fetch_add(1, Ordering::Relaxed);
    let (tx, mut rx) = mpsc::unbounded_channel::<[u8; FRAME_LEN]>();
    // Events come from the clock task at any time; the writer keeps
    // replies and events whole and in order.
    let writer_task = tokio::spawn(async move {
        while let Some(frame) = rx.recv().await {
            if writer.write_all(&frame).await.is_err() {
                break;
            }
            let _ = writer.flush().await;
        }
    });
    let start = Instant::now();
    let mut assembler = FrameAssembler::new(inter_byte_timeout.as_nanos() as u64);
    let mut buf = [0u8; 512];
    let result = loop {
        let n = match reader.read(&mut buf).await {
            Ok(0) => break Ok(()),
            Ok(n) => n,
            Err(e) => break Err(e),
        };
        let now = start.elapsed().as_nanos() as u64;
        let mut frames = Vec::new();
        assembler.push_all(&buf[..n], now, |f| frames.push(f));
        for frame in frames {
            let (reply, delay) = module.handle(link, &tx, &frame);
            if let Some(reply) = reply {
                if !delay.is_zero() {
                    tokio::time::sleep(delay).await;
                }
                if tx.send(reply).is_err() {
                    break;
                }
            }
        }
    };
    drop(tx);
    let _ = writer_task.await;
    result
}
