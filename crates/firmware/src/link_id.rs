//! Who sent a frame: each TCP connection, the pty and in-process callers
//! are links of their own (docs/behaviour.md rule 91).

/// A link's number on a bus, given by whoever serves it.
pub type LinkId = u64;

/// The link of in-process callers (the Python package, the browser IDE's
/// commands, tests).
pub const IN_PROCESS: LinkId = 0;
