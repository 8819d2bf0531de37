//! A module's profile as the app shows it: parameter tables with access,
//! range, default and its source, ports, commands, the reference search
//! modes by name, and what the unit conversion needs (which rows are
//! velocities and accelerations, the motion controller's clock).

use serde_json::{Value, json};
use tmclsim_profile::{Parameter, PortDirection, Profile, Quantity};
use tmclsim_profile::{ReferenceSearchFamily, StallDetection};

fn parameter(p: &Parameter, bank: Option<u8>) -> Value {
    let a = &p.access;
    let access: String = [(a.read, 'R'), (a.write, 'W'), (a.eeprom, 'E')].iter().filter(|(on, _)| *on).map(|(_, c)| *c).collect();
    let source = match p.default_source {
        tmclsim_profile::DefaultSource::Manual => "manual",
        tmclsim_profile::DefaultSource::Sibling => "sibling",
        tmclsim_profile::DefaultSource::Assumed => "assumed",
    };
    let mut v = json!({
        "number": p.number, "name": p.label(), "unit": p.unit, "access": access,
        "min": p.min, "max": p.max, "default": p.default, "default_source": source,
        "note": p.note, "storable": a.eeprom, "ranges": p.ranges,
        "snake": crate::names::snake(p.label()),
        "quantity": p.quantity.map(|q| match q {
            Quantity::Velocity => "velocity",
            Quantity::Acceleration => "acceleration",
        }),
    });
    if let Some(b) = bank {
        v["bank"] = json!(b);
    }
    v
}

/// The modes AP 193 selects, as the manuals name them.
fn reference_modes(family: ReferenceSearchFamily) -> Vec<(i64, &'static str)> {
    match family {
        // TMCM-1141 manual, table 16, AP 193.
        ReferenceSearchFamily::Tmc429 => vec![
            (1, "1: left stop switch only"),
            (2, "2: right stop switch, then left stop switch"),
            (3, "3: right stop switch, then left stop switch from both sides"),
            (4, "4: left stop switch from both sides"),
            (5, "5: home switch, negative direction, reverse at the left stop switch"),
            (6, "6: home switch, positive direction, reverse at the right stop switch"),
            // Chapter 7.1's directions (docs/behaviour.md rule 49).
            (7, "7: home switch, negative direction, end switches ignored"),
            (8, "8: home switch, positive direction, end switches ignored"),
            (65, "65: right stop switch only (1 + 64)"),
            (66, "66: left stop switch, then right stop switch (2 + 64)"),
            (67, "67: left stop switch, then right stop switch from both sides (3 + 64)"),
            (68, "68: right stop switch from both sides (4 + 64)"),
            (133, "133: mode 5, home switch inverted (5 + 128)"),
            (134, "134: mode 6, home switch inverted (6 + 128)"),
            (135, "135: mode 7, home switch inverted (7 + 128)"),
            (136, "136: mode 8, home switch inverted (8 + 128)"),
        ],
        // TMCM-351 manual 5.7.5–5.7.8.
        ReferenceSearchFamily::Tmc428 => vec![
            (1, "1: left reference switch only"),
            (2, "2: right switch, then left switch"),
            (3, "3: right switch, then the reference switch"),
        ],
    }
}

/// The axis parameters of the tuning tools, by their role, for the
/// features the profile has (TMCM-1141 manual, table 16; the same numbers
/// on every module with these features). A role the module has no row for
/// is left out; a feature it lacks is null.
fn tuning(profile: &Profile) -> Value {
    let f = &profile.features;
    let has = |n: u8| profile.axis_parameters().any(|p| p.number == n);
    let roles = |pairs: &[(&str, u8)]| -> Value {
        let map: serde_json::Map<String, Value> = pairs.iter().filter(|(_, n)| has(*n)).map(|(k, n)| (k.to_string(), json!(n))).collect();
        Value::Object(map)
    };
    let stallguard2 = (f.stall_detection == StallDetection::Stallguard2)
        .then(|| roles(&[("threshold", 174), ("filter", 173), ("stop_speed", 181), ("load", 206), ("stall_flag", 207)]));
    let coolstep = f.coolstep.then(|| {
        roles(&[
            ("max_current", 6),
            ("minimum", 168),
            ("down_step", 169),
            ("hysteresis", 170),
            ("up_step", 171),
            ("hysteresis_start", 172),
            ("actual_current", 180),
            ("threshold_speed", 182),
            ("load", 206),
        ])
    });
    let reference = roles(&[
        ("mode", 193),
        ("search_speed", 194),
        ("switch_speed", 195),
        ("distance", 196),
        ("last_position", 197),
        ("left", 11),
        ("right", 10),
        ("home", 9),
    ]);
    json!({ "stallguard2": stallguard2, "coolstep": coolstep, "reference_search": reference })
}

/// A profile as the app reads it: the module, its commands, parameters,
/// inputs and outputs, and tuning hints.
pub fn of(profile: &Profile) -> Value {
    let m = &profile.module;
    let commands: Vec<&str> = m.opcodes.iter().filter_map(|&o| tmclsim_protocol::opcode::mnemonic(o)).collect();
    let axis: Vec<Value> = profile.axis_parameters().map(|p| parameter(p, None)).collect();
    let global: Vec<Value> = (0..=3u8).flat_map(|b| profile.global_parameters(b).map(move |p| parameter(p, Some(b)))).collect();
    let port = |d: PortDirection| -> Vec<Value> {
        profile
            .ports
            .iter()
            .filter(|p| p.direction == d)
            .map(|p| json!({"bank": p.bank, "number": p.number, "name": p.name, "min": p.min, "max": p.max, "unit": p.unit, "analog": d == PortDirection::Input && p.max > 1}))
            .collect()
    };
    json!({
        "name": m.name, "axes": m.axes, "program_memory": m.program_memory,
        "user_variables": m.user_variables, "commands": commands,
        "motion_clock_hz": profile.features.motion_clock_hz,
        "axis_parameters": axis, "global_parameters": global,
        "inputs": port(PortDirection::Input), "outputs": port(PortDirection::Output),
        "tuning": tuning(profile),
        "reference_modes": reference_modes(profile.features.reference_search).into_iter().map(|(v, n)| json!({"value": v, "name": n})).collect::<Vec<_>>(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use tmclsim_firmware::{Bus, Module};
    use tmclsim_protocol::{Instruction, Reply, Request, opcode};

    fn value(bus: &mut Bus, ins: Instruction) -> i32 {
        let reply = bus.handle_frame(&Request::new(1, ins).encode()).replies[0];
        Reply::decode(&reply).unwrap().value
    }

    /// The names of modes 7 and 8 say the direction the firmware searches
    /// in (docs/behaviour.md rule 49), from the middle of the stage.
    #[test]
    fn the_home_search_modes_are_named_by_the_direction_they_move() {
        for (mode, name) in reference_modes(ReferenceSearchFamily::Tmc429) {
            if !(7..=8).contains(&mode) {
                continue;
            }
            let mut bus = Bus::single(Module::built_in("tmcm-1141").unwrap());
            value(&mut bus, Instruction::new(opcode::SAP, 193, 0, mode as i32));
            value(&mut bus, Instruction::new(opcode::RFS, 0, 0, 0));
            bus.advance(200_000_000);
            let speed = value(&mut bus, Instruction::new(opcode::GAP, 3, 0, 0));
            let named = if name.contains("negative") { -1 } else { 1 };
            assert_eq!(speed.signum(), named, "mode {mode} ({name}) moves at {speed}");
        }
    }

    #[test]
    fn the_tuning_tools_parameters_follow_the_features() {
        let p = Profile::built_in("tmcm-1141").unwrap();
        let t = &of(&p)["tuning"];
        assert_eq!(t["stallguard2"]["threshold"], 174);
        assert_eq!(t["stallguard2"]["load"], 206);
        assert_eq!(t["coolstep"]["hysteresis_start"], 172);
        assert_eq!(t["coolstep"]["actual_current"], 180);
        assert_eq!(t["reference_search"]["switch_speed"], 195);
        // A module without stallGuard2 or coolStep has neither tool.
        let q = Profile::built_in("tmcm-351").unwrap();
        assert!(q.features.stall_detection != StallDetection::Stallguard2 && !q.features.coolstep);
        let t = &of(&q)["tuning"];
        assert!(t["stallguard2"].is_null() && t["coolstep"].is_null());
    }

    #[test]
    fn each_user_variable_is_named_by_its_number() {
        let p = Profile::built_in("tmcm-1141").unwrap();
        let rows = of(&p)["global_parameters"].as_array().unwrap().clone();
        let row = rows.iter().find(|r| r["bank"] == 2 && r["number"] == 17).unwrap();
        assert_eq!(row["name"], "User variable 17");
        assert_eq!(row["snake"], "user_variable_17");
    }
}
