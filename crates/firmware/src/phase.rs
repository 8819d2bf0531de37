//! What the ramp planners share: the phases a motion is planned in, what
//! the stop switches allow, and the tolerances against float dust. Below
//! the planners (the TMC429's in [`crate::motion`], the sixPoint's in
//! [`crate::sixpoint`], the TMC4361A's in [`crate::scurve`]) and
//! [`crate::motion::Motion`], which walks their phases.

/// Sign of a velocity or distance: −1, 0 or +1 (`f64::signum` gives +1
/// for 0).
pub(crate) trait Sgn {
    fn sgn(self) -> f64;
}

impl Sgn for f64 {
    fn sgn(self) -> f64 {
        if self > 0.0 {
            1.0
        } else if self < 0.0 {
            -1.0
        } else {
            0.0
        }
    }
}

/// What the stop switches allow right now.
#[derive(Clone, Copy, Debug, Default)]
pub struct Stops {
    /// Positive motion is blocked (right switch active and enabled).
    pub block_positive: bool,
    /// Negative motion is blocked (left switch active and enabled).
    pub block_negative: bool,
    /// AP 149: decelerate instead of stopping at once.
    pub soft: bool,
}

impl Stops {
    pub(crate) fn blocks(&self, dir: f64) -> bool {
        (dir > 0.0 && self.block_positive) || (dir < 0.0 && self.block_negative)
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Shape {
    /// Constant acceleration (µsteps/s²).
    Accel(f64),
    /// Soft-mode approach: `d(t) = d0·e^(−kt)` towards the target.
    Exponential { k: f64 },
    /// An immediate change of velocity (hard stop, stop-speed steps).
    Jump(f64),
    /// Standing still for the ramp wait (sixPoint TZEROWAIT).
    Wait,
    /// Constant jerk (µsteps/s³) from velocity `v` and acceleration `a`
    /// (the motion's own, or the values a start jumps to): the TMC4361A's
    /// S-shaped ramp. The position is a cubic in time, the velocity a
    /// quadratic, the acceleration linear.
    Jerk { v: f64, a: f64, j: f64 },
}

#[derive(Clone, Copy, Debug)]
pub(crate) struct Phase {
    pub(crate) shape: Shape,
    /// Seconds; `INFINITY` for "until something changes".
    pub(crate) duration: f64,
    /// At the end of the phase the motor stands on its target.
    pub(crate) arrives: bool,
}

impl Phase {
    pub(crate) fn accel(a: f64, duration: f64) -> Phase {
        Phase { shape: Shape::Accel(a), duration: duration.max(0.0), arrives: false }
    }

    pub(crate) fn jump(v: f64) -> Phase {
        Phase { shape: Shape::Jump(v), duration: 0.0, arrives: false }
    }

    pub(crate) fn wait(duration: f64) -> Phase {
        Phase { shape: Shape::Wait, duration, arrives: false }
    }
}

pub(crate) const EPS_POS: f64 = 1e-6;
pub(crate) const EPS_VEL: f64 = 1e-9;
/// A braking ramp that ends this close to the target (µsteps) ends on it:
/// ramps split into many steps (a step per millisecond, a switch edge)
/// collect float dust.
pub(crate) const EPS_LAND: f64 = 1e-2;
