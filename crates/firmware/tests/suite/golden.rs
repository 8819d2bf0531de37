//! Every binary example of the firmware manuals (tests/golden/manual_frames.rs,
//! the misprints corrected): the mnemonic encodes to the golden bytes, the
//! module it was printed for takes it, and its reply matches where the
//! manual prints one.

use crate::common;
#[path = "../../../../tests/golden/manual_frames.rs"]
mod manual_frames;

use common::{BusOfOne, frame, hex};

use tmclsim_protocol::{Instruction, Reply, Request, Status};

#[test]
fn request_frames_encode_as_printed() {
    for g in manual_frames::FRAMES {
        assert_eq!(frame(g.line), hex(g.frame), "{} {}: {}", g.module, g.manual, g.line);
    }
}

/// The commands that only a program runs answer status 6 in direct mode
/// (docs/behaviour.md rule 7); every other printed frame is carried out by
/// the module it was printed for, except where the manual's example and
/// its own parameter table disagree and the table wins (rule 27).
#[test]
fn the_module_takes_every_frame_printed_for_it() {
    let program_only = [21, 22, 23, 24, 27, 28, 38, 48, 49, 80];
    // The TMCM-1141's table 16 prints AP 6 as RW: not storable.
    let table_wins = [("tmcm-1141", "STAP 6, 0"), ("tmcm-1141", "RSAP 6, 0")];
    for g in manual_frames::FRAMES {
        let mut m = BusOfOne::built_in(g.module);
        let bytes = hex(g.frame);
        let r = Reply::decode(&m.handle_frame(&bytes).unwrap_or_else(|| panic!("{}: no reply", g.line))).unwrap();
        let expected = if program_only.contains(&bytes[1]) {
            Status::NotAvailable
        } else if table_wins.contains(&(g.module, g.line)) {
            Status::WrongType
        } else {
            Status::Ok
        };
        assert_eq!(r.status(), Some(expected), "{} {}: {}", g.module, g.manual, g.line);
    }
}

/// The replies the TMCM-351 manual V4.45 prints (the checksums computed).
#[test]
fn replies_of_the_351_manual() {
    let mut m = BusOfOne::built_in("tmcm-351");
    // §4.6.10 p.32: GGP 66, 0 answers the serial address 1.
    assert_eq!(m.handle_frame(&frame("GGP 66, 0")), Some(hex("02 01 64 0A 00 00 00 01 72")));
    // §4.6.15 p.38: GIO 0, 1 answers 506 (the world's 12-bit 2024 on the
    // 10-bit ADC).
    m.world_mut().set_analog(0, 2024);
    assert_eq!(m.handle_frame(&frame("GIO 0, 1")), Some(hex("02 01 64 0F 00 00 01 FA 71")));
    // §4.6.16 p.41: CALC MUL, -5000 answers the operand.
    assert_eq!(m.handle_frame(&frame("CALC MUL, -5000")), Some(hex("02 01 64 13 FF FF EC 78 DC")));
    // §4.6.26 p.51: GCO 1, 0 answers 0 (printed with the opcode byte $0A;
    // a reply carries the request's opcode, $1F).
    assert_eq!(m.handle_frame(&frame("GCO 1, 0")), Some(hex("02 01 64 1F 00 00 00 00 86")));
    // §4.6.6 p.28: GAP 6, 1 (the printed value $0280 lies outside AP 6's
    // 0…255; the reply carries what SAP set).
    m.handle_frame(&frame("SAP 6, 1, 128")).unwrap();
    assert_eq!(m.handle_frame(&frame("GAP 6, 1")), Some(hex("02 01 64 06 00 00 00 80 ED")));
    // §4.6.38 p.65: 138 with a motor bit mask: status 100 at once, then
    // status 128 when the motor has arrived, both with the mask.
    assert_eq!(m.handle_frame(&frame("#138 0 0 4")), Some(hex("02 01 64 8A 00 00 00 04 F5")));
    m.handle_frame(&frame("MVP ABS, 2, 1000")).unwrap();
    assert!(m.take_events().is_empty());
    m.advance(10_000_000_000);
    assert_eq!(m.take_events(), vec![hex("02 01 80 8A 00 00 00 04 11")]);
}

#[test]
fn replies_match_the_manual() {
    let mut m = BusOfOne::built_in("tmcm-1141");
    // GIO 0, 1 with the analog input at 302.
    m.world_mut().set_analog(0, 302);
    assert_eq!(m.handle_frame(&frame("GIO 0, 1")), Some(hex("02 01 64 0F 00 00 01 2E A5")));
    // CALC MUL, -5000 replies with the operand.
    assert_eq!(m.handle_frame(&frame("CALC MUL, -5000")), Some(hex("02 01 64 13 FF FF EC 78 DC")));
    assert_eq!(m.handle_frame(&frame("CALCV SUB, 27, 5000")), Some(hex("02 01 64 2D 00 00 13 88 2F")));
    // 138 type 1 mask 1: immediate reply, then the event when the motor arrives.
    assert_eq!(m.handle_frame(&frame("#138 1 0 1")), Some(hex("02 01 64 8A 00 00 00 01 F2")));
    m.handle_frame(&frame("MVP ABS, 0, 1000")).unwrap();
    assert!(m.take_events().is_empty());
    m.advance(10_000_000_000);
    assert_eq!(m.take_events(), vec![hex("02 01 80 8A 00 00 00 01 0E")]);
}

#[test]
fn firmware_version_replies() {
    let mut m = BusOfOne::built_in("tmcm-1141");
    let r = m.handle_frame(&Request::new(1, Instruction::new(136, 0, 0, 0)).encode()).unwrap();
    assert_eq!(&r, b"\x021141V146");
    let r = Reply::decode(&m.handle_frame(&Request::new(1, Instruction::new(136, 1, 0, 0)).encode()).unwrap()).unwrap();
    assert_eq!(r.status(), Some(Status::Ok));
    assert_eq!(r.value, 0x0475012E);
}
