//! The calculation commands: CALC, COMP, CALCX, the CALCV family (CALCVV,
//! CALCVA, CALCAV, CALCVX, CALCXV, CALCV), the indexed user variables
//! (AIV, SIV, GIV) and CLE.

use crate::commands::Exec;
use crate::module::Module;
use crate::outcome::Origin;
use crate::state::registers::Compare;
use tmclsim_protocol::{CalcOp, Command, Status};

impl Module {
    /// CALC, COMP, CALCX, CALCVV…CALCV, AIV, SIV, GIV, CLE.
    pub(crate) fn calculation_command(&mut self, cmd: Command, echo: i32, origin: Origin) -> Exec {
        use Command::*;
        match cmd {
            Calc { op, value } => {
                let a = self.registers.accumulator;
                let r = calculate(op, a, value)?;
                self.registers.load(r);
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
                        self.registers.load(x);
                    }
                    CalcOp::Not => self.registers.x = !x,
                    _ => {
                        let r = calculate(op, a, x)?;
                        self.registers.load(r);
                    }
                }
                Ok(echo)
            }
            CalcVV { op, var1, var2 } => {
                let i2 = self.user_variable_index(var2)?;
                let (a, b) = (self.user_variable(var1 as usize), self.user_variable(i2));
                self.calc_into(op, a, b, |m, v| m.set_user_variable(var1 as usize, v), |m, v| m.set_user_variable(i2, v))?;
                Ok(echo)
            }
            CalcVA { op, var } => {
                let (v, a) = (self.user_variable(var as usize), self.registers.accumulator);
                self.calc_into(op, v, a, |m, r| m.set_user_variable(var as usize, r), |m, r| m.registers.load(r))?;
                Ok(echo)
            }
            CalcAV { op, var } => {
                let (a, v) = (self.registers.accumulator, self.user_variable(var as usize));
                self.calc_into(op, a, v, |m, r| m.registers.load(r), |m, r| m.set_user_variable(var as usize, r))?;
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
                // NOT inverts the variable itself, the value is ignored
                // (manual 3.7.45).
                let value = if op == CalcOp::Not { v } else { value };
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
                    Ok(self.loaded(v, origin))
                }
                Err(_) => Ok(echo),
            },
            Cle { flag } => {
                self.registers.clear_errors(flag);
                Ok(echo)
            }
            _ => unreachable!("not a calculation command: {cmd:?}"),
        }
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
                let r = calculate(op, target, source)?;
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
}

/// 32-bit two's complement arithmetic (docs/behaviour.md rule 19).
fn calculate(op: CalcOp, a: i32, b: i32) -> Exec {
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

#[cfg(test)]
mod tests {
    use crate::state::registers::{Compare, error_flag};
    use crate::test_support::{direct, in_program, module, ok};
    use tmclsim_protocol::Status;

    #[test]
    fn calc_operations_wrap_in_32_bits() {
        let mut m = module("tmcm-1141");
        let acc = |m: &mut crate::module::Module, line: &str| {
            ok(m, line);
            m.registers.accumulator
        };
        assert_eq!(acc(&mut m, "CALC LOAD, 100"), 100);
        assert_eq!(acc(&mut m, "CALC ADD, 23"), 123);
        assert_eq!(acc(&mut m, "CALC SUB, 200"), -77);
        assert_eq!(acc(&mut m, "CALC MUL, -3"), 231);
        assert_eq!(acc(&mut m, "CALC DIV, 10"), 23);
        assert_eq!(acc(&mut m, "CALC MOD, 5"), 3);
        assert_eq!(acc(&mut m, "CALC OR, 12"), 15);
        assert_eq!(acc(&mut m, "CALC AND, 6"), 6);
        assert_eq!(acc(&mut m, "CALC XOR, 5"), 3);
        assert_eq!(acc(&mut m, "CALC NOT, 0"), !3);
        assert_eq!(acc(&mut m, "CALC LOAD, -7"), -7);
        assert_eq!(acc(&mut m, "CALC MOD, 3"), -1, "the remainder takes the dividend's sign");
        assert_eq!(acc(&mut m, "CALC LOAD, 2147483647"), i32::MAX);
        assert_eq!(acc(&mut m, "CALC ADD, 1"), i32::MIN);
        assert_eq!(acc(&mut m, "CALC LOAD, -2147483648"), i32::MIN);
        assert_eq!(acc(&mut m, "CALC DIV, -1"), i32::MIN, "overflowing division wraps");
    }

    #[test]
    fn division_by_zero_fails_and_keeps_the_accumulator() {
        let mut m = module("tmcm-1141");
        ok(&mut m, "CALC LOAD, 9");
        assert_eq!(direct(&mut m, "CALC DIV, 0"), (Status::InvalidValue, 0));
        assert_eq!(direct(&mut m, "CALC MOD, 0"), (Status::InvalidValue, 0));
        assert_eq!(m.registers.accumulator, 9);
    }

    #[test]
    fn accumulator_loads_and_comp_set_the_flags() {
        let mut m = module("tmcm-1141");
        ok(&mut m, "CALC LOAD, -1");
        assert_eq!(m.registers.compare, Compare::Less);
        ok(&mut m, "CALC ADD, 1");
        assert_eq!(m.registers.compare, Compare::Equal);
        ok(&mut m, "COMP -5");
        assert_eq!(m.registers.compare, Compare::Greater, "0 > -5");
        ok(&mut m, "COMP 5");
        assert_eq!(m.registers.compare, Compare::Less);
        ok(&mut m, "COMP 0");
        assert_eq!(m.registers.compare, Compare::Equal);
        assert_eq!(m.registers.accumulator, 0, "COMP leaves the accumulator");
    }

    #[test]
    fn calcx_load_swap_not_and_arithmetic() {
        let mut m = module("tmcm-1141");
        ok(&mut m, "CALC LOAD, 6");
        ok(&mut m, "CALCX LOAD");
        assert_eq!(m.registers.x, 6);
        ok(&mut m, "CALC LOAD, 4");
        ok(&mut m, "CALCX MUL");
        assert_eq!(m.registers.accumulator, 24);
        ok(&mut m, "CALCX SWAP");
        assert_eq!((m.registers.accumulator, m.registers.x), (6, 24));
        ok(&mut m, "CALCX NOT");
        assert_eq!((m.registers.accumulator, m.registers.x), (6, !24));
    }

    #[test]
    fn calcv_family_targets_and_sources() {
        let mut m = module("tmcm-1141");
        ok(&mut m, "SGP 1, 2, 10");
        ok(&mut m, "SGP 2, 2, 3");
        ok(&mut m, "CALCVV SUB, 1, 2");
        assert_eq!((m.user_variable(1), m.user_variable(2)), (7, 3));
        ok(&mut m, "CALCVV SWAP, 1, 2");
        assert_eq!((m.user_variable(1), m.user_variable(2)), (3, 7));
        ok(&mut m, "CALCVV COMP, 1, 2");
        assert_eq!(m.registers.compare, Compare::Less);
        ok(&mut m, "CALCV MUL, 2, 6");
        assert_eq!(m.user_variable(2), 42);
        ok(&mut m, "CALC LOAD, 100");
        ok(&mut m, "CALCVA ADD, 2");
        assert_eq!((m.user_variable(2), m.registers.accumulator), (142, 100));
        ok(&mut m, "CALCAV SUB, 2");
        assert_eq!((m.registers.accumulator, m.user_variable(2)), (-42, 142));
        ok(&mut m, "CALCX LOAD");
        ok(&mut m, "CALCVX LOAD, 3");
        assert_eq!(m.user_variable(3), -42);
        ok(&mut m, "CALCXV NOT, 2");
        assert_eq!(m.registers.x, !142);
        ok(&mut m, "CALCV NOT, 2, 5");
        assert_eq!(m.user_variable(2), !142, "CALCV NOT inverts the variable, the value is ignored");
        assert_eq!(direct(&mut m, "CALCVV ADD, 1, 300").0, Status::InvalidValue, "no user variable 300");
    }

    #[test]
    fn indexed_user_variables_follow_x() {
        let mut m = module("tmcm-1141");
        ok(&mut m, "CALC LOAD, 20");
        ok(&mut m, "CALCX LOAD");
        ok(&mut m, "SIV 77");
        assert_eq!(m.user_variable(20), 77);
        ok(&mut m, "CALC LOAD, -5");
        ok(&mut m, "AIV");
        assert_eq!(m.user_variable(20), -5);
        ok(&mut m, "CALC LOAD, 0");
        assert_eq!(ok(&mut m, "GIV"), -5);
        assert_eq!(m.registers.accumulator, 0, "a direct-mode GIV leaves the accumulator");
        assert_eq!(in_program(&mut m, "GIV"), Ok(-5));
        assert_eq!((m.registers.accumulator, m.registers.compare), (-5, Compare::Less), "in a program it loads");
        // An index out of range does nothing.
        ok(&mut m, "CALC LOAD, 1000");
        ok(&mut m, "CALCX LOAD");
        assert_eq!(direct(&mut m, "SIV 1"), (Status::Ok, 1));
        assert_eq!(direct(&mut m, "GIV"), (Status::Ok, 0));
    }

    #[test]
    fn cle_clears_one_flag_or_all() {
        let mut m = module("tmcm-1141");
        m.registers.errors = error_flag::TIMEOUT | error_flag::DEVIATION;
        ok(&mut m, "CLE ETO");
        assert_eq!(m.registers.errors, error_flag::DEVIATION);
        m.registers.errors |= error_flag::ALARM;
        ok(&mut m, "CLE ALL");
        assert_eq!(m.registers.errors, 0);
    }
}
