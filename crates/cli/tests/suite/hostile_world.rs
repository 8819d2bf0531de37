//! The real server process under hostile world commands: values out of
//! range on the control socket are refused with `error: …` and the module
//! keeps serving (docs/behaviour.md rule 84); a panic ends the process
//! instead of leaving it listening with nothing behind.

use crate::common;

use common::{Server, serve_command};
use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::Stdio;
use std::time::Duration;
use tmclsim_protocol::Reply;

/// A server with TCP and control on free loopback ports.
fn args<'a>(extra: &[&'a str]) -> Vec<&'a str> {
    [&["--tcp", "127.0.0.1:0", "--control", "127.0.0.1:0"][..], extra].concat()
}

fn ask(s: &mut TcpStream, line: &str) -> Reply {
    s.write_all(&common::frame(line)).unwrap();
    let mut b = [0u8; 9];
    s.read_exact(&mut b).unwrap_or_else(|e| panic!("{line}: {e}"));
    Reply::decode(&b).unwrap()
}

#[test]
fn values_out_of_range_are_refused_and_the_module_keeps_serving() {
    let mut command = serve_command(&args(&[]));
    command.stderr(Stdio::null());
    let server = Server::spawn(command);
    let control = TcpStream::connect(server.control()).unwrap();
    control.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
    let mut answers = BufReader::new(control.try_clone().unwrap());
    let mut say = |line: &str| -> String {
        (&control).write_all(format!("{line}\n").as_bytes()).unwrap();
        let mut a = String::new();
        answers.read_line(&mut a).unwrap();
        a.trim_end().to_string()
    };
    for (line, expected) in [
        ("travel 0 10 -10", "error: axis 0: travel from 10 to -10 is empty (FROM must be below TO)"),
        ("travel 0 5 5", "error: axis 0: travel from 5 to 5 is empty"),
        ("supply nan", "error: supply NaN is not a finite number (allowed: 0…100 V)"),
        ("supply 1e6", "error: supply 1000000 is outside 0…100 V"),
        ("temperature inf", "error: temperature inf is not a finite number (allowed: -50…200 °C)"),
        ("load 0 -1", "error: axis 0: load torque -1 is outside 0…1000 %"),
        ("load 0 NaN", "error: axis 0: load torque NaN is not a finite number"),
        ("load 0 20 50 10", "error: axis 0: load range from 50 to 10 is empty"),
        ("input 99 1", "error: digital input 99 does not exist on the TMCM-1141 (digital inputs: 0…3)"),
        ("analog 9 100", "error: analog input 9 does not exist on the TMCM-1141 (analog inputs: 0)"),
        ("place 0 left 0 -1", "error: axis 0: left switch width -1 is outside 0…1e12 µsteps"),
        ("place 0 home 9 inf", "error: axis 0: home switch TO inf is not a finite number"),
        ("@1 travel 0 nan nan", "error: axis 0: travel FROM NaN is not a finite number"),
    ] {
        let answer = say(line);
        assert!(answer.starts_with(expected), "{line}: {answer}");
    }
    // The module moves, in the world it had (the stage's end stops).
    let mut link = TcpStream::connect(server.tcp()).unwrap();
    link.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
    assert_eq!(ask(&mut link, "ROR 0, 500").status, 100);
    // It reaches its speed and covers ground (polled: the wall clock runs
    // the server's time).
    let deadline = std::time::Instant::now() + Duration::from_secs(10);
    let (mut speed, mut position) = (ask(&mut link, "GAP 3, 0"), ask(&mut link, "GAP 1, 0"));
    while (speed.value != 500 || position.value <= 0) && std::time::Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(20));
        (speed, position) = (ask(&mut link, "GAP 3, 0"), ask(&mut link, "GAP 1, 0"));
    }
    assert_eq!((speed.status, speed.value), (100, 500));
    assert!(position.status == 100 && position.value > 0, "{position:?}");
    assert_eq!(ask(&mut link, "MST 0").status, 100);
    let shown = say("show 0");
    assert!(shown.starts_with("ok time") && shown.contains("speed"), "{shown}");
    // Good values still go through.
    assert_eq!(say("travel 0 -2000000 2000000"), "ok");
    assert_eq!(say("supply 12.5"), "ok");
    assert_eq!(ask(&mut link, "GIO 8, 1").value, 125);
}

#[test]
fn a_panic_ends_the_server_process() {
    // A panic is provoked without a bug: with stderr closed, the server's
    // log line for a refused connection (more than --max-connections)
    // cannot be written, and printing to stderr panics.
    let mut child = serve_command(&args(&["--max-connections", "1"])).spawn().unwrap();
    drop(child.stderr.take());
    let mut server = Server::of(child);
    let mut first = TcpStream::connect(server.tcp()).unwrap();
    first.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
    assert_eq!(ask(&mut first, "GAP 4, 0").status, 100);
    let _second = TcpStream::connect(server.tcp()).unwrap();
    // Without the panic hook the process would go on listening with its
    // TCP task gone; with it, it ends with the status of a panic.
    assert_eq!(server.exit_code_within(Duration::from_secs(10)), Some(101));
}
