//! The I/O commands: SIO and GIO (single ports and the 255 bit vectors,
//! pull-ups, analog inputs and the supply) and SAC, the SPI transfer of the
//! TMCM-351.

use crate::commands::Exec;
use crate::module::Module;
use crate::outcome::Origin;
use tmclsim_profile::PortDirection;
use tmclsim_protocol::{Command, Status};

impl Module {
    /// SIO, GIO, SAC.
    pub(crate) fn io_command(&mut self, cmd: Command, echo: i32, origin: Origin) -> Exec {
        use Command::*;
        match cmd {
            Sio { port, bank, value } => self.set_output(port, bank, value).map(|_| echo),
            Gio { port, bank } => {
                let v = self.get_input(port, bank)?;
                Ok(self.loaded(v, origin))
            }
            Sac { bus, count, value } => self.io.spi_transfer(bus, count, value),
            _ => unreachable!("not an I/O command: {cmd:?}"),
        }
    }

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

    pub(crate) fn get_input(&self, port: u8, bank: u8) -> Exec {
        let mut in_bank = self.profile.ports.iter().filter(|p| p.bank == bank && p.direction != PortDirection::Pullup);
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
            _ if p.role == Some(tmclsim_profile::PortRole::Supply) => self.world.supply_decivolts as i32,
            _ => {
                let v = self.world.analog_inputs.get(port as usize).copied().unwrap_or(0) as i64;
                // The world's ADC values are 12 bit (0…4095). A plain analog
                // input (no unit) with a coarser ADC reads them at its own
                // resolution: range 0…1023 reads a quarter.
                if p.unit.is_none() && (1..4095).contains(&p.max) { (v * (p.max + 1) / 4096) as i32 } else { v as i32 }
            }
        })
    }

    /// The states of the digital outputs, bit n = OUTn.
    pub fn outputs(&self) -> u32 {
        self.io.outputs
    }

    pub fn pullups(&self) -> bool {
        self.io.pullups
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
        assert_eq!(status(&mut m, "SAC 3, 1, 0"), Status::WrongType);
        assert_eq!(status(&mut m, "SAC 0, 5, 0"), Status::InvalidValue);
        let mut m = module("tmcm-1141");
        assert_eq!(status(&mut m, "SAC 0, 1, 0"), Status::InvalidCommand, "the TMCM-1141 has no SAC");
    }
}
