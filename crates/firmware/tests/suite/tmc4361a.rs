//! The TMC4361A's ramps (docs/behaviour.md rules 114–118) against their
//! closed form: the S-shaped ramp's phases of constant jerk are worked
//! out here from the definitions alone (the acceleration is the integral
//! of the bow, the speed of the acceleration, the position of the
//! speed), the motion sampled every millisecond of stepped time must lie
//! on them; the trapezoid is the sixPoint planner's; the units and rows
//! by the wire on a test module made from the TMCM-1260's profile.

use crate::common::{self, BusOfOne, MS, send, status, until};
use tmclsim_firmware::motion::{Motion, Ramp, RampMode, SixPoint, Step, Stops, Tmc4361a, Units};

/// An S-shaped ramp: VMAX, AMAX and the chip's values.
#[derive(Clone, Copy, Debug)]
struct Set {
    vmax: f64,
    amax: f64,
    chip: Tmc4361a,
}

/// Bows that differ from each other, so that a phase with the wrong bow
/// shows.
const S: Set = Set {
    vmax: 100_000.0,
    amax: 40_000.0,
    chip: Tmc4361a {
        s_shaped: true,
        vstart: 0.0,
        astart: 0.0,
        vbreak: 0.0,
        dmax: 50_000.0,
        dfinal: 1.0,
        vstop: 0.0,
        dstop: 20_000.0,
        bows: [100_000.0, 200_000.0, 125_000.0, 250_000.0],
    },
};

fn ramp(s: Set) -> Ramp {
    Ramp { vmax: s.vmax, vmin: 0.0, accel_position: s.amax, accel_velocity: s.amax, target_velocity: 0.0, six: None }
}

/// A phase of the closed form: jerk and duration.
type Piece = (f64, f64);

/// The phases that take the speed from `from` to `to` (both ≥ 0) with
/// the acceleration starting at `a0` and ending at 0: up with AMAX and
/// BOW1/BOW2, down with DMAX and BOW3/BOW4; the peak lowered where the
/// bows meet first (a triangle).
fn s_curve(s: Set, from: f64, to: f64, a0: f64) -> Vec<Piece> {
    let [b1, b2, b3, b4] = s.chip.bows;
    let (peak, grow, shrink, sign) = if to >= from { (s.amax, b1, b2, 1.0) } else { (s.chip.dmax, b3, b4, -1.0) };
    let need = (to - from).abs();
    let a0 = a0 * sign;
    // (ap² − a0²)/(2 grow) + ap²/(2 shrink) = need
    let ap = ((need + a0 * a0 / (2.0 * grow)) / (1.0 / (2.0 * grow) + 1.0 / (2.0 * shrink))).sqrt().min(peak);
    let hold = need - (ap * ap - a0 * a0) / (2.0 * grow) - ap * ap / (2.0 * shrink);
    let mut p = vec![(sign * grow, (ap - a0) / grow)];
    if hold > 1e-9 {
        p.push((0.0, hold / ap));
    }
    p.push((-sign * shrink, ap / shrink));
    p.retain(|q| q.1 > 0.0);
    p
}

/// Position, speed and acceleration `t` seconds into `phases` from `v0`
/// with acceleration `a0`.
fn at(phases: &[Piece], v0: f64, a0: f64, mut t: f64) -> (f64, f64, f64) {
    let (mut x, mut v, mut a) = (0.0, v0, a0);
    for &(j, dt) in phases {
        let tt = t.min(dt);
        x += v * tt + a * tt * tt / 2.0 + j * tt * tt * tt / 6.0;
        v += a * tt + j * tt * tt / 2.0;
        a += j * tt;
        if t <= dt {
            return (x, v, a);
        }
        t -= dt;
    }
    (x, v, a)
}

fn distance(phases: &[Piece], v0: f64, a0: f64) -> f64 {
    at(phases, v0, a0, phases.iter().map(|p| p.1).sum()).0
}

fn duration(phases: &[Piece]) -> f64 {
    phases.iter().map(|p| p.1).sum()
}

/// A move of `d` from rest: up to the peak speed (VMAX, or lower where
/// the move is too short: found by bisection), cruise, down to 0.
fn closed_form(s: Set, d: f64) -> Vec<Piece> {
    let total = |w: f64| distance(&s_curve(s, 0.0, w, 0.0), 0.0, 0.0) + distance(&s_curve(s, w, 0.0, 0.0), w, 0.0);
    let mut peak = s.vmax;
    if total(s.vmax) > d {
        let (mut lo, mut hi) = (0.0, s.vmax);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if total(mid) > d { hi = mid } else { lo = mid }
        }
        peak = lo;
    }
    let mut phases = s_curve(s, 0.0, peak, 0.0);
    let cruise = d - total(peak);
    if cruise > 1e-9 {
        phases.push((0.0, cruise / peak));
    }
    phases.extend(s_curve(s, peak, 0.0, 0.0));
    phases
}

fn step(m: &mut Motion, s: &Set, r: &Ramp, dt: f64) -> Step {
    m.advance_on(dt, r, Some(&s.chip), &mut |_| Stops::default(), &[], false)
}

/// Runs a move of `d` in 1 ms steps against the closed form `phases`
/// (from `v0`, `a0`): position, speed and acceleration on it, the
/// acceleration continuous (no step larger than a bow's millisecond),
/// the arrival on time and on the target microstep.
fn check(name: &str, s: Set, d: f64, phases: &[Piece], v0: f64, a0: f64) {
    let r = ramp(s);
    let total = duration(phases);
    let mut m = Motion { target: d, ..Motion::default() };
    let dt = 0.001;
    let bow = s.chip.bows.iter().fold(0.0f64, |a, &b| a.max(b));
    let mut t = 0.0;
    let mut last_a = None;
    loop {
        let st = step(&mut m, &s, &r, dt);
        t += dt;
        if st.arrived {
            break;
        }
        let (x, v, a) = at(phases, v0, a0, t);
        assert!((m.x - x).abs() < 1e-3, "{name}: at {t:.3} s the motor is at {}, the closed form at {x}", m.x);
        assert!((m.v - v).abs() < 1e-3, "{name}: at {t:.3} s the speed is {}, the closed form's {v}", m.v);
        assert!((m.a - a).abs() < 1e-3, "{name}: at {t:.3} s the acceleration is {}, the closed form's {a}", m.a);
        if let Some(last) = last_a {
            let jump: f64 = m.a - last;
            assert!(jump.abs() <= bow * dt + 1e-6, "{name}: the acceleration jumps by {jump} at {t:.3} s");
        }
        last_a = Some(m.a);
        assert!(t < total + 1.0, "{name}: no arrival after {t} s (closed form: {total} s)");
    }
    assert_eq!(m.x, d, "{name}: on the target microstep");
    assert_eq!((m.v, m.a), (0.0, 0.0), "{name}");
    assert!((t - total).abs() <= dt + 1e-9, "{name}: arrived after {t} s, the closed form after {total} s");
    // The phases in one call: the same end, in a handful of phases.
    let mut once = Motion { target: d, ..Motion::default() };
    let st = step(&mut once, &s, &r, total + 1.0);
    assert!(st.arrived, "{name}");
    assert_eq!(once.x, d, "{name}");
    assert!(st.phases <= phases.len() + 3, "{name}: {} phases for the closed form's {}", st.phases, phases.len());
}

#[test]
fn a_full_move_has_seven_phases() {
    let phases = closed_form(S, 1_000_000.0);
    // B1 0.4 s, B12 2.2 s, B2 0.2 s, cruise, B3 0.4 s, B34 1.7 s, B4 0.2 s.
    let expect = [(100_000.0, 0.4), (0.0, 2.2), (-200_000.0, 0.2), (0.0, f64::NAN), (-125_000.0, 0.4), (0.0, 1.7), (250_000.0, 0.2)];
    assert_eq!(phases.len(), 7);
    for (i, (&(j, t), &(ej, et))) in phases.iter().zip(&expect).enumerate() {
        assert_eq!(j, ej, "phase {i}'s bow");
        assert!(et.is_nan() || (t - et).abs() < 1e-9, "phase {i} lasts {t} s, not {et}");
    }
    // The distances of the phases: up 12 000 pps with B1 and B2 … and the
    // rest at VMAX.
    let up = distance(&phases[..3], 0.0, 0.0);
    let down = distance(&phases[4..], 100_000.0, 0.0);
    assert!((phases[3].1 - (1_000_000.0 - up - down) / 100_000.0).abs() < 1e-9);
    check("seven phases", S, 1_000_000.0, &phases, 0.0, 0.0);
}

#[test]
fn short_moves_lower_the_peaks() {
    // VMAX too low for AMAX: the bows meet, a triangle of acceleration.
    let slow = Set { vmax: 10_000.0, ..S };
    let phases = closed_form(slow, 200_000.0);
    assert_eq!(phases.len(), 5, "B1, B2, cruise, B3, B4: {phases:?}");
    let peak = phases[0].0 * phases[0].1;
    assert!(peak < S.amax, "the acceleration peaks at {peak}");
    check("too slow for AMAX", slow, 200_000.0, &phases, 0.0, 0.0);
    // Too short for VMAX: braking starts before VMAX.
    let phases = closed_form(S, 100_000.0);
    assert!(!phases.iter().any(|p| p.0 == 0.0 && p.1 > 0.0 && phases.iter().position(|q| q == p) == Some(3)));
    check("too short for VMAX", S, 100_000.0, &phases, 0.0, 0.0);
    // So short that neither AMAX nor DMAX is reached.
    let phases = closed_form(S, 2_000.0);
    check("too short for AMAX", S, 2_000.0, &phases, 0.0, 0.0);
    // A negative move mirrors a positive one.
    let r = ramp(S);
    let mut a = Motion { target: 30_000.0, ..Motion::default() };
    let mut b = Motion { target: -30_000.0, ..Motion::default() };
    for _ in 0..3000 {
        step(&mut a, &S, &r, 0.001);
        step(&mut b, &S, &r, 0.001);
        assert_eq!((a.x, a.v, a.a), (-b.x, -b.v, -b.a));
    }
    assert_eq!((a.x, b.x), (30_000.0, -30_000.0));
}

#[test]
fn vstart_skips_b1_and_vstop_skips_b4() {
    let s = Set { chip: Tmc4361a { vstart: 5_000.0, vstop: 3_000.0, ..S.chip }, ..S };
    let [_, b2, b3, _] = s.chip.bows;
    // Up: at VSTART with AMAX, held, B2 to VMAX.
    let hold = (s.vmax - 5_000.0 - s.amax * s.amax / (2.0 * b2)) / s.amax;
    let up = vec![(0.0, hold), (-b2, s.amax / b2)];
    // Down: B3 to DMAX, held down to VSTOP, the stop there.
    let dmax = s.chip.dmax;
    let hold_down = (s.vmax - dmax * dmax / (2.0 * b3) - 3_000.0) / dmax;
    let down = vec![(-b3, dmax / b3), (0.0, hold_down)];
    let d = 1_000_000.0;
    let mut phases = up.clone();
    let cruise = d - distance(&up, 5_000.0, s.amax) - distance_from(&down, s.vmax, 0.0);
    phases.push((0.0, cruise / s.vmax));
    phases.extend(down);
    check("VSTART and VSTOP", s, d, &phases, 5_000.0, s.amax);
}

/// `distance` with the speed and acceleration a list starts from.
fn distance_from(phases: &[Piece], v0: f64, a0: f64) -> f64 {
    distance(phases, v0, a0)
}

#[test]
fn a_target_ahead_is_followed_one_behind_is_reached_by_a_reversal() {
    let r = ramp(S);
    // Ahead, during the cruise: as if the farther target had been there
    // from the start.
    let mut m = Motion { target: 1_000_000.0, ..Motion::default() };
    step(&mut m, &S, &r, 5.0);
    m.target = 1_500_000.0;
    let mut t = 5.0;
    while !step(&mut m, &S, &r, 0.001).arrived {
        t += 0.001;
        assert!(t < 100.0);
    }
    let total = duration(&closed_form(S, 1_500_000.0));
    assert!((t + 0.001 - total).abs() <= 0.001 + 1e-9, "{t} vs {total}");
    assert_eq!(m.x, 1_500_000.0);
    // Behind, at full speed: B3, B34, B4 to a standstill, then back.
    let mut m = Motion { target: 1_000_000.0, ..Motion::default() };
    step(&mut m, &S, &r, 5.0);
    assert_eq!((m.v, m.a), (100_000.0, 0.0));
    let from = m.x;
    m.target = 0.0;
    let brake = s_curve(S, 100_000.0, 0.0, 0.0);
    let mut farthest = m.x;
    let mut t = 0.0;
    while m.v > 0.0 {
        step(&mut m, &S, &r, 0.001);
        t += 0.001;
        farthest = farthest.max(m.x);
    }
    assert!((t - duration(&brake)).abs() <= 0.001 + 1e-9, "stopped after {t} s, not {}", duration(&brake));
    assert!((farthest - from - distance(&brake, 100_000.0, 0.0)).abs() < 1e-3, "braking distance {}", farthest - from);
    step(&mut m, &S, &r, 100.0);
    assert_eq!((m.x, m.v, m.a), (0.0, 0.0, 0.0), "back on the new target");
    // Closer than the braking distance: passed, stopped, approached again.
    let mut m = Motion { target: 1_000_000.0, ..Motion::default() };
    step(&mut m, &S, &r, 5.0);
    m.target = m.x + 1_000.0;
    let target = m.target;
    let mut beyond = 0.0f64;
    for _ in 0..30_000 {
        step(&mut m, &S, &r, 0.001);
        beyond = beyond.max(m.x - target);
    }
    assert!(beyond > 10_000.0, "it passes the target ({beyond})");
    assert_eq!((m.x, m.v), (target, 0.0));
}

#[test]
fn vmax_lowered_while_moving_is_followed_with_the_deceleration_bows() {
    let mut r = ramp(S);
    let mut m = Motion { target: 5_000_000.0, ..Motion::default() };
    step(&mut m, &S, &r, 5.0);
    assert_eq!(m.v, 100_000.0);
    r.vmax = 50_000.0;
    let down = s_curve(S, 100_000.0, 50_000.0, 0.0);
    let mut t = 0.0;
    for _ in 0..5000 {
        step(&mut m, &S, &r, 0.001);
        t += 0.001;
        let (_, v, a) = at(&down, 100_000.0, 0.0, t);
        assert!((m.v - v).abs() < 1e-3 && (m.a - a).abs() < 1e-3, "at {t}: {} {} vs {v} {a}", m.v, m.a);
    }
    assert_eq!(m.v, 50_000.0);
    step(&mut m, &S, &r, 1000.0);
    assert_eq!(m.x, 5_000_000.0);
}

#[test]
fn velocity_mode_up_down_and_reversal() {
    let mut r = ramp(S);
    r.target_velocity = 50_000.0;
    let mut m = Motion { mode: RampMode::Velocity, ..Motion::default() };
    let sample = |m: &mut Motion, r: &Ramp, phases: &[Piece], v0: f64, name: &str| {
        let mut t = 0.0;
        let total = duration(phases);
        while t < total - 1e-9 {
            step(m, &S, r, 0.001);
            t += 0.001;
            let (_, v, a) = at(phases, v0, 0.0, t);
            assert!((m.v - v).abs() < 1e-3 && (m.a - a).abs() < 1e-3, "{name} at {t}: {} {} vs {v} {a}", m.v, m.a);
        }
    };
    sample(&mut m, &r, &s_curve(S, 0.0, 50_000.0, 0.0), 0.0, "up");
    step(&mut m, &S, &r, 1.0);
    assert_eq!((m.v, m.a), (50_000.0, 0.0));
    r.target_velocity = 20_000.0;
    sample(&mut m, &r, &s_curve(S, 50_000.0, 20_000.0, 0.0), 50_000.0, "down");
    step(&mut m, &S, &r, 1.0);
    assert_eq!((m.v, m.a), (20_000.0, 0.0));
    // A reversal: to a standstill with the deceleration bows, then up the
    // other way.
    r.target_velocity = -20_000.0;
    let mut phases = s_curve(S, 20_000.0, 0.0, 0.0);
    phases.extend(s_curve(S, 0.0, 20_000.0, 0.0).iter().map(|&(j, t)| (-j, t)));
    sample(&mut m, &r, &phases, 20_000.0, "reversal");
    step(&mut m, &S, &r, 1.0);
    assert_eq!((m.v, m.a), (-20_000.0, 0.0));
    // MST: velocity mode with target 0, with VSTOP: DMAX down to it and
    // the stop.
    let s = Set { chip: Tmc4361a { vstop: 2_000.0, ..S.chip }, ..S };
    r.target_velocity = 0.0;
    let mut t = 0.0;
    while m.v != 0.0 {
        m.advance_on(0.001, &r, Some(&s.chip), &mut |_| Stops::default(), &[], false);
        t += 0.001;
        assert!(t < 10.0);
    }
    let dmax = s.chip.dmax;
    let b3 = s.chip.bows[2];
    let expect = dmax / b3 + (20_000.0 - dmax * dmax / (2.0 * b3) - 2_000.0) / dmax;
    assert!((t - expect).abs() <= 0.001 + 1e-9, "stopped after {t} s, not {expect}");
}

#[test]
fn an_hour_costs_a_handful_of_phases() {
    let mut r = ramp(S);
    r.target_velocity = 80_000.0;
    let mut m = Motion { mode: RampMode::Velocity, ..Motion::default() };
    let st = step(&mut m, &S, &r, 3600.0);
    assert!((st.elapsed - 3600.0).abs() < 1e-9, "{}", st.elapsed);
    assert!(st.phases <= 4, "{} phases", st.phases);
    let expect = distance(&s_curve(S, 0.0, 80_000.0, 0.0), 0.0, 0.0) + 80_000.0 * (3600.0 - duration(&s_curve(S, 0.0, 80_000.0, 0.0)));
    assert!((m.x - expect).abs() < 1e-3, "{} vs {expect}", m.x);
    // An hour-long move from rest to its target.
    let d = 100_000.0 * 3600.0;
    let mut m = Motion { target: d, ..Motion::default() };
    let st = step(&mut m, &S, &ramp(S), 4000.0);
    assert!(st.arrived && st.phases <= 10, "{} phases", st.phases);
    assert_eq!(m.x, d);
    let total = Motion { target: d, ..Motion::default() }.time_to_rest_on(&ramp(S), Some(&S.chip), &mut |_| Stops::default()).unwrap();
    assert!((total - duration(&closed_form(S, d))).abs() < 1e-6, "{total}");
}

#[test]
fn bows_of_zero_make_the_trapezoid() {
    let s = Set { chip: Tmc4361a { bows: [0.0; 4], ..S.chip }, ..S };
    let r = ramp(s);
    let mut m = Motion { target: 1_000_000.0, ..Motion::default() };
    step(&mut m, &s, &r, 1.0);
    assert!((m.v - s.amax).abs() < 1e-6, "AMAX at once: {}", m.v);
    let total = m.time_to_rest_on(&r, Some(&s.chip), &mut |_| Stops::default()).unwrap() + 1.0;
    let expect = s.vmax / s.amax
        + s.vmax / s.chip.dmax
        + (1_000_000.0 - s.vmax * s.vmax / (2.0 * s.amax) - s.vmax * s.vmax / (2.0 * s.chip.dmax)) / s.vmax;
    assert!((total - expect).abs() < 1e-6, "{total} vs {expect}");
}

#[test]
fn the_trapezoid_is_the_band_planner() {
    let chip =
        Tmc4361a { s_shaped: false, vstart: 1_000.0, astart: 10_000.0, vbreak: 20_000.0, dfinal: 15_000.0, vstop: 2_000.0, ..S.chip };
    let six = SixPoint {
        vstart: 1_000.0,
        a1: 10_000.0,
        v1: 20_000.0,
        dmax: 50_000.0,
        d1: 15_000.0,
        a2: 0.0,
        v2: 0.0,
        d2: 0.0,
        vstop: 2_000.0,
        zero_wait: 0.0,
    };
    let plain = ramp(S);
    let bands = Ramp { six: Some(six), ..plain };
    for d in [1_000_000.0, 20_000.0, 3_000.0, -400_000.0] {
        let mut a = Motion { target: d, ..Motion::default() };
        let mut b = a.clone();
        for _ in 0..20_000 {
            a.advance_on(0.001, &plain, Some(&chip), &mut |_| Stops::default(), &[], false);
            b.advance(0.001, &bands, &mut |_| Stops::default(), &[], false);
            assert_eq!((a.x, a.v), (b.x, b.v), "{d}");
        }
        assert_eq!(a.x, d);
    }
    // Velocity mode: AMAX (ASTART below VBREAK) up from VSTART, DMAX
    // (DFINAL) down, the stop at VSTOP.
    let mut r = plain;
    r.target_velocity = 60_000.0;
    let mut m = Motion { mode: RampMode::Velocity, ..Motion::default() };
    m.advance_on(1e-9, &r, Some(&chip), &mut |_| Stops::default(), &[], false);
    assert!((m.v - 1_000.0).abs() < 1e-3, "VSTART at once: {}", m.v);
    m.advance_on(1.0, &r, Some(&chip), &mut |_| Stops::default(), &[], false);
    assert!((m.v - (1_000.0 + 10_000.0)).abs() < 1e-3, "ASTART below VBREAK: {}", m.v);
    m.advance_on(0.9 + 0.5, &r, Some(&chip), &mut |_| Stops::default(), &[], false);
    assert!((m.v - (20_000.0 + 0.5 * 40_000.0)).abs() < 1e-3, "AMAX above: {}", m.v);
    m.advance_on(10.0, &r, Some(&chip), &mut |_| Stops::default(), &[], false);
    assert_eq!(m.v, 60_000.0);
    r.target_velocity = 0.0;
    m.advance_on(0.5, &r, Some(&chip), &mut |_| Stops::default(), &[], false);
    assert!((m.v - 35_000.0).abs() < 1e-3, "DMAX down: {}", m.v);
    let t = m.time_to_rest_on(&r, Some(&chip), &mut |_| Stops::default()).unwrap();
    assert!((t - (15_000.0 / 50_000.0 + 18_000.0 / 15_000.0)).abs() < 1e-9, "DMAX to VBREAK, DFINAL to VSTOP: {t}");
}

#[test]
fn the_soft_stop_is_linear_with_dstop() {
    let mut r = ramp(S);
    r.target_velocity = 60_000.0;
    let mut m = Motion { mode: RampMode::Velocity, ..Motion::default() };
    step(&mut m, &S, &r, 5.0);
    let soft = Stops { block_positive: true, block_negative: false, soft: true };
    m.advance_on(1.0, &r, Some(&S.chip), &mut |_| soft, &[], false);
    assert!((m.v - 40_000.0).abs() < 1e-6, "DSTOP 20 000 pps² for a second: {}", m.v);
    m.advance_on(2.0, &r, Some(&S.chip), &mut |_| soft, &[], false);
    assert_eq!(m.v, 0.0);
    let hard = Stops { soft: false, ..soft };
    let mut n = Motion { mode: RampMode::Velocity, ..Motion::default() };
    step(&mut n, &S, &r, 5.0);
    n.advance_on(0.001, &r, Some(&S.chip), &mut |_| hard, &[], false);
    assert_eq!(n.v, 0.0, "a hard stop at once");
    // A switch edge crossed in an S-shaped phase stops the motor on it.
    let mut k = Motion { mode: RampMode::Velocity, ..Motion::default() };
    let mut stops = |x: f64| Stops { block_positive: x >= 1_234.5, block_negative: false, soft: false };
    k.advance_on(10.0, &r, Some(&S.chip), &mut stops, &[1_234.5], false);
    assert_eq!((k.x, k.v), (1_234.5, 0.0));
}

#[test]
fn units_in_both_unit_modes() {
    let pps = Units::Tmc4361a { fclk: 16_000_000, internal: false, direct: false };
    let internal = Units::Tmc4361a { fclk: 16_000_000, internal: true, direct: false };
    assert_eq!(pps.velocity_pps(51_200.0), 51_200.0);
    assert_eq!(internal.velocity_pps(51_200.0 * 256.0), 51_200.0);
    assert_eq!(internal.velocity_pps(1.0), 1.0 / 256.0, "24.8 fixed point");
    assert_eq!(pps.accel_pps2(51_200.0), 51_200.0);
    assert_eq!(internal.accel_pps2(204_800.0), 51_200.0, "22.2 fixed point");
    assert_eq!(pps.accel_pps2(0.0), 0.25, "0 acts as the smallest");
    // VACTUAL reads whole pps, towards zero.
    assert_eq!(pps.velocity_value(51_200.9), 51_200.0);
    assert_eq!(pps.velocity_value(-3.5), -3.0);
    assert_eq!(internal.velocity_value(51_200.9), 51_200.0 * 256.0);
    // Above 4 194 303 pps² the module writes the chip's direct values.
    let direct = Units::Tmc4361a { fclk: 16_000_000, internal: false, direct: true };
    let unit = 16e6 * 16e6 / 2f64.powi(37);
    assert_eq!(direct.accel_pps2(5_000_000.0), (5_000_000.0 / unit).trunc() * unit);
    assert_eq!(direct.accel_pps2(10_000.0), (10_000.0 / unit).trunc() * unit);
}

fn module() -> BusOfOne {
    common::tmc4361a_module()
}

/// The test module with a right switch at +1 000 000 µsteps.
fn module_with_switch() -> BusOfOne {
    let mut m = common::tmc4361a_module();
    m.world_mut().axes[0].right_switch = Some(1_000_000.0);
    m
}

#[test]
fn an_s_shaped_move_by_the_wire() {
    let mut m = module();
    for (n, v) in [(14, 1), (4, 100_000), (5, 40_000), (17, 50_000), (22, 100_000), (23, 200_000), (24, 125_000), (25, 250_000)] {
        send(&mut m, &format!("SAP {n}, 0, {v}"));
    }
    send(&mut m, "MVP ABS, 0, 1000000");
    let phases = closed_form(S, 1_000_000.0);
    let total = duration(&phases);
    let speed_at = |m: &mut BusOfOne, t: f64| {
        m.advance_to((t * 1e9).round() as u64);
        send(m, "GAP 3, 0")
    };
    let (_, v, _) = at(&phases, 0.0, 0.0, 0.3);
    assert_eq!(speed_at(&mut m, 0.3), v.trunc() as i32, "B1: whole pps");
    assert_eq!(speed_at(&mut m, 5.0), 100_000);
    assert_eq!(send(&mut m, "GAP 8, 0"), 0);
    m.advance_to(((total - 0.001) * 1e9) as u64);
    assert_ne!(send(&mut m, "GAP 1, 0"), 1_000_000, "not before {total} s");
    m.advance_to(((total + 0.001) * 1e9) as u64);
    assert_eq!((send(&mut m, "GAP 1, 0"), send(&mut m, "GAP 3, 0"), send(&mut m, "GAP 8, 0")), (1_000_000, 0, 1));
    // Unit mode 0: the registers (24.8, 22.2); bows pps³ either way.
    send(&mut m, "SAP 255, 0, 0");
    assert_eq!(send(&mut m, "GAP 3, 0"), 0);
    send(&mut m, "SAP 2, 0, 0");
    send(&mut m, &format!("ROR 0, {}", 20_000 * 256));
    let t = until(&mut m, 10_000, |m| send(m, "GAP 3, 0") == 20_000 * 256).expect("reaches the speed");
    let expect = duration(&s_curve(Set { amax: 10_000.0, ..S }, 0.0, 20_000.0, 0.0));
    assert!((f64::from(t as u32) / 1000.0 - expect).abs() <= 0.0011, "AMAX 40 000 as 22.2 is 10 000 pps²: {t} ms vs {expect} s");
    assert_eq!(m.axis(0).params[138], 0, "AP 138 is a row of its own");
}

#[test]
fn switches_rows_soft_stop_and_shaft() {
    let mut m = module_with_switch();
    for (n, v) in [(4, 200_000), (5, 400_000), (17, 400_000), (21, 100_000)] {
        send(&mut m, &format!("SAP {n}, 0, {v}"));
    }
    send(&mut m, "ROR 0, 200000");
    until(&mut m, 20_000, |m| send(m, "GAP 3, 0") == 0).expect("stops at the right switch");
    assert_eq!(send(&mut m, "GAP 10, 0"), 1);
    let hard = send(&mut m, "GAP 1, 0");
    // Bit 0 off: the switch does not stop the motor; bit 1 inverts it.
    send(&mut m, "SAP 12, 0, 2");
    assert_eq!(send(&mut m, "GAP 10, 0"), 0, "polarity inverted");
    send(&mut m, "SAP 12, 0, 3");
    assert_eq!(send(&mut m, "GAP 10, 0"), 0);
    send(&mut m, "SAP 12, 0, 0");
    send(&mut m, "ROR 0, 200000");
    m.advance(200 * MS);
    assert!(send(&mut m, "GAP 1, 0") > hard, "passes the disabled switch");
    // Soft stop with DSTOP: from 200 000 pps, 2 s of 100 000 pps².
    let mut m = module_with_switch();
    for (n, v) in [(4, 200_000), (5, 400_000), (34, 1), (21, 100_000)] {
        send(&mut m, &format!("SAP {n}, 0, {v}"));
    }
    send(&mut m, "ROR 0, 200000");
    until(&mut m, 20_000, |m| send(m, "GAP 10, 0") == 1).expect("reaches the right switch");
    m.advance(1000 * MS);
    let v = send(&mut m, "GAP 3, 0");
    assert!((99_000..=101_000).contains(&v), "DSTOP: {v}");
    // The swap: the right switch now reads as the left one.
    send(&mut m, "SAP 33, 0, 1");
    assert_eq!((send(&mut m, "GAP 10, 0"), send(&mut m, "GAP 11, 0")), (0, 1));
    assert_eq!(status(&mut m, "SAP 14, 0, 2"), 4, "ramp type 0 or 1");
}

/// PyTrinamic's S-shaped ramp demo (TMCM-1316, 1321, 1370, 1378): VSTART
/// 5000 with AMAX 51 200 and bows of 500 pps³, far too gentle to bring
/// AMAX back to 0 by VMAX: the start takes less acceleration, and the
/// moves there and back end on their targets.
#[test]
fn the_demo_s_gentle_bows_still_arrive() {
    let mut m = module();
    for (n, v) in [(14, 1), (4, 51_200), (5, 51_200), (17, 20_000), (15, 5_000), (16, 5_000), (18, 7_000), (19, 8_000)] {
        send(&mut m, &format!("SAP {n}, 0, {v}"));
    }
    for n in 22..=25 {
        send(&mut m, &format!("SAP {n}, 0, 500"));
    }
    for target in [100_000, 0] {
        send(&mut m, &format!("MVP ABS, 0, {target}"));
        let mut top = 0;
        until(&mut m, 120_000, |m| {
            top = top.max(send(m, "GAP 3, 0").abs());
            send(m, "GAP 8, 0") == 1
        })
        .expect("arrives");
        assert_eq!(send(&mut m, "GAP 1, 0"), target);
        assert!(top <= 51_200, "no faster than VMAX: {top}");
    }
}

/// Every built-in TMC4361A module moves on every axis with both ramp
/// types, to the target microstep, and stops on MST (none yet: vacuous).
#[test]
fn every_tmc4361a_module_moves_with_both_ramps() {
    use tmclsim_firmware::Profile;
    for name in Profile::names() {
        let p = Profile::built_in(name).unwrap();
        if p.features.motion_controller != tmclsim_firmware::profile::MotionController::Tmc4361a {
            continue;
        }
        let mut m = BusOfOne::built_in(name);
        for motor in 0..p.module.axes {
            for (n, v) in [(4, 51_200), (5, 51_200), (17, 51_200), (22, 100_000), (23, 100_000), (24, 100_000), (25, 100_000)] {
                send(&mut m, &format!("SAP {n}, {motor}, {v}"));
            }
            for (ramp_type, target) in [(1, 100_000), (0, -20_000)] {
                send(&mut m, &format!("SAP 14, {motor}, {ramp_type}"));
                send(&mut m, &format!("MVP ABS, {motor}, {target}"));
                until(&mut m, 20_000, |m| send(m, &format!("GAP 8, {motor}")) == 1)
                    .unwrap_or_else(|| panic!("{name} motor {motor}: arrives"));
                assert_eq!(send(&mut m, &format!("GAP 1, {motor}")), target, "{name} motor {motor}");
            }
            send(&mut m, &format!("ROR {motor}, 30000"));
            m.advance(2_000 * MS);
            assert_eq!(send(&mut m, &format!("GAP 3, {motor}")), 30_000, "{name} motor {motor}");
            send(&mut m, &format!("MST {motor}"));
            until(&mut m, 10_000, |m| send(m, &format!("GAP 3, {motor}")) == 0).unwrap_or_else(|| panic!("{name} motor {motor}: stops"));
        }
    }
}

/// The reference search runs on the S-shaped ramp as on the others: to
/// the left switch and back to it, the counter 0 there.
#[test]
fn a_reference_search_on_the_s_shaped_ramp() {
    let mut m = module();
    m.world_mut().axes[0].left_switch = Some(-50_000.0);
    for (n, v) in [
        (14, 1),
        (4, 100_000),
        (5, 40_000),
        (17, 50_000),
        (22, 100_000),
        (23, 200_000),
        (24, 125_000),
        (25, 250_000),
        (193, 1),
        (194, 50_000),
        (195, 5_000),
    ] {
        send(&mut m, &format!("SAP {n}, 0, {v}"));
    }
    send(&mut m, "RFS START, 0");
    until(&mut m, 60_000, |m| send(m, "RFS STATUS, 0") == 0).expect("the search ends");
    assert_eq!(send(&mut m, "GAP 1, 0"), 0);
    assert_eq!(send(&mut m, "GAP 3, 0"), 0);
    assert_eq!(send(&mut m, "GAP 11, 0"), 1, "on the left switch");
}
