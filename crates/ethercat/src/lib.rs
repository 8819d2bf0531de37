//! A software EtherCAT slave: the TMCM-1310's EtherCAT side. Its identity
//! comes from the module's profile (`[features.ethercat]`); its process
//! image and object dictionary are the TMCM-1310's.
//!
//! - `frame.rs`: Ethernet frames of EtherType 0x88A4 and their datagrams;
//! - `esc.rs`: the EtherCAT slave controller: registers, station address,
//!   DL status, SII EEPROM access, SyncManagers, FMMUs, the AL state
//!   machine and the datagram commands with their working counters;
//! - `identity.rs`: how a slave names itself, from its module's profile;
//! - `sii.rs`: the SII EEPROM image (identity, mailbox, PDO description);
//! - `mailbox.rs`: CoE SDO transfers, which carry TMCL (object 0x2000);
//! - `slave.rs`: one TMCM-1310 behind an ESC: process data and mailbox;
//! - `segment.rs`: slaves in a line, one frame passing through all of them.
//!
//! Pure and deterministic: a segment takes a frame and the time and
//! returns the frame as it leaves the last slave. The raw-socket link
//! lives in the server crate.

mod esc;
pub mod frame;
pub mod identity;
mod mailbox;
pub mod segment;
mod sii;
mod slave;

pub use identity::{Identity, NotASlave};
pub use segment::Segment;
