//! An axis in the world: the position counter and speed (AP 1, AP 3) in
//! the module's counter width, motor ↔ carriage coordinates (GP 90), the
//! switches the carriage presses (GP 79, AP 12/13) and the ramp the axis
//! runs with (AP 4/5/130, in TMC429 units with AP 153/154 or in pps;
//! reference search speeds, torque mode).

use crate::motion::{self, RampMode};
use crate::motor::{Motor, MotorMut};
use crate::parameter_numbers::{ap, sp, tmc4361a};
use crate::reference_search::{SearchAxis, Switch};
use tmclsim_profile::{LimitSwitchRows, MotionController, MotionUnits};

impl Motor<'_> {
    /// AP 1: the position counter.
    pub(crate) fn actual_position(&self) -> i32 {
        self.wrap_position(self.axis.motion.position())
    }

    /// The units of the axis's velocities and accelerations: the
    /// profile's `motion_units`, with the divisors AP 154/153 in TMC429
    /// units.
    pub(crate) fn units(&self) -> motion::Units {
        match self.at.features().motion_units {
            MotionUnits::Tmc429 => motion::Units::Tmc429 {
                pulse_div: self.axis.params[ap::PULSE_DIVISOR as usize].clamp(0, 13) as u32,
                ramp_div: self.axis.params[ap::RAMP_DIVISOR as usize].clamp(0, 13) as u32,
            },
            MotionUnits::Pps => motion::Units::Pps,
            MotionUnits::Sixpoint => motion::Units::Sixpoint {
                fclk: self.at.features().motion_clock_hz,
                internal: self.at.features().unit_mode.is_some_and(|n| self.axis.params[n as usize] == 0),
                // The TMC5240's acceleration registers have 18 bits, the
                // TMC5130/TMC5160's 16.
                accel_max: if self.at.features().motion_controller == MotionController::Eightpoint { 262_143 } else { 65_535 },
            },
            MotionUnits::Tmc4361a => {
                let p = &self.axis.params;
                motion::Units::Tmc4361a {
                    fclk: self.at.features().motion_clock_hz,
                    internal: self.at.features().unit_mode.is_some_and(|n| p[n as usize] == 0),
                    // The module writes all five accelerations as direct values
                    // when one of them is too large for the pps registers.
                    direct: tmc4361a::ACCELERATIONS.iter().any(|&n| f64::from(p[n as usize]) > motion::TMC4361A_MAX_PPS_ACC),
                }
            }
        }
    }

    /// The TMC4361A drives this axis: its rows number the ramp type, the
    /// bows, the switches' enable and polarity bits, their swap and the
    /// soft stop (docs/behaviour.md rules 114–118).
    pub(crate) fn tmc4361a(&self) -> bool {
        self.at.features().motion_controller == MotionController::Tmc4361a
    }

    /// The TMC4361A's own ramp values (AP 14–25) in µsteps, seconds; `None`
    /// on the other motion controllers.
    pub(crate) fn chip(&self) -> Option<motion::Tmc4361a> {
        self.tmc4361a().then(|| self.axis.tmc4361a_ramp(self.units()))
    }

    /// The sixPoint (or eight-point) motion controller drives this axis:
    /// its family's rows number the soft stop, the switch polarities and
    /// swap, and the shaft's direction (docs/behaviour.md rules 108, 113).
    pub(crate) fn six_point(&self) -> bool {
        matches!(self.at.features().motion_controller, MotionController::Sixpoint | MotionController::Eightpoint)
    }

    /// −1 with the motor's direction reversed (GP 90; AP 251 on a
    /// sixPoint module), else 1.
    pub(crate) fn shaft_sign(&self) -> f64 {
        if self.six_point() || self.tmc4361a() {
            if self.axis.params[sp::REVERSE_SHAFT as usize] == 1 { -1.0 } else { 1.0 }
        } else {
            self.at.shaft_sign()
        }
    }

    /// AP 3: the actual speed in the module's velocity units.
    pub(crate) fn actual_speed(&self) -> i32 {
        // `as` truncates towards zero (and saturates), as the register does.
        self.units().velocity_value(self.axis.motion.v) as i32
    }

    /// Sign-extends to the module's position width (32 or 24 bits).
    pub(crate) fn wrap_position(&self, v: i64) -> i32 {
        crate::motor::wrap_position(v, self.at.position_bits())
    }

    /// Where the carriage is, in the world's coordinates.
    pub(crate) fn mechanical_position(&self) -> f64 {
        self.mech(self.axis.motion.x)
    }

    /// Mechanical position of the carriage for a motor position.
    pub(crate) fn mech(&self, x: f64) -> f64 {
        x * self.shaft_sign() + self.axis.mech_offset
    }

    /// Logical switch states (after GP 79 polarity): (left, right, home).
    pub(crate) fn switches(&self) -> (bool, bool, bool) {
        self.switches_at(self.axis.motion.x)
    }

    /// The switch states with the motor at `x`.
    pub(crate) fn switches_at(&self, x: f64) -> (bool, bool, bool) {
        let w = self.world;
        let (left, right, home) = if !w.has_switch_positions() {
            // Only levels driven by hand: the same everywhere.
            (w.forced_left.unwrap_or(false), w.forced_right.unwrap_or(false), w.forced_home.unwrap_or(false))
        } else {
            let m = self.mech(x);
            (w.left_pressed(m), w.right_pressed(m), w.home_pressed(m))
        };
        if self.six_point() {
            // Each switch has its polarity (AP 25 left, AP 24 right); AP 14
            // swaps what the two inputs mean.
            let p = &self.axis.params;
            let (left, right) = if p[sp::SWAP_SWITCHES as usize] == 1 { (right, left) } else { (left, right) };
            let left = left ^ (p[sp::LEFT_SWITCH_POLARITY as usize] == 1);
            let right = right ^ (p[sp::RIGHT_SWITCH_POLARITY as usize] == 1);
            return (left, right, home);
        }
        if self.tmc4361a() {
            // Bit 1 of AP 13 (left) and AP 12 (right) inverts the switch;
            // AP 33 swaps the two inputs.
            let p = &self.axis.params;
            let (left, right) = if p[tmc4361a::SWAP_SWITCHES as usize] != 0 { (right, left) } else { (left, right) };
            let inverted = |n: u8| p[n as usize] & tmc4361a::SWITCH_POLARITY != 0;
            return (left ^ inverted(ap::LEFT_SWITCH_DISABLE), right ^ inverted(ap::RIGHT_SWITCH_DISABLE), home);
        }
        let invert = self.at.switches_inverted();
        (left ^ invert, right ^ invert, home)
    }

    /// What the switches stop with the motor at `x` (AP 12/13, AP 149).
    pub(crate) fn stops_at(&self, x: f64) -> motion::Stops {
        if self.axis.rfs.is_some() {
            // AP 12/13 do not influence the reference search.
            return motion::Stops::default();
        }
        let (left, right, _) = self.switches_at(x);
        let p = &self.axis.params;
        // AP 12/13 disable the switches, or on some modules enable them
        // (on some with bit 0, bit 1 being the polarity).
        let rows = self.at.features().limit_switch_rows;
        let stops = |n: u8| match rows {
            LimitSwitchRows::Disable => p[n as usize] == 0,
            LimitSwitchRows::Enable => p[n as usize] != 0,
            LimitSwitchRows::EnablePolarity => p[n as usize] & tmc4361a::SWITCH_ENABLE != 0,
        };
        let soft = if self.tmc4361a() {
            p[tmc4361a::SOFT_STOP as usize] != 0
        } else {
            p[if self.six_point() { sp::SOFT_STOP } else { ap::SOFT_STOP } as usize] == 1
        };
        motion::Stops {
            block_positive: right && stops(ap::RIGHT_SWITCH_DISABLE),
            block_negative: left && stops(ap::LEFT_SWITCH_DISABLE),
            soft,
        }
    }

    /// Ramp settings of the axis in µsteps and seconds. The plain ramp (no
    /// interpolated move, torque mode or reference search) is worked out
    /// once per change of the axis parameters it comes from.
    #[inline]
    pub(crate) fn ramp(&self) -> motion::Ramp {
        let axis = self.axis;
        if let Some(r) = axis.ramp_override {
            return r;
        }
        let units = self.units();
        if axis.closed_loop.torque_mode || axis.rfs.is_some() {
            return axis.work_out_ramp(
                units,
                self.at.features().motion_controller,
                axis.closed_loop.torque_mode.then(|| self.torque_mode_velocity()),
            );
        }
        axis.plain_ramp(|| axis.work_out_ramp(units, self.at.features().motion_controller, None))
    }

    /// An axis parameter as a read finds it: the measured ones (position,
    /// speed, acceleration, switches, current, load, encoder, driver flags,
    /// closed loop) computed now, the others as stored.
    #[inline]
    pub(crate) fn parameter(&self, param: u8) -> i32 {
        if let Some(v) = self.read_closed_loop(param) {
            return v;
        }
        let axis = self.axis;
        let units = self.units();
        let motion = &axis.motion;
        match param {
            ap::TARGET_POSITION => axis.target_word,
            ap::ACTUAL_POSITION => self.actual_position(),
            ap::ACTUAL_SPEED => self.actual_speed(),
            ap::ACTUAL_ACCELERATION => {
                let max = f64::from(units.max_value());
                units.accel_value(motion.a).round().clamp(-max, max) as i32
            }
            ap::POSITION_REACHED => i32::from(self.actual_position() == axis.target_word),
            ap::LEFT_SWITCH => i32::from(self.switches().0),
            ap::RIGHT_SWITCH => i32::from(self.switches().1),
            // On a TMC428 module (the TMCM-351) AP 9 is the STOP_L input: the
            // reference switch in series with the left limit switch, so
            // either one reads (V4.45 §5 p.68, §7.1; docs/behaviour.md rule 77).
            ap::HOME_SWITCH if self.at.features().reference_search == tmclsim_profile::ReferenceSearchFamily::Tmc428 => {
                let (left, _, home) = self.switches();
                i32::from(left || home)
            }
            ap::HOME_SWITCH => i32::from(self.switches().2),
            ap::ACTUAL_CURRENT => self.current_scale().round() as i32,
            ap::LOAD_VALUE => axis.driver.load_value,
            ap::ENCODER_POSITION if self.at.features().encoder != tmclsim_profile::Encoder::None => self.encoder_position(),
            ap::DRIVER_ERROR_FLAGS => self.driver_flags(),
            // The measured speed: µsteps per second, whatever the unit mode.
            sp::MEASURED_SPEED if self.six_point() => motion.v as i32,
            _ => axis.params[param as usize],
        }
    }

    /// Where the switches change state, in motor coordinates (at most
    /// eight edges): the edges and how many there are.
    pub(crate) fn switch_edges(&self) -> ([f64; 8], usize) {
        let mut edges = [0.0f64; 8];
        if !self.world.has_switch_positions() {
            return (edges, 0);
        }
        let offset = self.axis.mech_offset;
        let sign = self.shaft_sign();
        let mut count = 0;
        for m in self.world.thresholds().take(edges.len()) {
            edges[count] = (m - offset) * sign;
            count += 1;
        }
        (edges, count)
    }
}

impl MotorMut<'_> {
    /// Sets AP 0 and the target the ramp generator runs to: the short way
    /// round in the module's position counter width.
    pub(crate) fn set_target(&mut self, target: i32) {
        let view = self.view();
        let diff = view.wrap_position(i64::from(target) - i64::from(view.actual_position()));
        let axis = &mut *self.axis;
        axis.target_word = target;
        axis.params[ap::TARGET_POSITION as usize] = target;
        axis.motion.target = axis.motion.position() as f64 + f64::from(diff);
    }

    /// Writing AP 1: the position counter takes `value` and the carriage
    /// does not move; the target stays where AP 0 says.
    pub(crate) fn set_counter(&mut self, value: i32) {
        let target = self.axis.target_word;
        let sign = self.view().shaft_sign();
        let axis = &mut *self.axis;
        let mech = axis.motion.x * sign + axis.mech_offset;
        axis.motion.x = f64::from(value);
        axis.mech_offset = mech - axis.motion.x * sign;
        self.set_target(target);
        self.closed_loop_sync();
    }
}

/// The reference search runs on the motor model's view of its axis.
impl SearchAxis for MotorMut<'_> {
    fn position(&self) -> f64 {
        self.axis.motion.x
    }

    fn switch_at(&self, switch: Switch, probe: f64) -> bool {
        let (l, r, h) = self.view().switches_at(probe);
        match switch {
            Switch::Left => l,
            Switch::Right => r,
            Switch::Home => h,
        }
    }

    fn halt(&mut self) {
        self.axis.motion.v = 0.0;
    }

    fn approach(&mut self, reference: f64) -> bool {
        let axis = &mut *self.axis;
        axis.set_ramp_mode(RampMode::Position);
        axis.motion.target = reference.round();
        axis.motion.x == axis.motion.target && axis.motion.v == 0.0
    }

    /// At the reference point: AP 197 keeps the old count, the counter
    /// becomes 0 here, AP 196 gets the switch distance.
    fn zero_here(&mut self, distance: Option<f64>) {
        let last = self.view().actual_position();
        self.axis.params[ap::LAST_REFERENCE_POSITION as usize] = last;
        if let Some(d) = distance {
            self.axis.params[ap::END_SWITCH_DISTANCE as usize] = d.round() as i32;
        }
        self.set_counter(0);
        self.set_target(0);
    }
}
