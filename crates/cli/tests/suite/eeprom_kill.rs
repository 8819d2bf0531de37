//! A `tmclsim serve` process killed (SIGKILL) at random moments in storms of
//! STAP, STGP and program downloads, hundreds of times, always leaves a
//! loadable EEPROM file in which every cell holds either its last
//! acknowledged value or the one in flight, and the next start serves
//! exactly what the file holds.

use crate::common;

use common::ask;

use std::net::TcpStream;
use std::process::{Child, Stdio};
use std::time::Duration;
use tmclsim_protocol::Instruction;
use tmclsim_server::eeprom_file;

fn spawn(eeprom: &std::path::Path) -> (Child, String) {
    common::serve(&["--eeprom", eeprom.to_str().unwrap()], Stdio::null())
}

/// One EEPROM cell under test: what was last acknowledged and what was
/// sent without an acknowledgement when the process died.
#[derive(Clone, Copy, Default, Debug)]
struct Cell {
    acked: Option<i32>,
    in_flight: Option<i32>,
}

impl Cell {
    /// The stored value after a kill must be the old or the new one.
    fn settle(&mut self, stored: Option<i32>, what: &str, round: usize) {
        let ok = stored == self.acked || (stored.is_some() && stored == self.in_flight);
        assert!(ok, "round {round}: {what} holds {stored:?}, expected {:?} or {:?}", self.acked, self.in_flight);
        self.acked = stored;
        self.in_flight = None;
    }
}

/// The cells: AP 4 of motor 0 (STAP, a speed), GP 10 of bank 2 (STGP), and
/// program words 0 and 1 (downloads). Every value written differs from the
/// one before (a counter), so old and new can always be told apart.
#[derive(Default)]
struct Cells {
    axis: Cell,
    global: Cell,
    word: [Cell; 2],
}

/// Sends one step of the storm; false when the process is gone.
fn storm_step(s: &mut TcpStream, cells: &mut Cells, counter: i32, download: bool) -> bool {
    let store = |s: &mut TcpStream, cell: &mut Cell, value: i32, lines: &[String]| -> bool {
        cell.in_flight = Some(value);
        let done = lines.iter().all(|l| ask(s, l).is_some());
        if done {
            cell.acked = Some(value);
            cell.in_flight = None;
        }
        done
    };
    if download {
        if ask(s, "#132 0 0 0").is_none() {
            return false;
        }
        for w in 0..2 {
            // The word itself is the cell: SGP 10, 2, counter at address w.
            if !store(s, &mut cells.word[w], counter, &[format!("SGP 10, 2, {counter}")]) {
                return false;
            }
        }
        ask(s, "#133 0 0 0").is_some()
    } else {
        let speed = 1 + counter % 2047;
        store(s, &mut cells.axis, speed, &[format!("SAP 4, 0, {speed}"), "STAP 4, 0".into()])
            && store(s, &mut cells.global, counter, &[format!("SGP 10, 2, {counter}"), "STGP 10, 2".into()])
    }
}

#[test]
fn killed_during_store_and_download_storms_leaves_old_or_new_values() {
    let dir = std::env::temp_dir().join(format!("tmclsim-kill-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("storm.eeprom");
    let mut seed: u64 = 0x9E37_79B9_7F4A_7C15 ^ u64::from(std::process::id());
    let mut counter = 0i32;
    let mut cells = Cells::default();
    let rounds = 300;
    for round in 0..rounds {
        let (mut child, addr) = spawn(&path);
        let mut s = TcpStream::connect(&addr).unwrap();
        s.set_read_timeout(Some(Duration::from_secs(2))).unwrap();
        // The restarted module serves what the file holds.
        if let Some(v) = cells.global.acked {
            assert_eq!(ask(&mut s, "GGP 10, 2").unwrap().value, v, "round {round}: GP 10 after restart");
        }
        if let Some(v) = cells.axis.acked {
            assert_eq!(ask(&mut s, "GAP 4, 0").unwrap().value, v, "round {round}: AP 4 after restart");
        }
        for (w, cell) in cells.word.iter().enumerate() {
            if let Some(v) = cell.acked {
                let word = ask(&mut s, &format!("#134 0 0 {w}")).unwrap();
                assert_eq!(word.value, v, "round {round}: program word {w} after restart");
            }
        }
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        let kill_after = Duration::from_micros(500 + (seed >> 33) % 30_000);
        let download = round % 2 == 1;
        let killer = std::thread::spawn(move || {
            // About time: the kill lands at a random moment of the run.
            std::thread::sleep(kill_after);
            let _ = child.kill();
            let _ = child.wait();
        });
        loop {
            counter += 1;
            if !storm_step(&mut s, &mut cells, counter, download) {
                break;
            }
        }
        killer.join().unwrap();
        let image = eeprom_file::load(&path).unwrap_or_else(|e| panic!("round {round}: {e}")).expect("file exists");
        cells.axis.settle(image.axis(0, 4), "AP 4", round);
        cells.global.settle(image.global(2, 10), "GP 10", round);
        for (w, cell) in cells.word.iter_mut().enumerate() {
            let word = image.program.get(&(w as u16)).map(|b| Instruction::from_bytes(b).value);
            cell.settle(word, &format!("program word {w}"), round);
        }
        // The file, its lock, and at most the temporary file of the save
        // the kill interrupted (the next start removes it).
        let names: Vec<_> = std::fs::read_dir(&dir).unwrap().filter_map(Result::ok).map(|e| e.file_name()).collect();
        let temporaries = names.iter().filter(|n| n.to_string_lossy().ends_with(".tmp")).count();
        assert!(names.len() <= 3 && temporaries <= 1, "stray temporary files: {names:?}");
    }
    assert!(cells.word[1].acked.is_some() && cells.global.acked.is_some(), "the storms stored something");
    std::fs::remove_dir_all(&dir).unwrap();
}
