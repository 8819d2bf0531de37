//! The `[features]` table of a profile: what a module can do beyond its
//! parameter tables, stated as data so that no code has to guess it from a
//! module name or from "the profile has parameter N".
//!
//! Every key is required except the ones that name a global parameter a
//! module may lack (`shutdown_pin`, `eeprom_lock`, `eeprom_magic`,
//! `[features.can]`): absent, the module has no such thing; and the ones
//! with a default (`error_flags`, `motion_units`). The schema is in
//! `profiles/README.md`.

use serde::Deserialize;

/// The reference search (RFS) family: which modes AP 193 selects.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ReferenceSearchFamily {
    /// TMC429 modules (TMCM-1141): modes 1…8, +64 search the right
    /// switch, +128 inverted home switch.
    Tmc429,
    /// TMC428 modules (TMCM-351): modes 1…3 (left switch; right then left;
    /// right then the home switch).
    Tmc428,
}

/// How the driver detects a stall.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum StallDetection {
    /// stallGuard2 (TMC262 and alike): load value 0…1023 in AP 206,
    /// threshold AP 174, stop on stall above the speed in AP 181.
    Stallguard2,
    /// The TMC249's load indicator: 0…7 in AP 206, the motor stops when it
    /// exceeds AP 205.
    Tmc249,
    /// No stall detection.
    None,
}

impl StallDetection {
    /// The name a profile's `[features]` table gives it.
    pub fn name(self) -> &'static str {
        match self {
            StallDetection::Stallguard2 => "stallguard2",
            StallDetection::Tmc249 => "tmc249",
            StallDetection::None => "none",
        }
    }
}

/// The encoder input.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Encoder {
    /// No encoder input.
    None,
    /// An incremental encoder on a TMC423 interface: AP 209 position,
    /// AP 210 prescaler.
    Tmc423,
    /// An incremental a/b/n or an absolute SSI encoder, chosen by AP 201
    /// (closed-loop modules).
    AbnSsi,
    /// An incremental a/b/n encoder on the TMC5130/TMC5160's encoder
    /// interface: AP 209 is the chip's encoder position, the counts
    /// scaled as `encoder_scale` says (docs/behaviour.md rule 112).
    Abn,
}

/// The axis parameters an `abn` encoder's scale comes from: the encoder's
/// counts per revolution and the motor's full steps per revolution. The
/// module scales the counts to microsteps with them
/// (`fullsteps × microsteps / resolution`; a resolution of 0: one a
/// microstep a count).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EncoderScale {
    /// The axis parameter of the encoder's counts per revolution.
    pub resolution: u8,
    /// The axis parameter of the motor's full steps per revolution.
    pub fullsteps: u8,
}

/// The units of a module's velocity and acceleration parameters (AP 2…5,
/// 130, 181, 182, 194, 195 and the closed-loop velocities).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MotionUnits {
    /// The TMC429's internal units: a value becomes microsteps per second
    /// (per second²) with the pulse and ramp divisors (AP 154, 153) and
    /// `motion_clock_hz` (docs/behaviour.md rule 23).
    #[default]
    Tmc429,
    /// Microsteps per second and per second², as written: no divisors.
    Pps,
    /// The sixPoint and eight-point modules' (TMC5130/TMC5160/TMC5240):
    /// pps and pps² turned into the chip's register values, or with the
    /// unit mode (`unit_mode`'s row) at 0 the registers themselves
    /// (`v·f_CLK/2^24` µsteps/s, `a·f_CLK²/2^41` µsteps/s², with
    /// `motion_clock_hz`; docs/behaviour.md rule 104).
    Sixpoint,
    /// The TMC4361A modules': pps, pps² and pps³ as written, the chip's
    /// registers holding velocities in 24.8 and accelerations in 22.2
    /// fixed point; with the unit mode (`unit_mode`'s row) at 0 the
    /// register values themselves (docs/behaviour.md rule 114).
    Tmc4361a,
}

impl MotionUnits {
    /// The name a profile's `[features]` table gives it.
    pub fn name(self) -> &'static str {
        match self {
            MotionUnits::Tmc429 => "tmc429",
            MotionUnits::Pps => "pps",
            MotionUnits::Sixpoint => "sixpoint",
            MotionUnits::Tmc4361a => "tmc4361a",
        }
    }
}

impl MotionController {
    /// The name a profile's `[features]` table gives it.
    pub fn name(self) -> &'static str {
        match self {
            MotionController::Tmc429 => "tmc429",
            MotionController::Sixpoint => "sixpoint",
            MotionController::Eightpoint => "eightpoint",
            MotionController::Tmc4361a => "tmc4361a",
        }
    }
}

/// What AP 12 (right) and AP 13 (left) say of the stop switches.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LimitSwitchRows {
    /// 1 disables the switch: it no longer stops the motor (the TMCM-1141
    /// manual's "right/left limit switch disable").
    #[default]
    Disable,
    /// 1 enables the automatic stop at the switch, 0 leaves the switch
    /// without effect on the motor ("automatic right/left stop").
    Enable,
    /// Bit 0 enables the automatic stop at the switch, bit 1 inverts its
    /// polarity (the TMC4361A modules' "limit switch enable/polarity").
    #[serde(rename = "enable-polarity")]
    EnablePolarity,
}

/// The motion controller a module's axes run on: the part of the
/// firmware that turns the ramp parameters into motion.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MotionController {
    /// The TMC429 (and TMC428): a trapezoid with AP 4, AP 5 and the stop
    /// speed AP 130, soft and velocity modes by AP 138.
    #[default]
    Tmc429,
    /// The TMC5130/TMC5160 sixPoint ramp: VSTART, A1 to V1, AMAX to VMAX,
    /// DMAX to V1, D1 to VSTOP (AP 15…21), docs/behaviour.md rules 104–110.
    Sixpoint,
    /// The TMC5240 eight-point ramp: the sixPoint ramp with a second knee
    /// V2 (AP 35) and its A2 (AP 34) and D2 (AP 36), docs/behaviour.md
    /// rule 113.
    Eightpoint,
    /// The TMC4361A: a trapezoid with the sixPoint's bands (VSTART,
    /// ASTART to VBREAK, AMAX to VMAX, DMAX to VBREAK, DFINAL to VSTOP)
    /// or, with AP 14 = 1, an S-shaped ramp whose acceleration changes
    /// with the bows BOW1…BOW4 (AP 22…25).
    Tmc4361a,
}

/// The global parameters (bank 0) holding a module's own CAN identifiers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CanIds {
    /// The identifier the module listens to.
    pub id: u8,
    /// The identifier of its replies.
    pub reply_id: u8,
    /// A second identifier it listens to (0 = off).
    pub secondary_id: u8,
}

/// How an EtherCAT slave names itself to a master (SII EEPROM and object
/// 0x1018). The device name is the module's name and the revision its
/// firmware version (major in the high word, minor in the low word).
#[derive(Clone, Debug, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EthercatIdentity {
    /// The vendor's EtherCAT identifier.
    pub vendor_id: u32,
    /// The product code.
    pub product_code: u32,
    /// The order code (the SII's order string).
    pub order_code: String,
    /// The device group (the SII's group string).
    pub group: String,
}

/// A global parameter (bank 0) whose stored value says whether the EEPROM
/// is initialised: any other value re-initialises it at power-up.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EepromMagic {
    /// The global parameter number.
    pub parameter: u8,
    /// The value that marks an initialised EEPROM.
    pub value: i32,
}

/// The bits of AP 207 (extended error flags) and what clears them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ErrorFlags {
    /// The bit value set when the motor was stopped for a stall.
    pub stall: i32,
    /// The bit value set when the motor was stopped for an encoder
    /// deviation (AP 212).
    pub deviation: i32,
    /// Reading AP 207 clears it (it is always cleared by the next motion
    /// command).
    pub cleared_by_read: bool,
}

impl Default for ErrorFlags {
    /// The TMCM-1141's: 1 after a stall stop, cleared by reading.
    fn default() -> ErrorFlags {
        ErrorFlags { stall: 1, deviation: 2, cleared_by_read: true }
    }
}

/// What tells one module from another, beyond its parameter tables.
#[derive(Clone, Debug, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Features {
    /// Which reference search modes RFS knows.
    pub reference_search: ReferenceSearchFamily,
    /// How stalls are detected.
    pub stall_detection: StallDetection,
    /// coolStep current regulation (AP 168…172).
    pub coolstep: bool,
    /// The encoder input.
    pub encoder: Encoder,
    /// How an `abn` encoder's counts become AP 209. `None`: one count is
    /// one unit of AP 209.
    #[serde(default)]
    pub encoder_scale: Option<EncoderScale>,
    /// AP 212: the motor stops when position counter and encoder drift
    /// apart further than it allows.
    pub encoder_deviation_stop: bool,
    /// AP 167 (chopper off time) = 0 switches the driver off.
    pub chopper_off_disables_driver: bool,
    /// AP 213: motors with the same non-zero group index receive each
    /// other's motion commands.
    pub motion_groups: bool,
    /// Closed-loop operation (position, velocity and torque mode).
    pub closed_loop: bool,
    /// The module is an EtherCAT slave, named so. `None`: it is not.
    #[serde(default)]
    pub ethercat: Option<EthercatIdentity>,
    /// Global parameter (bank 0) of a shutdown input's function: 0 off,
    /// 1 high active, 2 low active. `None`: no shutdown input.
    #[serde(default)]
    pub shutdown_pin: Option<u8>,
    /// Global parameter (bank 0) that locks EEPROM writes (status 5) while
    /// it reads 1. `None`: the EEPROM cannot be locked.
    #[serde(default)]
    pub eeprom_lock: Option<u8>,
    /// The EEPROM's "initialised" mark. `None`: none.
    #[serde(default)]
    pub eeprom_magic: Option<EepromMagic>,
    /// The module's own CAN identifier parameters. `None`: on CAN the
    /// module uses its serial address (GP 66, secondary GP 87) and host
    /// address (GP 76) as identifiers.
    #[serde(default)]
    pub can: Option<CanIds>,
    /// AP 207's bits. Absent: stall 1, deviation 2, cleared by reading.
    #[serde(default)]
    pub error_flags: ErrorFlags,
    /// Bits per second, indexed by the GP 65 code.
    pub baud_rates: Vec<u32>,
    /// The motor current (mA RMS) that AP 6 = 255 (100 %) means.
    pub full_scale_current_ma: u32,
    /// The motion controller's clock (Hz): the f_CLK of the formulas that
    /// turn velocity and acceleration values into microsteps per second
    /// (docs/behaviour.md rule 23).
    pub motion_clock_hz: u32,
    /// The units of velocities and accelerations. Absent: the TMC429's.
    #[serde(default)]
    pub motion_units: MotionUnits,
    /// The motion controller part. Absent: the TMC429.
    #[serde(default)]
    pub motion_controller: MotionController,
    /// The axis parameter of the unit mode (AP 255: 1 pps, 0 the chip's
    /// registers) on a module with `motion_units = "sixpoint"` or
    /// `"tmc4361a"`. `None`: always pps.
    #[serde(default)]
    pub unit_mode: Option<u8>,
    /// What AP 12 and 13 say of the stop switches. Absent: they disable.
    #[serde(default)]
    pub limit_switch_rows: LimitSwitchRows,
}

fn yes_no(b: bool) -> String {
    if b { "yes" } else { "no" }.to_string()
}

impl Features {
    /// Every feature as (key, human-readable value), in the order of the
    /// schema.
    pub fn list(&self) -> Vec<(&'static str, String)> {
        let gp_or_none = |n: Option<u8>| n.map_or("none".to_string(), |n| format!("GP {n}"));
        vec![
            (
                "reference_search",
                match self.reference_search {
                    ReferenceSearchFamily::Tmc429 => "TMC429 (AP 193 modes 1…8, +64 right switch, +128 inverted home)",
                    ReferenceSearchFamily::Tmc428 => "TMC428 (AP 193 modes 1…3)",
                }
                .to_string(),
            ),
            (
                "stall_detection",
                match self.stall_detection {
                    StallDetection::Stallguard2 => "stallGuard2 (load 0…1023)",
                    StallDetection::Tmc249 => "TMC249 load indicator (0…7, threshold AP 205)",
                    StallDetection::None => "none",
                }
                .to_string(),
            ),
            ("coolstep", yes_no(self.coolstep)),
            (
                "encoder",
                match self.encoder {
                    Encoder::None => "none",
                    Encoder::Tmc423 => "incremental, TMC423 interface",
                    Encoder::AbnSsi => "incremental a/b/n or absolute SSI",
                    Encoder::Abn => "incremental a/b/n on the sixPoint chip's encoder interface",
                }
                .to_string(),
            ),
            (
                "encoder_scale",
                match self.encoder_scale {
                    Some(s) => format!(
                        "AP 209 in microsteps: AP {} full steps × microsteps / AP {} counts per revolution",
                        s.fullsteps, s.resolution
                    ),
                    None => "one count is one unit of AP 209".to_string(),
                },
            ),
            ("encoder_deviation_stop", yes_no(self.encoder_deviation_stop)),
            ("chopper_off_disables_driver", yes_no(self.chopper_off_disables_driver)),
            ("motion_groups", yes_no(self.motion_groups)),
            ("closed_loop", yes_no(self.closed_loop)),
            (
                "ethercat",
                match &self.ethercat {
                    Some(e) => format!(
                        "slave: vendor {:#X}, product code {}, order code {}, group {}",
                        e.vendor_id, e.product_code, e.order_code, e.group
                    ),
                    None => "no".to_string(),
                },
            ),
            (
                "error_flags",
                format!(
                    "AP 207: stall {}, deviation {}, cleared by {}",
                    self.error_flags.stall,
                    self.error_flags.deviation,
                    if self.error_flags.cleared_by_read { "reading it or a motion command" } else { "the next motion command" }
                ),
            ),
            ("shutdown_pin", gp_or_none(self.shutdown_pin)),
            ("eeprom_lock", gp_or_none(self.eeprom_lock)),
            ("eeprom_magic", self.eeprom_magic.map_or("none".to_string(), |m| format!("GP {} = {:#X}", m.parameter, m.value))),
            (
                "can",
                match self.can {
                    Some(c) => format!("own identifiers: GP {} id, GP {} reply id, GP {} secondary id", c.id, c.reply_id, c.secondary_id),
                    None => "serial addresses (GP 66/87 id, GP 76 reply id)".to_string(),
                },
            ),
            ("baud_rates", {
                let rates = self.baud_rates.iter().map(u32::to_string).collect::<Vec<_>>().join(", ");
                match self.baud_rates.len() {
                    1 => format!("{rates} bit/s (every GP 65 code)"),
                    n => format!("{rates} bit/s (GP 65 codes 0…{})", n - 1),
                }
            }),
            ("full_scale_current_ma", format!("{} mA RMS", self.full_scale_current_ma)),
            ("motion_clock_hz", format!("{} Hz", self.motion_clock_hz)),
            (
                "motion_units",
                match self.motion_units {
                    MotionUnits::Tmc429 => "TMC429 internal units (pulse and ramp divisors, AP 154/153)",
                    MotionUnits::Pps => "pps and pps² (microsteps per second, per second²)",
                    MotionUnits::Sixpoint => match self.unit_mode {
                        Some(_) => "pps and pps² with the unit mode 1, the chip's internal units with 0",
                        None => "pps and pps², as the chip's registers hold them",
                    },
                    MotionUnits::Tmc4361a => match self.unit_mode {
                        Some(_) => "pps, pps², pps³ with the unit mode 1; with 0 the registers (velocities × 256, accelerations × 4)",
                        None => "pps, pps² and pps³",
                    },
                }
                .to_string(),
            ),
            ("unit_mode", self.unit_mode.map_or("none (pps)".to_string(), |n| format!("AP {n}"))),
            (
                "limit_switch_rows",
                match self.limit_switch_rows {
                    LimitSwitchRows::Disable => "AP 12/13 = 1 disables the right/left stop switch",
                    LimitSwitchRows::Enable => "AP 12/13 = 1 enables the automatic stop at the right/left switch",
                    LimitSwitchRows::EnablePolarity => {
                        "AP 12/13 bit 0 enables the automatic stop at the right/left switch, bit 1 inverts its polarity"
                    }
                }
                .to_string(),
            ),
            (
                "motion_controller",
                match self.motion_controller {
                    MotionController::Tmc429 => "TMC429 (trapezoid, AP 4/5/130, modes by AP 138)",
                    MotionController::Sixpoint => "sixPoint (TMC5130/TMC5160: VSTART, A1, V1, AMAX, VMAX, DMAX, D1, VSTOP)",
                    MotionController::Eightpoint => "eight-point (TMC5240: VSTART, A1, V1, A2, V2, AMAX, VMAX, DMAX, D2, D1, VSTOP)",
                    MotionController::Tmc4361a => "TMC4361A (trapezoid with VBREAK, or S-shaped with BOW1…BOW4 by AP 14)",
                }
                .to_string(),
            ),
        ]
    }
}
