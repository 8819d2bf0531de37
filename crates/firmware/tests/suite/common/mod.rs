//! Helpers shared by the firmware's integration tests: a module on a bus
//! of its own, and commands by mnemonic (or `#op type motor value`) sent
//! as frames to module address 1.
#![allow(dead_code)]

use std::ops::{Deref, DerefMut};
use tmclsim_firmware::world::Load;
use tmclsim_firmware::{Bus, Module};
use tmclsim_protocol::mnemonic::parse_line;
use tmclsim_protocol::{Reply, Request};

/// One millisecond of virtual time.
pub const MS: u64 = 1_000_000;

/// A module on a bus of its own, as the tests drive it: requests and
/// looks go to the module (it derefs to it), time moves on the bus.
#[derive(Clone, Debug)]
pub struct BusOfOne(Bus);

impl BusOfOne {
    pub fn new(module: Module) -> BusOfOne {
        BusOfOne(Bus::single(module))
    }

    /// A built-in module by profile name.
    pub fn built_in(profile: &str) -> BusOfOne {
        BusOfOne::new(Module::built_in(profile).unwrap())
    }

    /// Moves virtual time on by `dt_ns`.
    pub fn advance(&mut self, dt_ns: u64) {
        self.0.advance(dt_ns);
    }

    /// Moves virtual time to `t_ns` (no-op for the past).
    pub fn advance_to(&mut self, t_ns: u64) {
        self.0.advance_to(t_ns);
    }
}

impl Deref for BusOfOne {
    type Target = Module;
    fn deref(&self) -> &Module {
        self.0.module(0)
    }
}

impl DerefMut for BusOfOne {
    fn deref_mut(&mut self) -> &mut Module {
        self.0.module_mut(0)
    }
}

/// A module that powers up with `m`'s EEPROM (a power cycle).
pub fn power_cycle(m: &BusOfOne) -> BusOfOne {
    BusOfOne::new(Module::with_eeprom(m.profile().clone(), m.eeprom().clone()))
}

/// Advances in steps of 1 ms until `done` holds; the steps it took, or
/// `None` after `limit_ms`.
pub fn until(m: &mut BusOfOne, limit_ms: u64, mut done: impl FnMut(&mut BusOfOne) -> bool) -> Option<u64> {
    for t in 1..=limit_ms {
        m.advance(MS);
        if done(m) {
            return Some(t);
        }
    }
    None
}

/// The request frame of a command to address 1.
pub fn frame(line: &str) -> [u8; 9] {
    Request::new(1, parse_line(line).unwrap_or_else(|e| panic!("{line}: {e}"))).encode()
}

/// Sends one command and returns the decoded reply.
pub fn reply(m: &mut Module, line: &str) -> Reply {
    Reply::decode(&m.handle_frame(&frame(line)).unwrap_or_else(|| panic!("{line}: no reply"))).unwrap()
}

/// The status of a command's reply.
pub fn status(m: &mut Module, line: &str) -> u8 {
    reply(m, line).status
}

/// Sends a command that must succeed (status 100) and returns its value.
pub fn send(m: &mut Module, line: &str) -> i32 {
    let r = reply(m, line);
    assert_eq!(r.status, 100, "{line}");
    r.value
}

/// Nine bytes from their hex spelling (`"01 04 00 …"`).
pub fn hex(s: &str) -> [u8; 9] {
    let v: Vec<u8> = s.split_whitespace().map(|b| u8::from_str_radix(b, 16).unwrap()).collect();
    v.try_into().unwrap()
}

/// A constant load on axis 0, in % of the motor's rated torque.
pub fn load(m: &mut Module, torque: f64) {
    m.world_mut().axes[0].loads = vec![Load { torque, ..Load::default() }];
}

/// A TMC4361A module for the tests, made from the TMCM-1260's profile:
/// its sixPoint rows replaced by the TMC4361A's (the TMCL-Lite 1316
/// numbering: AP 14 ramp type, 15–25 the ramp and bows, 12/13 enable and
/// polarity bits, 33 swap, 34 soft stop, 255 unit mode) and its features
/// saying `motion_controller = "tmc4361a"`.
pub fn tmc4361a_profile() -> std::sync::Arc<tmclsim_firmware::profile::Profile> {
    let text = include_str!("../../../../../profiles/tmcm-1260.toml");
    let rows: [(u8, &str, i64, i64, &str); 21] = [
        (2, "Target velocity", -8_388_607, 8_388_607, "pps"),
        (3, "Actual velocity", -8_388_607, 8_388_607, "pps"),
        (4, "Maximum positioning velocity", 0, 8_388_607, "pps"),
        (5, "Maximum acceleration", 0, 16_777_215, "pps²"),
        (12, "Right limit switch enable/polarity", 0, 3, ""),
        (13, "Left limit switch enable/polarity", 0, 3, ""),
        (14, "Ramp type", 0, 1, ""),
        (15, "Start velocity", 0, 8_388_607, "pps"),
        (16, "Start acceleration", 0, 16_777_215, "pps²"),
        (17, "Maximum deceleration", 0, 16_777_215, "pps²"),
        (18, "Break velocity", 0, 8_388_607, "pps"),
        (19, "Final deceleration", 0, 16_777_215, "pps²"),
        (20, "Stop velocity", 0, 8_388_607, "pps"),
        (21, "Stop deceleration", 0, 16_777_215, "pps²"),
        (22, "Bow 1", 0, 16_777_215, "pps³"),
        (23, "Bow 2", 0, 16_777_215, "pps³"),
        (24, "Bow 3", 0, 16_777_215, "pps³"),
        (25, "Bow 4", 0, 16_777_215, "pps³"),
        (33, "Swap limit switches", 0, 1, ""),
        (34, "Soft stop enable", 0, 1, ""),
        (255, "Unit mode", 0, 1, ""),
    ];
    let mut sections: Vec<String> = text.split("\n[").map(str::to_string).collect();
    sections.retain(|s| !(2..=5).chain(12..=40).chain([255]).any(|n| s.starts_with(&format!("[axis_parameter]]\nnumber = {n}\n"))));
    let mut text = sections.join("\n[");
    text = text
        .replace("\nmotion_controller = \"sixpoint\"\n", "\nmotion_controller = \"tmc4361a\"\nlimit_switch_rows = \"enable-polarity\"\n");
    text = text.replace("\nmotion_units = \"sixpoint\"\n", "\nmotion_units = \"tmc4361a\"\n");
    for (number, name, min, max, unit) in rows {
        let default = match number {
            255 => 1,
            12 | 13 => 1,
            4 | 5 | 17 => 51_200,
            _ => 0,
        };
        let unit = if unit.is_empty() { String::new() } else { format!("unit = \"{unit}\"\n") };
        text.push_str(&format!(
            "\n[[axis_parameter]]\nnumber = {number}\nname = \"{name}\"\naccess = \"RW\"\nmin = {min}\nmax = {max}\ndefault = {default}\n\
             default_source = \"assumed\"\n{unit}source = \"a test\"\n"
        ));
    }
    std::sync::Arc::new(tmclsim_firmware::profile::Profile::from_toml(&text).unwrap())
}

/// A TMC4361A module (`tmc4361a_profile`) on a bus of its own.
pub fn tmc4361a_module() -> BusOfOne {
    BusOfOne::new(Module::new(tmc4361a_profile()))
}
