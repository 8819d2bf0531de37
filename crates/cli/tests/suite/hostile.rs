//! A served module under hostile input: 100 MB of random bytes, thousands
//! of connects and disconnects, idle connections up to the limit. No
//! crash, bounded memory, correct replies to the valid frames that follow.

use crate::common;

use common::Server;
use std::io::{Read, Write};
use std::net::TcpStream;
use std::time::Duration;
use tmclsim_protocol::Reply;

/// A server with TCP on a free loopback port and `extra` arguments.
fn start(extra: &[&str]) -> Server {
    Server::start(&[&["--tcp", "127.0.0.1:0"][..], extra].concat())
}

/// xorshift64: the same "random" bytes every run. Every ninth byte (counted
/// from the start of the stream) is made a wrong checksum for the eight
/// before it, so no frame in the noise is ever executed: a random frame with
/// a good checksum could legitimately change the module address or switch
/// the link to ASCII mode, and then no later check could tell a healthy
/// server from a broken one.
/// Returns how many of the frames are addressed to module 1 (the only ones
/// answered: other addresses belong to other modules on the bus).
fn noise(seed: &mut u64, offset: u64, buf: &mut [u8], sum: &mut u8) -> u64 {
    let mut ours = 0;
    for (i, b) in buf.iter_mut().enumerate() {
        *seed ^= *seed << 13;
        *seed ^= *seed >> 7;
        *seed ^= *seed << 17;
        if (offset + i as u64) % 9 == 8 {
            *b = sum.wrapping_add(1 + (*seed as u8 % 255));
            *sum = 0;
        } else {
            *b = *seed as u8;
            *sum = sum.wrapping_add(*b);
            if (offset + i as u64).is_multiple_of(9) && *b == 1 {
                ours += 1;
            }
        }
    }
    ours
}

#[test]
fn a_hundred_megabytes_of_random_bytes() {
    // No partial frame is ever dropped on a pause: the stream stays aligned.
    let server = start(&["--inter-byte-timeout", "600000", "--bad-frame-limit", "0"]);
    server.check();
    let before = server.rss_kib();
    let mut s = TcpStream::connect(server.tcp()).unwrap();
    // Every frame addressed to the module is answered with a checksum error
    // (status 1); the replies are drained and counted while the noise goes
    // out.
    let mut r = s.try_clone().unwrap();
    let drain = std::thread::spawn(move || {
        let mut r = std::io::BufReader::with_capacity(1 << 16, &mut r);
        let (mut frames, mut bad) = (0u64, 0u64);
        let mut b = [0u8; 9];
        while r.read_exact(&mut b).is_ok() {
            frames += 1;
            match Reply::decode(&b) {
                Some(reply) if reply.status == 1 => {}
                _ => bad += 1,
            }
        }
        (frames, bad)
    });
    let (mut seed, mut sum) = (0x1234_5678_9ABC_DEF0u64, 0u8);
    let mut buf = vec![0u8; 1 << 20];
    let total = 100u64 << 20;
    let mut ours = 0;
    for chunk in 0..100u64 {
        ours += noise(&mut seed, chunk << 20, &mut buf, &mut sum);
        s.write_all(&buf).unwrap();
    }
    // The last frame is left four bytes short; finish the stream so the
    // reply count is exact.
    let rest = 9 - (total % 9) as usize;
    let mut tail = vec![0u8; rest];
    ours += noise(&mut seed, total, &mut tail, &mut sum);
    s.write_all(&tail).unwrap();
    s.shutdown(std::net::Shutdown::Write).unwrap();
    let (frames, bad) = drain.join().unwrap();
    assert!(ours > total / 9 / 300, "the noise addresses the module often: {ours}");
    assert_eq!(frames, ours, "one reply per frame addressed to the module");
    assert_eq!(bad, 0, "every reply is a checksum error");
    server.check();
    let after = server.rss_kib();
    assert!(after < before + 16 * 1024, "memory stays bounded: {before} KiB → {after} KiB");
}

#[test]
fn thousands_of_connects_and_disconnects() {
    let server = start(&[]);
    let before = server.rss_kib();
    for i in 0..3000 {
        let mut s = TcpStream::connect(server.tcp()).unwrap();
        if i % 3 == 0 {
            // Leave a partial frame behind.
            let _ = s.write_all(&[1, 6, 4]);
        }
        drop(s);
    }
    server.check_soon();
    let after = server.rss_kib();
    assert!(after < before + 8 * 1024, "{before} KiB → {after} KiB");
}

#[test]
fn idle_connections_up_to_the_limit() {
    let server = start(&["--max-connections", "20"]);
    // Each of the 20 is served once, so the server holds all of them (a
    // connection still in the listen queue takes no slot yet); then idle.
    let idle: Vec<TcpStream> = (0..20)
        .map(|_| {
            let mut s = server.connect();
            assert_eq!(common::ask(&mut s, "GGP 66, 0").map(|r| r.status), Some(100));
            s
        })
        .collect();
    // The 21st is refused: accepted and closed at once, with a log line.
    let mut extra = TcpStream::connect(server.tcp()).unwrap();
    extra.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
    let mut b = [0u8; 1];
    assert_eq!(extra.read(&mut b).unwrap_or(0), 0, "closed by the server");
    assert!(server.logged(&["refusing connection", "20 connections"]).is_some(), "no refusal in the log: {:?}", server.log.lock().unwrap());
    drop(idle);
    server.check_soon();
}

#[test]
fn half_open_and_half_closed_connections() {
    let server = start(&["--max-connections", "8"]);
    // A host that sends its last command and closes its sending half still
    // gets the reply.
    let mut s = TcpStream::connect(server.tcp()).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
    s.write_all(&common::frame("GAP 4, 0")).unwrap();
    s.shutdown(std::net::Shutdown::Write).unwrap();
    let mut b = [0u8; 9];
    s.read_exact(&mut b).unwrap();
    assert_eq!(Reply::decode(&b).unwrap().status, 100);
    assert_eq!(s.read(&mut b).unwrap(), 0, "then the server closes");
    // Hosts that vanish in the middle of a frame (half-open from the
    // server's side) hold no more than their own slot; others are served.
    let stuck: Vec<TcpStream> = (0..7)
        .map(|_| {
            let mut s = TcpStream::connect(server.tcp()).unwrap();
            s.write_all(&[1, 6, 4, 0]).unwrap();
            s
        })
        .collect();
    server.check_soon();
    drop(stuck);
    server.check_soon();
}
