//! EEPROM file text on arbitrary bytes: every image that parses is checked
//! against each module (docs/behaviour.md rule 88) and powered up, whether
//! the check accepts it or not (Rust code may hand a module any image).
//! Properties: no panic; the check refuses exactly when it names refused
//! entries, and its message names the first; a module powered up from any
//! image answers at once (a telegram pause of at most 255 ms) at an
//! address its GP 66 takes.
#![no_main]

use libfuzzer_sys::fuzz_target;
use tmclsim_firmware::{Eeprom, Module, Profile};

const MODULES: [&str; 3] = ["tmcm-1141", "tmcm-351", "tmcm-1310"];

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let Ok(parsed) = Eeprom::from_json(text) else { return };
    for name in MODULES {
        let profile = Profile::built_in(name).unwrap();
        let mut image = parsed.clone();
        image.module = profile.module.name.clone();
        let refused = image.refused_entries(&profile);
        match image.check(&profile) {
            Ok(()) => assert!(refused.is_empty(), "{refused:?}"),
            Err(e) => {
                let first = refused.first().unwrap_or_else(|| panic!("refused without an entry: {e}"));
                assert!(e.to_string().contains(&first.to_string()), "{e}");
            }
        }
        let module = Module::with_eeprom(profile.clone(), image);
        assert!(module.reply_delay_ns() <= 255_000_000, "{name}: {} ns", module.reply_delay_ns());
        let address = profile.global_parameter(0, 66).unwrap();
        assert!(address.accepts(module.address() as i32), "{name}: address {}", module.address());
    }
});
