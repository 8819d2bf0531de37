//! The 9-byte TMCL frame, its checksum, and the reply layouts.

use crate::status::Status;

/// Length of a TMCL frame on serial-type links (RS485, USB, TCP, pty).
pub const FRAME_LEN: usize = 9;

/// 8-bit sum of the bytes (TMCM-1141 manual 3.1.1).
pub fn checksum(bytes: &[u8]) -> u8 {
    bytes.iter().fold(0u8, |sum, b| sum.wrapping_add(*b))
}

/// The seven bytes every TMCL command has on every link: instruction
/// number, type, motor/bank and a 32-bit value. This is also one word of
/// TMCL program memory.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Instruction {
    /// Instruction number ([`crate::opcode`]).
    pub opcode: u8,
    /// Type byte: a parameter number, a condition, an operation, …
    pub kind: u8,
    /// Motor or bank number (a user variable for some instructions).
    pub motor: u8,
    /// The value (big-endian on the wire).
    pub value: i32,
}

impl Instruction {
    /// An instruction from its four fields.
    pub const fn new(opcode: u8, kind: u8, motor: u8, value: i32) -> Self {
        Instruction { opcode, kind, motor, value }
    }

    /// The seven bytes: opcode, type, motor, value big-endian.
    pub fn to_bytes(self) -> [u8; 7] {
        let v = self.value.to_be_bytes();
        [self.opcode, self.kind, self.motor, v[0], v[1], v[2], v[3]]
    }

    /// An instruction from its seven bytes (as [`Instruction::to_bytes`]).
    pub fn from_bytes(b: &[u8; 7]) -> Self {
        Instruction { opcode: b[0], kind: b[1], motor: b[2], value: i32::from_be_bytes([b[3], b[4], b[5], b[6]]) }
    }
}

/// A request frame: `[address][opcode][type][motor][value BE][checksum]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Request {
    /// The module address the request is for.
    pub address: u8,
    /// What to do.
    pub instruction: Instruction,
}

impl Request {
    /// A request to the module at `address`.
    pub const fn new(address: u8, instruction: Instruction) -> Self {
        Request { address, instruction }
    }

    /// The nine bytes, checksum included.
    pub fn encode(&self) -> [u8; FRAME_LEN] {
        let i = self.instruction.to_bytes();
        let mut f = [self.address, i[0], i[1], i[2], i[3], i[4], i[5], i[6], 0];
        f[8] = checksum(&f[..8]);
        f
    }

    /// Splits a frame into its fields; `Err` carries the request anyway so a
    /// module can answer a checksum error with its own address.
    pub fn decode(frame: &[u8; FRAME_LEN]) -> Result<Request, Request> {
        let request = Request { address: frame[0], instruction: Instruction::from_bytes(frame[1..8].try_into().unwrap()) };
        if checksum(&frame[..8]) == frame[8] { Ok(request) } else { Err(request) }
    }
}

/// A normal reply: `[host][module][status][opcode][value BE][checksum]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Reply {
    /// The host address the reply goes to.
    pub host: u8,
    /// The address of the module that answers.
    pub module: u8,
    /// The status code ([`Status`]); kept as a byte so that unknown codes
    /// survive.
    pub status: u8,
    /// The instruction number of the request answered.
    pub opcode: u8,
    /// The value (big-endian on the wire).
    pub value: i32,
}

impl Reply {
    /// A reply with a known status.
    pub fn new(host: u8, module: u8, status: Status, opcode: u8, value: i32) -> Self {
        Reply { host, module, status: status.code(), opcode, value }
    }

    /// The status, when TMCL defines its code.
    pub fn status(&self) -> Option<Status> {
        Status::from_code(self.status)
    }

    /// The nine bytes, checksum included.
    pub fn encode(&self) -> [u8; FRAME_LEN] {
        let v = self.value.to_be_bytes();
        let mut f = [self.host, self.module, self.status, self.opcode, v[0], v[1], v[2], v[3], 0];
        f[8] = checksum(&f[..8]);
        f
    }

    /// Decodes a reply; `None` when the checksum is wrong.
    pub fn decode(frame: &[u8; FRAME_LEN]) -> Option<Reply> {
        if checksum(&frame[..8]) != frame[8] {
            return None;
        }
        Some(Reply {
            host: frame[0],
            module: frame[1],
            status: frame[2],
            opcode: frame[3],
            value: i32::from_be_bytes([frame[4], frame[5], frame[6], frame[7]]),
        })
    }
}

/// The special reply of 136 type 0: the host address followed by eight ASCII
/// characters such as `1141V146`, without checksum (docs/behaviour.md rule 8).
pub fn version_string_reply(host: u8, text: &[u8; 8]) -> [u8; FRAME_LEN] {
    let mut f = [host, 0, 0, 0, 0, 0, 0, 0, 0];
    f[1..].copy_from_slice(text);
    f
}

/// The special reply of 134 (read program memory): the module address byte
/// is replaced by the stored instruction (docs/behaviour.md rule 16).
pub fn memory_reply(host: u8, stored: Instruction) -> [u8; FRAME_LEN] {
    let i = stored.to_bytes();
    let mut f = [host, i[0], i[1], i[2], i[3], i[4], i[5], i[6], 0];
    f[8] = checksum(&f[..8]);
    f
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checksum_of_manual_examples() {
        // ROR 0, 1000 and the reply to GIO 0, 1 (manual 3.7.1, 3.7.15).
        assert_eq!(Request::new(1, Instruction::new(1, 0, 0, 1000)).encode(), [0x01, 0x01, 0x00, 0x00, 0x00, 0x00, 0x03, 0xE8, 0xED]);
        let reply = Reply::new(2, 1, Status::Ok, 15, 302);
        assert_eq!(reply.encode(), [0x02, 0x01, 0x64, 0x0F, 0x00, 0x00, 0x01, 0x2E, 0xA5]);
        assert_eq!(Reply::decode(&reply.encode()), Some(reply));
    }

    #[test]
    fn bad_checksum_is_reported_with_fields() {
        let mut f = Request::new(1, Instruction::new(6, 1, 0, 0)).encode();
        f[8] ^= 1;
        let err = Request::decode(&f).unwrap_err();
        assert_eq!(err.address, 1);
        assert_eq!(err.instruction.opcode, 6);
        let mut r = Reply::new(2, 1, Status::Ok, 6, 5).encode();
        r[8] = r[8].wrapping_add(1);
        assert_eq!(Reply::decode(&r), None);
    }

    #[test]
    fn negative_values_are_big_endian_twos_complement() {
        let f = Request::new(1, Instruction::new(4, 1, 0, -10000)).encode();
        assert_eq!(f, [0x01, 0x04, 0x01, 0x00, 0xFF, 0xFF, 0xD8, 0xF0, 0xCC]);
        assert_eq!(Request::decode(&f).unwrap().instruction.value, -10000);
    }
}
