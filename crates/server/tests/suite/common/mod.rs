//! Helpers shared by the server's tests: frames of commands and their
//! replies over a link.
#![allow(dead_code)]

use std::io::{Read, Write};
use tmclsim_protocol::mnemonic::parse_line;
use tmclsim_protocol::{Reply, Request};

/// The request frame of a command (mnemonic or `#op type motor value`) to
/// module address 1.
pub fn frame(line: &str) -> [u8; 9] {
    Request::new(1, parse_line(line).unwrap()).encode()
}

/// Reads one reply frame.
pub fn read_reply(s: &mut impl Read) -> Reply {
    let mut buf = [0u8; 9];
    s.read_exact(&mut buf).unwrap();
    Reply::decode(&buf).expect("reply checksum")
}

/// Sends a command and reads its reply.
pub fn ask(s: &mut (impl Read + Write), line: &str) -> Reply {
    s.write_all(&frame(line)).unwrap();
    read_reply(s)
}
