//! EtherCAT on a network interface needs raw Ethernet frames (an
//! AF_PACKET socket), which only Linux offers: elsewhere [`serve`] refuses,
//! before anything is opened.

use crate::eeprom_file::EepromFile;
use std::convert::Infallible;
use std::io;
use std::sync::{Arc, Mutex};
use tmclsim_ethercat::Segment;

/// A segment served on an interface, which is never made here.
pub struct EthercatHandle {
    /// The slaves.
    pub segment: Arc<Mutex<Segment>>,
    /// Frames processed and frames ignored (not EtherCAT or malformed).
    pub counters: Arc<Mutex<(u64, u64)>>,
    never: Infallible,
}

impl EthercatHandle {
    /// Stops the frame thread and waits until every EEPROM write is saved.
    pub fn stop(self) {
        match self.never {}
    }

    /// Waits until the frame thread ends and every EEPROM write is saved.
    pub fn wait(self) {
        match self.never {}
    }
}

/// Refuses: raw Ethernet is Linux's.
pub fn serve(iface: &str, _segment: Segment, _eeproms: Vec<Option<EepromFile>>) -> io::Result<EthercatHandle> {
    Err(io::Error::new(
        io::ErrorKind::Unsupported,
        format!(
            "EtherCAT on {iface} needs raw Ethernet (an AF_PACKET socket), which only Linux has: serve the slaves from a Linux machine"
        ),
    ))
}
