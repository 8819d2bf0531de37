//! Reading the files a user hands tmclsim (world files, fleet files,
//! program binaries, symbol files) with a size limit: a file larger than
//! its limit, or one that never ends (`/dev/zero`), is refused with a
//! message instead of being read into memory (docs/robustness.md lists
//! the limits). The firmware parses what is read here and reads nothing
//! itself.

use std::io::Read;
use std::path::{Path, PathBuf};
use tmclsim_firmware::World;

/// Configuration files: world, fleet and symbol files.
pub const MAX_CONFIG_BYTES: u64 = 1 << 20;
/// Program binaries (8 bytes per instruction; far more than any module's
/// program memory).
pub const MAX_BINARY_BYTES: u64 = 1 << 20;

/// Why a file was not read; the text starts with the file's path.
#[derive(Debug)]
pub struct FileError {
    /// The file.
    pub path: PathBuf,
    /// What went wrong.
    pub problem: FileProblem,
}

/// What went wrong reading a file.
#[derive(Debug)]
pub enum FileProblem {
    /// It cannot be opened or read.
    Io(std::io::Error),
    /// It is larger than its limit.
    TooLarge {
        /// The limit in bytes.
        limit: u64,
        /// The kind of file (`a world file`).
        what: String,
    },
    /// A text file that is not UTF-8.
    NotText(std::string::FromUtf8Error),
}

impl std::fmt::Display for FileError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let path = self.path.display();
        match &self.problem {
            FileProblem::Io(e) => write!(f, "{path}: {e}"),
            FileProblem::TooLarge { limit, what } => write!(f, "{path}: larger than {}, the limit for {what}", size_text(*limit)),
            FileProblem::NotText(e) => write!(f, "{path}: not UTF-8 text ({e})"),
        }
    }
}

impl std::error::Error for FileError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match &self.problem {
            FileProblem::Io(e) => Some(e),
            FileProblem::TooLarge { .. } => None,
            FileProblem::NotText(e) => Some(e),
        }
    }
}

impl From<FileError> for String {
    fn from(e: FileError) -> String {
        e.to_string()
    }
}

/// Why a world was not found or not read.
#[derive(Debug)]
pub enum WorldError {
    /// The name is no built-in world and no file.
    NoSuchFile(String),
    /// The world file cannot be read.
    File(FileError),
    /// The world's TOML is wrong (the file, when read from one).
    Invalid {
        /// The world file, if the world came from one.
        path: Option<PathBuf>,
        /// What is wrong, as the firmware says it.
        message: String,
    },
}

impl WorldError {
    fn invalid(path: Option<&Path>, e: impl std::fmt::Display) -> WorldError {
        WorldError::Invalid { path: path.map(Path::to_path_buf), message: e.to_string() }
    }
}

impl std::fmt::Display for WorldError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            WorldError::NoSuchFile(path) => {
                write!(f, "{path}: no such world file; the built-in worlds are stage (the default) and free")
            }
            WorldError::File(e) => write!(f, "{e}"),
            WorldError::Invalid { path: Some(path), message } => write!(f, "{}: {message}", path.display()),
            WorldError::Invalid { path: None, message } => write!(f, "{message}"),
        }
    }
}

impl std::error::Error for WorldError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            WorldError::File(e) => Some(e),
            WorldError::NoSuchFile(_) | WorldError::Invalid { .. } => None,
        }
    }
}

impl From<WorldError> for String {
    fn from(e: WorldError) -> String {
        e.to_string()
    }
}

/// Reads at most `limit` bytes of a file; `what` names the kind of file in
/// the message when it is larger.
pub fn read_limited(path: &Path, limit: u64, what: &str) -> Result<Vec<u8>, FileError> {
    let error = |problem| FileError { path: path.to_path_buf(), problem };
    let file = std::fs::File::open(path).map_err(|e| error(FileProblem::Io(e)))?;
    let mut bytes = Vec::new();
    file.take(limit + 1).read_to_end(&mut bytes).map_err(|e| error(FileProblem::Io(e)))?;
    if bytes.len() as u64 > limit {
        return Err(error(FileProblem::TooLarge { limit, what: what.to_string() }));
    }
    Ok(bytes)
}

/// [`read_limited`] for a text file (UTF-8).
pub fn read_text_limited(path: &Path, limit: u64, what: &str) -> Result<String, FileError> {
    let bytes = read_limited(path, limit, what)?;
    String::from_utf8(bytes).map_err(|e| FileError { path: path.to_path_buf(), problem: FileProblem::NotText(e) })
}

/// The world a front end names: `stage` (the built-in linear stage),
/// `free` (no switches, no end stops), TOML text (anything with a line
/// break) or the path of a TOML file.
pub fn world_named(spec: &str, axes: usize) -> Result<World, WorldError> {
    if let Some(world) = World::built_in(spec, axes) {
        return Ok(world);
    }
    match spec {
        text if text.contains('\n') => World::from_toml(text, axes).map_err(|e| WorldError::invalid(None, e)),
        path if !Path::new(path).exists() => Err(WorldError::NoSuchFile(path.to_string())),
        path => load_world(Path::new(path), axes),
    }
}

/// Reads a world file (at most [`MAX_CONFIG_BYTES`]) for a module with
/// `axes` axes; the errors name the file.
pub fn load_world(path: &Path, axes: usize) -> Result<World, WorldError> {
    let text = read_text_limited(path, MAX_CONFIG_BYTES, "a world file").map_err(WorldError::File)?;
    World::from_toml(&text, axes).map_err(|e| WorldError::invalid(Some(path), e))
}

/// A byte count for messages: "1 MiB", "512 KiB", "100 bytes".
pub fn size_text(bytes: u64) -> String {
    if bytes >= 1 << 20 && bytes.is_multiple_of(1 << 20) {
        format!("{} MiB", bytes >> 20)
    } else if bytes >= 1 << 10 && bytes.is_multiple_of(1 << 10) {
        format!("{} KiB", bytes >> 10)
    } else {
        format!("{bytes} bytes")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_within_its_limit_is_read_whole() {
        let dir = std::env::temp_dir().join(format!("tmclsim-files-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("w.toml");
        std::fs::write(&path, b"0123456789").unwrap();
        assert_eq!(read_limited(&path, 10, "a test file").unwrap(), b"0123456789");
        let e = read_limited(&path, 9, "a test file").unwrap_err().to_string();
        assert!(e.ends_with("w.toml: larger than 9 bytes, the limit for a test file"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn an_endless_file_is_refused_not_read() {
        let e = read_text_limited(Path::new("/dev/zero"), MAX_CONFIG_BYTES, "a world file").unwrap_err().to_string();
        assert_eq!(e, "/dev/zero: larger than 1 MiB, the limit for a world file");
        assert!(read_limited(Path::new("/nonexistent/x"), 10, "x").unwrap_err().to_string().starts_with("/nonexistent/x: "));
    }

    #[test]
    fn a_world_by_name_text_or_file() {
        assert_eq!(world_named("stage", 1).unwrap(), World::stage(1));
        assert_eq!(world_named("free", 3).unwrap(), World::free(3));
        assert_eq!(world_named("supply = 12.5\n", 1).unwrap().supply_decivolts, 125);
        let e = world_named("/nonexistent/w.toml", 1).unwrap_err().to_string();
        assert_eq!(e, "/nonexistent/w.toml: no such world file; the built-in worlds are stage (the default) and free");
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("w.toml");
        std::fs::write(&path, "supply = 30\n").unwrap();
        assert_eq!(world_named(path.to_str().unwrap(), 1).unwrap().supply_decivolts, 300);
        std::fs::write(&path, "supply = 1000\n").unwrap();
        assert!(load_world(&path, 1).unwrap_err().to_string().starts_with(&format!("{}: ", path.display())));
    }

    #[test]
    fn sizes_read_as_people_write_them() {
        assert_eq!(size_text(1 << 20), "1 MiB");
        assert_eq!(size_text(4096), "4 KiB");
        assert_eq!(size_text(100), "100 bytes");
    }
}
