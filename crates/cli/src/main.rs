//! The `tmclsim` binary: the command of [`tmclsim_cli::run`].

fn main() -> std::process::ExitCode {
    std::process::ExitCode::from(tmclsim_cli::run(std::env::args_os()))
}
