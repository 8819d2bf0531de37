//! The sixPoint ramp (docs/behaviour.md rules 104–107) and the
//! eight-point ramp (rule 113) against their closed form: for each
//! parameter set the phases of a move from rest are worked out here on
//! their own (the speeds a phase ends at listed, the peak of a short move
//! found by bisection), and the motion sampled every millisecond of
//! stepped time must lie on them.
use tmclsim_firmware::motion::{Motion, Ramp, RampMode, SixPoint, Step, Stops, Units};

/// Ramp values as a module's axis parameters give them (pps, pps²,
/// TZEROWAIT in clock cycles / 512).
#[derive(Clone, Copy, Debug)]
struct Set {
    vstart: f64,
    a1: f64,
    v1: f64,
    amax: f64,
    vmax: f64,
    dmax: f64,
    d1: f64,
    vstop: f64,
    wait: f64,
    /// The eight-point ramp's second knee (0: the sixPoint ramp).
    a2: f64,
    v2: f64,
    d2: f64,
}

const FCLK: f64 = 16_000_000.0;

/// The demo's values (PyTrinamic's six-point ramp demos).
const DEMO: Set = Set {
    vstart: 5000.0,
    a1: 5000.0,
    v1: 10_000.0,
    amax: 30_000.0,
    vmax: 40_000.0,
    dmax: 20_000.0,
    d1: 5000.0,
    vstop: 5000.0,
    wait: 31_250.0,
    a2: 0.0,
    v2: 0.0,
    d2: 0.0,
};

/// PyTrinamic's eight-point demo's values (TMCM-1290, TMCM-3216), as its
/// names mean them: A2 15 000 up to V2 20 000, D2 10 000 down from it.
const EIGHT: Set = Set { a2: 15_000.0, v2: 20_000.0, d2: 10_000.0, ..DEMO };

fn ramp(s: Set) -> Ramp {
    Ramp {
        vmax: s.vmax,
        vmin: 0.0,
        accel_position: s.amax,
        accel_velocity: s.amax,
        target_velocity: 0.0,
        six: Some(SixPoint {
            vstart: s.vstart,
            a1: s.a1,
            v1: s.v1,
            dmax: s.dmax,
            d1: s.d1,
            a2: s.a2,
            v2: s.v2,
            d2: s.d2,
            vstop: s.vstop,
            zero_wait: s.wait * 512.0 / FCLK,
        }),
    }
}

/// The phases of a move of `d` from rest as (acceleration, duration,
/// speed at its start), worked out from the definitions alone.
fn closed_form(s: Set, d: f64) -> Vec<(f64, f64, f64)> {
    // The knees, ascending: A1/D1 below V1, A2/D2 from V1 to V2, AMAX/DMAX
    // above; a knee of 0 (or V2 not above V1) has no band.
    // V1 = 0 switches both knees off (rule 113).
    let mut knees = Vec::new();
    if s.v1 > 0.0 {
        knees.push(s.v1);
        if s.v2 > s.v1 {
            knees.push(s.v2);
        }
    }
    let band = |w: f64, rising: bool| {
        // Rising through w: the band w lies in (w < knee); falling: the
        // band below w (w <= knee).
        let below = |k: f64| if rising { w < k } else { w <= k };
        if s.v1 > 0.0 && below(s.v1) {
            (s.a1, s.d1)
        } else if s.v1 > 0.0 && s.v2 > s.v1 && below(s.v2) {
            (s.a2, s.d2)
        } else {
            (s.amax, s.dmax)
        }
    };
    let up = |w: f64| band(w, true).0;
    let down = |w: f64| band(w, false).1;
    // The speeds a phase ends at between `from` and `to`.
    let edges = |from: f64, to: f64| {
        let (lo, hi) = if from < to { (from, to) } else { (to, from) };
        let mut e: Vec<f64> = knees.iter().copied().filter(|&k| k > lo && k < hi).collect();
        e.push(to);
        if from > to {
            e.sort_by(|a, b| b.total_cmp(a));
        }
        e
    };
    // Distance to speed up from VSTART to w, and to slow from w to VSTOP.
    let rise = |w: f64| {
        let mut v = s.vstart;
        let mut x = 0.0;
        for e in edges(s.vstart, w.max(s.vstart)) {
            x += (e * e - v * v) / (2.0 * up(v));
            v = e;
        }
        x
    };
    let fall = |w: f64| {
        if w <= s.vstop {
            return 0.0;
        }
        let mut v = w;
        let mut x = 0.0;
        for e in edges(w, s.vstop) {
            x += (v * v - e * e) / (2.0 * down(v));
            v = e;
        }
        x
    };
    let mut peak = s.vmax;
    if rise(s.vmax) + fall(s.vmax) > d {
        let (mut lo, mut hi) = (s.vstart, s.vmax);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if rise(mid) + fall(mid) > d { hi = mid } else { lo = mid }
        }
        peak = lo;
    }
    let mut phases = Vec::new();
    let mut w = s.vstart;
    if peak > w {
        for e in edges(w, peak) {
            phases.push((up(w), (e - w) / up(w), w));
            w = e;
        }
    }
    let cruise = d - rise(peak) - fall(peak);
    if cruise > 1e-9 {
        phases.push((0.0, cruise / peak, peak));
    }
    if w > s.vstop {
        for e in edges(w, s.vstop) {
            phases.push((-down(w), (w - e) / down(w), w));
            w = e;
        }
    }
    phases
}

/// Position and speed of the closed form `t` seconds after the start.
fn at(phases: &[(f64, f64, f64)], mut t: f64) -> (f64, f64) {
    let mut x = 0.0;
    for &(a, dt, v0) in phases {
        let tt = t.min(dt);
        x += v0 * tt + 0.5 * a * tt * tt;
        if t <= dt {
            return (x, v0 + a * tt);
        }
        t -= dt;
    }
    (x, 0.0)
}

fn step(m: &mut Motion, r: &Ramp, dt: f64) -> Step {
    m.advance(dt, r, &mut |_| Stops::default(), &[], false)
}

/// Runs a move of `d` in 1 ms steps against the closed form.
fn check(name: &str, s: Set, d: f64) {
    let r = ramp(s);
    let phases = closed_form(s, d);
    let total: f64 = phases.iter().map(|p| p.1).sum();
    let mut m = Motion { target: d, ..Motion::default() };
    let dt = 0.001;
    let mut t = 0.0;
    loop {
        let st = step(&mut m, &r, dt);
        t += dt;
        if st.arrived {
            break;
        }
        let (x, v) = at(&phases, t);
        assert!((m.x - x).abs() < 1e-3, "{name}: at {t:.3} s the motor is at {}, the closed form at {x}", m.x);
        assert!((m.v - v).abs() < 1e-3, "{name}: at {t:.3} s the speed is {}, the closed form's {v}", m.v);
        assert!(t < total + 1.0, "{name}: no arrival after {t} s (closed form: {total} s)");
    }
    assert_eq!(m.x, d, "{name}: on the target microstep");
    assert_eq!(m.v, 0.0, "{name}");
    assert!((t - total).abs() <= dt + 1e-9, "{name}: arrived after {t} s, the closed form after {total} s");
    // The phases in one call: the same end.
    let mut once = Motion { target: d, ..Motion::default() };
    assert!(step(&mut once, &r, total + 1.0).arrived, "{name}");
    assert_eq!(once.x, d, "{name}");
    assert!(m.zero_wait > 0.0 || s.wait == 0.0, "{name}: the ramp wait follows the stop");
}

#[test]
fn the_demo_s_move_has_six_points() {
    let phases = closed_form(DEMO, 100_000.0);
    let shape: Vec<(f64, f64)> = phases.iter().map(|p| (p.0, p.2)).collect();
    assert_eq!(
        shape,
        [(5000.0, 5000.0), (30_000.0, 10_000.0), (0.0, 40_000.0), (-20_000.0, 40_000.0), (-5000.0, 10_000.0)],
        "A1 from VSTART, AMAX from V1, cruise at VMAX, DMAX down to V1, D1 down to VSTOP"
    );
    check("demo", DEMO, 100_000.0);
}

#[test]
fn a_table_of_moves_against_the_closed_form() {
    let table = [
        ("demo backwards distance", DEMO, 100_000.0),
        ("V1 = 0: AMAX and DMAX only", Set { v1: 0.0, ..DEMO }, 100_000.0),
        ("VSTART = VMAX: no acceleration", Set { vstart: 40_000.0, vstop: 40_000.0, ..DEMO }, 100_000.0),
        ("too short for VMAX (peak above V1)", DEMO, 20_000.0),
        ("too short for V1 (peak below V1)", DEMO, 6_000.0),
        ("VSTOP 1, VSTART 0", Set { vstart: 0.0, vstop: 1.0, ..DEMO }, 51_200.0),
        ("V1 above VMAX: A1 and D1 only", Set { v1: 50_000.0, ..DEMO }, 200_000.0),
        ("V1 below VSTOP: DMAX down to VSTOP", Set { v1: 2_000.0, ..DEMO }, 100_000.0),
        (
            "slow and long",
            Set { vmax: 1_000.0, amax: 200.0, a1: 100.0, v1: 500.0, dmax: 300.0, d1: 150.0, vstart: 10.0, vstop: 20.0, wait: 0.0, ..DEMO },
            1_000_000.0,
        ),
    ];
    for (name, s, d) in table {
        check(name, s, d);
    }
}

#[test]
fn the_eight_point_move_has_its_eight_points() {
    let phases = closed_form(EIGHT, 100_000.0);
    let shape: Vec<(f64, f64)> = phases.iter().map(|p| (p.0, p.2)).collect();
    assert_eq!(
        shape,
        [
            (5000.0, 5000.0),
            (15_000.0, 10_000.0),
            (30_000.0, 20_000.0),
            (0.0, 40_000.0),
            (-20_000.0, 40_000.0),
            (-10_000.0, 20_000.0),
            (-5000.0, 10_000.0)
        ],
        "A1 from VSTART, A2 from V1, AMAX from V2, cruise, DMAX down to V2, D2 down to V1, D1 down to VSTOP"
    );
    let table = [
        ("the demo's eight points", EIGHT, 100_000.0),
        ("too short for VMAX (peak above V2)", EIGHT, 30_000.0),
        ("too short for V2 (peak between V1 and V2)", EIGHT, 9_000.0),
        ("too short for V1", EIGHT, 5_500.0),
        ("V1 = 0: AMAX and DMAX only", Set { v1: 0.0, ..EIGHT }, 100_000.0),
        ("V2 = 0: the sixPoint ramp", Set { v2: 0.0, ..EIGHT }, 100_000.0),
        ("V2 not above V1: no A2/D2 band", Set { v2: 8000.0, ..EIGHT }, 100_000.0),
        ("V2 above VMAX: A2 up to VMAX", Set { v2: 60_000.0, ..EIGHT }, 100_000.0),
    ];
    for (name, s, d) in table {
        check(name, s, d);
    }
    // V1 = 0 is AMAX and DMAX only, whatever V2 says.
    let only = closed_form(Set { v1: 0.0, ..EIGHT }, 100_000.0);
    assert!(only.iter().all(|p| p.0 == 0.0 || p.0.abs() == 30_000.0 || p.0.abs() == 20_000.0), "{only:?}");
    // V2 = 0 is exactly the sixPoint ramp.
    let mut six = Motion { target: 77_777.0, ..Motion::default() };
    let mut eight = six.clone();
    for _ in 0..10_000 {
        step(&mut six, &ramp(DEMO), 0.001);
        step(&mut eight, &ramp(Set { v2: 0.0, ..EIGHT }), 0.001);
        assert_eq!((six.x, six.v), (eight.x, eight.v));
    }
}

#[test]
fn the_eight_point_soft_stop_brakes_with_dmax_d2_and_d1() {
    let mut r = ramp(EIGHT);
    r.target_velocity = 40_000.0;
    let mut m = Motion { mode: RampMode::Velocity, ..Motion::default() };
    let blocked = Stops { block_positive: true, block_negative: false, soft: true };
    step(&mut m, &r, 2.0);
    assert_eq!(m.v, 40_000.0);
    m.advance(1.0, &r, &mut |_| blocked, &[], false);
    assert!((m.v - 20_000.0).abs() < 1e-6, "DMAX down to V2: {}", m.v);
    m.advance(0.5, &r, &mut |_| blocked, &[], false);
    assert!((m.v - 15_000.0).abs() < 1e-6, "then D2: {}", m.v);
    m.advance(0.5, &r, &mut |_| blocked, &[], false);
    assert!((m.v - 10_000.0).abs() < 1e-6, "D2 down to V1: {}", m.v);
    m.advance(1.0, &r, &mut |_| blocked, &[], false);
    assert!((m.v - 5_000.0).abs() < 1e-6, "D1 down to VSTOP: {}", m.v);
}

#[test]
fn a_negative_move_mirrors_a_positive_one() {
    let r = ramp(DEMO);
    let mut a = Motion { target: 30_000.0, ..Motion::default() };
    let mut b = Motion { target: -30_000.0, ..Motion::default() };
    for _ in 0..3000 {
        step(&mut a, &r, 0.001);
        step(&mut b, &r, 0.001);
        assert_eq!(a.x, -b.x);
        assert_eq!(a.v, -b.v);
    }
    assert_eq!((a.x, b.x), (30_000.0, -30_000.0));
}

#[test]
fn the_ramp_wait_holds_the_motor_before_it_moves_again() {
    let r = ramp(DEMO);
    let wait = DEMO.wait * 512.0 / FCLK;
    assert_eq!(wait, 1.0, "31250 × 512 cycles of 16 MHz");
    let mut m = Motion { target: 10_000.0, ..Motion::default() };
    assert!(step(&mut m, &r, 10.0).arrived);
    m.target = 0.0;
    step(&mut m, &r, wait - 0.01);
    assert_eq!((m.x, m.v), (10_000.0, 0.0), "still waiting");
    step(&mut m, &r, 0.02);
    assert!(m.v < 0.0 && m.x < 10_000.0, "moving back after the wait");
    assert!(m.v >= -DEMO.vstart - 0.02 * DEMO.a1 - 1e-6, "it starts at VSTART");
    // Time to rest counts the wait.
    let mut fresh = Motion { target: 10_000.0, ..Motion::default() };
    let plain = fresh.time_to_rest(&r, &mut |_| Stops::default()).unwrap();
    step(&mut fresh, &r, 100.0);
    fresh.target = 0.0;
    let back = fresh.time_to_rest(&r, &mut |_| Stops::default()).unwrap();
    assert!((back - plain - wait).abs() < 1e-9, "{back} = {plain} + {wait}");
}

#[test]
fn a_target_behind_the_motor_decelerates_waits_and_reverses() {
    let r = ramp(DEMO);
    let mut m = Motion { target: 100_000.0, ..Motion::default() };
    // At full speed, the target moves behind the motor.
    step(&mut m, &r, 2.5);
    assert_eq!(m.v, 40_000.0);
    let turn_from = m.x;
    m.target = 0.0;
    // DMAX down to V1, D1 down to VSTOP, a stop there.
    let mut t: f64 = 0.0;
    let mut peak_x = m.x;
    while m.v > 0.0 {
        step(&mut m, &r, 0.001);
        t += 0.001;
        peak_x = peak_x.max(m.x);
    }
    let down = (40_000.0 - 10_000.0) / 20_000.0 + (10_000.0 - 5000.0) / 5000.0;
    assert!((t - down).abs() <= 0.001 + 1e-9, "stopped after {t} s, DMAX and D1 take {down} s");
    let brake = (40_000.0f64.powi(2) - 10_000.0f64.powi(2)) / 40_000.0 + (10_000.0f64.powi(2) - 5000.0f64.powi(2)) / 10_000.0;
    assert!((peak_x - turn_from - brake).abs() < 1e-3, "braking distance {} vs {brake}", peak_x - turn_from);
    assert!(m.zero_wait > 0.0);
    step(&mut m, &r, 60.0);
    assert_eq!((m.x, m.v), (0.0, 0.0), "back on the new target");
}

#[test]
fn a_target_moved_closer_is_passed_and_approached_again() {
    let r = ramp(Set { wait: 0.0, ..DEMO });
    let mut m = Motion { target: 100_000.0, ..Motion::default() };
    step(&mut m, &r, 2.5);
    m.target = m.x + 100.0;
    let target = m.target;
    let mut beyond = 0.0f64;
    for _ in 0..20_000 {
        step(&mut m, &r, 0.001);
        beyond = beyond.max(m.x - target);
    }
    assert!(beyond > 10_000.0, "it passes the target ({beyond})");
    assert_eq!((m.x, m.v), (target, 0.0));
}

#[test]
fn vmax_lowered_while_moving_is_followed_with_amax_and_a1() {
    let mut r = ramp(DEMO);
    let mut m = Motion { target: 1_000_000.0, ..Motion::default() };
    step(&mut m, &r, 3.0);
    assert_eq!(m.v, 40_000.0);
    r.vmax = 20_000.0;
    step(&mut m, &r, 0.5);
    assert!((m.v - 25_000.0).abs() < 1e-6, "AMAX takes 15 000 pps off in 0.5 s: {}", m.v);
    step(&mut m, &r, 1.0);
    assert_eq!(m.v, 20_000.0);
    // Below V1, A1 brings it down.
    r.vmax = 8_000.0;
    step(&mut m, &r, 10_000.0 / 30_000.0);
    assert!((m.v - 10_000.0).abs() < 1e-6, "AMAX down to V1: {}", m.v);
    step(&mut m, &r, 0.2);
    assert!((m.v - 9_000.0).abs() < 1e-6, "then A1: {}", m.v);
    step(&mut m, &r, 1000.0);
    assert_eq!(m.x, 1_000_000.0);
}

#[test]
fn velocity_mode_uses_amax_both_ways_and_waits_before_reversing() {
    let mut r = ramp(DEMO);
    r.target_velocity = 30_000.0;
    let mut m = Motion { mode: RampMode::Velocity, ..Motion::default() };
    step(&mut m, &r, 0.5);
    assert!((m.v - 15_000.0).abs() < 1e-6, "AMAX from standstill, no VSTART: {}", m.v);
    step(&mut m, &r, 1.0);
    assert_eq!(m.v, 30_000.0);
    r.target_velocity = -30_000.0;
    step(&mut m, &r, 0.5);
    assert!((m.v - 15_000.0).abs() < 1e-6, "AMAX down: {}", m.v);
    step(&mut m, &r, 0.5);
    assert_eq!(m.v, 0.0);
    step(&mut m, &r, 0.9);
    assert_eq!(m.v, 0.0, "the ramp wait");
    step(&mut m, &r, 0.2);
    assert!(m.v < 0.0 && m.v > -30_000.0, "reversing after the wait: {}", m.v);
}

#[test]
fn soft_stop_at_a_switch_uses_the_deceleration_ramp() {
    let mut r = ramp(DEMO);
    r.target_velocity = 40_000.0;
    let mut m = Motion { mode: RampMode::Velocity, ..Motion::default() };
    let blocked = Stops { block_positive: true, block_negative: false, soft: true };
    step(&mut m, &r, 2.0);
    assert_eq!(m.v, 40_000.0);
    m.advance(1.0, &r, &mut |_| blocked, &[], false);
    assert!((m.v - 20_000.0).abs() < 1e-6, "DMAX: {}", m.v);
    m.advance(0.5, &r, &mut |_| blocked, &[], false);
    assert!((m.v - 10_000.0).abs() < 1e-6);
    m.advance(1.0, &r, &mut |_| blocked, &[], false);
    assert!((m.v - 5_000.0).abs() < 1e-6, "D1 down to VSTOP: {}", m.v);
    m.advance(0.001, &r, &mut |_| blocked, &[], false);
    assert_eq!(m.v, 0.0, "stopped at VSTOP");
    let hard = Stops { soft: false, ..blocked };
    let mut n = Motion { mode: RampMode::Velocity, ..Motion::default() };
    step(&mut n, &r, 2.0);
    n.advance(0.001, &r, &mut |_| hard, &[], false);
    assert_eq!(n.v, 0.0, "a hard stop at once");
}

#[test]
fn units_are_the_chip_s_registers() {
    let pps = Units::Sixpoint { fclk: 16_000_000, internal: false, accel_max: 65_535 };
    let internal = Units::Sixpoint { fclk: 16_000_000, internal: true, accel_max: 65_535 };
    let vu = 16e6 / 16_777_216.0;
    let au = 16e6 * 16e6 / 2_199_023_255_552.0;
    // 40000 pps: register 41943, which reads back as 40000.
    assert_eq!(pps.velocity_pps(40_000.0), 41_943.0 * vu);
    assert_eq!(pps.velocity_value(pps.velocity_pps(40_000.0)), 40_000.0);
    assert_eq!(pps.velocity_value(-pps.velocity_pps(40_000.0)), -40_000.0);
    for v in [1.0, 2.0, 999.0, 5000.0, 123_457.0, 3_000_000.0] {
        assert_eq!(pps.velocity_value(pps.velocity_pps(v)), v, "{v} pps reads back");
    }
    assert_eq!(internal.velocity_pps(41_943.0), 41_943.0 * vu);
    assert_eq!(internal.velocity_value(41_943.0 * vu), 41_943.0);
    // 30000 pps²: register 258 (116.4 pps² each).
    assert_eq!(pps.accel_pps2(30_000.0), 258.0 * au);
    assert_eq!(pps.accel_pps2(1.0), au, "at least one unit");
    assert_eq!(internal.accel_pps2(258.0), 258.0 * au);
    assert_eq!(pps.max_value(), i32::MAX);
}
