//! ASCII mode: the module switched to ASCII (139) and fed arbitrary
//! characters, and the mnemonic line parser on arbitrary text. Properties:
//! no panic; a parsed line formats to text that parses to the same
//! instruction.
#![no_main]

use libfuzzer_sys::fuzz_target;
use tmclsim_firmware::Module;
use tmclsim_protocol::mnemonic::{format, parse_line};
use tmclsim_protocol::{Instruction, Request};

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        for line in text.lines() {
            if let Ok(ins) = parse_line(line) {
                let again = parse_line(&format(ins));
                assert_eq!(again, Ok(ins), "{line:?} → {:?}", format(ins));
            }
        }
    }
    let mut module = Module::built_in("tmcm-1141").unwrap();
    let switch = Request::new(1, Instruction::new(139, 0, 0, 0)).encode();
    let _ = module.handle_frame(&switch);
    let mut out = Vec::new();
    let mut now = 0;
    for &b in data {
        module.ascii_byte(b, &mut out);
        now += 1_000_000;
        module.advance_to(now);
        out.clear();
    }
});
