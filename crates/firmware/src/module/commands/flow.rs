//! The branch commands that need more than the program part: DJNZ (a
//! user variable) and WAIT (the motors, the switches, time), with the
//! check that ends a WAIT. The other branches (JA, JC, CSUB, CALL, RSUB,
//! RST, STOP, RETI) are the program part's (`program.rs`).

use crate::module::Module;
use crate::program::Wait;
use crate::state::registers::error_flag;
use tmclsim_protocol::{Status, WaitCondition};

/// Ten milliseconds: one WAIT tick.
const TICK_NS: u64 = 10_000_000;

impl Module {
    /// DJNZ: decrements a user variable and jumps while it stays above 0.
    pub(crate) fn decrement_and_jump(&mut self, var: u8, address: i32) -> Result<(), Status> {
        let a = self.program.target(address)?;
        let i = var as usize;
        if i >= self.profile.module.user_variables as usize {
            return Err(Status::InvalidValue);
        }
        let v = self.globals.user_variable(i).wrapping_sub(1);
        self.globals.set_user_variable(i, v);
        if v > 0 {
            self.program.pc = a;
        }
        Ok(())
    }

    /// WAIT: the program waits from `at` until the condition holds or the
    /// ticks (or the accumulator's, with -1) have passed.
    pub(crate) fn start_wait(&mut self, condition: WaitCondition, motor: u8, ticks: i32, at: u64) -> Result<(), Status> {
        let ticks = if ticks == -1 { self.registers.accumulator } else { ticks }.max(0) as u64;
        // Deadlines saturate: a WAIT that would end past the clock's range
        // ends never (docs/behaviour.md rule 84).
        let until = (ticks > 0 || condition == WaitCondition::Ticks).then_some(at.saturating_add(ticks.saturating_mul(TICK_NS)));
        if condition != WaitCondition::Ticks {
            self.motor(motor)?;
        }
        self.program.wait = Some(Wait { condition, motor, until_ns: until });
        self.check_wait();
        Ok(())
    }

    /// Ends a WAIT whose condition holds or whose time is up.
    pub(crate) fn check_wait(&mut self) {
        let Some(w) = self.program.wait else { return };
        let m = w.motor as usize;
        let met = match w.condition {
            WaitCondition::Ticks => w.until_ns.is_none_or(|u| self.now_ns >= u),
            WaitCondition::Position => self.actual_position(m) == self.axes[m].target_word && self.axes[m].motion.v == 0.0,
            WaitCondition::ReferenceSwitch => self.switches(m).2,
            WaitCondition::LimitSwitch => {
                let (l, r, _) = self.switches(m);
                l || r
            }
            WaitCondition::ReferenceSearch => !self.axes[m].reference_search_active(),
        };
        if met {
            self.program.wait = None;
        } else if w.condition != WaitCondition::Ticks && w.until_ns.is_some_and(|u| self.now_ns >= u) {
            self.registers.errors |= error_flag::TIMEOUT;
            self.program.wait = None;
        }
        if self.program.wait.is_none() {
            self.program.next_ns = self.program.next_ns.max(self.now_ns);
        }
    }
}
