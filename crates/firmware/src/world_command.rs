//! Typed commands that change (or show) the world around a module, and
//! their text form: the control protocol of docs/world.md. Every front end
//! (control socket, `tmclsim world`, Python) parses a line into a
//! [`WorldCommand`] and applies it through [`crate::Bus::apply_world`]
//! (crate::bus::Bus::apply_world).

use crate::module::Module;
use crate::world::Load;
use crate::world_error::WorldError;
use crate::world_rules::{ANALOG, POSITION, SUPPLY, TEMPERATURE, check, check_input, check_load, check_span, check_stop, check_travel};
use tmclsim_profile::Profile;

pub use crate::world_help::{HELP, help_items};

/// One of the three switches of an axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SwitchKind {
    /// The left stop switch.
    Left,
    /// The right stop switch.
    Right,
    /// The home switch.
    Home,
}

/// One of the driver's coil faults.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CoilFault {
    /// Coil A shorted.
    ShortA,
    /// Coil B shorted.
    ShortB,
    /// Coil A open.
    OpenA,
    /// Coil B open.
    OpenB,
}

/// A change of the world (or a look at it).
#[derive(Clone, Debug, PartialEq)]
pub enum WorldCommand {
    /// The world the module was served in again, carriages at its start.
    Reset,
    /// Switches the module off and on: it starts as after power-up (its
    /// bootloader first, which stays when the flash holds no valid
    /// firmware; docs/behaviour.md rule 100).
    PowerCycle,
    /// Puts the carriage of an axis at a position (the motor does not move).
    PlaceCarriage {
        /// The axis.
        axis: usize,
        /// The carriage's mechanical position, in µsteps.
        position: f64,
    },
    /// Drives a digital input high or low.
    Input {
        /// The input's number.
        number: u8,
        /// True: high.
        high: bool,
    },
    /// Sets an ADC reading (0…4095).
    Analog {
        /// The analog input's number.
        number: u8,
        /// The ADC reading.
        value: u16,
    },
    /// Supply voltage in volts.
    Supply {
        /// The voltage.
        volts: f64,
    },
    /// Driver temperature.
    Temperature {
        /// The temperature, in °C.
        celsius: f64,
    },
    /// Forces a switch pressed (`Some(true)`), released, or back to what
    /// the carriage position says (`None`).
    Switch {
        /// The axis.
        axis: usize,
        /// Which switch.
        which: SwitchKind,
        /// Pressed, released, or `None`: by position.
        pressed: Option<bool>,
    },
    /// Places a stop switch at a position (with an optional width).
    PlaceStop {
        /// The axis.
        axis: usize,
        /// Left or right.
        which: SwitchKind,
        /// The switch's position, in µsteps.
        position: f64,
        /// How far the switch reaches beyond it (`None`: all the way).
        width: Option<f64>,
    },
    /// Places the home switch between two positions.
    PlaceHome {
        /// The axis.
        axis: usize,
        /// Lower end, in µsteps.
        from: f64,
        /// Upper end, in µsteps.
        to: f64,
    },
    /// Mechanical end stops of the axis.
    Travel {
        /// The axis.
        axis: usize,
        /// Lower end stop, in µsteps.
        from: f64,
        /// Upper end stop, in µsteps.
        to: f64,
    },
    /// A load torque (% of rated) everywhere or between two positions; 0
    /// removes the loads.
    Load {
        /// The axis.
        axis: usize,
        /// Torque demand in % of the rated torque.
        torque: f64,
        /// Start of the position range, in µsteps.
        from: Option<f64>,
        /// End of the position range, in µsteps.
        to: Option<f64>,
    },
    /// Injects or clears a driver coil fault (AP 208 flags).
    Fault {
        /// The axis.
        axis: usize,
        /// Which fault.
        which: CoilFault,
        /// True: the fault is present.
        on: bool,
    },
    /// Positions and switches of one axis or all.
    Show {
        /// The axis (`None`: all axes).
        axis: Option<usize>,
    },
}

/// A parsed control line: which module it is for (`@ADDRESS`, `None`: the
/// first one) and what to do.
#[derive(Clone, Debug, PartialEq)]
pub struct Addressed {
    /// The module's address (`None`: the first module on the bus).
    pub address: Option<u8>,
    /// What to do.
    pub command: WorldCommand,
}

fn num<T: std::str::FromStr>(w: Option<&str>, what: &'static str) -> Result<T, WorldError> {
    let w = w.ok_or(WorldError::Missing { what })?;
    w.parse().map_err(|_| WorldError::Invalid { word: w.to_string(), what })
}

fn optional(w: Option<&str>) -> Result<Option<f64>, WorldError> {
    w.map(|x| x.parse().map_err(|_| WorldError::NotANumber { word: x.to_string() })).transpose()
}

/// `on`/`1` or `off`/`0`, as a world or link command takes it.
pub fn on_off(w: Option<&str>) -> Result<bool, WorldError> {
    match w {
        Some("on" | "1") => Ok(true),
        Some("off" | "0") => Ok(false),
        other => Err(expected("on or off", other)),
    }
}

/// A keyword was expected; `found` is the word there, if any.
fn expected(expected: &'static str, found: Option<&str>) -> WorldError {
    WorldError::Expected { expected, found: found.map(str::to_string) }
}

fn switch_kind(w: Option<&str>) -> Result<SwitchKind, WorldError> {
    match w {
        Some("left") => Ok(SwitchKind::Left),
        Some("right") => Ok(SwitchKind::Right),
        Some("home") => Ok(SwitchKind::Home),
        other => Err(expected("left, right or home", other)),
    }
}

impl WorldCommand {
    /// Parses the words of a control line (without `@ADDRESS`; `link` and
    /// `help` belong to the link, not the world).
    pub fn parse(words: &[&str]) -> Result<WorldCommand, WorldError> {
        let mut w = words.iter().copied();
        let cmd = w.next().ok_or(WorldError::EmptyCommand)?;
        Ok(match cmd {
            "input" => {
                let number = num(w.next(), "input number")?;
                let high = match w.next() {
                    Some("1") => true,
                    Some("0") => false,
                    other => return Err(expected("level 0 or 1", other)),
                };
                WorldCommand::Input { number, high }
            }
            "analog" => {
                let number = num(w.next(), "input number")?;
                let value: u16 = num(w.next(), "value")?;
                if value > 4095 {
                    return Err(WorldError::AnalogAbove { value });
                }
                WorldCommand::Analog { number, value }
            }
            "supply" => WorldCommand::Supply { volts: num(w.next(), "voltage")? },
            "temperature" => WorldCommand::Temperature { celsius: num(w.next(), "temperature")? },
            "switch" => {
                let axis = num(w.next(), "axis")?;
                let which = switch_kind(w.next())?;
                let pressed = match w.next() {
                    Some("press") => Some(true),
                    Some("release") => Some(false),
                    Some("auto") => None,
                    other => return Err(expected("press, release or auto", other)),
                };
                WorldCommand::Switch { axis, which, pressed }
            }
            "reset" => WorldCommand::Reset,
            "power" => match w.next() {
                Some("cycle") => WorldCommand::PowerCycle,
                other => return Err(expected("cycle", other)),
            },
            "place" => {
                let axis = num(w.next(), "axis")?;
                if w.clone().next() == Some("carriage") {
                    w.next();
                    return Ok(WorldCommand::PlaceCarriage { axis, position: num(w.next(), "position")? });
                }
                let which = switch_kind(w.next())?;
                let position = num(w.next(), "position")?;
                let rest = optional(w.next())?;
                match which {
                    SwitchKind::Home => WorldCommand::PlaceHome { axis, from: position, to: rest.ok_or(WorldError::HomeNeedsTo)? },
                    _ => WorldCommand::PlaceStop { axis, which, position, width: rest },
                }
            }
            "travel" => {
                WorldCommand::Travel { axis: num(w.next(), "axis")?, from: num(w.next(), "position")?, to: num(w.next(), "position")? }
            }
            "load" => {
                let axis = num(w.next(), "axis")?;
                let torque = num(w.next(), "torque in %")?;
                WorldCommand::Load { axis, torque, from: optional(w.next())?, to: optional(w.next())? }
            }
            "fault" => {
                let axis = num(w.next(), "axis")?;
                let which = match w.next() {
                    Some("short-a") => CoilFault::ShortA,
                    Some("short-b") => CoilFault::ShortB,
                    Some("open-a") => CoilFault::OpenA,
                    Some("open-b") => CoilFault::OpenB,
                    other => return Err(expected("short-a, short-b, open-a or open-b", other)),
                };
                WorldCommand::Fault { axis, which, on: on_off(w.next())? }
            }
            "show" => WorldCommand::Show { axis: w.next().map(|a| num(Some(a), "axis")).transpose()? },
            other => return Err(WorldError::UnknownCommand { word: other.to_string() }),
        })
    }

    /// The axis the command names, if any.
    pub fn axis(&self) -> Option<usize> {
        match *self {
            WorldCommand::Switch { axis, .. }
            | WorldCommand::PlaceCarriage { axis, .. }
            | WorldCommand::PlaceStop { axis, .. }
            | WorldCommand::PlaceHome { axis, .. }
            | WorldCommand::Travel { axis, .. }
            | WorldCommand::Load { axis, .. }
            | WorldCommand::Fault { axis, .. } => Some(axis),
            WorldCommand::Show { axis } => axis,
            _ => None,
        }
    }

    /// Applies the command to a module, after checking its values
    /// ([`WorldCommand::validate`], docs/behaviour.md rule 84): a refused
    /// command changes nothing. `Ok` carries what to print after `ok`
    /// (only `show` prints something).
    pub fn apply(&self, m: &mut Module) -> Result<String, WorldError> {
        self.validate(m.profile())?;
        let axes = m.profile().module.axes as usize;
        match *self {
            WorldCommand::Reset => {
                m.reset_world();
                return Ok(String::new());
            }
            WorldCommand::PowerCycle => {
                m.reset();
                return Ok(String::new());
            }
            WorldCommand::PlaceCarriage { axis, position } => {
                m.place_carriage(axis, position);
                return Ok(String::new());
            }
            _ => {}
        }
        let world = m.world_mut();
        match *self {
            WorldCommand::Reset | WorldCommand::PowerCycle | WorldCommand::PlaceCarriage { .. } => {}
            WorldCommand::Input { number, high } => world.set_digital(number, high),
            WorldCommand::Analog { number, value } => world.set_analog(number, value),
            WorldCommand::Supply { volts } => world.supply_decivolts = (volts * 10.0).round() as u16,
            WorldCommand::Temperature { celsius } => world.temperature = celsius,
            WorldCommand::Switch { axis, which, pressed } => {
                let wa = &mut world.axes[axis];
                match which {
                    SwitchKind::Left => wa.forced_left = pressed,
                    SwitchKind::Right => wa.forced_right = pressed,
                    SwitchKind::Home => wa.forced_home = pressed,
                }
            }
            WorldCommand::PlaceStop { axis, which, position, width } => {
                let wa = &mut world.axes[axis];
                match which {
                    SwitchKind::Left => (wa.left_switch, wa.left_width) = (Some(position), width),
                    _ => (wa.right_switch, wa.right_width) = (Some(position), width),
                }
            }
            WorldCommand::PlaceHome { axis, from, to } => world.axes[axis].home_switch = Some((from, to)),
            WorldCommand::Travel { axis, from, to } => world.axes[axis].travel = Some((from, to)),
            WorldCommand::Load { axis, torque, from, to } => {
                let loads = &mut world.axes[axis].loads;
                loads.clear();
                if torque > 0.0 {
                    loads.push(Load { torque, from, to, ..Load::default() });
                }
            }
            WorldCommand::Fault { axis, which, on } => {
                let f = &mut world.axes[axis].faults;
                match which {
                    CoilFault::ShortA => f.short_a = on,
                    CoilFault::ShortB => f.short_b = on,
                    CoilFault::OpenA => f.open_a = on,
                    CoilFault::OpenB => f.open_b = on,
                }
            }
            WorldCommand::Show { axis } => {
                let list: Vec<usize> = axis.map_or_else(|| (0..axes).collect(), |a| vec![a]);
                let mut out = format!("time {:.3} s", m.now_ns() as f64 * 1e-9);
                for a in list {
                    let (l, r, h) = m.switches(a);
                    let load = m.world().axes[a].load_at(m.mechanical_position(a), m.now_ns() as f64 * 1e-9);
                    out.push_str(&format!(
                        "; axis {a}: position {} carriage {:.1} speed {} left {} right {} home {} load {load} %",
                        m.actual_position(a),
                        m.mechanical_position(a),
                        m.actual_speed(a),
                        u8::from(l),
                        u8::from(r),
                        u8::from(h)
                    ));
                }
                return Ok(out);
            }
        }
        Ok(String::new())
    }
}

impl WorldCommand {
    /// Checks the command's values against the rule set and the module's
    /// profile (its axes and inputs); `apply` does this first.
    pub fn validate(&self, profile: &Profile) -> Result<(), WorldError> {
        let axes = profile.module.axes as usize;
        if let Some(a) = self.axis()
            && a >= axes
        {
            return Err(WorldError::NoAxis { axis: a, axes });
        }
        let on_axis = |axis: usize, r: Result<(), WorldError>| r.map_err(|e| e.on_axis(axis));
        match *self {
            WorldCommand::Input { number, .. } => check_input(profile, 0, number),
            WorldCommand::Analog { number, value } => {
                check_input(profile, 1, number)?;
                check("analog value", f64::from(value), ANALOG).map(drop)
            }
            WorldCommand::Supply { volts } => check("supply", volts, SUPPLY).map(drop),
            WorldCommand::Temperature { celsius } => check("temperature", celsius, TEMPERATURE).map(drop),
            WorldCommand::PlaceStop { axis, which, position, width } => {
                let name = if which == SwitchKind::Left { "left" } else { "right" };
                on_axis(axis, check_stop(name, position, width))
            }
            WorldCommand::PlaceHome { axis, from, to } => on_axis(axis, check_span("home switch", from, to)),
            WorldCommand::Travel { axis, from, to } => on_axis(axis, check_travel(from, to)),
            WorldCommand::Load { axis, torque, from, to } => on_axis(axis, check_load(&Load { torque, from, to, ..Load::default() })),
            WorldCommand::PlaceCarriage { axis, position } => on_axis(axis, check("carriage position", position, POSITION).map(drop)),
            WorldCommand::Switch { .. }
            | WorldCommand::Fault { .. }
            | WorldCommand::Show { .. }
            | WorldCommand::Reset
            | WorldCommand::PowerCycle => Ok(()),
        }
    }
}

impl Addressed {
    /// Parses `[@ADDRESS] COMMAND …`.
    pub fn parse(line: &str) -> Result<Addressed, WorldError> {
        let words: Vec<&str> = line.split_whitespace().collect();
        let (address, rest) = match words.first().and_then(|w| w.strip_prefix('@')) {
            Some(a) => (Some(a.parse().map_err(|_| WorldError::BadAddress { word: a.to_string() })?), &words[1..]),
            None => (None, &words[..]),
        };
        Ok(Addressed { address, command: WorldCommand::parse(rest)? })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_parse_into_typed_commands() {
        assert_eq!(
            Addressed::parse("input 2 1").unwrap(),
            Addressed { address: None, command: WorldCommand::Input { number: 2, high: true } }
        );
        assert_eq!(
            Addressed::parse("@3 load 1 50 10 20").unwrap(),
            Addressed { address: Some(3), command: WorldCommand::Load { axis: 1, torque: 50.0, from: Some(10.0), to: Some(20.0) } }
        );
        assert_eq!(
            WorldCommand::parse(&["place", "0", "home", "5", "9"]).unwrap(),
            WorldCommand::PlaceHome { axis: 0, from: 5.0, to: 9.0 }
        );
        assert_eq!(WorldCommand::parse(&["show"]).unwrap(), WorldCommand::Show { axis: None });
    }

    #[test]
    fn bad_lines_say_what_is_wrong() {
        assert_eq!(WorldCommand::parse(&["analog", "0", "5000"]).unwrap_err().to_string(), "5000 is above 4095");
        assert_eq!(
            WorldCommand::parse(&["switch", "0", "middle", "press"]).unwrap_err().to_string(),
            "expected left, right or home, found middle"
        );
        assert_eq!(WorldCommand::parse(&["place", "0", "home", "5"]).unwrap_err().to_string(), "place home takes FROM and TO");
        assert_eq!(Addressed::parse("@x input 0 1").unwrap_err().to_string(), "'@x' is not a module address (0…255)");
        assert!(WorldCommand::parse(&["fly"]).unwrap_err().to_string().starts_with("unknown command 'fly'"));
    }

    #[test]
    fn commands_change_the_world_and_check_the_axis() {
        let mut m = Module::built_in("tmcm-1141").unwrap();
        WorldCommand::Input { number: 1, high: true }.apply(&mut m).unwrap();
        assert!(m.world().digital(1));
        WorldCommand::Supply { volts: 12.3 }.apply(&mut m).unwrap();
        assert_eq!(m.world().supply_decivolts, 123);
        assert_eq!(
            WorldCommand::Travel { axis: 1, from: 0.0, to: 1.0 }.apply(&mut m).unwrap_err().to_string(),
            "axis 1 does not exist (the module has 1)"
        );
        WorldCommand::Switch { axis: 0, which: SwitchKind::Left, pressed: Some(true) }.apply(&mut m).unwrap();
        assert_eq!(m.switches(0), (true, false, false));
        let shown = WorldCommand::Show { axis: None }.apply(&mut m).unwrap();
        assert!(shown.contains("axis 0: position 0") && shown.contains("left 1"), "{shown}");
    }
}
