//! `tmclsim trace`: record a host's session with a module, real or
//! virtual, through a transparent proxy (`record`), and replay a recorded
//! session on a virtual module, comparing every reply (`check`). The trace
//! format is `tmclsim_host::trace`; docs/host-software.md, "Validate
//! tmclsim against your module", is the user's side of it.

mod check;
mod record;

use std::process::ExitCode;

#[derive(clap::Args)]
pub struct TraceArgs {
    #[command(subcommand)]
    pub command: TraceCommand,
}

#[derive(clap::Subcommand)]
pub enum TraceCommand {
    /// A transparent TMCL proxy: a host connects to --listen, every frame goes on to the module and back, and each is recorded with its time.
    Record(record::RecordArgs),
    /// Replay a trace's requests on a fresh virtual module in virtual time and compare every reply: exit 0 when all match, 1 with a report of the differences, 2 on a bad file.
    Check(check::CheckArgs),
}

pub fn run(args: TraceArgs) -> Result<ExitCode, String> {
    match args.command {
        TraceCommand::Record(a) => record::run(a),
        TraceCommand::Check(a) => check::run(a),
    }
}
