//! The IDE against a module reached over TMCL (`tmclsim ide --tcp`): the
//! module list from 136, requests over the link, breakpoints by steps.

use crate::common;

use common::{Served, app_on_loopback, app_over_tcp, eventually, get, post, post_text};
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
    assert!(eventually(5.0, || get(&url("/api/modules/0/program/state")).1["breakpoint"] == 3));
    let (_, st) = get(&url("/api/modules/0/program/state"));
    assert_eq!((st["pc"].as_u64(), st["accumulator"].as_i64()), (Some(3), Some(2)));
    assert!(st["flags"].is_null(), "TMCL does not report flags");
    post(&url("/api/modules/0/program/continue"), json!({}));
    assert!(eventually(5.0, || get(&url("/api/modules/0/program/state")).1["accumulator"] == 4));
    post(&url("/api/modules/0/program/stop"), json!({}));
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
    let source = "Loop: CALC ADD, 1\n  WAIT TICKS, 0, 2\n  CALC ADD, 10\n  JA Loop\n";
    let last = post_text(&url("/api/modules/0/program/download"), json!({"source": source}));
    assert!(last.contains("\"verified\":true"), "{last}");
    post(&url("/api/modules/0/program/breakpoints"), json!({"addresses": [2]}));
    post(&url("/api/modules/0/program/run"), json!({}));
    for round in 1..=3 {
        let mut st = serde_json::Value::Null;
        assert!(
            eventually(5.0, || {
                st = get(&url("/api/modules/0/program/state")).1;
                st["breakpoint"] == 2
            }),
            "round {round}: {st}"
        );
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
    // The program read back (134) up to its end, disassembled.
    let (status, back) = get(&url("/api/modules/0/program/source"));
    assert_eq!((status, back["words"].as_u64()), (200, Some(4)), "{back}");
    let text = back["source"].as_str().unwrap();
    assert!(text.contains("CALC ADD, 1") && text.contains("WAIT TICKS, 0, 2") && text.contains("JA "), "{text}");
    // Run starts over at address 0: the last hit is not reported there.
    let (_, st) = post(&url("/api/modules/0/program/run"), json!({}));
    assert!(st["breakpoint"].is_null() || st["pc"] == 2, "{st}");
    post(&url("/api/modules/0/program/stop"), json!({}));
}

#[test]
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
