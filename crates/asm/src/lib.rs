//! TMCL assembler and disassembler.
//!
//! [`assemble`] turns TMCL source (the TMCL-IDE syntax of the Trinamic
//! manuals: labels, constants, expressions, `#include`) into a [`Program`];
//! [`disassemble`] turns instructions back into source that assembles to
//! the same bytes. [`Program::to_binary`] and [`Program::symbol_file`] write
//! the binary image and the label table. With a module [`Profile`], the
//! assembler also checks that the module has every instruction, parameter,
//! motor, bank, port, coordinate and interrupt the program uses.
//!
//! The assembler reads no files: it takes source text, and `#include`s go
//! through an [`IncludeResolver`] ([`MemoryResolver`] for text held in
//! memory; files on disk are read by `tmclsim_server::sources`).
//!
//! The source files, by stage:
//! - `lexer.rs`: comments out, lines into tokens;
//! - `expr.rs`: integer expressions and their parser;
//! - `parser.rs`: a line into labels and a body (instruction, constant,
//!   raw word, include);
//! - `include.rs`: finding `#include`d files (the resolver trait);
//! - `eval.rs`: labels, constants and the values of expressions;
//! - `encoder.rs`: an instruction line into seven bytes;
//! - `check.rs`: checks against a module profile;
//! - `assembler.rs`: the passes that tie these together;
//! - `binary.rs`, `symbol_file.rs`: output formats;
//! - `source_map.rs`: the source line of every instruction;
//! - `disasm.rs`: the disassembler;
//! - `diagnostic.rs`: error messages with file, line and column;
//! - `limits.rs`: how much source is read and how many errors reported.

mod assembler;
pub mod binary;
mod check;
mod diagnostic;
pub mod disasm;
mod encoder;
mod eval;
mod expr;
pub mod include;
mod lexer;
pub mod limits;
mod parser;
pub mod source_map;
pub mod symbol_file;

use std::collections::BTreeMap;

pub use assembler::assemble;
pub use diagnostic::{Diagnostic, render};
pub use disasm::disassemble;
pub use include::{IncludeResolver, IncludedFile, MemoryResolver, NoIncludes};
pub use source_map::{LinePlace, SourceLine};
pub use tmclsim_profile::Profile;
pub use tmclsim_protocol::Instruction;

/// An assembled program.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Program {
    /// One instruction per program memory word, from address 0.
    pub instructions: Vec<Instruction>,
    /// Label → address.
    pub symbols: BTreeMap<String, u32>,
    /// Constant → value (those of included files too).
    pub constants: BTreeMap<String, i64>,
    /// The source of every instruction, same index as `instructions`;
    /// empty for a program read from a binary.
    pub source_map: Vec<SourceLine>,
}

impl Program {
    /// The binary image: 8 bytes per instruction (see [`binary`]).
    pub fn to_binary(&self) -> Vec<u8> {
        binary::encode(&self.instructions)
    }

    /// Reads a binary image (length a multiple of 8, checksums checked).
    pub fn from_binary(bytes: &[u8]) -> Result<Vec<Instruction>, String> {
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

    /// Reads a symbol file written by [`Program::symbol_file`].
    pub fn parse_symbol_file(text: &str) -> Result<BTreeMap<String, u32>, String> {
        symbol_file::parse(text)
    }

    /// Source text for this program, with its own labels.
    pub fn disassemble(&self) -> String {
        disassemble(&self.instructions, Some(&self.symbols))
    }
}
