//! `tmclsim serve --serial DEVICE`: the module answers on an existing
//! serial device (docs/behaviour.md rule 98). The device here is the slave
//! side of a pty the test opens; the test is the host on its master side,
//! which also shows the line settings the server made (a pty master reports
//! its slave's).
#![cfg(unix)]

use crate::common::{Server, serve_command, tmclsim};
use std::fs::File;
use std::io::{Read, Write};
use std::os::fd::{AsRawFd, FromRawFd};
use std::path::Path;
use std::time::{Duration, Instant};
use tmclsim_protocol::mnemonic::parse_line;
use tmclsim_protocol::{Reply, Request};

/// A pty whose slave is the "serial device"; the test holds the master.
struct Device {
    master: File,
    slave: String,
}

impl Device {
    /// A new pty. The master is opened close-on-exec, so that no server
    /// another test starts meanwhile holds it: closing it is the device
    /// vanishing. The slave is opened only by the server, by its name.
    fn open() -> Device {
        let check = |r: libc::c_int| {
            assert!(r >= 0, "{}", std::io::Error::last_os_error());
            r
        };
        // SAFETY: plain libc calls on the descriptor this function opens.
        unsafe {
            let master = File::from_raw_fd(check(libc::posix_openpt(libc::O_RDWR | libc::O_NOCTTY | libc::O_CLOEXEC)));
            check(libc::grantpt(master.as_raw_fd()));
            check(libc::unlockpt(master.as_raw_fd()));
            let mut name = [0 as libc::c_char; 128];
            check(libc::ptsname_r(master.as_raw_fd(), name.as_mut_ptr(), name.len()));
            let slave = std::ffi::CStr::from_ptr(name.as_ptr()).to_string_lossy().into_owned();
            Device { master, slave }
        }
    }

    /// The baud rate the device is set to (its output speed; a pty master
    /// reports its slave's settings, which the server sets with termios2).
    fn baud(&self) -> u32 {
        // SAFETY: TCGETS2 fills the struct it is given.
        unsafe {
            let mut t: libc::termios2 = std::mem::zeroed();
            assert_eq!(libc::ioctl(self.master.as_raw_fd(), libc::TCGETS2, &mut t), 0, "{}", std::io::Error::last_os_error());
            t.c_ospeed
        }
    }

    /// Sends a request to module 1 as the host and reads its reply (5 s
    /// at most).
    fn ask(&mut self, line: &str) -> Reply {
        self.ask_module(1, line)
    }

    fn ask_module(&mut self, address: u8, line: &str) -> Reply {
        self.master.write_all(&Request::new(address, parse_line(line).unwrap()).encode()).unwrap();
        let mut got = Vec::new();
        let deadline = Instant::now() + Duration::from_secs(5);
        while got.len() < 9 {
            let left = deadline.saturating_duration_since(Instant::now());
            assert!(!left.is_zero(), "{line}: no reply within 5 s (got {got:02X?})");
            let mut p = libc::pollfd { fd: self.master.as_raw_fd(), events: libc::POLLIN, revents: 0 };
            // SAFETY: one pollfd, of this length.
            if unsafe { libc::poll(&mut p, 1, left.as_millis() as i32) } == 1 {
                let mut buf = [0u8; 9];
                let n = self.master.read(&mut buf[..9 - got.len()]).unwrap();
                got.extend_from_slice(&buf[..n]);
            }
        }
        Reply::decode(&got.try_into().unwrap()).unwrap()
    }
}

/// Polls `done` for up to 20 s; fails saying what was awaited.
fn until(what: &str, mut done: impl FnMut() -> bool) {
    let deadline = Instant::now() + Duration::from_secs(20);
    while !done() {
        assert!(Instant::now() < deadline, "waited 20 s for {what}");
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn serve(args: &[&str]) -> Server {
    Server::spawn(serve_command(args))
}

#[test]
fn the_module_answers_on_the_device_at_the_rate_of_gp_65_after_a_power_cycle() {
    let mut device = Device::open();
    let server = serve(&["--serial", &device.slave, "--tcp", "127.0.0.1:0"]);
    // TMCM-1141 manual, GP 65: code 0 = 9600 baud, the default.
    assert!(
        server
            .banner
            .iter()
            .any(|l| l == &format!("serial: {} at 9600 baud, 8N1 (host software opens the other end of the line)", device.slave)),
        "{:?}",
        server.banner
    );
    assert_eq!(device.baud(), 9600);
    let r = device.ask("SAP 4, 0, 1000");
    assert_eq!((r.status, r.value), (100, 1000));
    assert_eq!(device.ask("GAP 4, 0").value, 1000);
    // The same module over TCP.
    let mut tcp = server.connect();
    assert_eq!(crate::common::ask(&mut tcp, "GAP 4, 0").unwrap().value, 1000);
    // GP 65 = 7 (115200) is stored at once but takes effect after a power
    // cycle (TMCM-1141 manual §5.1: interface bit rates need one).
    assert_eq!(device.ask("SGP 65, 0, 7").status, 100);
    assert_eq!(device.baud(), 9600);
    // 255 with 1234: the software reset, as a power cycle; its reply goes
    // out first (rule 9).
    assert_eq!(device.ask("#255 0 0 1234").status, 100);
    until("the line at 115200 baud", || device.baud() == 115_200);
    assert_eq!(device.ask("GGP 65, 0").value, 7);
}

#[test]
fn a_fixed_baud_rate_stays_whatever_gp_65_says() {
    let mut device = Device::open();
    let server = serve(&["--serial", &device.slave, "--baud", "57600"]);
    assert!(server.banner.iter().any(|l| l.contains("at 57600 baud")), "{:?}", server.banner);
    assert_eq!(device.baud(), 57600);
    assert_eq!(device.ask("SGP 65, 0, 7").status, 100);
    assert_eq!(device.ask("#255 0 0 1234").status, 100);
    assert_eq!(device.ask("GGP 65, 0").value, 7, "the module is back after its reset");
    assert_eq!(device.baud(), 57600);
}

#[test]
fn a_vanished_device_is_reported_served_again_when_back_and_the_other_links_go_on() {
    let dir = tempfile::tempdir().unwrap();
    let link = dir.path().join("ttyRS485");
    let first = Device::open();
    std::os::unix::fs::symlink(&first.slave, &link).unwrap();
    let link_name = link.display().to_string();
    let server = serve(&["--serial", &link_name, "--tcp", "127.0.0.1:0"]);
    // Unplugged: the device's other side is gone.
    drop(first);
    assert!(server.logged(&[&format!("serial {link_name}: lost (")]).is_some(), "no 'lost' line: {:?}", server.log.lock().unwrap());
    server.check();
    // Plugged in again, as a new device behind the same name.
    let mut second = Device::open();
    replace_link(&link, &second.slave);
    until("the 'back' line", || server.log_has(&format!("serial {link_name}: back")) > 0);
    let r = second.ask("GAP 4, 0");
    assert_eq!((r.status, r.value), (100, 1234), "the module set through TCP while the device was gone");
}

fn replace_link(link: &Path, target: &str) {
    let tmp = link.with_extension("new");
    std::os::unix::fs::symlink(target, &tmp).unwrap();
    std::fs::rename(&tmp, link).unwrap();
}

#[test]
fn a_device_that_cannot_be_opened_or_a_bad_rate_is_refused_with_the_reason() {
    let out = tmclsim(&["serve", "--serial", "/nonexistent/ttyUSB9"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("cannot open the serial device /nonexistent/ttyUSB9"), "{err}");
    let out = tmclsim(&["serve", "--serial", "/nonexistent/ttyUSB9", "--baud", "0"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("0 baud: a serial line runs at 50…12000000 baud"), "{err}");
    let out = tmclsim(&["serve", "--baud", "9600"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("--serial"), "{err}");
}

#[test]
fn a_fleet_link_on_a_serial_device() {
    let mut device = Device::open();
    let dir = tempfile::tempdir().unwrap();
    let fleet = dir.path().join("fleet.toml");
    std::fs::write(
        &fleet,
        format!("[[link]]\nserial = [\"{}\"]\nbaud = 19200\nmodules = [\"tmcm-1141@1\", \"tmcm-1141@2\"]\n", device.slave),
    )
    .unwrap();
    let _server = Server::spawn(serve_command(&["--fleet", fleet.to_str().unwrap()]));
    assert_eq!(device.baud(), 19200);
    // Each module of the bus answers its own address (GP 66).
    let r = device.ask_module(2, "GGP 66, 0");
    assert_eq!((r.module, r.status, r.value), (2, 100, 2));
    let r = device.ask_module(1, "GGP 66, 0");
    assert_eq!((r.module, r.status, r.value), (1, 100, 1));
    std::fs::write(&fleet, format!("[[link]]\nserial = \"{}\"\ncount = 2\nmodules = [\"tmcm-1141@1\"]\n", device.slave)).unwrap();
    let out = tmclsim(&["serve", "--fleet", fleet.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("a serial device is one link: count must be 1"), "{err}");
}
