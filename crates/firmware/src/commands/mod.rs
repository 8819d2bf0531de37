//! The command families that span several parts of the module, one file
//! per family; `executor.rs` matches every decoded command once and hands
//! it here or straight to the part that owns it. Here: what the families
//! share.

mod calculation;
mod coordinates;
mod events;
mod io;
mod motion;
mod parameters;
mod program_control;

use crate::module::Module;
use tmclsim_protocol::Status;

impl Module {
    /// The axis of a motor number.
    pub(crate) fn motor(&self, motor: u8) -> Result<usize, Status> {
        if (motor as usize) < self.axes.len() { Ok(motor as usize) } else { Err(Status::InvalidValue) }
    }
}
