//! TMCL over CAN (TMCM-1141 manual 3.1/3.2 notes): the CAN identifier
//! replaces the address byte and there is no checksum. A request is 7 data
//! bytes `[opcode][type][motor][value MSB first]` (more are ignored); the
//! reply goes out with the reply identifier and 7 data bytes `[module
//! address][status][opcode][value]`. 136 type 0 answers with the eight
//! characters of the version; 134 with the stored instruction.
//!
//! Identifiers: modules whose profile names CAN identifier parameters
//! (features `[features.can]`; TMCM-351: GP 71 CAN ID, GP 83 secondary ID,
//! GP 70 reply ID) use them; the others use their serial address (GP 66,
//! GP 87) and the host address (GP 76).

use crate::module::Module;
use crate::outcome::Special;
use crate::parameter_numbers::gp;
use tmclsim_protocol::{Instruction, Status, opcode};

/// A CAN frame: 11-bit identifier and up to 8 data bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CanFrame {
    /// The 11-bit CAN identifier.
    pub id: u32,
    /// How many of `data`'s bytes the frame carries (0…8).
    pub len: u8,
    /// The data bytes; those past `len` are 0.
    pub data: [u8; 8],
}

impl CanFrame {
    /// A frame with identifier `id` and the first 8 of `bytes`.
    pub fn new(id: u32, bytes: &[u8]) -> CanFrame {
        let mut data = [0u8; 8];
        let len = bytes.len().min(8);
        data[..len].copy_from_slice(&bytes[..len]);
        CanFrame { id, len: len as u8, data }
    }

    /// The frame's data bytes (the first `len`).
    pub fn bytes(&self) -> &[u8] {
        &self.data[..self.len as usize]
    }
}

impl Module {
    /// The identifiers this module answers to.
    pub fn can_ids(&self) -> (u32, Option<u32>) {
        if let Some(can) = self.profile.features.can {
            let secondary = self.globals[0][can.secondary_id as usize] as u32;
            (self.globals[0][can.id as usize] as u32, (secondary != 0).then_some(secondary))
        } else {
            let secondary = u32::from(self.secondary_address());
            (u32::from(self.address()), (secondary != 0).then_some(secondary))
        }
    }

    /// The identifier of this module's replies.
    pub fn can_reply_id(&self) -> u32 {
        match self.profile.features.can {
            Some(can) => self.globals[0][can.reply_id as usize] as u32,
            None => u32::from(self.host_address()),
        }
    }

    /// Handles a CAN frame; `None` when it is not for this module (or
    /// replies are suppressed).
    pub fn handle_can(&mut self, frame: &CanFrame) -> Option<CanFrame> {
        let (id, secondary) = self.can_ids();
        if frame.id != id && Some(frame.id) != secondary {
            return None;
        }
        if frame.len < 7 {
            return None;
        }
        self.link.restart_heartbeat(self.now_ns);
        // A new reply identifier takes effect with the next frame, as a
        // new serial address does (docs/behaviour.md rules 2 and 92).
        let reply_id = self.can_reply_id();
        let d = frame.data;
        let ins = Instruction::new(d[0], d[1], d[2], i32::from_be_bytes([d[3], d[4], d[5], d[6]]));
        let outcome =
            if self.program.download.is_some() && !opcode::is_control(ins.opcode) { self.download_word(ins) } else { self.execute(ins) };
        let reply = match outcome.special {
            Special::Silent => return None,
            // 136 type 0: the 8 characters; 134: the instruction (the
            // 9-byte forms without host byte and checksum).
            Special::Frame(f) if ins.opcode == opcode::FIRMWARE_VERSION => CanFrame::new(reply_id, &f[1..9]),
            Special::Frame(f) => CanFrame::new(reply_id, &f[1..8]),
            Special::None => {
                let v = outcome.value.to_be_bytes();
                CanFrame::new(reply_id, &[self.address(), outcome.status.code(), ins.opcode, v[0], v[1], v[2], v[3]])
            }
        };
        if ins.opcode == opcode::RESET && outcome.status == Status::Ok {
            self.reset();
            return Some(reply);
        }
        if self.globals[0][gp::SUPPRESS_REPLY as usize] == 1 && !matches!(ins.opcode, opcode::GAP | opcode::GGP | opcode::GIO) {
            return None;
        }
        Some(reply)
    }

    /// An unsolicited 138 event frame as a CAN frame of this module.
    pub fn event_as_can(&self, event: &[u8; 9]) -> CanFrame {
        CanFrame::new(self.can_reply_id(), &event[1..8])
    }
}
