//! Error messages with their place in the source, and the "did you mean"
//! suggestions they carry (made by `tmclsim_protocol::suggest`, only for
//! errors that are kept, and within
//! [`MAX_SUGGESTION_WORK`](crate::limits::MAX_SUGGESTION_WORK) for one
//! assembly).

use std::fmt;
use std::sync::Arc;

use tmclsim_protocol::opcode as op;
use tmclsim_protocol::suggest::closest_within;

use crate::limits::MAX_SUGGESTION_WORK;

/// One error found while assembling: where it is and what is wrong.
///
/// `line` and `column` are 1-based; the column counts characters (a tab is
/// one column). Errors that belong to a whole file (it cannot be read) have
/// line 0 and column 0.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Diagnostic {
    /// The file's name as diagnostics show it (the main file as given, an
    /// include as its resolver names it).
    pub file: String,
    /// 1-based line; 0 for an error of the whole file.
    pub line: usize,
    /// 1-based column in characters; 0 for an error of the whole file.
    pub column: usize,
    /// What is wrong, in words.
    pub message: String,
}

impl Diagnostic {
    /// A diagnostic at `line`:`column` of `file`.
    pub fn new(file: impl Into<String>, line: usize, column: usize, message: impl Into<String>) -> Diagnostic {
        Diagnostic { file: file.into(), line, column, message: message.into() }
    }
}

/// `prog.tmc:12:5: error: unknown label 'Lop' (did you mean 'Loop'?)`
impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match (self.line, self.column) {
            (0, _) => write!(f, "{}: error: {}", self.file, self.message),
            (line, 0) => write!(f, "{}:{line}: error: {}", self.file, self.message),
            (line, column) => write!(f, "{}:{line}:{column}: error: {}", self.file, self.message),
        }
    }
}

impl std::error::Error for Diagnostic {}

/// Formats a list of diagnostics one per line, as a compiler prints them.
pub fn render(diagnostics: &[Diagnostic]) -> String {
    diagnostics.iter().map(|d| format!("{d}\n")).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_like_a_compiler() {
        let d = Diagnostic::new("prog.tmc", 12, 5, "unknown label 'Lop' (did you mean 'Loop'?)");
        assert_eq!(d.to_string(), "prog.tmc:12:5: error: unknown label 'Lop' (did you mean 'Loop'?)");
        assert_eq!(Diagnostic::new("x.tmc", 0, 0, "cannot read").to_string(), "x.tmc: error: cannot read");
    }
}

/// Where a statement is: its index in the assembled statement list (to keep
/// diagnostics in source order), its file (index into the file names) and
/// its line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Loc {
    pub seq: usize,
    pub file: usize,
    pub line: usize,
}

/// `unknown instruction 'MVPP' (did you mean 'MVP'?)`, or, for a word
/// that stands alone on its line (`nothing_follows`) and resembles no
/// mnemonic, the hint that a label needs a colon.
pub(crate) fn unknown_instruction(name: &str, nothing_follows: bool, budget: &mut u64) -> String {
    let hint = suggestion(name, (0..=255u8).filter_map(op::mnemonic), budget);
    if hint.is_empty() && nothing_follows {
        return format!("unknown instruction '{name}' (a label needs a colon: '{name}:')");
    }
    format!("unknown instruction '{name}'{hint}")
}

/// ` (did you mean 'Loop'?)` or nothing, within what is left of `budget`.
pub(crate) fn suggestion<'a>(name: &str, candidates: impl IntoIterator<Item = &'a str>, budget: &mut u64) -> String {
    closest_within(name, candidates, budget).map_or(String::new(), |c| format!(" (did you mean '{c}'?)"))
}

/// Collects the diagnostics of one assembly: the first
/// [`MAX_ERRORS`](crate::limits::MAX_ERRORS) in source order, and how many
/// there were in all.
#[derive(Debug)]
pub(crate) struct Reporter {
    pub files: Vec<Arc<str>>,
    /// The earliest errors so far, the latest of them on top.
    items: std::collections::BinaryHeap<Ranked>,
    total: usize,
    /// What the "did you mean" searches may still take.
    budget: u64,
}

impl Default for Reporter {
    fn default() -> Reporter {
        Reporter { files: Vec::new(), items: Default::default(), total: 0, budget: MAX_SUGGESTION_WORK }
    }
}

/// An error ordered by its place in the source.
#[derive(Debug, PartialEq, Eq)]
struct Ranked {
    seq: usize,
    column: usize,
    /// Order of arrival: equal places keep it.
    arrival: usize,
    file: usize,
    line: usize,
    message: String,
}

impl Ord for Ranked {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        (self.seq, self.column, self.arrival).cmp(&(other.seq, other.column, other.arrival))
    }
}

impl PartialOrd for Ranked {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Reporter {
    pub fn add_file(&mut self, name: &str) -> usize {
        self.files.push(Arc::from(name));
        self.files.len() - 1
    }

    /// Whether an error at this place would be kept now (it is among the
    /// earliest so far).
    pub fn keeps(&self, at: Loc, column: usize) -> bool {
        self.items.len() < crate::limits::MAX_ERRORS || self.items.peek().is_some_and(|top| (top.seq, top.column) > (at.seq, column))
    }

    pub fn error(&mut self, at: Loc, column: usize, message: impl Into<String>) {
        self.error_with(at, column, |_| message.into());
    }

    /// An error whose message is written only if the error is kept, so
    /// that errors past the limit cost no work: suggestions, chains of
    /// names. The message gets what is left of the suggestions' budget.
    pub fn error_with(&mut self, at: Loc, column: usize, message: impl FnOnce(&mut u64) -> String) {
        self.total += 1;
        if !self.keeps(at, column) {
            return;
        }
        let message = message(&mut self.budget);
        let ranked = Ranked { seq: at.seq, column, arrival: self.total, file: at.file, line: at.line, message };
        self.items.push(ranked);
        if self.items.len() > crate::limits::MAX_ERRORS {
            self.items.pop();
        }
    }

    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// The diagnostics in source order; past the limit, a last one says
    /// how many more there were.
    pub fn finish(self) -> Vec<Diagnostic> {
        let shown = self.items.len();
        let files = &self.files;
        let file = |index: usize| files.get(index).map_or_else(String::new, ToString::to_string);
        let mut out: Vec<Diagnostic> =
            self.items.into_sorted_vec().into_iter().map(|r| Diagnostic::new(file(r.file), r.line, r.column, r.message)).collect();
        if self.total > shown {
            out.push(Diagnostic::new(file(0), 0, 0, format!("{} more errors not shown (the first {shown} are)", self.total - shown)));
        }
        out
    }
}
