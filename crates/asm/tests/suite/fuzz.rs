//! Random source text and random bytes never make the assembler, the
//! disassembler or the file readers panic.

use crate::common;

use common::{Rng, tmcm_1141};
use tmclsim_asm::{Instruction, MemoryResolver, Program, assemble, disassemble};

const PIECES: &[&str] = &[
    "MVP",
    "ABS",
    "REL",
    "COORD",
    "SAP",
    "GAP",
    "SGP",
    "JA",
    "JC",
    "NZ",
    "GE",
    "CALL",
    "CSUB",
    "RSUB",
    "WAIT",
    "TICKS",
    "POS",
    "DJNZ",
    "VECT",
    "EI",
    "DI",
    "RETI",
    "STOP",
    "CALC",
    "CALCX",
    "MUL",
    "SWAP",
    "SIO",
    "GIO",
    "SCO",
    "UF0",
    "SAC",
    "CLE",
    "ETO",
    "RFS",
    "START",
    "Loop",
    "Loop:",
    "Loop :",
    "X",
    "X =",
    "Y = X + 1",
    "X = Y",
    "#include",
    "#include a.inc",
    "#include \"b.inc\"",
    "#include <",
    "#db",
    "#",
    "#1",
    ",",
    ", ",
    " ",
    "  ",
    "\t",
    "\n",
    "\r\n",
    ":",
    "=",
    "+",
    "-",
    "*",
    "/",
    "%",
    "&",
    "|",
    "^",
    "~",
    "<<",
    ">>",
    "(",
    ")",
    "0",
    "1",
    "-1",
    "255",
    "256",
    "$FF",
    "0x7FFFFFFF",
    "4294967295",
    "4294967296",
    "99999999999999999999",
    "0b102",
    "12ab",
    "$",
    "//",
    "/*",
    "*/",
    "@",
    "ä",
    "\u{0}",
    "\u{FEFF}",
    "€",
    ";",
    "\"",
    "'",
    "TI_GLOBAL",
    "AP_TargetPosition",
];

fn random_source(rng: &mut Rng) -> String {
    let mut s = String::new();
    for _ in 0..rng.below(60) {
        let piece: &&str = rng.pick(PIECES);
        s.push_str(piece);
        if rng.below(3) == 0 {
            s.push(' ');
        }
    }
    s
}

fn random_bytes(rng: &mut Rng, max: u64) -> Vec<u8> {
    (0..rng.below(max)).map(|_| rng.byte()).collect()
}

#[test]
fn random_sources_never_panic() {
    let profile = tmcm_1141();
    let mut rng = Rng(0xF022_0001);
    for round in 0..20_000 {
        let source = random_source(&mut rng);
        let files = MemoryResolver::new()
            .with("a.inc", &random_source(&mut rng))
            .with("b.inc", &format!("#include a.inc\n{}", random_source(&mut rng)))
            .with("prog.tmc", &source);
        let with_profile = (round % 2 == 0).then_some(&*profile);
        if let Err(diagnostics) = assemble(&source, "prog.tmc", &files, with_profile) {
            assert!(!diagnostics.is_empty());
            for d in &diagnostics {
                assert!(d.line >= 1 && d.column >= 1, "{d}\nsource: {source:?}");
            }
        }
    }
}

#[test]
fn random_bytes_as_source_never_panic() {
    let profile = tmcm_1141();
    let mut rng = Rng(0xF022_0002);
    for _ in 0..10_000 {
        let bytes = random_bytes(&mut rng, 200);
        let text = String::from_utf8_lossy(&bytes);
        let _ = assemble(&text, "bytes.tmc", &MemoryResolver::new(), Some(&profile));
        let _ = Program::parse_symbol_file(&text);
    }
}

#[test]
fn random_binaries_never_panic() {
    let mut rng = Rng(0xF022_0003);
    for _ in 0..2000 {
        let bytes = random_bytes(&mut rng, 100);
        let _ = Program::from_binary(&bytes);
        let words: Vec<Instruction> = bytes.chunks_exact(7).map(|c| Instruction::from_bytes(c.try_into().unwrap())).collect();
        let _ = disassemble(&words, None);
    }
}

#[test]
fn pathological_sources_are_errors_not_crashes() {
    let deep = format!("X = {}1{}", "(".repeat(100_000), ")".repeat(100_000));
    assert!(assemble(&deep, "p.tmc", &MemoryResolver::new(), None).is_err());
    let minus = format!("SAP 4, 0, {}1", "-".repeat(100_000));
    assert!(assemble(&minus, "p.tmc", &MemoryResolver::new(), None).is_err());
    let long = format!("X = 1{}", "+1".repeat(100_000));
    assert!(assemble(&long, "p.tmc", &MemoryResolver::new(), None).is_err());
    let chain: String = (0..20_000).map(|i| format!("C{i} = C{} + 1\n", i + 1)).collect::<String>() + "C20000 = 0\n";
    assert!(assemble(&chain, "p.tmc", &MemoryResolver::new(), None).is_err());
    let mut includes = MemoryResolver::new();
    for i in 0..200 {
        includes = includes.with(&format!("f{i}.inc"), &format!("#include f{}.inc\n", i + 1));
    }
    assert!(assemble("#include f0.inc", "p.tmc", &includes, None).is_err());
}
