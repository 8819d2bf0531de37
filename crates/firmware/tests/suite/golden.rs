//! Every binary example of the TMCM-1141 manual (as corrected in the
//! reference notes): the mnemonic encodes to the golden bytes, and the
//! module's reply matches where the manual gives one.

use crate::common;
#[path = "../../../../tests/golden/manual_frames.rs"]
mod manual_frames;

use common::{BusOfOne, frame, hex};

use tmclsim_protocol::{Instruction, Reply, Request, Status};

#[test]
fn request_frames_encode_as_printed() {
    for (line, bytes, _) in manual_frames::TMCM_1141_FRAMES {
        assert_eq!(frame(line), hex(bytes), "{line}");
    }
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
