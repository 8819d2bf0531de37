//! Modules reached over a TMCL link (`tmclsim ide --tcp` / `--port`), real
//! or virtual, polled as a host polls them. TMCL has no breakpoints: with
//! breakpoints set, `run` single-steps the program (130) and reads the
//! program counter (135 type 1) after every step, until it reaches one
//! (docs/behaviour.md rule 86).

use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, Weak};
use std::time::{Duration, Instant};
use tmclsim_host::Client;
use tmclsim_host::client::profile_of_version;
use tmclsim_ide::target::{Found, ModuleEntry, Target, TargetError, check};
use tmclsim_protocol::{FRAME_LEN, Instruction, opcode};

#[derive(Default)]
struct Debug {
    breakpoints: Vec<u16>,
    hit: Option<u16>,
    /// Set to stop the stepping thread, which is joined before anything
    /// else is sent (a late step or hit would land in the next run).
    halt: Option<(Arc<AtomicBool>, std::thread::JoinHandle<()>)>,
}

/// The modules on one TMCL link, as the app's target.
pub struct LinkTarget {
    /// The target itself, for the stepping thread of a run with
    /// breakpoints.
    me: Weak<LinkTarget>,
    client: Mutex<Client>,
    entries: Vec<ModuleEntry>,
    opened: Instant,
    debug: Mutex<HashMap<usize, Debug>>,
    description: String,
    missing: Vec<u8>,
    scan_timeout: (usize, Duration),
}

/// Which addresses to look at when the link is opened.
pub enum Probe<'a> {
    /// These addresses; those that do not answer are reported and skipped.
    Addresses(&'a [u8]),
    /// Every address 1…255 ([`LinkTarget::scan`]).
    Scan,
}

/// How a scan asks: on a TCP link a window of addresses at once, then a
/// short wait for their replies; on a serial link one address at a time,
/// waiting for the frames' time at its baud rate.
fn scan_timeout(tcp: bool, baud: u32) -> (usize, Duration) {
    if tcp { (16, Duration::from_millis(25)) } else { (1, Duration::from_millis(20 + 2 * 9 * 10 * 1000 / u64::from(baud.max(1200)))) }
}

impl LinkTarget {
    /// Opens the link and asks the addresses for their firmware (136); an
    /// address that does not answer is left out and named in
    /// [`LinkTarget::missing`]. No module at all is an error.
    pub fn open(tcp: Option<&str>, port: Option<&str>, baud: u32, probe: Probe, timeout: Duration) -> Result<Arc<LinkTarget>, String> {
        let mut client = Client::open(tcp, port, baud, 1, timeout)?;
        let link = match (tcp, port) {
            (Some(a), _) => format!("tcp {a}"),
            (None, Some(p)) => format!("serial {p}"),
            _ => String::new(),
        };
        let (addresses, scanned): (Vec<u8>, bool) = match probe {
            Probe::Addresses(a) => (a.to_vec(), false),
            Probe::Scan => (scan_addresses(&mut client, scan_timeout(tcp.is_some(), baud)), true),
        };
        let mut entries = Vec::new();
        let mut missing = Vec::new();
        for &address in &addresses {
            match identify(&mut client, address) {
                Ok((firmware, profile)) => entries.push(ModuleEntry { address, profile, firmware, link: link.clone() }),
                Err(_) => missing.push(address),
            }
        }
        if entries.is_empty() {
            return Err(if scanned {
                format!("no module on {link} answered 136 at any address 1…255")
            } else {
                let list: Vec<String> = addresses.iter().map(u8::to_string).collect();
                format!("no module on {link} answered at address {}", list.join(", "))
            });
        }
        Ok(Arc::new_cyclic(|me| LinkTarget {
            me: me.clone(),
            client: Mutex::new(client),
            entries,
            missing,
            opened: Instant::now(),
            debug: Mutex::new(HashMap::new()),
            description: link,
            scan_timeout: scan_timeout(tcp.is_some(), baud),
        }))
    }

    /// The addresses asked at opening that did not answer.
    pub fn missing(&self) -> &[u8] {
        &self.missing
    }

    /// Asks every address 1…255 for its type and firmware (136 type 1,
    /// a short wait each, then 136 type 0 for those that answered).
    pub fn scan(&self) -> Vec<Found> {
        let mut c = self.client.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        let addresses = scan_addresses(&mut c, self.scan_timeout);
        addresses
            .into_iter()
            .filter_map(|address| {
                let (firmware, profile) = identify(&mut c, address).ok()?;
                Some(Found { address, firmware, profile: profile.map(|p| p.module.name.clone()) })
            })
            .collect()
    }

    fn exchange(&self, id: usize, ins: Instruction) -> Result<[u8; FRAME_LEN], TargetError> {
        let address = self.entries.get(id).ok_or(TargetError::NoModule)?.address;
        let mut c = self.client.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        c.address = address;
        c.exchange(ins).map_err(|e| TargetError::Failed(e.to_string()))
    }

    fn with_debug<R>(&self, id: usize, f: impl FnOnce(&mut Debug) -> R) -> R {
        f(self.debug.lock().unwrap_or_else(std::sync::PoisonError::into_inner).entry(id).or_default())
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

impl Target for LinkTarget {
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
        let me = self.me.upgrade().ok_or_else(|| TargetError::Failed("the link is closing".into()))?;
        let flag = halt.clone();
        let thread = std::thread::spawn(move || me.step_to_breakpoint(id, flag));
        self.with_debug(id, |d| d.halt = Some((halt, thread)));
        Ok(())
    }

    fn scan(&self) -> Result<Vec<Found>, TargetError> {
        Ok(LinkTarget::scan(self))
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

/// The firmware text (136 type 0) and profile (136 type 1) of `address`.
fn identify(client: &mut Client, address: u8) -> Result<(String, Option<Arc<tmclsim_profile::Profile>>), String> {
    client.address = address;
    let text = client.exchange(Instruction::new(opcode::FIRMWARE_VERSION, 0, 0, 0))?;
    let firmware = String::from_utf8_lossy(&text[1..]).trim_end_matches('\0').to_string();
    let word = client.request(Instruction::new(opcode::FIRMWARE_VERSION, 1, 0, 0))?;
    Ok((firmware, profile_of_version(word.value)))
}

/// The addresses 1…255 that answer 136 type 1: `window` requests at a
/// time, then replies until none came for `each`. A reply names the
/// address it comes from, so one that arrives late is still counted for
/// its module.
fn scan_addresses(client: &mut Client, (window, each): (usize, Duration)) -> Vec<u8> {
    let timeout = client.timeout;
    client.timeout = each;
    let mut found = std::collections::BTreeSet::new();
    let all: Vec<u8> = (1..=255).collect();
    for chunk in all.chunks(window.max(1)) {
        for &address in chunk {
            client.address = address;
            if client.send_only(Instruction::new(opcode::FIRMWARE_VERSION, 1, 0, 0)).is_err() {
                break;
            }
        }
        while let Ok(raw) = client.read_reply() {
            if raw[3] == opcode::FIRMWARE_VERSION && raw[2] >= 100 {
                found.insert(raw[1]);
            }
        }
    }
    client.timeout = timeout;
    found.into_iter().collect()
}
