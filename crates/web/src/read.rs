//! Reads of parameters and inputs by kind and number, as the read route
//! and the live stream take them.

use crate::target::{Target, TargetError};
use serde::Deserialize;
use tmclsim_protocol::{Instruction, opcode};

#[derive(Deserialize, Clone, Copy)]
pub struct Read {
    pub kind: ReadKind,
    pub number: u8,
    #[serde(default)]
    pub index: u8,
}

#[derive(Deserialize, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum ReadKind {
    Ap,
    Gp,
    Input,
    Output,
}

impl Read {
    pub fn instruction(self) -> Instruction {
        match self.kind {
            ReadKind::Ap => Instruction::new(opcode::GAP, self.number, self.index, 0),
            ReadKind::Gp => Instruction::new(opcode::GGP, self.number, self.index, 0),
            ReadKind::Input => Instruction::new(opcode::GIO, self.number, self.index, 0),
            ReadKind::Output => Instruction::new(opcode::GIO, self.number, 2, 0),
        }
    }
}

/// The values of `reads` (`None` where the module answered an error) and
/// the module's clock after them.
pub fn read_all(target: &dyn Target, id: usize, reads: &[Read]) -> Result<(Vec<Option<i32>>, f64), TargetError> {
    let all: Vec<Instruction> = reads.iter().map(|r| r.instruction()).collect();
    let (replies, t) = target.observe(id, &all)?;
    Ok((replies.iter().map(|raw| (raw[2] >= 100).then(|| i32::from_be_bytes([raw[4], raw[5], raw[6], raw[7]]))).collect(), t))
}
