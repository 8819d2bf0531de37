//! Direct-mode behaviour of the virtual TMCM-1141: statuses for every kind
//! of bad input, addressing, parameter access, calculation, I/O,
//! coordinates and the control commands of the foundation.

use crate::common;

use common::{BusOfOne, reply, send, status};

use tmclsim_protocol::mnemonic::parse_line;
use tmclsim_protocol::{Instruction, Reply, Request, Status, checksum};

fn module() -> BusOfOne {
    BusOfOne::built_in("tmcm-1141")
}

#[test]
fn wrong_checksum_gets_status_1_with_opcode_0() {
    let mut m = module();
    let mut f = Request::new(1, Instruction::new(6, 1, 0, 0)).encode();
    f[8] = f[8].wrapping_add(1);
    let r = Reply::decode(&m.handle_frame(&f).unwrap()).unwrap();
    assert_eq!((r.host, r.module, r.status, r.opcode, r.value), (2, 1, 1, 0, 0));
}

#[test]
fn other_addresses_get_no_reply() {
    let mut m = module();
    for address in [0u8, 2, 3, 255] {
        let f = Request::new(address, Instruction::new(6, 1, 0, 0)).encode();
        assert_eq!(m.handle_frame(&f), None, "address {address}");
        // Not even a checksum error.
        let mut bad = f;
        bad[8] ^= 0x55;
        assert_eq!(m.handle_frame(&bad), None);
    }
}

#[test]
fn secondary_address_and_address_change() {
    let mut m = module();
    assert_eq!(status(&mut m, "SGP 87, 0, 9"), 100);
    let f = Request::new(9, parse_line("GAP 4, 0").unwrap()).encode();
    let r = Reply::decode(&m.handle_frame(&f).unwrap()).unwrap();
    assert_eq!(r.module, 9, "reply carries the address the request used");
    // SGP 66 changes the primary address at once.
    assert_eq!(status(&mut m, "SGP 66, 0, 3"), 100);
    let old = Request::new(1, parse_line("GAP 4, 0").unwrap()).encode();
    assert_eq!(m.handle_frame(&old), None);
    let new = Request::new(3, parse_line("GAP 4, 0").unwrap()).encode();
    assert!(m.handle_frame(&new).is_some());
}

#[test]
fn host_address_gp76_is_used_in_replies() {
    let mut m = module();
    reply(&mut m, "SGP 76, 0, 7");
    assert_eq!(reply(&mut m, "GAP 4, 0").host, 7);
}

#[test]
fn error_statuses_for_each_kind_of_bad_input() {
    let mut m = module();
    // Unknown opcode, and an opcode this module lacks (SAC).
    assert_eq!(status(&mut m, "#16 0 0 0"), 2);
    assert_eq!(status(&mut m, "#29 0 0 0"), 2);
    assert_eq!(status(&mut m, "#200 0 0 0"), 2);
    // Type out of range; parameter not in the table.
    assert_eq!(status(&mut m, "#4 3 0 0"), 3);
    assert_eq!(status(&mut m, "GAP 14, 0"), 3);
    assert_eq!(status(&mut m, "SAP 250, 0, 1"), 3);
    assert_eq!(status(&mut m, "GGP 64, 0"), 3);
    // Motor or bank out of range.
    assert_eq!(status(&mut m, "GAP 1, 1"), 4);
    assert_eq!(status(&mut m, "ROR 1, 100"), 4);
    assert_eq!(status(&mut m, "GGP 0, 1"), 4);
    assert_eq!(status(&mut m, "GGP 0, 4"), 4);
    // Value out of the parameter's range.
    assert_eq!(status(&mut m, "SAP 4, 0, 2048"), 4);
    assert_eq!(status(&mut m, "SAP 4, 0, 0"), 4);
    assert_eq!(status(&mut m, "SAP 140, 0, 9"), 4);
    assert_eq!(status(&mut m, "SGP 65, 0, 9"), 4);
    assert_eq!(status(&mut m, "ROL 0, 2048"), 4);
    // Access: SAP on read-only, STAP on a parameter without E.
    assert_eq!(status(&mut m, "SAP 3, 0, 5"), 3);
    assert_eq!(status(&mut m, "SAP 8, 0, 1"), 3);
    assert_eq!(status(&mut m, "STAP 6, 0"), 3);
    assert_eq!(status(&mut m, "STGP 56, 2"), 3);
    assert_eq!(status(&mut m, "STGP 0, 3"), 3);
    assert_eq!(status(&mut m, "SGP 128, 0, 1"), 3);
    // Program-only commands in direct mode.
    for line in ["JA 10", "JC GE, 10", "CSUB 100", "RSUB", "WAIT POS, 0, 0", "STOP", "RST 10", "DJNZ 42, 1", "CALL LT, 100", "RETI"] {
        assert_eq!(status(&mut m, line), 6, "{line}");
    }
    // User functions without a customer extension.
    assert_eq!(status(&mut m, "UF0 0, 0, 0"), 6);
    // The value of an error reply echoes the request.
    assert_eq!(reply(&mut m, "SAP 4, 0, 4000").value, 4000);
}

#[test]
fn every_table_16_parameter_obeys_its_access_and_range() {
    let mut m = module();
    let profile = m.profile().clone();
    for p in profile.axis_parameters() {
        let n = p.number;
        let get = reply(&mut m, &format!("GAP {n}, 0"));
        assert_eq!(get.status, if p.access.read { 100 } else { 3 }, "GAP {n}");
        if p.access.write {
            let max = p.max.min(i64::from(i32::MAX));
            if !matches!(n, 0..=2) {
                assert_eq!(status(&mut m, &format!("SAP {n}, 0, {max}")), 100, "SAP {n} max");
                assert_eq!(send(&mut m, &format!("GAP {n}, 0")), max as i32, "GAP {n} after SAP");
            }
            if p.max < i64::from(i32::MAX) {
                assert_eq!(status(&mut m, &format!("SAP {n}, 0, {}", p.max + 1)), 4, "SAP {n} above max");
            }
            if p.min > i64::from(i32::MIN) {
                assert_eq!(status(&mut m, &format!("SAP {n}, 0, {}", p.min - 1)), 4, "SAP {n} below min");
            }
        } else {
            assert_eq!(status(&mut m, &format!("SAP {n}, 0, 0")), 3, "SAP {n} read-only");
        }
        assert_eq!(status(&mut m, &format!("STAP {n}, 0")), if p.access.eeprom { 100 } else { 3 }, "STAP {n}");
    }
}

#[test]
fn defaults_after_power_up() {
    let mut m = module();
    assert_eq!(send(&mut m, "GAP 130, 0"), 1);
    assert_eq!(send(&mut m, "GAP 214, 0"), 200);
    assert_eq!(send(&mut m, "GAP 140, 0"), 8);
    assert_eq!(send(&mut m, "GGP 65, 0"), 0);
    assert_eq!(send(&mut m, "GGP 77, 0"), 0);
    assert_eq!(send(&mut m, "GGP 66, 0"), 1);
    assert!(!m.restored_from_eeprom());
}

#[test]
fn direct_mode_reads_do_not_touch_the_accumulator() {
    let mut m = module();
    reply(&mut m, "CALC LOAD, 77");
    reply(&mut m, "SAP 4, 0, 1234");
    assert_eq!(send(&mut m, "GAP 4, 0"), 1234);
    send(&mut m, "GGP 66, 0");
    send(&mut m, "GIO 0, 0");
    send(&mut m, "GCO 1, 0");
    assert_eq!(m.registers().accumulator, 77);
}

#[test]
fn calculation_commands_in_direct_mode() {
    let mut m = module();
    reply(&mut m, "CALC LOAD, 10");
    reply(&mut m, "CALC MUL, -5000");
    assert_eq!(m.registers().accumulator, -50000);
    reply(&mut m, "CALCX LOAD");
    reply(&mut m, "CALC LOAD, 7");
    reply(&mut m, "CALCX SWAP");
    assert_eq!((m.registers().accumulator, m.registers().x), (-50000, 7));
    reply(&mut m, "CALC MOD, 7");
    assert_eq!(m.registers().accumulator, -50000 % 7, "MOD takes the dividend's sign");
    // Division by zero: status 4, accumulator unchanged.
    let before = m.registers().accumulator;
    assert_eq!(status(&mut m, "CALC DIV, 0"), 4);
    assert_eq!(m.registers().accumulator, before);
    // Wrap-around.
    reply(&mut m, "CALC LOAD, 2147483647");
    reply(&mut m, "CALC ADD, 1");
    assert_eq!(m.registers().accumulator, i32::MIN);
    // User-variable family.
    reply(&mut m, "SGP 65, 2, 100");
    reply(&mut m, "SGP 42, 2, 58");
    reply(&mut m, "CALCVV SUB, 65, 42");
    assert_eq!(send(&mut m, "GGP 65, 2"), 42);
    reply(&mut m, "CALCV ADD, 27, 5000");
    reply(&mut m, "CALCV SUB, 27, 1000");
    assert_eq!(send(&mut m, "GGP 27, 2"), 4000);
    reply(&mut m, "CALC LOAD, 3");
    reply(&mut m, "CALCAV ADD, 27");
    assert_eq!(m.registers().accumulator, 4003);
    reply(&mut m, "CALCVA LOAD, 5");
    assert_eq!(send(&mut m, "GGP 5, 2"), 4003);
    // Indexed variables.
    reply(&mut m, "CALC LOAD, 12");
    reply(&mut m, "CALCX LOAD");
    reply(&mut m, "SIV 99");
    assert_eq!(send(&mut m, "GGP 12, 2"), 99);
    assert_eq!(send(&mut m, "GIV"), 99);
}

#[test]
fn outputs_inputs_and_pullups() {
    let mut m = module();
    assert_eq!(status(&mut m, "SIO 0, 2, 1"), 100);
    assert_eq!(send(&mut m, "GIO 0, 2"), 1);
    assert_eq!(send(&mut m, "GIO 1, 2"), 0);
    assert_eq!(status(&mut m, "SIO 1, 2, 2"), 4);
    assert_eq!(status(&mut m, "SIO 2, 2, 1"), 3, "the TMCM-1141 has OUT0 and OUT1 only");
    // SIO 255 sets all outputs; -1 takes the accumulator.
    reply(&mut m, "SIO 255, 2, 2");
    assert_eq!(m.outputs(), 0b10);
    reply(&mut m, "CALC LOAD, 3");
    reply(&mut m, "SIO 255, 2, -1");
    assert_eq!(m.outputs(), 0b11);
    assert_eq!(status(&mut m, "SIO 255, 2, 256"), 4);
    // Pull-ups: on by default, SIO 0, 0, x.
    assert!(m.pullups());
    reply(&mut m, "SIO 0, 0, 0");
    assert!(!m.pullups());
    // Inputs.
    m.world_mut().set_digital(2, true);
    m.world_mut().set_digital(3, true);
    assert_eq!(send(&mut m, "GIO 2, 0"), 1);
    assert_eq!(send(&mut m, "GIO 255, 0"), 0b1100);
    assert_eq!(status(&mut m, "GIO 4, 0"), 3);
    assert_eq!(send(&mut m, "GIO 8, 1"), 240, "24.0 V supply");
    m.world_mut().set_analog(0, 1234);
    assert_eq!(send(&mut m, "GIO 0, 1"), 1234);
}

#[test]
fn coordinates_in_ram_and_eeprom() {
    let mut m = module();
    reply(&mut m, "SCO 1, 0, 1000");
    assert_eq!(send(&mut m, "GCO 1, 0"), 1000);
    assert_eq!(status(&mut m, "SCO 21, 0, 1"), 3);
    // GP 84 = 0: RAM only; lost at reset unless copied with SCO n, 255.
    reply(&mut m, "SCO 2, 0, 2000");
    reply(&mut m, "SCO 2, 255, 0");
    reply(&mut m, "#255 0 0 1234");
    reply(&mut m, "GCO 0, 255"); // EEPROM → RAM
    assert_eq!(send(&mut m, "GCO 1, 0"), 0);
    assert_eq!(send(&mut m, "GCO 2, 0"), 2000);
    // GP 84 = 1: stored and restored automatically.
    reply(&mut m, "SGP 84, 0, 1");
    reply(&mut m, "SCO 5, 0, -77");
    reply(&mut m, "CALC LOAD, 555");
    reply(&mut m, "ACO 6, 0");
    reply(&mut m, "#255 0 0 1234");
    assert_eq!(send(&mut m, "GCO 5, 0"), -77);
    assert_eq!(send(&mut m, "GCO 6, 0"), 555);
    // CCO captures the actual position.
    reply(&mut m, "SAP 1, 0, 4321");
    reply(&mut m, "CCO 7, 0");
    assert_eq!(send(&mut m, "GCO 7, 0"), 4321);
    // Coordinate 0 is RAM only.
    reply(&mut m, "SCO 0, 0, 9");
    reply(&mut m, "#255 0 0 1234");
    assert_eq!(send(&mut m, "GCO 0, 0"), 0);
}

#[test]
fn interrupt_configuration_in_direct_mode() {
    let mut m = module();
    assert_eq!(status(&mut m, "EI 0"), 100);
    assert_eq!(status(&mut m, "EI 255"), 100);
    assert_eq!(status(&mut m, "EI 4"), 3, "no interrupt 4 on the TMCM-1141");
    assert_eq!(status(&mut m, "VECT 0, 50"), 100);
    assert_eq!(status(&mut m, "VECT 0, 5000"), 4);
    assert_eq!(status(&mut m, "DI 0"), 100);
}

#[test]
fn suppress_reply_gp255() {
    let mut m = module();
    let on = Request::new(1, parse_line("SGP 255, 0, 1").unwrap()).encode();
    assert_eq!(m.handle_frame(&on), None, "the SGP itself is not answered");
    let sap = Request::new(1, parse_line("SAP 4, 0, 100").unwrap()).encode();
    assert_eq!(m.handle_frame(&sap), None);
    assert_eq!(send(&mut m, "GAP 4, 0"), 100, "GAP is still answered");
    assert_eq!(send(&mut m, "GGP 255, 0"), 1);
    send(&mut m, "GIO 0, 0");
    // Not stored: a reset clears it.
    let reset = Request::new(1, parse_line("#255 0 0 1234").unwrap()).encode();
    m.handle_frame(&reset);
    assert_eq!(send(&mut m, "GGP 255, 0"), 0);
}

#[test]
fn control_commands_137_and_255() {
    let mut m = module();
    assert_eq!(status(&mut m, "#137 0 0 1"), 4);
    assert_eq!(status(&mut m, "#255 0 0 1"), 4);
    reply(&mut m, "SAP 4, 0, 1500");
    reply(&mut m, "STAP 4, 0");
    reply(&mut m, "SGP 76, 0, 5");
    // 255 replies before restarting.
    let r = Reply::decode(&m.handle_frame(&Request::new(1, parse_line("#255 0 0 1234").unwrap()).encode()).unwrap()).unwrap();
    assert_eq!((r.host, r.status), (5, 100));
    assert_eq!(m.resets(), 1);
    assert_eq!(send(&mut m, "GAP 4, 0"), 1500);
    // 137 restores factory defaults and does not reply.
    let f = Request::new(1, parse_line("#137 0 0 1234").unwrap()).encode();
    assert_eq!(m.handle_frame(&f), None);
    assert_eq!(send(&mut m, "GAP 4, 0"), m.profile().axis_parameter(4).unwrap().default as i32);
    assert_eq!(reply(&mut m, "GGP 76, 0").host, 2);
}

#[test]
fn tick_timer_and_random() {
    let mut m = module();
    m.advance(1_500_000_000);
    assert_eq!(send(&mut m, "GGP 132, 0"), 1500);
    reply(&mut m, "SGP 132, 0, 10");
    m.advance(5_000_000);
    assert_eq!(send(&mut m, "GGP 132, 0"), 15);
    let a = send(&mut m, "GGP 133, 0");
    let b = send(&mut m, "GGP 133, 0");
    assert_ne!(a, b);
    assert!(a >= 0 && b >= 0);
}

#[test]
fn heartbeat_stops_the_motor() {
    let mut m = module();
    reply(&mut m, "SGP 68, 0, 100");
    reply(&mut m, "ROR 0, 500");
    m.advance(50_000_000);
    assert_ne!(send(&mut m, "GAP 3, 0"), 0);
    m.advance(99_000_000); // a frame came 0 ms ago: GAP above
    assert_ne!(m.axis(0).motion.v, 0.0, "the GAP frame restarted the heartbeat");
    m.advance(2_000_000);
    assert_eq!(send(&mut m, "GAP 2, 0"), 0, "target speed zeroed by the heartbeat stop");
    m.advance(5_000_000_000);
    assert_eq!(send(&mut m, "GAP 3, 0"), 0);
}

#[test]
fn raw_frames_with_every_byte_value_never_panic() {
    let mut m = module();
    for op in 0..=255u8 {
        for kind in [0u8, 1, 2, 3, 8, 11, 12, 55, 56, 128, 254, 255] {
            for motor in [0u8, 1, 2, 255] {
                for value in [0, 1, -1, 1234, i32::MAX, i32::MIN] {
                    if op == 255 || op == 137 {
                        continue;
                    }
                    let mut f = Request::new(1, Instruction::new(op, kind, motor, value)).encode();
                    f[8] = checksum(&f[..8]);
                    let _ = m.handle_frame(&f);
                    m.advance(1_000_000);
                }
            }
        }
    }
    assert_eq!(Status::from_code(reply(&mut m, "GAP 4, 0").status), Some(Status::Ok));
}
