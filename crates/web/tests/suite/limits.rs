//! What a client can hold of the app's server, and what an observer can
//! change of a module: nothing (docs/robustness.md, docs/behaviour.md
//! rule 86).

use crate::common;

use common::{Served, ask, get};
use serde_json::json;
use std::io::{Read, Write};
use std::net::TcpStream;
use std::time::{Duration, Instant};
use tmclsim_web::Limits;
use tungstenite::Message;

/// Reads until the server closes the connection (at most 5 s): what came.
fn read_to_close(s: &mut TcpStream) -> String {
    s.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
    let mut text = Vec::new();
    let _ = s.read_to_end(&mut text);
    String::from_utf8_lossy(&text).into_owned()
}

#[test]
fn a_client_that_sends_no_request_head_in_time_is_closed() {
    let s = Served::with_limits(Limits { head_timeout: Duration::from_millis(300), ..Limits::default() });
    // Silent.
    let t = Instant::now();
    let mut silent = TcpStream::connect(s.web.addr()).unwrap();
    assert_eq!(read_to_close(&mut silent), "");
    assert!(t.elapsed() < Duration::from_secs(3), "{:?}", t.elapsed());
    // A head sent a byte at a time, slower than the limit allows in all.
    let mut slow = TcpStream::connect(s.web.addr()).unwrap();
    let t = Instant::now();
    for b in b"GET /api/info HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Slow: aaaaaaaaaaaaaaaaaaaa" {
        if slow.write_all(&[*b]).is_err() {
            break;
        }
        // About time: a byte every 20 ms, slower than the head timeout allows.
        std::thread::sleep(Duration::from_millis(20));
    }
    let answer = read_to_close(&mut slow);
    assert!(!answer.contains("200 OK"), "{answer}");
    assert!(t.elapsed() < Duration::from_secs(5));
    // A keep-alive connection idle after its answer is closed as well.
    let mut idle = TcpStream::connect(s.web.addr()).unwrap();
    write!(idle, "GET /api/info HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n").unwrap();
    let answer = read_to_close(&mut idle);
    assert!(answer.starts_with("HTTP/1.1 200"), "{answer}");
}

#[test]
fn connections_past_the_limit_are_answered_503() {
    let s = Served::with_limits(Limits { connections: 4, ..Limits::default() });
    // The server takes connections in the order they came: the four take
    // the slots before the fifth is looked at.
    let held: Vec<TcpStream> = (0..4).map(|_| TcpStream::connect(s.web.addr()).unwrap()).collect();
    let mut fifth = TcpStream::connect(s.web.addr()).unwrap();
    let answer = read_to_close(&mut fifth);
    assert!(answer.starts_with("HTTP/1.1 503") && answer.contains("4 connections at once"), "{answer}");
    drop(held);
    common::until("/api/info answered once the four closed", || get(&s.url("/api/info")).0, |code| *code == 200);
}

#[test]
fn a_head_larger_than_the_limit_is_refused() {
    let s = Served::new();
    let mut c = TcpStream::connect(s.web.addr()).unwrap();
    let big = "a".repeat(64 * 1024);
    let _ = write!(c, "GET /api/info HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Big: {big}\r\n\r\n");
    let answer = read_to_close(&mut c);
    assert!(answer.starts_with("HTTP/1.1 431"), "{}", &answer[..answer.len().min(80)]);
}

fn live(s: &Served) -> tungstenite::WebSocket<tungstenite::stream::MaybeTlsStream<TcpStream>> {
    tungstenite::connect(format!("ws://{}/api/modules/0/live", s.web.addr())).unwrap().0
}

#[test]
fn a_websocket_message_past_64_kib_closes_the_socket() {
    let s = Served::new();
    let mut ws = live(&s);
    let huge = format!("{{\"signals\": [], \"pad\": \"{}\"}}", "x".repeat(1 << 20));
    let _ = ws.send(Message::text(huge));
    let closed = (0..10).any(|_| matches!(ws.read(), Err(_) | Ok(Message::Close(_))));
    assert!(closed, "the socket is closed");
}

#[test]
fn a_flood_of_websocket_messages_closes_the_socket_with_the_reason() {
    let s = Served::new();
    let mut ws = live(&s);
    for _ in 0..60 {
        if ws.send(Message::text(r#"{"signals": [], "rate": 1}"#)).is_err() {
            break;
        }
    }
    let mut said = String::new();
    for _ in 0..10 {
        match ws.read() {
            Ok(Message::Text(t)) => said.push_str(&t),
            Ok(Message::Close(Some(f))) => {
                said.push_str(&f.reason);
                break;
            }
            Ok(_) => {}
            Err(_) => break,
        }
    }
    assert!(said.contains("more than 50 messages in a second"), "{said}");
}

#[test]
fn wrong_tokens_wait_longer_and_longer() {
    let s = Served::new();
    let target = std::sync::Arc::new(tmclsim_web::VirtualTarget::new(s.server.links()));
    let web =
        tmclsim_web::start(target, tmclsim_web::WebConfig { addr: "0.0.0.0:0".parse().unwrap(), public: true, limits: Limits::default() })
            .unwrap();
    let base = format!("http://127.0.0.1:{}/api/info", web.addr().port());
    let timed = |url: &str| {
        let t = Instant::now();
        let code = get(url).0;
        (code, t.elapsed())
    };
    let mut waits = Vec::new();
    for _ in 0..6 {
        let (code, took) = timed(&format!("{base}?token=0123456789abcdef0123456789abcdef"));
        assert_eq!(code, 403);
        waits.push(took);
    }
    assert!(waits[5] >= Duration::from_millis(300), "the sixth failure in a row waits 640 ms: {waits:?}");
    let (code, _) = timed(&format!("{base}?token={}", web.token().unwrap()));
    assert_eq!(code, 200);
    let (code, took) = timed(&format!("{base}?token=wrong"));
    assert_eq!(code, 403);
    assert!(took < waits[5], "the right token ended the run: {took:?}");
}

#[test]
fn observing_changes_nothing_a_host_reads() {
    // GP 133 hands out a new random number to each read: the app's
    // observations of it must not take numbers from the host.
    let s = Served::new();
    let mut host = s.host();
    ask(&mut host, "SGP 133, 0, 4711");
    let observed: Vec<i64> = (0..5)
        .map(|_| {
            let (code, v) = common::post(&s.url("/api/modules/0/read"), json!({"reads": [{"kind": "gp", "number": 133}]}));
            assert_eq!(code, 200, "{v}");
            v["values"][0].as_i64().unwrap()
        })
        .collect();
    assert!(observed.windows(2).all(|w| w[0] == w[1]), "{observed:?}");
    assert_eq!(i64::from(ask(&mut host, "GGP 133, 0").value), observed[0], "the host gets the number the app saw next");
}
