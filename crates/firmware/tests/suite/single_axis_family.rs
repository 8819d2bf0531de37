//! The TMCM-1110 (stepRocker), TMCM-1140 and TMCM-1160 on the wire: modules
//! made of a profile and nothing else answer as their data say (version,
//! power-up values, ports, the stepRocker's missing ASCII mode) and run the
//! family's motion, stallGuard2 and EEPROM behaviour unchanged.

use crate::common;

use common::{BusOfOne, MS, load, reply, send, status};

use tmclsim_firmware::Module;
use tmclsim_protocol::{Instruction, Reply, Request, Status};

const MODULES: [(&str, &[u8; 8]); 3] = [("tmcm-1110", b"1110V109"), ("tmcm-1140", b"1140V127"), ("tmcm-1160", b"1160V147")];

#[test]
fn command_136_names_each_module_and_its_firmware() {
    for (name, version) in MODULES {
        let mut m = BusOfOne::built_in(name);
        let text = m.handle_frame(&Request::new(1, Instruction::new(136, 0, 0, 0)).encode()).unwrap();
        assert_eq!(&text[1..], version, "{name}");
        let r = Reply::decode(&m.handle_frame(&Request::new(1, Instruction::new(136, 1, 0, 0)).encode()).unwrap()).unwrap();
        assert_eq!(r.value, m.profile().version_word(), "{name}");
    }
}

#[test]
fn power_up_values_are_the_profiles_defaults() {
    let mut m = BusOfOne::built_in("tmcm-1110");
    assert_eq!(["GAP 5, 0", "GAP 6, 0", "GAP 7, 0", "GAP 153, 0", "GAP 154, 0"].map(|c| send(&mut m, c)), [500, 255, 32, 3, 2]);
    for name in ["tmcm-1140", "tmcm-1160"] {
        let mut m = BusOfOne::built_in(name);
        assert_eq!(["GAP 5, 0", "GAP 153, 0", "GAP 154, 0", "GAP 140, 0"].map(|c| send(&mut m, c)), [1000, 7, 3, 8], "{name}");
        assert_eq!(send(&mut m, "GGP 71, 0"), 1, "{name}: CAN ID");
    }
}

#[test]
fn parameters_a_module_lacks_answer_wrong_type() {
    let wrong = Status::WrongType.code();
    let mut m = BusOfOne::built_in("tmcm-1110");
    for c in ["GAP 150, 0", "GAP 200, 0", "GAP 207, 0", "GAP 215, 0", "GGP 67, 0", "GGP 131, 0"] {
        assert_eq!(status(&mut m, c), wrong, "TMCM-1110 {c}");
    }
    assert_eq!(send(&mut m, "GAP 213, 0"), 0, "the group index is held");
    let mut m = BusOfOne::built_in("tmcm-1160");
    assert_eq!(send(&mut m, "GAP 254, 0"), 0);
    assert_eq!(status(&mut m, "GGP 131, 0"), wrong);
    let mut m = BusOfOne::built_in("tmcm-1140");
    assert_eq!(status(&mut m, "GAP 254, 0"), wrong);
}

#[test]
fn the_steprocker_has_no_ascii_mode_and_the_others_do() {
    let mut m = BusOfOne::built_in("tmcm-1110");
    assert_eq!(status(&mut m, "#139 0 0 0"), Status::InvalidCommand.code());
    assert!(!m.ascii_mode());
    for name in ["tmcm-1140", "tmcm-1160"] {
        let mut m = BusOfOne::built_in(name);
        assert_eq!(status(&mut m, "#139 0 0 0"), Status::Ok.code(), "{name}");
        assert!(m.ascii_mode(), "{name}");
    }
}

#[test]
fn inputs_and_outputs_of_each_module() {
    for (name, inputs, outputs) in [("tmcm-1110", 7, 8), ("tmcm-1140", 4, 2), ("tmcm-1160", 2, 2)] {
        let mut m = BusOfOne::built_in(name);
        for i in 0..inputs {
            assert!((0..=1).contains(&send(&mut m, &format!("GIO {i}, 0"))), "{name} IN{i}");
        }
        assert_ne!(status(&mut m, &format!("GIO {inputs}, 0")), 100, "{name}: no IN{inputs}");
        for o in 0..outputs {
            send(&mut m, &format!("SIO {o}, 2, 1"));
            assert_eq!(send(&mut m, &format!("GIO {o}, 2")), 1, "{name} OUT{o}");
        }
        assert_ne!(status(&mut m, &format!("SIO {outputs}, 2, 1")), 100, "{name}: no OUT{outputs}");
    }
    // The TMCM-1140 reads the supply at GIO 8, 1 (24.0 V in the default world).
    let mut m = BusOfOne::built_in("tmcm-1140");
    assert_eq!(send(&mut m, "GIO 8, 1"), 240);
}

#[test]
fn each_moves_and_stops_on_a_stall() {
    for (name, _) in MODULES {
        let mut m = BusOfOne::built_in(name);
        send(&mut m, "MVP ABS, 0, 20000");
        m.advance(5000 * MS);
        assert_eq!(send(&mut m, "GAP 1, 0"), 20000, "{name}");
        assert_eq!(send(&mut m, "GAP 8, 0"), 1, "{name}");
        // stallGuard2: stop on stall above speed 300.
        send(&mut m, "SAP 6, 0, 255");
        send(&mut m, "SAP 181, 0, 300");
        send(&mut m, "ROR 0, 500");
        m.advance(500 * MS);
        assert_ne!(send(&mut m, "GAP 3, 0"), 0, "{name} runs");
        load(&mut m, 150.0);
        m.advance(10 * MS);
        assert_eq!(send(&mut m, "GAP 3, 0"), 0, "{name}: stopped on the stall");
        let at = send(&mut m, "GAP 1, 0");
        m.advance(100 * MS);
        assert_eq!(send(&mut m, "GAP 1, 0"), at, "{name}: stays stopped");
        // AP 207 reports the stop where the module has it (not the stepRocker).
        let flags = reply(&mut m, "GAP 207, 0");
        if name == "tmcm-1110" {
            assert_eq!(flags.status, Status::WrongType.code());
        } else {
            assert_eq!(flags.value, 1, "{name}: stallGuard2 stop flag");
        }
    }
}

#[test]
fn stored_parameters_survive_a_power_cycle() {
    for (name, _) in MODULES {
        let mut m = BusOfOne::built_in(name);
        send(&mut m, "SAP 4, 0, 1234");
        send(&mut m, "STAP 4, 0");
        send(&mut m, "SGP 7, 2, -42");
        send(&mut m, "STGP 7, 2");
        let mut again = Module::with_eeprom(m.profile().clone(), m.eeprom().clone());
        assert_eq!((send(&mut again, "GAP 4, 0"), send(&mut again, "GGP 7, 2")), (1234, -42), "{name}");
    }
}
