//! Slaves in a line: a frame passes through each in turn, as on the
//! wire, and comes back from the last one.

use crate::frame;
use crate::slave::Slave;

pub struct Segment {
    pub slaves: Vec<Slave>,
}

impl Segment {
    pub fn new(mut slaves: Vec<Slave>) -> Segment {
        let n = slaves.len();
        for (i, s) in slaves.iter_mut().enumerate() {
            s.esc.next_port_open = i + 1 < n;
        }
        Segment { slaves }
    }

    /// Processes a frame at virtual time `now_ns`; `false` when it is not
    /// an EtherCAT frame or is malformed (an ESC drops it unchanged).
    pub fn process(&mut self, frame: &mut [u8], now_ns: u64) -> bool {
        let Some(datagrams) = frame::datagrams(frame) else { return false };
        for slave in &mut self.slaves {
            slave.before_frame(now_ns);
            for d in &datagrams {
                slave.esc.datagram(frame, *d);
            }
            slave.after_frame(now_ns);
        }
        // Frames that passed a slave carry its mark in the source address.
        frame[6] |= 0x02;
        true
    }
}
