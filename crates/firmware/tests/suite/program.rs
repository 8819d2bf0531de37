//! Standalone programs on the virtual TMCM-1141: download, control
//! commands, every flow command, WAIT, interrupts, persistence.

use crate::common;

use common::{BusOfOne, MS, reply, send};

use tmclsim_firmware::Module;
use tmclsim_firmware::program::RunMode;
use tmclsim_protocol::mnemonic::parse_line;
use tmclsim_protocol::{Instruction, Request};

fn module() -> BusOfOne {
    BusOfOne::built_in("tmcm-1141")
}

fn raw(m: &mut BusOfOne, ins: Instruction) -> [u8; 9] {
    m.handle_frame(&Request::new(1, ins).encode()).expect("reply")
}

/// Downloads source lines (numeric operands) over frames, like the IDE.
fn download(m: &mut BusOfOne, lines: &[&str]) {
    assert_eq!(reply(m, "#132 0 0 0").status, 100);
    for l in lines {
        let r = reply(m, l);
        assert_eq!(r.status, 101, "{l}");
    }
    assert_eq!(reply(m, "#133 0 0 0").status, 100);
}

fn run(m: &mut BusOfOne, lines: &[&str], for_ms: u64) {
    download(m, lines);
    assert_eq!(reply(m, "#129 1 0 0").status, 100);
    m.advance(for_ms * MS);
}

fn var(m: &mut BusOfOne, n: u8) -> i32 {
    send(m, &format!("GGP {n}, 2"))
}

#[test]
fn download_read_back_and_status() {
    let mut m = module();
    download(&mut m, &["ROL 0, 1000", "WAIT TICKS, 0, 500", "MST 0", "JA 0"]);
    // 134: the stored instruction replaces the module address byte.
    let f = raw(&mut m, Instruction::new(134, 0, 0, 1));
    let stored = parse_line("WAIT TICKS, 0, 500").unwrap().to_bytes();
    assert_eq!(f[0], 2);
    assert_eq!(&f[1..8], &stored);
    assert_eq!(f[8], tmclsim_protocol::checksum(&f[..8]));
    assert_eq!(reply(&mut m, "#134 0 0 1024").status, 4);
    // 135 type 0: mode, wait flag, download pointer.
    assert_eq!(send(&mut m, "#135 0 0 0"), 4);
    assert_eq!(send(&mut m, "#129 0 0 0"), 0);
    m.advance(MS);
    let status = send(&mut m, "#135 1 0 0");
    assert_eq!(status >> 24, 1, "running");
    assert_eq!(status >> 16 & 0xFF, 1, "waiting");
    assert_eq!(status & 0xFFFF, 1, "the program counter is held at the WAIT");
    assert_eq!(send(&mut m, "GGP 128, 0"), 1);
    assert_eq!(send(&mut m, "GGP 130, 0"), 1);
    assert_eq!(reply(&mut m, "#128 0 0 0").status, 100);
    assert_eq!(send(&mut m, "GGP 128, 0"), 0);
    // Download past the end of memory.
    reply(&mut m, "#132 0 0 1023");
    assert_eq!(reply(&mut m, "MST 0").status, 101);
    assert_eq!(reply(&mut m, "MST 0").status, 4);
    reply(&mut m, "#133 0 0 0");
    assert_eq!(reply(&mut m, "#132 0 0 1024").status, 4);
}

#[test]
fn counting_loop_with_compare_and_jump() {
    let mut m = module();
    run(&mut m, &["CALC LOAD, 0", "CALC ADD, 1", "COMP 100", "JC LT, 1", "AGP 7, 2", "STOP"], 100);
    assert_eq!(var(&mut m, 7), 100);
    assert_eq!(send(&mut m, "GGP 128, 0"), 0, "STOP ends the program");
    assert_eq!(send(&mut m, "#135 2 0 0"), 100);
}

#[test]
fn djnz_loop_runs_exactly_100_times() {
    let mut m = module();
    run(&mut m, &["SGP 42, 2, 100", "CALCV ADD, 43, 1", "DJNZ 42, 1", "STOP"], 100);
    assert_eq!(var(&mut m, 43), 100);
    assert_eq!(var(&mut m, 42), 0);
}

#[test]
fn instructions_take_virtual_time() {
    let mut m = module();
    // 0: GGP 132 → var 0; then 1000 loop iterations of 2 words; then GGP 132 → var 1.
    run(&mut m, &["GGP 132, 0", "AGP 0, 2", "SGP 2, 2, 1000", "DJNZ 2, 3", "GGP 132, 0", "AGP 1, 2", "STOP"], 1000);
    let elapsed = var(&mut m, 1) - var(&mut m, 0);
    // 1000 DJNZ + 4 others at 25 µs each: 25 ms.
    assert!((24..=27).contains(&elapsed), "{elapsed} ms");
}

#[test]
fn subroutines_stack_depth_and_empty_rsub() {
    let mut m = module();
    // 0: CSUB 3; 1: CALCV ADD 10,1; 2: STOP; 3: CALCV ADD 11, 1; 4: RSUB
    run(&mut m, &["CSUB 3", "CALCV ADD, 10, 1", "STOP", "CALCV ADD, 11, 1", "RSUB"], 10);
    assert_eq!((var(&mut m, 10), var(&mut m, 11)), (1, 1));
    // Nine nested calls: the ninth is ignored (stack of 8).
    let mut m = module();
    let mut prog: Vec<String> = (0..9).map(|i| format!("CSUB {}", i + 1)).collect();
    prog[8] = "CSUB 20".into(); // would go to 20
    prog.push("CALCV ADD, 12, 1".into()); // 9: reached after the ignored call
    prog.push("STOP".into()); // 10
    let lines: Vec<&str> = prog.iter().map(String::as_str).collect();
    run(&mut m, &lines, 10);
    assert_eq!(var(&mut m, 12), 1);
    // RSUB with an empty stack is ignored.
    let mut m = module();
    run(&mut m, &["RSUB", "CALCV ADD, 13, 1", "STOP"], 10);
    assert_eq!(var(&mut m, 13), 1);
}

#[test]
fn call_with_conditions() {
    let mut m = module();
    // 0 CALC LOAD -5; 1 COMP 0; 2 CALL LT 6; 3 CALL GE 8; 4 STOP; 5 -; 6 CALCV ADD 20 1; 7 RSUB; 8 CALCV ADD 21 1; 9 RSUB
    run(
        &mut m,
        &["CALC LOAD, -5", "COMP 0", "CALL LT, 6", "CALL GE, 8", "STOP", "STOP", "CALCV ADD, 20, 1", "RSUB", "CALCV ADD, 21, 1", "RSUB"],
        10,
    );
    assert_eq!((var(&mut m, 20), var(&mut m, 21)), (1, 0));
}

#[test]
fn every_jc_condition() {
    use tmclsim_protocol::mnemonic::CONDITIONS;
    // (accumulator, compare value) → which conditions hold.
    for (acc, cmp) in [(5, 3), (3, 3), (1, 3)] {
        for (k, cond) in CONDITIONS.iter().enumerate().take(8) {
            let mut m = module();
            let jc = format!("JC {cond}, 5");
            run(&mut m, &[&format!("CALC LOAD, {acc}"), &format!("COMP {cmp}"), &jc, "STOP", "STOP", "CALCV LOAD, 30, 1", "STOP"], 5);
            let holds = match k {
                0 | 2 => acc == cmp,
                1 | 3 => acc != cmp,
                4 => acc > cmp,
                5 => acc >= cmp,
                6 => acc < cmp,
                _ => acc <= cmp,
            };
            assert_eq!(var(&mut m, 30) == 1, holds, "{acc} vs {cmp}: {cond}");
        }
    }
    // ZE/NZ after an accumulator load compare the new value with 0.
    let mut m = module();
    run(&mut m, &["CALC LOAD, 0", "JC ZE, 3", "STOP", "CALCV LOAD, 31, 1", "STOP"], 5);
    assert_eq!(var(&mut m, 31), 1);
}

#[test]
fn wait_ticks_and_accumulator_ticks() {
    let mut m = module();
    run(&mut m, &["WAIT TICKS, 0, 50", "CALCV LOAD, 1, 1", "CALC LOAD, 30", "WAIT TICKS, 0, -1", "CALCV LOAD, 2, 1", "STOP"], 490);
    assert_eq!(var(&mut m, 1), 0, "still waiting at 490 ms");
    m.advance(20 * MS);
    assert_eq!(var(&mut m, 1), 1);
    m.advance(290 * MS);
    assert_eq!(var(&mut m, 2), 0);
    m.advance(20 * MS);
    assert_eq!(var(&mut m, 2), 1, "WAIT -1 takes the accumulator (300 ms)");
}

#[test]
fn wait_pos_and_timeout_sets_eto() {
    let mut m = module();
    // Move far with a timeout of 10 ticks: ETO is set, JC ETO jumps.
    run(
        &mut m,
        &[
            "MVP ABS, 0, 10000000",
            "WAIT POS, 0, 10",
            "JC ETO, 4",
            "STOP",
            "CALCV LOAD, 40, 1",
            "CLE ETO",
            "JC ETO, 3",
            "CALCV LOAD, 41, 1",
            "STOP",
        ],
        200,
    );
    assert_eq!(var(&mut m, 40), 1);
    assert_eq!(var(&mut m, 41), 1, "CLE cleared the flag");
    // WAIT POS without timeout ends when the motor arrives.
    let mut m = module();
    reply(&mut m, "SAP 4, 0, 2047");
    run(&mut m, &["MVP ABS, 0, 5000", "WAIT POS, 0, 0", "GAP 1, 0", "AGP 42, 2", "STOP"], 5000);
    assert_eq!(var(&mut m, 42), 5000);
}

#[test]
fn wait_for_switches() {
    let mut m = module();
    m.world_mut().axes[0].right_switch = Some(3000.0);
    run(&mut m, &["ROR 0, 300", "WAIT LIMSW, 0, 0", "GAP 1, 0", "AGP 43, 2", "STOP"], 10_000);
    assert_eq!(var(&mut m, 43), 3000);
    let mut m = module();
    m.world_mut().axes[0].home_switch = Some((-1000.0, -900.0));
    run(&mut m, &["ROL 0, 300", "WAIT REFSW, 0, 0", "MST 0", "GAP 1, 0", "AGP 44, 2", "STOP"], 10_000);
    let p = var(&mut m, 44);
    assert!((-1000..=-900).contains(&p) || (p - -900).abs() < 20, "{p}");
}

#[test]
fn rst_restarts_and_clears() {
    let mut m = module();
    // 0 CALCV ADD 50 1; 1 GGP 50 2; 2 COMP 3; 3 JC GE 6; 4 CSUB 7; 5 STOP; 6 STOP; 7 RST 0
    run(&mut m, &["CALCV ADD, 50, 1", "GGP 50, 2", "COMP 3", "JC GE, 6", "CSUB 7", "STOP", "STOP", "RST 0"], 10);
    assert_eq!(var(&mut m, 50), 3);
    assert!(m.program().stack.is_empty());
}

#[test]
fn timer_interrupt_fires_every_period() {
    let mut m = module();
    // 0 VECT 0, 6; 1 SGP 0, 3, 100; 2 EI 0; 3 EI 255; 4 JA 4; 6 CALCV ADD, 60, 1; 7 RETI
    run(&mut m, &["VECT 0, 6", "SGP 0, 3, 100", "EI 0", "EI 255", "JA 4", "STOP", "CALCV ADD, 60, 1", "RETI"], 1050);
    assert_eq!(var(&mut m, 60), 10);
}

#[test]
fn interrupt_priority_no_nesting_and_context_restore() {
    let mut m = module();
    // Timers 0 and 1 both at 100 ms: timer 0 (higher priority) first, then 1,
    // never nested. Each handler appends its number to var 70 (×10 + n).
    let prog = [
        "VECT 0, 10",
        "VECT 1, 20",
        "SGP 0, 3, 100",
        "SGP 1, 3, 100",
        "EI 0",
        "EI 1",
        "CALC LOAD, 1234",
        "EI 255",
        "JA 8",
        "STOP",
        // 10: handler 0
        "CALCV MUL, 70, 10",
        "CALCV ADD, 70, 1",
        "CALC LOAD, -1",
        "RETI",
        "STOP",
        "STOP",
        "STOP",
        "STOP",
        "STOP",
        "STOP",
        // 20: handler 1
        "CALCV MUL, 70, 10",
        "CALCV ADD, 70, 2",
        "CALC LOAD, -2",
        "RETI",
    ];
    run(&mut m, &prog, 105);
    assert_eq!(var(&mut m, 70), 12, "timer 0 before timer 1");
    assert_eq!(m.registers().accumulator, 1234, "RETI restored the accumulator");
}

#[test]
fn input_change_interrupt_with_trigger_transition() {
    let mut m = module();
    // Input 1 (interrupt 40), trigger high→low only (2).
    run(&mut m, &["VECT 40, 6", "SGP 40, 3, 2", "EI 40", "EI 255", "JA 4", "STOP", "CALCV ADD, 80, 1", "RETI"], 5);
    m.world_mut().set_digital(1, true);
    m.advance(5 * MS);
    assert_eq!(var(&mut m, 80), 0, "rising edge is not selected");
    m.world_mut().set_digital(1, false);
    m.advance(5 * MS);
    assert_eq!(var(&mut m, 80), 1);
}

#[test]
fn target_reached_and_stop_switch_interrupts() {
    let mut m = module();
    m.world_mut().axes[0].right_switch = Some(20000.0);
    reply(&mut m, "SAP 4, 0, 2047");
    reply(&mut m, "SGP 28, 3, 1");
    let prog = [
        "VECT 3, 8",
        "VECT 28, 10",
        "EI 3",
        "EI 28",
        "EI 255",
        "MVP ABS, 0, 10000",
        "JA 6",
        "STOP",
        "CALCV ADD, 90, 1", // 8: target reached
        "RETI",
        "CALCV ADD, 91, 1", // 10: right switch
        "RETI",
    ];
    run(&mut m, &prog, 3000);
    assert_eq!(var(&mut m, 90), 1);
    reply(&mut m, "MVP ABS, 0, 30000");
    m.advance(3000 * MS);
    assert_eq!(var(&mut m, 91), 1);
    assert_eq!(send(&mut m, "GAP 1, 0"), 20000);
}

#[test]
fn direct_mode_keeps_working_and_leaves_the_accumulator_alone() {
    let mut m = module();
    run(&mut m, &["CALC LOAD, 77", "WAIT TICKS, 0, 100", "AGP 5, 2", "STOP"], 10);
    assert_eq!(send(&mut m, "GAP 4, 0"), 1000);
    send(&mut m, "GGP 66, 0");
    send(&mut m, "GIO 0, 0");
    reply(&mut m, "SAP 4, 0, 1500");
    m.advance(2000 * MS);
    assert_eq!(var(&mut m, 5), 77);
}

#[test]
fn step_and_breakpoints() {
    let mut m = module();
    download(&mut m, &["CALC LOAD, 1", "CALC ADD, 2", "CALC ADD, 3", "STOP"]);
    reply(&mut m, "#130 0 0 0");
    assert_eq!(m.registers().accumulator, 1);
    reply(&mut m, "#130 0 0 0");
    assert_eq!(m.registers().accumulator, 3);
    assert_eq!(send(&mut m, "GGP 128, 0"), 2, "step mode");
    reply(&mut m, "#131 0 0 0");
    assert_eq!(m.registers().accumulator, 0);
    assert_eq!(m.program().pc, 0);
    m.set_breakpoints(&[2]);
    reply(&mut m, "#129 0 0 0");
    m.advance(10 * MS);
    assert_eq!(m.program().hit_breakpoint, Some(2));
    assert_eq!(m.registers().accumulator, 3);
    reply(&mut m, "#129 0 0 0");
    m.advance(10 * MS);
    assert_eq!(m.registers().accumulator, 6);
    assert_eq!(m.program().mode, RunMode::Stop);
}

#[test]
fn programs_persist_and_autostart() {
    let mut m = module();
    download(&mut m, &["CALCV ADD, 3, 1", "STOP"]);
    reply(&mut m, "SGP 77, 0, 1");
    reply(&mut m, "#255 0 0 1234");
    m.advance(10 * MS);
    assert_eq!(var(&mut m, 3), 1, "autostarted after the reset");
    let mut m2 = BusOfOne::new(Module::with_eeprom(m.profile().clone(), m.eeprom().clone()));
    m2.advance(10 * MS);
    assert_eq!(var(&mut m2, 3), 1);
    assert_eq!(raw(&mut m2, Instruction::new(134, 0, 0, 0))[1], 45, "CALCV stored");
}

#[test]
fn code_protection() {
    let mut m = module();
    download(&mut m, &["STOP"]);
    reply(&mut m, "SGP 81, 0, 1");
    assert_eq!(reply(&mut m, "#134 0 0 0").status, 5, "protected against reading");
    reply(&mut m, "SGP 81, 0, 2");
    assert_eq!(raw(&mut m, Instruction::new(134, 0, 0, 0))[1], 0, "lifting read protection erased the program");
    assert_eq!(reply(&mut m, "#132 0 0 0").status, 5, "protected against overwriting");
}

/// A download as TMCL-IDE makes it (docs/behaviour.md rules 93, 94): the
/// words, the STOP it appends after a program's last instruction, then a
/// NOP before 133. Every word in download mode, the NOP too, is stored at
/// the next address and answered with status 101; 135 type 0 then points
/// after the NOP; the NOP, if a program ever runs it, is skipped with
/// status 2 as any command the module does not have (rule 21).
#[test]
fn the_nop_tmcl_ide_sends_after_the_last_word_is_stored_and_skipped_when_run() {
    for profile in ["tmcm-1141", "tmcm-351", "tmcm-1310"] {
        let mut m = BusOfOne::built_in(profile);
        m.set_trace(true);
        assert_eq!(reply(&mut m, "#132 0 0 0").status, 100);
        for line in ["CALCV ADD, 1, 1", "JA 0", "STOP", "#0 0 0 0"] {
            let r = reply(&mut m, line);
            let sent = parse_line(line).unwrap();
            assert_eq!((r.status, r.opcode, r.value), (101, sent.opcode, sent.value), "{profile}: {line}");
        }
        assert_eq!(reply(&mut m, "#133 0 0 0").status, 100);
        // Stopped (the mode in the high byte), the download pointer at 4.
        assert_eq!(send(&mut m, "#135 0 0 0"), 4, "{profile}");
        let f = raw(&mut m, Instruction::new(134, 0, 0, 3));
        assert_eq!(f[1..8], [0; 7], "{profile}: the NOP is stored at address 3");
        // Run from the NOP: skipped with status 2, the program goes on.
        assert_eq!(reply(&mut m, "#129 1 0 3").status, 100);
        m.advance(MS);
        let trace = m.take_trace();
        assert_eq!((trace[0].pc, trace[0].failed), (3, Some(2)), "{profile}");
        assert_eq!(trace[1].pc, 4, "{profile}");
    }
}

#[test]
fn failed_commands_are_skipped_and_traced() {
    let mut m = module();
    m.set_trace(true);
    run(&mut m, &["SAP 4, 0, 99999", "CALC DIV, 0", "CALCV ADD, 1, 1", "STOP"], 5);
    assert_eq!(var(&mut m, 1), 1);
    let trace = m.take_trace();
    assert_eq!(trace[0].failed, Some(4));
    assert_eq!(trace[1].failed, Some(4));
    assert_eq!(trace[2].failed, None);
}

#[test]
fn random_programs_never_panic_or_hang() {
    let mut seed: u64 = 12345;
    let mut next = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed
    };
    for _ in 0..200 {
        let mut m = module();
        let words: Vec<Instruction> = (0..64)
            .map(|_| {
                let r = next();
                let opcode = [
                    1u8, 2, 3, 4, 5, 6, 9, 10, 14, 15, 19, 20, 21, 22, 23, 24, 25, 26, 27, 28, 33, 36, 37, 38, 40, 45, 48, 49, 55, 56, 57,
                    80, 200,
                ][(r % 33) as usize];
                Instruction::new(opcode, (r >> 8) as u8 % 16, (r >> 16) as u8 % 3, ((r >> 24) as i32) % 70)
            })
            .collect();
        m.load_program(&words).unwrap();
        m.start_program();
        m.advance(200 * MS);
        reply(&mut m, "#128 0 0 0");
    }
}

/// One long `advance` runs a program exactly as many short ones do: a
/// program that moves back and forth with WAIT POS counts the same number
/// of trips either way, also when a switch edge lies on a target (the home
/// switch of the built-in stage starts at 100 000).
#[test]
fn one_long_advance_equals_many_short_ones() {
    for far in [20_000, 100_000] {
        let far_line = format!("MVP ABS, 0, {far}");
        let program = [
            "SAP 4, 0, 2047",
            far_line.as_str(),
            "WAIT POS, 0, 0",
            "MVP ABS, 0, 0",
            "WAIT POS, 0, 0",
            "GGP 51, 2",
            "CALC ADD, 1",
            "AGP 51, 2",
            "JA 1",
        ];
        let stage = || {
            let profile = tmclsim_firmware::Profile::built_in("tmcm-1141").unwrap();
            BusOfOne::new(Module::with_world(profile, tmclsim_firmware::Eeprom::new("TMCM-1141"), tmclsim_firmware::World::stage(1)))
        };
        let mut long = stage();
        run(&mut long, &program, 0);
        long.advance(60_000 * MS);
        let mut short = stage();
        run(&mut short, &program, 0);
        for _ in 0..60_000 {
            short.advance(MS);
        }
        let trips = var(&mut short, 51);
        assert!(trips > 10, "the stepped module made {trips} trips to {far}");
        assert_eq!(var(&mut long, 51), trips, "trips to {far}");
        assert_eq!(send(&mut long, "GAP 1, 0"), send(&mut short, "GAP 1, 0"));
    }
}
