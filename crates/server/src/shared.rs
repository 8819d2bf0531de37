//! A [`Bus`] shared by the connections of a link, its clock task, its
//! control socket and any in-process user (the Python package): the bus
//! behind a lock, plus what only a server has — EEPROM files, the link
//! that receives events, link faults and counters.

use crate::faults::LinkFaults;
use std::path::PathBuf;
use std::sync::Mutex;
use std::time::{Duration, Instant};
use tmclsim_firmware::can::CanFrame;
use tmclsim_firmware::eeprom::save_atomic;
use tmclsim_firmware::world_command::WorldCommand;
use tmclsim_firmware::{Bus, Module};
use tmclsim_protocol::FRAME_LEN;
use tokio::sync::{Notify, mpsc};

/// Where unsolicited frames (138 events) go: the link that spoke last.
type EventSink = mpsc::UnboundedSender<[u8; FRAME_LEN]>;

/// Events kept for an in-process reader while no link has spoken.
const UNCLAIMED_EVENTS: usize = 1024;

struct State {
    bus: Bus,
    /// EEPROM file of each module.
    eeproms: Vec<Option<PathBuf>>,
    sink: Option<(u64, EventSink)>,
    /// Events no link has claimed yet, by module index.
    unclaimed: Vec<(usize, [u8; FRAME_LEN])>,
    /// What the clock task sleeps until (`None`: nothing).
    scheduled: Option<u64>,
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
    /// Times the clock task woke for something due.
    pub wakeups: u64,
}

impl Stats {
    pub fn merged(self, o: Stats) -> Stats {
        Stats {
            frames: self.frames + o.frames,
            missed_deadlines: self.missed_deadlines + o.missed_deadlines,
            max_lateness_ns: self.max_lateness_ns.max(o.max_lateness_ns),
            wakeups: self.wakeups + o.wakeups,
        }
    }
}

/// The bus of a link, shared.
pub struct SharedBus {
    stats: Mutex<Stats>,
    state: Mutex<State>,
    changed: Notify,
    faults: Mutex<LinkFaults>,
    /// Some module of the link is in ASCII mode.
    ascii: std::sync::atomic::AtomicBool,
}

impl SharedBus {
    /// A bus with each module's EEPROM file (`eeproms` shorter than the
    /// bus: no file for the rest).
    pub fn new(bus: Bus, mut eeproms: Vec<Option<PathBuf>>) -> SharedBus {
        eeproms.resize(bus.len(), None);
        let shared = SharedBus {
            stats: Mutex::new(Stats::default()),
            state: Mutex::new(State { bus, eeproms, sink: None, unclaimed: Vec::new(), scheduled: None }),
            changed: Notify::new(),
            faults: Mutex::new(LinkFaults::default()),
            ascii: std::sync::atomic::AtomicBool::new(false),
        };
        shared.update_ascii(&shared.lock());
        shared
    }

    /// Modules with their EEPROM files on one link, in wall-clock time.
    pub fn wall(modules: Vec<(Module, Option<PathBuf>)>, wire_timing: bool) -> SharedBus {
        let (modules, eeproms): (Vec<Module>, Vec<Option<PathBuf>>) = modules.into_iter().unzip();
        let mut bus = Bus::new(modules);
        bus.set_wire_timing(wire_timing);
        bus.set_stepped(false);
        SharedBus::new(bus, eeproms)
    }

    /// Some module of the link reads text (ASCII mode): bytes go to
    /// [`SharedBus::ascii_byte`] instead of the frame assembler.
    pub fn ascii_active(&self) -> bool {
        self.ascii.load(std::sync::atomic::Ordering::Relaxed)
    }

    fn update_ascii(&self, s: &State) {
        self.ascii.store(s.bus.ascii_active(), std::sync::atomic::Ordering::Relaxed);
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(|p| p.into_inner())
    }

    pub fn stats(&self) -> Stats {
        *self.stats.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// The clock woke `late_ns` after a due time.
    pub(crate) fn record_wakeup(&self, late_ns: u64) {
        let mut s = self.stats.lock().unwrap_or_else(|p| p.into_inner());
        s.wakeups += 1;
        if late_ns > 1_000_000 {
            s.missed_deadlines += 1;
        }
        s.max_lateness_ns = s.max_lateness_ns.max(late_ns);
    }

    /// How many modules the link has.
    pub fn len(&self) -> usize {
        self.lock().bus.len()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
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

    /// Virtual time now, by the bus's clock.
    pub fn now_ns(&self) -> u64 {
        self.lock().bus.now_ns()
    }

    /// The wall-clock instant of a virtual time (`None` in stepped time).
    pub fn instant_of(&self, ns: u64) -> Option<Instant> {
        self.lock().bus.clock().instant_of(ns)
    }

    /// Stepped virtual time (`true`): time stands still between calls of
    /// [`SharedBus::advance`]. `false` goes back to the wall clock from
    /// where the modules are.
    pub fn set_stepped(&self, stepped: bool) {
        self.with_bus(|bus| bus.set_stepped(stepped));
        self.changed.notify_one();
    }

    pub fn is_stepped(&self) -> bool {
        self.lock().bus.clock().is_stepped()
    }

    /// Moves every module on by `dt_ns` (events go out on their links as
    /// they become due).
    pub fn advance(&self, dt_ns: u64) {
        self.with_bus(|bus| bus.advance(dt_ns));
        self.changed.notify_one();
    }

    /// Runs `f` on the bus, brought up to the clock's now; then carries out
    /// what changed (EEPROM files, events) and wakes the clock task.
    pub fn with_bus<R>(&self, f: impl FnOnce(&mut Bus) -> R) -> R {
        let mut s = self.lock();
        s.bus.catch_up();
        let r = f(&mut s.bus);
        Self::after_change(&mut s);
        self.update_ascii(&s);
        drop(s);
        self.changed.notify_one();
        r
    }

    /// Runs `f` on module `index` (in bus order), brought up to now.
    pub fn with_module<R>(&self, index: usize, f: impl FnOnce(&mut Module) -> R) -> R {
        self.with_bus(|bus| f(bus.module_mut(index)))
    }

    /// Runs `f` on the first module.
    pub fn with<R>(&self, f: impl FnOnce(&mut Module) -> R) -> R {
        self.with_module(0, f)
    }

    /// Applies a world command to the module at `address` (`None`: the
    /// first one).
    pub fn apply_world(&self, address: Option<u8>, command: &WorldCommand) -> Result<String, String> {
        self.with_bus(|bus| bus.apply_world(address, command))
    }

    /// Takes the modules out (the bus is left empty), e.g. to put them on
    /// another bus.
    pub fn take_modules(&self) -> Vec<Module> {
        let mut s = self.lock();
        s.bus.catch_up();
        Self::after_change(&mut s);
        s.eeproms.clear();
        std::mem::replace(&mut s.bus, Bus::new(Vec::new())).into_modules()
    }

    /// Events of module `index` that no link received (an in-process user
    /// reads them here).
    pub fn take_unclaimed_events(&self, index: usize) -> Vec<[u8; FRAME_LEN]> {
        let mut s = self.lock();
        let (mine, rest) = std::mem::take(&mut s.unclaimed).into_iter().partition(|(i, _)| *i == index);
        s.unclaimed = rest;
        mine.into_iter().map(|(_, e)| e).collect()
    }

    /// Handles one frame from link `link`, whose events go to `sink`.
    /// Returns the replies and how long to wait before sending them.
    pub(crate) fn handle(&self, link: u64, sink: &EventSink, frame: &[u8; FRAME_LEN]) -> (Vec<[u8; FRAME_LEN]>, Duration) {
        self.stats.lock().unwrap_or_else(|p| p.into_inner()).frames += 1;
        let mut s = self.lock();
        let answer = s.bus.handle_frame(frame);
        self.after_request(s, link, sink, !answer.replies.is_empty());
        (answer.replies, Duration::from_nanos(answer.delay_ns))
    }

    /// Handles a CAN frame: every module sees it, those it is for answer.
    pub(crate) fn handle_can(&self, link: u64, sink: &EventSink, frame: &CanFrame) -> Vec<CanFrame> {
        self.stats.lock().unwrap_or_else(|p| p.into_inner()).frames += 1;
        let mut s = self.lock();
        let replies = s.bus.handle_can(frame);
        self.after_request(s, link, sink, true);
        replies
    }

    /// One byte of text for the modules in ASCII mode from a link whose
    /// lines are `lines`; echoes and replies are appended to `out`.
    pub(crate) fn ascii_byte(&self, lines: &mut tmclsim_firmware::ascii::LineState, byte: u8, out: &mut Vec<u8>) {
        let mut s = self.lock();
        s.bus.ascii_byte(lines, byte, out);
        Self::after_change(&mut s);
        self.update_ascii(&s);
    }

    /// After a request from `link`: that link receives events from now on
    /// (if it got an answer or events are waiting), effects are carried
    /// out, and the clock task is woken if something is due sooner than it
    /// sleeps for.
    fn after_request(&self, mut s: std::sync::MutexGuard<'_, State>, link: u64, sink: &EventSink, answered: bool) {
        self.update_ascii(&s);
        let has_events = s.bus.modules().iter().any(Module::has_events);
        if (answered || has_events) && s.sink.as_ref().is_none_or(|(id, _)| *id != link) {
            s.sink = Some((link, sink.clone()));
        }
        Self::after_change(&mut s);
        let due = s.bus.next_deadline();
        let wake = due.is_some_and(|d| s.scheduled.is_none_or(|sch| d < sch));
        drop(s);
        if wake {
            self.changed.notify_one();
        }
    }

    /// A 138 event (9-byte form) as the CAN frame of the module it is from.
    pub(crate) fn event_as_can(&self, event: &[u8; FRAME_LEN]) -> Option<CanFrame> {
        let s = self.lock();
        s.bus.index_of(event[1]).map(|i| s.bus.event_as_can(i, event))
    }

    /// The clock task: brings the bus to now, carries out what became due
    /// and returns the next deadline, remembered so that requests know
    /// whether to wake the task earlier.
    pub(crate) fn tick(&self) -> Option<u64> {
        let mut s = self.lock();
        s.bus.catch_up();
        Self::after_change(&mut s);
        let due = s.bus.next_deadline();
        s.scheduled = due;
        due
    }

    /// Resolves when something changed the bus's plans.
    pub(crate) async fn changed(&self) {
        self.changed.notified().await
    }

    fn after_change(s: &mut State) {
        let effects = s.bus.take_effects();
        for (index, event) in effects.events {
            match &s.sink {
                Some((_, sink)) => {
                    let _ = sink.send(event);
                }
                None if s.unclaimed.len() < UNCLAIMED_EVENTS => s.unclaimed.push((index, event)),
                None => {}
            }
        }
        for index in effects.eeprom_written {
            if let Some(path) = &s.eeproms[index]
                && let Err(e) = save_atomic(path, s.bus.module(index).eeprom())
            {
                eprintln!("tmclsim: cannot write EEPROM file {}: {e}", path.display());
            }
        }
    }
}
