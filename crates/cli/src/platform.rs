//! Where the command differs between Unix and Windows, in one place: the
//! links only Unix has (refused on Windows before anything is opened,
//! naming Windows' way to the same end), SIGPIPE, ending a child server so
//! that it stops cleanly, and the CPU time and memory of processes that
//! the benchmarks report. The signals that stop a server are signal.rs's.

use crate::ServeArgs;
use std::process::{Child, Command};
use std::time::Duration;

/// Why a pty cannot be served on this system (`None`: it can).
pub(crate) const PTY_REFUSED: Option<&str> = if cfg!(unix) {
    None
} else {
    Some(
        "a pty is a Unix device; on Windows serve the module on a COM port with --serial COMn (a com0com virtual \
         null-modem pair gives host software that only opens COM ports its own port), or on --tcp",
    )
};

/// Why the SLCAN adapter (which lives on a pty) cannot be served here.
pub(crate) const SLCAN_REFUSED: Option<&str> = if cfg!(unix) {
    None
} else {
    Some(
        "the SLCAN adapter is served on a pty, a Unix device, and Windows has none; on Windows serve the modules on --tcp \
         (PyTrinamic: --interface socket_serial_tmcl), or serve the SLCAN adapter from a Linux or macOS host",
    )
};

/// Why EtherCAT slaves cannot be served here.
pub(crate) const ETHERCAT_REFUSED: Option<&str> = if cfg!(target_os = "linux") {
    None
} else {
    Some("raw Ethernet (an AF_PACKET socket) needs Linux; serve the EtherCAT slaves from a Linux machine")
};

/// Refuses the links this system cannot serve, before anything is opened.
pub(crate) fn check_serve(args: &ServeArgs) -> Result<(), String> {
    let refuse = |option: String, why: Option<&str>| why.map_or(Ok(()), |why| Err(format!("{option}: {why}")));
    if let Some(path) = &args.pty {
        refuse(format!("--pty {}", path.display()), PTY_REFUSED)?;
    }
    if let Some(path) = &args.slcan {
        refuse(format!("--slcan {}", path.display()), SLCAN_REFUSED)?;
    }
    if let Some(iface) = &args.ethercat {
        refuse(format!("--ethercat {iface}"), ETHERCAT_REFUSED)?;
    }
    Ok(())
}

/// A command whose output goes to a reader that stops early ends quietly,
/// as other tools do: SIGPIPE back to its default (Rust ignores it).
/// Windows has no SIGPIPE.
///
/// Called before any other thread exists.
pub(crate) fn default_sigpipe() {
    #[cfg(unix)]
    // SAFETY: called before any other thread exists.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

/// Makes `command` a child that [`stop`] can end cleanly: on Windows a
/// process group of its own, to which Ctrl-Break goes (and the parent's
/// Ctrl-C does not). Nothing on Unix.
pub(crate) fn stoppable(command: &mut Command) -> &mut Command {
    #[cfg(windows)]
    {
        use std::os::windows::process::CommandExt;
        command.creation_flags(windows_sys::Win32::System::Threading::CREATE_NEW_PROCESS_GROUP);
    }
    command
}

/// Asks a child server started with [`stoppable`] to stop as Ctrl-C
/// stops it: SIGTERM on Unix, Ctrl-Break on Windows (killed when that
/// cannot be sent).
pub(crate) fn stop(child: &mut Child) {
    #[cfg(unix)]
    // SAFETY: signalling the child we started.
    unsafe {
        libc::kill(child.id() as i32, libc::SIGTERM);
    }
    #[cfg(windows)]
    {
        use windows_sys::Win32::System::Console::{CTRL_BREAK_EVENT, GenerateConsoleCtrlEvent};
        // SAFETY: a plain call; the group is the child's own.
        if unsafe { GenerateConsoleCtrlEvent(CTRL_BREAK_EVENT, child.id()) } == 0 {
            let _ = child.kill();
        }
    }
}

/// User and system CPU time of a process, from /proc.
#[cfg(unix)]
pub(crate) fn process_cpu(pid: u32) -> Result<(Duration, Duration), String> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).map_err(|e| e.to_string())?;
    let after = stat.rsplit_once(')').ok_or("bad /proc stat")?.1;
    let fields: Vec<&str> = after.split_whitespace().collect();
    let field = |i: usize| fields[i].parse::<u64>().map_err(|e| e.to_string());
    // SAFETY: sysconf has no preconditions.
    let hz = unsafe { libc::sysconf(libc::_SC_CLK_TCK) }.max(1) as u64;
    let time = |ticks: u64| Duration::from_nanos(ticks * 1_000_000_000 / hz);
    Ok((time(field(11)?), time(field(12)?)))
}

/// User and system CPU time of a process (GetProcessTimes).
#[cfg(windows)]
pub(crate) fn process_cpu(pid: u32) -> Result<(Duration, Duration), String> {
    use windows_sys::Win32::Foundation::CloseHandle;
    use windows_sys::Win32::System::Threading::{OpenProcess, PROCESS_QUERY_LIMITED_INFORMATION};
    // SAFETY: opens a handle that is closed below.
    let process = unsafe { OpenProcess(PROCESS_QUERY_LIMITED_INFORMATION, 0, pid) };
    if process.is_null() {
        return Err(format!("process {pid}: {}", std::io::Error::last_os_error()));
    }
    let times = windows::times(process);
    // SAFETY: the handle opened above.
    unsafe { CloseHandle(process) };
    times
}

/// User plus system CPU time of this process, to the microsecond.
#[cfg(unix)]
pub(crate) fn self_cpu() -> Duration {
    // SAFETY: getrusage writes into the struct we pass.
    let usage = unsafe {
        let mut u: libc::rusage = std::mem::zeroed();
        libc::getrusage(libc::RUSAGE_SELF, &mut u);
        u
    };
    let tv = |t: libc::timeval| Duration::from_secs(t.tv_sec as u64) + Duration::from_micros(t.tv_usec as u64);
    tv(usage.ru_utime) + tv(usage.ru_stime)
}

/// User plus system CPU time of this process (GetProcessTimes).
#[cfg(windows)]
pub(crate) fn self_cpu() -> Duration {
    // SAFETY: the pseudo handle of this process needs no closing.
    let process = unsafe { windows_sys::Win32::System::Threading::GetCurrentProcess() };
    windows::times(process).map_or(Duration::ZERO, |(user, system)| user + system)
}

/// The resident memory of a process in KiB, where the system tells it.
#[cfg(unix)]
pub(crate) fn resident_kib(pid: u32) -> Option<u64> {
    std::fs::read_to_string(format!("/proc/{pid}/status"))
        .ok()
        .and_then(|s| s.lines().find(|l| l.starts_with("VmRSS:")).and_then(|l| l.split_whitespace().nth(1)?.parse::<u64>().ok()))
}

/// The working set of a process in KiB (GetProcessMemoryInfo).
#[cfg(windows)]
pub(crate) fn resident_kib(pid: u32) -> Option<u64> {
    use windows_sys::Win32::Foundation::CloseHandle;
    use windows_sys::Win32::System::ProcessStatus::{K32GetProcessMemoryInfo, PROCESS_MEMORY_COUNTERS};
    use windows_sys::Win32::System::Threading::{OpenProcess, PROCESS_QUERY_LIMITED_INFORMATION};
    // SAFETY: opens a handle that is closed below; the counters are
    // plain data, written by the call with the size given.
    unsafe {
        let process = OpenProcess(PROCESS_QUERY_LIMITED_INFORMATION, 0, pid);
        if process.is_null() {
            return None;
        }
        let mut counters: PROCESS_MEMORY_COUNTERS = std::mem::zeroed();
        let size = std::mem::size_of::<PROCESS_MEMORY_COUNTERS>() as u32;
        let ok = K32GetProcessMemoryInfo(process, &mut counters, size) != 0;
        CloseHandle(process);
        ok.then_some(counters.WorkingSetSize as u64 / 1024)
    }
}

#[cfg(windows)]
mod windows {
    use std::time::Duration;
    use windows_sys::Win32::Foundation::{FILETIME, HANDLE};

    /// User and system CPU time of a process handle.
    pub(super) fn times(process: HANDLE) -> Result<(Duration, Duration), String> {
        let zero = FILETIME { dwLowDateTime: 0, dwHighDateTime: 0 };
        let (mut created, mut exited, mut kernel, mut user) = (zero, zero, zero, zero);
        // SAFETY: a valid process handle and four FILETIMEs to write.
        let ok =
            unsafe { windows_sys::Win32::System::Threading::GetProcessTimes(process, &mut created, &mut exited, &mut kernel, &mut user) };
        if ok == 0 {
            return Err(std::io::Error::last_os_error().to_string());
        }
        // FILETIME counts 100 ns.
        let time = |t: FILETIME| Duration::from_nanos(((u64::from(t.dwHighDateTime) << 32) | u64::from(t.dwLowDateTime)) * 100);
        Ok((time(user), time(kernel)))
    }
}
