//! Motion of the virtual TMCM-1141 against the TMC429 closed forms
//! (docs/behaviour.md rules 23–25): durations, exact final positions, velocity
//! ramps, limit switches.

use crate::common;

use common::{BusOfOne, send};

use tmclsim_firmware::motion::{self, Motion, Ramp};

/// Polls AP 8 every `poll` ms and returns the virtual time of arrival.
fn time_to_reach(m: &mut BusOfOne, poll_ms: u64, limit_s: u64) -> f64 {
    let start = m.now_ns();
    while send(m, "GAP 8, 0") == 0 {
        m.advance(poll_ms * 1_000_000);
        assert!(m.now_ns() - start < limit_s * 1_000_000_000, "no arrival within {limit_s} s");
    }
    (m.now_ns() - start) as f64 * 1e-9
}

/// The closed-form duration from the axis parameters, per rules 23–24.
fn closed_form(vmax: u32, a: u32, vmin: u32, rd: u32, pd: u32, distance: f64) -> f64 {
    let ramp = Ramp {
        vmax: motion::velocity_pps(f64::from(vmax), pd),
        vmin: motion::velocity_pps(f64::from(vmin), pd),
        accel_position: motion::accel_pps2(motion::positioning_accel(a, rd, pd), rd, pd),
        accel_velocity: 0.0,
        target_velocity: 0.0,
        six: None,
    };
    Motion::closed_form_duration(distance, &ramp)
}

#[test]
fn mvp_durations_match_the_closed_form() {
    // (vmax, amax, vmin, ramp_div, pulse_div, distance)
    let cases = [
        (1000, 1000, 1, 7, 3, 51_200),   // trapezoid
        (2047, 100, 1, 7, 3, 512_000),   // long cruise
        (2047, 5, 1, 7, 3, 2_000),       // triangle
        (500, 2047, 20, 9, 4, -100_000), // higher stop speed, negative
        (1500, 1, 1, 9, 3, 30_000),      // AP 5 below the clamp: 2^(9-3-1)
        (300, 2047, 1, 3, 5, 10_000),    // AP 5 above the clamp
    ];
    for (vmax, a, vmin, rd, pd, dist) in cases {
        let mut m = BusOfOne::built_in("tmcm-1141");
        for line in [
            format!("SAP 4, 0, {vmax}"),
            format!("SAP 5, 0, {a}"),
            format!("SAP 130, 0, {vmin}"),
            format!("SAP 153, 0, {rd}"),
            format!("SAP 154, 0, {pd}"),
        ] {
            send(&mut m, &line);
        }
        send(&mut m, &format!("MVP ABS, 0, {dist}"));
        let t = time_to_reach(&mut m, 1, 3600);
        let expect = closed_form(vmax, a, vmin, rd, pd, f64::from(dist));
        let tolerance = (0.005 * expect).max(0.001) + 0.001; // + one poll period
        assert!((t - expect).abs() <= tolerance, "{vmax}/{a}/{vmin}/{rd}/{pd} {dist}: {t} s vs {expect} s");
        assert_eq!(send(&mut m, "GAP 1, 0"), dist, "exact final position");
        assert_eq!(send(&mut m, "GAP 3, 0"), 0);
    }
}

#[test]
fn relative_and_coordinate_moves() {
    let mut m = BusOfOne::built_in("tmcm-1141");
    send(&mut m, "SAP 4, 0, 2047");
    send(&mut m, "MVP REL, 0, -10000");
    m.advance(10_000_000_000);
    assert_eq!(send(&mut m, "GAP 1, 0"), -10000);
    send(&mut m, "MVP REL, 0, 2500");
    m.advance(10_000_000_000);
    assert_eq!(send(&mut m, "GAP 1, 0"), -7500);
    send(&mut m, "SCO 8, 0, 1234");
    send(&mut m, "MVP COORD, 0, 8");
    m.advance(10_000_000_000);
    assert_eq!(send(&mut m, "GAP 1, 0"), 1234);
    assert_eq!(send(&mut m, "GAP 0, 0"), 1234);
    assert_eq!(send(&mut m, "GAP 8, 0"), 1);
}

#[test]
fn position_reached_flag_and_speed_during_a_move() {
    let mut m = BusOfOne::built_in("tmcm-1141");
    send(&mut m, "MVP ABS, 0, 200000");
    m.advance(20_000_000);
    assert_eq!(send(&mut m, "GAP 8, 0"), 0);
    assert!(send(&mut m, "GAP 3, 0") > 0);
    assert!(send(&mut m, "GAP 135, 0") > 0, "accelerating");
    m.advance(60_000_000_000);
    assert_eq!(send(&mut m, "GAP 8, 0"), 1);
    assert_eq!(send(&mut m, "GAP 1, 0"), 200000);
}

#[test]
fn velocity_mode_ramps_with_ap5() {
    let mut m = BusOfOne::built_in("tmcm-1141");
    // a = 100 with rd 7, pd 3 → 46566 pps²; v = 1000 → 30518 pps.
    send(&mut m, "SAP 5, 0, 100");
    send(&mut m, "ROR 0, 1000");
    assert_eq!(send(&mut m, "GAP 138, 0"), 2);
    assert_eq!(send(&mut m, "GAP 2, 0"), 1000);
    let a = motion::accel_pps2(100.0, 7, 3);
    let v = motion::velocity_pps(1000.0, 3);
    let t_ramp = v / a;
    m.advance((t_ramp * 0.5 * 1e9) as u64);
    let half = send(&mut m, "GAP 3, 0");
    assert!((half - 500).abs() <= 1, "half way: {half}");
    m.advance((t_ramp * 0.6 * 1e9) as u64);
    assert_eq!(send(&mut m, "GAP 3, 0"), 1000);
    assert_eq!(send(&mut m, "GAP 135, 0"), 0);
    // ROL reverses, MST stops with the same ramp.
    send(&mut m, "ROL 0, 1000");
    assert_eq!(send(&mut m, "GAP 2, 0"), -1000);
    m.advance((t_ramp * 2.1 * 1e9) as u64);
    assert_eq!(send(&mut m, "GAP 3, 0"), -1000);
    send(&mut m, "MST 0");
    m.advance((t_ramp * 1.01 * 1e9) as u64);
    assert_eq!(send(&mut m, "GAP 3, 0"), 0);
}

#[test]
fn limit_switches_stop_the_motor() {
    let mut m = BusOfOne::built_in("tmcm-1141");
    m.world_mut().axes[0].right_switch = Some(50_000.0);
    m.world_mut().axes[0].left_switch = Some(-50_000.0);
    send(&mut m, "SAP 4, 0, 2047");
    send(&mut m, "MVP ABS, 0, 100000");
    m.advance(30_000_000_000);
    assert_eq!(send(&mut m, "GAP 1, 0"), 50_000, "hard stop at the switch");
    assert_eq!(send(&mut m, "GAP 10, 0"), 1);
    assert_eq!(send(&mut m, "GAP 11, 0"), 0);
    assert_eq!(send(&mut m, "GAP 8, 0"), 0, "target not reached");
    // The other direction is free.
    send(&mut m, "ROL 0, 500");
    m.advance(1_000_000_000);
    assert!(send(&mut m, "GAP 1, 0") < 50_000);
    assert_eq!(send(&mut m, "GAP 10, 0"), 0);
    // Left switch with soft stop (AP 149): decelerates past the switch.
    send(&mut m, "SAP 149, 0, 1");
    send(&mut m, "ROL 0, 2047");
    m.advance(60_000_000_000);
    let pos = send(&mut m, "GAP 1, 0");
    assert!(pos < -50_000, "soft stop overruns the switch: {pos}");
    assert_eq!(send(&mut m, "GAP 3, 0"), 0);
    assert_eq!(send(&mut m, "GAP 11, 0"), 1);
}

#[test]
fn disabled_switch_and_reversed_polarity() {
    let mut m = BusOfOne::built_in("tmcm-1141");
    m.world_mut().axes[0].right_switch = Some(10_000.0);
    send(&mut m, "SAP 12, 0, 1");
    send(&mut m, "MVP ABS, 0, 20000");
    m.advance(30_000_000_000);
    assert_eq!(send(&mut m, "GAP 1, 0"), 20_000, "disabled switch does not stop");
    assert_eq!(send(&mut m, "GAP 10, 0"), 1, "but its state is reported");
    // GP 79 reverses the polarity: an open switch reads as active.
    send(&mut m, "SGP 79, 0, 1");
    assert_eq!(send(&mut m, "GAP 10, 0"), 0);
    assert_eq!(send(&mut m, "GAP 11, 0"), 1);
    send(&mut m, "SAP 12, 0, 0");
    send(&mut m, "MVP ABS, 0, 0");
    m.advance(1_000_000_000);
    assert_eq!(send(&mut m, "GAP 1, 0"), 20_000, "the (inverted) left switch blocks negative moves");
}

#[test]
fn hand_driven_switch_levels() {
    let mut m = BusOfOne::built_in("tmcm-1141");
    send(&mut m, "ROR 0, 1000");
    m.advance(1_000_000_000);
    m.world_mut().axes[0].forced_right = Some(true);
    m.advance(1_000_000);
    assert_eq!(send(&mut m, "GAP 3, 0"), 0);
    let pos = send(&mut m, "GAP 1, 0");
    m.advance(1_000_000_000);
    assert_eq!(send(&mut m, "GAP 1, 0"), pos);
}

#[test]
fn soft_mode_arrives_exactly() {
    let mut m = BusOfOne::built_in("tmcm-1141");
    send(&mut m, "SAP 138, 0, 1");
    send(&mut m, "MVP ABS, 0, 80000");
    assert_eq!(send(&mut m, "GAP 138, 0"), 1);
    let t = time_to_reach(&mut m, 5, 600);
    assert_eq!(send(&mut m, "GAP 1, 0"), 80000);
    assert!(t > closed_form(1000, 1000, 1, 7, 3, 80000.0));
}

#[test]
fn thirty_two_bit_wrap_takes_the_short_way() {
    let mut m = BusOfOne::built_in("tmcm-1141");
    send(&mut m, "SAP 1, 0, 2147483000");
    send(&mut m, "MVP ABS, 0, -2147483000");
    m.advance(5_000_000_000);
    assert_eq!(send(&mut m, "GAP 1, 0"), -2147483000);
    assert!(m.axis(0).motion.x > 2147483000.0, "moved forward through the wrap");
}

#[test]
fn currents_follow_motion() {
    let mut m = BusOfOne::built_in("tmcm-1141");
    send(&mut m, "SAP 6, 0, 200");
    send(&mut m, "SAP 7, 0, 40");
    send(&mut m, "SAP 200, 0, 248");
    send(&mut m, "SAP 214, 0, 10"); // 100 ms
    send(&mut m, "ROR 0, 1000");
    m.advance(1_000_000);
    assert_eq!(send(&mut m, "GAP 180, 0"), 248 >> 3, "boost while accelerating");
    m.advance(2_000_000_000);
    assert_eq!(send(&mut m, "GAP 180, 0"), 200 >> 3, "run current at constant speed");
    send(&mut m, "MST 0");
    m.advance(2_000_000_000);
    assert_eq!(send(&mut m, "GAP 180, 0"), 40 >> 3, "standby after the power-down delay");
    send(&mut m, "SAP 204, 0, 1");
    m.advance(20_000_000);
    assert_eq!(send(&mut m, "GAP 180, 0"), 0, "freewheeling");
}

#[test]
fn an_hour_of_motion_in_one_advance() {
    let mut m = BusOfOne::built_in("tmcm-1141");
    send(&mut m, "ROR 0, 2047");
    m.advance(3_600_000_000_000);
    let v = motion::velocity_pps(2047.0, 3);
    let expected = v * 3600.0 - v * v / (2.0 * motion::accel_pps2(1000.0, 7, 3));
    let pos = m.axis(0).motion.x;
    assert!((pos - expected).abs() < 1.0, "{pos} vs {expected}");
}

/// The clock every built-in profile states is the one the ramp generator
/// runs at, so the IDE's unit conversion (profile data) and the simulated
/// motion agree.
#[test]
fn every_built_in_profile_states_the_clock_the_ramps_run_at() {
    for name in tmclsim_profile::Profile::names() {
        let p = tmclsim_profile::Profile::built_in(name).unwrap();
        assert_eq!(f64::from(p.features.motion_clock_hz), motion::FCLK, "{name}");
    }
}
