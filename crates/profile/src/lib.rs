//! Module profiles: the data that makes a TMCM-1141 a TMCM-1141.
//!
//! A profile is loaded from a TOML file (`profiles/*.toml`, schema in
//! `profiles/README.md`) and indexed for constant-time lookups by the
//! executor. The built-in profiles are compiled into the binary.
//!
//! Everything that tells one module from another is here: its parameter
//! tables, ports and interrupts, and its [`Features`] (which reference
//! search, stall detection, encoder, CAN identifiers, EEPROM lock, …). The
//! firmware and the assembler read them; neither knows module names.

mod bootloader;
mod error;
mod features;

pub use bootloader::Bootloader;
pub use error::{FeatureProblem, ParameterProblem, ProfileError};
pub use features::{
    CanIds, EepromMagic, Encoder, EncoderScale, ErrorFlags, Features, LimitSwitchRows, MotionController, MotionUnits,
    ReferenceSearchFamily, StallDetection,
};

use serde::Deserialize;
use std::sync::Arc;

/// Access letters of the manuals' parameter tables.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Access {
    /// R: GAP/GGP.
    pub read: bool,
    /// W: SAP/AAP, SGP/AGP.
    pub write: bool,
    /// E: STAP/RSAP, STGP/RSGP.
    pub eeprom: bool,
    /// A: stored in the EEPROM automatically by SGP.
    pub auto: bool,
}

impl Access {
    /// Reads the letters of a manual's access column (`RWE`, `R`, …).
    pub fn parse(text: &str) -> Result<Access, ProfileError> {
        let mut a = Access::default();
        for c in text.chars() {
            match c {
                'R' => a.read = true,
                'W' => a.write = true,
                'E' => a.eeprom = true,
                'A' => a.auto = true,
                _ => return Err(ProfileError::AccessLetter { letter: c, text: text.to_string() }),
            }
        }
        Ok(a)
    }
}

impl std::fmt::Display for Access {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        for (on, c) in [(self.read, 'R'), (self.write, 'W'), (self.eeprom, 'E'), (self.auto, 'A')] {
            if on {
                write!(f, "{c}")?;
            }
        }
        Ok(())
    }
}

/// Where a parameter's default value comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum DefaultSource {
    /// The module's own manual states it.
    Manual,
    /// Another module of the family or public Trinamic code for the same
    /// chips gives it; the row's note names which.
    Sibling,
    /// No source gives it: chosen for the simulator.
    Assumed,
}

impl DefaultSource {
    /// The word the profile files use (`manual`, `sibling`, `assumed`).
    pub fn as_str(self) -> &'static str {
        match self {
            DefaultSource::Manual => "manual",
            DefaultSource::Sibling => "sibling",
            DefaultSource::Assumed => "assumed",
        }
    }
}

/// One axis or global parameter (or a run of them, for user variables).
#[derive(Clone, Debug)]
pub struct Parameter {
    /// The parameter number (the type byte of SAP/GAP, SGP/GGP).
    pub number: u8,
    /// The name as the manual gives it (a range row's name for its run).
    pub name: String,
    /// Its own name when it is one of a range row's parameters ("User
    /// variable 17"); `name` is then the range's.
    pub own_name: Option<String>,
    /// What may be done with it: read, write, store in the EEPROM, …
    pub access: Access,
    /// The smallest value.
    pub min: i64,
    /// The largest value.
    pub max: i64,
    /// The value after a reset with a fresh EEPROM.
    pub default: i64,
    /// Where the default comes from.
    pub default_source: DefaultSource,
    /// The unit, when the manual names one.
    pub unit: Option<String>,
    /// Where a value or rule comes from, or what is special about it.
    pub note: Option<String>,
    /// When the values within `min…max` are not all valid: the valid
    /// ones, as inclusive ranges (e.g. AP 193's modes 1–8, 65–68, 133–136).
    pub ranges: Vec<(i64, i64)>,
    /// What the value measures when it is a velocity or an acceleration in
    /// the motion controller's units (docs/behaviour.md rule 23); only on
    /// modules whose `motion_units` are the TMC429's.
    pub quantity: Option<Quantity>,
    /// For a duration: the milliseconds one unit stands for, read from
    /// `unit` when the profile is loaded ([`Parameter::ms_per_unit`]).
    duration_ms: Option<u64>,
}

/// A parameter whose value is in the motion controller's units: converted
/// to microsteps per second (or per second²) with the pulse and ramp
/// divisors and `features.motion_clock_hz`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Quantity {
    /// A velocity (pulse divisor).
    Velocity,
    /// An acceleration (pulse and ramp divisors).
    Acceleration,
}

impl Parameter {
    /// The parameter's own name: a range row's parameters are each named
    /// by their number where the profile says how.
    pub fn label(&self) -> &str {
        self.own_name.as_deref().unwrap_or(&self.name)
    }

    /// Checks a wire value against the range (and the valid ranges within
    /// it). Ranges above 2^31−1 (the timer periods of bank 3) read the 32
    /// bits as unsigned.
    pub fn accepts(&self, value: i32) -> bool {
        let v = if self.max > i64::from(i32::MAX) { i64::from(value as u32) } else { i64::from(value) };
        (self.min..=self.max).contains(&v) && (self.ranges.is_empty() || self.ranges.iter().any(|&(lo, hi)| (lo..=hi).contains(&v)))
    }

    /// The valid values for messages: "1…8, 65…68, 133…136" or "0…2047".
    pub fn range_text(&self) -> String {
        if self.ranges.is_empty() {
            return format!("{}…{}", self.min, self.max);
        }
        self.ranges.iter().map(|(lo, hi)| if lo == hi { lo.to_string() } else { format!("{lo}…{hi}") }).collect::<Vec<_>>().join(", ")
    }

    /// The default as the 32-bit word the module holds.
    pub fn default_word(&self) -> i32 {
        self.default as i32
    }

    /// For a duration: the milliseconds one unit of the value stands for,
    /// read from the row's unit (`ms` 1, `10ms` or `10 ms` 10, `s` 1000);
    /// `None` when the unit is no duration.
    pub fn ms_per_unit(&self) -> Option<u64> {
        self.duration_ms
    }
}

/// What kind of I/O channel a port is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PortDirection {
    /// An input (GIO).
    Input,
    /// An output (SIO, GIO bank 2).
    Output,
    /// The pull-up resistors of inputs (SIO bank 0): with range 0…1 one
    /// switch for all, with a wider range a bit mask, one bit an input.
    Pullup,
    /// The range of the analog inputs marked `ranged` (SIO): each value
    /// selects the full-scale voltage `full_scale_volts` lists for it.
    #[serde(rename = "input_range")]
    InputRange,
}

/// What an input channel measures, where that is more than a pin.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PortRole {
    /// The supply voltage: in 0.1 V, or with `span` the ADC reading of
    /// it.
    Supply,
    /// The module's temperature, as the ADC reading `span` describes.
    Temperature,
}

/// An I/O port of the module (SIO/GIO), from the profile's `[[port]]` rows.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Port {
    /// Input, output or pull-up.
    pub direction: PortDirection,
    /// The bank of SIO/GIO.
    pub bank: u8,
    /// The port number within its bank.
    pub number: u8,
    /// The name as the manual gives it (`OUT1`).
    pub name: String,
    /// The smallest value.
    pub min: i64,
    /// The largest value.
    pub max: i64,
    /// The value after a reset.
    #[serde(default)]
    pub default: i64,
    /// The unit, when the manual names one.
    #[serde(default)]
    pub unit: Option<String>,
    /// What the channel measures (`None`: a plain digital or analog input).
    #[serde(default)]
    pub role: Option<PortRole>,
    /// For a `role` read by an ADC: the measured quantity (volts, °C) at
    /// the readings `min` and `max`, in between linear.
    #[serde(default)]
    pub span: Option<[f64; 2]>,
    /// For an `input_range` port: the full-scale voltage that each value
    /// (from `min`) selects.
    #[serde(default)]
    pub full_scale_volts: Vec<f64>,
    /// An analog input whose full scale follows the `input_range` port.
    #[serde(default)]
    pub ranged: bool,
    /// An analog input on a pin of its own: not the digital input of the
    /// same number read through the ADC (docs/behaviour.md rule 55).
    #[serde(default)]
    pub own_line: bool,
    /// Where a value or rule comes from, or what is special about it.
    #[serde(default)]
    pub note: Option<String>,
}

impl Port {
    /// What the port is, in the same words on every module (`analog
    /// input 0`, `digital output 1`, `supply voltage`), where `name` is
    /// the module's manual's pin name (`IN0` on one module, `AIN0` or
    /// `AIN_0` on others for the same meaning).
    pub fn meaning(&self) -> String {
        let n = self.number;
        match (self.direction, self.role) {
            (PortDirection::Input, Some(PortRole::Supply)) => "supply voltage".into(),
            (PortDirection::Input, Some(PortRole::Temperature)) => "temperature".into(),
            (PortDirection::Input, None) if self.bank == 1 => format!("analog input {n}"),
            (PortDirection::Input, None) => format!("digital input {n}"),
            (PortDirection::Output, _) => format!("digital output {n}"),
            (PortDirection::Pullup, _) => "pull-ups".into(),
            (PortDirection::InputRange, _) => "analog input range".into(),
        }
    }
}

/// An interrupt of the module's TMCL interrupt table (EI, DI, VECT).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Interrupt {
    /// The interrupt number.
    pub number: u8,
    /// Its name in the manual.
    pub name: String,
    /// Its symbol in `Interrupts.inc` (`TI_TIMER0`).
    pub symbol: String,
}

/// The `[module]` table of a profile: what the module is and has.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModuleInfo {
    /// The module's name (`TMCM-1141`).
    pub name: String,
    /// The type number 136 type 1 reports (1141).
    pub type_number: u16,
    /// The firmware version, major and minor (1, 46 for V1.46).
    pub firmware: [u8; 2],
    /// Number of motors.
    pub axes: u8,
    /// Width of the position counters in bits.
    pub position_bits: u8,
    /// The motion controller chip (`TMC429`).
    pub motion_controller: String,
    /// Words of TMCL program memory.
    pub program_memory: u16,
    /// Where `program_memory` comes from, when not from the manual.
    #[serde(default)]
    pub program_memory_source: Option<String>,
    /// Number of user variables.
    pub user_variables: u16,
    /// How many of them (from 0) can be stored in the EEPROM.
    pub user_variables_stored: u16,
    /// Number of coordinates per motor (SCO, GCO, CCO).
    pub coordinates: u8,
    /// The 8 characters of the 136 type 0 reply, when the manual prints
    /// another form than `1141V146` (type number, `V`, version digits).
    #[serde(default)]
    pub version_text: Option<String>,
    /// The instruction numbers the module has.
    pub opcodes: Vec<u8>,
    /// The instruction numbers it executes in ASCII mode.
    #[serde(default)]
    pub ascii_opcodes: Vec<u8>,
    /// The host interfaces the module has, as its manual lists them: a
    /// link of another kind is refused (a CAN adapter, a multi-drop bus).
    pub interfaces: Vec<Interface>,
}

/// A host interface of a module.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum Interface {
    /// USB (a virtual serial port).
    Usb,
    /// RS-232.
    Rs232,
    /// RS-485 (a multi-drop bus).
    Rs485,
    /// CAN.
    Can,
    /// EtherCAT.
    Ethercat,
}

impl Interface {
    /// As manuals write it.
    pub fn name(self) -> &'static str {
        match self {
            Interface::Usb => "USB",
            Interface::Rs232 => "RS-232",
            Interface::Rs485 => "RS-485",
            Interface::Can => "CAN",
            Interface::Ethercat => "EtherCAT",
        }
    }
}

impl ModuleInfo {
    /// Whether the module has host interface `i`.
    pub fn has_interface(&self, i: Interface) -> bool {
        self.interfaces.contains(&i)
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ParameterRow {
    #[serde(default)]
    bank: Option<u8>,
    number: u8,
    #[serde(default)]
    last: Option<u8>,
    name: String,
    /// The name of each parameter of a range row, `{}` standing for its
    /// number ("User variable {}").
    #[serde(default)]
    each: Option<String>,
    access: String,
    min: i64,
    max: i64,
    default: i64,
    default_source: DefaultSource,
    #[serde(default)]
    unit: Option<String>,
    /// Where the row's facts come from (a manual's page): for readers of
    /// the file, not for the simulation.
    #[serde(default)]
    #[allow(dead_code)]
    source: Option<String>,
    #[serde(default)]
    note: Option<String>,
    /// Valid values as inclusive `[from, to]` ranges within min…max.
    #[serde(default)]
    ranges: Vec<[i64; 2]>,
    #[serde(default)]
    quantity: Option<Quantity>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ProfileFile {
    module: ModuleInfo,
    axis_parameter: Vec<ParameterRow>,
    global_parameter: Vec<ParameterRow>,
    features: Features,
    #[serde(default)]
    port: Vec<Port>,
    #[serde(default)]
    interrupt: Vec<Interrupt>,
    #[serde(default)]
    bootloader: Option<Bootloader>,
}

/// What raises an interrupt, read from the symbols of a profile's interrupt
/// table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InterruptSource {
    /// Timer n (`TI_TIMERn`).
    Timer(u8),
    /// Motor n reached its target (`TI_TARGETn`).
    TargetReached(u8),
    /// Motor n stalled (`TI_STALLn`).
    Stall(u8),
    /// Motor n's left stop switch (`TI_STOPLEFTn`).
    StopLeft(u8),
    /// Motor n's right stop switch (`TI_STOPRIGHTn`).
    StopRight(u8),
    /// Input n changed (`TI_INPUTCHANGEn`).
    InputChange(u8),
    /// Motor n's encoder deviates (`TI_DEVIATIONn`).
    Deviation(u8),
}

impl InterruptSource {
    /// Reads the interrupt's source from its symbol (`TI_TIMER0`,
    /// `TI_TARGET0`, `TI_STALL0`, `TI_STOPLEFT0`, `TI_STOPRIGHT0`,
    /// `TI_INPUTCHANGE3`, `TI_DEVIATION0`).
    pub fn from_symbol(symbol: &str) -> Option<InterruptSource> {
        let s = symbol.strip_prefix("TI_")?;
        let digits = s.trim_start_matches(|c: char| c.is_ascii_alphabetic());
        let name = &s[..s.len() - digits.len()];
        let n: u8 = digits.parse().ok()?;
        Some(match name {
            "TIMER" => InterruptSource::Timer(n),
            "TARGET" => InterruptSource::TargetReached(n),
            "STALL" => InterruptSource::Stall(n),
            "STOPLEFT" => InterruptSource::StopLeft(n),
            "STOPRIGHT" => InterruptSource::StopRight(n),
            "INPUTCHANGE" => InterruptSource::InputChange(n),
            "DEVIATION" => InterruptSource::Deviation(n),
            _ => return None,
        })
    }
}

/// Number of global parameter banks (0…3).
pub const BANKS: usize = 4;

/// A loaded, indexed module profile.
#[derive(Debug)]
pub struct Profile {
    /// What the module is and has.
    pub module: ModuleInfo,
    /// What this module can do, beyond its parameter tables.
    pub features: Features,
    axis: Vec<Option<Parameter>>,
    global: [Vec<Option<Parameter>>; BANKS],
    /// The I/O ports.
    pub ports: Vec<Port>,
    /// The interrupt table.
    pub interrupts: Vec<Interrupt>,
    /// The TMCL bootloader, on modules whose firmware can be updated.
    pub bootloader: Option<Bootloader>,
    /// The interrupts' sources, read from their symbols once.
    sources: Vec<(InterruptSource, u8)>,
    /// The interrupt numbers of timers 0, 1 and 2 (looked up on every
    /// step of virtual time).
    timers: [Option<u8>; 3],
    opcode_set: [bool; 256],
    ascii_set: [bool; 256],
}

// `BUILT_IN`: one (name, TOML text) per `profiles/*.toml`, sorted by name,
// generated by build.rs.
include!(concat!(env!("OUT_DIR"), "/built_in.rs"));

impl Profile {
    /// Parses and checks a profile.
    pub fn from_toml(text: &str) -> Result<Profile, ProfileError> {
        let file: ProfileFile = toml::from_str(text).map_err(ProfileError::Toml)?;
        let mut axis: Vec<Option<Parameter>> = vec![None; 256];
        for row in &file.axis_parameter {
            expand(row, &mut axis)?;
        }
        let mut global: [Vec<Option<Parameter>>; BANKS] = std::array::from_fn(|_| vec![None; 256]);
        for row in &file.global_parameter {
            let bank = row.bank.ok_or(ProfileError::NoBank { number: row.number })?;
            let table = global.get_mut(bank as usize).ok_or(ProfileError::NoSuchBank { number: row.number, bank })?;
            expand(row, table)?;
        }
        if file.module.axes == 0 {
            return Err(ProfileError::NoAxis);
        }
        let opcode_set = set_of(&file.module.opcodes);
        let ascii_set = set_of(&file.module.ascii_opcodes);
        let sources: Vec<(InterruptSource, u8)> =
            file.interrupt.iter().filter_map(|i| InterruptSource::from_symbol(&i.symbol).map(|s| (s, i.number))).collect();
        let timer = |t: u8| sources.iter().find(|(s, _)| *s == InterruptSource::Timer(t)).map(|(_, n)| *n);
        let timers = [timer(0), timer(1), timer(2)];
        let profile = Profile {
            module: file.module,
            features: file.features,
            axis,
            global,
            ports: file.port,
            sources,
            timers,
            interrupts: file.interrupt,
            bootloader: file.bootloader,
            opcode_set,
            ascii_set,
        };
        check_features(&profile).map_err(ProfileError::Features)?;
        if let Some(why) = profile.bootloader.as_ref().and_then(Bootloader::problem) {
            return Err(ProfileError::Bootloader(why));
        }
        Ok(profile)
    }

    /// A built-in profile by name (`tmcm-1141`, case-insensitive, the
    /// `tmcm-` prefix optional).
    pub fn built_in(name: &str) -> Result<Arc<Profile>, ProfileError> {
        let key = name.to_ascii_lowercase();
        let key = if key.starts_with("tmcm-") { key } else { format!("tmcm-{key}") };
        // Each built-in profile is parsed once per process and shared.
        static PARSED: [std::sync::OnceLock<Result<Arc<Profile>, ProfileError>>; BUILT_IN.len()] =
            [const { std::sync::OnceLock::new() }; BUILT_IN.len()];
        let i = BUILT_IN
            .iter()
            .position(|(n, _)| *n == key)
            .ok_or_else(|| ProfileError::NotBuiltIn { name: name.to_string(), known: Profile::names() })?;
        PARSED[i]
            .get_or_init(|| {
                Profile::from_toml(BUILT_IN[i].1).map(Arc::new).map_err(|e| ProfileError::BuiltIn { name: key, error: Box::new(e) })
            })
            .clone()
    }

    /// The built-in profiles' names, sorted (`tmcm-1110`, `tmcm-1140`, …).
    pub fn names() -> Vec<&'static str> {
        BUILT_IN.iter().map(|(n, _)| *n).collect()
    }

    /// The axis parameter of this number, if the module has it.
    pub fn axis_parameter(&self, number: u8) -> Option<&Parameter> {
        self.axis[number as usize].as_ref()
    }

    /// The global parameter of this bank and number, if the module has it.
    pub fn global_parameter(&self, bank: u8, number: u8) -> Option<&Parameter> {
        self.global.get(bank as usize)?[number as usize].as_ref()
    }

    /// Every axis parameter, by number.
    pub fn axis_parameters(&self) -> impl Iterator<Item = &Parameter> {
        self.axis.iter().flatten()
    }

    /// Every global parameter of a bank, by number.
    pub fn global_parameters(&self, bank: u8) -> impl Iterator<Item = &Parameter> {
        self.global.get(bank as usize).into_iter().flatten().flatten()
    }

    /// Whether the bank exists on this module (has any parameter).
    pub fn has_bank(&self, bank: u8) -> bool {
        self.global_parameters(bank).next().is_some()
    }

    /// Whether the module has this instruction.
    pub fn has_opcode(&self, opcode: u8) -> bool {
        self.opcode_set[opcode as usize]
    }

    /// Whether ASCII mode executes this instruction.
    pub fn ascii_allows(&self, opcode: u8) -> bool {
        self.ascii_set[opcode as usize]
    }

    /// The port of this kind, bank and number, if the module has it.
    pub fn port(&self, direction: PortDirection, bank: u8, number: u8) -> Option<&Port> {
        self.ports.iter().find(|p| p.direction == direction && p.bank == bank && p.number == number)
    }

    /// The interrupt of this number, if the module has it.
    pub fn interrupt(&self, number: u8) -> Option<&Interrupt> {
        self.interrupts.iter().find(|i| i.number == number)
    }

    /// The interrupt number of a source, by the symbols of the interrupt
    /// table.
    pub fn interrupt_for(&self, source: InterruptSource) -> Option<u8> {
        self.sources.iter().find(|(s, _)| *s == source).map(|(_, n)| *n)
    }

    /// The interrupt number of timer `t` (0…2), if the module has it.
    pub fn timer_interrupt(&self, t: u8) -> Option<u8> {
        self.timers.get(t as usize).copied().flatten()
    }

    /// Every interrupt with a known source: (source, number).
    pub fn interrupt_sources(&self) -> &[(InterruptSource, u8)] {
        &self.sources
    }

    /// Bits per second of a GP 65 baud rate code (features `baud_rates`);
    /// codes the module does not have give the first rate.
    pub fn baud_rate(&self, code: i32) -> u32 {
        let rates = &self.features.baud_rates;
        usize::try_from(code).ok().and_then(|i| rates.get(i)).copied().unwrap_or(rates[0])
    }

    /// Looks an axis parameter up by name (case-insensitive).
    pub fn axis_parameter_named(&self, name: &str) -> Option<&Parameter> {
        self.axis_parameters().find(|p| p.name.eq_ignore_ascii_case(name))
    }

    /// The 136 type 0 text: the profile's `version_text`, or the
    /// `1141V146` form (type number, `V`, version digits).
    pub fn version_text(&self) -> [u8; 8] {
        self.version_text_for(self.module.firmware)
    }

    /// The 136 type 0 text of firmware `version` on this module (one a
    /// firmware update installed, docs/behaviour.md rule 101): the
    /// profile's text with its last three characters, the version digits,
    /// those of `version`.
    pub fn version_text_for(&self, version: [u8; 2]) -> [u8; 8] {
        let mut out = [b'0'; 8];
        match &self.module.version_text {
            Some(text) if text.len() == 8 => out.copy_from_slice(text.as_bytes()),
            _ => out[..5].copy_from_slice(format!("{:04}V", self.module.type_number % 10000).as_bytes()),
        }
        out[5..].copy_from_slice(format!("{}{:02}", version[0] % 10, version[1] % 100).as_bytes());
        out
    }

    /// 136 type 1 value: `[type high][type low][major][minor]`.
    pub fn version_word(&self) -> i32 {
        self.version_word_for(self.module.firmware)
    }

    /// 136 type 1 value of firmware `version` on this module.
    pub fn version_word_for(&self, version: [u8; 2]) -> i32 {
        (u32::from(self.module.type_number) << 16 | u32::from(version[0]) << 8 | u32::from(version[1])) as i32
    }

    /// Position counter mask for modules with 24-bit positions.
    pub fn position_bits(&self) -> u32 {
        u32::from(self.module.position_bits)
    }
}

/// GP 65: the baud rate code that the features' `baud_rates` is indexed by.
const BAUD_RATE: u8 = 65;

/// A lookup table of the opcodes listed.
fn set_of(opcodes: &[u8]) -> [bool; 256] {
    let mut set = [false; 256];
    for &o in opcodes {
        set[o as usize] = true;
    }
    set
}

/// Checks one row of a parameter table and enters the parameters it
/// defines (one, or `number…last`) into `table`.
fn expand(row: &ParameterRow, table: &mut [Option<Parameter>]) -> Result<(), ProfileError> {
    let access = Access::parse(&row.access)?;
    check_row(row).map_err(|problem| ProfileError::Parameter { number: row.number, name: row.name.clone(), problem })?;
    for n in row.number..=row.last.unwrap_or(row.number) {
        if table[n as usize].is_some() {
            return Err(ProfileError::DefinedTwice { number: n, name: row.name.clone() });
        }
        table[n as usize] = Some(Parameter {
            number: n,
            name: row.name.clone(),
            own_name: row.each.as_ref().map(|e| e.replace("{}", &n.to_string())),
            access,
            min: row.min,
            max: row.max,
            default: row.default,
            default_source: row.default_source,
            unit: row.unit.clone(),
            note: row.note.clone(),
            ranges: row.ranges.iter().map(|&[lo, hi]| (lo, hi)).collect(),
            quantity: row.quantity,
            duration_ms: row.unit.as_deref().and_then(duration_ms),
        });
    }
    Ok(())
}

/// The milliseconds a duration unit stands for (`ms` 1, `10ms` or `10 ms`
/// 10, `s` 1000); `None` for a unit that is no duration.
fn duration_ms(unit: &str) -> Option<u64> {
    let unit: String = unit.chars().filter(|c| !c.is_whitespace()).collect();
    let (count, scale) = if let Some(n) = unit.strip_suffix("ms") { (n, 1) } else { (unit.strip_suffix('s')?, 1000) };
    let count = if count.is_empty() { 1 } else { count.parse::<u64>().ok()? };
    Some(count * scale)
}

/// The rules of one parameter row: default within its bounds and ranges,
/// ranges within the bounds, a note for a sibling's default, `each` only on
/// a range.
fn check_row(row: &ParameterRow) -> Result<(), ParameterProblem> {
    let (min, max, default) = (row.min, row.max, row.default);
    if !(min..=max).contains(&default) {
        return Err(ParameterProblem::DefaultOutside { default, min, max });
    }
    if row.ranges.iter().any(|&[lo, hi]| lo > hi || lo < min || hi > max) {
        return Err(ParameterProblem::RangesOutside { min, max });
    }
    if !row.ranges.is_empty() && !row.ranges.iter().any(|&[lo, hi]| (lo..=hi).contains(&default)) {
        return Err(ParameterProblem::DefaultOutsideRanges { default });
    }
    if row.default_source == DefaultSource::Sibling && row.note.as_deref().is_none_or(|n| n.trim().is_empty()) {
        return Err(ParameterProblem::SiblingWithoutNote);
    }
    if row.each.as_ref().is_some_and(|e| row.last.is_none() || !e.contains("{}")) {
        return Err(ParameterProblem::EachWithoutRange);
    }
    Ok(())
}

/// Checks a profile's features against the rest of it: every global
/// parameter they name exists, and the lists fit.
fn check_features(profile: &Profile) -> Result<(), FeatureProblem> {
    let f = &profile.features;
    let named = [
        ("shutdown_pin", f.shutdown_pin),
        ("eeprom_lock", f.eeprom_lock),
        ("eeprom_magic.parameter", f.eeprom_magic.map(|m| m.parameter)),
        ("can.id", f.can.map(|c| c.id)),
        ("can.reply_id", f.can.map(|c| c.reply_id)),
        ("can.secondary_id", f.can.map(|c| c.secondary_id)),
    ];
    for (key, n) in named {
        if let Some(n) = n
            && profile.global_parameter(0, n).is_none()
        {
            return Err(FeatureProblem::MissingParameter { key, number: n });
        }
    }
    if let Some(scale) = f.encoder_scale {
        if f.encoder != Encoder::Abn {
            return Err(FeatureProblem::ScaleWithoutAbnEncoder);
        }
        for (key, n) in [("encoder_scale.resolution", scale.resolution), ("encoder_scale.fullsteps", scale.fullsteps)] {
            if profile.axis_parameter(n).is_none() {
                return Err(FeatureProblem::MissingAxisParameter { key, number: n });
            }
        }
    }
    if f.baud_rates.is_empty() {
        return Err(FeatureProblem::NoBaudRates);
    }
    if let Some(p) = profile.global_parameter(0, BAUD_RATE)
        && p.max + 1 != f.baud_rates.len() as i64
    {
        return Err(FeatureProblem::BaudRates {
            rates: f.baud_rates.len(),
            parameter: BAUD_RATE,
            name: p.name.clone(),
            min: p.min,
            max: p.max,
        });
    }
    if f.full_scale_current_ma == 0 {
        return Err(FeatureProblem::NoCurrent);
    }
    if f.motion_clock_hz == 0 {
        return Err(FeatureProblem::NoClock);
    }
    if f.encoder_deviation_stop && f.encoder == Encoder::None {
        return Err(FeatureProblem::DeviationStopWithoutEncoder);
    }
    if f.motion_units != MotionUnits::Tmc429
        && let Some(p) = profile.axis_parameters().find(|p| p.quantity.is_some())
    {
        return Err(FeatureProblem::QuantityInPps { number: p.number, name: p.name.clone() });
    }
    let points = matches!(f.motion_controller, MotionController::Sixpoint | MotionController::Eightpoint);
    let tmc4361a = f.motion_controller == MotionController::Tmc4361a;
    if (f.motion_units == MotionUnits::Sixpoint) != points || (f.motion_units == MotionUnits::Tmc4361a) != tmc4361a {
        return Err(FeatureProblem::Units { controller: f.motion_controller, units: f.motion_units });
    }
    if let Some(n) = f.unit_mode
        && (!matches!(f.motion_units, MotionUnits::Sixpoint | MotionUnits::Tmc4361a) || profile.axis_parameter(n).is_none())
    {
        return Err(FeatureProblem::MissingAxisParameter { key: "unit_mode", number: n });
    }
    if let Some(text) = &profile.module.version_text
        && (text.len() != 8 || !text.is_ascii())
    {
        return Err(FeatureProblem::VersionText { text: text.clone() });
    }
    for p in &profile.ports {
        let problem = |problem| Err(FeatureProblem::PortScale { bank: p.bank, number: p.number, problem });
        if let Some([lo, hi]) = p.span
            && (p.role.is_none() || !(lo.is_finite() && hi.is_finite()) || lo == hi)
        {
            return problem("span needs a role and two different finite values");
        }
        if p.role == Some(PortRole::Temperature) && p.span.is_none() {
            return problem("a temperature port needs a span");
        }
        let choices = usize::try_from(p.max - p.min + 1).unwrap_or(0);
        if p.direction == PortDirection::InputRange
            && (p.full_scale_volts.len() != choices || p.full_scale_volts.iter().any(|v| !(v.is_finite() && *v > 0.0)))
        {
            return problem("an input_range port needs one positive full_scale_volts for each value from min to max");
        }
        if p.direction != PortDirection::InputRange && !p.full_scale_volts.is_empty() {
            return problem("full_scale_volts belongs to an input_range port");
        }
        if p.ranged && !profile.ports.iter().any(|r| r.direction == PortDirection::InputRange) {
            return problem("a ranged input needs an input_range port");
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn text(name: &str) -> &'static str {
        BUILT_IN.iter().find(|(n, _)| *n == name).unwrap().1
    }

    #[test]
    fn a_range_rows_parameters_are_each_named_by_their_number() {
        let p = Profile::built_in("tmcm-1141").unwrap();
        let v = p.global_parameter(2, 17).unwrap();
        assert_eq!((v.label(), v.name.as_str()), ("User variable 17", "User variables #0…#55"));
        assert_eq!(p.global_parameter(2, 200).unwrap().label(), "User variable 200");
        assert_eq!(p.axis_parameter(1).unwrap().label(), "Actual position");
        // `each` needs a range and a place for the number.
        let t = text("tmcm-1141");
        let no_number = t.replacen("each = \"User variable {}\"", "each = \"User variable\"", 1);
        let no_range = t.replacen("last = 55\n", "", 1);
        for broken in [no_number, no_range] {
            assert!(Profile::from_toml(&broken).unwrap_err().to_string().contains("`each`"));
        }
    }

    #[test]
    fn every_profile_file_is_built_in_sorted_by_name() {
        // build.rs compiles in profiles/*.toml: a new module needs no Rust.
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../profiles");
        let mut files: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|x| x == "toml"))
            .map(|p| p.file_stem().unwrap().to_str().unwrap().to_string())
            .collect();
        files.sort();
        assert_eq!(Profile::names(), files);
        let mut sorted = Profile::names();
        sorted.sort();
        assert_eq!(Profile::names(), sorted);
        for (name, text) in BUILT_IN {
            assert_eq!(
                text.trim(),
                std::fs::read_to_string(format!("{}/../../profiles/{name}.toml", env!("CARGO_MANIFEST_DIR"))).unwrap().trim()
            );
            Profile::built_in(name).unwrap_or_else(|e| panic!("{e}"));
        }
        let e = Profile::built_in("tmcm-9999").unwrap_err().to_string();
        assert!(e.contains("known: ") && e.contains(&Profile::names().join(", ")), "{e}");
    }

    #[test]
    fn a_port_means_the_same_on_every_module_whatever_its_pin_name() {
        let meaning = |module: &str, direction: PortDirection, bank: u8, number: u8| {
            let p = Profile::built_in(module).unwrap();
            let port = p.ports.iter().find(|q| (q.direction, q.bank, q.number) == (direction, bank, number)).unwrap();
            (port.name.clone(), port.meaning())
        };
        // The manuals name the analog input IN0, AIN0 and AIN_0.
        assert_eq!(meaning("tmcm-1141", PortDirection::Input, 1, 0), ("IN0".into(), "analog input 0".into()));
        assert_eq!(meaning("tmcm-1140", PortDirection::Input, 1, 0), ("AIN0".into(), "analog input 0".into()));
        assert_eq!(meaning("tmcm-351", PortDirection::Input, 1, 0), ("AIN_0".into(), "analog input 0".into()));
        assert_eq!(meaning("tmcm-351", PortDirection::Input, 0, 6).1, "digital input 6");
        assert_eq!(meaning("tmcm-351", PortDirection::Input, 1, 4).1, "supply voltage");
        assert_eq!(meaning("tmcm-351", PortDirection::Input, 1, 5).1, "temperature");
        assert_eq!(meaning("tmcm-1141", PortDirection::Input, 1, 8).1, "supply voltage");
        assert_eq!(meaning("tmcm-1141", PortDirection::Output, 2, 1).1, "digital output 1");
        assert_eq!(meaning("tmcm-1141", PortDirection::Pullup, 0, 0).1, "pull-ups");
    }

    #[test]
    fn tmcm_1141_profile_loads_with_every_table_row() {
        let p = Profile::built_in("tmcm-1141").unwrap();
        assert_eq!(p.module.axes, 1);
        // Table 16 has 59 rows.
        assert_eq!(p.axis_parameters().count(), 59);
        for n in [
            0u8, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 130, 135, 138, 140, 149, 150, 153, 154, 193, 194, 195, 196, 197, 200, 204, 206,
            207, 208, 214, 254,
        ] {
            assert!(p.axis_parameter(n).is_some(), "AP {n}");
        }
        for n in 160..=184 {
            assert!(p.axis_parameter(n).is_some(), "AP {n}");
        }
        assert!(p.axis_parameter(14).is_none());
        // Table 18.
        for n in [65u8, 66, 67, 68, 75, 76, 77, 79, 81, 84, 85, 87, 90, 128, 129, 130, 132, 133, 255] {
            assert!(p.global_parameter(0, n).is_some(), "GP {n}");
        }
        assert_eq!(p.global_parameters(2).count(), 256);
        assert!(p.global_parameter(2, 55).unwrap().access.eeprom);
        assert!(!p.global_parameter(2, 56).unwrap().access.eeprom);
        for n in [0u8, 1, 2, 27, 28, 39, 40, 41, 42] {
            assert!(p.global_parameter(3, n).is_some(), "bank 3 {n}");
        }
        assert!(!p.has_bank(1));
        assert_eq!(p.interrupts.len(), 12);
    }

    #[test]
    fn manual_defaults_and_access() {
        let p = Profile::built_in("1141").unwrap();
        let ap = |n| p.axis_parameter(n).unwrap();
        assert_eq!(ap(130).default, 1);
        assert_eq!(ap(214).default, 200);
        assert_eq!(ap(140).default, 8);
        assert_eq!(ap(140).default_source, DefaultSource::Manual);
        assert_eq!(ap(4).access.to_string(), "RWE");
        assert_eq!(ap(3).access.to_string(), "R");
        assert_eq!(p.global_parameter(0, 66).unwrap().access.to_string(), "RWA");
        assert_eq!(p.global_parameter(0, 65).unwrap().default, 0);
        assert_eq!(p.global_parameter(0, 77).unwrap().default, 0);
    }

    #[test]
    fn version_encodings() {
        let p = Profile::built_in("tmcm-1141").unwrap();
        assert_eq!(&p.version_text(), b"1141V146");
        assert_eq!(p.version_word(), 0x0475012E);
    }

    #[test]
    fn unsigned_ranges() {
        let p = Profile::built_in("tmcm-1141").unwrap();
        let timer = p.global_parameter(3, 0).unwrap();
        assert!(timer.accepts(-1)); // 4294967295
        let speed = p.axis_parameter(4).unwrap();
        assert!(!speed.accepts(0));
        assert!(speed.accepts(2047));
        assert!(!speed.accepts(2048));
    }

    #[test]
    fn bad_profiles_are_rejected_with_a_reason() {
        assert!(Profile::from_toml("nonsense").is_err());
        let base = text("tmcm-1141");
        let dup = format!(
            "{base}\n[[axis_parameter]]\nnumber = 4\nname = \"x\"\naccess = \"RW\"\nmin = 0\nmax = 1\ndefault = 0\ndefault_source = \"assumed\"\n"
        );
        assert!(Profile::from_toml(&dup).unwrap_err().to_string().contains("twice"));
    }

    #[test]
    fn default_sources_are_manual_sibling_or_assumed() {
        let p = Profile::built_in("tmcm-1141").unwrap();
        assert_eq!(p.axis_parameter(140).unwrap().default_source, DefaultSource::Manual);
        // AP 4's default comes from TMC-API's TMC429 driver, not the manual.
        assert_eq!(p.axis_parameter(4).unwrap().default_source, DefaultSource::Sibling);
        assert_eq!(p.axis_parameter(0).unwrap().default_source, DefaultSource::Assumed);
        let row = "[[axis_parameter]]\nnumber = 250\nname = \"x\"\naccess = \"RW\"\nmin = 0\nmax = 1\ndefault = 0\n";
        let base = text("tmcm-1141");
        let unknown = Profile::from_toml(&format!("{base}\n{row}default_source = \"folklore\"\n")).unwrap_err().to_string();
        assert!(
            unknown.contains("folklore") && unknown.contains("manual") && unknown.contains("sibling") && unknown.contains("assumed"),
            "{unknown}"
        );
        let bare = Profile::from_toml(&format!("{base}\n{row}default_source = \"sibling\"\n")).unwrap_err().to_string();
        assert!(bare.contains("parameter 250 (x)") && bare.contains("needs a note"), "{bare}");
        Profile::from_toml(&format!("{base}\n{row}default_source = \"sibling\"\nnote = \"TMCM-1140 manual\"\n")).unwrap();
    }

    #[test]
    fn timer_interrupts_are_the_timer_symbols() {
        for (name, _) in BUILT_IN {
            let p = Profile::built_in(name).unwrap();
            for t in 0..3 {
                assert_eq!(p.timer_interrupt(t), p.interrupt_for(InterruptSource::Timer(t)), "{name} timer {t}");
            }
            assert_eq!(p.timer_interrupt(3), None);
        }
        let p = Profile::built_in("tmcm-1141").unwrap();
        assert_eq!((p.timer_interrupt(0), p.timer_interrupt(2)), (Some(0), Some(2)), "TI_TIMER0…2 are interrupts 0…2");
    }

    #[test]
    fn reference_search_mode_takes_only_the_manual_modes() {
        for name in ["tmcm-1141", "tmcm-1310"] {
            let p = Profile::built_in(name).unwrap();
            let mode = p.axis_parameter(193).unwrap();
            let valid: Vec<i32> = (-5..300).filter(|&v| mode.accepts(v)).collect();
            let expected: Vec<i32> = (1..=8).chain(65..=68).chain(133..=136).collect();
            assert_eq!(valid, expected, "{name}");
            assert_eq!(mode.range_text(), "1…8, 65…68, 133…136");
        }
        let bad = text("tmcm-1141").replace("ranges = [[1, 8], [65, 68], [133, 136]]", "ranges = [[1, 8], [65, 200]]");
        assert!(Profile::from_toml(&bad).unwrap_err().to_string().contains("ranges must lie within 1…136"));
    }
}

/// The features of the built-in profiles and the checks of `[features]`
/// tables (here, beside the profile they are checked against).
#[cfg(test)]
mod feature_tests {
    use super::*;
    use crate::features::*;

    fn text(name: &str) -> &'static str {
        BUILT_IN.iter().find(|(n, _)| *n == name).unwrap().1
    }

    /// The built-in profile's text with its `[features]` header followed by
    /// `extra`.
    fn with_features(name: &str, extra: &str) -> String {
        let t = text(name);
        assert_eq!(t.matches("\n[features]\n").count(), 1);
        t.replace("\n[features]\n", &format!("\n[features]\n{extra}\n"))
    }

    /// The built-in profile's text with one feature line replaced.
    fn replacing(name: &str, line: &str, by: &str) -> String {
        let t = text(name);
        assert_eq!(t.matches(line).count(), 1, "{line}");
        t.replace(line, by)
    }

    /// The TMC4361A's units go with its controller and only with it; its
    /// switch rows' bits parse as `enable-polarity`.
    #[test]
    fn the_tmc4361a_s_units_go_with_its_controller_only() {
        let t = text("tmcm-1260");
        let ok = t
            .replace(
                "\nmotion_controller = \"sixpoint\"\n",
                "\nmotion_controller = \"tmc4361a\"\nlimit_switch_rows = \"enable-polarity\"\n",
            )
            .replace("\nmotion_units = \"sixpoint\"\n", "\nmotion_units = \"tmc4361a\"\n");
        let p = Profile::from_toml(&ok).unwrap();
        let f = &p.features;
        assert_eq!(
            (f.motion_controller, f.motion_units, f.limit_switch_rows, f.unit_mode),
            (MotionController::Tmc4361a, MotionUnits::Tmc4361a, LimitSwitchRows::EnablePolarity, Some(255))
        );
        assert_eq!((f.motion_controller.name(), f.motion_units.name()), ("tmc4361a", "tmc4361a"));
        assert!(f.list().iter().any(|(k, v)| *k == "limit_switch_rows" && v.contains("bit 1")));
        let mixed = t.replace("\nmotion_units = \"sixpoint\"\n", "\nmotion_units = \"tmc4361a\"\n");
        assert!(Profile::from_toml(&mixed).is_err(), "sixPoint controller, TMC4361A units");
        let mixed = ok.replace("\nmotion_units = \"tmc4361a\"\n", "\nmotion_units = \"sixpoint\"\n");
        assert!(Profile::from_toml(&mixed).is_err(), "TMC4361A controller, sixPoint units");
    }

    #[test]
    fn tmcm_1141_features() {
        let p = Profile::built_in("tmcm-1141").unwrap();
        let f = &p.features;
        assert_eq!(f.reference_search, ReferenceSearchFamily::Tmc429);
        assert_eq!(f.stall_detection, StallDetection::Stallguard2);
        assert!(f.coolstep);
        assert!(!f.closed_loop);
        assert_eq!(f.ethercat, None);
        assert_eq!(f.encoder, Encoder::None);
        assert_eq!(f.can, None, "CAN identifiers are the serial addresses");
        assert_eq!(f.eeprom_lock, None);
        assert_eq!(f.eeprom_magic, None);
        assert_eq!(f.shutdown_pin, None);
        assert_eq!(f.full_scale_current_ma, 1100);
        assert_eq!(f.motion_clock_hz, 16_000_000, "manual 6.1.1");
        // GP 65 codes → bit/s; codes the module lacks fall back to code 0.
        assert_eq!(p.baud_rate(0), 9600);
        assert_eq!(p.baud_rate(7), 115_200);
        assert_eq!(p.baud_rate(8), 230_400);
        assert_eq!(p.baud_rate(9), 9600);
        assert_eq!(p.baud_rate(-1), 9600);
    }

    #[test]
    fn tmcm_351_features() {
        let p = Profile::built_in("tmcm-351").unwrap();
        let f = &p.features;
        assert_eq!(f.reference_search, ReferenceSearchFamily::Tmc428);
        assert_eq!(f.stall_detection, StallDetection::Tmc249);
        for kind in [StallDetection::Stallguard2, StallDetection::Tmc249, StallDetection::None] {
            let read: StallDetection = toml::Value::String(kind.name().into()).try_into().unwrap();
            assert_eq!(read, kind, "{} names what the profile data names", kind.name());
        }
        assert!(!f.coolstep);
        assert!(!f.closed_loop);
        assert_eq!(f.encoder, Encoder::Tmc423);
        assert!(f.encoder_deviation_stop);
        assert!(f.motion_groups);
        assert_eq!(f.can, Some(CanIds { id: 71, reply_id: 70, secondary_id: 83 }));
        assert_eq!(f.eeprom_lock, Some(73));
        assert_eq!(f.eeprom_magic, Some(EepromMagic { parameter: 64, value: 0xE4 }));
        assert_eq!(f.shutdown_pin, Some(80));
        assert_eq!(f.full_scale_current_ma, 2800);
        assert_eq!(p.baud_rate(8), 230_400);
        assert_eq!(p.baud_rate(11), 1_000_000);
        assert_eq!(p.baud_rate(12), 9600);
    }

    #[test]
    fn tmcm_1310_features() {
        let p = Profile::built_in("tmcm-1310").unwrap();
        let f = &p.features;
        assert!(f.closed_loop);
        let e = f.ethercat.as_ref().expect("an EtherCAT slave");
        assert_eq!((e.vendor_id, e.product_code, e.order_code.as_str(), e.group.as_str()), (0x286, 1310, "TMCM-1310-CL", "Stepper"));
        assert_eq!(f.encoder, Encoder::AbnSsi);
        assert_eq!(f.reference_search, ReferenceSearchFamily::Tmc429);
        assert_eq!(f.can, None);
        assert_eq!(f.full_scale_current_ma, 3000);
        assert_eq!(f.motion_units, MotionUnits::Pps);
        // No GP 65: every code gives the one rate.
        assert_eq!(p.baud_rate(0), 9600);
        assert_eq!(p.baud_rate(5), 9600);
    }

    #[test]
    fn motion_units_are_the_tmc429_s_unless_the_profile_says_pps() {
        for name in Profile::names() {
            let p = Profile::built_in(name).unwrap();
            let pps = p.features.motion_units == MotionUnits::Pps;
            assert_eq!(pps, name == "tmcm-1310", "{name}");
            // TMC429 modules mark their velocity rows; a pps or sixPoint
            // module has no such row: its values are microsteps per second
            // as written (or the chip's units, by AP 255).
            let tmc429 = p.features.motion_units == MotionUnits::Tmc429;
            assert_eq!(p.axis_parameter(4).unwrap().quantity.is_some(), tmc429, "{name}");
            let points = matches!(p.features.motion_controller, MotionController::Sixpoint | MotionController::Eightpoint);
            assert_eq!(p.features.motion_units == MotionUnits::Sixpoint, points, "{name}");
        }
        // An encoder scale names rows the profile has, on an abn encoder.
        let e = Profile::from_toml(&replacing("tmcm-6214", "resolution = 210", "resolution = 250")).unwrap_err().to_string();
        assert!(e.contains("encoder_scale.resolution names axis parameter 250"), "{e}");
        let e = Profile::from_toml(&replacing("tmcm-6214", "\nencoder = \"abn\"", "\nencoder = \"tmc423\"")).unwrap_err().to_string();
        assert!(e.contains("encoder_scale needs features.encoder = \"abn\""), "{e}");
        // The sixPoint units belong to the sixPoint controller, and it to them.
        let e = Profile::from_toml(&with_features("tmcm-1310", "motion_controller = \"sixpoint\"")).unwrap_err().to_string();
        assert!(e.contains("motion_units = \"pps\" does not go with features.motion_controller = \"sixpoint\""), "{e}");
        let e = Profile::from_toml(&replacing("tmcm-1310", "\nmotion_units = \"pps\"", "\nmotion_units = \"sixpoint\""))
            .unwrap_err()
            .to_string();
        assert!(e.contains("motion_units = \"sixpoint\" does not go with features.motion_controller = \"tmc429\""), "{e}");
        let e = Profile::from_toml(&with_features("tmcm-1310", "motion_controller = \"tmc5072\"")).unwrap_err().to_string();
        assert!(e.contains("tmc5072"), "{e}");
        let e = Profile::from_toml(&with_features("tmcm-1141", "motion_units = \"pps\"")).unwrap_err().to_string();
        assert!(e.contains("axis parameter 2 (") && e.contains("motion_units"), "{e}");
        let e = Profile::from_toml(&with_features("tmcm-1141", "motion_units = \"rpm\"")).unwrap_err().to_string();
        assert!(e.contains("rpm"), "{e}");
        // The TMCM-1310's velocity rows: pps, in the range its closed-loop
        // sibling TMCM-1311 gives its velocities (manual V1.11, AP 108/109).
        let p = Profile::built_in("tmcm-1310").unwrap();
        for n in [4, 108, 109, 130, 194, 195] {
            let row = p.axis_parameter(n).unwrap();
            assert_eq!((row.max, row.unit.as_deref()), (327_679_999, Some("pps")), "AP {n}");
        }
        assert!(p.axis_parameter(4).unwrap().accepts(20_000), "PyTrinamic's TMCM-1311 examples");
        assert!(!p.axis_parameter(4).unwrap().accepts(327_680_000));
        assert_eq!(p.axis_parameter(5).unwrap().unit.as_deref(), Some("pps²"));
        assert!(p.axis_parameter(153).is_none() && p.axis_parameter(154).is_none(), "no divisors");
    }

    #[test]
    fn only_the_1310_is_an_ethercat_slave_or_runs_closed_loop() {
        for name in Profile::names() {
            let p = Profile::built_in(name).unwrap();
            assert_eq!(p.features.ethercat.is_some(), name == "tmcm-1310", "{name}");
            assert_eq!(p.features.closed_loop, name == "tmcm-1310", "{name}");
        }
    }

    #[test]
    fn supply_channels_have_the_supply_role() {
        for (name, bank, number) in [("tmcm-1141", 1, 8), ("tmcm-1310", 1, 8)] {
            let p = Profile::built_in(name).unwrap();
            assert_eq!(p.port(PortDirection::Input, bank, number).unwrap().role, Some(PortRole::Supply), "{name}");
            assert_eq!(p.ports.iter().filter(|q| q.role == Some(PortRole::Supply)).count(), 1, "{name}");
        }
        // The TMCM-351 reads its supply and temperature on GIO 4, 1 and
        // 5, 1 with its 10-bit ADC (V4.45 §4.6.15 p.40), through a span.
        let p = Profile::built_in("tmcm-351").unwrap();
        let supply = p.port(PortDirection::Input, 1, 4).unwrap();
        assert_eq!((supply.role, supply.max, supply.span.is_some()), (Some(PortRole::Supply), 1023, true));
        let temperature = p.port(PortDirection::Input, 1, 5).unwrap();
        assert_eq!((temperature.role, temperature.max, temperature.span.is_some()), (Some(PortRole::Temperature), 1023, true));
    }

    #[test]
    fn port_scales_are_checked() {
        let e = Profile::from_toml(&replacing("tmcm-351", "span = [-50.0, 280.0]\n", "")).unwrap_err().to_string();
        assert!(e.contains("port 5 of bank 1") && e.contains("temperature port needs a span"), "{e}");
        let e = Profile::from_toml(&replacing("tmcm-351", "span = [0.0, 36.3]", "span = [3.0, 3.0]")).unwrap_err().to_string();
        assert!(e.contains("port 4 of bank 1") && e.contains("two different finite values"), "{e}");
        let e = Profile::from_toml(&replacing("tmcm-351", "full_scale_volts = [3.3, 10.0]", "full_scale_volts = [3.3]"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("port 8 of bank 0") && e.contains("one positive full_scale_volts"), "{e}");
        let e = Profile::from_toml(&replacing("tmcm-351", "version_text = \"351V.445\"", "version_text = \"351V4.45x\""))
            .unwrap_err()
            .to_string();
        assert!(e.contains("8 ASCII characters"), "{e}");
    }

    #[test]
    fn an_unknown_feature_is_rejected_by_name() {
        let e = Profile::from_toml(&with_features("tmcm-1141", "teleport = true")).unwrap_err().to_string();
        assert!(e.contains("unknown field") && e.contains("teleport"), "{e}");
        let e = Profile::from_toml(&replacing("tmcm-351", "secondary_id = 83\n", "secondary_id = 83\nbroadcast_id = 1\n"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("unknown field") && e.contains("broadcast_id"), "{e}");
        let e = Profile::from_toml(&replacing("tmcm-1141", "reference_search = \"tmc429\"", "reference_search = \"tmc430\""))
            .unwrap_err()
            .to_string();
        assert!(e.contains("tmc430"), "{e}");
    }

    #[test]
    fn the_features_table_is_required() {
        let t = text("tmcm-1141");
        let start = t.find("\n[features]\n").unwrap();
        let end = start + t[start..].find("\n# ---").unwrap();
        let e = Profile::from_toml(&format!("{}{}", &t[..start], &t[end..])).unwrap_err().to_string();
        assert!(e.contains("features"), "{e}");
        // So is every key that is not optional.
        let e = Profile::from_toml(&replacing("tmcm-1141", "coolstep = true", "")).unwrap_err().to_string();
        assert!(e.contains("coolstep"), "{e}");
    }

    #[test]
    fn features_must_name_parameters_the_profile_has() {
        // The TMCM-1141 has no GP 73.
        let e = Profile::from_toml(&with_features("tmcm-1141", "eeprom_lock = 73")).unwrap_err().to_string();
        assert!(e.contains("features.eeprom_lock") && e.contains("73"), "{e}");
        let e =
            Profile::from_toml(&with_features("tmcm-1141", "can = { id = 71, reply_id = 70, secondary_id = 83 }")).unwrap_err().to_string();
        assert!(e.contains("features.can.id"), "{e}");
        // One rate per GP 65 code.
        let e = Profile::from_toml(&replacing("tmcm-1141", ", 230400]", "]")).unwrap_err().to_string();
        assert!(e.contains("baud_rates") && e.contains("0…8"), "{e}");
        let e = Profile::from_toml(&replacing("tmcm-1310", "baud_rates = [9600]", "baud_rates = []")).unwrap_err().to_string();
        assert!(e.contains("baud_rates"), "{e}");
        let e = Profile::from_toml(&replacing("tmcm-1141", "encoder_deviation_stop = false", "encoder_deviation_stop = true"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("needs an encoder"), "{e}");
    }

    #[test]
    fn durations_follow_the_rows_unit() {
        let p1141 = Profile::built_in("tmcm-1141").unwrap();
        let p351 = Profile::built_in("tmcm-351").unwrap();
        let ms = |p: &Profile, n| p.axis_parameter(n).unwrap().ms_per_unit();
        assert_eq!(ms(&p1141, 204), Some(10), "TMCM-1141 freewheeling: 10 ms");
        assert_eq!(ms(&p1141, 214), Some(10));
        assert_eq!(ms(&p351, 204), Some(1), "TMCM-351 freewheeling: ms (V4.45 §5 p.69)");
        assert_eq!(ms(&p351, 214), Some(10), "TMCM-351 power down delay: 10 ms (p.70)");
        assert_eq!(ms(&p351, 4), None, "a velocity is no duration");
    }

    #[test]
    fn every_listed_feature_is_documented() {
        let readme = include_str!("../../../profiles/README.md");
        let p = Profile::built_in("tmcm-351").unwrap();
        let list = p.features.list();
        assert_eq!(list.len(), 22);
        for (key, value) in &list {
            let row = if matches!(*key, "can" | "ethercat" | "error_flags" | "encoder_scale") {
                format!("| `[features.{key}]` |")
            } else {
                format!("| `{key}` |")
            };
            assert!(readme.contains(&row), "{key} has no row in the README's features table");
            assert!(!value.is_empty(), "{key}");
        }
        let get = |k: &str| list.iter().find(|(key, _)| *key == k).unwrap().1.clone();
        assert_eq!(get("eeprom_magic"), "GP 64 = 0xE4");
        assert_eq!(get("full_scale_current_ma"), "2800 mA RMS");
        assert_eq!(get("motion_clock_hz"), "16000000 Hz");
        assert!(get("motion_units").starts_with("TMC429"));
        assert!(get("motion_controller").starts_with("TMC429"));
        assert!(get("baud_rates").contains("codes 0…11"));
    }
}
