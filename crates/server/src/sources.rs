//! TMCL source files on disk: the assembler reads no files itself
//! (`tmclsim_asm::assemble` takes text and an [`IncludeResolver`]); this is
//! its file side, used by `tmclsim asm`, `run`, `upload` and the Python
//! package.

use std::io::Read;
use std::path::{Path, PathBuf};
use tmclsim_asm::include::normalize;
use tmclsim_asm::limits::MAX_SOURCE_BYTES;
use tmclsim_asm::{Diagnostic, IncludeResolver, IncludedFile, Profile, Program, assemble};

/// Reads a source file, at most [`MAX_SOURCE_BYTES`]; the error is a
/// message for the user.
pub fn read_source(path: &Path) -> Result<String, String> {
    let file = std::fs::File::open(path).map_err(|e| e.to_string())?;
    let mut bytes = Vec::new();
    file.take(MAX_SOURCE_BYTES + 1).read_to_end(&mut bytes).map_err(|e| e.to_string())?;
    if bytes.len() as u64 > MAX_SOURCE_BYTES {
        return Err(format!("larger than {} MiB, the limit for a source file", MAX_SOURCE_BYTES >> 20));
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

    fn resolve(&self, from: &str, name: &str) -> Result<IncludedFile, String> {
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
            let text = read_source(path).map_err(|e| format!("cannot read include file '{}': {e}", path.display()))?;
            let key = std::fs::canonicalize(path).unwrap_or_else(|_| normalize(path));
            return Ok(IncludedFile {
                key: key.to_string_lossy().into_owned(),
                name: normalize(path).to_string_lossy().into_owned(),
                text,
            });
        }
        let looked: Vec<String> = candidates.iter().map(|p| p.display().to_string()).collect();
        Err(format!("cannot find include file '{name}' (looked for {})", looked.join(", ")))
    }
}
