//! EEPROM behaviour across power cycles: STAP/RSAP, STGP/RSGP, auto-stored
//! bank 0, user variables and GP 85, and the check of every image a module
//! stores (the EEPROM file is the server's: crates/server/tests/suite/eeprom_file.rs).

use crate::common;

use common::{BusOfOne, power_cycle, send};

use tmclsim_firmware::{Eeprom, Module, Profile};

#[test]
fn stap_rsap_survive_power_cycles() {
    let mut m = BusOfOne::built_in("tmcm-1141");
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
    let mut m = BusOfOne::built_in("tmcm-1141");
    send(&mut m, "SGP 75, 0, 15");
    send(&mut m, "SGP 77, 0, 1");
    let mut m = power_cycle(&m);
    assert_eq!(send(&mut m, "GGP 75, 0"), 15);
    assert_eq!(send(&mut m, "GGP 77, 0"), 1);
}

#[test]
fn user_variables_and_gp85() {
    let mut m = BusOfOne::built_in("tmcm-1141");
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
    let mut m = BusOfOne::built_in("tmcm-1141");
    m.world_mut().axes[0].right_switch = Some(1000.0);
    send(&mut m, "MVP ABS, 0, 800");
    m.advance(5_000_000_000);
    send(&mut m, "#255 0 0 1234");
    assert_eq!(send(&mut m, "GAP 1, 0"), 0, "the counter restarts at 0");
    send(&mut m, "MVP ABS, 0, 500");
    m.advance(5_000_000_000);
    assert_eq!(send(&mut m, "GAP 1, 0"), 200, "but the switch is still 200 steps away");
}

/// `execute` a command, whatever the module's address; its status.
fn run(m: &mut BusOfOne, line: &str) -> tmclsim_protocol::Status {
    m.execute(tmclsim_protocol::mnemonic::parse_line(line).unwrap_or_else(|e| panic!("{line}: {e}"))).status
}

#[test]
fn every_image_a_module_stores_passes_the_check_of_rule_88() {
    // A module driven through everything that writes its EEPROM: each
    // storable parameter at the ends of its range and where motion and
    // reference searches leave it, coordinates, a full program memory,
    // the EEPROM lock. Whatever it stored, the check accepts.
    for name in Profile::names() {
        let profile = Profile::built_in(name).unwrap();
        let mut m = BusOfOne::new(Module::new(profile.clone()));
        run(&mut m, "SGP 84, 0, 1");
        for motor in 0..profile.module.axes {
            for p in profile.axis_parameters().filter(|p| p.access.eeprom) {
                for v in [p.min, p.max, p.default] {
                    run(&mut m, &format!("SAP {}, {motor}, {}", p.number, v as i32));
                    run(&mut m, &format!("STAP {}, {motor}", p.number));
                }
            }
            run(&mut m, &format!("MVP ABS, {motor}, 5000"));
            run(&mut m, &format!("RFS START, {motor}"));
            m.advance(3_000_000_000);
            for p in profile.axis_parameters().filter(|p| p.access.eeprom) {
                run(&mut m, &format!("STAP {}, {motor}", p.number));
            }
            for n in 1..=profile.module.coordinates {
                run(&mut m, &format!("SCO {n}, {motor}, {}", i32::MIN + i32::from(n)));
            }
            run(&mut m, &format!("CCO 1, {motor}"));
        }
        run(&mut m, "SCO 0, 255, 0");
        for bank in 0..4 {
            for p in profile.global_parameters(bank).filter(|p| p.access.eeprom || p.access.auto) {
                if bank == 0 && profile.features.eeprom_lock == Some(p.number) {
                    continue;
                }
                for v in [p.min, p.max, p.default] {
                    run(&mut m, &format!("SGP {}, {bank}, {}", p.number, v as u32 as i32));
                    if p.access.eeprom {
                        run(&mut m, &format!("STGP {}, {bank}", p.number));
                    }
                }
            }
        }
        // Back to a module that answers commands (ASCII mode, code
        // protection, the address were varied above).
        run(&mut m, "SGP 81, 0, 0");
        // A download goes by frames (execute runs commands, never stores them).
        for line in [format!("#132 0 0 {}", profile.module.program_memory - 1), "ROL 0, 100".into(), "#133 0 0 0".into()] {
            let ins = tmclsim_protocol::mnemonic::parse_line(&line).unwrap();
            let frame = tmclsim_protocol::Request::new(m.address(), ins).encode();
            assert!(m.handle_frame(&frame).is_some(), "{name}: {line}");
        }
        if let Some(lock) = profile.features.eeprom_lock {
            assert_eq!(run(&mut m, &format!("SGP {lock}, 0, 1234")), tmclsim_protocol::Status::Ok);
        }
        assert!(m.eeprom().program.contains_key(&(profile.module.program_memory - 1)), "{name}");
        assert_eq!(m.eeprom().check(&profile), Ok(()), "{name}: {:#?}", m.eeprom());
        let back = Eeprom::from_json(&m.eeprom().to_json()).unwrap();
        assert_eq!(back.check(&profile), Ok(()), "{name}");
    }
}

#[test]
fn an_image_from_rust_with_values_out_of_range_powers_up_with_the_defaults() {
    // Files are refused (rule 88); an image handed over directly is not,
    // and the module still answers at once: GP 75 = 2^31 − 1 would delay
    // every reply by 24 days.
    let profile = Profile::built_in("tmcm-1141").unwrap();
    let mut image = Eeprom::new("TMCM-1141");
    image.set_global(0, 75, i32::MAX);
    image.set_global(0, 66, 0);
    image.set_axis(0, 4, i32::MIN);
    image.set_axis(0, 5, 700);
    assert!(image.check(&profile).is_err());
    let mut m = BusOfOne::new(Module::with_eeprom(profile.clone(), image));
    assert_eq!((m.reply_delay_ns(), m.address()), (0, 1));
    assert_eq!(send(&mut m, "GGP 75, 0"), 0);
    assert_eq!(send(&mut m, "GAP 4, 0"), profile.axis_parameter(4).unwrap().default as i32);
    assert_eq!(send(&mut m, "GAP 5, 0"), 700, "the values in range are taken");
    send(&mut m, "SAP 4, 0, 99");
    send(&mut m, "RSAP 4, 0");
    assert_eq!(send(&mut m, "GAP 4, 0"), profile.axis_parameter(4).unwrap().default as i32, "RSAP does not take it either");
}
