//! The module's I/O as the firmware keeps it: the digital outputs, the
//! pull-ups, the inputs and stop switches as last seen (for input-change and
//! switch interrupts), and the shift registers behind SAC's chip selects.

use tmclsim_protocol::Status;

#[derive(Clone, Debug)]
pub struct Io {
    /// Bit n = OUTn.
    pub outputs: u32,
    pub pullups: bool,
    /// Digital inputs and stop switches at the last look.
    pub last_inputs: u32,
    pub last_switches: Vec<(bool, bool)>,
    /// SAC: the shift register of the SPI device on each chip select.
    pub spi: [u32; 3],
}

impl Default for Io {
    fn default() -> Io {
        Io { outputs: 0, pullups: true, last_inputs: 0, last_switches: Vec::new(), spi: [0; 3] }
    }
}

impl Io {
    /// Switches one output on or off.
    pub fn set_output(&mut self, port: u8, on: bool) {
        if on {
            self.outputs |= 1 << port;
        } else {
            self.outputs &= !(1 << port);
        }
    }

    /// Sets the outputs of `mask` to the bits of `bits`; the others stay.
    pub fn set_outputs(&mut self, mask: u32, bits: u32) {
        self.outputs = (self.outputs & !mask) | (bits & mask);
    }

    /// SAC: an SPI transfer of `count` bytes on chip select `bus`. The
    /// simulated device on each bus is a shift register: it answers with
    /// what the previous transfer sent.
    pub fn spi_transfer(&mut self, bus: u8, count: u8, value: i32) -> Result<i32, Status> {
        let slot = self.spi.get_mut(bus as usize).ok_or(Status::WrongType)?;
        if !(1..=4).contains(&count) {
            return Err(Status::InvalidValue);
        }
        let mask = if count == 4 { u32::MAX } else { (1u32 << (8 * count)) - 1 };
        let answer = *slot & mask;
        *slot = value as u32 & mask;
        Ok(answer as i32)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outputs_one_by_one_and_by_mask() {
        let mut io = Io::default();
        io.set_output(3, true);
        io.set_output(0, true);
        io.set_output(3, false);
        assert_eq!(io.outputs, 0b1);
        io.set_outputs(0xF0, 0xAB);
        assert_eq!(io.outputs, 0xA1, "bits outside the mask stay");
        assert!(io.pullups, "pull-ups are on by default");
    }

    #[test]
    fn spi_devices_are_shift_registers() {
        let mut io = Io::default();
        assert_eq!(io.spi_transfer(1, 2, 0x1234), Ok(0));
        assert_eq!(io.spi_transfer(1, 2, 0x5678), Ok(0x1234));
        assert_eq!(io.spi_transfer(1, 1, 0x1FF), Ok(0x78), "one byte of the last word");
        assert_eq!(io.spi_transfer(1, 4, -1), Ok(0xFF));
        assert_eq!(io.spi_transfer(1, 4, 0), Ok(-1));
        assert_eq!(io.spi_transfer(0, 2, 7), Ok(0), "each chip select has its own");
        assert_eq!(io.spi_transfer(3, 1, 0), Err(Status::WrongType));
        assert_eq!(io.spi_transfer(2, 0, 0), Err(Status::InvalidValue));
        assert_eq!(io.spi_transfer(2, 5, 0), Err(Status::InvalidValue));
    }
}
