//! The world file parser (TOML) on arbitrary text, and a module moving in
//! every world it accepts. Properties: no panic; errors are readable text.
#![no_main]

use libfuzzer_sys::fuzz_target;
use tmclsim_firmware::{Eeprom, Module, Profile, World};
use tmclsim_protocol::{Instruction, Request};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let world = match World::from_toml(text, 1) {
        Ok(w) => w,
        Err(e) => {
            assert!(!e.to_string().is_empty());
            return;
        }
    };
    let profile = Profile::built_in("tmcm-1141").unwrap();
    let mut module = Module::with_world(profile, Eeprom::new("TMCM-1141"), world);
    for (i, line) in [(0u8, 2_000_000i32), (1, -2_000_000), (13, 1)].into_iter().enumerate() {
        let ins = if line.0 == 13 { Instruction::new(13, 1, 0, 0) } else { Instruction::new(4, 0, 0, line.1) };
        let _ = module.handle_frame(&Request::new(1, ins).encode());
        module.advance_to((i as u64 + 1) * 20_000_000_000);
    }
});
