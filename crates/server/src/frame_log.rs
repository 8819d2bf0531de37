//! `serve --log-frames`: every frame in and out on stderr, decoded, with
//! the wall time since the server started and the link it came on:
//!
//! ```text
//! tmclsim: 12.345678 s tcp 127.0.0.1:40112 #3 → 01 06 01 00 00 00 00 00 08  to 1: GAP 1, 0
//! tmclsim: 12.345701 s tcp 127.0.0.1:40112 #3 ← 02 01 64 06 00 00 03 E8 58  from 1: status 100 (ok), value 1000
//! ```
//!
//! The browser IDE's commands (`serve --web`) are logged as coming on the
//! link `web`; its polled reads for charts, the grid and the program state
//! are not (fifty lines a second would bury everything else).

use std::sync::OnceLock;
use std::time::Instant;
use tmclsim_protocol::{FRAME_LEN, Reply, Request, Status, mnemonic};

/// Which way a logged frame goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Direction {
    /// From the host to the modules.
    In,
    /// From a module to the host.
    Out,
}

/// The server's start, for timestamps (taken when the first server that
/// logs frames starts).
pub(crate) fn started() -> Instant {
    static START: OnceLock<Instant> = OnceLock::new();
    *START.get_or_init(Instant::now)
}

/// The log line of one frame (without the `tmclsim:` prefix and time).
pub(crate) fn describe(direction: Direction, frame: &[u8; FRAME_LEN]) -> String {
    let hex: Vec<String> = frame.iter().map(|b| format!("{b:02X}")).collect();
    let meaning = match direction {
        Direction::In => match Request::decode(frame) {
            Ok(r) => format!("to {}: {}", r.address, mnemonic::format(r.instruction)),
            Err(r) => format!("to {}: wrong checksum", r.address),
        },
        Direction::Out => match Reply::decode(frame) {
            Some(r) => {
                let status = Status::from_code(r.status).map_or_else(|| r.status.to_string(), |s| s.to_string());
                format!("from {}: status {status}, value {}", r.module, r.value)
            }
            None => format!("version string '{}'", String::from_utf8_lossy(&frame[1..]).trim_end_matches('\0')),
        },
    };
    let arrow = if direction == Direction::In { "→" } else { "←" };
    format!("{arrow} {}  {meaning}", hex.join(" "))
}

pub(crate) fn print(link_name: &str, link: u64, direction: Direction, frame: &[u8; FRAME_LEN]) {
    print_from(&format!("{link_name} #{link}"), direction, frame);
}

/// One frame's log line, from `source` (a link and its number, or `web`).
pub fn print_from(source: &str, direction: Direction, frame: &[u8; FRAME_LEN]) {
    let t = started().elapsed().as_secs_f64();
    eprintln!("tmclsim: {t:.6} s {source} {}", describe(direction, frame));
}

#[cfg(test)]
mod tests {
    use super::*;
    use tmclsim_protocol::mnemonic::parse_line;

    #[test]
    fn frames_read_as_commands_and_replies() {
        let request = Request::new(1, parse_line("GAP 1, 0").unwrap()).encode();
        assert_eq!(describe(Direction::In, &request), "→ 01 06 01 00 00 00 00 00 08  to 1: GAP 1, 0");
        let reply = Reply::new(2, 1, Status::Ok, 6, 1000).encode();
        assert!(describe(Direction::Out, &reply).ends_with("from 1: status 100 (ok), value 1000"), "{}", describe(Direction::Out, &reply));
        let mut bad = request;
        bad[8] ^= 1;
        assert!(describe(Direction::In, &bad).ends_with("to 1: wrong checksum"));
    }
}
