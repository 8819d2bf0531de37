//! Closed-loop operation (TMCM-1310): the ramp generator drives a virtual
//! position, the encoder measures the rotor, and the controller scales the
//! current to the load and corrects the position error instead of losing
//! steps. In open loop the rotor loses steps under overload as on the
//! TMCM-1141. Position, velocity and torque mode. (docs/closed-loop.md)
//!
//! The model, in the units of the module (its velocity units, µsteps):
//! - Rotor = virtual position − lag. In closed loop the current scale
//!   (AP 123, %) is what the load needs plus a reserve, between AP 113 and
//!   AP 114 (or AP 114 when regulation is off, AP 122 = 0); the lag grows
//!   while the load exceeds the torque at that scale and shrinks at the
//!   correction velocity (AP 126) when it does not. In open loop the
//!   current is AP 6 and lost steps stay lost.
//! - AP 1 is the rotor position measured by the encoder; AP 233 the
//!   virtual position; AP 237 their difference. A difference above AP 125
//!   raises interrupt 21 (deviation) and sets the EDV flag.
//! - Encoder (AP 201: 0 incremental ABN, counting from power-up; 1 absolute
//!   SSI): AP 210 counts per revolution of an AP 202 full-step motor. A
//!   lost encoder signal freezes the count.
//! - Torque mode (SAP 14, mA): the driver sets that current; the motor runs
//!   at the speed where its torque equals the load.

use crate::motion::RampMode;
use crate::motor::{Motor, MotorMut};
use crate::parameter_numbers::ap;

/// Current scale reserve above what the load needs (%).
pub const RESERVE_PERCENT: f64 = 20.0;

pub(crate) mod cl {
    pub const TORQUE_TARGET: u8 = 14;
    pub const MAX_POSSIBLE_CURRENT: u8 = 15;
    pub const VELOCITY_REACHED: u8 = 16;
    pub const VELOCITY_WINDOW: u8 = 17;
    pub const STATUS_WORD: u8 = 18;
    pub const TORQUE_ACTUAL: u8 = 19;
    pub const SCALE_MIN: u8 = 113;
    pub const SCALE_MAX: u8 = 114;
    pub const SCALE_ENABLE: u8 = 122;
    pub const SCALE_ACTUAL: u8 = 123;
    pub const MAX_FOLLOWING_ERROR: u8 = 125;
    pub const MAX_CORRECTION_VELOCITY: u8 = 126;
    pub const MODE: u8 = 129;
    pub const MEASURED_VELOCITY: u8 = 131;
    pub const INIT_FLAG: u8 = 133;
    pub const POSITION_WINDOW: u8 = 134;
    pub const ENCODER_MODE: u8 = 201;
    pub const FULLSTEPS: u8 = 202;
    pub const ENCODER_RESOLUTION: u8 = 210;
    pub const GAMMA: u8 = 230;
    pub const VIRTUAL_POSITION: u8 = 233;
    pub const TARGET_SCALE: u8 = 236;
    pub const POSITION_ERROR: u8 = 237;
}

pub use crate::state::axis::ClosedLoop;

impl Motor<'_> {
    /// The module's current for 100 % (features `full_scale_current_ma`),
    /// mA RMS.
    fn full_scale_ma(&self) -> f64 {
        f64::from(self.at.features().full_scale_current_ma)
    }

    /// The axis runs in closed loop (AP 129 = 1 on a module that can).
    pub(crate) fn closed_loop_on(&self) -> bool {
        self.at.features().closed_loop && self.axis.params[cl::MODE as usize] == 1
    }

    /// Virtual position minus rotor position, µsteps.
    pub(crate) fn lag(&self) -> f64 {
        let axis = self.axis;
        (axis.closed_loop.sync_offset - axis.mech_offset) * self.shaft_sign()
    }

    /// The world's load on the carriage now (% of the rated torque).
    fn load(&self) -> f64 {
        self.world.load_at(self.mechanical_position(), self.at.now_ns() as f64 * 1e-9)
    }

    /// Encoder counts of the rotor (raw, before SAP 209's offset).
    fn encoder_counts(&self) -> f64 {
        let p = &self.axis.params;
        let per_rev = f64::from(p[cl::FULLSTEPS as usize].max(1)) * self.axis.microsteps();
        self.mechanical_position() / per_rev * f64::from(p[cl::ENCODER_RESOLUTION as usize].max(1))
    }

    /// What the encoder delivers now: the rotor's count, or the last one
    /// while its signal is lost.
    fn encoder_now(&self) -> f64 {
        if self.world.encoder_lost { self.axis.closed_loop.encoder_last } else { self.encoder_counts() }
    }

    /// AP 209 of a closed-loop module.
    pub(crate) fn closed_loop_encoder(&self) -> i32 {
        let c = &self.axis.closed_loop;
        let absolute = self.axis.params[cl::ENCODER_MODE as usize] & 1 == 1;
        let now = self.encoder_now();
        let counts = if absolute { now } else { now - c.encoder_zero };
        (counts + c.encoder_offset).round() as i32
    }

    /// The rotor position the encoder reports, in µsteps of the counter.
    pub(crate) fn measured_position(&self) -> f64 {
        let p = &self.axis.params;
        let per_rev = f64::from(p[cl::FULLSTEPS as usize].max(1)) * self.axis.microsteps();
        let counts = self.encoder_now();
        // The counter and the rotor agreed at `sync_offset`.
        let mech = counts / f64::from(p[cl::ENCODER_RESOLUTION as usize].max(1)) * per_rev;
        (mech - self.axis.closed_loop.sync_offset) * self.shaft_sign()
    }

    /// Torque available at a current scale (% of rated torque).
    fn torque_at(&self, scale_percent: f64) -> f64 {
        let fullsteps = self.axis.motion.v.abs() / self.axis.microsteps();
        if self.driver_off() {
            return 0.0;
        }
        scale_percent * (1.0 - fullsteps / crate::driver::CORNER_FULLSTEPS).max(0.0)
    }

    /// The velocity (the module's units) at which the motor's torque at
    /// the torque-mode current equals the load.
    pub(crate) fn torque_mode_velocity(&self) -> f64 {
        let p = &self.axis.params;
        let target = f64::from(p[cl::TORQUE_TARGET as usize]);
        let percent = (target.abs() / self.full_scale_ma() * 100.0).min(100.0);
        let load = self.load();
        if self.driver_off() || percent <= load {
            return 0.0;
        }
        let fullsteps = crate::driver::CORNER_FULLSTEPS * (1.0 - load / percent);
        let pps = fullsteps * self.axis.microsteps();
        let units = self.units();
        units.velocity_value(pps).min(f64::from(units.max_value())) * target.signum()
    }

    /// Reads of the closed-loop parameters; `None` for the others.
    pub(crate) fn read_closed_loop(&self, param: u8) -> Option<i32> {
        if !self.at.features().closed_loop {
            return None;
        }
        let axis = self.axis;
        let p = &axis.params;
        let torque_ma = if axis.closed_loop.torque_mode {
            f64::from(p[cl::TORQUE_TARGET as usize]).clamp(-self.full_scale_ma(), self.full_scale_ma())
        } else {
            axis.closed_loop.scale / 100.0 * self.full_scale_ma()
        };
        Some(match param {
            ap::ACTUAL_POSITION if self.closed_loop_on() => self.measured_position().round() as i32,
            ap::POSITION_REACHED => i32::from(self.closed_loop_target_reached()),
            cl::MAX_POSSIBLE_CURRENT => self.full_scale_ma() as i32,
            cl::VELOCITY_REACHED => i32::from(self.velocity_reached()),
            cl::STATUS_WORD => self.status_word(),
            cl::TORQUE_ACTUAL => torque_ma.round() as i32,
            cl::SCALE_ACTUAL | cl::TARGET_SCALE => {
                if axis.closed_loop.torque_mode {
                    (torque_ma.abs() / self.full_scale_ma() * 100.0).round() as i32
                } else {
                    axis.closed_loop.scale.round() as i32
                }
            }
            cl::MEASURED_VELOCITY => self.units().velocity_value(axis.closed_loop.rotor_velocity).round() as i32,
            cl::INIT_FLAG => i32::from(self.closed_loop_on()),
            ap::ENCODER_POSITION => self.closed_loop_encoder(),
            cl::GAMMA => {
                let torque = self.torque_at(axis.closed_loop.scale.max(1.0));
                (256.0 * (self.load() / torque.max(1e-9)).min(1.0)).round() as i32
            }
            cl::VIRTUAL_POSITION => self.wrap_position(axis.motion.position()),
            cl::POSITION_ERROR => (axis.motion.x - self.measured_position()).round() as i32,
            _ => return None,
        })
    }

    fn closed_loop_target_reached(&self) -> bool {
        let axis = self.axis;
        let window = f64::from(axis.params[cl::POSITION_WINDOW as usize].max(0));
        if !self.closed_loop_on() {
            return self.actual_position() == axis.target_word;
        }
        axis.motion.mode != RampMode::Velocity
            && axis.motion.v == 0.0
            && (f64::from(axis.target_word) - self.measured_position()).abs() <= window.max(0.5)
    }

    fn velocity_reached(&self) -> bool {
        let axis = self.axis;
        let window = axis.params[cl::VELOCITY_WINDOW as usize].max(0);
        (self.actual_speed() - axis.params[ap::TARGET_SPEED as usize]).abs() <= window
    }

    /// AP 18 (bits per tmcm-1310.md).
    pub(crate) fn status_word(&self) -> i32 {
        let axis = self.axis;
        let (l, r, h) = self.switches();
        let velocity = axis.motion.mode == RampMode::Velocity && !axis.closed_loop.torque_mode;
        let bits = [
            self.closed_loop_target_reached(),
            self.velocity_reached(),
            self.closed_loop_on(),
            axis.motion.mode != RampMode::Velocity,
            velocity,
            axis.closed_loop.torque_mode,
            h,
            l,
            r,
            self.at.supply_decivolts() < crate::driver::UNDERVOLTAGE_DV,
            self.at.supply_decivolts() > 550,
            self.at.temperature() >= crate::driver::SHUTDOWN_C,
        ];
        bits.iter().enumerate().fold(0, |w, (i, b)| w | i32::from(*b) << i)
    }
}

impl MotorMut<'_> {
    /// Sets the encoder at power-up and when the counter is set.
    pub(crate) fn closed_loop_sync(&mut self) {
        if !self.at.features().closed_loop {
            return;
        }
        let counts = self.view().encoder_counts();
        let axis = &mut *self.axis;
        axis.closed_loop.sync_offset = axis.mech_offset;
        axis.closed_loop.encoder_last = counts;
    }

    /// At power-up: an incremental encoder counts from here.
    pub(crate) fn closed_loop_power_on(&mut self) {
        if !self.at.features().closed_loop {
            return;
        }
        self.closed_loop_sync();
        let counts = self.axis.closed_loop.encoder_last;
        self.axis.closed_loop.encoder_zero = counts;
    }

    /// After a step of `dt` seconds in which the virtual position moved by
    /// `moved`: current regulation, lag, correction, encoder, deviation.
    /// `open_loop_slips`: in open loop, the driver model says the rotor
    /// could not follow. True when a deviation is to be reported.
    pub(crate) fn closed_loop_step(&mut self, moved: f64, dt: f64, open_loop_slips: bool) -> bool {
        let p = self.axis.params;
        let units = self.view().units();
        let load = self.view().load();
        let sign = self.view().shaft_sign();
        let before = self.view().mechanical_position() - moved * sign;
        if self.view().closed_loop_on() {
            let (lo, hi) = (f64::from(p[cl::SCALE_MIN as usize].clamp(0, 100)), f64::from(p[cl::SCALE_MAX as usize].clamp(0, 100)));
            let speed_factor = (1.0 - self.axis.motion.v.abs() / self.axis.microsteps() / crate::driver::CORNER_FULLSTEPS).max(0.01);
            let needed = load / speed_factor + RESERVE_PERCENT;
            let scale = if self.axis.closed_loop.torque_mode {
                f64::from(p[cl::TORQUE_TARGET as usize]).abs() / self.view().full_scale_ma() * 100.0
            } else if p[cl::SCALE_ENABLE as usize] == 1 {
                needed.clamp(lo.min(hi), hi)
            } else {
                hi
            };
            self.axis.closed_loop.scale = scale;
            let torque = self.view().torque_at(scale);
            let axis = &mut *self.axis;
            if moved != 0.0 && load > torque {
                // The rotor stalls; the controller keeps the error.
                axis.mech_offset -= moved * sign;
            } else {
                // Correct the error at up to the correction velocity.
                let lag = (axis.closed_loop.sync_offset - axis.mech_offset) * sign;
                let v_corr = units.velocity_pps(f64::from(p[cl::MAX_CORRECTION_VELOCITY as usize].clamp(0, units.max_value())));
                let step = (v_corr * dt).min(lag.abs());
                if load <= torque {
                    axis.mech_offset += step * lag.signum() * sign;
                }
            }
        } else {
            // Open loop: lost steps stay lost.
            self.axis.closed_loop.scale = (f64::from(self.view().motor_current()) / 255.0 * 100.0).round();
            let axis = &mut *self.axis;
            if open_loop_slips {
                axis.mech_offset -= moved * sign;
            }
            axis.closed_loop.sync_offset = axis.mech_offset;
        }
        self.keep_within_travel();
        if dt > 0.0 {
            self.axis.closed_loop.rotor_velocity = (self.view().mechanical_position() - before) * sign / dt;
        }
        // The encoder counts the rotor, unless its signal is lost. Its index
        // (N) pulse comes once per revolution; with AP 201 bit 2 the next
        // one clears the count.
        if !self.world.encoder_lost {
            let last = self.axis.closed_loop.encoder_last;
            let now = self.view().encoder_counts();
            let per_rev = f64::from(p[cl::ENCODER_RESOLUTION as usize].max(1));
            let (a, b) = ((last / per_rev).floor(), (now / per_rev).floor());
            let index = if now >= last { (a < b).then_some(b * per_rev) } else { (b < a).then_some(a * per_rev) };
            if let (Some(at), true) = (index, p[cl::ENCODER_MODE as usize] & 0b101 == 0b100) {
                let c = &mut self.axis.closed_loop;
                c.encoder_offset = c.encoder_zero - at;
                self.axis.params[cl::ENCODER_MODE as usize] &= !4;
            }
            self.axis.closed_loop.encoder_last = now;
        }
        // Deviation: measured rotor against the virtual position.
        let limit = p[cl::MAX_FOLLOWING_ERROR as usize];
        let error = (self.axis.motion.x - self.view().measured_position()).abs();
        let mut report = false;
        if limit > 0 && error > f64::from(limit) {
            if !self.axis.closed_loop.deviation_reported {
                self.axis.closed_loop.deviation_reported = true;
                self.axis.params[ap::EXTENDED_ERROR_FLAGS as usize] |= 2;
                report = true;
            }
        } else {
            self.axis.closed_loop.deviation_reported = false;
        }
        if self.world.encoder_lost {
            self.axis.params[ap::EXTENDED_ERROR_FLAGS as usize] |= 4;
        }
        report
    }
}
