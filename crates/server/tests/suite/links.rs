//! The server's links: TCP (several clients), the pty (reopened by the
//! host), resynchronisation after a lost byte, 138 events, GP 75, GP 68.

use crate::common;

use common::{ask, frame, read_reply};

use std::io::{Read, Write};
use std::net::TcpStream;
use std::time::{Duration, Instant};
use tmclsim_firmware::Module;
use tmclsim_server::{ServerConfig, ServerHandle, start};

fn serve_tcp() -> ServerHandle {
    let config = ServerConfig { tcp: Some("127.0.0.1:0".parse().unwrap()), ..ServerConfig::default() };
    start(Module::built_in("tmcm-1141").unwrap(), config).unwrap()
}

fn connect(server: &ServerHandle) -> TcpStream {
    let s = TcpStream::connect(server.endpoints().tcp.unwrap()).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
    s.set_nodelay(true).unwrap();
    s
}

#[test]
fn several_tcp_clients_share_one_module() {
    let server = serve_tcp();
    let mut a = connect(&server);
    let mut b = connect(&server);
    assert_eq!(ask(&mut a, "SAP 4, 0, 777").status, 100);
    assert_eq!(ask(&mut b, "GAP 4, 0").value, 777);
    // Frames sent in one write are answered one by one, whole.
    let mut two = frame("GAP 4, 0").to_vec();
    two.extend_from_slice(&frame("GGP 66, 0"));
    a.write_all(&two).unwrap();
    assert_eq!(read_reply(&mut a).value, 777);
    assert_eq!(read_reply(&mut a).value, 1);
    server.stop();
}

#[test]
fn a_lost_byte_is_dropped_after_the_inter_byte_timeout() {
    let server = serve_tcp();
    let mut s = connect(&server);
    s.write_all(&frame("GAP 4, 0")[..5]).unwrap();
    // About time: a gap longer than the 5 ms inter-byte timeout.
    std::thread::sleep(Duration::from_millis(30));
    let r = ask(&mut s, "GGP 66, 0");
    assert_eq!((r.status, r.opcode, r.value), (100, 10, 1));
    // Nothing else is pending.
    s.set_read_timeout(Some(Duration::from_millis(100))).unwrap();
    let mut extra = [0u8; 1];
    assert!(s.read(&mut extra).is_err());
    server.stop();
}

#[test]
fn target_reached_event_arrives_on_the_link() {
    let server = serve_tcp();
    let mut s = connect(&server);
    ask(&mut s, "SAP 4, 0, 2047");
    ask(&mut s, "SAP 5, 0, 2047");
    let r = ask(&mut s, "#138 0 0 1");
    assert_eq!((r.status, r.value), (100, 1));
    let started = Instant::now();
    assert_eq!(ask(&mut s, "MVP ABS, 0, 3000").status, 100);
    let event = read_reply(&mut s);
    assert_eq!((event.status, event.opcode, event.value), (128, 138, 1));
    let t = started.elapsed();
    assert!(t < Duration::from_secs(2), "{t:?}");
    assert_eq!(ask(&mut s, "GAP 1, 0").value, 3000, "the event came when the motor arrived");
    // Type 0 armed one move only: the motor arrives, and every frame read
    // meanwhile is a GAP's reply, none an event.
    ask(&mut s, "MVP ABS, 0, 0");
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        let r = ask(&mut s, "GAP 8, 0");
        assert_eq!((r.status, r.opcode), (100, 6), "a reply, not an event: {r:?}");
        if r.value == 1 {
            break;
        }
        assert!(Instant::now() < deadline, "the motor did not arrive within 10 s");
        std::thread::sleep(Duration::from_millis(20));
    }
    assert_eq!(ask(&mut s, "GAP 1, 0").value, 0);
    server.stop();
}

#[test]
fn telegram_pause_delays_replies() {
    let server = serve_tcp();
    let mut s = connect(&server);
    ask(&mut s, "SGP 75, 0, 60");
    let t = Instant::now();
    ask(&mut s, "GAP 4, 0");
    assert!(t.elapsed() >= Duration::from_millis(60));
    ask(&mut s, "SGP 75, 0, 0");
    server.stop();
}

#[test]
fn heartbeat_stops_the_motor_when_the_host_falls_silent() {
    let server = serve_tcp();
    let mut s = connect(&server);
    ask(&mut s, "SGP 68, 0, 100");
    ask(&mut s, "ROR 0, 200");
    // About time: the host stays silent longer than the 100 ms heartbeat
    // (a poll would be a frame, which restarts it).
    std::thread::sleep(Duration::from_millis(400));
    assert_eq!(ask(&mut s, "GAP 2, 0").value, 0, "target speed zeroed by the heartbeat");
    ask(&mut s, "SGP 68, 0, 0");
    server.stop();
}

#[test]
#[cfg_attr(windows, ignore = "a pty is a Unix device: the server refuses one on Windows")]
fn the_pty_works_like_a_serial_port_and_survives_reopening() {
    let dir = std::env::temp_dir().join(format!("tmclsim-pty-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let link = dir.join("tmcm");
    let config = ServerConfig { pty: Some(link.clone()), ..ServerConfig::default() };
    let server = start(Module::built_in("tmcm-1141").unwrap(), config).unwrap();
    assert_eq!(server.endpoints().pty.as_ref().unwrap().0, link);
    for round in 0..3 {
        let mut port = std::fs::OpenOptions::new().read(true).write(true).open(&link).unwrap();
        let r = ask(&mut port, &format!("SAP 4, 0, {}", 100 + round));
        assert_eq!(r.status, 100);
        assert_eq!(ask(&mut port, "GAP 4, 0").value, 100 + round);
        drop(port);
    }
    server.stop();
    assert!(!link.exists(), "stop removes the symlink");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn eeprom_file_is_written_on_store() {
    let dir = std::env::temp_dir().join(format!("tmclsim-srv-ee-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("m.eeprom");
    let file = std::sync::Arc::new(tmclsim_server::eeprom_file::EepromFile::open(&path).unwrap());
    let config = ServerConfig { tcp: Some("127.0.0.1:0".parse().unwrap()), eeprom: Some(file), ..ServerConfig::default() };
    let server = start(Module::built_in("tmcm-1141").unwrap(), config).unwrap();
    let mut s = connect(&server);
    ask(&mut s, "SAP 4, 0, 1999");
    ask(&mut s, "STAP 4, 0");
    // The file is written before the reply is sent.
    let image = tmclsim_server::eeprom_file::load(&path).unwrap().unwrap();
    assert_eq!(image.axis(0, 4), Some(1999));
    server.stop();
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn stepped_virtual_time() {
    let server = serve_tcp();
    server.bus().set_stepped(true);
    let mut s = connect(&server);
    ask(&mut s, "ROR 0, 1000");
    // About time: wall time passes, virtual time does not.
    std::thread::sleep(Duration::from_millis(100));
    assert_eq!(ask(&mut s, "GAP 1, 0").value, 0, "time stands still");
    server.bus().advance(3_600_000_000_000);
    assert_eq!(ask(&mut s, "GAP 3, 0").value, 1000);
    let p = ask(&mut s, "GAP 1, 0").value;
    assert!(p > 100_000_000, "an hour of motion: {p}");
    // 138 events come when stepped time reaches them.
    ask(&mut s, "SAP 4, 0, 2047");
    ask(&mut s, "#138 0 0 1");
    ask(&mut s, "MVP REL, 0, 100000");
    server.bus().advance(10_000_000_000);
    let event = read_reply(&mut s);
    assert_eq!((event.status, event.opcode), (128, 138));
    server.bus().set_stepped(false);
    ask(&mut s, "ROR 0, 1000");
    let deadline = Instant::now() + Duration::from_secs(10);
    while ask(&mut s, "GAP 1, 0").value == 0 {
        assert!(Instant::now() < deadline, "back on the wall clock, the motor moves");
        std::thread::sleep(Duration::from_millis(20));
    }
    server.stop();
}

#[test]
#[cfg_attr(windows, ignore = "a pty is a Unix device: the server refuses one on Windows")]
fn ascii_session_on_the_pty_in_every_echo_mode() {
    let dir = std::env::temp_dir().join(format!("tmclsim-ascii-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let link = dir.join("tmcm");
    let config = ServerConfig { pty: Some(link.clone()), ..ServerConfig::default() };
    let server = start(Module::built_in("tmcm-1141").unwrap(), config).unwrap();
    let mut port = std::fs::OpenOptions::new().read(true).write(true).open(&link).unwrap();
    // The motor is stopped before AP 1 is overwritten, as the manual asks:
    // in position mode (the power-on mode) it would head for its target.
    assert_eq!(ask(&mut port, "MST 0").status, 100);
    assert_eq!(ask(&mut port, "#139 0 0 0").status, 100);
    let mut session = |line: &str, expect: &str| {
        port.write_all(line.as_bytes()).unwrap();
        let mut got = vec![0u8; expect.len()];
        port.read_exact(&mut got).unwrap();
        assert_eq!(String::from_utf8_lossy(&got), expect, "{line:?}");
    };
    session("ASAP 1, 0, -5000\r", "ASAP 1, 0, -5000\rBA 100 -5000\r");
    session("AGAP 1, 0\r", "AGAP 1, 0\rBA 100 -5000\r");
    session("ASGP 67, 0, 16\r", "ASGP 67, 0, 16\rBA 100 16\r");
    session("AGAP 1, 0\r", "AGAP 1, 0\rBA 100 -5000\r");
    session("ASGP 67, 0, 32\r", "ASGP 67, 0, 32\rBA 100 32\r");
    session("AGAP 1, 0\r", "BA 100 -5000\r");
    session("ABIN\r", "BA 100 0\r");
    // Binary again.
    assert_eq!(ask(&mut port, "GAP 1, 0").value, -5000);
    server.stop();
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn wire_timing_follows_the_baud_rate() {
    let config = ServerConfig { tcp: Some("127.0.0.1:0".parse().unwrap()), wire_timing: true, ..ServerConfig::default() };
    let server = start(Module::built_in("tmcm-1141").unwrap(), config).unwrap();
    let mut s = connect(&server);
    // GP 65 = 0: 9600 baud; 18 bytes of 10 bits take 18.75 ms.
    let t = Instant::now();
    ask(&mut s, "GAP 4, 0");
    assert!(t.elapsed() >= Duration::from_micros(18_750), "{:?}", t.elapsed());
    ask(&mut s, "SGP 65, 0, 8"); // 230400 baud: 0.8 ms
    let t = Instant::now();
    ask(&mut s, "GAP 4, 0");
    // At least the bytes' time; how much less than at 9600 is the bus's
    // own test (a wall-clock upper bound fails on a busy machine).
    let e = t.elapsed();
    assert!(e >= Duration::from_micros(780), "{e:?}");
    server.stop();
}
