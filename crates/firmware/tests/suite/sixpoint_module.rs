//! A sixPoint module (the TMCM-1260, TMC5160) by the wire: the ramp in the
//! chip's register units, the unit mode, the ramp wait, the switches and
//! the shaft of the family's own rows, MST, and the driver's modes
//! (docs/behaviour.md rules 104–111).

use crate::common;

use common::{BusOfOne, MS, load, send, status, until};

const FCLK: f64 = 16_000_000.0;

/// The register value the module writes for a velocity in pps, and the
/// step rate it gives (rule 104).
fn velocity(pps: f64) -> f64 {
    (pps * 16_777_216.0 / FCLK).round() * FCLK / 16_777_216.0
}

/// The same for an acceleration in pps².
fn acceleration(pps2: f64) -> f64 {
    (pps2 * 2_199_023_255_552.0 / (FCLK * FCLK)).round().max(1.0) * FCLK * FCLK / 2_199_023_255_552.0
}

fn module() -> BusOfOne {
    let mut m = BusOfOne::built_in("tmcm-1260");
    send(&mut m, "SAP 6, 0, 255");
    m
}

/// PyTrinamic's six-point demo values for the TMCM-1276 and its siblings.
fn demo_ramp(m: &mut BusOfOne) {
    for (n, v) in [(4, 40_000), (5, 30_000), (15, 5_000), (16, 10_000), (17, 20_000), (18, 5_000), (19, 5_000), (20, 5_000), (21, 31_250)] {
        send(m, &format!("SAP {n}, 0, {v}"));
    }
}

#[test]
fn a_move_takes_the_six_points_in_the_chip_s_units() {
    let mut m = module();
    demo_ramp(&mut m);
    send(&mut m, "MVP ABS, 0, 100000");
    // The phases' ends in closed form, with the register values.
    let (vstart, v1, vmax, vstop) = (velocity(5000.0), velocity(10_000.0), velocity(40_000.0), velocity(5000.0));
    let (a1, amax, dmax, d1) = (acceleration(5000.0), acceleration(30_000.0), acceleration(20_000.0), acceleration(5000.0));
    let t1 = (v1 - vstart) / a1;
    let t2 = (vmax - v1) / amax;
    let s_up = (v1 * v1 - vstart * vstart) / (2.0 * a1) + (vmax * vmax - v1 * v1) / (2.0 * amax);
    let s_down = (vmax * vmax - v1 * v1) / (2.0 * dmax) + (v1 * v1 - vstop * vstop) / (2.0 * d1);
    let cruise = (100_000.0 - s_up - s_down) / vmax;
    let total = t1 + t2 + cruise + (vmax - v1) / dmax + (v1 - vstop) / d1;
    // Halfway through A1's phase, AMAX's, and the cruise: the speed there.
    let speed_at = |m: &mut BusOfOne, t: f64| {
        m.advance_to((t * 1e9).round() as u64);
        send(m, "GAP 3, 0")
    };
    let expect = vstart + a1 * t1 / 2.0;
    assert!((f64::from(speed_at(&mut m, t1 / 2.0)) - expect).abs() <= 1.0, "A1 from VSTART: {expect}");
    let expect = vstart + a1 * t1 + amax * t2 / 2.0;
    assert!((f64::from(speed_at(&mut m, t1 + t2 / 2.0)) - expect).abs() <= 1.0, "AMAX from V1: {expect}");
    assert_eq!(speed_at(&mut m, t1 + t2 + cruise / 2.0), 40_000, "VMAX reads back as set");
    assert_eq!(send(&mut m, "GAP 8, 0"), 0);
    // Arrival on the closed form's millisecond, on the target microstep.
    m.advance_to(((total - 0.001) * 1e9) as u64);
    assert_ne!(send(&mut m, "GAP 1, 0"), 100_000, "not before {total} s");
    m.advance_to(((total + 0.001) * 1e9) as u64);
    assert_eq!(send(&mut m, "GAP 1, 0"), 100_000);
    assert_eq!((send(&mut m, "GAP 3, 0"), send(&mut m, "GAP 8, 0")), (0, 1));
}

#[test]
fn the_ramp_wait_comes_before_the_way_back() {
    let mut m = module();
    demo_ramp(&mut m);
    send(&mut m, "MVP ABS, 0, 20000");
    until(&mut m, 10_000, |m| send(m, "GAP 8, 0") == 1).expect("arrives");
    send(&mut m, "MVP ABS, 0, 0");
    // 31250 × 512 clock cycles of 16 MHz: one second standing still.
    m.advance(990 * MS);
    assert_eq!((send(&mut m, "GAP 1, 0"), send(&mut m, "GAP 3, 0")), (20_000, 0));
    let waited = until(&mut m, 100, |m| send(m, "GAP 3, 0") != 0).expect("moves after the wait");
    assert!(waited <= 11, "{waited} ms late");
    assert!(send(&mut m, "GAP 3, 0") <= -5000, "starts at −VSTART");
    until(&mut m, 10_000, |m| send(m, "GAP 8, 0") == 1).expect("back");
    assert_eq!(send(&mut m, "GAP 1, 0"), 0);
}

#[test]
fn unit_mode_0_takes_the_chip_s_registers() {
    let mut m = module();
    assert_eq!(send(&mut m, "GAP 255, 0"), 1, "pps by default");
    send(&mut m, "SAP 255, 0, 0");
    send(&mut m, "SAP 5, 0, 1000");
    send(&mut m, "ROR 0, 41943");
    m.advance(1000 * MS);
    // 41943 units = 39999.6 pps: the register reads back as is.
    assert_eq!(send(&mut m, "GAP 3, 0"), 41_943);
    assert_eq!(send(&mut m, "GAP 29, 0"), 39_999, "the measured speed is pps whatever the unit mode");
    send(&mut m, "SAP 255, 0, 1");
    assert_eq!(send(&mut m, "GAP 3, 0"), 40_000);
}

#[test]
fn velocity_mode_and_mst_ramp_with_amax() {
    let mut m = module();
    demo_ramp(&mut m);
    send(&mut m, "ROR 0, 30000");
    let a = acceleration(30_000.0);
    m.advance(500 * MS);
    let expect = a * 0.5;
    assert!((f64::from(send(&mut m, "GAP 3, 0")) - expect).abs() <= 1.0, "AMAX from standstill, no VSTART: {expect}");
    m.advance(1000 * MS);
    assert_eq!(send(&mut m, "GAP 3, 0"), 30_000);
    // MST during a positioning move: AMAX, not DMAX and D1.
    send(&mut m, "MVP REL, 0, 1000000");
    until(&mut m, 10_000, |m| send(m, "GAP 3, 0") == 40_000).expect("cruises");
    send(&mut m, "MST 0");
    let stopped = until(&mut m, 10_000, |m| send(m, "GAP 3, 0") == 0).expect("stops") as f64 / 1000.0;
    assert!((stopped - velocity(40_000.0) / a).abs() <= 0.002, "{stopped} s");
}

#[test]
fn switches_have_their_own_polarity_swap_and_soft_stop() {
    let mut m = module();
    m.world_mut().axes[0].forced_right = Some(true);
    assert_eq!((send(&mut m, "GAP 10, 0"), send(&mut m, "GAP 11, 0")), (1, 0));
    send(&mut m, "SAP 14, 0, 1");
    assert_eq!((send(&mut m, "GAP 10, 0"), send(&mut m, "GAP 11, 0")), (0, 1), "swapped");
    send(&mut m, "SAP 25, 0, 1");
    assert_eq!((send(&mut m, "GAP 10, 0"), send(&mut m, "GAP 11, 0")), (0, 0), "the left switch inverted alone");
    send(&mut m, "SAP 24, 0, 1");
    assert_eq!((send(&mut m, "GAP 10, 0"), send(&mut m, "GAP 11, 0")), (1, 0));
    // A stop switch ahead: hard by default, soft with AP 26.
    let stop_at_switch = |soft: i32| {
        let mut m = module();
        demo_ramp(&mut m);
        send(&mut m, &format!("SAP 26, 0, {soft}"));
        m.world_mut().axes[0].right_switch = Some(50_000.0);
        send(&mut m, "ROR 0, 40000");
        until(&mut m, 10_000, |m| send(m, "GAP 10, 0") == 1).expect("reaches the switch");
        let at = send(&mut m, "GAP 1, 0");
        until(&mut m, 10_000, |m| send(m, "GAP 3, 0") == 0).expect("stops");
        send(&mut m, "GAP 1, 0") - at
    };
    assert!(stop_at_switch(0) <= 40, "a hard stop at the switch");
    let brake = (velocity(40_000.0).powi(2) - velocity(10_000.0).powi(2)) / (2.0 * acceleration(20_000.0))
        + (velocity(10_000.0).powi(2) - velocity(5000.0).powi(2)) / (2.0 * acceleration(5000.0));
    let soft = f64::from(stop_at_switch(1));
    assert!((soft - brake).abs() <= 60.0, "soft: DMAX and D1 down to VSTOP ({soft} vs {brake})");
}

#[test]
fn reverse_shaft_turns_the_motor_the_other_way() {
    let mut m = module();
    let start = m.mechanical_position(0);
    send(&mut m, "SAP 251, 0, 1");
    assert_eq!(m.mechanical_position(0), start, "the carriage stays");
    send(&mut m, "MVP ABS, 0, 5000");
    until(&mut m, 10_000, |m| send(m, "GAP 8, 0") == 1).expect("arrives");
    assert_eq!(send(&mut m, "GAP 1, 0"), 5000);
    assert_eq!(m.mechanical_position(0), start - 5000.0);
}

/// Runs at `speed` pps under a load the motor cannot carry at 20 % of
/// its current, with stop on stall above 1000 pps: the speed afterwards.
fn under_overload(setup: &[&str], speed: i32) -> (i32, i32) {
    let mut m = module();
    send(&mut m, "SAP 5, 0, 200000");
    send(&mut m, "SAP 181, 0, 1000");
    for line in setup {
        send(&mut m, line);
    }
    send(&mut m, &format!("ROR 0, {speed}"));
    m.advance(500 * MS);
    load(&mut m, 150.0);
    m.advance(100 * MS);
    (send(&mut m, "GAP 3, 0"), send(&mut m, "GAP 207, 0"))
}

#[test]
fn stallguard2_stops_in_spreadcycle_only() {
    assert_eq!(under_overload(&[], 20_000), (0, 1), "spreadCycle: a stall stops the motor");
    assert_eq!(under_overload(&["SAP 187, 0, 10", "SAP 186, 0, 30000"], 20_000), (20_000, 0), "stealthChop: no stall detection");
    assert_eq!(under_overload(&["SAP 187, 0, 10", "SAP 186, 0, 10000"], 20_000), (0, 1), "above AP 186: spreadCycle again");
    assert_eq!(under_overload(&["SAP 22, 0, 15000"], 20_000), (20_000, 0), "high-speed mode: no stall detection");
}

#[test]
fn dcstep_loses_no_steps() {
    // Overloaded in spreadCycle below the stall stop: steps are lost.
    let mut m = module();
    send(&mut m, "SAP 5, 0, 200000");
    send(&mut m, "ROR 0, 20000");
    m.advance(500 * MS);
    load(&mut m, 150.0);
    let (counter, carriage) = (send(&mut m, "GAP 1, 0"), m.mechanical_position(0));
    m.advance(100 * MS);
    assert!(send(&mut m, "GAP 1, 0") - counter > 1000);
    assert_eq!(m.mechanical_position(0), carriage, "the carriage does not follow");
    // In dcStep the counter stays with the carriage.
    let mut m = module();
    send(&mut m, "SAP 5, 0, 200000");
    send(&mut m, "SAP 23, 0, 10000");
    send(&mut m, "ROR 0, 20000");
    m.advance(500 * MS);
    load(&mut m, 150.0);
    let (counter, carriage) = (send(&mut m, "GAP 1, 0"), m.mechanical_position(0));
    m.advance(100 * MS);
    assert_eq!(f64::from(send(&mut m, "GAP 1, 0") - counter), m.mechanical_position(0) - carriage);
}

#[test]
fn dcstep_s_stall_detection_stops_the_motor() {
    let (speed, flags) = under_overload(&["SAP 23, 0, 10000"], 20_000);
    assert_eq!((speed, flags), (20_000, 0), "dcStep without AP 33: no stall");
    let (speed, flags) = under_overload(&["SAP 23, 0, 10000", "SAP 33, 0, 100"], 20_000);
    assert_eq!((speed, flags), (0, 1), "AP 33 on: a motor that cannot move is a stall");
}

#[test]
fn the_current_ramps_down_to_standby_after_the_delay() {
    let mut m = module();
    let p = m.profile().clone();
    let ms_per_unit = p.axis_parameter(214).and_then(tmclsim_profile::Parameter::ms_per_unit).unwrap_or(10);
    send(&mut m, "SAP 6, 0, 248");
    send(&mut m, "SAP 7, 0, 80");
    send(&mut m, "SAP 214, 0, 10");
    send(&mut m, "SAP 31, 0, 5");
    send(&mut m, "MVP REL, 0, 1000");
    until(&mut m, 10_000, |m| send(m, "GAP 8, 0") == 1).expect("arrives");
    assert_eq!(send(&mut m, "GAP 180, 0"), 31, "the run current while the delay lasts");
    // 5 × 2^18 cycles of 16 MHz: 81.92 ms a step after the delay.
    let delay = 10 * ms_per_unit;
    let step = 5.0 * 262_144.0 / 16_000.0;
    m.advance((delay + 70) * MS);
    let first = send(&mut m, "GAP 180, 0");
    assert!(first == 31 || first == 30, "ramping down: {first}");
    m.advance((step * 30.0) as u64 * MS);
    assert_eq!(send(&mut m, "GAP 180, 0"), 10, "then the standby current (80 / 8)");
}

#[test]
fn the_global_scaler_scales_the_torque() {
    let mut m = module();
    send(&mut m, "ROR 0, 2000");
    m.advance(200 * MS);
    load(&mut m, 40.0);
    m.advance(10 * MS);
    let full = send(&mut m, "GAP 206, 0");
    send(&mut m, "SAP 178, 0, 128");
    m.advance(10 * MS);
    let half = send(&mut m, "GAP 206, 0");
    assert!(half < full, "half the current, less margin: {half} < {full}");
}

#[test]
fn values_outside_a_row_s_range_answer_status_4() {
    let mut m = module();
    assert_eq!(status(&mut m, "SAP 18, 0, 0"), 4, "D1 = 0 is refused (the datasheet: never 0)");
    assert_eq!(status(&mut m, "SAP 255, 0, 2"), 4);
    assert_eq!(status(&mut m, "SAP 130, 0, 1"), 3, "no TMC429 stop speed here");
    assert_eq!(status(&mut m, "SAP 153, 0, 1"), 3, "no ramp divisor");
}

#[test]
fn on_the_tmcm_1276_ap_12_enables_the_automatic_stop() {
    let run_into_the_switch = |enable: i32| {
        let mut m = BusOfOne::built_in("tmcm-1276");
        assert_eq!(send(&mut m, "GAP 12, 0"), 1, "the automatic stop is on after power-up");
        send(&mut m, &format!("SAP 12, 0, {enable}"));
        m.world_mut().axes[0].right_switch = Some(20_000.0);
        send(&mut m, "ROR 0, 20000");
        m.advance(3000 * MS);
        send(&mut m, "GAP 3, 0")
    };
    assert_eq!(run_into_the_switch(1), 0, "1: the switch stops the motor");
    assert_eq!(run_into_the_switch(0), 20_000, "0: it does not");
    // The TMCM-1260's rows disable instead.
    let mut m = module();
    send(&mut m, "SAP 12, 0, 1");
    m.world_mut().axes[0].right_switch = Some(20_000.0);
    send(&mut m, "ROR 0, 20000");
    m.advance(3000 * MS);
    assert_eq!(send(&mut m, "GAP 3, 0"), 20_000, "disabled");
}

#[test]
fn ap_204_is_no_freewheeling_delay_here() {
    let mut m = module();
    send(&mut m, "SAP 7, 0, 80");
    send(&mut m, "SAP 204, 0, 1");
    send(&mut m, "SAP 31, 0, 0");
    m.advance(10_000 * MS);
    assert_eq!(send(&mut m, "GAP 180, 0"), 10, "the standby current, not switched off");
}

#[test]
fn the_encoder_counts_microsteps_with_its_resolution() {
    // The TMCM-6214: AP 210 is the encoder's resolution, AP 202 the
    // motor's full steps; the world's encoder has 2000 counts a turn.
    let mut m = BusOfOne::built_in("tmcm-6214");
    send(&mut m, "MVP ABS, 0, 51200");
    until(&mut m, 20_000, |m| send(m, "GAP 8, 0") == 1).expect("arrives");
    assert_eq!(send(&mut m, "GAP 209, 0"), 2000, "resolution 0: the counts themselves (one turn)");
    send(&mut m, "SAP 210, 0, 2000");
    assert_eq!(send(&mut m, "GAP 209, 0"), 51_200, "2000 counts a turn: microsteps, as AP 1");
    send(&mut m, "SAP 209, 0, 0");
    send(&mut m, "MVP REL, 0, -25600");
    until(&mut m, 20_000, |m| send(m, "GAP 8, 0") == 1).expect("arrives");
    assert_eq!(send(&mut m, "GAP 209, 0"), -25_600, "set, then counted on");
    // The TMCM-1260's AP 210 is no resolution: the counts as they are.
    let mut m = module();
    send(&mut m, "MVP ABS, 0, 51200");
    until(&mut m, 20_000, |m| send(m, "GAP 8, 0") == 1).expect("arrives");
    assert_eq!(send(&mut m, "GAP 209, 0"), 2000);
}

#[test]
fn an_encoder_deviation_stops_the_motor() {
    let mut m = BusOfOne::built_in("tmcm-6214");
    send(&mut m, "SAP 210, 0, 2000");
    send(&mut m, "SAP 212, 0, 1000");
    send(&mut m, "SAP 6, 0, 255");
    send(&mut m, "ROR 0, 20000");
    m.advance(500 * MS);
    // The carriage is held: the encoder stands, the counter goes on.
    load(&mut m, 150.0);
    let stopped = until(&mut m, 1000, |m| send(m, "GAP 3, 0") == 0);
    assert!(stopped.is_some(), "stopped on the deviation");
    assert_eq!(send(&mut m, "GAP 207, 0") & 2, 2, "the deviation bit");
}
