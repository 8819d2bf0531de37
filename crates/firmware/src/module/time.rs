//! Virtual time: advancing the module and what happens on its own — the
//! program's batches and WAITs, timers, input and switch edges, the
//! heartbeat, the motors moving and the driver watching them; and the
//! debugger's single step, which runs time until one instruction is done.

use crate::module::Module;
use crate::parameter_numbers::gp;
use crate::program::{RunMode, Source};
use tmclsim_protocol::{Instruction, WaitCondition, opcode};

/// The driver measures load, stall and encoder deviation of a watched,
/// moving motor once a millisecond (docs/behaviour.md rule 81).
const DRIVER_SAMPLE_NS: u64 = 1_000_000;

/// How far ahead a switch edge is looked for.
const EDGE_HORIZON_S: f64 = 3600.0;

fn earliest(a: Option<u64>, b: Option<u64>) -> Option<u64> {
    match (a, b) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

impl Module {
    /// Advances virtual time by `dt_ns` nanoseconds: the program runs its
    /// instructions, the motors move, interrupts and events fire, each at
    /// its own moment. Only the bus moves a module's time ([`crate::Bus`],
    /// with its clock).
    pub(crate) fn advance(&mut self, dt_ns: u64) {
        let end = self.now_ns.saturating_add(dt_ns);
        self.look_at_inputs();
        // The world's next event, when a batch that left the world as it
        // was has just computed it.
        let mut known = None;
        // The world was found quiet ([`Quiet`]) and only world steps and
        // batches that left the world as it was came since: it still is.
        let mut quiet = false;
        // The inputs and switches read as at the last look: they do not
        // depend on where the carriages are (the world itself does not
        // change while time advances), and only world steps and batches
        // that left the world as it was came since.
        let fixed_switches = self.world.axes.iter().all(|w| !w.has_switch_positions());
        let mut as_seen = fixed_switches;
        loop {
            // After such a batch the timers are as they were too: the time
            // is the same and no instruction of the batch touches them.
            let (timer, world) = match known.take() {
                Some((timer, world)) => (timer, Some(world)),
                None if quiet => (None, None),
                None => (self.run_timers(), None),
            };
            if self.program.is_running() {
                if self.program.wait.is_some() {
                    self.check_wait();
                }
                if self.program.wait.is_some() && self.interrupt_ready() {
                    // An interrupt is served during a WAIT; RETI resumes it.
                    self.take_interrupt();
                }
                if self.program.wait.is_none() && self.program.next_ns <= self.now_ns && self.now_ns < end {
                    // Pure instructions run ahead of the world only up to
                    // the world's next event.
                    let world = self.next_world_event(timer, &mut quiet);
                    if self.run_batch(world.map_or(end, |d| d.min(end))) {
                        known = Some((timer, world));
                    } else {
                        quiet = false;
                        as_seen = false;
                    }
                    continue;
                }
            }
            if self.now_ns >= end {
                break;
            }
            // The next moment something happens on its own.
            let world = match world {
                Some(w) => w,
                None => self.next_world_event(timer, &mut quiet),
            };
            let t = earliest(world, self.program_deadline()).filter(|&d| d > self.now_ns).map_or(end, |d| d.min(end));
            self.step_world(t, !as_seen);
            as_seen = fixed_switches;
        }
    }

    /// [`Module::world_deadline`] while [`Module::advance`] goes on: only
    /// the heartbeat's while the world is known to be quiet; else worked
    /// out, and whether the world is quiet found out with it.
    fn next_world_event(&self, timer: Option<u64>, quiet: &mut bool) -> Option<u64> {
        if *quiet {
            return self.heartbeat_deadline();
        }
        let (world, q) = self.world_deadline_and_quiet(timer);
        *quiet = q == Quiet::Yes && timer.is_none();
        world
    }

    /// Moves the motors to `t` and looks at what changed (the inputs and
    /// switches with `look`).
    fn step_world(&mut self, t: u64, look: bool) {
        let dt = t - self.now_ns;
        for motor in 0..self.axes.len() {
            self.advance_axis(motor, dt);
        }
        self.now_ns = t;
        if let Some(deadline) = self.heartbeat_deadline()
            && self.now_ns >= deadline
        {
            self.link.heartbeat_tripped = true;
            for motor in 0..self.axes.len() {
                self.axes[motor].run_at(0);
            }
        }
        if look {
            self.look_at_inputs();
        }
    }

    /// Raises input-change and stop-switch interrupts for the transitions
    /// their bank 3 trigger setting selects.
    fn look_at_inputs(&mut self) {
        let inputs = self.world.digital_inputs;
        if inputs != self.io.last_inputs() {
            self.inputs_changed(inputs);
        }
        for m in 0..self.axes.len().min(self.io.switches_seen()) {
            let (l, r, _) = self.switches(m);
            if (l, r) != self.io.last_switches(m) {
                self.switches_changed(m, (l, r));
            }
        }
    }

    #[inline(never)]
    fn inputs_changed(&mut self, inputs: u32) {
        let changed = self.io.see_inputs(inputs);
        for n in 0..8u8 {
            if changed & (1 << n) != 0 {
                let rising = inputs & (1 << n) != 0;
                self.trigger(Source::InputChange(n), rising);
            }
        }
    }

    #[inline(never)]
    fn switches_changed(&mut self, m: usize, (l, r): (bool, bool)) {
        let (pl, pr) = self.io.see_switches(m, (l, r));
        if l != pl {
            self.trigger(Source::StopLeft(m as u8), l);
        }
        if r != pr {
            self.trigger(Source::StopRight(m as u8), r);
        }
    }

    /// An edge on an input: raise its interrupt if bank 3 selects the edge
    /// (0 off, 1 low→high, 2 high→low, 3 both).
    fn trigger(&mut self, source: Source, rising: bool) {
        let Some(n) = self.profile.interrupt_for(source) else { return };
        let mode = self.globals[3][n as usize];
        if mode == 3 || (mode == 1 && rising) || (mode == 2 && !rising) {
            self.raise(source);
        }
    }

    /// Runs until one more instruction has executed (a WAIT in progress
    /// first ends), then pauses; time stops at most `slice_ns` after it.
    /// Returns false when `limit_ns` came first. Front ends step with
    /// [`crate::Bus::step_instruction`].
    pub(crate) fn step_instruction(&mut self, limit_ns: u64, slice_ns: u64) -> bool {
        let before = self.program.executed;
        self.program.single_step = true;
        self.start_program();
        while self.program.executed == before && self.now_ns < limit_ns && self.program.mode == RunMode::Run {
            let next = if self.program.wait.is_some() {
                self.now_ns.saturating_add(slice_ns)
            } else {
                self.program.next_ns.max(self.now_ns.saturating_add(1))
            };
            self.advance_to(next.min(limit_ns));
        }
        self.program.single_step = false;
        self.pause_program();
        self.program.executed != before
    }

    /// Advances virtual time to an absolute time (no-op if in the past).
    pub(crate) fn advance_to(&mut self, t_ns: u64) {
        if t_ns > self.now_ns {
            self.advance(t_ns - self.now_ns);
        }
    }

    pub(crate) fn heartbeat_deadline(&self) -> Option<u64> {
        let hb = self.globals[0][gp::HEARTBEAT as usize];
        (hb > 0 && !self.link.heartbeat_tripped).then(|| self.link.last_frame_ns.saturating_add(hb as u64 * 1_000_000))
    }

    /// The next virtual time at which something happens on its own: a timer
    /// interrupt, the end of a WAIT, the next program instruction, a motor
    /// arriving or crossing a switch edge that a WAIT, an interrupt or a
    /// 138 event watches, a heartbeat stop, the driver's next measurement
    /// of a watched moving motor (docs/behaviour.md rule 81). `None`: nothing
    /// happens until a request comes. A deadline at or before now means
    /// "due now". `Module::advance` moves from one deadline to the next.
    pub fn next_deadline(&self) -> Option<u64> {
        self.deadline_after(self.next_timer())
    }

    /// [`Module::next_deadline`] with the timers' next firing given.
    fn deadline_after(&self, timer: Option<u64>) -> Option<u64> {
        earliest(self.world_deadline(timer), self.program_deadline())
    }

    /// The program's next instruction, or when its WAIT must be looked at
    /// again; `None` while it does not run.
    fn program_deadline(&self) -> Option<u64> {
        if !self.program.is_running() {
            None
        } else if self.program.wait.is_none() {
            Some(self.program.next_ns)
        } else if self.interrupt_ready() {
            // An interrupt is served during the WAIT.
            Some(self.now_ns)
        } else {
            self.wait_horizon()
        }
    }

    /// The next event of the world and the interrupt system (everything but
    /// the program's own next instruction or WAIT).
    fn world_deadline(&self, timer: Option<u64>) -> Option<u64> {
        self.world_deadline_and_quiet(timer).0
    }

    /// [`Module::world_deadline`], and whether the world is quiet.
    fn world_deadline_and_quiet(&self, timer: Option<u64>) -> (Option<u64>, Quiet) {
        let mut next = earliest(self.heartbeat_deadline(), timer);
        let watches = self.driver_watches();
        if watches {
            next = earliest(next, Some(self.now_ns.saturating_add(DRIVER_SAMPLE_NS)));
        }
        let armed = self.motion_interrupts_armed();
        let mut quiet = !watches && !armed && !self.profile.features.closed_loop;
        for (motor, axis) in self.axes.iter().enumerate() {
            quiet &= !axis.notify_on_arrival && axis.rfs.is_none();
            if axis.motion.v == 0.0 && !axis.notify_on_arrival && !armed {
                continue;
            }
            if axis.notify_on_arrival || armed {
                next = earliest(next, self.rest_deadline(motor));
            }
            if armed {
                next = earliest(next, self.edge_deadline(motor));
            }
        }
        (next, if quiet { Quiet::Yes } else { Quiet::No })
    }

    /// When the motor comes to rest, if it moves and will.
    fn rest_deadline(&self, motor: usize) -> Option<u64> {
        match self.time_to_rest(motor) {
            Some(s) if s > 0.0 => Some(self.now_ns.saturating_add((s * 1e9).ceil() as u64)),
            _ => None,
        }
    }

    /// When the carriage next reaches a switch edge (within an hour), by
    /// walking the planned ramp without moving.
    fn edge_deadline(&self, motor: usize) -> Option<u64> {
        if self.axes[motor].motion.v == 0.0 && self.time_to_rest(motor).is_some_and(|s| s <= 0.0) {
            return None;
        }
        let view = self.motor_view(motor);
        let (edges, count) = view.switch_edges();
        if count == 0 {
            return None;
        }
        let (ramp, chip) = (view.ramp(), view.chip());
        let mut probe = view.axis.motion.clone();
        let mut stops = |x: f64| view.stops_at(x);
        let step = probe.advance_on(EDGE_HORIZON_S, &ramp, chip.as_ref(), &mut stops, &edges[..count], true);
        step.crossed.map(|_| self.now_ns.saturating_add((step.elapsed * 1e9).ceil().max(1.0) as u64))
    }

    /// Timer `t`'s interrupt number and period in ns, while it runs (the
    /// program runs, the period is not 0, the interrupt is enabled).
    fn timer_period(&self, t: u8) -> Option<(u8, u64)> {
        if !self.program.is_running() {
            return None;
        }
        let n = self.profile.timer_interrupt(t)?;
        let period_ms = u64::from(self.globals[3][n as usize] as u32);
        (period_ms != 0 && self.interrupts.enabled[n as usize]).then_some((n, period_ms * 1_000_000))
    }

    /// The next firing of the timer interrupts, without firing them.
    fn next_timer(&self) -> Option<u64> {
        let mut next = None;
        for t in 0..3u8 {
            if let Some((_, period)) = self.timer_period(t) {
                next = earliest(next, Some(self.program.timers[t as usize].unwrap_or(self.now_ns.saturating_add(period))));
            }
        }
        next
    }

    fn time_to_rest(&self, motor: usize) -> Option<f64> {
        let view = self.motor_view(motor);
        let (ramp, chip) = (view.ramp(), view.chip());
        let mut stops = |x: f64| view.stops_at(x);
        view.axis.motion.time_to_rest_on(&ramp, chip.as_ref(), &mut stops)
    }

    fn advance_axis(&mut self, motor: usize, dt_ns: u64) {
        let (edges, count) = self.motor_view(motor).switch_edges();
        let edges = &edges[..count];
        let was_moving = self.axes[motor].motion.v != 0.0;
        let searching = self.axes[motor].rfs.is_some();
        let mut left = dt_ns as f64 * 1e-9;
        let mut stopped_at = None;
        let mut arrived = false;
        let mut elapsed = 0.0;
        // A reference search looks at every switch edge it passes; plain
        // motion goes through the whole step at once.
        for _ in 0..64 {
            let (ramp, chip) = (self.motor_view(motor).ramp(), self.motor_view(motor).chip());
            let x_before = self.axes[motor].motion.x;
            let step = if self.world.axes[motor].has_switch_positions() {
                let mut motion = std::mem::take(&mut self.axes[motor].motion);
                let view = self.motor_view(motor);
                let mut stops = |x: f64| view.stops_at(x);
                let step = motion.advance_on(left, &ramp, chip.as_ref(), &mut stops, edges, searching);
                self.axes[motor].motion = motion;
                step
            } else {
                // The switches read the same everywhere: so do the stops.
                let fixed = self.motor_view(motor).stops_at(x_before);
                self.axes[motor].motion.advance_on(left, &ramp, chip.as_ref(), &mut |_| fixed, edges, searching)
            };
            let alarms = self.motor_view_mut(motor).drive(x_before, step.elapsed);
            self.sound(motor, alarms);
            if let Some(t) = step.stopped_at {
                stopped_at = Some(elapsed + t);
            }
            elapsed += step.elapsed;
            left -= step.elapsed;
            arrived |= step.arrived;
            if searching {
                self.reference_search_step(motor, step.crossed.is_some(), step.arrived);
            }
            if !searching || step.crossed.is_none() || left <= 0.0 {
                break;
            }
        }
        // Time the motion did not use (standing still): the driver and the
        // closed loop still act.
        let rest = dt_ns as f64 * 1e-9 - elapsed;
        if rest > 1e-12 {
            let x = self.axes[motor].motion.x;
            let alarms = self.motor_view_mut(motor).drive(x, rest);
            self.sound(motor, alarms);
        }
        let moving = self.axes[motor].motion.v != 0.0;
        let axis = &mut self.axes[motor];
        if moving {
            axis.standstill_since = None;
        } else if let Some(t) = stopped_at {
            axis.standstill_since = Some(self.now_ns.saturating_add((t * 1e9) as u64));
        } else if was_moving || axis.standstill_since.is_none() {
            axis.standstill_since = Some(self.now_ns);
        }
        if arrived {
            axis.ramp_override = None;
        }
        if arrived && axis.notify_on_arrival {
            axis.notify_on_arrival = false;
            self.push_event(1 << motor);
        }
        if arrived && !searching {
            self.raise(Source::TargetReached(motor as u8));
        }
    }

    /// Runs instructions due at `now` (and pure ones after them, up to
    /// `limit`) without moving the world; returns when the world must catch
    /// up, the program stops or waits: true when the program still runs,
    /// does not wait and every instruction left the world as it was (its
    /// next event is still the one `limit` came from).
    pub(crate) fn run_batch(&mut self, limit: u64) -> bool {
        loop {
            self.take_interrupt();
            let pc = self.program.pc;
            if !self.program.breakpoints.is_empty()
                && self.program.breakpoints.binary_search(&pc).is_ok()
                && self.program.hit_breakpoint != Some(pc)
            {
                self.program.hit_breakpoint = Some(pc);
                self.program.mode = RunMode::Step;
                return false;
            }
            self.program.hit_breakpoint = None;
            let Some(ins) = self.program.memory.get(pc as usize).copied() else {
                self.program.mode = RunMode::Stop;
                return false;
            };
            // With the trace on, every instruction sees the world of its
            // own moment (positions in the trace are exact).
            let traced = self.program.trace.is_some();
            let pure = is_pure(ins) && !traced;
            if !pure && self.program.next_ns > self.now_ns {
                return true;
            }
            self.execute_next();
            // After an instruction that changed the world, `limit` is stale.
            let world_unchanged = pure || (observes_only(ins) && !traced);
            if !self.program.is_running() || self.program.wait.is_some() || !world_unchanged {
                return false;
            }
            if self.program.next_ns > limit {
                return true;
            }
        }
    }

    /// When the world must be looked at again for the WAIT in progress.
    pub(crate) fn wait_horizon(&self) -> Option<u64> {
        let w = self.program.wait?;
        let mut t = w.until_ns;
        let m = w.motor as usize;
        let candidate = match w.condition {
            WaitCondition::Ticks => None,
            // The ramp is known in closed form: wake up when it ends. At
            // rest off the target (a switch stopped it) nothing changes by
            // itself and only the timeout ends the wait; a motor that never
            // rests (velocity mode) may still meet a switch.
            WaitCondition::Position => match self.time_to_rest(m) {
                None => self.edge_deadline(m),
                Some(_) => self.rest_deadline(m),
            },
            // Switch waits end at the next edge the carriage reaches; a
            // reference search ends at an edge or where it arrives.
            WaitCondition::ReferenceSwitch | WaitCondition::LimitSwitch => self.edge_deadline(m),
            WaitCondition::ReferenceSearch => earliest(self.edge_deadline(m), self.rest_deadline(m)),
        };
        if let Some(c) = candidate {
            t = Some(t.map_or(c, |u| u.min(c)));
        }
        t
    }

    /// Interrupts that depend on motion are enabled: the world must then be
    /// looked at often (every millisecond) even while the program waits.
    pub(crate) fn motion_interrupts_armed(&self) -> bool {
        self.interrupts.global
            && self.program.is_running()
            && self.profile.interrupt_sources().iter().any(|&(source, n)| {
                self.interrupts.enabled[n as usize]
                    && matches!(
                        source,
                        Source::TargetReached(_) | Source::StopLeft(_) | Source::StopRight(_) | Source::Stall(_) | Source::Deviation(_)
                    )
            })
    }

    /// Timer interrupts: fire those due, return the next firing time.
    pub(crate) fn run_timers(&mut self) -> Option<u64> {
        let mut next = None;
        for t in 0..3u8 {
            let Some((n, period)) = self.timer_period(t) else {
                self.program.timers[t as usize] = None;
                continue;
            };
            let due = *self.program.timers[t as usize].get_or_insert(self.now_ns.saturating_add(period));
            if self.now_ns >= due {
                self.program.set_pending(n);
                let behind = (self.now_ns - due) / period + 1;
                self.program.timers[t as usize] = Some(due.saturating_add(behind.saturating_mul(period)));
            }
            let d = self.program.timers[t as usize].expect("set above");
            next = Some(next.map_or(d, |x: u64| x.min(d)));
        }
        next
    }

    /// Some moving axis has something the driver must look at often
    /// ([`crate::motor::Motor::watched`]).
    pub(crate) fn driver_watches(&self) -> bool {
        (0..self.axes.len()).any(|m| self.motor_view(m).watched())
    }
}

/// The world is quiet when its next event can only be the heartbeat's or a
/// timer's: the driver watches no motor, no interrupt or 138 event waits
/// for motion, no reference search runs, no closed loop regulates. World
/// steps keep it quiet (a motor only comes to rest, or stops when the
/// heartbeat trips), and so do instructions that leave the world as it was
/// ([`is_pure`], [`observes_only`]); any other instruction may end it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Quiet {
    Yes,
    No,
}

/// Instructions that read the world at their own moment (docs/behaviour.md
/// rule 81) but change nothing the world's next event depends on: pure
/// instructions after them may still run ahead of the world.
fn observes_only(ins: Instruction) -> bool {
    matches!(ins.opcode, opcode::GAP | opcode::GGP | opcode::GIO)
}

/// Instructions that touch neither the motors, the I/O nor time: a batch of
/// them runs without moving the world.
fn is_pure(ins: Instruction) -> bool {
    matches!(
        ins.opcode,
        opcode::CALC
            | opcode::COMP
            | opcode::JC
            | opcode::JA
            | opcode::CSUB
            | opcode::RSUB
            | opcode::CALCX
            | opcode::CLE
            | opcode::CALCVV
            | opcode::CALCVA
            | opcode::CALCAV
            | opcode::CALCVX
            | opcode::CALCXV
            | opcode::CALCV
            | opcode::DJNZ
            | opcode::SIV
            | opcode::GIV
            | opcode::AIV
            | opcode::CALL
            | opcode::RST
    ) || (matches!(ins.opcode, opcode::SGP | opcode::GGP) && ins.motor == 2)
}
