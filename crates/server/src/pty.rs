//! A pseudo-terminal that host software opens like the module's serial
//! port, behind a stable symlink.
//!
//! The server keeps the slave side open itself, so the pty survives the
//! host closing and reopening the port. The slave is put in raw mode (no
//! echo, no line editing) as a USB/RS485 serial port behaves.
//!
//! A server claims the symlink's path `P` by holding an exclusive lock on
//! `P.lock` for its whole life: a second server refuses a path a live one
//! serves, and replaces a link whose server is gone. The link is removed
//! when the claim ends, but only while it still points to this pty.

use crate::ServerConfig;
use crate::SharedBus;
use std::io;
use std::io::{Read, Write};
use std::os::fd::{AsRawFd, FromRawFd, OwnedFd, RawFd};
use std::os::unix::fs::{MetadataExt, OpenOptionsExt};
use std::path::{Path, PathBuf};
use std::pin::Pin;
use std::sync::Arc;
use std::task::{Context, Poll, ready};
use tokio::io::unix::AsyncFd;
use tokio::io::{AsyncRead, AsyncWrite, ReadBuf};
use tokio::sync::watch;

pub(crate) struct Pty {
    master: OwnedFd,
    /// Held open so the master never sees a hang-up.
    _slave: OwnedFd,
    pub link: PathBuf,
    pub device: PathBuf,
    /// The claim on `link`; whoever holds it removes the link at the end.
    pub claim: Option<LinkClaim>,
}

/// The exclusive lock on `P.lock` that says a live server serves `P`.
struct PathLock {
    path: PathBuf,
    _file: std::fs::File,
}

impl PathLock {
    fn take(link: &Path) -> io::Result<PathLock> {
        let mut path = link.as_os_str().to_owned();
        path.push(".lock");
        let path = PathBuf::from(path);
        loop {
            let mut file = std::fs::OpenOptions::new().read(true).write(true).create(true).truncate(false).mode(0o644).open(&path)?;
            // SAFETY: flock on a descriptor the file owns.
            if unsafe { libc::flock(file.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) } < 0 {
                let e = io::Error::last_os_error();
                if e.raw_os_error() != Some(libc::EWOULDBLOCK) {
                    return Err(e);
                }
                let mut pid = String::new();
                let _ = file.read_to_string(&mut pid);
                return Err(io::Error::new(
                    io::ErrorKind::AddrInUse,
                    format!(
                        "{} is served by a running tmclsim (process {}, lock {}); stop it or choose another path",
                        link.display(),
                        pid.trim(),
                        path.display()
                    ),
                ));
            }
            // The previous owner may have removed the file between our open
            // and our lock: then the lock is on a file nobody else sees.
            let current = std::fs::metadata(&path);
            let ours = file.metadata()?;
            if current.is_ok_and(|c| c.ino() == ours.ino() && c.dev() == ours.dev()) {
                file.set_len(0)?;
                write!(file, "{}", std::process::id())?;
                return Ok(PathLock { path, _file: file });
            }
        }
    }
}

impl Drop for PathLock {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
    }
}

/// A symlink this server created and serves; dropping it removes the link
/// (if it still points to our device) and then the lock.
pub(crate) struct LinkClaim {
    link: PathBuf,
    device: PathBuf,
    _lock: PathLock,
}

impl Drop for LinkClaim {
    fn drop(&mut self) {
        if std::fs::read_link(&self.link).is_ok_and(|target| target == self.device) {
            let _ = std::fs::remove_file(&self.link);
        }
    }
}

fn check(r: libc::c_int) -> io::Result<libc::c_int> {
    if r < 0 { Err(io::Error::last_os_error()) } else { Ok(r) }
}

impl Pty {
    /// Opens a pty and points `link` at its serial device: refused while
    /// another live server serves `link`; a stale link is replaced.
    pub fn open(link: &Path) -> io::Result<Pty> {
        let lock = PathLock::take(link)?;
        // SAFETY: plain libc calls on descriptors this function owns.
        unsafe {
            let master = check(libc::posix_openpt(libc::O_RDWR | libc::O_NOCTTY))?;
            let master = OwnedFd::from_raw_fd(master);
            check(libc::grantpt(master.as_raw_fd()))?;
            check(libc::unlockpt(master.as_raw_fd()))?;
            let mut name = [0 as libc::c_char; 128];
            check(libc::ptsname_r(master.as_raw_fd(), name.as_mut_ptr(), name.len()))?;
            let device = PathBuf::from(std::ffi::CStr::from_ptr(name.as_ptr()).to_string_lossy().into_owned());
            let cpath = std::ffi::CString::new(device.as_os_str().as_encoded_bytes()).map_err(io::Error::other)?;
            let slave = check(libc::open(cpath.as_ptr(), libc::O_RDWR | libc::O_NOCTTY))?;
            let slave = OwnedFd::from_raw_fd(slave);
            let mut tio: libc::termios = std::mem::zeroed();
            check(libc::tcgetattr(slave.as_raw_fd(), &mut tio))?;
            libc::cfmakeraw(&mut tio);
            check(libc::tcsetattr(slave.as_raw_fd(), libc::TCSANOW, &tio))?;
            let flags = check(libc::fcntl(master.as_raw_fd(), libc::F_GETFL))?;
            check(libc::fcntl(master.as_raw_fd(), libc::F_SETFL, flags | libc::O_NONBLOCK))?;
            match std::fs::symlink_metadata(link) {
                Ok(meta) if meta.file_type().is_symlink() => std::fs::remove_file(link)?,
                Ok(_) => {
                    return Err(io::Error::new(
                        io::ErrorKind::AlreadyExists,
                        format!("{} exists and is not a symlink; not replacing it", link.display()),
                    ));
                }
                Err(_) => {}
            }
            std::os::unix::fs::symlink(&device, link)?;
            let claim = LinkClaim { link: link.to_path_buf(), device: device.clone(), _lock: lock };
            Ok(Pty { master, _slave: slave, link: link.to_path_buf(), device, claim: Some(claim) })
        }
    }
}

/// The master side as an async byte stream.
#[derive(Clone)]
pub(crate) struct Master(Arc<AsyncFd<OwnedFd>>);

impl Pty {
    /// The master side as a stream (the slave stays open with the pty).
    pub(crate) fn into_stream(self) -> io::Result<(Master, OwnedFd)> {
        // The server handle took the claim out before: the link lives as
        // long as the handle, not as this task.
        let Pty { master, _slave, .. } = self;
        // SAFETY: the AsyncFd owns the descriptor for its whole life.
        let fd = unsafe { AsyncFd::register(master) }.map_err(|e| e.into_parts().1)?;
        Ok((Master(Arc::new(fd)), _slave))
    }
}

fn raw(fd: &AsyncFd<OwnedFd>) -> RawFd {
    fd.get_ref().as_raw_fd()
}

impl AsyncRead for Master {
    fn poll_read(self: Pin<&mut Self>, cx: &mut Context<'_>, buf: &mut ReadBuf<'_>) -> Poll<io::Result<()>> {
        loop {
            let mut guard = ready!(self.0.poll_read_ready(cx))?;
            let unfilled = buf.initialize_unfilled();
            let result = guard.try_io(|fd| {
                // SAFETY: reading into a buffer we own, of its length.
                let n = unsafe { libc::read(raw(fd), unfilled.as_mut_ptr().cast(), unfilled.len()) };
                if n < 0 { Err(io::Error::last_os_error()) } else { Ok(n as usize) }
            });
            match result {
                Ok(Ok(n)) => {
                    buf.advance(n);
                    return Poll::Ready(Ok(()));
                }
                Ok(Err(e)) => return Poll::Ready(Err(e)),
                Err(_would_block) => continue,
            }
        }
    }
}

impl AsyncWrite for Master {
    fn poll_write(self: Pin<&mut Self>, cx: &mut Context<'_>, data: &[u8]) -> Poll<io::Result<usize>> {
        loop {
            let mut guard = ready!(self.0.poll_write_ready(cx))?;
            let result = guard.try_io(|fd| {
                // SAFETY: writing from a slice we borrow, of its length.
                let n = unsafe { libc::write(raw(fd), data.as_ptr().cast(), data.len()) };
                if n < 0 { Err(io::Error::last_os_error()) } else { Ok(n as usize) }
            });
            match result {
                Ok(r) => return Poll::Ready(r),
                Err(_would_block) => continue,
            }
        }
    }

    fn poll_flush(self: Pin<&mut Self>, _: &mut Context<'_>) -> Poll<io::Result<()>> {
        Poll::Ready(Ok(()))
    }

    fn poll_shutdown(self: Pin<&mut Self>, _: &mut Context<'_>) -> Poll<io::Result<()>> {
        Poll::Ready(Ok(()))
    }
}

pub(crate) async fn run(pty: Pty, bus: Arc<SharedBus>, config: ServerConfig, mut stop: watch::Receiver<bool>) {
    let (master, _slave) = match pty.into_stream() {
        Ok(v) => v,
        Err(e) => {
            eprintln!("tmclsim: pty: {e}");
            return;
        }
    };
    // One line, as on the module's serial port (docs/behaviour.md rule 83).
    let mut lines = Default::default();
    let activity = crate::slots::Activity::new();
    let options = crate::link::Options::local(&config, "pty".into());
    loop {
        let served = crate::link::serve(master.clone(), master.clone(), bus.clone(), &options, &mut lines, &activity);
        tokio::select! {
            r = served => {
                if let Err(e) = r {
                    eprintln!("tmclsim: pty: {e}");
                    tokio::time::sleep(std::time::Duration::from_millis(50)).await;
                }
            }
            _ = stop.changed() => return,
        }
    }
}
