//! The module's EEPROM: the cells that survive a power cycle.
//!
//! The image holds only cells that were written; a missing cell reads as
//! the factory default. An image is kept as JSON text ([`Eeprom::to_json`],
//! [`Eeprom::from_json`]); whoever keeps it (the server's crash-safe
//! EEPROM file, `tmclsim_server::eeprom_file`) checks a loaded image
//! against its module with [`Eeprom::check`].

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Format version of the EEPROM file.
pub const FORMAT: u32 = 1;

#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
/// The module's EEPROM image: what survives a power cycle (stored axis and
/// global parameters, coordinates, the TMCL program). Front ends keep it as
/// JSON (`to_json`, `from_json`).
pub struct Eeprom {
    /// File format version.
    pub format: u32,
    /// The module the image belongs to (a TMCM-351 image is not loaded
    /// into a TMCM-1141).
    pub module: String,
    /// Axis parameters: key `"motor/parameter"`.
    pub axis: BTreeMap<String, i32>,
    /// Global parameters: key `"bank/parameter"`.
    pub global: BTreeMap<String, i32>,
    /// Coordinates: key `"motor/coordinate"`.
    pub coordinates: BTreeMap<String, i32>,
    /// TMCL program memory: address → instruction bytes.
    #[serde(default)]
    pub program: BTreeMap<u16, [u8; 7]>,
    /// The firmware in flash, kept with the EEPROM because both outlive a
    /// power cycle (docs/behaviour.md rule 102); absent: the factory's.
    #[serde(default, skip_serializing_if = "Firmware::is_factory")]
    pub firmware: Firmware,
}

/// The firmware the module's flash holds, which the bootloader starts at
/// power-up when it is valid (docs/behaviour.md rules 99–103).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "state", rename_all = "lowercase")]
pub enum Firmware {
    /// The firmware the module left the factory with (its profile's).
    #[default]
    Factory,
    /// A complete image written by a firmware update, of this version.
    Installed {
        /// Major and minor version (1, 47 for V1.47).
        version: [u8; 2],
    },
    /// Erased, or written but not completed: the bootloader stays.
    Invalid,
}

impl Firmware {
    /// The factory's firmware (not written to the file).
    pub fn is_factory(&self) -> bool {
        *self == Firmware::Factory
    }
}

fn key(a: u8, b: u8) -> String {
    format!("{a}/{b}")
}

impl Eeprom {
    /// An empty image for the module named `module`.
    pub fn new(module: &str) -> Eeprom {
        Eeprom { format: FORMAT, module: module.to_string(), ..Eeprom::default() }
    }

    /// The stored value of axis parameter `param` of `motor`, if any.
    pub fn axis(&self, motor: u8, param: u8) -> Option<i32> {
        self.axis.get(&key(motor, param)).copied()
    }

    /// Stores a value of axis parameter `param` of `motor` (STAP).
    pub fn set_axis(&mut self, motor: u8, param: u8, value: i32) {
        self.axis.insert(key(motor, param), value);
    }

    /// The stored value of global parameter `param` of `bank`, if any.
    pub fn global(&self, bank: u8, param: u8) -> Option<i32> {
        self.global.get(&key(bank, param)).copied()
    }

    /// Stores a value of global parameter `param` of `bank` (STGP).
    pub fn set_global(&mut self, bank: u8, param: u8, value: i32) {
        self.global.insert(key(bank, param), value);
    }

    /// Stored coordinate `n` of `motor`, if any.
    pub fn coordinate(&self, motor: u8, n: u8) -> Option<i32> {
        self.coordinates.get(&key(motor, n)).copied()
    }

    /// Stores coordinate `n` of `motor`.
    pub fn set_coordinate(&mut self, motor: u8, n: u8, value: i32) {
        self.coordinates.insert(key(motor, n), value);
    }

    /// Forgets every setting (137: restore factory settings). The TMCL
    /// program stays: it is not a setting.
    pub fn clear(&mut self) {
        let module = std::mem::take(&mut self.module);
        let program = std::mem::take(&mut self.program);
        let firmware = self.firmware;
        *self = Eeprom::new(&module);
        self.program = program;
        self.firmware = firmware;
    }

    /// The image as pretty-printed JSON, the form of an EEPROM file.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("EEPROM image serialises")
    }

    /// Reads an image written by `to_json`; refuses text that is no image or
    /// another format version.
    pub fn from_json(text: &str) -> Result<Eeprom, ImageTextError> {
        let e: Eeprom = serde_json::from_str(text).map_err(|e| ImageTextError::Unreadable(e.to_string()))?;
        if e.format != FORMAT {
            return Err(ImageTextError::Format(e.format));
        }
        Ok(e)
    }
}

/// Why the text of an EEPROM image is not taken ([`Eeprom::from_json`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ImageTextError {
    /// Not JSON of an image; what the parser says.
    Unreadable(String),
    /// An image of another format version.
    Format(u32),
}

impl std::fmt::Display for ImageTextError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ImageTextError::Unreadable(e) => write!(f, "EEPROM file is not readable: {e}"),
            ImageTextError::Format(n) => write!(f, "EEPROM file has format {n}, this tmclsim reads {FORMAT}"),
        }
    }
}

impl std::error::Error for ImageTextError {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_through_json_text() {
        let mut e = Eeprom::new("TMCM-1141");
        e.set_axis(0, 4, 1234);
        e.set_global(2, 7, -5);
        e.set_coordinate(0, 3, 99);
        e.program.insert(0, [2, 0, 0, 0, 0, 3, 0xE8]);
        assert_eq!(Eeprom::from_json(&e.to_json()), Ok(e));
        assert!(Eeprom::from_json("{ torn").unwrap_err().to_string().starts_with("EEPROM file is not readable: "));
        let other = Eeprom { format: FORMAT + 1, ..Eeprom::new("TMCM-1141") };
        assert_eq!(
            Eeprom::from_json(&other.to_json()).unwrap_err().to_string(),
            format!("EEPROM file has format {}, this tmclsim reads {FORMAT}", FORMAT + 1)
        );
    }
}
