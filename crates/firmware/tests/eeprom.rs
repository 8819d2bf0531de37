//! EEPROM behaviour across power cycles: STAP/RSAP, STGP/RSGP, auto-stored
//! bank 0, user variables and GP 85, and persistence through the file.

mod common;

use common::send;

use tmclsim_firmware::{Eeprom, Module, Profile};

fn power_cycle(m: &Module) -> Module {
    Module::with_eeprom(m.profile().clone(), m.eeprom().clone())
}

#[test]
fn stap_rsap_survive_power_cycles() {
    let mut m = Module::built_in("tmcm-1141").unwrap();
    send(&mut m, "SAP 4, 0, 1234");
    send(&mut m, "STAP 4, 0");
    send(&mut m, "SAP 4, 0, 99");
    send(&mut m, "SAP 5, 0, 77"); // not stored
    assert_eq!(send(&mut m, "GAP 4, 0"), 99);
    send(&mut m, "RSAP 4, 0");
    assert_eq!(send(&mut m, "GAP 4, 0"), 1234);
    send(&mut m, "SAP 4, 0, 99");
    let mut m = power_cycle(&m);
    assert!(m.restored_from_eeprom());
    assert_eq!(send(&mut m, "GAP 4, 0"), 1234);
    assert_eq!(send(&mut m, "GAP 5, 0"), m.profile().axis_parameter(5).unwrap().default as i32);
}

#[test]
fn bank0_is_stored_automatically() {
    let mut m = Module::built_in("tmcm-1141").unwrap();
    send(&mut m, "SGP 75, 0, 15");
    send(&mut m, "SGP 77, 0, 1");
    let mut m = power_cycle(&m);
    assert_eq!(send(&mut m, "GGP 75, 0"), 15);
    assert_eq!(send(&mut m, "GGP 77, 0"), 1);
}

#[test]
fn user_variables_and_gp85() {
    let mut m = Module::built_in("tmcm-1141").unwrap();
    send(&mut m, "SGP 42, 2, 4242");
    send(&mut m, "STGP 42, 2");
    send(&mut m, "SGP 42, 2, 1");
    send(&mut m, "RSGP 42, 2");
    assert_eq!(send(&mut m, "GGP 42, 2"), 4242);
    send(&mut m, "SGP 100, 2, 5"); // RAM only
    let mut m = power_cycle(&m);
    assert_eq!(send(&mut m, "GGP 42, 2"), 4242);
    assert_eq!(send(&mut m, "GGP 100, 2"), 0);
    // GP 85 = 1: user variables are not restored (but stay stored).
    send(&mut m, "SGP 85, 0, 1");
    let mut m = power_cycle(&m);
    assert_eq!(send(&mut m, "GGP 42, 2"), 0);
    send(&mut m, "RSGP 42, 2");
    assert_eq!(send(&mut m, "GGP 42, 2"), 4242);
}

#[test]
fn restart_keeps_the_carriage_where_it_is() {
    let mut m = Module::built_in("tmcm-1141").unwrap();
    m.world_mut().axes[0].right_switch = Some(1000.0);
    send(&mut m, "MVP ABS, 0, 800");
    m.advance(5_000_000_000);
    send(&mut m, "#255 0 0 1234");
    assert_eq!(send(&mut m, "GAP 1, 0"), 0, "the counter restarts at 0");
    send(&mut m, "MVP ABS, 0, 500");
    m.advance(5_000_000_000);
    assert_eq!(send(&mut m, "GAP 1, 0"), 200, "but the switch is still 200 steps away");
}

#[test]
fn eeprom_file_round_trip_and_atomic_writes() {
    let dir = std::env::temp_dir().join(format!("tmclsim-ee-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("1141.eeprom");
    let profile = Profile::built_in("tmcm-1141").unwrap();
    let mut m = Module::new(profile.clone());
    send(&mut m, "SAP 4, 0, 321");
    send(&mut m, "STAP 4, 0");
    tmclsim_firmware::eeprom::save_atomic(&path, m.eeprom()).unwrap();
    let image = Eeprom::load(&path).unwrap().unwrap();
    let mut m = Module::with_eeprom(profile, image);
    assert_eq!(send(&mut m, "GAP 4, 0"), 321);
    // No temporary files are left behind.
    let names: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(names.len(), 1, "{names:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}
