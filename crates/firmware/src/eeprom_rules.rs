//! What an EEPROM image may hold (docs/behaviour.md rule 88): only what
//! the module itself could have stored there. Every axis parameter of a
//! motor the module has, every global parameter of a bank it has, with E
//! (or A) access and a value its SAP/SGP takes; coordinates 1…N of its
//! motors; program words inside its program memory. A real module never
//! stores a value its SAP refused, so an image holding one was edited or
//! damaged, and it is refused as a whole, naming every entry it refuses.
//!
//! Pure logic on the image and the profile: reading and writing the file
//! is `crate::eeprom`'s business.

use crate::eeprom::Eeprom;
use std::collections::BTreeMap;
use tmclsim_profile::{Parameter, Profile};

/// Refused entries a message lists; the rest are counted.
pub const LISTED: usize = 10;

/// An entry of an image that the module never stores.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Refused {
    /// The entry as the file holds it: `global "0/75" = 2147483647`.
    pub entry: String,
    /// Why: the parameter (number and name), the motor or bank, and what
    /// the module takes.
    pub reason: String,
}

impl std::fmt::Display for Refused {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.entry, self.reason)
    }
}

/// `"3/75"` → (3, 75); only the form the image is written in (no sign, no
/// leading zero, no blank), so that no two keys name one cell.
fn cell_key(key: &str) -> Option<(u8, u8)> {
    let (a, b) = key.split_once('/')?;
    let number = |s: &str| s.parse::<u8>().ok().filter(|n| n.to_string() == s);
    Some((number(a)?, number(b)?))
}

/// "motor 0" / "motors 0…2".
fn motors(profile: &Profile) -> String {
    match profile.module.axes {
        1 => "motor 0".to_string(),
        n => format!("motors 0…{}", n - 1),
    }
}

/// What the module takes for a parameter it stores.
fn takes(profile: &Profile, bank: Option<u8>, p: &Parameter, value: i32) -> Option<String> {
    // The EEPROM lock (GP 73 on the TMCM-351) is stored as its state,
    // not as the word SGP takes (1234 locks, 4321 unlocks).
    if bank == Some(0) && profile.features.eeprom_lock == Some(p.number) {
        return (!matches!(value, 0 | 1)).then(|| "is stored as 0 or 1 (unlocked, locked)".to_string());
    }
    (!p.accepts(value)).then(|| format!("takes {}", p.range_text()))
}

impl Eeprom {
    /// Every entry of the image that a module of `profile` never stores
    /// (docs/behaviour.md rule 88), in file order: axis parameters, global
    /// parameters, coordinates, program words. Empty: the image may be
    /// loaded. The module name is not looked at ([`Eeprom::check`] does).
    pub fn refused_entries(&self, profile: &Profile) -> Vec<Refused> {
        let name = &profile.module.name;
        let mut refused = Vec::new();
        let mut refuse = |table: &str, key: &str, value: i32, reason: String| {
            refused.push(Refused { entry: format!("{table} \"{key}\" = {value}"), reason });
        };
        let cells = |map: &BTreeMap<String, i32>| map.iter().map(|(k, &v)| (k.clone(), cell_key(k), v)).collect::<Vec<_>>();

        for (key, cell, value) in cells(&self.axis) {
            let Some((motor, number)) = cell else {
                refuse("axis", &key, value, "not a MOTOR/PARAMETER key".into());
                continue;
            };
            if motor >= profile.module.axes {
                refuse("axis", &key, value, format!("motor {motor} does not exist (a {name} has {})", motors(profile)));
                continue;
            }
            let Some(p) = profile.axis_parameter(number) else {
                refuse("axis", &key, value, format!("a {name} has no AP {number}"));
                continue;
            };
            if !p.access.eeprom {
                refuse("axis", &key, value, format!("AP {number} ({}) is not stored in the EEPROM (access {})", p.name, p.access));
            } else if let Some(allowed) = takes(profile, None, p, value) {
                refuse("axis", &key, value, format!("AP {number} ({}) of motor {motor} {allowed}", p.name));
            }
        }

        for (key, cell, value) in cells(&self.global) {
            let Some((bank, number)) = cell else {
                refuse("global", &key, value, "not a BANK/PARAMETER key".into());
                continue;
            };
            if !profile.has_bank(bank) {
                let banks: Vec<String> = (0..=u8::MAX).filter(|&b| profile.has_bank(b)).map(|b| b.to_string()).collect();
                refuse("global", &key, value, format!("bank {bank} does not exist (a {name} has banks {})", banks.join(", ")));
                continue;
            }
            let Some(p) = profile.global_parameter(bank, number) else {
                refuse("global", &key, value, format!("a {name} has no GP {number} in bank {bank}"));
                continue;
            };
            if !(p.access.eeprom || p.access.auto) {
                refuse(
                    "global",
                    &key,
                    value,
                    format!("GP {number} ({}) of bank {bank} is not stored in the EEPROM (access {})", p.name, p.access),
                );
            } else if let Some(allowed) = takes(profile, Some(bank), p, value) {
                refuse("global", &key, value, format!("GP {number} ({}) of bank {bank} {allowed}", p.name));
            }
        }

        let coordinates = profile.module.coordinates;
        for (key, cell, value) in cells(&self.coordinates) {
            let Some((motor, n)) = cell else {
                refuse("coordinates", &key, value, "not a MOTOR/COORDINATE key".into());
                continue;
            };
            if motor >= profile.module.axes {
                refuse("coordinates", &key, value, format!("motor {motor} does not exist (a {name} has {})", motors(profile)));
            } else if n == 0 {
                refuse("coordinates", &key, value, "coordinate 0 is kept in RAM only".into());
            } else if n > coordinates {
                refuse("coordinates", &key, value, format!("a {name} has coordinates 1…{coordinates}"));
            }
        }

        let words = profile.module.program_memory;
        for &address in self.program.keys().filter(|&&a| a >= words) {
            refused.push(Refused {
                entry: format!("program \"{address}\""),
                reason: format!("the address is outside the program memory of a {name} (0…{})", words.saturating_sub(1)),
            });
        }
        refused
    }

    /// The image checked against the module it is for (docs/behaviour.md
    /// rule 88): it must be that module's, and hold nothing the module
    /// never stores. The error reads as a sentence to put after the file's
    /// name.
    pub fn check(&self, profile: &Profile) -> Result<(), ImageError> {
        let name = &profile.module.name;
        if self.module != *name {
            return Err(ImageError::OtherModule { image: self.module.clone(), module: name.clone() });
        }
        let refused = self.refused_entries(profile);
        if refused.is_empty() {
            return Ok(());
        }
        Err(ImageError::Refused { module: name.clone(), entries: refused })
    }
}

/// Why an image is not loaded into a module ([`Eeprom::check`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ImageError {
    /// The image is another module's.
    OtherModule {
        /// The module named in the image.
        image: String,
        /// The module it was to be loaded into.
        module: String,
    },
    /// Entries the module never stores (at least one).
    Refused {
        /// The module that refuses them.
        module: String,
        /// The entries, each with why it is refused.
        entries: Vec<Refused>,
    },
}

impl std::fmt::Display for ImageError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ImageError::OtherModule { image, module } => write!(f, "the file holds the EEPROM of a {image}, not of a {module}"),
            ImageError::Refused { module, entries } => {
                let mut list: Vec<String> = entries.iter().take(LISTED).map(Refused::to_string).collect();
                if entries.len() > LISTED {
                    list.push(format!("and {} more", entries.len() - LISTED));
                }
                let (what, these) = if entries.len() == 1 { ("an entry", "it") } else { ("entries", "them") };
                write!(
                    f,
                    "refused: {what} a {module} never stores, so the file was edited or damaged: {}; correct or remove {these} \
                     (or remove the file to start from factory defaults)",
                    list.join("; ")
                )
            }
        }
    }
}

impl std::error::Error for ImageError {}

#[cfg(test)]
mod tests {
    use super::*;

    fn profile(name: &str) -> std::sync::Arc<Profile> {
        Profile::built_in(name).unwrap()
    }

    fn reasons(image: &Eeprom, profile: &Profile) -> Vec<String> {
        image.refused_entries(profile).iter().map(Refused::to_string).collect()
    }

    #[test]
    fn what_the_module_stores_is_accepted() {
        for name in Profile::names() {
            let p = profile(name);
            let mut e = Eeprom::new(&p.module.name);
            for motor in 0..p.module.axes {
                for a in p.axis_parameters().filter(|a| a.access.eeprom) {
                    e.set_axis(motor, a.number, a.default_word());
                    e.set_axis(motor, a.number, a.max.min(i64::from(i32::MAX)) as i32);
                }
                for n in 1..=p.module.coordinates {
                    e.set_coordinate(motor, n, i32::MIN);
                }
            }
            for bank in 0..4 {
                for g in p.global_parameters(bank).filter(|g| g.access.eeprom || g.access.auto) {
                    let v = if p.features.eeprom_lock == Some(g.number) && bank == 0 { 1 } else { g.default_word() };
                    e.set_global(bank, g.number, v);
                }
            }
            e.program.insert(p.module.program_memory - 1, [255; 7]);
            assert_eq!(reasons(&e, &p), Vec::<String>::new(), "{name}");
            assert_eq!(e.check(&p), Ok(()), "{name}");
        }
    }

    #[test]
    fn a_value_outside_the_range_is_refused_naming_parameter_motor_bank_value_and_range() {
        let p = profile("tmcm-1141");
        let mut e = Eeprom::new("TMCM-1141");
        e.set_global(0, 75, i32::MAX);
        e.set_axis(0, 4, i32::MIN);
        assert_eq!(
            reasons(&e, &p),
            [
                "axis \"0/4\" = -2147483648: AP 4 (Maximum positioning speed) of motor 0 takes 1…2047",
                "global \"0/75\" = 2147483647: GP 75 (Telegram pause time) of bank 0 takes 0…255",
            ]
        );
        let message = e.check(&p).unwrap_err().to_string();
        assert!(
            message.starts_with("refused: entries a TMCM-1141 never stores, so the file was edited or damaged: axis \"0/4\""),
            "{message}"
        );
        assert!(
            message.contains("; global \"0/75\" = 2147483647: GP 75 (Telegram pause time) of bank 0 takes 0…255; correct"),
            "{message}"
        );
        let mut e = Eeprom::new("TMCM-1141");
        e.set_axis(0, 12, 2);
        assert_eq!(reasons(&e, &p), ["axis \"0/12\" = 2: AP 12 (Right limit switch disable) of motor 0 takes 0…1"]);
        assert!(e.check(&p).unwrap_err().to_string().starts_with("refused: an entry a TMCM-1141 never stores"));
    }

    #[test]
    fn cells_the_module_lacks_or_never_stores_are_refused() {
        let p = profile("tmcm-1141");
        let mut e = Eeprom::new("TMCM-1141");
        e.set_axis(1, 4, 100);
        e.set_axis(0, 6, 100);
        e.set_axis(0, 250, 1);
        e.axis.insert("0/04".into(), 100);
        e.axis.insert("+0/4".into(), 100);
        e.axis.insert("zero".into(), 100);
        e.set_global(1, 0, 1);
        e.set_global(0, 200, 1);
        e.set_global(2, 100, 5);
        e.set_global(0, 66, 0);
        e.set_coordinate(0, 0, 5);
        e.set_coordinate(0, 21, 5);
        e.set_coordinate(3, 1, 5);
        e.program.insert(1024, [0; 7]);
        let r = reasons(&e, &p);
        for expected in [
            "axis \"1/4\" = 100: motor 1 does not exist (a TMCM-1141 has motor 0)",
            "axis \"0/6\" = 100: AP 6 (Maximum current) is not stored in the EEPROM (access RW)",
            "axis \"0/250\" = 1: a TMCM-1141 has no AP 250",
            "axis \"0/04\" = 100: not a MOTOR/PARAMETER key",
            "axis \"+0/4\" = 100: not a MOTOR/PARAMETER key",
            "axis \"zero\" = 100: not a MOTOR/PARAMETER key",
            "global \"1/0\" = 1: bank 1 does not exist (a TMCM-1141 has banks 0, 2, 3)",
            "global \"0/200\" = 1: a TMCM-1141 has no GP 200 in bank 0",
            "global \"2/100\" = 5: GP 100 (User variables #56…#255) of bank 2 is not stored in the EEPROM (access RW)",
            "global \"0/66\" = 0: GP 66 (Serial address) of bank 0 takes 1…255",
            "coordinates \"0/0\" = 5: coordinate 0 is kept in RAM only",
            "coordinates \"0/21\" = 5: a TMCM-1141 has coordinates 1…20",
            "coordinates \"3/1\" = 5: motor 3 does not exist (a TMCM-1141 has motor 0)",
            "program \"1024\": the address is outside the program memory of a TMCM-1141 (0…1023)",
        ] {
            assert!(r.iter().any(|l| l == expected), "{expected} not in {r:#?}");
        }
        assert_eq!(r.len(), 14, "{r:#?}");
        let message = e.check(&p).unwrap_err().to_string();
        assert!(message.contains("; and 4 more; correct or remove them"), "{message}");
    }

    #[test]
    fn the_eeprom_lock_is_stored_as_its_state() {
        let p = profile("tmcm-351");
        let mut e = Eeprom::new("TMCM-351");
        e.set_global(0, 73, 1);
        e.set_axis(2, 4, 100);
        assert_eq!(e.check(&p), Ok(()));
        e.set_global(0, 73, 1234);
        assert_eq!(
            reasons(&e, &p),
            ["global \"0/73\" = 1234: GP 73 (Configuration EEPROM lock flag) of bank 0 is stored as 0 or 1 (unlocked, locked)"]
        );
        e.set_global(0, 73, 0);
        e.set_axis(3, 4, 100);
        assert_eq!(reasons(&e, &p), ["axis \"3/4\" = 100: motor 3 does not exist (a TMCM-351 has motors 0…2)"]);
    }

    #[test]
    fn another_modules_image_is_refused_before_its_cells() {
        let mut e = Eeprom::new("TMCM-351");
        e.set_axis(2, 4, 100);
        assert_eq!(e.check(&profile("tmcm-1141")).unwrap_err().to_string(), "the file holds the EEPROM of a TMCM-351, not of a TMCM-1141");
    }
}
