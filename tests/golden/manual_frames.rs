//! The request frames of the TMCM-1141 firmware manual V1.46, one table
//! for every crate that tests against them (the assembler: each line
//! assembles to the frame's instruction bytes; the firmware: each line
//! encodes to the frame). `Printed::Corrected` marks the frames the manual
//! prints wrong, as the reference notes correct them. Included by the tests
//! with `#[path]`.

/// How the manual prints a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(dead_code)]
pub enum Printed {
    /// Right as printed.
    AsIs,
    /// Printed wrong; the bytes here are corrected.
    Corrected,
}

/// (command, request frame to address 1, how the manual prints it)
pub const TMCM_1141_FRAMES: &[(&str, &str, Printed)] = &[
    ("ROR 0, 1000", "01 01 00 00 00 00 03 E8 ED", Printed::AsIs),
    ("ROL 0, 1000", "01 02 00 00 00 00 03 E8 EE", Printed::AsIs),
    ("MST 0", "01 03 00 00 00 00 00 00 04", Printed::AsIs),
    ("MVP ABS, 0, 90000", "01 04 00 00 00 01 5F 90 F5", Printed::AsIs),
    ("MVP REL, 0, -10000", "01 04 01 00 FF FF D8 F0 CC", Printed::AsIs),
    ("MVP COORD, 0, 8", "01 04 02 00 00 00 00 08 0F", Printed::AsIs),
    ("SAP 4, 0, 1000", "01 05 04 00 00 00 03 E8 F5", Printed::AsIs),
    ("GAP 1, 0", "01 06 01 00 00 00 00 00 08", Printed::AsIs),
    ("STAP 6, 0", "01 07 06 00 00 00 00 00 0E", Printed::Corrected),
    ("RSAP 6, 0", "01 08 06 00 00 00 00 00 0F", Printed::Corrected),
    ("SGP 66, 0, 3", "01 09 42 00 00 00 00 03 4F", Printed::AsIs),
    ("GGP 66, 0", "01 0A 42 00 00 00 00 00 4D", Printed::AsIs),
    ("STGP 42, 2", "01 0B 2A 02 00 00 00 00 38", Printed::AsIs),
    ("RSGP 42, 2", "01 0C 2A 02 00 00 00 00 39", Printed::AsIs),
    ("RFS START, 0", "01 0D 00 00 00 00 00 00 0E", Printed::AsIs),
    ("SIO 0, 2, 1", "01 0E 00 02 00 00 00 01 12", Printed::AsIs),
    ("GIO 0, 1", "01 0F 00 01 00 00 00 00 11", Printed::AsIs),
    ("CALC MUL, -5000", "01 13 02 00 FF FF EC 78 78", Printed::AsIs),
    ("COMP 1000", "01 14 00 00 00 00 03 E8 00", Printed::AsIs),
    ("JC GE, 10", "01 15 05 00 00 00 00 0A 25", Printed::AsIs),
    ("JA 10", "01 16 00 00 00 00 00 0A 21", Printed::AsIs),
    ("CSUB 100", "01 17 00 00 00 00 00 64 7C", Printed::AsIs),
    ("RSUB", "01 18 00 00 00 00 00 00 19", Printed::AsIs),
    ("WAIT POS, 0, 0", "01 1B 01 00 00 00 00 00 1D", Printed::AsIs),
    ("STOP", "01 1C 00 00 00 00 00 00 1D", Printed::AsIs),
    ("SCO 1, 0, 1000", "01 1E 01 00 00 00 03 E8 0B", Printed::AsIs),
    ("GCO 1, 0", "01 1F 01 00 00 00 00 00 21", Printed::AsIs),
    ("CCO 3, 0", "01 20 03 00 00 00 00 00 24", Printed::Corrected),
    ("ACO 1, 0", "01 27 01 00 00 00 00 00 29", Printed::AsIs),
    ("CALCX MUL", "01 21 02 00 00 00 00 00 24", Printed::AsIs),
    ("AAP 0, 0", "01 22 00 00 00 00 00 00 23", Printed::AsIs),
    ("AGP 42, 2", "01 23 2A 02 00 00 00 00 50", Printed::AsIs),
    ("CLE ETO", "01 24 01 00 00 00 00 00 26", Printed::AsIs),
    ("EI 255", "01 19 FF 00 00 00 00 00 19", Printed::AsIs),
    ("DI 255", "01 1A FF 00 00 00 00 00 1A", Printed::AsIs),
    ("VECT 0, 50", "01 25 00 00 00 00 00 32 58", Printed::Corrected),
    ("RETI", "01 26 00 00 00 00 00 00 27", Printed::Corrected),
    ("CALCVV SUB, 65, 42", "01 28 01 41 00 00 00 2A 95", Printed::AsIs),
    ("CALCVA SUB, 27", "01 29 01 1B 00 00 00 00 46", Printed::AsIs),
    ("CALCAV SUB, 27", "01 2A 01 1B 00 00 00 00 47", Printed::AsIs),
    ("CALCVX SUB, 27", "01 2B 01 1B 00 00 00 00 48", Printed::AsIs),
    ("CALCXV SUB, 27", "01 2C 01 1B 00 00 00 00 49", Printed::AsIs),
    ("CALCV SUB, 27, 5000", "01 2D 01 1B 00 00 13 88 E5", Printed::AsIs),
    ("MVPA ABS, 0", "01 2E 00 00 00 00 00 00 2F", Printed::AsIs),
    ("RST 10", "01 30 00 00 00 00 00 0A 3B", Printed::Corrected),
    ("DJNZ 42, 1", "01 31 2A 00 00 00 00 01 5D", Printed::Corrected),
    ("ROLA 0", "01 32 00 00 00 00 00 00 33", Printed::AsIs),
    ("RORA 0", "01 33 00 00 00 00 00 00 34", Printed::Corrected),
    ("SIV 3", "01 37 00 00 00 00 00 03 3B", Printed::AsIs),
    ("GIV", "01 38 00 00 00 00 00 00 39", Printed::Corrected),
    ("AIV", "01 39 00 00 00 00 00 00 3A", Printed::AsIs),
    ("CALL LT, 100", "01 50 06 00 00 00 00 64 BB", Printed::AsIs),
    ("#138 1 0 1", "01 8A 01 00 00 00 00 01 8D", Printed::AsIs),
];
