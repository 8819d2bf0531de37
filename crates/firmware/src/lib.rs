//! The TMCL firmware as software: the command executor, EEPROM, the TMC429
//! motion model and the simulated world, for the module profiles of
//! `tmclsim-profile` (re-exported as [`profile`]).
//!
//! Pure and deterministic: a [`Module`] changes only through
//! [`Module::handle_frame`] / [`Module::execute`] and the passing of
//! virtual time, which only a [`Bus`] moves ([`Bus::advance_to`]).

pub mod bootloader;
pub mod bus;
pub mod clock;
pub mod closed_loop;
pub mod driver;
pub mod eeprom;
pub mod eeprom_rules;
pub mod link_id;
mod mechanics;
pub mod module;
pub mod motion;
mod motor;
mod outcome;
mod parameter_numbers;
mod phase;
pub use tmclsim_profile as profile;
pub mod program;
pub mod reference_search;
pub mod scurve;
pub mod sixpoint;
pub mod snapshot;
mod state;
#[cfg(test)]
mod test_support;
pub mod world;
pub mod world_command;
pub mod world_error;
pub mod world_file;
mod world_help;
pub mod world_rules;

pub use bus::Bus;
pub use clock::{Clock, Speed};
pub use eeprom::{Eeprom, Firmware};
pub use link_id::{IN_PROCESS, LinkId};
pub use module::{Module, Outcome, Special};
pub use module::{ascii, can};
pub use profile::Profile;
pub use world::World;
pub use world_error::WorldError;
