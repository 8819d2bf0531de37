//! Standalone TMCL programs: program memory, the interpreter's state,
//! interrupts and the trace.
//!
//! The interpreter itself lives in `interpreter.rs`; this file holds the
//! data it works on, so that a reader sees the machine before the loop,
//! and the control flow of the branch commands (jumps, the subroutine
//! stack, entering and leaving an interrupt handler), which touches
//! nothing but the program's own state.

use crate::link_id::LinkId;
use crate::state::registers::Registers;
use tmclsim_protocol::{Instruction, Status, WaitCondition};

/// Subroutine stack depth (manual 3.7.20, 3.7.44).
pub const STACK_DEPTH: usize = 8;

/// Virtual time one program instruction takes by default: 25 µs, i.e.
/// 40 000 instructions per second (docs/behaviour.md rule 20).
pub const DEFAULT_INSTRUCTION_NS: u64 = 25_000;

/// GP 128 / 135: what the interpreter is doing.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum RunMode {
    #[default]
    /// Not running.
    Stop = 0,
    /// Running.
    Run = 1,
    /// Paused in step mode: the next instruction runs on a step command.
    Step = 2,
    /// Stopped by a reset (131): counter and registers back at 0.
    Reset = 3,
}

/// A WAIT in progress.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Wait {
    /// What the WAIT waits for.
    pub condition: WaitCondition,
    /// The motor a WAIT on a motor's state watches.
    pub motor: u8,
    /// WAIT TICKS: when it ends; the others: when they time out (`None`:
    /// no timeout).
    pub until_ns: Option<u64>,
}

/// What an interrupt saves and RETI restores.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Context {
    /// Accumulator, X register and flags.
    pub registers: Registers,
    /// The program counter.
    pub pc: u16,
    /// The WAIT in progress, if any.
    pub wait: Option<Wait>,
}

/// What raises an interrupt, derived from the profile's interrupt table.
pub use tmclsim_profile::InterruptSource as Source;

/// One executed instruction, for `--trace` and the debugger.
#[derive(Clone, Debug, PartialEq)]
pub struct TraceRecord {
    /// Virtual time at which the instruction ran.
    pub time_ns: u64,
    /// Address of the instruction.
    pub pc: u16,
    /// The instruction as it was fetched.
    pub instruction: Instruction,
    /// Registers after the instruction.
    pub registers: Registers,
    /// Status when the command failed and was skipped (docs/behaviour.md rule 21).
    pub failed: Option<u8>,
    /// Per axis after the instruction: actual position and actual speed
    /// (internal units).
    pub axes: Vec<(i32, i32)>,
}

/// What download mode means for a frame from one link.
pub(crate) enum Download {
    /// No download is going on.
    Off,
    /// This link downloads: its words are stored.
    Owner,
    /// Another link downloads: this one talks to the module in direct mode.
    Other,
}

/// The interpreter's state.
#[derive(Clone, Debug)]
pub struct Program {
    /// Program memory, one instruction per address.
    pub memory: Vec<Instruction>,
    /// What the interpreter is doing (GP 128).
    pub mode: RunMode,
    /// Address of the next instruction.
    pub pc: u16,
    /// Return addresses of CSUB (at most `STACK_DEPTH`).
    pub stack: Vec<u16>,
    /// The WAIT in progress, if any.
    pub wait: Option<Wait>,
    /// In an interrupt handler: the interrupted context.
    pub handler: Option<Context>,
    /// Pending interrupts, one bit per interrupt number.
    pub pending: [u64; 4],
    /// Virtual time at which the next instruction runs.
    pub next_ns: u64,
    /// Virtual time one instruction takes, in ns (`DEFAULT_INSTRUCTION_NS`
    /// unless set).
    pub instruction_ns: u64,
    /// Download mode: the address the next stored word goes to.
    pub download: Option<u16>,
    /// Address after the last downloaded word (135 type 0).
    pub download_pointer: u16,
    /// The link whose frames download mode stores (docs/behaviour.md
    /// rule 91); `None`: the next link that speaks.
    pub download_owner: Option<LinkId>,
    /// Next firing time of timers 0…2.
    pub timers: [Option<u64>; 3],
    /// Addresses at which execution pauses (the debugger's breakpoints).
    pub breakpoints: Vec<u16>,
    /// Set when execution stopped at a breakpoint.
    pub hit_breakpoint: Option<u16>,
    /// Executed instructions recorded while tracing is on (`None`: off).
    pub trace: Option<Vec<TraceRecord>>,
    /// Instructions executed since power-up.
    pub executed: u64,
    /// Pause (step mode) after the next instruction.
    pub single_step: bool,
}

impl Program {
    /// An empty program of `words` instructions, stopped, at address 0.
    pub fn new(words: usize) -> Program {
        Program {
            memory: vec![Instruction::default(); words],
            mode: RunMode::Stop,
            pc: 0,
            stack: Vec::with_capacity(STACK_DEPTH),
            wait: None,
            handler: None,
            pending: [0; 4],
            next_ns: 0,
            instruction_ns: DEFAULT_INSTRUCTION_NS,
            download: None,
            download_pointer: 0,
            download_owner: None,
            timers: [None; 3],
            breakpoints: Vec::new(),
            hit_breakpoint: None,
            trace: None,
            executed: 0,
            single_step: false,
        }
    }

    /// True while the program runs (GP 128 = 1).
    pub fn is_running(&self) -> bool {
        matches!(self.mode, RunMode::Run)
    }

    /// The program counter as the module reports it (GP 130, 135 type 1):
    /// during a WAIT it is held at the WAIT's own address
    /// (docs/behaviour.md rule 35); `pc` already points past it.
    pub fn counter(&self) -> u16 {
        if self.wait.is_some() { self.pc.wrapping_sub(1) } else { self.pc }
    }

    /// Marks interrupt `n` pending.
    pub fn set_pending(&mut self, n: u8) {
        self.pending[n as usize / 64] |= 1 << (n % 64);
    }

    /// Clears interrupt `n`'s pending mark.
    pub fn clear_pending(&mut self, n: u8) {
        self.pending[n as usize / 64] &= !(1 << (n % 64));
    }

    /// True when interrupt `n` is pending.
    pub fn is_pending(&self, n: u8) -> bool {
        self.pending[n as usize / 64] & (1 << (n % 64)) != 0
    }

    /// Download mode as link `link` meets it; a download whose owner is
    /// gone passes to the link that speaks next.
    pub(crate) fn download_role(&mut self, link: LinkId) -> Download {
        if self.download.is_none() {
            return Download::Off;
        }
        match self.download_owner {
            Some(owner) if owner != link => Download::Other,
            _ => {
                self.download_owner = Some(link);
                Download::Owner
            }
        }
    }

    /// Link `link` is gone: a download it owned waits for the next link
    /// that speaks (docs/behaviour.md rule 91).
    pub fn release_download(&mut self, link: LinkId) {
        if self.download_owner == Some(link) {
            self.download_owner = None;
        }
    }

    /// Sets the breakpoints: the addresses inside program memory, each
    /// once, in order (so at most one per word, and the interpreter finds
    /// one by a binary search).
    pub fn set_breakpoints(&mut self, addresses: &[u16]) {
        let words = self.memory.len();
        let mut kept: Vec<u16> = addresses.iter().copied().filter(|&a| usize::from(a) < words).collect();
        kept.sort_unstable();
        kept.dedup();
        self.breakpoints = kept;
    }

    /// Pauses a running program (step mode), as a debugger does.
    pub fn pause(&mut self) {
        if self.mode == RunMode::Run {
            self.mode = RunMode::Step;
        }
    }

    /// Lowest pending interrupt number for which `ready` holds.
    pub fn first_pending(&self, ready: impl Fn(u8) -> bool) -> Option<u8> {
        for (w, bits) in self.pending.iter().enumerate() {
            let mut b = *bits;
            while b != 0 {
                let n = (w * 64) as u8 + b.trailing_zeros() as u8;
                if ready(n) {
                    return Some(n);
                }
                b &= b - 1;
            }
        }
        None
    }

    /// 131: stop, program counter and stack to zero, registers cleared.
    pub fn reset(&mut self) {
        self.mode = RunMode::Stop;
        self.pc = 0;
        self.stack.clear();
        self.wait = None;
        self.handler = None;
        self.pending = [0; 4];
        self.hit_breakpoint = None;
    }

    /// STOP: the program ends.
    pub fn stop(&mut self) {
        self.mode = RunMode::Stop;
    }

    // ----- program control, 128–135: the host's part ----------------

    /// 128: stops the program; a reset program stays reset.
    pub fn stop_application(&mut self) {
        if self.mode != RunMode::Reset {
            self.mode = RunMode::Stop;
        }
    }

    /// 129 with an address: the program goes on from there, with an empty
    /// stack, no handler and no WAIT.
    pub fn run_from(&mut self, address: i32) -> Result<(), Status> {
        let a = self.target(address)?;
        self.restart_at(a);
        self.hit_breakpoint = None;
        Ok(())
    }

    /// 130: step mode; the next instruction runs now.
    pub fn step_mode(&mut self, now_ns: u64) {
        self.mode = RunMode::Step;
        self.hit_breakpoint = None;
        self.next_ns = now_ns;
    }

    /// 131: reset (the caller clears the registers).
    pub fn reset_application(&mut self) {
        self.reset();
        self.mode = RunMode::Reset;
    }

    /// 132: download mode from `address` on; the program stops.
    pub fn enter_download(&mut self, address: i32) -> Result<(), Status> {
        let a = self.target(address)?;
        self.mode = RunMode::Stop;
        self.download = Some(a);
        self.download_pointer = a;
        Ok(())
    }

    /// 133: leaves download mode; true when it was on.
    pub fn exit_download(&mut self) -> bool {
        self.download.take().is_some()
    }

    /// Stores a word in download mode and moves on: the address it went to.
    pub fn store_download(&mut self, ins: Instruction) -> Result<u16, Status> {
        let address = self.download.ok_or(Status::NotAvailable)?;
        let slot = self.memory.get_mut(address as usize).ok_or(Status::InvalidValue)?;
        *slot = ins;
        self.download = Some(address + 1);
        self.download_pointer = address + 1;
        Ok(address)
    }

    /// 134: the word at `address`, unless the program is protected against
    /// reading.
    pub fn read(&self, address: i32, read_protected: bool) -> Result<Instruction, Status> {
        if !(0..self.memory.len() as i32).contains(&address) {
            return Err(Status::InvalidValue);
        }
        if read_protected {
            return Err(Status::EepromLocked);
        }
        Ok(self.memory[address as usize])
    }

    /// 135 types 0 and 1: mode, whether a WAIT waits, and the download
    /// pointer (type 0) or the program counter (1).
    pub fn status_word(&self, kind: u8) -> i32 {
        let address = if kind == 0 { self.download_pointer } else { self.counter() };
        ((self.mode as i32) << 24) | (i32::from(self.wait.is_some()) << 16) | i32::from(address)
    }

    /// Loads a program from address 0 (the rest of memory empties); the
    /// program stops.
    pub fn load(&mut self, words: &[Instruction]) -> Result<(), Status> {
        if words.len() > self.memory.len() {
            return Err(Status::InvalidValue);
        }
        self.mode = RunMode::Stop;
        for (a, w) in self.memory.iter_mut().enumerate() {
            *w = words.get(a).copied().unwrap_or_default();
        }
        self.download_pointer = words.len() as u16;
        Ok(())
    }

    /// Empties program memory and resets the interpreter (lifting the code
    /// protection against reading, SGP 81).
    pub fn erase(&mut self) {
        for w in &mut self.memory {
            *w = Instruction::default();
        }
        self.reset();
    }

    /// Length of the program: up to the last word that is not empty.
    pub fn length(&self) -> usize {
        self.memory.iter().rposition(|i| *i != Instruction::default()).map_or(0, |p| p + 1)
    }

    // ----- the control flow: the branch commands' part of the machine ---

    /// A branch target: an address inside program memory.
    pub fn target(&self, address: i32) -> Result<u16, Status> {
        if (0..self.memory.len() as i32).contains(&address) { Ok(address as u16) } else { Err(Status::InvalidValue) }
    }

    /// JA: goes on at `address`.
    pub fn jump(&mut self, address: i32) -> Result<(), Status> {
        self.pc = self.target(address)?;
        Ok(())
    }

    /// JC: goes on at `address` when the condition holds (the address is
    /// checked either way).
    pub fn jump_if(&mut self, holds: bool, address: i32) -> Result<(), Status> {
        let a = self.target(address)?;
        if holds {
            self.pc = a;
        }
        Ok(())
    }

    /// CSUB (`holds` true), CALL: calls the subroutine at `address` when
    /// the condition holds (the address is checked either way).
    pub fn call_if(&mut self, holds: bool, address: i32) -> Result<(), Status> {
        let a = self.target(address)?;
        if holds {
            self.call(a);
        }
        Ok(())
    }

    /// CSUB, CALL: the return address goes on the stack; a call with a
    /// full stack is ignored (manual 3.7.44).
    pub fn call(&mut self, address: u16) {
        if self.stack.len() < STACK_DEPTH {
            self.stack.push(self.pc);
            self.pc = address;
        }
    }

    /// RSUB; on an empty stack it is ignored.
    pub fn return_from_subroutine(&mut self) {
        if let Some(ret) = self.stack.pop() {
            self.pc = ret;
        }
    }

    /// RST: the stack, the interrupt handler and the WAIT are dropped and
    /// the program goes on at `address` (the caller clears the registers).
    pub fn restart_at(&mut self, address: u16) {
        self.stack.clear();
        self.handler = None;
        self.wait = None;
        self.pc = address;
    }

    /// Enters the handler at `vector` from where the program is: its
    /// registers, counter and WAIT are kept for RETI.
    pub fn enter_handler(&mut self, vector: u16, registers: Registers, now_ns: u64) {
        self.handler = Some(Context { registers, pc: self.pc, wait: self.wait.take() });
        self.pc = vector;
        self.next_ns = self.next_ns.max(now_ns);
    }

    /// RETI: back to where the handler was entered, with the registers to
    /// restore; `None` outside a handler (ignored).
    pub fn return_from_interrupt(&mut self) -> Option<Registers> {
        let ctx = self.handler.take()?;
        self.pc = ctx.pc;
        self.wait = ctx.wait;
        Some(ctx.registers)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interrupt_sources_from_symbols() {
        assert_eq!(Source::from_symbol("TI_TIMER2"), Some(Source::Timer(2)));
        assert_eq!(Source::from_symbol("TI_INPUTCHANGE3"), Some(Source::InputChange(3)));
        assert_eq!(Source::from_symbol("TI_STOPRIGHT0"), Some(Source::StopRight(0)));
        assert_eq!(Source::from_symbol("TI_GLOBAL"), None);
    }

    #[test]
    fn pending_interrupts_by_priority() {
        let mut p = Program::new(16);
        p.set_pending(40);
        p.set_pending(3);
        p.set_pending(200);
        assert_eq!(p.first_pending(|_| true), Some(3));
        assert_eq!(p.first_pending(|n| n > 3), Some(40));
        p.clear_pending(40);
        assert_eq!(p.first_pending(|n| n > 3), Some(200));
    }

    #[test]
    fn control_flow_owns_the_stack_and_the_handler() {
        let mut p = Program::new(16);
        assert_eq!(p.target(15), Ok(15));
        assert_eq!(p.target(16), Err(Status::InvalidValue), "outside program memory");
        assert_eq!(p.target(-1), Err(Status::InvalidValue));
        p.pc = 3;
        for _ in 0..STACK_DEPTH + 2 {
            p.call(10);
        }
        assert_eq!(p.stack.len(), STACK_DEPTH, "a call with a full stack is ignored");
        for _ in 0..STACK_DEPTH + 2 {
            p.return_from_subroutine();
        }
        assert_eq!(p.pc, 3, "back where the first call came from; RSUB on an empty stack is ignored");
        assert_eq!(p.return_from_interrupt(), None, "RETI outside a handler");
        let registers = Registers { accumulator: 7, ..Registers::default() };
        p.wait = Some(Wait { condition: WaitCondition::Ticks, motor: 0, until_ns: Some(5) });
        p.enter_handler(12, registers, 100);
        assert_eq!((p.pc, p.wait, p.next_ns), (12, None, 100), "the handler does not wait");
        assert_eq!(p.return_from_interrupt(), Some(registers));
        assert_eq!(p.pc, 3);
        assert!(p.wait.is_some(), "the WAIT goes on after RETI");
        p.call(9);
        p.restart_at(4);
        assert!((p.stack.is_empty(), p.handler, p.wait) == (true, None, None) && p.pc == 4);
    }
}
