//! The binary program format: 8 bytes per instruction — opcode, type,
//! motor/bank, value (4 bytes, MSB first) and a checksum, the 8-bit sum of
//! the seven bytes before it. It is a TMCL request frame without the
//! address byte, so a host can download it word by word.
//!
//! A program assembled from source ends with a STOP: when its last
//! instruction is not one, the assembler appends [`END_STOP`], as TMCL-IDE
//! does in the binary files it writes (docs/behaviour.md rule 93).

use tmclsim_protocol::{Instruction, checksum, opcode};

/// Bytes per instruction in a binary file.
pub const WORD_LEN: usize = 8;

/// The STOP the assembler appends to a program whose last instruction is
/// not a STOP: type, motor and value 0, in a binary image the word
/// `1C 00 00 00 00 00 00 1C` (docs/behaviour.md rule 93).
pub const END_STOP: Instruction = Instruction::new(opcode::STOP, 0, 0, 0);

/// Whether a program assembled from these instructions gets [`END_STOP`]
/// after them: it is empty, or its last word is not a STOP (opcode 28,
/// whatever its other fields).
pub fn needs_end_stop(instructions: &[Instruction]) -> bool {
    instructions.last().is_none_or(|w| w.opcode != opcode::STOP)
}

/// The binary image of a list of instructions, word for word (a program
/// assembled from source has its STOP already).
pub fn encode(instructions: &[Instruction]) -> Vec<u8> {
    let mut out = Vec::with_capacity(instructions.len() * WORD_LEN);
    for ins in instructions {
        let bytes = ins.to_bytes();
        out.extend_from_slice(&bytes);
        out.push(checksum(&bytes));
    }
    out
}

/// Why a binary image cannot be read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BinaryError {
    /// The length is no multiple of 8 bytes.
    Length(usize),
    /// A word's checksum byte is wrong.
    Checksum {
        /// The word's address.
        address: usize,
        /// The checksum byte stored.
        stored: u8,
        /// The checksum of the word's seven bytes.
        expected: u8,
    },
}

impl std::fmt::Display for BinaryError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            BinaryError::Length(len) => write!(
                f,
                "binary length {len} is not a multiple of {WORD_LEN} bytes ({} trailing byte(s) after address {})",
                len % WORD_LEN,
                len / WORD_LEN
            ),
            BinaryError::Checksum { address, stored, expected } => write!(
                f,
                "bad checksum at address {address} (byte offset {}): stored 0x{stored:02X}, expected 0x{expected:02X}",
                address * WORD_LEN
            ),
        }
    }
}

impl std::error::Error for BinaryError {}

impl From<BinaryError> for String {
    fn from(e: BinaryError) -> String {
        e.to_string()
    }
}

/// Reads a binary image; the length must be a multiple of 8 and every
/// checksum must match.
pub fn decode(bytes: &[u8]) -> Result<Vec<Instruction>, BinaryError> {
    if !bytes.len().is_multiple_of(WORD_LEN) {
        return Err(BinaryError::Length(bytes.len()));
    }
    let mut out = Vec::with_capacity(bytes.len() / WORD_LEN);
    for (address, word) in bytes.chunks_exact(WORD_LEN).enumerate() {
        let mut seven = [0u8; 7];
        seven.copy_from_slice(&word[..7]);
        let expected = checksum(&seven);
        if word[7] != expected {
            return Err(BinaryError::Checksum { address, stored: word[7], expected });
        }
        out.push(Instruction::from_bytes(&seven));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_are_frames_without_address() {
        let bytes = encode(&[Instruction::new(1, 0, 0, 1000), Instruction::new(4, 1, 0, -10000)]);
        assert_eq!(bytes, [0x01, 0x00, 0x00, 0x00, 0x00, 0x03, 0xE8, 0xEC, 0x04, 0x01, 0x00, 0xFF, 0xFF, 0xD8, 0xF0, 0xCB]);
        assert_eq!(decode(&bytes).unwrap()[1].value, -10000);
    }

    #[test]
    fn the_end_stop_is_the_word_tmcl_ide_appends() {
        assert_eq!(encode(&[END_STOP]), [0x1C, 0, 0, 0, 0, 0, 0, 0x1C]);
        assert!(needs_end_stop(&[]));
        assert!(needs_end_stop(&[Instruction::new(opcode::JA, 0, 0, 0)]));
        assert!(!needs_end_stop(&[Instruction::new(opcode::JA, 0, 0, 0), END_STOP]));
        assert!(!needs_end_stop(&[Instruction::new(opcode::STOP, 1, 0, 0)]), "a STOP is a STOP whatever its type");
        assert!(needs_end_stop(&[END_STOP, Instruction::new(opcode::JA, 0, 0, 0)]), "only the last word counts");
    }

    #[test]
    fn errors_name_the_address() {
        let mut bytes = encode(&[Instruction::new(1, 0, 0, 1), Instruction::new(2, 0, 0, 2)]);
        bytes[15] ^= 0xFF;
        let e = decode(&bytes).unwrap_err().to_string();
        assert!(e.starts_with("bad checksum at address 1 (byte offset 8)"), "{e}");
        assert!(decode(&bytes[..13]).unwrap_err().to_string().contains("not a multiple of 8"));
        assert_eq!(decode(&[]).unwrap(), vec![]);
    }
}
