//! TMCL instruction numbers and their mnemonics.

pub const ROR: u8 = 1;
pub const ROL: u8 = 2;
pub const MST: u8 = 3;
pub const MVP: u8 = 4;
pub const SAP: u8 = 5;
pub const GAP: u8 = 6;
pub const STAP: u8 = 7;
pub const RSAP: u8 = 8;
pub const SGP: u8 = 9;
pub const GGP: u8 = 10;
pub const STGP: u8 = 11;
pub const RSGP: u8 = 12;
pub const RFS: u8 = 13;
pub const SIO: u8 = 14;
pub const GIO: u8 = 15;
pub const CALC: u8 = 19;
pub const COMP: u8 = 20;
pub const JC: u8 = 21;
pub const JA: u8 = 22;
pub const CSUB: u8 = 23;
pub const RSUB: u8 = 24;
pub const EI: u8 = 25;
pub const DI: u8 = 26;
pub const WAIT: u8 = 27;
pub const STOP: u8 = 28;
pub const SAC: u8 = 29;
pub const SCO: u8 = 30;
pub const GCO: u8 = 31;
pub const CCO: u8 = 32;
pub const CALCX: u8 = 33;
pub const AAP: u8 = 34;
pub const AGP: u8 = 35;
pub const CLE: u8 = 36;
pub const VECT: u8 = 37;
pub const RETI: u8 = 38;
pub const ACO: u8 = 39;
pub const CALCVV: u8 = 40;
pub const CALCVA: u8 = 41;
pub const CALCAV: u8 = 42;
pub const CALCVX: u8 = 43;
pub const CALCXV: u8 = 44;
pub const CALCV: u8 = 45;
pub const MVPA: u8 = 46;
pub const RST: u8 = 48;
pub const DJNZ: u8 = 49;
pub const ROLA: u8 = 50;
pub const RORA: u8 = 51;
pub const SIV: u8 = 55;
pub const GIV: u8 = 56;
pub const AIV: u8 = 57;
pub const UF0: u8 = 64;
pub const UF7: u8 = 71;
pub const CALL: u8 = 80;
pub const STOP_APPLICATION: u8 = 128;
pub const RUN_APPLICATION: u8 = 129;
pub const STEP_APPLICATION: u8 = 130;
pub const RESET_APPLICATION: u8 = 131;
pub const ENTER_DOWNLOAD: u8 = 132;
pub const EXIT_DOWNLOAD: u8 = 133;
pub const READ_MEMORY: u8 = 134;
pub const APPLICATION_STATUS: u8 = 135;
pub const FIRMWARE_VERSION: u8 = 136;
pub const FACTORY_DEFAULTS: u8 = 137;
pub const TARGET_REACHED_EVENT: u8 = 138;
pub const ASCII_MODE: u8 = 139;
pub const RESET: u8 = 255;

/// Mnemonic of an instruction number; control commands have none.
pub fn mnemonic(opcode: u8) -> Option<&'static str> {
    Some(match opcode {
        ROR => "ROR",
        ROL => "ROL",
        MST => "MST",
        MVP => "MVP",
        SAP => "SAP",
        GAP => "GAP",
        STAP => "STAP",
        RSAP => "RSAP",
        SGP => "SGP",
        GGP => "GGP",
        STGP => "STGP",
        RSGP => "RSGP",
        RFS => "RFS",
        SIO => "SIO",
        GIO => "GIO",
        CALC => "CALC",
        COMP => "COMP",
        JC => "JC",
        JA => "JA",
        CSUB => "CSUB",
        RSUB => "RSUB",
        EI => "EI",
        DI => "DI",
        WAIT => "WAIT",
        STOP => "STOP",
        SAC => "SAC",
        SCO => "SCO",
        GCO => "GCO",
        CCO => "CCO",
        CALCX => "CALCX",
        AAP => "AAP",
        AGP => "AGP",
        CLE => "CLE",
        VECT => "VECT",
        RETI => "RETI",
        ACO => "ACO",
        CALCVV => "CALCVV",
        CALCVA => "CALCVA",
        CALCAV => "CALCAV",
        CALCVX => "CALCVX",
        CALCXV => "CALCXV",
        CALCV => "CALCV",
        MVPA => "MVPA",
        RST => "RST",
        DJNZ => "DJNZ",
        ROLA => "ROLA",
        RORA => "RORA",
        SIV => "SIV",
        GIV => "GIV",
        AIV => "AIV",
        64 => "UF0",
        65 => "UF1",
        66 => "UF2",
        67 => "UF3",
        68 => "UF4",
        69 => "UF5",
        70 => "UF6",
        71 => "UF7",
        CALL => "CALL",
        _ => return None,
    })
}

/// Instruction number of a mnemonic (case-insensitive).
pub fn from_mnemonic(name: &str) -> Option<u8> {
    (0..=255u8).find(|&op| mnemonic(op).is_some_and(|m| m.eq_ignore_ascii_case(name)))
}

/// A readable name for any instruction number, control commands included.
pub fn name(opcode: u8) -> &'static str {
    if let Some(m) = mnemonic(opcode) {
        return m;
    }
    match opcode {
        STOP_APPLICATION => "stop application",
        RUN_APPLICATION => "run application",
        STEP_APPLICATION => "step application",
        RESET_APPLICATION => "reset application",
        ENTER_DOWNLOAD => "enter download mode",
        EXIT_DOWNLOAD => "exit download mode",
        READ_MEMORY => "read program memory",
        APPLICATION_STATUS => "get application status",
        FIRMWARE_VERSION => "get firmware version",
        FACTORY_DEFAULTS => "restore factory settings",
        TARGET_REACHED_EVENT => "request target position reached event",
        ASCII_MODE => "enter ASCII mode",
        RESET => "software reset",
        _ => "unknown",
    }
}

/// Control commands (128…139, 255): direct mode only, never stored in a
/// program, executed even while downloading.
pub const fn is_control(opcode: u8) -> bool {
    matches!(opcode, 128..=139 | 255)
}
