//! Parameters by name, the one lookup every front end uses (the console,
//! the IDE, the debugger, the Python package): a name is compared without
//! case and without anything but letters and digits, so that "Maximum
//! positioning speed", "maximum_positioning_speed" and
//! "MaximumPositioningSpeed" are the same name. A parameter answers to its
//! own name ("User variable 17") and to the name of its group ("User
//! variables #0…#55", which names several).

use std::collections::HashMap;
use tmclsim_profile::Parameter;
use tmclsim_profile::Profile;

/// `Actual position` → `actual_position`; `Maximum speed (pps)` →
/// `maximum_speed_pps`: the spelling the console offers.
pub fn snake(name: &str) -> String {
    let mut out = String::new();
    for c in name.chars() {
        if c.is_ascii_alphanumeric() {
            out.push(c.to_ascii_lowercase());
        } else if !out.is_empty() && !out.ends_with('_') {
            out.push('_');
        }
    }
    out.trim_end_matches('_').to_string()
}

/// The lookup key of a name: its letters and digits in lower case.
pub fn key(name: &str) -> String {
    name.chars().filter(char::is_ascii_alphanumeric).map(|c| c.to_ascii_lowercase()).collect()
}

/// Which table a command's type operand names.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Table {
    /// Axis parameters (SAP, GAP, …).
    Axis,
    /// Global parameters (SGP, GGP, …).
    Global,
}

/// The table of the opcode's type operand, if it names a parameter.
pub fn table_of(opcode: u8) -> Option<Table> {
    use tmclsim_protocol::opcode as op;
    match opcode {
        op::SAP | op::GAP | op::STAP | op::RSAP | op::AAP => Some(Table::Axis),
        op::SGP | op::GGP | op::STGP | op::RSGP | op::AGP => Some(Table::Global),
        _ => None,
    }
}

/// Every parameter of a table with its bank (0 for axis parameters).
pub fn parameters(profile: &Profile, table: Table) -> Vec<(u8, &Parameter)> {
    match table {
        Table::Axis => profile.axis_parameters().map(|p| (0, p)).collect(),
        Table::Global => (0..tmclsim_profile::BANKS as u8).flat_map(|b| profile.global_parameters(b).map(move |p| (b, p))).collect(),
    }
}

/// key → (the name as the profile writes it, [(bank, number)]).
type Index = HashMap<String, (String, Vec<(u8, u8)>)>;

/// The parameter names of one profile.
#[derive(Debug, Default)]
pub struct Names {
    module: String,
    axis: Index,
    global: Index,
}

impl Names {
    /// The names of every parameter of `profile`.
    pub fn new(profile: &Profile) -> Names {
        let mut names = Names { module: profile.module.name.clone(), ..Names::default() };
        for table in [Table::Axis, Table::Global] {
            let map = match table {
                Table::Axis => &mut names.axis,
                Table::Global => &mut names.global,
            };
            for (bank, p) in parameters(profile, table) {
                let mut spellings = vec![p.name.as_str()];
                if p.label() != p.name {
                    spellings.push(p.label());
                }
                for name in spellings {
                    map.entry(key(name)).or_insert_with(|| (name.to_string(), Vec::new())).1.push((bank, p.number));
                }
            }
        }
        names
    }

    fn table(&self, table: Table) -> &Index {
        match table {
            Table::Axis => &self.axis,
            Table::Global => &self.global,
        }
    }

    /// Whether `name` names a parameter of the table (in any bank).
    pub fn knows(&self, table: Table, name: &str) -> bool {
        self.table(table).contains_key(&key(name))
    }

    /// The bank and number of every parameter `name` names, in `bank` when
    /// given (axis parameters are in bank 0).
    pub fn places(&self, table: Table, name: &str, bank: Option<u8>) -> Vec<(u8, u8)> {
        self.table(table)
            .get(&key(name))
            .map_or(Vec::new(), |(_, all)| all.iter().copied().filter(|(b, _)| bank.is_none_or(|want| *b == want)).collect())
    }

    /// The number of the axis parameter with this name.
    pub fn axis(&self, name: &str) -> Result<u8, NameError> {
        self.one(Table::Axis, name, None).map(|(_, n)| n)
    }

    /// The bank and number of the global parameter with this name; `bank`,
    /// when given, must agree.
    pub fn global(&self, name: &str, bank: Option<u8>) -> Result<(u8, u8), NameError> {
        self.one(Table::Global, name, bank)
    }

    fn one(&self, table: Table, name: &str, bank: Option<u8>) -> Result<(u8, u8), NameError> {
        let Some((full, places)) = self.table(table).get(&key(name)) else {
            return Err(NameError::Unknown {
                module: self.module.clone(),
                table,
                name: name.to_string(),
                suggestion: suggest(name, self.table(table).values().map(|v| v.0.as_str())),
            });
        };
        let matching = self.places(table, name, bank);
        match matching.as_slice() {
            [one] => Ok(*one),
            [] => Err(NameError::OtherBank { name: full.clone(), bank: places[0].0, asked: bank.unwrap_or(0) }),
            many => Err(NameError::Several { name: full.clone(), table, bank: many[0].0, first: many[0].1, last: many[many.len() - 1].1 }),
        }
    }
}

/// Why a name is no single parameter of the profile.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum NameError {
    /// No parameter of the table has this name.
    Unknown {
        /// The module's name.
        module: String,
        /// The table looked in.
        table: Table,
        /// The name as given.
        name: String,
        /// ` (did you mean …?)`, or empty.
        suggestion: String,
    },
    /// The global parameter is in another bank than the one given.
    OtherBank {
        /// The parameter's name as the profile spells it.
        name: String,
        /// Its bank.
        bank: u8,
        /// The bank given (0 when none was).
        asked: u8,
    },
    /// The name stands for a range of parameters (user variables).
    Several {
        /// The name as the profile spells it.
        name: String,
        /// The table.
        table: Table,
        /// Their bank.
        bank: u8,
        /// The first parameter number.
        first: u8,
        /// The last parameter number.
        last: u8,
    },
}

impl std::fmt::Display for NameError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            NameError::Unknown { module, table, name, suggestion } => {
                let what = if *table == Table::Axis { "axis" } else { "global" };
                write!(f, "the {module} has no {what} parameter named '{name}'{suggestion}")
            }
            NameError::OtherBank { name, bank, asked } => write!(f, "'{name}' is a parameter of bank {bank}, not of bank {asked}"),
            NameError::Several { name, table: Table::Axis, first, last, .. } => {
                write!(f, "'{name}' names axis parameters {first}…{last}: give the number")
            }
            NameError::Several { name, table: Table::Global, bank, first, last } => {
                write!(f, "'{name}' names global parameters {first}…{last} of bank {bank}: give the number")
            }
        }
    }
}

impl std::error::Error for NameError {}

impl From<NameError> for String {
    fn from(e: NameError) -> String {
        e.to_string()
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

/// A parameter by its name (the first, where a name names several) or its
/// number, in `bank` when given.
pub fn find<'p>(profile: &'p Profile, table: Table, word: &str, bank: Option<u8>) -> Option<(u8, &'p Parameter)> {
    let (b, n) = match tmclsim_protocol::mnemonic::parse_number(word) {
        Some(n) => (bank.unwrap_or(0), u8::try_from(n).ok()?),
        None => *Names::new(profile).places(table, word, bank).first()?,
    };
    let p = match table {
        Table::Axis => profile.axis_parameter(n),
        Table::Global => profile.global_parameter(b, n),
    };
    p.map(|p| (b, p))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_in_snake_case() {
        assert_eq!(snake("Actual position"), "actual_position");
        assert_eq!(snake("Maximum speed (pps)"), "maximum_speed_pps");
        assert_eq!(snake("User variables #0…#55"), "user_variables_0_55");
        assert_eq!(snake("Chopper hysteresis end / fast decay time"), "chopper_hysteresis_end_fast_decay_time");
        assert_eq!(snake("SmartEnergy current minimum (SEIMIN)"), "smartenergy_current_minimum_seimin");
    }

    #[test]
    fn found_by_name_or_number_in_their_table() {
        let p = Profile::built_in("tmcm-1141").unwrap();
        assert_eq!(find(&p, Table::Axis, "actual_position", None).map(|(_, q)| q.number), Some(1));
        assert_eq!(find(&p, Table::Axis, "Actual_Position", None).map(|(_, q)| q.number), Some(1));
        assert_eq!(find(&p, Table::Axis, "4", None).map(|(_, q)| q.number), Some(4));
        assert!(find(&p, Table::Axis, "tmcl_tick_timer", None).is_none());
        assert_eq!(find(&p, Table::Global, "tmcl_tick_timer", None).map(|(b, q)| (b, q.number)), Some((0, 132)));
        assert_eq!(find(&p, Table::Global, "user_variable_17", Some(2)).map(|(b, q)| (b, q.number)), Some((2, 17)));
    }

    #[test]
    fn spellings_of_one_name() {
        let p = Profile::built_in("tmcm-1141").unwrap();
        let n = Names::new(&p);
        assert_eq!(n.axis("Maximum positioning speed"), Ok(4));
        assert_eq!(n.axis("maximum_positioning_speed"), Ok(4));
        assert_eq!(n.axis("MAXIMUM POSITIONING SPEED"), Ok(4));
        assert_eq!(n.axis("MaximumPositioningSpeed"), Ok(4));
        assert!(n.axis("positioning").unwrap_err().to_string().contains("Maximum positioning speed"));
        assert_eq!(n.global("Serial address", None), Ok((0, 66)));
        assert_eq!(
            n.global("Serial address", Some(2)).unwrap_err().to_string(),
            "'Serial address' is a parameter of bank 0, not of bank 2"
        );
        assert_eq!(n.global("User variable 17", None), Ok((2, 17)));
        assert!(n.global("User variables #0…#55", None).unwrap_err().to_string().ends_with("of bank 2: give the number"));
        assert!(n.knows(Table::Global, "tmcl_tick_timer") && !n.knows(Table::Axis, "tmcl_tick_timer"));
    }
}
