//! What a stream connection opens with: TMCL (frames or ASCII lines), or
//! another protocol that reached a TMCL port by mistake or on purpose — an
//! HTTP request (a web page can make a browser send one to any loopback
//! port) or a TLS client hello (docs/behaviour.md rule 90).
//!
//! [`Preamble`] looks at a connection's first bytes, one at a time, and
//! decides as soon as it can: at the first byte for almost all TMCL
//! traffic, after the method and its space for HTTP, after nine bytes for
//! a TLS record header and the start of its handshake. Until it has
//! decided, the link holds the bytes back and executes nothing.

/// Request methods a browser or an HTTP client sends first. None of them
/// is a TMCL mnemonic, and as a binary frame each would start with an
/// address byte and an opcode that no module's host sends together.
const HTTP_METHODS: [&[u8]; 10] =
    [b"GET ", b"HEAD ", b"POST ", b"PUT ", b"DELETE ", b"CONNECT ", b"OPTIONS ", b"TRACE ", b"PATCH ", b"PRI "];

/// Bytes a TLS record header and the start of its client hello take.
const TLS_HEADER: usize = 9;

/// The most bytes [`Preamble`] needs before it decides.
pub const MAX_PREAMBLE: usize = 9;

/// What a connection's first bytes are.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// More bytes are needed.
    Undecided,
    /// TMCL: the bytes held so far, and everything after, are the host's.
    Tmcl,
    /// An HTTP request line.
    Http,
    /// A TLS client hello.
    Tls,
}

impl Verdict {
    /// The foreign protocol in words, for a log line.
    pub fn describe(self) -> &'static str {
        match self {
            Verdict::Http => "an HTTP request",
            Verdict::Tls => "a TLS client hello",
            Verdict::Undecided | Verdict::Tmcl => "TMCL",
        }
    }
}

/// The first bytes of a connection, until they tell what it speaks.
#[derive(Clone, Debug, Default)]
pub struct Preamble {
    bytes: [u8; MAX_PREAMBLE],
    len: usize,
    verdict: Option<Verdict>,
}

impl Preamble {
    /// A preamble with no byte yet.
    pub fn new() -> Preamble {
        Preamble::default()
    }

    /// The verdict so far ([`Verdict::Undecided`] until one is reached;
    /// once reached it stays).
    pub fn verdict(&self) -> Verdict {
        self.verdict.unwrap_or(Verdict::Undecided)
    }

    /// The bytes held back while undecided (replayed to TMCL once the
    /// verdict is [`Verdict::Tmcl`]).
    pub fn held(&self) -> &[u8] {
        &self.bytes[..self.len]
    }

    /// Takes the next byte of the connection; returns the verdict after it.
    /// Bytes after a verdict are not looked at.
    pub fn push(&mut self, byte: u8) -> Verdict {
        if let Some(v) = self.verdict {
            return v;
        }
        self.bytes[self.len] = byte;
        self.len += 1;
        let verdict = classify(self.held());
        if verdict != Verdict::Undecided {
            self.verdict = Some(verdict);
        }
        verdict
    }
}

/// The verdict on a connection's first bytes.
pub fn classify(first: &[u8]) -> Verdict {
    let http = HTTP_METHODS.iter().map(|m| prefix_match(first, m)).max().unwrap_or(Match::No);
    let tls = tls_match(first);
    match (http, tls) {
        (Match::Yes, _) => Verdict::Http,
        (_, Match::Yes) => Verdict::Tls,
        (Match::No, Match::No) => Verdict::Tmcl,
        _ if first.len() >= MAX_PREAMBLE => Verdict::Tmcl,
        _ => Verdict::Undecided,
    }
}

#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Match {
    No,
    Maybe,
    Yes,
}

fn prefix_match(first: &[u8], pattern: &[u8]) -> Match {
    let n = first.len().min(pattern.len());
    if first[..n] != pattern[..n] {
        Match::No
    } else if n == pattern.len() {
        Match::Yes
    } else {
        Match::Maybe
    }
}

/// A TLS record of type handshake (22), version 3.x (x ≤ 4), carrying a
/// client hello (1) whose 24-bit length is the record's length less the
/// four bytes of the handshake header.
fn tls_match(first: &[u8]) -> Match {
    // Each byte the header fixes: its place and the values it may take.
    let fixed = [(0, 0x16..=0x16), (1, 0x03..=0x03), (2, 0x00..=0x04), (5, 0x01..=0x01)];
    for (i, allowed) in fixed {
        match first.get(i) {
            Some(b) if !allowed.contains(b) => return Match::No,
            None => return Match::Maybe,
            _ => {}
        }
    }
    if first.len() < TLS_HEADER {
        return Match::Maybe;
    }
    let record = u32::from(u16::from_be_bytes([first[3], first[4]]));
    let hello = u32::from_be_bytes([0, first[6], first[7], first[8]]);
    if record == hello + 4 { Match::Yes } else { Match::No }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Instruction, Request};

    fn verdict_of(bytes: &[u8]) -> (Verdict, usize) {
        let mut p = Preamble::new();
        for (i, &b) in bytes.iter().enumerate() {
            let v = p.push(b);
            if v != Verdict::Undecided {
                return (v, i + 1);
            }
        }
        (p.verdict(), bytes.len())
    }

    #[test]
    fn http_request_lines_are_recognised_after_the_method() {
        for m in HTTP_METHODS {
            let line = [m, b"/ HTTP/1.1\r\n".as_slice()].concat();
            assert_eq!(verdict_of(&line), (Verdict::Http, m.len()), "{}", String::from_utf8_lossy(m));
        }
    }

    #[test]
    fn a_tls_client_hello_is_recognised() {
        // Record: handshake, TLS 1.0 record version, 512 bytes; client
        // hello of 508 bytes.
        let hello = [0x16, 0x03, 0x01, 0x02, 0x00, 0x01, 0x00, 0x01, 0xFC, 0x03, 0x03];
        assert_eq!(verdict_of(&hello), (Verdict::Tls, 9));
        let mut wrong_length = hello;
        wrong_length[8] = 0xFD;
        assert_eq!(verdict_of(&wrong_length).0, Verdict::Tmcl);
    }

    #[test]
    fn tmcl_frames_and_ascii_commands_are_decided_at_once_or_soon() {
        let frames = [
            Request::new(1, Instruction::new(6, 1, 0, 0)).encode(),
            Request::new(71, Instruction::new(6, 1, 0, 0)).encode(), // 'G' then not 'E'
            Request::new(22, Instruction::new(3, 0, 0, 0)).encode(), // 0x16 0x03: MST to address 22
            Request::new(80, Instruction::new(79, 83, 84, 0)).encode(), // "POST" then a 0
        ];
        for f in frames {
            assert_eq!(verdict_of(&f).0, Verdict::Tmcl, "{f:02X?}");
        }
        assert_eq!(verdict_of(b"ROR 0, 500\r"), (Verdict::Tmcl, 1));
        assert_eq!(verdict_of(b"GAP 1, 0\r"), (Verdict::Tmcl, 2));
        assert_eq!(verdict_of(b"PUSH"), (Verdict::Tmcl, 3));
    }

    #[test]
    fn no_pattern_needs_more_than_the_preamble() {
        for first in [b"PATCH".as_slice(), b"\x16\x03\x01\x00\x20\x01\x00\x00"] {
            let mut p = Preamble::new();
            for &b in first {
                assert_eq!(p.push(b), Verdict::Undecided);
            }
            assert!(p.held().len() < MAX_PREAMBLE);
        }
        assert_eq!(classify(b"\x16\x03\x01\x00\x20\x01\x00\x00\x1D"), Verdict::Tmcl, "a length that does not fit");
    }
}
