//! Checks of an encoded instruction against a module profile: does the
//! module have the instruction, the parameter (with the access the
//! instruction needs), the motor, bank, port, coordinate and interrupt, is
//! an immediate parameter value in range and a jump target in program
//! memory. Each finding is a column and a message.
//!
//! These are the checks that would make the module answer a direct-mode
//! command with an error status (docs/behaviour.md rule 6) and skip it in a
//! program (rule 21).

use tmclsim_profile::Profile;
use tmclsim_profile::{Access, Parameter, PortDirection};
use tmclsim_protocol::opcode as op;

use crate::encoder::Encoded;

/// A problem found: column and message.
pub type Finding = (usize, String);

/// What an instruction does with a parameter, i.e. which access letter it
/// needs.
#[derive(Clone, Copy)]
enum Use {
    Read,
    Write,
    Store,
}

impl Use {
    fn allowed(self, a: Access) -> bool {
        match self {
            Use::Read => a.read,
            Use::Write => a.write,
            Use::Store => a.eeprom,
        }
    }

    fn refusal(self) -> &'static str {
        match self {
            Use::Read => "cannot be read",
            Use::Write => "cannot be written",
            Use::Store => "cannot be stored in or restored from the EEPROM",
        }
    }
}

struct Checker<'a> {
    profile: &'a Profile,
    e: &'a Encoded,
    findings: Vec<Finding>,
}

/// Every problem of one instruction on this module.
pub fn check(e: &Encoded, profile: &Profile) -> Vec<Finding> {
    let mut c = Checker { profile, e, findings: Vec::new() };
    c.run();
    c.findings
}

impl<'a> Checker<'a> {
    fn module(&self) -> &str {
        &self.profile.module.name
    }

    fn report(&mut self, column: usize, message: String) {
        self.findings.push((column, message));
    }

    fn run(&mut self) {
        let ins = self.e.instruction;
        let (kind, motor, value) = (ins.kind, ins.motor, ins.value);
        let name = op::mnemonic(ins.opcode).unwrap_or("?");
        if !self.profile.has_opcode(ins.opcode) {
            let message = format!("{name} is not available on the {}", self.module());
            self.report(self.e.mnemonic_column, message);
            return;
        }
        match ins.opcode {
            op::ROR | op::ROL => {
                self.motor(motor, false);
                self.velocity(value);
            }
            op::MST | op::ROLA | op::RORA | op::MVPA | op::RFS => self.motor(motor, false),
            op::MVP => {
                self.motor(motor, false);
                if kind == 2 {
                    self.coordinate(i64::from(value), self.e.value_column);
                }
            }
            op::SAP => {
                self.motor(motor, false);
                if let Some(p) = self.axis_parameter(kind, Use::Write) {
                    self.range(p, value, &format!("axis parameter {kind}"));
                }
            }
            op::AAP => {
                self.motor(motor, false);
                self.axis_parameter(kind, Use::Write);
            }
            op::GAP => {
                self.motor(motor, false);
                self.axis_parameter(kind, Use::Read);
            }
            op::STAP | op::RSAP => {
                self.motor(motor, false);
                self.axis_parameter(kind, Use::Store);
            }
            op::SGP => {
                if let Some(p) = self.global_parameter(motor, kind, Use::Write) {
                    self.range(p, value, &format!("global parameter {kind} of bank {motor}"));
                }
            }
            op::AGP => {
                let _ = self.global_parameter(motor, kind, Use::Write);
            }
            op::GGP => {
                let _ = self.global_parameter(motor, kind, Use::Read);
            }
            op::STGP | op::RSGP => {
                let _ = self.global_parameter(motor, kind, Use::Store);
            }
            op::SIO => self.output(kind, motor, value),
            op::GIO => self.input(kind, motor),
            op::JC | op::JA | op::CSUB | op::CALL | op::RST => self.address(value),
            op::DJNZ => {
                self.user_variable(i64::from(kind), self.e.type_column);
                self.address(value);
            }
            op::EI | op::DI => self.interrupt(kind, true),
            op::VECT => {
                self.interrupt(kind, false);
                self.address(value);
            }
            // WAIT TICKS has no motor ("don't care").
            op::WAIT if kind != 0 => self.motor(motor, false),
            op::SCO | op::GCO => {
                self.coordinate(i64::from(kind), self.e.type_column);
                self.motor(motor, true);
            }
            op::CCO | op::ACO => {
                self.coordinate(i64::from(kind), self.e.type_column);
                self.motor(motor, false);
            }
            op::CALCVV => {
                self.user_variable(i64::from(motor), self.e.motor_column);
                self.user_variable(i64::from(value), self.e.value_column);
            }
            op::CALCVA | op::CALCAV | op::CALCVX | op::CALCXV | op::CALCV => self.user_variable(i64::from(motor), self.e.motor_column),
            _ => {}
        }
    }

    /// Motor numbers 0…axes−1; `eeprom_form`: 255 is allowed too (SCO/GCO
    /// copy coordinates between RAM and EEPROM).
    fn motor(&mut self, motor: u8, eeprom_form: bool) {
        let axes = self.profile.module.axes;
        if motor < axes || (eeprom_form && motor == 255) {
            return;
        }
        let motors = if axes == 1 { "it has motor 0 only".to_string() } else { format!("motors 0...{}", axes.saturating_sub(1)) };
        let message = format!("motor {motor} does not exist on the {} ({motors})", self.module());
        self.report(self.e.motor_column, message);
    }

    fn velocity(&mut self, value: i32) {
        // The velocity of ROR/ROL goes to axis parameter 2 (target speed).
        match self.profile.axis_parameter(2) {
            Some(p) if !p.accepts(value) => {
                let message = format!("velocity {value} is out of range {}...{}", p.min, p.max);
                self.report(self.e.value_column, message);
            }
            _ => {}
        }
    }

    fn axis_parameter(&mut self, number: u8, need: Use) -> Option<&'a Parameter> {
        let profile = self.profile;
        let Some(p) = profile.axis_parameter(number) else {
            let message = format!("axis parameter {number} does not exist on the {} (see Parameters.inc)", self.module());
            self.report(self.e.type_column, message);
            return None;
        };
        if !need.allowed(p.access) {
            let message = format!("axis parameter {number} ({}) {} (access {})", p.name, need.refusal(), p.access);
            self.report(self.e.type_column, message);
            return None;
        }
        Some(p)
    }

    fn global_parameter(&mut self, bank: u8, number: u8, need: Use) -> Option<&'a Parameter> {
        let profile = self.profile;
        if !profile.has_bank(bank) {
            let banks: Vec<String> = (0..=255u8).filter(|&b| profile.has_bank(b)).map(|b| b.to_string()).collect();
            let message = format!("bank {bank} does not exist on the {} (banks: {})", self.module(), banks.join(", "));
            self.report(self.e.motor_column, message);
            return None;
        }
        let Some(p) = profile.global_parameter(bank, number) else {
            let message = format!("global parameter {number} does not exist in bank {bank} of the {}", self.module());
            self.report(self.e.type_column, message);
            return None;
        };
        if !need.allowed(p.access) {
            let message = format!("global parameter {number} of bank {bank} ({}) {} (access {})", p.name, need.refusal(), p.access);
            self.report(self.e.type_column, message);
            return None;
        }
        Some(p)
    }

    fn range(&mut self, p: &Parameter, value: i32, what: &str) {
        if p.accepts(value) {
            return;
        }
        let shown = if p.max > i64::from(i32::MAX) { i64::from(value as u32) } else { i64::from(value) };
        let message = format!("value {shown} is out of range for {what} ({}): {}...{}", p.name, p.min, p.max);
        self.report(self.e.value_column, message);
    }

    fn address(&mut self, target: i32) {
        let size = i64::from(self.profile.module.program_memory);
        if !(0..size).contains(&i64::from(target)) {
            let message = format!("jump target {target} is outside the program memory of the {} (0...{})", self.module(), size - 1);
            self.report(self.e.value_column, message);
        }
    }

    fn interrupt(&mut self, number: u8, global_allowed: bool) {
        if number == 255 {
            if !global_allowed {
                self.report(self.e.type_column, "VECT needs a single interrupt; 255 (all interrupts) is only for EI and DI".into());
            }
            return;
        }
        if self.profile.interrupt(number).is_none() {
            let known: Vec<String> = self.profile.interrupts.iter().filter(|i| i.number != 255).map(|i| i.number.to_string()).collect();
            let message = format!(
                "interrupt {number} does not exist on the {} (interrupts: {}; see Interrupts.inc)",
                self.module(),
                known.join(", ")
            );
            self.report(self.e.type_column, message);
        }
    }

    fn coordinate(&mut self, number: i64, column: usize) {
        let max = i64::from(self.profile.module.coordinates);
        if !(0..=max).contains(&number) {
            let message = format!("coordinate {number} does not exist on the {} (0...{max})", self.module());
            self.report(column, message);
        }
    }

    fn user_variable(&mut self, number: i64, column: usize) {
        let count = i64::from(self.profile.module.user_variables);
        if !(0..count).contains(&number) {
            let message = format!("user variable {number} does not exist on the {} (0...{})", self.module(), count - 1);
            self.report(column, message);
        }
    }

    /// SIO: a setting (the pull-ups, the analog input range), an output,
    /// or 255 (all outputs of the bank).
    fn output(&mut self, port: u8, bank: u8, value: i32) {
        let ports = &self.profile.ports;
        let has = |d: PortDirection| ports.iter().any(|p| p.direction == d && p.bank == bank);
        let exists = |d: PortDirection| ports.iter().any(|p| p.direction == d && p.bank == bank && p.number == port);
        let setting = ports
            .iter()
            .find(|p| matches!(p.direction, PortDirection::Pullup | PortDirection::InputRange) && p.bank == bank && p.number == port);
        let (port_ok, range) = if let Some(p) = setting {
            (true, (p.min as i32, p.max as i32))
        } else if has(PortDirection::Pullup) || has(PortDirection::InputRange) {
            (false, (0, 1))
        } else if has(PortDirection::Output) {
            if port == 255 { (true, (0, 255)) } else { (exists(PortDirection::Output), (0, 1)) }
        } else {
            let mut banks: Vec<u8> = ports.iter().filter(|p| p.direction != PortDirection::Input).map(|p| p.bank).collect();
            banks.sort_unstable();
            banks.dedup();
            let banks: Vec<String> = banks.iter().map(u8::to_string).collect();
            let message = format!("bank {bank} has no outputs on the {} (SIO banks: {})", self.module(), banks.join(", "));
            self.report(self.e.motor_column, message);
            return;
        };
        if !port_ok {
            let mut numbers: Vec<String> =
                ports.iter().filter(|p| p.bank == bank && p.direction != PortDirection::Input).map(|p| p.number.to_string()).collect();
            if has(PortDirection::Output) {
                numbers.push("255".into());
            }
            let message = format!("SIO port {port} does not exist in bank {bank} of the {} (ports: {})", self.module(), numbers.join(", "));
            self.report(self.e.type_column, message);
            return;
        }
        let accumulator = port == 255 && value == -1;
        if !accumulator && !(range.0..=range.1).contains(&value) {
            let extra = if port == 255 { " or -1 (accumulator)" } else { "" };
            let message = format!("SIO value {value} is out of range {}...{}{extra}", range.0, range.1);
            self.report(self.e.value_column, message);
        }
    }

    /// GIO: an input, an output read back, or 255 (all lines of the bank).
    fn input(&mut self, port: u8, bank: u8) {
        let in_bank: Vec<u8> = self
            .profile
            .ports
            .iter()
            .filter(|p| p.bank == bank && matches!(p.direction, PortDirection::Input | PortDirection::Output))
            .map(|p| p.number)
            .collect();
        if in_bank.is_empty() {
            let message = format!("bank {bank} has no inputs or outputs on the {}", self.module());
            self.report(self.e.motor_column, message);
            return;
        }
        if port != 255 && !in_bank.contains(&port) {
            let mut numbers: Vec<String> = in_bank.iter().map(u8::to_string).collect();
            numbers.push("255".into());
            let message = format!("GIO port {port} does not exist in bank {bank} of the {} (ports: {})", self.module(), numbers.join(", "));
            self.report(self.e.type_column, message);
        }
    }
}
