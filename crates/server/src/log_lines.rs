//! The lines a TMCL port writes to standard error when it refuses or
//! closes a connection (docs/robustness.md, "Hostile links"), in one
//! place: the served links and the trace proxy (`tmclsim trace record`)
//! say the same things in the same words.

use std::net::SocketAddr;
use std::time::Duration;
use tmclsim_protocol::preamble::Verdict;

/// A connection that opened with another protocol (an HTTP request, a TLS
/// client hello): `name` is the link's (`tcp 127.0.0.1:50312`).
pub fn foreign(name: &str, what: Verdict) -> String {
    format!("closing connection {name}: it opened with {}, not TMCL; nothing was executed", what.describe())
}

/// A connection that sent `count` frames in a row with a wrong checksum.
pub fn bad_frames(name: &str, count: u32) -> String {
    format!("closing connection {name}: {count} frames in a row with a wrong checksum")
}

/// A connection closed for a new client: it went `idle` without a request
/// and all `limit` slots were taken.
pub fn idle_closed(what: &str, peer: SocketAddr, idle: Duration, limit: usize) -> String {
    let taken = if limit == 1 { "its only slot is wanted".to_string() } else { format!("all {limit} slots are taken") };
    format!("closing {what} from {peer}: no request for {} s and {taken}", idle.as_secs_f64().round())
}

/// Why a new client was refused: every slot is taken by a client that is
/// not idle long enough to be closed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Full {
    /// How many slots there are.
    pub limit: usize,
    /// What a slot holds (`connection`).
    pub what: &'static str,
}

impl std::fmt::Display for Full {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let s = if self.limit == 1 { "" } else { "s" };
        write!(f, "{} {}{s} open (the limit)", self.limit, self.what)
    }
}

impl std::error::Error for Full {}

/// A refused client: `refusing connection from PEER: 64 connections open
/// (the limit)`.
pub fn refused(what: &str, peer: SocketAddr, why: Full) -> String {
    format!("refusing {what} from {peer}: {why}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_lines_read_well_for_one_slot_and_for_many() {
        let peer: SocketAddr = "127.0.0.1:5000".parse().unwrap();
        let full = |limit| Full { limit, what: "connection" };
        assert_eq!(refused("connection", peer, full(64)), "refusing connection from 127.0.0.1:5000: 64 connections open (the limit)");
        assert_eq!(refused("connection", peer, full(1)), "refusing connection from 127.0.0.1:5000: 1 connection open (the limit)");
        let idle = Duration::from_millis(30_400);
        assert_eq!(
            idle_closed("connection", peer, idle, 64),
            "closing connection from 127.0.0.1:5000: no request for 30 s and all 64 slots are taken"
        );
        assert_eq!(
            idle_closed("connection", peer, idle, 1),
            "closing connection from 127.0.0.1:5000: no request for 30 s and its only slot is wanted"
        );
        assert_eq!(
            foreign("tcp 127.0.0.1:5000", Verdict::Http),
            "closing connection tcp 127.0.0.1:5000: it opened with an HTTP request, not TMCL; nothing was executed"
        );
    }
}
