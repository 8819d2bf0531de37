//! `tmclsim clock --speed N -- python SCRIPT …`: runs an unmodified Python
//! program with its clocks N times as fast as the wall clock, through the
//! Python package's clock patch (`python -m tmclsim.clock`), so that it
//! keeps pace with modules served with `tmclsim serve --speed N`
//! (docs/host-software.md).

use clap::Args;
use std::ffi::OsString;
use std::process::{Command, ExitCode};
use tmclsim_firmware::Speed;

#[derive(Args)]
pub struct ClockArgs {
    /// How many times as fast as the wall clock the program's clocks run
    /// (a positive number; the served modules' `--speed`).
    #[arg(long, value_name = "N", value_parser = crate::speed)]
    pub speed: Speed,
    /// The program: a Python interpreter and its arguments, after `--`
    /// (`-- python script.py --port 127.0.0.1:1141`, `-- python3 -m pkg`).
    #[arg(required = true, last = true, value_name = "PYTHON ARGS")]
    pub command: Vec<OsString>,
}

/// The interpreter's arguments that run `args` with the clock patch:
/// `python ARGS` becomes `python -m tmclsim.clock --speed N ARGS`.
pub fn patched(speed: Speed, command: &[OsString]) -> Result<(OsString, Vec<OsString>), String> {
    let (program, args) = command.split_first().ok_or("name the Python program to run after --")?;
    // The file name, with either separator (a Windows path is checked the
    // same on every system).
    let text = program.to_string_lossy().to_lowercase();
    let name = text.rsplit(['/', '\\']).next().unwrap_or_default();
    if !name.starts_with("python") && !name.starts_with("pypy") {
        return Err(format!(
            "'{}' is no Python interpreter: the clock patch works inside Python programs (-- python SCRIPT …); \
             other hosts keep the wall clock (serve with --speed and scale their waits, docs/host-software.md)",
            program.to_string_lossy()
        ));
    }
    let mut out: Vec<OsString> = ["-m", "tmclsim.clock", "--speed"].iter().map(OsString::from).collect();
    out.push(speed.factor().to_string().into());
    out.extend(args.iter().cloned());
    Ok((program.clone(), out))
}

pub fn run(args: ClockArgs) -> Result<ExitCode, String> {
    let (program, arguments) = patched(args.speed, &args.command)?;
    let status =
        Command::new(&program).args(&arguments).status().map_err(|e| format!("cannot start {}: {e}", program.to_string_lossy()))?;
    Ok(match status.code() {
        Some(code) => ExitCode::from(u8::try_from(code).unwrap_or(1)),
        // Ended by a signal: as a shell reports it.
        None => ExitCode::from(128 + exit_signal(&status).unwrap_or(0)),
    })
}

#[cfg(unix)]
fn exit_signal(status: &std::process::ExitStatus) -> Option<u8> {
    use std::os::unix::process::ExitStatusExt;
    status.signal().and_then(|s| u8::try_from(s).ok())
}

#[cfg(not(unix))]
fn exit_signal(_: &std::process::ExitStatus) -> Option<u8> {
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn words(v: &[&str]) -> Vec<OsString> {
        v.iter().map(OsString::from).collect()
    }

    #[test]
    fn python_programs_get_the_patch_in_front() {
        let fifty = Speed::new(50.0).unwrap();
        let (p, a) = patched(fifty, &words(&["python3", "homing.py", "--port", "x"])).unwrap();
        assert_eq!(p, "python3");
        assert_eq!(a, words(&["-m", "tmclsim.clock", "--speed", "50", "homing.py", "--port", "x"]));
        let (_, a) = patched(Speed::new(2.5).unwrap(), &words(&["/usr/bin/python3.11", "-m", "pkg.main"])).unwrap();
        assert_eq!(a, words(&["-m", "tmclsim.clock", "--speed", "2.5", "-m", "pkg.main"]));
        assert!(patched(fifty, &words(&["C:\\Python312\\python.exe", "s.py"])).is_ok());
        let e = patched(fifty, &words(&["./labview_host", "s.py"])).unwrap_err();
        assert!(e.contains("'./labview_host' is no Python interpreter"), "{e}");
    }
}
