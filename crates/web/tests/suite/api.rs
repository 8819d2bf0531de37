//! The IDE's API against a served TMCM-1141: every request goes through
//! the module's request path, so a host on the module's TCP link and the
//! app see each other's changes.

use crate::common;
use std::io::Write;

use common::{Served, ask, get, post, post_text, until};
use serde_json::{Value, json};
use tmclsim_protocol::Status;

#[test]
fn the_module_list_names_profile_firmware_and_link() {
    let s = Served::new();
    let (code, list) = get(&s.url("/api/modules"));
    assert_eq!(code, 200);
    let m = &list[0];
    assert_eq!((m["address"].as_u64(), m["profile"].as_str(), m["firmware"].as_str()), (Some(1), Some("TMCM-1141"), Some("1141V146")));
    assert_eq!(m["link"], format!("tcp {}", s.tcp()));
    assert_eq!(m["virtual"], true);
    assert_eq!(get(&s.url("/api/info")).1["target"], "virtual");
    assert_eq!(get(&s.url("/api/modules/1/profile")).0, 404);
}

#[test]
fn the_profile_has_ranges_defaults_sources_and_reference_modes() {
    let s = Served::new();
    let (_, p) = get(&s.url("/api/modules/0/profile"));
    let ap4 = p["axis_parameters"].as_array().unwrap().iter().find(|r| r["number"] == 4).unwrap();
    // TMCM-1141 manual, table 16: AP 4 is 1…2047 (profiles/tmcm-1141.toml), readable and writable.
    assert_eq!((ap4["min"].as_i64(), ap4["max"].as_i64()), (Some(1), Some(2047)));
    assert!(ap4["access"].as_str().unwrap().starts_with("RW"));
    assert!(["manual", "sibling", "assumed"].contains(&ap4["default_source"].as_str().unwrap()));
    let modes: Vec<i64> = p["reference_modes"].as_array().unwrap().iter().map(|m| m["value"].as_i64().unwrap()).collect();
    assert_eq!(modes, [1, 2, 3, 4, 5, 6, 7, 8, 65, 66, 67, 68, 133, 134, 135, 136]);
    assert!(p["commands"].as_array().unwrap().contains(&json!("MVP")));
    let gp = p["global_parameters"].as_array().unwrap();
    assert!(gp.iter().any(|r| r["bank"] == 0 && r["number"] == 65), "GP 65 (baud rate) in bank 0");
}

#[test]
fn the_profile_says_what_the_unit_conversion_needs() {
    let s = Served::new();
    let (_, p) = get(&s.url("/api/modules/0/profile"));
    // TMCM-1141 manual 6.1.1: f_CLK = 16 MHz; AP 2, 3, 4, 130, 181, 182,
    // 194, 195 are velocities, AP 5 an acceleration.
    assert_eq!(p["motion_clock_hz"], 16_000_000);
    let quantity = |n: i64| p["axis_parameters"].as_array().unwrap().iter().find(|r| r["number"] == n).unwrap()["quantity"].clone();
    for n in [2, 3, 4, 130, 181, 182, 194, 195] {
        assert_eq!(quantity(n), "velocity", "AP {n}");
    }
    assert_eq!(quantity(5), "acceleration");
    assert_eq!(quantity(1), Value::Null, "a position is neither");
    assert_eq!(quantity(154), Value::Null, "the pulse divisor is neither");
    // In the TMC429's units, with the motor's microsteps and divisors.
    assert_eq!(p["motion_units"], "tmc429");
    assert_eq!(p["conversion"], json!({"microsteps": 140, "ramp_divisor": 153, "pulse_divisor": 154}));
}

#[test]
fn direct_mode_takes_names_and_answers_in_words() {
    let s = Served::new();
    let (code, r) = post(&s.url("/api/modules/0/command"), json!({"line": "SAP maximum_positioning_speed, 0, 1234"}));
    assert_eq!(code, 200);
    assert_eq!((r["status"].as_u64(), r["request"].as_str()), (Some(100), Some("01 05 04 00 00 00 04 d2 e0")));
    // The host on the link sees what the app set.
    let mut host = s.host();
    assert_eq!(ask(&mut host, "GAP 4, 0").value, 1234);
    let (_, r) = post(&s.url("/api/modules/0/command"), json!({"line": "GAP 4, 0"}));
    assert_eq!(r["text"], "Maximum positioning speed (4) = 1234 int");
    // A typo is a 400 with a suggestion; an invalid value the module's status 4.
    let (code, r) = post(&s.url("/api/modules/0/command"), json!({"line": "GPA 4, 0"}));
    assert_eq!(code, 400);
    assert!(r["error"].as_str().unwrap().contains("did you mean 'GAP'"), "{r}");
    let (_, r) = post(&s.url("/api/modules/0/command"), json!({"line": "SAP 4, 0, 99999"}));
    assert_eq!(r["status"].as_u64(), Some(u64::from(Status::InvalidValue.code())));
    assert!(r["text"].as_str().unwrap().contains("1…2047"), "{r}");
}

#[test]
fn reads_and_writes_go_through_the_module() {
    let s = Served::new();
    let mut host = s.host();
    assert_eq!(ask(&mut host, "SAP 5, 0, 777").status, 100);
    let reads = json!({"reads": [{"kind": "ap", "number": 5, "index": 0}, {"kind": "gp", "number": 66, "index": 0}, {"kind": "ap", "number": 250, "index": 0}]});
    let (_, r) = post(&s.url("/api/modules/0/read"), reads);
    // AP 250 does not exist on the TMCM-1141: null, not a number.
    assert_eq!(r["values"], json!([777, 1, null]));
    let (_, w) = post(&s.url("/api/modules/0/write"), json!({"kind": "ap", "number": 5, "index": 0, "value": 500}));
    assert_eq!(w["status"].as_u64(), Some(100));
    assert_eq!(ask(&mut host, "GAP 5, 0").value, 500);
    let (_, w) = post(&s.url("/api/modules/0/write"), json!({"kind": "ap", "number": 5, "index": 0, "value": 5_000_000_000i64}));
    assert!(w["error"].as_str().unwrap().contains("32-bit"));
    let (_, w) = post(&s.url("/api/modules/0/write"), json!({"kind": "gp", "number": 0, "index": 2, "value": 42}));
    assert_eq!(w["status"].as_u64(), Some(100));
    let (_, w) = post(&s.url("/api/modules/0/write"), json!({"op": "store", "kind": "gp", "number": 0, "index": 2}));
    assert_eq!(w["request"].as_str().unwrap().split(' ').nth(1), Some("0b"), "STGP");
}

const COUNTER: &str = "Start:  SAP 4, 0, 1000\nLoop:   CALC ADD, 1\n        WAIT TICKS, 0, 1\n        JA Loop\n";

#[test]
fn assembling_reports_errors_at_line_and_column_and_maps_addresses_to_lines() {
    let s = Served::new();
    let (_, r) = post(&s.url("/api/assemble"), json!({"source": "Loop: CALC ADD, 1\n  JA Lop\n", "profile": "TMCM-1141"}));
    assert_eq!(r["ok"], false);
    let d = &r["diagnostics"][0];
    assert_eq!((d["line"].as_u64(), d["column"].as_u64()), (Some(2), Some(6)));
    assert!(d["message"].as_str().unwrap().contains("did you mean 'Loop'"));
    let (_, r) = post(&s.url("/api/assemble"), json!({"source": COUNTER}));
    // Four instructions and the STOP appended after JA Loop
    // (docs/behaviour.md rule 93), which no line of the source map names.
    assert_eq!((r["words"].as_u64(), r["appended_stop"].as_bool()), (Some(5), Some(true)));
    let lines: Vec<u64> = r["source_map"].as_array().unwrap().iter().map(|e| e["line"].as_u64().unwrap()).collect();
    assert_eq!(lines, [1, 2, 3, 4]);
    assert!(r["listing"].as_str().unwrap().ends_with("    4  STOP  // appended: the program does not end in STOP\n"), "{r}");
    assert_eq!(r["symbols"]["Loop"], 1);
}

fn download(s: &Served, source: &str) -> Vec<Value> {
    post_text(&s.url("/api/modules/0/program/download"), json!({"source": source}))
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

#[test]
fn download_verifies_every_word_and_the_host_reads_them_back() {
    let s = Served::new();
    let lines = download(&s, COUNTER);
    let last = lines.last().unwrap();
    // The four words of the source and the STOP appended after JA Loop.
    assert_eq!((last["done"].as_bool(), last["verified"].as_bool(), last["words"].as_u64()), (Some(true), Some(true), Some(5)));
    assert_eq!(lines[lines.len() - 2]["progress"], lines[lines.len() - 2]["total"]);
    // 134 on the host's link reads the stored CALC ADD, 1 at address 1,
    // the STOP at 4 and, at 5, the NOP sent after it before 133
    // (docs/behaviour.md rule 94), stored as the module stores every word.
    let mut host = s.host();
    use std::io::{Read, Write};
    let mut read = |op: u8, value: i32| {
        host.write_all(&tmclsim_protocol::Request::new(1, tmclsim_protocol::Instruction::new(op, 0, 0, value)).encode()).unwrap();
        let mut raw = [0u8; 9];
        host.read_exact(&mut raw).unwrap();
        raw
    };
    assert_eq!(&read(134, 1)[1..4], &[19, 0, 0], "CALC (19) ADD (0)");
    assert_eq!(&read(134, 4)[1..8], &[28, 0, 0, 0, 0, 0, 0], "STOP");
    assert_eq!(&read(134, 5)[1..8], &[0; 7], "the NOP");
    // 135 type 0: stopped, the download pointer after the NOP.
    let status = read(135, 0);
    assert_eq!((status[2], i32::from_be_bytes(status[4..8].try_into().unwrap())), (100, 6));
    // An error in the source: no download, the diagnostics.
    let lines = download(&s, "JA Nowhere\n");
    assert_eq!(lines[0]["ok"], false);
}

#[test]
fn a_breakpoint_stops_the_program_on_its_line_with_the_accumulator_shown() {
    let s = Served::new();
    download(&s, COUNTER);
    let m = |p: &str| s.url(&format!("/api/modules/0/program/{p}"));
    let (_, st) = post(&m("breakpoints"), json!({"addresses": [2]}));
    assert_eq!(st["breakpoints"], json!([2]));
    post(&m("run"), json!({}));
    until("the breakpoint hit", || get(&m("state")).1, |st| st["breakpoint"] == 2);
    let (_, st) = get(&m("state"));
    assert_eq!((st["pc"].as_u64(), st["accumulator"].as_i64()), (Some(2), Some(1)));
    assert!(st["stack_depth"].is_number() && st["flags"].is_string(), "a virtual module shows flags and stack depth: {st}");
    post(&m("continue"), json!({}));
    until("the next hit, accumulator 2", || get(&m("state")).1, |st| st["accumulator"] == 2 && st["breakpoint"] == 2);
    // Stopped (128) on the breakpoint's address, the program no longer
    // stands at a breakpoint: the next run must not look paused there.
    let (_, st) = post(&m("stop"), json!({}));
    assert_eq!((st["mode"].as_str(), st["pc"].as_u64()), (Some("stopped"), Some(2)), "{st}");
    assert!(st["breakpoint"].is_null(), "{st}");
    let (code, e) = post(&m("jump"), json!({}));
    assert_eq!(code, 400, "{e}");
}

#[test]
fn the_world_panel_stops_the_motor_with_a_switch() {
    let s = Served::new();
    let mut host = s.host();
    assert_eq!(ask(&mut host, "ROL 0, 500").status, 100);
    until("the motor turning left", || get(&s.url("/api/modules/0/world")).1["axes"][0].clone(), |a| a["speed"].as_i64().unwrap_or(0) < 0);
    let (code, r) = post(&s.url("/api/modules/0/world"), json!({"line": "switch 0 left press"}));
    assert_eq!(code, 200, "{r}");
    until(
        "the left switch pressed and the motor stopped",
        || get(&s.url("/api/modules/0/world")).1["axes"][0].clone(),
        |a| a["left"] == true && a["speed"] == 0,
    );
    let (code, r) = post(&s.url("/api/modules/0/world"), json!({"line": "switch 0 sideways press"}));
    assert_eq!(code, 400, "{r}");
}

#[test]
fn the_live_socket_streams_positions_a_host_changes() {
    let s = Served::new();
    let url = format!("ws://{}/api/modules/0/live", s.web.addr());
    let (mut ws, _) = tungstenite::connect(url).unwrap();
    let sub = json!({"signals": [{"kind": "ap", "number": 1, "index": 0}, {"kind": "ap", "number": 3, "index": 0}], "rate": 50});
    ws.send(tungstenite::Message::Text(sub.to_string().into())).unwrap();
    let mut next = || -> Value {
        loop {
            if let tungstenite::Message::Text(t) = ws.read().unwrap() {
                return serde_json::from_str(&t).unwrap();
            }
        }
    };
    let first = next();
    assert_eq!(first["values"], json!([0, 0]));
    let mut host = s.host();
    assert_eq!(ask(&mut host, "MVP ABS, 0, 51200").status, 100);
    let (mut t, mut moved) = (first["t"].as_f64().unwrap(), false);
    for _ in 0..250 {
        let m = next();
        let now = m["t"].as_f64().unwrap();
        assert!(now >= t, "time runs forward");
        t = now;
        if m["values"][0].as_i64().unwrap() > 0 {
            moved = true;
            break;
        }
    }
    assert!(moved, "the position the host's MVP changes reaches the stream");
}

#[test]
fn every_sample_names_the_subscription_it_was_read_for() {
    let s = Served::new();
    let url = format!("ws://{}/api/modules/0/live", s.web.addr());
    let (mut ws, _) = tungstenite::connect(url).unwrap();
    let one = json!({"signals": [{"kind": "ap", "number": 4, "index": 0}], "rate": 100, "id": 7});
    ws.send(tungstenite::Message::Text(one.to_string().into())).unwrap();
    let two =
        json!({"signals": [{"kind": "ap", "number": 4, "index": 0}, {"kind": "ap", "number": 154, "index": 0}], "rate": 100, "id": 8});
    ws.send(tungstenite::Message::Text(two.to_string().into())).unwrap();
    // Samples of the first subscription may still come; each says which it
    // is and has that subscription's signals; then only the second's come.
    let mut seen_two = 0;
    for _ in 0..200 {
        let Ok(tungstenite::Message::Text(t)) = ws.read() else { continue };
        let m: Value = serde_json::from_str(&t).unwrap();
        let n = m["values"].as_array().unwrap().len();
        match m["sub"].as_u64() {
            Some(7) => assert_eq!((seen_two, n), (0, 1), "{m}"),
            Some(8) => {
                assert_eq!(m["values"], json!([1000, 3]), "AP 4 and AP 154 defaults");
                seen_two += 1;
                if seen_two == 3 {
                    return;
                }
            }
            other => panic!("sample without its subscription: {other:?} in {m}"),
        }
    }
    panic!("the second subscription's samples did not come");
}

#[test]
fn foreign_origins_and_hosts_are_refused() {
    let s = Served::new();
    let agent: ureq::Agent = ureq::Agent::config_builder().http_status_as_error(false).build().into();
    let r = agent.get(&s.url("/api/info")).header("Origin", "http://attacker.example").call();
    assert_eq!(common::answer(r).0, 403);
    let r = agent.get(&s.url("/api/info")).header("Host", "attacker.example").call();
    assert_eq!(common::answer(r).0, 403);
    let own = format!("http://{}", s.web.addr());
    let r = agent.get(&s.url("/api/info")).header("Origin", own.as_str()).call();
    assert_eq!(common::answer(r).0, 200);
}

#[test]
fn a_public_bind_needs_the_flag_and_then_the_token() {
    let s = Served::new();
    let target = std::sync::Arc::new(tmclsim_web::VirtualTarget::new(s.server.links()));
    let cfg = |public| tmclsim_web::WebConfig { addr: "0.0.0.0:0".parse().unwrap(), public, limits: Default::default() };
    let e = tmclsim_web::start(target.clone(), cfg(false)).err().unwrap();
    assert!(e.to_string().contains("--web-public"), "{e}");
    let web = tmclsim_web::start(target, cfg(true)).unwrap();
    let token = web.token().unwrap().to_string();
    let base = format!("http://127.0.0.1:{}", web.addr().port());
    assert_eq!(get(&format!("{base}/api/info")).0, 403);
    assert_eq!(get(&format!("{base}/api/info?token=wrong")).0, 403);
    assert_eq!(get(&format!("{base}/api/info?token={token}")).0, 200);
    assert!(web.url().ends_with(&format!("?token={token}")));
}

#[test]
fn a_live_stream_does_not_slip_into_a_download() {
    // In download mode a module stores every command as a program word: the
    // app's own reads must wait, or the program read back would differ.
    let s = Served::new();
    let url = format!("ws://{}/api/modules/0/live", s.web.addr());
    let (mut ws, _) = tungstenite::connect(url).unwrap();
    let sub = json!({"signals": [{"kind": "ap", "number": 1, "index": 0}], "rate": 100, "program": true});
    ws.send(tungstenite::Message::Text(sub.to_string().into())).unwrap();
    ws.read().unwrap();
    let source: String = "CALC ADD, 1\n".repeat(1000) + "STOP\n";
    let reader = {
        let url = s.url("/api/modules/0/read");
        std::thread::spawn(move || {
            let mut refused = 0;
            for _ in 0..200 {
                let (code, _) = post(&url, json!({"reads": [{"kind": "ap", "number": 1, "index": 0}]}));
                assert!(code == 200 || code == 409, "{code}");
                refused += usize::from(code == 409);
            }
            refused
        })
    };
    let lines = download(&s, &source);
    let last = lines.last().unwrap();
    assert_eq!((last["verified"].as_bool(), last["words"].as_u64()), (Some(true), Some(1001)), "{last}");
    reader.join().unwrap();
    // The stream goes on after the download.
    ws.read().unwrap();
    let (code, _) = post(&s.url("/api/modules/0/read"), json!({"reads": [{"kind": "ap", "number": 1, "index": 0}]}));
    assert_eq!(code, 200);
}

#[test]
fn a_module_in_its_bootloader_is_shown_as_such_and_its_tools_are_refused_with_the_reason() {
    let s = Served::new();
    // A host starts a firmware update: 242 with its key, no reply.
    let mut host = s.host();
    host.write_all(&tmclsim_protocol::Request::new(1, tmclsim_protocol::mnemonic::parse_line("BOOT").unwrap()).encode()).unwrap();
    until("the module list to say bootloader", || get(&s.url("/api/modules")).1[0].clone(), |m| m["bootloader"] == "1141B106");
    let (code, body) = post(&s.url("/api/modules/0/command"), json!({"line": "GAP 1, 0"}));
    assert_eq!(code, 409);
    assert!(body["error"].as_str().unwrap().contains("in its bootloader (1141B106)"), "{body}");
    let (code, _) = post(&s.url("/api/modules/0/read"), json!({"reads": [{"kind": "ap", "number": 1, "index": 0}]}));
    assert_eq!(code, 409);
    // BOOT_START_APPL with the firmware untouched: the tools are back.
    host.write_all(&tmclsim_protocol::Request::new(1, tmclsim_protocol::Instruction::new(205, 0, 0, 0)).encode()).unwrap();
    until("the module list to say firmware", || get(&s.url("/api/modules")).1[0].clone(), |m| m["bootloader"].is_null());
    assert_eq!(post(&s.url("/api/modules/0/command"), json!({"line": "GAP 1, 0"})).0, 200);
}
