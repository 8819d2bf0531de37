//! The `[features]` table of a profile: what a module can do beyond its
//! parameter tables, stated as data so that no code has to guess it from a
//! module name or from "the profile has parameter N".
//!
//! Every key is required except the ones that name a global parameter a
//! module may lack (`shutdown_pin`, `eeprom_lock`, `eeprom_magic`,
//! `[features.can]`): absent, the module has no such thing. The schema is in
//! `profiles/README.md`.

use crate::Profile;
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
    None,
    /// An incremental encoder on a TMC423 interface: AP 209 position,
    /// AP 210 prescaler.
    Tmc423,
    /// An incremental a/b/n or an absolute SSI encoder, chosen by AP 201
    /// (closed-loop modules).
    AbnSsi,
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
    pub parameter: u8,
    pub value: i32,
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
    /// Bits per second, indexed by the GP 65 code.
    pub baud_rates: Vec<u32>,
    /// The motor current (mA RMS) that AP 6 = 255 (100 %) means.
    pub full_scale_current_ma: u32,
    /// The motion controller's clock (Hz): the f_CLK of the formulas that
    /// turn velocity and acceleration values into microsteps per second
    /// (docs/behaviour.md rule 23).
    pub motion_clock_hz: u32,
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
                }
                .to_string(),
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
        ]
    }

    /// Checks the features against the rest of the profile: every global
    /// parameter they name exists, and the lists fit.
    pub(crate) fn check(&self, profile: &Profile) -> Result<(), String> {
        let named = [
            ("shutdown_pin", self.shutdown_pin),
            ("eeprom_lock", self.eeprom_lock),
            ("eeprom_magic.parameter", self.eeprom_magic.map(|m| m.parameter)),
            ("can.id", self.can.map(|c| c.id)),
            ("can.reply_id", self.can.map(|c| c.reply_id)),
            ("can.secondary_id", self.can.map(|c| c.secondary_id)),
        ];
        for (key, n) in named {
            if let Some(n) = n
                && profile.global_parameter(0, n).is_none()
            {
                return Err(format!("features.{key} names global parameter {n}, which the profile does not have (bank 0)"));
            }
        }
        if self.baud_rates.is_empty() {
            return Err("features.baud_rates is empty: it needs at least the rate of code 0".into());
        }
        if let Some(p) = profile.global_parameter(0, BAUD_RATE)
            && p.max + 1 != self.baud_rates.len() as i64
        {
            return Err(format!(
                "features.baud_rates has {} rates, but GP {BAUD_RATE} ({}) takes codes {}…{}",
                self.baud_rates.len(),
                p.name,
                p.min,
                p.max
            ));
        }
        if self.full_scale_current_ma == 0 {
            return Err("features.full_scale_current_ma is 0".into());
        }
        if self.motion_clock_hz == 0 {
            return Err("features.motion_clock_hz is 0".into());
        }
        if self.encoder_deviation_stop && self.encoder == Encoder::None {
            return Err("features.encoder_deviation_stop needs an encoder (features.encoder is \"none\")".into());
        }
        Ok(())
    }
}

/// GP 65: the baud rate code that `baud_rates` is indexed by.
const BAUD_RATE: u8 = 65;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{BUILT_IN, PortDirection, PortRole};

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
        // No GP 65: every code gives the one rate.
        assert_eq!(p.baud_rate(0), 9600);
        assert_eq!(p.baud_rate(5), 9600);
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
        // The TMCM-351's profile has no supply channel.
        assert!(Profile::built_in("tmcm-351").unwrap().ports.iter().all(|q| q.role.is_none()));
    }

    #[test]
    fn an_unknown_feature_is_rejected_by_name() {
        let e = Profile::from_toml(&with_features("tmcm-1141", "teleport = true")).unwrap_err();
        assert!(e.contains("unknown field") && e.contains("teleport"), "{e}");
        let e = Profile::from_toml(&replacing("tmcm-351", "secondary_id = 83\n", "secondary_id = 83\nbroadcast_id = 1\n")).unwrap_err();
        assert!(e.contains("unknown field") && e.contains("broadcast_id"), "{e}");
        let e = Profile::from_toml(&replacing("tmcm-1141", "reference_search = \"tmc429\"", "reference_search = \"tmc430\"")).unwrap_err();
        assert!(e.contains("tmc430"), "{e}");
    }

    #[test]
    fn the_features_table_is_required() {
        let t = text("tmcm-1141");
        let start = t.find("\n[features]\n").unwrap();
        let end = start + t[start..].find("\n# ---").unwrap();
        let e = Profile::from_toml(&format!("{}{}", &t[..start], &t[end..])).unwrap_err();
        assert!(e.contains("features"), "{e}");
        // So is every key that is not optional.
        let e = Profile::from_toml(&replacing("tmcm-1141", "coolstep = true", "")).unwrap_err();
        assert!(e.contains("coolstep"), "{e}");
    }

    #[test]
    fn features_must_name_parameters_the_profile_has() {
        // The TMCM-1141 has no GP 73.
        let e = Profile::from_toml(&with_features("tmcm-1141", "eeprom_lock = 73")).unwrap_err();
        assert!(e.contains("features.eeprom_lock") && e.contains("73"), "{e}");
        let e = Profile::from_toml(&with_features("tmcm-1141", "can = { id = 71, reply_id = 70, secondary_id = 83 }")).unwrap_err();
        assert!(e.contains("features.can.id"), "{e}");
        // One rate per GP 65 code.
        let e = Profile::from_toml(&replacing("tmcm-1141", ", 230400]", "]")).unwrap_err();
        assert!(e.contains("baud_rates") && e.contains("0…8"), "{e}");
        let e = Profile::from_toml(&replacing("tmcm-1310", "baud_rates = [9600]", "baud_rates = []")).unwrap_err();
        assert!(e.contains("baud_rates"), "{e}");
        let e = Profile::from_toml(&replacing("tmcm-1141", "encoder_deviation_stop = false", "encoder_deviation_stop = true")).unwrap_err();
        assert!(e.contains("needs an encoder"), "{e}");
    }

    #[test]
    fn every_listed_feature_is_documented() {
        let readme = include_str!("../../../profiles/README.md");
        let p = Profile::built_in("tmcm-351").unwrap();
        let list = p.features.list();
        assert_eq!(list.len(), 16);
        for (key, value) in &list {
            let row = if matches!(*key, "can" | "ethercat") { format!("| `[features.{key}]` |") } else { format!("| `{key}` |") };
            assert!(readme.contains(&row), "{key} has no row in the README's features table");
            assert!(!value.is_empty(), "{key}");
        }
        let get = |k: &str| list.iter().find(|(key, _)| *key == k).unwrap().1.clone();
        assert_eq!(get("eeprom_magic"), "GP 64 = 0xE4");
        assert_eq!(get("full_scale_current_ma"), "2800 mA RMS");
        assert_eq!(get("motion_clock_hz"), "16000000 Hz");
        assert!(get("baud_rates").contains("codes 0…11"));
    }
}
