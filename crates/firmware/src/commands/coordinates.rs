//! The coordinate commands: SCO, GCO, CCO, ACO — coordinates in RAM, and
//! with motor 255 (or GP 84) in the EEPROM.

use crate::commands::Exec;
use crate::module::Module;
use crate::outcome::Origin;
use crate::parameter_numbers::gp;
use tmclsim_protocol::{Command, Status};

impl Module {
    /// SCO, GCO, CCO, ACO.
    pub(crate) fn coordinate_command(&mut self, cmd: Command, echo: i32, origin: Origin) -> Exec {
        use Command::*;
        match cmd {
            Sco { coordinate, motor, value } => self.set_coordinate(coordinate, motor, Some(value)).map(|_| echo),
            Aco { coordinate, motor } => {
                let a = self.registers.accumulator;
                self.set_coordinate(coordinate, motor, Some(a)).map(|_| echo)
            }
            Cco { coordinate, motor } => {
                let m = self.motor(motor)?;
                let pos = self.actual_position(m);
                self.set_coordinate(coordinate, motor, Some(pos))?;
                Ok(pos)
            }
            Gco { coordinate, motor } => {
                if motor == 255 {
                    self.coordinates_from_eeprom(coordinate)?;
                    return Ok(echo);
                }
                let m = self.motor(motor)?;
                let v = *self.axes[m].coordinates.get(coordinate as usize).ok_or(Status::WrongType)?;
                Ok(self.loaded(v, origin))
            }
            _ => unreachable!("not a coordinate command: {cmd:?}"),
        }
    }

    fn set_coordinate(&mut self, n: u8, motor: u8, value: Option<i32>) -> Result<(), Status> {
        if n as usize > self.profile.module.coordinates as usize {
            return Err(Status::WrongType);
        }
        if motor == 255 {
            if self.eeprom_locked() {
                return Err(Status::EepromLocked);
            }
            // SCO n, 255, 0: RAM → EEPROM (0 = all but coordinate 0).
            let range = if n == 0 { 1..=self.profile.module.coordinates } else { n..=n };
            for m in 0..self.axes.len() {
                for c in range.clone() {
                    let v = self.axes[m].coordinates[c as usize];
                    self.persistence.eeprom.set_coordinate(m as u8, c, v);
                }
            }
            self.persistence.mark_written();
            return Ok(());
        }
        let m = self.motor(motor)?;
        let v = value.unwrap_or(0);
        self.axes[m].coordinates[n as usize] = v;
        if n > 0 && self.globals[0][gp::COORDINATE_STORAGE as usize] == 1 {
            self.persistence.eeprom.set_coordinate(motor, n, v);
            self.persistence.mark_written();
        }
        Ok(())
    }

    /// GCO n, 255: EEPROM → RAM (0 = all but coordinate 0).
    fn coordinates_from_eeprom(&mut self, n: u8) -> Result<(), Status> {
        if n as usize > self.profile.module.coordinates as usize {
            return Err(Status::WrongType);
        }
        let range = if n == 0 { 1..=self.profile.module.coordinates } else { n..=n };
        for m in 0..self.axes.len() {
            for c in range.clone() {
                self.axes[m].coordinates[c as usize] = self.persistence.eeprom.coordinate(m as u8, c).unwrap_or(0);
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
