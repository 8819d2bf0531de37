//! An axis in the world: the position counter and speed (AP 1, AP 3) in
//! the module's counter width, motor ↔ carriage coordinates (GP 90), the
//! switches the carriage presses (GP 79, AP 12/13) and the ramp the axis
//! runs with (AP 4/5/130/153/154, reference search speeds, torque mode).

use crate::module::Module;
use crate::motion;
use crate::parameter_numbers::{ap, gp};

impl Module {
    /// AP 1: the position counter.
    pub fn actual_position(&self, m: usize) -> i32 {
        self.wrap_position(self.axes[m].motion.position())
    }

    /// AP 3: the actual speed in internal units.
    pub fn actual_speed(&self, m: usize) -> i32 {
        let pd = self.axes[m].params[ap::PULSE_DIVISOR as usize].clamp(0, 13) as u32;
        // `as` truncates towards zero (and saturates), as the register does.
        motion::velocity_internal(self.axes[m].motion.v, pd) as i32
    }

    /// Sign-extends to the module's position width (32 or 24 bits).
    pub(crate) fn wrap_position(&self, v: i64) -> i32 {
        let bits = self.profile.position_bits();
        let shift = 64 - bits;
        ((v << shift) >> shift) as i32
    }

    /// Where the carriage of an axis is, in the world's coordinates.
    pub fn mechanical_position(&self, motor: usize) -> f64 {
        self.mech(motor, self.axes[motor].motion.x)
    }

    pub(crate) fn shaft_sign(&self) -> f64 {
        if self.globals[0][gp::REVERSE_SHAFT as usize] == 1 { -1.0 } else { 1.0 }
    }

    /// Mechanical position of an axis for a motor position.
    pub(crate) fn mech(&self, motor: usize, x: f64) -> f64 {
        x * self.shaft_sign() + self.axes[motor].mech_offset
    }

    /// Logical switch states (after GP 79 polarity): (left, right, home).
    pub fn switches(&self, motor: usize) -> (bool, bool, bool) {
        self.switches_at(motor, self.axes[motor].motion.x)
    }

    pub(crate) fn switches_at(&self, motor: usize, x: f64) -> (bool, bool, bool) {
        let w = &self.world.axes[motor];
        let invert = self.globals[0][gp::END_SWITCH_POLARITY as usize] == 1;
        if !w.has_switch_positions() {
            // Only levels driven by hand: the same everywhere.
            return (w.forced_left.unwrap_or(false) ^ invert, w.forced_right.unwrap_or(false) ^ invert, w.forced_home.unwrap_or(false));
        }
        let m = self.mech(motor, x);
        (w.left_pressed(m) ^ invert, w.right_pressed(m) ^ invert, w.home_pressed(m))
    }

    pub(crate) fn stops_at(&self, motor: usize, x: f64) -> motion::Stops {
        if self.axes[motor].rfs.is_some() {
            // AP 12/13 do not influence the reference search.
            return motion::Stops::default();
        }
        let (left, right, _) = self.switches_at(motor, x);
        let p = &self.axes[motor].params;
        motion::Stops {
            block_positive: right && p[ap::RIGHT_SWITCH_DISABLE as usize] == 0,
            block_negative: left && p[ap::LEFT_SWITCH_DISABLE as usize] == 0,
            soft: p[ap::SOFT_STOP as usize] == 1,
        }
    }

    /// Ramp settings of an axis in µsteps and seconds. The plain ramp (no
    /// interpolated move, torque mode or reference search) is worked out
    /// once per change of the axis parameters it comes from.
    pub(crate) fn ramp(&self, motor: usize) -> motion::Ramp {
        let axis = &self.axes[motor];
        if let Some(r) = axis.ramp_override {
            return r;
        }
        if axis.closed_loop.torque_mode || axis.rfs.is_some() {
            return axis.work_out_ramp(axis.closed_loop.torque_mode.then(|| self.torque_mode_velocity(motor)));
        }
        axis.plain_ramp(|| axis.work_out_ramp(None))
    }
}

#[cfg(test)]
mod tests {
    use crate::test_support::{module, ok};

    #[test]
    fn positions_wrap_in_the_counter_width() {
        let m = module("tmcm-351");
        assert_eq!(m.wrap_position(8_388_608), -8_388_608, "24 bits");
        assert_eq!(m.wrap_position(-8_388_609), 8_388_607);
        let m = module("tmcm-1141");
        assert_eq!(m.wrap_position(i64::from(i32::MAX) + 1), i32::MIN, "32 bits");
    }

    #[test]
    fn reversed_shaft_mirrors_the_carriage() {
        let mut m = module("tmcm-1141");
        ok(&mut m, "SAP 1, 0, 1000");
        assert_eq!(m.mechanical_position(0), 0.0, "setting the counter does not move the carriage");
        m.axes[0].motion.x += 500.0;
        assert_eq!(m.mechanical_position(0), 500.0);
        ok(&mut m, "SGP 90, 0, 1");
        assert_eq!(m.mechanical_position(0), -2500.0, "1500 · −1 − 1000");
    }

    #[test]
    fn switch_polarity_gp79_and_disabled_switches() {
        let mut m = module("tmcm-1141");
        m.world_mut().axes[0].left_switch = Some(0.0);
        assert_eq!(m.switches(0), (true, false, false));
        assert!(m.stops_at(0, 0.0).block_negative);
        ok(&mut m, "SAP 13, 0, 1");
        assert!(!m.stops_at(0, 0.0).block_negative, "AP 13 disables the left switch");
        ok(&mut m, "SGP 79, 0, 1");
        assert_eq!(m.switches(0), (false, true, false), "GP 79 inverts the stop switches");
    }

    #[test]
    fn ramp_follows_the_axis_parameters() {
        let mut m = module("tmcm-1141");
        ok(&mut m, "SAP 4, 0, 1000");
        ok(&mut m, "SAP 154, 0, 3");
        let r = m.ramp(0);
        assert_eq!(r.vmax, crate::motion::velocity_pps(1000.0, 3));
        ok(&mut m, "ROR 0, 200");
        assert_eq!(m.ramp(0).target_velocity, crate::motion::velocity_pps(200.0, 3));
    }
}
