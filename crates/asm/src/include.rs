//! Finding the files that `#include` names.
//!
//! A resolver turns the name written after `#include` into the file's text.
//! Names are relative to the including file. When a resolver cannot find a
//! file, the assembler falls back to the include files shipped with
//! tmclsim (`include/Interrupts.inc`, `include/Parameters.inc`), so that
//! `#include Interrupts.inc` works everywhere, as it does in the TMCL-IDE.
//!
//! The assembler reads no files: the resolver that reads them from disk is
//! `tmclsim_server::sources::FileResolver`.

use std::collections::BTreeMap;
use std::path::{Component, Path, PathBuf};

/// A file found for an `#include`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct IncludedFile {
    /// Identifies the file: two includes with the same key are the same
    /// file (used to include a file only once and to find cycles).
    pub key: String,
    /// The name diagnostics use for the file.
    pub name: String,
    /// The file's source text.
    pub text: String,
}

/// Finds included files.
pub trait IncludeResolver {
    /// Resolves `name` as written in `#include` in the file `from` (the
    /// `name` of an earlier [`IncludedFile`], or the file name given to
    /// `assemble`). The error's text is shown to the user.
    fn resolve(&self, from: &str, name: &str) -> Result<IncludedFile, IncludeError>;

    /// The key of the file given to `assemble` (so that a file including
    /// the main file is found to be a cycle).
    fn key(&self, file: &str) -> String {
        file.to_string()
    }
}

/// Why an included file was not found.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum IncludeError {
    /// No file has this name.
    NotFound {
        /// The name as written after `#include`.
        name: String,
        /// The paths looked at, in order (empty: not told).
        looked: Vec<String>,
    },
    /// The file is there but cannot be read.
    Unreadable {
        /// The file's path.
        path: String,
        /// Why, in words.
        reason: String,
    },
}

impl std::fmt::Display for IncludeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            IncludeError::NotFound { name, looked } if looked.is_empty() => write!(f, "cannot find include file '{name}'"),
            IncludeError::NotFound { name, looked } => {
                write!(f, "cannot find include file '{name}' (looked for {})", looked.join(", "))
            }
            IncludeError::Unreadable { path, reason } => write!(f, "cannot read include file '{path}': {reason}"),
        }
    }
}

impl std::error::Error for IncludeError {}

impl From<IncludeError> for String {
    fn from(e: IncludeError) -> String {
        e.to_string()
    }
}

/// The include files shipped with tmclsim, by file name.
pub const BUILT_IN: &[(&str, &str)] = &[
    ("Interrupts.inc", include_str!("../../../include/Interrupts.inc")),
    ("Parameters.inc", include_str!("../../../include/Parameters.inc")),
];

/// A shipped include file by name (case-insensitive, directories ignored).
pub fn built_in(name: &str) -> Option<IncludedFile> {
    let base = name.rsplit(['/', '\\']).next().unwrap_or(name);
    BUILT_IN.iter().find(|(n, _)| n.eq_ignore_ascii_case(base)).map(|(n, text)| IncludedFile {
        key: format!("<built-in>/{n}"),
        name: n.to_string(),
        text: text.to_string(),
    })
}

/// Include files held in memory: a map from path to text. Names are looked
/// up relative to the including file's directory first, then as written.
#[derive(Clone, Debug, Default)]
pub struct MemoryResolver {
    /// Path → source text.
    pub files: BTreeMap<String, String>,
}

impl MemoryResolver {
    /// A resolver that finds no file yet.
    pub fn new() -> MemoryResolver {
        MemoryResolver::default()
    }

    /// Adds a file at the path `name`.
    pub fn with(mut self, name: &str, text: &str) -> MemoryResolver {
        self.files.insert(name.to_string(), text.to_string());
        self
    }
}

impl IncludeResolver for MemoryResolver {
    fn resolve(&self, from: &str, name: &str) -> Result<IncludedFile, IncludeError> {
        let base = Path::new(from).parent().unwrap_or(Path::new(""));
        let relative = normalize(&base.join(name)).to_string_lossy().replace('\\', "/");
        for candidate in [relative.as_str(), name] {
            if let Some(text) = self.files.get(candidate) {
                return Ok(IncludedFile { key: candidate.to_string(), name: candidate.to_string(), text: text.clone() });
            }
        }
        Err(IncludeError::NotFound { name: name.to_string(), looked: Vec::new() })
    }
}

/// Never finds a file (only the shipped include files are available).
#[derive(Clone, Copy, Debug, Default)]
pub struct NoIncludes;

impl IncludeResolver for NoIncludes {
    fn resolve(&self, _from: &str, name: &str) -> Result<IncludedFile, IncludeError> {
        Err(IncludeError::NotFound { name: name.to_string(), looked: Vec::new() })
    }
}

/// Removes `.` and resolves `..` textually.
pub fn normalize(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                if !out.pop() {
                    out.push("..");
                }
            }
            other => out.push(other),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn memory_resolver_is_relative_to_the_includer() {
        let r = MemoryResolver::new().with("lib/a.inc", "X = 1").with("b.inc", "Y = 2");
        assert_eq!(r.resolve("lib/main.tmc", "a.inc").unwrap().name, "lib/a.inc");
        assert_eq!(r.resolve("lib/main.tmc", "../b.inc").unwrap().name, "b.inc");
        assert_eq!(r.resolve("main.tmc", "b.inc").unwrap().name, "b.inc");
        assert!(r.resolve("main.tmc", "c.inc").is_err());
    }

    #[test]
    fn shipped_files_by_name() {
        assert!(built_in("interrupts.inc").is_some());
        assert!(built_in("some/dir/Parameters.inc").is_some());
        assert!(built_in("TMCLParam.tmc").is_none());
    }
}
