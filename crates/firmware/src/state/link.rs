//! The host link as the module sees it: the address of the last request
//! (events answer with it), when the host last spoke (the heartbeat), and
//! the ASCII interface's mode and the line being typed.
//!
//! The mode belongs to the module; a line belongs to a link (docs/
//! behaviour.md rule 83): the module keeps one for its own serial port, a
//! server keeps one per connection ([`LineState`]).

/// Longest ASCII line kept; the rest of a longer line is dropped.
pub const MAX_LINE: usize = 128;

#[derive(Clone, Debug)]
pub struct Link {
    /// Address byte of the last request.
    pub last_address: u8,
    /// Virtual time of the last request (or of the power-up).
    pub last_frame_ns: u64,
    /// The heartbeat (GP 68) ran out and stopped the motors.
    pub heartbeat_tripped: bool,
    /// The link speaks text (ASCII mode).
    pub ascii: bool,
    /// Counts the entries into ASCII mode: a line typed in an earlier
    /// session is dropped (docs/behaviour.md rule 83).
    pub ascii_session: u64,
    pub ascii_line: AsciiLine,
}

impl Default for Link {
    fn default() -> Link {
        Link {
            last_address: 1,
            last_frame_ns: 0,
            heartbeat_tripped: false,
            ascii: false,
            ascii_session: 0,
            ascii_line: AsciiLine::default(),
        }
    }
}

impl Link {
    /// The host spoke (or the module powered up) at `now_ns`: the heartbeat
    /// starts over.
    pub fn restart_heartbeat(&mut self, now_ns: u64) {
        self.last_frame_ns = now_ns;
        self.heartbeat_tripped = false;
    }

    /// Command 139: the link speaks text, in a new session.
    pub fn enter_ascii_mode(&mut self) {
        self.ascii = true;
        self.new_ascii_session();
    }

    /// A new ASCII session: lines typed before now are dropped at their
    /// next character.
    pub fn new_ascii_session(&mut self) {
        self.ascii_session += 1;
        self.ascii_line.clear();
    }
}

/// The ASCII line being typed on one link.
#[derive(Clone, Debug, Default)]
pub struct AsciiLine {
    buf: Vec<u8>,
    /// The module's ASCII session the line was typed in.
    pub(crate) session: u64,
}

/// The ASCII lines of one link to a bus: one per module (each module
/// decides for itself what a backspace deletes and which lines it keeps).
#[derive(Clone, Debug, Default)]
pub struct LineState {
    pub(crate) lines: Vec<AsciiLine>,
}

impl AsciiLine {
    /// The characters received so far.
    pub fn bytes(&self) -> &[u8] {
        &self.buf
    }

    /// How many characters the line holds.
    pub fn len(&self) -> usize {
        self.buf.len()
    }

    /// True when the line holds no character.
    pub fn is_empty(&self) -> bool {
        self.buf.is_empty()
    }

    /// Appends a character; false (and nothing kept) when the line is full.
    pub fn push(&mut self, byte: u8) -> bool {
        if self.buf.len() >= MAX_LINE {
            return false;
        }
        self.buf.push(byte);
        true
    }

    /// Backspace.
    pub fn pop(&mut self) {
        self.buf.pop();
    }

    /// Empties the line.
    pub fn clear(&mut self) {
        self.buf.clear();
    }

    /// The line typed so far; the line starts over.
    pub fn take(&mut self) -> Vec<u8> {
        std::mem::take(&mut self.buf)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn heartbeat_restarts() {
        let mut l = Link { heartbeat_tripped: true, ..Link::default() };
        l.restart_heartbeat(42);
        assert_eq!((l.last_frame_ns, l.heartbeat_tripped), (42, false));
        assert_eq!(l.last_address, 1);
    }

    #[test]
    fn a_line_is_typed_edited_and_taken() {
        let mut line = AsciiLine::default();
        for b in *b"AGAP 1, 00" {
            assert!(line.push(b));
        }
        line.pop();
        assert_eq!(line.bytes(), b"AGAP 1, 0");
        assert_eq!(line.take(), b"AGAP 1, 0");
        assert!(line.is_empty());
    }

    #[test]
    fn a_full_line_keeps_no_more() {
        let mut line = AsciiLine::default();
        for _ in 0..MAX_LINE {
            assert!(line.push(b'x'));
        }
        assert!(!line.push(b'y'));
        assert_eq!(line.len(), MAX_LINE);
        line.clear();
        assert!(line.is_empty());
    }
}
