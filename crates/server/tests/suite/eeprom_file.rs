//! EEPROM files with the modules that keep them: what a module stores
//! comes back after a save and a load, and a file holding what the module
//! never stores is refused.

use crate::common;

use tmclsim_firmware::{Eeprom, Module, Profile};
use tmclsim_server::eeprom_file::{LoadError, load, load_for, save_atomic};

/// Sends a command that must succeed (status 100) and returns its value.
fn send(m: &mut Module, line: &str) -> i32 {
    let r = tmclsim_protocol::Reply::decode(&m.handle_frame(&common::frame(line)).expect("a reply")).unwrap();
    assert_eq!(r.status, 100, "{line}");
    r.value
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
    save_atomic(&path, m.eeprom()).unwrap();
    let image = load(&path).unwrap().unwrap();
    let mut m = Module::with_eeprom(profile, image);
    assert_eq!(send(&mut m, "GAP 4, 0"), 321);
    // No temporary files are left behind.
    let names: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(names.len(), 1, "{names:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_file_with_a_value_out_of_range_is_refused_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.eeprom");
    let profile = Profile::built_in("tmcm-1141").unwrap();
    let mut image = Eeprom::new("TMCM-1141");
    image.set_global(0, 75, i32::MAX);
    save_atomic(&path, &image).unwrap();
    let e = load_for(&path, &profile).unwrap_err();
    assert!(matches!(e, LoadError::Refused(_)), "{e:?}");
    assert_eq!(
        e.to_string(),
        format!(
            "{}: refused: an entry a TMCM-1141 never stores, so the file was edited or damaged: global \"0/75\" = 2147483647: \
             GP 75 (Telegram pause time) of bank 0 takes 0…255; correct or remove it (or remove the file to start from factory \
             defaults)",
            path.display()
        )
    );
}
