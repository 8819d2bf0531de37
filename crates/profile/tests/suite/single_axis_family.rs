//! The TMCM-1110 (stepRocker), TMCM-1140 and TMCM-1160: three TMC429 +
//! TMC262 modules that are nothing but their profiles. What their own
//! manuals' reachable pages state (firmware version, chips, interfaces, the
//! TMCM-1110's missing ASCII interface) and which parameters and ports
//! PyTrinamic's classes and ADI's tmcl_ros lists name, module by module.

use std::collections::BTreeSet;
use tmclsim_profile::{DefaultSource, InterruptSource, PortDirection, Profile};

/// (profile, version text of the 136 reply, full-scale current in mA).
const MODULES: [(&str, &[u8; 8], u32); 3] =
    [("tmcm-1110", b"1110V109", 1100), ("tmcm-1140", b"1140V127", 2000), ("tmcm-1160", b"1160V147", 2800)];

fn axis_numbers(p: &Profile) -> BTreeSet<u8> {
    p.axis_parameters().map(|q| q.number).collect()
}

fn global_numbers(p: &Profile, bank: u8) -> BTreeSet<u8> {
    p.global_parameters(bank).map(|q| q.number).collect()
}

#[test]
fn version_chips_and_interfaces_as_the_first_pages_of_their_manuals_state() {
    for (name, version, current) in MODULES {
        let p = Profile::built_in(name).unwrap();
        assert_eq!(&p.version_text(), version, "{name}");
        let number: u16 = name[5..].parse().unwrap();
        assert_eq!(p.module.type_number, number, "{name}");
        assert_eq!(p.version_word() >> 16, i32::from(number), "{name}: type number in the high word");
        assert_eq!(p.module.axes, 1, "{name}");
        assert_eq!(p.module.motion_controller, "TMC429", "{name}");
        assert!(p.features.coolstep, "{name}: coolStep");
        assert!(!p.features.closed_loop && !p.features.motion_groups, "{name}");
        assert_eq!(p.features.full_scale_current_ma, current, "{name}");
        // USB, RS485 and CAN: the module's own CAN identifiers.
        let can = p.features.can.expect(name);
        assert_eq!((can.id, can.reply_id, can.secondary_id), (71, 70, 83), "{name}");
        assert_eq!(p.baud_rate(8), 230_400, "{name}");
    }
    assert_eq!(Profile::built_in("tmcm-1160").unwrap().version_word(), 0x0488_012F, "1160, V1.47");
    assert_eq!(Profile::built_in("tmcm-1110").unwrap().version_word(), 0x0456_0109, "1110, V1.09");
}

#[test]
fn only_the_stepper_without_an_ascii_interface_section_lacks_ascii_mode() {
    // The TMCM-1110 manual V1.09 goes from standalone applications (3.3) to
    // the command overview (3.4): no ASCII interface, no command 139, no GP 67.
    let p = Profile::built_in("tmcm-1110").unwrap();
    assert!(!p.has_opcode(139));
    assert!((0..=255).all(|o| !p.ascii_allows(o)));
    assert!(p.global_parameter(0, 67).is_none());
    for name in ["tmcm-1140", "tmcm-1160"] {
        let p = Profile::built_in(name).unwrap();
        assert!(p.has_opcode(139) && p.ascii_allows(4) && !p.ascii_allows(19), "{name}");
        assert!(p.global_parameter(0, 67).is_some(), "{name}");
    }
    // The PD-1160 manual V1.42 lists commands up to ACO (39) and the UF0…UF7
    // user functions; the TMCM-1141 V1.46's later CALCVV (40) is not among them.
    let p = Profile::built_in("tmcm-1160").unwrap();
    for o in [1, 15, 19, 28, 33, 36, 37, 38, 39, 64, 71, 128, 136, 138, 139, 255] {
        assert!(p.has_opcode(o), "TMCM-1160 opcode {o}");
    }
    for o in [16, 29, 40, 46, 80] {
        assert!(!p.has_opcode(o), "TMCM-1160 opcode {o}");
    }
}

#[test]
fn axis_parameters_are_those_pytrinamic_and_tmcl_ros_name() {
    let shared: BTreeSet<u8> = [0u8, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 130, 135, 138, 140, 141, 149, 153, 154]
        .into_iter()
        .chain(160..=184)
        .chain([193, 194, 195, 196, 204, 206, 208, 209, 210, 212, 214])
        .collect();
    let with = |extra: &[u8]| shared.iter().copied().chain(extra.iter().copied()).collect::<BTreeSet<u8>>();
    let p = |name| Profile::built_in(name).unwrap();
    assert_eq!(axis_numbers(&p("tmcm-1110")), with(&[213, 254]));
    assert_eq!(axis_numbers(&p("tmcm-1140")), with(&[150, 197, 200, 207, 215, 216, 217, 218]));
    assert_eq!(axis_numbers(&p("tmcm-1160")), with(&[150, 197, 200, 207, 215, 216, 217, 218, 254]));
    // Bank 0: the family's rows; the stepRocker has no ASCII mode.
    let bank0: BTreeSet<u8> =
        [65u8, 66, 67, 68, 69, 70, 71, 75, 76, 77, 79, 81, 82, 83, 84, 85, 87, 90, 128, 129, 130, 132, 133, 255].into();
    assert_eq!(global_numbers(&p("tmcm-1140"), 0), bank0);
    assert_eq!(global_numbers(&p("tmcm-1160"), 0), bank0);
    assert_eq!(global_numbers(&p("tmcm-1110"), 0), bank0.iter().copied().filter(|&n| n != 67).collect());
    for name in ["tmcm-1110", "tmcm-1140", "tmcm-1160"] {
        let p = p(name);
        // Not modelled: last TMCL error (GP 131), and no bank 1.
        assert!(p.global_parameter(0, 131).is_none() && !p.has_bank(1), "{name}");
        assert_eq!(p.global_parameters(2).count(), 256, "{name}");
        assert!(p.global_parameter(2, 55).unwrap().access.eeprom && !p.global_parameter(2, 56).unwrap().access.eeprom, "{name}");
    }
}

#[test]
fn ranges_and_access_of_the_family() {
    for (name, ..) in MODULES {
        let p = Profile::built_in(name).unwrap();
        let ap = |n| p.axis_parameter(n).unwrap();
        assert_eq!((ap(4).min, ap(4).max, ap(4).access.to_string().as_str()), (1, 2047, "RWE"), "{name} AP 4");
        assert_eq!((ap(6).min, ap(6).max, ap(6).access.to_string().as_str()), (0, 255, "RW"), "{name} AP 6");
        assert_eq!((ap(140).max, ap(140).default), (8, 8), "{name}: 256 microsteps");
        assert_eq!((ap(174).min, ap(174).max), (-64, 63), "{name}: stallGuard2 threshold");
        assert_eq!(ap(206).max, 1023, "{name}: stallGuard2 load");
        assert_eq!(ap(208).access.to_string(), "R", "{name}");
        assert_eq!(ap(193).range_text(), "1…8, 65…68, 133…136", "{name}");
        assert!(ap(3).access.read && !ap(3).access.write, "{name}: actual speed is read-only");
        let gp = |n| p.global_parameter(0, n).unwrap();
        assert_eq!((gp(65).max, gp(65).access.to_string().as_str()), (8, "RWA"), "{name}");
        assert_eq!((gp(66).default, gp(76).default), (1, 2), "{name}: address 1, host 2");
        assert_eq!(gp(71).default, 1, "{name}: CAN ID");
    }
}

#[test]
fn the_steprocker_starts_as_trinamics_steprocker_code_does() {
    // Trinamic's stepRocker Mini-TMCL (Globals.c), for this board: speed
    // 1000, acceleration 500, run current 255, standby 32, divisors 3 and 2.
    let p = Profile::built_in("tmcm-1110").unwrap();
    for (n, default) in [(4u8, 1000), (5, 500), (6, 255), (7, 32), (153, 3), (154, 2), (181, 0), (204, 0), (214, 200)] {
        let q = p.axis_parameter(n).unwrap();
        assert_eq!((q.default, q.default_source), (default, DefaultSource::Sibling), "AP {n}");
    }
    // The TMCM-1140 and 1160 keep the family's TMC-API values.
    for name in ["tmcm-1140", "tmcm-1160"] {
        let p = Profile::built_in(name).unwrap();
        assert_eq!([5u8, 153, 154].map(|n| p.axis_parameter(n).unwrap().default), [1000, 7, 3], "{name}");
    }
}

#[test]
fn no_row_claims_a_manual_whose_tables_were_not_read_and_every_sibling_names_its_source() {
    for (name, ..) in MODULES {
        let p = Profile::built_in(name).unwrap();
        let rows = p.axis_parameters().chain((0..4).flat_map(|b| p.global_parameters(b)));
        for q in rows {
            assert_ne!(q.default_source, DefaultSource::Manual, "{name} parameter {} ({})", q.number, q.name);
            if q.default_source == DefaultSource::Sibling {
                assert!(q.note.as_deref().is_some_and(|n| n.len() > 20), "{name} parameter {}", q.number);
            }
        }
        // The TMC429's motion registers start at zero (Init429).
        for n in [0u8, 1, 2, 3, 135, 138, 149] {
            let q = p.axis_parameter(n).unwrap();
            assert_eq!((q.default, q.default_source), (0, DefaultSource::Sibling), "{name} AP {n}");
        }
    }
}

#[test]
fn ports_interrupts_and_trigger_rows_of_each_module() {
    // (profile, inputs, outputs): PyTrinamic's IO classes.
    for (name, inputs, outputs) in [("tmcm-1110", 7u8, 8u8), ("tmcm-1140", 4, 2), ("tmcm-1160", 2, 2)] {
        let p = Profile::built_in(name).unwrap();
        for i in 0..inputs {
            assert!(p.port(PortDirection::Input, 0, i).is_some(), "{name} IN{i}");
            assert_eq!(p.interrupt_for(InterruptSource::InputChange(i)), Some(39 + i), "{name} IN{i}");
            assert!(p.global_parameter(3, 39 + i).is_some(), "{name} IN{i} trigger");
        }
        assert!(p.port(PortDirection::Input, 0, inputs).is_none(), "{name}");
        assert!(p.global_parameter(3, 39 + inputs).is_none(), "{name}");
        for o in 0..outputs {
            assert!(p.port(PortDirection::Output, 2, o).is_some(), "{name} OUT{o}");
        }
        assert!(p.port(PortDirection::Output, 2, outputs).is_none(), "{name}");
        for s in [InterruptSource::TargetReached(0), InterruptSource::Stall(0), InterruptSource::StopLeft(0), InterruptSource::StopRight(0)]
        {
            assert!(p.interrupt_for(s).is_some(), "{name}: {s:?}");
        }
        assert_eq!((p.timer_interrupt(0), p.timer_interrupt(2)), (Some(0), Some(2)), "{name}");
        assert!(p.global_parameter(3, 27).is_some() && p.global_parameter(3, 28).is_some(), "{name}");
        // The stepRocker's step/direction axes 1 and 2 are not modelled.
        assert!(p.global_parameter(3, 29).is_none(), "{name}");
    }
    // Only the TMCM-1140's profile reads the supply (GIO 8, 1).
    assert!(Profile::built_in("tmcm-1140").unwrap().port(PortDirection::Input, 1, 8).is_some());
    for name in ["tmcm-1110", "tmcm-1160"] {
        assert!(Profile::built_in(name).unwrap().ports.iter().all(|q| q.bank != 1), "{name}");
    }
}
