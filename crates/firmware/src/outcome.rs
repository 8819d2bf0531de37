//! What executing one instruction produces (`Outcome`, `Special`) and how
//! the instruction was reached (`Origin`).

use tmclsim_protocol::{FRAME_LEN, Status};

/// How `execute` was reached: the host (direct mode) or a program.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Origin {
    /// A command from the host over a link.
    Direct,
    /// An instruction of the TMCL program (a read loads the accumulator).
    Program,
}

/// What a command produced besides status and value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Special {
    /// A normal reply.
    None,
    /// Send these 9 bytes instead of a normal reply.
    Frame([u8; FRAME_LEN]),
    /// Send no reply at all.
    Silent,
}

/// The result of executing one instruction.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Outcome {
    /// The reply's status (100 when the command was carried out).
    pub status: Status,
    /// The reply's value (what a read answers; for a write, the value written).
    pub value: i32,
    /// Whether the reply is normal, replaced by another frame, or suppressed.
    pub special: Special,
}

impl Outcome {
    /// A normal reply with status 100 and `value`.
    pub fn ok(value: i32) -> Outcome {
        Outcome { status: Status::Ok, value, special: Special::None }
    }

    /// A normal reply with an error `status` and `value`.
    pub fn error(status: Status, value: i32) -> Outcome {
        Outcome { status, value, special: Special::None }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ok_and_error_are_normal_replies() {
        assert_eq!(Outcome::ok(7), Outcome { status: Status::Ok, value: 7, special: Special::None });
        assert_eq!(Outcome::error(Status::WrongType, -1), Outcome { status: Status::WrongType, value: -1, special: Special::None });
    }
}
