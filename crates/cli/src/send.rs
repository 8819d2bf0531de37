//! `tmclsim send`: one command to any TMCL module, the reply decoded.

use crate::SendArgs;
use crate::client::hex;
use std::process::ExitCode;
use tmclsim_host::reply::Shape;
use tmclsim_protocol::{Reply, Request, Status, mnemonic, opcode};

pub fn run(args: SendArgs) -> Result<ExitCode, String> {
    let line = args.command.join(" ");
    let parsed = mnemonic::parse_line(&line);
    if let Err(e) = &parsed
        && !tmclsim_host::line::names_a_parameter(&line)
    {
        return Err(format!("{line}: {e}"));
    }
    let mut client = args.link.open(crate::millis(args.timeout))?;
    // A parameter's name needs the module's profile: named with --module,
    // or the one of the type the module reports (136), asked only then.
    let ins = match parsed {
        Ok(ins) => ins,
        Err(_) => {
            let profile = crate::client::profile(&mut client, args.module.as_deref())?;
            tmclsim_host::line::parse(&line, profile.as_deref()).map_err(|e| format!("{line}: {e}"))?
        }
    };
    println!("request: {}  ({})", hex(&Request::new(args.link.address, ins).encode()), mnemonic::format(ins));
    if ins.opcode == opcode::FACTORY_DEFAULTS {
        client.send_only(ins)?;
        println!("(137 sends no reply)");
        return Ok(ExitCode::SUCCESS);
    }
    // The two bootloader commands that restart the module send no reply
    // (docs/behaviour.md rule 99).
    if ins.opcode == opcode::BOOT_START_APPL || ins.opcode == opcode::BOOT && mnemonic::format(ins) == "BOOT" {
        client.send_only(ins)?;
        println!(
            "({} sends no reply: the module restarts, {}; '#136 0 0 0' says what answers)",
            opcode::name(ins.opcode),
            if ins.opcode == opcode::BOOT {
                "into its bootloader, which answers at address 1"
            } else {
                "into its firmware if that is complete"
            }
        );
        return Ok(ExitCode::SUCCESS);
    }
    // A module that does not answer failed the command, as one that
    // answers an error does: exit status 1 (README.md, "Exit status").
    let reply = match client.exchange(ins) {
        Ok(reply) => reply,
        Err(e) if e.is_unanswered() => {
            println!("{e}");
            return Ok(ExitCode::from(1));
        }
        Err(e) => return Err(e.into()),
    };
    println!("reply:   {}", hex(&reply));
    match tmclsim_host::reply::shape(ins, args.link.address, &reply) {
        Shape::Version => {
            println!("version: {}", String::from_utf8_lossy(&reply[1..]));
            return Ok(ExitCode::SUCCESS);
        }
        Shape::Memory => {
            let stored = tmclsim_protocol::Instruction::from_bytes(reply[1..8].try_into().unwrap());
            println!("memory:  {}", mnemonic::format(stored));
            return Ok(ExitCode::SUCCESS);
        }
        Shape::Normal => {}
    }
    let Some(r) = Reply::decode(&reply) else {
        println!("the reply's checksum is wrong");
        return Ok(ExitCode::from(1));
    };
    let status = Status::from_code(r.status).map_or(format!("{} (unknown)", r.status), |s| s.to_string());
    println!("host {} module {} status {status} opcode {} ({}) value {}", r.host, r.module, r.opcode, opcode::name(r.opcode), r.value);
    Ok(if r.status < 100 { ExitCode::from(1) } else { ExitCode::SUCCESS })
}
