//! What can be wrong with a profile: its TOML, a parameter row, the
//! features, or the name asked for.

use std::fmt;

/// Why a profile could not be loaded. The texts name the parameter or the
/// `features` key at fault, as the profile file spells them.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ProfileError {
    /// The text is no TOML, or does not match the profile schema.
    Toml(toml::de::Error),
    /// An access string holds a letter other than R, W, E and A.
    AccessLetter {
        /// The letter that is none of them.
        letter: char,
        /// The whole access string.
        text: String,
    },
    /// A parameter row breaks a rule of the schema.
    Parameter {
        /// The row's (first) parameter number.
        number: u8,
        /// The row's name.
        name: String,
        /// Which rule, in words.
        problem: ParameterProblem,
    },
    /// Two rows define the same parameter number.
    DefinedTwice {
        /// The parameter defined twice.
        number: u8,
        /// The name of the second row that defines it.
        name: String,
    },
    /// A global parameter row has no `bank`.
    NoBank {
        /// The row's parameter number.
        number: u8,
    },
    /// A global parameter row names a bank the module does not have.
    NoSuchBank {
        /// The row's parameter number.
        number: u8,
        /// The bank it names.
        bank: u8,
    },
    /// `axes = 0`.
    NoAxis,
    /// The features disagree with the parameter tables, or a value is
    /// impossible.
    Features(FeatureProblem),
    /// The `[bootloader]` facts cannot be used (why, in words).
    Bootloader(String),
    /// No built-in profile has this name.
    NotBuiltIn {
        /// The name asked for, as given.
        name: String,
        /// The built-in profiles' names.
        known: Vec<&'static str>,
    },
    /// A built-in profile does not load (a broken profile file).
    BuiltIn {
        /// The profile's name (`tmcm-1141`).
        name: String,
        /// What is wrong with it.
        error: Box<ProfileError>,
    },
}

/// A rule that a parameter row breaks.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ParameterProblem {
    /// The default lies outside `min…max`.
    DefaultOutside {
        /// The row's default.
        default: i64,
        /// The row's minimum.
        min: i64,
        /// The row's maximum.
        max: i64,
    },
    /// A range is reversed or reaches beyond `min…max`.
    RangesOutside {
        /// The row's minimum.
        min: i64,
        /// The row's maximum.
        max: i64,
    },
    /// The default lies in none of the row's ranges.
    DefaultOutsideRanges {
        /// The row's default.
        default: i64,
    },
    /// `default_source = "sibling"` without a note saying where from.
    SiblingWithoutNote,
    /// `each` without `last`, or without `{}` for the number.
    EachWithoutRange,
}

/// A way in which a profile's features do not fit the rest of it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum FeatureProblem {
    /// A feature names a global parameter (bank 0) the profile lacks.
    MissingParameter {
        /// The features key (`can.id`, `eeprom_lock`, …).
        key: &'static str,
        /// The parameter number it names.
        number: u8,
    },
    /// A feature names an axis parameter the profile lacks.
    MissingAxisParameter {
        /// The features key (`encoder_scale.resolution`, …).
        key: &'static str,
        /// The parameter number it names.
        number: u8,
    },
    /// `encoder_scale` on a module whose encoder is not `abn`.
    ScaleWithoutAbnEncoder,
    /// `baud_rates` lists no rate.
    NoBaudRates,
    /// `baud_rates` has another length than GP 65 has codes.
    BaudRates {
        /// How many rates the list has.
        rates: usize,
        /// The global parameter of the baud rate code (65).
        parameter: u8,
        /// GP 65's name.
        name: String,
        /// GP 65's smallest code.
        min: i64,
        /// GP 65's largest code.
        max: i64,
    },
    /// `full_scale_current_ma = 0`.
    NoCurrent,
    /// `motion_clock_hz = 0`.
    NoClock,
    /// `encoder_deviation_stop` on a module without an encoder.
    DeviationStopWithoutEncoder,
    /// A row marked `quantity` (TMC429 units) on a module whose velocities
    /// and accelerations are in pps (`motion_units = "pps"`).
    QuantityInPps {
        /// The row's parameter number.
        number: u8,
        /// The row's name.
        name: String,
    },
    /// `motion_units` and `motion_controller` do not go together: the
    /// sixPoint controllers have the sixPoint units, the TMC4361A its
    /// own, and only they.
    Units {
        /// The profile's motion controller.
        controller: crate::features::MotionController,
        /// The profile's units.
        units: crate::features::MotionUnits,
    },
    /// `version_text` is not 8 ASCII characters.
    VersionText {
        /// The text as the profile gives it.
        text: String,
    },
    /// A port row's `span` or `full_scale_volts` does not fit the port.
    PortScale {
        /// The port's bank.
        bank: u8,
        /// The port's number.
        number: u8,
        /// Which rule, in words.
        problem: &'static str,
    },
}

impl fmt::Display for ProfileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ProfileError::Toml(e) => write!(f, "{e}"),
            ProfileError::AccessLetter { letter, text } => write!(f, "unknown access letter '{letter}' in \"{text}\""),
            ProfileError::Parameter { number, name, problem } => write!(f, "parameter {number} ({name}){problem}"),
            ProfileError::DefinedTwice { number, name } => write!(f, "parameter {number} ({name}) is defined twice"),
            ProfileError::NoBank { number } => write!(f, "global parameter {number} has no bank"),
            ProfileError::NoSuchBank { number, bank } => write!(f, "global parameter {number}: bank {bank} does not exist"),
            ProfileError::NoAxis => f.write_str("a module has at least one axis"),
            ProfileError::Features(p) => write!(f, "{p}"),
            ProfileError::Bootloader(why) => f.write_str(why),
            ProfileError::NotBuiltIn { name, known } => write!(f, "no built-in profile '{name}' (known: {})", known.join(", ")),
            ProfileError::BuiltIn { name, error } => write!(f, "profile {name}: {error}"),
        }
    }
}

/// Written after "parameter N (name)".
impl fmt::Display for ParameterProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ParameterProblem::DefaultOutside { default, min, max } => write!(f, ": default {default} outside {min}…{max}"),
            ParameterProblem::RangesOutside { min, max } => write!(f, ": ranges must lie within {min}…{max}, each from ≤ to"),
            ParameterProblem::DefaultOutsideRanges { default } => write!(f, ": default {default} outside its ranges"),
            ParameterProblem::SiblingWithoutNote => {
                f.write_str(": default_source \"sibling\" needs a note naming the module or code the default comes from")
            }
            ParameterProblem::EachWithoutRange => {
                f.write_str(": `each` names the parameters of a range (with `last`), `{}` for the number")
            }
        }
    }
}

impl fmt::Display for FeatureProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FeatureProblem::MissingParameter { key, number } => {
                write!(f, "features.{key} names global parameter {number}, which the profile does not have (bank 0)")
            }
            FeatureProblem::MissingAxisParameter { key, number } => {
                write!(f, "features.{key} names axis parameter {number}, which the profile does not have")
            }
            FeatureProblem::ScaleWithoutAbnEncoder => f.write_str("features.encoder_scale needs features.encoder = \"abn\""),
            FeatureProblem::NoBaudRates => f.write_str("features.baud_rates is empty: it needs at least the rate of code 0"),
            FeatureProblem::BaudRates { rates, parameter, name, min, max } => {
                write!(f, "features.baud_rates has {rates} rates, but GP {parameter} ({name}) takes codes {min}…{max}")
            }
            FeatureProblem::NoCurrent => f.write_str("features.full_scale_current_ma is 0"),
            FeatureProblem::NoClock => f.write_str("features.motion_clock_hz is 0"),
            FeatureProblem::DeviationStopWithoutEncoder => {
                f.write_str("features.encoder_deviation_stop needs an encoder (features.encoder is \"none\")")
            }
            FeatureProblem::QuantityInPps { number, name } => {
                write!(f, "axis parameter {number} ({name}) has a `quantity` (TMC429 units), but features.motion_units is not \"tmc429\"")
            }
            FeatureProblem::Units { controller, units } => write!(
                f,
                "features.motion_units = \"{}\" does not go with features.motion_controller = \"{}\": \
                 the sixpoint and eightpoint controllers take motion_units = \"sixpoint\", the tmc4361a controller \
                 motion_units = \"tmc4361a\", and only they do",
                units.name(),
                controller.name()
            ),
            FeatureProblem::VersionText { text } => {
                write!(f, "module.version_text \"{text}\" must be 8 ASCII characters (the 136 type 0 reply)")
            }
            FeatureProblem::PortScale { bank, number, problem } => write!(f, "port {number} of bank {bank}: {problem}"),
        }
    }
}

impl std::error::Error for ProfileError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            ProfileError::Toml(e) => Some(e),
            ProfileError::BuiltIn { error, .. } => Some(error.as_ref()),
            _ => None,
        }
    }
}

/// For callers whose errors are text (the command line, the bindings).
impl From<ProfileError> for String {
    fn from(e: ProfileError) -> String {
        e.to_string()
    }
}
