//! The EEPROM part: what survives a power cycle. The image, a marker that
//! changes whenever the image was written (a server saves the image when
//! it changes), whether the last power-up found stored values, and the
//! stores and restores of the commands that reach the EEPROM (STAP, RSAP,
//! STGP, RSGP, SCO and GCO with motor 255, the program download, 137),
//! with the lock that may forbid them (docs/behaviour.md rule 73).

use crate::eeprom::Eeprom;
use crate::state::globals::Globals;
use tmclsim_profile::Parameter;
use tmclsim_protocol::{Instruction, Status};

#[derive(Clone, Debug)]
pub struct Persistence {
    eeprom: Eeprom,
    /// Bumped on every EEPROM write.
    generation: u64,
    /// The last power-up found stored values in the EEPROM.
    pub restored: bool,
    /// The global parameter (bank 0) that locks the configuration EEPROM
    /// (features `eeprom_lock`, GP 73 on the TMCM-351), if the module has one.
    lock: Option<u8>,
}

impl Persistence {
    pub fn new(eeprom: Eeprom, lock: Option<u8>) -> Persistence {
        Persistence { eeprom, generation: 0, restored: false, lock }
    }

    /// The image as it is.
    pub fn eeprom(&self) -> &Eeprom {
        &self.eeprom
    }

    /// Puts back an image (no write: it is known to be stored).
    pub fn replace(&mut self, image: Eeprom) {
        self.eeprom = image;
    }

    /// Records the firmware a firmware update left in flash (kept with the
    /// EEPROM; the EEPROM lock does not guard the flash).
    pub fn set_firmware(&mut self, firmware: crate::eeprom::Firmware) {
        self.eeprom.firmware = firmware;
        self.mark_written();
    }

    /// Records that the EEPROM image was written.
    pub fn mark_written(&mut self) {
        self.generation += 1;
    }

    /// Changes whenever the image was written.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// The lock parameter reads 1: the configuration EEPROM is locked.
    pub fn locked(&self, globals: &Globals) -> bool {
        self.lock.is_some_and(|n| globals[0][n as usize] == 1)
    }

    fn unlocked(&self, globals: &Globals) -> Result<(), Status> {
        if self.locked(globals) { Err(Status::EepromLocked) } else { Ok(()) }
    }

    /// Whether `param` of `bank` is the lock parameter.
    pub fn is_lock(&self, bank: u8, param: u8) -> bool {
        bank == 0 && self.lock == Some(param)
    }

    /// SGP of the lock parameter: 1234 locks, 4321 unlocks; the state (1,
    /// 0) is kept in RAM and in the EEPROM.
    pub fn set_lock(&mut self, globals: &mut Globals, param: u8, word: i32) -> Result<(), Status> {
        let locked = match word {
            1234 => 1,
            4321 => 0,
            _ => return Err(Status::InvalidValue),
        };
        globals[0][param as usize] = locked;
        self.store_global(0, param, locked);
        Ok(())
    }

    /// Stores a global parameter in the EEPROM (no lock check: SGP of an
    /// auto-stored parameter checks it, `set_address` does not).
    pub fn store_global(&mut self, bank: u8, param: u8, value: i32) {
        self.eeprom.set_global(bank, param, value);
        self.mark_written();
    }

    /// STAP: stores an axis parameter's value.
    pub fn store_axis(&mut self, globals: &Globals, motor: u8, param: u8, value: i32) -> Result<(), Status> {
        self.unlocked(globals)?;
        self.eeprom.set_axis(motor, param, value);
        self.mark_written();
        Ok(())
    }

    /// STGP: stores a global parameter's value.
    pub fn store_global_checked(&mut self, globals: &Globals, bank: u8, param: u8) -> Result<(), Status> {
        self.unlocked(globals)?;
        self.store_global(bank, param, globals[bank as usize][param as usize]);
        Ok(())
    }

    /// Checks the lock before a write of an auto-stored global parameter.
    pub fn check_unlocked(&self, globals: &Globals) -> Result<(), Status> {
        self.unlocked(globals)
    }

    /// RSAP: the stored value of an axis parameter, or its default; a
    /// stored value out of range is not taken, as at power-up
    /// (docs/behaviour.md rule 88).
    pub fn restore_axis(&self, motor: u8, spec: &Parameter) -> i32 {
        self.eeprom.axis(motor, spec.number).filter(|&v| spec.accepts(v)).unwrap_or(spec.default_word())
    }

    /// RSGP: the stored value of a global parameter, or its default.
    pub fn restore_global(&self, bank: u8, spec: &Parameter) -> i32 {
        self.eeprom.global(bank, spec.number).filter(|&v| spec.accepts(v)).unwrap_or(spec.default_word())
    }

    /// SCO n, 255: the coordinates `range` of every motor (`coordinates[motor]`)
    /// into the EEPROM.
    pub fn store_coordinates(
        &mut self,
        globals: &Globals,
        coordinates: &[&[i32]],
        range: std::ops::RangeInclusive<u8>,
    ) -> Result<(), Status> {
        self.unlocked(globals)?;
        for (m, coords) in coordinates.iter().enumerate() {
            for c in range.clone() {
                self.eeprom.set_coordinate(m as u8, c, coords[c as usize]);
            }
        }
        self.mark_written();
        Ok(())
    }

    /// SCO with GP 84 set: one coordinate goes to the EEPROM as well.
    pub fn store_coordinate(&mut self, motor: u8, n: u8, value: i32) {
        self.eeprom.set_coordinate(motor, n, value);
        self.mark_written();
    }

    /// GCO n, 255 and power-up: a stored coordinate, 0 when none is.
    pub fn coordinate(&self, motor: u8, n: u8) -> i32 {
        self.eeprom.coordinate(motor, n).unwrap_or(0)
    }

    /// A downloaded word is in the EEPROM when it is acknowledged.
    pub fn store_program_word(&mut self, address: u16, ins: Instruction) {
        self.eeprom.program.insert(address, ins.to_bytes());
        self.mark_written();
    }

    /// A whole program replaces the stored one.
    pub fn store_program(&mut self, words: &[Instruction]) {
        self.eeprom.program = words.iter().enumerate().map(|(a, w)| (a as u16, w.to_bytes())).collect();
        self.mark_written();
    }

    /// The stored program is erased (SGP 81 lifting the read protection).
    pub fn erase_program(&mut self) {
        self.eeprom.program.clear();
        self.mark_written();
    }

    /// 137: every setting is forgotten, unless the EEPROM is locked
    /// (docs/behaviour.md rule 73).
    pub fn factory_defaults(&mut self, globals: &Globals) -> Result<(), Status> {
        self.unlocked(globals)?;
        self.eeprom.clear();
        self.mark_written();
        Ok(())
    }

    /// Power-up: an image whose magic word (`parameter` of bank 0) is not
    /// `value` is re-initialised (TMCM-351 GP 64).
    pub fn check_magic(&mut self, parameter: u8, value: i32) {
        if self.eeprom.global(0, parameter).is_some_and(|v| v != value) {
            self.eeprom.clear();
            self.eeprom.set_global(0, parameter, value);
            self.mark_written();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_write_changes_the_generation() {
        let mut p = Persistence::new(Eeprom::new("TMCM-1141"), None);
        assert_eq!(p.generation(), 0);
        p.mark_written();
        assert_eq!(p.generation(), 1);
        p.store_global(0, 66, 5);
        assert_eq!(p.generation(), 2);
        assert_eq!(p.eeprom.global(0, 66), Some(5));
        assert!(!p.restored);
    }

    #[test]
    fn the_lock_refuses_stores() {
        let mut globals = Globals::default();
        let mut p = Persistence::new(Eeprom::new("TMCM-351"), Some(73));
        assert_eq!(p.set_lock(&mut globals, 73, 7), Err(Status::InvalidValue));
        p.set_lock(&mut globals, 73, 1234).unwrap();
        assert!(p.locked(&globals) && p.eeprom.global(0, 73) == Some(1));
        assert_eq!(p.store_axis(&globals, 0, 4, 1), Err(Status::EepromLocked));
        assert_eq!(p.factory_defaults(&globals), Err(Status::EepromLocked));
        p.set_lock(&mut globals, 73, 4321).unwrap();
        assert_eq!(p.store_axis(&globals, 0, 4, 1), Ok(()));
        assert_eq!(p.eeprom.axis(0, 4), Some(1));
    }
}
