//! What can be wrong with a change of the world: a control line that does
//! not parse, a value the rule set refuses (docs/behaviour.md rule 84), a
//! world file, or an address no module answers to. The texts are the ones
//! users see (control socket, `tmclsim world`, HTTP answers, Python
//! exceptions): a value is refused with the same words whether it comes
//! from a line or a file.

use crate::world::{WORLD_ANALOG_INPUTS, WORLD_DIGITAL_INPUTS};
use crate::world_help::HELP;
use std::fmt;

/// An allowed range of a world value, with its unit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Allowed {
    /// Lowest allowed value.
    pub min: f64,
    /// Highest allowed value.
    pub max: f64,
    /// The unit messages show after the range (may be empty).
    pub unit: &'static str,
}

impl std::fmt::Display for Allowed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}…{}", number(self.min), number(self.max))?;
        if !self.unit.is_empty() {
            write!(f, " {}", self.unit)?;
        }
        Ok(())
    }
}

/// A value as a message shows it: `12.5`, `NaN`, `inf`, `1e300`.
pub fn number(value: f64) -> String {
    if value.is_finite() && value.abs() >= 1e9 { format!("{value:e}") } else { format!("{value}") }
}

/// Why a world command, value or file was refused. A refused command or
/// file changes nothing.
#[derive(Clone, Debug, PartialEq)]
pub enum WorldError {
    /// A control line without a command.
    EmptyCommand,
    /// The first word of a control line is no world command.
    UnknownCommand {
        /// The word, as given.
        word: String,
    },
    /// `@ADDRESS` that is not a number 0…255.
    BadAddress {
        /// What followed the `@`.
        word: String,
    },
    /// A word the command needs is missing.
    Missing {
        /// What is missing ("axis", "position", …).
        what: &'static str,
    },
    /// A word does not parse as the number the command needs.
    Invalid {
        /// The word, as given.
        word: String,
        /// What it should have been ("axis", "input number", …).
        what: &'static str,
    },
    /// An optional number (a width, a load range end) does not parse.
    NotANumber {
        /// The word, as given.
        word: String,
    },
    /// A word is none of the keywords allowed at its place.
    Expected {
        /// The keywords allowed, in words ("on or off").
        expected: &'static str,
        /// The word found, `None` when the line ended.
        found: Option<String>,
    },
    /// `analog N VALUE` with a value above the ADC's 4095.
    AnalogAbove {
        /// The value given.
        value: u16,
    },
    /// `place AXIS home` with only one position.
    HomeNeedsTo,
    /// A value that is not a finite number (NaN, ±inf).
    NotFinite {
        /// The value's name ("supply", "travel FROM", …).
        what: String,
        /// The value given.
        value: f64,
        /// Its allowed range.
        allowed: Allowed,
    },
    /// A finite value outside its allowed range.
    Outside {
        /// The value's name.
        what: String,
        /// The value given.
        value: f64,
        /// Its allowed range.
        allowed: Allowed,
    },
    /// End stops with FROM not below TO.
    EmptyTravel {
        /// The lower end stop given, in µsteps.
        from: f64,
        /// The upper end stop given, in µsteps.
        to: f64,
    },
    /// A range of positions (home switch, load range) with FROM above TO.
    EmptySpan {
        /// The range's name ("home switch", "load range").
        what: String,
        /// Its start, in µsteps.
        from: f64,
        /// Its end, in µsteps.
        to: f64,
    },
    /// A load's time window with AFTER not below UNTIL.
    EmptyWindow {
        /// Start of the window, in seconds of virtual time.
        after: f64,
        /// End of the window, in seconds of virtual time.
        until: f64,
    },
    /// An input the module does not have (a plain input of its profile).
    NoInput {
        /// 0: digital, 1: analog.
        bank: u8,
        /// The input asked for.
        number: u8,
        /// The module's name.
        module: String,
        /// The numbers of the inputs the module has in that bank.
        have: Vec<u8>,
    },
    /// An axis the module does not have.
    NoAxis {
        /// The axis asked for.
        axis: usize,
        /// The module's number of axes.
        axes: usize,
    },
    /// A value of one axis was refused.
    OnAxis {
        /// The axis.
        axis: usize,
        /// What was wrong with it.
        error: Box<WorldError>,
    },
    /// A world with more analog inputs than a world holds.
    TooManyAnalogInputs {
        /// How many it has.
        count: usize,
    },
    /// A world file that is no TOML or does not match the file's schema.
    Toml(toml::de::Error),
    /// A world file's `base` other than `stage` and `free`.
    UnknownBase {
        /// The base given.
        base: String,
    },
    /// A world file that describes more axes than the module has.
    TooManyAxes {
        /// The axes the file describes.
        described: usize,
        /// The module's axes.
        axes: usize,
    },
    /// A world file's `inputs` list longer than the digital inputs a
    /// world holds.
    TooManyLevels {
        /// The length of the list.
        count: usize,
    },
    /// A digital input level other than 0 and 1 in a world file.
    Level {
        /// The input (the index in `inputs`).
        index: usize,
        /// The level given.
        level: u8,
    },
    /// A world file's `analog` list longer than the analog inputs a world
    /// holds.
    TooManyAnalogValues {
        /// The length of the list.
        count: usize,
    },
    /// No module on the bus answers to the `@ADDRESS` of a line.
    NoModule {
        /// The address.
        address: u8,
    },
}

impl WorldError {
    /// The error, as one of axis `axis`'s values.
    pub fn on_axis(self, axis: usize) -> WorldError {
        WorldError::OnAxis { axis, error: Box::new(self) }
    }
}

/// `0…3`, or `0, 2, 5` when there are gaps, or `none`.
fn list(numbers: &[u8]) -> String {
    match (numbers.first(), numbers.last()) {
        (Some(a), Some(b)) if numbers.len() > 1 && usize::from(*b - *a) + 1 == numbers.len() => format!("{a}…{b}"),
        (Some(_), _) => numbers.iter().map(u8::to_string).collect::<Vec<_>>().join(", "),
        _ => "none".into(),
    }
}

impl fmt::Display for WorldError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            WorldError::EmptyCommand => f.write_str("empty command"),
            WorldError::UnknownCommand { word } => write!(f, "unknown command '{word}' ({HELP})"),
            WorldError::BadAddress { word } => write!(f, "'@{word}' is not a module address (0…255)"),
            WorldError::Missing { what } => write!(f, "{what} is missing"),
            WorldError::Invalid { word, what } => write!(f, "'{word}' is not a valid {what}"),
            WorldError::NotANumber { word } => write!(f, "'{word}' is not a number"),
            WorldError::Expected { expected, found } => {
                write!(f, "expected {expected}, found {}", found.as_deref().unwrap_or("nothing"))
            }
            WorldError::AnalogAbove { value } => write!(f, "{value} is above 4095"),
            WorldError::HomeNeedsTo => f.write_str("place home takes FROM and TO"),
            WorldError::NotFinite { what, value, allowed } => {
                write!(f, "{what} {value} is not a finite number (allowed: {allowed})")
            }
            WorldError::Outside { what, value, allowed } => write!(f, "{what} {} is outside {allowed}", number(*value)),
            WorldError::EmptyTravel { from, to } => {
                write!(f, "travel from {} to {} is empty (FROM must be below TO)", number(*from), number(*to))
            }
            WorldError::EmptySpan { what, from, to } => {
                write!(f, "{what} from {} to {} is empty (FROM must not be above TO)", number(*from), number(*to))
            }
            WorldError::EmptyWindow { after, until } => {
                write!(f, "load window after {after} s until {until} s is empty (AFTER must be below UNTIL)")
            }
            WorldError::NoInput { bank, number, module, have } => {
                let kind = if *bank == 0 { "digital" } else { "analog" };
                write!(f, "{kind} input {number} does not exist on the {module} ({kind} inputs: {})", list(have))
            }
            WorldError::NoAxis { axis, axes } => write!(f, "axis {axis} does not exist (the module has {axes})"),
            WorldError::OnAxis { axis, error } => write!(f, "axis {axis}: {error}"),
            WorldError::TooManyAnalogInputs { count } => {
                write!(f, "{count} analog inputs: the world has {WORLD_ANALOG_INPUTS}")
            }
            WorldError::Toml(e) => write!(f, "{e}"),
            WorldError::UnknownBase { base } => write!(f, "base = \"{base}\": use \"stage\" or \"free\""),
            WorldError::TooManyAxes { described, axes } => {
                write!(f, "the world describes {described} axes, the module has {axes}")
            }
            WorldError::TooManyLevels { count } => {
                write!(f, "inputs lists {count} levels: the world has {WORLD_DIGITAL_INPUTS} digital inputs")
            }
            WorldError::Level { index, level } => write!(f, "inputs[{index}] = {level}: a level is 0 or 1"),
            WorldError::TooManyAnalogValues { count } => {
                write!(f, "analog lists {count} values: the world has {WORLD_ANALOG_INPUTS} analog inputs")
            }
            WorldError::NoModule { address } => write!(f, "no module on the bus answers to address {address}"),
        }
    }
}

impl std::error::Error for WorldError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            WorldError::Toml(e) => Some(e),
            WorldError::OnAxis { error, .. } => Some(error.as_ref()),
            _ => None,
        }
    }
}

impl From<toml::de::Error> for WorldError {
    fn from(e: toml::de::Error) -> WorldError {
        WorldError::Toml(e)
    }
}

/// For front ends that report errors as text.
impl From<WorldError> for String {
    fn from(e: WorldError) -> String {
        e.to_string()
    }
}
