//! Random program memory: disassembled (which must always succeed and
//! reassemble to the same words, with the STOP the assembler appends when
//! they do not end in one: docs/behaviour.md rule 93) and run on the VM
//! for 200 virtual ms,
//! in one long advance and in 1 ms steps. Properties: no panic, no hang,
//! both runs end in the same state, the module still answers afterwards.
#![no_main]

use libfuzzer_sys::fuzz_target;
use tmclsim_asm::{assemble, disassemble, NoIncludes};
use tmclsim_firmware::Module;
use tmclsim_protocol::{Instruction, Request};

const MODULES: [&str; 3] = ["tmcm-1141", "tmcm-351", "tmcm-1310"];

fuzz_target!(|data: &[u8]| {
    let Some((&pick, data)) = data.split_first() else { return };
    let words: Vec<Instruction> = data.chunks_exact(7).map(|c| Instruction::from_bytes(c.try_into().unwrap())).collect();
    if words.is_empty() {
        return;
    }
    let text = disassemble(&words, None);
    let again = assemble(&text, "again.tmc", &NoIncludes, None).unwrap_or_else(|e| panic!("disassembly does not assemble: {e:?}\n{text}"));
    let mut ended = words.clone();
    if tmclsim_asm::binary::needs_end_stop(&words) {
        ended.push(tmclsim_asm::binary::END_STOP);
    }
    assert_eq!(again.instructions, ended, "\n{text}");
    let start = || {
        let mut module = Module::built_in(MODULES[pick as usize % 3]).unwrap();
        module.load_program(&words).ok()?;
        module.start_program();
        Some(module)
    };
    let Some(mut module) = start() else { return };
    module.advance(200_000_000);
    let mut stepped = start().unwrap();
    for ms in 1..=200u64 {
        stepped.advance_to(ms * 1_000_000);
    }
    assert_eq!(module.program().pc, stepped.program().pc);
    assert_eq!(module.program().executed, stepped.program().executed);
    let probe = Request::new(module.address(), Instruction::new(136, 1, 0, 0)).encode();
    if !module.ascii_mode() {
        let _ = module.handle_frame(&probe);
    }
});
