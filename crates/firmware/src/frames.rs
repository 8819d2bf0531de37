//! The binary interface: 9-byte request frames in, 9-byte replies out
//! (RS-232, RS-485, USB and the links a server offers) — address filter,
//! checksum, download mode, reply suppression (GP 255).

use crate::module::Module;
use crate::outcome::Special;
use crate::parameter_numbers::gp;
use tmclsim_protocol::frame::version_string_reply;
use tmclsim_protocol::{FRAME_LEN, Reply, Request, Status, opcode};

impl Module {
    /// Handles one 9-byte frame from a serial-type link: address filter,
    /// checksum, execution, reply (docs/behaviour.md rules 2–4, 11).
    pub fn handle_frame(&mut self, frame: &[u8; FRAME_LEN]) -> Option<[u8; FRAME_LEN]> {
        let (request, checksum_ok) = match Request::decode(frame) {
            Ok(r) => (r, true),
            Err(r) => (r, false),
        };
        if !self.answers_to(request.address) {
            return None;
        }
        self.link.last_address = request.address;
        self.link.restart_heartbeat(self.now_ns);
        let host = self.host_address();
        if !checksum_ok {
            if self.replies_suppressed(0) {
                return None;
            }
            return Some(Reply::new(host, request.address, Status::WrongChecksum, 0, 0).encode());
        }
        let ins = request.instruction;
        let outcome =
            if self.program.download.is_some() && !opcode::is_control(ins.opcode) { self.download_word(ins) } else { self.execute(ins) };
        let reply = match outcome.special {
            Special::Silent => return None,
            Special::Frame(f) => f,
            Special::None => Reply::new(host, request.address, outcome.status, ins.opcode, outcome.value).encode(),
        };
        if ins.opcode == opcode::RESET && outcome.status == Status::Ok {
            // The reply goes out, then the module restarts.
            self.reset();
            return Some(reply);
        }
        if self.replies_suppressed(ins.opcode) {
            return None;
        }
        Some(reply)
    }

    /// A resync frame on a point-to-point link (docs/behaviour.md rule 85):
    /// address 0 and opcode 0 with a good checksum, as hosts send when they
    /// open the port, are answered with status 2 (invalid command) from the
    /// module's own address. Any other frame: `None` (not for this rule).
    pub fn answer_resync(&mut self, frame: &[u8; FRAME_LEN]) -> Option<[u8; FRAME_LEN]> {
        let request = Request::decode(frame).ok()?;
        if request.address != 0 || request.instruction.opcode != 0 || self.answers_to(0) || self.replies_suppressed(0) {
            return None;
        }
        self.link.restart_heartbeat(self.now_ns);
        Some(Reply::new(self.host_address(), self.address(), Status::InvalidCommand, 0, 0).encode())
    }

    /// Does a frame with this address byte reach this module?
    pub fn answers_to(&self, address: u8) -> bool {
        address == self.address() || (self.secondary_address() != 0 && address == self.secondary_address())
    }

    /// GP 255: replies in direct mode are suppressed except for GAP, GGP
    /// and GIO.
    fn replies_suppressed(&self, op: u8) -> bool {
        self.globals[0][gp::SUPPRESS_REPLY as usize] == 1 && !matches!(op, opcode::GAP | opcode::GGP | opcode::GIO)
    }

    /// 136 type 0: the version text as a frame.
    pub(crate) fn special_version(&self) -> [u8; FRAME_LEN] {
        version_string_reply(self.host_address(), &self.profile.version_text())
    }
}
