//! Slaves in a line: a frame passes through each in turn, as on the
//! wire, and comes back from the last one. The modules behind the slaves
//! are a [`Bus`] (one clock for the segment; EEPROM writes and events are
//! its effects, as on every other front end).

use crate::frame;
use crate::identity::{Identity, NotASlave};
use crate::slave::Slave;
use tmclsim_firmware::{Bus, Module};

/// EtherCAT slaves in a line, each in front of a module.
pub struct Segment {
    /// The slaves, in the order a frame passes them.
    pub(crate) slaves: Vec<Slave>,
    /// The modules, slave `i` in front of module `i`.
    pub bus: Bus,
}

impl Segment {
    /// One slave per module, in line, with serial numbers 1, 2, …; an
    /// error names a module whose profile makes it no EtherCAT slave.
    pub fn new(modules: Vec<Module>) -> Result<Segment, NotASlave> {
        let n = modules.len();
        let slaves = modules
            .iter()
            .enumerate()
            .map(|(i, m)| {
                let mut s = Slave::new(Identity::required(m.profile())?, 1 + i as u32);
                s.esc.next_port_open = i + 1 < n;
                Ok(s)
            })
            .collect::<Result<_, NotASlave>>()?;
        Ok(Segment { slaves, bus: Bus::new(modules) })
    }

    /// Processes a frame at the bus clock's now; `false` when it is not an
    /// EtherCAT frame or is malformed (an ESC drops it unchanged).
    pub fn process(&mut self, frame: &mut [u8]) -> bool {
        let Some(datagrams) = frame::datagrams(frame) else { return false };
        self.bus.catch_up();
        let now_ns = self.bus.now_ns();
        for (i, slave) in self.slaves.iter_mut().enumerate() {
            let module = self.bus.module_mut(i);
            slave.before_frame(module, now_ns);
            for d in &datagrams {
                slave.esc.datagram(frame, *d);
            }
            slave.after_frame(module, now_ns);
        }
        // Frames that passed a slave carry its mark in the source address.
        frame[6] |= 0x02;
        true
    }
}
