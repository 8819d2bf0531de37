//! Every binary example of the TMCM-1141 manual (as corrected in the
//! reference notes): the mnemonic encodes to the golden bytes, and the
//! module's reply matches where the manual gives one.

mod common;

use common::{frame, hex};

use tmclsim_firmware::Module;
use tmclsim_protocol::{Instruction, Reply, Request, Status};

#[test]
fn request_frames_encode_as_printed() {
    let golden = [
        ("ROR 0, 1000", "01 01 00 00 00 00 03 E8 ED"),
        ("ROL 0, 1000", "01 02 00 00 00 00 03 E8 EE"),
        ("MST 0", "01 03 00 00 00 00 00 00 04"),
        ("MVP ABS, 0, 90000", "01 04 00 00 00 01 5F 90 F5"),
        ("MVP REL, 0, -10000", "01 04 01 00 FF FF D8 F0 CC"),
        ("MVP COORD, 0, 8", "01 04 02 00 00 00 00 08 0F"),
        ("SAP 4, 0, 1000", "01 05 04 00 00 00 03 E8 F5"),
        ("GAP 1, 0", "01 06 01 00 00 00 00 00 08"),
        ("STAP 6, 0", "01 07 06 00 00 00 00 00 0E"),
        ("RSAP 6, 0", "01 08 06 00 00 00 00 00 0F"),
        ("SGP 66, 0, 3", "01 09 42 00 00 00 00 03 4F"),
        ("GGP 66, 0", "01 0A 42 00 00 00 00 00 4D"),
        ("STGP 42, 2", "01 0B 2A 02 00 00 00 00 38"),
        ("RSGP 42, 2", "01 0C 2A 02 00 00 00 00 39"),
        ("RFS START, 0", "01 0D 00 00 00 00 00 00 0E"),
        ("SIO 0, 2, 1", "01 0E 00 02 00 00 00 01 12"),
        ("GIO 0, 1", "01 0F 00 01 00 00 00 00 11"),
        ("CALC MUL, -5000", "01 13 02 00 FF FF EC 78 78"),
        ("COMP 1000", "01 14 00 00 00 00 03 E8 00"),
        ("JC GE, 10", "01 15 05 00 00 00 00 0A 25"),
        ("JA 10", "01 16 00 00 00 00 00 0A 21"),
        ("CSUB 100", "01 17 00 00 00 00 00 64 7C"),
        ("RSUB", "01 18 00 00 00 00 00 00 19"),
        ("WAIT POS, 0, 0", "01 1B 01 00 00 00 00 00 1D"),
        ("STOP", "01 1C 00 00 00 00 00 00 1D"),
        ("SCO 1, 0, 1000", "01 1E 01 00 00 00 03 E8 0B"),
        ("GCO 1, 0", "01 1F 01 00 00 00 00 00 21"),
        ("CCO 3, 0", "01 20 03 00 00 00 00 00 24"),
        ("ACO 1, 0", "01 27 01 00 00 00 00 00 29"),
        ("CALCX MUL", "01 21 02 00 00 00 00 00 24"),
        ("AAP 0, 0", "01 22 00 00 00 00 00 00 23"),
        ("AGP 42, 2", "01 23 2A 02 00 00 00 00 50"),
        ("CLE ETO", "01 24 01 00 00 00 00 00 26"),
        ("EI 255", "01 19 FF 00 00 00 00 00 19"),
        ("DI 255", "01 1A FF 00 00 00 00 00 1A"),
        ("VECT 0, 50", "01 25 00 00 00 00 00 32 58"),
        ("RETI", "01 26 00 00 00 00 00 00 27"),
        ("CALCVV SUB, 65, 42", "01 28 01 41 00 00 00 2A 95"),
        ("CALCVA SUB, 27", "01 29 01 1B 00 00 00 00 46"),
        ("CALCAV SUB, 27", "01 2A 01 1B 00 00 00 00 47"),
        ("CALCVX SUB, 27", "01 2B 01 1B 00 00 00 00 48"),
        ("CALCXV SUB, 27", "01 2C 01 1B 00 00 00 00 49"),
        ("CALCV SUB, 27, 5000", "01 2D 01 1B 00 00 13 88 E5"),
        ("MVPA ABS, 0", "01 2E 00 00 00 00 00 00 2F"),
        ("RST 10", "01 30 00 00 00 00 00 0A 3B"),
        ("DJNZ 42, 1", "01 31 2A 00 00 00 00 01 5D"),
        ("ROLA 0", "01 32 00 00 00 00 00 00 33"),
        ("RORA 0", "01 33 00 00 00 00 00 00 34"),
        ("SIV 3", "01 37 00 00 00 00 00 03 3B"),
        ("GIV", "01 38 00 00 00 00 00 00 39"),
        ("AIV", "01 39 00 00 00 00 00 00 3A"),
        ("CALL LT, 100", "01 50 06 00 00 00 00 64 BB"),
        ("#138 1 0 1", "01 8A 01 00 00 00 00 01 8D"),
    ];
    for (line, bytes) in golden {
        assert_eq!(frame(line), hex(bytes), "{line}");
    }
}

#[test]
fn replies_match_the_manual() {
    let mut m = Module::built_in("tmcm-1141").unwrap();
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
    let mut m = Module::built_in("tmcm-1141").unwrap();
    let r = m.handle_frame(&Request::new(1, Instruction::new(136, 0, 0, 0)).encode()).unwrap();
    assert_eq!(&r, b"\x021141V146");
    let r = Reply::decode(&m.handle_frame(&Request::new(1, Instruction::new(136, 1, 0, 0)).encode()).unwrap()).unwrap();
    assert_eq!(r.status(), Some(Status::Ok));
    assert_eq!(r.value, 0x0475012E);
}
