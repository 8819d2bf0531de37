//! The I/O part: the digital outputs, the pull-ups, the inputs and stop
//! switches as last seen (for input-change and switch interrupts), and the
//! shift registers behind SAC's chip selects; and the I/O commands on
//! them: SIO and GIO (single ports and the 255 bit vectors, pull-ups,
//! analog inputs and the supply, as the profile's port table says) and
//! SAC, the SPI transfer of the TMCM-351. Inputs come from the world.

use crate::world::World;
use tmclsim_profile::{PortDirection, PortRole, Profile};
use tmclsim_protocol::Status;

#[derive(Clone, Debug)]
pub struct Io {
    /// Bit n = OUTn.
    outputs: u32,
    /// The pull-ups that are on, one bit an input (all bits for a module
    /// whose pull-ups switch together).
    pullups: u32,
    /// The value of the `input_range` port (SIO), selecting the ranged
    /// analog inputs' full scale.
    input_range: i32,
    /// Digital inputs and stop switches at the last look.
    last_inputs: u32,
    last_switches: Vec<(bool, bool)>,
    /// SAC: the shift register of the SPI device on each chip select.
    spi: [u32; 3],
}

impl Default for Io {
    fn default() -> Io {
        Io { outputs: 0, pullups: u32::MAX, input_range: 0, last_inputs: 0, last_switches: Vec::new(), spi: [0; 3] }
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

    /// SIO: sets an output, the outputs of a bank (port 255, with -1 the
    /// accumulator's bits), the pull-ups or the analog input range.
    pub fn set_port(&mut self, profile: &Profile, port: u8, bank: u8, value: i32, accumulator: i32) -> Result<(), Status> {
        let has = |d: PortDirection| profile.ports.iter().any(|p| p.direction == d && p.bank == bank);
        let setting = |d: PortDirection| profile.port(d, bank, port).map(|p| (d, p));
        if let Some((direction, p)) = setting(PortDirection::Pullup).or_else(|| setting(PortDirection::InputRange)) {
            if !(p.min..=p.max).contains(&i64::from(value)) {
                return Err(Status::InvalidValue);
            }
            match direction {
                PortDirection::Pullup => self.pullups = pullup_bits(p.max, value),
                _ => self.input_range = value,
            }
            return Ok(());
        }
        if has(PortDirection::Pullup) || has(PortDirection::InputRange) {
            return Err(Status::WrongType);
        }
        if !has(PortDirection::Output) {
            return Err(Status::InvalidValue);
        }
        if port == 255 {
            let v = if value == -1 { accumulator } else { value };
            if !(0..=255).contains(&v) {
                return Err(Status::InvalidValue);
            }
            self.set_outputs(output_mask(profile, bank), v as u32);
            return Ok(());
        }
        if profile.port(PortDirection::Output, bank, port).is_none() {
            return Err(Status::WrongType);
        }
        if !(0..=1).contains(&value) {
            return Err(Status::InvalidValue);
        }
        self.set_output(port, value == 1);
        Ok(())
    }

    /// GIO: an output read back, a digital or analog input of the world,
    /// the supply; port 255 reads a bank's outputs or digital inputs as
    /// bits.
    pub fn read_port(&self, profile: &Profile, world: &World, port: u8, bank: u8) -> Result<i32, Status> {
        let mut in_bank =
            profile.ports.iter().filter(|p| p.bank == bank && matches!(p.direction, PortDirection::Input | PortDirection::Output));
        let Some(first) = in_bank.clone().next() else {
            return Err(Status::InvalidValue);
        };
        if port == 255 {
            return Ok(if first.direction == PortDirection::Output {
                (self.outputs & output_mask(profile, bank)) as i32
            } else {
                in_bank.filter(|p| p.max == 1 && p.number < 8).fold(0, |m, p| m | i32::from(world.digital(p.number)) << p.number)
            });
        }
        let p = in_bank.find(|p| p.number == port).ok_or(Status::WrongType)?;
        Ok(match p.direction {
            PortDirection::Output => (self.outputs >> port & 1) as i32,
            _ if p.max == 1 => i32::from(world.digital(port)),
            // A measured quantity that an ADC reads over the port's span.
            _ if p.role.is_some() && p.span.is_some() => {
                let quantity = match p.role {
                    Some(PortRole::Temperature) => world.temperature,
                    _ => f64::from(world.supply_decivolts) / 10.0,
                };
                adc_reading(p, quantity)
            }
            // Otherwise the supply voltage channel reads 0.1 V.
            _ if p.role == Some(PortRole::Supply) => i32::from(world.supply_decivolts),
            _ => {
                let v = i64::from(world.analog_inputs.get(port as usize).copied().unwrap_or(0));
                // The world's ADC values are 12 bit (0…4095). A plain analog
                // input (no unit) with a coarser ADC reads them at its own
                // resolution: range 0…1023 reads a quarter.
                let v = if p.unit.is_none() && (1..4095).contains(&p.max) { v * (p.max + 1) / 4096 } else { v };
                // A ranged input: the world's value is the pin's voltage as
                // a share of the widest range; a narrower one reads it larger,
                // up to the port's maximum (docs/behaviour.md rule 54).
                match self.full_scale(profile) {
                    Some((selected, widest)) if p.ranged => ((v as f64 * widest / selected) as i64).min(p.max) as i32,
                    _ => v as i32,
                }
            }
        })
    }

    /// The ranged inputs' selected and widest full-scale voltages.
    fn full_scale(&self, profile: &Profile) -> Option<(f64, f64)> {
        let p = profile.ports.iter().find(|p| p.direction == PortDirection::InputRange)?;
        let selected = *p.full_scale_volts.get(usize::try_from(i64::from(self.input_range) - p.min).ok()?)?;
        let widest = p.full_scale_volts.iter().copied().fold(0.0, f64::max);
        Some((selected, widest))
    }

    /// The states of the digital outputs, bit n = OUTn.
    pub fn outputs(&self) -> u32 {
        self.outputs
    }

    /// The pull-ups that are on, one bit an input.
    pub fn pullups(&self) -> u32 {
        self.pullups
    }

    /// Power-up: outputs off, pull-ups and input range as the profile's
    /// defaults, the inputs and switches as they are now.
    pub fn power_on(&mut self, profile: &Profile, inputs: u32, switches: Vec<(bool, bool)>) {
        self.outputs = 0;
        let default = |d: PortDirection| profile.ports.iter().find(|p| p.direction == d);
        self.pullups = default(PortDirection::Pullup).map_or(u32::MAX, |p| pullup_bits(p.max, p.default as i32));
        self.input_range = default(PortDirection::InputRange).map_or(0, |p| p.default as i32);
        self.last_inputs = inputs;
        self.last_switches = switches;
    }

    /// The digital inputs at the last look.
    pub fn last_inputs(&self) -> u32 {
        self.last_inputs
    }

    /// A look at the digital inputs: the bits that changed since the last.
    pub fn see_inputs(&mut self, inputs: u32) -> u32 {
        let changed = inputs ^ self.last_inputs;
        self.last_inputs = inputs;
        changed
    }

    /// Axes whose stop switches are watched.
    pub fn switches_seen(&self) -> usize {
        self.last_switches.len()
    }

    /// The stop switches (left, right) of axis `m` at the last look.
    pub fn last_switches(&self, m: usize) -> (bool, bool) {
        self.last_switches[m]
    }

    /// A look at the stop switches of axis `m`: what they were before.
    pub fn see_switches(&mut self, m: usize, now: (bool, bool)) -> (bool, bool) {
        std::mem::replace(&mut self.last_switches[m], now)
    }

    /// SAC: an SPI transfer of `count` bytes on the chip select of bus
    /// number `bus`: 0, 2 and 3 select SPI_SEL0…2 (bus 1 is no chip
    /// select of the connector); with bit 7 set the accumulator is sent
    /// instead of `value`. The simulated device on each chip select is a
    /// shift register: it answers with what the previous transfer sent.
    pub fn spi_transfer(&mut self, bus: u8, count: u8, value: i32, accumulator: i32) -> Result<i32, Status> {
        let value = if bus & 0x80 != 0 { accumulator } else { value };
        let select = match bus & 0x7F {
            0 => 0,
            2 => 1,
            3 => 2,
            _ => return Err(Status::WrongType),
        };
        let slot = &mut self.spi[select];
        if !(1..=4).contains(&count) {
            return Err(Status::InvalidValue);
        }
        let mask = if count == 4 { u32::MAX } else { (1u32 << (8 * count)) - 1 };
        let answer = *slot & mask;
        *slot = value as u32 & mask;
        Ok(answer as i32)
    }
}

/// The pull-up bits a value sets: a port of range 0…1 switches them all.
fn pullup_bits(max: i64, value: i32) -> u32 {
    match (max, value) {
        (1, 0) => 0,
        (1, _) => u32::MAX,
        (_, v) => v as u32,
    }
}

/// The reading of an ADC port of `p.min…p.max` over the quantity's span,
/// clamped to the port's range.
fn adc_reading(p: &tmclsim_profile::Port, quantity: f64) -> i32 {
    let [lo, hi] = p.span.unwrap_or([0.0, 1.0]);
    let share = (quantity - lo) / (hi - lo);
    (p.min as f64 + share * (p.max - p.min) as f64).round().clamp(p.min as f64, p.max as f64) as i32
}

/// The outputs of a bank, as bits.
fn output_mask(profile: &Profile, bank: u8) -> u32 {
    profile
        .ports
        .iter()
        .filter(|p| p.direction == PortDirection::Output && p.bank == bank && p.number < 32)
        .fold(0, |m, p| m | 1 << p.number)
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
        assert_eq!(io.pullups, u32::MAX, "pull-ups are on by default");
    }

    #[test]
    fn spi_devices_are_shift_registers() {
        let mut io = Io::default();
        assert_eq!(io.spi_transfer(2, 2, 0x1234, 0), Ok(0));
        assert_eq!(io.spi_transfer(2, 2, 0x5678, 0), Ok(0x1234));
        assert_eq!(io.spi_transfer(2, 1, 0x1FF, 0), Ok(0x78), "one byte of the last word");
        assert_eq!(io.spi_transfer(2, 4, -1, 0), Ok(0xFF));
        assert_eq!(io.spi_transfer(2, 4, 0, 0), Ok(-1));
        assert_eq!(io.spi_transfer(0, 2, 7, 0), Ok(0), "each chip select has its own");
        assert_eq!(io.spi_transfer(3, 2, 7, 0), Ok(0));
        assert_eq!(io.spi_transfer(131, 2, 0, 0x0BEE), Ok(7), "bus 131: SPI_SEL2, sending the accumulator");
        assert_eq!(io.spi_transfer(3, 2, 0, 0), Ok(0x0BEE));
        assert_eq!(io.spi_transfer(1, 1, 0, 0), Err(Status::WrongType), "bus 1 is no chip select");
        assert_eq!(io.spi_transfer(4, 1, 0, 0), Err(Status::WrongType));
        assert_eq!(io.spi_transfer(2, 0, 0, 0), Err(Status::InvalidValue));
        assert_eq!(io.spi_transfer(2, 5, 0, 0), Err(Status::InvalidValue));
    }
}
