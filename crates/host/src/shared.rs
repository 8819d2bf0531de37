//! A [`Bus`] shared by everyone who drives it: the Python package's
//! modules in process, and while they are served, the connections of a
//! link, its clock task and its control socket. The bus behind a lock,
//! with the EEPROM files of its modules (a write a file does not take is
//! answered with status 5, docs/behaviour.md rule 82), the events no link
//! has received yet, and what a served link adds: the link that receives
//! events, link faults and counters. No I/O but the EEPROM files and no
//! async runtime: a server wakes its clock task through
//! [`SharedBus::set_waker`].

use crate::eeprom_file::EepromFile;
use crate::eeprom_files::EepromFiles;
use crate::faults::LinkFaults;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use tmclsim_firmware::can::CanFrame;
use tmclsim_firmware::world_command::{Addressed, HELP, WorldCommand, on_off};
use tmclsim_firmware::{Bus, Module, Speed, WorldError};
use tmclsim_protocol::{FRAME_LEN, Instruction, Reply, Status};

/// Where unsolicited frames (138 events) go: the link that spoke last.
pub type EventSink = Arc<dyn Fn([u8; FRAME_LEN]) + Send + Sync>;

/// What wakes a server's clock task when the bus's plans changed.
type Waker = Arc<dyn Fn() + Send + Sync>;

/// Events kept for an in-process reader while no link has spoken.
const UNCLAIMED_EVENTS: usize = 1024;

struct State {
    bus: Bus,
    /// EEPROM file of each module, held (locked) while the bus has it.
    eeproms: EepromFiles,
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
    /// The counts of two buses together: sums, and the larger of the maxima.
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
    waker: Mutex<Option<Waker>>,
    faults: Mutex<LinkFaults>,
    /// Some module of the link is in ASCII mode.
    ascii: std::sync::atomic::AtomicBool,
}

impl SharedBus {
    /// A bus with each module's EEPROM file (`eeproms` shorter than the
    /// bus: no file for the rest). A module's EEPROM image is taken to be
    /// what its file holds.
    pub fn new(bus: Bus, eeproms: Vec<Option<Arc<EepromFile>>>) -> SharedBus {
        let eeproms = EepromFiles::new(&bus, eeproms, true);
        let shared = SharedBus {
            stats: Mutex::new(Stats::default()),
            state: Mutex::new(State { bus, eeproms, sink: None, unclaimed: Vec::new(), scheduled: None }),
            waker: Mutex::new(None),
            faults: Mutex::new(LinkFaults::default()),
            ascii: std::sync::atomic::AtomicBool::new(false),
        };
        shared.update_ascii(&shared.lock());
        shared
    }

    /// Modules with their EEPROM files on one link, in wall-clock time
    /// running `speed` times as fast.
    pub fn wall(modules: Vec<(Module, Option<Arc<EepromFile>>)>, wire_timing: bool, speed: Speed) -> SharedBus {
        let (modules, eeproms): (Vec<Module>, Vec<Option<Arc<EepromFile>>>) = modules.into_iter().unzip();
        let mut bus = Bus::new(modules);
        bus.set_wire_timing(wire_timing);
        bus.set_speed(speed);
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
        self.state.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// How often virtual time fell behind the clock's speed
    /// ([`Bus::fell_behind`]), and the speed; a look that changes nothing
    /// and wakes nobody.
    pub fn fell_behind(&self) -> (u64, f64) {
        let s = self.lock();
        (s.bus.fell_behind(), s.bus.speed().factor())
    }

    /// The counters of this bus's clock and frames so far.
    pub fn stats(&self) -> Stats {
        *self.stats.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// `wake` is called whenever something changed the bus's plans (a
    /// request, an advance, the clock switched): a server's clock task
    /// waits for it. It replaces the one set before.
    pub fn set_waker(&self, wake: impl Fn() + Send + Sync + 'static) {
        *self.waker.lock().unwrap_or_else(std::sync::PoisonError::into_inner) = Some(Arc::new(wake));
    }

    fn wake(&self) {
        let waker = self.waker.lock().unwrap_or_else(std::sync::PoisonError::into_inner).clone();
        if let Some(wake) = waker {
            wake();
        }
    }

    /// The clock woke `late_ns` after a due time.
    pub fn record_wakeup(&self, late_ns: u64) {
        let mut s = self.stats.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
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

    /// No module on the link.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The link faults in force.
    pub fn link_faults(&self) -> LinkFaults {
        *self.faults.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// Replaces the link faults in force.
    pub fn set_link_faults(&self, f: LinkFaults) {
        *self.faults.lock().unwrap_or_else(std::sync::PoisonError::into_inner) = f;
    }

    /// Passes an outgoing frame through the link faults: `None` drops it;
    /// the duration is an extra delay.
    pub fn outgoing(&self, frame: [u8; FRAME_LEN]) -> (Option<[u8; FRAME_LEN]>, Duration) {
        let mut f = self.faults.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
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
        self.wake();
    }

    /// Whether time stands still between calls of [`SharedBus::advance`].
    pub fn is_stepped(&self) -> bool {
        self.lock().bus.clock().is_stepped()
    }

    /// Moves every module on by `dt_ns` (events go out on their links as
    /// they become due).
    pub fn advance(&self, dt_ns: u64) {
        self.with_bus(|bus| bus.advance(dt_ns));
        self.wake();
    }

    /// Runs `f` on the bus, brought up to the clock's now; then carries out
    /// what changed (EEPROM files, events) and wakes the clock task.
    pub fn with_bus<R>(&self, f: impl FnOnce(&mut Bus) -> R) -> R {
        self.with_bus_saved(f).0
    }

    /// As [`SharedBus::with_bus`], and says whether an EEPROM write that
    /// `f` made could not be saved to its file: the module's EEPROM is then
    /// back to what the file holds (docs/behaviour.md rule 82).
    pub fn with_bus_saved<R>(&self, f: impl FnOnce(&mut Bus) -> R) -> (R, bool) {
        let mut s = self.lock();
        let before = Self::generations(&mut s, Bus::catch_up);
        let r = f(&mut s.bus);
        let written = Self::written_since(&s, before);
        let failed = Self::after_change(&mut s);
        self.update_ascii(&s);
        drop(s);
        self.wake();
        (r, written.iter().any(|i| failed.contains(i)))
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
    pub fn apply_world(&self, address: Option<u8>, command: &WorldCommand) -> Result<String, WorldError> {
        self.with_bus(|bus| bus.apply_world(address, command))
    }

    /// Takes the modules out (the bus is left empty), e.g. to put them on
    /// another bus.
    pub fn take_modules(&self) -> Vec<Module> {
        let mut s = self.lock();
        s.bus.catch_up();
        Self::after_change(&mut s);
        let bus = std::mem::replace(&mut s.bus, Bus::new(Vec::new()));
        s.eeproms = EepromFiles::new(&s.bus, Vec::new(), true);
        bus.into_modules()
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
    pub fn handle(&self, link: u64, sink: &EventSink, frame: &[u8; FRAME_LEN]) -> (Vec<[u8; FRAME_LEN]>, Duration) {
        self.stats.lock().unwrap_or_else(std::sync::PoisonError::into_inner).frames += 1;
        let mut s = self.lock();
        // The addressed modules first catch up on their own, so that what
        // their programs store is not taken for the request's.
        let before = Self::generations(&mut s, |bus| bus.catch_up_addressed(frame[0]));
        let mut answer = s.bus.handle_frame_from(link, frame);
        // A reply's delay is the modules' time (GP 75, the wire): on the
        // wall clock it is as much shorter as the clock runs faster.
        let delay = s.bus.clock().wall_duration(answer.delay_ns);
        let written = Self::written_since(&s, before);
        let failed = self.after_request(s, link, sink, !answer.replies.is_empty());
        if written.iter().any(|i| failed.contains(i)) {
            for r in &mut answer.replies {
                *r = Self::not_stored(*r, frame[1]);
            }
        }
        (answer.replies, delay)
    }

    /// Handles a CAN frame: every module sees it, those it is for answer.
    pub fn handle_can(&self, link: u64, sink: &EventSink, frame: &CanFrame) -> Vec<CanFrame> {
        self.stats.lock().unwrap_or_else(std::sync::PoisonError::into_inner).frames += 1;
        let mut s = self.lock();
        let before = Self::generations(&mut s, Bus::catch_up);
        let mut replies = s.bus.handle_can(frame);
        let written = Self::written_since(&s, before);
        let failed = self.after_request(s, link, sink, true);
        if written.iter().any(|i| failed.contains(i)) {
            // `[module address][status][opcode][value]`: a 9-byte reply
            // without host byte and checksum.
            for r in replies.iter_mut().filter(|r| r.len == 7) {
                let mut nine = [0u8; FRAME_LEN];
                nine[1..8].copy_from_slice(&r.data[..7]);
                nine[8] = tmclsim_protocol::frame::checksum(&nine[..8]);
                r.data[..7].copy_from_slice(&Self::not_stored(nine, frame.data[0])[1..8]);
            }
        }
        replies
    }

    /// Puts one frame on the bus from in process and returns the replies
    /// as a link would carry them: a write the EEPROM file did not take is
    /// answered with status 5 (docs/behaviour.md rule 82).
    pub fn frame(&self, frame: &[u8; FRAME_LEN]) -> Vec<[u8; FRAME_LEN]> {
        let (answer, unsaved) = self.with_bus_saved(|bus| bus.handle_frame(frame));
        answer.replies.into_iter().map(|r| if unsaved { Self::not_stored(r, frame[1]) } else { r }).collect()
    }

    /// An observer's reads of module `index` (in bus order), under one
    /// lock: the replies the module's model gives, with none of a
    /// request's effects (`None` for what is not a read), and the bus's
    /// time (docs/behaviour.md rule 86).
    pub fn observe(&self, index: usize, all: &[Instruction]) -> (Vec<Option<[u8; FRAME_LEN]>>, u64) {
        self.with_bus(|bus| (bus.observe(index, all), bus.now_ns()))
    }

    /// Link `link` is gone (docs/behaviour.md rule 91).
    pub fn link_closed(&self, link: u64) {
        self.lock().bus.link_closed(link);
    }

    /// Sends one frame to module `index` (in bus order) alone, from in
    /// process; its reply as in [`SharedBus::frame`].
    pub fn module_frame(&self, index: usize, frame: &[u8; FRAME_LEN]) -> Option<[u8; FRAME_LEN]> {
        let (reply, unsaved) = self.with_bus_saved(|bus| bus.module_mut(index).handle_frame(frame));
        reply.map(|r| if unsaved { Self::not_stored(r, frame[1]) } else { r })
    }

    /// Before a request: `prepare` runs on the bus, then the EEPROM
    /// generation of every module is noted (`None`: no module has an
    /// EEPROM file, nothing to note).
    fn generations(s: &mut State, prepare: impl FnOnce(&mut Bus)) -> Option<Vec<u64>> {
        prepare(&mut s.bus);
        s.eeproms.any().then(|| s.bus.modules().iter().map(Module::eeprom_generation).collect())
    }

    /// After a request: the modules whose EEPROM it wrote.
    fn written_since(s: &State, before: Option<Vec<u64>>) -> Vec<usize> {
        let Some(before) = before else { return Vec::new() };
        s.bus.modules().iter().zip(before).enumerate().filter(|(_, (m, g))| m.eeprom_generation() != *g).map(|(i, _)| i).collect()
    }

    /// A reply that said the request was carried out (100, or 101 for a
    /// downloaded word) says instead that the EEPROM did not take it: 5
    /// (docs/behaviour.md rule 82). Other replies, and frames that are no
    /// reply to `opcode`, stay as they are.
    fn not_stored(frame: [u8; FRAME_LEN], opcode: u8) -> [u8; FRAME_LEN] {
        match Reply::decode(&frame) {
            Some(mut r) if r.opcode == opcode && matches!(r.status(), Some(Status::Ok | Status::Loaded)) => {
                r.status = Status::EepromLocked.code();
                r.encode()
            }
            _ => frame,
        }
    }

    /// One byte of text for the modules in ASCII mode from a link whose
    /// lines are `lines`; echoes and replies are appended to `out`.
    pub fn ascii_byte(&self, lines: &mut tmclsim_firmware::ascii::LineState, byte: u8, out: &mut Vec<u8>) {
        let mut s = self.lock();
        s.bus.ascii_byte(lines, byte, out);
        Self::after_change(&mut s);
        self.update_ascii(&s);
    }

    /// After a request from `link`: that link receives events from now on
    /// (if it got an answer or events are waiting), effects are carried
    /// out, and the clock task is woken if something is due sooner than it
    /// sleeps for.
    /// Returns the modules whose EEPROM file could not be saved.
    fn after_request(&self, mut s: std::sync::MutexGuard<'_, State>, link: u64, sink: &EventSink, answered: bool) -> Vec<usize> {
        self.update_ascii(&s);
        let has_events = s.bus.modules().iter().any(Module::has_events);
        if (answered || has_events) && s.sink.as_ref().is_none_or(|(id, _)| *id != link) {
            s.sink = Some((link, sink.clone()));
        }
        let failed = Self::after_change(&mut s);
        let due = s.bus.next_deadline();
        let wake = due.is_some_and(|d| s.scheduled.is_none_or(|sch| d < sch));
        drop(s);
        if wake {
            self.wake();
        }
        failed
    }

    /// A 138 event (9-byte form) as the CAN frame of the module it is from.
    pub fn event_as_can(&self, event: &[u8; FRAME_LEN]) -> Option<CanFrame> {
        let s = self.lock();
        s.bus.index_of(event[1]).map(|i| s.bus.event_as_can(i, event))
    }

    /// The clock task: brings the bus to now, carries out what became due
    /// and returns the next deadline, remembered so that requests know
    /// whether to wake the task earlier.
    pub fn tick(&self) -> Option<u64> {
        let mut s = self.lock();
        s.bus.catch_up();
        Self::after_change(&mut s);
        let due = s.bus.next_deadline();
        s.scheduled = due;
        due
    }

    /// Carries out what changed: events go to the link that spoke last,
    /// written EEPROMs to their files. A module whose file cannot be saved
    /// goes back to the image its file holds, and says so on stderr
    /// (docs/behaviour.md rule 82); those modules are returned.
    fn after_change(s: &mut State) -> Vec<usize> {
        let effects = s.bus.take_effects();
        for (index, event) in effects.events {
            match &s.sink {
                Some((_, sink)) => sink(event),
                None if s.unclaimed.len() < UNCLAIMED_EVENTS => s.unclaimed.push((index, event)),
                None => {}
            }
        }
        effects.eeprom_written.into_iter().filter(|&index| !s.eeproms.save_from(&mut s.bus, index)).collect()
    }
}

/// Executes one control line (`[@ADDRESS] COMMAND …`, docs/world.md) on a
/// bus; `Ok` carries what to print after `ok`. `link …` changes the link's
/// faults; everything else is a typed world command applied through the
/// bus to the addressed module (the first one without `@ADDRESS`). The
/// control socket of a served link and the Python package both run their
/// lines here.
pub fn execute(bus: &SharedBus, line: &str) -> Result<String, ControlError> {
    let mut w = line.split_whitespace();
    match w.next() {
        None => return Ok(String::new()),
        Some("help") => return Ok(HELP.to_string()),
        Some("link") => {
            let mut f: LinkFaults = bus.link_faults();
            match w.next() {
                Some("drop") => f.drop = num(w.next(), "count")?,
                Some("corrupt") => f.corrupt = num(w.next(), "count")?,
                Some("delay") => f.delay = Duration::from_millis(num(w.next(), "delay in ms")?),
                Some("mute") => f.mute = on_off(w.next()).map_err(ControlError::world)?,
                Some("clear") => f = LinkFaults::default(),
                other => return Err(ControlError::LinkUsage(other.unwrap_or("").to_string())),
            }
            bus.set_link_faults(f);
            return Ok(String::new());
        }
        Some(_) => {}
    }
    let Addressed { address, command } = Addressed::parse(line).map_err(ControlError::world)?;
    bus.apply_world(address, &command).map_err(ControlError::world)
}

/// Why a control line failed.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ControlError {
    /// A `link` fault lacks its number.
    Missing {
        /// What is missing (`count`, `delay in ms`).
        what: &'static str,
    },
    /// A `link` fault's number is not one.
    Invalid {
        /// The word given.
        word: String,
        /// What it should be.
        what: &'static str,
    },
    /// `link` with another word than drop, corrupt, delay, mute or clear.
    LinkUsage(String),
    /// The world command is wrong or failed (the firmware's words).
    World(String),
}

impl ControlError {
    fn world(e: impl std::fmt::Display) -> ControlError {
        ControlError::World(e.to_string())
    }
}

impl std::fmt::Display for ControlError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ControlError::Missing { what } => write!(f, "{what} is missing"),
            ControlError::Invalid { word, what } => write!(f, "'{word}' is not a valid {what}"),
            ControlError::LinkUsage(word) => write!(f, "link {word}: use drop, corrupt, delay, mute or clear"),
            ControlError::World(message) => f.write_str(message),
        }
    }
}

impl std::error::Error for ControlError {}

impl From<ControlError> for String {
    fn from(e: ControlError) -> String {
        e.to_string()
    }
}

fn num<T: std::str::FromStr>(w: Option<&str>, what: &'static str) -> Result<T, ControlError> {
    let w = w.ok_or(ControlError::Missing { what })?;
    w.parse().map_err(|_| ControlError::Invalid { word: w.to_string(), what })
}

#[cfg(test)]
mod tests {
    use super::*;
    use tmclsim_protocol::{Instruction, Request, opcode};

    fn frame(op: u8, kind: u8, value: i32) -> [u8; FRAME_LEN] {
        Request::new(1, Instruction::new(op, kind, 0, value)).encode()
    }

    /// Sends a frame in process: the reply's status and opcode.
    fn ask(bus: &SharedBus, op: u8, kind: u8, value: i32) -> (u8, u8) {
        let raw = bus.module_frame(0, &frame(op, kind, value)).expect("a reply");
        let r = Reply::decode(&raw).expect("a valid checksum");
        (r.status, r.opcode)
    }

    #[test]
    fn writes_the_file_does_not_take_are_answered_with_status_5_on_every_path() {
        let dir = tempfile::tempdir().unwrap();
        let store = dir.path().join("store");
        std::fs::create_dir(&store).unwrap();
        let path = store.join("m.eeprom");
        let file = Arc::new(EepromFile::open(&path).unwrap());
        let bus = SharedBus::new(Bus::single(Module::built_in("tmcm-1141").unwrap()), vec![Some(file)]);
        assert_eq!(ask(&bus, opcode::SAP, 4, 1000), (100, opcode::SAP));
        assert_eq!(ask(&bus, opcode::STAP, 4, 0), (100, opcode::STAP));

        // No file can be created where the directory was.
        let away = dir.path().join("away");
        std::fs::rename(&store, &away).unwrap();
        std::fs::write(&store, "").unwrap();
        assert_eq!(ask(&bus, opcode::SAP, 4, 2000), (100, opcode::SAP), "a write of RAM only is unaffected");
        assert_eq!(ask(&bus, opcode::STAP, 4, 0), (5, opcode::STAP));
        assert_eq!(bus.with(|m| m.eeprom().axis(0, 4)), Some(1000), "the EEPROM is what the file holds");
        // A downloaded word: 5 instead of 101.
        assert_eq!(ask(&bus, opcode::ENTER_DOWNLOAD, 0, 0), (100, opcode::ENTER_DOWNLOAD));
        assert_eq!(ask(&bus, opcode::SAP, 4, 5), (5, opcode::SAP));
        assert_eq!(ask(&bus, opcode::EXIT_DOWNLOAD, 0, 0), (5, opcode::EXIT_DOWNLOAD));
        assert!(bus.with(|m| m.eeprom().program.is_empty()));
        // A link's frame and a CAN frame.
        let sink: EventSink = Arc::new(|_| ());
        let (replies, _) = bus.handle(1, &sink, &frame(opcode::STAP, 4, 0));
        let r = Reply::decode(&replies[0]).expect("a valid checksum");
        assert_eq!((r.status, r.opcode), (5, opcode::STAP));
        let can = CanFrame::new(1, &[opcode::STAP, 4, 0, 0, 0, 0, 0]);
        let replies = bus.handle_can(1, &sink, &can);
        assert_eq!(replies[0].bytes()[1..3], [5, opcode::STAP]);
        let can = CanFrame::new(1, &[opcode::GAP, 4, 0, 0, 0, 0, 0]);
        assert_eq!(bus.handle_can(1, &sink, &can)[0].bytes()[1..3], [100, opcode::GAP], "reads are unaffected");

        // Repaired: the next write stores the file's image and itself.
        std::fs::remove_file(&store).unwrap();
        std::fs::rename(&away, &store).unwrap();
        assert_eq!(ask(&bus, opcode::SAP, 5, 300), (100, opcode::SAP));
        assert_eq!(ask(&bus, opcode::STAP, 5, 0), (100, opcode::STAP));
        let image = crate::eeprom_file::load(&path).unwrap().unwrap();
        assert_eq!((image.axis(0, 4), image.axis(0, 5)), (Some(1000), Some(300)));
        assert!(image.program.is_empty());
    }

    #[test]
    fn in_process_without_a_server_events_wait_on_the_bus_and_changes_wake_the_clock() {
        let bus = SharedBus::new(Bus::single(Module::built_in("tmcm-1141").unwrap()), Vec::new());
        let woken = Arc::new(std::sync::atomic::AtomicUsize::new(0));
        let w = woken.clone();
        bus.set_waker(move || {
            w.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        });
        // 138 type 0 asks for the event at the target; MVP moves there.
        assert_eq!(ask(&bus, opcode::TARGET_REACHED_EVENT, 0, 1), (100, opcode::TARGET_REACHED_EVENT));
        assert_eq!(ask(&bus, opcode::MVP, 0, 1000), (100, opcode::MVP));
        assert!(woken.load(std::sync::atomic::Ordering::Relaxed) >= 2, "each request wakes the clock task");
        bus.advance(2_000_000_000);
        let events = bus.take_unclaimed_events(0);
        assert_eq!(events.len(), 1, "no link spoke: the event waits for an in-process reader");
        assert!(crate::trace::is_event(&events[0]));
        assert!(bus.take_unclaimed_events(0).is_empty());
        // A link that speaks receives the events from then on.
        let got = Arc::new(Mutex::new(Vec::new()));
        let g = got.clone();
        let sink: EventSink = Arc::new(move |e| g.lock().unwrap().push(e));
        bus.handle(7, &sink, &frame(opcode::TARGET_REACHED_EVENT, 0, 1));
        bus.handle(7, &sink, &frame(opcode::MVP, 0, 0));
        bus.advance(2_000_000_000);
        assert_eq!(got.lock().unwrap().len(), 1);
        assert!(bus.take_unclaimed_events(0).is_empty());
    }

    #[test]
    fn control_lines_change_the_world_and_the_link_faults() {
        let bus = SharedBus::new(Bus::single(Module::built_in("tmcm-1141").unwrap()), Vec::new());
        assert_eq!(execute(&bus, ""), Ok(String::new()));
        assert!(execute(&bus, "help").unwrap().contains("link"));
        assert_eq!(execute(&bus, "link drop 2"), Ok(String::new()));
        assert_eq!(bus.link_faults().drop, 2);
        assert!(execute(&bus, "link frob").unwrap_err().to_string().contains("use drop, corrupt"));
        assert_eq!(execute(&bus, "input 1 1"), Ok(String::new()));
        assert_eq!(ask(&bus, opcode::GIO, 1, 0).0, 100);
        assert!(execute(&bus, "@9 input 1 1").is_err(), "no module at address 9");
    }
}
