//! The 9-byte framing of serial-type links (RS485, USB, TCP, pty).
//!
//! [`FrameAssembler`] collects bytes into frames. A gap longer than the
//! inter-byte timeout discards a partial frame, so a host that lost a byte
//! resynchronises (docs/behaviour.md rule 1). Time is passed in by the caller,
//! which keeps this codec free of I/O and clocks.

use crate::frame::FRAME_LEN;

/// Default inter-byte timeout: 5 ms.
pub const DEFAULT_INTER_BYTE_TIMEOUT_NS: u64 = 5_000_000;

/// Collects bytes into 9-byte frames; a pause longer than the inter-byte
/// timeout starts a new frame.
#[derive(Clone, Debug)]
pub struct FrameAssembler {
    buf: [u8; FRAME_LEN],
    len: usize,
    last_byte_ns: u64,
    timeout_ns: u64,
}

impl Default for FrameAssembler {
    fn default() -> Self {
        Self::new(DEFAULT_INTER_BYTE_TIMEOUT_NS)
    }
}

impl FrameAssembler {
    /// An assembler with this inter-byte timeout.
    pub fn new(timeout_ns: u64) -> Self {
        FrameAssembler { buf: [0; FRAME_LEN], len: 0, last_byte_ns: 0, timeout_ns }
    }

    /// Bytes of an incomplete frame waiting for the rest.
    pub fn pending(&self) -> usize {
        self.len
    }

    /// Feeds one byte received at `now_ns`; returns a frame when it is
    /// complete.
    pub fn push(&mut self, byte: u8, now_ns: u64) -> Option<[u8; FRAME_LEN]> {
        if self.len > 0 && self.timeout_ns > 0 && now_ns.saturating_sub(self.last_byte_ns) > self.timeout_ns {
            self.len = 0;
        }
        self.last_byte_ns = now_ns;
        self.buf[self.len] = byte;
        self.len += 1;
        if self.len == FRAME_LEN {
            self.len = 0;
            Some(self.buf)
        } else {
            None
        }
    }

    /// Feeds a chunk that arrived at once, calling `on_frame` for each
    /// complete frame.
    pub fn push_all(&mut self, bytes: &[u8], now_ns: u64, mut on_frame: impl FnMut([u8; FRAME_LEN])) {
        for &b in bytes {
            if let Some(f) = self.push(b, now_ns) {
                on_frame(f);
            }
        }
    }

    /// Drops a partial frame (e.g. when the host reconnects).
    pub fn reset(&mut self) {
        self.len = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_split_across_reads() {
        let mut a = FrameAssembler::default();
        let frame = [1, 6, 1, 0, 0, 0, 0, 0, 8];
        let mut got = vec![];
        a.push_all(&frame[..4], 0, |f| got.push(f));
        a.push_all(&frame[4..], 1_000_000, |f| got.push(f));
        assert_eq!(got, vec![frame]);
    }

    #[test]
    fn gap_discards_partial_frame() {
        let mut a = FrameAssembler::default();
        let frame = [1, 6, 1, 0, 0, 0, 0, 0, 8];
        let mut got = vec![];
        a.push_all(&frame[..3], 0, |f| got.push(f)); // lost the rest
        a.push_all(&frame, 6_000_000, |f| got.push(f));
        assert_eq!(got, vec![frame]);
        assert_eq!(a.pending(), 0);
    }

    #[test]
    fn back_to_back_frames() {
        let mut a = FrameAssembler::default();
        let mut two = [0u8; 18];
        two[..9].copy_from_slice(&[1, 1, 0, 0, 0, 0, 3, 0xE8, 0xED]);
        two[9..].copy_from_slice(&[1, 3, 0, 0, 0, 0, 0, 0, 4]);
        let mut n = 0;
        a.push_all(&two, 0, |_| n += 1);
        assert_eq!(n, 2);
    }
}
