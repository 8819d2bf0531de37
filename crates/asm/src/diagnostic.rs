//! Error messages with their place in the source, and the "did you mean"
//! suggestions they carry (made by `tmclsim_protocol::suggest`).

use std::fmt;
use std::sync::Arc;

/// One error found while assembling: where it is and what is wrong.
///
/// `line` and `column` are 1-based; the column counts characters (a tab is
/// one column). Errors that belong to a whole file (it cannot be read) have
/// line 0 and column 0.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Diagnostic {
    pub file: String,
    pub line: usize,
    pub column: usize,
    pub message: String,
}

impl Diagnostic {
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

pub use tmclsim_protocol::suggest::suggestion;

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

/// Collects the diagnostics of one assembly: the first
/// [`MAX_ERRORS`](crate::limits::MAX_ERRORS) in source order, and how many
/// there were in all.
#[derive(Debug, Default)]
pub(crate) struct Reporter {
    /// File names, shared with the source map.
    pub files: Vec<Arc<str>>,
    /// The earliest errors so far, the latest of them on top.
    items: std::collections::BinaryHeap<Ranked>,
    total: usize,
}

/// A diagnostic ordered by its place in the source.
#[derive(Debug, PartialEq, Eq)]
struct Ranked {
    seq: usize,
    column: usize,
    /// Order of arrival: equal places keep it.
    arrival: usize,
    diagnostic: Diagnostic,
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

    pub fn error(&mut self, at: Loc, column: usize, message: impl Into<String>) {
        let limit = crate::limits::MAX_ERRORS;
        let ranked = |diagnostic, arrival| Ranked { seq: at.seq, column, arrival, diagnostic };
        self.total += 1;
        if self.items.len() == limit && self.items.peek().is_some_and(|top| (top.seq, top.column) <= (at.seq, column)) {
            return;
        }
        let file = self.files.get(at.file).map(|f| f.to_string()).unwrap_or_default();
        self.items.push(ranked(Diagnostic::new(file, at.line, column, message), self.total));
        if self.items.len() > limit {
            self.items.pop();
        }
    }

    /// `file:line:column` of a place, for "first defined at …".
    pub fn place(&self, at: Loc, column: usize) -> String {
        format!("{}:{}:{column}", self.files.get(at.file).map_or("", |f| &**f), at.line)
    }

    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// The diagnostics in source order; past the limit, a last one says
    /// how many more there were.
    pub fn finish(self) -> Vec<Diagnostic> {
        let shown = self.items.len();
        let mut out: Vec<Diagnostic> = self.items.into_sorted_vec().into_iter().map(|r| r.diagnostic).collect();
        if self.total > shown {
            let file = self.files.first().map(|f| f.to_string()).unwrap_or_default();
            out.push(Diagnostic::new(file, 0, 0, format!("{} more errors not shown (the first {shown} are)", self.total - shown)));
        }
        out
    }
}
