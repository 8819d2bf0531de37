//! An assembled program: its words, labels, constants and source map, and
//! the files it is written as.

use crate::binary::{self, BinaryError};
use crate::disasm::disassemble;
use crate::source_map::SourceLine;
use crate::symbol_file::{self, SymbolFileError};
use std::collections::BTreeMap;
use tmclsim_protocol::Instruction;

/// An assembled program.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Program {
    /// One instruction per program memory word, from address 0. Assembled
    /// from source, the program ends with a STOP: the assembler appends one
    /// when the source's last instruction is not a STOP (`appended_stop`,
    /// docs/behaviour.md rule 93).
    pub instructions: Vec<Instruction>,
    /// Label → address.
    pub symbols: BTreeMap<String, u32>,
    /// Constant → value (those of included files too).
    pub constants: BTreeMap<String, i64>,
    /// The source of every instruction, same index as `instructions`;
    /// the appended STOP has none (it comes from no line), and a program
    /// read from a binary has none at all.
    pub source_map: Vec<SourceLine>,
    /// The last instruction is the STOP the assembler appended after the
    /// source's last instruction ([`binary::END_STOP`]).
    pub appended_stop: bool,
}

impl Program {
    /// The binary image: 8 bytes per instruction (see [`binary`]), the
    /// appended STOP included: the file TMCL-IDE writes for the same source.
    pub fn to_binary(&self) -> Vec<u8> {
        binary::encode(&self.instructions)
    }

    /// Reads a binary image (length a multiple of 8, checksums checked).
    pub fn from_binary(bytes: &[u8]) -> Result<Vec<Instruction>, BinaryError> {
        binary::decode(bytes)
    }

    /// The symbol file: `label address` per line, sorted by address, then
    /// the source map.
    pub fn symbol_file(&self) -> String {
        symbol_file::write(&self.symbols, &self.source_map)
    }

    /// The source line of the instruction at `address`, if known.
    pub fn source_of(&self, address: u32) -> Option<&SourceLine> {
        self.source_map.get(address as usize)
    }

    /// The address of the STOP the assembler appended, if it did.
    pub fn appended_stop_address(&self) -> Option<u32> {
        self.appended_stop.then(|| self.instructions.len().saturating_sub(1) as u32)
    }

    /// Reads a symbol file written by [`Program::symbol_file`].
    pub fn parse_symbol_file(text: &str) -> Result<BTreeMap<String, u32>, SymbolFileError> {
        symbol_file::parse(text)
    }

    /// Source text for this program, with its own labels.
    pub fn disassemble(&self) -> String {
        disassemble(&self.instructions, Some(&self.symbols))
    }
}
