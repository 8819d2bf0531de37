//! The TMCM-351 by the wire, against its TMCL firmware manual V4.45
//! (rev. 1.06; "§" and "p." below are its sections and printed pages):
//! version and commands, 32-bit positions, MVP COORD motor masks, group
//! index, EEPROM lock and magic, user variables, interrupts, SAC, I/O,
//! reference search, stall detection, encoder, currents and ASCII mode.
//! Its printed frames are in the one golden table (golden.rs).

use crate::common;

use common::{BusOfOne, MS, power_cycle, reply, send, until};

use tmclsim_firmware::world::Load;
use tmclsim_firmware::{Module, World};
use tmclsim_protocol::mnemonic::parse_line;
use tmclsim_protocol::{Instruction, Request};

fn module() -> BusOfOne {
    BusOfOne::built_in("tmcm-351")
}

/// Loads a program of mnemonic lines (numeric addresses) and starts it.
fn run(m: &mut BusOfOne, lines: &[&str]) {
    let words: Vec<Instruction> = lines.iter().map(|l| parse_line(l).unwrap_or_else(|e| panic!("{l}: {e}"))).collect();
    m.load_program(&words).unwrap();
    assert_eq!(send(m, "#129 1 0 0"), 0);
}

#[test]
fn version_replies_of_the_manual() {
    // §4.6.40 p.66: type 0 is the host address and 8 characters in the
    // form of the printed "351V.442" (this firmware: 4.45), no checksum;
    // type 1 has $01 $5F (351) and the version bytes in the value.
    let mut m = module();
    let mut string = [2; 9];
    string[1..].copy_from_slice(b"351V.445");
    assert_eq!(m.handle_frame(&Request::new(1, Instruction::new(136, 0, 0, 0)).encode()), Some(string));
    assert_eq!(send(&mut m, "#136 1 0 0"), 0x015F_042D);
}

#[test]
fn the_commands_of_the_manual() {
    let mut m = module();
    // §4.4.1 p.14 and §4.4.2.7 p.16: the interrupt commands are there; EI,
    // DI and VECT work in direct mode, RETI only in a program (rule 7).
    for line in ["EI 3", "DI 3", "EI 255", "DI 255", "VECT 3, 500"] {
        assert_eq!(reply(&mut m, line).status, 100, "{line}");
    }
    assert_eq!(reply(&mut m, "RETI").status, 6);
    assert_eq!(reply(&mut m, "VECT 6, 5").status, 3, "6 is no interrupt vector of p.17");
    assert_eq!(reply(&mut m, "VECT 3, 2048").status, 4, "2048 TMCL instructions (§4 p.11)");
    // §4.6.38 p.65: 138 is there.
    assert_eq!(reply(&mut m, "#138 0 0 7").status, 100);
    assert_eq!(reply(&mut m, "#138 0 0 8").status, 4, "bits 0…2: motors 0…2");
    // Commands of other TMCL modules that §4.4.1 does not list.
    for line in [
        "CALCVV ADD, 1, 2",
        "CALCV ADD, 1, 2",
        "MVPA ABS, 0",
        "RST 0",
        "DJNZ 1, 0",
        "ROLA 0",
        "RORA 0",
        "SIV 1",
        "GIV",
        "AIV",
        "CALL ZE, 0",
    ] {
        assert_eq!(reply(&mut m, line).status, 2, "{line}");
    }
    // §4.6.1 p.22: ROR/ROL take 0…2047 on motors 0…2.
    assert_eq!(reply(&mut m, "ROR 2, 2047").status, 100);
    assert_eq!(reply(&mut m, "ROR 2, 2048").status, 4);
    assert_eq!(reply(&mut m, "ROR 3, 100").status, 4);
    assert_eq!(reply(&mut m, "GAP 1, 3").status, 4);
}

#[test]
fn positions_are_32_bit() {
    // p.80, firmware 4.37: "Positioning range enlarged: 32 Bit"; AP 0/1
    // (§5 p.67) and MVP (§4.6.4 p.25) take −2^31…2^31−1.
    let mut m = module();
    assert_eq!(reply(&mut m, "SAP 1, 0, 8388608").status, 100);
    assert_eq!(send(&mut m, "GAP 1, 0"), 8_388_608);
    assert_eq!(reply(&mut m, "MVP ABS, 0, 2147483647").status, 100);
    assert_eq!(reply(&mut m, "MVP ABS, 0, -2147483648").status, 100);
    send(&mut m, "MST 0");
    // Counting up through 2^23 no longer wraps.
    send(&mut m, "SAP 1, 1, 8388600");
    send(&mut m, "ROR 1, 10");
    m.advance(1000 * MS);
    let p = send(&mut m, "GAP 1, 1");
    assert!(p > 8_388_608, "past 2^23: {p}");
}

#[test]
fn mvp_coord_masks_interpolated_and_not() {
    for (mask, together) in [(0x87u8, false), (0x47u8, true)] {
        let mut m = module();
        // Axis 0 far, axis 1 near, axis 2 in between.
        for (a, c) in [(0, 100_000), (1, 10_000), (2, 40_000)] {
            send(&mut m, &format!("SCO 2, {a}, {c}"));
            send(&mut m, &format!("SAP 4, {a}, 1000"));
        }
        send(&mut m, &format!("MVP COORD, {mask}, 2"));
        let mut arrival = [None; 3];
        for step in 1..=20_000 {
            m.advance(MS);
            for (a, arrived) in arrival.iter_mut().enumerate() {
                if arrived.is_none() && send(&mut m, &format!("GAP 8, {a}")) == 1 {
                    *arrived = Some(step);
                }
            }
        }
        let t: Vec<i64> = arrival.iter().map(|a| a.expect("arrived")).collect();
        assert_eq!([send(&mut m, "GAP 1, 0"), send(&mut m, "GAP 1, 1"), send(&mut m, "GAP 1, 2")], [100_000, 10_000, 40_000]);
        if together {
            assert!(t.iter().all(|x| (x - t[0]).abs() <= 2), "interpolated: {t:?}");
        } else {
            assert!(t[1] < t[2] && t[2] < t[0], "each with its own ramp: {t:?}");
        }
    }
}

#[test]
fn group_index_shares_motion_commands() {
    // AP 213 (§5 p.70): motors with the same group index get ROL, ROR,
    // MST, MVP and RFS issued to one of them.
    let mut m = module();
    assert_eq!([0, 1, 2].map(|a| send(&mut m, &format!("GAP 213, {a}"))), [0, 0, 0], "no group at power-up");
    send(&mut m, "SAP 213, 0, 5");
    send(&mut m, "SAP 213, 2, 5");
    send(&mut m, "ROR 0, 300");
    assert_eq!(send(&mut m, "GAP 2, 2"), 300);
    assert_eq!(send(&mut m, "GAP 2, 1"), 0, "axis 1 is not in the group");
    send(&mut m, "MST 2");
    assert_eq!(send(&mut m, "GAP 2, 0"), 0);
    send(&mut m, "MVP ABS, 2, 1234");
    m.advance(5000 * MS);
    assert_eq!(send(&mut m, "GAP 1, 0"), 1234);
    assert_eq!(send(&mut m, "GAP 1, 2"), 1234);
    assert_eq!(send(&mut m, "GAP 1, 1"), 0);
}

#[test]
fn eeprom_lock_and_magic() {
    // GP 73 (§6.1 p.72), STAP while locked (§4.6.7 p.29), GP 64 (p.72).
    let mut m = module();
    send(&mut m, "SAP 4, 0, 1500");
    assert_eq!(send(&mut m, "GGP 73, 0"), 0);
    send(&mut m, "SGP 73, 0, 1234");
    assert_eq!(send(&mut m, "GGP 73, 0"), 1);
    assert_eq!(reply(&mut m, "STAP 4, 0").status, 5);
    assert_eq!(reply(&mut m, "STGP 3, 2").status, 5);
    assert_eq!(reply(&mut m, "SGP 75, 0, 10").status, 5, "bank 0 is stored on SGP");
    assert_eq!(reply(&mut m, "#132 0 0 0").status, 5, "no download while locked");
    assert_eq!(reply(&mut m, "SGP 73, 0, 77").status, 4);
    // The lock survives a power cycle; 4321 unlocks.
    let mut m = power_cycle(&m);
    assert_eq!(send(&mut m, "GGP 73, 0"), 1);
    send(&mut m, "SGP 73, 0, 4321");
    assert_eq!(send(&mut m, "STAP 4, 0"), 0);
    // Bank 0 64…87 print E: STGP and RSGP take them (§6.1 p.71).
    assert_eq!(reply(&mut m, "STGP 75, 0").status, 100);
    assert_eq!(reply(&mut m, "RSGP 75, 0").status, 100);
    assert_eq!(reply(&mut m, "STGP 128, 0").status, 3, "GP 128 is R only");
    // A magic other than 0xE4 re-initialises the EEPROM at the next start.
    send(&mut m, "SAP 4, 0, 1700");
    send(&mut m, "STAP 4, 0");
    send(&mut m, "SGP 64, 0, 0");
    let mut m = power_cycle(&m);
    assert_eq!(send(&mut m, "GAP 4, 0"), 1000, "factory value");
    assert_eq!(send(&mut m, "GGP 64, 0"), 0xE4);
}

#[test]
fn user_variables_0_to_55_are_stored() {
    // §6.3 p.74: 256 variables, 0…55 RWE (restored after booting),
    // 56…255 RW; GP 85 (p.73): 1 = not restored.
    let mut m = module();
    send(&mut m, "SGP 55, 2, 5555");
    send(&mut m, "SGP 56, 2, 5656");
    send(&mut m, "SGP 255, 2, -1");
    assert_eq!(send(&mut m, "STGP 55, 2"), 0);
    assert_eq!(reply(&mut m, "STGP 56, 2").status, 3, "56…255 have no E");
    let mut m = power_cycle(&m);
    assert_eq!([send(&mut m, "GGP 55, 2"), send(&mut m, "GGP 56, 2"), send(&mut m, "GGP 255, 2")], [5555, 0, 0]);
    assert_eq!(send(&mut m, "GGP 85, 0"), 0, "restored by default");
    send(&mut m, "SGP 85, 0, 1");
    let mut m = power_cycle(&m);
    assert_eq!(send(&mut m, "GGP 55, 2"), 0, "GP 85 = 1: not restored");
    assert_eq!(send(&mut m, "RSGP 55, 2"), 0);
    assert_eq!(send(&mut m, "GGP 55, 2"), 5555, "but still stored");
}

#[test]
fn the_timer_interrupt_example() {
    // §4.4.2.7.5 p.18, with the labels at their addresses: timer 0 every
    // 1000 ms toggles OUT_0 while the main loop toggles OUT_3 every 500 ms.
    let mut m = module();
    run(
        &mut m,
        &[
            "VECT 0, 9",
            "SGP 0, 3, 1000",
            "EI 0",
            "EI 255",
            "SIO 3, 2, 1", // 4: Loop
            "WAIT TICKS, 0, 50",
            "SIO 3, 2, 0",
            "WAIT TICKS, 0, 50",
            "JA 4",
            "GIO 0, 2", // 9: Timer0Irq
            "JC NZ, 13",
            "SIO 0, 2, 1",
            "RETI",
            "SIO 0, 2, 0", // 13: Out0Off
            "RETI",
        ],
    );
    // Looked at in the middle of each 500 ms phase: OUT_3 is high in the
    // first half of every second; OUT_0 goes high at 1000 ms, low at 2000.
    m.advance(250 * MS);
    let mut seen = vec![m.outputs() & 0b1001];
    for _ in 0..5 {
        m.advance(500 * MS);
        seen.push(m.outputs() & 0b1001);
    }
    assert_eq!(seen, [0b1000, 0b0000, 0b1001, 0b0001, 0b1000, 0b0000], "OUT_0 and OUT_3 at 0.25 s, 0.75 s, …");
}

#[test]
fn interrupts_of_the_three_axes_and_the_inputs() {
    // Vectors of p.17: 5 = target position reached 2, 44 = input change 5
    // (bank 3 GP 44 = 3: both transitions, §6.4 p.75), 29 = left stop
    // switch 1 (GP 29 = 1: low-high).
    let mut m = module();
    m.world_mut().axes[1].left_switch = Some(-500.0);
    run(
        &mut m,
        &[
            "VECT 5, 12",
            "VECT 44, 16",
            "VECT 29, 20",
            "SGP 44, 3, 3",
            "SGP 29, 3, 1",
            "EI 5",
            "EI 44",
            "EI 29",
            "EI 255",
            "MVP ABS, 2, 1000",
            "JA 10", // 10: the main loop
            "STOP",
            "GGP 1, 2", // 12: target reached 2
            "CALC ADD, 1",
            "AGP 1, 2",
            "RETI",
            "GGP 0, 2", // 16: input change 5
            "CALC ADD, 1",
            "AGP 0, 2",
            "RETI",
            "GGP 2, 2", // 20: left stop switch 1
            "CALC ADD, 1",
            "AGP 2, 2",
            "RETI",
        ],
    );
    let var = |m: &mut BusOfOne, n: u8| send(m, &format!("GGP {n}, 2"));
    assert!(until(&mut m, 5000, |m| var(m, 1) == 1).is_some(), "motor 2 arrived");
    m.world_mut().set_digital(5, true);
    m.advance(10 * MS);
    m.world_mut().set_digital(5, false);
    m.advance(10 * MS);
    assert_eq!(var(&mut m, 0), 2, "both edges of IN_5");
    assert_eq!(var(&mut m, 2), 0);
    send(&mut m, "ROL 1, 500");
    assert!(until(&mut m, 5000, |m| var(m, 2) == 1).is_some(), "axis 1 met its left stop switch");
    assert_eq!(var(&mut m, 1), 1, "the other axes raised nothing");
}

#[test]
fn sac_talks_to_a_shift_register() {
    // §4.6.24 p.49: bus numbers 0, 2 and 3 are SPI_SEL0…2 with the value
    // sent; 128, 130 and 131 send the accumulator; 1…4 bytes.
    let mut m = module();
    assert_eq!(send(&mut m, "SAC 0, 2, 4660"), 0);
    assert_eq!(send(&mut m, "SAC 0, 2, 0"), 4660);
    assert_eq!(send(&mut m, "SAC 2, 1, 511"), 0);
    assert_eq!(send(&mut m, "SAC 2, 1, 0"), 255, "one byte");
    assert_eq!(send(&mut m, "SAC 3, 4, -1"), 0, "SPI_SEL2 is a device of its own");
    assert_eq!(send(&mut m, "SAC 3, 4, 0"), -1);
    assert_eq!(reply(&mut m, "SAC 1, 1, 0").status, 3, "bus 1 is not in the manual's table");
    assert_eq!(reply(&mut m, "SAC 4, 1, 0").status, 3);
    assert_eq!(reply(&mut m, "SAC 0, 5, 0").status, 4);
    assert_eq!(reply(&mut m, "SAC 0, 0, 0").status, 4);
    // In a program, bus 128 sends the accumulator and the answer lands in it.
    run(&mut m, &["CALC LOAD, 4242", "SAC 128, 2, 0", "STOP"]);
    m.advance(10 * MS);
    assert_eq!(m.registers().accumulator, 0, "the device answered what the last direct transfer sent (0)");
    assert_eq!(send(&mut m, "SAC 0, 2, 0"), 4242, "and kept the accumulator's 4242");
}

#[test]
fn inputs_outputs_analog_range_and_pullups() {
    let mut m = module();
    // §4.6.14 p.37: SIO 255, 2 sets OUT_0…OUT_7 as bits; bank 2 reads them back (p.40).
    send(&mut m, "SIO 255, 2, 170");
    assert_eq!(m.outputs(), 170);
    assert_eq!(send(&mut m, "GIO 7, 2"), 1);
    assert_eq!(reply(&mut m, "SIO 8, 2, 1").status, 3, "OUT_0…OUT_7");
    // p.39: GIO 255, 0 reads IN_0…IN_5, ADIN_6, ADIN_7 as bits 0…7.
    m.world_mut().set_digital(7, true);
    m.world_mut().set_digital(0, true);
    assert_eq!(send(&mut m, "GIO 255, 0"), 0x81);
    // p.40: AIN_0…AIN_3 are 10-bit, 0…1023: the world's 12-bit 3000 reads 750.
    m.world_mut().set_analog(3, 3000);
    assert_eq!(send(&mut m, "GIO 3, 1"), 750);
    assert_eq!(send(&mut m, "GIO 3, 0"), 0, "IN_3 is another pin than AIN_3");
    // ADIN_7 is one line, read digitally in bank 0 and analog in bank 1.
    assert_eq!(send(&mut m, "GIO 7, 1"), 1023);
    m.world_mut().set_analog(7, 1000);
    assert_eq!((send(&mut m, "GIO 7, 0"), send(&mut m, "GIO 7, 1")), (0, 250));
    // §4.6.14 p.37: SIO 8, 0 selects 3.3 V (0) or 10 V (1): the same pin
    // voltage reads 10/3.3 times larger on the 3.3 V range, up to 1023.
    send(&mut m, "SIO 8, 0, 0");
    assert_eq!(send(&mut m, "GIO 3, 1"), 1023, "3000 of 4095 at 10 V is above 3.3 V");
    m.world_mut().set_analog(3, 1000);
    assert_eq!(send(&mut m, "GIO 3, 1"), 757, "250 × 10/3.3");
    send(&mut m, "SIO 8, 0, 1");
    assert_eq!(send(&mut m, "GIO 3, 1"), 250);
    assert_eq!(reply(&mut m, "SIO 8, 0, 2").status, 4);
    // The pull-ups: one bit an input, 0…255.
    assert_eq!(m.pullup_mask(), 255);
    send(&mut m, "SIO 0, 0, 63");
    assert_eq!(m.pullup_mask(), 63);
    assert_eq!(reply(&mut m, "SIO 0, 0, 256").status, 4);
    assert_eq!(reply(&mut m, "SIO 1, 0, 1").status, 3, "bank 0 has the pull-ups (0) and the range (8)");
    // p.40: GIO 4, 1 and 5, 1 are the supply and the temperature (0…1023).
    assert_eq!(send(&mut m, "GIO 4, 1"), 676, "24 V");
    m.world_mut().supply_decivolts = 120;
    assert_eq!(send(&mut m, "GIO 4, 1"), 338, "12 V");
    assert_eq!(send(&mut m, "GIO 5, 1"), 279, "40 °C");
    m.world_mut().temperature = 90.0;
    assert_eq!(send(&mut m, "GIO 5, 1"), 434, "90 °C");
    assert_eq!(reply(&mut m, "GIO 8, 1").status, 3, "no port 8 in bank 1");
}

#[test]
fn reference_search_modes_speeds_and_last_position() {
    // §7.1 p.76: the search speed is AP 4's unless AP 194 reduces it; the
    // switch speed a quarter of AP 4 by default.
    let mut m = module();
    let ap4 = send(&mut m, "GAP 4, 0");
    assert_eq!((send(&mut m, "GAP 194, 0"), send(&mut m, "GAP 195, 0")), (ap4, ap4 / 4));
    for (mode, zero, distance) in [(1, -20_000.0, None), (2, -20_000.0, Some(50_000)), (3, 6_000.0, Some(24_000))] {
        let mut m = module();
        let w = &mut m.world_mut().axes[1];
        w.left_switch = Some(-20_000.0);
        w.right_switch = Some(30_000.0);
        w.home_switch = Some((5_000.0, 6_000.0));
        send(&mut m, &format!("SAP 193, 1, {mode}"));
        send(&mut m, "SAP 194, 1, 2000");
        send(&mut m, "SAP 195, 1, 200");
        // AP 12 and 13 do not influence the search (§7.1).
        send(&mut m, "SAP 12, 1, 1");
        send(&mut m, "SAP 13, 1, 1");
        send(&mut m, "SAP 1, 1, 777");
        send(&mut m, "RFS START, 1");
        let ended = until(&mut m, 60_000, |m| send(m, "RFS STATUS, 1") == 0);
        assert!(ended.is_some(), "mode {mode} ended");
        assert_eq!(send(&mut m, "GAP 1, 1"), 0);
        assert!((m.mechanical_position(1) - zero).abs() <= 0.5, "mode {mode}: {}", m.mechanical_position(1));
        // p.80, 4.41: AP 197 is the count just before it was set to zero.
        let last = send(&mut m, "GAP 197, 1");
        assert!((f64::from(last) - (zero + 777.0)).abs() <= 1.0, "mode {mode}: AP 197 = {last}");
        if let Some(d) = distance {
            assert_eq!(send(&mut m, "GAP 196, 1"), d, "mode {mode}");
        }
    }
    let mut m = module();
    assert_eq!(reply(&mut m, "SAP 193, 0, 4").status, 4, "the 351 has modes 1–3");
}

#[test]
fn the_switch_readings() {
    // §5 p.68: AP 9 is the reference (left) switch, AP 10 the right one,
    // AP 11 the left limit switch in three-switch mode; §7.1 p.76: the
    // reference switch is in series with the left limit switch (STOP_L).
    let mut m = module();
    let w = &mut m.world_mut().axes[0];
    w.left_switch = Some(-20_000.0);
    w.right_switch = Some(30_000.0);
    w.home_switch = Some((5_000.0, 6_000.0));
    let read = |m: &mut BusOfOne| [9, 10, 11].map(|n| send(m, &format!("GAP {n}, 0")));
    assert_eq!(read(&mut m), [0, 0, 0]);
    for (at, expected) in [(5_500.0, [1, 0, 0]), (-25_000.0, [1, 0, 1]), (35_000.0, [0, 1, 0])] {
        m.place_carriage(0, at);
        assert_eq!(read(&mut m), expected, "at {at}");
    }
}

#[test]
fn stall_detection_rests_while_the_motor_accelerates() {
    // §7.3 p.78: the motor stops when the load value exceeds AP 205, but
    // not while it accelerates or decelerates; AP 207 bit 1 (p.69) tells,
    // until the next movement command.
    let mut m = module();
    send(&mut m, "SAP 6, 0, 255");
    send(&mut m, "SAP 5, 0, 20");
    m.world_mut().axes[0].loads = vec![Load { torque: 60.0, ..Load::default() }];
    send(&mut m, "SAP 205, 0, 1");
    send(&mut m, "ROR 0, 500");
    m.advance(20 * MS);
    let load = send(&mut m, "GAP 206, 0");
    assert!(load > 1, "loaded: {load}");
    assert!(send(&mut m, "GAP 3, 0") > 0, "still accelerating: no stall stop");
    assert_eq!(send(&mut m, "GAP 207, 0"), 0);
    let stopped = until(&mut m, 10_000, |m| send(m, "GAP 3, 0") == 0);
    assert!(stopped.is_some(), "stopped once at speed");
    assert_eq!(send(&mut m, "GAP 207, 0"), 2);
    assert_eq!(send(&mut m, "GAP 207, 0"), 2, "reading does not clear it");
    m.world_mut().axes[0].loads.clear();
    send(&mut m, "ROR 0, 100");
    assert_eq!(send(&mut m, "GAP 207, 0"), 0, "the next movement command does");
}

#[test]
fn stall_detection_finds_the_reference_point() {
    // §7.3 p.78's program: run left into a hard stop with stall detection
    // on, wait until the motor stands, call that position zero. (With a
    // WAIT before the loop: 25 µs after ROL the ramp has not yet made the
    // motor's speed read above 0, and the loop would end at once.)
    let mut m = module();
    m.world_mut().axes[0].loads = vec![Load { torque: 500.0, to: Some(-30_000.0), ..Load::default() }];
    run(&mut m, &["SAP 205, 0, 5", "ROL 0, 500", "WAIT TICKS, 0, 10", "GAP 3, 0", "COMP 0", "JC NE, 3", "SAP 1, 0, 0", "STOP"]);
    assert!(until(&mut m, 60_000, |m| !m.program().is_running()).is_some(), "the program ended");
    assert_eq!(send(&mut m, "GAP 1, 0"), 0);
    let at = m.mechanical_position(0);
    assert!((at + 30_000.0).abs() < 1000.0, "at the hard stop: {at}");
}

#[test]
fn encoder_prescaler_and_deviation_stop() {
    let mut m = BusOfOne::new(Module::with_world(
        tmclsim_firmware::Profile::built_in("tmcm-351").unwrap(),
        tmclsim_firmware::Eeprom::new("TMCM-351"),
        World::free(3),
    ));
    // §2.2.2 p.9's setup: 2000 encoder steps a turn, 64 µsteps,
    // 68672 = ×6.4 (§7.2 p.77): 12800 both ways.
    send(&mut m, "SAP 210, 0, 68672");
    send(&mut m, "SAP 209, 0, 0");
    send(&mut m, "SAP 140, 0, 6");
    send(&mut m, "SAP 212, 0, 250");
    send(&mut m, "SAP 4, 0, 2047");
    send(&mut m, "SAP 6, 0, 255");
    send(&mut m, "MVP ABS, 0, 128000");
    m.advance(20_000 * MS);
    assert_eq!(send(&mut m, "GAP 1, 0"), 128_000);
    assert!((send(&mut m, "GAP 209, 0") - 128_000).abs() <= 1, "encoder matches 12800 steps per turn");
    // §7.2: 1600 = ×3.125, and bit 0 counts the other way.
    send(&mut m, "SAP 210, 0, 1600");
    assert_eq!(send(&mut m, "GAP 209, 0"), 62_500, "10 turns × 2000 × 3.125");
    send(&mut m, "SAP 210, 0, 1601");
    assert_eq!(send(&mut m, "GAP 209, 0"), -62_500);
    send(&mut m, "SAP 210, 0, 68672");
    // Obstructed: the motor loses steps, the deviation stops it (AP 212,
    // §5 p.70) and AP 207 bit 0 says why (p.69).
    m.world_mut().axes[0].loads = vec![Load { torque: 500.0, ..Load::default() }];
    send(&mut m, "MVP ABS, 0, 0");
    m.advance(2000 * MS);
    assert_eq!(send(&mut m, "GAP 3, 0"), 0);
    let deviation = (send(&mut m, "GAP 1, 0") - send(&mut m, "GAP 209, 0")).abs();
    assert!(deviation > 250 && deviation < 5000, "stopped past the limit: {deviation}");
    assert_eq!(send(&mut m, "GAP 207, 0"), 1);
}

#[test]
fn currents_boost_standby_and_freewheeling() {
    let mut m = module();
    send(&mut m, "SAP 6, 0, 200");
    send(&mut m, "SAP 7, 0, 40");
    send(&mut m, "SAP 200, 0, 255");
    send(&mut m, "SAP 5, 0, 10");
    // AP 200 (p.69): the boost current while accelerating, AP 6 after.
    send(&mut m, "ROR 0, 300");
    m.advance(MS);
    assert_eq!(m.motor_current(0), 255, "boost");
    assert!(until(&mut m, 10_000, |m| m.motor_current(0) == 200).is_some(), "run current at speed");
    // AP 214 (p.70): standby current after 200 × 10 ms at rest (docs/behaviour.md rule 95).
    assert_eq!(send(&mut m, "GAP 214, 0"), 200);
    send(&mut m, "MST 0");
    assert!(until(&mut m, 10_000, |m| m.actual_speed(0) == 0).is_some());
    m.advance(1900 * MS);
    assert_eq!(m.motor_current(0), 200, "not yet");
    m.advance(200 * MS);
    assert_eq!(m.motor_current(0), 40, "standby");
    // AP 204 (p.69) counts ms: 500 cuts the current 0.5 s after the stop.
    send(&mut m, "SAP 204, 0, 500");
    send(&mut m, "ROR 0, 300");
    m.advance(2000 * MS);
    send(&mut m, "MST 0");
    assert!(until(&mut m, 10_000, |m| m.actual_speed(0) == 0).is_some());
    m.advance(450 * MS);
    assert_eq!(m.motor_current(0), 200);
    m.advance(100 * MS);
    assert_eq!(m.motor_current(0), 0, "freewheeling after 500 ms");
}

#[test]
fn ascii_examples_of_the_manual() {
    let mut m = module();
    send(&mut m, "#139 0 0 0");
    let mut text = |line: &str| {
        let mut out = Vec::new();
        for b in line.bytes() {
            m.ascii_byte(b, &mut out);
        }
        String::from_utf8(out).unwrap()
    };
    // §4.5.1 p.20's command lines and §4.5.2's reply.
    assert!(text("AMVP ABS, 1, 50000\r").ends_with("BA 100 50000\r"));
    assert!(text("A MVP ABS, 1, 50000\r").ends_with("BA 100 50000\r"));
    assert!(text("AROL 2, 500\r").ends_with("BA 100 500\r"));
    assert!(text("A MST 1\r").ends_with("BA 100 0\r"));
    assert!(text("ASAP 1, 1, -5000\r").ends_with("BA 100 -5000\r"));
    assert_eq!(text("AGAP 1, 1\r"), "AGAP 1, 1\rBA 100 -5000\r");
    // §4.5.3: SAC is not in V4.45's list (rev. 1.03 had it).
    assert!(text("ASAC 0, 1, 7\r").contains("BA 2 "), "SAC is refused in ASCII mode");
    assert!(text("ABIN\r").ends_with("BA 100 0\r"));
    assert!(!m.ascii_mode());
}
