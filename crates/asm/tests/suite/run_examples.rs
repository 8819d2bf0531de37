//! The manual's example programs, assembled and run on the virtual
//! TMCM-1141: they do what the manual says they do.

use crate::common;

use common::{BusOfOne, MS, assemble_path, send};
use std::path::Path;
use tmclsim_firmware::{Module, Profile};
use tmclsim_protocol::mnemonic::parse_line;
use tmclsim_protocol::{Reply, Request};

fn load(name: &str) -> (BusOfOne, tmclsim_asm::Program) {
    let profile = Profile::built_in("tmcm-1141").unwrap();
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/programs").join(name);
    let program = assemble_path(&path, Some(&profile)).unwrap_or_else(|d| panic!("{}", tmclsim_asm::render(&d)));
    let mut m = Module::new(profile);
    m.load_program(&program.instructions).unwrap();
    (BusOfOne::new(m), program)
}

#[test]
fn first_steps_program_oscillates_between_plus_and_minus_512000() {
    let (mut m, _) = load("first_steps_2_4.tmc");
    m.set_trace(true);
    m.start_program();
    // Where the motor stands when each MVP of the loop starts: the
    // previous WAIT POS has just seen it arrive.
    let mut starts = vec![];
    // 2 × 512000 µsteps at AP 4 = 100 (1526 pps) take about 11 minutes.
    for _ in 0..3600 {
        m.advance(1000 * MS);
        starts.extend(m.take_trace().iter().filter(|r| r.instruction.opcode == 4).map(|r| r.axes[0].0));
    }
    assert!(starts.len() >= 6, "{starts:?}");
    for pair in starts[1..].chunks(2) {
        assert_eq!(pair[0], 512_000, "{starts:?}");
        if let Some(p) = pair.get(1) {
            assert_eq!(*p, -512_000, "{starts:?}");
        }
    }
}

#[test]
fn timer_interrupt_toggles_out0_every_second_while_the_main_loop_blinks() {
    let (mut m, _) = load("timer_interrupt_3_6_6.tmc");
    m.start_program();
    let mut out0_changes = vec![];
    let mut out1_changes = 0;
    let mut last = m.outputs();
    for step in 1..=10_005 {
        m.advance(MS);
        let now = m.outputs();
        if (now ^ last) & 1 != 0 {
            out0_changes.push(step);
        }
        if (now ^ last) & 2 != 0 {
            out1_changes += 1;
        }
        last = now;
    }
    // OUT0 toggles at 1000, 2000, … ms (to the millisecond).
    assert_eq!(out0_changes.len(), 10, "{out0_changes:?}");
    for (k, t) in out0_changes.iter().enumerate() {
        assert!((i64::from(*t) - 1000 * (k as i64 + 1)).abs() <= 1, "{out0_changes:?}");
    }
    // OUT1 changes every 500 ms (WAIT TICKS 50), 20 times in 10 s.
    assert!((19..=21).contains(&out1_changes), "{out1_changes}");
}

#[test]
fn djnz_loop_runs_exactly_100_times() {
    let (mut m, _) = load("djnz_3_7_43.tmc");
    send(&mut m, "SAP 4, 0, 2047");
    m.set_trace(true);
    m.start_program();
    let mut moves = 0;
    for _ in 0..2000 {
        m.advance(1000 * MS);
        moves += m.take_trace().iter().filter(|r| r.instruction.opcode == 4).count();
    }
    assert_eq!(moves, 100);
    assert_eq!(m.actual_position(0), 100 * 51200);
    assert_eq!(send(&mut m, "GGP 42, 2"), 0);
}

#[test]
fn routines_start_with_129_type_1_at_addresses_0_1_2() {
    // Func1 (address 0): to 1000 and back.
    let (mut m, _) = load("routines_8_6.tmc");
    send(&mut m, "#129 1 0 0");
    m.advance(40 * MS);
    assert!(m.actual_position(0) > 0);
    m.advance(5000 * MS);
    assert_eq!(m.actual_position(0), 0);
    assert_eq!(send(&mut m, "GGP 128, 0"), 0, "STOP at the end");
    // Func2 (address 1): rotates left for 1 s.
    send(&mut m, "#129 1 0 1");
    m.advance(500 * MS);
    assert!(send(&mut m, "GAP 3, 0") < 0);
    m.advance(3000 * MS);
    assert_eq!(send(&mut m, "GAP 3, 0"), 0);
    let after_left = m.actual_position(0);
    assert!(after_left < 0);
    // Func3 (address 2): rotates right for 7 s.
    send(&mut m, "#129 1 0 2");
    m.advance(3000 * MS);
    assert_eq!(send(&mut m, "GAP 3, 0"), 1000);
    m.advance(10_000 * MS);
    assert!(m.actual_position(0) > after_left);
    assert_eq!(send(&mut m, "GAP 3, 0"), 0);
}

/// The CALL example of 3.7.44, run as printed. Loads of the accumulator
/// set the flags (docs/behaviour.md rule 18; the example's own `GAP 2, 0` /
/// `JC ZE` needs that), so a subroutine's last load decides the next CALL:
/// the example turns right, stops from standstill, and turns left, but
/// RunLeft's `CALC MUL, -1` and MotorStop's `GAP 2, 0` leave GT behind and
/// RunRight follows them.
#[test]
fn call_example_turns_the_analog_input_into_left_right_stop() {
    let (mut m, _) = load("call_3_7_44.tmc");
    m.set_trace(true);
    m.start_program();
    // At 512 from standstill: MotorStop, nothing moves.
    m.world_mut().set_analog(0, 512);
    m.advance(100 * MS);
    assert_eq!(send(&mut m, "GAP 2, 0"), 0);
    assert_eq!(send(&mut m, "GAP 3, 0"), 0);
    // Above 512: RunRight, RORA with the difference.
    m.world_mut().set_analog(0, 900);
    m.advance(100 * MS);
    assert_eq!(send(&mut m, "GAP 2, 0"), 388);
    // Below 512: RunLeft rotates left with 512 − 100 …
    m.take_trace();
    m.world_mut().set_analog(0, 100);
    m.advance(MS);
    let trace = m.take_trace();
    let rola = trace.iter().position(|r| r.instruction.opcode == 50).expect("RunLeft ran");
    assert_eq!(trace[rola].registers.accumulator, 412);
    // … and RunRight follows it in the same pass.
    let rora = trace[rola..].iter().position(|r| r.instruction.opcode == 51).expect("RunRight ran");
    assert_eq!(trace[rola + rora].registers.accumulator, 412);
    // At 512 while running: MotorStop stops the motor, RunRight restarts it.
    m.world_mut().set_analog(0, 512);
    m.advance(MS);
    let trace = m.take_trace();
    let mst = trace.iter().position(|r| r.instruction.opcode == 3).expect("MotorStop ran MST");
    assert!(trace[mst..].iter().any(|r| r.instruction.opcode == 51));
}

#[test]
fn copy_inputs_to_outputs() {
    let (mut m, _) = load("copy_inputs_3_7_14.tmc");
    m.start_program();
    m.world_mut().set_digital(1, true);
    m.advance(10 * MS);
    assert_eq!(m.outputs(), 0b10);
    m.world_mut().set_digital(0, true);
    m.world_mut().set_digital(1, false);
    m.advance(10 * MS);
    assert_eq!(m.outputs(), 0b01);
}

#[test]
fn download_over_frames_and_read_back_match_the_binary() {
    let (_, program) = load("timer_interrupt_3_6_6.tmc");
    let mut m = Module::built_in("tmcm-1141").unwrap();
    send(&mut m, "#132 0 0 0");
    for w in &program.instructions {
        let r = Reply::decode(&m.handle_frame(&Request::new(1, *w).encode()).unwrap()).unwrap();
        assert_eq!(r.status, 101);
    }
    send(&mut m, "#133 0 0 0");
    for (a, w) in program.instructions.iter().enumerate() {
        let f = m.handle_frame(&Request::new(1, parse_line(&format!("#134 0 0 {a}")).unwrap()).encode()).unwrap();
        assert_eq!(&f[1..8], &w.to_bytes(), "word {a}");
    }
}
