//! The TMCL commands, one file per family; `executor.rs` hands every
//! decoded command to its family. Here: what the families share.

mod calculation;
mod coordinates;
mod events;
mod io;
mod motion;
mod parameters;
mod program_control;

use crate::module::Module;
use crate::outcome::Origin;
use tmclsim_protocol::Status;

/// What a command returns: the value of a direct-mode reply, or the status
/// of its failure.
pub(crate) type Exec = Result<i32, Status>;

impl Module {
    /// The axis of a motor number.
    pub(crate) fn motor(&self, motor: u8) -> Result<usize, Status> {
        if (motor as usize) < self.axes.len() { Ok(motor as usize) } else { Err(Status::InvalidValue) }
    }

    /// A read in a program loads the accumulator and sets the flags; a
    /// direct-mode read leaves them alone (docs/behaviour.md rules 7, 18).
    pub(crate) fn loaded(&mut self, v: i32, origin: Origin) -> i32 {
        if origin == Origin::Program {
            self.registers.load(v);
        }
        v
    }
}
