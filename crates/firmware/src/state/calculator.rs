//! The calculation part: CALC, COMP, CALCX, the CALCV family (CALCVV,
//! CALCVA, CALCAV, CALCVX, CALCXV, CALCV) and the indexed user variables
//! (AIV, SIV, GIV), over the interpreter's registers and the user
//! variables (global parameter bank 2) — a view the module lends for one
//! command.

use crate::state::registers::{Compare, Registers};
use tmclsim_protocol::{CalcOp, Status};

/// A register or user variable an operation reads and writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Place {
    /// The accumulator: writing it loads it (the flags follow).
    Accumulator,
    X,
    Variable(usize),
}

/// The registers and the user variables, borrowed for one command.
pub struct Calculator<'a> {
    registers: &'a mut Registers,
    /// Bank 2, indexed by the variable number (CALCV and its kin do not
    /// check it against the count; the indexed ones and CALCVV's source do).
    variables: &'a mut [i32; 256],
    /// User variables the module has.
    count: usize,
}

impl<'a> Calculator<'a> {
    pub fn new(registers: &'a mut Registers, variables: &'a mut [i32; 256], count: usize) -> Calculator<'a> {
        Calculator { registers, variables, count }
    }

    fn get(&self, p: Place) -> i32 {
        match p {
            Place::Accumulator => self.registers.accumulator,
            Place::X => self.registers.x,
            Place::Variable(i) => self.variables[i],
        }
    }

    fn set(&mut self, p: Place, v: i32) {
        match p {
            Place::Accumulator => self.registers.load(v),
            Place::X => self.registers.x = v,
            Place::Variable(i) => self.variables[i] = v,
        }
    }

    /// CALC: accumulator op= value.
    pub fn calc(&mut self, op: CalcOp, value: i32) -> Result<(), Status> {
        let r = calculate(op, self.registers.accumulator, value)?;
        self.registers.load(r);
        Ok(())
    }

    /// COMP: compares the accumulator with a value.
    pub fn comp(&mut self, value: i32) {
        self.registers.compare = Compare::of(self.registers.accumulator, value);
    }

    /// CALCX: LOAD copies the accumulator to X, SWAP exchanges them, NOT
    /// inverts X; the others compute accumulator op= X.
    pub fn calc_x(&mut self, op: CalcOp) -> Result<(), Status> {
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
        Ok(())
    }

    /// CALCVV: variable op= variable.
    pub fn calc_vv(&mut self, op: CalcOp, var1: u8, var2: i32) -> Result<(), Status> {
        let i2 = self.index(var2)?;
        self.calc_into(op, Place::Variable(var1 as usize), Some(Place::Variable(i2)), None)
    }

    /// CALCVA: variable op= accumulator.
    pub fn calc_va(&mut self, op: CalcOp, var: u8) -> Result<(), Status> {
        self.calc_into(op, Place::Variable(var as usize), Some(Place::Accumulator), None)
    }

    /// CALCAV: accumulator op= variable.
    pub fn calc_av(&mut self, op: CalcOp, var: u8) -> Result<(), Status> {
        self.calc_into(op, Place::Accumulator, Some(Place::Variable(var as usize)), None)
    }

    /// CALCVX: variable op= X.
    pub fn calc_vx(&mut self, op: CalcOp, var: u8) -> Result<(), Status> {
        self.calc_into(op, Place::Variable(var as usize), Some(Place::X), None)
    }

    /// CALCXV: X op= variable.
    pub fn calc_xv(&mut self, op: CalcOp, var: u8) -> Result<(), Status> {
        self.calc_into(op, Place::X, Some(Place::Variable(var as usize)), None)
    }

    /// CALCV: variable op= value; NOT inverts the variable itself, the
    /// value is ignored (manual 3.7.45).
    pub fn calc_v(&mut self, op: CalcOp, var: u8, value: i32) -> Result<(), Status> {
        let target = Place::Variable(var as usize);
        let value = if op == CalcOp::Not { self.get(target) } else { value };
        self.calc_into(op, target, None, Some(value))
    }

    /// SIV, AIV: the variable X points at takes a value; an index out of
    /// range does nothing.
    pub fn set_indexed(&mut self, value: i32) {
        if let Ok(i) = self.index(self.registers.x) {
            self.variables[i] = value;
        }
    }

    /// GIV: the variable X points at; `None` for an index out of range.
    pub fn indexed(&self) -> Option<i32> {
        self.index(self.registers.x).ok().map(|i| self.variables[i])
    }

    fn index(&self, i: i32) -> Result<usize, Status> {
        if (0..self.count as i32).contains(&i) { Ok(i as usize) } else { Err(Status::InvalidValue) }
    }

    /// The CALCVV family: `target op= source` (a place, or a constant that
    /// is not written back), with NOT and LOAD copying from the source,
    /// SWAP exchanging, COMP comparing.
    fn calc_into(&mut self, op: CalcOp, target: Place, source: Option<Place>, constant: Option<i32>) -> Result<(), Status> {
        let t = self.get(target);
        let s = source.map_or(constant.unwrap_or(0), |p| self.get(p));
        match op {
            CalcOp::Comp => self.registers.compare = Compare::of(t, s),
            CalcOp::Swap => {
                self.set(target, s);
                if let Some(p) = source {
                    self.set(p, t);
                }
            }
            CalcOp::Not => self.set(target, !s),
            _ => {
                let r = calculate(op, t, s)?;
                self.set(target, r);
            }
        }
        Ok(())
    }
}

/// 32-bit two's complement arithmetic (docs/behaviour.md rule 19). SWAP
/// and COMP are no arithmetic: their callers handle them.
fn calculate(op: CalcOp, a: i32, b: i32) -> Result<i32, Status> {
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
        // CALC does not decode them (types 0…9); CALCX and the CALCV
        // family handle them before.
        CalcOp::Swap | CalcOp::Comp => return Err(Status::WrongType),
    })
}
