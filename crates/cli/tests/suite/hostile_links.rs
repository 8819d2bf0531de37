//! The real `tmclsim serve` under hostile or careless use of its links:
//! huge control lines, too many control clients, ASCII from two TCP clients
//! at once, two servers on one pty path, failed starts, exposure to other
//! machines, and running out of file descriptors.

use crate::common;

use common::{Server, serve_command};
use std::io::{BufRead, BufReader, Read, Write};
use std::net::{TcpListener, TcpStream};
#[cfg(unix)]
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// CPU time (user + system) a server used so far.
#[cfg(unix)]
fn cpu_time(server: &Server) -> Duration {
    let s = std::fs::read_to_string(format!("/proc/{}/stat", server.child.id())).unwrap();
    let after = &s[s.rfind(')').unwrap() + 2..];
    let f: Vec<u64> = after.split_whitespace().skip(11).take(2).map(|x| x.parse().unwrap()).collect();
    // SAFETY: sysconf has no preconditions.
    let hz = unsafe { libc::sysconf(libc::_SC_CLK_TCK) } as u64;
    Duration::from_millis((f[0] + f[1]) * 1000 / hz)
}

/// Runs a serve that should refuse to start: its exit success and stderr.
/// A serve still running after 10 s is killed (`None`).
fn refused(args: &[&str]) -> (Option<bool>, String) {
    let mut child = serve_command(args).stdout(Stdio::null()).spawn().unwrap();
    let mut err = child.stderr.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = err.read_to_string(&mut s);
        s
    });
    let start = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break Some(s.success());
        }
        if start.elapsed() > Duration::from_secs(10) {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    (status, reader.join().unwrap())
}

fn connect(addr: &str) -> TcpStream {
    let s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
    s
}

fn read_line(s: &mut BufReader<TcpStream>) -> String {
    let mut a = String::new();
    s.read_line(&mut a).unwrap();
    a.trim_end().to_string()
}

fn say(s: &mut BufReader<TcpStream>, line: &str) -> String {
    s.get_mut().write_all(format!("{line}\n").as_bytes()).unwrap();
    read_line(s)
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tmclsim-hostile-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn exists(p: &Path) -> bool {
    std::fs::symlink_metadata(p).is_ok()
}

#[test]
fn ten_megabytes_on_one_control_line() {
    let server = Server::start(&["--tcp", "127.0.0.1:0"]);
    let mut c = BufReader::new(connect(&server.control()));
    assert_eq!(say(&mut c, "input 1 1"), "ok");
    let before = server.rss_kib();
    let mut w = c.get_ref().try_clone().unwrap();
    let writer = std::thread::spawn(move || {
        let chunk = vec![b'x'; 1 << 20];
        for _ in 0..10 {
            w.write_all(&chunk).unwrap();
        }
    });
    assert_eq!(read_line(&mut c), "error: line longer than 4096 bytes", "refused while it is still coming");
    writer.join().unwrap();
    let after = server.rss_kib();
    assert!(after < before + 4 * 1024, "memory stays bounded: {before} KiB → {after} KiB");
    // The end of that line is dropped with it; then lines are served again.
    c.get_mut().write_all(b"\n").unwrap();
    assert_eq!(say(&mut c, "input 1 0"), "ok");
    server.check();
}

#[test]
fn control_connections_at_once_are_limited() {
    let server = Server::start(&["--tcp", "127.0.0.1:0"]);
    let held: Vec<BufReader<TcpStream>> = (0..16)
        .map(|i| {
            let mut c = BufReader::new(connect(&server.control()));
            assert_eq!(say(&mut c, &format!("input {} 1", i % 4)), "ok");
            c
        })
        .collect();
    let mut extra = BufReader::new(connect(&server.control()));
    assert_eq!(read_line(&mut extra), "error: 16 control connections open (the limit)");
    assert_eq!(read_line(&mut extra), "", "and closed");
    assert_eq!(server.log_has("refusing control connection"), 1);
    drop(held);
    // Served again once the server saw the 16 close.
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        let mut again = BufReader::new(connect(&server.control()));
        let answer = say(&mut again, "input 0 0");
        if answer == "ok" {
            break;
        }
        assert!(Instant::now() < deadline, "no slot 10 s after the 16 closed: {answer}");
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn two_tcp_clients_in_ascii_mode_keep_their_own_lines() {
    let server = Server::start(&["--tcp", "127.0.0.1:0"]);
    let (mut a, mut b) = (connect(&server.tcp()), connect(&server.tcp()));
    assert_eq!(common::ask(&mut a, "#139 0 0 0").unwrap().status, 100);
    let text = |s: &mut TcpStream, send: &str, len: usize| -> String {
        s.write_all(send.as_bytes()).unwrap();
        let mut got = vec![0u8; len];
        let r = s.read_exact(&mut got);
        assert!(r.is_ok(), "{send:?}: {r:?} {:?}", String::from_utf8_lossy(&got));
        String::from_utf8(got).unwrap()
    };
    // Echo each character (the default): each client sees its own.
    assert_eq!(text(&mut a, "ASAP 4, 0, 9", 12), "ASAP 4, 0, 9");
    assert_eq!(text(&mut b, "AGAP 1, 0\r", 19), "AGAP 1, 0\rBA 100 0\r", "B's line alone");
    assert_eq!(text(&mut a, "9\r", 12), "9\rBA 100 99\r");
    assert_eq!(text(&mut b, "AGAP 4, 0\r", 20), "AGAP 4, 0\rBA 100 99\r");
    assert_eq!(text(&mut b, "ABIN\r", 14), "ABIN\rBA 100 0\r");
    server.check();
}

#[test]
#[cfg_attr(windows, ignore = "a pty is a Unix device: Windows refuses --pty")]
fn a_pty_path_served_by_a_live_server_is_refused() {
    let dir = scratch("pty");
    let link = dir.join("tmcm");
    let p = link.to_str().unwrap();
    let first = Server::start(&["--tcp", "127.0.0.1:0", "--pty", p]);
    let device = std::fs::read_link(&link).unwrap();
    let (ok, err) = refused(&["--tcp", "127.0.0.1:0", "--pty", p]);
    assert_eq!(ok, Some(false), "{err}");
    assert!(err.contains(p) && err.contains("served by a running tmclsim"), "{err}");
    assert_eq!(std::fs::read_link(&link).unwrap(), device, "the first server's link stays");
    let mut port = std::fs::OpenOptions::new().read(true).write(true).open(&link).unwrap();
    port.write_all(&common::frame("GGP 66, 0")).unwrap();
    let mut b = [0u8; 9];
    port.read_exact(&mut b).unwrap();
    assert_eq!(tmclsim_protocol::Reply::decode(&b).unwrap().value, 1, "the first server still serves it");
    drop(first);
    // Killed: the link is stale now, and the next server replaces it.
    assert!(exists(&link));
    let second = Server::start(&["--tcp", "127.0.0.1:0", "--pty", p]);
    assert_ne!(std::fs::read_link(&link).unwrap(), device);
    assert_eq!(second.printed("pty"), p);
    drop(second);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
#[cfg(unix)] // A pty and a symbolic link to it.
fn a_stale_link_is_replaced() {
    let dir = scratch("stale");
    let link = dir.join("tmcm");
    std::os::unix::fs::symlink("/dev/pts/does-not-exist", &link).unwrap();
    let server = Server::start(&["--tcp", "127.0.0.1:0", "--pty", link.to_str().unwrap()]);
    let device = std::fs::read_link(&link).unwrap();
    assert!(device.starts_with("/dev/pts/") && device.exists(), "{device:?}");
    server.check();
    drop(server);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
#[cfg_attr(windows, ignore = "a pty is a Unix device: Windows refuses --pty")]
fn a_failed_start_names_the_address_and_leaves_no_link() {
    let dir = scratch("failed");
    let link = dir.join("tmcm");
    let taken = TcpListener::bind("127.0.0.1:0").unwrap();
    let at = taken.local_addr().unwrap().to_string();
    let (ok, err) = refused(&["--tcp", &at, "--pty", link.to_str().unwrap()]);
    assert_eq!(ok, Some(false));
    assert!(
        err.contains(&format!("cannot listen on {at} (TCP): ")) && err.contains("in use") && err.contains("choose another port"),
        "{err}"
    );
    assert!(!exists(&link));
    // The control socket is bound after the pty exists.
    let (ok, err) = refused(&["--tcp", "127.0.0.1:0", "--pty", link.to_str().unwrap(), "--control", &at]);
    assert_eq!(ok, Some(false));
    assert!(err.contains(&format!("cannot listen on {at} (control): ")), "{err}");
    let left: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert!(left.is_empty(), "nothing left behind: {left:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn max_connections_zero_is_refused() {
    let (ok, err) = refused(&["--tcp", "127.0.0.1:0", "--max-connections", "0"]);
    assert_eq!(ok, Some(false), "{err}");
    assert!(err.contains("--max-connections 0"), "{err}");
}

#[test]
fn a_public_control_socket_takes_a_flag_and_a_token() {
    let (ok, err) = refused(&["--tcp", "127.0.0.1:0", "--control", "0.0.0.0:0"]);
    assert_eq!(ok, Some(false), "{err}");
    assert!(err.contains("--control 0.0.0.0:0") && err.contains("--control-public"), "{err}");
    let server = Server::start(&["--tcp", "127.0.0.1:0", "--control", "0.0.0.0:0", "--control-public"]);
    let line = server.banner.iter().find(|l| l.starts_with("control: ")).unwrap().clone();
    let token = line.split_whitespace().nth(3).unwrap().to_string();
    assert_eq!(token.len(), 32, "{line}");
    let port = server.control().rsplit(':').next().unwrap().to_string();
    let at = format!("127.0.0.1:{port}");
    let mut c = BufReader::new(connect(&at));
    assert!(say(&mut c, "input 1 1").contains("needs a token"));
    let mut c = BufReader::new(connect(&at));
    assert_eq!(say(&mut c, "auth 0123"), "error: wrong token");
    let mut c = BufReader::new(connect(&at));
    assert_eq!(say(&mut c, &format!("auth {token} input 1 1")), "ok");
    assert_eq!(say(&mut c, "input 1 0"), "ok");
    // `tmclsim world` passes the token the same way.
    let out =
        Command::new(env!("CARGO_BIN_EXE_tmclsim")).args(["world", "--control", &at, "auth", &token, "input", "2", "1"]).output().unwrap();
    assert!(out.status.success(), "{out:?}");
    let log = server.whole_log();
    assert_eq!(log.iter().filter(|l| l.contains("warning: the control socket on 0.0.0.0:")).count(), 1, "{log:?}");
}

#[test]
fn a_tcp_link_open_to_other_machines_is_warned_about() {
    // The whole log, once stopped: the warning once, and none on loopback.
    let log = Server::start(&["--tcp", "0.0.0.0:0"]).whole_log();
    assert_eq!(log.iter().filter(|l| l.contains("warning: TMCL on 0.0.0.0:")).count(), 1, "{log:?}");
    assert_eq!(log.iter().filter(|l| l.contains("drive the motors")).count(), 1, "{log:?}");
    let quiet = Server::start(&["--tcp", "127.0.0.1:0"]).whole_log();
    assert!(!quiet.iter().any(|l| l.contains("warning")), "{quiet:?}");
}

#[test]
#[cfg(unix)] // A descriptor limit (setrlimit), CPU time from /proc and SIGTERM.
fn out_of_file_descriptors_the_accept_loop_backs_off() {
    let mut c = serve_command(&["--tcp", "127.0.0.1:0", "--max-connections", "1000"]);
    // SAFETY: setrlimit is async-signal-safe; nothing else runs in the hook.
    unsafe {
        c.pre_exec(|| {
            let limit = libc::rlimit { rlim_cur: 32, rlim_max: 32 };
            if libc::setrlimit(libc::RLIMIT_NOFILE, &limit) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
    let server = Server::spawn(c);
    server.check();
    // More clients than the server has descriptors: the rest wait in the
    // listen queue while every accept fails.
    let clients: Vec<TcpStream> = (0..60).map(|_| TcpStream::connect(server.tcp()).unwrap()).collect();
    assert!(server.logged(&["cannot accept a TCP connection on"]).is_some(), "{:?}", server.log.lock().unwrap());
    // A second of the server's CPU time, out of descriptors (about time:
    // the measurement's window).
    let (cpu, wall) = (cpu_time(&server), Instant::now());
    std::thread::sleep(Duration::from_secs(1));
    let used = cpu_time(&server) - cpu;
    assert!(used < wall.elapsed() / 5, "the server waits instead of spinning: {used:?} of CPU in {:?}", wall.elapsed());
    assert_eq!(server.log_has("cannot accept a TCP connection on"), 1, "logged once: {:?}", server.log.lock().unwrap());
    drop(clients);
    server.check_soon();
    // Out of descriptors again, it still stops on SIGTERM, at once and
    // cleanly: its signal handlers were installed before it served.
    let before = server.log_has("cannot accept a TCP connection on");
    let clients: Vec<TcpStream> = (0..60).map(|_| TcpStream::connect(server.tcp()).unwrap()).collect();
    let failing = server.log_has_at_least("cannot accept a TCP connection on", before + 1);
    assert!(failing > before, "out of descriptors again: {:?}", server.log.lock().unwrap());
    let mut server = server;
    // SAFETY: signalling the child this test started.
    unsafe {
        libc::kill(server.child.id() as i32, libc::SIGTERM);
    }
    assert_eq!(server.exit_code_within(Duration::from_secs(5)), Some(0), "{:?}", server.log.lock().unwrap());
    drop(clients);
}
