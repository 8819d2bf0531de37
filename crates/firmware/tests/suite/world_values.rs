//! The rule set for world values (docs/behaviour.md rule 84): control lines
//! and world files with values out of range are refused with a message that
//! names the value, the world stays as it was, and no value can make a
//! module panic.

use crate::common;

use common::{BusOfOne, MS, send};
use tmclsim_firmware::world_command::Addressed;
use tmclsim_firmware::{Bus, Module, World};

/// Parses and applies a control line to the first module of `bus`.
fn say(bus: &mut Bus, line: &str) -> Result<String, String> {
    let Addressed { address, command } = Addressed::parse(line)?;
    bus.apply_world(address, &command).map_err(String::from)
}

fn bus_of(profile: &str) -> Bus {
    Bus::single(Module::built_in(profile).unwrap())
}

#[test]
fn abuse_lines_are_refused_with_their_reason_and_change_nothing() {
    let cases: &[(&str, &str)] = &[
        ("travel 0 10 -10", "axis 0: travel from 10 to -10 is empty (FROM must be below TO)"),
        ("travel 0 5 5", "axis 0: travel from 5 to 5 is empty (FROM must be below TO)"),
        ("travel 0 nan 5", "axis 0: travel FROM NaN is not a finite number (allowed: -1e12…1e12 µsteps)"),
        ("travel 0 0 inf", "axis 0: travel TO inf is not a finite number"),
        ("supply nan", "supply NaN is not a finite number (allowed: 0…100 V)"),
        ("supply -inf", "supply -inf is not a finite number (allowed: 0…100 V)"),
        ("supply -1", "supply -1 is outside 0…100 V"),
        ("supply 230", "supply 230 is outside 0…100 V"),
        ("temperature inf", "temperature inf is not a finite number (allowed: -50…200 °C)"),
        ("temperature NaN", "temperature NaN is not a finite number"),
        ("temperature -300", "temperature -300 is outside -50…200 °C"),
        ("load 0 -1", "axis 0: load torque -1 is outside 0…1000 %"),
        ("load 0 nan", "axis 0: load torque NaN is not a finite number (allowed: 0…1000 %)"),
        ("load 0 inf", "axis 0: load torque inf is not a finite number"),
        ("load 0 50 20 10", "axis 0: load range from 20 to 10 is empty (FROM must not be above TO)"),
        ("load 0 50 nan 10", "axis 0: load range FROM NaN is not a finite number"),
        ("input 99 1", "digital input 99 does not exist on the TMCM-1141 (digital inputs: 0…3)"),
        ("input 4 0", "digital input 4 does not exist on the TMCM-1141 (digital inputs: 0…3)"),
        ("input 0 7", "expected level 0 or 1, found 7"),
        ("analog 3 100", "analog input 3 does not exist on the TMCM-1141 (analog inputs: 0)"),
        ("place 0 left nan", "axis 0: left switch position NaN is not a finite number"),
        ("place 0 right 100 -5", "axis 0: right switch width -5 is outside 0…1e12 µsteps"),
        ("place 0 left 100 inf", "axis 0: left switch width inf is not a finite number"),
        ("place 0 home 9 5", "axis 0: home switch from 9 to 5 is empty (FROM must not be above TO)"),
        ("place 0 home 0 1e300", "axis 0: home switch TO 1e300 is outside -1e12…1e12 µsteps"),
        ("travel 1 0 10", "axis 1 does not exist (the module has 1)"),
    ];
    let mut bus = bus_of("tmcm-1141");
    let before = bus.module(0).world().clone();
    for (line, expected) in cases {
        let e = say(&mut bus, line).expect_err(line);
        assert!(e.starts_with(expected), "{line}: {e}");
        assert_eq!(bus.module(0).world(), &before, "{line} changed the world");
    }
}

#[test]
fn values_in_range_are_accepted() {
    let mut bus = bus_of("tmcm-1141");
    for line in [
        "travel 0 -10 10",
        "supply 0",
        "supply 100",
        "temperature -50",
        "temperature 200",
        "load 0 0",
        "load 0 1000 5 5",
        "input 3 1",
        "analog 0 4095",
        "place 0 left 100 0",
        "place 0 home 5 5",
    ] {
        assert_eq!(say(&mut bus, line), Ok(String::new()), "{line}");
    }
    assert_eq!(bus.module(0).world().axes[0].travel, Some((-10.0, 10.0)));
    assert_eq!(bus.module(0).world().supply_decivolts, 1000);
}

#[test]
fn the_inputs_are_the_profiles() {
    let mut bus = bus_of("tmcm-351");
    assert_eq!(say(&mut bus, "input 7 1"), Ok(String::new()));
    assert_eq!(say(&mut bus, "analog 3 100"), Ok(String::new()));
    assert_eq!(say(&mut bus, "input 8 1").unwrap_err(), "digital input 8 does not exist on the TMCM-351 (digital inputs: 0…7)");
    assert_eq!(say(&mut bus, "analog 4 1").unwrap_err(), "analog input 4 does not exist on the TMCM-351 (analog inputs: 0, 1, 2, 3, 6, 7)");
}

#[test]
fn a_refused_travel_leaves_a_module_that_moves() {
    let mut bus = bus_of("tmcm-1141");
    assert!(say(&mut bus, "travel 0 10 -10").is_err());
    let m = bus.module_mut(0);
    send(m, "ROR 0, 500");
    bus.advance(1000 * MS);
    assert!(send(bus.module_mut(0), "GAP 1, 0") > 0);
}

#[test]
fn end_stops_set_around_the_rules_do_not_panic() {
    // Rust code may write the world directly; the motion holds the carriage
    // somewhere instead of panicking.
    for travel in [(10.0, -10.0), (f64::NAN, 5.0), (f64::NAN, f64::NAN), (0.0, f64::INFINITY)] {
        let mut m = BusOfOne::built_in("tmcm-1141");
        m.world_mut().axes[0].travel = Some(travel);
        send(&mut m, "ROR 0, 500");
        m.advance(200 * MS);
        let carriage = m.mechanical_position(0);
        assert!(!carriage.is_nan(), "{travel:?}: {carriage}");
        assert_eq!(send(&mut m, "GAP 2, 0"), 500, "{travel:?}");
    }
}

#[test]
fn world_files_follow_the_same_rules() {
    // The same value gives the same words from a file as from a line.
    let mut bus = bus_of("tmcm-1141");
    let pairs = [
        ("supply = nan\n", "supply nan"),
        ("temperature = inf\n", "temperature inf"),
        ("[[axis]]\ntravel = [10, -10]\n", "travel 0 10 -10"),
        ("[[axis]]\n[[axis.load]]\ntorque = -1\n", "load 0 -1"),
        ("[[axis]]\n[[axis.load]]\ntorque = nan\n", "load 0 nan"),
        ("[[axis]]\nhome_switch = { from = 9, to = 5 }\n", "place 0 home 9 5"),
        ("[[axis]]\nleft_switch = { position = 0, width = -5 }\n", "place 0 left 0 -5"),
    ];
    for (file, line) in pairs {
        let from_file = World::from_toml(file, 1).unwrap_err().to_string();
        let from_line = say(&mut bus, line).unwrap_err();
        assert_eq!(from_file, from_line, "{file}");
    }
    for (file, expected) in [
        ("[[axis]]\nstart = inf\n", "axis 0: start inf is not a finite number"),
        ("[[axis]]\nfullsteps = nan\n", "axis 0: fullsteps NaN is not a finite number"),
        ("[[axis]]\nfullsteps = 0\n", "axis 0: fullsteps 0 is outside 1…10000 steps"),
        ("[[axis]]\nencoder = -4000\n", "axis 0: encoder -4000 is outside 0…1000000 counts"),
        ("[[axis]]\n[[axis.load]]\ntorque = 5\nafter = 8\nuntil = 5\n", "axis 0: load window after 8 s until 5 s is empty"),
        ("[[axis]]\n[[axis.load]]\ntorque = 5\nafter = nan\n", "axis 0: load time NaN is not a finite number"),
        ("inputs = [0, 2]\n", "inputs[1] = 2: a level is 0 or 1"),
        ("analog = [0, 0, 0, 0, 0, 0, 0, 0, 0]\n", "analog lists 9 values: the world has 8 analog inputs"),
        ("supply = 101\n", "supply 101 is outside 0…100 V"),
    ] {
        let e = World::from_toml(file, 1).unwrap_err().to_string();
        assert!(e.starts_with(expected), "{file}: {e}");
    }
    assert!(World::from_toml("supply = 12\ntemperature = 80\n[[axis]]\ntravel = [-5, 5]\nstart = 0\n", 1).is_ok());
}

#[test]
fn the_built_in_worlds_follow_the_rules() {
    assert_eq!(World::stage(3).validate(), Ok(()));
    assert_eq!(World::free(3).validate(), Ok(()));
}

#[test]
fn reset_and_carriage_placement_bring_a_run_back_without_a_restart() {
    let mut m = Module::built_in("tmcm-1141").unwrap();
    *m.world_mut() = World::stage(1);
    let mut bus = Bus::single(Module::with_world(m.profile().clone(), m.eeprom().clone(), World::stage(1)));
    let start = World::stage(1).axes[0].start;
    // A run changes the world and drives the carriage onto the right end stop.
    say(&mut bus, "temperature 90").unwrap();
    say(&mut bus, "load 0 30").unwrap();
    send(bus.module_mut(0), "ROR 0, 2047");
    bus.advance(600_000 * MS);
    assert!(bus.module(0).switches(0).1, "the carriage stands on the right switch");
    // Placing the carriage moves it, not the motor: the counter keeps its value.
    send(bus.module_mut(0), "MST 0");
    let counter = bus.module(0).actual_position(0);
    say(&mut bus, "place 0 carriage 1000").unwrap();
    assert_eq!(bus.module(0).mechanical_position(0), 1000.0);
    assert_eq!(bus.module(0).actual_position(0), counter);
    assert!(!bus.module(0).switches(0).1, "off the switch");
    assert!(say(&mut bus, "place 0 carriage nan").unwrap_err().contains("carriage position"));
    assert!(say(&mut bus, "place 1 carriage 0").unwrap_err().contains("axis 1 does not exist"));
    // Reset: the world the module was served in, the carriage at its start.
    say(&mut bus, "reset").unwrap();
    let m = bus.module(0);
    assert_eq!(m.world(), &World::stage(1));
    assert_eq!(m.mechanical_position(0), start);
}
