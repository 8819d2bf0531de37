//! The modules of one link (a single module, or several on an RS485-style
//! multi-drop bus), shared by the link's connections and paced by the wall
//! clock or stepped by hand.

use crate::faults::LinkFaults;
use std::path::PathBuf;
use std::sync::Mutex;
use std::time::{Duration, Instant};
use tmclsim_firmware::Module;
use tmclsim_firmware::eeprom::save_atomic;
use tmclsim_protocol::FRAME_LEN;
use tokio::sync::{Notify, mpsc};

/// Where unsolicited frames (138 events) go: the link that spoke last.
type EventSink = mpsc::UnboundedSender<[u8; FRAME_LEN]>;

/// One module on the link, with its EEPROM file.
struct Node {
    module: Module,
    eeprom: Option<PathBuf>,
    saved_generation: u64,
}

struct State {
    nodes: Vec<Node>,
    sink: Option<(u64, EventSink)>,
    /// What the clock task sleeps until (`None`: nothing).
    scheduled: Option<u64>,
}

/// How virtual time passes.
#[derive(Clone, Copy, Debug)]
enum Clock {
    /// Paced by the wall clock: virtual time `origin_ns` at `origin`.
    Wall { origin: Instant, origin_ns: u64 },
    /// Only `SharedModule::advance` moves time (stepped virtual time).
    Stepped,
}

/// Counters of a served link.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    /// Frames (and CAN/ASCII commands) handled.
    pub frames: u64,
    /// Times the clock woke more than a millisecond after something was due.
    pub missed_deadlines: u64,
    /// The latest wake-up, in nanoseconds after its due time.
    pub max_lateness_ns: u64,
}

impl Stats {
    pub fn add(self, o: Stats) -> Stats {
        Stats {
            frames: self.frames + o.frames,
            missed_deadlines: self.missed_deadlines + o.missed_deadlines,
            max_lateness_ns: self.max_lateness_ns.max(o.max_lateness_ns),
        }
    }
}

/// The served module(s) behind a lock, with the clock and EEPROM files.
pub struct SharedModule {
    stats: Mutex<Stats>,
    state: Mutex<State>,
    clock: Mutex<Clock>,
    changed: Notify,
    faults: Mutex<LinkFaults>,
    /// Deliver bytes at the modules' baud rate (GP 65).
    wire_timing: bool,
    /// Some module of the link is in ASCII mode.
    ascii: std::sync::atomic::AtomicBool,
}

/// GP 65 codes → bits per second (TMCM-1141 table 18).
pub fn baud_rate(code: i32) -> u32 {
    match code {
        1 => 14_400,
        2 => 19_200,
        3 => 28_800,
        4 => 38_400,
        5 => 57_600,
        6 => 76_800,
        7 => 115_200,
        8 => 230_400,
        _ => 9_600,
    }
}

impl SharedModule {
    pub fn new(module: Module, eeprom: Option<PathBuf>) -> SharedModule {
        SharedModule::bus(vec![(module, eeprom)], false)
    }

    /// Several modules on one link; each with its own EEPROM file.
    pub fn bus(modules: Vec<(Module, Option<PathBuf>)>, wire_timing: bool) -> SharedModule {
        let origin_ns = modules.iter().map(|(m, _)| m.now_ns()).max().unwrap_or(0);
        let nodes = modules
            .into_iter()
            .map(|(mut module, eeprom)| {
                module.advance_to(origin_ns);
                let saved_generation = module.eeprom_generation();
                Node { module, eeprom, saved_generation }
            })
            .collect();
        let shared = SharedModule {
            stats: Mutex::new(Stats::default()),
            state: Mutex::new(State { nodes, sink: None, scheduled: None }),
            clock: Mutex::new(Clock::Wall { origin: Instant::now(), origin_ns }),
            changed: Notify::new(),
            faults: Mutex::new(LinkFaults::default()),
            wire_timing,
            ascii: std::sync::atomic::AtomicBool::new(false),
        };
        shared.update_ascii(&shared.lock());
        shared
    }

    /// Some module of the link reads text (ASCII mode): bytes go to
    /// [`SharedModule::ascii_byte`] instead of the frame assembler.
    pub fn ascii_active(&self) -> bool {
        self.ascii.load(std::sync::atomic::Ordering::Relaxed)
    }

    fn update_ascii(&self, s: &State) {
        let any = s.nodes.iter().any(|n| n.module.ascii_mode());
        self.ascii.store(any, std::sync::atomic::Ordering::Relaxed);
    }

    /// One byte of text for the modules in ASCII mode; echoes and replies
    /// are appended to `out`.
    pub(crate) fn ascii_byte(&self, byte: u8, out: &mut Vec<u8>) {
        let mut s = self.lock();
        let now = self.now_ns();
        for n in &mut s.nodes {
            n.module.advance_to(now);
            if n.module.ascii_mode() {
                n.module.ascii_byte(byte, out);
            }
        }
        Self::after_change(&mut s);
        self.update_ascii(&s);
    }

    pub fn stats(&self) -> Stats {
        *self.stats.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// The clock woke `late_ns` after a due time.
    pub(crate) fn record_wakeup(&self, late_ns: u64) {
        let mut s = self.stats.lock().unwrap_or_else(|p| p.into_inner());
        if late_ns > 1_000_000 {
            s.missed_deadlines += 1;
        }
        s.max_lateness_ns = s.max_lateness_ns.max(late_ns);
    }

    /// How many modules the link has.
    pub fn len(&self) -> usize {
        self.lock().nodes.len()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// The link faults in force.
    pub fn link_faults(&self) -> LinkFaults {
        *self.faults.lock().unwrap_or_else(|p| p.into_inner())
    }

    pub fn set_link_faults(&self, f: LinkFaults) {
        *self.faults.lock().unwrap_or_else(|p| p.into_inner()) = f;
    }

    /// Passes an outgoing frame through the link faults: `None` drops it;
    /// the duration is an extra delay.
    pub(crate) fn outgoing(&self, frame: [u8; FRAME_LEN]) -> (Option<[u8; FRAME_LEN]>, Duration) {
        let mut f = self.faults.lock().unwrap_or_else(|p| p.into_inner());
        let delay = f.delay;
        (f.apply(frame), delay)
    }

    /// Virtual time now: by the wall clock, or (stepped) 0, which moves
    /// nothing.
    pub fn now_ns(&self) -> u64 {
        match *self.clock.lock().unwrap_or_else(|p| p.into_inner()) {
            Clock::Wall { origin, origin_ns } => origin_ns + origin.elapsed().as_nanos() as u64,
            Clock::Stepped => 0,
        }
    }

    /// The wall-clock instant of a virtual time (`None` in stepped time).
    pub fn instant_of(&self, ns: u64) -> Option<Instant> {
        match *self.clock.lock().unwrap_or_else(|p| p.into_inner()) {
            Clock::Wall { origin, origin_ns } => Some(origin + Duration::from_nanos(ns.saturating_sub(origin_ns))),
            Clock::Stepped => None,
        }
    }

    /// Stepped virtual time (`true`): time stands still between calls of
    /// [`SharedModule::advance`]. `false` goes back to the wall clock from
    /// where the modules are.
    pub fn set_stepped(&self, stepped: bool) {
        if stepped {
            // Bring the modules up to the wall clock before time stops.
            self.tick();
            *self.clock.lock().unwrap_or_else(|p| p.into_inner()) = Clock::Stepped;
        } else {
            let s = self.lock();
            let now = s.nodes.iter().map(|n| n.module.now_ns()).max().unwrap_or(0);
            let mut clock = self.clock.lock().unwrap_or_else(|p| p.into_inner());
            if matches!(*clock, Clock::Stepped) {
                *clock = Clock::Wall { origin: Instant::now(), origin_ns: now };
            }
        }
        self.changed.notify_one();
    }

    pub fn is_stepped(&self) -> bool {
        matches!(*self.clock.lock().unwrap_or_else(|p| p.into_inner()), Clock::Stepped)
    }

    /// Stepped virtual time: moves every module on by `dt_ns` (events go
    /// out on their links as they become due).
    pub fn advance(&self, dt_ns: u64) {
        let mut s = self.lock();
        for n in &mut s.nodes {
            n.module.advance(dt_ns);
        }
        Self::after_change(&mut s);
    }

    /// Runs `f` on the first module, brought up to the current time.
    pub fn with<R>(&self, f: impl FnOnce(&mut Module) -> R) -> R {
        self.with_module(0, f)
    }

    /// Runs `f` on module `index` (in the order given to the server).
    pub fn with_module<R>(&self, index: usize, f: impl FnOnce(&mut Module) -> R) -> R {
        let mut s = self.lock();
        let now = self.now_ns();
        for n in &mut s.nodes {
            n.module.advance_to(now);
        }
        let r = f(&mut s.nodes[index].module);
        Self::after_change(&mut s);
        r
    }

    /// Handles one frame from link `link`, whose events go to `sink`: every
    /// module sees it, the addressed one answers. Returns the replies and
    /// how long to wait before sending them (GP 75 of the module that
    /// answered, and with wire timing the time the bytes take on the wire).
    pub(crate) fn handle(&self, link: u64, sink: &EventSink, frame: &[u8; FRAME_LEN]) -> (Vec<[u8; FRAME_LEN]>, Duration) {
        self.stats.lock().unwrap_or_else(|p| p.into_inner()).frames += 1;
        let mut s = self.lock();
        let now = self.now_ns();
        let mut replies = Vec::new();
        let mut delay = Duration::ZERO;
        for n in &mut s.nodes {
            // Only the addressed module does anything with a frame; the
            // others catch up with time when they are next looked at.
            if !n.module.answers_to(frame[0]) {
                continue;
            }
            n.module.advance_to(now);
            if let Some(r) = n.module.handle_frame(frame) {
                replies.push(r);
                delay = delay.max(Duration::from_nanos(n.module.reply_delay_ns()));
                if self.wire_timing {
                    // Request and reply, 10 bits a byte.
                    let baud = baud_rate(n.module.baud_rate_code()) as u64;
                    delay += Duration::from_nanos(2 * 9 * 10 * 1_000_000_000 / baud);
                }
            }
        }
        self.update_ascii(&s);
        let has_events = s.nodes.iter().any(|n| n.module.has_events());
        if (!replies.is_empty() || has_events) && s.sink.as_ref().is_none_or(|(id, _)| *id != link) {
            s.sink = Some((link, sink.clone()));
        }
        Self::after_change(&mut s);
        // Wake the clock task only when something is due sooner than what
        // it sleeps for.
        let due = s.nodes.iter().filter_map(|n| n.module.next_event_ns()).min();
        let wake = due.is_some_and(|d| s.scheduled.is_none_or(|sch| d < sch));
        drop(s);
        if wake {
            self.changed.notify_one();
        }
        (replies, delay)
    }

    /// Handles a CAN frame: every module sees it, those it is for answer.
    pub(crate) fn handle_can(
        &self,
        link: u64,
        sink: &EventSink,
        frame: &tmclsim_firmware::can::CanFrame,
    ) -> Vec<tmclsim_firmware::can::CanFrame> {
        let mut s = self.lock();
        let now = self.now_ns();
        let mut replies = Vec::new();
        for n in &mut s.nodes {
            n.module.advance_to(now);
            if let Some(r) = n.module.handle_can(frame) {
                replies.push(r);
            }
        }
        if s.sink.as_ref().is_none_or(|(id, _)| *id != link) {
            s.sink = Some((link, sink.clone()));
        }
        Self::after_change(&mut s);
        self.update_ascii(&s);
        drop(s);
        self.changed.notify_one();
        replies
    }

    /// A 138 event (9-byte form) as the CAN frame of the module it is from.
    pub(crate) fn event_as_can(&self, event: &[u8; FRAME_LEN]) -> Option<tmclsim_firmware::can::CanFrame> {
        let s = self.lock();
        s.nodes.iter().find(|n| n.module.answers_to(event[1])).map(|n| n.module.event_as_can(event))
    }

    /// The clock task's next wake-up: what is due, remembered so that
    /// frames know whether to wake it earlier.
    pub(crate) fn schedule(&self) -> Option<u64> {
        let mut s = self.lock();
        let now = self.now_ns();
        for n in &mut s.nodes {
            n.module.advance_to(now);
        }
        Self::after_change(&mut s);
        let due = s.nodes.iter().filter_map(|n| n.module.next_event_ns()).min();
        s.scheduled = due;
        due
    }

    /// Advances to now and dispatches what became due.
    pub(crate) fn tick(&self) {
        let mut s = self.lock();
        let now = self.now_ns();
        for n in &mut s.nodes {
            n.module.advance_to(now);
        }
        Self::after_change(&mut s);
    }

    /// Resolves when a frame changed the modules' plans.
    pub(crate) async fn changed(&self) {
        self.changed.notified().await
    }

    fn after_change(s: &mut State) {
        let State { nodes, sink, .. } = s;
        for n in nodes.iter_mut() {
            if n.module.has_events() {
                let events = n.module.take_events();
                if let Some((_, sink)) = sink {
                    for e in events {
                        let _ = sink.send(e);
                    }
                }
            }
            if n.module.eeprom_generation() != n.saved_generation {
                if let Some(path) = &n.eeprom
                    && let Err(e) = save_atomic(path, n.module.eeprom())
                {
                    eprintln!("tmclsim: cannot write EEPROM file {}: {e}", path.display());
                }
                n.saved_generation = n.module.eeprom_generation();
            }
        }
    }
}
