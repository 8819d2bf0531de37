//! Error messages with their place in the source, and the "did you mean"
//! suggestions they carry.

use std::fmt;

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

/// The candidate closest to `name` (case-insensitive edit distance), if it
/// is close enough to be a likely typo.
pub fn closest<'a>(name: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let wanted = name.to_ascii_lowercase();
    let limit = (wanted.chars().count() / 3).max(1);
    let mut best: Option<(usize, &str)> = None;
    for candidate in candidates {
        if candidate == name {
            continue;
        }
        let d = edit_distance(&wanted, &candidate.to_ascii_lowercase());
        if d <= limit && best.is_none_or(|(bd, _)| d < bd) {
            best = Some((d, candidate));
        }
    }
    best.map(|(_, c)| c)
}

/// ` (did you mean 'Loop'?)` or nothing.
pub fn suggestion<'a>(name: &str, candidates: impl IntoIterator<Item = &'a str>) -> String {
    closest(name, candidates).map_or(String::new(), |c| format!(" (did you mean '{c}'?)"))
}

/// Edit distance over characters where swapping two neighbours counts as
/// one edit (optimal string alignment), so `Strat` is one edit from `Start`.
fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    let mut d = vec![vec![0usize; b.len() + 1]; a.len() + 1];
    for (i, row) in d.iter_mut().enumerate() {
        row[0] = i;
    }
    for (j, cell) in d[0].iter_mut().enumerate() {
        *cell = j;
    }
    for i in 1..=a.len() {
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            let mut best = (d[i - 1][j] + 1).min(d[i][j - 1] + 1).min(d[i - 1][j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                best = best.min(d[i - 2][j - 2] + 1);
            }
            d[i][j] = best;
        }
    }
    d[a.len()][b.len()]
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

    #[test]
    fn suggestions() {
        assert_eq!(closest("Lop", ["Start", "Loop"]), Some("Loop"));
        assert_eq!(closest("loop", ["Loop"]), Some("Loop"));
        assert_eq!(closest("MVPP", ["MVP", "MST"]), Some("MVP"));
        assert_eq!(closest("Strat", ["Start"]), Some("Start"));
        assert_eq!(closest("Zebra", ["Loop"]), None);
        assert_eq!(suggestion("Zebra", ["Loop"]), "");
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
    pub files: Vec<String>,
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
        self.files.push(name.to_string());
        self.files.len() - 1
    }

    pub fn error(&mut self, at: Loc, column: usize, message: impl Into<String>) {
        let limit = crate::limits::MAX_ERRORS;
        let ranked = |diagnostic, arrival| Ranked { seq: at.seq, column, arrival, diagnostic };
        self.total += 1;
        if self.items.len() == limit && self.items.peek().is_some_and(|top| (top.seq, top.column) <= (at.seq, column)) {
            return;
        }
        let file = self.files.get(at.file).cloned().unwrap_or_default();
        self.items.push(ranked(Diagnostic::new(file, at.line, column, message), self.total));
        if self.items.len() > limit {
            self.items.pop();
        }
    }

    /// `file:line:column` of a place, for "first defined at …".
    pub fn place(&self, at: Loc, column: usize) -> String {
        format!("{}:{}:{column}", self.files.get(at.file).map_or("", String::as_str), at.line)
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
            let file = self.files.first().cloned().unwrap_or_default();
            out.push(Diagnostic::new(file, 0, 0, format!("{} more errors not shown (the first {shown} are)", self.total - shown)));
        }
        out
    }
}
