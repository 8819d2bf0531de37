//! A `tmclsim serve` process killed (SIGKILL) in the middle of a storm of
//! STAP/STGP always leaves a loadable EEPROM file holding the last
//! acknowledged value or the one in flight.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Child, Command, Stdio};
use std::time::Duration;
use tmclsim_firmware::Eeprom;
use tmclsim_protocol::mnemonic::parse_line;
use tmclsim_protocol::{Reply, Request};

fn spawn(eeprom: &std::path::Path) -> (Child, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_tmclsim"))
        .args(["serve", "--tcp", "127.0.0.1:0", "--eeprom"])
        .arg(eeprom)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut out = BufReader::new(child.stdout.take().unwrap());
    let mut addr = None;
    for _ in 0..20 {
        let mut line = String::new();
        if out.read_line(&mut line).unwrap() == 0 {
            break;
        }
        if let Some(a) = line.trim().strip_prefix("tcp: ") {
            addr = Some(a.to_string());
        }
        if line.starts_with("connect with:") {
            break;
        }
    }
    // Keep draining stdout so the child never blocks on it.
    std::thread::spawn(move || {
        let mut sink = Vec::new();
        let _ = out.read_to_end(&mut sink);
    });
    (child, addr.expect("server printed its tcp endpoint"))
}

fn ask(s: &mut TcpStream, line: &str) -> Option<Reply> {
    s.write_all(&Request::new(1, parse_line(line).unwrap()).encode()).ok()?;
    let mut buf = [0u8; 9];
    s.read_exact(&mut buf).ok()?;
    Reply::decode(&buf)
}

#[test]
fn killed_during_a_store_storm_leaves_a_loadable_file() {
    let dir = std::env::temp_dir().join(format!("tmclsim-kill-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("storm.eeprom");
    let mut seed: u64 = 0x9E37_79B9_7F4A_7C15 ^ std::process::id() as u64;
    let mut counter = 0i32;
    let mut last_acked = None;
    for round in 0..20 {
        let (mut child, addr) = spawn(&path);
        let mut s = TcpStream::connect(&addr).unwrap();
        s.set_read_timeout(Some(Duration::from_secs(2))).unwrap();
        if let Some(v) = last_acked {
            // What was acknowledged before the last kill is there after restart.
            assert_eq!(ask(&mut s, "GGP 10, 2").unwrap().value, v, "round {round}");
        }
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        let kill_after = Duration::from_millis(2 + (seed >> 33) % 40);
        let killer = std::thread::spawn(move || {
            std::thread::sleep(kill_after);
            let _ = child.kill();
            let _ = child.wait();
        });
        let in_flight = loop {
            counter += 1;
            let speed = 1 + counter % 2047;
            let ok = ask(&mut s, &format!("SAP 4, 0, {speed}")).is_some()
                && ask(&mut s, "STAP 4, 0").is_some()
                && ask(&mut s, &format!("SGP 10, 2, {counter}")).is_some()
                && ask(&mut s, "STGP 10, 2").is_some();
            if !ok {
                // The value of this round may or may not have been stored.
                break counter;
            }
            last_acked = Some(counter);
        };
        killer.join().unwrap();
        let image = Eeprom::load(&path).unwrap_or_else(|e| panic!("round {round}: {e}")).expect("file exists");
        let stored = image.global(2, 10);
        let acceptable: Vec<Option<i32>> = last_acked.into_iter().chain([in_flight]).map(Some).collect();
        assert!(stored.is_none() && last_acked.is_none() || acceptable.contains(&stored), "round {round}: {stored:?} not in {acceptable:?}");
        // The acknowledged value is the one the next start must see.
        if stored != last_acked {
            last_acked = stored;
        }
        let names: Vec<_> = std::fs::read_dir(&dir).unwrap().filter_map(|e| e.ok()).map(|e| e.file_name()).collect();
        assert!(names.len() <= 2, "stray temporary files: {names:?}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
