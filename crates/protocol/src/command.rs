//! Typed TMCL commands.
//!
//! [`Command::decode`] turns the seven bytes of an [`Instruction`] into a
//! typed command, checking what the protocol itself defines (which types an
//! instruction has). Whether a module has the instruction, the parameter or
//! the motor is the module's business: see the firmware crate.

use crate::frame::Instruction;
use crate::opcode as op;
use crate::status::Status;

/// MVP / MVPA addressing mode.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MoveMode {
    Absolute = 0,
    Relative = 1,
    Coordinate = 2,
}

/// RFS action.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RfsAction {
    Start = 0,
    Stop = 1,
    Status = 2,
}

/// Operations of CALC (0…9), CALCX (0…10) and the user-variable CALC
/// family (0…11, CALCV without SWAP).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CalcOp {
    Add = 0,
    Sub = 1,
    Mul = 2,
    Div = 3,
    Mod = 4,
    And = 5,
    Or = 6,
    Xor = 7,
    Not = 8,
    Load = 9,
    Swap = 10,
    Comp = 11,
}

impl CalcOp {
    pub const ALL: [CalcOp; 12] = [
        CalcOp::Add,
        CalcOp::Sub,
        CalcOp::Mul,
        CalcOp::Div,
        CalcOp::Mod,
        CalcOp::And,
        CalcOp::Or,
        CalcOp::Xor,
        CalcOp::Not,
        CalcOp::Load,
        CalcOp::Swap,
        CalcOp::Comp,
    ];

    pub fn from_code(code: u8) -> Option<CalcOp> {
        CalcOp::ALL.get(code as usize).copied()
    }

    pub const fn name(self) -> &'static str {
        ["ADD", "SUB", "MUL", "DIV", "MOD", "AND", "OR", "XOR", "NOT", "LOAD", "SWAP", "COMP"][self as usize]
    }
}

/// JC / CALL conditions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Condition {
    Zero = 0,
    NotZero = 1,
    Equal = 2,
    NotEqual = 3,
    Greater = 4,
    GreaterEqual = 5,
    Lower = 6,
    LowerEqual = 7,
    Timeout = 8,
    Alarm = 9,
    Deviation = 10,
    PositionError = 11,
}

impl Condition {
    pub const ALL: [Condition; 12] = [
        Condition::Zero,
        Condition::NotZero,
        Condition::Equal,
        Condition::NotEqual,
        Condition::Greater,
        Condition::GreaterEqual,
        Condition::Lower,
        Condition::LowerEqual,
        Condition::Timeout,
        Condition::Alarm,
        Condition::Deviation,
        Condition::PositionError,
    ];

    pub fn from_code(code: u8) -> Option<Condition> {
        Condition::ALL.get(code as usize).copied()
    }

    pub const fn name(self) -> &'static str {
        ["ZE", "NZ", "EQ", "NE", "GT", "GE", "LT", "LE", "ETO", "EAL", "EDV", "EPO"][self as usize]
    }
}

/// WAIT conditions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WaitCondition {
    Ticks = 0,
    Position = 1,
    ReferenceSwitch = 2,
    LimitSwitch = 3,
    ReferenceSearch = 4,
}

impl WaitCondition {
    pub fn from_code(code: u8) -> Option<WaitCondition> {
        Some(match code {
            0 => WaitCondition::Ticks,
            1 => WaitCondition::Position,
            2 => WaitCondition::ReferenceSwitch,
            3 => WaitCondition::LimitSwitch,
            4 => WaitCondition::ReferenceSearch,
            _ => return None,
        })
    }

    pub const fn name(self) -> &'static str {
        ["TICKS", "POS", "REFSW", "LIMSW", "RFS"][self as usize]
    }
}

/// CLE flags.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ErrorFlag {
    All = 0,
    Timeout = 1,
    Alarm = 2,
    Deviation = 3,
    Position = 4,
    Shutdown = 5,
}

impl ErrorFlag {
    pub fn from_code(code: u8) -> Option<ErrorFlag> {
        Some(match code {
            0 => ErrorFlag::All,
            1 => ErrorFlag::Timeout,
            2 => ErrorFlag::Alarm,
            3 => ErrorFlag::Deviation,
            4 => ErrorFlag::Position,
            5 => ErrorFlag::Shutdown,
            _ => return None,
        })
    }

    pub const fn name(self) -> &'static str {
        ["ALL", "ETO", "EAL", "EDV", "EPO", "ESD"][self as usize]
    }
}

/// Every TMCL command of the three modules, typed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Command {
    Ror {
        motor: u8,
        velocity: i32,
    },
    Rol {
        motor: u8,
        velocity: i32,
    },
    Mst {
        motor: u8,
    },
    Mvp {
        mode: MoveMode,
        motor: u8,
        value: i32,
    },
    Sap {
        param: u8,
        motor: u8,
        value: i32,
    },
    Gap {
        param: u8,
        motor: u8,
    },
    Stap {
        param: u8,
        motor: u8,
    },
    Rsap {
        param: u8,
        motor: u8,
    },
    Sgp {
        param: u8,
        bank: u8,
        value: i32,
    },
    Ggp {
        param: u8,
        bank: u8,
    },
    Stgp {
        param: u8,
        bank: u8,
    },
    Rsgp {
        param: u8,
        bank: u8,
    },
    Rfs {
        action: RfsAction,
        motor: u8,
    },
    Sio {
        port: u8,
        bank: u8,
        value: i32,
    },
    Gio {
        port: u8,
        bank: u8,
    },
    Calc {
        op: CalcOp,
        value: i32,
    },
    Comp {
        value: i32,
    },
    Jc {
        condition: Condition,
        address: i32,
    },
    Ja {
        address: i32,
    },
    Csub {
        address: i32,
    },
    Rsub,
    Ei {
        interrupt: u8,
    },
    Di {
        interrupt: u8,
    },
    Wait {
        condition: WaitCondition,
        motor: u8,
        ticks: i32,
    },
    Stop,
    Sac {
        bus: u8,
        count: u8,
        value: i32,
    },
    Sco {
        coordinate: u8,
        motor: u8,
        value: i32,
    },
    Gco {
        coordinate: u8,
        motor: u8,
    },
    Cco {
        coordinate: u8,
        motor: u8,
    },
    CalcX {
        op: CalcOp,
    },
    Aap {
        param: u8,
        motor: u8,
    },
    Agp {
        param: u8,
        bank: u8,
    },
    Cle {
        flag: ErrorFlag,
    },
    Vect {
        interrupt: u8,
        address: i32,
    },
    Reti,
    Aco {
        coordinate: u8,
        motor: u8,
    },
    /// var1 in the motor/bank byte, var2 in the value.
    CalcVV {
        op: CalcOp,
        var1: u8,
        var2: i32,
    },
    CalcVA {
        op: CalcOp,
        var: u8,
    },
    CalcAV {
        op: CalcOp,
        var: u8,
    },
    CalcVX {
        op: CalcOp,
        var: u8,
    },
    CalcXV {
        op: CalcOp,
        var: u8,
    },
    CalcV {
        op: CalcOp,
        var: u8,
        value: i32,
    },
    Mvpa {
        mode: MoveMode,
        motor: u8,
    },
    Rst {
        address: i32,
    },
    Djnz {
        var: u8,
        address: i32,
    },
    Rola {
        motor: u8,
    },
    Rora {
        motor: u8,
    },
    Siv {
        value: i32,
    },
    Giv,
    Aiv,
    UserFunction {
        number: u8,
        kind: u8,
        motor: u8,
        value: i32,
    },
    Call {
        condition: Condition,
        address: i32,
    },
    StopApplication,
    /// `None`: continue from the current address.
    RunApplication {
        from: Option<i32>,
    },
    StepApplication,
    ResetApplication,
    EnterDownload {
        address: i32,
    },
    ExitDownload,
    ReadMemory {
        address: i32,
    },
    ApplicationStatus {
        kind: u8,
    },
    FirmwareVersion {
        binary: bool,
    },
    FactoryDefaults {
        key: i32,
    },
    TargetReachedEvent {
        every_move: bool,
        mask: i32,
    },
    AsciiMode,
    Reset {
        key: i32,
    },
}

/// Why seven bytes are not a command.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DecodeError {
    /// No TMCL instruction has this number (status 2).
    UnknownOpcode(u8),
    /// The instruction has no such type (status 3).
    WrongType { opcode: u8, kind: u8 },
}

impl DecodeError {
    pub const fn status(self) -> Status {
        match self {
            DecodeError::UnknownOpcode(_) => Status::InvalidCommand,
            DecodeError::WrongType { .. } => Status::WrongType,
        }
    }
}

impl std::fmt::Display for DecodeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            DecodeError::UnknownOpcode(o) => write!(f, "unknown instruction number {o}"),
            DecodeError::WrongType { opcode, kind } => {
                write!(f, "{} has no type {kind}", op::name(*opcode))
            }
        }
    }
}

impl std::error::Error for DecodeError {}

fn move_mode(kind: u8) -> Option<MoveMode> {
    match kind {
        0 => Some(MoveMode::Absolute),
        1 => Some(MoveMode::Relative),
        2 => Some(MoveMode::Coordinate),
        _ => None,
    }
}

impl Command {
    /// Decodes an instruction. Fields the manual marks "don't care" are
    /// ignored.
    pub fn decode(i: Instruction) -> Result<Command, DecodeError> {
        let decoded = match i.opcode {
            op::ROR..=op::GIO => Self::decode_motion(i)?,
            op::CALC..=op::AIV | op::CALL => Self::decode_program(i)?,
            op::UF0..=op::UF7 => Some(Command::UserFunction { number: i.opcode - op::UF0, kind: i.kind, motor: i.motor, value: i.value }),
            op::STOP_APPLICATION.. => Self::decode_control(i)?,
            _ => None,
        };
        decoded.ok_or(DecodeError::UnknownOpcode(i.opcode))
    }

    /// Motors, parameters and ports (instructions 1…15); `None` for an
    /// unknown number.
    fn decode_motion(i: Instruction) -> Result<Option<Command>, DecodeError> {
        let Instruction { opcode, kind, motor, value } = i;
        let wrong = DecodeError::WrongType { opcode, kind };
        Ok(Some(match opcode {
            op::ROR => Command::Ror { motor, velocity: value },
            op::ROL => Command::Rol { motor, velocity: value },
            op::MST => Command::Mst { motor },
            op::MVP => Command::Mvp { mode: move_mode(kind).ok_or(wrong)?, motor, value },
            op::SAP => Command::Sap { param: kind, motor, value },
            op::GAP => Command::Gap { param: kind, motor },
            op::STAP => Command::Stap { param: kind, motor },
            op::RSAP => Command::Rsap { param: kind, motor },
            op::SGP => Command::Sgp { param: kind, bank: motor, value },
            op::GGP => Command::Ggp { param: kind, bank: motor },
            op::STGP => Command::Stgp { param: kind, bank: motor },
            op::RSGP => Command::Rsgp { param: kind, bank: motor },
            op::RFS => {
                let action = match kind {
                    0 => RfsAction::Start,
                    1 => RfsAction::Stop,
                    2 => RfsAction::Status,
                    _ => return Err(wrong),
                };
                Command::Rfs { action, motor }
            }
            op::SIO => Command::Sio { port: kind, bank: motor, value },
            op::GIO => Command::Gio { port: kind, bank: motor },
            _ => return Ok(None),
        }))
    }

    /// The instructions of stand-alone programs (19…57, CALL); `None` for
    /// an unknown number.
    fn decode_program(i: Instruction) -> Result<Option<Command>, DecodeError> {
        let Instruction { opcode, kind, motor, value } = i;
        let wrong = DecodeError::WrongType { opcode, kind };
        // CALC allows 0…9, CALCX 0…10, the user-variable family 0…11
        // (CALCV has no SWAP).
        let calc = |max: u8| match CalcOp::from_code(kind) {
            Some(c) if kind <= max => Ok(c),
            _ => Err(wrong),
        };
        let condition = || Condition::from_code(kind).ok_or(wrong);
        Ok(Some(match opcode {
            op::CALC => Command::Calc { op: calc(9)?, value },
            op::COMP => Command::Comp { value },
            op::JC => Command::Jc { condition: condition()?, address: value },
            op::JA => Command::Ja { address: value },
            op::CSUB => Command::Csub { address: value },
            op::RSUB => Command::Rsub,
            op::EI => Command::Ei { interrupt: kind },
            op::DI => Command::Di { interrupt: kind },
            op::WAIT => Command::Wait { condition: WaitCondition::from_code(kind).ok_or(wrong)?, motor, ticks: value },
            op::STOP => Command::Stop,
            op::SAC => Command::Sac { bus: kind, count: motor, value },
            op::SCO => Command::Sco { coordinate: kind, motor, value },
            op::GCO => Command::Gco { coordinate: kind, motor },
            op::CCO => Command::Cco { coordinate: kind, motor },
            op::CALCX => Command::CalcX { op: calc(10)? },
            op::AAP => Command::Aap { param: kind, motor },
            op::AGP => Command::Agp { param: kind, bank: motor },
            op::CLE => Command::Cle { flag: ErrorFlag::from_code(kind).ok_or(wrong)? },
            op::VECT => Command::Vect { interrupt: kind, address: value },
            op::RETI => Command::Reti,
            op::ACO => Command::Aco { coordinate: kind, motor },
            op::CALCVV => Command::CalcVV { op: calc(11)?, var1: motor, var2: value },
            op::CALCVA => Command::CalcVA { op: calc(11)?, var: motor },
            op::CALCAV => Command::CalcAV { op: calc(11)?, var: motor },
            op::CALCVX => Command::CalcVX { op: calc(11)?, var: motor },
            op::CALCXV => Command::CalcXV { op: calc(11)?, var: motor },
            op::CALCV => {
                let c = calc(11)?;
                if c == CalcOp::Swap {
                    return Err(wrong);
                }
                Command::CalcV { op: c, var: motor, value }
            }
            op::MVPA => Command::Mvpa { mode: move_mode(kind).ok_or(wrong)?, motor },
            op::RST => Command::Rst { address: value },
            op::DJNZ => Command::Djnz { var: kind, address: value },
            op::ROLA => Command::Rola { motor },
            op::RORA => Command::Rora { motor },
            op::SIV => Command::Siv { value },
            op::GIV => Command::Giv,
            op::AIV => Command::Aiv,
            op::CALL => Command::Call { condition: condition()?, address: value },
            _ => return Ok(None),
        }))
    }

    /// The host's control of the application and the module (128…);
    /// `None` for an unknown number.
    fn decode_control(i: Instruction) -> Result<Option<Command>, DecodeError> {
        let Instruction { opcode, kind, value, .. } = i;
        let command = match (opcode, kind) {
            (op::STOP_APPLICATION, _) => Command::StopApplication,
            (op::RUN_APPLICATION, 0) => Command::RunApplication { from: None },
            (op::RUN_APPLICATION, 1) => Command::RunApplication { from: Some(value) },
            (op::STEP_APPLICATION, _) => Command::StepApplication,
            (op::RESET_APPLICATION, _) => Command::ResetApplication,
            (op::ENTER_DOWNLOAD, _) => Command::EnterDownload { address: value },
            (op::EXIT_DOWNLOAD, _) => Command::ExitDownload,
            (op::READ_MEMORY, _) => Command::ReadMemory { address: value },
            (op::APPLICATION_STATUS, 0..=3) => Command::ApplicationStatus { kind },
            (op::FIRMWARE_VERSION, 0 | 1) => Command::FirmwareVersion { binary: kind == 1 },
            (op::FACTORY_DEFAULTS, _) => Command::FactoryDefaults { key: value },
            (op::TARGET_REACHED_EVENT, 0 | 1) => Command::TargetReachedEvent { every_move: kind == 1, mask: value },
            (op::ASCII_MODE, _) => Command::AsciiMode,
            (op::RESET, _) => Command::Reset { key: value },
            (op::RUN_APPLICATION | op::APPLICATION_STATUS | op::FIRMWARE_VERSION | op::TARGET_REACHED_EVENT, _) => {
                return Err(DecodeError::WrongType { opcode, kind });
            }
            _ => return Ok(None),
        };
        Ok(Some(command))
    }

    /// The instruction number of this command.
    pub fn opcode(&self) -> u8 {
        self.encode().opcode
    }

    /// Encodes the command; "don't care" fields are 0.
    pub fn encode(&self) -> Instruction {
        use Command::*;
        let i = Instruction::new;
        match *self {
            Ror { motor, velocity } => i(op::ROR, 0, motor, velocity),
            Rol { motor, velocity } => i(op::ROL, 0, motor, velocity),
            Mst { motor } => i(op::MST, 0, motor, 0),
            Mvp { mode, motor, value } => i(op::MVP, mode as u8, motor, value),
            Sap { param, motor, value } => i(op::SAP, param, motor, value),
            Gap { param, motor } => i(op::GAP, param, motor, 0),
            Stap { param, motor } => i(op::STAP, param, motor, 0),
            Rsap { param, motor } => i(op::RSAP, param, motor, 0),
            Sgp { param, bank, value } => i(op::SGP, param, bank, value),
            Ggp { param, bank } => i(op::GGP, param, bank, 0),
            Stgp { param, bank } => i(op::STGP, param, bank, 0),
            Rsgp { param, bank } => i(op::RSGP, param, bank, 0),
            Rfs { action, motor } => i(op::RFS, action as u8, motor, 0),
            Sio { port, bank, value } => i(op::SIO, port, bank, value),
            Gio { port, bank } => i(op::GIO, port, bank, 0),
            Calc { op: c, value } => i(op::CALC, c as u8, 0, value),
            Comp { value } => i(op::COMP, 0, 0, value),
            Jc { condition, address } => i(op::JC, condition as u8, 0, address),
            Ja { address } => i(op::JA, 0, 0, address),
            Csub { address } => i(op::CSUB, 0, 0, address),
            Rsub => i(op::RSUB, 0, 0, 0),
            Ei { interrupt } => i(op::EI, interrupt, 0, 0),
            Di { interrupt } => i(op::DI, interrupt, 0, 0),
            Wait { condition, motor, ticks } => i(op::WAIT, condition as u8, motor, ticks),
            Stop => i(op::STOP, 0, 0, 0),
            Sac { bus, count, value } => i(op::SAC, bus, count, value),
            Sco { coordinate, motor, value } => i(op::SCO, coordinate, motor, value),
            Gco { coordinate, motor } => i(op::GCO, coordinate, motor, 0),
            Cco { coordinate, motor } => i(op::CCO, coordinate, motor, 0),
            CalcX { op: c } => i(op::CALCX, c as u8, 0, 0),
            Aap { param, motor } => i(op::AAP, param, motor, 0),
            Agp { param, bank } => i(op::AGP, param, bank, 0),
            Cle { flag } => i(op::CLE, flag as u8, 0, 0),
            Vect { interrupt, address } => i(op::VECT, interrupt, 0, address),
            Reti => i(op::RETI, 0, 0, 0),
            Aco { coordinate, motor } => i(op::ACO, coordinate, motor, 0),
            CalcVV { op: c, var1, var2 } => i(op::CALCVV, c as u8, var1, var2),
            CalcVA { op: c, var } => i(op::CALCVA, c as u8, var, 0),
            CalcAV { op: c, var } => i(op::CALCAV, c as u8, var, 0),
            CalcVX { op: c, var } => i(op::CALCVX, c as u8, var, 0),
            CalcXV { op: c, var } => i(op::CALCXV, c as u8, var, 0),
            CalcV { op: c, var, value } => i(op::CALCV, c as u8, var, value),
            Mvpa { mode, motor } => i(op::MVPA, mode as u8, motor, 0),
            Rst { address } => i(op::RST, 0, 0, address),
            Djnz { var, address } => i(op::DJNZ, var, 0, address),
            Rola { motor } => i(op::ROLA, 0, motor, 0),
            Rora { motor } => i(op::RORA, 0, motor, 0),
            Siv { value } => i(op::SIV, 0, 0, value),
            Giv => i(op::GIV, 0, 0, 0),
            Aiv => i(op::AIV, 0, 0, 0),
            UserFunction { number, kind, motor, value } => i(op::UF0 + number, kind, motor, value),
            Call { condition, address } => i(op::CALL, condition as u8, 0, address),
            StopApplication => i(op::STOP_APPLICATION, 0, 0, 0),
            RunApplication { from: None } => i(op::RUN_APPLICATION, 0, 0, 0),
            RunApplication { from: Some(a) } => i(op::RUN_APPLICATION, 1, 0, a),
            StepApplication => i(op::STEP_APPLICATION, 0, 0, 0),
            ResetApplication => i(op::RESET_APPLICATION, 0, 0, 0),
            EnterDownload { address } => i(op::ENTER_DOWNLOAD, 0, 0, address),
            ExitDownload => i(op::EXIT_DOWNLOAD, 0, 0, 0),
            ReadMemory { address } => i(op::READ_MEMORY, 0, 0, address),
            ApplicationStatus { kind } => i(op::APPLICATION_STATUS, kind, 0, 0),
            FirmwareVersion { binary } => i(op::FIRMWARE_VERSION, u8::from(binary), 0, 0),
            FactoryDefaults { key } => i(op::FACTORY_DEFAULTS, 0, 0, key),
            TargetReachedEvent { every_move, mask } => i(op::TARGET_REACHED_EVENT, u8::from(every_move), 0, mask),
            AsciiMode => i(op::ASCII_MODE, 0, 0, 0),
            Reset { key } => i(op::RESET, 0, 0, key),
        }
    }

    /// Branch and flow commands: program-only (docs/behaviour.md rule 7).
    pub fn is_program_only(&self) -> bool {
        use Command::*;
        matches!(self, Jc { .. } | Ja { .. } | Csub { .. } | Rsub | Call { .. } | Djnz { .. } | Rst { .. } | Wait { .. } | Stop | Reti)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_manual_opcode_decodes() {
        let opcodes = (1..=15).chain(19..=46).chain(48..=51).chain(55..=57).chain(64..=71).chain([80]).chain(128..=139).chain([255]);
        for opcode in opcodes {
            let i = Instruction::new(opcode, 0, 0, 0);
            let c = Command::decode(i).unwrap_or_else(|e| panic!("{opcode}: {e}"));
            assert_eq!(c.opcode(), opcode);
        }
    }

    #[test]
    fn decode_encode_round_trip_over_all_types() {
        for opcode in 0..=255u8 {
            for kind in 0..=255u8 {
                let i = Instruction::new(opcode, kind, 7, -123456);
                if let Ok(c) = Command::decode(i) {
                    assert_eq!(c.encode().opcode, opcode);
                    assert_eq!(Command::decode(c.encode()), Ok(c), "{i:?}");
                }
            }
        }
    }

    #[test]
    fn unknown_opcodes_and_types() {
        for opcode in [0u8, 16, 17, 18, 47, 52, 53, 54, 58, 63, 72, 79, 81, 127, 140, 254] {
            assert_eq!(Command::decode(Instruction::new(opcode, 0, 0, 0)), Err(DecodeError::UnknownOpcode(opcode)));
        }
        let wrong = |o, k| Command::decode(Instruction::new(o, k, 0, 0)).unwrap_err().status();
        assert_eq!(wrong(op::MVP, 3), Status::WrongType);
        assert_eq!(wrong(op::CALC, 10), Status::WrongType);
        assert_eq!(wrong(op::CALCX, 11), Status::WrongType);
        assert_eq!(wrong(op::CALCV, 10), Status::WrongType);
        assert_eq!(wrong(op::JC, 12), Status::WrongType);
        assert_eq!(wrong(op::WAIT, 5), Status::WrongType);
        assert_eq!(wrong(op::RFS, 3), Status::WrongType);
        assert_eq!(wrong(op::CLE, 6), Status::WrongType);
        assert_eq!(wrong(op::FIRMWARE_VERSION, 2), Status::WrongType);
        assert_eq!(wrong(op::TARGET_REACHED_EVENT, 2), Status::WrongType);
    }
}
