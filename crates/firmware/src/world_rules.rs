//! The one rule set for world values (docs/behaviour.md rule 84, the table
//! in docs/world.md): every number finite and in its range, every range
//! not empty, every input one the module has. World commands (control
//! socket, Python, Rust) are checked by `WorldCommand::validate`
//! (crate::world_command) before they are applied, world files by
//! [`World::validate`]; both use the checks below, so a value is refused
//! with the same words wherever it comes from.

use crate::world::{AxisWorld, Load, World};
pub use crate::world::{WORLD_ANALOG_INPUTS, WORLD_DIGITAL_INPUTS};
use crate::world_error::WorldError;
pub use crate::world_error::{Allowed, number};
use tmclsim_profile::{PortDirection, Profile};

/// Supply voltage.
pub const SUPPLY: Allowed = Allowed { min: 0.0, max: 100.0, unit: "V" };
/// Driver temperature.
pub const TEMPERATURE: Allowed = Allowed { min: -50.0, max: 200.0, unit: "°C" };
/// Mechanical positions: switches, end stops, load ranges, the start.
pub const POSITION: Allowed = Allowed { min: -1e12, max: 1e12, unit: "µsteps" };
/// Widths of the stop switches.
pub const WIDTH: Allowed = Allowed { min: 0.0, max: 1e12, unit: "µsteps" };
/// A load's torque, in % of the motor's rated torque.
pub const TORQUE: Allowed = Allowed { min: 0.0, max: 1000.0, unit: "%" };
/// A load's time window, in seconds of virtual time.
pub const LOAD_TIME: Allowed = Allowed { min: 0.0, max: 1e9, unit: "s" };
/// An ADC reading.
pub const ANALOG: Allowed = Allowed { min: 0.0, max: 4095.0, unit: "" };
/// Encoder counts per revolution (0: no encoder).
pub const ENCODER_COUNTS: Allowed = Allowed { min: 0.0, max: 1e6, unit: "counts" };
/// Motor full steps per revolution.
pub const FULLSTEPS: Allowed = Allowed { min: 1.0, max: 10_000.0, unit: "steps" };

/// `value` is a finite number in `allowed`; the error names `what`.
pub fn check(what: &str, value: f64, allowed: Allowed) -> Result<f64, WorldError> {
    if !value.is_finite() {
        return Err(WorldError::NotFinite { what: what.to_string(), value, allowed });
    }
    if value < allowed.min || value > allowed.max {
        return Err(WorldError::Outside { what: what.to_string(), value, allowed });
    }
    Ok(value)
}

/// End stops: two positions, `from` below `to`.
pub fn check_travel(from: f64, to: f64) -> Result<(), WorldError> {
    check("travel FROM", from, POSITION)?;
    check("travel TO", to, POSITION)?;
    if from >= to {
        return Err(WorldError::EmptyTravel { from, to });
    }
    Ok(())
}

/// A closed range of positions (`what` from `from` to `to`).
pub fn check_span(what: &str, from: f64, to: f64) -> Result<(), WorldError> {
    check(&format!("{what} FROM"), from, POSITION)?;
    check(&format!("{what} TO"), to, POSITION)?;
    if from > to {
        return Err(WorldError::EmptySpan { what: what.to_string(), from, to });
    }
    Ok(())
}

/// A stop switch at `position`, pressed for `width` beyond it.
pub fn check_stop(which: &str, position: f64, width: Option<f64>) -> Result<(), WorldError> {
    check(&format!("{which} switch position"), position, POSITION)?;
    if let Some(w) = width {
        check(&format!("{which} switch width"), w, WIDTH)?;
    }
    Ok(())
}

/// A load: its torque, its position range and its time window.
pub fn check_load(load: &Load) -> Result<(), WorldError> {
    check("load torque", load.torque, TORQUE)?;
    match (load.from, load.to) {
        (Some(a), Some(b)) => check_span("load range", a, b)?,
        (Some(p), None) | (None, Some(p)) => {
            check("load range end", p, POSITION)?;
        }
        (None, None) => {}
    }
    for t in [load.after, load.until].into_iter().flatten() {
        check("load time", t, LOAD_TIME)?;
    }
    if let (Some(a), Some(u)) = (load.after, load.until)
        && a >= u
    {
        return Err(WorldError::EmptyWindow { after: a, until: u });
    }
    Ok(())
}

/// The numbers of the module's plain inputs in one bank (0: digital, 1:
/// analog), in order.
fn inputs(profile: &Profile, bank: u8) -> Vec<u8> {
    let mut n: Vec<u8> = profile
        .ports
        .iter()
        .filter(|p| p.direction == PortDirection::Input && p.bank == bank && p.role.is_none())
        .map(|p| p.number)
        .collect();
    n.sort_unstable();
    n
}

/// Input `number` of `bank` (0: digital, 1: analog) exists on the module.
pub fn check_input(profile: &Profile, bank: u8, number: u8) -> Result<(), WorldError> {
    let have = inputs(profile, bank);
    if have.contains(&number) {
        return Ok(());
    }
    Err(WorldError::NoInput { bank, number, module: profile.module.name.clone(), have })
}

impl AxisWorld {
    /// Checks the axis's values against the rule set.
    pub fn validate(&self) -> Result<(), WorldError> {
        if let Some(p) = self.left_switch {
            check_stop("left", p, self.left_width)?;
        }
        if let Some(p) = self.right_switch {
            check_stop("right", p, self.right_width)?;
        }
        if let Some((a, b)) = self.home_switch {
            check_span("home switch", a, b)?;
        }
        if let Some((a, b)) = self.travel {
            check_travel(a, b)?;
        }
        for load in &self.loads {
            check_load(load)?;
        }
        check("start", self.start, POSITION)?;
        if let Some(c) = self.encoder_counts {
            check("encoder", c, ENCODER_COUNTS)?;
        }
        check("fullsteps", self.fullsteps_per_rev, FULLSTEPS)?;
        Ok(())
    }
}

impl World {
    /// Checks every value of the world against the rule set.
    pub fn validate(&self) -> Result<(), WorldError> {
        check("supply", f64::from(self.supply_decivolts) / 10.0, SUPPLY)?;
        check("temperature", self.temperature, TEMPERATURE)?;
        if self.analog_inputs.len() > WORLD_ANALOG_INPUTS {
            return Err(WorldError::TooManyAnalogInputs { count: self.analog_inputs.len() });
        }
        for (n, v) in self.analog_inputs.iter().enumerate() {
            check(&format!("analog[{n}]"), f64::from(*v), ANALOG)?;
        }
        for (a, axis) in self.axes.iter().enumerate() {
            axis.validate().map_err(|e| e.on_axis(a))?;
        }
        Ok(())
    }
}
