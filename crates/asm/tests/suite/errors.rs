//! Diagnostics: exact file:line:column and message for each kind of error,
//! every error of a file reported, never more than one per mistake.

use crate::common;

use common::{asm_1141, errors, tmcm_1141};
use tmclsim_asm::{MemoryResolver, assemble};

fn one(source: &str, profile: bool) -> String {
    let e = errors(source, profile);
    assert_eq!(e.len(), 1, "{e:#?}");
    e[0].clone()
}

#[test]
fn unknown_mnemonic() {
    assert_eq!(one("ROL 0, 1000\n  MVPP ABS, 0, 10\n", false), "prog.tmc:2:3: error: unknown instruction 'MVPP' (did you mean 'MVP'?)");
    assert_eq!(one("Start\nJA Start", false), "prog.tmc:1:1: error: unknown instruction 'Start' (a label needs a colon: 'Start:')");
}

#[test]
fn unknown_label() {
    assert_eq!(one("Loop:\n  MVP ABS, 0, 0\n  JA Lop\n", false), "prog.tmc:3:6: error: unknown label 'Lop' (did you mean 'Loop'?)");
    assert_eq!(one("JC NZ, Nowhere", false), "prog.tmc:1:8: error: unknown label 'Nowhere'");
    assert_eq!(one("SAP 4, 0, Speed", false), "prog.tmc:1:11: error: unknown constant or label 'Speed'");
}

#[test]
fn bad_operand_count() {
    assert_eq!(one("  MVP ABS, 0\n", false), "prog.tmc:1:13: error: MVP takes 3 operands (ABS|REL|COORD, motor, position), found 2");
    assert_eq!(one("MST 0, 1", false), "prog.tmc:1:8: error: MST takes 1 operand (motor), found 2");
    assert_eq!(one("RSUB 1", false), "prog.tmc:1:6: error: RSUB takes no operands, found 1");
    assert_eq!(one("GAP 1", false), "prog.tmc:1:6: error: GAP takes 2 operands (parameter, motor), found 1");
    assert_eq!(
        one("MVP ABS, 0   // no position", false),
        "prog.tmc:1:11: error: MVP takes 3 operands (ABS|REL|COORD, motor, position), found 2"
    );
}

#[test]
fn bad_symbol() {
    assert_eq!(one("MVP UP, 0, 1", false), "prog.tmc:1:5: error: 'UP' is not a move mode (ABS, REL, COORD)");
    assert_eq!(
        one("L: JC NX, L", false),
        "prog.tmc:1:7: error: 'NX' is not a condition (ZE, NZ, EQ, NE, GT, GE, LT, LE, ETO, EAL, EDV, EPO) (did you mean 'NZ'?)"
    );
    assert_eq!(
        one("WAIT TICK, 0, 10", false),
        "prog.tmc:1:6: error: 'TICK' is not a wait condition (TICKS, POS, REFSW, LIMSW, RFS) (did you mean 'TICKS'?)"
    );
    assert_eq!(
        one("CALC SWAP, 1", false),
        "prog.tmc:1:6: error: SWAP cannot be used with CALC (valid: ADD, SUB, MUL, DIV, MOD, AND, OR, XOR, NOT, LOAD)"
    );
    assert_eq!(one("MVP 3, 0, 1", false), "prog.tmc:1:5: error: 3 is not a valid move mode for MVP (valid: ABS, REL, COORD)");
    assert_eq!(
        one("MVP ABS, REL, 51200", false),
        "prog.tmc:1:10: error: 'REL' is a move mode, not a motor number (MVP takes ABS|REL|COORD, motor, position)"
    );
}

#[test]
fn value_out_of_range() {
    assert_eq!(one("SAP 256, 0, 1", false), "prog.tmc:1:5: error: parameter 256 is out of range 0...255");
    assert_eq!(one("SAP 4, -1, 1", false), "prog.tmc:1:8: error: motor -1 is out of range 0...255");
    assert_eq!(
        one("SAP 4, 0, 4294967296", false),
        "prog.tmc:1:11: error: value 4294967296 does not fit in 32 bits (-2147483648...4294967295)"
    );
    assert_eq!(
        one("SAP 4, 0, 50000", true),
        "prog.tmc:1:11: error: value 50000 is out of range for axis parameter 4 (Maximum positioning speed): 1...2047"
    );
    assert_eq!(
        one("SGP 66, 0, 0", true),
        "prog.tmc:1:12: error: value 0 is out of range for global parameter 66 of bank 0 (Serial address): 1...255"
    );
    assert_eq!(one("ROL 0, 51200", true), "prog.tmc:1:8: error: velocity 51200 is out of range -2047...2047");
    assert_eq!(one("X = 1 / 0\nSAP 4, 0, X", false), "prog.tmc:1:7: error: division by zero");
}

#[test]
fn unknown_parameter_and_other_module_checks() {
    assert_eq!(one("GAP 14, 0", true), "prog.tmc:1:5: error: axis parameter 14 does not exist on the TMCM-1141 (see Parameters.inc)");
    assert_eq!(one("SAP 3, 0, 0", true), "prog.tmc:1:5: error: axis parameter 3 (Actual speed) cannot be written (access R)");
    assert_eq!(one("GGP 70, 0", true), "prog.tmc:1:5: error: global parameter 70 does not exist in bank 0 of the TMCM-1141");
    assert_eq!(one("SGP 1, 1, 0", true), "prog.tmc:1:8: error: bank 1 does not exist on the TMCM-1141 (banks: 0, 2, 3)");
    assert_eq!(
        one("STGP 60, 2", true),
        "prog.tmc:1:6: error: global parameter 60 of bank 2 (User variables #56…#255) cannot be stored in or restored from the EEPROM (access RW)"
    );
    assert_eq!(one("MST 1", true), "prog.tmc:1:5: error: motor 1 does not exist on the TMCM-1141 (it has motor 0 only)");
    assert_eq!(one("MVP COORD, 1, 3", true), "prog.tmc:1:12: error: motor 1 does not exist on the TMCM-1141 (it has motor 0 only)");
    assert_eq!(one("MVP COORD, 0, 21", true), "prog.tmc:1:15: error: coordinate 21 does not exist on the TMCM-1141 (0...20)");
    assert_eq!(one("SCO 21, 0, 5", true), "prog.tmc:1:5: error: coordinate 21 does not exist on the TMCM-1141 (0...20)");
    assert_eq!(one("JA 1024", true), "prog.tmc:1:4: error: jump target 1024 is outside the program memory of the TMCM-1141 (0...1023)");
    assert_eq!(one("SAC 0, 0, 0", true), "prog.tmc:1:1: error: SAC is not available on the TMCM-1141");
    assert_eq!(
        one("EI 5", true),
        "prog.tmc:1:4: error: interrupt 5 does not exist on the TMCM-1141 (interrupts: 0, 1, 2, 3, 15, 27, 28, 39, 40, 41, 42; see Interrupts.inc)"
    );
    assert_eq!(one("VECT 255, 0", true), "prog.tmc:1:6: error: VECT needs a single interrupt; 255 (all interrupts) is only for EI and DI");
    assert_eq!(one("GIO 4, 0", true), "prog.tmc:1:5: error: GIO port 4 does not exist in bank 0 of the TMCM-1141 (ports: 0, 1, 2, 3, 255)");
    assert_eq!(one("SIO 0, 2, 2", true), "prog.tmc:1:11: error: SIO value 2 is out of range 0...1");
    assert_eq!(one("SIO 0, 1, 1", true), "prog.tmc:1:8: error: bank 1 has no outputs on the TMCM-1141 (SIO banks: 0, 2)");
    // What is valid: the special forms.
    asm_1141(
        "EI 255\nDI 255\nSIO 255, 2, 3\nSIO 255, 2, -1\nGIO 255, 0\nSIO 0, 0, 1\nGIO 1, 2\nSCO 0, 255, 0\nGCO 3, 255\nWAIT TICKS, 7, 1\nUF0 1, 2, 3\nSGP 0, 3, 4294967295",
    );
}

#[test]
fn program_memory_size() {
    let source = "STOP\n".repeat(1025);
    assert_eq!(
        one(&source, true),
        "prog.tmc:1025:1: error: the program has more than 1024 instructions; the program memory of the TMCM-1141 holds 1024"
    );
    asm_1141(&"STOP\n".repeat(1024));
}

#[test]
fn duplicate_label_and_constant() {
    assert_eq!(
        one("Loop:\n  STOP\nLoop: STOP\n", false),
        "prog.tmc:3:1: error: duplicate label 'Loop' (already defined as a label at prog.tmc:1:1)"
    );
    assert_eq!(
        one("Speed = 1\n Speed = 2\n", false),
        "prog.tmc:2:2: error: duplicate constant 'Speed' (already defined as a constant at prog.tmc:1:1)"
    );
    assert_eq!(
        one("Speed = 1\nSpeed: STOP\n", false),
        "prog.tmc:2:1: error: duplicate label 'Speed' (already defined as a constant at prog.tmc:1:1)"
    );
}

#[test]
fn include_cycle() {
    let files = MemoryResolver::new().with("a.inc", "A = 1\n#include b.inc\n").with("b.inc", "B = 2\n  #include \"a.inc\"\n");
    let e = assemble("#include a.inc\nSTOP\n", "main.tmc", &files, None).unwrap_err();
    assert_eq!(e.len(), 1, "{e:?}");
    assert_eq!(e[0].to_string(), "b.inc:2:13: error: include cycle: a.inc -> b.inc -> a.inc");
    let e = assemble("STOP\n#include main.tmc\n", "main.tmc", &MemoryResolver::new().with("main.tmc", ""), None).unwrap_err();
    assert_eq!(e[0].to_string(), "main.tmc:2:10: error: 'main.tmc' includes itself");
}

#[test]
fn include_not_found() {
    let e = assemble("STOP\n#include nothere.inc\n", "prog.tmc", &MemoryResolver::new(), None).unwrap_err();
    assert_eq!(e.len(), 1);
    assert_eq!(
        e[0].to_string(),
        "prog.tmc:2:10: error: cannot find include file 'nothere.inc'; the include files shipped with tmclsim are Interrupts.inc and Parameters.inc (their names: crates/asm/README.md)"
    );
    assert_eq!(one("#include", false), "prog.tmc:1:9: error: #include needs a file name");
}

#[test]
fn every_error_of_a_file_is_reported() {
    let source = "\
Start:
  MVPP ABS, 0, 1000     // unknown instruction
  WAIT POS, 0, 0
  JA Strat              // unknown label
  SAP 4, 0, 50000       // out of range on the TMCM-1141
  JA Start
";
    let e = errors(source, true);
    assert_eq!(
        e,
        [
            "prog.tmc:2:3: error: unknown instruction 'MVPP' (did you mean 'MVP'?)",
            "prog.tmc:4:6: error: unknown label 'Strat' (did you mean 'Start'?)",
            "prog.tmc:5:13: error: value 50000 is out of range for axis parameter 4 (Maximum positioning speed): 1...2047",
        ]
    );
    // Several errors on one line, and a syntax error that does not shift
    // the addresses of later labels.
    let e = errors("SAP Foo, Bar, 1\nMVP ABS, 0,, 1\nEnd: JA End2\n", false);
    assert_eq!(
        e,
        [
            "prog.tmc:1:5: error: unknown constant or label 'Foo'",
            "prog.tmc:1:10: error: unknown constant or label 'Bar'",
            "prog.tmc:2:12: error: missing operand before ','",
            "prog.tmc:3:9: error: unknown label 'End2' (did you mean 'End'?)",
        ]
    );
}

#[test]
fn syntax_errors() {
    assert_eq!(one("SAP 4, 0, (1 + 2", false), "prog.tmc:1:17: error: missing ')' for the '(' at column 11");
    assert_eq!(one("ROL 0, 1000 @", false), "prog.tmc:1:13: error: unexpected character '@'");
    assert_eq!(one("ROL 0, 12ab", false), "prog.tmc:1:8: error: '12ab' is not a number");
    assert_eq!(one("STOP\n/* open\nSTOP", false), "prog.tmc:2:1: error: comment '/*' is never closed with '*/'");
    assert_eq!(one("#define X 1", false), "prog.tmc:1:1: error: unknown directive '#define' (known: #include, #db)");
    assert_eq!(one("#db 1, 2, 3", false), "prog.tmc:1:12: error: a raw word is '#db opcode, type, motor, value' (4 fields), found 3");
    assert_eq!(one("#db 256, 0, 0, 0", false), "prog.tmc:1:5: error: opcode 256 is out of range 0...255");
    assert_eq!(
        one("  #db 138, 1, 0, 1", true),
        "prog.tmc:1:3: error: control command 138 (request target position reached event) cannot be stored in a program: during download the module executes it"
    );
    assert_eq!(one("A = B + 1\nB = A * 2\n", false), "prog.tmc:2:5: error: constant 'A' is defined through itself (A -> B -> A)");
    assert_eq!(one("X = 1 << 64", false), "prog.tmc:1:7: error: shift by 64 (must be 0...63)");
}

#[test]
fn diagnostics_of_included_files_name_them() {
    let files = MemoryResolver::new().with("lib/motion.inc", "Speed = 100\n  JA Nowhere\n");
    let e = assemble("#include lib/motion.inc\n", "main.tmc", &files, Some(&tmcm_1141())).unwrap_err();
    assert_eq!(e[0].to_string(), "lib/motion.inc:2:6: error: unknown label 'Nowhere'");
}

#[test]
fn range_errors_point_at_the_start_of_the_operand() {
    assert_eq!(
        one("Speed = 1500\nSAP 4, 0, Speed * 2", true),
        "prog.tmc:2:11: error: value 3000 is out of range for axis parameter 4 (Maximum positioning speed): 1...2047"
    );
    assert_eq!(one("SAP 4, 0, 1 + 2 / (3 - 3)", false), "prog.tmc:1:17: error: division by zero");
}

/// The TMCM-351's settings on SIO bank 0 (V4.45 §4.6.14 p.37): the pull-up
/// mask 0…255 on port 0 and the analog input range 0/1 on port 8.
#[test]
fn sio_settings_of_the_351() {
    let p = tmclsim_profile::Profile::built_in("tmcm-351").unwrap();
    let check = |source: &str| assemble(source, "prog.tmc", &MemoryResolver::new(), Some(&p)).map_err(|d| d[0].to_string());
    for valid in ["SIO 0, 0, 63", "SIO 0, 0, 255", "SIO 8, 0, 0", "SIO 8, 0, 1", "SIO 255, 2, -1", "GIO 5, 1", "GIO 255, 0"] {
        assert!(check(valid).is_ok(), "{valid}: {:?}", check(valid).err());
    }
    assert_eq!(check("SIO 0, 0, 256").unwrap_err(), "prog.tmc:1:11: error: SIO value 256 is out of range 0...255");
    assert_eq!(check("SIO 8, 0, 2").unwrap_err(), "prog.tmc:1:11: error: SIO value 2 is out of range 0...1");
    assert_eq!(check("SIO 1, 0, 1").unwrap_err(), "prog.tmc:1:5: error: SIO port 1 does not exist in bank 0 of the TMCM-351 (ports: 0, 8)");
    assert_eq!(
        check("GIO 8, 0").unwrap_err(),
        "prog.tmc:1:5: error: GIO port 8 does not exist in bank 0 of the TMCM-351 (ports: 0, 1, 2, 3, 4, 5, 6, 7, 255)"
    );
}
