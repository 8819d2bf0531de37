//! The motion commands: ROR, ROL, MST, MVP (with COORD and its motor
//! masks), MVPA, RORA, ROLA and RFS; the group index (AP 213) that shares
//! them between motors; and the reference search as the module runs it.

use crate::module::Module;
use crate::motion::{Motion, RampMode};
use crate::parameter_numbers::ap;
use crate::reference_search::ReferenceSearch;
use tmclsim_protocol::{MoveMode, RfsAction, Status};

impl Module {
    /// ROR, ROL: rotation of `motor` and its group.
    pub(crate) fn rotate_group(&mut self, motor: u8, velocity: i32, sign: i32) -> Result<(), Status> {
        self.for_group(motor, |s, m| {
            let m = s.motor(m)?;
            s.axes[m].rotate(velocity, sign)
        })
    }

    /// MST: `motor` and its group stop.
    pub(crate) fn stop_group(&mut self, motor: u8) -> Result<(), Status> {
        self.for_group(motor, |s, m| {
            let m = s.motor(m)?;
            s.axes[m].run_at(0);
            Ok(())
        })
    }

    /// MVP: a move of `motor` and its group; MVP COORD with a motor mask on
    /// a module with more than one motor.
    pub(crate) fn move_group(&mut self, mode: MoveMode, motor: u8, value: i32) -> Result<(), Status> {
        if mode == MoveMode::Coordinate && motor & 0xC0 != 0 && self.axes.len() > 1 {
            return self.move_coordinate_mask(motor, value);
        }
        self.for_group(motor, |s, m| s.move_to(mode, m, value))
    }

    /// RFS START and STOP (`None`: the reply echoes the value) and STATUS
    /// (whether a search runs).
    pub(crate) fn reference_search_command(&mut self, action: RfsAction, motor: u8) -> Result<Option<i32>, Status> {
        let m = self.motor(motor)?;
        match action {
            RfsAction::Start => self.for_group(motor, |s, g| s.start_reference_search(g as usize))?,
            RfsAction::Stop => self.for_group(motor, |s, g| {
                let axis = &mut s.axes[g as usize];
                if axis.rfs.take().is_some() {
                    axis.run_at(0);
                }
                Ok(())
            })?,
            RfsAction::Status => return Ok(Some(i32::from(self.axes[m].reference_search_active()))),
        }
        Ok(None)
    }

    pub(crate) fn move_to(&mut self, mode: MoveMode, motor: u8, value: i32) -> Result<(), Status> {
        let m = self.motor(motor)?;
        let target = match mode {
            MoveMode::Absolute => value,
            MoveMode::Relative => self.wrap_position(i64::from(self.actual_position(m)) + i64::from(value)),
            MoveMode::Coordinate => {
                let n = usize::try_from(value).map_err(|_| Status::InvalidValue)?;
                *self.axes[m].coordinates.get(n).ok_or(Status::InvalidValue)?
            }
        };
        if mode == MoveMode::Absolute && !self.profile.axis_parameter(ap::TARGET_POSITION).is_some_and(|p| p.accepts(value)) {
            return Err(Status::InvalidValue);
        }
        self.axes[m].clear_motion_errors();
        let axis = &mut self.axes[m];
        axis.end_overrides();
        // MVP selects position mode; soft mode, once chosen, stays.
        if axis.motion.mode != RampMode::Soft {
            axis.set_ramp_mode(RampMode::Position);
        }
        self.motor_view_mut(m).set_target(target);
        if self.interrupts.claim_arrival_event(m) {
            self.axes[m].notify_on_arrival = true;
            if self.axes[m].motion.x == self.axes[m].motion.target && self.axes[m].motion.v == 0.0 {
                // Already there: the event follows at once.
                self.axes[m].notify_on_arrival = false;
                self.push_event(1 << m);
            }
        }
        Ok(())
    }

    /// Runs a motion command for `motor` and for every other motor with the
    /// same non-zero group index (AP 213, on modules that have it).
    fn for_group(&mut self, motor: u8, mut f: impl FnMut(&mut Module, u8) -> Result<(), Status>) -> Result<(), Status> {
        let m = self.motor(motor)?;
        f(self, motor)?;
        if self.profile.features.motion_groups {
            let group = self.axes[m].params[ap::GROUP_INDEX as usize];
            if group != 0 {
                for other in 0..self.axes.len() {
                    if other != m && self.axes[other].params[ap::GROUP_INDEX as usize] == group {
                        f(self, other as u8)?;
                    }
                }
            }
        }
        Ok(())
    }

    /// MVP COORD with a motor mask: bit 7 moves the masked motors each with
    /// its own ramp, bit 6 interpolates (all arrive together: the axis with
    /// the longest travel time sets the pace, the others scale speed and
    /// acceleration by their share of the distance).
    fn move_coordinate_mask(&mut self, motor: u8, coordinate: i32) -> Result<(), Status> {
        let mask = (motor & 0x3F) as usize;
        let motors: Vec<usize> = (0..self.axes.len()).filter(|m| mask & (1 << m) != 0).collect();
        if motors.is_empty() || mask >> self.axes.len() != 0 {
            return Err(Status::InvalidValue);
        }
        for &m in &motors {
            self.move_to(MoveMode::Coordinate, m as u8, coordinate)?;
        }
        if motor & 0x40 == 0 {
            return Ok(());
        }
        let plans: Vec<(usize, f64, f64)> = motors
            .iter()
            .map(|&m| {
                let d = (self.axes[m].motion.target - self.axes[m].motion.x).abs();
                (m, d, Motion::closed_form_duration(d, &self.motor_view(m).ramp()))
            })
            .collect();
        let &(lead, d_lead, _) = plans.iter().max_by(|a, b| a.2.total_cmp(&b.2)).expect("motors is not empty");
        if d_lead == 0.0 {
            return Ok(());
        }
        let lead_ramp = self.motor_view(lead).ramp();
        for (m, d, _) in plans {
            if m != lead {
                let k = d / d_lead;
                let mut r = lead_ramp;
                r.vmax *= k;
                r.vmin *= k;
                r.accel_position *= k;
                self.axes[m].ramp_override = (k > 0.0).then_some(r);
            }
        }
        Ok(())
    }

    /// RFS START with the mode of AP 193.
    fn start_reference_search(&mut self, m: usize) -> Result<(), Status> {
        let mode = self.axes[m].params[ap::REFERENCE_SEARCH_MODE as usize];
        let rfs = match self.profile.features.reference_search {
            tmclsim_profile::ReferenceSearchFamily::Tmc429 => ReferenceSearch::new(mode),
            tmclsim_profile::ReferenceSearchFamily::Tmc428 => ReferenceSearch::new_tmc428(mode),
        };
        let rfs = rfs.ok_or(Status::InvalidValue)?;
        self.axes[m].clear_motion_errors();
        let axis = &mut self.axes[m];
        axis.notify_on_arrival = false;
        axis.set_ramp_mode(RampMode::Velocity);
        axis.rfs = Some(rfs);
        self.reference_search_step(m, true, false);
        Ok(())
    }

    /// Lets the reference search look at its axis after a step of motion.
    pub(crate) fn reference_search_step(&mut self, m: usize, crossed: bool, arrived: bool) {
        let Some(mut rfs) = self.axes[m].rfs.take() else { return };
        if rfs.step(&mut self.motor_view_mut(m), crossed, arrived) {
            self.axes[m].rfs = Some(rfs);
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::motion::RampMode;
    use crate::parameter_numbers::ap;
    use crate::test_support::{MS, direct, in_program, module, ok, status};
    use tmclsim_protocol::Status;

    #[test]
    fn ror_rol_and_mst_select_velocity_mode() {
        let mut m = module("tmcm-1141");
        ok(&mut m, "ROR 0, 300");
        assert_eq!((ok(&mut m, "GAP 2, 0"), ok(&mut m, "GAP 138, 0")), (300, 2));
        assert_eq!(m.axes[0].motion.mode, RampMode::Velocity);
        ok(&mut m, "ROL 0, 300");
        assert_eq!(ok(&mut m, "GAP 2, 0"), -300);
        m.advance(500 * MS);
        assert!(m.actual_speed(0) < 0);
        ok(&mut m, "MST 0");
        assert_eq!((ok(&mut m, "GAP 2, 0"), ok(&mut m, "GAP 138, 0")), (0, 2));
        m.advance(2_000 * MS);
        assert_eq!(m.actual_speed(0), 0);
    }

    #[test]
    fn ror_range_and_motor_numbers() {
        let mut m = module("tmcm-1141");
        assert_eq!(direct(&mut m, "ROR 0, 2048"), (Status::InvalidValue, 2048));
        assert_eq!(status(&mut m, "ROL 0, -2048"), Status::InvalidValue);
        assert_eq!(status(&mut m, "ROR 0, 2047"), Status::Ok);
        assert_eq!(status(&mut m, "ROR 1, 10"), Status::InvalidValue, "one motor");
        assert_eq!(status(&mut m, "MST 1"), Status::InvalidValue);
        assert_eq!(status(&mut m, "MVP ABS, 1, 10"), Status::InvalidValue);
    }

    #[test]
    fn rora_and_rola_take_the_accumulator() {
        let mut m = module("tmcm-1141");
        ok(&mut m, "CALC LOAD, 123");
        assert_eq!(in_program(&mut m, "RORA 0"), Ok(0));
        assert_eq!(ok(&mut m, "GAP 2, 0"), 123);
        assert_eq!(in_program(&mut m, "ROLA 0"), Ok(0));
        assert_eq!(ok(&mut m, "GAP 2, 0"), -123);
    }

    #[test]
    fn mvp_absolute_relative_and_coordinate() {
        let mut m = module("tmcm-1141");
        ok(&mut m, "SAP 4, 0, 2047");
        ok(&mut m, "MVP ABS, 0, 5000");
        assert_eq!((ok(&mut m, "GAP 0, 0"), ok(&mut m, "GAP 138, 0")), (5000, 0));
        m.advance(5_000 * MS);
        assert_eq!(ok(&mut m, "GAP 1, 0"), 5000);
        ok(&mut m, "MVP REL, 0, -1500");
        assert_eq!(ok(&mut m, "GAP 0, 0"), 3500);
        ok(&mut m, "SCO 3, 0, -250");
        ok(&mut m, "MVP COORD, 0, 3");
        assert_eq!(ok(&mut m, "GAP 0, 0"), -250);
        assert_eq!(status(&mut m, "MVP COORD, 0, 21"), Status::InvalidValue, "coordinates 0…20");
        ok(&mut m, "CALC LOAD, 777");
        assert_eq!(in_program(&mut m, "MVPA ABS, 0"), Ok(0));
        assert_eq!(ok(&mut m, "GAP 0, 0"), 777);
    }

    #[test]
    fn mvp_keeps_soft_mode() {
        let mut m = module("tmcm-1141");
        ok(&mut m, "SAP 138, 0, 1");
        ok(&mut m, "MVP ABS, 0, 100");
        assert_eq!(ok(&mut m, "GAP 138, 0"), 1);
        ok(&mut m, "ROR 0, 10");
        ok(&mut m, "MVP ABS, 0, 100");
        assert_eq!(ok(&mut m, "GAP 138, 0"), 0, "after ROR, MVP selects position mode");
    }

    #[test]
    fn relative_moves_wrap_in_24_bits() {
        let mut m = crate::test_support::module_24_bit();
        ok(&mut m, "SAP 1, 0, 8388607");
        ok(&mut m, "MVP REL, 0, 1");
        assert_eq!(ok(&mut m, "GAP 0, 0"), -8388608);
        assert_eq!(m.axes[0].motion.target - m.axes[0].motion.x, 1.0, "the short way round");
    }

    #[test]
    fn group_index_shares_motion_commands() {
        let mut m = module("tmcm-351");
        ok(&mut m, "SAP 213, 0, 1");
        ok(&mut m, "SAP 213, 2, 1");
        ok(&mut m, "ROR 0, 200");
        assert_eq!([0, 1, 2].map(|a| ok(&mut m, &format!("GAP 2, {a}"))), [200, 0, 200]);
        ok(&mut m, "MST 2");
        assert_eq!([0, 1, 2].map(|a| ok(&mut m, &format!("GAP 2, {a}"))), [0, 0, 0]);
    }

    #[test]
    fn mvp_coord_motor_masks() {
        let mut m = module("tmcm-351");
        for a in 0..3 {
            ok(&mut m, &format!("SCO 1, {a}, {}", 1000 * (a + 1)));
        }
        // Bit 7: each motor with its own ramp; no override.
        ok(&mut m, "#4 2 133 1");
        assert_eq!([0, 2].map(|a| ok(&mut m, &format!("GAP 0, {a}"))), [1000, 3000]);
        assert_eq!(ok(&mut m, "GAP 0, 1"), 0);
        assert!(m.axes.iter().all(|a| a.ramp_override.is_none()));
        // Bit 6: interpolated; the shorter moves get scaled ramps.
        ok(&mut m, "SCO 2, 0, 500");
        ok(&mut m, "SCO 2, 1, 2000");
        ok(&mut m, "#4 2 67 2");
        assert!(m.axes[0].ramp_override.is_some());
        assert!(m.axes[1].ramp_override.is_none(), "the longest move sets the pace");
        assert_eq!(status(&mut m, "#4 2 192 1"), Status::InvalidValue, "no motor in the mask");
        assert_eq!(status(&mut m, "#4 2 136 1"), Status::InvalidValue, "motor 3 does not exist");
    }

    #[test]
    fn rfs_start_status_and_stop() {
        let mut m = module("tmcm-1141");
        m.world_mut().axes[0].left_switch = Some(-50_000.0);
        assert_eq!(ok(&mut m, "RFS STATUS, 0"), 0);
        ok(&mut m, "SAP 193, 0, 1");
        ok(&mut m, "RFS START, 0");
        assert_eq!(ok(&mut m, "RFS STATUS, 0"), 1);
        assert_eq!(m.axes[0].params[ap::RAMP_MODE as usize], RampMode::Velocity as i32);
        m.advance(10 * MS);
        assert!(m.actual_speed(0) < 0, "mode 1 searches to the left");
        ok(&mut m, "RFS STOP, 0");
        assert_eq!(ok(&mut m, "RFS STATUS, 0"), 0);
        assert_eq!(ok(&mut m, "GAP 2, 0"), 0, "stopped");
    }

    #[test]
    fn rfs_with_a_mode_the_module_lacks() {
        let mut m = module("tmcm-1141");
        // +64 only with modes 1–4: AP 193 refuses 69 (status 4), and a
        // mode that got past it (EEPROM written by an older tmclsim) stops
        // RFS with status 4.
        assert_eq!(status(&mut m, "SAP 193, 0, 69"), Status::InvalidValue);
        m.axes[0].params[193] = 69;
        assert_eq!(status(&mut m, "RFS START, 0"), Status::InvalidValue);
        assert_eq!(ok(&mut m, "RFS STATUS, 0"), 0);
    }
}
