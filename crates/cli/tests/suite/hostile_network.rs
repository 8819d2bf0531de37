//! The network faces of a served module against what a web page (through
//! a browser) or a careless client can send: another protocol on a TMCL
//! port, streams of bad frames, observers during a host's download, a
//! flood of the IDE's port (docs/robustness.md, docs/behaviour.md rules
//! 86, 90 and 91).

use crate::common;

use common::{Server, ask, frame, get, http_post_with_frames, send_and_read_to_close};
use std::io::{Read, Write};
use std::net::TcpStream;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};
use tmclsim_protocol::{Instruction, Reply, Request};

fn value_of(s: &mut TcpStream, line: &str) -> i32 {
    let r = ask(s, line).unwrap_or_else(|| panic!("{line}: no reply"));
    assert_eq!(r.status, 100, "{line}");
    r.value
}

#[test]
fn an_http_request_on_a_tmcl_port_executes_nothing() {
    for bus in [None, Some("tmcm-1141@1,tmcm-351@2")] {
        let args: Vec<&str> = match bus {
            Some(b) => vec!["--tcp", "127.0.0.1:0", "--bus", b],
            None => vec!["--tcp", "127.0.0.1:0"],
        };
        let server = Server::start(&args);
        let body: Vec<u8> = (0..20).flat_map(|_| frame("ROR 0, 500")).collect();
        let back = send_and_read_to_close(&server.tcp(), &http_post_with_frames(&server.tcp(), &body));
        assert!(back.is_empty(), "no reply to anything in an HTTP request: {back:02X?}");
        let mut s = server.connect();
        assert_eq!(value_of(&mut s, "GAP 2, 0"), 0, "the motor was not started ({bus:?})");
        assert!(server.logged(&["opened with an HTTP request", "nothing was executed"]).is_some(), "{:?}", server.log.lock().unwrap());
    }
}

#[test]
fn every_http_method_and_a_tls_hello_are_closed_unexecuted() {
    let server = Server::start(&["--tcp", "127.0.0.1:0"]);
    let body: Vec<u8> = (0..20).flat_map(|_| frame("ROR 0, 700")).collect();
    for method in ["GET", "HEAD", "PUT", "DELETE", "OPTIONS", "PATCH", "CONNECT", "TRACE"] {
        let mut request = http_post_with_frames(&server.tcp(), &body);
        request.splice(0..4, method.bytes());
        let back = send_and_read_to_close(&server.tcp(), &request);
        assert!(back.is_empty(), "{method}: {back:02X?}");
    }
    // A TLS 1.2 client hello record header, then frames.
    let hello = [[0x16, 0x03, 0x01, 0x00, 0xC8, 0x01, 0x00, 0x00, 0xC4].as_slice(), &body].concat();
    assert!(send_and_read_to_close(&server.tcp(), &hello).is_empty());
    assert!(server.logged(&["opened with a TLS client hello"]).is_some());
    assert_eq!(value_of(&mut server.connect(), "GAP 2, 0"), 0);
}

#[test]
fn an_http_request_reaches_no_module_in_ascii_mode() {
    let server = Server::start(&["--tcp", "127.0.0.1:0"]);
    let mut host = server.connect();
    assert_eq!(ask(&mut host, "#139 0 0 0").map(|r| r.status), Some(100), "ASCII mode");
    let request = http_post_with_frames(&server.tcp(), b"AROR 0, 500\rAROR 0, 500\r");
    assert!(send_and_read_to_close(&server.tcp(), &request).is_empty());
    // Back to binary on the host's connection, then read the speed.
    host.write_all(b"ABIN\r").unwrap();
    let mut answer = [0u8; 14];
    host.read_exact(&mut answer).unwrap();
    assert_eq!(&answer, b"ABIN\rBA 100 0\r", "the echo and the reply, nothing of the page's lines");
    assert_eq!(value_of(&mut host, "GAP 2, 0"), 0);
}

#[test]
fn an_http_request_on_the_control_port_changes_no_world() {
    let server = Server::start(&["--tcp", "127.0.0.1:0"]);
    let request = b"POST / HTTP/1.1\r\nHost: x\r\nContent-Length: 13\r\n\r\nlink mute on\n";
    let back = send_and_read_to_close(&server.control(), request);
    assert!(back.is_empty(), "{}", String::from_utf8_lossy(&back));
    assert!(ask(&mut server.connect(), "GAP 4, 0").is_some(), "the link is not muted");
    assert!(server.logged(&["closing control connection", "HTTP request"]).is_some());
}

#[test]
fn a_stream_of_bad_checksums_is_closed_after_the_limit() {
    let server = Server::start(&["--tcp", "127.0.0.1:0"]);
    let mut bad = frame("GAP 4, 0");
    bad[8] = bad[8].wrapping_add(1);
    let mut s = server.connect();
    // Fifteen in a row, then a good frame: the count starts again.
    for _ in 0..15 {
        s.write_all(&bad).unwrap();
        let mut r = [0u8; 9];
        s.read_exact(&mut r).unwrap();
        assert_eq!(r[2], 1, "status 1: wrong checksum");
    }
    value_of(&mut s, "GAP 4, 0");
    // Sixteen in a row: each is answered, then the connection is closed.
    for _ in 0..16 {
        s.write_all(&bad).unwrap();
    }
    let mut back = Vec::new();
    let _ = s.read_to_end(&mut back);
    assert_eq!(back.len(), 16 * 9, "sixteen replies, then the end");
    assert!(server.logged(&["16 frames in a row with a wrong checksum"]).is_some());
    server.check();
}

/// The words a host downloads: 500 different ones.
fn program() -> Vec<Instruction> {
    (0..500).map(|n| Instruction::new(5, 4, 0, 1000 + n)).collect()
}

/// Sends one frame and reads its reply, whole.
fn exchange(s: &mut TcpStream, ins: Instruction) -> [u8; 9] {
    s.write_all(&Request::new(1, ins).encode()).unwrap();
    let mut r = [0u8; 9];
    s.read_exact(&mut r).unwrap();
    r
}

/// A WebSocket client of the IDE's live stream: subscribes to signals and
/// the program's state at 100 Hz and reads samples until `stop`.
fn live_stream(web: String, stop: Arc<AtomicBool>, samples: Arc<AtomicU64>) {
    let addr = web.trim_start_matches("http://").trim_end_matches('/').to_string();
    let stream = TcpStream::connect(&addr).unwrap();
    let url = format!("ws://{addr}/api/modules/0/live");
    let (mut ws, _) = tungstenite::client(url.as_str(), stream).unwrap();
    let sub = r#"{"signals":[{"kind":"ap","number":1},{"kind":"ap","number":207},{"kind":"gp","number":133},{"kind":"input","number":0}],"rate":100,"program":true}"#;
    ws.send(tungstenite::Message::text(sub)).unwrap();
    while !stop.load(Ordering::Relaxed) {
        match ws.read() {
            Ok(tungstenite::Message::Text(t)) => {
                assert!(!t.starts_with("{\"error\""), "{t}");
                samples.fetch_add(1, Ordering::Relaxed);
            }
            Ok(_) => {}
            Err(e) => panic!("live stream: {e}"),
        }
    }
}

#[test]
fn observers_and_a_second_host_do_not_corrupt_a_hosts_download() {
    let server = Server::start(&["--tcp", "127.0.0.1:0", "--web", "127.0.0.1:0"]);
    let web = server.printed("web");
    let stop = Arc::new(AtomicBool::new(false));
    let (samples, states, polls) = (Arc::new(AtomicU64::new(0)), Arc::new(AtomicU64::new(0)), Arc::new(AtomicU64::new(0)));
    let mut observers = Vec::new();
    observers.push({
        let (web, stop, samples) = (web.clone(), stop.clone(), samples.clone());
        std::thread::spawn(move || live_stream(web, stop, samples))
    });
    observers.push({
        let (web, stop, states) = (web.clone(), stop.clone(), states.clone());
        std::thread::spawn(move || {
            while !stop.load(Ordering::Relaxed) {
                let (status, body) = get(&web, "/api/modules/0/program/state");
                assert!(status.contains("200"), "{status} {body}");
                states.fetch_add(1, Ordering::Relaxed);
            }
        })
    });
    // A second host on its own connection polls the position.
    observers.push({
        let (mut s, stop, polls) = (server.connect(), stop.clone(), polls.clone());
        std::thread::spawn(move || {
            while !stop.load(Ordering::Relaxed) {
                let r = Reply::decode(&exchange(&mut s, Instruction::new(6, 1, 0, 0))).unwrap();
                assert_eq!(r.status, 100, "the second host is answered in direct mode");
                polls.fetch_add(1, Ordering::Relaxed);
            }
        })
    });
    // Waits until every observer has run `more` times beyond `from`.
    let counts = || [&samples, &states, &polls].map(|n| n.load(Ordering::Relaxed));
    let wait_for = |from: [u64; 3], more: u64| {
        let t = Instant::now();
        while counts().iter().zip(from).any(|(now, from)| *now < from + more) {
            assert!(t.elapsed() < Duration::from_secs(10), "an observer does not run: {from:?} → {:?}", counts());
            std::thread::sleep(Duration::from_millis(10));
        }
    };
    wait_for([0; 3], 3);

    let mut host = server.connect();
    let words = program();
    assert_eq!(exchange(&mut host, Instruction::new(132, 0, 0, 0))[2], 100);
    // Another connection may not start, end or run a download it does not own.
    let mut other = server.connect();
    for op in [132, 133, 129] {
        assert_eq!(exchange(&mut other, Instruction::new(op, 0, 0, 0))[2], 6, "opcode {op} from another host: status 6");
    }
    // Every hundred words, each observer runs at least once more while
    // the download is under way.
    for (a, w) in words.iter().enumerate() {
        assert_eq!(exchange(&mut host, *w)[2], 101, "word {a} stored");
        if a % 100 == 0 {
            wait_for(counts(), 1);
        }
    }
    assert_eq!(exchange(&mut host, Instruction::new(133, 0, 0, 0))[2], 100);
    stop.store(true, Ordering::Relaxed);
    for o in observers {
        o.join().unwrap();
    }
    let back: Vec<Instruction> = (0..words.len() as i32)
        .map(|a| {
            let r = exchange(&mut host, Instruction::new(134, 0, 0, a));
            Instruction::from_bytes(r[1..8].try_into().unwrap())
        })
        .collect();
    assert!(back == words, "the program reads back as downloaded");
    let r = exchange(&mut host, Instruction::new(135, 0, 0, 0));
    assert_eq!(i32::from_be_bytes(r[4..8].try_into().unwrap()) & 0xFFFF, 500, "135 type 0: the download pointer");
}

#[test]
fn the_ides_reads_on_a_link_wait_for_its_download() {
    // The app on a link (`tmclsim ide --tcp`): its program state and reads
    // go over the same link as its download; a read that was checked
    // before the download was claimed must have its reply before the
    // download's first frame, or the module stores it as a word.
    let server = Server::start(&["--tcp", "127.0.0.1:0"]);
    let ide = Server::ide(&["--tcp", &server.tcp()]);
    let url = ide.printed("open");
    let stop = Arc::new(AtomicBool::new(false));
    let reads = Arc::new(AtomicU64::new(0));
    let pollers: Vec<_> = (0..3)
        .map(|n| {
            let (url, stop, reads) = (url.clone(), stop.clone(), reads.clone());
            std::thread::spawn(move || {
                while !stop.load(Ordering::Relaxed) {
                    let (status, body) = if n == 0 {
                        get(&url, "/api/modules/0/program/state")
                    } else {
                        common::post(&url, "/api/modules/0/read", r#"{"reads":[{"kind":"ap","number":1}]}"#)
                    };
                    assert!(status.contains("200") || status.contains("409"), "{status} {body}");
                    reads.fetch_add(1, Ordering::Relaxed);
                }
            })
        })
        .collect();
    let source: String = (0..64).map(|n| format!("SAP 4, 0, {}\\n", 1000 + n)).collect();
    let body = format!(r#"{{"source": "{source}"}}"#);
    for round in 0..10 {
        let before = reads.load(Ordering::Relaxed);
        let (status, answer) = common::post(&url, "/api/modules/0/program/download", &body);
        assert!(status.contains("200") && answer.contains("\"verified\":true"), "round {round}: {status} {answer}");
        let t = Instant::now();
        while reads.load(Ordering::Relaxed) < before + 3 {
            assert!(t.elapsed() < Duration::from_secs(10), "the pollers do not run");
            std::thread::sleep(Duration::from_millis(2));
        }
    }
    stop.store(true, Ordering::Relaxed);
    for p in pollers {
        p.join().unwrap();
    }
    let mut host = server.connect();
    for a in 0..64 {
        let r = exchange(&mut host, Instruction::new(134, 0, 0, a));
        assert_eq!(Instruction::from_bytes(r[1..8].try_into().unwrap()), Instruction::new(5, 4, 0, 1000 + a), "word {a}");
    }
}

#[test]
fn a_download_whose_host_left_passes_to_the_next_host() {
    let server = Server::start(&["--tcp", "127.0.0.1:0"]);
    let mut first = server.connect();
    assert_eq!(exchange(&mut first, Instruction::new(132, 0, 0, 0))[2], 100);
    assert_eq!(exchange(&mut first, Instruction::new(5, 4, 0, 1))[2], 101);
    drop(first);
    // As on a module whose host restarted: the next host takes the
    // download over where it stands (132 is status 6 while the first
    // host's close has not reached the module), its frames are stored,
    // and it can end the download.
    let mut next = server.connect();
    let deadline = Instant::now() + Duration::from_secs(10);
    let mut seen = Vec::new();
    loop {
        let status = exchange(&mut next, Instruction::new(132, 0, 0, 1))[2];
        seen.push(status);
        if status == 100 {
            break;
        }
        assert!(status == 6 && Instant::now() < deadline, "the download did not pass to the next host: 132 answered {seen:?}");
        std::thread::sleep(Duration::from_millis(20));
    }
    assert_eq!(exchange(&mut next, Instruction::new(5, 4, 0, 2))[2], 101);
    assert_eq!(exchange(&mut next, Instruction::new(133, 0, 0, 0))[2], 100);
    let r = exchange(&mut next, Instruction::new(134, 0, 0, 1));
    assert_eq!(Instruction::from_bytes(r[1..8].try_into().unwrap()), Instruction::new(5, 4, 0, 2));
}

#[test]
fn a_flood_of_the_ide_port_stops_neither_tmcl_nor_the_ide() {
    let server = Server::start(&["--tcp", "127.0.0.1:0", "--web", "127.0.0.1:0"]);
    let web = server.printed("web");
    let addr = web.trim_start_matches("http://").trim_end_matches('/').to_string();
    // 1100 connections that send nothing and stay open.
    let flood: Vec<TcpStream> = (0..1100).filter_map(|_| TcpStream::connect(&addr).ok()).collect();
    assert!(flood.len() >= 1000, "{} connections", flood.len());
    // TMCL answers at once.
    let t = Instant::now();
    let mut s = server.connect();
    value_of(&mut s, "GAP 4, 0");
    assert!(t.elapsed() < Duration::from_secs(2), "{:?}", t.elapsed());
    // The IDE answers too: 503 once the flood holds every slot (the server
    // takes the connections in as it gets to them).
    let ask_ide = || {
        let mut c = TcpStream::connect(&addr).unwrap();
        c.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
        // The server may answer (and close) before the request is
        // written: a failed write still leaves the answer to read.
        let _ = write!(c, "GET /api/modules HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\r\n");
        let mut answer = String::new();
        let _ = c.read_to_string(&mut answer);
        answer
    };
    let deadline = Instant::now() + Duration::from_secs(10);
    let mut answer = ask_ide();
    while !answer.starts_with("HTTP/1.1 503") && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(20));
        answer = ask_ide();
    }
    assert!(answer.starts_with("HTTP/1.1 503") && answer.contains("connections at once"), "{answer}");
    drop(flood);
    // Served again once the server saw the flood close.
    let deadline = Instant::now() + Duration::from_secs(10);
    let (mut status, mut body) = get(&web, "/api/modules");
    while !status.contains("200") && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(20));
        (status, body) = get(&web, "/api/modules");
    }
    assert!(status.contains("200"), "{status} {body}");
}

#[test]
fn the_ide_refuses_more_breakpoints_than_program_words() {
    let server = Server::start(&["--tcp", "127.0.0.1:0", "--web", "127.0.0.1:0"]);
    let web = server.printed("web");
    // The TMCM-1141 holds 1024 words: one more breakpoint than that is refused.
    let many: Vec<String> = (0..1025u32).map(|a| (a % 1024).to_string()).collect();
    let body = format!("{{\"addresses\":[{}]}}", many.join(","));
    let (status, text) = common::post(&web, "/api/modules/0/program/breakpoints", &body);
    assert!(status.contains("400") && text.contains("at most 1024 breakpoints"), "{status} {text}");
    let (status, text) = common::post(&web, "/api/modules/0/program/breakpoints", r#"{"addresses":[5000]}"#);
    assert!(status.contains("400") && text.contains("breakpoint at 5000"), "{status} {text}");
    let (status, _) = common::post(&web, "/api/modules/0/program/breakpoints", r#"{"addresses":[3,1,3]}"#);
    assert!(status.contains("200"), "{status}");
}
