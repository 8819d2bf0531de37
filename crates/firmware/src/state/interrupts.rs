//! The interrupt part: the configuration (enabled flags, vectors, the
//! global enable) that EI, DI and VECT set, and the target-reached events
//! of 138: which motors are armed and the event frames waiting to go out.

use tmclsim_profile::Profile;
use tmclsim_protocol::{FRAME_LEN, Status};

#[derive(Clone, Debug)]
pub struct Interrupts {
    pub enabled: [bool; 256],
    pub vectors: [Option<u16>; 256],
    /// EI 255 / DI 255.
    pub global: bool,
    /// 138: arm for the next MVP (`Some(false)`) or every MVP (`Some(true)`),
    /// with the motor mask.
    event_arm: Option<(bool, u32)>,
    /// Event frames not yet taken.
    events: Vec<[u8; FRAME_LEN]>,
}

impl Default for Interrupts {
    fn default() -> Interrupts {
        Interrupts { enabled: [false; 256], vectors: [None; 256], global: false, event_arm: None, events: Vec::new() }
    }
}

impl Interrupts {
    /// Power-up: everything off, no event armed or waiting.
    pub fn reset(&mut self) {
        self.enabled = [false; 256];
        self.vectors = [None; 256];
        self.global = false;
        self.event_arm = None;
        self.events.clear();
    }

    /// The 138 arming: `Some((every_move, mask))`, or `None` when no
    /// event is armed.
    #[cfg(test)]
    pub fn event_arm(&self) -> Option<(bool, u32)> {
        self.event_arm
    }

    /// Queues an event frame (138) for the front end to send.
    pub fn push_event(&mut self, frame: [u8; FRAME_LEN]) {
        self.events.push(frame);
    }

    /// The event frames queued since the last call, oldest first.
    pub fn take_events(&mut self) -> Vec<[u8; FRAME_LEN]> {
        std::mem::take(&mut self.events)
    }

    /// True when event frames are queued.
    pub fn has_events(&self) -> bool {
        !self.events.is_empty()
    }

    /// EI, DI: interrupt 255 is the global enable; the others must be in
    /// the profile's interrupt table.
    pub fn enable(&mut self, profile: &Profile, interrupt: u8, on: bool) -> Result<(), Status> {
        if interrupt == 255 {
            self.global = on;
        } else {
            profile.interrupt(interrupt).ok_or(Status::WrongType)?;
            self.enabled[interrupt as usize] = on;
        }
        Ok(())
    }

    /// VECT: the handler of an interrupt, an address inside program memory.
    pub fn set_vector(&mut self, profile: &Profile, interrupt: u8, address: i32) -> Result<(), Status> {
        if interrupt == 255 || profile.interrupt(interrupt).is_none() {
            return Err(Status::WrongType);
        }
        if address < 0 || address >= i32::from(profile.module.program_memory) {
            return Err(Status::InvalidValue);
        }
        self.vectors[interrupt as usize] = Some(address as u16);
        Ok(())
    }

    /// 138: arms the target-reached events of the motors in `mask` (of
    /// `axes` motors) for the next move or every move; the reply carries
    /// the mask.
    pub fn arm_events(&mut self, every_move: bool, mask: i32, axes: usize) -> Result<i32, Status> {
        let valid = (1u32 << axes) - 1;
        if mask <= 0 || mask as u32 & !valid != 0 {
            return Err(Status::InvalidValue);
        }
        self.event_arm = Some((every_move, mask as u32));
        Ok(mask)
    }

    /// Interrupt `n` is enabled and has a vector: a program can take it.
    pub fn serviceable(&self, n: u8) -> bool {
        self.enabled[n as usize] && self.vectors[n as usize].is_some()
    }

    /// An MVP of motor `m` starts: whether its arrival must be reported.
    /// Arming for the next move only is used up by it.
    pub fn claim_arrival_event(&mut self, m: usize) -> bool {
        let Some((every, mask)) = self.event_arm else { return false };
        if mask & (1 << m) == 0 {
            return false;
        }
        if !every {
            self.event_arm = None;
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn serviceable_needs_enable_and_vector() {
        let mut i = Interrupts::default();
        i.enabled[3] = true;
        assert!(!i.serviceable(3));
        i.vectors[3] = Some(10);
        assert!(i.serviceable(3));
        i.enabled[3] = false;
        assert!(!i.serviceable(3));
    }

    #[test]
    fn arming_for_the_next_move_is_used_up() {
        let mut i = Interrupts { event_arm: Some((false, 0b10)), ..Interrupts::default() };
        assert!(!i.claim_arrival_event(0), "motor 0 is not in the mask");
        assert_eq!(i.event_arm, Some((false, 0b10)));
        assert!(i.claim_arrival_event(1));
        assert!(!i.claim_arrival_event(1));
        assert_eq!(i.event_arm, None);
    }

    #[test]
    fn arming_for_every_move_stays() {
        let mut i = Interrupts { event_arm: Some((true, 0b11)), ..Interrupts::default() };
        assert!(i.claim_arrival_event(0) && i.claim_arrival_event(1) && i.claim_arrival_event(0));
    }

    #[test]
    fn reset_turns_everything_off() {
        let mut i = Interrupts { global: true, event_arm: Some((true, 1)), events: vec![[0; FRAME_LEN]], ..Interrupts::default() };
        i.enabled[5] = true;
        i.vectors[5] = Some(1);
        i.reset();
        assert!(!i.global && i.event_arm.is_none() && i.events.is_empty() && !i.enabled[5] && i.vectors[5].is_none());
    }
}
