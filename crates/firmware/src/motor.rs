//! The motor model's view of one axis: the axis's own state, its world
//! (switches, load, encoder, travel) and the few settings of the module
//! around it (`Surroundings`). The model does not know the module: the
//! readings (`mechanics.rs`, `driver.rs`, `closed_loop.rs`) take a
//! [`Motor`], the driver's step a [`MotorMut`], which answers the alarms
//! it raised instead of raising them itself.

use crate::parameter_numbers::gp;
use crate::state::axis::Axis;
use crate::state::globals::Globals;
use crate::world::{AxisWorld, World};
use tmclsim_profile::{Features, Profile};

/// What the motor model reads of the module around an axis: the profile's
/// features and counter width, the globals that change what a motor
/// does (GP 90 reversed shaft, GP 79 switch polarity, the shutdown pin's
/// setting), the supply and temperature, and the time. Each is read when
/// asked for: a view costs no more than the reads it makes.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Surroundings<'a> {
    profile: &'a Profile,
    globals: &'a Globals,
    world: &'a World,
    now_ns: u64,
}

impl<'a> Surroundings<'a> {
    /// The surroundings of a module's axes at `now_ns`.
    pub(crate) fn of(profile: &'a Profile, globals: &'a Globals, world: &'a World, now_ns: u64) -> Surroundings<'a> {
        Surroundings { profile, globals, world, now_ns }
    }

    /// The module's features (stall detection, coolStep, closed loop, …).
    pub(crate) fn features(&self) -> &'a Features {
        &self.profile.features
    }

    /// Milliseconds per unit of a duration axis parameter, as its row's
    /// unit says (10 ms when it says none).
    pub(crate) fn ms_per_unit(&self, param: u8) -> u64 {
        self.profile.axis_parameter(param).and_then(tmclsim_profile::Parameter::ms_per_unit).unwrap_or(10)
    }

    /// The position counter's width: 24 or 32 bits.
    pub(crate) fn position_bits(&self) -> u32 {
        self.profile.position_bits()
    }

    /// GP 90: −1 with the shaft reversed, else 1.
    pub(crate) fn shaft_sign(&self) -> f64 {
        if self.globals[0][gp::REVERSE_SHAFT as usize] == 1 { -1.0 } else { 1.0 }
    }

    /// GP 79: the stop switches read inverted.
    pub(crate) fn switches_inverted(&self) -> bool {
        self.globals[0][gp::END_SWITCH_POLARITY as usize] == 1
    }

    /// The shutdown input switches the drivers off (its GP selects the
    /// level: 1 high, 2 low).
    pub(crate) fn shutdown(&self) -> bool {
        match self.profile.features.shutdown_pin.map(|n| self.globals[0][n as usize]) {
            Some(1) => self.world.shutdown_input,
            Some(2) => !self.world.shutdown_input,
            _ => false,
        }
    }

    /// The driver's temperature, °C.
    pub(crate) fn temperature(&self) -> f64 {
        self.world.temperature
    }

    /// The supply, 0.1 V.
    pub(crate) fn supply_decivolts(&self) -> u16 {
        self.world.supply_decivolts
    }

    /// Virtual time, ns.
    pub(crate) fn now_ns(&self) -> u64 {
        self.now_ns
    }
}

/// One axis as the motor model reads it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Motor<'a> {
    /// The axis's own state: parameters, ramp generator, driver, closed loop.
    pub axis: &'a Axis,
    /// The axis's world: switches, load, encoder, travel.
    pub world: &'a AxisWorld,
    /// The module around the axis.
    pub at: Surroundings<'a>,
}

/// One axis as the driver's step changes it.
#[derive(Debug)]
pub(crate) struct MotorMut<'a> {
    /// The axis's own state.
    pub axis: &'a mut Axis,
    /// The axis's world.
    pub world: &'a AxisWorld,
    /// The module around the axis.
    pub at: Surroundings<'a>,
}

impl MotorMut<'_> {
    /// The axis as it reads now.
    pub(crate) fn view(&self) -> Motor<'_> {
        Motor { axis: self.axis, world: self.world, at: self.at }
    }
}

/// What a driver step found that the module must raise: a stall stopped
/// the motor (stallGuard2, AP 181), the encoder and the counter drifted
/// apart (AP 212, AP 125; the error flag and interrupt of a deviation).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[must_use]
pub(crate) struct Alarms {
    /// A stall stopped the motor.
    pub stall: bool,
    /// The position deviated further than allowed.
    pub deviation: bool,
}

/// Sign-extends `v` to a counter of `bits` bits (32 or 24).
pub(crate) fn wrap_position(v: i64, bits: u32) -> i32 {
    let shift = 64 - bits;
    ((v << shift) >> shift) as i32
}
