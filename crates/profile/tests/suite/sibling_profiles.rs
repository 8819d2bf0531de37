//! The TMCM-1141's siblings (TMCM-1140, 3110, 6110): served from data like
//! the other profiles, with what PyTrinamic's module classes name.

use tmclsim_profile::{DefaultSource, InterruptSource, PortDirection, PortRole, Profile};

/// (profile, axes, version text, inputs, outputs).
const SIBLINGS: [(&str, u8, &[u8; 8], u8, u8); 3] =
    [("tmcm-1140", 1, b"1140V127", 4, 2), ("tmcm-3110", 3, b"3110V111", 8, 8), ("tmcm-6110", 6, b"6110V119", 8, 8)];

#[test]
fn siblings_load_with_their_axes_and_version() {
    for (name, axes, version, _, _) in SIBLINGS {
        let p = Profile::built_in(name).unwrap();
        assert_eq!(p.module.axes, axes, "{name}");
        assert_eq!(&p.version_text(), version, "{name}");
        assert_eq!(p.module.motion_controller, "TMC429", "{name}");
        assert_eq!(p.features.motion_groups, axes > 1, "{name}: AP 213 groups the axes of the multi-axis modules");
    }
}

#[test]
fn siblings_have_the_error_flags_hosts_poll_and_the_reference_switch_tolerance() {
    for (name, ..) in SIBLINGS {
        let p = Profile::built_in(name).unwrap();
        let flags = p.axis_parameter(207).unwrap();
        assert!(flags.access.read && !flags.access.write, "{name}: AP 207 is read-only");
        let driver = p.axis_parameter(208).unwrap();
        assert!(driver.access.read && !driver.access.write, "{name}: AP 208 is read-only");
        assert_eq!(driver.max, 255, "{name}: AP 208 has the eight TMC262 bits");
        assert!(p.axis_parameter(141).is_some_and(|q| q.access.write), "{name}: PyTrinamic names AP 141");
    }
    // The TMCM-1141 manual V1.46 has no AP 141.
    assert!(Profile::built_in("tmcm-1141").unwrap().axis_parameter(141).is_none());
}

#[test]
fn no_sibling_row_claims_its_own_manual() {
    // Their own manuals' tables could not be read: every default is a
    // sibling's or assumed, and every sibling default says where it is from.
    for (name, ..) in SIBLINGS {
        let p = Profile::built_in(name).unwrap();
        let rows = p.axis_parameters().chain((0..4).flat_map(|b| p.global_parameters(b)));
        for q in rows {
            assert_ne!(q.default_source, DefaultSource::Manual, "{name} parameter {} ({})", q.number, q.name);
            if q.default_source == DefaultSource::Sibling {
                assert!(q.note.as_deref().is_some_and(|n| !n.is_empty()), "{name} parameter {}", q.number);
            }
        }
    }
}

#[test]
fn every_axis_has_its_interrupts_and_trigger_rows_and_every_input_its_port() {
    for (name, axes, _, inputs, outputs) in SIBLINGS {
        let p = Profile::built_in(name).unwrap();
        for a in 0..axes {
            for s in
                [InterruptSource::TargetReached(a), InterruptSource::Stall(a), InterruptSource::StopLeft(a), InterruptSource::StopRight(a)]
            {
                assert!(p.interrupt_for(s).is_some(), "{name}: {s:?}");
            }
            assert!(p.global_parameter(3, 27 + 2 * a).is_some() && p.global_parameter(3, 28 + 2 * a).is_some(), "{name} axis {a}");
        }
        for i in 0..inputs {
            assert!(p.port(PortDirection::Input, 0, i).is_some(), "{name} IN{i}");
            assert!(p.global_parameter(3, 39 + i).is_some(), "{name} input {i} trigger");
            assert_eq!(p.interrupt_for(InterruptSource::InputChange(i)), Some(39 + i), "{name}");
        }
        assert!(p.port(PortDirection::Input, 0, inputs).is_none(), "{name}");
        for o in 0..outputs {
            assert!(p.port(PortDirection::Output, 2, o).is_some(), "{name} OUT{o}");
        }
        assert!(p.port(PortDirection::Output, 2, outputs).is_none(), "{name}");
    }
}

#[test]
fn siblings_answer_on_can_with_their_own_identifiers() {
    for (name, ..) in SIBLINGS {
        let p = Profile::built_in(name).unwrap();
        let can = p.features.can.expect(name);
        assert_eq!((can.id, can.reply_id, can.secondary_id), (71, 70, 83), "{name}");
        assert_eq!(p.global_parameter(0, 71).unwrap().default, 1, "{name}");
    }
}

#[test]
fn the_multi_axis_siblings_read_the_supply_at_gio_8_bank_1() {
    // Host drivers of the TMCM-3110 and TMCM-6110 read the supply voltage
    // at GIO 8, 1, as on the TMCM-1141 (its manual V1.46, section 3.7.15).
    for name in ["tmcm-3110", "tmcm-6110"] {
        let p = Profile::built_in(name).unwrap();
        let supply = p.port(PortDirection::Input, 1, 8).unwrap_or_else(|| panic!("{name}: GIO 8, 1"));
        assert_eq!(supply.role, Some(PortRole::Supply), "{name}");
        assert_eq!(supply.unit.as_deref(), Some("0.1 V"), "{name}");
        // 12…48 V (TMCM-3110 manual V1.11) and 9…28 V (TMCM-6110 manual V1.46) fit.
        assert!(supply.max >= 480, "{name}");
    }
}

#[test]
fn the_tmcm_6110_follows_what_its_own_manuals_state() {
    let p = Profile::built_in("tmcm-6110").unwrap();
    // TMCM-6110 manual V1.31, section 4: up to 2048 TMCL instructions; the
    // program counter (GP 130) spans them.
    assert_eq!(p.module.program_memory, 2048);
    assert_eq!(p.global_parameter(0, 130).unwrap().max, 2047);
    // TMCM-6110 manual V1.19, 5.6.5: SAP 6, 2, 47 sets 200 mA (47/255 of the
    // 1.1 A RMS of its V1.31 title page).
    let ma = 47.0 * f64::from(p.features.full_scale_current_ma) / 255.0;
    assert!((ma - 200.0).abs() < 5.0, "{ma} mA");
    // 5.6.5, 5.6.6, 5.6.8: SAP, GAP and RSAP take motor 0…5.
    assert_eq!(p.module.axes, 6);
}
