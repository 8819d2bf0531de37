//! `tmclsim sweep`: a TMCL program against every scenario of a matrix
//! file, on this machine or a Dask cluster. The engine is the Python
//! package's (`tmclsim.sweep`, with Dask's `distributed`); this command
//! hands its arguments to it (docs/sweeps.md).

use std::process::{Command, ExitCode};

#[derive(clap::Args)]
#[command(disable_help_flag = true)]
pub struct SweepArgs {
    /// PROGRAM --matrix FILE [--workers N | --scheduler tcp://HOST:8786] [--out FILE.parquet|.csv] [--failures DIR] [--batch N]
    #[arg(trailing_var_arg = true, allow_hyphen_values = true, num_args = 0..)]
    pub args: Vec<String>,
}

pub fn run(args: SweepArgs) -> Result<ExitCode, String> {
    // Python's installer for Windows names its interpreter `python`.
    let python = std::env::var("TMCLSIM_PYTHON").unwrap_or_else(|_| if cfg!(windows) { "python" } else { "python3" }.into());
    let probe = Command::new(&python).args(["-c", "import tmclsim.sweep, dask.distributed, pandas, tomli_w"]).output();
    match probe {
        Err(e) => {
            return Err(format!("tmclsim sweep runs on Python ({python}: {e}); set TMCLSIM_PYTHON to an interpreter with the package"));
        }
        Ok(o) if !o.status.success() => {
            return Err(format!(
                "tmclsim sweep needs the Python package with its sweep extra in {python}: pip install './python[sweep]' \
                 (or set TMCLSIM_PYTHON to an interpreter that has it)\n{}",
                String::from_utf8_lossy(&o.stderr).lines().last().unwrap_or("")
            ));
        }
        Ok(_) => {}
    }
    let status = Command::new(&python).args(["-m", "tmclsim.sweep"]).args(&args.args).status().map_err(|e| format!("{python}: {e}"))?;
    Ok(ExitCode::from(status.code().unwrap_or(1).clamp(0, 255) as u8))
}
