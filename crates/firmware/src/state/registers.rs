//! The interpreter's registers: accumulator, X register, the result of the
//! last comparison and the error flags; and the jump conditions they decide.

use tmclsim_protocol::{Condition, ErrorFlag};

/// Result of the last comparison (or of an accumulator load against 0).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Compare {
    /// The first operand was below the second.
    Less,
    #[default]
    /// The operands were equal.
    Equal,
    /// The first operand was above the second.
    Greater,
}

impl Compare {
    /// How `a` compares with `b`.
    pub fn of(a: i32, b: i32) -> Compare {
        match a.cmp(&b) {
            std::cmp::Ordering::Less => Compare::Less,
            std::cmp::Ordering::Equal => Compare::Equal,
            std::cmp::Ordering::Greater => Compare::Greater,
        }
    }
}

/// Error flags (CLE / JC ETO…EPO), one bit each.
pub mod error_flag {
    /// ETO: a WAIT timed out.
    pub const TIMEOUT: u8 = 1 << 1;
    /// EAL: external alarm.
    pub const ALARM: u8 = 1 << 2;
    /// EDV: deviation error (the encoder or closed loop lost track of the
    /// motor).
    pub const DEVIATION: u8 = 1 << 3;
    /// EPO: position error.
    pub const POSITION: u8 = 1 << 4;
    /// ESD: shutdown error.
    pub const SHUTDOWN: u8 = 1 << 5;
}

/// Accumulator, X register and flags of the TMCL interpreter.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Registers {
    /// The accumulator.
    pub accumulator: i32,
    /// The X register.
    pub x: i32,
    /// Result of the last comparison.
    pub compare: Compare,
    /// Error flags, see [`error_flag`].
    pub errors: u8,
}

impl Registers {
    /// Loads the accumulator and compares the value with 0, as every
    /// accumulator load does.
    pub fn load(&mut self, v: i32) {
        self.accumulator = v;
        self.compare = Compare::of(v, 0);
    }

    /// CLE: clears one error flag, or all of them.
    pub fn clear_errors(&mut self, flag: ErrorFlag) {
        self.errors &= !match flag {
            ErrorFlag::All => 0xFF,
            ErrorFlag::Timeout => error_flag::TIMEOUT,
            ErrorFlag::Alarm => error_flag::ALARM,
            ErrorFlag::Deviation => error_flag::DEVIATION,
            ErrorFlag::Position => error_flag::POSITION,
            ErrorFlag::Shutdown => error_flag::SHUTDOWN,
        };
    }

    /// Whether the condition of a JC or CALL holds.
    pub fn holds(&self, c: Condition) -> bool {
        let cmp = self.compare;
        let e = self.errors;
        match c {
            Condition::Zero | Condition::Equal => cmp == Compare::Equal,
            Condition::NotZero | Condition::NotEqual => cmp != Compare::Equal,
            Condition::Greater => cmp == Compare::Greater,
            Condition::GreaterEqual => cmp != Compare::Less,
            Condition::Lower => cmp == Compare::Less,
            Condition::LowerEqual => cmp != Compare::Greater,
            Condition::Timeout => e & error_flag::TIMEOUT != 0,
            Condition::Alarm => e & error_flag::ALARM != 0,
            Condition::Deviation => e & error_flag::DEVIATION != 0,
            Condition::PositionError => e & error_flag::POSITION != 0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_load_compares_with_zero() {
        let mut r = Registers::default();
        r.load(-3);
        assert_eq!((r.accumulator, r.compare), (-3, Compare::Less));
        r.load(0);
        assert_eq!(r.compare, Compare::Equal);
        r.load(i32::MAX);
        assert_eq!(r.compare, Compare::Greater);
    }

    #[test]
    fn conditions_follow_the_comparison() {
        let at = |compare| Registers { compare, ..Registers::default() };
        let (lt, eq, gt) = (at(Compare::Less), at(Compare::Equal), at(Compare::Greater));
        assert!(eq.holds(Condition::Zero) && eq.holds(Condition::Equal) && !lt.holds(Condition::Zero));
        assert!(lt.holds(Condition::NotZero) && gt.holds(Condition::NotEqual) && !eq.holds(Condition::NotEqual));
        assert!(gt.holds(Condition::Greater) && !eq.holds(Condition::Greater));
        assert!(gt.holds(Condition::GreaterEqual) && eq.holds(Condition::GreaterEqual) && !lt.holds(Condition::GreaterEqual));
        assert!(lt.holds(Condition::Lower) && !eq.holds(Condition::Lower));
        assert!(lt.holds(Condition::LowerEqual) && eq.holds(Condition::LowerEqual) && !gt.holds(Condition::LowerEqual));
    }

    #[test]
    fn error_conditions_and_cle() {
        let mut r = Registers { errors: error_flag::TIMEOUT | error_flag::DEVIATION | error_flag::SHUTDOWN, ..Registers::default() };
        assert!(r.holds(Condition::Timeout) && r.holds(Condition::Deviation));
        assert!(!r.holds(Condition::Alarm) && !r.holds(Condition::PositionError));
        r.clear_errors(ErrorFlag::Timeout);
        assert!(!r.holds(Condition::Timeout) && r.holds(Condition::Deviation));
        assert_eq!(r.errors, error_flag::DEVIATION | error_flag::SHUTDOWN);
        r.clear_errors(ErrorFlag::All);
        assert_eq!(r.errors, 0);
    }
}
