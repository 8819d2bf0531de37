//! TMCL assembler and disassembler.
//!
//! [`assemble`] turns TMCL source (the TMCL-IDE syntax of the Trinamic
//! manuals: labels, constants, expressions, `#include`) into a [`Program`];
//! [`disassemble`] turns instructions back into source that assembles to
//! the same bytes. [`Program::to_binary`] and [`Program::symbol_file`] write
//! the binary image and the label table. As in the binary TMCL-IDE writes,
//! a program that does not end in STOP gets one after its last instruction
//! ([`binary::END_STOP`], docs/behaviour.md rule 93). With a module [`Profile`], the
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
//! - `program.rs`: the assembled program and what it gives;
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
mod program;
pub mod source_map;
pub mod symbol_file;

pub use assembler::assemble;
pub use diagnostic::{Diagnostic, render};
pub use disasm::disassemble;
pub use include::{IncludeError, IncludeResolver, IncludedFile, MemoryResolver, NoIncludes};
pub use program::Program;
pub use source_map::{LinePlace, SourceLine};
pub use tmclsim_profile::Profile;
pub use tmclsim_protocol::Instruction;
