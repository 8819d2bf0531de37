//! TMCL source files on disk (the assembler reads none itself): includes
//! relative to the including file, include-once and cycles through files,
//! unreadable and endless files.

use std::path::PathBuf;
use std::sync::Arc;

use tmclsim_asm::{Profile, render};
use tmclsim_server::sources::assemble_file;

fn tmcm_1141() -> Arc<Profile> {
    Profile::built_in("tmcm-1141").expect("built-in profile")
}

fn includes_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/includes")
}

#[test]
fn relative_includes_on_disk_and_include_once() {
    let program = assemble_file(includes_dir().join("main.tmc"), Some(&tmcm_1141())).unwrap_or_else(|d| panic!("{}", render(&d)));
    assert_eq!(program.symbols["MoveHome"], 1);
    assert_eq!(program.symbols["Start"], 4);
    assert_eq!(program.constants["Home"], 0);
    assert_eq!(program.constants["TI_GLOBAL"], 255);
    // Eight words of source and the STOP the assembler appends after a last
    // word that is none (docs/behaviour.md rule 93).
    assert_eq!(program.instructions.len(), 9);
    assert_eq!(program.appended_stop_address(), Some(8));
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
fn unreadable_file() {
    let e = assemble_file("/nonexistent/prog.tmc", None).unwrap_err();
    assert_eq!(e.len(), 1);
    assert!(e[0].to_string().starts_with("/nonexistent/prog.tmc: error: cannot read the file:"), "{}", e[0]);
}

#[test]
fn an_endless_source_file_is_refused_unread() {
    let d = assemble_file("/dev/zero", None).unwrap_err();
    assert_eq!(d.len(), 1);
    assert_eq!(d[0].to_string(), "/dev/zero: error: cannot read the file: larger than 2 MiB, the limit for a source file");
}
