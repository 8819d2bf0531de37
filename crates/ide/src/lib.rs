//! The browser IDE's requests and answers, without I/O: what the API
//! (crates/web/README.md) does with a [`Target`]'s modules and the JSON it
//! answers. The server (`tmclsim-web`, over HTTP) and the playground
//! (`tmclsim-wasm`, in the page) both answer from here, so the app sees the
//! same JSON from either.
//!
//! A host's words for TMCL are here too, shared with `tmclsim-host`:
//! parameter names ([`names`]), direct-mode lines with names ([`line`]),
//! replies in words ([`reply`]), a program's download with its
//! verification ([`download`]), and what an observer reads off a virtual
//! module ([`observe`]).

pub mod answers;
pub mod download;
pub mod line;
pub mod live;
pub mod names;
pub mod observe;
pub mod profile_json;
pub mod program;
pub mod reply;
pub mod target;

pub use target::{Found, ModuleEntry, Target, TargetError};
