//! `#include`: files on disk relative to the including file, the shipped
//! include files, include-once, cycles.

mod common;

use std::collections::BTreeSet;
use std::path::PathBuf;

use common::tmcm_1141;
use tmclsim_asm::{MemoryResolver, assemble, assemble_file, render};

fn includes_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/includes")
}

fn shipped(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../include").join(name)
}

#[test]
fn relative_includes_on_disk_and_include_once() {
    let program = assemble_file(includes_dir().join("main.tmc"), Some(&tmcm_1141())).unwrap_or_else(|d| panic!("{}", render(&d)));
    assert_eq!(program.symbols["MoveHome"], 1);
    assert_eq!(program.symbols["Start"], 4);
    assert_eq!(program.constants["Home"], 0);
    assert_eq!(program.constants["TI_GLOBAL"], 255);
    assert_eq!(program.instructions.len(), 8);
    assert_eq!(program.instructions[0], tmclsim_asm::Instruction::new(22, 0, 0, 4));
    assert_eq!(program.instructions[4], tmclsim_asm::Instruction::new(5, 4, 0, 1000));
}

#[test]
fn include_cycle_on_disk() {
    let e = assemble_file(includes_dir().join("cycle_main.tmc"), None).unwrap_err();
    assert_eq!(e.len(), 1, "{}", render(&e));
    assert!(e[0].file.ends_with("cycle_b.inc"), "{}", e[0]);
    assert_eq!((e[0].line, e[0].column), (2, 10));
    assert!(e[0].message.starts_with("include cycle: "), "{}", e[0]);
    assert!(e[0].message.ends_with("cycle_a.inc"), "{}", e[0]);
    let e = assemble_file(includes_dir().join("self.tmc"), None).unwrap_err();
    assert_eq!(e.len(), 1, "{}", render(&e));
    assert_eq!((e[0].line, e[0].column), (2, 10));
    assert!(e[0].message.ends_with("self.tmc' includes itself"), "{}", e[0]);
}

#[test]
fn include_not_found_on_disk_names_where_it_looked() {
    let dir = std::env::temp_dir().join(format!("tmclsim-asm-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("prog.tmc");
    std::fs::write(&file, "STOP\n#include \"missing.inc\"\n").unwrap();
    let e = assemble_file(&file, None).unwrap_err();
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(e.len(), 1);
    assert_eq!((e[0].line, e[0].column), (2, 11));
    assert!(e[0].message.starts_with("cannot find include file 'missing.inc' (looked for "), "{}", e[0]);
}

#[test]
fn a_file_included_twice_is_read_once() {
    let files = MemoryResolver::new().with("a.inc", "A = 1\nSubA: RSUB\n");
    let program = assemble("#include a.inc\n#include a.inc\nCSUB SubA\n", "main.tmc", &files, None).unwrap();
    assert_eq!(program.instructions.len(), 2);
    assert_eq!(program.symbols["SubA"], 0);
}

#[test]
fn shipped_include_files_assemble_and_match_the_profile() {
    let profile = tmcm_1141();
    let interrupts = assemble_file(shipped("Interrupts.inc"), Some(&profile)).unwrap_or_else(|d| panic!("{}", render(&d)));
    assert!(interrupts.instructions.is_empty());
    let expected: BTreeSet<(String, i64)> = profile.interrupts.iter().map(|i| (i.symbol.clone(), i.number as i64)).collect();
    let found: BTreeSet<(String, i64)> = interrupts.constants.clone().into_iter().collect();
    assert_eq!(found, expected);

    let parameters = assemble_file(shipped("Parameters.inc"), Some(&profile)).unwrap_or_else(|d| panic!("{}", render(&d)));
    assert!(parameters.instructions.is_empty());
    let with_prefix = |prefix: &str| -> Vec<i64> {
        let mut v: Vec<i64> = parameters.constants.iter().filter(|(n, _)| n.starts_with(prefix)).map(|(_, &v)| v).collect();
        v.sort_unstable();
        v
    };
    let axis: Vec<i64> = profile.axis_parameters().map(|p| p.number as i64).collect();
    assert_eq!(with_prefix("AP_"), axis, "one AP_ name for every axis parameter");
    let mut global: Vec<i64> = profile.global_parameters(0).chain(profile.global_parameters(3)).map(|p| p.number as i64).collect();
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
