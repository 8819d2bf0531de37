//! One motor axis: its parameter RAM, the ramp generator, coordinates, and
//! the per-axis state of the reference search, the driver and the closed
//! loop.

use crate::motion::{self, Motion, Ramp, RampMode, SixPoint, Tmc4361a, Units};
use crate::parameter_numbers::{ap, sp, tmc4361a};
use crate::reference_search::ReferenceSearch;
use std::cell::Cell;
use tmclsim_profile::MotionController;
use tmclsim_protocol::Status;

/// One motor axis.
#[derive(Clone, Debug)]
pub struct Axis {
    /// RAM values of the axis parameters (stored ones; measured ones are
    /// computed on read).
    pub params: [i32; 256],
    /// The ramp generator: position, velocity and ramp of the motor.
    pub motion: Motion,
    /// AP 0 as the host wrote it.
    pub target_word: i32,
    /// Coordinates 0…N.
    pub coordinates: Vec<i32>,
    /// Mechanical position minus motor position counter.
    pub mech_offset: f64,
    /// Virtual time (ns) since which the motor stands still.
    pub standstill_since: Option<u64>,
    /// A 138 event is due when this axis reaches its target.
    pub notify_on_arrival: bool,
    /// The reference search in progress.
    pub rfs: Option<ReferenceSearch>,
    /// The motor driver's state (currents, stallGuard, faults).
    pub driver: Driver,
    /// An interpolated move's ramp (MVP COORD with bit 6), until it ends.
    pub ramp_override: Option<Ramp>,
    /// AP 209 minus what the encoder measures (set by SAP 209).
    pub encoder_offset: i64,
    /// The closed-loop controller's state (modules with an encoder and
    /// closed-loop mode).
    pub closed_loop: ClosedLoop,
    /// The largest speed ROR and ROL take: the range of AP 2 (2047 on
    /// TMC429 modules).
    pub speed_limit: i32,
    /// The plain ramp last worked out and the parameter words it came
    /// from (`Module::ramp`).
    pub(crate) ramp_cache: Cell<Option<(RampKey, Ramp)>>,
    /// AP 138 is the ramp mode (the TMC429 modules'); elsewhere the mode
    /// is the ramp generator's alone and AP 138 a row of its own.
    pub ramp_mode_row: bool,
}

impl Axis {
    /// An axis at power-up: its parameters and coordinates as restored, the
    /// ramp generator at rest in the mode AP 138 selects, the carriage
    /// `mech_offset` away from the position counter's zero.
    pub fn new(params: [i32; 256], coordinates: Vec<i32>, mech_offset: f64, now_ns: u64) -> Axis {
        let mode = RampMode::from_code(params[ap::RAMP_MODE as usize]);
        Axis {
            params,
            motion: Motion { mode, ..Motion::default() },
            target_word: 0,
            coordinates,
            mech_offset,
            standstill_since: Some(now_ns),
            notify_on_arrival: false,
            rfs: None,
            driver: Driver::default(),
            ramp_override: None,
            encoder_offset: 0,
            closed_loop: Default::default(),
            speed_limit: 2047,
            ramp_cache: Cell::new(None),
            ramp_mode_row: true,
        }
    }

    /// Selects a ramp mode: AP 138 and the ramp generator's mode together.
    pub fn set_ramp_mode(&mut self, mode: RampMode) {
        if self.ramp_mode_row {
            self.params[ap::RAMP_MODE as usize] = mode as i32;
        }
        self.motion.mode = mode;
    }

    /// ROR, ROL, MST: velocity mode at `speed` (AP 2), no override, no
    /// arrival to report.
    pub fn run_at(&mut self, speed: i32) {
        self.end_overrides();
        self.params[ap::TARGET_SPEED as usize] = speed;
        self.set_ramp_mode(RampMode::Velocity);
        self.notify_on_arrival = false;
    }

    /// ROR, ROL (`sign` 1, −1) with a speed within ±`speed_limit` (else
    /// status 4): the motion errors are cleared and the axis runs at
    /// `velocity · sign`.
    pub fn rotate(&mut self, velocity: i32, sign: i32) -> Result<(), Status> {
        if !(-self.speed_limit..=self.speed_limit).contains(&velocity) {
            return Err(Status::InvalidValue);
        }
        self.clear_motion_errors();
        self.run_at(velocity * sign);
        Ok(())
    }

    /// A hard stop (the driver's protections): velocity mode, zero speed,
    /// at once.
    pub fn stop_now(&mut self) {
        self.run_at(0);
        self.motion.v = 0.0;
    }

    /// µsteps per full step (AP 140: 2 to the power 0…8).
    pub fn microsteps(&self) -> f64 {
        motion::pow2(self.params[ap::MICROSTEP_RESOLUTION as usize].clamp(0, 8))
    }

    /// A reference search is running on this axis (RFS STATUS).
    pub fn reference_search_active(&self) -> bool {
        self.rfs.is_some()
    }

    /// A new motion command clears the motion errors of AP 207.
    pub fn clear_motion_errors(&mut self) {
        self.params[ap::EXTENDED_ERROR_FLAGS as usize] = 0;
    }

    /// The plain ramp (no override, torque mode or reference search):
    /// the one last worked out while the parameters it comes from are
    /// the same, else `work_out`'s.
    pub(crate) fn plain_ramp(&self, work_out: impl FnOnce() -> Ramp) -> Ramp {
        let key = RampKey::of(&self.params);
        if let Some((k, r)) = self.ramp_cache.get()
            && k == key
        {
            return r;
        }
        let r = work_out();
        self.ramp_cache.set(Some((key, r)));
        r
    }

    /// Works the ramp out from the axis parameters in µsteps and seconds,
    /// their values read in `units`: the target speed is
    /// `torque_velocity` in torque mode (in `units`), the reference
    /// search's while one runs.
    pub(crate) fn work_out_ramp(&self, units: Units, controller: MotionController, torque_velocity: Option<f64>) -> Ramp {
        let p = &self.params;
        let max = units.max_value();
        let value = |n: u8| f64::from(p[n as usize].clamp(0, max));
        let a = p[ap::MAX_ACCELERATION as usize].clamp(0, max) as u32;
        let mut vmax = value(ap::MAX_SPEED);
        let mut target_velocity = f64::from(p[ap::TARGET_SPEED as usize]);
        if let Some(v) = torque_velocity {
            target_velocity = v;
        }
        if let Some(rfs) = &self.rfs {
            let slow = value(ap::REFERENCE_SWITCH_SPEED);
            match rfs.current() {
                Some(seek) => {
                    let fast = value(ap::REFERENCE_SEARCH_SPEED);
                    target_velocity = seek.dir * if seek.fast { fast } else { slow };
                }
                None => vmax = slow.max(1.0),
            }
        }
        let six = match (controller, units) {
            (MotionController::Sixpoint | MotionController::Eightpoint, Units::Sixpoint { fclk, .. }) => {
                Some(self.six_point(units, f64::from(fclk), controller == MotionController::Eightpoint))
            }
            _ => None,
        };
        Ramp {
            vmax: units.velocity_pps(vmax),
            vmin: units.velocity_pps(value(ap::MIN_SPEED)),
            accel_position: units.positioning_accel_pps2(a.max(1)),
            accel_velocity: units.accel_pps2(f64::from(a.max(1))),
            target_velocity: units.velocity_pps(target_velocity),
            six,
        }
    }

    /// The sixPoint ramp's values (AP 15…21; with `eight`, the
    /// eight-point ramp's A2, V2, D2, AP 34…36) in µsteps and seconds; an
    /// acceleration of 0 acts as the smallest one, so that every ramp
    /// ends (docs/behaviour.md rules 105, 113).
    fn six_point(&self, units: Units, fclk: f64, eight: bool) -> SixPoint {
        let p = &self.params;
        let value = |n: u8| f64::from(p[n as usize].max(0));
        let accel = |n: u8| units.accel_pps2(value(n).max(1.0));
        SixPoint {
            vstart: units.velocity_pps(value(sp::VSTART)),
            a1: accel(sp::A1),
            v1: units.velocity_pps(value(sp::V1)),
            dmax: accel(sp::DMAX),
            d1: accel(sp::D1),
            a2: if eight { accel(sp::A2) } else { 0.0 },
            v2: if eight { units.velocity_pps(value(sp::V2)) } else { 0.0 },
            d2: if eight { accel(sp::D2) } else { 0.0 },
            vstop: units.velocity_pps(value(sp::VSTOP)),
            zero_wait: value(sp::RAMP_WAIT) * 512.0 / fclk,
        }
    }

    /// The TMC4361A's ramp values (AP 14–25) in µsteps and seconds, read
    /// in `units` (bows in pps³ in either unit mode); an acceleration of 0
    /// acts as the smallest the register holds (docs/behaviour.md rules
    /// 114–118).
    pub(crate) fn tmc4361a_ramp(&self, units: Units) -> Tmc4361a {
        let p = &self.params;
        let value = |n: u8| f64::from(p[n as usize].max(0));
        let speed = |n: u8| units.velocity_pps(value(n));
        let accel = |n: u8| units.accel_pps2(value(n));
        let bow = |n: u8| value(n).min(16_777_215.0);
        Tmc4361a {
            s_shaped: p[tmc4361a::RAMP_TYPE as usize] == 1,
            vstart: speed(tmc4361a::VSTART),
            astart: accel(tmc4361a::ASTART),
            vbreak: speed(tmc4361a::VBREAK),
            dmax: accel(tmc4361a::DMAX),
            dfinal: accel(tmc4361a::DFINAL),
            vstop: speed(tmc4361a::VSTOP),
            dstop: accel(tmc4361a::DSTOP),
            bows: [bow(tmc4361a::BOW1), bow(tmc4361a::BOW2), bow(tmc4361a::BOW3), bow(tmc4361a::BOW4)],
        }
    }

    /// Ends what takes the ramp generator over from the plain ramp: a
    /// reference search, an interpolated move's ramp, torque mode.
    pub fn end_overrides(&mut self) {
        self.rfs = None;
        self.ramp_override = None;
        self.closed_loop.torque_mode = false;
    }
}

/// The axis parameters a plain ramp comes from (AP 4, 2, 130, 5, 154,
/// 153; the sixPoint's 15…21, the eight-point's 34…36 and the unit mode
/// 255), as their words: the
/// ramp worked out for them stays valid while they are the same.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct RampKey([i32; 17]);

impl RampKey {
    fn of(p: &[i32; 256]) -> RampKey {
        RampKey([
            p[ap::MAX_SPEED as usize],
            p[ap::TARGET_SPEED as usize],
            p[ap::MIN_SPEED as usize],
            p[ap::MAX_ACCELERATION as usize],
            p[ap::PULSE_DIVISOR as usize],
            p[ap::RAMP_DIVISOR as usize],
            p[sp::A1 as usize],
            p[sp::V1 as usize],
            p[sp::DMAX as usize],
            p[sp::D1 as usize],
            p[sp::VSTART as usize],
            p[sp::VSTOP as usize],
            p[sp::RAMP_WAIT as usize],
            p[sp::UNIT_MODE as usize],
            p[sp::A2 as usize],
            p[sp::V2 as usize],
            p[sp::D2 as usize],
        ])
    }
}

/// Per-axis driver state.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Driver {
    /// Last stallGuard2 reading, 0…1023.
    pub load_value: i32,
    /// coolStep's current scale (0…31), while coolStep regulates.
    pub cool_scale: Option<f64>,
    /// Measurements towards the next coolStep decrement.
    pub down_count: f64,
}

/// Per-axis closed-loop state.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ClosedLoop {
    /// Mechanical offset at which rotor and virtual position agree.
    pub sync_offset: f64,
    /// Current scale in effect, %.
    pub scale: f64,
    /// Torque mode is selected (SAP 14).
    pub torque_mode: bool,
    /// Encoder count at power-up (incremental encoders count from there).
    pub encoder_zero: f64,
    /// Last count the encoder delivered (frozen while its signal is lost).
    pub encoder_last: f64,
    /// Added by SAP 209.
    pub encoder_offset: f64,
    /// A deviation was reported and has not gone away yet.
    pub deviation_reported: bool,
    /// The rotor's velocity in µsteps/s over the last step.
    pub rotor_velocity: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn axis() -> Axis {
        let mut params = [0; 256];
        params[ap::RAMP_MODE as usize] = RampMode::Velocity as i32;
        Axis::new(params, vec![0; 21], 250.0, 7)
    }

    #[test]
    fn power_up_state() {
        let a = axis();
        assert_eq!(a.motion.mode, RampMode::Velocity, "AP 138 selects the mode");
        assert_eq!((a.motion.x, a.motion.v, a.target_word), (0.0, 0.0, 0));
        assert_eq!((a.mech_offset, a.standstill_since), (250.0, Some(7)));
        assert_eq!(a.coordinates.len(), 21);
        assert!(a.rfs.is_none() && a.ramp_override.is_none() && !a.notify_on_arrival);
        assert_eq!(a.driver, Driver::default());
        assert_eq!(a.closed_loop, ClosedLoop::default());
    }

    #[test]
    fn ramp_mode_sets_ap_138_and_the_generator() {
        let mut a = axis();
        for mode in [RampMode::Position, RampMode::Soft, RampMode::Velocity] {
            a.set_ramp_mode(mode);
            assert_eq!(a.motion.mode, mode);
            assert_eq!(a.params[ap::RAMP_MODE as usize], mode as i32);
        }
    }

    #[test]
    fn end_overrides_leaves_the_rest() {
        let mut a = axis();
        a.rfs = ReferenceSearch::new(1);
        a.ramp_override = Some(Ramp { vmax: 1.0, vmin: 0.0, accel_position: 1.0, accel_velocity: 1.0, target_velocity: 0.0, six: None });
        a.closed_loop.torque_mode = true;
        a.notify_on_arrival = true;
        a.end_overrides();
        assert!(a.rfs.is_none() && a.ramp_override.is_none() && !a.closed_loop.torque_mode);
        assert!(a.notify_on_arrival, "only the overrides end");
        assert_eq!(a.motion.mode, RampMode::Velocity);
    }
}
