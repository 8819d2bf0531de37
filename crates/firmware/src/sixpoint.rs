//! The TMC5130/TMC5160 sixPoint ramp generator, the motion controller of
//! the modules whose profile says `motion_controller = "sixpoint"`
//! (docs/behaviour.md rules 104–110), and the TMC5240's eight-point ramp,
//! which adds a second knee V2 with its own A2 and D2
//! (`motion_controller = "eightpoint"`, rule 113).
//!
//! A positioning move starts at VSTART, accelerates with A1 up to V1 and
//! with AMAX up to VMAX, cruises, decelerates with DMAX down to V1 and with
//! D1 down to VSTOP, where the motor stops on its target. V1 = 0 leaves
//! A1 and D1 out. After every stop the motor stands for the ramp wait time
//! (TZEROWAIT) before it moves again. Velocity mode ramps with AMAX
//! both ways.
//!
//! Like the TMC429's trapezoid ([`crate::motion`]), the ramp is planned in
//! phases of constant acceleration whose ends are known in closed form,
//! so that an hour of motion costs a handful of phases; the values are the
//! chip's register values (`Units::Sixpoint`), and a move is snapped onto
//! its target microstep on arrival.

use crate::phase::{EPS_LAND, EPS_POS, EPS_VEL, Phase, Sgn, Shape, Stops};

/// Where the motor is when a phase is planned: position, velocity and
/// target (µsteps, µsteps/s) and the ramp wait left (s).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Now {
    pub x: f64,
    pub v: f64,
    pub target: f64,
    pub zero_wait: f64,
}

/// The sixPoint ramp's own values beside VMAX, AMAX and the target speed
/// of the motion's ramp, in µsteps/s, µsteps/s² and seconds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SixPoint {
    /// VSTART (AP 19): the speed a move starts at.
    pub vstart: f64,
    /// A1 (AP 15): the acceleration below V1.
    pub a1: f64,
    /// V1 (AP 16): where A1 gives way to AMAX and DMAX to D1; 0 leaves A1
    /// and D1 out.
    pub v1: f64,
    /// DMAX (AP 17): the deceleration above V1.
    pub dmax: f64,
    /// D1 (AP 18): the deceleration below V1.
    pub d1: f64,
    /// A2 (eight-point only): the acceleration from V1 up to V2.
    pub a2: f64,
    /// V2 (eight-point only): where A2 gives way to AMAX and DMAX to D2;
    /// 0 (and the sixPoint ramp) leaves A2 and D2 out.
    pub v2: f64,
    /// D2 (eight-point only): the deceleration from V2 down to V1.
    pub d2: f64,
    /// VSTOP (AP 20): the speed at which the motor stops.
    pub vstop: f64,
    /// TZEROWAIT (AP 21) in seconds: the standstill after a stop before the
    /// motor moves again.
    pub zero_wait: f64,
}

/// A band of speeds `lo ≤ w < hi` and the acceleration and deceleration
/// the ramp uses in it.
#[derive(Clone, Copy, Debug, Default)]
struct Band {
    lo: f64,
    hi: f64,
    up: f64,
    down: f64,
}

/// A piece of the braking distance `b(w) = α·w² + β` for speeds
/// `lo ≤ w ≤ hi`.
#[derive(Clone, Copy, Debug, Default)]
struct Piece {
    lo: f64,
    hi: f64,
    alpha: f64,
    beta: f64,
}

impl SixPoint {
    /// The ramp's bands from standstill up: A1/D1 below V1, A2/D2 from V1
    /// to V2 (when V2 is above V1), AMAX/DMAX above; with V1 = 0 only
    /// AMAX/DMAX. How
    /// many there are.
    fn bands(&self, amax: f64) -> ([Band; 3], usize) {
        let mut bands = [Band::default(); 3];
        let mut n = 0;
        let mut lo = 0.0;
        // V1 = 0 switches the knees off: AMAX and DMAX only (the eight-point
        // ramp too, the TMCM-1290 manual §7.6; rule 113).
        let knees = if self.v1 > 0.0 { [(self.v1, self.a1, self.d1), (self.v2, self.a2, self.d2)] } else { [(0.0, 0.0, 0.0); 2] };
        for (knee, up, down) in knees {
            if knee > lo {
                bands[n] = Band { lo, hi: knee, up, down };
                n += 1;
                lo = knee;
            }
        }
        bands[n] = Band { lo, hi: f64::INFINITY, up: amax, down: self.dmax };
        (bands, n + 1)
    }

    /// The acceleration that speeds the motor up from `u` and the speed at
    /// which that acceleration ends (a knee, or VMAX).
    pub(crate) fn speeding_up(&self, u: f64, amax: f64, vmax: f64) -> (f64, f64) {
        let (bands, n) = self.bands(amax);
        let b = bands[..n].iter().find(|b| u < b.hi - EPS_VEL).unwrap_or(&bands[n - 1]);
        (b.up, b.hi.min(vmax))
    }

    /// The band below `u`: the one a motor slowing down from `u` is in.
    fn band_below(&self, u: f64, amax: f64) -> Band {
        let (bands, n) = self.bands(amax);
        *bands[..n].iter().find(|b| u <= b.hi + EPS_VEL).unwrap_or(&bands[n - 1])
    }

    /// The deceleration that slows the motor down from `u` and the speed at
    /// which it ends (a knee, or `floor`: VSTOP). Knees at or below the
    /// floor have no part.
    pub(crate) fn slowing_down(&self, u: f64, floor: f64) -> (f64, f64) {
        let b = self.band_below(u, 0.0);
        (b.down, b.lo.max(floor))
    }

    /// The braking distance from `w` down to VSTOP, piece by piece: each
    /// band above VSTOP with its deceleration. How many pieces there are
    /// (the first is the standstill below VSTOP).
    fn pieces(&self) -> ([Piece; 4], usize) {
        let vs = self.vstop;
        let mut pieces = [Piece::default(); 4];
        pieces[0] = Piece { lo: 0.0, hi: vs, alpha: 0.0, beta: 0.0 };
        let mut n = 1;
        let mut base = 0.0;
        let (bands, count) = self.bands(0.0);
        for b in &bands[..count] {
            if b.hi <= vs {
                continue;
            }
            let lo = b.lo.max(vs);
            pieces[n] = Piece { lo, hi: b.hi, alpha: 1.0 / (2.0 * b.down), beta: base - lo * lo / (2.0 * b.down) };
            n += 1;
            if b.hi.is_finite() {
                base += (b.hi * b.hi - lo * lo) / (2.0 * b.down);
            }
        }
        (pieces, n)
    }

    /// The braking distance from `u` to VSTOP (0 at or below VSTOP).
    pub fn brake(&self, u: f64) -> f64 {
        let u = u.abs();
        let (pieces, n) = self.pieces();
        let p = pieces[..n].iter().find(|p| u <= p.hi).unwrap_or(&pieces[n - 1]);
        (p.alpha * u * u + p.beta).max(0.0)
    }

    /// The speed `w ≥ u` at which accelerating with `acc` from `u` and then
    /// braking to VSTOP covers exactly `d`: where the braking point lies.
    fn peak(&self, u: f64, acc: f64, d: f64) -> f64 {
        let k = 1.0 / (2.0 * acc);
        let (pieces, n) = self.pieces();
        for p in &pieces[..n] {
            // k·(w² − u²) + α·w² + β = d
            let w2 = (d - p.beta + k * u * u) / (k + p.alpha);
            let w = w2.max(0.0).sqrt();
            if w <= p.hi && w >= p.lo {
                return w.max(u);
            }
        }
        u
    }

    /// The phase that brings a motor moving at `v` (either way) down to
    /// standstill: DMAX to V1, D1 to VSTOP, then the stop.
    fn braking(&self, v: f64) -> Phase {
        let w = v.abs();
        if w <= self.vstop + EPS_VEL {
            return Phase::jump(0.0);
        }
        let (dec, end) = self.slowing_down(w, self.vstop);
        Phase::accel(-v.sgn() * dec, (w - end) / dec)
    }

    /// A stop switch blocks the way: standing, nothing to do; moving, a hard
    /// stop at once or, with the soft stop, the braking ramp (rule 108).
    fn at_a_switch(&self, m: &Now, stops: &Stops) -> Option<Phase> {
        if m.v == 0.0 {
            None
        } else if !stops.soft {
            Some(Phase::jump(0.0))
        } else {
            Some(self.braking(m.v))
        }
    }

    /// Velocity mode: AMAX towards the target speed, either way; a reversal
    /// passes through standstill and the ramp wait.
    pub(crate) fn plan_velocity(&self, m: &Now, target_velocity: f64, amax: f64, stops: &Stops) -> Option<Phase> {
        let a = amax;
        let mut vt = target_velocity;
        if stops.blocks(vt.sgn()) || stops.blocks(m.v.sgn()) {
            return self.at_a_switch(m, stops);
        }
        if m.v == 0.0 {
            if vt == 0.0 {
                return None;
            }
            if m.zero_wait > 0.0 {
                return Some(Phase::wait(m.zero_wait));
            }
        } else if vt.sgn() != m.v.sgn() {
            // A reversal (or a stop): down to standstill first.
            vt = 0.0;
        }
        let dv = vt - m.v;
        if dv.abs() < EPS_VEL {
            if m.v != vt {
                return Some(Phase::jump(vt));
            }
            return if vt == 0.0 { None } else { Some(Phase::accel(0.0, f64::INFINITY)) };
        }
        Some(Phase::accel(a * dv.sgn(), dv.abs() / a))
    }

    /// Positioning mode: the six (or eight) points towards the target.
    pub(crate) fn plan_position(&self, m: &Now, vmax: f64, amax: f64, stops: &Stops) -> Option<Phase> {
        let delta = m.target - m.x;
        let d = delta.abs();
        if d < EPS_POS && m.v.abs() <= self.vstop + EPS_VEL {
            if m.v == 0.0 && delta == 0.0 {
                return None;
            }
            return Some(Phase { shape: Shape::Accel(0.0), duration: 0.0, arrives: true });
        }
        // Direction towards the target; at the target with speed, the
        // motor overshoots and comes back.
        let dir = if d < EPS_POS { -m.v.sgn() } else { delta.sgn() };
        if stops.blocks(dir) || stops.blocks(m.v.sgn()) {
            return self.at_a_switch(m, stops);
        }
        if m.v == 0.0 {
            if m.zero_wait > 0.0 {
                return Some(Phase::wait(m.zero_wait));
            }
            if self.vstart > 0.0 {
                return Some(Phase::jump(dir * self.vstart));
            }
        }
        let u = m.v * dir;
        if u < -EPS_VEL {
            // Moving away from the target: down to standstill first.
            return Some(self.braking(m.v));
        }
        let u = u.max(0.0);
        let b = self.brake(u);
        if d <= b + EPS_POS {
            if u > self.vstop + EPS_VEL {
                let (dec, end) = self.slowing_down(u, self.vstop);
                let segment = (u * u - end * end) / (2.0 * dec);
                if d < b - EPS_LAND && d < segment {
                    // A target moved closer: it comes before the ramp's
                    // end; the motor passes it and comes back.
                    let t_target = (u - (u * u - 2.0 * dec * d).max(0.0).sqrt()) / dec;
                    return Some(Phase::accel(-dir * dec, t_target));
                }
                let arrives = end <= self.vstop + EPS_VEL;
                return Some(Phase { shape: Shape::Accel(-dir * dec), duration: (u - end) / dec, arrives });
            }
            // At or below VSTOP: on to the target at this speed.
            if u > EPS_VEL {
                return Some(Phase { shape: Shape::Accel(0.0), duration: d / u, arrives: true });
            }
        }
        if u > vmax + EPS_VEL {
            // VMAX lowered while moving: down to it with the acceleration
            // values of the bands it passes, AMAX above V1 and A1 below
            // (rule 106).
            let b = self.band_below(u, amax);
            return Some(Phase::accel(-dir * b.up, (u - b.lo.max(vmax)) / b.up));
        }
        if u < vmax - EPS_VEL {
            let (acc, end) = self.speeding_up(u, amax, vmax);
            let w = self.peak(u, acc, d);
            if w <= self.vstop + EPS_VEL {
                // The target comes before the motor is faster than VSTOP.
                let t = (-u + (u * u + 2.0 * acc * d).sqrt()) / acc;
                return Some(Phase { shape: Shape::Accel(dir * acc), duration: t, arrives: true });
            }
            return Some(Phase::accel(dir * acc, (w.min(end) - u) / acc));
        }
        if m.v != dir * vmax {
            // Remove float dust from the acceleration phase.
            return Some(Phase::jump(dir * vmax));
        }
        Some(Phase::accel(0.0, (d - self.brake(vmax)) / vmax))
    }
}
