//! EEPROM files: a module's EEPROM image ([`Eeprom`]) kept in a JSON file
//! across runs (`--eeprom FILE`, `Module(eeprom=…)`).
//!
//! [`EepromFile`] is an EEPROM file in use: locked for as long as it is
//! held, so that one tmclsim at a time writes it, and saved so that a
//! process killed at any moment leaves either the old or the new file,
//! never a torn one (a new temporary file beside it, synced, renamed over
//! the file, the directory synced). A file its owner may not write is
//! never replaced (docs/behaviour.md rule 89). The image itself, its JSON
//! text and the check against a module are the firmware's
//! (`tmclsim_firmware::eeprom`, `tmclsim_firmware::eeprom_rules`).

#[cfg(unix)]
use std::fs::Permissions;
use std::fs::{File, OpenOptions};
use std::io::{Read, Write};
#[cfg(unix)]
use std::os::unix::fs::{OpenOptionsExt, PermissionsExt};
#[cfg(windows)]
use std::os::windows::fs::OpenOptionsExt;
use std::path::{Path, PathBuf};
use tmclsim_firmware::{Eeprom, Profile};

/// The largest EEPROM file read (1 MiB). The image of the largest module
/// with every cell and every program word written (a TMCM-351: 3 axes,
/// 2048 words) takes about a quarter of it.
pub const MAX_FILE_BYTES: u64 = 1 << 20;

/// Loads an EEPROM file; `Ok(None)` when it does not exist yet (and only
/// then: any other error reading it is reported, docs/behaviour.md rule
/// 89). A file that is not a regular file (a device, a pipe) or is larger
/// than [`MAX_FILE_BYTES`] is refused without being read. The cells are not
/// checked against a module ([`load_for`] does).
pub fn load(path: &Path) -> Result<Option<Eeprom>, LoadError> {
    let shown = path.display();
    match read_limited(path) {
        Ok(Some(text)) => Eeprom::from_json(&text).map(Some).map_err(|e| LoadError::Refused(format!("{shown}: {e}"))),
        Ok(None) => Ok(None),
        Err(LoadError::Unreadable(e)) => Err(LoadError::Unreadable(format!("{shown}: cannot read the EEPROM file: {e}"))),
        Err(LoadError::Refused(e)) => Err(LoadError::Refused(format!("{shown}: {e}"))),
    }
}

/// Why an EEPROM file is not loaded. Both carry the message, the file
/// named first.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum LoadError {
    /// The file could not be read: an error of the system other than
    /// "there is no such file" (no permission, a path through something
    /// that is no directory, an I/O error).
    Unreadable(String),
    /// The file was read and is refused: not an EEPROM file, too large, not
    /// a regular file, another module's, or holding what the module never
    /// stores (docs/behaviour.md rule 88).
    Refused(String),
}

impl LoadError {
    /// The message for the user, whichever kind of failure.
    pub fn message(&self) -> &str {
        match self {
            LoadError::Unreadable(m) | LoadError::Refused(m) => m,
        }
    }
}

impl std::fmt::Display for LoadError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.message())
    }
}

impl std::error::Error for LoadError {}

impl From<LoadError> for String {
    fn from(e: LoadError) -> String {
        e.message().to_string()
    }
}

/// Why an EEPROM file cannot be taken; the text starts with its path as
/// named.
#[derive(Debug)]
pub struct OpenError {
    /// The path as named.
    pub path: PathBuf,
    /// What went wrong.
    pub problem: OpenProblem,
}

/// What went wrong taking an EEPROM file.
#[derive(Debug)]
pub enum OpenProblem {
    /// The path cannot be followed to a file.
    Path(std::io::Error),
    /// The file is there and cannot be looked at.
    Unreadable(std::io::Error),
    /// The lock file cannot be opened or locked.
    CannotLock {
        /// The lock file.
        lock: PathBuf,
        /// Why.
        error: std::io::Error,
    },
    /// There is no lock file and none may be made.
    CannotCreateLock {
        /// The lock file.
        lock: PathBuf,
        /// Why it cannot be made.
        error: std::io::Error,
    },
    /// Another process holds the lock.
    InUse {
        /// The lock file.
        lock: PathBuf,
        /// The holder's process id, when the lock file tells it.
        pid: Option<u32>,
    },
}

impl std::fmt::Display for OpenError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let shown = self.path.display();
        match &self.problem {
            OpenProblem::Path(e) => write!(f, "{shown}: {e}"),
            OpenProblem::Unreadable(e) => write!(f, "{shown}: cannot read the EEPROM file: {e}"),
            OpenProblem::CannotLock { lock, error } => {
                write!(f, "{shown}: cannot lock the EEPROM file ({}): {error}", lock.display())
            }
            OpenProblem::CannotCreateLock { lock, error } => write!(
                f,
                "{shown}: cannot lock the EEPROM file: cannot create {}: {error}; tmclsim needs to write in the EEPROM \
                 file's directory (its lock file is there, and every save puts a new file there)",
                lock.display()
            ),
            OpenProblem::InUse { lock, pid } => {
                let pid = pid.map_or(String::new(), |p| format!(" (pid {p})"));
                write!(
                    f,
                    "{shown}: the EEPROM file is in use by another tmclsim{pid}; one module at a time keeps an EEPROM file \
                     (lock: {})",
                    lock.display()
                )
            }
        }
    }
}

impl std::error::Error for OpenError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match &self.problem {
            OpenProblem::Path(e) | OpenProblem::Unreadable(e) => Some(e),
            OpenProblem::CannotLock { error, .. } | OpenProblem::CannotCreateLock { error, .. } => Some(error),
            OpenProblem::InUse { .. } => None,
        }
    }
}

impl From<OpenError> for String {
    fn from(e: OpenError) -> String {
        e.to_string()
    }
}

/// The text of an EEPROM file (`None`: there is none), within the limits.
/// The errors name no file.
fn read_limited(path: &Path) -> Result<Option<String>, LoadError> {
    let refused = LoadError::Refused;
    let unreadable = |e: std::io::Error| LoadError::Unreadable(e.to_string());
    let regular = |m: &std::fs::Metadata| -> Result<(), LoadError> {
        if !m.is_file() {
            return Err(refused("not a regular file (an EEPROM file is a JSON file tmclsim writes)".into()));
        }
        if m.len() > MAX_FILE_BYTES {
            return Err(refused(format!("{} bytes, more than an EEPROM file can be ({MAX_FILE_BYTES} bytes)", m.len())));
        }
        Ok(())
    };
    // Looked at before opening: opening a pipe would wait for a writer.
    match std::fs::metadata(path) {
        Ok(m) => regular(&m)?,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(unreadable(e)),
    }
    let file = match File::open(path) {
        Ok(f) => f,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(unreadable(e)),
    };
    regular(&file.metadata().map_err(unreadable)?)?;
    let mut bytes = Vec::new();
    file.take(MAX_FILE_BYTES + 1).read_to_end(&mut bytes).map_err(unreadable)?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(refused(format!("grew beyond {MAX_FILE_BYTES} bytes while being read")));
    }
    String::from_utf8(bytes).map(Some).map_err(|_| refused("EEPROM file is not readable: not UTF-8 text".into()))
}

/// The EEPROM a module of `profile` powers up with from `path`: the
/// stored image (`true`), or an empty one when the file does not exist
/// yet (`false`). A file of another module, or one holding what the
/// module never stores (docs/behaviour.md rule 88), is refused, naming
/// the entries.
pub fn load_for(path: &Path, profile: &Profile) -> Result<(Eeprom, bool), LoadError> {
    match load(path)? {
        Some(image) => match image.check(profile) {
            Ok(()) => Ok((image, true)),
            Err(e) => Err(LoadError::Refused(format!("{}: {e}", path.display()))),
        },
        None => Ok((Eeprom::new(&profile.module.name), false)),
    }
}

/// Why the file at `path` is read-only for tmclsim, which then never
/// replaces it (docs/behaviour.md rule 89): its owner may not write it
/// (no `u+w` in its mode; this holds for every user, root included, who
/// may write any file), or this process may not (access(2): another
/// user's file, a read-only file system). `None`: no such file, or one
/// tmclsim may replace.
#[cfg(unix)]
pub fn read_only(path: &Path) -> Option<String> {
    let meta = std::fs::metadata(path).ok().filter(std::fs::Metadata::is_file)?;
    let mode = meta.permissions().mode() & 0o7777;
    if mode & 0o200 == 0 {
        return Some(format!("the file is read-only (mode {mode:04o}: no write permission for its owner)"));
    }
    let c = std::ffi::CString::new(path.as_os_str().as_encoded_bytes()).ok()?;
    // SAFETY: a valid, NUL-terminated path.
    if unsafe { libc::access(c.as_ptr(), libc::W_OK) } != 0 {
        let e = std::io::Error::last_os_error();
        return Some(format!("the file is read-only for this user ({e})"));
    }
    None
}

/// Why the file at `path` is read-only for tmclsim, which then never
/// replaces it (docs/behaviour.md rule 89): its read-only attribute is set
/// (what Windows has for the owner's missing `u+w`), or this process may
/// not open it for writing (the file's access control list, a read-only
/// share). `None`: no such file, or one tmclsim may replace.
#[cfg(windows)]
pub fn read_only(path: &Path) -> Option<String> {
    let meta = std::fs::metadata(path).ok().filter(std::fs::Metadata::is_file)?;
    if meta.permissions().readonly() {
        return Some("the file is read-only (its read-only attribute is set)".into());
    }
    // Opening for writing changes nothing (no truncation, no creation).
    match OpenOptions::new().write(true).open(path) {
        Err(e) if e.kind() == std::io::ErrorKind::PermissionDenied => Some(format!("the file is read-only for this user ({e})")),
        _ => None,
    }
}

/// Writes the image to `path` atomically (a symbolic link is followed: its
/// target is written, the link stays). Takes no lock: a file in use is
/// saved with [`EepromFile::save`].
pub fn save_atomic(path: &Path, image: &Eeprom) -> std::io::Result<()> {
    write_atomic(&resolve(path)?, image)
}

/// The file a path names: symbolic links are followed (a link to a link
/// too), so that the target is what is written and locked and the link
/// stays a link. A target that does not exist yet is named as well.
pub fn resolve(path: &Path) -> std::io::Result<PathBuf> {
    let mut p = path.to_path_buf();
    for _ in 0..40 {
        match std::fs::symlink_metadata(&p) {
            Ok(m) if m.file_type().is_symlink() => {
                let target = std::fs::read_link(&p)?;
                p = match p.parent() {
                    Some(dir) if target.is_relative() => dir.join(target),
                    _ => target,
                };
            }
            _ => return Ok(p),
        }
    }
    Err(std::io::Error::other(format!("{}: too many levels of symbolic links", path.display())))
}

/// The directory of a file and its name.
fn dir_and_name(path: &Path) -> std::io::Result<(&Path, String)> {
    let name = path
        .file_name()
        .ok_or_else(|| std::io::Error::new(std::io::ErrorKind::InvalidInput, format!("{} names no file", path.display())))?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    Ok((dir, name.to_string_lossy().into_owned()))
}

/// Temporary files of `name` are `.NAME.XXXXXX.tmp`: a new name each time,
/// created exclusively (nothing that is there already, a symbolic link
/// least of all, is opened).
const TEMP_RANDOM: usize = 6;

fn write_atomic(path: &Path, image: &Eeprom) -> std::io::Result<()> {
    let (dir, name) = dir_and_name(path)?;
    // A rename replaces a file whatever its mode: a read-only file is
    // looked at before every save and left as it is (rule 89).
    if let Some(why) = read_only(path) {
        return Err(std::io::Error::new(std::io::ErrorKind::PermissionDenied, format!("{why}; tmclsim leaves it as it is")));
    }
    let mut builder = tempfile::Builder::new();
    let prefix = format!(".{name}.");
    builder.prefix(&prefix).suffix(".tmp").rand_bytes(TEMP_RANDOM);
    // The file keeps its permissions; a new one gets what a created file
    // gets (0666 less the umask).
    #[cfg(unix)]
    let mode = std::fs::metadata(path).ok().filter(std::fs::Metadata::is_file).map(|m| m.permissions().mode() & 0o7777);
    #[cfg(unix)]
    builder.permissions(Permissions::from_mode(mode.unwrap_or(0o666)));
    // On Windows a file's only permission is its read-only attribute,
    // which a file tmclsim replaces does not have (read_only above): the
    // new file inherits its directory's access control list.
    let mut tmp = builder.tempfile_in(dir)?;
    tmp.write_all(image.to_json().as_bytes())?;
    #[cfg(unix)]
    if let Some(mode) = mode {
        tmp.as_file().set_permissions(Permissions::from_mode(mode))?;
    }
    tmp.as_file().sync_all()?;
    // A rename over the file (MoveFileEx with MOVEFILE_REPLACE_EXISTING
    // on Windows).
    tmp.persist(path).map_err(|e| e.error)?;
    // The rename is durable once the directory is synced; a file system
    // that cannot sync a directory (or a system that cannot open one, as
    // Windows) keeps the new file all the same.
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
    Ok(())
}

/// Opens the lock file `path`, created when `write`: never through a
/// symbolic link, never waiting (on a pipe).
#[cfg(unix)]
fn open_lock(path: &Path, write: bool) -> std::io::Result<File> {
    OpenOptions::new()
        .read(true)
        .write(write)
        .create(write)
        .mode(0o644)
        // Not through a symbolic link, and not waiting on a pipe.
        .custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK | libc::O_CLOEXEC)
        .open(path)
}

/// Opens the lock file `path`, created when `write`: a symbolic link (a
/// reparse point) is opened itself, not followed, and then refused as no
/// regular file. Windows has no pipes in the file system to wait on, and
/// its handles are not inherited unless asked for.
#[cfg(windows)]
fn open_lock(path: &Path, write: bool) -> std::io::Result<File> {
    /// FILE_FLAG_OPEN_REPARSE_POINT (winbase.h).
    const OPEN_REPARSE_POINT: u32 = 0x0020_0000;
    OpenOptions::new().read(true).write(write).create(write).custom_flags(OPEN_REPARSE_POINT).open(path)
}

/// An EEPROM file in use: the file a path names (symbolic links followed)
/// and an exclusive lock on it, held until the value is dropped. A second
/// holder, in this process or another, is refused.
///
/// The lock is taken on `.NAME.lock` beside the file, which is never
/// replaced (the file itself is, by every save); it holds the process id
/// of its holder.
#[derive(Debug)]
pub struct EepromFile {
    /// The path as named.
    named: PathBuf,
    /// The file written.
    path: PathBuf,
    _lock: File,
}

impl EepromFile {
    /// Takes the EEPROM file at `path` for this process.
    pub fn open(path: &Path) -> Result<EepromFile, OpenError> {
        let error = |problem| OpenError { path: path.to_path_buf(), problem };
        let target = resolve(path).map_err(|e| error(OpenProblem::Path(e)))?;
        // The file first: when it cannot be looked at, that is the error
        // to report (the lock beside it would fail too, and say less).
        // Only a file that does not exist yet is fine (rule 89).
        if let Err(e) = std::fs::metadata(&target)
            && e.kind() != std::io::ErrorKind::NotFound
        {
            return Err(error(OpenProblem::Unreadable(e)));
        }
        let (dir, name) = dir_and_name(&target).map_err(|e| error(OpenProblem::Path(e)))?;
        let lock_path = dir.join(format!(".{name}.lock"));
        let cannot = |e: std::io::Error| error(OpenProblem::CannotLock { lock: lock_path.clone(), error: e });
        let open = |write: bool| open_lock(&lock_path, write);
        let (mut lock, writable) = match open(true) {
            Ok(f) => (f, true),
            // Another user's lock file can still be locked.
            Err(e) if e.kind() == std::io::ErrorKind::PermissionDenied => match open(false) {
                Ok(f) => (f, false),
                // There is none, and none may be made here: say why.
                Err(none) if none.kind() == std::io::ErrorKind::NotFound => {
                    return Err(error(OpenProblem::CannotCreateLock { lock: lock_path.clone(), error: e }));
                }
                Err(other) => return Err(cannot(other)),
            },
            Err(e) => return Err(cannot(e)),
        };
        if !lock.metadata().map_err(cannot)?.is_file() {
            return Err(cannot(std::io::Error::other("not a regular file")));
        }
        match lock.try_lock() {
            Ok(()) => {}
            Err(std::fs::TryLockError::WouldBlock) => {
                let mut holder = String::new();
                let _ = (&lock).take(32).read_to_string(&mut holder);
                let pid = holder.trim().parse::<u32>().ok();
                return Err(error(OpenProblem::InUse { lock: lock_path.clone(), pid }));
            }
            Err(std::fs::TryLockError::Error(e)) => return Err(cannot(e)),
        }
        if writable {
            let _ = lock.set_len(0).and_then(|_| writeln!(lock, "{}", std::process::id()));
        }
        remove_stale_temporaries(dir, &name);
        Ok(EepromFile { named: path.to_path_buf(), path: target, _lock: lock })
    }

    /// The path as it was named.
    pub fn named(&self) -> &Path {
        &self.named
    }

    /// The file written (the target of a symbolic link).
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The EEPROM a module of `profile` powers up with (see
    /// [`load_for`]).
    pub fn load_for(&self, profile: &Profile) -> Result<(Eeprom, bool), LoadError> {
        load_for(&self.path, profile)
    }

    /// Why the file is read-only (see [`read_only`]): every save then
    /// fails and leaves it as it is. Looked at anew on every call.
    pub fn read_only(&self) -> Option<String> {
        read_only(&self.path)
    }

    /// Writes the image to the file atomically; a read-only file is not
    /// replaced (an error of kind `PermissionDenied`).
    pub fn save(&self, image: &Eeprom) -> std::io::Result<()> {
        write_atomic(&self.path, image)
    }
}

/// Temporary files a killed process left beside `name` (its lock is held
/// now, so nobody is writing them).
fn remove_stale_temporaries(dir: &Path, name: &str) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    let prefix = format!(".{name}.");
    for entry in entries.flatten() {
        let file = entry.file_name();
        let Some(middle) = file.to_str().and_then(|f| f.strip_prefix(&prefix)).and_then(|f| f.strip_suffix(".tmp")) else {
            continue;
        };
        if middle.len() == TEMP_RANDOM && entry.file_type().is_ok_and(|t| t.is_file()) {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    // Symbolic links on Windows need a privilege or developer mode: the
    // tests of links are Unix's.
    #[cfg(unix)]
    use std::os::unix::fs::symlink;

    fn tmcm_1141() -> std::sync::Arc<Profile> {
        Profile::built_in("tmcm-1141").unwrap()
    }

    fn image() -> Eeprom {
        let mut e = Eeprom::new("TMCM-1141");
        e.set_axis(0, 4, 1234);
        e.set_global(2, 7, -5);
        e.set_coordinate(0, 3, 99);
        e.program.insert(0, [2, 0, 0, 0, 0, 3, 0xE8]);
        e
    }

    #[test]
    fn round_trip_through_a_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.eeprom");
        assert_eq!(load(&path).unwrap(), None);
        let e = image();
        save_atomic(&path, &e).unwrap();
        assert_eq!(load(&path).unwrap(), Some(e));
        std::fs::write(&path, "{ torn").unwrap();
        assert!(load(&path).unwrap_err().message().contains("not readable"));
    }

    #[test]
    #[cfg(unix)]
    fn a_symlink_at_the_old_temporary_name_is_not_followed() {
        let dir = tempfile::tempdir().unwrap();
        let victim = dir.path().join("victim");
        std::fs::write(&victim, "precious").unwrap();
        let trap = dir.path().join(".m.eeprom.tmp");
        symlink(&victim, &trap).unwrap();
        let file = EepromFile::open(&dir.path().join("m.eeprom")).unwrap();
        file.save(&image()).unwrap();
        save_atomic(&dir.path().join("m.eeprom"), &image()).unwrap();
        assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious");
        assert!(std::fs::symlink_metadata(&trap).unwrap().file_type().is_symlink());
        assert_eq!(load(&dir.path().join("m.eeprom")).unwrap(), Some(image()));
        // Nothing is left behind but the file, its lock and the trap.
        let mut names: Vec<String> =
            std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        names.sort();
        assert_eq!(names, [".m.eeprom.lock", ".m.eeprom.tmp", "m.eeprom", "victim"]);
    }

    #[test]
    #[cfg(unix)]
    fn a_symlinked_file_writes_its_target_and_stays_a_link() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("store")).unwrap();
        let target = dir.path().join("store/real.eeprom");
        // Relative, through a second link, to a target that does not exist yet.
        symlink("store/real.eeprom", dir.path().join("hop")).unwrap();
        let link = dir.path().join("m.eeprom");
        symlink("hop", &link).unwrap();
        let file = EepromFile::open(&link).unwrap();
        assert_eq!(file.path(), dir.path().join("store/real.eeprom"));
        assert_eq!(file.named(), link);
        assert_eq!(file.load_for(&tmcm_1141()).unwrap(), (Eeprom::new("TMCM-1141"), false));
        file.save(&image()).unwrap();
        assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
        assert_eq!(load(&target).unwrap(), Some(image()));
        assert_eq!(file.load_for(&tmcm_1141()).unwrap(), (image(), true));
        // The lock is beside the target: the target named directly is taken.
        let e = EepromFile::open(&target).unwrap_err().to_string();
        assert!(e.contains("in use by another tmclsim"), "{e}");
        assert!(dir.path().join("store/.real.eeprom.lock").exists());
        drop(file);
        // save_atomic follows the link as well.
        let mut other = image();
        other.set_axis(0, 5, 7);
        save_atomic(&link, &other).unwrap();
        assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
        assert_eq!(load(&target).unwrap(), Some(other));
    }

    #[test]
    fn a_file_in_use_is_refused_to_a_second_holder_naming_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.eeprom");
        let first = EepromFile::open(&path).unwrap();
        let e = EepromFile::open(&path).unwrap_err().to_string();
        assert!(e.starts_with(&format!("{}: ", path.display())), "{e}");
        let holder = format!("in use by another tmclsim (pid {})", std::process::id());
        // Windows' locks are mandatory: the holder's pid in the locked file
        // cannot be read there (Wine reads it), and the message names none.
        assert!(e.contains(&holder) || (cfg!(windows) && e.contains("in use by another tmclsim; ")), "{e}");
        drop(first);
        let again = EepromFile::open(&path).unwrap();
        again.save(&image()).unwrap();
        assert_eq!(again.load_for(&tmcm_1141()).unwrap(), (image(), true));
    }

    #[test]
    #[cfg(unix)]
    fn a_symlink_at_the_lock_name_is_not_followed() {
        let dir = tempfile::tempdir().unwrap();
        let victim = dir.path().join("victim");
        std::fs::write(&victim, "precious").unwrap();
        symlink(&victim, dir.path().join(".m.eeprom.lock")).unwrap();
        let e = EepromFile::open(&dir.path().join("m.eeprom")).unwrap_err().to_string();
        assert!(e.contains("cannot lock the EEPROM file"), "{e}");
        assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious");
    }

    #[test]
    fn temporaries_of_a_killed_writer_are_removed_when_the_file_is_taken() {
        let dir = tempfile::tempdir().unwrap();
        let stale = dir.path().join(".m.eeprom.a1B2c3.tmp");
        std::fs::write(&stale, "half").unwrap();
        let unrelated = [".m.eeprom.tmp", ".m.eeprom.toolong.tmp", ".n.eeprom.a1B2c3.tmp"];
        for u in unrelated {
            std::fs::write(dir.path().join(u), "keep").unwrap();
        }
        let _file = EepromFile::open(&dir.path().join("m.eeprom")).unwrap();
        assert!(!stale.exists());
        for u in unrelated {
            assert!(dir.path().join(u).exists(), "{u}");
        }
    }

    #[test]
    #[cfg(unix)]
    fn a_save_keeps_the_files_permissions() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.eeprom");
        save_atomic(&path, &image()).unwrap();
        std::fs::set_permissions(&path, Permissions::from_mode(0o640)).unwrap();
        save_atomic(&path, &Eeprom::new("TMCM-1141")).unwrap();
        assert_eq!(std::fs::metadata(&path).unwrap().permissions().mode() & 0o7777, 0o640);
    }

    #[test]
    fn oversized_and_non_regular_files_are_refused_unread() {
        let dir = tempfile::tempdir().unwrap();
        let big = dir.path().join("big.eeprom");
        let f = File::create(&big).unwrap();
        f.set_len(MAX_FILE_BYTES + 1).unwrap();
        let e = load(&big).unwrap_err().to_string();
        assert!(e.contains(&format!("{} bytes, more than an EEPROM file can be ({MAX_FILE_BYTES} bytes)", MAX_FILE_BYTES + 1)), "{e}");
        f.set_len(MAX_FILE_BYTES).unwrap();
        assert!(load(&big).unwrap_err().message().contains("not readable"));
        drop(f);
        assert!(load(dir.path()).unwrap_err().message().contains("not a regular file"));
    }

    #[test]
    #[cfg(unix)]
    fn devices_and_pipes_are_refused_unread() {
        let dir = tempfile::tempdir().unwrap();
        let e = load(Path::new("/dev/zero")).unwrap_err().to_string();
        assert!(e.contains("/dev/zero: not a regular file"), "{e}");
        let fifo = dir.path().join("fifo");
        let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
        // SAFETY: a valid, NUL-terminated path.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        // Refused at once, not waiting for a writer.
        assert!(load_for(&fifo, &tmcm_1141()).unwrap_err().message().contains("not a regular file"));
    }

    #[test]
    fn a_read_only_file_is_never_replaced() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.eeprom");
        assert_eq!(read_only(&path), None);
        save_atomic(&path, &image()).unwrap();
        assert_eq!(read_only(&path), None);
        let mut permissions = std::fs::metadata(&path).unwrap().permissions();
        permissions.set_readonly(true);
        std::fs::set_permissions(&path, permissions.clone()).unwrap();
        let why = read_only(&path).unwrap();
        assert!(why.starts_with("the file is read-only"), "{why}");
        let file = EepromFile::open(&path).unwrap();
        let e = file.save(&Eeprom::new("TMCM-1141")).unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::PermissionDenied);
        assert!(e.to_string().contains("tmclsim leaves it as it is"), "{e}");
        assert_eq!(load(&path).unwrap(), Some(image()));
        // Writable again, so that the directory can be removed everywhere.
        #[allow(clippy::permissions_set_readonly_false)]
        permissions.set_readonly(false);
        std::fs::set_permissions(&path, permissions).unwrap();
        file.save(&Eeprom::new("TMCM-1141")).unwrap();
    }

    #[test]
    fn the_fullest_image_of_the_largest_module_is_well_within_the_limit() {
        let mut e = Eeprom::new("TMCM-351");
        for motor in 0..3 {
            for p in 0..=255 {
                e.set_axis(motor, p, i32::MIN);
            }
            for n in 0..=20 {
                e.set_coordinate(motor, n, i32::MIN);
            }
        }
        for bank in 0..4 {
            for p in 0..=255 {
                e.set_global(bank, p, i32::MIN);
            }
        }
        for a in 0..2048 {
            e.program.insert(a, [255; 7]);
        }
        let len = e.to_json().len() as u64;
        assert!(len * 3 < MAX_FILE_BYTES, "{len}");
        let dir = tempfile::tempdir().unwrap();
        save_atomic(&dir.path().join("m.eeprom"), &e).unwrap();
        assert_eq!(load(&dir.path().join("m.eeprom")).unwrap(), Some(e));
    }
}
