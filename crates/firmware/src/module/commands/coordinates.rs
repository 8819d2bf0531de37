//! The coordinate commands: SCO, GCO, CCO, ACO — coordinates in the axes'
//! RAM, and with motor 255 (or GP 84) in the EEPROM part.

use crate::module::Module;
use crate::parameter_numbers::gp;
use tmclsim_protocol::Status;

impl Module {
    /// SCO, ACO: sets coordinate `n` of a motor; with motor 255 copies it
    /// (0: all but coordinate 0) from RAM to the EEPROM.
    pub(crate) fn set_coordinate(&mut self, n: u8, motor: u8, value: i32) -> Result<(), Status> {
        let count = self.profile.module.coordinates;
        if n > count {
            return Err(Status::WrongType);
        }
        if motor == 255 {
            // SCO n, 255, 0: RAM → EEPROM (0 = all but coordinate 0).
            let range = if n == 0 { 1..=count } else { n..=n };
            let coordinates: Vec<&[i32]> = self.axes.iter().map(|a| a.coordinates.as_slice()).collect();
            return self.persistence.store_coordinates(&self.globals, &coordinates, range);
        }
        let m = self.motor(motor)?;
        self.axes[m].coordinates[n as usize] = value;
        if n > 0 && self.globals[0][gp::COORDINATE_STORAGE as usize] == 1 {
            self.persistence.store_coordinate(motor, n, value);
        }
        Ok(())
    }

    /// CCO: coordinate `n` becomes the actual position, which the reply
    /// carries.
    pub(crate) fn capture_coordinate(&mut self, n: u8, motor: u8) -> Result<i32, Status> {
        let m = self.motor(motor)?;
        let pos = self.actual_position(m);
        self.set_coordinate(n, motor, pos)?;
        Ok(pos)
    }

    /// GCO: coordinate `n` of a motor.
    pub(crate) fn coordinate(&self, n: u8, motor: u8) -> Result<i32, Status> {
        let m = self.motor(motor)?;
        self.axes[m].coordinates.get(n as usize).copied().ok_or(Status::WrongType)
    }

    /// GCO n, 255: EEPROM → RAM (0 = all but coordinate 0).
    pub(crate) fn coordinates_from_eeprom(&mut self, n: u8) -> Result<(), Status> {
        let count = self.profile.module.coordinates;
        if n > count {
            return Err(Status::WrongType);
        }
        let range = if n == 0 { 1..=count } else { n..=n };
        for (m, axis) in self.axes.iter_mut().enumerate() {
            for c in range.clone() {
                axis.coordinates[c as usize] = self.persistence.coordinate(m as u8, c);
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use crate::test_support::{direct, in_program, module, ok, status};
    use tmclsim_protocol::Status;

    #[test]
    fn sco_gco_aco_in_ram() {
        let mut m = module("tmcm-1141");
        ok(&mut m, "SCO 4, 0, -1234");
        assert_eq!(ok(&mut m, "GCO 4, 0"), -1234);
        ok(&mut m, "CALC LOAD, 99");
        ok(&mut m, "ACO 20, 0");
        assert_eq!(ok(&mut m, "GCO 20, 0"), 99);
        assert_eq!(status(&mut m, "SCO 21, 0, 1"), Status::WrongType, "coordinates 0…20");
        assert_eq!(status(&mut m, "GCO 21, 0"), Status::WrongType);
        assert_eq!(status(&mut m, "SCO 1, 1, 1"), Status::InvalidValue, "one motor");
        assert!(m.eeprom().coordinates.is_empty(), "GP 84 = 0: RAM only");
        assert_eq!(in_program(&mut m, "GCO 4, 0"), Ok(-1234));
        assert_eq!(m.registers.accumulator, -1234);
    }

    #[test]
    fn cco_captures_the_actual_position() {
        let mut m = module("tmcm-1141");
        ok(&mut m, "SAP 1, 0, 31415");
        assert_eq!(direct(&mut m, "CCO 2, 0"), (Status::Ok, 31415), "the reply carries the position");
        assert_eq!(ok(&mut m, "GCO 2, 0"), 31415);
    }

    #[test]
    fn motor_255_copies_between_ram_and_eeprom() {
        let mut m = module("tmcm-1141");
        ok(&mut m, "SCO 1, 0, 10");
        ok(&mut m, "SCO 2, 0, 20");
        ok(&mut m, "SCO 0, 0, 5");
        ok(&mut m, "SCO 2, 255, 0");
        assert_eq!((m.eeprom().coordinate(0, 1), m.eeprom().coordinate(0, 2)), (None, Some(20)));
        ok(&mut m, "SCO 0, 255, 0");
        assert_eq!(m.eeprom().coordinate(0, 1), Some(10), "0: all but coordinate 0");
        assert_eq!(m.eeprom().coordinate(0, 0), None);
        ok(&mut m, "SCO 1, 0, 0");
        ok(&mut m, "SCO 2, 0, 0");
        ok(&mut m, "GCO 1, 255");
        assert_eq!((ok(&mut m, "GCO 1, 0"), ok(&mut m, "GCO 2, 0")), (10, 0));
        ok(&mut m, "GCO 0, 255");
        assert_eq!(ok(&mut m, "GCO 2, 0"), 20);
        assert_eq!(ok(&mut m, "GCO 0, 0"), 5, "coordinate 0 stays");
    }

    #[test]
    fn gp84_stores_every_sco() {
        let mut m = module("tmcm-1141");
        ok(&mut m, "SGP 84, 0, 1");
        let written = m.eeprom_generation();
        ok(&mut m, "SCO 3, 0, 333");
        assert_eq!((m.eeprom().coordinate(0, 3), m.eeprom_generation()), (Some(333), written + 1));
        ok(&mut m, "SCO 0, 0, 7");
        assert_eq!(m.eeprom().coordinate(0, 0), None, "coordinate 0 is RAM only");
    }
}
