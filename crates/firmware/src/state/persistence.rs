//! What survives a power cycle: the EEPROM image, a marker that changes
//! whenever the image was written (a server saves the image when it
//! changes), and whether the last power-up found stored values.

use crate::eeprom::Eeprom;

#[derive(Clone, Debug)]
pub struct Persistence {
    pub eeprom: Eeprom,
    /// Bumped on every EEPROM write.
    generation: u64,
    /// The last power-up found stored values in the EEPROM.
    pub restored: bool,
}

impl Persistence {
    pub fn new(eeprom: Eeprom) -> Persistence {
        Persistence { eeprom, generation: 0, restored: false }
    }

    /// Records that the EEPROM image was written.
    pub fn mark_written(&mut self) {
        self.generation += 1;
    }

    /// Changes whenever the image was written.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// Stores a global parameter in the EEPROM.
    pub fn store_global(&mut self, bank: u8, param: u8, value: i32) {
        self.eeprom.set_global(bank, param, value);
        self.mark_written();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_write_changes_the_generation() {
        let mut p = Persistence::new(Eeprom::new("TMCM-1141"));
        assert_eq!(p.generation(), 0);
        p.mark_written();
        assert_eq!(p.generation(), 1);
        p.store_global(0, 66, 5);
        assert_eq!(p.generation(), 2);
        assert_eq!(p.eeprom.global(0, 66), Some(5));
        assert!(!p.restored);
    }
}
