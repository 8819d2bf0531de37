//! `tmclsim serve --web` and `tmclsim ide`: the browser IDE beside served
//! modules and against modules on a TMCL link, as processes.

use crate::common;

use common::{Server, get, post, text, tmclsim};

#[test]
fn serve_web_prints_the_url_and_lists_the_module() {
    let server = Server::start(&["--tcp", "127.0.0.1:0", "--web", "127.0.0.1:0"]);
    let url = server.printed("web");
    assert!(url.starts_with("http://127.0.0.1:"), "{url}");
    let (status, body) = get(&url, "/api/modules");
    assert!(status.contains("200"), "{status}");
    assert!(body.contains("\"profile\":\"TMCM-1141\"") && body.contains("\"virtual\":true"), "{body}");
    let (status, page) = get(&url, "/");
    assert!(status.contains("200") && page.to_ascii_lowercase().contains("<html"), "{status}");
    server.check();
}

#[test]
fn a_bus_lists_every_module() {
    let server = Server::start(&["--bus", "tmcm-1141@1,tmcm-351@2", "--tcp", "127.0.0.1:0", "--web", "127.0.0.1:0"]);
    let (_, body) = get(&server.printed("web"), "/api/modules");
    assert!(body.contains("TMCM-1141") && body.contains("TMCM-351") && body.contains("\"address\":2"), "{body}");
}

#[test]
fn a_public_web_address_needs_the_flag() {
    let out = tmclsim(&["serve", "--tcp", "127.0.0.1:0", "--web", "0.0.0.0:0"]);
    assert!(!out.status.success());
    assert!(text(&out).contains("--web-public"), "{}", text(&out));
}

#[test]
fn ide_reaches_a_served_module_over_tcp() {
    let server = Server::start(&["--tcp", "127.0.0.1:0"]);
    let ide = Server::ide(&["--tcp", &server.tcp()]);
    assert!(ide.banner.iter().any(|l| l.contains("1141V146 at address 1")), "{:?}", ide.banner);
    let (_, body) = get(&ide.printed("open"), "/api/modules");
    assert!(body.contains("\"virtual\":false") && body.contains("TMCM-1141"), "{body}");
}

#[test]
fn ide_names_the_link_it_cannot_open() {
    let out = tmclsim(&["ide", "--tcp", "127.0.0.1:1", "--web", "127.0.0.1:0"]);
    assert!(!out.status.success());
    assert!(text(&out).contains("cannot connect to 127.0.0.1:1"), "{}", text(&out));
}

#[test]
fn ethercat_slaves_are_not_served_to_the_ide() {
    let out = tmclsim(&["serve", "--module", "tmcm-1310", "--ethercat", "lo", "--web"]);
    assert!(!out.status.success());
    assert!(text(&out).contains("--web cannot serve EtherCAT slaves"), "{}", text(&out));
}

#[test]
fn log_frames_shows_the_apps_commands_on_the_link_web() {
    let server = Server::start(&["--tcp", "127.0.0.1:0", "--web", "127.0.0.1:0", "--log-frames"]);
    let url = server.printed("web");
    let (status, body) = post(&url, "/api/modules/0/command", r#"{"line":"SAP 4, 0, 1234"}"#);
    assert!(status.contains("200") && body.contains("\"status\":100"), "{status} {body}");
    let line = server.logged(&[" web ← "]).expect("the app's reply logged");
    assert!(line.ends_with("from 1: status 100 (ok), value 1234"), "{line}");
    let log = server.log.lock().unwrap().join("\n");
    assert!(log.contains(" s web → 01 05 04 00 00 00 04 D2 E0  to 1: SAP 4, 0, 1234"), "{log}");
    // The app's polled reads (charts, grid) are not logged; the next
    // command is, right after the first.
    let (status, body) = post(&url, "/api/modules/0/read", r#"{"reads":[{"kind":"ap","number":4}]}"#);
    assert!(status.contains("200") && body.contains("1234"), "{status} {body}");
    post(&url, "/api/modules/0/command", r#"{"line":"GAP 4, 0"}"#);
    server.logged(&[" web ← 02 01 64 06 "]).expect("the reply to GAP logged");
    let log = server.log.lock().unwrap().join("\n");
    let web: Vec<&str> = log.lines().filter(|l| l.contains(" s web ")).collect();
    assert_eq!(web.len(), 4, "{log}");
    assert!(web[2].ends_with("to 1: GAP 4, 0"), "{}", web[2]);
}

#[test]
fn ide_leaves_out_an_address_that_does_not_answer_and_a_scan_finds_every_module() {
    let server = Server::start(&["--bus", "tmcm-1141@1,tmcm-351@7", "--tcp", "127.0.0.1:0"]);
    let a = Server::ide(&["--tcp", &server.tcp(), "--bus-addresses", "1,2,5"]);
    let url = a.printed("open");
    assert!(a.banner.iter().any(|l| l.contains("1141V146 at address 1")), "{:?}", a.banner);
    let (_, body) = get(&url, "/api/modules");
    assert!(body.contains("\"address\":1") && !body.contains("\"address\":5"), "{body}");
    // The scan: every address in under 2 s, both modules with their
    // firmware and profile.
    let t = std::time::Instant::now();
    let (_, body) = post(&url, "/api/scan", "{}");
    let took = t.elapsed();
    assert!(took.as_secs_f64() < 2.0, "the scan took {took:?}");
    let one = r#"{"address":1,"firmware":"1141V146","listed":true,"profile":"TMCM-1141"}"#;
    let seven = r#"{"address":7,"firmware":"351V.445","listed":false,"profile":"TMCM-351"}"#;
    assert_eq!(body, format!(r#"{{"modules":[{one},{seven}]}}"#));
    // The link still answers in step afterwards.
    let (_, body) = post(&url, "/api/modules/0/command", r#"{"line": "GAP 1, 0"}"#);
    assert!(body.contains("\"status\":100"), "{body}");
    drop(a);
    // ide --scan lists what answers.
    let b = Server::ide(&["--tcp", &server.tcp(), "--scan"]);
    assert!(b.banner.iter().any(|l| l.contains("1141V146 at address 1") && l.contains("351V.445 at address 7")), "{:?}", b.banner);
    let (_, body) = get(&b.printed("open"), "/api/modules");
    assert!(body.contains("TMCM-351"), "{body}");
}

#[test]
fn a_virtual_target_has_no_scan() {
    let server = Server::start(&["--tcp", "127.0.0.1:0", "--web", "127.0.0.1:0"]);
    let (status, body) = post(&server.printed("web"), "/api/scan", "{}");
    assert!(status.contains("409") && body.contains("module list"), "{status} {body}");
}
