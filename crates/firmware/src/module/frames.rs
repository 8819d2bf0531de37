//! The binary interface: 9-byte request frames in, 9-byte replies out
//! (RS-232, RS-485, USB and the links a server offers) — address filter,
//! checksum, download mode and its owner, reply suppression (GP 255); and
//! an observer's reads, which change nothing.

use crate::module::Module;
use crate::outcome::{Outcome, Special};
use crate::parameter_numbers::gp;
use crate::program::Download;
use tmclsim_protocol::{Command, FRAME_LEN, Instruction, Reply, Request, Status, opcode};

use crate::link_id::{IN_PROCESS, LinkId};

impl Module {
    /// Handles one 9-byte frame from a serial-type link: address filter,
    /// checksum, execution, reply (docs/behaviour.md rules 2–4, 11), from
    /// an in-process caller.
    pub fn handle_frame(&mut self, frame: &[u8; FRAME_LEN]) -> Option<[u8; FRAME_LEN]> {
        self.handle_frame_from(IN_PROCESS, frame)
    }

    /// [`Module::handle_frame`] for a frame that came on link `link`: in
    /// download mode only the link that entered it has its frames stored
    /// (docs/behaviour.md rule 91).
    pub fn handle_frame_from(&mut self, link: LinkId, frame: &[u8; FRAME_LEN]) -> Option<[u8; FRAME_LEN]> {
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
        let outcome = match self.program.download_role(link) {
            Download::Owner if !opcode::is_control(ins.opcode) => self.download_word(ins),
            // Another link's download is not started, ended or run over.
            Download::Other if Self::changes_program_state(ins.opcode) => Outcome::error(Status::NotAvailable, ins.value),
            _ => self.execute(ins),
        };
        if ins.opcode == opcode::ENTER_DOWNLOAD && outcome.status == Status::Ok {
            self.program.download_owner = Some(link);
        }
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

    /// Opcodes a link other than the download's owner may not send while
    /// it downloads: run, step, reset, and entering or leaving download
    /// mode.
    fn changes_program_state(op: u8) -> bool {
        matches!(
            op,
            opcode::RUN_APPLICATION | opcode::STEP_APPLICATION | opcode::RESET_APPLICATION | opcode::ENTER_DOWNLOAD | opcode::EXIT_DOWNLOAD
        )
    }

    /// Link `link` is gone: a download it owned waits for the next link
    /// that speaks (docs/behaviour.md rule 91).
    pub fn link_closed(&mut self, link: LinkId) {
        self.program.release_download(link);
    }

    /// The reply a read would get, taken from the model without any of a
    /// request's effects: no download word is stored, AP 207 is not
    /// cleared, GP 133 does not move on, the heartbeat does not restart
    /// (docs/behaviour.md rule 86). Reads are GAP, GGP, GIO, 134, 135 and
    /// 136; anything else is `None`. The module's own address answers.
    pub fn observe(&self, ins: Instruction) -> Option<[u8; FRAME_LEN]> {
        let (host, address) = (self.host_address(), self.address());
        let reply = |r: Result<i32, Status>| {
            let (status, value) = match r {
                Ok(v) => (Status::Ok, v),
                Err(s) => (s, ins.value),
            };
            Some(Reply::new(host, address, status, ins.opcode, value).encode())
        };
        // The bootloader tells what it is and takes no reads (rule 99).
        if let Some(facts) = self.profile.bootloader.as_ref().filter(|_| self.in_bootloader()) {
            return match (ins.opcode, ins.kind) {
                (opcode::FIRMWARE_VERSION, 0) => {
                    let text = <[u8; 8]>::try_from(facts.version_text.as_bytes()).expect("checked when the profile loads");
                    Some(tmclsim_protocol::frame::version_string_reply(host, &text))
                }
                _ => reply(Err(Status::InvalidCommand)),
            };
        }
        if !self.profile.has_opcode(ins.opcode) {
            return reply(Err(Status::InvalidCommand));
        }
        match Command::decode(ins) {
            Ok(Command::Gap { param, motor }) => reply(self.peek_axis_parameter(param, motor)),
            Ok(Command::Ggp { param, bank }) => reply(self.peek_global_parameter(param, bank)),
            Ok(Command::Gio { port, bank }) => reply(self.io.read_port(&self.profile, &self.world, port, bank)),
            Ok(Command::FirmwareVersion { binary: false }) => Some(self.special_version()),
            Ok(Command::FirmwareVersion { binary: true }) => reply(Ok(self.profile.version_word_for(self.firmware_version()))),
            Ok(Command::ReadMemory { address: a }) => match self.read_memory(a) {
                Ok(word) => Some(tmclsim_protocol::frame::memory_reply(host, word)),
                Err(s) => reply(Err(s)),
            },
            Ok(Command::ApplicationStatus { kind }) => reply(Ok(self.application_status(kind))),
            Ok(_) => None,
            Err(e) => reply(Err(e.status())),
        }
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
        if self.in_bootloader() {
            return self.profile.bootloader.as_ref().is_some_and(|b| b.address == address);
        }
        address == self.address() || (self.secondary_address() != 0 && address == self.secondary_address())
    }

    /// GP 255: replies in direct mode are suppressed except for GAP, GGP
    /// and GIO.
    fn replies_suppressed(&self, op: u8) -> bool {
        self.globals[0][gp::SUPPRESS_REPLY as usize] == 1 && !matches!(op, opcode::GAP | opcode::GGP | opcode::GIO)
    }
}

#[cfg(test)]
mod tests {
    use crate::test_support::{module, ok};
    use tmclsim_protocol::Reply;
    use tmclsim_protocol::mnemonic::parse_line;

    #[test]
    fn looking_at_ap_207_does_not_clear_it() {
        let mut m = module("tmcm-1141");
        m.axes[0].params[207] = 1;
        let look = |m: &crate::Module| Reply::decode(&m.observe(parse_line("GAP 207, 0").unwrap()).unwrap()).unwrap().value;
        assert_eq!((look(&m), look(&m)), (1, 1), "not cleared by looking");
        assert_eq!(ok(&mut m, "GAP 207, 0"), 1);
        assert_eq!(ok(&mut m, "GAP 207, 0"), 0, "a GAP clears it (docs/behaviour.md rule 52)");
    }
}
