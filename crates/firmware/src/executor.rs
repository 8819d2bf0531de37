//! The command executor: `execute` takes a command in direct mode (a host
//! sent it) and `run_command` dispatches a decoded command to its family in
//! `commands/`; the program interpreter calls it with `Origin::Program`, so
//! that reads load the accumulator and branch commands are allowed.

use crate::commands::Exec;
use crate::module::Module;
use crate::outcome::{Origin, Outcome, Special};
use tmclsim_protocol::{Command, Instruction, Status, opcode};

/// Key that 137 and 255 require.
pub const MAGIC_KEY: i32 = 1234;

impl Module {
    /// Executes one instruction in direct mode.
    pub fn execute(&mut self, ins: Instruction) -> Outcome {
        if !self.profile.has_opcode(ins.opcode) {
            return Outcome::error(Status::InvalidCommand, ins.value);
        }
        let cmd = match Command::decode(ins) {
            Ok(c) => c,
            Err(e) => return Outcome::error(e.status(), ins.value),
        };
        if cmd.is_program_only() {
            return Outcome::error(Status::NotAvailable, ins.value);
        }
        match cmd {
            Command::FirmwareVersion { binary: false } => {
                return Outcome { status: Status::Ok, value: 0, special: Special::Frame(self.special_version()) };
            }
            Command::StopApplication
            | Command::RunApplication { .. }
            | Command::StepApplication
            | Command::ResetApplication
            | Command::EnterDownload { .. }
            | Command::ExitDownload
            | Command::ReadMemory { .. }
            | Command::ApplicationStatus { .. } => {
                return self.control(cmd).unwrap_or_else(|status| Outcome::error(status, ins.value));
            }
            Command::FactoryDefaults { key } => {
                if key != MAGIC_KEY {
                    return Outcome::error(Status::InvalidValue, key);
                }
                // A locked configuration EEPROM is not erased either
                // (docs/behaviour.md rule 73).
                if self.eeprom_locked() {
                    return Outcome::error(Status::EepromLocked, key);
                }
                self.persistence.eeprom.clear();
                self.persistence.mark_written();
                self.reset();
                return Outcome { status: Status::Ok, value: key, special: Special::Silent };
            }
            _ => {}
        }
        match self.run_command(cmd, ins, Origin::Direct) {
            Ok(value) => Outcome::ok(value),
            Err(status) => Outcome::error(status, ins.value),
        }
    }

    /// Executes a decoded command: hands it to its family (`commands/`);
    /// the parameter commands, the most frequent in a polling program, go
    /// straight to their own methods. The value is what a direct-mode reply
    /// carries.
    pub(crate) fn run_command(&mut self, cmd: Command, ins: Instruction, origin: Origin) -> Exec {
        use Command::*;
        let echo = ins.value;
        match cmd {
            Ror { .. } | Rol { .. } | Mst { .. } | Mvp { .. } | Mvpa { .. } | Rora { .. } | Rola { .. } | Rfs { .. } => {
                self.motion_command(cmd, echo)
            }
            Sap { param, motor, value } => self.set_axis_parameter(param, motor, value).map(|_| echo),
            Aap { param, motor } => self.set_axis_parameter(param, motor, self.registers.accumulator).map(|_| echo),
            Gap { param, motor } => {
                let v = self.get_axis_parameter(param, motor)?;
                Ok(self.loaded(v, origin))
            }
            Stap { param, motor } => self.store_axis_parameter(param, motor).map(|_| echo),
            Rsap { param, motor } => self.restore_axis_parameter(param, motor).map(|_| echo),
            Sgp { param, bank, value } => self.set_global_parameter(param, bank, value).map(|_| echo),
            Agp { param, bank } => self.set_global_parameter(param, bank, self.registers.accumulator).map(|_| echo),
            Ggp { param, bank } => {
                let v = self.get_global_parameter(param, bank)?;
                Ok(self.loaded(v, origin))
            }
            Stgp { param, bank } => self.store_global_parameter(param, bank).map(|_| echo),
            Rsgp { param, bank } => self.restore_global_parameter(param, bank).map(|_| echo),
            Calc { .. }
            | Comp { .. }
            | CalcX { .. }
            | CalcVV { .. }
            | CalcVA { .. }
            | CalcAV { .. }
            | CalcVX { .. }
            | CalcXV { .. }
            | CalcV { .. }
            | Aiv
            | Siv { .. }
            | Giv
            | Cle { .. } => self.calculation_command(cmd, echo, origin),
            Sio { .. } | Gio { .. } | Sac { .. } => self.io_command(cmd, echo, origin),
            Sco { .. } | Gco { .. } | Cco { .. } | Aco { .. } => self.coordinate_command(cmd, echo, origin),
            Ei { .. } | Di { .. } | Vect { .. } | TargetReachedEvent { .. } => self.event_command(cmd, echo),
            FirmwareVersion { binary: true } => Ok(self.profile.version_word()),
            Reset { key } => {
                if key != MAGIC_KEY {
                    return Err(Status::InvalidValue);
                }
                // handle_frame resets after the reply has been built.
                Ok(echo)
            }
            AsciiMode => {
                // The reply goes out in binary; then the link speaks text.
                self.enter_ascii_mode();
                Ok(echo)
            }
            UserFunction { .. } => Err(Status::NotAvailable),
            StopApplication
            | RunApplication { .. }
            | StepApplication
            | ResetApplication
            | EnterDownload { .. }
            | ExitDownload
            | ReadMemory { .. }
            | ApplicationStatus { .. }
            | FirmwareVersion { binary: false }
            | FactoryDefaults { .. } => unreachable!("handled in execute"),
            Jc { .. } | Ja { .. } | Csub { .. } | Rsub | Call { .. } | Djnz { .. } | Rst { .. } | Wait { .. } | Stop | Reti => {
                Err(Status::NotAvailable)
            }
        }
    }
}

/// Frame-level helpers for tests and tools.
pub fn opcode_name(op: u8) -> &'static str {
    opcode::name(op)
}
