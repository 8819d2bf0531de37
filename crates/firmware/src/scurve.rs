//! The TMC4361A's ramp generator, the motion controller of the modules
//! whose profile says `motion_controller = "tmc4361a"` (docs/behaviour.md
//! rules 114–118).
//!
//! With AP 14 = 0 (the factory value) the ramp is a trapezoid with the
//! sixPoint's bands: VSTART, ASTART up to VBREAK, AMAX up to VMAX, DMAX
//! down to VBREAK, DFINAL down to VSTOP. Positioning runs on the sixPoint
//! planner ([`crate::sixpoint`]); velocity mode here, with AMAX (ASTART)
//! up and DMAX (DFINAL) down.
//!
//! With AP 14 = 1 the ramp is S-shaped: the acceleration changes at a
//! constant rate, the bows. A move from rest has seven phases: B1 (the
//! acceleration rises with BOW1 from ASTART to AMAX), B12 (AMAX), B2 (it
//! falls with BOW2 to 0 at VMAX), B23 (cruise), B3 (the deceleration rises
//! with BOW3 to DMAX), B34 (DMAX) and B4 (it falls with BOW4 to 0 on the
//! target). VSTART ≠ 0 leaves B1 out (the motor starts at VSTART with
//! AMAX), VSTOP ≠ 0 leaves B4 out (DMAX down to VSTOP, a stop on the
//! target).
//!
//! Each phase is planned with its end in closed form; a phase that would
//! run past the braking point ends there (found by bisection on the
//! braking condition, whose braking distance is closed-form): the motor
//! starts braking when the distance left equals the distance it needs to
//! come to rest from its speed and acceleration, bringing a rising
//! acceleration back to 0 with BOW2 first. A move costs a handful of
//! phases, and on arrival the motor is snapped onto its target microstep.

use crate::phase::{EPS_LAND, EPS_POS, EPS_VEL, Phase, Sgn, Shape, Stops};
use crate::sixpoint::{Now, SixPoint};

/// Speeds this close (µsteps/s) are the same speed to the planner.
const TOL_V: f64 = 1e-7;
/// Accelerations this close (µsteps/s²) are the same to the planner.
const TOL_A: f64 = 1e-6;
/// Pieces (and folded jumps) one plan walks at most: a guard against
/// float dust.
const MAX_PIECES: usize = 12;

/// The TMC4361A's own ramp values beside VMAX, AMAX and the target speed
/// of the motion's ramp, in µsteps/s, µsteps/s² and µsteps/s³.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tmc4361a {
    /// AP 14 = 1: the S-shaped ramp; else the trapezoid.
    pub s_shaped: bool,
    /// VSTART (AP 15): the speed a move starts at.
    pub vstart: f64,
    /// ASTART (AP 16): the acceleration below VBREAK (trapezoid); where
    /// B1 starts from a standstill (S-shaped).
    pub astart: f64,
    /// VBREAK (AP 18): where ASTART gives way to AMAX and DMAX to DFINAL
    /// (trapezoid; 0 leaves ASTART and DFINAL out).
    pub vbreak: f64,
    /// DMAX (AP 17): the deceleration above VBREAK; the S-shaped ramp's
    /// largest deceleration.
    pub dmax: f64,
    /// DFINAL (AP 19): the deceleration below VBREAK (trapezoid).
    pub dfinal: f64,
    /// VSTOP (AP 20): the speed at which the motor stops.
    pub vstop: f64,
    /// DSTOP (AP 21): the deceleration of a soft stop at a switch.
    pub dstop: f64,
    /// BOW1…BOW4 (AP 22…25); 0: that change of the acceleration is a
    /// jump.
    pub bows: [f64; 4],
}

/// Where the motor is when a phase is planned: position, velocity,
/// acceleration and target (µsteps, /s, /s²) and the ramp wait left (s).
#[derive(Clone, Copy, Debug)]
pub(crate) struct State {
    pub x: f64,
    pub v: f64,
    pub a: f64,
    pub target: f64,
    pub zero_wait: f64,
}

/// Speed and acceleration in a frame where the speed counts along one
/// direction.
#[derive(Clone, Copy, Debug)]
struct Kin {
    u: f64,
    a: f64,
}

/// A piece of constant jerk `j` lasting `t` seconds, at whose end the
/// acceleration is `end` (exactly); a piece of no duration is a jump of
/// the acceleration to `end`.
#[derive(Clone, Copy, Debug)]
struct Piece {
    j: f64,
    t: f64,
    end: f64,
}

impl Kin {
    /// The state `t` seconds into `p` (its end at most), and the distance
    /// covered.
    fn after(self, p: Piece, t: f64) -> (Kin, f64) {
        if p.t <= 0.0 {
            return (Kin { u: self.u, a: p.end }, 0.0);
        }
        let t = t.clamp(0.0, p.t);
        let x = self.u * t + 0.5 * self.a * t * t + p.j * t * t * t / 6.0;
        let u = self.u + self.a * t + 0.5 * p.j * t * t;
        let a = if t >= p.t { p.end } else { self.a + p.j * t };
        (Kin { u, a }, x)
    }

    /// The state at the end of `p` and the distance covered.
    fn end(self, p: Piece) -> (Kin, f64) {
        self.after(p, p.t)
    }
}

/// The jerk a bow gives: a bow of 0 makes its change of acceleration a
/// jump.
fn jerk(bow: f64) -> f64 {
    if bow > 0.0 { bow } else { f64::INFINITY }
}

/// `1/(2j)`: the speed gained per acceleration² while a jerk `j` brings
/// an acceleration to 0 (none for a jump).
fn half_inverse(j: f64) -> f64 {
    if j.is_finite() { 0.5 / j } else { 0.0 }
}

/// The piece that takes the acceleration from `a` to `target` with a jerk
/// of magnitude `j`.
fn to_accel(a: f64, target: f64, j: f64) -> Piece {
    let diff = target - a;
    if !j.is_finite() || diff == 0.0 {
        return Piece { j: 0.0, t: 0.0, end: target };
    }
    Piece { j: diff.sgn() * j, t: diff.abs() / j, end: target }
}

/// The first piece of the S-curve that brings the speed from `u` up to
/// `w` (`u < w`), arriving with acceleration 0: a negative acceleration
/// back to 0 first (`recover`), then up towards `peak` (`grow`), held,
/// and down to 0 at `w` (`shrink`); a triangle where `w` is too close
/// for `peak`. An acceleration too large to be brought to 0 by `w` is
/// brought to 0 at once (the speed passes `w`). `None`: already there.
fn rise(u: f64, a: f64, w: f64, peak: f64, grow: f64, shrink: f64, recover: f64) -> Option<Piece> {
    let need = w - u;
    if need.abs() <= TOL_V && a.abs() <= TOL_A {
        return None;
    }
    if a < -TOL_A {
        return Some(to_accel(a, 0.0, recover));
    }
    let a = a.max(0.0);
    let (k1, k2) = (half_inverse(grow), half_inverse(shrink));
    if a > TOL_A && a * a * k2 >= need {
        return Some(to_accel(a, 0.0, shrink));
    }
    if a > peak + TOL_A {
        return Some(to_accel(a, peak, shrink));
    }
    let ap = if k1 + k2 > 0.0 { ((need + a * a * k1) / (k1 + k2)).max(0.0).sqrt().min(peak) } else { peak };
    if a < ap - TOL_A {
        return Some(to_accel(a, ap, grow));
    }
    if a <= TOL_A {
        return None;
    }
    let hold = need - a * a * k2;
    if ap >= peak - TOL_A && hold > TOL_V {
        return Some(Piece { j: 0.0, t: hold / a, end: a });
    }
    Some(to_accel(a, 0.0, shrink))
}

/// The first time in `(0, limit]` at which `u + a·t + j·t²/2` falls to
/// `floor`, from above.
fn time_to_speed(u: f64, a: f64, j: f64, floor: f64, limit: f64) -> Option<f64> {
    let c = u - floor;
    if c <= 0.0 {
        return None;
    }
    let speed = |t: f64| c + a * t + 0.5 * j * t * t;
    if speed(limit) > 0.0 {
        // A dip below the floor inside the piece: only at the vertex.
        if j > 0.0 && a < 0.0 {
            let tv = -a / j;
            if tv < limit && speed(tv) < 0.0 {
                return Some(bisect(|t| speed(t) > 0.0, 0.0, tv));
            }
        }
        return None;
    }
    Some(bisect(|t| speed(t) > 0.0, 0.0, limit))
}

/// The boundary between `lo` (where `ok` holds) and `hi` (where it does
/// not), to the last bits: the first point past it.
fn bisect(mut ok: impl FnMut(f64) -> bool, mut lo: f64, mut hi: f64) -> f64 {
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if ok(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

/// A piece cut where the speed falls to `floor` (a piece that ends on
/// it, as B4 ends at a standstill, is whole).
fn cut(k: Kin, p: Piece, floor: f64) -> Piece {
    if k.end(p).0.u >= floor - TOL_V {
        return p;
    }
    match time_to_speed(k.u, k.a, p.j, floor, p.t) {
        Some(t) if t < p.t => Piece { j: p.j, t, end: k.a + p.j * t },
        _ => p,
    }
}

impl Tmc4361a {
    fn bow(&self, n: usize) -> f64 {
        jerk(self.bows[n])
    }

    /// The ramp as the sixPoint planner takes it (the trapezoid): ASTART
    /// and DFINAL below VBREAK, no ramp wait.
    fn six(&self) -> SixPoint {
        SixPoint {
            vstart: self.vstart,
            a1: self.astart,
            v1: self.vbreak,
            dmax: self.dmax,
            d1: self.dfinal,
            a2: 0.0,
            v2: 0.0,
            d2: 0.0,
            vstop: self.vstop,
            zero_wait: 0.0,
        }
    }

    /// The S-curve's first piece from `k` towards speed `w`, up with
    /// AMAX, BOW1 and BOW2, down with DMAX, BOW3 and BOW4 (a rising
    /// acceleration that must end falls with BOW2, a deceleration that
    /// must end with BOW4). `None`: at `w` with no acceleration.
    fn towards(&self, k: Kin, w: f64, amax: f64) -> Option<Piece> {
        if k.u < w {
            rise(k.u, k.a, w, amax, self.bow(0), self.bow(1), self.bow(3))
        } else {
            rise(-k.u, -k.a, -w, self.dmax, self.bow(2), self.bow(3), self.bow(1)).map(|p| Piece { j: -p.j, t: p.t, end: -p.end })
        }
    }

    /// The next piece of braking to a standstill from `k` (speed along the
    /// motion): a rising acceleration back to 0 with BOW2, the
    /// deceleration up to DMAX with BOW3, held, and back to 0 with BOW4
    /// at standstill; with VSTOP ≠ 0 no BOW4: DMAX down to VSTOP. `None`:
    /// the motor stops now.
    fn brake_piece(&self, k: Kin) -> Option<Piece> {
        if self.vstop > 0.0 {
            if k.u <= self.vstop + TOL_V && k.a <= TOL_A {
                return None;
            }
            if k.a > TOL_A {
                return Some(to_accel(k.a, 0.0, self.bow(1)));
            }
            let dec = -k.a;
            let p = if dec < self.dmax - TOL_A {
                to_accel(k.a, -self.dmax, self.bow(2))
            } else if dec > self.dmax + TOL_A {
                to_accel(k.a, -self.dmax, self.bow(3))
            } else {
                Piece { j: 0.0, t: ((k.u - self.vstop) / dec).max(0.0), end: k.a }
            };
            return Some(cut(k, p, self.vstop));
        }
        if k.u <= TOL_V && k.a.abs() <= TOL_A {
            return None;
        }
        let p = if k.a > TOL_A { Some(to_accel(k.a, 0.0, self.bow(1))) } else { self.towards(k, 0.0, 0.0) };
        p.map(|p| cut(k, p, 0.0))
    }

    /// The distance braking to a standstill from `k` covers.
    fn brake_distance(&self, mut k: Kin) -> f64 {
        let mut x = 0.0;
        for _ in 0..MAX_PIECES {
            let Some(p) = self.brake_piece(k) else { break };
            let (next, dx) = k.end(p);
            x += dx;
            k = next;
        }
        x
    }

    /// The phase of a piece in the world's direction `dir` from `k`.
    fn phase(dir: f64, k: Kin, p: Piece, duration: f64, arrives: bool) -> Phase {
        Phase { shape: Shape::Jerk { v: dir * k.u, a: dir * k.a, j: dir * p.j }, duration, arrives }
    }

    /// A motor at a switch that blocks it: a hard stop, or with the soft
    /// stop a linear ramp with DSTOP. `None`: the switch does not stop it.
    fn switch_stop(&self, v: f64, dir: f64, stops: &Stops) -> Option<Option<Phase>> {
        if !(stops.blocks(dir) || stops.blocks(v.sgn())) {
            return None;
        }
        if v == 0.0 {
            return Some(None);
        }
        if !stops.soft {
            return Some(Some(Phase::jump(0.0)));
        }
        Some(Some(Phase::accel(-v.sgn() * self.dstop, v.abs() / self.dstop)))
    }

    /// Positioning mode: the phase the ramp generator is in now (`None`:
    /// at rest with nothing to do).
    pub(crate) fn plan_position(&self, s: &State, vmax: f64, amax: f64, stops: &Stops) -> Option<Phase> {
        let delta = s.target - s.x;
        let d = delta.abs();
        // At a standstill the acceleration is 0, whatever stopped the motor.
        let (v, a) = if s.v == 0.0 { (0.0, 0.0) } else { (s.v, s.a) };
        let dir = if d < EPS_POS { -v.sgn() } else { delta.sgn() };
        if !self.s_shaped {
            if let Some(p) = self.switch_stop(v, dir, stops) {
                return p;
            }
            let now = Now { x: s.x, v: s.v, target: s.target, zero_wait: s.zero_wait };
            return self.six().plan_position(&now, vmax, amax, stops);
        }
        if d < EPS_POS && v.abs() <= self.vstop + EPS_VEL {
            if v == 0.0 && delta == 0.0 {
                return None;
            }
            return Some(Phase { shape: Shape::Accel(0.0), duration: 0.0, arrives: true });
        }
        if let Some(p) = self.switch_stop(v, dir, stops) {
            return p;
        }
        if v == 0.0 {
            if s.zero_wait > 0.0 {
                return Some(Phase::wait(s.zero_wait));
            }
            if vmax <= TOL_V && self.vstart <= 0.0 {
                return None;
            }
            return Some(self.start(dir, d, vmax, amax));
        }
        let k = Kin { u: v * dir, a: a * dir };
        if k.u < 0.0 {
            // Moving away from the target: to a standstill first.
            let own = Kin { u: -k.u, a: -k.a };
            return Some(self.brake_phase(-dir, own, None));
        }
        Some(self.position_from(dir, k, d, vmax, amax))
    }

    /// A move from rest: VSTART (or 0) with AMAX (or ASTART), the
    /// acceleration no larger than BOW2 can bring back to 0 by VMAX and
    /// than the motor can brake from before the target; a move shorter
    /// than VSTART's braking distance runs at VSTART onto the target.
    fn start(&self, dir: f64, d: f64, vmax: f64, amax: f64) -> Phase {
        let v0 = self.vstart;
        if v0 > 0.0 && d <= self.brake_distance(Kin { u: v0, a: 0.0 }) + EPS_POS {
            return Self::phase(dir, Kin { u: v0, a: 0.0 }, Piece { j: 0.0, t: 0.0, end: 0.0 }, d / v0, true);
        }
        let mut a0 = if v0 > 0.0 { amax } else { self.astart.min(amax) };
        let k2 = half_inverse(self.bow(1));
        if k2 > 0.0 {
            a0 = a0.min(((vmax - v0).max(0.0) / k2).sqrt());
        }
        if self.brake_distance(Kin { u: v0, a: a0 }) > d {
            a0 = bisect(|a| self.brake_distance(Kin { u: v0, a }) <= d, 0.0, a0);
            // The last bits on the safe side.
            a0 *= 1.0 - 1e-12;
        }
        self.position_from(dir, Kin { u: v0, a: a0 }, d, vmax, amax)
    }

    /// Braking to a standstill in direction `dir` from `k`; `arrive`: the
    /// distance to the target, on which the last piece then ends.
    fn brake_phase(&self, dir: f64, mut k: Kin, arrive: Option<f64>) -> Phase {
        for _ in 0..MAX_PIECES {
            let Some(p) = self.brake_piece(k) else { break };
            if p.t <= 0.0 {
                k = k.end(p).0;
                continue;
            }
            let last = self.brake_piece(k.end(p).0).is_none();
            let arrives = last && arrive.is_some_and(|d| d >= self.brake_distance(k) - EPS_LAND);
            return Self::phase(dir, k, p, p.t, arrives);
        }
        Phase::jump(0.0)
    }

    /// The phase towards the target `d` ahead from `k` (moving towards it
    /// or at rest): up towards VMAX (or down to it), cruise, and braking
    /// from the moment the braking distance equals the distance left.
    fn position_from(&self, dir: f64, mut k: Kin, d: f64, vmax: f64, amax: f64) -> Phase {
        for _ in 0..MAX_PIECES {
            let b = self.brake_distance(k);
            if self.vstart > 0.0 && (k.u - self.vstart).abs() <= TOL_V && k.a.abs() <= TOL_A && d < b + EPS_POS {
                // At VSTART, too close to brake: on at VSTART onto the target.
                return Self::phase(dir, Kin { u: self.vstart, a: 0.0 }, Piece { j: 0.0, t: 0.0, end: 0.0 }, d / self.vstart, true);
            }
            if d <= b + EPS_POS {
                if self.brake_piece(k).is_none() {
                    return Phase { shape: Shape::Jerk { v: dir * k.u, a: 0.0, j: 0.0 }, duration: 0.0, arrives: true };
                }
                return self.brake_phase(dir, k, Some(d));
            }
            let Some(p) = self.towards(k, vmax, amax) else {
                // At VMAX: cruise to the braking point.
                if vmax <= TOL_V {
                    return Phase::jump(0.0);
                }
                let cruise = Kin { u: vmax, a: 0.0 };
                let t = (d - self.brake_distance(cruise)) / vmax;
                return Self::phase(dir, cruise, Piece { j: 0.0, t: 0.0, end: 0.0 }, t.max(0.0), false);
            };
            if p.t <= 0.0 {
                k = k.end(p).0;
                continue;
            }
            // Past the braking point? It ends there.
            let left = |t: f64| {
                let (next, dx) = k.after(p, t);
                d - dx - self.brake_distance(next)
            };
            let t = if left(p.t) > 0.0 { p.t } else { bisect(|t| left(t) > 0.0, 0.0, p.t) };
            return Self::phase(dir, k, p, t, false);
        }
        Phase::jump(dir * k.u)
    }

    /// Velocity mode: towards the target speed (S-shaped: with the bows;
    /// trapezoid: AMAX and ASTART up, DMAX and DFINAL down); a reversal
    /// passes through a standstill, and from a standstill the motor starts
    /// at VSTART; down to 0 it stops at VSTOP.
    pub(crate) fn plan_velocity(&self, s: &State, target_velocity: f64, amax: f64, stops: &Stops) -> Option<Phase> {
        let (v, a) = if s.v == 0.0 { (0.0, 0.0) } else { (s.v, s.a) };
        let vt = target_velocity;
        if let Some(p) = self.switch_stop(v, vt.sgn(), stops) {
            return p;
        }
        if v == 0.0 {
            if vt == 0.0 {
                return None;
            }
            if s.zero_wait > 0.0 {
                return Some(Phase::wait(s.zero_wait));
            }
            let (dir, w) = (vt.sgn(), vt.abs());
            if !self.s_shaped {
                if self.vstart > 0.0 {
                    return Some(Phase::jump(dir * self.vstart));
                }
                return Some(self.trapezoid_velocity(dir, 0.0, w, amax));
            }
            let v0 = self.vstart;
            let mut a0 = if v0 > 0.0 { amax } else { self.astart.min(amax) };
            let k2 = half_inverse(self.bow(1));
            if k2 > 0.0 {
                a0 = a0.min(((w - v0).max(0.0) / k2).sqrt());
            }
            if w <= v0 {
                a0 = 0.0;
            }
            return Some(self.velocity_from(dir, Kin { u: v0, a: a0 }, w, amax));
        }
        let dir = v.sgn();
        let w = if vt.sgn() == dir { vt.abs() } else { 0.0 };
        if !self.s_shaped {
            return Some(self.trapezoid_velocity(dir, v.abs(), w, amax));
        }
        Some(self.velocity_from(dir, Kin { u: v.abs(), a: a * dir }, w, amax))
    }

    /// The S-curve's phase from `k` to speed `w` (0: to a standstill) in
    /// direction `dir`.
    fn velocity_from(&self, dir: f64, mut k: Kin, w: f64, amax: f64) -> Phase {
        for _ in 0..MAX_PIECES {
            let piece = if w == 0.0 { self.brake_piece(k) } else { self.towards(k, w, amax) };
            let Some(p) = piece else {
                if w == 0.0 {
                    return Phase::jump(0.0);
                }
                return Self::phase(dir, Kin { u: w, a: 0.0 }, Piece { j: 0.0, t: 0.0, end: 0.0 }, f64::INFINITY, false);
            };
            if p.t <= 0.0 {
                k = k.end(p).0;
                continue;
            }
            return Self::phase(dir, k, p, p.t, false);
        }
        Phase::jump(dir * w)
    }

    /// The trapezoid's velocity mode from speed `u` to `w` in direction
    /// `dir`: the bands' accelerations up, their decelerations down,
    /// the stop at VSTOP.
    fn trapezoid_velocity(&self, dir: f64, u: f64, w: f64, amax: f64) -> Phase {
        let six = self.six();
        if w == 0.0 && u <= self.vstop + EPS_VEL {
            return Phase::jump(0.0);
        }
        if (u - w).abs() < EPS_VEL {
            if u != w {
                return Phase::jump(dir * w);
            }
            return Phase::accel(0.0, f64::INFINITY);
        }
        if u < w {
            let (acc, end) = six.speeding_up(u, amax, w);
            return Phase::accel(dir * acc, (end - u) / acc);
        }
        let (dec, end) = six.slowing_down(u, if w == 0.0 { self.vstop } else { w });
        Phase::accel(-dir * dec, (u - end) / dec)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chip(bows: [f64; 4]) -> Tmc4361a {
        Tmc4361a { s_shaped: true, vstart: 0.0, astart: 0.0, vbreak: 0.0, dmax: 40_000.0, dfinal: 1.0, vstop: 0.0, dstop: 10_000.0, bows }
    }

    #[test]
    fn the_braking_distance_is_the_closed_form() {
        let c = chip([100_000.0, 200_000.0, 50_000.0, 80_000.0]);
        // From 50 000 pps at rest: B3 to DMAX (0.8 s), B34, B4 (0.5 s).
        let (u, d, j3, j4) = (50_000.0, 40_000.0, 50_000.0, 80_000.0);
        let (t3, t4) = (d / j3, d / j4);
        let dv3 = d * d / (2.0 * j3);
        let dv4 = d * d / (2.0 * j4);
        let t34 = (u - dv3 - dv4) / d;
        let x3 = u * t3 - j3 * t3 * t3 * t3 / 6.0;
        let u3 = u - dv3;
        let x34 = u3 * t34 - 0.5 * d * t34 * t34;
        let u4 = u3 - d * t34;
        let x4 = u4 * t4 - 0.5 * d * t4 * t4 + j4 * t4 * t4 * t4 / 6.0;
        let b = c.brake_distance(Kin { u, a: 0.0 });
        assert!((b - (x3 + x34 + x4)).abs() < 1e-6, "{b} vs {}", x3 + x34 + x4);
    }

    #[test]
    fn a_bow_of_zero_is_a_jump() {
        let c = chip([0.0; 4]);
        // The trapezoid with DMAX: u²/(2 DMAX).
        let b = c.brake_distance(Kin { u: 40_000.0, a: 0.0 });
        assert!((b - 20_000.0).abs() < 1e-6, "{b}");
    }
}
