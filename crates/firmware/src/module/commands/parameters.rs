//! The parameter commands: SAP, GAP, STAP, RSAP, AAP for axis parameters
//! and SGP, GGP, STGP, RSGP, AGP for global parameters — their access and
//! range checks, the side effects of writes and the measured values reads
//! compute. The tables, access and range checks are the parameter
//! tables' (`state/parameters.rs`), the stores and restores the EEPROM
//! part's (`state/persistence.rs`); here the module coordinates them with
//! the axes, the program and virtual time.

use crate::closed_loop::cl;
use crate::module::Module;
use crate::motion::RampMode;
use crate::parameter_numbers::{ap, gp, sp};
use crate::state::parameters::{axis_spec, global_spec, takes};
use tmclsim_protocol::Status;

impl Module {
    /// STAP: stores an axis parameter's value in the EEPROM.
    pub(crate) fn store_axis_parameter(&mut self, param: u8, motor: u8) -> Result<(), Status> {
        let m = self.motor(motor)?;
        axis_spec(&self.profile, param, |a| a.eeprom)?;
        self.persistence.store_axis(&self.globals, motor, param, self.axes[m].params[param as usize])
    }

    /// RSAP: an axis parameter takes its value from the EEPROM again.
    pub(crate) fn restore_axis_parameter(&mut self, param: u8, motor: u8) -> Result<(), Status> {
        let m = self.motor(motor)?;
        let v = self.persistence.restore_axis(motor, axis_spec(&self.profile, param, |a| a.eeprom)?);
        self.write_axis_parameter(m, param, v);
        Ok(())
    }

    /// STGP: stores a global parameter's value in the EEPROM.
    pub(crate) fn store_global_parameter(&mut self, param: u8, bank: u8) -> Result<(), Status> {
        global_spec(&self.profile, param, bank, |a| a.eeprom)?;
        self.persistence.store_global_checked(&self.globals, bank, param)
    }

    /// RSGP: a global parameter takes its value from the EEPROM again.
    pub(crate) fn restore_global_parameter(&mut self, param: u8, bank: u8) -> Result<(), Status> {
        let v = self.persistence.restore_global(bank, global_spec(&self.profile, param, bank, |a| a.eeprom)?);
        self.globals[bank as usize][param as usize] = v;
        Ok(())
    }

    /// SAP: writes axis parameter `param` of `motor` after the profile's access
    /// and range checks; the status says why a write was refused.
    pub fn set_axis_parameter(&mut self, param: u8, motor: u8, value: i32) -> Result<(), Status> {
        let m = self.motor(motor)?;
        takes(axis_spec(&self.profile, param, |a| a.write)?, value)?;
        self.write_axis_parameter(m, param, value);
        Ok(())
    }

    /// GAP: reads axis parameter `param` of `motor` (measured values are
    /// computed at the module's now); the status says why a read was refused.
    pub fn get_axis_parameter(&mut self, param: u8, motor: u8) -> Result<i32, Status> {
        let m = self.motor(motor)?;
        axis_spec(&self.profile, param, |a| a.read)?;
        Ok(self.read_axis_parameter(m, param))
    }

    /// What GAP would answer, without its effects (AP 207 is not cleared):
    /// an observer's look (docs/behaviour.md rule 86).
    pub fn peek_axis_parameter(&self, param: u8, motor: u8) -> Result<i32, Status> {
        let m = self.motor(motor)?;
        axis_spec(&self.profile, param, |a| a.read)?;
        Ok(self.axis_parameter_value(m, param))
    }

    /// Writes a parameter with its side effects (no access check).
    pub(crate) fn write_axis_parameter(&mut self, m: usize, param: u8, value: i32) {
        let closed_loop = self.profile.features.closed_loop;
        let encoder = self.profile.features.encoder != tmclsim_profile::Encoder::None;
        let mut motor = self.motor_view_mut(m);
        // AP 251 reverses the shaft on the sixPoint and TMC4361A modules.
        let shaft_row = motor.view().six_point() || motor.view().tmc4361a();
        match param {
            // The shaft turns the other way from now on; the carriage stays
            // where it is (docs/behaviour.md rule 108).
            sp::REVERSE_SHAFT if shaft_row => {
                let mech = motor.view().mechanical_position();
                motor.axis.params[param as usize] = value;
                let sign = motor.view().shaft_sign();
                motor.axis.mech_offset = mech - motor.axis.motion.x * sign;
            }
            ap::TARGET_POSITION => motor.set_target(value),
            ap::ACTUAL_POSITION => motor.set_counter(value),
            ap::RAMP_MODE if motor.axis.ramp_mode_row => {
                motor.axis.set_ramp_mode(RampMode::from_code(value));
                // AP 138 keeps the word as written.
                motor.axis.params[param as usize] = value;
            }
            ap::ENCODER_POSITION if closed_loop => {
                let now = f64::from(motor.view().closed_loop_encoder()) - motor.axis.closed_loop.encoder_offset;
                motor.axis.closed_loop.encoder_offset = f64::from(value) - now;
            }
            // Without an encoder input AP 209 is a plain value (profiles/README.md).
            ap::ENCODER_POSITION if encoder => {
                let now = i64::from(motor.view().encoder_position()) - motor.axis.encoder_offset;
                motor.axis.encoder_offset = i64::from(value) - now;
            }
            cl::TORQUE_TARGET if closed_loop => {
                // Torque mode: the driver sets this current (mA).
                let axis = &mut *motor.axis;
                axis.params[param as usize] = value;
                axis.end_overrides();
                axis.closed_loop.torque_mode = true;
                axis.set_ramp_mode(RampMode::Velocity);
            }
            cl::MODE if closed_loop => {
                motor.axis.params[param as usize] = value;
                motor.closed_loop_sync();
            }
            _ => motor.axis.params[param as usize] = value,
        }
    }

    /// Reads a parameter, computing the measured ones, with the effects of
    /// a read (AP 207 is cleared by reading where the module's features
    /// say so, docs/behaviour.md rule 52).
    pub(crate) fn read_axis_parameter(&mut self, m: usize, param: u8) -> i32 {
        let v = self.axis_parameter_value(m, param);
        if param == ap::EXTENDED_ERROR_FLAGS && self.profile.features.error_flags.cleared_by_read {
            self.axes[m].params[param as usize] = 0;
        }
        v
    }

    /// A parameter's value as a read finds it, computing the measured ones.
    pub(crate) fn axis_parameter_value(&self, m: usize, param: u8) -> i32 {
        self.motor_view(m).parameter(param)
    }

    /// SGP: writes global parameter `param` of `bank` after the profile's
    /// access and range checks, with the parameter's side effects (address,
    /// ASCII mode, download mode…).
    pub fn set_global_parameter(&mut self, param: u8, bank: u8, value: i32) -> Result<(), Status> {
        let spec = global_spec(&self.profile, param, bank, |a| a.write)?;
        takes(spec, value)?;
        let auto = spec.access.auto;
        if self.persistence.is_lock(bank, param) {
            return self.persistence.set_lock(&mut self.globals, param, value);
        }
        if auto {
            self.persistence.check_unlocked(&self.globals)?;
        }
        match (bank, param) {
            (0, gp::TICK_TIMER) => self.globals.set_tick_timer(self.now_ns, i64::from(value)),
            (0, gp::RANDOM) => self.globals.seed_random(value),
            (0, gp::CODE_PROTECTION) => {
                let old = self.globals[0][param as usize];
                if matches!(old, 1 | 3) && matches!(value, 0 | 2) {
                    // Lifting the protection against reading erases the program.
                    self.program.erase();
                    self.persistence.erase_program();
                }
                self.globals[0][param as usize] = value;
            }
            (3, _) => {
                self.globals[3][param as usize] = value;
                // A new period restarts the timer whose interrupt this
                // parameter configures (bank 3 is indexed by interrupt
                // number, the timers by 0…2).
                if let Some(t) = (0..3u8).find(|&t| self.profile.timer_interrupt(t) == Some(param)) {
                    self.program.timers[t as usize] = None;
                }
            }
            _ => self.globals[bank as usize][param as usize] = value,
        }
        if auto {
            self.persistence.store_global(bank, param, value);
        }
        Ok(())
    }

    /// GGP: reads global parameter `param` of `bank` (GP 133 draws a new random
    /// number).
    pub fn get_global_parameter(&mut self, param: u8, bank: u8) -> Result<i32, Status> {
        let v = self.peek_global_parameter(param, bank)?;
        if (bank, param) == (0, gp::RANDOM) {
            // Reading takes the number.
            return Ok(self.globals.random());
        }
        Ok(v)
    }

    /// What GGP would answer, without its effects (GP 133 does not move to
    /// its next number): an observer's look (docs/behaviour.md rule 86).
    pub fn peek_global_parameter(&self, param: u8, bank: u8) -> Result<i32, Status> {
        global_spec(&self.profile, param, bank, |a| a.read)?;
        Ok(match (bank, param) {
            (0, gp::TICK_TIMER) => self.globals.tick_timer(self.now_ns),
            (0, gp::APPLICATION_STATUS) => self.program.mode as i32,
            (0, gp::DOWNLOAD_MODE) => i32::from(self.program.download.is_some()),
            (0, gp::PROGRAM_COUNTER) => i32::from(self.program.counter()),
            (0, gp::RANDOM) => self.globals.peek_random(),
            _ => self.globals[bank as usize][param as usize],
        })
    }
}

#[cfg(test)]
mod tests {
    use crate::state::registers::Compare;
    use crate::test_support::{direct, in_program, module, ok, status};
    use tmclsim_protocol::Status;

    #[test]
    fn sap_range_and_access_statuses() {
        let mut m = module("tmcm-1141");
        assert_eq!(direct(&mut m, "SAP 4, 0, 2047"), (Status::Ok, 2047));
        assert_eq!(direct(&mut m, "SAP 4, 0, 2048"), (Status::InvalidValue, 2048), "above the range");
        assert_eq!(status(&mut m, "SAP 4, 0, 0"), Status::InvalidValue, "below the range");
        assert_eq!(status(&mut m, "SAP 3, 0, 1"), Status::WrongType, "read-only");
        assert_eq!(status(&mut m, "SAP 250, 0, 1"), Status::WrongType, "not in the table");
        assert_eq!(status(&mut m, "SAP 4, 1, 100"), Status::InvalidValue, "no motor 1");
        assert_eq!(status(&mut m, "GAP 14, 0"), Status::WrongType);
        assert_eq!(status(&mut m, "GAP 4, 1"), Status::InvalidValue);
        assert_eq!(ok(&mut m, "GAP 4, 0"), 2047, "a failed SAP changes nothing");
    }

    #[test]
    fn reference_search_mode_takes_the_manuals_modes_only() {
        // AP 193: modes 1–8, +64 on modes 1–4, +128 on modes 5–8.
        let mut m = module("tmcm-1141");
        for v in [1, 4, 8, 65, 68, 133, 136] {
            assert_eq!(status(&mut m, &format!("SAP 193, 0, {v}")), Status::Ok, "mode {v}");
        }
        for v in [0, 9, 50, 64, 69, 100, 132, 137] {
            assert_eq!(status(&mut m, &format!("SAP 193, 0, {v}")), Status::InvalidValue, "mode {v}");
        }
        assert_eq!(ok(&mut m, "GAP 193, 0"), 136, "a refused mode changes nothing");
    }

    #[test]
    fn aap_and_agp_write_the_accumulator() {
        let mut m = module("tmcm-1141");
        ok(&mut m, "CALC LOAD, 1500");
        ok(&mut m, "AAP 4, 0");
        assert_eq!(ok(&mut m, "GAP 4, 0"), 1500);
        ok(&mut m, "CALC LOAD, 9");
        ok(&mut m, "AGP 10, 2");
        assert_eq!(ok(&mut m, "GGP 10, 2"), 9);
        ok(&mut m, "CALC LOAD, 5000");
        assert_eq!(status(&mut m, "AAP 4, 0"), Status::InvalidValue, "the range applies");
    }

    #[test]
    fn reads_load_the_accumulator_only_in_a_program() {
        let mut m = module("tmcm-1141");
        ok(&mut m, "SAP 4, 0, 321");
        assert_eq!(ok(&mut m, "GAP 4, 0"), 321);
        assert_eq!(m.registers.accumulator, 0);
        assert_eq!(in_program(&mut m, "GAP 4, 0"), Ok(321));
        assert_eq!((m.registers.accumulator, m.registers.compare), (321, Compare::Greater));
        assert_eq!(in_program(&mut m, "GGP 66, 0"), Ok(1));
        assert_eq!(m.registers.accumulator, 1);
    }

    #[test]
    fn stap_and_rsap_go_through_the_eeprom() {
        let mut m = module("tmcm-1141");
        let written = m.eeprom_generation();
        ok(&mut m, "SAP 4, 0, 1000");
        ok(&mut m, "STAP 4, 0");
        assert!(m.eeprom_generation() > written);
        assert_eq!(m.eeprom().axis(0, 4), Some(1000));
        ok(&mut m, "SAP 4, 0, 10");
        ok(&mut m, "RSAP 4, 0");
        assert_eq!(ok(&mut m, "GAP 4, 0"), 1000);
        assert_eq!(status(&mut m, "STAP 6, 0"), Status::WrongType, "AP 6 is not stored");
        // RSAP of a parameter never stored: the default.
        ok(&mut m, "SAP 5, 0, 7");
        ok(&mut m, "RSAP 5, 0");
        assert_eq!(ok(&mut m, "GAP 5, 0"), m.profile().axis_parameter(5).unwrap().default as i32);
    }

    #[test]
    fn global_parameters_banks_and_automatic_storage() {
        let mut m = module("tmcm-1141");
        assert_eq!(status(&mut m, "GGP 0, 1"), Status::InvalidValue, "no bank 1");
        assert_eq!(status(&mut m, "GGP 0, 4"), Status::InvalidValue);
        assert_eq!(status(&mut m, "SGP 128, 0, 1"), Status::WrongType, "read-only");
        assert_eq!(status(&mut m, "SGP 65, 0, 9"), Status::InvalidValue);
        // Bank 0 parameters with A are stored by SGP itself.
        let written = m.eeprom_generation();
        ok(&mut m, "SGP 76, 0, 5");
        assert_eq!((m.eeprom().global(0, 76), m.eeprom_generation()), (Some(5), written + 1));
        // User variables: STGP/RSGP.
        ok(&mut m, "SGP 7, 2, 1234");
        ok(&mut m, "STGP 7, 2");
        ok(&mut m, "SGP 7, 2, 0");
        ok(&mut m, "RSGP 7, 2");
        assert_eq!(ok(&mut m, "GGP 7, 2"), 1234);
    }

    #[test]
    fn eeprom_lock_gp73() {
        let mut m = module("tmcm-351");
        assert_eq!(status(&mut m, "SGP 73, 0, 1"), Status::InvalidValue, "1234 locks, 4321 unlocks");
        ok(&mut m, "SGP 73, 0, 1234");
        assert_eq!(ok(&mut m, "GGP 73, 0"), 1);
        assert_eq!(status(&mut m, "STAP 4, 0"), Status::EepromLocked);
        assert_eq!(status(&mut m, "STGP 0, 2"), Status::EepromLocked);
        ok(&mut m, "SGP 73, 0, 4321");
        assert_eq!(ok(&mut m, "GGP 73, 0"), 0);
        assert_eq!(status(&mut m, "STAP 4, 0"), Status::Ok);
    }

    #[test]
    fn ramp_mode_and_measured_values() {
        let mut m = module("tmcm-1141");
        ok(&mut m, "SAP 138, 0, 2");
        assert_eq!(m.axes[0].motion.mode, crate::motion::RampMode::Velocity);
        ok(&mut m, "SAP 1, 0, 4000");
        assert_eq!((ok(&mut m, "GAP 1, 0"), ok(&mut m, "GAP 0, 0")), (4000, 0));
        assert_eq!(ok(&mut m, "GAP 8, 0"), 0, "not at the target");
        ok(&mut m, "SAP 0, 0, 4000");
        assert_eq!(ok(&mut m, "GAP 8, 0"), 1);
        m.axes[0].params[207] = 3;
        assert_eq!((ok(&mut m, "GAP 207, 0"), ok(&mut m, "GAP 207, 0")), (3, 0), "cleared by reading");
    }

    #[test]
    fn tick_timer_and_random_seed() {
        let mut m = module("tmcm-1141");
        ok(&mut m, "SGP 132, 0, 1000");
        m.advance(25_000_000);
        assert_eq!(ok(&mut m, "GGP 132, 0"), 1025);
        ok(&mut m, "SGP 133, 0, 99");
        let a = [ok(&mut m, "GGP 133, 0"), ok(&mut m, "GGP 133, 0")];
        ok(&mut m, "SGP 133, 0, 99");
        assert_eq!([ok(&mut m, "GGP 133, 0"), ok(&mut m, "GGP 133, 0")], a, "the same seed, the same numbers");
    }

    // ----- the motor model read through the parameters (mechanics.rs)

    #[test]
    fn positions_wrap_in_the_counter_width() {
        let m = crate::test_support::module_24_bit();
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
        assert!(m.motor_view(0).stops_at(0.0).block_negative);
        ok(&mut m, "SAP 13, 0, 1");
        assert!(!m.motor_view(0).stops_at(0.0).block_negative, "AP 13 disables the left switch");
        ok(&mut m, "SGP 79, 0, 1");
        assert_eq!(m.switches(0), (false, true, false), "GP 79 inverts the stop switches");
    }

    #[test]
    fn ramp_follows_the_axis_parameters() {
        let mut m = module("tmcm-1141");
        ok(&mut m, "SAP 4, 0, 1000");
        ok(&mut m, "SAP 154, 0, 3");
        let r = m.motor_view(0).ramp();
        assert_eq!(r.vmax, crate::motion::velocity_pps(1000.0, 3));
        ok(&mut m, "ROR 0, 200");
        assert_eq!(m.motor_view(0).ramp().target_velocity, crate::motion::velocity_pps(200.0, 3));
    }
}
