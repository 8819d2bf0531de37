//! TMCL wire protocol: frames, replies, checksums, status codes, opcodes and
//! the typed commands they decode into.
//!
//! Nothing here does I/O or allocates on the hot path: a frame is a `[u8; 9]`,
//! a command is a plain enum. The per-link codecs (`serial` for the 9-byte
//! RS485/USB/TCP framing) live beside the frame types so that every link
//! shares one definition of a TMCL instruction.

pub mod command;
pub mod frame;
pub mod mnemonic;
pub mod opcode;
pub mod preamble;
pub mod serial;
pub mod slcan;
pub mod status;
pub mod suggest;

pub use command::{CalcOp, Command, Condition, DecodeError, ErrorFlag, MoveMode, RfsAction, WaitCondition};
pub use frame::{FRAME_LEN, Instruction, Reply, Request, checksum};
pub use status::Status;
