//! The command executor: what each TMCL command does to a module.
//!
//! `execute` is direct mode (a host sent the command); `run_command` is
//! shared with the program interpreter, which passes `Origin::Program` so
//! that reads load the accumulator and branch commands are allowed.

use crate::module::Module;
use crate::motion::RampMode;
use crate::outcome::{Origin, Outcome, Special};
use crate::parameter_numbers::{ap, gp};
use crate::profile::{Parameter, PortDirection};
use crate::reference_search::{ReferenceSearch, Switch};
use crate::state::registers::Compare;
use tmclsim_protocol::{CalcOp, Command, Instruction, MoveMode, RfsAction, Status, opcode};

type Exec = Result<i32, Status>;

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

    /// Executes a decoded command. The value is what a direct-mode reply
    /// carries.
    pub(crate) fn run_command(&mut self, cmd: Command, ins: Instruction, origin: Origin) -> Exec {
        use Command::*;
        let echo = ins.value;
        let program = origin == Origin::Program;
        match cmd {
            Ror { motor, velocity } => self.for_group(motor, |s, m| s.rotate(m, velocity, 1)).map(|_| echo),
            Rol { motor, velocity } => self.for_group(motor, |s, m| s.rotate(m, velocity, -1)).map(|_| echo),
            Mst { motor } => self
                .for_group(motor, |s, m| {
                    let m = s.motor(m)?;
                    s.motor_stop(m);
                    Ok(())
                })
                .map(|_| echo),
            Mvp { mode: MoveMode::Coordinate, motor, value } if motor & 0xC0 != 0 && self.axes.len() > 1 => {
                self.move_coordinate_mask(motor, value).map(|_| echo)
            }
            Mvp { mode, motor, value } => self.for_group(motor, |s, m| s.move_to(mode, m, value)).map(|_| echo),
            Mvpa { mode, motor } => {
                let a = self.registers.accumulator;
                self.move_to(mode, motor, a).map(|_| echo)
            }
            Rola { motor } => self.rotate(motor, self.registers.accumulator, -1).map(|_| echo),
            Rora { motor } => self.rotate(motor, self.registers.accumulator, 1).map(|_| echo),
            Sap { param, motor, value } => self.set_axis_parameter(param, motor, value).map(|_| echo),
            Aap { param, motor } => self.set_axis_parameter(param, motor, self.registers.accumulator).map(|_| echo),
            Gap { param, motor } => {
                let v = self.get_axis_parameter(param, motor)?;
                Ok(self.loaded(v, program))
            }
            Stap { param, motor } => {
                let m = self.motor(motor)?;
                self.axis_spec(param, |a| a.eeprom)?;
                if self.eeprom_locked() {
                    return Err(Status::EepromLocked);
                }
                let v = self.axes[m].params[param as usize];
                self.persistence.eeprom.set_axis(motor, param, v);
                self.persistence.mark_written();
                Ok(echo)
            }
            Rsap { param, motor } => {
                let m = self.motor(motor)?;
                let spec = self.axis_spec(param, |a| a.eeprom)?;
                let v = self.persistence.eeprom.axis(motor, param).unwrap_or(spec.default_word());
                self.write_axis_parameter(m, param, v);
                Ok(echo)
            }
            Sgp { param, bank, value } => self.set_global_parameter(param, bank, value).map(|_| echo),
            Agp { param, bank } => self.set_global_parameter(param, bank, self.registers.accumulator).map(|_| echo),
            Ggp { param, bank } => {
                let v = self.get_global_parameter(param, bank)?;
                Ok(self.loaded(v, program))
            }
            Stgp { param, bank } => {
                self.global_spec(param, bank, |a| a.eeprom)?;
                if self.eeprom_locked() {
                    return Err(Status::EepromLocked);
                }
                let v = self.globals[bank as usize][param as usize];
                self.persistence.eeprom.set_global(bank, param, v);
                self.persistence.mark_written();
                Ok(echo)
            }
            Rsgp { param, bank } => {
                let spec = self.global_spec(param, bank, |a| a.eeprom)?;
                let v = self.persistence.eeprom.global(bank, param).unwrap_or(spec.default_word());
                self.globals[bank as usize][param as usize] = v;
                Ok(echo)
            }
            Sio { port, bank, value } => self.set_output(port, bank, value).map(|_| echo),
            Gio { port, bank } => {
                let v = self.get_input(port, bank)?;
                Ok(self.loaded(v, program))
            }
            Sco { coordinate, motor, value } => self.set_coordinate(coordinate, motor, Some(value)).map(|_| echo),
            Aco { coordinate, motor } => {
                let a = self.registers.accumulator;
                self.set_coordinate(coordinate, motor, Some(a)).map(|_| echo)
            }
            Cco { coordinate, motor } => {
                let m = self.motor(motor)?;
                let pos = self.actual_position(m);
                self.set_coordinate(coordinate, motor, Some(pos))?;
                Ok(pos)
            }
            Gco { coordinate, motor } => {
                if motor == 255 {
                    self.coordinates_from_eeprom(coordinate)?;
                    return Ok(echo);
                }
                let m = self.motor(motor)?;
                let v = *self.axes[m].coordinates.get(coordinate as usize).ok_or(Status::WrongType)?;
                Ok(self.loaded(v, program))
            }
            Calc { op, value } => {
                let a = self.registers.accumulator;
                let r = self.calculate(op, a, value)?;
                self.load_accumulator(r);
                Ok(echo)
            }
            Comp { value } => {
                self.registers.compare = Compare::of(self.registers.accumulator, value);
                Ok(echo)
            }
            CalcX { op } => {
                let (a, x) = (self.registers.accumulator, self.registers.x);
                match op {
                    CalcOp::Load => self.registers.x = a,
                    CalcOp::Swap => {
                        self.registers.x = a;
                        self.load_accumulator(x);
                    }
                    CalcOp::Not => self.registers.x = !x,
                    _ => {
                        let r = self.calculate(op, a, x)?;
                        self.load_accumulator(r);
                    }
                }
                Ok(echo)
            }
            CalcVV { op, var1, var2 } => {
                let i2 = self.user_variable_index(var2)?;
                let (a, b) = (self.user_variable(var1 as usize), self.user_variable(i2));
                let r = self.calc_into(op, a, b, |m, v| m.set_user_variable(var1 as usize, v), |m, v| m.set_user_variable(i2, v))?;
                let _ = r;
                Ok(echo)
            }
            CalcVA { op, var } => {
                let (v, a) = (self.user_variable(var as usize), self.registers.accumulator);
                self.calc_into(op, v, a, |m, r| m.set_user_variable(var as usize, r), |m, r| m.load_accumulator(r))?;
                Ok(echo)
            }
            CalcAV { op, var } => {
                let (a, v) = (self.registers.accumulator, self.user_variable(var as usize));
                self.calc_into(op, a, v, |m, r| m.load_accumulator(r), |m, r| m.set_user_variable(var as usize, r))?;
                Ok(echo)
            }
            CalcVX { op, var } => {
                let (v, x) = (self.user_variable(var as usize), self.registers.x);
                self.calc_into(op, v, x, |m, r| m.set_user_variable(var as usize, r), |m, r| m.registers.x = r)?;
                Ok(echo)
            }
            CalcXV { op, var } => {
                let (x, v) = (self.registers.x, self.user_variable(var as usize));
                self.calc_into(op, x, v, |m, r| m.registers.x = r, |m, r| m.set_user_variable(var as usize, r))?;
                Ok(echo)
            }
            CalcV { op, var, value } => {
                let v = self.user_variable(var as usize);
                self.calc_into(op, v, value, |m, r| m.set_user_variable(var as usize, r), |_, _| {})?;
                Ok(echo)
            }
            Siv { value } => {
                if let Ok(i) = self.user_variable_index(self.registers.x) {
                    self.set_user_variable(i, value);
                }
                Ok(echo)
            }
            Aiv => {
                if let Ok(i) = self.user_variable_index(self.registers.x) {
                    self.set_user_variable(i, self.registers.accumulator);
                }
                Ok(echo)
            }
            Giv => match self.user_variable_index(self.registers.x) {
                Ok(i) => {
                    let v = self.user_variable(i);
                    Ok(self.loaded(v, program))
                }
                Err(_) => Ok(echo),
            },
            Cle { flag } => {
                self.registers.clear_errors(flag);
                Ok(echo)
            }
            Ei { interrupt } | Di { interrupt } => {
                let enable = matches!(cmd, Ei { .. });
                if interrupt == 255 {
                    self.interrupts.global = enable;
                } else {
                    self.profile.interrupt(interrupt).ok_or(Status::WrongType)?;
                    self.interrupts.enabled[interrupt as usize] = enable;
                }
                Ok(echo)
            }
            Vect { interrupt, address } => {
                if interrupt == 255 || self.profile.interrupt(interrupt).is_none() {
                    return Err(Status::WrongType);
                }
                if address < 0 || address >= self.profile.module.program_memory as i32 {
                    return Err(Status::InvalidValue);
                }
                self.interrupts.vectors[interrupt as usize] = Some(address as u16);
                Ok(echo)
            }
            FirmwareVersion { binary: true } => Ok(self.profile.version_word()),
            TargetReachedEvent { every_move, mask } => {
                let valid = (1u32 << self.axes.len()) - 1;
                if mask <= 0 || mask as u32 & !valid != 0 {
                    return Err(Status::InvalidValue);
                }
                self.interrupts.event_arm = Some((every_move, mask as u32));
                Ok(mask)
            }
            Reset { key } => {
                if key != MAGIC_KEY {
                    return Err(Status::InvalidValue);
                }
                // handle_frame resets after the reply has been built.
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
            | ApplicationStatus { .. } => unreachable!("handled in execute"),
            Rfs { action, motor } => {
                let m = self.motor(motor)?;
                match action {
                    RfsAction::Start => self.for_group(motor, |s, g| s.start_reference_search(g as usize))?,
                    RfsAction::Stop => self.for_group(motor, |s, g| {
                        if s.axes[g as usize].rfs.take().is_some() {
                            s.motor_stop(g as usize);
                        }
                        Ok(())
                    })?,
                    RfsAction::Status => return Ok(self.reference_search_active(m) as i32),
                }
                Ok(echo)
            }
            AsciiMode => {
                // The reply goes out in binary; then the link speaks text.
                self.enter_ascii_mode();
                Ok(echo)
            }
            Sac { bus, count, value } => self.io.spi_transfer(bus, count, value),
            FirmwareVersion { binary: false } | FactoryDefaults { .. } => unreachable!("handled in execute"),
            Jc { .. } | Ja { .. } | Csub { .. } | Rsub | Call { .. } | Djnz { .. } | Rst { .. } | Wait { .. } | Stop | Reti => {
                Err(Status::NotAvailable)
            }
        }
    }

    // ----- registers --------------------------------------------------

    /// A read in a program loads the accumulator and sets the flags; a
    /// direct-mode read leaves them alone (decisions.md rules 7, 18).
    fn loaded(&mut self, v: i32, program: bool) -> i32 {
        if program {
            self.load_accumulator(v);
        }
        v
    }

    pub(crate) fn load_accumulator(&mut self, v: i32) {
        self.registers.load(v);
    }

    /// 32-bit two's complement arithmetic (decisions.md rule 19).
    fn calculate(&self, op: CalcOp, a: i32, b: i32) -> Exec {
        Ok(match op {
            CalcOp::Add => a.wrapping_add(b),
            CalcOp::Sub => a.wrapping_sub(b),
            CalcOp::Mul => a.wrapping_mul(b),
            CalcOp::Div => {
                if b == 0 {
                    return Err(Status::InvalidValue);
                }
                a.wrapping_div(b)
            }
            CalcOp::Mod => {
                if b == 0 {
                    return Err(Status::InvalidValue);
                }
                a.wrapping_rem(b)
            }
            CalcOp::And => a & b,
            CalcOp::Or => a | b,
            CalcOp::Xor => a ^ b,
            CalcOp::Not => !a,
            CalcOp::Load => b,
            CalcOp::Swap | CalcOp::Comp => unreachable!("handled by the caller"),
        })
    }

    /// The CALCVV family: `target op= source`, with NOT and LOAD copying
    /// from the source, SWAP exchanging, COMP comparing.
    fn calc_into(
        &mut self,
        op: CalcOp,
        target: i32,
        source: i32,
        set_target: impl FnOnce(&mut Module, i32),
        set_source: impl FnOnce(&mut Module, i32),
    ) -> Exec {
        match op {
            CalcOp::Comp => {
                self.registers.compare = Compare::of(target, source);
                Ok(target)
            }
            CalcOp::Swap => {
                set_target(self, source);
                set_source(self, target);
                Ok(source)
            }
            CalcOp::Not => {
                set_target(self, !source);
                Ok(!source)
            }
            _ => {
                let r = self.calculate(op, target, source)?;
                set_target(self, r);
                Ok(r)
            }
        }
    }

    fn user_variable_index(&self, i: i32) -> Result<usize, Status> {
        if (0..self.profile.module.user_variables as i32).contains(&i) { Ok(i as usize) } else { Err(Status::InvalidValue) }
    }

    /// A user variable (bank 2), for tools.
    pub fn user_variable_value(&self, i: usize) -> i32 {
        self.globals[2].get(i).copied().unwrap_or(0)
    }

    pub(crate) fn user_variable(&self, i: usize) -> i32 {
        self.globals[2][i]
    }

    pub(crate) fn set_user_variable(&mut self, i: usize, v: i32) {
        self.globals[2][i] = v;
    }

    // ----- motion commands --------------------------------------------

    pub(crate) fn motor(&self, motor: u8) -> Result<usize, Status> {
        if (motor as usize) < self.axes.len() { Ok(motor as usize) } else { Err(Status::InvalidValue) }
    }

    fn rotate(&mut self, motor: u8, velocity: i32, sign: i32) -> Result<(), Status> {
        let m = self.motor(motor)?;
        if !(-2047..=2047).contains(&velocity) {
            return Err(Status::InvalidValue);
        }
        self.clear_motion_errors(m);
        let axis = &mut self.axes[m];
        axis.end_overrides();
        axis.params[ap::TARGET_SPEED as usize] = velocity * sign;
        axis.set_ramp_mode(RampMode::Velocity);
        axis.notify_on_arrival = false;
        Ok(())
    }

    /// MST: velocity mode with target speed 0.
    pub(crate) fn motor_stop(&mut self, m: usize) {
        let axis = &mut self.axes[m];
        axis.end_overrides();
        axis.params[ap::TARGET_SPEED as usize] = 0;
        axis.set_ramp_mode(RampMode::Velocity);
        axis.notify_on_arrival = false;
    }

    fn move_to(&mut self, mode: MoveMode, motor: u8, value: i32) -> Result<(), Status> {
        let m = self.motor(motor)?;
        let target = match mode {
            MoveMode::Absolute => value,
            MoveMode::Relative => self.wrap_position(self.actual_position(m) as i64 + value as i64),
            MoveMode::Coordinate => {
                let n = usize::try_from(value).map_err(|_| Status::InvalidValue)?;
                *self.axes[m].coordinates.get(n).ok_or(Status::InvalidValue)?
            }
        };
        if mode == MoveMode::Absolute && !self.profile.axis_parameter(ap::TARGET_POSITION).is_some_and(|p| p.accepts(value)) {
            return Err(Status::InvalidValue);
        }
        self.clear_motion_errors(m);
        let axis = &mut self.axes[m];
        axis.end_overrides();
        // MVP selects position mode; soft mode, once chosen, stays.
        if axis.motion.mode != RampMode::Soft {
            axis.set_ramp_mode(RampMode::Position);
        }
        self.set_target(m, target);
        if self.interrupts.claim_arrival_event(m) {
            self.axes[m].notify_on_arrival = true;
            if self.axes[m].motion.x == self.axes[m].motion.target && self.axes[m].motion.v == 0.0 {
                // Already there: the event follows at once.
                self.axes[m].notify_on_arrival = false;
                self.push_event(1 << m);
            }
        }
        Ok(())
    }

    /// Runs a motion command for `motor` and for every other motor with the
    /// same non-zero group index (AP 213, on modules that have it).
    fn for_group(&mut self, motor: u8, mut f: impl FnMut(&mut Module, u8) -> Result<(), Status>) -> Result<(), Status> {
        let m = self.motor(motor)?;
        f(self, motor)?;
        if self.profile.axis_parameter(ap::GROUP_INDEX).is_some() {
            let group = self.axes[m].params[ap::GROUP_INDEX as usize];
            if group != 0 {
                for other in 0..self.axes.len() {
                    if other != m && self.axes[other].params[ap::GROUP_INDEX as usize] == group {
                        f(self, other as u8)?;
                    }
                }
            }
        }
        Ok(())
    }

    /// MVP COORD with a motor mask: bit 7 moves the masked motors each with
    /// its own ramp, bit 6 interpolates (all arrive together: the axis with
    /// the longest travel time sets the pace, the others scale speed and
    /// acceleration by their share of the distance).
    fn move_coordinate_mask(&mut self, motor: u8, coordinate: i32) -> Result<(), Status> {
        let mask = (motor & 0x3F) as usize;
        let motors: Vec<usize> = (0..self.axes.len()).filter(|m| mask & (1 << m) != 0).collect();
        if motors.is_empty() || mask >> self.axes.len() != 0 {
            return Err(Status::InvalidValue);
        }
        for &m in &motors {
            self.move_to(MoveMode::Coordinate, m as u8, coordinate)?;
        }
        if motor & 0x40 == 0 {
            return Ok(());
        }
        let plans: Vec<(usize, f64, f64)> = motors
            .iter()
            .map(|&m| {
                let d = (self.axes[m].motion.target - self.axes[m].motion.x).abs();
                (m, d, crate::motion::Motion::closed_form_duration(d, &self.ramp(m)))
            })
            .collect();
        let &(lead, d_lead, _) = plans.iter().max_by(|a, b| a.2.total_cmp(&b.2)).expect("motors is not empty");
        if d_lead == 0.0 {
            return Ok(());
        }
        let lead_ramp = self.ramp(lead);
        for (m, d, _) in plans {
            if m != lead {
                let k = d / d_lead;
                let mut r = lead_ramp;
                r.vmax *= k;
                r.vmin *= k;
                r.accel_position *= k;
                self.axes[m].ramp_override = (k > 0.0).then_some(r);
            }
        }
        Ok(())
    }

    /// GP 73 on modules that have it: the configuration EEPROM is locked.
    pub(crate) fn eeprom_locked(&self) -> bool {
        self.profile.global_parameter(0, gp::EEPROM_LOCK).is_some() && self.globals[0][gp::EEPROM_LOCK as usize] == 1
    }

    fn clear_motion_errors(&mut self, m: usize) {
        self.axes[m].params[ap::EXTENDED_ERROR_FLAGS as usize] = 0;
    }

    /// Sets AP 0 and the target the ramp generator runs to: the short way
    /// round in the module's position counter width.
    pub(crate) fn set_target(&mut self, m: usize, target: i32) {
        let actual = self.actual_position(m);
        let diff = self.wrap_position(target as i64 - actual as i64);
        let axis = &mut self.axes[m];
        axis.target_word = target;
        axis.params[ap::TARGET_POSITION as usize] = target;
        axis.motion.target = axis.motion.position() as f64 + diff as f64;
    }

    /// Sign-extends to the module's position width (32 or 24 bits).
    pub(crate) fn wrap_position(&self, v: i64) -> i32 {
        let bits = self.profile.position_bits();
        let shift = 64 - bits;
        ((v << shift) >> shift) as i32
    }

    /// A reference search is running on this axis.
    pub(crate) fn reference_search_active(&self, m: usize) -> bool {
        self.axes[m].rfs.is_some()
    }

    /// RFS START with the mode of AP 193.
    fn start_reference_search(&mut self, m: usize) -> Result<(), Status> {
        let mode = self.axes[m].params[ap::REFERENCE_SEARCH_MODE as usize];
        let rfs =
            if self.profile.module.motion_controller == "TMC428" { ReferenceSearch::new_tmc428(mode) } else { ReferenceSearch::new(mode) };
        let rfs = rfs.ok_or(Status::InvalidValue)?;
        self.clear_motion_errors(m);
        let axis = &mut self.axes[m];
        axis.notify_on_arrival = false;
        axis.set_ramp_mode(RampMode::Velocity);
        axis.rfs = Some(rfs);
        self.reference_search_step(m, true, false);
        Ok(())
    }

    /// Lets the reference search look at the switches after a step of
    /// motion: next seek, final positioning, zeroing.
    pub(crate) fn reference_search_step(&mut self, m: usize, crossed: bool, arrived: bool) {
        let Some(mut rfs) = self.axes[m].rfs.take() else { return };
        let motion = &self.axes[m].motion;
        if rfs.finish.is_none() && crossed {
            let x = motion.x;
            let invert_home = rfs.invert_home;
            let changed = rfs.look(x, |s, probe| {
                let (l, r, h) = self.switches_at(m, probe);
                match s {
                    Switch::Left => l,
                    Switch::Right => r,
                    Switch::Home => h ^ invert_home,
                }
            });
            if changed {
                // The switch stops the motor at once; the next seek starts
                // from standstill.
                self.axes[m].motion.v = 0.0;
            }
            if let Some((reference, distance)) = rfs.finish {
                // Move to the reference point at the switch speed.
                let axis = &mut self.axes[m];
                axis.set_ramp_mode(RampMode::Position);
                axis.motion.target = reference.round();
                if axis.motion.x != axis.motion.target || axis.motion.v != 0.0 {
                    self.axes[m].rfs = Some(rfs);
                } else {
                    self.finish_reference_search(m, distance);
                }
                return;
            }
        } else if let (Some((_, distance)), true) = (rfs.finish, arrived) {
            self.finish_reference_search(m, distance);
            return;
        }
        self.axes[m].rfs = Some(rfs);
    }

    /// At the reference point: AP 197 keeps the old count, the counter
    /// becomes 0 here, AP 196 gets the switch distance.
    fn finish_reference_search(&mut self, m: usize, distance: Option<f64>) {
        {
            let last = self.actual_position(m);
            self.axes[m].params[ap::LAST_REFERENCE_POSITION as usize] = last;
            if let Some(d) = distance {
                self.axes[m].params[ap::END_SWITCH_DISTANCE as usize] = d.round() as i32;
            }
            self.write_axis_parameter(m, ap::ACTUAL_POSITION, 0);
            self.set_target(m, 0);
        }
    }

    /// AP 3: the actual speed in internal units.
    pub fn actual_speed(&self, m: usize) -> i32 {
        let pd = self.axes[m].params[ap::PULSE_DIVISOR as usize].clamp(0, 13) as u32;
        crate::motion::velocity_internal(self.axes[m].motion.v, pd).trunc() as i32
    }

    pub fn actual_position(&self, m: usize) -> i32 {
        self.wrap_position(self.axes[m].motion.position())
    }

    // ----- axis parameters ----------------------------------------------

    fn axis_spec(&self, param: u8, need: impl Fn(crate::profile::Access) -> bool) -> Result<&Parameter, Status> {
        let spec = self.profile.axis_parameter(param).ok_or(Status::WrongType)?;
        if need(spec.access) { Ok(spec) } else { Err(Status::WrongType) }
    }

    pub fn set_axis_parameter(&mut self, param: u8, motor: u8, value: i32) -> Result<(), Status> {
        let m = self.motor(motor)?;
        let spec = self.axis_spec(param, |a| a.write)?;
        if !spec.accepts(value) {
            return Err(Status::InvalidValue);
        }
        self.write_axis_parameter(m, param, value);
        Ok(())
    }

    pub fn get_axis_parameter(&mut self, param: u8, motor: u8) -> Result<i32, Status> {
        let m = self.motor(motor)?;
        self.axis_spec(param, |a| a.read)?;
        Ok(self.read_axis_parameter(m, param))
    }

    /// Writes a parameter with its side effects (no access check).
    pub(crate) fn write_axis_parameter(&mut self, m: usize, param: u8, value: i32) {
        match param {
            ap::TARGET_POSITION => self.set_target(m, value),
            ap::ACTUAL_POSITION => {
                let target = self.axes[m].target_word;
                let sign = self.shaft_sign();
                let axis = &mut self.axes[m];
                // The carriage does not move: only the counter changes.
                let mech = axis.motion.x * sign + axis.mech_offset;
                axis.motion.x = value as f64;
                axis.mech_offset = mech - axis.motion.x * sign;
                self.set_target(m, target);
                self.closed_loop_sync(m);
            }
            ap::RAMP_MODE => {
                let axis = &mut self.axes[m];
                axis.set_ramp_mode(RampMode::from_code(value));
                // AP 138 keeps the word as written.
                axis.params[param as usize] = value;
            }
            ap::ENCODER_POSITION if self.has_closed_loop() => {
                let now = self.closed_loop_encoder(m) as f64 - self.axes[m].closed_loop.encoder_offset;
                self.axes[m].closed_loop.encoder_offset = value as f64 - now;
            }
            ap::ENCODER_POSITION => {
                let now = self.encoder_position(m) as i64 - self.axes[m].encoder_offset;
                self.axes[m].encoder_offset = value as i64 - now;
            }
            crate::closed_loop::cl::TORQUE_TARGET if self.has_closed_loop() => {
                // Torque mode: the driver sets this current (mA).
                let axis = &mut self.axes[m];
                axis.params[param as usize] = value;
                axis.end_overrides();
                axis.closed_loop.torque_mode = true;
                axis.set_ramp_mode(RampMode::Velocity);
            }
            crate::closed_loop::cl::MODE if self.has_closed_loop() => {
                self.axes[m].params[param as usize] = value;
                self.closed_loop_sync(m);
            }
            _ => self.axes[m].params[param as usize] = value,
        }
    }

    /// Reads a parameter, computing the measured ones.
    pub(crate) fn read_axis_parameter(&mut self, m: usize, param: u8) -> i32 {
        if let Some(v) = self.read_closed_loop(m, param) {
            return v;
        }
        let pd = self.axes[m].params[ap::PULSE_DIVISOR as usize].clamp(0, 13) as u32;
        let rd = self.axes[m].params[ap::RAMP_DIVISOR as usize].clamp(0, 13) as u32;
        let motion = &self.axes[m].motion;
        match param {
            ap::TARGET_POSITION => self.axes[m].target_word,
            ap::ACTUAL_POSITION => self.actual_position(m),
            ap::ACTUAL_SPEED => self.actual_speed(m),
            ap::ACTUAL_ACCELERATION => crate::motion::accel_internal(motion.a, rd, pd).round().clamp(-2047.0, 2047.0) as i32,
            ap::POSITION_REACHED => (self.actual_position(m) == self.axes[m].target_word) as i32,
            ap::LEFT_SWITCH => self.switches(m).0 as i32,
            ap::RIGHT_SWITCH => self.switches(m).1 as i32,
            ap::HOME_SWITCH => self.switches(m).2 as i32,
            ap::ACTUAL_CURRENT => self.current_scale(m).round() as i32,
            ap::LOAD_VALUE => self.axes[m].driver.load_value,
            ap::ENCODER_POSITION if self.profile.axis_parameter(ap::ENCODER_POSITION).is_some() => self.encoder_position(m),
            ap::DRIVER_ERROR_FLAGS => self.driver_flags(m),
            ap::EXTENDED_ERROR_FLAGS => {
                // Cleared by reading.
                std::mem::take(&mut self.axes[m].params[param as usize])
            }
            _ => self.axes[m].params[param as usize],
        }
    }

    /// The current setting in effect (0…255): run, boost, standby or off.
    pub fn motor_current(&self, m: usize) -> u32 {
        let axis = &self.axes[m];
        let p = &axis.params;
        let run = p[ap::MAX_CURRENT as usize].clamp(0, 255) as u32;
        if axis.motion.v != 0.0 {
            let slow = p[ap::SMART_ENERGY_SLOW_RUN_CURRENT as usize].clamp(0, 255) as u32;
            if p[ap::SMART_ENERGY_HYSTERESIS_START as usize] > 0
                && slow > 0
                && self.actual_speed(m).abs() < p[ap::SMART_ENERGY_THRESHOLD_SPEED as usize]
            {
                return slow;
            }
            let boost = p[ap::BOOST_CURRENT as usize].clamp(0, 255) as u32;
            return if axis.motion.a != 0.0 && boost > 0 { boost } else { run };
        }
        let standby = p[ap::STANDBY_CURRENT as usize].clamp(0, 255) as u32;
        if axis.motion.stopped_by_switch && p[ap::END_SWITCH_POWER_DOWN as usize] == 1 {
            return standby;
        }
        let Some(since) = axis.standstill_since else { return run };
        let still_ms = (self.now_ns.saturating_sub(since)) / 1_000_000;
        let freewheel = p[ap::FREEWHEELING as usize].max(0) as u64 * 10;
        if freewheel > 0 && still_ms >= freewheel {
            return 0;
        }
        let delay = p[ap::POWER_DOWN_DELAY as usize].max(0) as u64 * 10;
        if still_ms >= delay { standby } else { run }
    }

    // ----- global parameters ------------------------------------------

    fn global_spec(&self, param: u8, bank: u8, need: impl Fn(crate::profile::Access) -> bool) -> Result<&Parameter, Status> {
        if !self.profile.has_bank(bank) {
            return Err(Status::InvalidValue);
        }
        let spec = self.profile.global_parameter(bank, param).ok_or(Status::WrongType)?;
        if need(spec.access) { Ok(spec) } else { Err(Status::WrongType) }
    }

    pub fn set_global_parameter(&mut self, param: u8, bank: u8, value: i32) -> Result<(), Status> {
        let spec = self.global_spec(param, bank, |a| a.write)?;
        if !spec.accepts(value) {
            return Err(Status::InvalidValue);
        }
        let auto = spec.access.auto;
        if (bank, param) == (0, gp::EEPROM_LOCK) {
            // 1234 locks, 4321 unlocks; the state itself is kept.
            let locked = match value {
                1234 => 1,
                4321 => 0,
                _ => return Err(Status::InvalidValue),
            };
            self.globals[0][param as usize] = locked;
            self.persistence.eeprom.set_global(0, param, locked);
            self.persistence.mark_written();
            return Ok(());
        }
        if auto && self.eeprom_locked() {
            return Err(Status::EepromLocked);
        }
        match (bank, param) {
            (0, gp::TICK_TIMER) => self.globals.set_tick_timer(self.now_ns, value as i64),
            (0, gp::RANDOM) => self.globals.seed_random(value),
            (0, gp::CODE_PROTECTION) => {
                let old = self.globals[0][param as usize];
                if matches!(old, 1 | 3) && matches!(value, 0 | 2) {
                    // Lifting the protection against reading erases the program.
                    for w in self.program.memory.iter_mut() {
                        *w = Instruction::default();
                    }
                    self.program.reset();
                    self.persistence.eeprom.program.clear();
                    self.persistence.mark_written();
                }
                self.globals[0][param as usize] = value;
            }
            (3, _) => {
                self.globals[3][param as usize] = value;
                // A new period restarts the timer.
                if let Some(t) = self.program.timers.get_mut(param as usize) {
                    *t = None;
                }
            }
            _ => self.globals[bank as usize][param as usize] = value,
        }
        if auto {
            self.persistence.eeprom.set_global(bank, param, value);
            self.persistence.mark_written();
        }
        Ok(())
    }

    pub fn get_global_parameter(&mut self, param: u8, bank: u8) -> Result<i32, Status> {
        self.global_spec(param, bank, |a| a.read)?;
        Ok(match (bank, param) {
            (0, gp::TICK_TIMER) => self.globals.tick_timer(self.now_ns),
            (0, gp::APPLICATION_STATUS) => self.program.mode as i32,
            (0, gp::DOWNLOAD_MODE) => self.program.download.is_some() as i32,
            (0, gp::PROGRAM_COUNTER) => self.program.pc as i32,
            (0, gp::RANDOM) => self.globals.random(),
            _ => self.globals[bank as usize][param as usize],
        })
    }

    // ----- I/O ----------------------------------------------------------

    fn set_output(&mut self, port: u8, bank: u8, value: i32) -> Result<(), Status> {
        let has = |d: PortDirection| self.profile.ports.iter().any(|p| p.direction == d && p.bank == bank);
        if has(PortDirection::Pullup) {
            if self.profile.port(PortDirection::Pullup, bank, port).is_none() {
                return Err(Status::WrongType);
            }
            if !(0..=1).contains(&value) {
                return Err(Status::InvalidValue);
            }
            self.io.pullups = value == 1;
            return Ok(());
        }
        if !has(PortDirection::Output) {
            return Err(Status::InvalidValue);
        }
        if port == 255 {
            let v = if value == -1 { self.registers.accumulator } else { value };
            if !(0..=255).contains(&v) {
                return Err(Status::InvalidValue);
            }
            let mask = self.output_mask(bank);
            self.io.set_outputs(mask, v as u32);
            return Ok(());
        }
        if self.profile.port(PortDirection::Output, bank, port).is_none() {
            return Err(Status::WrongType);
        }
        if !(0..=1).contains(&value) {
            return Err(Status::InvalidValue);
        }
        self.io.set_output(port, value == 1);
        Ok(())
    }

    fn output_mask(&self, bank: u8) -> u32 {
        self.profile
            .ports
            .iter()
            .filter(|p| p.direction == PortDirection::Output && p.bank == bank && p.number < 32)
            .fold(0, |m, p| m | 1 << p.number)
    }

    fn get_input(&mut self, port: u8, bank: u8) -> Exec {
        let profile = self.profile.clone();
        let mut in_bank = profile.ports.iter().filter(|p| p.bank == bank && p.direction != PortDirection::Pullup);
        let Some(first) = in_bank.clone().next() else {
            return Err(Status::InvalidValue);
        };
        if port == 255 {
            return Ok(if first.direction == PortDirection::Output {
                (self.io.outputs & self.output_mask(bank)) as i32
            } else {
                in_bank.filter(|p| p.max == 1 && p.number < 8).fold(0, |m, p| m | (self.world.digital(p.number) as i32) << p.number)
            });
        }
        let p = in_bank.find(|p| p.number == port).ok_or(Status::WrongType)?;
        Ok(match p.direction {
            PortDirection::Output => (self.io.outputs >> port & 1) as i32,
            _ if p.max == 1 => self.world.digital(port) as i32,
            // The supply voltage channel is the one with a 0.1 V unit.
            _ if p.unit.as_deref().is_some_and(|u| u.contains('V')) => self.world.supply_decivolts as i32,
            _ => self.world.analog_inputs.get(port as usize).copied().unwrap_or(0) as i32,
        })
    }

    /// The states of the digital outputs, bit n = OUTn.
    pub fn outputs(&self) -> u32 {
        self.io.outputs
    }

    pub fn pullups(&self) -> bool {
        self.io.pullups
    }

    // ----- coordinates --------------------------------------------------

    fn set_coordinate(&mut self, n: u8, motor: u8, value: Option<i32>) -> Result<(), Status> {
        if n as usize > self.profile.module.coordinates as usize {
            return Err(Status::WrongType);
        }
        if motor == 255 {
            if self.eeprom_locked() {
                return Err(Status::EepromLocked);
            }
            // SCO n, 255, 0: RAM → EEPROM (0 = all but coordinate 0).
            let range = if n == 0 { 1..=self.profile.module.coordinates } else { n..=n };
            for m in 0..self.axes.len() {
                for c in range.clone() {
                    let v = self.axes[m].coordinates[c as usize];
                    self.persistence.eeprom.set_coordinate(m as u8, c, v);
                }
            }
            self.persistence.mark_written();
            return Ok(());
        }
        let m = self.motor(motor)?;
        let v = value.unwrap_or(0);
        self.axes[m].coordinates[n as usize] = v;
        if n > 0 && self.globals[0][gp::COORDINATE_STORAGE as usize] == 1 {
            self.persistence.eeprom.set_coordinate(motor, n, v);
            self.persistence.mark_written();
        }
        Ok(())
    }

    /// GCO n, 255: EEPROM → RAM (0 = all but coordinate 0).
    fn coordinates_from_eeprom(&mut self, n: u8) -> Result<(), Status> {
        if n as usize > self.profile.module.coordinates as usize {
            return Err(Status::WrongType);
        }
        let range = if n == 0 { 1..=self.profile.module.coordinates } else { n..=n };
        for m in 0..self.axes.len() {
            for c in range.clone() {
                self.axes[m].coordinates[c as usize] = self.persistence.eeprom.coordinate(m as u8, c).unwrap_or(0);
            }
        }
        Ok(())
    }
}

/// Frame-level helpers for tests and tools.
pub fn opcode_name(op: u8) -> &'static str {
    opcode::name(op)
}
