//! The command executor: direct mode (`control.rs`, for every command but
//! the control commands) and the interpreter (`interpreter.rs`) hand a
//! decoded command to [`Module::dispatch`], the one place it is matched.
//! Each arm goes to the part of the module that owns
//! the command's family: the I/O (`state/io.rs`), the registers and user
//! variables (`state/calculator.rs`), the interrupts (`state/interrupts.rs`),
//! the EEPROM (`state/persistence.rs`), the program (`program.rs`); the
//! families that need more than one part are coordinated in `commands/`.

use crate::module::Module;
use crate::outcome::{Origin, Outcome};
use tmclsim_protocol::{Command, Instruction, Status};

impl Module {
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
            Sac { bus, count, value } => {
                let v = self.io.spi_transfer(bus, count, value, accumulator)?;
                self.loaded(v, origin)
            }

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

            UserFunction { .. } => return Err(Status::NotAvailable),

            // ----- the control commands (128–139, 255) are the direct
            // mode's (control.rs); a program has them refused.
            StopApplication
            | RunApplication { .. }
            | StepApplication
            | ResetApplication
            | EnterDownload { .. }
            | ExitDownload
            | ReadMemory { .. }
            | ApplicationStatus { .. }
            | FirmwareVersion { .. }
            | FactoryDefaults { .. }
            | TargetReachedEvent { .. }
            | AsciiMode
            | Reset { .. } => return Err(Status::InvalidCommand),
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
