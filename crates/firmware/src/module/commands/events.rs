//! Interrupts and events: EI, DI, VECT and 138 are the interrupt part's
//! (`state/interrupts.rs`); here what raises an interrupt (a source the
//! program enabled, the alarms of a driver step) and the event frames that
//! the arrival of an armed move produces, addressed as the link last spoke.

use crate::module::Module;
use crate::motor::Alarms;
use crate::program::Source;
use crate::state::registers::error_flag;
use tmclsim_protocol::{FRAME_LEN, Reply, Status, opcode};

impl Module {
    /// Unsolicited frames (138 events) produced since the last call.
    pub fn take_events(&mut self) -> Vec<[u8; FRAME_LEN]> {
        self.interrupts.take_events()
    }

    /// True when 138 event frames are waiting to be taken (`take_events`).
    pub fn has_events(&self) -> bool {
        self.interrupts.has_events()
    }

    /// Raises the interrupt of a source, if the program has it enabled.
    pub(crate) fn raise(&mut self, source: Source) {
        if !self.program.is_running() {
            return;
        }
        if let Some(n) = self.profile.interrupt_for(source)
            && self.interrupts.enabled[n as usize]
        {
            self.program.set_pending(n);
        }
    }

    /// Raises what a driver step of axis `m` found: a stall, a deviation
    /// (with its error flag).
    pub(crate) fn sound(&mut self, m: usize, alarms: Alarms) {
        if alarms.stall {
            self.raise(Source::Stall(m as u8));
        }
        if alarms.deviation {
            self.registers.errors |= error_flag::DEVIATION;
            self.raise(Source::Deviation(m as u8));
        }
    }

    /// Queues a 138 event frame for the motors of `mask`, addressed as the
    /// link last spoke.
    pub(crate) fn push_event(&mut self, mask: u32) {
        let reply = Reply::new(self.host_address(), self.link.last_address, Status::Event, opcode::TARGET_REACHED_EVENT, mask as i32);
        self.interrupts.push_event(reply.encode());
    }
}

#[cfg(test)]
mod tests {
    use crate::test_support::{MS, direct, module, ok, status};
    use tmclsim_protocol::{Reply, Status};

    #[test]
    fn ei_di_and_vect() {
        let mut m = module("tmcm-1141");
        ok(&mut m, "EI 0");
        assert!(m.interrupts.enabled[0] && !m.interrupts.global);
        ok(&mut m, "EI 255");
        assert!(m.interrupts.global);
        ok(&mut m, "DI 0");
        assert!(!m.interrupts.enabled[0]);
        ok(&mut m, "DI 255");
        assert!(!m.interrupts.global);
        assert_eq!(status(&mut m, "EI 4"), Status::WrongType, "no interrupt 4 on the TMCM-1141");
        ok(&mut m, "VECT 0, 50");
        assert_eq!(m.interrupts.vectors[0], Some(50));
        assert_eq!(status(&mut m, "VECT 255, 50"), Status::WrongType);
        assert_eq!(status(&mut m, "VECT 0, 2048"), Status::InvalidValue, "outside program memory");
        assert_eq!(status(&mut m, "VECT 0, -1"), Status::InvalidValue);
    }

    #[test]
    fn arming_138_checks_the_mask() {
        let mut m = module("tmcm-1141");
        assert_eq!(direct(&mut m, "#138 0 0 1"), (Status::Ok, 1));
        assert_eq!(m.interrupts.event_arm(), Some((false, 1)));
        assert_eq!(direct(&mut m, "#138 1 0 1"), (Status::Ok, 1));
        assert_eq!(m.interrupts.event_arm(), Some((true, 1)));
        assert_eq!(status(&mut m, "#138 0 0 2"), Status::InvalidValue, "one motor");
        assert_eq!(status(&mut m, "#138 0 0 0"), Status::InvalidValue);
        assert_eq!(status(&mut m, "#138 0 0 -1"), Status::InvalidValue);
        assert_eq!(m.interrupts.event_arm(), Some((true, 1)), "a refused arming changes nothing");
        let mut m = module("tmcm-351");
        assert_eq!(status(&mut m, "#138 0 0 4"), Status::Ok, "three motors: bits 0…2");
        assert_eq!(status(&mut m, "#138 0 0 8"), Status::InvalidValue);
    }

    #[test]
    fn the_next_move_reports_its_arrival_once() {
        let mut m = module("tmcm-1141");
        ok(&mut m, "SAP 4, 0, 2047");
        ok(&mut m, "#138 0 0 1");
        ok(&mut m, "MVP ABS, 0, 2000");
        assert!(m.interrupts.event_arm().is_none(), "used up by the move");
        m.advance(1_000 * MS);
        let events = m.take_events();
        assert_eq!(events.len(), 1);
        let e = Reply::decode(&events[0]).unwrap();
        assert_eq!((e.status, e.opcode, e.value), (Status::Event.code(), 138, 1));
        ok(&mut m, "MVP ABS, 0, 0");
        m.advance(1_000 * MS);
        assert!(!m.has_events());
    }

    #[test]
    fn every_move_and_a_move_already_there() {
        let mut m = module("tmcm-1141");
        ok(&mut m, "#138 1 0 1");
        ok(&mut m, "MVP ABS, 0, 0");
        assert_eq!(m.take_events().len(), 1, "already at the target: at once");
        ok(&mut m, "MVP ABS, 0, 0");
        assert_eq!(m.take_events().len(), 1, "armed for every move");
        ok(&mut m, "ROR 0, 10");
        assert!(!m.axes[0].notify_on_arrival);
    }
}
