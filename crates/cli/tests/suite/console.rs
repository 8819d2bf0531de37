//! `tmclsim console` against a served module, over TCP and the pty, with a
//! script on standard input (as a user pipes one).

use crate::common;

use common::Server;
use std::io::Write;
use std::process::{Command, Stdio};

/// Runs `tmclsim console LINK…` with `script` on stdin; exit code and
/// standard output.
fn console(link: &[&str], script: &str) -> (Option<i32>, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_tmclsim"))
        .arg("console")
        .args(link)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    child.stdin.take().unwrap().write_all(script.as_bytes()).unwrap();
    let o = child.wait_with_output().unwrap();
    (o.status.code(), format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr)))
}

#[test]
fn a_script_over_tcp_names_parameters_and_units() {
    let server = Server::start(&["--tcp", "127.0.0.1:0"]);
    let tcp = server.tcp();
    let script = "SAP maximum_positioning_speed, 0, 1000\nGAP 4, 0\nMVP ABS, 0, 5120\nGAP target_position 0\nhelp GAP\nhelp actual_position\nquit\nGAP 1, 0\n";
    let (code, out) = console(&["--tcp", &tcp], script);
    assert_eq!(code, Some(0), "{out}");
    // The module says what it is (136 type 1); its profile gives names.
    assert!(out.starts_with("TMCM-1141 (firmware V1.46) at address 1 on TCP "), "{out}");
    for line in [
        "> SAP maximum_positioning_speed, 0, 1000\nok: Maximum positioning speed (4) = 1000",
        "> GAP 4, 0\nMaximum positioning speed (4) = 1000",
        "> MVP ABS, 0, 5120\nok\n",
        "> GAP target_position 0\nTarget position (0) = 5120",
        "GAP (instruction 6): GAP TYPE, MOTOR/BANK",
        "AP 1 Actual position (actual_position): access RW, -2147483648…2147483647, default 0",
    ] {
        assert!(out.contains(line), "{line}\n---\n{out}");
    }
    assert!(!out.contains("> GAP 1, 0"), "quit ends the script: {out}");
    server.stop();
}

#[test]
fn errors_are_explained_and_fail_the_script() {
    let server = Server::start(&["--tcp", "127.0.0.1:0"]);
    let (code, out) = console(&["--tcp", &server.tcp()], "GAP 141, 0\nGAPP 1, 0\nGAP actual_postion, 0\nSAP 4, 0, 99999\nGAP 1, 0\n");
    assert_eq!(code, Some(1), "{out}");
    for line in [
        "error 3 (wrong type): the TMCM-1141 has no axis parameter 141",
        "^ column 1: unknown command 'GAPP' (did you mean 'GAP'?)",
        "^ column 5: the TMCM-1141 has no axis parameter 'actual_postion' (did you mean 'actual_position'?)",
        "error 4 (invalid value): Maximum positioning speed takes 1…2047",
        "Actual position (1) = 0",
    ] {
        assert!(out.contains(line), "{line}\n---\n{out}");
    }
    server.stop();
}

#[test]
#[cfg_attr(windows, ignore = "a pty is a Unix device: Windows refuses --pty")]
fn the_pty_and_another_module_type() {
    let dir = tempfile::tempdir().unwrap();
    let pty = dir.path().join("pty");
    let server = Server::start(&["--module", "tmcm-351", "--pty", pty.to_str().unwrap()]);
    let (code, out) = console(&["--port", pty.to_str().unwrap()], "GAP actual_position, 2\nGAP 1, 3\n");
    assert!(out.starts_with("TMCM-351 (firmware V"), "{out}");
    assert!(out.contains("Actual position (1) = 0"), "{out}");
    assert!(out.contains("> GAP 1, 3\nerror 4 (invalid value): the TMCM-351 has motors 0…2"), "{out}");
    assert_eq!(code, Some(1));
    server.stop();
}

#[test]
#[cfg(unix)] // The console on a terminal: a pty (openpty).
fn on_a_terminal_tab_completes_names_and_history_is_kept() {
    use std::io::Read;
    use std::os::fd::{FromRawFd, OwnedFd};
    let server = Server::start(&["--tcp", "127.0.0.1:0"]);
    let home = tempfile::tempdir().unwrap();
    let (mut master, mut slave) = (0, 0);
    // SAFETY: openpty fills two descriptors that this test then owns.
    let rc = unsafe { libc::openpty(&mut master, &mut slave, std::ptr::null_mut(), std::ptr::null(), std::ptr::null()) };
    assert_eq!(rc, 0);
    let (master, slave) = unsafe { (OwnedFd::from_raw_fd(master), OwnedFd::from_raw_fd(slave)) };
    let mut child = Command::new(env!("CARGO_BIN_EXE_tmclsim"))
        .args(["console", "--tcp", &server.tcp()])
        .env("HOME", home.path())
        .env("TERM", "xterm")
        .stdin(Stdio::from(slave.try_clone().unwrap()))
        .stdout(Stdio::from(slave.try_clone().unwrap()))
        .stderr(Stdio::from(slave))
        .spawn()
        .unwrap();
    let mut terminal = std::fs::File::from(master);
    let reader = terminal.try_clone().unwrap();
    let seen = std::sync::Arc::new(std::sync::Mutex::new(String::new()));
    let sink = seen.clone();
    std::thread::spawn(move || {
        let mut reader = reader;
        let mut buf = [0u8; 4096];
        while let Ok(n) = reader.read(&mut buf) {
            if n == 0 {
                break;
            }
            sink.lock().unwrap().push_str(&String::from_utf8_lossy(&buf[..n]));
        }
    });
    let wait_for = |what: &str| {
        let start = std::time::Instant::now();
        while !seen.lock().unwrap().contains(what) {
            assert!(start.elapsed().as_secs() < 10, "no '{what}' in {:?}", seen.lock().unwrap());
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
    };
    wait_for("tmcl> ");
    // Tab completes the parameter's name in place.
    terminal.write_all(b"GAP actual_p\t, 0\r").unwrap();
    wait_for("Actual position (1) = 0");
    terminal.write_all(b"quit\r").unwrap();
    assert!(child.wait().unwrap().success());
    let history = std::fs::read_to_string(home.path().join(".tmclsim_history")).unwrap();
    assert!(history.contains("GAP actual_position, 0\n"), "{history}");
    server.stop();
}

#[test]
fn a_line_past_4096_bytes_is_skipped_unheld_and_fails_the_script() {
    let server = Server::start(&["--tcp", "127.0.0.1:0"]);
    let mut child = Command::new(env!("CARGO_BIN_EXE_tmclsim"))
        .args(["console", "--tcp", &server.tcp()])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    // 256 MiB of one line, then a command.
    let chunk = vec![b'A'; 1 << 20];
    for _ in 0..256 {
        stdin.write_all(&chunk).unwrap();
    }
    // The peak of its resident memory, from /proc (Unix).
    #[cfg(unix)]
    {
        let pid = child.id();
        let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap();
        let peak: u64 = status.lines().find(|l| l.starts_with("VmHWM:")).unwrap().split_whitespace().nth(1).unwrap().parse().unwrap();
        assert!(peak < 64 * 1024, "the line is not held: {peak} KiB at its peak");
    }
    stdin.write_all(b"\nGAP 4, 0\n").unwrap();
    drop(stdin);
    let o = child.wait_with_output().unwrap();
    let out = format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    assert!(out.contains("error: line 1 is longer than 4096 bytes; it was skipped"), "{}", &out[..out.len().min(400)]);
    assert!(out.contains("> GAP 4, 0\nMaximum positioning speed (4) = "), "the next line is served: {out}");
    assert_eq!(o.status.code(), Some(1), "a skipped line fails the script");
}

#[test]
fn comment_lines_are_skipped_and_raw_commands_are_not() {
    let server = Server::start(&["--tcp", "127.0.0.1:0"]);
    let script = "// set the speed first\n# then read it back\n#\nSAP 4, 0, 700\n#6 4 0 0\n";
    let (code, out) = console(&["--tcp", &server.tcp()], script);
    assert_eq!(code, Some(0), "comments are no failures: {out}");
    assert!(out.contains("> #6 4 0 0\nMaximum positioning speed (4) = 700"), "a raw command still runs: {out}");
    server.stop();
}

#[test]
fn the_bootloaders_commands_by_name() {
    let server = Server::start(&["--tcp", "127.0.0.1:0"]);
    let tcp = server.tcp();
    // 242 restarts the module into its bootloader without a reply; it then
    // answers at address 1 (docs/behaviour.md rule 99).
    let script = "help BOOT_GET_INFO\nBOOT_GET_INFO 0\nBOOT_GET_INFO 1\n#136 0 0 0\nBOOT_START_APPL\n";
    let (_, before) = console(&["--tcp", &tcp], "BOOT_GET_INFO 0\n");
    assert!(before.contains("invalid command"), "the firmware has no 206: {before}");
    let mut host = server.connect();
    std::io::Write::write_all(&mut host, &common::frame("#242 129 146 2746533334")).unwrap();
    // On the same connection, after the 242: the bootloader is there.
    std::io::Write::write_all(&mut host, &common::frame("#136 0 0 0")).unwrap();
    let mut text = [0u8; 9];
    std::io::Read::read_exact(&mut host, &mut text).unwrap();
    assert_eq!(&text[1..], b"1141B106");
    let (_, out) = console(&["--tcp", &tcp], script);
    for line in [
        "BOOT_GET_INFO (instruction 206, the bootloader's): BOOT_GET_INFO [TYPE[, MOTOR[, VALUE]]]",
        "> BOOT_GET_INFO 0\nvalue 2048",
        "> BOOT_GET_INFO 1\nvalue 134234112",
        "version 1141B106",
    ] {
        assert!(out.contains(line), "{line}\n---\n{out}");
    }
    server.stop();
}
