//! A module shared by the links of a server, paced by the wall clock.

use std::path::PathBuf;
use std::sync::Mutex;
use std::time::{Duration, Instant};
use tmclsim_firmware::eeprom::save_atomic;
use tmclsim_firmware::Module;
use tmclsim_protocol::FRAME_LEN;
use crate::faults::LinkFaults;
use tokio::sync::{mpsc, Notify};

/// Where unsolicited frames (138 events) go: the link that spoke last.
type EventSink = mpsc::UnboundedSender<[u8; FRAME_LEN]>;

struct State {
    module: Module,
    saved_generation: u64,
    sink: Option<(u64, EventSink)>,
    /// What the clock task sleeps until (`None`: nothing).
    scheduled: Option<u64>,
}

/// How virtual time passes for a served module.
#[derive(Clone, Copy, Debug)]
enum Clock {
    /// Paced by the wall clock: virtual time `origin_ns` at `origin`.
    Wall { origin: Instant, origin_ns: u64 },
    /// Only `SharedModule::advance` moves time (stepped virtual time).
    Stepped,
}

/// The served module behind a lock, with its clock and EEPROM file.
pub struct SharedModule {
    state: Mutex<State>,
    clock: Mutex<Clock>,
    eeprom: Option<PathBuf>,
    changed: Notify,
    faults: Mutex<LinkFaults>,
}

impl SharedModule {
    pub fn new(module: Module, eeprom: Option<PathBuf>) -> SharedModule {
        let origin_ns = module.now_ns();
        let saved_generation = module.eeprom_generation();
        SharedModule {
            state: Mutex::new(State { module, saved_generation, sink: None, scheduled: None }),
            clock: Mutex::new(Clock::Wall { origin: Instant::now(), origin_ns }),
            eeprom,
            changed: Notify::new(),
            faults: Mutex::new(LinkFaults::default()),
        }
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

    /// Virtual time now: by the wall clock, or (stepped) where the module is.
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
    /// where the module is.
    pub fn set_stepped(&self, stepped: bool) {
        let s = self.state.lock().unwrap_or_else(|p| p.into_inner());
        let mut clock = self.clock.lock().unwrap_or_else(|p| p.into_inner());
        match (stepped, *clock) {
            (true, Clock::Wall { origin, origin_ns }) => {
                drop(clock);
                drop(s);
                // Bring the module up to the wall clock before it stops.
                let now = origin_ns + origin.elapsed().as_nanos() as u64;
                self.with(|m| m.advance_to(now));
                *self.clock.lock().unwrap_or_else(|p| p.into_inner()) = Clock::Stepped;
            }
            (false, Clock::Stepped) => *clock = Clock::Wall { origin: Instant::now(), origin_ns: s.module.now_ns() },
            _ => {}
        }
        self.changed.notify_one();
    }

    pub fn is_stepped(&self) -> bool {
        matches!(*self.clock.lock().unwrap_or_else(|p| p.into_inner()), Clock::Stepped)
    }

    /// Stepped virtual time: moves the module on by `dt_ns` (events go out
    /// on their links as they become due).
    pub fn advance(&self, dt_ns: u64) {
        let mut s = self.state.lock().unwrap_or_else(|p| p.into_inner());
        s.module.advance(dt_ns);
        self.after_change(&mut s);
    }

    /// Runs `f` on the module, brought up to the current time.
    pub fn with<R>(&self, f: impl FnOnce(&mut Module) -> R) -> R {
        let mut s = self.state.lock().unwrap_or_else(|p| p.into_inner());
        let now = self.now_ns();
        s.module.advance_to(now);
        let r = f(&mut s.module);
        self.after_change(&mut s);
        r
    }

    /// Handles one frame from link `link`, whose events go to `sink`.
    /// Returns the reply and how long to wait before sending it (GP 75).
    pub(crate) fn handle(&self, link: u64, sink: &EventSink, frame: &[u8; FRAME_LEN]) -> (Option<[u8; FRAME_LEN]>, Duration) {
        let mut s = self.state.lock().unwrap_or_else(|p| p.into_inner());
        let now = self.now_ns();
        s.module.advance_to(now);
        let reply = s.module.handle_frame(frame);
        if reply.is_some() || s.module.has_events() {
            if s.sink.as_ref().is_none_or(|(id, _)| *id != link) {
                s.sink = Some((link, sink.clone()));
            }
        }
        let delay = Duration::from_nanos(s.module.reply_delay_ns());
        self.after_change(&mut s);
        // Wake the clock task only when something is due sooner than what
        // it sleeps for.
        let due = s.module.next_event_ns();
        let wake = due.is_some_and(|d| s.scheduled.is_none_or(|sch| d < sch));
        drop(s);
        if wake {
            self.changed.notify_one();
        }
        (reply, delay)
    }

    /// The clock task's next wake-up: what is due, remembered so that
    /// frames know whether to wake it earlier.
    pub(crate) fn schedule(&self) -> Option<u64> {
        let mut s = self.state.lock().unwrap_or_else(|p| p.into_inner());
        let now = self.now_ns();
        s.module.advance_to(now);
        self.after_change(&mut s);
        let due = s.module.next_event_ns();
        s.scheduled = due;
        due
    }

    /// Advances to now and dispatches what became due.
    pub(crate) fn tick(&self) {
        let mut s = self.state.lock().unwrap_or_else(|p| p.into_inner());
        let now = self.now_ns();
        s.module.advance_to(now);
        self.after_change(&mut s);
    }

    /// Resolves when a frame changed the module's plans.
    pub(crate) async fn changed(&self) {
        self.changed.notified().await
    }

    fn after_change(&self, s: &mut State) {
        if s.module.has_events() {
            let events = s.module.take_events();
            if let Some((_, sink)) = &s.sink {
                for e in events {
                    let _ = sink.send(e);
                }
            }
        }
        if s.module.eeprom_generation() != s.saved_generation {
            if let Some(path) = &self.eeprom {
                if let Err(e) = save_atomic(path, s.module.eeprom()) {
                    eprintln!("tmclsim: cannot write EEPROM file {}: {e}", path.display());
                }
            }
            s.saved_generation = s.module.eeprom_generation();
        }
    }
}
