//! Module differences are data: a built-in profile whose `[features]` (or
//! port roles) are edited makes a module that behaves as the edited data
//! say, not as the module's name or its parameter table would suggest.

use crate::common;

use common::BusOfOne;
use std::sync::Arc;
use tmclsim_firmware::profile::BUILT_IN;
use tmclsim_firmware::world::Load;
use tmclsim_firmware::{Eeprom, Module, Profile, World};
use tmclsim_protocol::mnemonic::parse_line;
use tmclsim_protocol::{Reply, Request};

const MS: u64 = 1_000_000;

/// The text of a built-in profile.
fn text(name: &str) -> String {
    BUILT_IN.iter().find(|(n, _)| *n == name).unwrap().1.to_string()
}

/// `text` with `from` (which must occur once) replaced by `to`.
fn edit(text: &str, from: &str, to: &str) -> String {
    assert_eq!(text.matches(from).count(), 1, "{from}");
    text.replace(from, to)
}

/// Adds lines to the `[features]` table.
fn with_features(text: &str, lines: &str) -> String {
    edit(text, "\n[features]\n", &format!("\n[features]\n{lines}\n"))
}

fn module(text: &str) -> BusOfOne {
    let profile = Arc::new(Profile::from_toml(text).unwrap());
    BusOfOne::new(Module::with_world(profile.clone(), Eeprom::new(&profile.module.name), World::free(profile.module.axes as usize)))
}

fn reply(m: &mut BusOfOne, line: &str) -> Reply {
    let f = Request::new(m.address(), parse_line(line).unwrap()).encode();
    Reply::decode(&m.handle_frame(&f).unwrap()).unwrap()
}

fn send(m: &mut BusOfOne, line: &str) -> i32 {
    let r = reply(m, line);
    assert_eq!(r.status, 100, "{line}");
    r.value
}

/// A GP 73 row for the TMCM-1141, which has none.
const GP_73: &str = "
[[global_parameter]]
bank = 0
number = 73
name = \"EEPROM lock\"
access = \"RWA\"
min = 0
max = 4321
default = 0
default_source = \"assumed\"
";

#[test]
fn eeprom_lock_is_the_feature_not_the_parameter() {
    // A TMCM-1141 with a GP 73 but no eeprom_lock feature: GP 73 is a plain
    // setting, and STAP works whatever it holds.
    let plain = format!("{}{GP_73}", text("tmcm-1141"));
    let mut m = module(&plain);
    send(&mut m, "SGP 73, 0, 1234");
    assert_eq!(send(&mut m, "GGP 73, 0"), 1234);
    send(&mut m, "SAP 4, 0, 1500");
    assert_eq!(reply(&mut m, "STAP 4, 0").status, 100);
    // The same with `eeprom_lock = 73`: 1234 locks, EEPROM writes answer 5.
    let mut m = module(&with_features(&plain, "eeprom_lock = 73"));
    send(&mut m, "SGP 73, 0, 1234");
    assert_eq!(send(&mut m, "GGP 73, 0"), 1, "reads 1 while locked");
    assert_eq!(reply(&mut m, "STAP 4, 0").status, 5);
    assert_eq!(reply(&mut m, "STGP 0, 2").status, 5);
    assert_eq!(reply(&mut m, "SGP 77, 0, 1").status, 5, "bank 0 is stored on SGP");
    assert_eq!(reply(&mut m, "SGP 73, 0, 77").status, 4, "only 1234 and 4321");
    // 137 would erase the EEPROM: refused, and the settings stay.
    send(&mut m, "SGP 73, 0, 4321");
    send(&mut m, "SAP 4, 0, 1500");
    assert_eq!(reply(&mut m, "STAP 4, 0").status, 100);
    send(&mut m, "SGP 73, 0, 1234");
    assert_eq!(reply(&mut m, "#137 0 0 1234").status, 5);
    assert_eq!(send(&mut m, "GAP 4, 0"), 1500);
    assert_eq!(send(&mut m, "GGP 73, 0"), 1, "still locked");
    send(&mut m, "SGP 73, 0, 4321");
    assert_eq!(reply(&mut m, "STAP 4, 0").status, 100);
    // And the TMCM-351 without the feature cannot be locked any more.
    let mut m = module(&edit(&text("tmcm-351"), "\neeprom_lock = 73", "\n"));
    send(&mut m, "SGP 73, 0, 1234");
    assert_eq!(reply(&mut m, "STAP 4, 0").status, 100);
}

#[test]
fn reference_search_modes_follow_the_family() {
    // TMC429 family: mode 5 (home switch) exists.
    let mut m = module(&text("tmcm-1141"));
    send(&mut m, "SAP 193, 0, 5");
    assert_eq!(reply(&mut m, "RFS START, 0").status, 100);
    // The same module declared TMC428: only modes 1…3.
    let tmc428 = edit(&text("tmcm-1141"), "reference_search = \"tmc429\"", "reference_search = \"tmc428\"");
    let mut m = module(&tmc428);
    send(&mut m, "SAP 193, 0, 5");
    assert_eq!(reply(&mut m, "RFS START, 0").status, 4);
    send(&mut m, "SAP 193, 0, 3");
    assert_eq!(reply(&mut m, "RFS START, 0").status, 100);
}

#[test]
fn can_identifiers_follow_the_can_table() {
    let m = {
        let mut m = module(&text("tmcm-351"));
        send(&mut m, "SGP 66, 0, 5");
        send(&mut m, "SGP 71, 0, 9");
        m
    };
    assert_eq!(m.can_ids(), (9, None), "GP 71");
    assert_eq!(m.can_reply_id(), 2, "GP 70's default");
    // Without [features.can] the serial and host addresses are the identifiers.
    let t = text("tmcm-351");
    let start = t.find("[features.can]").unwrap();
    let end = start + t[start..].find("secondary_id = 83\n").unwrap() + "secondary_id = 83\n".len();
    let mut m = module(&format!("{}{}", &t[..start], &t[end..]));
    send(&mut m, "SGP 66, 0, 5");
    send(&mut m, "SGP 71, 0, 9");
    assert_eq!(m.can_ids(), (5, None), "GP 66");
    assert_eq!(m.can_reply_id(), u32::from(m.host_address()));
}

#[test]
fn eeprom_magic_follows_the_feature() {
    let stored = {
        let mut m = module(&text("tmcm-351"));
        send(&mut m, "SAP 4, 0, 1700");
        send(&mut m, "STAP 4, 0");
        send(&mut m, "SGP 64, 0, 228"); // 0xE4, stored automatically
        m.eeprom().clone()
    };
    let power_on = |text: &str| {
        let mut m = BusOfOne::new(Module::with_eeprom(Arc::new(Profile::from_toml(text).unwrap()), stored.clone()));
        (send(&mut m, "GAP 4, 0"), send(&mut m, "GGP 64, 0"))
    };
    assert_eq!(power_on(&text("tmcm-351")), (1700, 0xE4), "the magic matches: the EEPROM is kept");
    let other = edit(&text("tmcm-351"), "value = 0xE4", "value = 0x5A");
    assert_eq!(power_on(&other), (1000, 0x5A), "another magic: re-initialised");
    let none = edit(&text("tmcm-351"), "\neeprom_magic = { parameter = 64, value = 0xE4 }", "\n");
    assert_eq!(power_on(&none), (1700, 0xE4), "no magic: nothing is checked");
}

#[test]
fn full_scale_current_follows_the_feature() {
    let torque_scale = |text: &str| {
        let mut m = module(text);
        send(&mut m, "SAP 129, 0, 1");
        send(&mut m, "SAP 14, 0, 750");
        m.advance(100 * MS);
        (send(&mut m, "GAP 15, 0"), send(&mut m, "GAP 123, 0"))
    };
    assert_eq!(torque_scale(&text("tmcm-1310")), (3000, 25));
    let half = edit(&text("tmcm-1310"), "full_scale_current_ma = 3000", "full_scale_current_ma = 1500");
    assert_eq!(torque_scale(&half), (1500, 50), "750 mA is half of 1.5 A");
}

#[test]
fn stall_detection_follows_the_feature() {
    let run_into_load = |text: &str| {
        let mut m = module(text);
        send(&mut m, "SAP 6, 0, 255");
        send(&mut m, "SAP 181, 0, 300");
        send(&mut m, "ROR 0, 500");
        m.advance(500 * MS);
        m.world_mut().axes[0].loads = vec![Load { torque: 150.0, ..Load::default() }];
        m.advance(10 * MS);
        send(&mut m, "GAP 3, 0")
    };
    assert_eq!(run_into_load(&text("tmcm-1141")), 0, "stallGuard2 stops the motor");
    let none = edit(&text("tmcm-1141"), "stall_detection = \"stallguard2\"", "stall_detection = \"none\"");
    assert_eq!(run_into_load(&none), 500, "no stall detection: it runs on, losing steps");
}

#[test]
fn the_supply_channel_is_the_one_with_the_supply_role() {
    let mut m = module(&text("tmcm-1141"));
    m.world_mut().analog_inputs = vec![0, 0, 0, 0, 0, 0, 0, 0, 1234];
    assert_eq!(send(&mut m, "GIO 8, 1"), 240, "24.0 V supply");
    // The same channel without its role is a plain analog input, whatever its unit.
    let mut m = module(&edit(&text("tmcm-1141"), "role = \"supply\"\n", ""));
    m.world_mut().analog_inputs = vec![0, 0, 0, 0, 0, 0, 0, 0, 1234];
    assert_eq!(send(&mut m, "GIO 8, 1"), 1234);
}
