//! The TMCL program interpreter: one instruction at a time, with jumps,
//! WAIT, subroutines and interrupts; and the debugger's controls
//! (breakpoints, the trace). DJNZ and WAIT are in `commands/flow.rs`, the
//! control commands 128–135 in `control.rs`, the interpreter's clock and
//! the debugger's single step in `time.rs`.

use crate::module::Module;
use crate::outcome::Origin;
use crate::program::{RunMode, TraceRecord};
use tmclsim_protocol::{Command, Instruction, Status, opcode};

impl Module {
    // ----- the debugger -------------------------------------------------

    /// The TMCL program: its memory, counter, stack, timers and run mode.
    pub fn program(&self) -> &crate::program::Program {
        &self.program
    }

    /// Breakpoints: execution pauses (mode step) before these addresses.
    /// Sets the program's breakpoints: the addresses inside program memory,
    /// each once, in order (so at most one per word, and the interpreter
    /// finds one by a binary search).
    pub fn set_breakpoints(&mut self, addresses: &[u16]) {
        self.program.set_breakpoints(addresses);
    }

    /// Turns the instruction trace on or off.
    pub fn set_trace(&mut self, on: bool) {
        self.program.trace = on.then(Vec::new);
    }

    /// Trace records since the last call.
    pub fn take_trace(&mut self) -> Vec<TraceRecord> {
        self.program.trace.as_mut().map(std::mem::take).unwrap_or_default()
    }

    /// Virtual time per program instruction (default 25 µs).
    pub fn set_instruction_time_ns(&mut self, ns: u64) {
        self.program.instruction_ns = ns.max(1);
    }

    // ----- the interpreter ----------------------------------------------

    /// Executes the instruction at the program counter now (130). A WAIT
    /// still waiting is the step's instruction: its condition is looked at
    /// once, and the instruction after it waits for the next step
    /// (docs/behaviour.md rule 31).
    pub(crate) fn step_program(&mut self) {
        if self.program.wait.is_some() {
            self.check_wait();
            return;
        }
        self.take_interrupt();
        self.execute_next();
    }

    /// Executes the word at the program counter at time `program.next_ns`.
    pub(crate) fn execute_next(&mut self) {
        let pc = self.program.pc;
        let Some(ins) = self.program.memory.get(pc as usize).copied() else {
            self.program.mode = RunMode::Stop;
            return;
        };
        let at = self.program.next_ns.max(self.now_ns);
        self.program.pc = pc.wrapping_add(1);
        self.program.next_ns = at.saturating_add(self.program.instruction_ns);
        self.program.executed += 1;
        let failed = match self.program_instruction(ins, at) {
            Ok(()) => None,
            Err(status) => Some(status.code()),
        };
        if self.program.trace.is_some() {
            let axes = (0..self.axes.len()).map(|m| (self.actual_position(m), self.actual_speed(m))).collect();
            let record = TraceRecord { time_ns: at, pc, instruction: ins, registers: self.registers, failed, axes };
            if let Some(trace) = &mut self.program.trace {
                trace.push(record);
            }
        }
        if self.program.pc as usize >= self.program.memory.len() && self.program.mode == RunMode::Run {
            self.program.mode = RunMode::Stop;
        }
        if std::mem::take(&mut self.program.single_step) && self.program.mode == RunMode::Run {
            self.program.mode = RunMode::Step;
        }
    }

    /// One program instruction; `Err` when it failed and was skipped
    /// (docs/behaviour.md rule 21). The control commands are refused by
    /// opcode; every other command goes to the one dispatch.
    fn program_instruction(&mut self, ins: Instruction, at: u64) -> Result<(), Status> {
        if !self.profile.has_opcode(ins.opcode) || opcode::is_control(ins.opcode) {
            return Err(Status::InvalidCommand);
        }
        let cmd = Command::decode(ins).map_err(tmclsim_protocol::DecodeError::status)?;
        self.dispatch(cmd, ins, Origin::Program, at).map(|_| ())
    }

    /// Enters the handler of the most urgent pending interrupt, if the
    /// program may take one now (docs/behaviour.md rule 22).
    /// An enabled interrupt with a vector is pending and may be taken.
    pub(crate) fn interrupt_ready(&self) -> bool {
        self.interrupts.global
            && self.program.handler.is_none()
            && self.program.pending != [0; 4]
            && self.program.first_pending(|n| self.interrupts.serviceable(n)).is_some()
    }

    pub(crate) fn take_interrupt(&mut self) {
        if !self.interrupts.global || self.program.handler.is_some() || self.program.pending == [0; 4] {
            return;
        }
        let interrupts = &self.interrupts;
        let Some(n) = self.program.first_pending(|n| interrupts.serviceable(n)) else {
            return;
        };
        self.program.clear_pending(n);
        let vector = self.interrupts.vectors[n as usize].expect("checked");
        self.program.enter_handler(vector, self.registers, self.now_ns);
    }
}
