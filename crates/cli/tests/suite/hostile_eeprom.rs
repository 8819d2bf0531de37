//! A served module's EEPROM file under hostile conditions: a second
//! server on the same file is refused, a write the file cannot take is
//! not acknowledged as stored while the module keeps serving, a file
//! holding what the module never stores is refused naming the entry
//! (docs/behaviour.md rule 88), a read-only file is served and never
//! replaced, and a file that cannot be read is reported with the error of
//! the system (rule 89).

use crate::common;

use common::{Server, ask};
use std::io::Read;
#[cfg(unix)]
use std::os::unix::fs::{MetadataExt, PermissionsExt};
#[cfg(unix)]
use std::os::unix::process::CommandExt;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};
use tmclsim_firmware::Eeprom;
use tmclsim_server::eeprom_file;

/// A served module keeping its EEPROM in `eeprom`, its stderr collected.
fn start(eeprom: &Path) -> Server {
    Server::start(&["--tcp", "127.0.0.1:0", "--eeprom", eeprom.to_str().unwrap()])
}

/// `tmclsim serve` on `eeprom`, its stdout dropped and stderr piped.
fn serve_on(eeprom: &Path) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_tmclsim"));
    c.args(["serve", "--tcp", "127.0.0.1:0", "--eeprom", eeprom.to_str().unwrap()]).stdout(Stdio::null()).stderr(Stdio::piped());
    c
}

/// Runs `tmclsim serve` on `eeprom` expecting it to give up: its exit
/// status and stderr. A server that serves instead is stopped after 10 s.
fn refused(eeprom: &Path) -> (Option<i32>, String) {
    refused_by(serve_on(eeprom))
}

/// Runs a `tmclsim serve` command expecting it to give up (see [`refused`]).
fn refused_by(mut command: Command) -> (Option<i32>, String) {
    let mut child = command.spawn().unwrap();
    let deadline = Instant::now() + Duration::from_secs(10);
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            panic!("the server started serving: {command:?}");
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
    // Windows' locks are mandatory: the holder's pid in the locked file
    // cannot be read there (Wine reads it), and the message names none.
    let holder = format!("in use by another tmclsim (pid {})", first.child.id());
    let named = |err: &str| err.contains(&holder) || (cfg!(windows) && err.contains("in use by another tmclsim; "));
    assert!(err.contains(&format!("{}: ", path.display())) && named(&err), "{err}");
    // The same file through a symbolic link is the same file (symbolic
    // links on Windows need a privilege: Unix only).
    let link = dir.path().join("link.eeprom");
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(&path, &link).unwrap();
        let (code, err) = refused(&link);
        assert_eq!(code, Some(2), "{err}");
        assert!(err.contains(&format!("{}: ", link.display())) && named(&err), "{err}");
    }

    // The first server was not disturbed: it serves, its file holds its write.
    assert_eq!(ask(&mut s, "SAP 5, 0, 700").unwrap().status, 100);
    assert_eq!(ask(&mut s, "STAP 5, 0").unwrap().status, 100);
    let image = eeprom_file::load(&path).unwrap().unwrap();
    assert_eq!((image.axis(0, 4), image.axis(0, 5)), (Some(1500), Some(700)));
    drop(s);
    drop(first);

    // Once it is gone the file is free again, and through the link too.
    let next = start(if cfg!(unix) { &link } else { &path });
    let mut s = next.connect();
    assert_eq!(ask(&mut s, "GAP 4, 0").unwrap().value, 1500);
    #[cfg(unix)]
    assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
}

#[test]
#[cfg_attr(windows, ignore = "Windows renames no directory while a file in it (the EEPROM file's lock) is open")]
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
    let image = eeprom_file::load(&path).unwrap().unwrap();
    assert_eq!((image.axis(0, 4), image.axis(0, 5)), (Some(1000), Some(300)));
    // A reset powers up from the same EEPROM.
    assert_eq!(ask(&mut s, "#255 0 0 1234").unwrap().status, 100);
    // The restart follows the reply: RAM's 2000 gives way to the
    // EEPROM's 1000 once it is done.
    let deadline = Instant::now() + Duration::from_secs(10);
    let mut seen = Vec::new();
    let mut s = loop {
        let mut s = server.connect();
        let r = ask(&mut s, "GAP 4, 0").map(|r| r.value);
        seen.push(r);
        if r == Some(1000) {
            break s;
        }
        assert!(Instant::now() < deadline, "no restart from the EEPROM within 10 s: GAP 4 read {seen:?}");
        std::thread::sleep(Duration::from_millis(20));
    };
    assert_eq!(ask(&mut s, "GAP 5, 0").unwrap().value, 300);
}

#[test]
fn a_file_with_a_value_the_module_never_stores_is_refused_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    // GP 75 = 2^31 − 1 would delay every reply by 24 days: a module that
    // never answers again. AP 4 = −2^31 is no speed SAP takes.
    for (name, text, entry) in [
        (
            "gp75.eeprom",
            r#"{"format": 1, "module": "TMCM-1141", "axis": {"0/4": 1500}, "global": {"0/75": 2147483647}, "coordinates": {}}"#,
            r#"global "0/75" = 2147483647: GP 75 (Telegram pause time) of bank 0 takes 0…255"#,
        ),
        (
            "ap4.eeprom",
            r#"{"format": 1, "module": "TMCM-1141", "axis": {"0/4": -2147483648}, "global": {}, "coordinates": {}}"#,
            r#"axis "0/4" = -2147483648: AP 4 (Maximum positioning speed) of motor 0 takes 1…2047"#,
        ),
    ] {
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        let (code, err) = refused(&path);
        assert_eq!(code, Some(2), "{err}");
        assert!(err.contains(&format!("tmclsim: {}: refused: an entry a TMCM-1141 never stores", path.display())), "{err}");
        assert!(err.contains(entry) && err.contains("correct or remove it"), "{err}");
        assert_eq!(std::fs::read_to_string(&path).unwrap(), text, "the file is left as it is");
    }
}

#[test]
fn a_read_only_file_is_served_and_never_replaced() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.eeprom");
    let mut image = Eeprom::new("TMCM-1141");
    image.set_axis(0, 4, 1500);
    eeprom_file::save_atomic(&path, &image).unwrap();
    set_read_only(&path, true);
    let before = (std::fs::read(&path).unwrap(), identity(&path));

    // Served from the file, with a warning (whoever runs the server: root
    // may write any file, and still this one is not replaced).
    let server = start(&path);
    assert!(server.banner.iter().any(|l| l.contains("EEPROM: restored from") && l.contains("(read-only")), "{:?}", server.banner);
    let warning = server.logged(&["warning", &path.display().to_string(), READ_ONLY]).expect("a warning at start");
    assert!(warning.contains("answered with status 5"), "{warning}");
    let mut s = server.connect();
    assert_eq!(ask(&mut s, "GAP 4, 0").unwrap().value, 1500);

    // Every EEPROM write is answered with status 5; RAM takes the value.
    assert_eq!(ask(&mut s, "SAP 4, 0, 2000").unwrap().status, 100);
    let r = ask(&mut s, "STAP 4, 0").expect("a reply with a valid checksum");
    assert_eq!((r.status, r.opcode), (5, 7), "STAP on a read-only file");
    let line = server.logged(&["cannot write EEPROM file", READ_ONLY]).expect("a line on stderr");
    assert!(line.contains("tmclsim leaves it as it is") && line.contains("status 5"), "{line}");
    assert_eq!(ask(&mut s, "SGP 75, 0, 10").unwrap().status, 5, "bank 0 is stored by SGP");
    assert_eq!(ask(&mut s, "GAP 4, 0").unwrap().value, 2000);
    assert_eq!(ask(&mut s, "RSAP 4, 0").unwrap().status, 100);
    assert_eq!(ask(&mut s, "GAP 4, 0").unwrap().value, 1500, "the EEPROM is what the file holds");
    assert_eq!((std::fs::read(&path).unwrap(), identity(&path)), before, "the file is the same file, unchanged");
    #[cfg(unix)]
    assert_eq!(std::fs::metadata(&path).unwrap().permissions().mode() & 0o7777, 0o444);
    assert!(std::fs::metadata(&path).unwrap().permissions().readonly());

    // Made writable again, the file takes the next write.
    set_read_only(&path, false);
    assert_eq!(ask(&mut s, "SAP 4, 0, 1800").unwrap().status, 100);
    assert_eq!(ask(&mut s, "STAP 4, 0").unwrap().status, 100);
    assert_eq!(eeprom_file::load(&path).unwrap().unwrap().axis(0, 4), Some(1800));
}

/// How the server says a file is read-only.
const READ_ONLY: &str = if cfg!(unix) { "read-only (mode 0444" } else { "read-only (its read-only attribute is set)" };

/// Makes a file read-only (mode 0444 on Unix, the read-only attribute on
/// Windows), or writable again (0644).
fn set_read_only(path: &Path, read_only: bool) {
    #[cfg(unix)]
    let permissions = std::fs::Permissions::from_mode(if read_only { 0o444 } else { 0o644 });
    #[cfg(not(unix))]
    let permissions = {
        let mut p = std::fs::metadata(path).unwrap().permissions();
        #[allow(clippy::permissions_set_readonly_false)]
        p.set_readonly(read_only);
        p
    };
    std::fs::set_permissions(path, permissions).unwrap();
}

/// What tells a file from another put in its place: its inode.
#[cfg(unix)]
fn identity(path: &Path) -> u64 {
    std::fs::metadata(path).unwrap().ino()
}

/// What tells a file from another put in its place: on Windows, whose
/// file index std does not tell, its last write time.
#[cfg(not(unix))]
fn identity(path: &Path) -> std::time::SystemTime {
    std::fs::metadata(path).unwrap().modified().unwrap()
}

/// The user a test runs a server as to meet permission errors: root may
/// read and write any file, so as root the server runs as `nobody`.
#[cfg(unix)]
fn as_a_user_without_rights(command: &mut Command) {
    // SAFETY: geteuid has no preconditions.
    if unsafe { libc::geteuid() } == 0 {
        command.uid(65534).gid(65534);
    }
}

#[test]
#[cfg(unix)] // Mode bits, ENOTDIR and a server run as another user.
fn a_file_that_cannot_be_read_is_reported_with_the_error_of_the_system() {
    let dir = tempfile::tempdir().unwrap();
    // A path through a regular file: ENOTDIR, whoever runs the server.
    let not_a_dir = dir.path().join("plain");
    std::fs::write(&not_a_dir, "a file").unwrap();
    let path = not_a_dir.join("m.eeprom");
    let (code, err) = refused(&path);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains(&format!("{}: cannot read the EEPROM file: Not a directory", path.display())), "{err}");

    // No permission (EACCES): a directory its user may not enter, and one
    // it may not write (so no lock file can be made beside the file).
    std::fs::set_permissions(dir.path(), std::fs::Permissions::from_mode(0o755)).unwrap();
    let closed = dir.path().join("closed");
    let read_only = dir.path().join("read-only");
    for d in [&closed, &read_only] {
        std::fs::create_dir(d).unwrap();
        eeprom_file::save_atomic(&d.join("m.eeprom"), &Eeprom::new("TMCM-1141")).unwrap();
        std::fs::set_permissions(d.join("m.eeprom"), std::fs::Permissions::from_mode(0o644)).unwrap();
    }
    std::fs::set_permissions(&closed, std::fs::Permissions::from_mode(0o000)).unwrap();
    std::fs::set_permissions(&read_only, std::fs::Permissions::from_mode(0o555)).unwrap();
    let run = |path: &Path| {
        let mut command = serve_on(path);
        as_a_user_without_rights(&mut command);
        refused_by(command)
    };
    let path = closed.join("m.eeprom");
    let (code, err) = run(&path);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains(&format!("{}: cannot read the EEPROM file: Permission denied", path.display())), "{err}");
    let path = read_only.join("m.eeprom");
    let (code, err) = run(&path);
    assert_eq!(code, Some(2), "{err}");
    let lock = read_only.join(".m.eeprom.lock");
    assert!(
        err.contains(&format!("{}: cannot lock the EEPROM file: cannot create {}: Permission denied", path.display(), lock.display())),
        "{err}"
    );
    assert!(!err.contains("No such file"), "{err}");
    for d in [&closed, &read_only] {
        std::fs::set_permissions(d, std::fs::Permissions::from_mode(0o755)).unwrap();
    }
    assert_eq!(eeprom_file::load(&path).unwrap(), Some(Eeprom::new("TMCM-1141")), "nothing was written");
}
