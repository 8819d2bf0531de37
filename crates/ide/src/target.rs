//! What the app talks to: a list of modules that answer TMCL requests.
//! Virtual targets (modules this process serves) add what only a
//! simulator can give: the world, breakpoints in the firmware, flags and
//! stack depth, virtual time.

use std::sync::Arc;
use tmclsim_firmware::snapshot::ModuleSnapshot;
use tmclsim_profile::Profile;
use tmclsim_protocol::{FRAME_LEN, Instruction};

/// One module of a target, as the module list shows it.
#[derive(Clone)]
pub struct ModuleEntry {
    /// Its TMCL module address.
    pub address: u8,
    /// The profile of the type the module reports (136 type 1), if any.
    pub profile: Option<Arc<Profile>>,
    /// The 136 type 0 answer, e.g. `1141V146`.
    pub firmware: String,
    /// The link it is reached on, e.g. `tcp 127.0.0.1:1141`.
    pub link: String,
}

/// A module that answered a scan.
#[derive(Clone, Debug)]
pub struct Found {
    /// The address that answered.
    pub address: u8,
    /// Its 136 type 0 answer, e.g. `1141V146`.
    pub firmware: String,
    /// The profile's name, if the module's type has one.
    pub profile: Option<String>,
}

/// Why a target cannot do something.
#[derive(Debug)]
pub enum TargetError {
    /// No such module id.
    NoModule,
    /// The target cannot do this at all (the world of a real module).
    Unsupported(String),
    /// The request failed (no reply, a link error).
    Failed(String),
}

impl std::fmt::Display for TargetError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TargetError::NoModule => write!(f, "no such module"),
            TargetError::Unsupported(s) | TargetError::Failed(s) => write!(f, "{s}"),
        }
    }
}

/// Modules the app works with: those this process simulates, or real
/// (or served) modules on a TMCL link.
pub trait Target: Send + Sync + 'static {
    /// `virtual` or `link`.
    fn kind(&self) -> &'static str;
    /// Where the modules are, in words.
    fn describe(&self) -> String;
    /// The modules, by id (their index).
    fn modules(&self) -> &[ModuleEntry];
    /// One TMCL request to module `id` through the same request path as a
    /// frame from a link; the raw reply.
    fn request(&self, id: usize, ins: Instruction) -> Result<[u8; FRAME_LEN], TargetError>;
    /// An observer's reads of module `id` (the live stream's samples, the
    /// parameter grid, the program's state): they must not change the
    /// module (docs/behaviour.md rule 86). On a link they are TMCL
    /// requests, which the app sends only while it does not download
    /// ([`Target::observes_the_model`] is false); a virtual module answers
    /// them from its model. The replies and the module's clock after them.
    fn observe(&self, id: usize, all: &[Instruction]) -> Result<(Vec<[u8; FRAME_LEN]>, f64), TargetError> {
        let replies = all.iter().map(|ins| self.request(id, *ins)).collect::<Result<_, _>>()?;
        Ok((replies, self.time(id)))
    }
    /// [`Target::observe`] reads the model and never reaches the module's
    /// request path, so observing is safe even during a download.
    fn observes_the_model(&self) -> bool {
        false
    }
    /// Requests wait on a link (run them off the async threads), or are
    /// answered in process within microseconds.
    fn blocks(&self) -> bool {
        true
    }
    /// The module's clock in seconds: virtual time, or wall time since the
    /// target was opened.
    fn time(&self, id: usize) -> f64;
    /// How many times as fast as the wall clock the modules' virtual time
    /// runs (`serve --speed`); 1 on a link to real modules.
    fn speed(&self) -> f64 {
        1.0
    }
    /// Virtual time has fallen behind the speed at least once: the
    /// modules could not compute it as fast (docs/behaviour.md rule 119);
    /// never on a link to real modules.
    fn fell_behind(&self) -> bool {
        false
    }
    /// A typed picture of a virtual module.
    fn snapshot(&self, _id: usize) -> Option<ModuleSnapshot> {
        None
    }
    /// One line of the control protocol (docs/world.md) for module `id`.
    fn world(&self, _id: usize, _line: &str) -> Result<String, TargetError> {
        Err(TargetError::Unsupported("the world exists only around virtual modules".into()))
    }
    /// Sets the program's breakpoints; the firmware stops on them (virtual)
    /// or the target emulates them by single steps (link).
    fn set_breakpoints(&self, id: usize, addresses: &[u16]) -> Result<(), TargetError>;
    /// The program's breakpoints.
    fn breakpoints(&self, id: usize) -> Vec<u16>;
    /// The breakpoint the program stands on, if it stopped at one.
    fn breakpoint_hit(&self, id: usize) -> Option<u16>;
    /// Starts the program at address 0, or continues it (`start` false),
    /// honouring the breakpoints.
    fn run(&self, id: usize, start: bool) -> Result<(), TargetError>;
    /// Stops a run that the target drives itself (breakpoints by steps).
    fn halt(&self, _id: usize) {}
    /// The bootloader's version text while module `id` runs its bootloader
    /// instead of its firmware (a firmware update did not complete,
    /// docs/behaviour.md rule 100): on a link, a module whose 136 answer
    /// has the bootloader's `B` in it.
    fn bootloader(&self, id: usize) -> Option<String> {
        self.modules().get(id).filter(|m| m.firmware.to_ascii_uppercase().contains('B')).map(|m| m.firmware.clone())
    }
    /// Every module that answers on the link (136 at addresses 1…255).
    fn scan(&self) -> Result<Vec<Found>, TargetError> {
        Err(TargetError::Unsupported("a scan looks for modules on a TMCL link; virtual modules are all in the module list".into()))
    }
}

/// An error status in a reply as a failure.
pub fn check(reply: &[u8; FRAME_LEN]) -> Result<(), TargetError> {
    match reply[2] {
        s if s >= 100 => Ok(()),
        s => Err(TargetError::Failed(format!("the module answered status {s} ({})", tmclsim_protocol::Status::text(s)))),
    }
}
