//! The EEPROM files of a bus's modules and the image each file holds:
//! module `i`'s EEPROM writes are saved to file `i`, and a save that fails
//! puts the module back to what its file holds (docs/behaviour.md rule
//! 82). The shared bus ([`crate::shared::SharedBus`]) and a server's
//! EtherCAT segment both save through it.

use crate::eeprom_file::EepromFile;
use std::sync::Arc;
use tmclsim_firmware::{Bus, Eeprom};

/// The EEPROM files of a bus's modules, by module index.
pub struct EepromFiles {
    files: Vec<Option<Arc<EepromFile>>>,
    /// The image each module's file holds: what the module's EEPROM goes
    /// back to when a save fails.
    persisted: Vec<Eeprom>,
    /// The command that made a write is answered status 5 when the write
    /// cannot be saved (on a TMCL link; an EtherCAT frame has passed by
    /// then).
    answered_not_stored: bool,
}

impl EepromFiles {
    /// The files of `bus`'s modules (`files` shorter than the bus: no file
    /// for the rest). A module's EEPROM image is taken to be what its
    /// file holds.
    pub fn new(bus: &Bus, mut files: Vec<Option<Arc<EepromFile>>>, answered_not_stored: bool) -> EepromFiles {
        files.resize(bus.len(), None);
        let persisted = bus.modules().iter().map(|m| m.eeprom().clone()).collect();
        EepromFiles { files, persisted, answered_not_stored }
    }

    /// Some module has a file.
    pub fn any(&self) -> bool {
        self.files.iter().any(Option::is_some)
    }

    /// Saves `image`, module `index`'s EEPROM, to its file (nothing to do
    /// without one). False when the file does not take it: that is said
    /// on stderr, and the module must go back to [`EepromFiles::held`].
    pub fn save(&mut self, index: usize, image: &Eeprom) -> bool {
        let Some(Some(file)) = self.files.get(index) else { return true };
        match file.save(image) {
            Ok(()) => {
                self.persisted[index] = image.clone();
                true
            }
            Err(e) => {
                let status = if self.answered_not_stored { "status 5 to the command that made it; " } else { "" };
                eprintln!(
                    "tmclsim: cannot write EEPROM file {}: {e}; the write is not kept ({status}the module keeps the EEPROM the file holds)",
                    file.named().display()
                );
                false
            }
        }
    }

    /// The image module `index`'s file holds.
    pub fn held(&self, index: usize) -> &Eeprom {
        &self.persisted[index]
    }

    /// Saves module `index`'s EEPROM on `bus` to its file; when the file
    /// does not take it, the module goes back to what the file holds and
    /// `false` is returned.
    pub fn save_from(&mut self, bus: &mut Bus, index: usize) -> bool {
        if self.save(index, bus.module(index).eeprom()) {
            return true;
        }
        bus.module_mut(index).restore_eeprom(self.held(index).clone());
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tmclsim_firmware::Module;

    #[test]
    fn a_save_the_file_does_not_take_puts_the_module_back() {
        let dir = tempfile::tempdir().unwrap();
        let store = dir.path().join("store");
        std::fs::create_dir(&store).unwrap();
        let file = Arc::new(EepromFile::open(&store.join("m.eeprom")).unwrap());
        let mut bus = Bus::new(vec![Module::built_in("tmcm-1141").unwrap(), Module::built_in("tmcm-1141").unwrap()]);
        let mut files = EepromFiles::new(&bus, vec![Some(file)], true);
        assert!(files.any());
        let mut image = bus.module(0).eeprom().clone();
        image.set_axis(0, 4, 1000);
        bus.module_mut(0).restore_eeprom(image.clone());
        assert!(files.save_from(&mut bus, 0));
        assert_eq!(files.held(0), &image);
        assert!(files.save_from(&mut bus, 1), "no file: nothing to save");

        // No file can be created where the directory was.
        std::fs::rename(&store, dir.path().join("away")).unwrap();
        std::fs::write(&store, "").unwrap();
        let mut newer = image.clone();
        newer.set_axis(0, 4, 2000);
        bus.module_mut(0).restore_eeprom(newer);
        assert!(!files.save_from(&mut bus, 0));
        assert_eq!(bus.module(0).eeprom(), &image, "back to what the file holds");
    }
}
