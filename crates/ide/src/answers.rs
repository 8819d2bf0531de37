//! Direct mode, parameters and the world: a request to module `id` of a
//! target and its answer as the app shows it.

use crate::target::{ModuleEntry, Target, TargetError};
use serde::Deserialize;
use serde_json::{Value, json};
use tmclsim_firmware::snapshot::ModuleSnapshot;
use tmclsim_profile::Profile;
use tmclsim_protocol::mnemonic::ParseError;
use tmclsim_protocol::{FRAME_LEN, Instruction, Request, opcode};

/// Bytes as hex pairs: `01 06 01 …`.
pub fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02x}")).collect::<Vec<_>>().join(" ")
}

/// Module `id` of the target.
pub fn entry(target: &dyn Target, id: usize) -> Result<&ModuleEntry, TargetError> {
    target.modules().get(id).ok_or(TargetError::NoModule)
}

/// A direct-mode line for module `id` (parameter names from its profile),
/// or what is wrong with it: `column N: …`.
pub fn parse_line(target: &dyn Target, id: usize, line: &str) -> Result<Instruction, ParseError> {
    let profile = target.modules().get(id).and_then(|m| m.profile.clone());
    crate::line::parse(line, profile.as_deref())
}

/// A request and its reply as the app shows them.
pub fn exchange(target: &dyn Target, id: usize, ins: Instruction) -> Result<Value, TargetError> {
    let m = entry(target, id)?;
    let (address, profile) = (m.address, m.profile.clone());
    let raw = target.request(id, ins)?;
    let unit = profile.as_deref().and_then(|p| unit_now(target, id, p, ins));
    Ok(described(address, profile.as_deref(), ins, &raw, unit))
}

/// The unit a sixPoint module's velocity or acceleration row addressed by
/// SAP or GAP is in: pps and pps² (as its profile says) unless the motor's
/// unit mode (AP 255, read now) is 0, the chip's registers
/// (docs/behaviour.md rule 104). `None` for any other row or module.
fn unit_now(target: &dyn Target, id: usize, profile: &Profile, ins: Instruction) -> Option<&'static str> {
    if !matches!(ins.opcode, opcode::SAP | opcode::GAP) {
        return None;
    }
    let (quantity, "sixpoint") = crate::profile_json::quantity(profile, profile.axis_parameter(ins.kind)?)? else {
        return None;
    };
    let (replies, _) = target.observe(id, &[Instruction::new(opcode::GAP, 255, ins.motor, 0)]).ok()?;
    let mode = replies.first().filter(|raw| raw[2] >= 100).map(|raw| i32::from_be_bytes([raw[4], raw[5], raw[6], raw[7]]))?;
    Some(match (mode, quantity) {
        (0, "velocity") => "int (v·f_CLK/2^24 pps)",
        (0, _) => "int (a·f_CLK²/2^41 pps²)",
        (_, "velocity") => "pps",
        _ => "pps²",
    })
}

fn described(address: u8, profile: Option<&Profile>, ins: Instruction, raw: &[u8; FRAME_LEN], unit: Option<&str>) -> Value {
    let value = i32::from_be_bytes([raw[4], raw[5], raw[6], raw[7]]);
    if ins.opcode == opcode::FIRMWARE_VERSION && ins.kind == 0 {
        // The reply is text from its second byte on: no status, no value.
        let version = String::from_utf8_lossy(&raw[1..]).trim_end_matches('\0').to_string();
        return json!({
            "request": hex(&Request::new(address, ins).encode()), "reply": hex(raw),
            "status": null, "status_text": null, "value": null, "version": version,
            "text": format!("version {version}"),
        });
    }
    json!({
        "request": hex(&Request::new(address, ins).encode()), "reply": hex(raw),
        "status": raw[2], "status_text": tmclsim_protocol::Status::text(raw[2]), "value": value,
        "text": crate::reply::describe_in(ins, raw, address, profile, unit),
    })
}

/// One value the app reads: an axis or global parameter, an input or an
/// output.
#[derive(Deserialize, Clone, Copy)]
pub struct Read {
    /// What is read.
    pub kind: ReadKind,
    /// The parameter or port number.
    pub number: u8,
    /// The motor (`ap`) or bank (`gp`, `input`); unused for outputs.
    #[serde(default)]
    pub index: u8,
}

/// What a [`Read`] reads (its JSON `kind`).
#[derive(Deserialize, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum ReadKind {
    /// An axis parameter (GAP).
    Ap,
    /// A global parameter (GGP).
    Gp,
    /// An input (GIO).
    Input,
    /// An output (GIO bank 2).
    Output,
}

impl Read {
    /// The request that reads it.
    pub fn instruction(self) -> Instruction {
        match self.kind {
            ReadKind::Ap => Instruction::new(opcode::GAP, self.number, self.index, 0),
            ReadKind::Gp => Instruction::new(opcode::GGP, self.number, self.index, 0),
            ReadKind::Input => Instruction::new(opcode::GIO, self.number, self.index, 0),
            ReadKind::Output => Instruction::new(opcode::GIO, self.number, 2, 0),
        }
    }
}

/// Most values read at once.
pub const MAX_READS: usize = 4096;

/// The values of `reads` (`None` where the module answered an error) and
/// the module's clock after them.
pub fn read_all(target: &dyn Target, id: usize, reads: &[Read]) -> Result<(Vec<Option<i32>>, f64), TargetError> {
    let all: Vec<Instruction> = reads.iter().map(|r| r.instruction()).collect();
    let (replies, t) = target.observe(id, &all)?;
    Ok((replies.iter().map(|raw| (raw[2] >= 100).then(|| i32::from_be_bytes([raw[4], raw[5], raw[6], raw[7]]))).collect(), t))
}

/// `{"values": […], "t": seconds}` for the reads, at most [`MAX_READS`].
pub fn read_json(target: &dyn Target, id: usize, reads: &[Read]) -> Result<Value, TargetError> {
    if reads.len() > MAX_READS {
        return Err(TargetError::Failed(format!("at most {MAX_READS} reads at once")));
    }
    let (values, t) = read_all(target, id, reads)?;
    Ok(json!({ "values": values, "t": t }))
}

/// A parameter write: a value set, or the parameter stored to or restored
/// from the EEPROM.
#[derive(Deserialize)]
pub struct Write {
    /// `ap` or `gp` (the others are refused).
    pub kind: ReadKind,
    /// The parameter number.
    pub number: u8,
    /// The motor (`ap`) or bank (`gp`).
    #[serde(default)]
    pub index: u8,
    /// The value to set (`set` only).
    pub value: Option<i64>,
    /// `set` (the default), `store` or `restore`.
    pub op: Option<String>,
}

/// What is wrong with a parameter write.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum WriteError {
    /// A kind other than `ap` or `gp`.
    Kind,
    /// The value does not fit 32 bits.
    TooLarge(i64),
    /// `set` without a value.
    NoValue,
    /// An op other than set, store or restore.
    Op(String),
}

impl std::fmt::Display for WriteError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            WriteError::Kind => write!(f, "write takes kind 'ap' or 'gp'; outputs are set with SIO in a command"),
            WriteError::TooLarge(v) => write!(f, "{v} does not fit a 32-bit value"),
            WriteError::NoValue => write!(f, "give a value"),
            WriteError::Op(op) => write!(f, "op '{op}': use set, store or restore"),
        }
    }
}

impl std::error::Error for WriteError {}

impl From<WriteError> for String {
    fn from(e: WriteError) -> String {
        e.to_string()
    }
}

impl Write {
    /// The instruction that does it (SAP/STAP/RSAP, SGP/STGP/RSGP), or what
    /// is wrong.
    pub fn instruction(&self) -> Result<Instruction, WriteError> {
        let axis = match self.kind {
            ReadKind::Ap => true,
            ReadKind::Gp => false,
            _ => return Err(WriteError::Kind),
        };
        let (set, store, restore) =
            if axis { (opcode::SAP, opcode::STAP, opcode::RSAP) } else { (opcode::SGP, opcode::STGP, opcode::RSGP) };
        let (number, index) = (self.number, self.index);
        match (self.op.as_deref(), self.value) {
            (None | Some("set"), Some(v)) => {
                let v = i32::try_from(v).map_err(|_| WriteError::TooLarge(v))?;
                Ok(Instruction::new(set, number, index, v))
            }
            (None | Some("set"), None) => Err(WriteError::NoValue),
            (Some("store"), _) => Ok(Instruction::new(store, number, index, 0)),
            (Some("restore"), _) => Ok(Instruction::new(restore, number, index, 0)),
            (Some(other), _) => Err(WriteError::Op(other.to_string())),
        }
    }
}

/// The module list as the app shows it.
pub fn modules_json(target: &dyn Target) -> Value {
    let virt = target.kind() == "virtual";
    let list: Vec<Value> = target
        .modules()
        .iter()
        .enumerate()
        .map(|(id, m)| {
            json!({"id": id, "address": m.address, "profile": m.profile.as_ref().map(|p| p.module.name.clone()),
                   "firmware": m.firmware, "link": m.link, "virtual": virt, "bootloader": target.bootloader(id)})
        })
        .collect();
    Value::Array(list)
}

/// Longest world line.
pub const MAX_WORLD_LINE: usize = 4096;

/// One line of the control protocol (docs/world.md) for module `id`.
pub fn world_json(target: &dyn Target, id: usize, line: &str) -> Result<Value, TargetError> {
    if line.len() > MAX_WORLD_LINE {
        return Err(TargetError::Failed(format!("a world line is at most {MAX_WORLD_LINE} bytes")));
    }
    Ok(json!({ "ok": target.world(id, line)? }))
}

/// The world around a virtual module: switches, load, carriage and IO.
pub fn world_state_json(s: &ModuleSnapshot) -> Value {
    let axes: Vec<Value> = s
        .axes
        .iter()
        .map(|a| {
            json!({"left": a.left, "right": a.right, "home": a.home, "load": a.load, "carriage": a.carriage,
                        "position": a.position, "speed": a.speed, "current": a.current, "stallguard": a.stallguard,
                        "stopped_by_switch": a.stopped_by_switch})
        })
        .collect();
    json!({"time": s.time_ns as f64 * 1e-9, "axes": axes, "inputs": s.io.inputs, "outputs": s.io.outputs,
           "analog": s.io.analog, "supply": s.io.supply, "temperature": s.io.temperature})
}
