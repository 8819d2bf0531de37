//! What an observer reads off a virtual module without changing it
//! (docs/behaviour.md rule 86): the IDE's program state, the Python
//! package's `Module` and its sweeps read here.

use tmclsim_firmware::Module;
use tmclsim_firmware::module::error_flag;
use tmclsim_protocol::{Instruction, Reply, opcode};

/// The interpreter's error flags, each bit with the name CLE and JC give
/// it.
const ERROR_FLAGS: [(u8, &str); 5] = [
    (error_flag::TIMEOUT, "ETO"),
    (error_flag::ALARM, "EAL"),
    (error_flag::DEVIATION, "EDV"),
    (error_flag::POSITION, "EPO"),
    (error_flag::SHUTDOWN, "ESD"),
];

/// The names of the set error flags (`errors` as the interpreter keeps
/// them): "ETO", "EAL", "EDV", "EPO", "ESD".
pub fn error_flag_names(errors: u8) -> Vec<&'static str> {
    ERROR_FLAGS.iter().filter(|(bit, _)| errors & bit != 0).map(|(_, name)| *name).collect()
}

/// AP 207, the extended error flags of `motor` (1 stall stop, 2 position
/// deviation, 4 encoder lost), as an observer reads it: without clearing
/// it as a GAP 207 does, so that the program reads what it would have
/// read. 0 on a module without AP 207.
pub fn extended_error_flags(m: &Module, motor: u8) -> i32 {
    m.observe(Instruction::new(opcode::GAP, 207, motor, 0))
        .and_then(|raw| Reply::decode(&raw))
        .filter(|r| r.status >= 100)
        .map_or(0, |r| r.value)
}

/// Whether the carriage of `motor` stands at one of the world's mechanical
/// end stops (never in a world without them, nor for a motor the module
/// lacks).
pub fn at_end_stop(m: &Module, motor: usize) -> bool {
    let Some((lo, hi)) = m.world().axes.get(motor).and_then(|a| a.travel) else { return false };
    let c = m.mechanical_position(motor);
    c <= lo || c >= hi
}

#[cfg(test)]
mod tests {
    use super::*;
    use tmclsim_protocol::mnemonic::parse_line;

    #[test]
    fn error_flags_by_the_names_cle_and_jc_give_them() {
        assert_eq!(error_flag_names(0), Vec::<&str>::new());
        assert_eq!(error_flag_names(error_flag::TIMEOUT | error_flag::SHUTDOWN), ["ETO", "ESD"]);
        assert_eq!(error_flag_names(0xFF), ["ETO", "EAL", "EDV", "EPO", "ESD"]);
    }

    fn gap(bus: &mut tmclsim_firmware::Bus, line: &str) -> i32 {
        let raw = bus.handle_frame(&tmclsim_protocol::Request::new(1, parse_line(line).unwrap()).encode()).replies[0];
        Reply::decode(&raw).unwrap().value
    }

    #[test]
    fn ap_207_as_the_program_reads_it() {
        let mut bus = tmclsim_firmware::Bus::single(Module::built_in("tmcm-1141").unwrap());
        assert_eq!(extended_error_flags(bus.module(0), 0), gap(&mut bus, "GAP 207, 0"));
        assert_eq!(extended_error_flags(bus.module(0), 0), 0);
    }

    #[test]
    fn at_an_end_stop_when_the_carriage_stands_on_it() {
        let profile = tmclsim_profile::Profile::built_in("tmcm-1141").unwrap();
        let mut world = tmclsim_firmware::World::free(1);
        assert!(!at_end_stop(&Module::with_world(profile.clone(), tmclsim_firmware::Eeprom::new("TMCM-1141"), world.clone()), 0));
        world.axes[0].travel = Some((-1000.0, 1000.0));
        let m = Module::with_world(profile.clone(), tmclsim_firmware::Eeprom::new("TMCM-1141"), world);
        let mut bus = tmclsim_firmware::Bus::single(m);
        assert!(!at_end_stop(bus.module(0), 0));
        gap(&mut bus, "ROR 0, 2047");
        bus.advance(1_000_000_000);
        assert!(at_end_stop(bus.module(0), 0), "the carriage ran into the end stop");
        assert!(!at_end_stop(bus.module(0), 5), "no such motor");
    }
}
