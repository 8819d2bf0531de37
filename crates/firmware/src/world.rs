//! The simulated world around a module: stop and home switches along each
//! axis, the module's inputs and its supply.
//!
//! Positions are mechanical: what the carriage sees. The motor position
//! counter and the mechanical position differ by an offset that changes
//! when the host overwrites the actual position or the module restarts
//! (the carriage does not move when the counter is reset).

/// Digital inputs a world holds (bit n of a 32-bit word).
pub const WORLD_DIGITAL_INPUTS: usize = 32;
/// Analog inputs a world holds.
pub const WORLD_ANALOG_INPUTS: usize = 8;

/// Switches along one axis.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AxisWorld {
    /// The left stop switch is pressed at or below this position…
    pub left_switch: Option<f64>,
    /// …down to this far below it (`None`: all the way).
    pub left_width: Option<f64>,
    /// The right stop switch is pressed at or above this position…
    pub right_switch: Option<f64>,
    /// …up to this far above it (`None`: all the way).
    pub right_width: Option<f64>,
    /// The home switch is pressed between these positions (inclusive).
    pub home_switch: Option<(f64, f64)>,
    /// Levels driven by hand; they override the positions above.
    pub forced_left: Option<bool>,
    /// Level of the right switch driven by hand (`None`: by position).
    pub forced_right: Option<bool>,
    /// Level of the home switch driven by hand (`None`: by position).
    pub forced_home: Option<bool>,
    /// Mechanical end stops: the carriage cannot leave this range (the
    /// motor loses steps against them).
    pub travel: Option<(f64, f64)>,
    /// Mechanical loads, in % of the motor's rated torque.
    pub loads: Vec<Load>,
    /// Where the carriage stands at the first power-up.
    pub start: f64,
    /// Driver faults injected by hand.
    pub faults: DriverFaults,
    /// An incremental encoder on the motor shaft: counts per revolution
    /// (`None`: no encoder).
    pub encoder_counts: Option<f64>,
    /// Full steps of the motor per revolution.
    pub fullsteps_per_rev: f64,
    /// The encoder's signal is lost (the count stands still).
    pub encoder_lost: bool,
}

/// A load on an axis: a torque demand in % of what the motor gives at
/// full current and standstill, optionally only in a position range and/or
/// a time window.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Load {
    /// The torque demand, in % of the motor's rated torque.
    pub torque: f64,
    /// Mechanical position range (inclusive).
    pub from: Option<f64>,
    /// End of the position range (inclusive).
    pub to: Option<f64>,
    /// Virtual time window in seconds.
    pub after: Option<f64>,
    /// End of the time window (exclusive).
    pub until: Option<f64>,
}

impl Load {
    /// True when the load acts at mechanical position `mech` and time `t_s`
    /// (s).
    pub fn applies(&self, mech: f64, t_s: f64) -> bool {
        self.from.is_none_or(|a| mech >= a)
            && self.to.is_none_or(|b| mech <= b)
            && self.after.is_none_or(|a| t_s >= a)
            && self.until.is_none_or(|u| t_s < u)
    }
}

/// Motor driver faults (TMC262 flags of AP 208).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DriverFaults {
    /// Coil A shorted to ground.
    pub short_a: bool,
    /// Coil B shorted to ground.
    pub short_b: bool,
    /// Coil A open.
    pub open_a: bool,
    /// Coil B open.
    pub open_b: bool,
}

impl AxisWorld {
    /// True when the left switch reads pressed with the carriage at `mech` (a
    /// forced level wins).
    pub fn left_pressed(&self, mech: f64) -> bool {
        self.forced_left.unwrap_or_else(|| self.left_switch.is_some_and(|p| mech <= p && self.left_width.is_none_or(|w| mech >= p - w)))
    }

    /// True when the right switch reads pressed with the carriage at `mech` (a
    /// forced level wins).
    pub fn right_pressed(&self, mech: f64) -> bool {
        self.forced_right.unwrap_or_else(|| self.right_switch.is_some_and(|p| mech >= p && self.right_width.is_none_or(|w| mech <= p + w)))
    }

    /// True when the home switch reads pressed with the carriage at `mech` (a
    /// forced level wins).
    pub fn home_pressed(&self, mech: f64) -> bool {
        self.forced_home.unwrap_or_else(|| self.home_switch.is_some_and(|(a, b)| mech >= a && mech <= b))
    }

    /// The torque demand at a mechanical position and time (sum of the
    /// loads that apply).
    pub fn load_at(&self, mech: f64, t_s: f64) -> f64 {
        // A fold from +0.0: an empty float sum is -0.0.
        self.loads.iter().filter(|l| l.applies(mech, t_s)).fold(0.0, |sum, l| sum + l.torque)
    }

    /// `mech` held within the end stops (unchanged without them). Unlike
    /// `f64::clamp` this never panics: values that bypassed the rule set
    /// (docs/behaviour.md rule 84) through `world_mut` give a wrong
    /// position, not a dead module (an inverted range holds at its upper
    /// end; a NaN end is no end).
    pub fn within_travel(&self, mech: f64) -> f64 {
        match self.travel {
            Some((lo, hi)) => mech.max(lo).min(hi),
            None => mech,
        }
    }

    /// Some switch is pressed at some positions (and not at others): the
    /// switches depend on where the carriage is. Without, they read only
    /// the levels driven by hand.
    pub fn has_switch_positions(&self) -> bool {
        self.left_switch.is_some() || self.right_switch.is_some() || self.home_switch.is_some()
    }

    /// Mechanical positions where a switch changes state.
    pub fn thresholds(&self) -> impl Iterator<Item = f64> + '_ {
        let home = self.home_switch.map(|(a, b)| [a, b]);
        let left_end = self.left_switch.zip(self.left_width).map(|(p, w)| p - w);
        let right_end = self.right_switch.zip(self.right_width).map(|(p, w)| p + w);
        self.left_switch.into_iter().chain(left_end).chain(self.right_switch).chain(right_end).chain(home.into_iter().flatten())
    }
}

/// Everything outside the module that it senses.
#[derive(Clone, Debug, PartialEq)]
pub struct World {
    /// The world of each axis, axis 0 first.
    pub axes: Vec<AxisWorld>,
    /// Digital input levels, bit n = input n.
    pub digital_inputs: u32,
    /// ADC readings (0…4095) by analog input number.
    pub analog_inputs: Vec<u16>,
    /// Bit n: analog input n is a line of its own, not digital input n
    /// read through the ADC (the profile's `own_line` ports; the module
    /// sets it from its profile).
    pub own_analog_lines: u32,
    /// Supply voltage in 0.1 V.
    pub supply_decivolts: u16,
    /// Driver temperature in °C.
    pub temperature: f64,
    /// Level of the shutdown input (TMCM-351 GP 80).
    pub shutdown_input: bool,
}

impl World {
    /// A world with free axes (no switches), inputs low, 24 V supply,
    /// 40 °C.
    pub fn free(axes: usize) -> World {
        let axis = AxisWorld { fullsteps_per_rev: 200.0, encoder_counts: Some(2000.0), ..AxisWorld::default() };
        World {
            axes: vec![axis; axes],
            digital_inputs: 0,
            analog_inputs: vec![0; 8],
            own_analog_lines: 0,
            supply_decivolts: 240,
            temperature: 40.0,
            shutdown_input: false,
        }
    }

    /// The built-in world: every axis a linear stage of ±1 050 000 µsteps
    /// (about ±20 revolutions at 256 microsteps) with a left stop switch
    /// pressed from −1 000 000 for 20 000 µsteps, a right one from
    /// +1 000 000, a home switch between 100 000 and 110 000, no load; the
    /// carriage starts at 0.
    pub fn stage(axes: usize) -> World {
        let mut w = World::free(axes);
        for a in &mut w.axes {
            a.left_switch = Some(-1_000_000.0);
            a.left_width = Some(20_000.0);
            a.right_switch = Some(1_000_000.0);
            a.right_width = Some(20_000.0);
            a.home_switch = Some((100_000.0, 110_000.0));
            a.travel = Some((-1_050_000.0, 1_050_000.0));
        }
        w
    }

    /// True when digital input `n` is high (inputs past 31 read low).
    pub fn digital(&self, n: u8) -> bool {
        n < 32 && self.digital_inputs & (1 << n) != 0
    }

    /// True when digital input `n` and analog input `n` are one line.
    fn one_line(&self, n: u8) -> bool {
        n < 32 && self.own_analog_lines & (1 << n) == 0
    }

    /// Drives a digital input; an input that is also analog follows
    /// (low = 0, high = 4095).
    pub fn set_digital(&mut self, n: u8, high: bool) {
        if n < 32 {
            if high {
                self.digital_inputs |= 1 << n;
            } else {
                self.digital_inputs &= !(1 << n);
            }
        }
        if !self.one_line(n) {
            return;
        }
        if let Some(a) = self.analog_inputs.get_mut(n as usize) {
            *a = if high { 4095 } else { 0 };
        }
    }

    /// Sets an analog input; the same line read digitally is high from
    /// half scale up.
    pub fn set_analog(&mut self, n: u8, value: u16) {
        if let Some(a) = self.analog_inputs.get_mut(n as usize) {
            *a = value.min(4095);
        }
        if self.one_line(n) {
            if value >= 2048 {
                self.digital_inputs |= 1 << n;
            } else {
                self.digital_inputs &= !(1 << n);
            }
        }
    }
}
