//! A module's profile as the app shows it: parameter tables with access,
//! range, default and its source, ports, commands, the reference search
//! modes by name, and what the unit conversion needs (which rows are
//! velocities and accelerations and in which units, the motion
//! controller's clock, the axis parameters a conversion reads).

use serde_json::{Value, json};
use tmclsim_profile::{MotionUnits, Parameter, PortDirection, Profile, Quantity};
use tmclsim_profile::{ReferenceSearchFamily, StallDetection};

/// The velocities of a sixPoint module whose unit AP 255 (unit mode)
/// selects (docs/behaviour.md rules 104, 108, 111): target and actual
/// speed (AP 2, 3), VMAX (4), V1 (16), VSTART (19), VSTOP (20), the
/// driver's threshold speeds (high speed 22, dcStep 23, stop on stall 181,
/// coolStep 182, stealthChop 186) and the reference search speeds (194,
/// 195), and an eight-point module's V2 (35, rule 113; the eight-point
/// modules have no unit mode: pps always). AP 29 (measured speed) is pps
/// in either mode.
const SIXPOINT_VELOCITIES: [u8; 14] = [2, 3, 4, 16, 19, 20, 22, 23, 35, 181, 182, 186, 194, 195];

/// The accelerations of a sixPoint module whose unit AP 255 selects: AMAX
/// (AP 5), A1 (15), DMAX (17), D1 (18), and an eight-point module's A2
/// (34) and D2 (36).
const SIXPOINT_ACCELERATIONS: [u8; 6] = [5, 15, 17, 18, 34, 36];

/// The velocities of a TMC4361A module whose unit AP 255 selects
/// (docs/behaviour.md rule 114): target and actual speed (AP 2, 3), VMAX
/// (4), VSTART (15), VBREAK (18), VSTOP (20), the stall and coolStep
/// threshold speeds (181, 182) and the reference search speeds (194,
/// 195).
const TMC4361A_VELOCITIES: [u8; 10] = [2, 3, 4, 15, 18, 20, 181, 182, 194, 195];

/// The accelerations of a TMC4361A module whose unit AP 255 selects:
/// AMAX (AP 5), ASTART (16), DMAX (17), DFINAL (19), DSTOP (21). The bows
/// (22–25) are pps³ in either unit mode, no quantity of the conversion.
const TMC4361A_ACCELERATIONS: [u8; 5] = [5, 16, 17, 19, 21];

/// The name a profile gives a quantity.
fn quantity_name(q: Quantity) -> &'static str {
    match q {
        Quantity::Velocity => "velocity",
        Quantity::Acceleration => "acceleration",
    }
}

/// A velocity or an acceleration by the profile's unit of the row: what a
/// pps module's rows (and a sixPoint module's that are pps in either unit
/// mode) say they are.
fn quantity_by_unit(p: &Parameter) -> Option<&'static str> {
    match p.unit.as_deref()? {
        "pps" => Some("velocity"),
        "pps²" | "pps^2" | "pps/s" => Some("acceleration"),
        _ => None,
    }
}

/// What an axis parameter's value is for the app's unit conversion: the
/// quantity (`"velocity"`, `"acceleration"`) and the units it is in
/// (`"tmc429"`: the TMC429's with the motor's divisors; `"pps"`: pps and
/// pps² as written; `"sixpoint"`: as AP 255 selects). On a TMC429 module
/// the profile's `quantity` says it; on a pps module the row's unit (pps,
/// pps²); on a sixPoint module the rows of the sixPoint roles, and the
/// other rows in pps by their unit; on a TMC4361A module (`"tmc4361a"`:
/// as AP 255 selects, 1 pps, 0 the chip's 24.8 and 22.2 registers) the
/// rows of its roles likewise.
pub fn quantity(profile: &Profile, p: &Parameter) -> Option<(&'static str, &'static str)> {
    match profile.features.motion_units {
        MotionUnits::Tmc429 => p.quantity.map(|q| (quantity_name(q), "tmc429")),
        MotionUnits::Pps => quantity_by_unit(p).map(|q| (q, "pps")),
        MotionUnits::Sixpoint => {
            if SIXPOINT_VELOCITIES.contains(&p.number) {
                Some(("velocity", "sixpoint"))
            } else if SIXPOINT_ACCELERATIONS.contains(&p.number) {
                Some(("acceleration", "sixpoint"))
            } else {
                quantity_by_unit(p).map(|q| (q, "pps"))
            }
        }
        MotionUnits::Tmc4361a => {
            if TMC4361A_VELOCITIES.contains(&p.number) {
                Some(("velocity", "tmc4361a"))
            } else if TMC4361A_ACCELERATIONS.contains(&p.number) {
                Some(("acceleration", "tmc4361a"))
            } else {
                quantity_by_unit(p).map(|q| (q, "pps"))
            }
        }
    }
}

/// The axis parameters a conversion of the motor's velocities and
/// accelerations reads, by role, those the profile has: the microstep
/// resolution (AP 140, for rpm) and, in TMC429 units, the ramp and pulse
/// divisors (AP 153, 154), in sixPoint units the unit mode (AP 255).
fn conversion(profile: &Profile) -> Value {
    let roles: &[(&str, u8)] = match profile.features.motion_units {
        MotionUnits::Tmc429 => &[("microsteps", 140), ("ramp_divisor", 153), ("pulse_divisor", 154)],
        MotionUnits::Pps => &[("microsteps", 140)],
        MotionUnits::Sixpoint | MotionUnits::Tmc4361a => &[("microsteps", 140)],
    };
    let has = |n: u8| profile.axis_parameters().any(|p| p.number == n);
    let mut roles: serde_json::Map<String, Value> = roles.iter().filter(|(_, n)| has(*n)).map(|(k, n)| (k.to_string(), json!(n))).collect();
    // The unit mode's row, where the module has one (else always pps).
    if let Some(n) = profile.features.unit_mode {
        roles.insert("unit_mode".to_string(), json!(n));
    }
    Value::Object(roles)
}

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
        "quantity": p.quantity.map(quantity_name),
        "quantity_units": p.quantity.map(|_| "tmc429"),
    });
    if let Some(b) = bank {
        v["bank"] = json!(b);
    }
    v
}

/// An axis parameter's row: with its quantity as the conversion takes it.
fn axis_parameter(profile: &Profile, p: &Parameter) -> Value {
    let mut v = parameter(p, None);
    let q = quantity(profile, p);
    v["quantity"] = json!(q.map(|(q, _)| q));
    v["quantity_units"] = json!(q.map(|(_, u)| u));
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
    let axis: Vec<Value> = profile.axis_parameters().map(|p| axis_parameter(profile, p)).collect();
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
        "motion_units": profile.features.motion_units.name(),
        "motion_controller": profile.features.motion_controller.name(),
        "conversion": conversion(profile),
        "axis_parameters": axis, "global_parameters": global,
        "inputs": port(PortDirection::Input), "outputs": port(PortDirection::Output),
        "tuning": tuning(profile),
        "reference_modes": reference_modes(profile.features.reference_search).into_iter().map(|(v, n)| json!({"value": v, "name": n})).collect::<Vec<_>>(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;
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

    fn row(json: &Value, number: u8) -> &Value {
        json["axis_parameters"].as_array().unwrap().iter().find(|r| r["number"] == number).unwrap_or_else(|| panic!("no AP {number}"))
    }

    /// (quantity, units) of every axis parameter that has one.
    fn quantities(json: &Value) -> Vec<(u64, String, String)> {
        json["axis_parameters"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|r| !r["quantity"].is_null())
            .map(|r| (r["number"].as_u64().unwrap(), r["quantity"].as_str().unwrap().into(), r["quantity_units"].as_str().unwrap().into()))
            .collect()
    }

    /// A sixPoint module made from the TMCM-1141's profile: the sixPoint
    /// motion controller and units, without the TMC429's rows (AP 130,
    /// 135, 138, 149, 153, 154) and quantities, with the speeds and
    /// accelerations in the chip's ranges (AP 2–5), the ramp rows
    /// (AP 15–21), the driver's threshold speeds (22, 23, 186), the
    /// measured speed (29) and the unit mode (255).
    fn sixpoint_profile() -> Arc<Profile> {
        let text = include_str!("../../../profiles/tmcm-1141.toml");
        let mut sections: Vec<String> = text.split("\n[").map(str::to_string).collect();
        let gone = [2, 3, 4, 5, 130, 135, 138, 149, 153, 154].map(|n| format!("[axis_parameter]]\nnumber = {n}\n"));
        sections.retain(|s| !gone.iter().any(|g| s.starts_with(g.as_str())));
        let mut text = sections.join("\n[").lines().filter(|l| !l.starts_with("quantity =")).collect::<Vec<_>>().join("\n");
        text = text.replace("[features]\n", "[features]\nmotion_controller = \"sixpoint\"\nmotion_units = \"sixpoint\"\nunit_mode = 255\n");
        let rows: [(u8, &str, i64, &str); 17] = [
            (2, "Target velocity", 8_388_096, "pps"),
            (3, "Actual velocity", 8_388_096, "pps"),
            (4, "Maximum positioning velocity", 8_388_096, "pps"),
            (5, "Maximum acceleration", 7_629_278, "pps²"),
            (15, "Acceleration A1", 7_629_278, "pps²"),
            (16, "Velocity V1", 1_048_575, "pps"),
            (17, "Maximum deceleration", 7_629_278, "pps²"),
            (18, "Deceleration D1", 7_629_278, "pps²"),
            (19, "Start velocity (VSTART)", 262_143, "pps"),
            (20, "Stop velocity (VSTOP)", 262_143, "pps"),
            (21, "Ramp wait time (TZEROWAIT)", 65_535, "512 clocks"),
            (22, "High speed threshold (THIGH)", 8_388_096, "pps"),
            (23, "Minimum dcStep speed (VDCMIN)", 8_388_096, "pps"),
            (29, "Measured speed", 8_388_096, "pps"),
            (186, "PWM threshold speed", 8_388_096, "pps"),
            (187, "PWM gradient", 255, ""),
            (255, "Unit mode", 1, ""),
        ];
        for (number, name, max, unit) in rows {
            let default = if number == 255 { 1 } else { 0 };
            let min = if number <= 3 { -max } else { 0 };
            let unit = if unit.is_empty() { String::new() } else { format!("unit = \"{unit}\"\n") };
            text.push_str(&format!(
                "\n[[axis_parameter]]\nnumber = {number}\nname = \"{name}\"\naccess = \"RW\"\nmin = {min}\nmax = {max}\ndefault = {default}\n\
                 default_source = \"assumed\"\n{unit}source = \"a test\"\n"
            ));
        }
        Arc::new(Profile::from_toml(&text).unwrap())
    }

    /// On a sixPoint module the velocities and accelerations are the rows
    /// whose unit AP 255 selects (the ramp's, the threshold speeds, the
    /// reference search speeds), converted with the unit mode and the
    /// microstep resolution; the measured speed is pps either way; the ramp
    /// wait and the positions are no quantity.
    #[test]
    fn a_sixpoint_module_says_which_rows_follow_the_unit_mode() {
        let json = of(&sixpoint_profile());
        assert_eq!((json["motion_units"].as_str(), json["motion_controller"].as_str()), (Some("sixpoint"), Some("sixpoint")));
        assert_eq!(json["conversion"], json!({"microsteps": 140, "unit_mode": 255}));
        let velocities =
            [2, 3, 4, 16, 19, 20, 22, 23, 181, 182, 186, 194, 195].map(|n| (n, "velocity".to_string(), "sixpoint".to_string()));
        let accelerations = [5, 15, 17, 18].map(|n| (n, "acceleration".to_string(), "sixpoint".to_string()));
        let mut expected: Vec<_> = velocities.into_iter().chain(accelerations).chain([(29, "velocity".into(), "pps".into())]).collect();
        expected.sort();
        let mut got = quantities(&json);
        got.sort();
        assert_eq!(got, expected);
        assert_eq!((row(&json, 21)["quantity"].clone(), row(&json, 21)["unit"].as_str()), (Value::Null, Some("512 clocks")));
    }

    /// A TMC4361A module's profile as a test makes it: the TMCM-1141's
    /// rows with the TMC4361A's ramp rows (TMCL-Lite 1316 numbering).
    fn tmc4361a_profile() -> Arc<Profile> {
        let text = include_str!("../../../profiles/tmcm-1141.toml");
        let mut sections: Vec<String> = text.split("\n[").map(str::to_string).collect();
        let gone = [2, 3, 4, 5, 12, 13, 130, 135, 138, 149, 153, 154].map(|n| format!("[axis_parameter]]\nnumber = {n}\n"));
        sections.retain(|s| !gone.iter().any(|g| s.starts_with(g.as_str())));
        let mut text = sections.join("\n[").lines().filter(|l| !l.starts_with("quantity =")).collect::<Vec<_>>().join("\n");
        text = text.replace(
            "[features]\n",
            "[features]\nmotion_controller = \"tmc4361a\"\nmotion_units = \"tmc4361a\"\nunit_mode = 255\nlimit_switch_rows = \"enable-polarity\"\n",
        );
        let rows: [(u8, &str, i64, &str); 15] = [
            (2, "Target velocity", 8_388_607, "pps"),
            (3, "Actual velocity", 8_388_607, "pps"),
            (4, "Maximum positioning velocity", 8_388_607, "pps"),
            (5, "Maximum acceleration", 16_777_215, "pps²"),
            (12, "Right limit switch enable/polarity", 3, ""),
            (13, "Left limit switch enable/polarity", 3, ""),
            (14, "Ramp type", 1, ""),
            (15, "Start velocity", 8_388_607, "pps"),
            (16, "Start acceleration", 16_777_215, "pps²"),
            (17, "Maximum deceleration", 16_777_215, "pps²"),
            (18, "Break velocity", 8_388_607, "pps"),
            (19, "Final deceleration", 16_777_215, "pps²"),
            (21, "Stop deceleration", 16_777_215, "pps²"),
            (22, "Bow 1", 16_777_215, "pps³"),
            (255, "Unit mode", 1, ""),
        ];
        for (number, name, max, unit) in rows {
            let default = if number == 255 { 1 } else { 0 };
            let min = if number <= 3 { -max } else { 0 };
            let unit = if unit.is_empty() { String::new() } else { format!("unit = \"{unit}\"\n") };
            text.push_str(&format!(
                "\n[[axis_parameter]]\nnumber = {number}\nname = \"{name}\"\naccess = \"RW\"\nmin = {min}\nmax = {max}\ndefault = {default}\n\
                 default_source = \"assumed\"\n{unit}source = \"a test\"\n"
            ));
        }
        Arc::new(Profile::from_toml(&text).unwrap())
    }

    /// On a TMC4361A module the ramp's velocities and accelerations follow
    /// the unit mode (`tmc4361a`: 24.8 and 22.2 registers in unit mode 0);
    /// a bow is pps³ either way, no quantity.
    #[test]
    fn a_tmc4361a_module_says_which_rows_follow_the_unit_mode() {
        let json = of(&tmc4361a_profile());
        assert_eq!((json["motion_units"].as_str(), json["motion_controller"].as_str()), (Some("tmc4361a"), Some("tmc4361a")));
        assert_eq!(json["conversion"], json!({"microsteps": 140, "unit_mode": 255}));
        let mut got = quantities(&json);
        got.sort();
        let velocities = [2, 3, 4, 15, 18, 181, 182, 194, 195].map(|n| (n, "velocity".to_string(), "tmc4361a".to_string()));
        let accelerations = [5, 16, 17, 19, 21].map(|n| (n, "acceleration".to_string(), "tmc4361a".to_string()));
        let mut expected: Vec<_> = velocities.into_iter().chain(accelerations).filter(|(n, _, _)| got.iter().any(|g| g.0 == *n)).collect();
        expected.sort();
        assert_eq!(got, expected);
        assert_eq!(row(&json, 22)["quantity"], Value::Null, "a bow");
        assert!(got.iter().any(|g| g.0 == 194), "the reference search speed follows the unit mode");
    }

    /// The conversion the app makes of a sixPoint module's values is the
    /// module's: in unit mode 0 a velocity v runs at v·f_CLK/2^24 pps (the
    /// measured speed, AP 29, is pps) and an acceleration a speeds the
    /// motor up by a·f_CLK²/2^41 pps per second; in unit mode 1 both are
    /// pps as written.
    #[test]
    fn a_sixpoint_module_s_units_are_the_firmware_s() {
        let profile = sixpoint_profile();
        let clock = f64::from(of(&profile)["motion_clock_hz"].as_u64().unwrap() as u32);
        let measured = |mode: i32, v: i32, a: i32, seconds: f64| {
            let mut bus = Bus::single(Module::new(profile.clone()));
            for (n, x) in [(255, mode), (5, a)] {
                value(&mut bus, Instruction::new(opcode::SAP, n, 0, x));
            }
            value(&mut bus, Instruction::new(opcode::ROR, 0, 0, v));
            bus.advance((seconds * 1e9) as u64);
            (value(&mut bus, Instruction::new(opcode::GAP, 29, 0, 0)), value(&mut bus, Instruction::new(opcode::GAP, 3, 0, 0)))
        };
        // Unit mode 0: 100 000 units are 95 367 pps; 1000 units of
        // acceleration 116 415 pps², 11 642 pps after 0.1 s.
        let (pps, speed) = measured(0, 100_000, 1000, 2.0);
        assert!((f64::from(pps) - 100_000.0 * clock / 2f64.powi(24)).abs() <= 1.0, "{pps}");
        assert!((f64::from(speed) - 100_000.0).abs() <= 1.0, "AP 3 in the chip's units: {speed}");
        let (pps, _) = measured(0, 100_000, 1000, 0.1);
        assert!((f64::from(pps) - 1000.0 * clock * clock / 2f64.powi(41) * 0.1).abs() <= 2.0, "{pps}");
        // Unit mode 1: pps as written.
        let (pps, speed) = measured(1, 20_000, 100_000, 1.0);
        assert!((f64::from(pps) - 20_000.0).abs() <= 1.0 && (f64::from(speed) - 20_000.0).abs() <= 1.0, "{pps} {speed}");
    }

    /// A pps module (the TMCM-1310): its rows in pps and pps² by their
    /// unit, converted with the microstep resolution only; AP 153 and 154
    /// (supply voltage and current there) are no divisors.
    #[test]
    fn a_pps_module_s_speeds_are_pps_by_their_unit() {
        let json = of(&Profile::built_in("tmcm-1310").unwrap());
        assert_eq!((json["motion_units"].as_str(), json["motion_controller"].as_str()), (Some("pps"), Some("tmc429")));
        assert_eq!(json["conversion"], json!({"microsteps": 140}));
        for n in [2, 3, 4, 181, 194, 195] {
            assert_eq!(
                (row(&json, n)["quantity"].as_str(), row(&json, n)["quantity_units"].as_str()),
                (Some("velocity"), Some("pps")),
                "AP {n}"
            );
        }
        assert_eq!(row(&json, 5)["quantity"], "acceleration");
        assert!(row(&json, 1)["quantity"].is_null());
        let rows = json["axis_parameters"].as_array().unwrap();
        assert!(rows.iter().filter(|r| r["number"] == 153 || r["number"] == 154).all(|r| r["quantity"].is_null()));
    }

    /// A TMC429 module as before: the profile's quantities, converted with
    /// the microstep resolution and the ramp and pulse divisors.
    #[test]
    fn a_tmc429_module_s_quantities_are_the_profile_s() {
        let p = Profile::built_in("tmcm-1141").unwrap();
        let json = of(&p);
        assert_eq!(json["motion_units"], "tmc429");
        assert_eq!(json["conversion"], json!({"microsteps": 140, "ramp_divisor": 153, "pulse_divisor": 154}));
        let from_profile: Vec<_> = p
            .axis_parameters()
            .filter_map(|r| r.quantity.map(|q| (u64::from(r.number), quantity_name(q).to_string(), "tmc429".to_string())))
            .collect();
        assert_eq!(quantities(&json), from_profile);
        assert_eq!(row(&json, 130)["quantity"], "velocity");
    }

    /// The tuning tools' roles have the same numbers on a sixPoint module;
    /// and every built-in sixPoint profile agrees with the roles above:
    /// the rows that follow the unit mode say pps or pps², and of the
    /// others only the measured speed does.
    #[test]
    fn the_tuning_roles_and_the_sixpoint_rows_agree_with_the_profiles() {
        let json = of(&sixpoint_profile());
        let t = &json["tuning"];
        assert_eq!(t["stallguard2"], json!({"threshold": 174, "filter": 173, "stop_speed": 181, "load": 206, "stall_flag": 207}));
        assert_eq!(t["coolstep"]["threshold_speed"], 182);
        assert_eq!(t["coolstep"]["actual_current"], 180);
        assert_eq!(t["reference_search"]["search_speed"], 194);
        for name in Profile::names() {
            let p = Profile::built_in(name).unwrap();
            if p.features.motion_units != MotionUnits::Sixpoint {
                continue;
            }
            for r in p.axis_parameters() {
                let role = SIXPOINT_VELOCITIES.contains(&r.number) || SIXPOINT_ACCELERATIONS.contains(&r.number);
                let by_unit = quantity_by_unit(r);
                if role {
                    let expected = if SIXPOINT_VELOCITIES.contains(&r.number) { "velocity" } else { "acceleration" };
                    assert_eq!(by_unit, Some(expected), "{name} AP {} ({}) says {:?}", r.number, r.name, r.unit);
                } else {
                    assert!(by_unit.is_none() || r.number == 29, "{name} AP {} ({}) says {:?}", r.number, r.name, r.unit);
                }
            }
            let t = &of(&p)["tuning"];
            for (role, number) in t["stallguard2"].as_object().into_iter().chain(t["coolstep"].as_object()).flatten() {
                assert!(p.axis_parameters().any(|r| json!(r.number) == *number), "{name}: {role} AP {number}");
            }
        }
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
