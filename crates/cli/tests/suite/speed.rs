//! `tmclsim serve --speed N`: the served modules' virtual time runs N times
//! as fast as the wall clock, and bad values are refused.

use crate::common;

use common::{Server, ask, text, tmclsim};
use std::time::{Duration, Instant};

/// GP 132 (the tick timer, virtual ms) of a served module.
fn ticks(s: &mut std::net::TcpStream) -> i64 {
    i64::from(ask(s, "GGP 132, 0").expect("a reply").value)
}

#[test]
fn virtual_time_runs_n_times_as_fast() {
    let server = Server::start(&["--speed", "50", "--world", "free"]);
    assert_eq!(server.printed("time"), "50", "the banner says the speed");
    let mut s = server.connect();
    // The module's own clock against the wall clock, over at least 40
    // virtual seconds; the wall time measured around the two reads is at
    // least the true interval, so the ratio is at most 50.
    let (v0, w0) = (ticks(&mut s), Instant::now());
    let deadline = w0 + Duration::from_secs(60);
    let mut v1 = v0;
    while v1 - v0 < 40_000 && Instant::now() < deadline {
        v1 = ticks(&mut s);
    }
    let wall = w0.elapsed().as_secs_f64();
    let ratio = (v1 - v0) as f64 / 1000.0 / wall;
    assert!((40.0..=50.5).contains(&ratio), "{} virtual ms in {wall} s: ratio {ratio}", v1 - v0);
    // A move follows it: 51200 µsteps at the factory speed and acceleration
    // of the TMCM-1141 take about 1.3 virtual seconds.
    assert_eq!(ask(&mut s, "MVP ABS, 0, 51200").unwrap().status, 100);
    let start = (ticks(&mut s), Instant::now());
    while ask(&mut s, "GAP 8, 0").unwrap().value == 0 && start.1.elapsed() < Duration::from_secs(60) {}
    let virtual_ms = ticks(&mut s) - start.0;
    assert!(virtual_ms >= 1000, "the move took {virtual_ms} virtual ms");
    assert!(start.1.elapsed() < Duration::from_millis(virtual_ms as u64), "faster than the wall clock");
    server.stop();
}

#[test]
fn a_speed_must_be_a_positive_number() {
    for bad in ["0", "-2", "fast", "inf", "NaN"] {
        let o = tmclsim(&["serve", &format!("--speed={bad}"), "--tcp", "127.0.0.1:0"]);
        assert!(!o.status.success(), "--speed {bad} was taken");
        let t = text(&o);
        assert!(t.contains("--speed") && t.contains("positive") || t.contains("not a number"), "{bad}: {t}");
    }
}

#[test]
fn a_fleet_file_gives_the_speed_of_its_links() {
    let dir = tempfile::tempdir().unwrap();
    let fleet = dir.path().join("fleet.toml");
    std::fs::write(&fleet, "speed = 0\n[[link]]\ntcp = \"127.0.0.1:0\"\nmodules = [\"tmcm-1141@1\"]\n").unwrap();
    let o = tmclsim(&["serve", "--fleet", fleet.to_str().unwrap()]);
    assert!(!o.status.success());
    assert!(text(&o).contains("link 1: speed 0 is not a positive finite number"), "{}", text(&o));
    std::fs::write(&fleet, "speed = 20\n[[link]]\ntcp = \"127.0.0.1:0\"\nmodules = [\"tmcm-1141@1\"]\n").unwrap();
    let server = Server::start(&["--fleet", fleet.to_str().unwrap()]);
    // The fleet's banner names its first link in the connect hint.
    let hint = server.banner.iter().find(|l| l.starts_with("connect with:")).unwrap();
    let port = hint.split("--port ").nth(1).unwrap().trim_end_matches(|c: char| !c.is_ascii_digit());
    let mut s = std::net::TcpStream::connect(port).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
    let (v0, w0) = (ticks(&mut s), Instant::now());
    let mut v1 = v0;
    while v1 - v0 < 10_000 && w0.elapsed() < Duration::from_secs(60) {
        v1 = ticks(&mut s);
    }
    let ratio = (v1 - v0) as f64 / 1000.0 / w0.elapsed().as_secs_f64();
    assert!((15.0..=20.5).contains(&ratio), "ratio {ratio}");
    server.stop();
}

#[test]
fn the_ide_says_the_speed() {
    let server = Server::start(&["--speed", "50", "--tcp", "127.0.0.1:0", "--web", "127.0.0.1:0"]);
    let (_, body) = common::get(&server.printed("web"), "/api/info");
    assert!(body.contains("\"speed\":50.0"), "{body}");
    assert!(body.contains("\"behind\":false"), "an idle module keeps up: {body}");
    server.stop();
}

/// Uploads `source` to the module at `address` of a served link and starts
/// it (`tmclsim upload --run`).
fn upload_and_run(tcp: &str, address: u8, source: &std::path::Path) {
    let o = tmclsim(&["upload", "--tcp", tcp, "--address", &address.to_string(), "--run", source.to_str().unwrap()]);
    assert!(o.status.success(), "upload to {address}: {}", text(&o));
}

/// Round trips of GAP 1 to `address`: the slowest, failing when one takes
/// longer than `limit` (a generous deadline: the module computes behind,
/// requests wait at most one slice of it).
fn slowest_reply(s: &mut std::net::TcpStream, address: u8, n: usize, limit: Duration) -> Duration {
    s.set_read_timeout(Some(limit)).unwrap();
    let mut slowest = Duration::ZERO;
    for _ in 0..n {
        let mut f = common::frame("GAP 1, 0");
        f[0] = address;
        f[8] = f[..8].iter().fold(0u8, |a, b| a.wrapping_add(*b));
        let t = Instant::now();
        std::io::Write::write_all(s, &f).unwrap();
        let mut buf = [0u8; 9];
        std::io::Read::read_exact(s, &mut buf).unwrap_or_else(|e| panic!("no reply from {address} within {limit:?}: {e}"));
        slowest = slowest.max(t.elapsed());
    }
    slowest
}

#[test]
#[cfg_attr(windows, ignore = "a clean stop needs Ctrl-C in the child, which Wine does not deliver to another process")]
fn a_tight_loop_at_speed_100000_falls_behind_and_stays_responsive() {
    // docs/behaviour.md rule 119: the modules cannot compute 100 000
    // virtual seconds of `CALC ADD / JA` a wall second; virtual time falls
    // behind, replies keep their latency, the server stops on SIGTERM.
    let dir = tempfile::tempdir().unwrap();
    let source = dir.path().join("tight.tmc");
    std::fs::write(&source, "Loop:\n  CALC ADD, 1\n  JA Loop\n").unwrap();
    let mut server = Server::start(&["--tcp", "127.0.0.1:0", "--speed", "100000", "--world", "free", "--web", "127.0.0.1:0"]);
    upload_and_run(&server.tcp(), 1, &source);
    let mut s = server.connect();
    let slowest = slowest_reply(&mut s, 1, 50, Duration::from_secs(5));
    assert!(server.logged(&["virtual time falls behind --speed 100000"]).is_some(), "{:?}", server.log.lock().unwrap());
    let (_, body) = common::get(&server.printed("web"), "/api/info");
    assert!(body.contains("\"behind\":true"), "the IDE says so: {body}");
    assert_eq!(ask(&mut s, "GGP 128, 0").map(|r| r.value), Some(1), "the program runs on");
    common::interrupt(&mut server.child);
    assert!(server.exit_code_within(Duration::from_secs(10)).is_some(), "SIGTERM did not stop the server within 10 s");
    let log = server.whole_log();
    assert_eq!(log.iter().filter(|l| l.contains("falls behind")).count(), 1, "said once: {log:?}");
    eprintln!("slowest GAP round trip at speed 100000 with a tight loop: {slowest:?}");
}

#[test]
#[cfg_attr(windows, ignore = "a clean stop needs Ctrl-C in the child, which Wine does not deliver to another process")]
fn a_bus_of_eight_at_speed_500_with_timer_interrupts_stays_responsive() {
    let dir = tempfile::tempdir().unwrap();
    let source = dir.path().join("timer.tmc");
    // A 1 ms timer interrupt counting in user variable 0, the main loop
    // waiting in WAIT TICKS.
    std::fs::write(
        &source,
        "  VECT 0, Tick\n  SGP 0, 3, 1\n  EI 0\n  EI 255\nLoop:\n  WAIT TICKS, 0, 10\n  JA Loop\nTick:\n  GGP 0, 2\n  CALC ADD, 1\n  AGP 0, 2\n  RETI\n",
    )
    .unwrap();
    let bus = (1..=8).map(|a| format!("tmcm-1141@{a}")).collect::<Vec<_>>().join(",");
    let mut server = Server::start(&["--tcp", "127.0.0.1:0", "--speed", "500", "--world", "free", "--bus", &bus]);
    for address in 1..=8u8 {
        upload_and_run(&server.tcp(), address, &source);
    }
    let mut s = server.connect();
    let mut slowest = Duration::ZERO;
    for address in 1..=8u8 {
        slowest = slowest.max(slowest_reply(&mut s, address, 10, Duration::from_secs(5)));
    }
    common::interrupt(&mut server.child);
    assert!(server.exit_code_within(Duration::from_secs(10)).is_some(), "SIGTERM did not stop the server within 10 s");
    eprintln!("slowest GAP round trip on a bus of eight at speed 500 with 1 ms timers: {slowest:?}");
}
