//! Helpers for the unit tests of the `impl Module` files: a module by
//! profile name, and commands by mnemonic (or `#op type motor value`) in
//! direct mode or as a program instruction.

use crate::module::Module;
use crate::outcome::Origin;
use tmclsim_protocol::mnemonic::parse_line;
use tmclsim_protocol::{Command, Instruction, Status};

/// One millisecond of virtual time.
pub const MS: u64 = 1_000_000;

pub fn module(profile: &str) -> Module {
    Module::built_in(profile).unwrap()
}

/// A module with 24-bit position counters (TMC428 counters, as the
/// TMCM-351 had before its firmware 4.37): the TMCM-351 so changed.
pub fn module_24_bit() -> Module {
    let (_, text) = tmclsim_profile::BUILT_IN.iter().find(|(n, _)| *n == "tmcm-351").unwrap();
    let text = text.replace("position_bits = 32", "position_bits = 24");
    Module::new(std::sync::Arc::new(tmclsim_profile::Profile::from_toml(&text).unwrap()))
}

fn instruction(line: &str) -> Instruction {
    parse_line(line).unwrap_or_else(|e| panic!("{line}: {e}"))
}

/// A command in direct mode: its status and value.
pub fn direct(m: &mut Module, line: &str) -> (Status, i32) {
    let o = m.execute(instruction(line));
    (o.status, o.value)
}

/// The status of a command in direct mode.
pub fn status(m: &mut Module, line: &str) -> Status {
    direct(m, line).0
}

/// The value of a command in direct mode, which must succeed.
pub fn ok(m: &mut Module, line: &str) -> i32 {
    let (status, value) = direct(m, line);
    assert_eq!(status, Status::Ok, "{line}");
    value
}

/// A command as a program instruction (reads load the accumulator).
pub fn in_program(m: &mut Module, line: &str) -> Result<i32, Status> {
    let ins = instruction(line);
    let cmd = Command::decode(ins).unwrap_or_else(|e| panic!("{line}: {e:?}"));
    let at = m.now_ns();
    m.dispatch(cmd, ins, Origin::Program, at).map(|o| o.value)
}
