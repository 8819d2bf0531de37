//! The command families that span several parts of the module, one file
//! per family; `executor.rs` matches every decoded command but the
//! control commands (`control.rs`) once and hands it here or straight to
//! the part that owns it. Here: what the families share.

mod calculation;
mod coordinates;
mod events;
mod flow;
mod io;
mod motion;
mod parameters;

use crate::module::Module;
use tmclsim_protocol::Status;

impl Module {
    /// The axis of a motor number.
    pub(crate) fn motor(&self, motor: u8) -> Result<usize, Status> {
        if (motor as usize) < self.axes.len() { Ok(motor as usize) } else { Err(Status::InvalidValue) }
    }
}
