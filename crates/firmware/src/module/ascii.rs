//! The ASCII interface (TMCM-1141 manual 3.4): entered by command 139 or
//! at power-up by GP 67 bit 0, left with `BIN`.
//!
//! A line is `<address character><command>` and a carriage return, e.g.
//! `AMVP ABS, 1, 50000`; the address character is `A` for address 1, `B`
//! for 2, and so on. The reply is `<host character><module character>
//! <status> <value>` and a carriage return, e.g. `BA 100 -5000`. GP 67
//! bits 4 and 5 choose the echo: each character as it comes (00, with
//! backspace editing), the whole line after the carriage return (01), or
//! none (10). Only the commands the module permits in ASCII mode run;
//! `RUN` and `STOP` start and stop the TMCL program.

use crate::module::Module;
use crate::parameter_numbers::gp;
use tmclsim_protocol::{Instruction, Status, mnemonic};

pub use crate::state::link::{AsciiLine, LineState};

const CR: u8 = b'\r';
const BACKSPACE: u8 = 0x08;
const DELETE: u8 = 0x7F;

/// The character that stands for an address (`A` = 1).
pub fn address_char(address: u8) -> u8 {
    b'@'.wrapping_add(address)
}

impl Module {
    /// The module reads text (ASCII mode) rather than 9-byte frames.
    pub fn ascii_mode(&self) -> bool {
        self.link.ascii
    }

    fn echo_mode(&self) -> i32 {
        (self.globals[0][gp::ASCII_MODE as usize] >> 4) & 3
    }

    /// One character from the module's own serial port in ASCII mode; what
    /// the module sends back (echo, reply) is appended to `out`.
    pub fn ascii_byte(&mut self, byte: u8, out: &mut Vec<u8>) {
        let mut line = std::mem::take(&mut self.link.ascii_line);
        self.ascii_byte_on(&mut line, byte, out);
        self.link.ascii_line = line;
    }

    /// One character in ASCII mode from a link whose line is `line`
    /// (docs/behaviour.md rule 83: each link types its own line).
    pub fn ascii_byte_on(&mut self, line: &mut AsciiLine, byte: u8, out: &mut Vec<u8>) {
        if line.session != self.link.ascii_session {
            line.clear();
            line.session = self.link.ascii_session;
        }
        let addressed = |m: &Module, line: &[u8]| {
            line.first().is_some_and(|&c| {
                c == address_char(m.address()) || (m.secondary_address() != 0 && c == address_char(m.secondary_address()))
            })
        };
        match byte {
            CR => {
                let line = line.take();
                if !addressed(self, &line) {
                    return;
                }
                match self.echo_mode() {
                    0 => out.push(CR),
                    1 => {
                        out.extend_from_slice(&line);
                        out.push(CR);
                    }
                    _ => {}
                }
                self.link.restart_heartbeat(self.now_ns);
                let text = String::from_utf8_lossy(&line[1..]).into_owned();
                let (status, value) = self.ascii_command(text.trim());
                if let Some((status, value)) = status.zip(value) {
                    let reply = format!("{}{} {} {}\r", address_char(self.host_address()) as char, line[0] as char, status.code(), value);
                    out.extend_from_slice(reply.as_bytes());
                }
            }
            b'\n' | 0 => {}
            BACKSPACE | DELETE => {
                if line.len() > 1 && self.echo_mode() == 0 && addressed(self, line.bytes()) {
                    out.push(BACKSPACE);
                }
                if line.len() > 1 || !addressed(self, line.bytes()) {
                    line.pop();
                }
            }
            _ => {
                if line.push(byte) && self.echo_mode() == 0 && addressed(self, line.bytes()) {
                    out.push(byte);
                }
            }
        }
    }

    /// Runs one command line (without the address character). `None`:
    /// nothing to answer.
    fn ascii_command(&mut self, text: &str) -> (Option<Status>, Option<i32>) {
        match text.to_ascii_uppercase().as_str() {
            "" => return (None, None),
            "BIN" => {
                self.link.ascii = false;
                return (Some(Status::Ok), Some(0));
            }
            "RUN" => {
                self.start_program();
                return (Some(Status::Ok), Some(0));
            }
            "STOP" => {
                self.pause_program();
                self.program.mode = crate::program::RunMode::Stop;
                return (Some(Status::Ok), Some(0));
            }
            _ => {}
        }
        let ins: Instruction = match mnemonic::parse_line(text) {
            Ok(i) => i,
            Err(_) if text.split_whitespace().next().and_then(tmclsim_protocol::opcode::from_mnemonic).is_none() => {
                return (Some(Status::InvalidCommand), Some(0));
            }
            Err(_) => return (Some(Status::WrongType), Some(0)),
        };
        if !self.profile.ascii_allows(ins.opcode) {
            return (Some(Status::InvalidCommand), Some(ins.value));
        }
        let outcome = self.execute(ins);
        (Some(outcome.status), Some(outcome.value))
    }
}
