//! Parameters by name: the names of the module profile, compared without
//! case and without anything but letters and digits, so that
//! "Maximum positioning speed", "maximum_positioning_speed" and
//! "MaximumPositioningSpeed" are the same name.

use std::collections::HashMap;
use tmclsim_firmware::Profile;

/// The lookup key of a name.
pub fn key(name: &str) -> String {
    name.chars().filter(|c| c.is_ascii_alphanumeric()).map(|c| c.to_ascii_lowercase()).collect()
}

/// The snake_case spelling of a profile name ("Maximum positioning
/// speed" → "maximum_positioning_speed"), as the console and the IDE take it.
pub use tmclsim_host::names::snake as snake_case;

/// The parameter names of one profile.
#[derive(Debug, Default)]
pub struct Names {
    module: String,
    /// key → (profile name, numbers)
    axis: HashMap<String, (String, Vec<u8>)>,
    /// key → (profile name, [(bank, number)])
    global: HashMap<String, (String, Vec<(u8, u8)>)>,
}

impl Names {
    pub fn new(profile: &Profile) -> Names {
        let mut names = Names { module: profile.module.name.clone(), ..Names::default() };
        for p in profile.axis_parameters() {
            names.axis.entry(key(&p.name)).or_insert_with(|| (p.name.clone(), Vec::new())).1.push(p.number);
        }
        for bank in 0..tmclsim_firmware::profile::BANKS as u8 {
            for p in profile.global_parameters(bank) {
                names.global.entry(key(&p.name)).or_insert_with(|| (p.name.clone(), Vec::new())).1.push((bank, p.number));
            }
        }
        names
    }

    /// The number of the axis parameter with this name.
    pub fn axis(&self, name: &str) -> Result<u8, String> {
        let Some((full, numbers)) = self.axis.get(&key(name)) else {
            return Err(format!(
                "the {} has no axis parameter named '{name}'{}",
                self.module,
                suggest(name, self.axis.values().map(|v| v.0.as_str()))
            ));
        };
        match numbers.as_slice() {
            [n] => Ok(*n),
            many => Err(format!("'{full}' names axis parameters {}…{}: give the number", many[0], many[many.len() - 1])),
        }
    }

    /// The bank and number of the global parameter with this name; `bank`,
    /// when given, must agree.
    pub fn global(&self, name: &str, bank: Option<u8>) -> Result<(u8, u8), String> {
        let Some((full, places)) = self.global.get(&key(name)) else {
            return Err(format!(
                "the {} has no global parameter named '{name}'{}",
                self.module,
                suggest(name, self.global.values().map(|v| v.0.as_str()))
            ));
        };
        let matching: Vec<(u8, u8)> = places.iter().copied().filter(|(b, _)| bank.is_none_or(|want| *b == want)).collect();
        match matching.as_slice() {
            [one] => Ok(*one),
            [] => Err(format!("'{full}' is a parameter of bank {}, not of bank {}", places[0].0, bank.unwrap_or(0))),
            many => Err(format!(
                "'{full}' names global parameters {}…{} of bank {}: give the number",
                many[0].1,
                many[many.len() - 1].1,
                many[0].0
            )),
        }
    }
}

/// " (did you mean 'A' or 'B'?)" for names that contain what was asked for.
fn suggest<'a>(name: &str, candidates: impl Iterator<Item = &'a str>) -> String {
    let wanted = key(name);
    if wanted.is_empty() {
        return String::new();
    }
    let mut found: Vec<&str> = candidates.filter(|c| key(c).contains(&wanted)).collect();
    found.sort();
    found.truncate(3);
    match found.as_slice() {
        [] => String::new(),
        [one] => format!(" (did you mean '{one}'?)"),
        many => format!(" (did you mean {}?)", many.iter().map(|n| format!("'{n}'")).collect::<Vec<_>>().join(" or ")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spellings_of_one_name() {
        let p = Profile::built_in("tmcm-1141").unwrap();
        let n = Names::new(&p);
        assert_eq!(n.axis("Maximum positioning speed"), Ok(4));
        assert_eq!(n.axis("maximum_positioning_speed"), Ok(4));
        assert_eq!(n.axis("MAXIMUM POSITIONING SPEED"), Ok(4));
        assert!(n.axis("positioning").unwrap_err().contains("Maximum positioning speed"));
        assert_eq!(n.global("Serial address", None), Ok((0, 66)));
        assert!(n.global("Serial address", Some(2)).is_err());
        assert_eq!(snake_case("Chopper hysteresis end / fast decay time"), "chopper_hysteresis_end_fast_decay_time");
        assert_eq!(snake_case("SmartEnergy current minimum (SEIMIN)"), "smartenergy_current_minimum_seimin");
    }
}
