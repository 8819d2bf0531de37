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
    /// ABS: to an absolute position.
    Absolute = 0,
    /// REL: by a distance from the actual position.
    Relative = 1,
    /// COORD: to a stored coordinate.
    Coordinate = 2,
}

/// RFS action.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RfsAction {
    /// Start the reference search.
    Start = 0,
    /// Stop the reference search.
    Stop = 1,
    /// Whether a reference search is running.
    Status = 2,
}

/// Operations of CALC (0…9), CALCX (0…10) and the user-variable CALC
/// family (0…11, CALCV without SWAP).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CalcOp {
    /// ADD: a + b.
    Add = 0,
    /// SUB: a − b.
    Sub = 1,
    /// MUL: a × b.
    Mul = 2,
    /// DIV: a / b.
    Div = 3,
    /// MOD: a mod b.
    Mod = 4,
    /// AND: bitwise a and b.
    And = 5,
    /// OR: bitwise a or b.
    Or = 6,
    /// XOR: bitwise a xor b.
    Xor = 7,
    /// NOT: bitwise not a (b unused).
    Not = 8,
    /// LOAD: a ⟵ b.
    Load = 9,
    /// SWAP: exchange a and b.
    Swap = 10,
    /// COMP: compare a with b (sets the flags for JC).
    Comp = 11,
}

impl CalcOp {
    /// Every operation, by code.
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

    /// The operation of a type byte.
    pub fn from_code(code: u8) -> Option<CalcOp> {
        CalcOp::ALL.get(code as usize).copied()
    }

    /// The mnemonic (`ADD`).
    pub const fn name(self) -> &'static str {
        ["ADD", "SUB", "MUL", "DIV", "MOD", "AND", "OR", "XOR", "NOT", "LOAD", "SWAP", "COMP"][self as usize]
    }
}

/// JC / CALL conditions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Condition {
    /// ZE: the last result is zero.
    Zero = 0,
    /// NZ: the last result is not zero.
    NotZero = 1,
    /// EQ: equal.
    Equal = 2,
    /// NE: not equal.
    NotEqual = 3,
    /// GT: greater.
    Greater = 4,
    /// GE: greater or equal.
    GreaterEqual = 5,
    /// LT: lower.
    Lower = 6,
    /// LE: lower or equal.
    LowerEqual = 7,
    /// ETO: a WAIT timed out.
    Timeout = 8,
    /// EAL: an external alarm.
    Alarm = 9,
    /// EDV: the encoder deviates.
    Deviation = 10,
    /// EPO: position error.
    PositionError = 11,
}

impl Condition {
    /// Every condition, by code.
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

    /// The condition of a type byte.
    pub fn from_code(code: u8) -> Option<Condition> {
        Condition::ALL.get(code as usize).copied()
    }

    /// The mnemonic (`ZE`).
    pub const fn name(self) -> &'static str {
        ["ZE", "NZ", "EQ", "NE", "GT", "GE", "LT", "LE", "ETO", "EAL", "EDV", "EPO"][self as usize]
    }
}

/// WAIT conditions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WaitCondition {
    /// TICKS: a number of 10 ms ticks.
    Ticks = 0,
    /// POS: the motor reaches its target.
    Position = 1,
    /// REFSW: the reference switch.
    ReferenceSwitch = 2,
    /// LIMSW: a limit switch.
    LimitSwitch = 3,
    /// RFS: the reference search ends.
    ReferenceSearch = 4,
}

impl WaitCondition {
    /// The condition of a type byte.
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

    /// The mnemonic (`TICKS`).
    pub const fn name(self) -> &'static str {
        ["TICKS", "POS", "REFSW", "LIMSW", "RFS"][self as usize]
    }
}

/// CLE flags.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ErrorFlag {
    /// ALL: every flag.
    All = 0,
    /// ETO: the WAIT timeout flag.
    Timeout = 1,
    /// EAL: the external alarm flag.
    Alarm = 2,
    /// EDV: the deviation flag.
    Deviation = 3,
    /// EPO: the position error flag.
    Position = 4,
    /// ESD: the shutdown flag.
    Shutdown = 5,
}

impl ErrorFlag {
    /// The flag of a type byte.
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

    /// The mnemonic (`ALL`).
    pub const fn name(self) -> &'static str {
        ["ALL", "ETO", "EAL", "EDV", "EPO", "ESD"][self as usize]
    }
}

/// Every TMCL command of the three modules, typed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Command {
    /// ROR: rotate right (positive direction).
    Ror {
        /// Motor number.
        motor: u8,
        /// Velocity in internal units.
        velocity: i32,
    },
    /// ROL: rotate left (negative direction).
    Rol {
        /// Motor number.
        motor: u8,
        /// Velocity in internal units.
        velocity: i32,
    },
    /// MST: stop the motor.
    Mst {
        /// Motor number.
        motor: u8,
    },
    /// MVP: move to a position.
    Mvp {
        /// ABS, REL or COORD.
        mode: MoveMode,
        /// Motor number.
        motor: u8,
        /// Target position, distance or coordinate number, by mode (microsteps).
        value: i32,
    },
    /// SAP: set an axis parameter.
    Sap {
        /// Axis parameter number.
        param: u8,
        /// Motor number.
        motor: u8,
        /// The new value.
        value: i32,
    },
    /// GAP: get an axis parameter.
    Gap {
        /// Axis parameter number.
        param: u8,
        /// Motor number.
        motor: u8,
    },
    /// STAP: store an axis parameter in the EEPROM.
    Stap {
        /// Axis parameter number.
        param: u8,
        /// Motor number.
        motor: u8,
    },
    /// RSAP: restore an axis parameter from the EEPROM.
    Rsap {
        /// Axis parameter number.
        param: u8,
        /// Motor number.
        motor: u8,
    },
    /// SGP: set a global parameter.
    Sgp {
        /// Global parameter number.
        param: u8,
        /// Bank of the parameter.
        bank: u8,
        /// The new value.
        value: i32,
    },
    /// GGP: get a global parameter.
    Ggp {
        /// Global parameter number.
        param: u8,
        /// Bank of the parameter.
        bank: u8,
    },
    /// STGP: store a global parameter in the EEPROM.
    Stgp {
        /// Global parameter number.
        param: u8,
        /// Bank of the parameter.
        bank: u8,
    },
    /// RSGP: restore a global parameter from the EEPROM.
    Rsgp {
        /// Global parameter number.
        param: u8,
        /// Bank of the parameter.
        bank: u8,
    },
    /// RFS: reference search.
    Rfs {
        /// Start, stop or status.
        action: RfsAction,
        /// Motor number.
        motor: u8,
    },
    /// SIO: set an output.
    Sio {
        /// Output number.
        port: u8,
        /// Bank (2: digital outputs).
        bank: u8,
        /// 0 or 1.
        value: i32,
    },
    /// GIO: get an input or output.
    Gio {
        /// Input or output number.
        port: u8,
        /// Bank (0: digital inputs, 1: analog inputs, 2: outputs).
        bank: u8,
    },
    /// CALC: accumulator ⟵ accumulator `op` value.
    Calc {
        /// The operation.
        op: CalcOp,
        /// The second operand.
        value: i32,
    },
    /// COMP: compare the accumulator with a value (sets the flags for JC).
    Comp {
        /// The value compared with.
        value: i32,
    },
    /// JC: jump if a condition holds.
    Jc {
        /// The condition.
        condition: Condition,
        /// Program address jumped to.
        address: i32,
    },
    /// JA: jump.
    Ja {
        /// Program address jumped to.
        address: i32,
    },
    /// CSUB: call a subroutine.
    Csub {
        /// Program address of the subroutine.
        address: i32,
    },
    /// RSUB: return from a subroutine.
    Rsub,
    /// EI: enable an interrupt (255: all).
    Ei {
        /// Interrupt number.
        interrupt: u8,
    },
    /// DI: disable an interrupt (255: all).
    Di {
        /// Interrupt number.
        interrupt: u8,
    },
    /// WAIT: wait for an event or a time.
    Wait {
        /// What to wait for.
        condition: WaitCondition,
        /// Motor of POS, REFSW, LIMSW and RFS.
        motor: u8,
        /// Time (TICKS) or timeout (the others; 0: none), in 10 ms ticks.
        ticks: i32,
    },
    /// STOP: end the program.
    Stop,
    /// SAC: exchange bytes over an SPI bus.
    Sac {
        /// SPI bus number (the type byte).
        bus: u8,
        /// Number of bytes (the motor byte).
        count: u8,
        /// The bytes to send.
        value: i32,
    },
    /// SCO: set a coordinate.
    Sco {
        /// Coordinate number.
        coordinate: u8,
        /// Motor number.
        motor: u8,
        /// Position in microsteps.
        value: i32,
    },
    /// GCO: get a coordinate.
    Gco {
        /// Coordinate number.
        coordinate: u8,
        /// Motor number.
        motor: u8,
    },
    /// CCO: capture the actual position as a coordinate.
    Cco {
        /// Coordinate number.
        coordinate: u8,
        /// Motor number.
        motor: u8,
    },
    /// CALCX: calculate with the accumulator and the X register.
    CalcX {
        /// The operation.
        op: CalcOp,
    },
    /// AAP: set an axis parameter to the accumulator.
    Aap {
        /// Axis parameter number.
        param: u8,
        /// Motor number.
        motor: u8,
    },
    /// AGP: set a global parameter to the accumulator.
    Agp {
        /// Global parameter number.
        param: u8,
        /// Bank of the parameter.
        bank: u8,
    },
    /// CLE: clear error flags.
    Cle {
        /// The flag to clear.
        flag: ErrorFlag,
    },
    /// VECT: set the address of an interrupt handler.
    Vect {
        /// Interrupt number.
        interrupt: u8,
        /// Program address of the handler.
        address: i32,
    },
    /// RETI: return from an interrupt handler.
    Reti,
    /// ACO: set a coordinate to the accumulator.
    Aco {
        /// Coordinate number.
        coordinate: u8,
        /// Motor number.
        motor: u8,
    },
    /// CALCVV: user variable ⟵ variable `op` variable (var1 in the motor
    /// byte, var2 in the value).
    CalcVV {
        /// The operation.
        op: CalcOp,
        /// User variable that holds the result.
        var1: u8,
        /// User variable of the second operand.
        var2: i32,
    },
    /// CALCVA: user variable ⟵ variable `op` accumulator.
    CalcVA {
        /// The operation.
        op: CalcOp,
        /// User variable number.
        var: u8,
    },
    /// CALCAV: accumulator ⟵ accumulator `op` user variable.
    CalcAV {
        /// The operation.
        op: CalcOp,
        /// User variable number.
        var: u8,
    },
    /// CALCVX: user variable ⟵ variable `op` X register.
    CalcVX {
        /// The operation.
        op: CalcOp,
        /// User variable number.
        var: u8,
    },
    /// CALCXV: X register ⟵ X register `op` user variable.
    CalcXV {
        /// The operation.
        op: CalcOp,
        /// User variable number.
        var: u8,
    },
    /// CALCV: user variable ⟵ variable `op` value.
    CalcV {
        /// The operation.
        op: CalcOp,
        /// User variable number.
        var: u8,
        /// The second operand.
        value: i32,
    },
    /// MVPA: move to the position in the accumulator.
    Mvpa {
        /// ABS, REL or COORD, as for MVP.
        mode: MoveMode,
        /// Motor number.
        motor: u8,
    },
    /// RST: restart the program at an address.
    Rst {
        /// Program address to restart at.
        address: i32,
    },
    /// DJNZ: decrement a user variable and jump unless it is zero.
    Djnz {
        /// User variable counted down.
        var: u8,
        /// Program address jumped to.
        address: i32,
    },
    /// ROLA: rotate left at the velocity in the accumulator.
    Rola {
        /// Motor number.
        motor: u8,
    },
    /// RORA: rotate right at the velocity in the accumulator.
    Rora {
        /// Motor number.
        motor: u8,
    },
    /// SIV: set the indexed variable (the user variable the X register points to).
    Siv {
        /// The new value.
        value: i32,
    },
    /// GIV: get the indexed variable into the accumulator.
    Giv,
    /// AIV: set the indexed variable to the accumulator.
    Aiv,
    /// UF0…UF7: a user function (the module defines what it does).
    UserFunction {
        /// 0…7 (instruction 64…71).
        number: u8,
        /// The type byte.
        kind: u8,
        /// The motor byte.
        motor: u8,
        /// The value.
        value: i32,
    },
    /// CALL: call a subroutine if a condition holds.
    Call {
        /// The condition.
        condition: Condition,
        /// Program address of the subroutine.
        address: i32,
    },
    /// 128: stop the program.
    StopApplication,
    /// 129: run the program.
    RunApplication {
        /// Address to start at; `None`: continue from the current address.
        from: Option<i32>,
    },
    /// 130: execute one instruction of the program.
    StepApplication,
    /// 131: stop the program and set it to address 0.
    ResetApplication,
    /// 132: enter download mode.
    EnterDownload {
        /// Program address of the first word stored.
        address: i32,
    },
    /// 133: exit download mode.
    ExitDownload,
    /// 134: read a word of program memory.
    ReadMemory {
        /// Program address.
        address: i32,
    },
    /// 135: get the application status.
    ApplicationStatus {
        /// 0, 1: state and address; 2: accumulator; 3: X register.
        kind: u8,
    },
    /// 136: get the firmware version.
    FirmwareVersion {
        /// Type 1: the version as a number; type 0: as text.
        binary: bool,
    },
    /// 137: restore the factory settings.
    FactoryDefaults {
        /// Must be 1234 (the command is refused otherwise).
        key: i32,
    },
    /// 138: ask for target reached events.
    TargetReachedEvent {
        /// Type 1: an event after every move, not only the next.
        every_move: bool,
        /// Motors as bits (bit 0: motor 0).
        mask: i32,
    },
    /// 139: enter ASCII mode.
    AsciiMode,
    /// 255: software reset.
    Reset {
        /// Must be 1234 (the command is refused otherwise).
        key: i32,
    },
}

/// Why seven bytes are not a command.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DecodeError {
    /// No TMCL instruction has this number (status 2).
    UnknownOpcode(u8),
    /// The instruction has no such type (status 3).
    WrongType {
        /// The instruction number.
        opcode: u8,
        /// The type byte.
        kind: u8,
    },
}

impl DecodeError {
    /// The status a module answers.
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
