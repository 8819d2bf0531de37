//! `next_deadline` is exact: a module says when it next does something on
//! its own (end of a WAIT, a timer, an arrival, a switch edge), never a
//! polling period, and one long `advance` meets the same moments.

use crate::common;

use common::{BusOfOne, MS, send};
use tmclsim_protocol::{Instruction, mnemonic};

fn program(m: &mut BusOfOne, lines: &[&str]) {
    let words: Vec<Instruction> = lines.iter().map(|l| mnemonic::parse_line(l).expect(l)).collect();
    m.load_program(&words).unwrap();
    m.start_program();
}

#[test]
fn an_idle_module_has_no_deadline() {
    let m = BusOfOne::built_in("tmcm-1141");
    assert_eq!(m.next_deadline(), None);
}

#[test]
fn a_program_in_wait_ticks_sleeps_until_the_wait_ends() {
    let mut m = BusOfOne::built_in("tmcm-1141");
    // Loop: WAIT TICKS, 0, 1000 (10 s).
    program(&mut m, &["WAIT TICKS, 0, 1000", "JA 0"]);
    m.advance(1);
    assert_eq!(m.next_deadline(), Some(10_000 * MS), "the end of the WAIT, not a millisecond later");
    m.advance_to(10_000 * MS);
    // JA is due now (at 10 s), the next WAIT 25 µs later, then 10 s.
    assert_eq!(m.next_deadline(), Some(10_000 * MS));
    m.advance(1);
    assert_eq!(m.next_deadline(), Some(10_000 * MS + 25_000));
    m.advance_to(10_000 * MS + 25_000 + 1);
    assert_eq!(m.next_deadline(), Some(20_000 * MS + 25_000));
}

#[test]
fn a_timer_interrupt_is_a_deadline() {
    let mut m = BusOfOne::built_in("tmcm-1141");
    // Timer 0 every 250 ms; the main loop waits 10 s.
    program(&mut m, &["VECT 0, 4", "EI 0", "EI 255", "WAIT TICKS, 0, 1000", "RETI"]);
    send(&mut m, "SGP 0, 3, 250");
    m.advance(MS);
    // SGP came after start: the timer counts from the first look at it.
    let d = m.next_deadline().unwrap();
    assert!((250 * MS..=251 * MS).contains(&d), "the timer's firing, not the WAIT's end: {d}");
    m.advance_to(d);
    m.advance(1);
    // The handler ran (RETI back into the WAIT); next: the following firing.
    let next = m.next_deadline().unwrap();
    assert_eq!(next, d + 250 * MS);
}

#[test]
fn a_move_with_a_138_event_wakes_at_the_arrival() {
    let mut m = BusOfOne::built_in("tmcm-1141");
    send(&mut m, "#138 0 0 1");
    send(&mut m, "MVP ABS, 0, 51200");
    let d = m.next_deadline().expect("arrival");
    m.advance_to(d - 1_000);
    assert!(!m.has_events());
    m.advance_to(d);
    assert!(m.has_events(), "the event is out at the deadline");
    assert_eq!(send(&mut m, "GAP 1, 0"), 51200);
}

#[test]
fn wait_refsw_ends_at_the_home_switch_edge() {
    let mut m = BusOfOne::built_in("tmcm-1141");
    // Home switch between 100 000 and 110 000 µsteps; constant speed.
    m.world_mut().axes[0].home_switch = Some((100_000.0, 110_000.0));
    program(&mut m, &["ROR 0, 2047", "WAIT REFSW, 0, 0", "MST 0", "STOP"]);
    m.advance(MS);
    assert!(m.program().wait.is_some());
    let edge = m.next_deadline().expect("the edge");
    assert!(!m.switches(0).2);
    m.advance_to(edge);
    assert!(m.switches(0).2, "pressed at the deadline");
    m.advance(100_000);
    assert!(!m.program().is_running(), "the program stopped right after the edge");
    // The motor stopped within the MST's ramp of the edge, not 1 ms later.
    let p = send(&mut m, "GAP 1, 0");
    assert!(p >= 100_000, "{p}");
}

#[test]
fn a_polling_loop_leaves_when_the_move_ends_however_time_is_sliced() {
    // GAP 8 / JC polls while the motor moves; the loop reads the tick
    // timer when it leaves. WAIT POS gives the arrival itself.
    let polling = ["MVP ABS, 0, 51200", "GAP 8, 0", "JC ZE, 1", "GGP 132, 0", "STOP"];
    let waiting = ["MVP ABS, 0, 51200", "WAIT POS, 0, 0", "GGP 132, 0", "STOP"];
    let run = |lines: &[&str], slice: u64| {
        let mut m = BusOfOne::built_in("tmcm-1141");
        program(&mut m, lines);
        let mut t = 0;
        while t < 20_000 * MS {
            t += slice;
            m.advance_to(t);
        }
        (m.registers().accumulator, m.program().executed, m.actual_position(0))
    };
    let (arrival_ms, _, _) = run(&waiting, 20_000 * MS);
    let (left_ms, executed, position) = run(&polling, 20_000 * MS);
    assert_eq!(position, 51200);
    assert!((arrival_ms..=arrival_ms + 1).contains(&left_ms), "polling left at {left_ms} ms, the move ended at {arrival_ms} ms");
    // One GAP and one JC every 50 µs until then.
    let pairs = (executed - 3) / 2;
    assert!((pairs * 50_000).abs_diff(left_ms as u64 * MS) <= MS, "{pairs} polls in {left_ms} ms");
    for slice in [MS, 25_000, 77_777] {
        assert_eq!(run(&polling, slice), (left_ms, executed, position), "sliced in {slice} ns");
    }
}

#[test]
fn a_wait_past_the_end_of_the_clock_s_range_waits_until_the_end() {
    // `Loop: WAIT TICKS, 0, 2147483647 / JA Loop` near the last nanosecond
    // the clock holds: each WAIT would end past it; the deadline saturates
    // (docs/behaviour.md rule 84), so the program waits instead of looping.
    use tmclsim_firmware::{Bus, Module};
    use tmclsim_protocol::mnemonic::parse_line;
    let words: Vec<_> = ["WAIT TICKS, 0, 2147483647", "JA 0"].iter().map(|l| parse_line(l).unwrap()).collect();
    let mut m = Module::built_in("tmcm-1141").unwrap();
    m.load_program(&words).unwrap();
    m.start_program();
    let mut bus = Bus::single(m);
    let end = u64::MAX - 1;
    bus.advance_to(end - 30_000_000_000_000_000);
    let before = bus.module(0).program().executed;
    bus.advance_to(end);
    let after = bus.module(0).program().executed;
    assert!(after - before <= 4, "{} instructions in the last 3·10^16 ns: the WAIT ended early", after - before);
    assert_eq!(bus.now_ns(), end);
}
