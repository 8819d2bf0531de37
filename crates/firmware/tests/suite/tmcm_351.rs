//! The TMCM-351: golden frames of its manual, three axes, 24-bit
//! positions, MVP COORD motor masks, group index, EEPROM lock and magic,
//! SAC, the commands it lacks, its reference search, stall detection and
//! encoders.

use crate::common;

use common::{BusOfOne, MS, hex, reply, send};

use tmclsim_firmware::world::Load;
use tmclsim_firmware::{Module, World};
use tmclsim_protocol::Request;
use tmclsim_protocol::mnemonic::parse_line;

fn module() -> BusOfOne {
    BusOfOne::built_in("tmcm-351")
}

#[test]
fn golden_frames_of_the_351_manual() {
    let golden = [
        ("ROL 1, 1200", "01 02 00 01 00 00 04 B0 B8"),
        ("MST 1", "01 03 00 01 00 00 00 00 05"),
        ("MVP ABS, 1, 90000", "01 04 00 01 00 01 5F 90 F6"),
        ("MVP REL, 0, -1000", "01 04 01 00 FF FF FC 18 18"),
        ("SAP 6, 1, 200", "01 05 06 01 00 00 00 C8 D5"),
        ("GAP 1, 2", "01 06 01 02 00 00 00 00 0A"),
        ("STAP 4, 1", "01 07 04 01 00 00 00 00 0D"),
        ("RSAP 6, 1", "01 08 06 01 00 00 00 00 10"),
        ("SGP 66, 0, 3", "01 09 42 00 00 00 00 03 4F"),
        ("GGP 66, 0", "01 0A 42 00 00 00 00 00 4D"),
        ("STGP 42, 2", "01 0B 2A 02 00 00 00 00 38"),
        ("RFS START, 1", "01 0D 00 01 00 00 00 00 0F"),
        ("SIO 7, 2, 1", "01 0E 07 02 00 00 00 01 19"),
        ("ROR 2, 350", "01 01 00 02 00 00 01 5E 63"),
        ("RSGP 66, 0", "01 0C 42 00 00 00 00 00 4F"),
        ("MVP COORD, $47, 2", "01 04 02 47 00 00 00 02 50"),
        ("MVP COORD, $87, 5", "01 04 02 87 00 00 00 05 93"),
    ];
    for (line, bytes) in golden {
        assert_eq!(Request::new(1, parse_line(line).unwrap()).encode(), hex(bytes), "{line}");
    }
    // Replies printed: GAP 1, 2 with 711 and GGP 66, 0 with 1.
    let mut m = module();
    send(&mut m, "SAP 1, 2, 711");
    assert_eq!(m.handle_frame(&hex("01 06 01 02 00 00 00 00 0A")), Some(hex("02 01 64 06 00 00 02 C7 36")));
    assert_eq!(m.handle_frame(&hex("01 0A 42 00 00 00 00 00 4D")), Some(hex("02 01 64 0A 00 00 00 01 72")));
    // Every printed request is accepted.
    for (line, _) in golden {
        // (STGP/RSGP 66: bank 0 is stored automatically, no E access.)
        if !line.starts_with("RFS") && !line.starts_with("SGP 66") && !line.starts_with("RSGP") {
            assert!(reply(&mut m, line).status >= 100, "{line}");
        }
    }
}

#[test]
fn examples_of_the_v4_45_manual() {
    // 4.6.15: GIO 0, 1 and its reply, the 10-bit value 506 (the world's
    // 12-bit 2024 at the module's resolution).
    let mut m = module();
    assert_eq!(Request::new(1, parse_line("GIO 0, 1").unwrap()).encode(), hex("01 0F 00 01 00 00 00 00 11"));
    m.world_mut().set_analog(0, 2024);
    assert_eq!(m.handle_frame(&hex("01 0F 00 01 00 00 00 00 11")), Some(hex("02 01 64 0F 00 00 01 FA 71")));
    // 4.6.5: SAP 6, 0, 128 (the manual prints the value byte as $12; 128 is
    // $80, checksum $8C).
    assert_eq!(Request::new(1, parse_line("SAP 6, 0, 128").unwrap()).encode(), hex("01 05 06 00 00 00 00 80 8C"));
    assert_eq!(m.handle_frame(&hex("01 05 06 00 00 00 00 80 8C")), Some(hex("02 01 64 05 00 00 00 80 EC")));
    assert_eq!(send(&mut m, "GAP 6, 0"), 128);
    // 4.6.1: ROR/ROL take 0…2047 on motors 0…2.
    assert_eq!(reply(&mut m, "ROR 2, 2047").status, 100);
    assert_eq!(reply(&mut m, "ROR 2, 2048").status, 4);
    assert_eq!(reply(&mut m, "ROR 3, 100").status, 4);
    send(&mut m, "MST 2");
    // Title page: firmware V4.45, in both forms of 136.
    assert_eq!(send(&mut m, "#136 1 0 0"), 351 << 16 | 4 << 8 | 45);
    let mut string = [2; 9];
    string[1..].copy_from_slice(b"0351V445");
    assert_eq!(m.handle_frame(&hex("01 88 00 00 00 00 00 00 89")), Some(string));
    // No supply voltage port was found in either edition: GIO 8, 1 is a
    // port the module lacks.
    assert_eq!(reply(&mut m, "GIO 8, 1").status, 3);
}

#[test]
fn commands_the_351_lacks_answer_status_2() {
    let mut m = module();
    for line in [
        "EI 0",
        "DI 0",
        "VECT 0, 5",
        "RETI",
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
        "#138 1 0 1",
    ] {
        assert_eq!(reply(&mut m, line).status, 2, "{line}");
    }
    assert_eq!(reply(&mut m, "GAP 1, 3").status, 4, "three axes: 0…2");
}

#[test]
fn positions_are_24_bit_and_wrap() {
    let mut m = module();
    assert_eq!(reply(&mut m, "MVP ABS, 0, 8388608").status, 4);
    assert_eq!(reply(&mut m, "SAP 1, 0, 8388608").status, 4);
    send(&mut m, "SAP 4, 0, 2047");
    send(&mut m, "SAP 1, 0, 8388000");
    // 8388000 → −8388000 is 608 µsteps forward through the wrap.
    send(&mut m, "MVP ABS, 0, -8388000");
    m.advance(1000 * MS);
    assert_eq!(send(&mut m, "GAP 1, 0"), -8388000);
    assert!((m.axis(0).motion.x - 8_388_608.0 - 8_388_608.0 + 8_388_000.0).abs() < 1.0 || m.axis(0).motion.x > 8_388_000.0);
    // Counting up through 2^23 − 1 wraps to −2^23.
    send(&mut m, "SAP 1, 1, 8388600");
    send(&mut m, "ROR 1, 10");
    m.advance(1000 * MS);
    let p = send(&mut m, "GAP 1, 1");
    assert!(p < 0, "wrapped: {p}");
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
    let mut m = module();
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
    let mut m = module();
    send(&mut m, "SAP 4, 0, 1500");
    send(&mut m, "SGP 73, 0, 1234");
    assert_eq!(send(&mut m, "GGP 73, 0"), 1);
    assert_eq!(reply(&mut m, "STAP 4, 0").status, 5);
    assert_eq!(reply(&mut m, "STGP 3, 2").status, 5);
    assert_eq!(reply(&mut m, "SGP 75, 0, 10").status, 5, "bank 0 is stored on SGP");
    assert_eq!(reply(&mut m, "#132 0 0 0").status, 5, "no download while locked");
    assert_eq!(reply(&mut m, "SGP 73, 0, 77").status, 4);
    // The lock survives a power cycle; 4321 unlocks.
    let mut m = BusOfOne::new(Module::with_eeprom(m.profile().clone(), m.eeprom().clone()));
    assert_eq!(send(&mut m, "GGP 73, 0"), 1);
    send(&mut m, "SGP 73, 0, 4321");
    assert_eq!(send(&mut m, "STAP 4, 0"), 0);
    // A magic other than 0xE4 re-initialises the EEPROM at the next start.
    send(&mut m, "SAP 4, 0, 1700");
    send(&mut m, "STAP 4, 0");
    send(&mut m, "SGP 64, 0, 0");
    let mut m = BusOfOne::new(Module::with_eeprom(m.profile().clone(), m.eeprom().clone()));
    assert_eq!(send(&mut m, "GAP 4, 0"), 1000, "factory value");
    assert_eq!(send(&mut m, "GGP 64, 0"), 0xE4);
}

#[test]
fn sac_talks_to_a_shift_register() {
    // V4.45 §4.6.24 (p.49): bus numbers 0, 2 and 3 are SPI_SEL0…2 with the
    // value sent; 128, 130 and 131 send the accumulator; 1…4 bytes.
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
    let words = ["CALC LOAD, 4242", "SAC 128, 2, 0", "STOP"].map(|l| parse_line(l).unwrap());
    m.load_program(&words).unwrap();
    send(&mut m, "#129 1 0 0");
    m.advance(10 * MS);
    assert_eq!(m.registers().accumulator, 0, "the device answered what the last direct transfer sent (0)");
    assert_eq!(send(&mut m, "SAC 0, 2, 0"), 4242, "and kept the accumulator's 4242");
}

#[test]
fn eight_inputs_four_analog_eight_outputs() {
    let mut m = module();
    send(&mut m, "SIO 255, 2, 170");
    assert_eq!(m.outputs(), 170);
    assert_eq!(send(&mut m, "GIO 7, 2"), 1);
    m.world_mut().set_digital(7, true);
    m.world_mut().set_digital(0, true);
    assert_eq!(send(&mut m, "GIO 255, 0"), 0x81);
    // V4.45 4.6.15: a 10-bit ADC, 0…1023: the world's 12-bit 3000 reads 750.
    m.world_mut().set_analog(3, 3000);
    assert_eq!(send(&mut m, "GIO 3, 1"), 750);
    m.world_mut().set_analog(3, 4095);
    assert_eq!(send(&mut m, "GIO 3, 1"), 1023, "full scale");
    assert_eq!(reply(&mut m, "GIO 4, 1").status, 3);
}

#[test]
fn reference_search_modes_1_to_3() {
    for (mode, zero, distance) in [(1, -20_000.0, None), (2, -20_000.0, Some(50_000)), (3, 6_000.0, Some(24_000))] {
        let mut m = module();
        let w = &mut m.world_mut().axes[1];
        w.left_switch = Some(-20_000.0);
        w.right_switch = Some(30_000.0);
        w.home_switch = Some((5_000.0, 6_000.0));
        send(&mut m, &format!("SAP 193, 1, {mode}"));
        send(&mut m, "SAP 194, 1, 2000");
        send(&mut m, "SAP 195, 1, 200");
        send(&mut m, "RFS START, 1");
        for _ in 0..60_000 {
            m.advance(MS);
            if send(&mut m, "RFS STATUS, 1") == 0 {
                break;
            }
        }
        assert_eq!(send(&mut m, "RFS STATUS, 1"), 0, "mode {mode} ended");
        assert_eq!(send(&mut m, "GAP 1, 1"), 0);
        assert!((m.mechanical_position(1) - zero).abs() <= 0.5, "mode {mode}: {}", m.mechanical_position(1));
        if let Some(d) = distance {
            assert_eq!(send(&mut m, "GAP 196, 1"), d, "mode {mode}");
        }
    }
    let mut m = module();
    assert_eq!(reply(&mut m, "SAP 193, 0, 4").status, 4, "the 351 has modes 1–3");
}

#[test]
fn stall_detection_ap205_ap206() {
    let mut m = module();
    send(&mut m, "SAP 6, 0, 255");
    send(&mut m, "ROR 0, 500");
    m.advance(300 * MS);
    assert_eq!(send(&mut m, "GAP 206, 0"), 0, "no load");
    m.world_mut().axes[0].loads = vec![Load { torque: 60.0, ..Load::default() }];
    m.advance(10 * MS);
    let v = send(&mut m, "GAP 206, 0");
    assert!((3..=7).contains(&v), "{v}");
    send(&mut m, &format!("SAP 205, 0, {}", v - 1));
    m.advance(10 * MS);
    assert_eq!(send(&mut m, "GAP 3, 0"), 0, "stopped above the threshold");
}

#[test]
fn encoder_prescaler_and_deviation_stop() {
    let mut m = BusOfOne::new(Module::with_world(
        tmclsim_firmware::Profile::built_in("tmcm-351").unwrap(),
        tmclsim_firmware::Eeprom::new("TMCM-351"),
        World::free(3),
    ));
    // The manual's encoder demo setup: 2000-line encoder, 64 µsteps, 68672 = ×6.4.
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
    // Obstructed: the motor loses steps, the deviation stops it.
    m.world_mut().axes[0].loads = vec![Load { torque: 500.0, ..Load::default() }];
    send(&mut m, "MVP ABS, 0, 0");
    m.advance(2000 * MS);
    assert_eq!(send(&mut m, "GAP 3, 0"), 0);
    let deviation = (send(&mut m, "GAP 1, 0") - send(&mut m, "GAP 209, 0")).abs();
    assert!(deviation > 250 && deviation < 1000, "stopped just past the limit: {deviation}");
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
    // Manual 3.4.2's command lines and 3.4.3's reply.
    assert!(text("AMVP ABS, 1, 50000\r").ends_with("BA 100 50000\r"));
    assert!(text("A MVP ABS, 1, 50000\r").ends_with("BA 100 50000\r"));
    assert!(text("AROL 2, 500\r").ends_with("BA 100 500\r"));
    assert!(text("A MST 1\r").ends_with("BA 100 0\r"));
    assert!(text("ASAP 1, 1, -5000\r").ends_with("BA 100 -5000\r"));
    assert_eq!(text("AGAP 1, 1\r"), "AGAP 1, 1\rBA 100 -5000\r");
    assert!(text("ASAC 0, 1, 7\r").ends_with("BA 100 0\r"), "SAC is permitted in ASCII mode on the 351");
    assert!(text("ABIN\r").ends_with("BA 100 0\r"));
    assert!(!m.ascii_mode());
}
