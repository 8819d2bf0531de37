//! The assembler's limits: how much source it reads and how many errors it
//! reports (docs/robustness.md lists them with what a user sees).

/// Bytes of one source file (a module's whole program memory in source
/// with comments is a few hundred KiB at most), for whoever reads source
/// files (`tmclsim_server::sources::read_source`).
pub const MAX_SOURCE_BYTES: u64 = 2 << 20;
/// Bytes of all the source one assembly reads, includes counted.
pub const MAX_TOTAL_SOURCE_BYTES: usize = 4 << 20;
/// Bytes of one source line; a longer line is an error and not parsed.
pub const MAX_LINE_BYTES: usize = 4096;
/// Statements (lines with a label, an instruction, a constant or an
/// include) of one assembly: twenty times the largest program memory.
pub const MAX_STATEMENTS: usize = 100_000;
/// Errors reported by one assembly; the rest are counted in a last line.
pub const MAX_ERRORS: usize = 100;
/// Work the "did you mean" suggestions of one assembly may take, in cells
/// of the edit distance tables they fill
/// (`tmclsim_protocol::suggest::closest_within`): about a tenth of a
/// second. A hundred typos in a program of a few thousand names take a
/// small part of it; once it is spent, errors come without suggestion.
pub const MAX_SUGGESTION_WORK: u64 = 20_000_000;
