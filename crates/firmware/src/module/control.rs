//! Direct mode: a host's command. The control commands (128–139, 255)
//! are a host's only: stop, run, step and reset the program; enter and
//! leave download mode and store words in it; read program memory and the
//! application status; the version, factory defaults, 138 events, ASCII
//! mode and reset. Every other command goes to the one dispatch
//! (`executor.rs`), as a program's instructions do. Also the same program
//! operations for tools.

use crate::module::Module;
use crate::outcome::{Origin, Outcome, Special};
use crate::parameter_numbers::gp;
use crate::program::RunMode;
use tmclsim_protocol::frame::version_string_reply;
use tmclsim_protocol::{Command, FRAME_LEN, Instruction, Status, opcode};

/// Key that 137 and 255 require.
pub(crate) const MAGIC_KEY: i32 = 1234;

impl Module {
    /// Executes one instruction in direct mode.
    pub fn execute(&mut self, ins: Instruction) -> Outcome {
        if let Some(answer) = self.boot_command(ins) {
            return answer;
        }
        if !self.profile.has_opcode(ins.opcode) {
            return Outcome::error(Status::InvalidCommand, ins.value);
        }
        let cmd = match Command::decode(ins) {
            Ok(c) => c,
            Err(e) => return Outcome::error(e.status(), ins.value),
        };
        let outcome =
            if opcode::is_control(ins.opcode) { self.control(cmd, ins) } else { self.dispatch(cmd, ins, Origin::Direct, self.now_ns) };
        outcome.unwrap_or_else(|status| Outcome::error(status, ins.value))
    }

    /// A control command (128–139, 255), the one match over them. The
    /// value of the outcome is what the reply carries.
    fn control(&mut self, cmd: Command, ins: Instruction) -> Result<Outcome, Status> {
        use Command::*;
        let echo = ins.value;
        let value = match cmd {
            // ----- the program: 128–135 -----------------------------------
            StopApplication => {
                self.program.stop_application();
                0
            }
            RunApplication { from } => self.run_application(from)?,
            StepApplication => {
                self.step_application();
                0
            }
            ResetApplication => {
                self.program.reset_application();
                self.registers = Default::default();
                0
            }
            EnterDownload { address } => self.enter_download(address)?,
            ExitDownload => {
                if self.program.exit_download() {
                    // The downloaded words are in the EEPROM image; save it.
                    self.persistence.mark_written();
                }
                0
            }
            ReadMemory { address } => {
                let stored = self.read_memory(address)?;
                let frame = tmclsim_protocol::frame::memory_reply(self.host_address(), stored);
                return Ok(Outcome { status: Status::Ok, value: address, special: Special::Frame(frame) });
            }
            ApplicationStatus { kind } => self.application_status(kind),

            // ----- the module: 136–139, 255 -------------------------------
            FirmwareVersion { binary: true } => self.profile.version_word_for(self.firmware_version()),
            FirmwareVersion { binary: false } => {
                return Ok(Outcome { status: Status::Ok, value: 0, special: Special::Frame(self.special_version()) });
            }
            FactoryDefaults { key } => {
                if key != MAGIC_KEY {
                    return Err(Status::InvalidValue);
                }
                // A locked configuration EEPROM is not erased either
                // (docs/behaviour.md rule 73).
                self.persistence.factory_defaults(&self.globals)?;
                self.reset();
                return Ok(Outcome { status: Status::Ok, value: key, special: Special::Silent });
            }
            Reset { key } => {
                if key != MAGIC_KEY {
                    return Err(Status::InvalidValue);
                }
                // handle_frame resets after the reply has been built.
                echo
            }
            TargetReachedEvent { every_move, mask } => self.interrupts.arm_events(every_move, mask, self.axes.len())?,
            AsciiMode => {
                // The reply goes out in binary; then the link speaks text.
                self.link.enter_ascii_mode();
                echo
            }
            // Not a control command: `execute` dispatches those.
            _ => return Err(Status::InvalidCommand),
        };
        Ok(Outcome::ok(value))
    }

    /// 136 type 0: the version text as a frame.
    pub(crate) fn special_version(&self) -> [u8; FRAME_LEN] {
        version_string_reply(self.host_address(), &self.profile.version_text_for(self.firmware_version()))
    }

    /// 129: runs the program, from `from` when given; the reply carries it.
    pub(crate) fn run_application(&mut self, from: Option<i32>) -> Result<i32, Status> {
        if let Some(address) = from {
            self.program.run_from(address)?;
        }
        self.start_program();
        Ok(from.unwrap_or(0))
    }

    /// 130: executes one instruction now.
    pub(crate) fn step_application(&mut self) {
        self.program.step_mode(self.now_ns);
        self.step_program();
    }

    /// 132: download mode, unless the code protection (GP 81) or the
    /// EEPROM lock forbids writing the program.
    pub(crate) fn enter_download(&mut self, address: i32) -> Result<i32, Status> {
        if matches!(self.globals[0][gp::CODE_PROTECTION as usize], 2 | 3) || self.persistence.locked(&self.globals) {
            return Err(Status::EepromLocked);
        }
        self.program.enter_download(address)?;
        Ok(address)
    }

    /// 134: the word at `address` of the program memory.
    pub(crate) fn read_memory(&self, address: i32) -> Result<Instruction, Status> {
        self.program.read(address, matches!(self.globals[0][gp::CODE_PROTECTION as usize], 1 | 3))
    }

    /// 135: the program's status word (types 0, 1), the accumulator (2)
    /// or the X register (3).
    pub(crate) fn application_status(&self, kind: u8) -> i32 {
        match kind {
            0 | 1 => self.program.status_word(kind),
            2 => self.registers.accumulator,
            _ => self.registers.x,
        }
    }

    /// Stores a word in download mode (status 101), docs/behaviour.md rule 15.
    pub(crate) fn download_word(&mut self, ins: Instruction) -> Outcome {
        match self.program.store_download(ins) {
            Ok(address) => {
                // Each word is in the EEPROM when it is acknowledged, as on the module.
                self.persistence.store_program_word(address, ins);
                Outcome { status: Status::Loaded, value: ins.value, special: Special::None }
            }
            Err(status) => Outcome::error(status, ins.value),
        }
    }

    /// Loads a program into memory from address 0 (as a download would)
    /// and stores it in the EEPROM.
    pub fn load_program(&mut self, words: &[Instruction]) -> Result<(), Status> {
        self.program.load(words)?;
        self.persistence.store_program(words);
        Ok(())
    }

    /// Starts (or continues) the program as 129 does.
    pub fn start_program(&mut self) {
        // A program paused at a breakpoint resumes with that instruction.
        self.program.mode = RunMode::Run;
        self.program.next_ns = self.program.next_ns.max(self.now_ns);
    }

    /// Pauses the program (step mode), as a debugger does.
    pub fn pause_program(&mut self) {
        self.program.pause();
    }
}

#[cfg(test)]
mod tests {
    use crate::program::RunMode;
    use crate::test_support::{direct, module, ok, status};
    use tmclsim_protocol::mnemonic::parse_line;
    use tmclsim_protocol::{Instruction, Reply, Status};

    fn program(lines: &[&str]) -> Vec<Instruction> {
        lines.iter().map(|l| parse_line(l).unwrap()).collect()
    }

    #[test]
    fn download_stores_words_in_memory_and_eeprom() {
        let mut m = module("tmcm-1141");
        assert_eq!(direct(&mut m, "#132 0 0 10"), (Status::Ok, 10));
        assert_eq!(ok(&mut m, "GGP 129, 0"), 1, "download mode");
        let written = m.eeprom_generation();
        let word = parse_line("MVP ABS, 0, 1000").unwrap();
        let o = m.download_word(word);
        assert_eq!((o.status, o.value), (Status::Loaded, 1000));
        assert_eq!(m.program.memory[10], word);
        assert_eq!(m.eeprom().program.get(&10), Some(&word.to_bytes()));
        assert_eq!(m.eeprom_generation(), written + 1, "each word is written at once");
        assert_eq!(ok(&mut m, "#135 0 0 0") & 0xFFFF, 11, "135 type 0: the download pointer");
        ok(&mut m, "#133 0 0 0");
        assert_eq!(ok(&mut m, "GGP 129, 0"), 0);
        assert_eq!(m.download_word(word).status, Status::NotAvailable, "not in download mode");
        assert_eq!(status(&mut m, "#132 0 0 2048"), Status::InvalidValue, "outside program memory");
    }

    #[test]
    fn read_memory_134_answers_with_the_stored_word() {
        let mut m = module("tmcm-1141");
        let words = program(&["SAP 4, 0, 500", "STOP"]);
        m.load_program(&words).unwrap();
        let o = m.execute(parse_line("#134 0 0 0").unwrap());
        let crate::outcome::Special::Frame(frame) = o.special else { panic!("134 answers with a frame") };
        assert_eq!(frame[1..8], words[0].to_bytes(), "the seven bytes of the word");
        assert_eq!(status(&mut m, "#134 0 0 -1"), Status::InvalidValue);
    }

    #[test]
    fn run_step_stop_and_reset() {
        let mut m = module("tmcm-1141");
        m.load_program(&program(&["CALC LOAD, 1", "CALC ADD, 1", "CALC ADD, 1", "JA 1"])).unwrap();
        ok(&mut m, "#130 0 0 0");
        assert_eq!((m.program.mode, m.program.pc, m.registers.accumulator), (RunMode::Step, 1, 1), "130 runs one instruction");
        ok(&mut m, "#130 0 0 0");
        assert_eq!((m.program.pc, m.registers.accumulator), (2, 2));
        assert_eq!(direct(&mut m, "#129 1 0 3"), (Status::Ok, 3), "run from address 3");
        assert_eq!((m.program.mode, m.program.pc), (RunMode::Run, 3));
        m.advance(1_000_000);
        assert!(m.registers.accumulator > 2);
        ok(&mut m, "#128 0 0 0");
        assert_eq!(m.program.mode, RunMode::Stop);
        ok(&mut m, "#131 0 0 0");
        assert_eq!((m.program.mode, m.program.pc, m.registers.accumulator), (RunMode::Reset, 0, 0), "131 clears the registers");
        ok(&mut m, "#128 0 0 0");
        assert_eq!(m.program.mode, RunMode::Reset, "128 leaves a reset program alone");
        assert_eq!(status(&mut m, "#129 1 0 5000"), Status::InvalidValue);
    }

    #[test]
    fn a_step_that_ends_a_wait_executes_nothing_more() {
        let mut m = module("tmcm-1141");
        m.load_program(&program(&["WAIT TICKS, 0, 2", "CALC LOAD, 7", "CALC ADD, 1", "STOP"])).unwrap();
        ok(&mut m, "#130 0 0 0");
        assert!(m.program.wait.is_some(), "the WAIT waits 20 ms");
        assert_eq!(ok(&mut m, "#135 1 0 0") & 0xFFFF, 0, "the counter stands on the WAIT");
        ok(&mut m, "#130 0 0 0");
        assert!(m.program.wait.is_some(), "a step before its time executes nothing");
        m.advance(30_000_000);
        ok(&mut m, "#130 0 0 0");
        assert!(m.program.wait.is_none(), "the step ends the WAIT");
        assert_eq!((m.program.pc, m.registers.accumulator), (1, 0), "and stops on the instruction after it (rule 31)");
        ok(&mut m, "#130 0 0 0");
        assert_eq!((m.program.pc, m.registers.accumulator), (2, 7), "which the next step executes");
    }

    #[test]
    fn application_status_135() {
        let mut m = module("tmcm-1141");
        m.load_program(&program(&["WAIT TICKS, 0, 100", "STOP"])).unwrap();
        ok(&mut m, "#129 0 0 0");
        m.advance(1_000_000);
        let word = ok(&mut m, "#135 1 0 0");
        assert_eq!((word >> 24, (word >> 16) & 0xFF, word & 0xFFFF), (RunMode::Run as i32, 1, 0), "mode, waiting, pc held at the WAIT");
        assert_eq!(ok(&mut m, "GGP 130, 0"), 0, "GP 130 too");
        m.advance(1_000_000_000);
        let word = ok(&mut m, "#135 1 0 0");
        assert_eq!((word >> 24, (word >> 16) & 0xFF, word & 0xFFFF), (RunMode::Stop as i32, 0, 2), "after the WAIT and STOP");
        ok(&mut m, "CALC LOAD, -9");
        assert_eq!(ok(&mut m, "#135 2 0 0"), -9, "type 2: the accumulator");
        ok(&mut m, "CALCX LOAD");
        assert_eq!(ok(&mut m, "#135 3 0 0"), -9, "type 3: X");
    }

    #[test]
    fn code_protection_locks_download_and_read() {
        let mut m = module("tmcm-1141");
        m.load_program(&program(&["STOP"])).unwrap();
        ok(&mut m, "SGP 81, 0, 3");
        assert_eq!(status(&mut m, "#132 0 0 0"), Status::EepromLocked);
        assert_eq!(status(&mut m, "#134 0 0 0"), Status::EepromLocked);
        ok(&mut m, "SGP 81, 0, 0");
        assert_eq!(m.program.length(), 0, "lifting the read protection erases the program");
    }

    #[test]
    fn control_commands_in_a_frame_are_answered_in_download_mode() {
        let mut m = module("tmcm-1141");
        ok(&mut m, "#132 0 0 0");
        let f = tmclsim_protocol::Request::new(1, parse_line("#135 0 0 0").unwrap()).encode();
        let r = Reply::decode(&m.handle_frame(&f).unwrap()).unwrap();
        assert_eq!(r.status, Status::Ok.code(), "135 is not stored");
    }
}
