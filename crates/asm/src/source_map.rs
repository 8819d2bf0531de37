//! The source map: for every instruction of a program, the file, line and
//! column it was assembled from and the text of that line. Debuggers show
//! source lines with it and take breakpoints as `file:line`.

use std::collections::BTreeMap;
use std::sync::Arc;

/// Where one instruction comes from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SourceLine {
    /// The file as the assembler named it (the path given, or the name in
    /// `#include`); the instructions of a file share one copy.
    pub file: Arc<str>,
    /// 1-based line.
    pub line: u32,
    /// 1-based column of the mnemonic (characters).
    pub column: u32,
    /// The line as written, without its comment and surrounding blanks.
    pub text: String,
}

/// A place asked for by a debugger: `file:line`, or `line` alone for the
/// program's main file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LinePlace {
    /// The file as the user wrote it (its end must match a file's name);
    /// `None` for the main file.
    pub file: Option<String>,
    /// 1-based line.
    pub line: u32,
}

impl LinePlace {
    /// Reads `12`, `prog.tmc:12` or `dir/prog.tmc:12`; anything else is
    /// not a line place.
    pub fn parse(text: &str) -> Option<LinePlace> {
        let (file, line) = match text.rsplit_once(':') {
            Some((file, line)) if !file.is_empty() => (Some(file.to_string()), line),
            Some(_) => return None,
            None => (None, text),
        };
        let line: u32 = line.parse().ok().filter(|l| *l > 0)?;
        Some(LinePlace { file, line })
    }
}

/// The first instruction assembled from `place` or, when that line holds
/// none, from the next line of the same file that does (as debuggers put a
/// breakpoint on a comment or blank line). `None` when the file holds no
/// instruction at or after that line, or no file of the map matches.
///
/// A file matches when it is the name in the map, or when the map's name
/// ends with `/` + the name given (on Windows also `\` + the name, its
/// paths' separator). Without a file, the file of the first
/// instruction (the main file) is meant.
pub fn address_of(map: &[SourceLine], place: &LinePlace) -> Result<u32, PlaceError> {
    let file = match &place.file {
        Some(f) => {
            let names: BTreeMap<&str, ()> = map.iter().map(|s| (&*s.file, ())).collect();
            let below = |n: &str| n.ends_with(&format!("/{f}")) || (cfg!(windows) && n.ends_with(&format!("\\{f}")));
            let matching: Vec<&str> = names.keys().copied().filter(|n| *n == f || below(n)).collect();
            match matching.as_slice() {
                [one] => one.to_string(),
                [] => {
                    let files = names.keys().map(|n| (*n).to_string()).collect();
                    return Err(PlaceError::NoSuchFile { file: f.clone(), files });
                }
                many => {
                    let files = many.iter().map(|n| (*n).to_string()).collect();
                    return Err(PlaceError::SeveralFiles { file: f.clone(), files });
                }
            }
        }
        None => match map.first() {
            Some(s) => s.file.to_string(),
            None => return Err(PlaceError::NoSourceMap),
        },
    };
    map.iter()
        .enumerate()
        .filter(|(_, s)| *s.file == *file && s.line >= place.line)
        .min_by_key(|(a, s)| (s.line, *a))
        .map(|(a, _)| a as u32)
        .ok_or(PlaceError::NoInstruction { file, line: place.line })
}

/// Why a source line has no instruction address.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum PlaceError {
    /// No instruction comes from a file of this name.
    NoSuchFile {
        /// The file as given.
        file: String,
        /// The program's files.
        files: Vec<String>,
    },
    /// The name fits several of the program's files.
    SeveralFiles {
        /// The file as given.
        file: String,
        /// The files it fits.
        files: Vec<String>,
    },
    /// The program was not assembled from source.
    NoSourceMap,
    /// The file holds no instruction at or after the line.
    NoInstruction {
        /// The file, as the source map names it.
        file: String,
        /// The line asked for.
        line: u32,
    },
}

impl std::fmt::Display for PlaceError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PlaceError::NoSuchFile { file, files } => {
                write!(f, "no instruction comes from a file '{file}' (the program's files: {})", files.join(", "))
            }
            PlaceError::SeveralFiles { file, files } => write!(f, "'{file}' names several files: {}", files.join(", ")),
            PlaceError::NoSourceMap => write!(f, "the program has no source map (it was not assembled from source)"),
            PlaceError::NoInstruction { file, line } => write!(f, "{file}: no instruction at or after line {line}"),
        }
    }
}

impl std::error::Error for PlaceError {}

impl From<PlaceError> for String {
    fn from(e: PlaceError) -> String {
        e.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(file: &str, line: u32) -> SourceLine {
        SourceLine { file: file.into(), line, column: 1, text: String::new() }
    }

    #[test]
    fn places_parse() {
        assert_eq!(LinePlace::parse("12"), Some(LinePlace { file: None, line: 12 }));
        assert_eq!(LinePlace::parse("a/b.tmc:3"), Some(LinePlace { file: Some("a/b.tmc".into()), line: 3 }));
        for bad in ["", "0", ":3", "x.tmc:", "x.tmc:-1", "Loop"] {
            assert_eq!(LinePlace::parse(bad), None, "{bad}");
        }
    }

    #[test]
    fn a_line_without_instruction_means_the_next_one() {
        let map = [line("dir/main.tmc", 2), line("dir/main.tmc", 5), line("lib.tmc", 1), line("dir/main.tmc", 9)];
        let at = |f: Option<&str>, l| address_of(&map, &LinePlace { file: f.map(str::to_string), line: l });
        assert_eq!(at(None, 1), Ok(0));
        assert_eq!(at(None, 3), Ok(1));
        assert_eq!(at(Some("main.tmc"), 6), Ok(3));
        assert_eq!(at(Some("lib.tmc"), 1), Ok(2));
        assert!(at(None, 10).unwrap_err().to_string().contains("no instruction at or after line 10"));
        assert!(at(Some("other.tmc"), 1).unwrap_err().to_string().contains("the program's files: dir/main.tmc, lib.tmc"));
        assert!(address_of(&[], &LinePlace { file: None, line: 1 }).unwrap_err().to_string().contains("no source map"));
    }
}
