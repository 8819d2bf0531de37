//! The TMCM-1310: closed loop against open loop under load, torque mode,
//! the status word, the deviation interrupt, ABN and SSI encoders, a lost
//! encoder signal, and its motion parameters in pps (docs/modules.md).

use crate::common;

use common::{BusOfOne, MS, load, reply, send, status};

use tmclsim_firmware::{Eeprom, Module, Profile, World};
use tmclsim_protocol::mnemonic::parse_line;

fn module() -> BusOfOne {
    let p = Profile::built_in("tmcm-1310").unwrap();
    BusOfOne::new(Module::with_world(p, Eeprom::new("TMCM-1310"), World::free(1)))
}

fn setup(m: &mut BusOfOne, closed: bool) {
    send(m, "SAP 6, 0, 128"); // open loop: 50 % current
    send(m, &format!("SAP 129, 0, {}", i32::from(closed)));
    send(m, "SAP 113, 0, 10");
    send(m, "SAP 114, 0, 100");
    send(m, "SAP 122, 0, 1");
    send(m, "SAP 126, 0, 15000"); // correct at up to 15000 pps
    send(m, "SAP 210, 0, 4000");
    send(m, "SAP 202, 0, 200");
}

#[test]
fn closed_loop_holds_position_where_open_loop_loses_steps() {
    // Open loop at 50 % current against a 60 % load: steps are lost.
    let mut m = module();
    setup(&mut m, false);
    load(&mut m, 60.0);
    send(&mut m, "MVP ABS, 0, 51200");
    m.advance(10_000 * MS);
    assert_eq!(send(&mut m, "GAP 1, 0"), 51200, "the counter says arrived");
    assert!(m.mechanical_position(0) < 51_000.0, "the rotor did not: {}", m.mechanical_position(0));
    // Closed loop: the current rises to what the load needs; no step is lost.
    let mut m = module();
    setup(&mut m, true);
    load(&mut m, 60.0);
    send(&mut m, "MVP ABS, 0, 51200");
    m.advance(10_000 * MS);
    assert_eq!(send(&mut m, "GAP 1, 0"), 51200);
    assert!((m.mechanical_position(0) - 51_200.0).abs() < 0.5);
    assert_eq!(send(&mut m, "GAP 237, 0"), 0);
    assert_eq!(send(&mut m, "GAP 8, 0"), 1);
    let scale = send(&mut m, "GAP 123, 0");
    assert!((70..=100).contains(&scale), "current scale follows the load: {scale}");
    // Without load, the scale drops.
    load(&mut m, 0.0);
    send(&mut m, "MVP ABS, 0, 0");
    m.advance(10_000 * MS);
    assert!(send(&mut m, "GAP 123, 0") < scale);
}

#[test]
fn overload_in_closed_loop_is_corrected_afterwards() {
    let mut m = module();
    setup(&mut m, true);
    send(&mut m, "MVP ABS, 0, 40000");
    m.advance(100 * MS);
    load(&mut m, 150.0); // more than the motor can give
    m.advance(500 * MS);
    let error = send(&mut m, "GAP 237, 0");
    assert!(error > 0, "the rotor lags: {error}");
    load(&mut m, 0.0);
    m.advance(10_000 * MS);
    assert_eq!(send(&mut m, "GAP 237, 0"), 0, "the error was corrected");
    assert_eq!(send(&mut m, "GAP 1, 0"), 40000);
    assert!((m.mechanical_position(0) - 40_000.0).abs() < 0.5);
}

#[test]
fn torque_mode_produces_the_set_current() {
    let mut m = module();
    setup(&mut m, true);
    send(&mut m, "SAP 14, 0, 1500");
    m.advance(2000 * MS);
    assert_eq!(send(&mut m, "GAP 19, 0"), 1500);
    assert_eq!(send(&mut m, "GAP 123, 0"), 50);
    assert!(send(&mut m, "GAP 131, 0") > 0, "runs against no load");
    assert_eq!(send(&mut m, "GAP 18, 0") & 0b111000, 0b100000, "torque mode bit");
    // A load above the torque stops it.
    load(&mut m, 60.0);
    m.advance(2000 * MS);
    assert_eq!(send(&mut m, "GAP 131, 0"), 0);
    // Negative current turns it the other way.
    load(&mut m, 10.0);
    send(&mut m, "SAP 14, 0, -2400");
    m.advance(2000 * MS);
    assert!(send(&mut m, "GAP 131, 0") < 0);
    assert_eq!(send(&mut m, "GAP 19, 0"), -2400);
}

#[test]
fn status_word_bits_follow_the_state() {
    let mut m = module();
    setup(&mut m, true);
    let word = |m: &mut BusOfOne| send(m, "GAP 18, 0");
    assert_eq!(word(&mut m) & 0b111101, 0b1101, "target reached, closed loop, position mode");
    send(&mut m, "ROR 0, 500");
    m.advance(1000 * MS);
    assert_eq!(word(&mut m) & 0b11011, 0b10010, "velocity mode, velocity reached");
    send(&mut m, "SAP 129, 0, 0");
    assert_eq!(word(&mut m) & 0b100, 0, "closed loop off");
    m.world_mut().axes[0].forced_home = Some(true);
    m.world_mut().axes[0].forced_left = Some(true);
    assert_eq!(word(&mut m) & (0b111 << 6), 0b011 << 6);
    m.world_mut().temperature = 160.0;
    assert_ne!(word(&mut m) & (1 << 11), 0);
}

#[test]
fn deviation_interrupt_fires() {
    let mut m = module();
    setup(&mut m, true);
    send(&mut m, "SAP 125, 0, 2000");
    // (No CALCV on the 1310: the handler counts with GGP/CALC/AGP.)
    let words: Vec<_> = ["VECT 21, 5", "EI 21", "EI 255", "MVP ABS, 0, 200000", "JA 4", "GGP 7, 2", "CALC ADD, 1", "AGP 7, 2", "RETI"]
        .iter()
        .map(|l| parse_line(l).unwrap())
        .collect();
    m.load_program(&words).unwrap();
    m.start_program();
    m.advance(200 * MS);
    assert_eq!(send(&mut m, "GGP 7, 2"), 0);
    load(&mut m, 150.0);
    m.advance(1000 * MS);
    assert_eq!(send(&mut m, "GGP 7, 2"), 1, "once per deviation");
    assert_ne!(send(&mut m, "GAP 207, 0") & 2, 0);
}

#[test]
fn incremental_and_absolute_encoders() {
    // The carriage starts one turn away from 0 (256 µsteps × 200 full steps).
    let p = Profile::built_in("tmcm-1310").unwrap();
    let mut w = World::free(1);
    w.axes[0].start = 51_200.0;
    let mut m = BusOfOne::new(Module::with_world(p, Eeprom::new("TMCM-1310"), w));
    setup(&mut m, true);
    assert_eq!(send(&mut m, "GAP 209, 0"), 0, "ABN counts from power-up");
    send(&mut m, "SAP 201, 0, 1");
    assert_eq!(send(&mut m, "GAP 209, 0"), 4000, "SSI is absolute: one turn");
    send(&mut m, "SAP 201, 0, 0");
    send(&mut m, "MVP REL, 0, 25600");
    m.advance(5000 * MS);
    assert_eq!(send(&mut m, "GAP 209, 0"), 2000, "half a turn");
    send(&mut m, "SAP 209, 0, 0");
    assert_eq!(send(&mut m, "GAP 209, 0"), 0);
    // Index (N) channel: clear the count at the next index pulse. The
    // rotor stands at 1.5 turns; the index is at 2 turns.
    send(&mut m, "SAP 209, 0, 777");
    send(&mut m, "SAP 201, 0, 4");
    send(&mut m, "MVP REL, 0, 38400"); // to 2.25 turns
    m.advance(5000 * MS);
    assert_eq!(send(&mut m, "GAP 209, 0"), 1000, "a quarter turn past the index");
    assert_eq!(send(&mut m, "GAP 201, 0"), 0, "the clear-at-index bit cleared itself");
}

#[test]
fn a_lost_encoder_signal_is_detectable() {
    let mut m = module();
    setup(&mut m, true);
    send(&mut m, "SAP 125, 0, 1000");
    m.world_mut().axes[0].encoder_lost = true;
    send(&mut m, "MVP ABS, 0, 20000");
    m.advance(5000 * MS);
    assert_eq!(send(&mut m, "GAP 209, 0"), 0, "the count stands still");
    assert!(send(&mut m, "GAP 237, 0") > 1000, "the position error shows it");
    assert_ne!(send(&mut m, "GAP 207, 0") & 4, 0, "encoder fault flag");
}

#[test]
fn version_replies() {
    // 136 as V1.11 6.8.39 lays it out: the type 1310 ($051E) in the high
    // word of the binary form; the version is the V1.14 pages'.
    let mut m = module();
    assert_eq!(send(&mut m, "#136 1 0 0"), 0x051E_010E);
    let mut string = [2; 9];
    string[1..].copy_from_slice(b"1310V114");
    assert_eq!(m.handle_frame(&common::hex("01 88 00 00 00 00 00 00 89")), Some(string));
}

#[test]
fn commands_the_1310_lacks() {
    let mut m = module();
    for line in ["CALCVV ADD, 1, 2", "MVPA ABS, 0", "RST 0", "DJNZ 1, 0", "ROLA 0", "SIV 1", "CALL ZE, 0", "SAC 0, 1, 0"] {
        assert_eq!(reply(&mut m, line).status, 2, "{line}");
    }
    assert_eq!(send(&mut m, "EI 21"), 0, "deviation interrupt exists");
}

#[test]
fn motion_parameters_take_pps_in_the_sibling_s_range() {
    // PyTrinamic's TMCM-1311 examples: AP 4 = 20000, AP 5 = 40000, ROR 20000.
    let mut m = module();
    for line in ["SAP 4, 0, 20000", "SAP 5, 0, 40000", "ROR 0, 20000", "ROL 0, 20000"] {
        assert_eq!(status(&mut m, line), 100, "{line}");
    }
    assert_eq!(send(&mut m, "GAP 4, 0"), 20000);
    assert_eq!(send(&mut m, "GAP 5, 0"), 40000);
    send(&mut m, "MST 0");
    // The TMCM-1311 manual V1.11 gives velocities up to 327 679 999 pps.
    for (n, lo) in [(2, -327_679_999), (4, 1), (108, 0), (109, 0), (130, 1), (194, 0), (195, 0)] {
        assert_eq!(status(&mut m, &format!("SAP {n}, 0, 327679999")), 100, "AP {n}");
        assert_eq!(status(&mut m, &format!("SAP {n}, 0, 327680000")), 4, "AP {n}: just above the range");
        assert_eq!(status(&mut m, &format!("SAP {n}, 0, {}", lo - 1)), 4, "AP {n}: just below the range");
    }
    assert_eq!(status(&mut m, "ROR 0, 327679999"), 100);
    assert_eq!(status(&mut m, "ROR 0, 327680000"), 4, "ROR takes AP 2's range");
    assert_eq!(status(&mut m, "ROL 0, 327680000"), 4);
    assert_eq!(status(&mut m, "SAP 5, 0, 2147483647"), 100, "any positive acceleration");
    assert_eq!(status(&mut m, "SAP 5, 0, 0"), 4);
    // No pulse or ramp divisor in pps units.
    assert_eq!(status(&mut m, "GAP 153, 0"), 3);
    assert_eq!(status(&mut m, "SAP 154, 0, 3"), 3);
}

#[test]
fn a_velocity_in_pps_covers_its_distance_in_virtual_time() {
    let mut m = module();
    setup(&mut m, true);
    // Velocity mode: 25600 pps reached with 51200 pps² in 0.5 s (6400
    // µsteps), then 25600 µsteps every second.
    send(&mut m, "SAP 5, 0, 51200");
    send(&mut m, "ROR 0, 25600");
    m.advance(2500 * MS);
    assert_eq!(send(&mut m, "GAP 3, 0"), 25600);
    assert_eq!(send(&mut m, "GAP 233, 0"), 6400 + 2 * 25600);
    assert_eq!(send(&mut m, "GAP 1, 0"), 6400 + 2 * 25600);
    // Over a stretch at constant speed the encoder measures the same speed.
    m.advance(100 * MS);
    assert_eq!(send(&mut m, "GAP 1, 0"), 6400 + 2 * 25600 + 2560);
    assert_eq!(send(&mut m, "GAP 131, 0"), 25600);
    send(&mut m, "MST 0");
    m.advance(1000 * MS);
    // Position mode: 51200 µsteps at 25600 pps and 51200 pps² take
    // 0.5 s up, 1.5 s at speed and 0.5 s down (to the stop speed, 1 pps).
    send(&mut m, "SAP 1, 0, 0");
    send(&mut m, "SAP 4, 0, 25600");
    send(&mut m, "MVP ABS, 0, 51200");
    m.advance(2480 * MS);
    assert_eq!(send(&mut m, "GAP 8, 0"), 0, "not yet");
    let before = send(&mut m, "GAP 1, 0");
    assert!((51_150..51_200).contains(&before), "{before}");
    m.advance(40 * MS);
    assert_eq!(send(&mut m, "GAP 8, 0"), 1);
    assert_eq!(send(&mut m, "GAP 1, 0"), 51200);
    assert_eq!(send(&mut m, "GAP 3, 0"), 0);
}
