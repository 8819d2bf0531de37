//! The IDE against a module reached over TMCL (`tmclsim ide --tcp`): the
//! module list from 136, requests over the link, breakpoints by steps.

use crate::common;

use common::{Served, app_on_loopback, app_over_tcp, get, post, post_text, until};
use serde_json::json;
use std::time::Duration;
use tmclsim_web::LinkTarget;

#[test]
fn a_served_module_over_tcp_lists_answers_and_stops_at_breakpoints() {
    let s = Served::new();
    let tcp = s.tcp().to_string();
    let web = app_over_tcp(&tcp);
    let url = |p: &str| format!("http://{}{p}", web.addr());
    let (_, list) = get(&url("/api/modules"));
    assert_eq!(
        (list[0]["profile"].as_str(), list[0]["firmware"].as_str(), list[0]["virtual"].as_bool()),
        (Some("TMCM-1141"), Some("1141V146"), Some(false))
    );
    let (_, r) = post(&url("/api/modules/0/command"), json!({"line": "GAP 4, 0"}));
    assert_eq!(r["status"].as_u64(), Some(100));
    // 136 type 0 answers a string, not a status.
    let (_, r) = post(&url("/api/modules/0/command"), json!({"line": "#136 0 0 0"}));
    assert_eq!(
        (r["version"].as_str(), r["text"].as_str(), r["status"].is_null()),
        (Some("1141V146"), Some("version 1141V146"), true),
        "{r}"
    );
    // The world is the simulator's: a link target has none.
    assert_eq!(post(&url("/api/modules/0/world"), json!({"line": "reset"})).0, 409);

    let source = "Start: SAP 4, 0, 1000\nLoop: CALC ADD, 1\n  CALC ADD, 1\n  JA Loop\n";
    let last = post_text(&url("/api/modules/0/program/download"), json!({"source": source}));
    assert!(last.trim_end().ends_with("}") && last.contains("\"verified\":true"), "{last}");
    post(&url("/api/modules/0/program/breakpoints"), json!({"addresses": [3]}));
    post(&url("/api/modules/0/program/run"), json!({}));
    until("the breakpoint hit", || get(&url("/api/modules/0/program/state")).1, |st| st["breakpoint"] == 3);
    let (_, st) = get(&url("/api/modules/0/program/state"));
    assert_eq!((st["pc"].as_u64(), st["accumulator"].as_i64()), (Some(3), Some(2)));
    assert!(st["flags"].is_null(), "TMCL does not report flags");
    post(&url("/api/modules/0/program/continue"), json!({}));
    until("accumulator 4", || get(&url("/api/modules/0/program/state")).1, |st| st["accumulator"] == 4);
    post(&url("/api/modules/0/program/stop"), json!({}));
}

/// The frames a proxy saw: the host's, and the module's.
type Frames = std::sync::Arc<std::sync::Mutex<(Vec<[u8; 9]>, Vec<[u8; 9]>)>>;

/// Frames a host sends through a TCP proxy to `to`, and the module's
/// answers, nine bytes each, in order; the proxy's address.
fn recording_proxy(to: std::net::SocketAddr) -> (String, Frames) {
    use std::io::{Read, Write};
    let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = listener.local_addr().unwrap().to_string();
    let log = std::sync::Arc::new(std::sync::Mutex::new((Vec::new(), Vec::new())));
    let frames = log.clone();
    std::thread::spawn(move || {
        let (host, _) = listener.accept().unwrap();
        let module = std::net::TcpStream::connect(to).unwrap();
        let pipe = |mut from: std::net::TcpStream, mut into: std::net::TcpStream, requests: bool| {
            let log = frames.clone();
            std::thread::spawn(move || {
                let mut f = [0u8; 9];
                while from.read_exact(&mut f).is_ok() {
                    let mut l = log.lock().unwrap();
                    let side = if requests { &mut l.0 } else { &mut l.1 };
                    side.push(f);
                    drop(l);
                    if into.write_all(&f).is_err() {
                        break;
                    }
                }
            })
        };
        pipe(host.try_clone().unwrap(), module.try_clone().unwrap(), true);
        pipe(module, host, false);
    });
    (addr, log)
}

/// The IDE's Download over a link sends what TMCL-IDE sends
/// (docs/behaviour.md rules 93, 94): 132, the words, the STOP appended
/// after the source's last instruction, a NOP, 133; every word, the NOP
/// too, answered with status 101.
#[test]
fn a_download_over_a_link_ends_with_the_stop_and_the_nop_before_133() {
    let s = Served::new();
    let (proxy, log) = recording_proxy(s.tcp());
    let web = app_over_tcp(&proxy);
    let url = |p: &str| format!("http://{}{p}", web.addr());
    let last = post_text(&url("/api/modules/0/program/download"), json!({"source": "Loop: ROR 0, 100\n  WAIT TICKS, 0, 10\n  JA Loop\n"}));
    assert!(last.contains("\"verified\":true") && last.contains("\"words\":4"), "{last}");
    let (sent, answered) = log.lock().unwrap().clone();
    let start = sent.iter().position(|f| f[1] == 132).expect("132");
    let opcodes: Vec<u8> = sent[start..].iter().map(|f| f[1]).take(7).collect();
    assert_eq!(opcodes, [132, 1, 27, 22, 28, 0, 133], "{sent:02X?}");
    assert_eq!(sent[start + 4], [0x01, 0x1C, 0, 0, 0, 0, 0, 0, 0x1D], "the STOP");
    assert_eq!(sent[start + 5], [0x01, 0, 0, 0, 0, 0, 0, 0, 0x01], "the NOP");
    let statuses: Vec<u8> = answered[start..start + 7].iter().map(|f| f[2]).collect();
    assert_eq!(statuses, [100, 101, 101, 101, 101, 101, 100], "{answered:02X?}");
    // Then 134 reads the four words back.
    assert_eq!(sent[start + 7..].iter().filter(|f| f[1] == 134).count(), 4);
}

#[test]
fn an_address_that_does_not_answer_is_named_and_left_out() {
    let s = Served::new();
    let tcp = s.tcp().to_string();
    let target = LinkTarget::open(Some(&tcp), None, 9600, tmclsim_web::Probe::Addresses(&[1, 7]), Duration::from_millis(200)).unwrap();
    assert_eq!(target.missing(), &[7]);
    assert_eq!(tmclsim_web::Target::modules(target.as_ref()).iter().map(|m| m.address).collect::<Vec<_>>(), vec![1]);
    let e = LinkTarget::open(Some(&tcp), None, 9600, tmclsim_web::Probe::Addresses(&[5, 7]), Duration::from_millis(200)).err().unwrap();
    assert!(e.contains("answered at address 5, 7"), "{e}");
}

#[test]
#[cfg_attr(windows, ignore = "a pty is a Unix device: the server refuses one on Windows")]
fn a_module_on_a_serial_port_is_reached_as_a_real_one() {
    // A served module's pty stands in for a module's USB serial port.
    let dir = tempfile::tempdir().unwrap();
    let link = dir.path().join("ttyTMCM");
    let module = tmclsim_firmware::Module::new(tmclsim_firmware::Profile::built_in("tmcm-3110").unwrap());
    let config = tmclsim_server::ServerConfig { pty: Some(link.clone()), warn_exposure: false, ..Default::default() };
    let server = tmclsim_server::start(module, config).unwrap();
    let target =
        LinkTarget::open(None, Some(link.to_str().unwrap()), 9600, tmclsim_web::Probe::Addresses(&[1]), Duration::from_secs(1)).unwrap();
    let web = app_on_loopback(target, Default::default());
    let url = |p: &str| format!("http://{}{p}", web.addr());
    let (_, list) = get(&url("/api/modules"));
    assert_eq!(list[0]["profile"], "TMCM-3110");
    assert!(list[0]["link"].as_str().unwrap().starts_with("serial "));
    let (_, p) = get(&url("/api/modules/0/profile"));
    assert_eq!(p["axes"], 3);
    let (_, r) = post(&url("/api/modules/0/command"), json!({"line": "GAP 4, 2"}));
    assert_eq!(r["status"].as_u64(), Some(100), "{r}");
    drop(web);
    drop(server);
}

/// A loop with a WAIT and a breakpoint on the instruction after it: the
/// program stops there every time it comes round, also after Continue, and
/// no state read while it runs on names a breakpoint.
fn stops_every_time(url: &dyn Fn(&str) -> String) {
    // Half a second between two hits: more than the app needs, even on a
    // busy machine, to read the program's state (about twenty requests)
    // between them.
    let source = "Loop: CALC ADD, 1\n  WAIT TICKS, 0, 50\n  CALC ADD, 10\n  JA Loop\n";
    let last = post_text(&url("/api/modules/0/program/download"), json!({"source": source}));
    assert!(last.contains("\"verified\":true"), "{last}");
    post(&url("/api/modules/0/program/breakpoints"), json!({"addresses": [2]}));
    post(&url("/api/modules/0/program/run"), json!({}));
    for round in 1..=3 {
        let st = until(&format!("round {round}: the hit"), || get(&url("/api/modules/0/program/state")).1, |st| st["breakpoint"] == 2);
        assert_eq!((st["pc"].as_u64(), st["accumulator"].as_i64()), (Some(2), Some(11 * round - 10)), "round {round}: {st}");
        assert_ne!(st["mode"], "running");
        let (_, st) = post(&url("/api/modules/0/program/continue"), json!({}));
        assert!(st["breakpoint"].is_null(), "{st}");
        for _ in 0..5 {
            let st = get(&url("/api/modules/0/program/state")).1;
            let at_the_next_hit = st["pc"] == 2 && st["accumulator"].as_i64() == Some(11 * round + 1);
            assert!(st["breakpoint"].is_null() || at_the_next_hit, "{st}");
        }
    }
    // The program read back (134) up to its end, disassembled: the four
    // words and the STOP appended after JA (docs/behaviour.md rule 93); the
    // NOP after it (rule 94) is an empty word, not part of the program.
    let (status, back) = get(&url("/api/modules/0/program/source"));
    assert_eq!((status, back["words"].as_u64()), (200, Some(5)), "{back}");
    let text = back["source"].as_str().unwrap();
    assert!(text.contains("CALC ADD, 1") && text.contains("WAIT TICKS, 0, 50") && text.contains("JA "), "{text}");
    assert!(text.contains("    STOP"), "{text}");
    // Run starts over at address 0: the last hit is not reported there.
    let (_, st) = post(&url("/api/modules/0/program/run"), json!({}));
    assert!(st["breakpoint"].is_null() || st["pc"] == 2, "{st}");
    post(&url("/api/modules/0/program/stop"), json!({}));
}

#[test]
#[cfg_attr(
    windows,
    ignore = "under Wine a TCP round trip takes a millisecond: the stepped loop goes round while one state read (some twenty requests) is assembled"
)]
fn a_breakpoint_by_steps_stops_every_time_the_loop_reaches_it() {
    let s = Served::new();
    let tcp = s.tcp().to_string();
    let web = app_over_tcp(&tcp);
    stops_every_time(&|p: &str| format!("http://{}{p}", web.addr()));
}

#[test]
fn a_breakpoint_in_the_firmware_stops_every_time_the_loop_reaches_it() {
    let s = Served::new();
    stops_every_time(&|p: &str| s.url(p));
}
