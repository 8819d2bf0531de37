//! What host drivers of the TMCM-1140, 3110 and 6110 poll: the error flags
//! of every axis (AP 207) and the user variables of bank 2 across
//! power cycles (docs/behaviour.md rules 52, 57).

use crate::common;

use common::{BusOfOne, MS, reply, send};

use tmclsim_firmware::Module;
use tmclsim_firmware::world::Load;

const SIBLINGS: [(&str, u8); 3] = [("tmcm-1140", 1), ("tmcm-3110", 3), ("tmcm-6110", 6)];

fn stall(m: &mut BusOfOne, axis: u8) {
    send(m, &format!("SAP 6, {axis}, 255"));
    send(m, &format!("SAP 181, {axis}, 300"));
    send(m, &format!("ROR {axis}, 500"));
    m.advance(500 * MS);
    m.world_mut().axes[axis as usize].loads = vec![Load { torque: 150.0, ..Load::default() }];
    m.advance(10 * MS);
}

#[test]
fn a_stall_sets_ap207_of_its_axis_only_and_reading_clears_it() {
    for (name, axes) in SIBLINGS {
        let last = axes - 1;
        let mut m = BusOfOne::built_in(name);
        for a in 0..axes {
            assert_eq!(send(&mut m, &format!("GAP 207, {a}")), 0, "{name} axis {a} after start");
        }
        stall(&mut m, last);
        assert_eq!(send(&mut m, &format!("GAP 3, {last}")), 0, "{name}: stopped on the stall");
        for a in 0..last {
            assert_eq!(send(&mut m, &format!("GAP 207, {a}")), 0, "{name}: axis {a} did not stall");
        }
        assert_eq!(send(&mut m, &format!("GAP 207, {last}")), 1, "{name}: stallGuard error bit");
        assert_eq!(send(&mut m, &format!("GAP 207, {last}")), 0, "{name}: cleared by reading");
    }
}

#[test]
fn stored_user_variables_survive_a_power_cycle_and_the_others_do_not() {
    for (name, _) in SIBLINGS {
        let mut m = BusOfOne::built_in(name);
        for (n, v) in [(0, 7), (17, -123456), (55, 2147483647), (56, 99), (255, 5)] {
            send(&mut m, &format!("SGP {n}, 2, {v}"));
        }
        for n in [0, 17, 55] {
            send(&mut m, &format!("STGP {n}, 2"));
        }
        // Power cycle: a new module with the old one's EEPROM.
        let mut again = BusOfOne::new(Module::with_eeprom(m.profile().clone(), m.eeprom().clone()));
        let read = |m: &mut BusOfOne, n: u8| send(m, &format!("GGP {n}, 2"));
        assert_eq!(
            [0, 17, 55, 56, 255].map(|n| read(&mut again, n)),
            [7, -123456, 2147483647, 0, 0],
            "{name}: 0…55 restored, 56…255 RAM only"
        );
        // GP 85 = 1: the stored values are not restored at start.
        send(&mut again, "SGP 85, 0, 1");
        let mut third = BusOfOne::new(Module::with_eeprom(again.profile().clone(), again.eeprom().clone()));
        assert_eq!(read(&mut third, 17), 0, "{name}: GP 85 = 1");
    }
}

#[test]
fn every_sibling_answers_the_supply_voltage_at_gio_8_bank_1() {
    // An unchanged host driver reads the supply at GIO 8, 1 on each of them
    // (the family's port, TMCM-1141 manual V1.46 section 3.7.15).
    for (name, _) in SIBLINGS {
        let mut m = BusOfOne::built_in(name);
        assert_eq!(send(&mut m, "GIO 8, 1"), 240, "{name}: 24.0 V supply");
    }
}

#[test]
fn the_tmcm_6110_downloads_2048_words() {
    // TMCM-6110 manual V1.31, section 4: up to 2048 TMCL instructions.
    let mut m = BusOfOne::built_in("tmcm-6110");
    assert_eq!(reply(&mut m, "#132 0 0 2047").status, 100);
    assert_eq!(reply(&mut m, "MST 0").status, 101, "the last word is stored");
    assert_eq!(reply(&mut m, "MST 0").status, 4, "past the end of memory");
    reply(&mut m, "#133 0 0 0");
    assert_eq!(reply(&mut m, "#132 0 0 2048").status, 4);
}
