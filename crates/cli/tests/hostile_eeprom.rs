//! A served module's EEPROM file under hostile conditions: a second
//! server on the same file is refused, and a write the file cannot take
//! is not acknowledged as stored while the module keeps serving.

mod common;

use common::{Server, ask};
use std::io::Read;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};
use tmclsim_firmware::Eeprom;

/// A served module keeping its EEPROM in `eeprom`, its stderr collected.
fn start(eeprom: &Path) -> Server {
    Server::start(&["--tcp", "127.0.0.1:0", "--eeprom", eeprom.to_str().unwrap()])
}

/// Runs `tmclsim serve` on `eeprom` expecting it to give up: its exit
/// status and stderr. A server that serves instead is stopped after 10 s.
fn refused(eeprom: &Path) -> (Option<i32>, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_tmclsim"))
        .args(["serve", "--tcp", "127.0.0.1:0", "--eeprom", eeprom.to_str().unwrap()])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let deadline = Instant::now() + Duration::from_secs(10);
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            panic!("a second server on {} started serving", eeprom.display());
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let mut err = String::new();
    child.stderr.take().unwrap().read_to_string(&mut err).unwrap();
    (status.code(), err)
}

#[test]
fn a_second_server_on_the_same_file_is_refused_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.eeprom");
    let first = start(&path);
    let mut s = first.connect();
    assert_eq!(ask(&mut s, "SAP 4, 0, 1500").unwrap().status, 100);
    assert_eq!(ask(&mut s, "STAP 4, 0").unwrap().status, 100);

    let (code, err) = refused(&path);
    assert_eq!(code, Some(2), "{err}");
    let holder = format!("in use by another tmclsim (pid {})", first.child.id());
    assert!(err.contains(&format!("{}: ", path.display())) && err.contains(&holder), "{err}");
    // The same file through a symbolic link is the same file.
    let link = dir.path().join("link.eeprom");
    std::os::unix::fs::symlink(&path, &link).unwrap();
    let (code, err) = refused(&link);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains(&format!("{}: ", link.display())) && err.contains(&holder), "{err}");

    // The first server was not disturbed: it serves, its file holds its write.
    assert_eq!(ask(&mut s, "SAP 5, 0, 700").unwrap().status, 100);
    assert_eq!(ask(&mut s, "STAP 5, 0").unwrap().status, 100);
    let image = Eeprom::load(&path).unwrap().unwrap();
    assert_eq!((image.axis(0, 4), image.axis(0, 5)), (Some(1500), Some(700)));
    drop(s);
    drop(first);

    // Once it is gone the file is free again, and through the link too.
    let next = start(&link);
    let mut s = next.connect();
    assert_eq!(ask(&mut s, "GAP 4, 0").unwrap().value, 1500);
    assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
}

#[test]
fn a_write_the_file_cannot_take_is_answered_with_status_5_and_serving_goes_on() {
    let dir = tempfile::tempdir().unwrap();
    let store = dir.path().join("store");
    std::fs::create_dir(&store).unwrap();
    let path = store.join("m.eeprom");
    let server = start(&path);
    let mut s = server.connect();
    assert_eq!(ask(&mut s, "SAP 4, 0, 1000").unwrap().status, 100);
    assert_eq!(ask(&mut s, "STAP 4, 0").unwrap().status, 100);

    // The directory is moved away and a file put in its place: no file
    // can be created there any more, whoever the server runs as.
    let away = dir.path().join("away");
    std::fs::rename(&store, &away).unwrap();
    std::fs::write(&store, "not a directory").unwrap();
    assert_eq!(ask(&mut s, "SAP 4, 0, 2000").unwrap().status, 100);
    let r = ask(&mut s, "STAP 4, 0").expect("a reply with a valid checksum");
    assert_eq!((r.status, r.opcode), (5, 7), "STAP that was not stored");
    let line = server.logged(&["cannot write EEPROM file", &path.display().to_string()]).expect("a line on stderr");
    assert!(line.contains("Not a directory") && line.contains("status 5"), "{line}");
    // The module serves on: RAM keeps the value, the EEPROM does not.
    let r = ask(&mut s, "GAP 4, 0").unwrap();
    assert_eq!((r.status, r.value), (100, 2000));
    let r = ask(&mut s, "RSAP 4, 0").unwrap();
    assert_eq!(r.status, 100);
    assert_eq!(ask(&mut s, "GAP 4, 0").unwrap().value, 1000, "RSAP restores what the file holds");

    // Repaired: the next write is stored, and the file has the earlier
    // value, not the one that was refused.
    std::fs::remove_file(&store).unwrap();
    std::fs::rename(&away, &store).unwrap();
    assert_eq!(ask(&mut s, "SAP 4, 0, 2000").unwrap().status, 100);
    assert_eq!(ask(&mut s, "SAP 5, 0, 300").unwrap().status, 100);
    assert_eq!(ask(&mut s, "STAP 5, 0").unwrap().status, 100);
    let image = Eeprom::load(&path).unwrap().unwrap();
    assert_eq!((image.axis(0, 4), image.axis(0, 5)), (Some(1000), Some(300)));
    // A reset powers up from the same EEPROM.
    assert_eq!(ask(&mut s, "#255 0 0 1234").unwrap().status, 100);
    std::thread::sleep(Duration::from_millis(50));
    let mut s = server.connect();
    assert_eq!(ask(&mut s, "GAP 4, 0").unwrap().value, 1000);
    assert_eq!(ask(&mut s, "GAP 5, 0").unwrap().value, 300);
}
