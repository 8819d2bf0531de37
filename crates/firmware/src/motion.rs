//! The TMC429/TMC428 ramp generator in continuous time.
//!
//! Units and formulas follow docs/behaviour.md rules 23–25:
//! `v_pps = fclk·v / 2^(pulse_div+16)`,
//! `a_pps = fclk²·a / 2^(ramp_div+pulse_div+29)`, fclk = 16 MHz; on a
//! module whose profile says `motion_units = "pps"` the values are
//! microsteps per second (per second²) as written ([`Units`]).
//!
//! The profile is planned piecewise: every phase has a constant
//! acceleration (or, in soft mode, an exponential approach) and an end time
//! known in closed form, so advancing an hour of virtual time costs a handful
//! of phases, not millions of ticks. Positions are kept unwrapped in `f64`
//! and snapped to the exact target on arrival.
//!
//! The sixPoint ramp of the TMC5130/TMC5160 modules plans its phases in
//! [`crate::sixpoint`], the TMC4361A's trapezoid and S-shaped ramp in
//! [`crate::scurve`], on the same machinery (an S-shaped phase has a
//! constant jerk: the motion then carries its acceleration as state).

pub use crate::phase::Stops;
use crate::phase::{EPS_LAND, EPS_POS, EPS_VEL, Phase, Sgn, Shape};
use crate::scurve::State;
pub use crate::scurve::Tmc4361a;
use crate::sixpoint::Now;
pub use crate::sixpoint::SixPoint;

/// The TMC429's clock in Hz: velocities and accelerations in internal units
/// scale with it (pulse and ramp divisors, AP 154 and AP 153).
pub const FCLK: f64 = 16_000_000.0;

/// 2^e, exactly (the same value as `pow2(e)`, without the call).
#[inline]
pub fn pow2(e: i32) -> f64 {
    if (-1022..=1023).contains(&e) { f64::from_bits(((e + 1023) as u64) << 52) } else { 2f64.powi(e) }
}

// Dividing by a power of two is multiplying by its inverse, exactly; the
// multiplication is the cheaper of the two.

/// Microsteps per second of an internal velocity value.
pub fn velocity_pps(v: f64, pulse_div: u32) -> f64 {
    FCLK * v * pow2(-(pulse_div as i32 + 16))
}

/// Internal velocity units of a step rate.
pub fn velocity_internal(pps: f64, pulse_div: u32) -> f64 {
    pps * pow2(pulse_div as i32 + 16) / FCLK
}

/// Microsteps per second² of an internal acceleration value.
pub fn accel_pps2(a: f64, ramp_div: u32, pulse_div: u32) -> f64 {
    FCLK * FCLK * a * pow2(-((ramp_div + pulse_div) as i32 + 29))
}

/// Internal acceleration units of an acceleration in µsteps/s².
pub fn accel_internal(pps2: f64, ramp_div: u32, pulse_div: u32) -> f64 {
    pps2 * pow2((ramp_div + pulse_div) as i32 + 29) / (FCLK * FCLK)
}

/// The acceleration the TMC429 can use for positioning ramps: AP 5 clamped
/// to `[2^(rd−pd−1), min(2047, 2^(rd−pd+12)−1)]` (manual 6.1.3).
pub fn positioning_accel(a: u32, ramp_div: u32, pulse_div: u32) -> f64 {
    let e = ramp_div as i32 - pulse_div as i32;
    let lower = pow2(e - 1);
    let upper = (pow2(e + 12) - 1.0).min(2047.0);
    f64::from(a).clamp(lower.min(upper), upper)
}

/// How an axis's velocity and acceleration values (AP 2–5, 130, 131, 135,
/// 181, 182, 194, 195 and the closed-loop velocities) turn into
/// microsteps per second and per second²: the profile's `motion_units`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Units {
    /// The TMC429's internal units with the axis's pulse and ramp divisors
    /// (AP 154, AP 153; rules 23 and 24).
    Tmc429 {
        /// AP 154.
        pulse_div: u32,
        /// AP 153.
        ramp_div: u32,
    },
    /// Microsteps per second (per second²), as written.
    Pps,
    /// The TMC5130/TMC5160's (docs/behaviour.md rule 104): a value is
    /// what the module writes into the chip's register, VMAX-like
    /// `v·f_CLK/2^24` µsteps/s and AMAX-like `a·f_CLK²/2^41` µsteps/s².
    /// With `internal` (AP 255 = 0) the values are the registers; else
    /// (pps) the module turns a step rate into the nearest register
    /// value (an acceleration into at least 1) and a register back into
    /// the nearest step rate.
    Sixpoint {
        /// The chip's clock, Hz.
        fclk: u32,
        /// The unit mode is 0: the chip's internal units.
        internal: bool,
        /// The largest acceleration register value (2^16 − 1 on the
        /// TMC5130/TMC5160, 2^18 − 1 on the TMC5240).
        accel_max: u32,
    },
    /// The TMC4361A modules' (docs/behaviour.md rule 114): velocities in
    /// pps and accelerations in pps², which the module writes into the
    /// chip's 24.8 and 22.2 fixed-point registers (× 256, × 4); with
    /// `internal` (the unit mode 0) the values are the registers. With
    /// `direct` (one of AMAX, ASTART, DMAX, DFINAL, DSTOP above
    /// 4 194 303) the module writes every acceleration as the chip's
    /// direct value, `a·2^37/(16 MHz)²` truncated, which the chip runs as
    /// `value·f_CLK²/2^37`.
    Tmc4361a {
        /// The chip's clock, Hz.
        fclk: u32,
        /// The unit mode is 0: the registers.
        internal: bool,
        /// The accelerations are the chip's direct values.
        direct: bool,
    },
}

/// The largest velocity a TMC4361A's 24.8 register holds, pps.
const TMC4361A_VMAX: f64 = 8_388_607.996_093_75;
/// The largest acceleration the module writes in pps² (22.2 registers);
/// above, it switches to the chip's direct values.
pub(crate) const TMC4361A_MAX_PPS_ACC: f64 = 4_194_303.0;

/// The TMC4361A's acceleration register value of `value` (pps², or the
/// register in unit mode 0) and the acceleration it means, µsteps/s².
fn tmc4361a_accel(value: f64, fclk: f64, internal: bool, direct: bool) -> f64 {
    if direct {
        // The module's conversion: a float's value times 2^37 over
        // (16 MHz)², truncated; the chip runs it at its own clock.
        let register = (f64::from(value as f32) * pow2(37) / 2.56e14).trunc().max(1.0);
        return register * fclk * fclk * pow2(-37);
    }
    let register = if internal { value.min(16_777_215.0) } else { (value * 4.0).min(16_777_215.0) };
    register.max(1.0) * 0.25
}

/// The largest velocity register value of the TMC5130/TMC5160 (VMAX, 23
/// bits less 512): a larger value is taken as this one.
const SIX_POINT_VMAX: f64 = 8_388_096.0;

/// µsteps per second of one sixPoint velocity unit at `fclk`.
fn six_point_velocity_unit(fclk: f64) -> f64 {
    fclk * pow2(-24)
}

/// µsteps per second² of one sixPoint acceleration unit at `fclk`.
fn six_point_accel_unit(fclk: f64) -> f64 {
    fclk * fclk * pow2(-41)
}

impl Units {
    /// The largest velocity (and acceleration) value the motion controller
    /// holds: the TMC429's 11 bits, or any positive 32-bit value.
    pub fn max_value(self) -> i32 {
        match self {
            Units::Tmc429 { .. } => 2047,
            Units::Pps | Units::Sixpoint { .. } | Units::Tmc4361a { .. } => i32::MAX,
        }
    }

    /// Microsteps per second of a velocity value.
    pub fn velocity_pps(self, v: f64) -> f64 {
        match self {
            Units::Tmc429 { pulse_div, .. } => velocity_pps(v, pulse_div),
            Units::Pps => v,
            Units::Sixpoint { fclk, internal, .. } => {
                let unit = six_point_velocity_unit(f64::from(fclk));
                let register = if internal { v } else { (v / unit).round() };
                register.clamp(-SIX_POINT_VMAX, SIX_POINT_VMAX) * unit
            }
            Units::Tmc4361a { internal, .. } => (if internal { v / 256.0 } else { v }).clamp(-TMC4361A_VMAX, TMC4361A_VMAX),
        }
    }

    /// The velocity value of a step rate.
    pub fn velocity_value(self, pps: f64) -> f64 {
        match self {
            Units::Tmc429 { pulse_div, .. } => velocity_internal(pps, pulse_div),
            Units::Pps => pps,
            Units::Sixpoint { fclk, internal, .. } => {
                // The chip's velocity register holds whole units (towards zero).
                let unit = six_point_velocity_unit(f64::from(fclk));
                let register = (pps / unit + pps.sgn() * 1e-9).trunc();
                if internal { register } else { (register * unit).round() }
            }
            Units::Tmc4361a { internal, .. } => {
                // VACTUAL holds whole pps (towards zero).
                let whole = (pps + pps.sgn() * 1e-9).trunc();
                if internal { whole * 256.0 } else { whole }
            }
        }
    }

    /// Microsteps per second² of an acceleration value.
    pub fn accel_pps2(self, a: f64) -> f64 {
        match self {
            Units::Tmc429 { pulse_div, ramp_div } => accel_pps2(a, ramp_div, pulse_div),
            Units::Pps => a,
            Units::Sixpoint { fclk, internal, accel_max } => {
                let unit = six_point_accel_unit(f64::from(fclk));
                let register = if internal { a } else { (a / unit).round().max(if a > 0.0 { 1.0 } else { 0.0 }) };
                register.min(f64::from(accel_max)) * unit
            }
            Units::Tmc4361a { fclk, internal, direct } => tmc4361a_accel(a, f64::from(fclk), internal, direct),
        }
    }

    /// The acceleration value of an acceleration in µsteps/s².
    pub fn accel_value(self, pps2: f64) -> f64 {
        match self {
            Units::Tmc429 { pulse_div, ramp_div } => accel_internal(pps2, ramp_div, pulse_div),
            Units::Pps => pps2,
            Units::Sixpoint { fclk, internal, .. } => {
                let value = pps2 / six_point_accel_unit(f64::from(fclk));
                if internal { value } else { pps2 }
            }
            Units::Tmc4361a { internal, .. } => {
                if internal {
                    pps2 * 4.0
                } else {
                    pps2
                }
            }
        }
    }

    /// AP 5 as positioning ramps use it, in µsteps/s²: clamped by the
    /// TMC429 (rule 24), as is in pps.
    pub fn positioning_accel_pps2(self, a: u32) -> f64 {
        match self {
            Units::Tmc429 { pulse_div, ramp_div } => accel_pps2(positioning_accel(a, ramp_div, pulse_div), ramp_div, pulse_div),
            Units::Pps => f64::from(a),
            Units::Sixpoint { .. } | Units::Tmc4361a { .. } => self.accel_pps2(f64::from(a)),
        }
    }
}

/// `x.floor() as i64` without a call into the maths library: the
/// conversion truncates towards zero (and saturates, NaN gives 0), one step
/// down makes it the floor of a negative fraction.
fn floor_i64(x: f64) -> i64 {
    let t = x as i64;
    if (t as f64) > x { t.saturating_sub(1) } else { t }
}

/// `x.ceil() as i64`, as [`floor_i64`].
fn ceil_i64(x: f64) -> i64 {
    let t = x as i64;
    if (t as f64) < x { t.saturating_add(1) } else { t }
}

/// The first time in `(0, limit]` at which a phase of constant jerk `j`
/// from velocity `v` and acceleration `a` has moved by `dx`: the velocity's
/// roots split the phase into stretches where the position is monotonic;
/// the first stretch that passes `dx` holds it, found by bisection.
fn jerk_crossing(dx: f64, v: f64, a: f64, j: f64, limit: f64) -> Option<f64> {
    let moved = |t: f64| v * t + 0.5 * a * t * t + j * t * t * t / 6.0 - dx;
    let mut ends = [limit; 3];
    let mut n = 0;
    // v + a t + j t²/2 = 0.
    let roots = if j == 0.0 {
        if a == 0.0 { [f64::NAN; 2] } else { [-v / a, f64::NAN] }
    } else {
        let disc = a * a - 2.0 * j * v;
        if disc < 0.0 {
            [f64::NAN; 2]
        } else {
            let r = disc.sqrt();
            let (t1, t2) = ((-a - r) / j, (-a + r) / j);
            if t1 < t2 { [t1, t2] } else { [t2, t1] }
        }
    };
    for r in roots {
        if r > 0.0 && r < limit {
            ends[n] = r;
            n += 1;
        }
    }
    ends[n] = limit;
    let mut lo = 0.0;
    for &hi in &ends[..=n] {
        let (f_lo, f_hi) = (moved(lo), moved(hi));
        if f_hi == 0.0 {
            return (hi > 1e-12).then_some(hi);
        }
        if f_lo.sgn() * f_hi.sgn() < 0.0 {
            let (mut a_, mut b_) = (lo, hi);
            for _ in 0..200 {
                let mid = 0.5 * (a_ + b_);
                if mid <= a_ || mid >= b_ {
                    break;
                }
                if moved(mid).sgn() == f_lo.sgn() {
                    a_ = mid;
                } else {
                    b_ = mid;
                }
            }
            return (b_ > 1e-12).then_some(b_);
        }
        lo = hi;
    }
    None
}

/// What happened during one `advance`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Step {
    /// The motor arrived on its target.
    pub arrived: bool,
    /// Seconds into the step at which the motor came to rest (if it did).
    pub stopped_at: Option<f64>,
    /// With `until_crossing`: the threshold reached, where the step ended.
    pub crossed: Option<f64>,
    /// Seconds the step covered (less than asked when it ended at a crossing).
    pub elapsed: f64,
    /// The phases the step walked through (a phase cut by the step's end
    /// counts).
    pub phases: usize,
}

/// AP 138.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RampMode {
    /// Ramp to the target position with trapezoidal acceleration.
    Position = 0,
    /// Approach the target position exponentially (soft ramp).
    Soft = 1,
    /// Run at the target speed; the position is not a target.
    Velocity = 2,
}

impl RampMode {
    /// The mode for a value of AP 138 (anything other than 1 and 2 is position
    /// mode).
    pub fn from_code(v: i32) -> RampMode {
        match v {
            1 => RampMode::Soft,
            2 => RampMode::Velocity,
            _ => RampMode::Position,
        }
    }
}

/// The ramp settings of one axis, converted to µsteps and seconds.
#[derive(Clone, Copy, Debug)]
pub struct Ramp {
    /// AP 4 in µsteps/s.
    pub vmax: f64,
    /// AP 130 in µsteps/s.
    pub vmin: f64,
    /// AP 5 clamped for positioning, in µsteps/s².
    pub accel_position: f64,
    /// AP 5 as is (velocity mode), in µsteps/s².
    pub accel_velocity: f64,
    /// AP 2 in µsteps/s.
    pub target_velocity: f64,
    /// The sixPoint ramp's other values on a sixPoint module; `None`: the
    /// TMC429's trapezoid (docs/behaviour.md rule 104).
    pub six: Option<SixPoint>,
}

impl Ramp {
    /// The standstill after a stop before the motor moves again, seconds
    /// (the sixPoint ramp wait; none on the TMC429).
    fn zero_wait(&self) -> f64 {
        self.six.map_or(0.0, |s| s.zero_wait)
    }
}

/// Phases one `advance` may walk through; a guard against float dust.
const MAX_PHASES: usize = 64;

/// One axis of the motion controller.
#[derive(Clone, Debug)]
pub struct Motion {
    /// Actual position in µsteps (unwrapped).
    pub x: f64,
    /// Actual velocity in µsteps/s.
    pub v: f64,
    /// Acceleration in effect, µsteps/s² (for AP 135).
    pub a: f64,
    /// The ramp mode in effect (AP 138).
    pub mode: RampMode,
    /// Target position in the unwrapped space of `x`.
    pub target: f64,
    /// The motor was stopped by a stop switch and has not moved since.
    pub stopped_by_switch: bool,
    /// Seconds of the ramp wait left before the motor may move again
    /// (sixPoint TZEROWAIT, from its last stop).
    pub zero_wait: f64,
}

impl Default for Motion {
    fn default() -> Self {
        Motion { x: 0.0, v: 0.0, a: 0.0, mode: RampMode::Position, target: 0.0, stopped_by_switch: false, zero_wait: 0.0 }
    }
}

impl Motion {
    /// True when the motor does not move and nothing will make it move.
    pub fn is_idle(&self, ramp: &Ramp, stops: &Stops) -> bool {
        self.is_idle_on(ramp, None, stops)
    }

    /// [`Motion::is_idle`] on a TMC4361A (`chip`: its own ramp values).
    pub fn is_idle_on(&self, ramp: &Ramp, chip: Option<&Tmc4361a>, stops: &Stops) -> bool {
        self.v == 0.0 && self.plan(ramp, chip, stops).is_none()
    }

    /// Advances by `dt` seconds. `thresholds` are positions (in the space
    /// of `x`) where a switch changes state; a phase ends there so that the
    /// caller can re-evaluate the switches. With `until_crossing` the step
    /// ends at the first threshold reached.
    pub fn advance<F: FnMut(f64) -> Stops + ?Sized>(
        &mut self,
        dt: f64,
        ramp: &Ramp,
        stops: &mut F,
        thresholds: &[f64],
        until_crossing: bool,
    ) -> Step {
        self.advance_on(dt, ramp, None, stops, thresholds, until_crossing)
    }

    /// [`Motion::advance`] on a TMC4361A (`chip`: its own ramp values,
    /// beside VMAX, AMAX and the target speed of `ramp`).
    pub fn advance_on<F: FnMut(f64) -> Stops + ?Sized>(
        &mut self,
        mut dt: f64,
        ramp: &Ramp,
        chip: Option<&Tmc4361a>,
        stops: &mut F,
        thresholds: &[f64],
        until_crossing: bool,
    ) -> Step {
        let mut step = Step::default();
        let mut elapsed = 0.0;
        for _ in 0..MAX_PHASES {
            if dt <= 0.0 {
                break;
            }
            let s = stops(self.x);
            let Some(phase) = self.plan(ramp, chip, &s) else {
                self.a = 0.0;
                break;
            };
            step.phases += 1;
            let mut t = phase.duration.min(dt);
            let mut crossing = None;
            for &th in thresholds {
                // An edge within a nanosecond of the phase's end is reached
                // at its end: splitting the phase there would leave float
                // dust in the speed (a motor a hair short of its target
                // with speed left).
                let tc = self.crossing(phase.shape, th, t).map(|tc| if t - tc < 1e-9 { t } else { tc });
                if let Some(tc) = tc
                    && (tc < t || crossing.is_none() && tc <= t)
                {
                    t = tc;
                    crossing = Some(th);
                }
            }
            let was_moving = self.v != 0.0;
            self.integrate(phase.shape, t);
            dt -= t;
            elapsed += t;
            // The phase ran to its end: on the target when it arrives there,
            // even if a switch edge lies exactly on the target.
            let arrived = t >= phase.duration && phase.arrives;
            if arrived {
                self.x = self.target;
                self.v = 0.0;
                self.a = 0.0;
                step.arrived = true;
            }
            if let Some(th) = crossing {
                if !arrived {
                    self.x = th;
                }
                let s = stops(self.x);
                if !s.soft && s.blocks(self.v.sgn()) {
                    self.v = 0.0;
                    self.stopped_by_switch = true;
                }
                if until_crossing {
                    step.crossed = Some(th);
                    if was_moving && self.v == 0.0 {
                        step.stopped_at = Some(elapsed);
                        self.zero_wait = ramp.zero_wait();
                    }
                    break;
                }
            }
            if was_moving && self.v == 0.0 {
                step.stopped_at = Some(elapsed);
                self.zero_wait = ramp.zero_wait();
            }
        }
        if self.v != 0.0 {
            self.stopped_by_switch = false;
            step.stopped_at = None;
        }
        step.elapsed = elapsed;
        step
    }

    /// Seconds until the motor comes to rest (on its target, or stopped
    /// for good), if it will; walks the planned phases without moving.
    pub fn time_to_rest<F: FnMut(f64) -> Stops + ?Sized>(&self, ramp: &Ramp, stops: &mut F) -> Option<f64> {
        self.time_to_rest_on(ramp, None, stops)
    }

    /// [`Motion::time_to_rest`] on a TMC4361A (`chip`: its own ramp values).
    pub fn time_to_rest_on<F: FnMut(f64) -> Stops + ?Sized>(&self, ramp: &Ramp, chip: Option<&Tmc4361a>, stops: &mut F) -> Option<f64> {
        let mut probe = self.clone();
        let mut total = 0.0;
        for _ in 0..MAX_PHASES {
            let s = stops(probe.x);
            let Some(phase) = probe.plan(ramp, chip, &s) else {
                return Some(total);
            };
            if !phase.duration.is_finite() {
                return None;
            }
            probe.integrate(phase.shape, phase.duration);
            total += phase.duration;
            if phase.arrives {
                return Some(total);
            }
        }
        None
    }

    /// The position counter: the steps made so far (rounded towards where
    /// the motor comes from while it moves).
    pub fn position(&self) -> i64 {
        if self.v > 0.0 {
            floor_i64(self.x + 1e-9)
        } else if self.v < 0.0 {
            ceil_i64(self.x - 1e-9)
        } else {
            self.x.round() as i64
        }
    }

    fn integrate(&mut self, shape: Shape, t: f64) {
        match shape {
            Shape::Accel(a) => {
                self.x += self.v * t + 0.5 * a * t * t;
                self.v += a * t;
                self.a = a;
                if self.v.abs() < EPS_VEL {
                    self.v = 0.0;
                }
            }
            Shape::Jump(v) => {
                self.v = v;
                self.a = 0.0;
            }
            Shape::Wait => {
                self.a = 0.0;
                self.zero_wait = (self.zero_wait - t).max(0.0);
            }
            Shape::Exponential { k } => {
                let f = (-k * t).exp();
                let d = self.target - self.x;
                self.x = self.target - d * f;
                self.v = k * d * f;
                self.a = -k * self.v;
            }
            Shape::Jerk { v, a, j } => {
                self.x += v * t + 0.5 * a * t * t + j * t * t * t / 6.0;
                self.v = v + a * t + 0.5 * j * t * t;
                self.a = a + j * t;
            }
        }
    }

    /// First time in `(0, limit]` at which the phase reaches `x = th`.
    fn crossing(&self, shape: Shape, th: f64, limit: f64) -> Option<f64> {
        let dx = th - self.x;
        if dx.abs() < 1e-12 {
            return None;
        }
        let t = match shape {
            Shape::Accel(a) => {
                if a.abs() < 1e-12 {
                    if self.v.abs() < EPS_VEL {
                        return None;
                    }
                    dx / self.v
                } else {
                    // x + v t + a t²/2 = th
                    let disc = self.v * self.v + 2.0 * a * dx;
                    if disc < 0.0 {
                        return None;
                    }
                    let r = disc.sqrt();
                    let t1 = (-self.v - r) / a;
                    let t2 = (-self.v + r) / a;
                    let (lo, hi) = if t1 < t2 { (t1, t2) } else { (t2, t1) };
                    if lo > 1e-12 { lo } else { hi }
                }
            }
            Shape::Jump(_) | Shape::Wait => return None,
            Shape::Jerk { v, a, j } => return jerk_crossing(dx, v, a, j, limit),
            Shape::Exponential { k } => {
                let d0 = self.target - self.x;
                let d1 = self.target - th;
                if d0 == 0.0 || d1 / d0 <= 0.0 || d1.abs() >= d0.abs() {
                    return None;
                }
                (d0 / d1).ln() / k
            }
        };
        (t > 1e-12 && t <= limit).then_some(t)
    }

    /// The phase the ramp generator is in now; `None` when standing still
    /// with nothing to do.
    fn plan(&self, ramp: &Ramp, chip: Option<&Tmc4361a>, stops: &Stops) -> Option<Phase> {
        if let Some(chip) = chip {
            let now = State { x: self.x, v: self.v, a: self.a, target: self.target, zero_wait: self.zero_wait };
            return if self.mode == RampMode::Velocity {
                chip.plan_velocity(&now, ramp.target_velocity, ramp.accel_velocity, stops)
            } else {
                chip.plan_position(&now, ramp.vmax, ramp.accel_position, stops)
            };
        }
        if let Some(six) = &ramp.six {
            let now = Now { x: self.x, v: self.v, target: self.target, zero_wait: self.zero_wait };
            return if self.mode == RampMode::Velocity {
                six.plan_velocity(&now, ramp.target_velocity, ramp.accel_velocity, stops)
            } else {
                six.plan_position(&now, ramp.vmax, ramp.accel_position, stops)
            };
        }
        match self.mode {
            RampMode::Velocity => self.plan_velocity(ramp, stops),
            RampMode::Position | RampMode::Soft => self.plan_position(ramp, stops),
        }
    }

    fn plan_velocity(&self, ramp: &Ramp, stops: &Stops) -> Option<Phase> {
        let a = ramp.accel_velocity;
        let mut vt = ramp.target_velocity;
        if stops.blocks(vt.sgn()) || stops.blocks(self.v.sgn()) {
            if self.v != 0.0 && !stops.soft {
                // A hard stop happens at the crossing; arriving here means
                // the switch was already active: stop dead.
                return Some(Phase::jump(0.0));
            }
            vt = 0.0;
        }
        let dv = vt - self.v;
        if dv.abs() < EPS_VEL {
            if self.v != vt {
                return Some(Phase::jump(vt));
            }
            return if vt == 0.0 { None } else { Some(Phase::accel(0.0, f64::INFINITY)) };
        }
        Some(Phase::accel(a * dv.sgn(), dv.abs() / a))
    }

    fn plan_position(&self, ramp: &Ramp, stops: &Stops) -> Option<Phase> {
        let a = ramp.accel_position;
        let vmax = ramp.vmax;
        let vmin = ramp.vmin.min(vmax);
        let delta = self.target - self.x;
        let d = delta.abs();
        if d < EPS_POS && self.v.abs() <= vmin + EPS_VEL {
            if self.v == 0.0 && delta == 0.0 {
                return None;
            }
            return Some(Phase { shape: Shape::Accel(0.0), duration: 0.0, arrives: true });
        }
        // Direction towards the target; at the target with speed, the
        // motor overshoots and comes back.
        let dir = if d < EPS_POS { -self.v.sgn() } else { delta.sgn() };
        let u = self.v * dir;
        if stops.blocks(dir) || stops.blocks(self.v.sgn()) {
            if self.v == 0.0 {
                return None;
            }
            if !stops.soft {
                return Some(Phase::jump(0.0));
            }
            return Some(Phase::accel(-self.v.sgn() * a, self.v.abs() / a));
        }
        if u < -EPS_VEL {
            // Moving away from the target: brake to zero first.
            return Some(Phase::accel(dir * a, -u / a));
        }
        if self.mode == RampMode::Soft {
            return Some(self.plan_soft(ramp, dir, u, d));
        }
        let brake = |s: f64| if s > vmin { (s * s - vmin * vmin) / (2.0 * a) } else { 0.0 };
        let b = brake(u);
        if d <= b + EPS_POS {
            if u > vmin + EPS_VEL {
                // Decelerate; if the target comes first (a target moved
                // closer), pass it and come back.
                if d < b - EPS_LAND {
                    let t_target = (u - (u * u - 2.0 * a * d).sqrt()) / a;
                    return Some(Phase::accel(-dir * a, t_target));
                }
                // The braking ramp ends on the target at the stop speed,
                // where the motor stops.
                let t_vmin = (u - vmin) / a;
                return Some(Phase { shape: Shape::Accel(-dir * a), duration: t_vmin, arrives: true });
            }
            // Creep at the stop speed for the last fraction of a step.
            let speed = u.max(vmin);
            if (self.v - dir * speed).abs() > EPS_VEL {
                return Some(Phase::jump(dir * speed));
            }
            return Some(Phase { shape: Shape::Accel(0.0), duration: d / speed, arrives: true });
        }
        if u > vmax + EPS_VEL {
            return Some(Phase::accel(-dir * a, (u - vmax) / a));
        }
        if u < vmax - EPS_VEL {
            // Accelerate until vmax or the braking point, whichever first.
            let b0 = (u * u - vmin * vmin) / (2.0 * a);
            let s_cross = (d - b0) / 2.0;
            let t_of = |s: f64| (-u + (u * u + 2.0 * a * s).max(0.0).sqrt()) / a;
            if s_cross >= d {
                return Some(Phase { shape: Shape::Accel(dir * a), duration: t_of(d), arrives: true });
            }
            let t = t_of(s_cross.max(0.0)).min((vmax - u) / a);
            return Some(Phase::accel(dir * a, t));
        }
        // Cruise at vmax until the braking point.
        if self.v != dir * vmax {
            // Remove float dust from the acceleration phase.
            return Some(Phase::jump(dir * vmax));
        }
        Some(Phase::accel(0.0, (d - brake(vmax)) / vmax))
    }

    /// Soft mode: ramp up with AP 5, then approach the target with a speed
    /// proportional to the distance left (`v = k·d`, `k = a/vmax`), down
    /// to the stop speed.
    fn plan_soft(&self, ramp: &Ramp, dir: f64, u: f64, d: f64) -> Phase {
        let a = ramp.accel_position;
        let vmax = ramp.vmax;
        let vmin = ramp.vmin.min(vmax).max(1e-3);
        let k = a / vmax;
        if u >= k * d - EPS_VEL {
            if k * d <= vmin + EPS_VEL {
                if (u - vmin).abs() > EPS_VEL {
                    return Phase::jump(dir * vmin);
                }
                return Phase { shape: Shape::Accel(0.0), duration: d / vmin, arrives: true };
            }
            if (u - k * d).abs() > EPS_VEL {
                return Phase::jump(dir * k * d);
            }
            return Phase { shape: Shape::Exponential { k }, duration: (k * d / vmin).ln() / k, arrives: false };
        }
        if u < vmax - EPS_VEL {
            // u + a t = k (d − u t − a t²/2)
            let qa = k * a / 2.0;
            let qb = a + k * u;
            let qc = u - k * d;
            let t_meet = (-qb + (qb * qb - 4.0 * qa * qc).sqrt()) / (2.0 * qa);
            return Phase::accel(dir * a, t_meet.min((vmax - u) / a));
        }
        Phase::accel(0.0, (d - vmax / k) / vmax)
    }

    /// Total time of a positioning move from rest, in closed form
    /// (trapezoid or triangle from 0 to `vmax` and down to `vmin`).
    pub fn closed_form_duration(distance: f64, ramp: &Ramp) -> f64 {
        let a = ramp.accel_position;
        let vmax = ramp.vmax;
        let vmin = ramp.vmin.min(vmax);
        let d = distance.abs();
        let d_full = vmax * vmax / (2.0 * a) + (vmax * vmax - vmin * vmin) / (2.0 * a);
        if d >= d_full {
            vmax / a + (vmax - vmin) / a + (d - d_full) / vmax
        } else {
            let vp = ((2.0 * a * d + vmin * vmin) / 2.0).sqrt();
            if vp <= vmin {
                // The whole move is shorter than the stop-speed ramp.
                (2.0 * d / a).sqrt()
            } else {
                vp / a + (vp - vmin) / a
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floor_and_ceil_are_the_library_s() {
        let mut cases = vec![0.0, -0.0, 0.5, -0.5, 1.0, -1.0, 2.5, -2.5, 1e-9, -1e-9, 4503599627370495.5, -4503599627370495.5];
        cases.extend([9.3e18, -9.3e18, 2f64.powi(63), -(2f64.powi(63)), 1e300, -1e300, f64::NAN, f64::INFINITY, f64::NEG_INFINITY]);
        cases.extend((0..100_000).map(|i| f64::from(i) * 0.37 - 18_000.0 + 1e-9));
        for x in cases {
            assert_eq!(floor_i64(x), x.floor() as i64, "floor {x}");
            assert_eq!(ceil_i64(x), x.ceil() as i64, "ceil {x}");
        }
    }

    #[test]
    fn pow2_is_exact() {
        for e in -1100..1100 {
            assert_eq!(pow2(e), 2f64.powi(e), "2^{e}");
        }
    }

    fn ramp(vmax: f64, a: f64, vmin: f64) -> Ramp {
        Ramp { vmax, vmin, accel_position: a, accel_velocity: a, target_velocity: 0.0, six: None }
    }

    fn run_to_target(m: &mut Motion, r: &Ramp, step: f64) -> f64 {
        let mut t = 0.0;
        while !m.is_idle(r, &Stops::default()) {
            m.advance(step, r, &mut |_| Stops::default(), &[], false);
            t += step;
            assert!(t < 1e6, "never arrives");
        }
        t
    }

    #[test]
    fn manual_unit_examples() {
        // 6.1.1: v = 1678, pulse_div = 3 → about 51208.5 pps.
        assert!((velocity_pps(1678.0, 3) - 51208.5).abs() < 0.1);
        // 6.1.2: a = 100, ramp_div = 7, pulse_div = 3 → about 46566 pps².
        assert!((accel_pps2(100.0, 7, 3) - 46566.1).abs() < 0.5);
    }

    #[test]
    fn pps_units_are_the_values_as_written() {
        let tmc429 = Units::Tmc429 { pulse_div: 3, ramp_div: 7 };
        assert_eq!(tmc429.velocity_pps(1000.0), velocity_pps(1000.0, 3));
        assert_eq!(tmc429.accel_pps2(100.0), accel_pps2(100.0, 7, 3));
        assert_eq!(tmc429.positioning_accel_pps2(1), accel_pps2(8.0, 7, 3), "clamped");
        assert_eq!(tmc429.velocity_value(tmc429.velocity_pps(1234.0)), 1234.0);
        assert_eq!(tmc429.max_value(), 2047);
        let pps = Units::Pps;
        assert_eq!((pps.velocity_pps(20_000.0), pps.velocity_value(20_000.0)), (20_000.0, 20_000.0));
        assert_eq!((pps.accel_pps2(40_000.0), pps.accel_value(40_000.0)), (40_000.0, 40_000.0));
        assert_eq!(pps.positioning_accel_pps2(1), 1.0, "no clamp");
        assert_eq!(pps.max_value(), i32::MAX);
    }

    #[test]
    fn positioning_acceleration_is_clamped() {
        assert_eq!(positioning_accel(1, 7, 3), 8.0); // 2^(4-1)
        assert_eq!(positioning_accel(2047, 7, 3), 2047.0);
        assert_eq!(positioning_accel(2047, 3, 3), 2047.0);
        assert_eq!(positioning_accel(2047, 0, 3), pow2(9) - 1.0);
    }

    #[test]
    fn trapezoid_duration_and_exact_arrival() {
        let r = ramp(10_000.0, 20_000.0, 10.0);
        let mut m = Motion { target: 51_200.0, ..Motion::default() };
        let t = run_to_target(&mut m, &r, 0.001);
        assert_eq!(m.x, 51_200.0);
        let expect = Motion::closed_form_duration(51_200.0, &r);
        assert!((t - expect).abs() <= (0.005 * expect).max(0.001) + 0.001, "{t} vs {expect}");
    }

    #[test]
    fn triangle_and_negative_moves() {
        let r = ramp(100_000.0, 1_000.0, 5.0);
        let mut m = Motion { target: -300.0, ..Motion::default() };
        let t = run_to_target(&mut m, &r, 0.0005);
        assert_eq!(m.x, -300.0);
        let expect = Motion::closed_form_duration(300.0, &r);
        assert!((t - expect).abs() <= (0.005 * expect).max(0.001) + 0.0005, "{t} vs {expect}");
    }

    #[test]
    fn one_big_advance_equals_many_small() {
        let r = ramp(30_000.0, 50_000.0, 1.0);
        let mut a = Motion { target: 1_000_000.0, ..Motion::default() };
        let mut b = a.clone();
        a.advance(12.0, &r, &mut |_| Stops::default(), &[], false);
        for _ in 0..12_000 {
            b.advance(0.001, &r, &mut |_| Stops::default(), &[], false);
        }
        assert!((a.x - b.x).abs() < 1e-3, "{} {}", a.x, b.x);
        assert!((a.v - b.v).abs() < 1e-3);
    }

    #[test]
    fn velocity_mode_ramps_to_target_speed() {
        let mut r = ramp(1.0, 1_000.0, 1.0);
        r.target_velocity = 5_000.0;
        let mut m = Motion { mode: RampMode::Velocity, ..Motion::default() };
        m.advance(2.5, &r, &mut |_| Stops::default(), &[], false);
        assert!((m.v - 2_500.0).abs() < 1e-6);
        m.advance(10.0, &r, &mut |_| Stops::default(), &[], false);
        assert_eq!(m.v, 5_000.0);
        r.target_velocity = 0.0;
        m.advance(10.0, &r, &mut |_| Stops::default(), &[], false);
        assert_eq!(m.v, 0.0);
    }

    #[test]
    fn hard_stop_at_switch_position() {
        let mut r = ramp(1.0, 1_000.0, 1.0);
        r.target_velocity = 2_000.0;
        let mut m = Motion { mode: RampMode::Velocity, ..Motion::default() };
        let mut stops = |x: f64| Stops { block_positive: x >= 5_000.0, block_negative: false, soft: false };
        m.advance(100.0, &r, &mut stops, &[5_000.0], false);
        assert_eq!(m.x, 5_000.0);
        assert_eq!(m.v, 0.0);
        assert!(m.stopped_by_switch);
    }

    #[test]
    fn soft_mode_reaches_target_exactly() {
        let r = ramp(10_000.0, 20_000.0, 10.0);
        let mut m = Motion { target: 40_000.0, mode: RampMode::Soft, ..Motion::default() };
        let t = run_to_target(&mut m, &r, 0.01);
        assert_eq!(m.x, 40_000.0);
        // Slower than the linear ramp, but finite.
        assert!(t > Motion::closed_form_duration(40_000.0, &r));
    }
}
