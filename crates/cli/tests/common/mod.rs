//! Starting the real `tmclsim serve` process in tests, and talking to it
//! in frames over TCP.
#![allow(dead_code)]

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Child, Command, Stdio};
use tmclsim_protocol::mnemonic::parse_line;
use tmclsim_protocol::{Reply, Request};

/// Starts `tmclsim serve` with `args` (plus `--tcp 127.0.0.1:0`) and waits
/// until it serves; returns the process and its TCP endpoint. Its stdout
/// keeps being drained so it never blocks.
pub fn serve(args: &[&str], stderr: Stdio) -> (Child, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_tmclsim"))
        .args(["serve", "--tcp", "127.0.0.1:0"])
        .args(args)
        .stdout(Stdio::piped())
        .stderr(stderr)
        .spawn()
        .unwrap();
    let mut out = BufReader::new(child.stdout.take().unwrap());
    let mut tcp = None;
    loop {
        let mut line = String::new();
        assert!(out.read_line(&mut line).unwrap() > 0, "the server ended before serving");
        if let Some(a) = line.trim().strip_prefix("tcp: ") {
            tcp = Some(a.to_string());
        }
        if line.starts_with("connect with:") {
            break;
        }
    }
    std::thread::spawn(move || {
        let mut sink = vec![];
        let _ = out.read_to_end(&mut sink);
    });
    (child, tcp.expect("the server printed its tcp endpoint"))
}

/// The request frame of a command (mnemonic or `#op type motor value`) to
/// module address 1.
pub fn frame(line: &str) -> [u8; 9] {
    Request::new(1, parse_line(line).unwrap()).encode()
}

/// Sends a command and reads the reply; `None` when the connection fails
/// or the reply is not a valid frame.
pub fn ask(s: &mut TcpStream, line: &str) -> Option<Reply> {
    s.write_all(&frame(line)).ok()?;
    let mut buf = [0u8; 9];
    s.read_exact(&mut buf).ok()?;
    Reply::decode(&buf)
}

/// Runs `tmclsim ARGS` to the end with standard input closed.
pub fn tmclsim(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_tmclsim")).args(args).stdin(Stdio::null()).output().unwrap()
}

/// Standard output and standard error of a finished command, together.
pub fn text(o: &std::process::Output) -> String {
    format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr))
}
