//! Limits and life cycles of a served link: ASCII lines per connection,
//! connection slots and the idle rule, the control socket's limits and
//! token, pty paths claimed by a live server, errors that name what failed.

use crate::common;

use common::ask;

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{TcpListener, TcpStream};
use std::path::PathBuf;
use std::time::Duration;
use tmclsim_firmware::Module;
use tmclsim_server::{LinkSpec, ServerConfig, ServerHandle, start, start_fleet};

fn module() -> Module {
    Module::built_in("tmcm-1141").unwrap()
}

fn loopback() -> Option<std::net::SocketAddr> {
    Some("127.0.0.1:0".parse().unwrap())
}

fn connect(addr: std::net::SocketAddr) -> TcpStream {
    let s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
    s.set_nodelay(true).unwrap();
    s
}

fn read_text(s: &mut TcpStream, len: usize) -> String {
    let mut b = vec![0u8; len];
    s.read_exact(&mut b).unwrap();
    String::from_utf8_lossy(&b).into_owned()
}

/// True when the server closed the connection (EOF or reset) within 2 s.
fn closed(s: &mut TcpStream) -> bool {
    s.set_read_timeout(Some(Duration::from_secs(2))).unwrap();
    let mut b = [0u8; 64];
    loop {
        match s.read(&mut b) {
            Ok(0) => return true,
            Ok(_) => continue,
            Err(e) if e.kind() == std::io::ErrorKind::WouldBlock || e.kind() == std::io::ErrorKind::TimedOut => return false,
            Err(_) => return true,
        }
    }
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tmclsim-limits-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn two_tcp_clients_type_their_own_ascii_lines() {
    let server = start(module(), ServerConfig { tcp: loopback(), ..ServerConfig::default() }).unwrap();
    let addr = server.endpoints().tcp.unwrap();
    let (mut a, mut b) = (connect(addr), connect(addr));
    assert_eq!(ask(&mut a, "SAP 4, 0, 777").status, 100);
    assert_eq!(ask(&mut a, "#139 0 0 0").status, 100);
    // No echo from now on: only replies come back.
    a.write_all(b"ASGP 67, 0, 32\r").unwrap();
    assert_eq!(read_text(&mut a, 25), "ASGP 67, 0, 32\rBA 100 32\r");
    // A types half a line; B types a whole one; A finishes its own.
    a.write_all(b"AGAP 4").unwrap();
    // Not a synchronisation (no echo tells when A's bytes are in): the
    // answers are the same in either order; the pause makes the
    // interleaving likely.
    std::thread::sleep(Duration::from_millis(50));
    b.write_all(b"ASAP 4, 0, 555\r").unwrap();
    assert_eq!(read_text(&mut b, 11), "BA 100 555\r");
    a.write_all(b", 0\r").unwrap();
    assert_eq!(read_text(&mut a, 11), "BA 100 555\r");
    // B's half line is not finished by A's carriage return.
    b.write_all(b"AGAP 4").unwrap();
    // As above: either order gives the same answers.
    std::thread::sleep(Duration::from_millis(50));
    a.write_all(b"\r").unwrap();
    b.write_all(b", 0\r").unwrap();
    assert_eq!(read_text(&mut b, 11), "BA 100 555\r");
    a.set_read_timeout(Some(Duration::from_millis(200))).unwrap();
    assert!(a.read(&mut [0u8; 16]).is_err(), "A's empty line is answered by nobody");
    server.stop();
}

#[test]
fn an_idle_client_gives_its_slot_to_a_new_one() {
    let config = ServerConfig { tcp: loopback(), max_connections: 2, idle_timeout: Duration::from_millis(300), ..ServerConfig::default() };
    let server = start(module(), config).unwrap();
    let addr = server.endpoints().tcp.unwrap();
    // A slow client: a byte every 50 ms never makes a frame.
    let mut slow = connect(addr);
    let mut dribble = slow.try_clone().unwrap();
    let dribbler = std::thread::spawn(move || {
        for _ in 0..20 {
            if dribble.write_all(&[1]).is_err() {
                break;
            }
            // About time: slower than any frame's inter-byte timeout.
            std::thread::sleep(Duration::from_millis(50));
        }
    });
    // About time: longer than the 300 ms idle timeout.
    std::thread::sleep(Duration::from_millis(400));
    let mut busy = connect(addr);
    assert_eq!(ask(&mut busy, "GAP 4, 0").status, 100);
    // Both slots taken; the slow client has made no request for 400 ms.
    let mut new = connect(addr);
    assert_eq!(ask(&mut new, "GGP 66, 0").value, 1, "the new client is served");
    assert!(closed(&mut slow), "the slow client lost its slot");
    // Now no one is idle long enough: the next client is refused.
    let mut refused = connect(addr);
    assert!(closed(&mut refused));
    assert_eq!(ask(&mut busy, "GAP 4, 0").status, 100);
    dribbler.join().unwrap();
    server.stop();
}

fn control_server(config: ServerConfig) -> (ServerHandle, std::net::SocketAddr) {
    let server = start(module(), ServerConfig { control: loopback(), ..config }).unwrap();
    let addr = server.endpoints().control.unwrap();
    (server, addr)
}

fn say(s: &mut BufReader<TcpStream>, line: &str) -> String {
    s.get_mut().write_all(format!("{line}\n").as_bytes()).unwrap();
    let mut a = String::new();
    s.read_line(&mut a).unwrap();
    a.trim_end().to_string()
}

#[test]
fn a_control_line_longer_than_the_limit_is_refused_and_dropped() {
    let (server, addr) = control_server(ServerConfig { control_max_line: 64, ..ServerConfig::default() });
    let mut c = BufReader::new(connect(addr));
    assert!(say(&mut c, &"x".repeat(64)).starts_with(&format!("error: unknown command '{}'", "x".repeat(64))), "64 bytes are a line");
    // Without a line end the error comes as soon as the limit is passed.
    c.get_mut().write_all(&[b'y'; 1000]).unwrap();
    let mut a = String::new();
    c.read_line(&mut a).unwrap();
    assert_eq!(a, "error: line longer than 64 bytes\n");
    // The rest of that line, up to its line end, is dropped without a
    // second error; the next line is served.
    c.get_mut().write_all(&[b'y'; 1000]).unwrap();
    c.get_mut().write_all(b"\n").unwrap();
    assert_eq!(say(&mut c, "input 3 1"), "ok");
    assert_eq!(say(&mut c, &"z".repeat(100)), "error: line longer than 64 bytes");
    assert_eq!(say(&mut c, "input 3 0"), "ok");
    server.stop();
}

#[test]
fn control_connections_are_limited_and_idle_ones_give_way() {
    let config = ServerConfig { control_max_connections: 2, idle_timeout: Duration::from_millis(300), ..ServerConfig::default() };
    let (server, addr) = control_server(config);
    let mut idle = connect(addr);
    let mut first = BufReader::new(connect(addr));
    assert_eq!(say(&mut first, "input 1 1"), "ok");
    let mut third = BufReader::new(connect(addr));
    let mut a = String::new();
    third.read_line(&mut a).unwrap();
    assert_eq!(a, "error: 2 control connections open (the limit)\n");
    assert!(closed(third.get_mut()));
    // About time: longer than the 300 ms idle timeout.
    std::thread::sleep(Duration::from_millis(400));
    assert_eq!(say(&mut first, "input 1 0"), "ok");
    // The silent one has gone 400 ms without a line: it makes room.
    let mut fourth = BufReader::new(connect(addr));
    assert_eq!(say(&mut fourth, "input 2 1"), "ok");
    assert!(closed(&mut idle));
    server.stop();
}

#[test]
fn a_control_token_is_asked_for_first() {
    let config = ServerConfig { control_token: Some("s3cret".into()), ..ServerConfig::default() };
    let (server, addr) = control_server(config);
    let mut c = BufReader::new(connect(addr));
    assert_eq!(say(&mut c, "input 1 1"), "error: this control socket needs a token: send \"auth TOKEN\" first");
    assert!(closed(c.get_mut()));
    let mut c = BufReader::new(connect(addr));
    assert_eq!(say(&mut c, "auth s3cre"), "error: wrong token");
    assert!(closed(c.get_mut()));
    let mut c = BufReader::new(connect(addr));
    assert_eq!(say(&mut c, "auth s3cret"), "ok");
    assert_eq!(say(&mut c, "input 1 1"), "ok");
    // The token and a command on one line (what `tmclsim world` sends).
    let mut c = BufReader::new(connect(addr));
    assert!(say(&mut c, "auth s3cret show").starts_with("ok time"));
    server.stop();
}

#[test]
fn a_public_control_socket_needs_a_token() {
    let config = ServerConfig { control: Some("0.0.0.0:0".parse().unwrap()), ..ServerConfig::default() };
    let e = start(module(), config).err().expect("refused");
    assert!(e.to_string().contains("0.0.0.0:0") && e.to_string().contains("token"), "{e}");
    let config = ServerConfig { tcp: loopback(), max_connections: 0, ..ServerConfig::default() };
    assert!(start(module(), config).err().expect("refused").to_string().contains("max_connections is 0"));
}

#[test]
fn a_bind_error_names_the_address() {
    let taken = TcpListener::bind("127.0.0.1:0").unwrap();
    let at = taken.local_addr().unwrap();
    let e = start(module(), ServerConfig { tcp: Some(at), ..ServerConfig::default() }).err().expect("in use");
    assert_eq!(e.kind(), std::io::ErrorKind::AddrInUse);
    assert!(e.to_string().starts_with(&format!("cannot listen on {at} (TCP): ")), "{e}");
}

#[test]
#[cfg(unix)] // A pty, and symbolic links to it.
fn a_pty_path_is_claimed_while_its_server_lives() {
    let dir = scratch("claim");
    let link = dir.join("tmcm");
    let config = ServerConfig { pty: Some(link.clone()), ..ServerConfig::default() };
    let first = start(module(), config.clone()).unwrap();
    let device = first.endpoints().pty.as_ref().unwrap().1.clone();
    let e = start(module(), config.clone()).err().expect("refused");
    assert!(e.to_string().contains(&link.display().to_string()) && e.to_string().contains("running tmclsim"), "{e}");
    assert_eq!(std::fs::read_link(&link).unwrap(), device, "the link is untouched");
    let mut port = std::fs::OpenOptions::new().read(true).write(true).open(&link).unwrap();
    assert_eq!(ask(&mut port, "GGP 66, 0").value, 1, "the first server still serves it");
    drop(port);
    first.stop();
    assert!(std::fs::symlink_metadata(&link).is_err(), "removed at the end");
    // A stale link (its server gone without cleaning up) is replaced.
    std::os::unix::fs::symlink("/dev/null", &link).unwrap();
    let second = start(module(), config.clone()).unwrap();
    let device = second.endpoints().pty.as_ref().unwrap().1.clone();
    assert_eq!(std::fs::read_link(&link).unwrap(), device);
    // A link someone else made since is not ours to remove.
    std::fs::remove_file(&link).unwrap();
    std::os::unix::fs::symlink("/dev/null", &link).unwrap();
    second.stop();
    assert_eq!(std::fs::read_link(&link).unwrap(), PathBuf::from("/dev/null"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
#[cfg_attr(windows, ignore = "a pty is a Unix device: the server refuses one on Windows")]
fn a_failed_start_leaves_no_pty_link() {
    let dir = scratch("failed");
    let taken = TcpListener::bind("127.0.0.1:0").unwrap();
    let at = taken.local_addr().unwrap();
    // The control socket is bound after the pty exists.
    let link = dir.join("tmcm");
    let config = ServerConfig { pty: Some(link.clone()), control: Some(at), ..ServerConfig::default() };
    let e = start(module(), config).err().expect("in use");
    assert!(e.to_string().contains(&format!("cannot listen on {at} (control)")), "{e}");
    assert!(std::fs::symlink_metadata(&link).is_err(), "no link left behind");
    // A fleet: the links opened before the failing one are removed too.
    let spec = |config: ServerConfig| LinkSpec { modules: vec![(module(), None)], config };
    let links: Vec<PathBuf> = (0..3).map(|i| dir.join(format!("link{i}"))).collect();
    let mut specs: Vec<LinkSpec> = links.iter().map(|l| spec(ServerConfig { pty: Some(l.clone()), ..ServerConfig::default() })).collect();
    specs.push(spec(ServerConfig { tcp: Some(at), ..ServerConfig::default() }));
    let e = start_fleet(specs).err().expect("in use");
    assert!(e.to_string().contains(&format!("cannot listen on {at} (TCP)")), "{e}");
    let left: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert!(left.is_empty(), "nothing left behind: {left:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}
