//! The I/O family: SIO, GIO and SAC are the I/O part's
//! (`state/io.rs`), which the executor hands them to; here the module's
//! view of its outputs for tools, and the family's tests.

use crate::module::Module;

impl Module {
    /// The states of the digital outputs, bit n = OUTn.
    pub fn outputs(&self) -> u32 {
        self.io.outputs()
    }

    /// True when the inputs' pull-up resistors are on (all of them, as
    /// at power-up on a module whose pull-ups switch together).
    pub fn pullups(&self) -> bool {
        self.io.pullups() == u32::MAX
    }

    /// The pull-ups that are on, one bit an input (all bits on a module
    /// whose pull-ups switch together).
    pub fn pullup_mask(&self) -> u32 {
        self.io.pullups()
    }
}

#[cfg(test)]
mod tests {
    use crate::test_support::{direct, in_program, module, ok, status};
    use tmclsim_protocol::Status;

    #[test]
    fn sio_single_outputs_and_the_bit_vector() {
        let mut m = module("tmcm-351");
        ok(&mut m, "SIO 3, 2, 1");
        ok(&mut m, "SIO 5, 2, 1");
        assert_eq!(m.outputs(), 0b10_1000);
        ok(&mut m, "SIO 3, 2, 0");
        assert_eq!(m.outputs(), 0b10_0000);
        assert_eq!(ok(&mut m, "GIO 255, 2"), 0b10_0000, "GIO 255 reads the outputs back");
        ok(&mut m, "SIO 255, 2, 165");
        assert_eq!(m.outputs(), 0xA5);
        assert_eq!([0, 1, 2, 5, 7].map(|p| ok(&mut m, &format!("GIO {p}, 2"))), [1, 0, 1, 1, 1]);
        ok(&mut m, "CALC LOAD, 15");
        ok(&mut m, "SIO 255, 2, -1");
        assert_eq!(m.outputs(), 0x0F, "-1 takes the accumulator");
        assert_eq!(status(&mut m, "SIO 255, 2, 256"), Status::InvalidValue);
        assert_eq!(status(&mut m, "SIO 0, 2, 2"), Status::InvalidValue);
        assert_eq!(status(&mut m, "SIO 8, 2, 1"), Status::WrongType, "OUT0…OUT7");
    }

    #[test]
    fn gio_inputs_bit_vector_and_analog() {
        let mut m = module("tmcm-351");
        for n in [0, 3, 7] {
            m.world_mut().set_digital(n, true);
        }
        assert_eq!(ok(&mut m, "GIO 255, 0"), 0b1000_1001);
        assert_eq!([0, 1, 3].map(|p| ok(&mut m, &format!("GIO {p}, 0"))), [1, 0, 1]);
        m.world_mut().set_analog(2, 512);
        assert_eq!(ok(&mut m, "GIO 2, 1"), 128, "a 10-bit ADC reads the world's 12-bit value at its resolution");
        assert_eq!(status(&mut m, "GIO 0, 7"), Status::InvalidValue, "no bank 7");
        assert_eq!(in_program(&mut m, "GIO 255, 0"), Ok(0b1000_1001));
        assert_eq!(m.registers.accumulator, 0b1000_1001, "a program's GIO loads the accumulator");
    }

    #[test]
    fn pullups_and_supply_of_the_1141() {
        let mut m = module("tmcm-1141");
        assert!(m.pullups());
        ok(&mut m, "SIO 0, 0, 0");
        assert!(!m.pullups());
        assert_eq!(status(&mut m, "SIO 0, 0, 2"), Status::InvalidValue);
        ok(&mut m, "SIO 0, 0, 1");
        assert!(m.pullups());
        m.world_mut().supply_decivolts = 123;
        assert_eq!(ok(&mut m, "GIO 8, 1"), 123, "the supply in 0.1 V");
    }

    #[test]
    fn sac_talks_to_shift_registers() {
        let mut m = module("tmcm-351");
        assert_eq!(direct(&mut m, "SAC 0, 2, 4660"), (Status::Ok, 0));
        assert_eq!(ok(&mut m, "SAC 0, 2, 0"), 0x1234);
        assert_eq!(status(&mut m, "SAC 1, 1, 0"), Status::WrongType, "bus 1 is no chip select (V4.45 §4.6.24 p.49)");
        assert_eq!(in_program(&mut m, "SAC 0, 2, 0"), Ok(0));
        assert_eq!(m.registers.accumulator, 0, "a program's SAC loads the accumulator");
        assert_eq!(status(&mut m, "SAC 0, 5, 0"), Status::InvalidValue);
        let mut m = module("tmcm-1141");
        assert_eq!(status(&mut m, "SAC 0, 1, 0"), Status::InvalidCommand, "the TMCM-1141 has no SAC");
    }
}
