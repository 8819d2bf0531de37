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
