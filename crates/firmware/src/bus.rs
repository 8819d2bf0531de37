//! The one thing every front end drives: modules on a link (a single
//! module is a bus of one) with their [`Clock`].
//!
//! Requests go in (9-byte frames, CAN frames, ASCII bytes), replies come
//! out; time moves with [`Bus::advance_to`] (and a debugger's
//! [`Bus::step_instruction`]), and only here: a module's own time-moving
//! methods are the firmware's. [`Bus::next_deadline`] says exactly when
//! something happens next on its own. What a front end
//! must carry out (EEPROM images to persist, 138 events to send) it takes
//! with [`Bus::take_effects`]; observers look at [`Bus::snapshot`].

use crate::clock::{Budget, Clock, Speed};
use crate::module::Module;
use crate::module::can::CanFrame;
use crate::snapshot::ModuleSnapshot;
use crate::world_command::WorldCommand;
use crate::world_error::WorldError;
use std::time::Duration;
use tmclsim_protocol::FRAME_LEN;

/// The replies to one frame and when they may go out.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Answer {
    /// The reply frames, in order (none when the module keeps silent: GP 255,
    /// 137).
    pub replies: Vec<[u8; FRAME_LEN]>,
    /// Delay before the replies: GP 75 of the module that answered and,
    /// with wire timing, the time request and reply take on the wire.
    pub delay_ns: u64,
}

/// What a front end must carry out after the bus changed.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Effects {
    /// Modules (by index) whose EEPROM was written: persist
    /// `bus.module(i).eeprom()`.
    pub eeprom_written: Vec<usize>,
    /// Unsolicited frames (138 events), by module index, in order.
    pub events: Vec<(usize, [u8; FRAME_LEN])>,
}

impl Effects {
    /// Nothing to carry out: no EEPROM written, no event frame.
    pub fn is_empty(&self) -> bool {
        self.eeprom_written.is_empty() && self.events.is_empty()
    }
}

/// Modules on one link and their clock.
#[derive(Clone, Debug)]
pub struct Bus {
    modules: Vec<Module>,
    clock: Clock,
    /// How fast a wall clock runs (kept while the clock is stepped).
    speed: Speed,
    /// The latest virtual time the bus was brought to. Modules a frame is
    /// not for may lag behind; they catch up when next looked at.
    now_ns: u64,
    /// EEPROM generation of each module when its effects were last taken.
    saved: Vec<u64>,
    /// Deliver bytes at the modules' baud rate (GP 65), as a real RS485
    /// bus does.
    wire_timing: bool,
    /// Virtual time fell behind the wall clock's speed: the modules could
    /// not compute it as fast (docs/behaviour.md rule 119). How often.
    fell_behind: u64,
}

/// The most wall-clock time one catch-up to the wall clock's now may take:
/// a request, the clock task and a stop signal never wait longer for the
/// modules. What the modules could not compute within it is given up:
/// virtual time goes on from where they are (docs/behaviour.md rule 119).
pub const CATCH_UP_BUDGET: Duration = Duration::from_millis(2);

impl Bus {
    /// Modules on one link, brought to one virtual time (the latest of
    /// theirs), with a stepped clock.
    pub fn new(mut modules: Vec<Module>) -> Bus {
        let now_ns = modules.iter().map(Module::now_ns).max().unwrap_or(0);
        for m in &mut modules {
            m.advance_to(now_ns);
        }
        let saved = modules.iter().map(Module::eeprom_generation).collect();
        Bus { modules, clock: Clock::Stepped, speed: Speed::REAL_TIME, now_ns, saved, wire_timing: false, fell_behind: 0 }
    }

    /// A bus of one.
    pub fn single(module: Module) -> Bus {
        Bus::new(vec![module])
    }

    /// Replies wait for the time the bytes take on the wire (GP 65).
    pub fn set_wire_timing(&mut self, on: bool) {
        self.wire_timing = on;
    }

    /// The bus's source of "now".
    pub fn clock(&self) -> Clock {
        self.clock
    }

    /// Stepped (`true`): time stands still between calls of
    /// [`Bus::advance`]. `false`: time follows the wall clock from where
    /// the bus is.
    pub fn set_stepped(&mut self, stepped: bool) {
        if stepped {
            self.catch_up();
            self.clock = Clock::Stepped;
        } else if self.clock.is_stepped() {
            self.clock = Clock::wall_from(self.now_ns, self.speed);
        }
    }

    /// How fast virtual time runs while the clock follows the wall clock.
    pub fn speed(&self) -> Speed {
        self.speed
    }

    /// Virtual time runs `speed` times as fast as the wall clock (from now
    /// on; a stepped clock keeps standing still and runs at that speed
    /// once it follows the wall clock again).
    pub fn set_speed(&mut self, speed: Speed) {
        if !self.clock.is_stepped() {
            self.catch_up();
            self.clock = Clock::wall_from(self.now_ns, speed);
        }
        self.speed = speed;
    }

    /// Virtual time now, by the clock.
    pub fn now_ns(&self) -> u64 {
        self.clock.now_ns(self.now_ns)
    }

    /// Brings every module to the clock's now (within
    /// [`CATCH_UP_BUDGET`] of wall-clock time on a wall clock).
    pub fn catch_up(&mut self) {
        self.reach_now(|_| true);
    }

    /// How often virtual time fell behind the wall clock's speed because
    /// the modules could not compute it as fast (0: never).
    pub fn fell_behind(&self) -> u64 {
        self.fell_behind
    }

    /// Brings the modules `pick` takes to the clock's now and answers the
    /// time they reached. On a wall clock it moves in slices sized to take
    /// about a tenth of the budget's wall-clock time and stops when the
    /// catch-up has taken [`CATCH_UP_BUDGET`]: the backlog is then given up and the
    /// clock goes on from where the modules are, so that virtual time runs
    /// as fast as the modules can compute it (docs/behaviour.md rule 119).
    fn reach_now(&mut self, pick: impl Fn(&Module) -> bool) -> u64 {
        let target = self.now_ns();
        if self.clock.is_stepped() {
            for m in self.modules.iter_mut().filter(|m| pick(m)) {
                m.advance_to(target);
            }
            self.now_ns = self.now_ns.max(target);
            return target;
        }
        let budget = Budget::new(CATCH_UP_BUDGET);
        // Slices of virtual time that take about a tenth of a millisecond
        // of wall-clock time each: a millisecond of virtual time at first,
        // twice as much after a quick slice, half after a slow one.
        let mut slice: u64 = 1_000_000;
        let mut at = self.modules.iter().filter(|m| pick(m)).map(Module::now_ns).min().unwrap_or(target).min(target);
        loop {
            let before = budget.elapsed();
            at = at.saturating_add(slice).min(target);
            for m in self.modules.iter_mut().filter(|m| pick(m)) {
                m.advance_to(at);
            }
            if at >= target {
                break;
            }
            if budget.spent() {
                self.clock = Clock::wall_from(at, self.speed);
                self.fell_behind += 1;
                break;
            }
            let took = budget.elapsed().saturating_sub(before);
            if took < CATCH_UP_BUDGET / 20 {
                slice = slice.saturating_mul(2);
            } else if took > CATCH_UP_BUDGET / 5 {
                slice = (slice / 2).max(1_000);
            }
        }
        self.now_ns = self.now_ns.max(at);
        at
    }

    /// Moves every module to virtual time `t_ns` (no-op for the past).
    pub fn advance_to(&mut self, t_ns: u64) {
        for m in &mut self.modules {
            m.advance_to(t_ns);
        }
        self.now_ns = self.now_ns.max(t_ns);
    }

    /// Moves the bus on by `dt_ns`. With a wall clock, the clock is moved
    /// on with it.
    pub fn advance(&mut self, dt_ns: u64) {
        let t = self.now_ns().saturating_add(dt_ns);
        self.advance_to(t);
        if !self.clock.is_stepped() {
            self.clock = Clock::wall_from(self.now_ns, self.speed);
        }
    }

    /// Runs the program of module `index` until one more instruction has
    /// executed (a WAIT in progress first ends), then pauses it, as a
    /// debugger's single step; the bus is brought to now first and goes
    /// on to where the step ended, at most `limit_ns`, in pieces of at most
    /// `slice_ns` while a WAIT waits. False when `limit_ns` came first.
    pub fn step_instruction(&mut self, index: usize, limit_ns: u64, slice_ns: u64) -> bool {
        self.catch_up();
        let done = self.modules[index].step_instruction(limit_ns, slice_ns);
        let now = self.modules[index].now_ns();
        self.advance_to(now);
        if !self.clock.is_stepped() {
            self.clock = Clock::wall_from(self.now_ns, self.speed);
        }
        done
    }

    /// Brings the modules a frame to `address` is for to the clock's now
    /// (the others may lag until they are next looked at): what their
    /// programs do until now is then told apart from what the frame does.
    pub fn catch_up_addressed(&mut self, address: u8) {
        self.reach_now(|m| m.answers_to(address));
    }

    /// The next virtual time at which something happens on its own on any
    /// module (`None`: nothing until a request comes).
    pub fn next_deadline(&self) -> Option<u64> {
        self.modules.iter().filter_map(Module::next_deadline).min()
    }

    /// One 9-byte frame on the link from an in-process caller: every
    /// module sees it, the addressed one answers.
    pub fn handle_frame(&mut self, frame: &[u8; FRAME_LEN]) -> Answer {
        self.handle_frame_from(crate::link_id::IN_PROCESS, frame)
    }

    /// [`Bus::handle_frame`] for a frame that came on link `link` (a
    /// download belongs to the link that started it, docs/behaviour.md
    /// rule 91).
    pub fn handle_frame_from(&mut self, link: crate::link_id::LinkId, frame: &[u8; FRAME_LEN]) -> Answer {
        let single = self.modules.len() == 1;
        let now = self.reach_now(|m| single || m.answers_to(frame[0]));
        let mut answer = Answer::default();
        let wire_timing = self.wire_timing;
        let reply = |answer: &mut Answer, m: &Module, r: [u8; FRAME_LEN]| {
            answer.replies.push(r);
            answer.delay_ns = answer.delay_ns.max(m.reply_delay_ns());
            if wire_timing {
                // Request and reply, 10 bits a byte.
                answer.delay_ns += 2 * FRAME_LEN as u64 * 10 * 1_000_000_000 / u64::from(m.profile().baud_rate(m.baud_rate_code()));
            }
        };
        if let [m] = self.modules.as_mut_slice() {
            // A link with one module is point-to-point: it answers a
            // resync frame (docs/behaviour.md rule 85).
            if !m.answers_to(frame[0]) {
                m.advance_to(now);
                if let Some(r) = m.answer_resync(frame) {
                    reply(&mut answer, m, r);
                }
                return answer;
            }
        }
        for m in &mut self.modules {
            // Only the addressed module does anything with a frame; the
            // others catch up when they are next looked at.
            if !m.answers_to(frame[0]) {
                continue;
            }
            m.advance_to(now);
            if let Some(r) = m.handle_frame_from(link, frame) {
                reply(&mut answer, m, r);
            }
        }
        answer
    }

    /// Link `link` is gone: downloads it owned pass to the next link that
    /// speaks (docs/behaviour.md rule 91).
    pub fn link_closed(&mut self, link: crate::link_id::LinkId) {
        for m in &mut self.modules {
            m.link_closed(link);
        }
    }

    /// Reads of module `index` as an observer makes them: the replies
    /// from the model, and nothing changed ([`Module::observe`],
    /// docs/behaviour.md rule 86). The bus is brought to now first.
    pub fn observe(&mut self, index: usize, all: &[tmclsim_protocol::Instruction]) -> Vec<Option<[u8; FRAME_LEN]>> {
        self.catch_up();
        let m = &self.modules[index];
        all.iter().map(|ins| m.observe(*ins)).collect()
    }

    /// One CAN frame on the bus: every module sees it, those it is for
    /// answer.
    pub fn handle_can(&mut self, frame: &CanFrame) -> Vec<CanFrame> {
        self.catch_up();
        self.modules.iter_mut().filter_map(|m| m.handle_can(frame)).collect()
    }

    /// Some module reads text (ASCII mode).
    pub fn ascii_active(&self) -> bool {
        self.modules.iter().any(Module::ascii_mode)
    }

    /// One byte of text for the modules in ASCII mode from a link whose
    /// lines are `lines` (docs/behaviour.md rule 83); echoes and replies
    /// are appended to `out`.
    pub fn ascii_byte(&mut self, lines: &mut crate::module::ascii::LineState, byte: u8, out: &mut Vec<u8>) {
        self.catch_up();
        if lines.lines.len() < self.modules.len() {
            lines.lines.resize_with(self.modules.len(), Default::default);
        }
        for (m, line) in self.modules.iter_mut().zip(&mut lines.lines) {
            if m.ascii_mode() {
                m.ascii_byte_on(line, byte, out);
            }
        }
    }

    /// A 138 event of module `index` as its CAN frame.
    pub fn event_as_can(&self, index: usize, event: &[u8; FRAME_LEN]) -> CanFrame {
        self.modules[index].event_as_can(event)
    }

    /// What the front end must carry out since the last call.
    pub fn take_effects(&mut self) -> Effects {
        let mut effects = Effects::default();
        for (i, m) in self.modules.iter_mut().enumerate() {
            if m.has_events() {
                effects.events.extend(m.take_events().into_iter().map(|e| (i, e)));
            }
            if m.eeprom_generation() != self.saved[i] {
                self.saved[i] = m.eeprom_generation();
                effects.eeprom_written.push(i);
            }
        }
        effects
    }

    /// How many modules are on the bus.
    pub fn len(&self) -> usize {
        self.modules.len()
    }

    /// True when the bus holds no module.
    pub fn is_empty(&self) -> bool {
        self.modules.is_empty()
    }

    /// The modules, in bus order.
    pub fn modules(&self) -> &[Module] {
        &self.modules
    }

    /// The module at `index` in bus order (panics when there is none).
    pub fn module(&self, index: usize) -> &Module {
        &self.modules[index]
    }

    /// Module `index`, for changes a front end makes outside the protocol
    /// (programs, parameters by name, the world).
    pub fn module_mut(&mut self, index: usize) -> &mut Module {
        &mut self.modules[index]
    }

    /// The index of the module that answers to `address` now.
    pub fn index_of(&self, address: u8) -> Option<usize> {
        self.modules.iter().position(|m| m.answers_to(address))
    }

    /// Takes the modules out of the bus.
    pub fn into_modules(self) -> Vec<Module> {
        self.modules
    }

    /// Applies a world command to the module at `address` (`None`: the
    /// first module), at the clock's now.
    pub fn apply_world(&mut self, address: Option<u8>, command: &WorldCommand) -> Result<String, WorldError> {
        let index = match address {
            None => 0,
            Some(a) => self.index_of(a).ok_or(WorldError::NoModule { address: a })?,
        };
        self.catch_up();
        command.apply(&mut self.modules[index])
    }

    /// A picture of every module, in bus order.
    pub fn snapshot(&self) -> Vec<ModuleSnapshot> {
        self.modules.iter().map(ModuleSnapshot::of).collect()
    }
}

/// The first address two modules share, if any: on one link every module
/// needs its own address, or two would answer one frame.
pub fn duplicate_address(addresses: impl IntoIterator<Item = u8>) -> Option<u8> {
    let mut seen = [false; 256];
    addresses.into_iter().find(|&a| std::mem::replace(&mut seen[a as usize], true))
}

#[cfg(test)]
mod tests {
    use super::*;
    use tmclsim_protocol::{Instruction, Reply, Request, Status};

    fn module(address: u8) -> Module {
        let mut m = Module::built_in("tmcm-1141").unwrap();
        m.set_address(address);
        m
    }

    fn frame(address: u8, op: u8, kind: u8, value: i32) -> [u8; FRAME_LEN] {
        Request::new(address, Instruction::new(op, kind, 0, value)).encode()
    }

    /// A tight program loop (`CALC ADD, 1 / JA 0`) running on `m`.
    fn tight_loop(mut m: Module) -> Module {
        let words = [Instruction::new(19, 0, 0, 1), Instruction::new(22, 0, 0, 0)];
        m.load_program(&words).unwrap();
        m.start_program();
        m
    }

    #[test]
    fn a_wall_clock_faster_than_the_modules_falls_behind_instead_of_piling_up() {
        // docs/behaviour.md rule 119: 100 000 virtual seconds a wall second
        // of a tight loop cannot be computed; each catch-up gives up after
        // its budget and the clock goes on from where the modules are.
        let mut bus = Bus::new(vec![tight_loop(module(1)), tight_loop(module(2))]);
        bus.set_speed(Speed::new(Speed::MAX).unwrap());
        bus.set_stepped(false);
        for _ in 0..3 {
            std::thread::sleep(Duration::from_millis(30)); // about time: let the wall clock run ahead
            bus.catch_up();
        }
        assert!(bus.fell_behind() >= 1, "never fell behind");
        // The clock now reads where the modules are, not the backlog.
        let behind = bus.now_ns();
        assert!(bus.modules().iter().all(|m| m.now_ns() <= behind));
        // A request is answered at once by the module it is for.
        let answer = bus.handle_frame(&frame(2, 6, 1, 0));
        assert_eq!(Reply::decode(&answer.replies[0]).unwrap().status, Status::Ok.code());
        // A stepped clock computes all it is told to, and never falls behind.
        let mut stepped = Bus::new(vec![tight_loop(module(1))]);
        stepped.advance(1_000_000_000);
        assert_eq!((stepped.now_ns(), stepped.fell_behind()), (1_000_000_000, 0));
    }

    #[test]
    fn only_the_addressed_module_answers() {
        let mut bus = Bus::new(vec![module(1), module(2)]);
        let a = bus.handle_frame(&frame(2, 6, 1, 0));
        assert_eq!(a.replies.len(), 1);
        let r = Reply::decode(&a.replies[0]).unwrap();
        assert_eq!((r.module, r.status), (2, Status::Ok.code()));
        assert!(bus.handle_frame(&frame(3, 6, 1, 0)).replies.is_empty());
        assert_eq!(bus.index_of(2), Some(1));
    }

    #[test]
    fn modules_are_brought_to_one_time() {
        let mut late = module(2);
        late.advance(5_000_000);
        let bus = Bus::new(vec![module(1), late]);
        assert!(bus.modules().iter().all(|m| m.now_ns() == 5_000_000));
        assert_eq!(bus.now_ns(), 5_000_000);
    }

    #[test]
    fn a_stepped_bus_moves_only_when_advanced() {
        let mut bus = Bus::single(module(1));
        assert!(bus.clock().is_stepped());
        bus.handle_frame(&frame(1, 1, 0, 1000)); // ROR 0, 1000
        let before = bus.snapshot()[0].axes[0].speed;
        bus.catch_up();
        assert_eq!(bus.now_ns(), 0);
        bus.advance(100_000_000);
        assert_eq!(bus.now_ns(), 100_000_000);
        let after = bus.snapshot()[0].axes[0].clone();
        assert!(after.speed > before && after.position > 0, "{after:?}");
    }

    #[test]
    fn eeprom_writes_and_events_are_effects() {
        let mut bus = Bus::new(vec![module(1), module(2)]);
        assert!(bus.take_effects().is_empty());
        bus.handle_frame(&frame(2, 7, 4, 0)); // STAP 4, 0 on module 2
        assert_eq!(bus.take_effects().eeprom_written, vec![1]);
        assert!(bus.take_effects().is_empty(), "taken once");
        // 138 on the next MVP of motor 0, then the move.
        bus.handle_frame(&frame(1, 138, 0, 1));
        bus.handle_frame(&frame(1, 4, 0, 1000));
        let due = bus.next_deadline().expect("the event is due");
        bus.advance_to(due);
        let effects = bus.take_effects();
        assert_eq!(effects.events.len(), 1);
        assert_eq!(effects.events[0].0, 0);
        assert_eq!(effects.events[0].1[2], 128);
    }

    #[test]
    fn world_commands_reach_the_module_by_address() {
        let mut bus = Bus::new(vec![module(1), module(2)]);
        bus.apply_world(Some(2), &WorldCommand::Input { number: 0, high: true }).unwrap();
        assert!(!bus.module(0).world().digital(0));
        assert!(bus.module(1).world().digital(0));
        assert_eq!(bus.snapshot()[1].io.inputs & 1, 1);
        assert_eq!(
            bus.apply_world(Some(9), &WorldCommand::Show { axis: None }).unwrap_err().to_string(),
            "no module on the bus answers to address 9"
        );
    }

    #[test]
    fn wire_timing_adds_the_bytes_time() {
        let mut bus = Bus::single(module(1));
        bus.set_wire_timing(true);
        // 9600 baud (GP 65 = 0): 180 bits.
        assert_eq!(bus.handle_frame(&frame(1, 6, 1, 0)).delay_ns, 18_750_000);
        // 230400 baud (GP 65 = 8): the same 180 bits in 0.78 ms.
        bus.handle_frame(&frame(1, 9, 65, 8));
        assert_eq!(bus.handle_frame(&frame(1, 6, 1, 0)).delay_ns, 781_250);
    }

    #[test]
    fn a_shared_address_is_found() {
        assert_eq!(super::duplicate_address([1, 2, 3]), None);
        assert_eq!(super::duplicate_address([1, 2, 1, 2]), Some(1));
        assert_eq!(super::duplicate_address([]), None);
    }
}
