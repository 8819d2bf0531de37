//! The module's EEPROM: the cells that survive a power cycle.
//!
//! The image holds only cells that were written; a missing cell reads as
//! the factory default. [`save_atomic`] writes an image to a file so that a
//! process killed at any moment leaves either the old or the new file,
//! never a torn one (write to a temporary file, sync, rename, sync the
//! directory).

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::io::Write;
use std::path::Path;

/// Format version of the EEPROM file.
pub const FORMAT: u32 = 1;

#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
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
}

fn key(a: u8, b: u8) -> String {
    format!("{a}/{b}")
}

impl Eeprom {
    pub fn new(module: &str) -> Eeprom {
        Eeprom { format: FORMAT, module: module.to_string(), ..Eeprom::default() }
    }

    pub fn axis(&self, motor: u8, param: u8) -> Option<i32> {
        self.axis.get(&key(motor, param)).copied()
    }

    pub fn set_axis(&mut self, motor: u8, param: u8, value: i32) {
        self.axis.insert(key(motor, param), value);
    }

    pub fn global(&self, bank: u8, param: u8) -> Option<i32> {
        self.global.get(&key(bank, param)).copied()
    }

    pub fn set_global(&mut self, bank: u8, param: u8, value: i32) {
        self.global.insert(key(bank, param), value);
    }

    pub fn coordinate(&self, motor: u8, n: u8) -> Option<i32> {
        self.coordinates.get(&key(motor, n)).copied()
    }

    pub fn set_coordinate(&mut self, motor: u8, n: u8, value: i32) {
        self.coordinates.insert(key(motor, n), value);
    }

    /// Forgets every setting (137: restore factory settings). The TMCL
    /// program stays: it is not a setting.
    pub fn clear(&mut self) {
        let module = std::mem::take(&mut self.module);
        let program = std::mem::take(&mut self.program);
        *self = Eeprom::new(&module);
        self.program = program;
    }

    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("EEPROM image serialises")
    }

    pub fn from_json(text: &str) -> Result<Eeprom, String> {
        let e: Eeprom = serde_json::from_str(text).map_err(|e| format!("EEPROM file is not readable: {e}"))?;
        if e.format != FORMAT {
            return Err(format!("EEPROM file has format {}, this tmclsim reads {FORMAT}", e.format));
        }
        Ok(e)
    }

    /// Loads an EEPROM file; `Ok(None)` when it does not exist yet.
    pub fn load(path: &Path) -> Result<Option<Eeprom>, String> {
        match std::fs::read_to_string(path) {
            Ok(text) => Eeprom::from_json(&text).map(Some).map_err(|e| format!("{}: {e}", path.display())),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
            Err(e) => Err(format!("{}: {e}", path.display())),
        }
    }
}

/// The EEPROM a module of `module_name` powers up with from `path`: the
/// stored image (`true`), or an empty one when the file does not exist
/// yet (`false`). A file of another module is refused.
pub fn load_for(path: &Path, module_name: &str) -> Result<(Eeprom, bool), String> {
    match Eeprom::load(path)? {
        Some(image) if image.module != module_name => {
            Err(format!("{} holds the EEPROM of a {}, not of a {module_name}", path.display(), image.module))
        }
        Some(image) => Ok((image, true)),
        None => Ok((Eeprom::new(module_name), false)),
    }
}

/// Writes the image to `path` atomically.
pub fn save_atomic(path: &Path, image: &Eeprom) -> std::io::Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| "eeprom".into());
    // One writer per file: a temporary left by a killed process is simply
    // overwritten by the next save.
    let tmp = dir.join(format!(".{name}.tmp"));
    {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(image.to_json().as_bytes())?;
        f.sync_all()?;
    }
    std::fs::rename(&tmp, path)?;
    if let Ok(d) = std::fs::File::open(dir) {
        let _ = d.sync_all();
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_through_a_file() {
        let dir = std::env::temp_dir().join(format!("tmclsim-eeprom-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("m.eeprom");
        assert_eq!(Eeprom::load(&path).unwrap(), None);
        let mut e = Eeprom::new("TMCM-1141");
        e.set_axis(0, 4, 1234);
        e.set_global(2, 7, -5);
        e.set_coordinate(0, 3, 99);
        e.program.insert(0, [2, 0, 0, 0, 0, 3, 0xE8]);
        save_atomic(&path, &e).unwrap();
        assert_eq!(Eeprom::load(&path).unwrap(), Some(e));
        std::fs::write(&path, "{ torn").unwrap();
        assert!(Eeprom::load(&path).unwrap_err().contains("not readable"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
