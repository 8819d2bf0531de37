//! docs/behaviour.md rule 85: a resync frame (address 0, opcode 0: nine
//! zero bytes) on a point-to-point link is answered with status 2; on a
//! multi-drop bus only the addressed module answers.

use tmclsim_firmware::{Bus, Module};
use tmclsim_protocol::{Instruction, Reply, Request, Status};

const RESYNC: [u8; 9] = [0; 9];

fn module(name: &str, address: u8) -> Module {
    let mut m = Module::built_in(name).unwrap();
    m.set_address(address);
    m
}

#[test]
fn one_module_answers_nine_zero_bytes_with_invalid_command() {
    for name in ["tmcm-1141", "tmcm-1140", "tmcm-3110", "tmcm-6110", "tmcm-351", "tmcm-1310"] {
        for address in [1, 7] {
            let mut bus = Bus::single(module(name, address));
            let answer = bus.handle_frame(&RESYNC);
            assert_eq!(answer.replies.len(), 1, "{name} at {address}");
            let r = Reply::decode(&answer.replies[0]).expect("a reply with a good checksum");
            assert_eq!(r.status, Status::InvalidCommand.code(), "{name}");
            assert_eq!((r.host, r.module, r.opcode, r.value), (2, address, 0, 0), "{name}: from the module's own address");
        }
    }
}

#[test]
fn after_a_resync_the_module_answers_as_before() {
    let mut bus = Bus::single(module("tmcm-1141", 1));
    bus.handle_frame(&RESYNC);
    let a = bus.handle_frame(&Request::new(1, Instruction::new(6, 140, 0, 0)).encode());
    let r = Reply::decode(&a.replies[0]).unwrap();
    assert_eq!((r.status, r.value), (Status::Ok.code(), 8), "GAP 140 reads the default after a resync");
}

#[test]
fn only_the_resync_frame_is_answered_from_address_0() {
    let mut bus = Bus::single(module("tmcm-1141", 1));
    // Address 0 with a real command, and a resync frame with a bad checksum.
    assert!(bus.handle_frame(&Request::new(0, Instruction::new(6, 1, 0, 0)).encode()).replies.is_empty());
    let mut bad = RESYNC;
    bad[8] = 1;
    assert!(bus.handle_frame(&bad).replies.is_empty());
}

#[test]
fn suppressed_replies_suppress_the_resync_answer_too() {
    let mut bus = Bus::single(module("tmcm-1141", 1));
    bus.handle_frame(&Request::new(1, Instruction::new(9, 255, 0, 1)).encode()); // SGP 255, 0, 1
    assert!(bus.handle_frame(&RESYNC).replies.is_empty());
}

#[test]
fn on_a_multi_drop_bus_nobody_answers_address_0() {
    let mut bus = Bus::new(vec![module("tmcm-1141", 1), module("tmcm-3110", 2)]);
    assert!(bus.handle_frame(&RESYNC).replies.is_empty());
    let a = bus.handle_frame(&Request::new(2, Instruction::new(0, 0, 0, 0)).encode());
    let r = Reply::decode(&a.replies[0]).unwrap();
    assert_eq!((r.module, r.status), (2, Status::InvalidCommand.code()), "opcode 0 addressed to module 2");
}
