//! Link faults for host robustness tests: replies dropped, corrupted,
//! delayed, or not sent at all.

use std::time::Duration;

/// The faults a link applies to the replies it sends (none by default).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LinkFaults {
    /// Drop this many of the next replies.
    pub drop: u32,
    /// Corrupt one byte (the checksum) of this many of the next replies.
    pub corrupt: u32,
    /// Delay every reply by this much.
    pub delay: Duration,
    /// Send nothing at all until cleared.
    pub mute: bool,
}

impl LinkFaults {
    /// Applies the faults to one outgoing frame: `None` drops it.
    pub fn apply(&mut self, mut frame: [u8; 9]) -> Option<[u8; 9]> {
        if self.mute {
            return None;
        }
        if self.drop > 0 {
            self.drop -= 1;
            return None;
        }
        if self.corrupt > 0 {
            self.corrupt -= 1;
            frame[8] = frame[8].wrapping_add(0x5A);
        }
        Some(frame)
    }
}
