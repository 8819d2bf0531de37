//! Small value types: a decoded reply, one instruction, the interpreter's
//! registers.

use crate::errors::{tmcl_error, value_error};
use pyo3::prelude::*;
use pyo3::types::{PyInt, PySequence, PyString};
use std::borrow::Cow;
use tmclsim_firmware::module::Compare;
use tmclsim_protocol::{FRAME_LEN, Instruction as Ins, Status, checksum, mnemonic};

/// What kind of frame a reply is: a normal reply, the version text of 136
/// type 0, or the stored word of 134 (told apart from an error reply as
/// every host of tmclsim tells it).
pub use tmclsim_host::reply::Shape as ReplyKind;

/// A module's answer to one command.
///
/// The fields read the nine bytes as a normal reply does: ``host``,
/// ``module`` (the address the request used), ``status``, ``opcode`` and
/// ``value``. The special replies keep their bytes in ``raw``: the answer to
/// 136 type 0 (``version`` gives its text) and to 134 (``instruction``
/// gives the stored word).
#[pyclass(frozen, module = "tmclsim", name = "Reply")]
pub struct Reply {
    pub raw: [u8; FRAME_LEN],
    pub kind: ReplyKind,
}

impl Reply {
    pub fn new(raw: [u8; FRAME_LEN], kind: ReplyKind) -> Reply {
        Reply { raw, kind }
    }

    fn value_word(&self) -> i32 {
        i32::from_be_bytes([self.raw[4], self.raw[5], self.raw[6], self.raw[7]])
    }

    fn is_ok(&self) -> bool {
        match self.kind {
            ReplyKind::Normal => matches!(self.raw[2], 100 | 101 | 128) && self.checksum_ok(),
            ReplyKind::Version => true,
            ReplyKind::Memory => self.checksum_ok(),
        }
    }

    fn status_text(&self) -> String {
        Status::text(self.raw[2]).into_owned()
    }
}

#[pymethods]
impl Reply {
    /// Reply(raw: bytes, special: str | None = None)
    /// --
    ///
    /// Decodes nine bytes a module sent. ``special`` is ``"version"`` for
    /// the answer to 136 type 0 and ``"memory"`` for the answer to 134.
    #[new]
    #[pyo3(signature = (raw, special=None))]
    fn py_new(raw: Cow<'_, [u8]>, special: Option<&str>) -> PyResult<Reply> {
        let raw: [u8; FRAME_LEN] =
            raw.as_ref().try_into().map_err(|_| value_error(format!("a reply is {FRAME_LEN} bytes, not {}", raw.len())))?;
        let kind = match special {
            None => ReplyKind::Normal,
            Some("version") => ReplyKind::Version,
            Some("memory") => ReplyKind::Memory,
            Some(other) => return Err(value_error(format!("special is 'version' or 'memory', not '{other}'"))),
        };
        Ok(Reply { raw, kind })
    }

    /// The host address (byte 0).
    #[getter]
    fn host(&self) -> u8 {
        self.raw[0]
    }

    /// The module address the request used (byte 1).
    #[getter]
    fn module(&self) -> u8 {
        self.raw[1]
    }

    /// The TMCL status code: 100 ok, 101 loaded into program memory, 128
    /// event, 1…6 errors (byte 2).
    #[getter]
    fn status(&self) -> u8 {
        self.raw[2]
    }

    /// The opcode the reply answers (byte 3).
    #[getter]
    fn opcode(&self) -> u8 {
        self.raw[3]
    }

    /// The 32-bit signed value (bytes 4…7, most significant first).
    #[getter]
    fn value(&self) -> i32 {
        self.value_word()
    }

    /// The nine bytes as they came from the module.
    #[getter]
    fn raw(&self) -> [u8; FRAME_LEN] {
        self.raw
    }

    /// True for the special replies of 136 type 0 and 134.
    #[getter]
    fn special(&self) -> bool {
        self.kind != ReplyKind::Normal
    }

    /// Whether byte 8 is the checksum of bytes 0…7 (the version reply of
    /// 136 has none).
    #[getter]
    fn checksum_ok(&self) -> bool {
        checksum(&self.raw[..8]) == self.raw[8]
    }

    /// True when the command succeeded (status 100, 101 or 128, or a
    /// special reply).
    #[getter]
    fn ok(&self) -> bool {
        self.is_ok()
    }

    /// The status in words ("ok", "wrong type", …).
    #[getter]
    fn description(&self) -> String {
        match self.kind {
            ReplyKind::Normal => self.status_text(),
            ReplyKind::Version => "version".to_string(),
            ReplyKind::Memory => "program memory word".to_string(),
        }
    }

    /// The version text of a 136 type 0 reply (e.g. ``"1141V146"``), else
    /// None.
    #[getter]
    fn version(&self) -> Option<String> {
        (self.kind == ReplyKind::Version).then(|| String::from_utf8_lossy(&self.raw[1..]).into_owned())
    }

    /// The stored instruction of a 134 reply, else None.
    #[getter]
    fn instruction(&self) -> Option<Instruction> {
        (self.kind == ReplyKind::Memory).then(|| Instruction(Ins::from_bytes(self.raw[1..8].try_into().unwrap())))
    }

    /// check() -> Reply
    /// --
    ///
    /// Returns the reply when it reports success; raises ``TmclError``
    /// with its status otherwise.
    fn check(slf: Bound<'_, Self>) -> PyResult<Bound<'_, Self>> {
        let r = slf.get();
        if r.is_ok() {
            return Ok(slf);
        }
        let status = Status::from_code(r.raw[2]).unwrap_or(Status::WrongChecksum);
        let message = if r.checksum_ok() {
            format!("opcode {}: {} (status {})", r.raw[3], r.status_text(), r.raw[2])
        } else {
            "the reply's checksum is wrong".to_string()
        };
        Err(tmcl_error(slf.py(), status, message))
    }

    fn __bytes__(&self) -> [u8; FRAME_LEN] {
        self.raw
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other.cast::<Reply>().is_ok_and(|o| o.get().raw == self.raw)
    }

    fn __hash__(&self) -> u64 {
        u64::from_be_bytes(self.raw[..8].try_into().unwrap())
    }

    fn __repr__(&self) -> String {
        match self.kind {
            ReplyKind::Version => format!("<Reply version {:?} host={}>", String::from_utf8_lossy(&self.raw[1..]), self.raw[0]),
            ReplyKind::Memory => {
                format!("<Reply memory {} host={}>", exact_text(Ins::from_bytes(self.raw[1..8].try_into().unwrap())), self.raw[0])
            }
            ReplyKind::Normal => format!(
                "<Reply status={} ({}) value={} opcode={} module={} host={}>",
                self.raw[2],
                self.status_text(),
                self.value_word(),
                self.raw[3],
                self.raw[1],
                self.raw[0]
            ),
        }
    }
}

/// One TMCL instruction: opcode, type, motor (or bank) and value. Also one
/// word of program memory.
#[pyclass(frozen, eq, hash, module = "tmclsim", name = "Instruction", from_py_object)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Instruction(pub Ins);

#[pymethods]
impl Instruction {
    /// Instruction(opcode: int, type: int = 0, motor: int = 0, value: int = 0)
    /// --
    ///
    /// Opcode, type and motor are bytes (0…255); the value is a signed
    /// 32-bit number (values up to 2**32 - 1 wrap as on the wire).
    #[new]
    #[pyo3(signature = (opcode, r#type=0, motor=0, value=0))]
    fn py_new(opcode: u8, r#type: u8, motor: u8, value: i64) -> PyResult<Instruction> {
        Ok(Instruction(Ins::new(opcode, r#type, motor, wire_value(value)?)))
    }

    /// parse(line: str) -> Instruction
    /// --
    ///
    /// One command as text: a mnemonic with numeric operands
    /// (``"MVP ABS, 0, 1000"``, ``"GAP 1, 0"``) or the raw form
    /// ``"#136 0 0 0"`` (opcode type motor value).
    #[staticmethod]
    fn parse(line: &str) -> PyResult<Instruction> {
        parse_line(line).map(Instruction)
    }

    /// The instruction number (4 = MVP, 6 = GAP, …).
    #[getter]
    fn opcode(&self) -> u8 {
        self.0.opcode
    }

    /// The type byte (parameter number, port, move mode…).
    #[getter]
    fn r#type(&self) -> u8 {
        self.0.kind
    }

    /// The motor or bank byte.
    #[getter]
    fn motor(&self) -> u8 {
        self.0.motor
    }

    /// The signed 32-bit value.
    #[getter]
    fn value(&self) -> i32 {
        self.0.value
    }

    /// The instruction as source text (``"MVP ABS, 0, 1000"``; raw form
    /// for instructions without a mnemonic).
    #[getter]
    fn mnemonic(&self) -> String {
        exact_text(self.0)
    }

    /// to_bytes() -> bytes
    /// --
    ///
    /// The seven bytes: opcode, type, motor, value (most significant first).
    #[allow(clippy::wrong_self_convention)]
    fn to_bytes(&self) -> [u8; 7] {
        self.0.to_bytes()
    }

    /// frame(address: int = 1) -> bytes
    /// --
    ///
    /// The 9-byte request frame for a module at ``address``.
    #[pyo3(signature = (address=1))]
    fn frame(&self, address: u8) -> [u8; FRAME_LEN] {
        tmclsim_protocol::Request::new(address, self.0).encode()
    }

    fn __iter__(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        let t = (self.0.opcode, self.0.kind, self.0.motor, self.0.value).into_pyobject(py)?;
        Ok(t.try_iter()?.into_any().unbind())
    }

    fn __str__(&self) -> String {
        exact_text(self.0)
    }

    fn __repr__(&self) -> String {
        format!("Instruction.parse({:?})", exact_text(self.0))
    }
}

/// Source text that parses back to exactly this instruction: the mnemonic
/// form when it is exact, else the raw form `#opcode type motor value`.
pub fn exact_text(ins: Ins) -> String {
    if tmclsim_asm::disasm::has_mnemonic_form(ins) {
        mnemonic::format(ins)
    } else {
        format!("#{} {} {} {}", ins.opcode, ins.kind, ins.motor, ins.value)
    }
}

/// A value as the wire carries it: −2**31 … 2**32 − 1, the upper half
/// wrapping to negative numbers.
pub fn wire_value(v: i64) -> PyResult<i32> {
    if (i64::from(i32::MIN)..=i64::from(u32::MAX)).contains(&v) {
        Ok(v as u32 as i32)
    } else {
        Err(value_error(format!("{v} does not fit in 32 bits")))
    }
}

/// Parses one command line; errors name the column.
pub fn parse_line(line: &str) -> PyResult<Ins> {
    mnemonic::parse_line(line).map_err(|e| value_error(format!("'{line}': column {}: {}", e.column, e.message)))
}

/// An instruction from Python: an `Instruction`, a command line, or a
/// sequence `(opcode, type, motor, value)`.
pub fn instruction_from(obj: &Bound<'_, PyAny>) -> PyResult<Ins> {
    if let Ok(i) = obj.cast::<Instruction>() {
        return Ok(i.get().0);
    }
    if let Ok(s) = obj.cast::<PyString>() {
        return parse_line(&s.to_cow()?);
    }
    if let Ok(seq) = obj.cast::<PySequence>()
        && seq.len()? == 4
    {
        let opcode: u8 = seq.get_item(0)?.extract()?;
        let kind: u8 = seq.get_item(1)?.extract()?;
        let motor: u8 = seq.get_item(2)?.extract()?;
        let value: i64 = seq.get_item(3)?.extract()?;
        return Ok(Ins::new(opcode, kind, motor, wire_value(value)?));
    }
    Err(pyo3::exceptions::PyTypeError::new_err(format!(
        "expected an Instruction, a command line or (opcode, type, motor, value), not {}",
        obj.get_type().name()?
    )))
}

/// The instruction a `send(command, type, motor, value)` call means.
pub fn command_from(command: &Bound<'_, PyAny>, kind: Option<u8>, motor: Option<u8>, value: Option<i64>) -> PyResult<Ins> {
    if command.is_instance_of::<PyInt>() {
        let opcode: u8 = command.extract()?;
        return Ok(Ins::new(opcode, kind.unwrap_or(0), motor.unwrap_or(0), wire_value(value.unwrap_or(0))?));
    }
    if kind.is_some() || motor.is_some() || value.is_some() {
        return Err(pyo3::exceptions::PyTypeError::new_err(
            "type, motor and value go with a numeric opcode: send(opcode, type, motor, value)",
        ));
    }
    instruction_from(command)
}

/// Accumulator, X register and flags of the TMCL interpreter.
#[pyclass(frozen, module = "tmclsim", name = "Registers")]
pub struct Registers {
    /// The accumulator.
    #[pyo3(get)]
    accumulator: i32,
    /// The X register.
    #[pyo3(get)]
    x: i32,
    /// The result of the last comparison: "less", "equal" or "greater".
    #[pyo3(get)]
    compare: &'static str,
    /// The error flags as a bit mask (ETO 2, EAL 4, EDV 8, EPO 16, ESD 32).
    #[pyo3(get)]
    errors: u8,
}

impl Registers {
    pub fn new(r: tmclsim_firmware::module::Registers) -> Registers {
        let compare = match r.compare {
            Compare::Less => "less",
            Compare::Equal => "equal",
            Compare::Greater => "greater",
        };
        Registers { accumulator: r.accumulator, x: r.x, compare, errors: r.errors }
    }
}

#[pymethods]
impl Registers {
    /// The set error flags by name: "ETO", "EAL", "EDV", "EPO", "ESD".
    #[getter]
    fn error_flags(&self) -> Vec<&'static str> {
        tmclsim_host::observe::error_flag_names(self.errors)
    }

    fn __repr__(&self) -> String {
        format!("<Registers accumulator={} x={} compare={} errors={:#04x}>", self.accumulator, self.x, self.compare, self.errors)
    }
}
