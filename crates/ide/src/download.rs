//! A program's download and its verification, over any way of sending a
//! request (docs/behaviour.md rules 15, 16, 29 and 94): 128 stops the
//! program, 132 enters download mode, every word must be answered with
//! status 101 (stored), then the NOP that TMCL-IDE sends after the last
//! word ([`TRAILER`]), 133 leaves download mode, and 134 reads every word
//! back, which must be the word sent. `tmclsim upload` and the IDE both
//! download through here.

use tmclsim_protocol::{FRAME_LEN, Instruction, Status, mnemonic, opcode};

/// The word TMCL-IDE sends after a program's last word and before 133: a
/// NOP, opcode 0 and every field 0 (docs/behaviour.md rule 94). The module
/// stores it like any word (status 101) at the address after the program;
/// when the program fills the memory it lands past the end and is answered
/// with status 4 (rule 14), which ends nothing: the words are all stored.
pub const TRAILER: Instruction = Instruction::new(0, 0, 0, 0);

/// Why a download stopped.
#[derive(Debug, PartialEq, Eq)]
pub enum DownloadError<E> {
    /// The request could not be made or was not answered.
    Link(E),
    /// A control command (`what`: "stop", "enter download mode", "exit
    /// download mode") was answered with an error status.
    Refused {
        /// The command, in words.
        what: &'static str,
        /// The status answered.
        status: u8,
    },
    /// A word was answered with another status than 101.
    NotStored {
        /// The word's address.
        address: usize,
        /// The word.
        word: Instruction,
        /// The status answered.
        status: u8,
    },
    /// 134 of a word was answered with an error status (code protection).
    Unreadable {
        /// The word's address.
        address: usize,
        /// The status answered.
        status: u8,
    },
    /// A word reads back as another word.
    Differs {
        /// The word's address.
        address: usize,
        /// The word read back.
        stored: Instruction,
        /// The word sent.
        sent: Instruction,
    },
}

impl<E: std::fmt::Display> std::fmt::Display for DownloadError<E> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            DownloadError::Link(e) => write!(f, "{e}"),
            DownloadError::Refused { what, status } => write!(f, "{what}: the module answered status {}", status_words(*status)),
            DownloadError::NotStored { address, word, status } => {
                write!(f, "word {address} ({}) was not stored: status {}", mnemonic::format(*word), status_words(*status))
            }
            DownloadError::Unreadable { address, status } => {
                write!(f, "reading back word {address}: status {} (code protection?)", status_words(*status))
            }
            DownloadError::Differs { address, stored, sent } => {
                write!(f, "word {address} reads back as {}, not {}", mnemonic::format(*stored), mnemonic::format(*sent))
            }
        }
    }
}

/// `4 (invalid value)`.
fn status_words(status: u8) -> String {
    format!("{status} ({})", Status::text(status))
}

/// Downloads `words` from address 0 through `request` (one request to the
/// module at `address`, its raw reply), then [`TRAILER`], and reads the
/// words back. `progress` hears how many of the `2 × words` steps are done
/// (each word sent, each word read back), after every step.
pub fn download_and_verify<E>(
    request: &mut dyn FnMut(Instruction) -> Result<[u8; FRAME_LEN], E>,
    address: u8,
    words: &[Instruction],
    progress: &mut dyn FnMut(usize),
) -> Result<(), DownloadError<E>> {
    control(request, opcode::STOP_APPLICATION, "stop")?;
    control(request, opcode::ENTER_DOWNLOAD, "enter download mode")?;
    for (a, w) in words.iter().enumerate() {
        let raw = request(*w).map_err(DownloadError::Link)?;
        if raw[2] != Status::Loaded.code() {
            let _ = request(Instruction::new(opcode::EXIT_DOWNLOAD, 0, 0, 0));
            return Err(DownloadError::NotStored { address: a, word: *w, status: raw[2] });
        }
        progress(a + 1);
    }
    let raw = request(TRAILER).map_err(DownloadError::Link)?;
    if raw[2] != Status::Loaded.code() && raw[2] != Status::InvalidValue.code() {
        let _ = request(Instruction::new(opcode::EXIT_DOWNLOAD, 0, 0, 0));
        return Err(DownloadError::NotStored { address: words.len(), word: TRAILER, status: raw[2] });
    }
    control(request, opcode::EXIT_DOWNLOAD, "exit download mode")?;
    for (a, w) in words.iter().enumerate() {
        let raw = request(Instruction::new(opcode::READ_MEMORY, 0, 0, a as i32)).map_err(DownloadError::Link)?;
        let stored = crate::reply::memory_word(&raw, address).map_err(|status| DownloadError::Unreadable { address: a, status })?;
        if stored != *w {
            return Err(DownloadError::Differs { address: a, stored, sent: *w });
        }
        progress(words.len() + a + 1);
    }
    Ok(())
}

/// A control command without operands; an error status stops the download.
fn control<E>(
    request: &mut dyn FnMut(Instruction) -> Result<[u8; FRAME_LEN], E>,
    op: u8,
    what: &'static str,
) -> Result<(), DownloadError<E>> {
    let raw = request(Instruction::new(op, 0, 0, 0)).map_err(DownloadError::Link)?;
    if raw[2] < 100 { Err(DownloadError::Refused { what, status: raw[2] }) } else { Ok(()) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tmclsim_firmware::Module;
    use tmclsim_protocol::{Request, mnemonic::parse_line};

    fn words(lines: &[&str]) -> Vec<Instruction> {
        lines.iter().map(|l| parse_line(l).unwrap()).collect()
    }

    #[test]
    fn a_download_is_read_back_word_for_word() {
        let mut m = Module::built_in("tmcm-1141").unwrap();
        let program = words(&["MVP ABS, 0, 51200", "WAIT POS, 0, 0", "STOP"]);
        let mut sent = Vec::new();
        let mut replies = Vec::new();
        let mut request = |ins: Instruction| -> Result<[u8; FRAME_LEN], &str> {
            sent.push(ins);
            let raw = m.handle_frame(&Request::new(1, ins).encode()).ok_or("no reply")?;
            replies.push(raw[2]);
            Ok(raw)
        };
        let mut done = Vec::new();
        assert_eq!(download_and_verify(&mut request, 1, &program, &mut |n| done.push(n)), Ok(()));
        // The words, then the NOP TMCL-IDE sends before 133 (rule 94).
        let opcodes: Vec<u8> = sent.iter().map(|i| i.opcode).collect();
        assert_eq!(opcodes, [128, 132, 4, 27, 28, 0, 133, 134, 134, 134]);
        assert_eq!(sent[5], Instruction::new(0, 0, 0, 0));
        // Every word in download mode, the NOP too, is answered 101.
        assert_eq!(replies[2..6], [101; 4]);
        assert_eq!(done, [1, 2, 3, 4, 5, 6]);
        // The NOP is stored after the program: 135 type 0 points past it.
        let pointer = m.handle_frame(&Request::new(1, Instruction::new(135, 0, 0, 0)).encode()).unwrap();
        assert_eq!(i32::from_be_bytes(pointer[4..8].try_into().unwrap()), 4);
    }

    #[test]
    fn a_program_that_fills_the_memory_has_its_nop_refused_and_is_still_good() {
        // Rule 14: the NOP past the last word answers 4; the words are all
        // stored and read back.
        let mut m = Module::built_in("tmcm-1141").unwrap();
        let mut statuses = Vec::new();
        let mut request = |ins: Instruction| -> Result<[u8; FRAME_LEN], &str> {
            let raw = m.handle_frame(&Request::new(1, ins).encode()).ok_or("no reply")?;
            statuses.push((ins.opcode, raw[2]));
            Ok(raw)
        };
        let full = [vec![parse_line("MST 0").unwrap(); 1023], words(&["STOP"])].concat();
        assert_eq!(download_and_verify(&mut request, 1, &full, &mut |_| ()), Ok(()));
        assert_eq!(statuses[1026], (0, 4), "the NOP after word 1023");
        assert_eq!(statuses[1027], (133, 100));
    }

    #[test]
    fn a_word_past_the_memory_and_code_protection_stop_the_download() {
        // Rule 14: a download that runs past the last word answers 4.
        let mut m = Module::built_in("tmcm-1141").unwrap();
        let mut request =
            |ins: Instruction| -> Result<[u8; FRAME_LEN], &str> { m.handle_frame(&Request::new(1, ins).encode()).ok_or("no reply") };
        let too_long = vec![parse_line("MVP ABS, 0, 1").unwrap(); 1025];
        let e = download_and_verify(&mut request, 1, &too_long, &mut |_| ()).unwrap_err();
        assert_eq!(e, DownloadError::NotStored { address: 1024, word: too_long[0], status: 4 });
        assert_eq!(e.to_string(), "word 1024 (MVP ABS, 0, 1) was not stored: status 4 (invalid value)");

        // Rule 30: GP 81 = 1 protects the program against reading: 134
        // answers 5.
        let mut m = Module::built_in("tmcm-1141").unwrap();
        m.handle_frame(&Request::new(1, parse_line("SGP 81, 0, 1").unwrap()).encode());
        let mut request =
            |ins: Instruction| -> Result<[u8; FRAME_LEN], &str> { m.handle_frame(&Request::new(1, ins).encode()).ok_or("no reply") };
        let e = download_and_verify(&mut request, 1, &words(&["STOP"]), &mut |_| ()).unwrap_err();
        assert_eq!(e, DownloadError::Unreadable { address: 0, status: 5 });
        assert_eq!(e.to_string(), "reading back word 0: status 5 (configuration EEPROM locked) (code protection?)");
    }
}
