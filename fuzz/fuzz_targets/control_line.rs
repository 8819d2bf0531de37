//! Control-socket lines (docs/world.md) on arbitrary text: each line parsed
//! and applied to a bus of one module whose motor runs, time moving on
//! after each. Properties: no panic; errors are readable text; whatever
//! lines are accepted, the world keeps to the rule set (docs/behaviour.md
//! rule 84) and the module still answers.
#![no_main]

use libfuzzer_sys::fuzz_target;
use tmclsim_firmware::world_command::Addressed;
use tmclsim_firmware::{Bus, Module};
use tmclsim_protocol::{Instruction, Reply, Request};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let mut bus = Bus::single(Module::built_in("tmcm-1141").unwrap());
    let ror = Request::new(1, Instruction::new(1, 0, 0, 500)).encode();
    let _ = bus.handle_frame(&ror);
    for line in text.lines().take(64) {
        let applied = Addressed::parse(line).and_then(|a| bus.apply_world(a.address, &a.command));
        match applied {
            Ok(_) => assert_eq!(bus.module(0).world().validate(), Ok(()), "{line:?}"),
            Err(e) => assert!(!e.to_string().is_empty(), "{line:?}"),
        }
        bus.advance(10_000_000);
    }
    let gap = Request::new(1, Instruction::new(6, 1, 0, 0)).encode();
    let answer = bus.handle_frame(&gap);
    let reply = Reply::decode(&answer.replies[0]).unwrap();
    assert_eq!(reply.status, 100);
});
