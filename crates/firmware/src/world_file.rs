//! The world description file (TOML), see `docs/world.md`.

use crate::world::{AxisWorld, Load, World};
use crate::world_error::WorldError;
use crate::world_rules::{ANALOG, WORLD_ANALOG_INPUTS, WORLD_DIGITAL_INPUTS, check};
use serde::Deserialize;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct WorldFile {
    /// Start from the built-in stage (true) or from free axes (false).
    #[serde(default)]
    base: Option<String>,
    /// Supply voltage in volts.
    supply: Option<f64>,
    /// Driver temperature in °C.
    temperature: Option<f64>,
    /// Digital input levels, IN0 first.
    #[serde(default)]
    inputs: Vec<u8>,
    /// ADC values (0…4095), by analog input.
    #[serde(default)]
    analog: Vec<u16>,
    #[serde(default)]
    axis: Vec<AxisFile>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct SwitchFile {
    position: f64,
    width: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct HomeFile {
    from: f64,
    to: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct LoadFile {
    torque: f64,
    from: Option<f64>,
    to: Option<f64>,
    after: Option<f64>,
    until: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct AxisFile {
    travel: Option<[f64; 2]>,
    start: Option<f64>,
    left_switch: Option<SwitchFile>,
    right_switch: Option<SwitchFile>,
    home_switch: Option<HomeFile>,
    /// `false` removes a switch of the base world.
    #[serde(default)]
    no_left_switch: bool,
    #[serde(default)]
    no_right_switch: bool,
    #[serde(default)]
    no_home_switch: bool,
    #[serde(default)]
    load: Vec<LoadFile>,
    /// Encoder counts per revolution (0: no encoder).
    encoder: Option<f64>,
    /// Motor full steps per revolution (200 by default).
    fullsteps: Option<f64>,
}

impl World {
    /// A built-in world by name: `stage` (the built-in linear stage) or
    /// `free` (no switches, no end stops). World files are read by the
    /// front ends (`tmclsim_server::files::world_named`).
    pub fn built_in(name: &str, axes: usize) -> Option<World> {
        match name {
            "stage" => Some(World::stage(axes)),
            "free" => Some(World::free(axes)),
            _ => None,
        }
    }

    /// Reads a world description for a module with `axes` axes.
    pub fn from_toml(text: &str, axes: usize) -> Result<World, WorldError> {
        let f: WorldFile = toml::from_str(text)?;
        let mut w = match f.base.as_deref() {
            None | Some("stage") => World::stage(axes),
            Some("free") => World::free(axes),
            Some(other) => return Err(WorldError::UnknownBase { base: other.to_string() }),
        };
        if f.axis.len() > axes {
            return Err(WorldError::TooManyAxes { described: f.axis.len(), axes });
        }
        if let Some(v) = f.supply {
            crate::world_rules::check("supply", v, crate::world_rules::SUPPLY)?;
            w.supply_decivolts = (v * 10.0).round() as u16;
        }
        if let Some(t) = f.temperature {
            w.temperature = t;
        }
        if f.inputs.len() > WORLD_DIGITAL_INPUTS {
            return Err(WorldError::TooManyLevels { count: f.inputs.len() });
        }
        for (n, level) in f.inputs.iter().enumerate() {
            if *level > 1 {
                return Err(WorldError::Level { index: n, level: *level });
            }
            w.set_digital(n as u8, *level != 0);
        }
        if f.analog.len() > WORLD_ANALOG_INPUTS {
            return Err(WorldError::TooManyAnalogValues { count: f.analog.len() });
        }
        for (n, v) in f.analog.iter().enumerate() {
            check(&format!("analog[{n}]"), f64::from(*v), ANALOG)?;
            w.set_analog(n as u8, *v);
        }
        for (a, af) in f.axis.into_iter().enumerate() {
            let axis: &mut AxisWorld = &mut w.axes[a];
            if let Some([lo, hi]) = af.travel {
                axis.travel = Some((lo, hi));
            }
            if let Some(s) = af.start {
                axis.start = s;
            }
            if let Some(e) = af.encoder {
                axis.encoder_counts = (e != 0.0).then_some(e);
            }
            if let Some(f) = af.fullsteps {
                axis.fullsteps_per_rev = f;
            }
            if af.no_left_switch {
                axis.left_switch = None;
            }
            if af.no_right_switch {
                axis.right_switch = None;
            }
            if af.no_home_switch {
                axis.home_switch = None;
            }
            if let Some(s) = af.left_switch {
                axis.left_switch = Some(s.position);
                axis.left_width = s.width;
            }
            if let Some(s) = af.right_switch {
                axis.right_switch = Some(s.position);
                axis.right_width = s.width;
            }
            if let Some(h) = af.home_switch {
                axis.home_switch = Some((h.from, h.to));
            }
            for l in af.load {
                axis.loads.push(Load { torque: l.torque, from: l.from, to: l.to, after: l.after, until: l.until });
            }
        }
        // Every value by the one rule set (docs/behaviour.md rule 84).
        w.validate()?;
        Ok(w)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_world_file() {
        let w = World::from_toml(
            r#"
            supply = 12.5
            inputs = [1, 0, 1]
            [[axis]]
            travel = [-5000, 5000]
            left_switch = { position = -4000 }
            no_home_switch = true
            [[axis.load]]
            torque = 30
            from = 1000
            to = 2000
            "#,
            1,
        )
        .unwrap();
        assert_eq!(w.supply_decivolts, 125);
        assert_eq!(w.digital_inputs, 0b101);
        let a = &w.axes[0];
        assert_eq!(a.travel, Some((-5000.0, 5000.0)));
        assert_eq!((a.left_switch, a.left_width), (Some(-4000.0), None));
        assert_eq!(a.right_switch, Some(1_000_000.0), "kept from the built-in stage");
        assert_eq!(a.home_switch, None);
        assert_eq!(a.load_at(1500.0, 0.0), 30.0);
        assert_eq!(a.load_at(2500.0, 0.0), 0.0);
    }

    #[test]
    fn errors_say_what_is_wrong() {
        assert!(World::from_toml("[[axis]]\ntravel = [5, 1]\n", 1).unwrap_err().to_string().contains("empty"));
        assert!(World::from_toml("[[axis]]\n[[axis]]\n", 1).unwrap_err().to_string().contains("1"));
        assert!(World::from_toml("bogus = 1\n", 1).is_err());
        assert!(World::from_toml("analog = [5000]\n", 1).unwrap_err().to_string().contains("4095"));
    }
}
