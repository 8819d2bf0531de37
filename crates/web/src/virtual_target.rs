//! The modules this process serves (`tmclsim serve --web`): requests go
//! through `SharedBus::frame`, the path of a frame from a link, so the app
//! and a host on the link see each other's effects; observations read the
//! model and change nothing (docs/behaviour.md rule 86).

use std::sync::Arc;
use tmclsim_firmware::snapshot::ModuleSnapshot;
use tmclsim_host::SharedBus;
use tmclsim_ide::target::{ModuleEntry, Target, TargetError};
use tmclsim_protocol::{FRAME_LEN, Instruction, Request, opcode};
use tmclsim_server::LinkHandle;
use tmclsim_server::frame_log::{self, Direction};

struct Place {
    bus: Arc<SharedBus>,
    index: usize,
}

/// The virtual modules of the running server's links, as the app's target.
pub struct VirtualTarget {
    entries: Vec<ModuleEntry>,
    places: Vec<Place>,
    description: String,
    /// `serve --log-frames`: the app's commands are logged on link `web`.
    log_frames: bool,
}

impl VirtualTarget {
    /// Every module of every link, in link order, then bus order.
    pub fn new(links: &[LinkHandle]) -> VirtualTarget {
        let mut entries = Vec::new();
        let mut places = Vec::new();
        for link in links {
            let name = link_name(link);
            for index in 0..link.bus.len() {
                let (address, profile, firmware) = link.bus.with_module(index, |m| {
                    let p = m.profile().clone();
                    (m.address(), p.clone(), String::from_utf8_lossy(&p.version_text()).into_owned())
                });
                entries.push(ModuleEntry { address, profile: Some(profile), firmware, link: name.clone() });
                places.push(Place { bus: link.bus.clone(), index });
            }
        }
        let description = match links {
            [one] => link_name(one),
            _ => format!("{} links", links.len()),
        };
        VirtualTarget { entries, places, description, log_frames: false }
    }

    /// Logs each command of the app and its reply as `serve --log-frames`
    /// logs a link's frames (polled reads are not logged).
    pub fn with_frame_log(mut self, on: bool) -> VirtualTarget {
        self.log_frames = on;
        self
    }

    fn place(&self, id: usize) -> Result<&Place, TargetError> {
        self.places.get(id).ok_or(TargetError::NoModule)
    }
}

fn link_name(link: &LinkHandle) -> String {
    let e = &link.endpoints;
    match (&e.tcp, &e.pty, &e.slcan) {
        (Some(a), _, _) => format!("tcp {a}"),
        (None, Some((l, _)), _) => format!("pty {}", l.display()),
        (None, None, Some((l, _))) => format!("slcan {}", l.display()),
        _ => "in process".into(),
    }
}

impl Target for VirtualTarget {
    fn kind(&self) -> &'static str {
        "virtual"
    }

    fn describe(&self) -> String {
        self.description.clone()
    }

    fn speed(&self) -> f64 {
        self.places.first().map_or(1.0, |p| p.bus.with_bus(|b| b.speed().factor()))
    }

    fn fell_behind(&self) -> bool {
        self.places.iter().any(|p| p.bus.fell_behind().0 > 0)
    }

    fn modules(&self) -> &[ModuleEntry] {
        &self.entries
    }

    fn request(&self, id: usize, ins: Instruction) -> Result<[u8; FRAME_LEN], TargetError> {
        let p = self.place(id)?;
        // The module's address now: a program or a host may have changed it.
        let address = p.bus.with_module(p.index, |m| m.address());
        let frame = Request::new(address, ins).encode();
        if self.log_frames {
            frame_log::print_from("web", Direction::In, &frame);
        }
        // Only the addressed module answers (136 type 0 and 134 replies
        // carry text or the stored word where the address would be).
        let reply = p.bus.frame(&frame).into_iter().next();
        if let (true, Some(r)) = (self.log_frames, &reply) {
            frame_log::print_from("web", Direction::Out, r);
        }
        reply.ok_or_else(|| TargetError::Failed("no reply (replies suppressed by GP 255?)".into()))
    }

    fn observe(&self, id: usize, all: &[Instruction]) -> Result<(Vec<[u8; FRAME_LEN]>, f64), TargetError> {
        let p = self.place(id)?;
        let (replies, now) = p.bus.observe(p.index, all);
        let replies = replies
            .into_iter()
            .zip(all)
            .map(|(r, ins)| r.ok_or_else(|| TargetError::Failed(format!("opcode {} is not a read", ins.opcode))))
            .collect::<Result<_, _>>()?;
        Ok((replies, now as f64 * 1e-9))
    }

    fn observes_the_model(&self) -> bool {
        true
    }

    fn blocks(&self) -> bool {
        false
    }

    fn time(&self, id: usize) -> f64 {
        self.place(id).map_or(0.0, |p| p.bus.now_ns() as f64 * 1e-9)
    }

    fn bootloader(&self, id: usize) -> Option<String> {
        let p = self.place(id).ok()?;
        p.bus.with_module(p.index, |m| m.profile().bootloader.as_ref().filter(|_| m.in_bootloader()).map(|b| b.version_text.clone()))
    }

    fn snapshot(&self, id: usize) -> Option<ModuleSnapshot> {
        let p = self.place(id).ok()?;
        Some(p.bus.with_module(p.index, |m| ModuleSnapshot::of(m)))
    }

    fn world(&self, id: usize, line: &str) -> Result<String, TargetError> {
        let p = self.place(id)?;
        let first = line.split_whitespace().next().unwrap_or("");
        let line = if matches!(first, "link" | "help") || first.starts_with('@') {
            line.to_string()
        } else {
            format!("@{} {line}", self.entries[id].address)
        };
        tmclsim_server::control::execute(&p.bus, &line).map_err(|e| TargetError::Failed(e.to_string()))
    }

    fn set_breakpoints(&self, id: usize, addresses: &[u16]) -> Result<(), TargetError> {
        let p = self.place(id)?;
        p.bus.with_module(p.index, |m| m.set_breakpoints(addresses));
        Ok(())
    }

    fn breakpoints(&self, id: usize) -> Vec<u16> {
        self.place(id).map_or(Vec::new(), |p| p.bus.with_module(p.index, |m| m.program().breakpoints.clone()))
    }

    fn breakpoint_hit(&self, id: usize) -> Option<u16> {
        let p = self.place(id).ok()?;
        p.bus.with_module(p.index, |m| m.program().hit_breakpoint)
    }

    fn run(&self, id: usize, start: bool) -> Result<(), TargetError> {
        let kind = u8::from(start);
        let r = self.request(id, Instruction::new(opcode::RUN_APPLICATION, kind, 0, 0))?;
        tmclsim_ide::target::check(&r)
    }
}
