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
