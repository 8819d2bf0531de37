//! The example programs of the TMCM-1141 manual (tests/programs/*.tmc):
//! each assembles against the TMCM-1141 profile and survives
//! assemble → disassemble → assemble byte for byte.

use crate::common;

use common::{asm, assemble_path, errors, example_programs, tmcm_1141};
use tmclsim_asm::{MemoryResolver, NoIncludes, assemble, render};

#[test]
fn every_manual_example_assembles_for_the_tmcm_1141() {
    let profile = tmcm_1141();
    let files = example_programs();
    assert!(files.len() >= 16, "{files:?}");
    for path in files {
        let program = assemble_path(&path, Some(&profile)).unwrap_or_else(|d| panic!("{}:\n{}", path.display(), render(&d)));
        assert!(!program.instructions.is_empty(), "{}", path.display());
    }
}

#[test]
fn first_steps_program_binary_checked_by_hand() {
    let program = assemble_path(common::programs_dir().join("first_steps_2_4.tmc"), Some(&tmcm_1141())).unwrap();
    let bin = program.to_binary();
    // Thirteen instructions, the last JA Loop, and the STOP appended.
    assert_eq!(bin.len(), 14 * 8);
    let words: Vec<&[u8]> = bin.chunks(8).collect();
    // ROL 0, 1000: opcode 2, value 0x3E8; checksum 02+03+E8 = ED.
    assert_eq!(words[0], [0x02, 0x00, 0x00, 0x00, 0x00, 0x03, 0xE8, 0xED]);
    // WAIT TICKS, 0, 500: opcode 27 = 1B, value 0x1F4; 1B+01+F4 = 110 → 10.
    assert_eq!(words[1], [0x1B, 0x00, 0x00, 0x00, 0x00, 0x01, 0xF4, 0x10]);
    // MST 0.
    assert_eq!(words[2], [0x03, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x03]);
    // ROR 0, 100: 01+64 = 65.
    assert_eq!(words[3], [0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x64, 0x65]);
    // SAP 4, 0, 100 and SAP 5, 0, 100: 05+04+64 = 6D, 05+05+64 = 6E.
    assert_eq!(words[6], [0x05, 0x04, 0x00, 0x00, 0x00, 0x00, 0x64, 0x6D]);
    assert_eq!(words[7], [0x05, 0x05, 0x00, 0x00, 0x00, 0x00, 0x64, 0x6E]);
    // Loop: MVP ABS, 0, 512000 = 0x0007D000: 04+07+D0 = DB.
    assert_eq!(words[8], [0x04, 0x00, 0x00, 0x00, 0x07, 0xD0, 0x00, 0xDB]);
    // WAIT POS, 0, 0: 1B+01 = 1C.
    assert_eq!(words[9], [0x1B, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x1C]);
    // MVP ABS, 0, -512000 = 0xFFF83000: 04+FF+F8+30 = 22B → 2B.
    assert_eq!(words[10], [0x04, 0x00, 0x00, 0xFF, 0xF8, 0x30, 0x00, 0x2B]);
    // JA Loop, Loop = 8: 16+08 = 1E.
    assert_eq!(words[12], [0x16, 0x00, 0x00, 0x00, 0x00, 0x00, 0x08, 0x1E]);
    // The program ends in JA: a STOP follows it, as in the binary TMCL-IDE
    // writes (docs/behaviour.md rule 93): 1C, six zero bytes, checksum 1C.
    assert_eq!(words[13], [0x1C, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x1C]);
    assert!(program.appended_stop);
    assert_eq!(program.appended_stop_address(), Some(13));
    assert_eq!(program.symbols["Loop"], 8);
    // The label, then the source map: "Loop:" stands alone on line 11, so
    // address 8 is the MVP of line 12; the text loses its comment.
    let symbols = program.symbol_file();
    assert!(symbols.starts_with("Loop 8\n// source map"), "{symbols}");
    let name = common::programs_dir().join("first_steps_2_4.tmc").display().to_string();
    assert!(symbols.contains(&format!("\n@0\t{name}\t2\t1\tROL 0, 1000\n")), "{symbols}");
    assert!(symbols.contains(&format!("\n@8\t{name}\t12\t1\tMVP ABS, 0, 512000\n")), "{symbols}");
    // The appended STOP comes from no line: the map ends with JA Loop.
    assert_eq!(program.source_map.len(), program.instructions.len() - 1);
    assert_eq!(program.source_of(12).map(|s| (s.line, s.text.as_str())), Some((16, "JA Loop")));
    assert_eq!(program.source_of(13), None);
    assert!(symbols.ends_with(&format!("\n@12\t{name}\t16\t1\tJA Loop\n")), "{symbols}");
}

#[test]
fn every_example_round_trips_through_the_disassembler() {
    let profile = tmcm_1141();
    for path in example_programs() {
        let program = assemble_path(&path, Some(&profile)).unwrap();
        for symbols in [Some(&program.symbols), None] {
            let text = tmclsim_asm::disassemble(&program.instructions, symbols);
            let again = assemble(&text, "disassembled.tmc", &NoIncludes, Some(&profile))
                .unwrap_or_else(|d| panic!("{}:\n{text}\n{}", path.display(), render(&d)));
            assert_eq!(again.to_binary(), program.to_binary(), "{}:\n{text}", path.display());
            if symbols.is_some() {
                assert_eq!(again.symbols, program.symbols, "{}", path.display());
            }
        }
    }
}

#[test]
fn disassembly_is_readable() {
    let program = assemble_path(common::programs_dir().join("call_3_7_44.tmc"), Some(&tmcm_1141())).unwrap();
    let text = program.disassemble();
    // 16 instructions and the STOP appended after the last one, RSUB.
    assert!(text.starts_with("// TMCL program disassembled by tmclsim-asm: 17 instruction(s)."), "{text}");
    for line in ["Loop:", "    CALL LT, RunLeft", "    CALL ZE, MotorStop", "    CALC SUB, 512", "RunRight:", "    JC ZE, MotorIsStopped"] {
        assert!(text.lines().any(|l| l.starts_with(line)), "{line}\n{text}");
    }
    let generated = tmclsim_asm::disassemble(&program.instructions, None);
    assert!(generated.contains("L7:\n    CALC MUL, -1") && generated.contains("    CALL LT, L7"), "{generated}");
}

#[test]
fn symbolic_constants_example_uses_the_shipped_parameters() {
    let program = assemble_path(common::programs_dir().join("symbolic_constants_8_3.tmc"), Some(&tmcm_1141())).unwrap();
    assert_eq!(program.constants["MaxSpeed"], 2047);
    assert_eq!(program.constants["AP_MaxPositioningSpeed"], 4);
    assert_eq!(program.constants["Motor0"], 0);
    let first: Vec<u8> = program.to_binary()[..8].to_vec();
    assert_eq!(first, [0x05, 0x04, 0x00, 0x00, 0x00, 0x07, 0xFF, 0x0F]);
    assert_eq!(program.symbols["MainLoop"], 2);
}

#[test]
fn routines_example_symbol_file_gives_the_entry_addresses() {
    let program = assemble_path(common::programs_dir().join("routines_8_6.tmc"), None).unwrap();
    let symbols = program.symbol_file();
    assert!(symbols.starts_with("Func1 0\nFunc2 1\nFunc3 2\nFunc1Start 3\n"), "{symbols}");
    assert_eq!(tmclsim_asm::Program::parse_symbol_file(&symbols).unwrap(), program.symbols);
}

#[test]
fn interrupt_example_with_include_equals_the_numeric_one() {
    let dir = common::programs_dir();
    let p = tmcm_1141();
    let numeric = assemble_path(dir.join("timer_interrupt_3_6_6.tmc"), Some(&p)).unwrap();
    let symbolic = assemble_path(dir.join("timer_interrupt_include_3_6_6.tmc"), Some(&p)).unwrap();
    assert_eq!(numeric.to_binary(), symbolic.to_binary());
    assert_eq!(symbolic.constants["TI_GLOBAL"], 255);
}

/// The lines of the manual's examples that do not work on a TMCM-1141 as
/// printed, and what the assembler says about them.
#[test]
fn the_manuals_misprints_are_reported() {
    assert_eq!(
        errors("Loop:\n  MVP ABS, REL, 51200\n  DJNZ 42, Loop\n", false),
        ["prog.tmc:2:12: error: 'REL' is a move mode, not a motor number (MVP takes ABS|REL|COORD, motor, position)"]
    );
    assert_eq!(
        errors("SAP 4, 0, 50000 //define maximum positioning speed\nSAP 5, 0, 10000\n", true),
        [
            "prog.tmc:1:11: error: value 50000 is out of range for axis parameter 4 (Maximum positioning speed): 1...2047",
            "prog.tmc:2:11: error: value 10000 is out of range for axis parameter 5 (Maximum acceleration): 1...2047",
        ]
    );
    assert_eq!(
        errors("SIO 3, 2, 1\n", true),
        ["prog.tmc:1:5: error: SIO port 3 does not exist in bank 2 of the TMCM-1141 (ports: 0, 1, 255)"]
    );
    assert_eq!(
        errors("STAP 6, 0\n", true),
        ["prog.tmc:1:6: error: axis parameter 6 (Maximum current) cannot be stored in or restored from the EEPROM (access RW)"]
    );
    // Without the include file, the symbolic names are unknown.
    let e = assemble("VECT TI_TIMER0, 5\n", "prog.tmc", &MemoryResolver::new(), None).unwrap_err();
    assert_eq!(e[0].to_string(), "prog.tmc:1:6: error: unknown constant or label 'TI_TIMER0'");
    // Numbers without a program: every one-line example also assembles
    // alone (with the STOP appended after it).
    assert_eq!(asm("CALCVV SUB, 65, 42").instructions.len(), 2);
}
