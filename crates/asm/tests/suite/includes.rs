//! `#include`: the shipped include files, include-once. Files on disk
//! relative to the including file and cycles through them are read by the
//! server's file resolver and tested there (crates/server/tests/suite/sources.rs).

use crate::common;

use std::collections::BTreeSet;
use std::path::PathBuf;

use common::{assemble_path, tmcm_1141};
use tmclsim_asm::{MemoryResolver, assemble, render};

fn shipped(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../include").join(name)
}

#[test]
fn a_file_included_twice_is_read_once() {
    let files = MemoryResolver::new().with("a.inc", "A = 1\nSubA: RSUB\n");
    let program = assemble("#include a.inc\n#include a.inc\nCSUB SubA\n", "main.tmc", &files, None).unwrap();
    // RSUB, CSUB and the STOP appended after it (docs/behaviour.md rule 93).
    assert_eq!(program.instructions.len(), 3);
    assert_eq!(program.symbols["SubA"], 0);
}

#[test]
fn shipped_include_files_assemble_and_match_the_profile() {
    let profile = tmcm_1141();
    let interrupts = assemble_path(shipped("Interrupts.inc"), Some(&profile)).unwrap_or_else(|d| panic!("{}", render(&d)));
    // Constants only: the program is the STOP the assembler appends.
    assert_eq!(interrupts.instructions, [tmclsim_asm::binary::END_STOP]);
    let expected: BTreeSet<(String, i64)> = profile.interrupts.iter().map(|i| (i.symbol.clone(), i64::from(i.number))).collect();
    let found: BTreeSet<(String, i64)> = interrupts.constants.clone().into_iter().collect();
    assert_eq!(found, expected);

    let parameters = assemble_path(shipped("Parameters.inc"), Some(&profile)).unwrap_or_else(|d| panic!("{}", render(&d)));
    assert_eq!(parameters.instructions, [tmclsim_asm::binary::END_STOP]);
    let with_prefix = |prefix: &str| -> Vec<i64> {
        let mut v: Vec<i64> = parameters.constants.iter().filter(|(n, _)| n.starts_with(prefix)).map(|(_, &v)| v).collect();
        v.sort_unstable();
        v
    };
    let axis: Vec<i64> = profile.axis_parameters().map(|p| i64::from(p.number)).collect();
    assert_eq!(with_prefix("AP_"), axis, "one AP_ name for every axis parameter");
    let mut global: Vec<i64> = profile.global_parameters(0).chain(profile.global_parameters(3)).map(|p| i64::from(p.number)).collect();
    global.sort_unstable();
    assert_eq!(with_prefix("GP_"), global, "one GP_ name for every parameter of banks 0 and 3");
    assert_eq!(parameters.constants["Motor0"], 0);
    assert_eq!(parameters.constants["AP_TargetPosition"], 0);
    assert_eq!(parameters.constants["AP_ActualPosition"], 1);
    assert_eq!(parameters.constants["AP_MaxPositioningSpeed"], 4);
    assert_eq!(parameters.constants["GP_TickTimer"], 132);

    // Both together, used by a program, checked against the profile.
    let source = "#include Parameters.inc\n#include Interrupts.inc\n\
        SAP AP_MaxCurrent, Motor0, 128\nGGP GP_TickTimer, GlobalBank\nSGP GP_Timer0Period, InterruptBank, 1000\n\
        SGP GP_Input0Trigger, InterruptBank, 3\nVECT TI_INPUTCHANGE0, Irq\nEI TI_INPUTCHANGE0\nEI TI_GLOBAL\nIrq: RETI\n";
    assemble(source, "use.tmc", &MemoryResolver::new(), Some(&profile)).unwrap_or_else(|d| panic!("{}", render(&d)));
}

#[test]
fn shipped_files_are_the_built_in_ones() {
    for (name, text) in tmclsim_asm::include::BUILT_IN {
        assert_eq!(std::fs::read_to_string(shipped(name)).unwrap(), *text);
    }
}
