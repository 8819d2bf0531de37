//! The assembler on arbitrary source text. Properties: no panic; every
//! error has a line and column (inside the source when it is about the
//! source); an assembled program disassembles to source that assembles to
//! the same words.
#![no_main]

use libfuzzer_sys::fuzz_target;
use tmclsim_asm::{assemble, NoIncludes, Profile};

fuzz_target!(|data: &[u8]| {
    let Ok(source) = std::str::from_utf8(data) else { return };
    let profile = Profile::built_in("tmcm-1141").unwrap();
    match assemble(source, "fuzz.tmc", &NoIncludes, Some(&profile)) {
        Ok(program) => {
            let text = program.disassemble();
            let again =
                assemble(&text, "again.tmc", &NoIncludes, None).unwrap_or_else(|e| panic!("disassembly does not assemble: {e:?}\n{text}"));
            assert_eq!(again.instructions, program.instructions, "\n{text}");
        }
        Err(diagnostics) => {
            assert!(!diagnostics.is_empty());
            let lines = source.split('\n').count();
            // Lines are checked for the source itself; a diagnostic may
            // also point into a shipped include file.
            for d in &diagnostics {
                assert!(d.line >= 1, "{d:?}");
                assert!(d.file != "fuzz.tmc" || d.line <= lines.max(1), "{d:?} in {lines} lines");
                assert!(d.column >= 1, "{d:?}");
            }
        }
    }
});
