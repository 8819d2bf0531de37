//! `tmclsim trace`: sessions recorded through the proxy against a served
//! module (over TCP and over the pty), checked on a fresh virtual module;
//! an altered reply is exactly one difference; bad trace files are refused
//! with their line.

use crate::common;

use common::{Server, frame, http_post_with_frames, send_and_read_to_close, text, tmclsim};
use std::io::{Read, Write};
use std::net::TcpStream;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// `tmclsim trace record --listen 127.0.0.1:0 LINK… --out OUT`, once it
/// listens.
fn recorder(link: &[&str], out: &Path) -> Server {
    let mut c = Command::new(env!("CARGO_BIN_EXE_tmclsim"));
    c.args(["trace", "record", "--listen", "127.0.0.1:0", "--timeout", "200", "--out", out.to_str().unwrap()]).args(link);
    c.stdout(Stdio::piped()).stderr(Stdio::piped());
    Server::spawn(c)
}

/// Ends a recording as Ctrl-C would; its exit code.
fn stop(mut rec: Server) -> Option<i32> {
    common::interrupt(&mut rec.child);
    rec.exit_code_within(Duration::from_secs(10))
}

fn is_event(f: &[u8; 9]) -> bool {
    f[2] == 128 && f[3] == 138
}

/// A host on the proxy: sends frames, reads replies, counts the 138
/// events that come between them.
struct Host {
    s: TcpStream,
    events: usize,
}

impl Host {
    fn connect(addr: &str) -> Host {
        let s = TcpStream::connect(addr).unwrap();
        s.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
        Host { s, events: 0 }
    }

    fn read(&mut self) -> [u8; 9] {
        let mut f = [0u8; 9];
        self.s.read_exact(&mut f).unwrap();
        f
    }

    fn raw(&mut self, request: [u8; 9]) -> [u8; 9] {
        self.s.write_all(&request).unwrap();
        loop {
            let f = self.read();
            if is_event(&f) {
                self.events += 1;
            } else {
                return f;
            }
        }
    }

    fn value(&mut self, line: &str) -> i32 {
        let r = self.raw(frame(line));
        assert_eq!(r[2], 100, "{line}: {r:?}");
        i32::from_be_bytes(r[4..8].try_into().unwrap())
    }
}

fn check(trace: &Path, more: &[&str]) -> (Option<i32>, String) {
    let o = tmclsim(&[&["trace", "check", trace.to_str().unwrap()][..], more].concat());
    (o.status.code(), text(&o))
}

/// The trace's lines.
fn lines(trace: &Path) -> Vec<String> {
    std::fs::read_to_string(trace).unwrap().lines().map(str::to_string).collect()
}

/// Replaces the value of the reply on line `n` (1-based), checksum and all.
fn alter_value(trace: &Path, n: usize, value: i32, out: &Path) {
    let mut all = lines(trace);
    let line = &all[n - 1];
    let at = line.find("\"frame\": \"").unwrap() + 10;
    let mut f: Vec<u8> = line[at..at + 26].split(' ').map(|b| u8::from_str_radix(b, 16).unwrap()).collect();
    f[4..8].copy_from_slice(&value.to_be_bytes());
    f[8] = f[..8].iter().fold(0u8, |s, b| s.wrapping_add(*b));
    let hex: Vec<String> = f.iter().map(|b| format!("{b:02X}")).collect();
    all[n - 1] = format!("{}{}{}", &line[..at], hex.join(" "), &line[at + 26..]);
    std::fs::write(out, all.join("\n") + "\n").unwrap();
}

/// The line number of the reply that follows the request `request`.
fn reply_line(trace: &Path, request: [u8; 9]) -> usize {
    let hex: Vec<String> = request.iter().map(|b| format!("{b:02X}")).collect();
    let all = lines(trace);
    let i = all.iter().position(|l| l.contains(&hex.join(" "))).unwrap_or_else(|| panic!("no request {hex:?}"));
    assert!(all[i + 1].contains("\"module\""), "{}", all[i + 1]);
    i + 2
}

#[test]
#[cfg_attr(windows, ignore = "a clean stop needs Ctrl-C in the child, which Wine does not deliver to another process")]
fn a_session_over_tcp_checks_clean_and_an_altered_reply_is_one_difference() {
    let dir = tempfile::tempdir().unwrap();
    let trace = dir.path().join("session.jsonl");
    let server = Server::start(&["--tcp", "127.0.0.1:0"]);
    let rec = recorder(&["--tcp", &server.tcp()], &trace);
    let mut host = Host::connect(&rec.printed("listen"));
    assert_eq!(host.value("SAP 4, 0, 2047"), 2047);
    assert_eq!(host.value("SAP 5, 0, 1000"), 1000);
    assert_eq!(host.value("GAP 4, 0"), 2047);
    host.value("#138 0 0 1"); // a 138 event when motor 0 arrives
    host.value("MVP ABS, 0, 30000");
    let start = Instant::now();
    let mut seen = Vec::new();
    while host.value("GAP 8, 0") == 0 {
        seen.push(host.value("GAP 1, 0"));
        host.value("GAP 3, 0");
        assert!(start.elapsed() < Duration::from_secs(10), "the motor never arrived");
        std::thread::sleep(Duration::from_millis(5));
    }
    assert!(seen.iter().any(|p| *p > 0 && *p < 30000), "no position read while moving: {seen:?}");
    assert_eq!(host.value("GAP 1, 0"), 30000);
    if host.events == 0 {
        assert!(is_event(&host.read()), "the 138 event");
    }
    assert_eq!(&host.raw(frame("#136 0 0 0"))[1..], b"1141V146");
    host.value("GGP 132, 0"); // the tick timer: not comparable
    // Nobody at address 5: no reply, and nothing recorded for the module.
    let mut nobody = frame("GAP 1, 0");
    nobody[0] = 5;
    nobody[8] = nobody[..8].iter().fold(0u8, |s, b| s.wrapping_add(*b));
    host.s.write_all(&nobody).unwrap();
    assert!(rec.logged(&["no reply to 05 06 01 00"]).is_some(), "{:?}", rec.log.lock().unwrap());
    // A wrong checksum: status 1.
    let mut bad = frame("GAP 1, 0");
    bad[8] ^= 0x55;
    assert_eq!(host.raw(bad)[2], 1);
    drop(host);
    assert_eq!(stop(rec), Some(0));
    let all = lines(&trace);
    assert!(all.iter().any(|l| l.contains("\"module\"") && l.contains(" 80 8A ")), "the event is recorded");
    let i = all.iter().position(|l| l.contains("05 06 01 00")).unwrap();
    assert!(all[i + 1].contains("\"host\""), "no reply recorded after the request to address 5: {}", all[i + 1]);

    // The module served here shares a test machine that may be busy: its
    // 138 event can leave tens of milliseconds late, which a module's own
    // firmware would not do. The window is widened to 100 ms for that.
    let patient = ["--time-tolerance", "100"];
    let (code, out) = check(&trace, &[&["--module", "tmcm-1141"][..], &patient].concat());
    assert_eq!(code, Some(0), "{out}");
    assert!(out.contains("result: 0 differences, 1 not comparable"), "{out}");
    assert!(out.contains("GGP 132 (TMCL tick timer), bank 0: 1 reply; tick timer"), "{out}");
    assert!(out.contains("and 1 event replayed on a virtual TMCM-1141"), "{out}");
    // The session's own 136 reply tells its module: checked as another,
    // the report says so first; `--module auto` takes it.
    let (code, out) = check(&trace, &[&["--module", "tmcm-6110"][..], &patient].concat());
    assert_eq!(code, Some(1), "{out}");
    let version_line = reply_line(&trace, frame("#136 0 0 0"));
    assert_eq!(
        out.lines().next(),
        Some(
            format!(
                "this trace is from a TMCM-1141 (136: 1141V146 on line {version_line}); checked as tmcm-6110: give --module tmcm-1141 (or --module auto)"
            )
            .as_str()
        ),
        "{out}"
    );
    assert!(out.contains("get firmware version (136), type 0: 1 difference\n"), "{out}");
    assert!(out.contains(": get firmware version (136), type 0\n"), "control commands by name: {out}");
    let (code, out) = check(&trace, &[&["--module", "auto"][..], &patient].concat());
    assert_eq!(code, Some(0), "{out}");
    assert_eq!(
        out.lines().next(),
        Some(format!("module: tmcm-1141, from the trace's 136: 1141V146 on line {version_line}").as_str()),
        "{out}"
    );
    assert!(out.contains("result: 0 differences, 1 not comparable"), "{out}");

    // One reply altered: exactly that difference, at its line.
    let altered = dir.path().join("altered.jsonl");
    let n = reply_line(&trace, frame("GAP 4, 0"));
    alter_value(&trace, n, 2000, &altered);
    let (code, out) = check(&altered, &patient);
    assert_eq!(code, Some(1), "{out}");
    assert!(out.contains("result: 1 difference, 1 not comparable"), "{out}");
    assert!(out.contains("GAP 4 (Maximum positioning speed), motor 0: 1 difference\n"), "{out}");
    assert!(out.contains(&format!("  line {n} (request on line {} at ", n - 1)), "{out}");
    assert!(out.contains("expected  02 01 64 06 00 00 07 D0 "), "{out}");
    assert!(out.contains("status 100 (ok), value 2000\n    actual    02 01 64 06 00 00 07 FF "), "{out}");

    // The event taken out: the virtual module's event is the difference.
    let no_event = dir.path().join("no-event.jsonl");
    let kept: Vec<String> = lines(&trace).into_iter().filter(|l| !l.contains(" 80 8A ")).collect();
    std::fs::write(&no_event, kept.join("\n") + "\n").unwrap();
    let (code, out) = check(&no_event, &[]);
    assert_eq!(code, Some(1), "{out}");
    assert!(out.contains("138 events (target position reached): 1 difference"), "{out}");
    assert!(out.contains("the virtual module sent this event; the recorded module did not"), "{out}");
    assert!(out.contains("result: 1 difference,"), "{out}");
    server.stop();
}

#[test]
#[cfg_attr(windows, ignore = "a pty is a Unix device: Windows refuses --pty")]
fn a_session_over_the_pty_with_another_address() {
    let dir = tempfile::tempdir().unwrap();
    let pty = dir.path().join("pty");
    let trace = dir.path().join("pty.jsonl");
    let server = Server::start(&["--pty", pty.to_str().unwrap(), "--address", "3"]);
    let rec = recorder(&["--port", pty.to_str().unwrap()], &trace);
    let mut host = Host::connect(&rec.printed("listen"));
    let at3 = |line: &str| {
        let mut f = frame(line);
        f[0] = 3;
        f[8] = f[..8].iter().fold(0u8, |s, b| s.wrapping_add(*b));
        f
    };
    assert_eq!(host.raw(at3("SAP 6, 0, 100"))[2], 100);
    assert_eq!(host.raw(at3("GAP 6, 0"))[7], 100);
    assert_eq!(host.raw(at3("GGP 66, 0"))[7], 3);
    assert_eq!(&host.raw(at3("#136 0 0 0"))[1..], b"1141V146");
    drop(host);
    assert_eq!(stop(rec), Some(0));
    assert_eq!(lines(&trace).len(), 8);
    // The virtual module answers to 1 unless told.
    let (code, out) = check(&trace, &[]);
    assert_eq!(code, Some(1), "{out}");
    assert!(out.contains("note: the trace's first request goes to address 3; the virtual module answers to 1: give --address 3"), "{out}");
    let (code, out) = check(&trace, &["--address", "3"]);
    assert_eq!(code, Some(0), "{out}");
    assert!(out.contains("result: 0 differences, 0 not comparable, 4 match"), "{out}");
    server.stop();
}

#[test]
fn one_host_at_a_time_and_the_end_of_the_module_link() {
    let dir = tempfile::tempdir().unwrap();
    let trace = dir.path().join("t.jsonl");
    let server = Server::start(&["--tcp", "127.0.0.1:0"]);
    let rec = recorder(&["--tcp", &server.tcp()], &trace);
    let listen = rec.printed("listen");
    let mut first = Host::connect(&listen);
    assert_eq!(first.value("GAP 4, 0"), first.value("GAP 4, 0"));
    // A second host is refused once it has said it speaks TMCL; its frame
    // goes nowhere.
    let mut second = TcpStream::connect(&listen).unwrap();
    second.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
    second.write_all(&frame("SAP 4, 0, 7")).unwrap();
    assert_eq!(second.read(&mut [0u8; 9]).unwrap_or(0), 0, "the second host is closed");
    assert!(rec.logged(&["refusing connection from", ": 1 connection open (the limit)"]).is_some(), "{:?}", rec.log.lock().unwrap());
    first.value("GAP 4, 0");
    drop(first);
    // The next host is served.
    assert!(rec.logged(&["disconnected"]).is_some());
    let mut next = Host::connect(&listen);
    next.value("GAP 4, 0");
    // The module's link goes away: the recording ends, with what it has.
    server.stop();
    let mut rec = rec;
    assert_eq!(rec.exit_code_within(Duration::from_secs(10)), Some(2));
    assert!(rec.logged(&["the link to the module closed; 8 frame(s) in"]).is_some(), "{:?}", rec.log.lock().unwrap());
    assert!(!lines(&trace).iter().any(|l| l.contains("01 05 04 00 00 00 00 07")), "the refused host's frame is not recorded");
}

#[test]
fn the_proxy_port_has_the_defences_of_a_tmcl_port() {
    let dir = tempfile::tempdir().unwrap();
    let trace = dir.path().join("t.jsonl");
    let server = Server::start(&["--tcp", "127.0.0.1:0"]);
    let mut rec = recorder(&["--tcp", &server.tcp(), "--bad-frame-limit", "3", "--idle-timeout", "1"], &trace);
    let listen = rec.printed("listen");
    let seen = rec.log.clone();
    let log = move || format!("{:?}", seen.lock().unwrap());

    // What a web page sends: an HTTP request whose body holds frames in
    // step, and a TLS client hello. Closed before anything is forwarded,
    // in the TMCL port's words.
    let body: Vec<u8> = (0..20).flat_map(|_| frame("ROR 0, 500")).collect();
    assert!(send_and_read_to_close(&listen, &http_post_with_frames(&listen, &body)).is_empty());
    assert!(
        rec.logged(&["closing connection tcp 127.0.0.1:", "it opened with an HTTP request, not TMCL; nothing was executed"]).is_some(),
        "{}",
        log()
    );
    let hello = [[0x16, 0x03, 0x01, 0x00, 0xC8, 0x01, 0x00, 0x00, 0xC4].as_slice(), &body].concat();
    assert!(send_and_read_to_close(&listen, &hello).is_empty());
    assert!(rec.logged(&["it opened with a TLS client hello, not TMCL"]).is_some(), "{}", log());
    let mut s = server.connect();
    assert_eq!(common::ask(&mut s, "GAP 2, 0").unwrap().value, 0, "the motor was not started");

    // Frames with a wrong checksum, three in a row: answered (status 1),
    // then the connection is closed.
    let mut bad = Host::connect(&listen);
    let mut wrong = frame("GAP 1, 0");
    wrong[8] ^= 0x55;
    for _ in 0..3 {
        assert_eq!(bad.raw(wrong)[2], 1);
    }
    assert_eq!(bad.s.read(&mut [0u8; 9]).unwrap_or(0), 0, "closed after three bad frames");
    assert!(rec.logged(&["closing connection tcp 127.0.0.1:", ": 3 frames in a row with a wrong checksum"]).is_some(), "{}", log());
    assert!(rec.logged(&["disconnected"]).is_some(), "{}", log());

    // One host at a time; one that has sent no frame for the idle timeout
    // gives its place to a new one.
    let mut first = Host::connect(&listen);
    assert_eq!(first.value("GAP 4, 0"), 1000);
    // About time: longer than the 1 s idle timeout.
    std::thread::sleep(Duration::from_millis(1300));
    let mut next = Host::connect(&listen);
    assert_eq!(next.value("GGP 66, 0"), 1);
    assert!(rec.logged(&["closing connection from 127.0.0.1:", "no request for 1 s and its only slot is wanted"]).is_some(), "{}", log());
    assert_eq!(first.s.read(&mut [0u8; 9]).unwrap_or(0), 0, "the idle host was closed");
    drop(next);

    // None of it ended the recording, and nothing of the refused
    // connections is in the trace (each line is written and flushed before
    // its frame goes on, so the last reply is in it).
    assert!(rec.child.try_wait().unwrap().is_none(), "the recording goes on: {}", log());
    let all = lines(&trace);
    assert_eq!(all.len(), 10, "3 bad frames, 2 requests, their 5 replies: {all:#?}");
    assert!(!all.iter().any(|l| l.contains("01 01 00 00 00 00 01 F4")), "no frame of the page's body: {all:#?}");
    drop(rec);
    server.stop();
}

#[test]
#[cfg_attr(windows, ignore = "a clean stop needs Ctrl-C in the child, which Wine does not deliver to another process")]
fn a_proxy_on_a_public_address_is_warned_about() {
    let dir = tempfile::tempdir().unwrap();
    let server = Server::start(&["--tcp", "127.0.0.1:0"]);
    let mut c = Command::new(env!("CARGO_BIN_EXE_tmclsim"));
    c.args(["trace", "record", "--listen", "0.0.0.0:0", "--tcp", &server.tcp(), "--out"]).arg(dir.path().join("t.jsonl"));
    c.stdout(Stdio::piped()).stderr(Stdio::piped());
    let rec = Server::spawn(c);
    assert!(rec.logged(&["warning: TMCL on 0.0.0.0:", "is open to other machines"]).is_some());
    assert_eq!(stop(rec), Some(0));
}

#[test]
fn bad_trace_files_are_refused_with_their_line() {
    let dir = tempfile::tempdir().unwrap();
    let good = r#"{"t": 0.1, "dir": "host", "frame": "01 06 01 00 00 00 00 00 08"}"#;
    let cases = [
        ("not-json", "hello\n".to_string(), ":1:1: not a JSON object: expected value\n"),
        // The column in the file's line (indent included), not the parser's "line 1".
        ("column", "  {\"t\": 0.1, \"dir\": host}\n".to_string(), ":1:21: not a JSON object: expected value\n"),
        ("short", format!("{good}\n{}\n", good.replace(" 08\"", "\"")), ":2: \"frame\" has 8 bytes; a TMCL frame has 9"),
        ("dir", good.replace("host", "hots"), ":1: \"dir\" is \"hots\"; write \"host\" or \"module\""),
        ("back", format!("{good}\n{}\n", good.replace("0.1", "0.05")), ":2: \"t\" goes back in time (0.050000 after 0.100000)"),
        ("long", format!("{good}\n\n{}\n", " ".repeat(5000)), ":3: line longer than 4096 bytes"),
        ("empty", String::new(), ": holds no frames"),
    ];
    for (name, content, expected) in cases {
        let path = dir.path().join(name);
        std::fs::write(&path, content).unwrap();
        let o = tmclsim(&["trace", "check", path.to_str().unwrap()]);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{name}: {stderr}");
        assert!(stderr.contains(&format!("{}{expected}", path.display())), "{name}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{name}: one line: {stderr}");
    }
    let o = tmclsim(&["trace", "check", "/dev/zero"]);
    assert_eq!(o.status.code(), Some(2));
    let o = tmclsim(&["trace", "check", dir.path().join("missing").to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    let path = dir.path().join("ok");
    std::fs::write(&path, good).unwrap();
    let o = tmclsim(&["trace", "check", path.to_str().unwrap(), "--module", "tmcm-9999"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
}

/// A trace file of (seconds, direction, frame) lines.
fn write_trace(path: &Path, frames: &[(f64, &str, [u8; 9])]) {
    let text: String = frames
        .iter()
        .map(|(t, dir, f)| {
            let hex: Vec<String> = f.iter().map(|b| format!("{b:02X}")).collect();
            format!("{{\"t\": {t}, \"dir\": \"{dir}\", \"frame\": \"{}\"}}\n", hex.join(" "))
        })
        .collect();
    std::fs::write(path, text).unwrap();
}

/// A module's reply to the host (address 2 from module 1).
fn reply(status: u8, op: u8, value: i32) -> [u8; 9] {
    let mut f = [2, 1, status, op, 0, 0, 0, 0, 0];
    f[4..8].copy_from_slice(&value.to_be_bytes());
    f[8] = f[..8].iter().fold(0u8, |s, b| s.wrapping_add(*b));
    f
}

#[test]
fn a_trace_without_136_from_another_module_is_told_by_what_it_touches() {
    let dir = tempfile::tempdir().unwrap();
    let trace = dir.path().join("three-axes.jsonl");
    // Motor 2 answered with status 100: no TMCM-1141 (one motor) did that.
    write_trace(
        &trace,
        &[
            (0.001, "host", frame("GAP 4, 2")),
            (0.002, "module", reply(100, 6, 2047)),
            (0.003, "host", frame("GAP 4, 0")),
            (0.004, "module", reply(100, 6, 1000)),
        ],
    );
    let (code, out) = check(&trace, &[]);
    assert_eq!(code, Some(1), "{out}");
    let first = out.lines().next().unwrap_or_default();
    assert!(
        first.starts_with(
            "this trace is not from a TMCM-1141: its module accepted what a TMCM-1141 does not have (motor 2 on line 2); it fits "
        ),
        "{out}"
    );
    assert!(first.contains("tmcm-351") && !first.contains("tmcm-1141"), "{out}");
    // Without a 136 reply, `auto` has nothing to go by.
    let o = tmclsim(&["trace", "check", trace.to_str().unwrap(), "--module", "auto"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("--module auto: the trace holds no reply to 136"), "{}", text(&o));
    // A trace of the module it is checked as says nothing of the kind.
    let own = dir.path().join("own.jsonl");
    write_trace(&own, &[(0.001, "host", frame("GAP 4, 0")), (0.002, "module", reply(100, 6, 1000))]);
    let (code, out) = check(&own, &[]);
    assert_eq!(code, Some(0), "{out}");
    assert!(out.starts_with(&format!("{}: 1 request and 0 events replayed", own.display())), "{out}");
}

#[test]
fn not_comparable_readings_are_listed_only_when_they_differ() {
    let dir = tempfile::tempdir().unwrap();
    let trace = dir.path().join("inputs.jsonl");
    // The virtual module's analog input 0 reads 0 in the stage world: the
    // first reading is the same, the other two differ.
    write_trace(
        &trace,
        &[
            (0.001, "host", frame("GIO 0, 1")),
            (0.002, "module", reply(100, 15, 0)),
            (0.003, "host", frame("GIO 0, 1")),
            (0.004, "module", reply(100, 15, 256)),
            (0.005, "host", frame("GIO 0, 1")),
            (0.006, "module", reply(100, 15, 300)),
        ],
    );
    // The TMCM-1141's manual calls the pin IN0, the TMCM-1140's AIN0.
    for module in ["tmcm-1141", "tmcm-1140"] {
        let (code, out) = check(&trace, &["--module", module]);
        assert_eq!(code, Some(0), "{module}: {out}");
        // The same words for the same port on both modules, whatever their
        // manuals call the pin.
        assert!(out.contains("GIO 0, bank 1 (analog input 0): 2 replies; "), "{module}: {out}");
        assert!(!out.contains("line 2 "), "the identical reading is not listed: {out}");
        assert!(out.contains("  line 4 (request on line 3") && out.contains("  line 6 (request on line 5"), "{out}");
        assert!(out.contains("1 reply not comparable but the same on both modules (not listed)\n"), "{out}");
        assert!(out.contains("result: 0 differences, 3 not comparable (1 of them the same), 0 match"), "{out}");
    }
}

#[test]
#[cfg_attr(windows, ignore = "a clean stop needs Ctrl-C in the child, which Wine does not deliver to another process")]
fn a_sixpoint_session_checks_clean_on_the_module_its_136_names() {
    // A TMCM-1260 (the sixPoint ramp): the ramp written, a move polled to
    // its end, the version; checked with --module auto.
    let dir = tempfile::tempdir().unwrap();
    let trace = dir.path().join("sixpoint.jsonl");
    let server = Server::start(&["--module", "tmcm-1260", "--tcp", "127.0.0.1:0"]);
    let rec = recorder(&["--tcp", &server.tcp()], &trace);
    let mut host = Host::connect(&rec.printed("listen"));
    assert_eq!(&host.raw(frame("#136 0 0 0"))[1..], b"1260V144");
    for (n, v) in [(4, 40_000), (5, 30_000), (15, 5_000), (16, 10_000), (17, 20_000), (18, 5_000), (19, 5_000), (20, 5_000)] {
        assert_eq!(host.value(&format!("SAP {n}, 0, {v}")), v);
    }
    host.value("MVP ABS, 0, 20000");
    let start = Instant::now();
    while host.value("GAP 8, 0") == 0 {
        host.value("GAP 1, 0");
        assert!(start.elapsed() < Duration::from_secs(10), "the motor never arrived");
        // A poll's interval: the loop ends on arrival or at its deadline.
        std::thread::sleep(Duration::from_millis(20));
    }
    assert_eq!(host.value("GAP 1, 0"), 20_000);
    assert_eq!(host.value("GAP 16, 0"), 10_000);
    drop(host);
    assert_eq!(stop(rec), Some(0));
    let (code, out) = check(&trace, &["--module", "auto", "--time-tolerance", "100"]);
    assert_eq!(code, Some(0), "{out}");
    assert!(out.contains("result: 0 differences"), "{out}");
    assert!(out.contains("TMCM-1260"), "{out}");
    server.stop();
}
