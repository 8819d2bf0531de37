//! `tmclsim upload`: download a program to any TMCL module, real or
//! virtual, as TMCL-IDE does (132, the words, a NOP, 133: docs/behaviour.md
//! rule 94), verify it by reading it back with 134, optionally start it.

use std::path::PathBuf;
use std::process::ExitCode;
use tmclsim_asm::Program;
use tmclsim_host::LinkError;
use tmclsim_host::download::{DownloadError, download_and_verify};
use tmclsim_protocol::{Instruction, Status, opcode};

#[derive(clap::Args)]
pub struct UploadArgs {
    /// TMCL source (.tmc) or binary (.bin, 8 bytes per instruction).
    pub program: PathBuf,
    #[command(flatten)]
    pub link: crate::client::LinkArgs,
    /// Profile to check the source against.
    #[arg(long, default_value = "tmcm-1141")]
    pub module: String,
    /// Start the program after the upload (129 from address 0).
    #[arg(long)]
    pub run: bool,
    /// Make the program start at power-up (GP 77 = 1).
    #[arg(long)]
    pub autostart: bool,
    /// Reply timeout in milliseconds.
    #[arg(long, value_name = "MS", default_value_t = 2000)]
    pub timeout: u64,
}

/// Why an upload stopped: the module refused or did not answer a command,
/// or holds other words than were sent (exit status 1, as `send` when a
/// command fails), or the upload could not be made at all (the program,
/// the link: exit status 2).
enum Stop {
    Failed(String),
    Error(String),
}

impl From<String> for Stop {
    fn from(e: String) -> Stop {
        Stop::Error(e)
    }
}

impl From<LinkError> for Stop {
    fn from(e: LinkError) -> Stop {
        if e.is_unanswered() { Stop::Failed(e.to_string()) } else { Stop::Error(e.to_string()) }
    }
}

pub fn run(args: UploadArgs) -> Result<ExitCode, String> {
    match upload(args) {
        Ok(()) => Ok(ExitCode::SUCCESS),
        Err(Stop::Failed(e)) => {
            eprintln!("tmclsim: {e}");
            Ok(ExitCode::from(1))
        }
        Err(Stop::Error(e)) => Err(e),
    }
}

fn upload(args: UploadArgs) -> Result<(), Stop> {
    // A binary is downloaded word for word; a source as the assembler
    // writes it, with the STOP it appends (docs/behaviour.md rule 93).
    let (words, appended): (Vec<Instruction>, bool) = if args.program.extension().is_some_and(|e| e == "bin") {
        use tmclsim_server::files::{MAX_BINARY_BYTES, read_limited};
        let bytes = read_limited(&args.program, MAX_BINARY_BYTES, "a program binary").map_err(String::from)?;
        (Program::from_binary(&bytes).map_err(String::from)?, false)
    } else {
        let program = crate::asm::assemble(&args.program, &args.module)?.0;
        (program.instructions, program.appended_stop)
    };
    let mut c = args.link.open(crate::millis(args.timeout))?;
    let ok = |r: tmclsim_protocol::Reply, what: &str| -> Result<(), Stop> {
        if r.status < 100 {
            let s = Status::from_code(r.status).map_or(r.status.to_string(), |s| s.to_string());
            return Err(Stop::Failed(format!("{what}: the module answered status {s}")));
        }
        Ok(())
    };
    let mut progress = crate::progress::Progress::new(2 * words.len() as u64, "{bar:40} {pos}/{len} words sent and read back");
    let address = args.link.address;
    let mut request = |ins: Instruction| c.request(ins).map(|r| r.encode());
    download_and_verify(&mut request, address, &words, &mut |done| progress.set(done as u64)).map_err(|e| match e {
        DownloadError::Link(e) => Stop::from(e),
        e => Stop::Failed(e.to_string()),
    })?;
    progress.finish();
    let note = if appended { " (the last one the STOP appended after the program's last instruction)" } else { "" };
    println!("uploaded and verified {} instructions{note}", words.len());
    if args.autostart {
        ok(c.request(Instruction::new(opcode::SGP, 77, 0, 1))?, "autostart (GP 77)")?;
        println!("autostart on");
    }
    if args.run {
        ok(c.request(Instruction::new(opcode::RUN_APPLICATION, 1, 0, 0))?, "run")?;
        println!("running");
    }
    Ok(())
}
