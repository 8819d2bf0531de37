//! The command executor: `execute` takes a command in direct mode (a host
//! sent it), the interpreter (`interpreter.rs`) one of a program, and both
//! hand the decoded command to [`Module::dispatch`], the one place a
//! command is matched. Each arm goes to the part of the module that owns
//! the command's family: the I/O (`state/io.rs`), the registers and user
//! variables (`state/calculator.rs`), the interrupts (`state/interrupts.rs`),
//! the EEPROM (`state/persistence.rs`), the program (`program.rs`); the
//! families that need more than one part are coordinated in `commands/`.

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
        self.dispatch(cmd, ins, Origin::Direct, self.now_ns).unwrap_or_else(|status| Outcome::error(status, ins.value))
    }

    /// Executes a decoded command, reached by `origin` at virtual time
    /// `at`: the one match over the commands. The branch commands are a
    /// program's only (in direct mode: status 5); the control commands
    /// (128–139, 255) never reach here from a program, which refuses them
    /// by opcode before decoding. A read loads the accumulator in a program
    /// only (docs/behaviour.md rules 7, 18). The value of the outcome is
    /// what a direct-mode reply carries.
    pub(crate) fn dispatch(&mut self, cmd: Command, ins: Instruction, origin: Origin, at: u64) -> Result<Outcome, Status> {
        use Command::*;
        let echo = ins.value;
        let accumulator = self.registers.accumulator;
        let value = match cmd {
            // ----- the program's control flow (program.rs) --------------
            Ja { .. } | Jc { .. } | Csub { .. } | Rsub | Call { .. } | Djnz { .. } | Rst { .. } | Wait { .. } | Stop | Reti
                if origin == Origin::Direct =>
            {
                return Err(Status::NotAvailable);
            }
            Ja { address } => self.program.jump(address).map(|_| echo)?,
            Jc { condition, address } => self.program.jump_if(self.registers.holds(condition), address).map(|_| echo)?,
            Csub { address } => self.program.call_if(true, address).map(|_| echo)?,
            Call { condition, address } => self.program.call_if(self.registers.holds(condition), address).map(|_| echo)?,
            Rsub => {
                self.program.return_from_subroutine();
                echo
            }
            Djnz { var, address } => self.decrement_and_jump(var, address).map(|_| echo)?,
            Rst { address } => {
                let a = self.program.target(address)?;
                self.program.restart_at(a);
                self.registers = Default::default();
                echo
            }
            Stop => {
                self.program.stop();
                echo
            }
            Reti => {
                if let Some(registers) = self.program.return_from_interrupt() {
                    self.registers = registers;
                }
                echo
            }
            Wait { condition, motor, ticks } => self.start_wait(condition, motor, ticks, at).map(|_| echo)?,

            // ----- motion (commands/motion.rs) --------------------------
            Ror { motor, velocity } => self.rotate_group(motor, velocity, 1).map(|_| echo)?,
            Rol { motor, velocity } => self.rotate_group(motor, velocity, -1).map(|_| echo)?,
            Rora { motor } => {
                let m = self.motor(motor)?;
                self.axes[m].rotate(accumulator, 1).map(|_| echo)?
            }
            Rola { motor } => {
                let m = self.motor(motor)?;
                self.axes[m].rotate(accumulator, -1).map(|_| echo)?
            }
            Mst { motor } => self.stop_group(motor).map(|_| echo)?,
            Mvp { mode, motor, value } => self.move_group(mode, motor, value).map(|_| echo)?,
            Mvpa { mode, motor } => self.move_to(mode, motor, accumulator).map(|_| echo)?,
            Rfs { action, motor } => self.reference_search_command(action, motor)?.unwrap_or(echo),

            // ----- parameters (commands/parameters.rs) ------------------
            Sap { param, motor, value } => self.set_axis_parameter(param, motor, value).map(|_| echo)?,
            Aap { param, motor } => self.set_axis_parameter(param, motor, accumulator).map(|_| echo)?,
            Gap { param, motor } => {
                let v = self.get_axis_parameter(param, motor)?;
                self.loaded(v, origin)
            }
            Stap { param, motor } => self.store_axis_parameter(param, motor).map(|_| echo)?,
            Rsap { param, motor } => self.restore_axis_parameter(param, motor).map(|_| echo)?,
            Sgp { param, bank, value } => self.set_global_parameter(param, bank, value).map(|_| echo)?,
            Agp { param, bank } => self.set_global_parameter(param, bank, accumulator).map(|_| echo)?,
            Ggp { param, bank } => {
                let v = self.get_global_parameter(param, bank)?;
                self.loaded(v, origin)
            }
            Stgp { param, bank } => self.store_global_parameter(param, bank).map(|_| echo)?,
            Rsgp { param, bank } => self.restore_global_parameter(param, bank).map(|_| echo)?,

            // ----- calculation: the registers and user variables --------
            Calc { op, value } => self.calculator().calc(op, value).map(|_| echo)?,
            Comp { value } => {
                self.calculator().comp(value);
                echo
            }
            CalcX { op } => self.calculator().calc_x(op).map(|_| echo)?,
            CalcVV { op, var1, var2 } => self.calculator().calc_vv(op, var1, var2).map(|_| echo)?,
            CalcVA { op, var } => self.calculator().calc_va(op, var).map(|_| echo)?,
            CalcAV { op, var } => self.calculator().calc_av(op, var).map(|_| echo)?,
            CalcVX { op, var } => self.calculator().calc_vx(op, var).map(|_| echo)?,
            CalcXV { op, var } => self.calculator().calc_xv(op, var).map(|_| echo)?,
            CalcV { op, var, value } => self.calculator().calc_v(op, var, value).map(|_| echo)?,
            Siv { value } => {
                self.calculator().set_indexed(value);
                echo
            }
            Aiv => {
                self.calculator().set_indexed(accumulator);
                echo
            }
            Giv => match self.calculator().indexed() {
                Some(v) => self.loaded(v, origin),
                None => echo,
            },
            Cle { flag } => {
                self.registers.clear_errors(flag);
                echo
            }

            // ----- I/O (state/io.rs) -------------------------------------
            Sio { port, bank, value } => self.io.set_port(&self.profile, port, bank, value, accumulator).map(|_| echo)?,
            Gio { port, bank } => {
                let v = self.io.read_port(&self.profile, &self.world, port, bank)?;
                self.loaded(v, origin)
            }
            Sac { bus, count, value } => self.io.spi_transfer(bus, count, value)?,

            // ----- coordinates (commands/coordinates.rs) -----------------
            Sco { coordinate, motor, value } => self.set_coordinate(coordinate, motor, value).map(|_| echo)?,
            Aco { coordinate, motor } => self.set_coordinate(coordinate, motor, accumulator).map(|_| echo)?,
            Cco { coordinate, motor } => self.capture_coordinate(coordinate, motor)?,
            Gco { coordinate, motor: 255 } => self.coordinates_from_eeprom(coordinate).map(|_| echo)?,
            Gco { coordinate, motor } => {
                let v = self.coordinate(coordinate, motor)?;
                self.loaded(v, origin)
            }

            // ----- interrupts and events (state/interrupts.rs) ----------
            Ei { interrupt } => self.interrupts.enable(&self.profile, interrupt, true).map(|_| echo)?,
            Di { interrupt } => self.interrupts.enable(&self.profile, interrupt, false).map(|_| echo)?,
            Vect { interrupt, address } => self.interrupts.set_vector(&self.profile, interrupt, address).map(|_| echo)?,
            TargetReachedEvent { every_move, mask } => self.interrupts.arm_events(every_move, mask, self.axes.len())?,

            // ----- program control, 128–135 (commands/program_control.rs)
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

            // ----- the module ---------------------------------------------
            FirmwareVersion { binary: true } => self.profile.version_word(),
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
            AsciiMode => {
                // The reply goes out in binary; then the link speaks text.
                self.link.enter_ascii_mode();
                echo
            }
            UserFunction { .. } => return Err(Status::NotAvailable),
        };
        Ok(Outcome::ok(value))
    }

    /// A read in a program loads the accumulator and sets the flags; a
    /// direct-mode read leaves them alone (docs/behaviour.md rules 7, 18).
    fn loaded(&mut self, v: i32, origin: Origin) -> i32 {
        if origin == Origin::Program {
            self.registers.load(v);
        }
        v
    }
}

/// Frame-level helpers for tests and tools.
pub fn opcode_name(op: u8) -> &'static str {
    opcode::name(op)
}
