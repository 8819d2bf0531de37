//! CAN as on a bus (docs/behaviour.md rules 67–69 and 92): modules placed
//! at their addresses are reached apart, and each answers with its own
//! reply identifier.

use tmclsim_firmware::can::CanFrame;
use tmclsim_firmware::{Bus, Module};

fn at(profile: &str, address: u8) -> Module {
    let mut m = Module::built_in(profile).unwrap();
    m.set_address(address);
    m
}

/// GAP 1, motor 0 to CAN identifier `id`: (reply identifier, the
/// replying module's address) of every reply.
fn ask(bus: &mut Bus, id: u32) -> Vec<(u32, u8)> {
    bus.handle_can(&CanFrame::new(id, &[6, 1, 0, 0, 0, 0, 0])).iter().map(|r| (r.id, r.data[0])).collect()
}

#[test]
fn modules_at_their_addresses_are_reached_apart() {
    let mut bus = Bus::new(vec![at("tmcm-351", 1), at("tmcm-351", 2), at("tmcm-6110", 3)]);
    assert_eq!(ask(&mut bus, 1), [(2, 1)], "only module 1 answers, with its reply identifier (GP 70)");
    assert_eq!(ask(&mut bus, 2), [(2, 2)]);
    assert_eq!(ask(&mut bus, 3), [(2, 3)]);
    assert_eq!(ask(&mut bus, 4), [], "nobody has identifier 4");
}

#[test]
fn each_module_replies_with_its_own_reply_identifier() {
    let mut bus = Bus::new(vec![at("tmcm-351", 1), at("tmcm-351", 5)]);
    // SGP 70 (CAN reply ID), bank 0, 0x105 to module 5.
    let set = bus.handle_can(&CanFrame::new(5, &[9, 70, 0, 0, 0, 0x01, 0x05]));
    assert_eq!((set[0].id, set[0].data[1]), (2, 100), "the reply to SGP still goes out under the old identifier");
    assert_eq!(ask(&mut bus, 5), [(0x105, 5)]);
    assert_eq!(ask(&mut bus, 1), [(2, 1)], "module 1 keeps its own");
}
