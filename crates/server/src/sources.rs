//! TMCL source files on disk: the assembler reads no files itself
//! (`tmclsim_asm::assemble` takes text and an [`IncludeResolver`]); this is
//! its file side, used by `tmclsim asm`, `run`, `upload` and the Python
//! package.

use std::io::Read;
use std::path::{Path, PathBuf};
use tmclsim_asm::include::normalize;
use tmclsim_asm::limits::MAX_SOURCE_BYTES;
use tmclsim_asm::{Diagnostic, IncludeError, IncludeResolver, IncludedFile, Profile, Program, assemble};

/// Why a source file was not read.
#[derive(Debug)]
pub enum SourceError {
    /// The file cannot be opened or read.
    Io(std::io::Error),
    /// The file is larger than [`MAX_SOURCE_BYTES`].
    TooLarge,
}

impl std::fmt::Display for SourceError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SourceError::Io(e) => write!(f, "{e}"),
            SourceError::TooLarge => write!(f, "larger than {} MiB, the limit for a source file", MAX_SOURCE_BYTES >> 20),
        }
    }
}

impl std::error::Error for SourceError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            SourceError::Io(e) => Some(e),
            SourceError::TooLarge => None,
        }
    }
}

impl From<SourceError> for String {
    fn from(e: SourceError) -> String {
        e.to_string()
    }
}

/// Reads a source file, at most [`MAX_SOURCE_BYTES`]; the error's text is
/// shown to the user.
pub fn read_source(path: &Path) -> Result<String, SourceError> {
    let file = std::fs::File::open(path).map_err(SourceError::Io)?;
    let mut bytes = Vec::new();
    file.take(MAX_SOURCE_BYTES + 1).read_to_end(&mut bytes).map_err(SourceError::Io)?;
    if bytes.len() as u64 > MAX_SOURCE_BYTES {
        return Err(SourceError::TooLarge);
    }
    Ok(String::from_utf8_lossy(&bytes).into_owned())
}

/// Assembles a file from disk. Includes are found relative to the
/// including file, then among the shipped include files.
pub fn assemble_file(path: impl AsRef<Path>, profile: Option<&Profile>) -> Result<Program, Vec<Diagnostic>> {
    let path = path.as_ref();
    let name = path.display().to_string();
    let text = read_source(path).map_err(|e| vec![Diagnostic::new(name.clone(), 0, 0, format!("cannot read the file: {e}"))])?;
    assemble(&text, &name, &FileResolver::new(), profile)
}

/// Reads included files from disk, relative to the including file, then
/// from extra search directories in order.
#[derive(Clone, Debug, Default)]
pub struct FileResolver {
    /// Directories searched after the including file's own, in order.
    pub search_path: Vec<PathBuf>,
}

impl FileResolver {
    /// A resolver with no extra search directories.
    pub fn new() -> FileResolver {
        FileResolver::default()
    }

    /// Adds a directory searched after the including file's directory.
    pub fn with_search_dir(mut self, dir: impl Into<PathBuf>) -> FileResolver {
        self.search_path.push(dir.into());
        self
    }
}

impl IncludeResolver for FileResolver {
    fn key(&self, file: &str) -> String {
        std::fs::canonicalize(file).map_or_else(|_| file.to_string(), |p| p.to_string_lossy().into_owned())
    }

    fn resolve(&self, from: &str, name: &str) -> Result<IncludedFile, IncludeError> {
        let base = Path::new(from).parent().unwrap_or(Path::new(""));
        let written = Path::new(name);
        let mut candidates = vec![base.join(written)];
        if written.is_relative() {
            candidates.extend(self.search_path.iter().map(|d| d.join(written)));
        }
        for path in &candidates {
            if !path.is_file() {
                continue;
            }
            let text =
                read_source(path).map_err(|e| IncludeError::Unreadable { path: path.display().to_string(), reason: e.to_string() })?;
            let key = std::fs::canonicalize(path).unwrap_or_else(|_| normalize(path));
            return Ok(IncludedFile {
                key: key.to_string_lossy().into_owned(),
                name: normalize(path).to_string_lossy().into_owned(),
                text,
            });
        }
        let looked = candidates.iter().map(|p| p.display().to_string()).collect();
        Err(IncludeError::NotFound { name: name.to_string(), looked })
    }
}
