//! Modules reached over a TMCL link (`tmclsim ide --tcp` / `--port`), real
//! or virtual, polled as a host polls them. TMCL has no breakpoints: with
//! breakpoints set, `run` single-steps the program (130) and reads the
//! program counter (135 type 1) after every step, until it reaches one
//! (docs/behaviour.md rule 86).

use crate::target::{ModuleEntry, Target, TargetError, check};
use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use tmclsim_host::Client;
use tmclsim_host::client::profile_of_version;
use tmclsim_protocol::{FRAME_LEN, Instruction, opcode};

#[derive(Default)]
struct Debug {
    breakpoints: Vec<u16>,
    hit: Option<u16>,
    /// Set to stop the stepping thread, which is joined before anything
    /// else is sent (a late step or hit would land in the next run).
    halt: Option<(Arc<AtomicBool>, std::thread::JoinHandle<()>)>,
}

pub struct LinkTarget {
    client: Mutex<Client>,
    entries: Vec<ModuleEntry>,
    opened: Instant,
    debug: Mutex<HashMap<usize, Debug>>,
    description: String,
}

impl LinkTarget {
    /// Opens the link and asks every address for its firmware (136); an
    /// address that does not answer is an error.
    pub fn open(tcp: Option<&str>, port: Option<&str>, baud: u32, addresses: &[u8], timeout: Duration) -> Result<Arc<LinkTarget>, String> {
        let mut client = Client::open(tcp, port, baud, addresses.first().copied().unwrap_or(1), timeout)?;
        let link = match (tcp, port) {
            (Some(a), _) => format!("tcp {a}"),
            (None, Some(p)) => format!("serial {p}"),
            _ => String::new(),
        };
        let mut entries = Vec::new();
        for &address in addresses {
            client.address = address;
            let text = client
                .exchange(Instruction::new(opcode::FIRMWARE_VERSION, 0, 0, 0))
                .map_err(|e| format!("module {address} on {link}: {e}"))?;
            let firmware = String::from_utf8_lossy(&text[1..]).trim_end_matches('\0').to_string();
            let word = client.request(Instruction::new(opcode::FIRMWARE_VERSION, 1, 0, 0)).map_err(|e| format!("module {address}: {e}"))?;
            entries.push(ModuleEntry { address, profile: profile_of_version(word.value), firmware, link: link.clone() });
        }
        Ok(Arc::new(LinkTarget {
            client: Mutex::new(client),
            entries,
            opened: Instant::now(),
            debug: Mutex::new(HashMap::new()),
            description: link,
        }))
    }

    fn exchange(&self, id: usize, ins: Instruction) -> Result<[u8; FRAME_LEN], TargetError> {
        let address = self.entries.get(id).ok_or(TargetError::NoModule)?.address;
        let mut c = self.client.lock().unwrap_or_else(|p| p.into_inner());
        c.address = address;
        c.exchange(ins).map_err(TargetError::Failed)
    }

    fn with_debug<R>(&self, id: usize, f: impl FnOnce(&mut Debug) -> R) -> R {
        f(self.debug.lock().unwrap_or_else(|p| p.into_inner()).entry(id).or_default())
    }

    /// The run mode and program counter (135 type 1).
    fn counter(&self, id: usize) -> Option<(u32, u16)> {
        let s = self.exchange(id, Instruction::new(opcode::APPLICATION_STATUS, 1, 0, 0)).ok()?;
        let word = u32::from_be_bytes([s[4], s[5], s[6], s[7]]);
        (s[2] >= 100).then_some((word >> 24, (word & 0xFFFF) as u16))
    }

    /// Steps until the program counter stands on a breakpoint, the program
    /// stops, or `halt` is set.
    fn step_to_breakpoint(self: &Arc<Self>, id: usize, halt: Arc<AtomicBool>) {
        let breakpoints = self.breakpoints(id);
        // A WAIT keeps the counter where it is: standing on a breakpoint is
        // a hit only when a step arrived there.
        let mut last = self.counter(id).map(|(_, pc)| pc);
        while !halt.load(Ordering::Relaxed) {
            let Ok(r) = self.exchange(id, Instruction::new(opcode::STEP_APPLICATION, 0, 0, 0)) else { break };
            if r[2] < 100 {
                break;
            }
            let Some((mode, pc)) = self.counter(id) else { break };
            if breakpoints.contains(&pc) && last != Some(pc) {
                self.with_debug(id, |d| {
                    if !halt.load(Ordering::Relaxed) {
                        d.hit = Some(pc);
                    }
                });
                break;
            }
            last = Some(pc);
            if mode == 0 {
                break;
            }
        }
    }
}

impl Target for Arc<LinkTarget> {
    fn kind(&self) -> &'static str {
        "link"
    }

    fn describe(&self) -> String {
        self.description.clone()
    }

    fn modules(&self) -> &[ModuleEntry] {
        &self.entries
    }

    fn request(&self, id: usize, ins: Instruction) -> Result<[u8; FRAME_LEN], TargetError> {
        self.exchange(id, ins)
    }

    fn time(&self, _id: usize) -> f64 {
        self.opened.elapsed().as_secs_f64()
    }

    fn set_breakpoints(&self, id: usize, addresses: &[u16]) -> Result<(), TargetError> {
        self.entries.get(id).ok_or(TargetError::NoModule)?;
        self.with_debug(id, |d| d.breakpoints = addresses.to_vec());
        Ok(())
    }

    fn breakpoints(&self, id: usize) -> Vec<u16> {
        self.with_debug(id, |d| d.breakpoints.clone())
    }

    fn breakpoint_hit(&self, id: usize) -> Option<u16> {
        self.with_debug(id, |d| d.hit)
    }

    fn run(&self, id: usize, start: bool) -> Result<(), TargetError> {
        self.halt(id);
        self.with_debug(id, |d| d.hit = None);
        if self.breakpoints(id).is_empty() {
            let r = self.exchange(id, Instruction::new(opcode::RUN_APPLICATION, u8::from(start), 0, 0))?;
            return check(&r);
        }
        if start {
            // Stopped at address 0 with a fresh stack: the steps begin there.
            check(&self.exchange(id, Instruction::new(opcode::STOP_APPLICATION, 0, 0, 0))?)?;
            check(&self.exchange(id, Instruction::new(opcode::RESET_APPLICATION, 0, 0, 0))?)?;
        }
        let halt = Arc::new(AtomicBool::new(false));
        let (me, flag) = (self.clone(), halt.clone());
        let thread = std::thread::spawn(move || me.step_to_breakpoint(id, flag));
        self.with_debug(id, |d| d.halt = Some((halt, thread)));
        Ok(())
    }

    fn halt(&self, id: usize) {
        if let Some((flag, thread)) = self.with_debug(id, |d| d.halt.take()) {
            flag.store(true, Ordering::Relaxed);
            // Not under the lock: the thread takes it to note a hit.
            if thread.thread().id() != std::thread::current().id() {
                let _ = thread.join();
            }
        }
    }
}
