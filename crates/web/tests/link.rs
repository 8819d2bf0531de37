//! The IDE against a module reached over TMCL (`tmclsim ide --tcp`): the
//! module list from 136, requests over the link, breakpoints by steps.

mod common;

use common::{Served, eventually, get, post, post_text};
use serde_json::json;
use std::sync::Arc;
use std::time::Duration;
use tmclsim_web::{LinkTarget, WebConfig};

#[test]
fn a_served_module_over_tcp_lists_answers_and_stops_at_breakpoints() {
    let s = Served::new();
    let tcp = s.tcp().to_string();
    let target = LinkTarget::open(Some(&tcp), None, 9600, &[1], Duration::from_secs(1)).unwrap();
    let web =
        tmclsim_web::start(Arc::new(target), WebConfig { addr: "127.0.0.1:0".parse().unwrap(), public: false, limits: Default::default() })
            .unwrap();
    let url = |p: &str| format!("http://{}{p}", web.addr());
    let (_, list) = get(&url("/api/modules"));
    assert_eq!(
        (list[0]["profile"].as_str(), list[0]["firmware"].as_str(), list[0]["virtual"].as_bool()),
        (Some("TMCM-1141"), Some("1141V146"), Some(false))
    );
    let (_, r) = post(&url("/api/modules/0/command"), json!({"line": "GAP 4, 0"}));
    assert_eq!(r["status"].as_u64(), Some(100));
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
fn an_address_that_does_not_answer_is_named() {
    let s = Served::new();
    let tcp = s.tcp().to_string();
    let e = LinkTarget::open(Some(&tcp), None, 9600, &[1, 7], Duration::from_millis(200)).err().unwrap();
    assert!(e.contains("module 7"), "{e}");
}

#[test]
fn a_module_on_a_serial_port_is_reached_as_a_real_one() {
    // A served module's pty stands in for a module's USB serial port.
    let dir = tempfile::tempdir().unwrap();
    let link = dir.path().join("ttyTMCM");
    let module = tmclsim_firmware::Module::new(tmclsim_firmware::Profile::built_in("tmcm-3110").unwrap());
    let config = tmclsim_server::ServerConfig { pty: Some(link.clone()), warn_exposure: false, ..Default::default() };
    let server = tmclsim_server::start(module, config).unwrap();
    let target = LinkTarget::open(None, Some(link.to_str().unwrap()), 9600, &[1], Duration::from_secs(1)).unwrap();
    let web =
        tmclsim_web::start(Arc::new(target), WebConfig { addr: "127.0.0.1:0".parse().unwrap(), public: false, limits: Default::default() })
            .unwrap();
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
