//! Every sixPoint module (the profiles whose motion controller is the
//! TMC5130/TMC5160's) and every eight-point module (the TMC5240's) does on
//! every axis what the TMC429 modules do: it names itself, moves to a
//! target on its ramp, runs a standalone program with a timer interrupt,
//! keeps what it stores across a power cycle, stops on a stall, and
//! answers bad values with the module's statuses.

use crate::common;

use common::{BusOfOne, MS, power_cycle, reply, send, status, until};

use tmclsim_firmware::world::Load;
use tmclsim_firmware::{Bus, Module, Profile};
use tmclsim_profile::MotionController;
use tmclsim_protocol::Request;
use tmclsim_protocol::mnemonic::parse_line;

/// The built-in modules whose motion controller is `controller`, with
/// their axis counts.
fn modules(controller: MotionController) -> Vec<(&'static str, u8)> {
    Profile::names()
        .into_iter()
        .filter_map(|name| {
            let p = Profile::built_in(name).unwrap();
            (p.features.motion_controller == controller).then_some((name, p.module.axes))
        })
        .collect()
}

/// The built-in sixPoint modules, with their axis counts.
fn family() -> Vec<(&'static str, u8)> {
    let names = modules(MotionController::Sixpoint);
    assert!(names.len() >= 10, "the sixPoint family: {names:?}");
    names
}

/// The built-in eight-point modules (TMC5240), with their axis counts.
fn eight_point() -> Vec<(&'static str, u8)> {
    let names = modules(MotionController::Eightpoint);
    assert!(names.len() >= 2, "the eight-point modules: {names:?}");
    names
}

/// Both families.
fn both() -> Vec<(&'static str, u8)> {
    family().into_iter().chain(eight_point()).collect()
}

#[test]
fn each_names_itself_with_its_type_and_firmware() {
    for (name, _) in both() {
        let mut m = BusOfOne::built_in(name);
        let p = m.profile().clone();
        let r = reply(&mut m, "#136 1 0 0");
        assert_eq!(r.status, 100, "{name}");
        assert_eq!(r.value >> 16, i32::from(p.module.type_number), "{name}: 136 type 1 high word");
        let [major, minor] = p.module.firmware;
        assert_eq!(r.value & 0xFFFF, i32::from(major) << 8 | i32::from(minor), "{name}: the firmware version");
    }
}

#[test]
fn every_axis_moves_to_its_target_on_the_sixpoint_ramp() {
    for (name, axes) in family() {
        let mut m = BusOfOne::built_in(name);
        for a in 0..axes {
            for (n, v) in [(4, 20_000), (5, 40_000), (15, 10_000), (16, 5_000), (17, 40_000), (18, 10_000), (19, 100), (20, 200)] {
                send(&mut m, &format!("SAP {n}, {a}, {v}"));
            }
            send(&mut m, &format!("MVP ABS, {a}, {}", 12_345 * (i32::from(a) + 1)));
        }
        until(&mut m, 20_000, |m| (0..axes).all(|a| send(m, &format!("GAP 8, {a}")) == 1))
            .unwrap_or_else(|| panic!("{name}: every axis arrives"));
        for a in 0..axes {
            assert_eq!(send(&mut m, &format!("GAP 1, {a}")), 12_345 * (i32::from(a) + 1), "{name} axis {a}");
        }
        assert_eq!(status(&mut m, &format!("GAP 1, {axes}")), 4, "{name}: no motor {axes}");
    }
}

#[test]
fn a_standalone_program_with_a_timer_interrupt_runs() {
    // The main loop moves axis 0 back and forth and waits for each
    // arrival; timer 0 counts its ticks in user variable 1.
    let program = [
        "VECT 0, 9",        // 0: timer 0 → label at 9
        "SGP 0, 3, 10",     // 1: every 10 ms
        "EI 0",             // 2
        "EI 255",           // 3
        "MVP ABS, 0, 3000", // 4
        "WAIT POS, 0, 0",   // 5
        "MVP ABS, 0, 0",    // 6
        "WAIT POS, 0, 0",   // 7
        "JA 4",             // 8
        "GGP 1, 2",         // 9: the handler
        "CALC ADD, 1",      // 10
        "AGP 1, 2",         // 11
        "RETI",             // 12
    ];
    for (name, _) in both() {
        let words: Vec<_> = program.iter().map(|l| parse_line(l).unwrap()).collect();
        let mut module = Module::built_in(name).unwrap();
        module.load_program(&words).unwrap_or_else(|s| panic!("{name}: {s:?}"));
        module.start_program();
        let mut bus = Bus::single(module);
        bus.advance(2000 * MS);
        let ticks = bus.handle_frame(&Request::new(1, parse_line("GGP 1, 2").unwrap()).encode()).replies[0];
        let ticks = i32::from_be_bytes([ticks[4], ticks[5], ticks[6], ticks[7]]);
        assert!((195..=200).contains(&ticks), "{name}: {ticks} timer ticks in 2 s");
        let pos = bus.handle_frame(&Request::new(1, parse_line("GAP 1, 0").unwrap()).encode()).replies[0];
        let pos = i32::from_be_bytes([pos[4], pos[5], pos[6], pos[7]]);
        assert!((0..=3000).contains(&pos), "{name}: {pos}");
    }
}

#[test]
fn stored_ramp_parameters_survive_a_power_cycle() {
    for (name, axes) in family() {
        let last = axes - 1;
        let mut m = BusOfOne::built_in(name);
        for (n, v) in [(15, 1234), (16, 4321), (17, 2345), (18, 3456), (19, 11), (20, 22), (21, 333), (26, 1)] {
            send(&mut m, &format!("SAP {n}, {last}, {v}"));
            send(&mut m, &format!("STAP {n}, {last}"));
        }
        send(&mut m, &format!("SAP 4, {last}, 7777"));
        let mut again = power_cycle(&m);
        for (n, v) in [(15, 1234), (16, 4321), (17, 2345), (18, 3456), (19, 11), (20, 22), (21, 333), (26, 1)] {
            assert_eq!(send(&mut again, &format!("GAP {n}, {last}")), v, "{name}: AP {n} stored");
        }
        assert_ne!(send(&mut again, &format!("GAP 4, {last}")), 7777, "{name}: AP 4 was not stored");
    }
}

#[test]
fn a_stall_stops_the_motor_and_sets_ap_207() {
    for (name, axes) in both() {
        let last = axes - 1;
        let mut m = BusOfOne::built_in(name);
        send(&mut m, &format!("SAP 6, {last}, 255"));
        send(&mut m, &format!("SAP 181, {last}, 1000"));
        send(&mut m, &format!("ROR {last}, 20000"));
        m.advance(1000 * MS);
        m.world_mut().axes[last as usize].loads = vec![Load { torque: 150.0, ..Load::default() }];
        m.advance(20 * MS);
        assert_eq!(send(&mut m, &format!("GAP 3, {last}")), 0, "{name}: stopped on the stall");
        assert_eq!(send(&mut m, &format!("GAP 207, {last}")) & 1, 1, "{name}: the stall bit");
    }
}

#[test]
fn bad_values_and_missing_rows_answer_the_module_s_statuses() {
    for (name, _) in both() {
        let mut m = BusOfOne::built_in(name);
        let p = m.profile().clone();
        let eight = p.features.motion_controller == MotionController::Eightpoint;
        let ramp: &[u8] = if eight { &[4, 5, 15, 16, 17, 18, 19, 20, 21, 34, 35, 36, 37] } else { &[4, 5, 15, 16, 17, 18, 19, 20, 21] };
        for &n in ramp {
            let row = p.axis_parameter(n).unwrap_or_else(|| panic!("{name}: AP {n}"));
            if row.max < i64::from(i32::MAX) {
                assert_eq!(status(&mut m, &format!("SAP {n}, 0, {}", row.max + 1)), 4, "{name}: AP {n} above its range");
            }
            assert_eq!(status(&mut m, &format!("SAP {n}, 0, {}", row.min - 1)), 4, "{name}: AP {n} below its range");
            assert_eq!(status(&mut m, &format!("SAP {n}, 0, {}", row.max)), 100, "{name}: AP {n} at its top");
        }
        for n in [130, 138, 149, 153, 154] {
            assert_eq!(status(&mut m, &format!("GAP {n}, 0")), 3, "{name}: AP {n} is the TMC429's, not here");
        }
        if eight {
            assert_eq!(status(&mut m, "GAP 255, 0"), 3, "{name}: no unit mode");
            let axes = p.module.axes;
            assert_eq!(status(&mut m, &format!("SAP 34, {axes}, 1000")), 4, "{name}: no motor {axes}");
        }
    }
}

/// An eight-point ramp's values: VSTART 100, A1 10 000 to V1 5000, A2
/// 20 000 to V2 15 000, AMAX 40 000 to VMAX 25 000, DMAX 40 000, D2
/// 20 000, D1 10 000 down to VSTOP 200 (pps, pps²).
const EIGHT: [(u8, i32); 11] = [
    (19, 100),
    (15, 10_000),
    (16, 5000),
    (34, 20_000),
    (35, 15_000),
    (5, 40_000),
    (4, 25_000),
    (17, 40_000),
    (36, 20_000),
    (18, 10_000),
    (20, 200),
];

/// An acceleration in pps² as the chip runs it: the nearest register value
/// at the profile's clock (docs/behaviour.md rule 104).
fn as_register(p: &Profile, a: f64) -> f64 {
    let unit = f64::from(p.features.motion_clock_hz).powi(2) / 2f64.powi(41);
    (a / unit).round().max(1.0) * unit
}

#[test]
fn every_axis_of_an_eight_point_module_runs_its_eight_point_ramp_to_the_target() {
    // All axes at once; the speed (AP 3) sampled every millisecond shows
    // A1 below V1, A2 from V1 to V2 and AMAX above, then the way down with
    // DMAX, D2 and D1, and every axis stops on its target.
    for (name, axes) in eight_point() {
        let mut m = BusOfOne::built_in(name);
        let p = m.profile().clone();
        for a in 0..axes {
            for (n, v) in EIGHT {
                send(&mut m, &format!("SAP {n}, {a}, {v}"));
            }
            send(&mut m, &format!("MVP ABS, {a}, {}", 30_000 * (i32::from(a) + 1)));
        }
        let mut samples: Vec<Vec<(f64, f64)>> = vec![Vec::new(); axes as usize];
        let mut t = 0.0;
        until(&mut m, 20_000, |m| {
            t += 1e-3;
            for a in 0..axes {
                samples[a as usize].push((t, f64::from(send(m, &format!("GAP 3, {a}")))));
            }
            (0..axes).all(|a| send(m, &format!("GAP 8, {a}")) == 1)
        })
        .unwrap_or_else(|| panic!("{name}: every axis arrives"));
        for a in 0..axes {
            assert_eq!(send(&mut m, &format!("GAP 1, {a}")), 30_000 * (i32::from(a) + 1), "{name} axis {a}");
            let s = &samples[a as usize];
            let top = s.iter().position(|&(_, v)| v >= 25_000.0).unwrap_or_else(|| panic!("{name} axis {a}: never at VMAX"));
            let last = s.iter().rposition(|&(_, v)| v >= 25_000.0).unwrap();
            // The slope of the samples strictly inside a band, on the way
            // up (before VMAX) or down (after it), in pps².
            let slope = |part: &[(f64, f64)], lo: f64, hi: f64| {
                let inside: Vec<_> = part.iter().filter(|&&(_, v)| v > lo + 50.0 && v < hi - 50.0).collect();
                assert!(inside.len() >= 20, "{name} axis {a}: {} samples between {lo} and {hi}", inside.len());
                let (first, last) = (inside[0], inside[inside.len() - 1]);
                (last.1 - first.1) / (last.0 - first.0)
            };
            let up = &s[..top];
            let down = &s[last..];
            for (what, got, want) in [
                ("A1", slope(up, 100.0, 5000.0), 10_000.0),
                ("A2", slope(up, 5000.0, 15_000.0), 20_000.0),
                ("AMAX", slope(up, 15_000.0, 25_000.0), 40_000.0),
                ("DMAX", -slope(down, 15_000.0, 25_000.0), 40_000.0),
                ("D2", -slope(down, 5000.0, 15_000.0), 20_000.0),
                ("D1", -slope(down, 200.0, 5000.0), 10_000.0),
            ] {
                let want = as_register(&p, want);
                assert!((got - want).abs() <= 0.02 * want, "{name} axis {a}: {what} slope {got:.0}, the register gives {want:.0}");
            }
        }
    }
}

#[test]
fn an_eight_point_module_has_no_stap_its_settings_come_back_from_an_autostart_program() {
    // The TMCM-1290's manual has no STAP/RSAP (SAP's settings are
    // volatile); what comes back after a power cycle is what the EEPROM
    // holds: user variables (STGP) and a program that starts by itself.
    for (name, axes) in eight_point() {
        let last = axes - 1;
        let mut m = BusOfOne::built_in(name);
        let p = m.profile().clone();
        for (n, v) in [(34, 12_345), (35, 23_456), (36, 34_567)] {
            send(&mut m, &format!("SAP {n}, {last}, {v}"));
            assert_eq!(status(&mut m, &format!("STAP {n}, {last}")), 2, "{name}: no STAP");
            assert_eq!(status(&mut m, &format!("RSAP {n}, {last}")), 2, "{name}: no RSAP");
        }
        send(&mut m, "SGP 7, 2, 4711");
        send(&mut m, "STGP 7, 2");
        let mut again = power_cycle(&m);
        for n in [34, 35, 36] {
            let default = p.axis_parameter(n).unwrap().default as i32;
            assert_eq!(send(&mut again, &format!("GAP {n}, {last}")), default, "{name}: AP {n} back at its default");
        }
        assert_eq!(send(&mut again, "GGP 7, 2"), 4711, "{name}: the stored user variable");
        // The module's way to keep them: a program that sets them, started
        // at power-up (GP 77 = 1, stored automatically).
        let program: Vec<_> =
            [format!("SAP 34, {last}, 12345"), format!("SAP 35, {last}, 23456"), format!("SAP 36, {last}, 34567"), "STOP".to_string()]
                .iter()
                .map(|l| parse_line(l).unwrap())
                .collect();
        again.load_program(&program).unwrap_or_else(|s| panic!("{name}: {s:?}"));
        send(&mut again, "SGP 77, 0, 1");
        let mut third = power_cycle(&again);
        third.advance(100 * MS);
        for (n, v) in [(34, 12_345), (35, 23_456), (36, 34_567)] {
            assert_eq!(send(&mut third, &format!("GAP {n}, {last}")), v, "{name}: AP {n} set by the autostart program");
        }
    }
}

#[test]
fn a_bus_carries_a_tmc429_module_and_a_sixpoint_module() {
    let mut a = Module::built_in("tmcm-1141").unwrap();
    let mut b = Module::built_in("tmcm-1260").unwrap();
    a.set_address(1);
    b.set_address(2);
    let mut bus = Bus::new(vec![a, b]);
    let ask = |bus: &mut Bus, address: u8, line: &str| {
        let r = bus.handle_frame(&Request::new(address, parse_line(line).unwrap()).encode()).replies;
        assert_eq!(r.len(), 1, "{line} to {address}: one reply");
        (r[0][2], i32::from_be_bytes([r[0][4], r[0][5], r[0][6], r[0][7]]))
    };
    ask(&mut bus, 1, "MVP ABS, 0, 1000");
    ask(&mut bus, 2, "MVP ABS, 0, 100000");
    bus.advance(20_000 * MS);
    assert_eq!(ask(&mut bus, 1, "GAP 1, 0"), (100, 1000));
    assert_eq!(ask(&mut bus, 2, "GAP 1, 0"), (100, 100_000));
    assert_eq!(ask(&mut bus, 1, "GAP 153, 0").0, 100, "the TMC429 module has its ramp divisor");
    assert_eq!(ask(&mut bus, 2, "GAP 15, 0").0, 100, "the sixPoint module its A1");
}
