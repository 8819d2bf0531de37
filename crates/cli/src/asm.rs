//! `tmclsim asm` and `tmclsim disasm`.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use tmclsim_asm::{Program, disassemble, render};
use tmclsim_firmware::Profile;
use tmclsim_server::sources::assemble_file;

#[derive(clap::Args)]
pub struct AsmArgs {
    /// TMCL source file.
    pub source: PathBuf,
    /// Binary output (default: SOURCE with .bin); the symbol file goes
    /// beside it with .sym.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Check the program against this module's profile.
    #[arg(long, default_value = "tmcm-1141")]
    pub module: String,
    /// Print a listing instead of writing files: address, bytes, source
    /// line number and source text.
    #[arg(long)]
    pub list: bool,
}

#[derive(clap::Args)]
pub struct DisasmArgs {
    /// Binary file (8 bytes per instruction).
    pub binary: PathBuf,
    /// Symbol file for label names (default: BINARY with .sym, if present).
    #[arg(long)]
    pub symbols: Option<PathBuf>,
    /// Output file (default: standard output).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
}

/// Assembles a file against a module profile; diagnostics go to stderr.
pub fn assemble(source: &Path, module: &str) -> Result<(Program, std::sync::Arc<Profile>), String> {
    let profile = Profile::built_in(module)?;
    match assemble_file(source, Some(&profile)) {
        Ok(p) => Ok((p, profile)),
        Err(diagnostics) => {
            eprint!("{}", render(&diagnostics));
            Err(format!("{}: {} error(s)", source.display(), diagnostics.len()))
        }
    }
}

pub fn asm(args: AsmArgs) -> Result<ExitCode, String> {
    let (program, _) = assemble(&args.source, &args.module)?;
    if args.list {
        let by_address: std::collections::BTreeMap<u32, &str> = program.symbols.iter().map(|(k, v)| (*v, k.as_str())).collect();
        for (a, ins) in program.instructions.iter().enumerate() {
            if let Some(label) = by_address.get(&(a as u32)) {
                println!("{label}:");
            }
            let b = ins.to_bytes();
            // The source line beside the bytes: its number, with the file
            // named when it is an included one.
            let main = program.source_map.first().map(|s| &*s.file);
            let source = match program.source_of(a as u32) {
                Some(s) if Some(&*s.file) == main => format!("{:>5}  {}", s.line, s.text),
                Some(s) => format!("{:>5}  {}  ({}:{})", s.line, s.text, s.file, s.line),
                None if program.appended_stop_address() == Some(a as u32) => {
                    format!("       {}  (appended: the program does not end in STOP)", tmclsim_protocol::mnemonic::format(*ins))
                }
                None => format!("       {}", tmclsim_protocol::mnemonic::format(*ins)),
            };
            println!("{a:5}  {}  {source}", crate::client::hex(&b));
        }
        return Ok(ExitCode::SUCCESS);
    }
    let out = args.output.unwrap_or_else(|| args.source.with_extension("bin"));
    std::fs::write(&out, program.to_binary()).map_err(|e| format!("{}: {e}", out.display()))?;
    let sym = out.with_extension("sym");
    std::fs::write(&sym, program.symbol_file()).map_err(|e| format!("{}: {e}", sym.display()))?;
    let note = if program.appended_stop { " (the last one a STOP appended after the program's last instruction)" } else { "" };
    println!("{}: {} instructions{note} → {} and {}", args.source.display(), program.instructions.len(), out.display(), sym.display());
    Ok(ExitCode::SUCCESS)
}

pub fn disasm(args: DisasmArgs) -> Result<ExitCode, String> {
    use tmclsim_server::files::{MAX_BINARY_BYTES, MAX_CONFIG_BYTES, read_limited, read_text_limited};
    let bytes = read_limited(&args.binary, MAX_BINARY_BYTES, "a program binary")?;
    let words = Program::from_binary(&bytes).map_err(|e| format!("{}: {e}", args.binary.display()))?;
    let sym_path = args.symbols.clone().unwrap_or_else(|| args.binary.with_extension("sym"));
    let symbols = if args.symbols.is_none() && !sym_path.exists() {
        None
    } else {
        let text = read_text_limited(&sym_path, MAX_CONFIG_BYTES, "a symbol file")?;
        Some(Program::parse_symbol_file(&text).map_err(|e| format!("{}: {e}", sym_path.display()))?)
    };
    let text = disassemble(&words, symbols.as_ref());
    match args.output {
        Some(out) => std::fs::write(&out, text).map_err(|e| format!("{}: {e}", out.display()))?,
        None => print!("{text}"),
    }
    Ok(ExitCode::SUCCESS)
}
