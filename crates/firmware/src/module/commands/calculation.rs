//! The calculation family: CALC, COMP, CALCX, the CALCV family, the
//! indexed user variables and CLE. The operations are the calculation
//! part's (`state/calculator.rs`); the module lends it the registers and
//! the user variables (bank 2) for one command.

use crate::module::Module;
use crate::state::calculator::Calculator;

impl Module {
    /// The registers and user variables, for one calculation command.
    pub(crate) fn calculator(&mut self) -> Calculator<'_> {
        let count = self.profile.module.user_variables as usize;
        Calculator::new(&mut self.registers, &mut self.globals[2], count)
    }

    /// A user variable (bank 2), for tools.
    pub fn user_variable_value(&self, i: usize) -> i32 {
        self.globals[2].get(i).copied().unwrap_or(0)
    }

    #[cfg(test)]
    pub(crate) fn user_variable(&self, i: usize) -> i32 {
        self.globals.user_variable(i)
    }
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
