//! Reference search modes against a world with switches at known
//! positions: the zero point, AP 196, AP 197 and the direction sequence.

use crate::common;

use common::{BusOfOne, MS, send};

use tmclsim_firmware::Module;
use tmclsim_protocol::mnemonic::parse_line;
use tmclsim_protocol::{Reply, Request};

/// Left stop switch pressed from −20000 down to −22000, right from 30000
/// up to 32000, home switch between 5000 and 6000.
fn stage(start: i32) -> BusOfOne {
    let mut m = BusOfOne::built_in("tmcm-1141");
    let w = &mut m.world_mut().axes[0];
    w.left_switch = Some(-20_000.0);
    w.left_width = Some(2_000.0);
    w.right_switch = Some(30_000.0);
    w.right_width = Some(2_000.0);
    w.home_switch = Some((5_000.0, 6_000.0));
    send(&mut m, "SAP 194, 0, 2000");
    send(&mut m, "SAP 195, 0, 200");
    send(&mut m, "SAP 5, 0, 500");
    if start != 0 {
        send(&mut m, "SAP 4, 0, 2047");
        send(&mut m, &format!("MVP ABS, 0, {start}"));
        m.advance(20_000 * MS);
        assert_eq!(send(&mut m, "GAP 1, 0"), start);
    }
    m
}

/// Runs a search; returns the signs of the velocity in the order they
/// occurred.
fn search(m: &mut BusOfOne, mode: i32) -> Vec<i32> {
    send(m, &format!("SAP 193, 0, {mode}"));
    send(m, "RFS START, 0");
    let mut dirs = vec![];
    for _ in 0..600_000 {
        m.advance(MS);
        let v = send(m, "GAP 3, 0").signum();
        if v != 0 && dirs.last() != Some(&v) {
            dirs.push(v);
        }
        if send(m, "RFS STATUS, 0") == 0 {
            return dirs;
        }
    }
    panic!("mode {mode}: the search did not end");
}

fn zero_point(m: &BusOfOne) -> f64 {
    m.mechanical_position(0)
}

#[test]
fn end_switch_modes() {
    // (mode, expected zero point, expected AP 196)
    let cases = [
        (1, -20_000.0, None),
        (65, 30_000.0, None),
        (2, -20_000.0, Some(50_000)),
        (66, 30_000.0, Some(50_000)),
        (3, -21_000.0, Some(51_000)),
        (67, 31_000.0, Some(51_000)),
        (4, -21_000.0, None),
        (68, 31_000.0, None),
    ];
    for (mode, zero, distance) in cases {
        let mut m = stage(0);
        search(&mut m, mode);
        assert_eq!(send(&mut m, "GAP 1, 0"), 0, "mode {mode}: counter zeroed");
        assert!((zero_point(&m) - zero).abs() <= 0.5, "mode {mode}: zero at {} not {zero}", zero_point(&m));
        assert_eq!(send(&mut m, "GAP 197, 0"), zero as i32, "mode {mode}: AP 197 holds the old count of the zero point");
        if let Some(d) = distance {
            assert_eq!(send(&mut m, "GAP 196, 0"), d, "mode {mode}: AP 196");
        }
    }
}

#[test]
fn home_switch_modes() {
    // (mode, start, zero point)
    let cases = [(5, 0, 6_000.0), (5, 10_000, 6_000.0), (6, 0, 5_000.0), (6, 10_000, 5_000.0), (7, 10_000, 5_500.0), (8, 0, 5_500.0)];
    for (mode, start, zero) in cases {
        let mut m = stage(start);
        search(&mut m, mode);
        assert_eq!(send(&mut m, "GAP 1, 0"), 0);
        assert!((zero_point(&m) - zero).abs() <= 0.5, "mode {mode} from {start}: zero at {}", zero_point(&m));
        // The counter read the carriage's position before the search.
        assert_eq!(f64::from(send(&mut m, "GAP 197, 0")), zero, "mode {mode} from {start}");
    }
}

#[test]
fn inverted_home_switch() {
    // Mode 5 + 128: the home input is active outside 5000…6000.
    let mut m = stage(5_500);
    search(&mut m, 133);
    assert!((zero_point(&m) - 5_000.0).abs() <= 0.5, "{}", zero_point(&m));
}

#[test]
fn direction_sequences() {
    let mut m = stage(0);
    let dirs = search(&mut m, 2);
    // Right switch first, then the left one. (The switches of this world
    // have no hysteresis: leaving and re-entering an edge to calibrate it
    // takes no travel.)
    assert_eq!(dirs, [1, -1], "{dirs:?}");
    let mut m = stage(0);
    let dirs = search(&mut m, 1);
    assert_eq!(dirs[0], -1);
    let mut m = stage(0);
    let dirs = search(&mut m, 5);
    assert_eq!(&dirs[..2], &[-1, 1], "reverses at the left switch: {dirs:?}");
}

#[test]
fn limit_switch_settings_do_not_influence_the_search() {
    let mut m = stage(0);
    send(&mut m, "SAP 13, 0, 1");
    send(&mut m, "SAP 149, 0, 1");
    search(&mut m, 1);
    assert!((zero_point(&m) - -20_000.0).abs() <= 0.5);
}

#[test]
fn stop_and_status() {
    let mut m = stage(0);
    send(&mut m, "SAP 193, 0, 1");
    send(&mut m, "RFS START, 0");
    m.advance(100 * MS);
    assert_ne!(send(&mut m, "RFS STATUS, 0"), 0);
    send(&mut m, "RFS STOP, 0");
    assert_eq!(send(&mut m, "RFS STATUS, 0"), 0);
    m.advance(5_000 * MS);
    assert_eq!(send(&mut m, "GAP 3, 0"), 0, "stopped");
    // A mode the module does not have is refused by AP 193 itself.
    let f = Request::new(1, parse_line("SAP 193, 0, 69").unwrap()).encode();
    assert_eq!(Reply::decode(&m.handle_frame(&f).unwrap()).unwrap().status, 4);
}

#[test]
fn wait_rfs_in_a_program() {
    let mut m = stage(0);
    send(&mut m, "SAP 193, 0, 1");
    let words: Vec<_> =
        ["RFS START, 0", "WAIT RFS, 0, 0", "GAP 197, 0", "AGP 9, 2", "STOP"].iter().map(|l| parse_line(l).unwrap()).collect();
    m.load_program(&words).unwrap();
    m.start_program();
    m.advance(600_000 * MS);
    assert_eq!(send(&mut m, "GGP 9, 2"), -20_000);
}

/// Mode 8 from far below the home switch of the built-in stage (home switch
/// 100 000…110 000, carriage at −500 000): the search ends on the middle of
/// the switch, in one long advance as in 1 ms steps.
#[test]
fn mode_8_from_far_below_in_one_long_advance() {
    for stepped in [true, false] {
        let profile = tmclsim_firmware::Profile::built_in("tmcm-1141").unwrap();
        let mut world = tmclsim_firmware::World::stage(1);
        world.axes[0].start = -500_000.0;
        let mut m = BusOfOne::new(Module::with_world(profile, tmclsim_firmware::Eeprom::new("TMCM-1141"), world));
        send(&mut m, "SAP 193, 0, 8");
        send(&mut m, "RFS START, 0");
        if stepped {
            for _ in 0..400_000 {
                m.advance(MS);
            }
        } else {
            m.advance(400_000 * MS);
        }
        assert_eq!(send(&mut m, "RFS STATUS, 0"), 0, "stepped: {stepped}");
        assert_eq!(send(&mut m, "GAP 197, 0"), 605_000, "stepped: {stepped}");
        assert!((zero_point(&m) - 105_000.0).abs() <= 0.5, "zero at {}", zero_point(&m));
    }
}
