//! The symbol file: one `label address` pair per line, sorted by address
//! (then by name), e.g.
//!
//! ```text
//! Func1 0
//! Func2 1
//! Loop 10
//! ```
//!
//! It tells a host the entry points of a program (manual 8.6: "run
//! application" from a label's address). The parser also skips blank lines
//! and `//` comments.
//!
//! A program assembled from source adds its source map after the labels,
//! one line per instruction, its five fields separated by tabs (shown
//! here as `→`):
//!
//! ```text
//! // source map: @address, file, line, column, source text
//! @0→shuttle.tmc→7→7→Loop: MVP ABS, 0, 51200
//! ```

use std::collections::BTreeMap;
use std::sync::Arc;

use tmclsim_protocol::mnemonic::parse_number;

use crate::source_map::SourceLine;

/// The comment line that opens the source map.
const SOURCE_MAP_HEADER: &str = "// source map: @address, file, line, column, source text";

/// Writes the symbol file of a label table and, when it is not empty, the
/// source map.
pub fn write(symbols: &BTreeMap<String, u32>, source_map: &[SourceLine]) -> String {
    let mut pairs: Vec<(&String, &u32)> = symbols.iter().collect();
    pairs.sort_by(|a, b| a.1.cmp(b.1).then_with(|| a.0.cmp(b.0)));
    let mut out: String = pairs.iter().map(|(name, address)| format!("{name} {address}\n")).collect();
    if !source_map.is_empty() {
        out.push_str(SOURCE_MAP_HEADER);
        out.push('\n');
    }
    // A tab or line break in a file name would break the line apart.
    let clean = |s: &str| s.replace(['\t', '\n', '\r'], " ");
    for (address, s) in source_map.iter().enumerate() {
        out.push_str(&format!("@{address}\t{}\t{}\t{}\t{}\n", clean(&s.file), s.line, s.column, clean(&s.text)));
    }
    out
}

fn is_label(name: &str) -> bool {
    let mut chars = name.chars();
    chars.next().is_some_and(|c| c.is_ascii_alphabetic() || c == '_') && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// What is wrong in a symbol file, and on which line.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SymbolFileError {
    /// The line, from 1.
    pub line: usize,
    /// What is wrong with it.
    pub problem: SymbolProblem,
}

/// What is wrong with a line of a symbol file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SymbolProblem {
    /// A source map line without its five fields.
    SourceFields,
    /// A source map line out of order.
    SourceAddress {
        /// The address whose line comes next.
        expected: usize,
        /// The `@address` field found.
        found: String,
    },
    /// A source map field that should be a number.
    NotANumber {
        /// `line number` or `column`.
        what: &'static str,
        /// The field.
        text: String,
    },
    /// A line that is not `label address` (the line, comment removed).
    NotLabelAddress(String),
    /// A label field that is no label name.
    NotALabel(String),
    /// An address field that is no address.
    NotAnAddress(String),
    /// A label that appears a second time.
    Twice(String),
}

impl std::fmt::Display for SymbolFileError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "line {}: ", self.line)?;
        match &self.problem {
            SymbolProblem::SourceFields => {
                write!(f, "a source map line has five tab-separated fields (@address, file, line, column, text)")
            }
            SymbolProblem::SourceAddress { expected, found } => write!(f, "expected the source of address {expected}, found '{found}'"),
            SymbolProblem::NotANumber { what, text } => write!(f, "'{text}' is not a {what}"),
            SymbolProblem::NotLabelAddress(line) => write!(f, "expected 'label address', found '{line}'"),
            SymbolProblem::NotALabel(name) => write!(f, "'{name}' is not a label name"),
            SymbolProblem::NotAnAddress(address) => write!(f, "'{address}' is not an address"),
            SymbolProblem::Twice(name) => write!(f, "label '{name}' appears twice"),
        }
    }
}

impl std::error::Error for SymbolFileError {}

impl From<SymbolFileError> for String {
    fn from(e: SymbolFileError) -> String {
        e.to_string()
    }
}

/// Reads the labels of a symbol file (its source map is checked, not kept).
pub fn parse(text: &str) -> Result<BTreeMap<String, u32>, SymbolFileError> {
    parse_all(text).map(|(labels, _)| labels)
}

/// Reads a source map line: `@address\tfile\tline\tcolumn\ttext`; its file
/// shares the `previous` line's copy of the name when they are the same.
fn parse_source_line(line: &str, number: usize, expected: usize, previous: Option<&SourceLine>) -> Result<SourceLine, SymbolFileError> {
    let error = |problem| SymbolFileError { line: number, problem };
    let fields: Vec<&str> = line.splitn(5, '\t').collect();
    let &[address, file, at, column, text] = fields.as_slice() else {
        return Err(error(SymbolProblem::SourceFields));
    };
    if address[1..].parse::<usize>().ok() != Some(expected) {
        return Err(error(SymbolProblem::SourceAddress { expected, found: address.to_string() }));
    }
    let number_field = |what, v: &str| v.parse::<u32>().map_err(|_| error(SymbolProblem::NotANumber { what, text: v.to_string() }));
    Ok(SourceLine {
        file: previous.filter(|p| *p.file == *file).map_or_else(|| Arc::from(file), |p| p.file.clone()),
        line: number_field("line number", at)?,
        column: number_field("column", column)?,
        text: text.trim_end_matches('\r').to_string(),
    })
}

/// Reads a symbol file: its labels and its source map (empty when it has
/// none).
pub fn parse_all(text: &str) -> Result<(BTreeMap<String, u32>, Vec<SourceLine>), SymbolFileError> {
    let mut out = BTreeMap::new();
    let mut source_map = Vec::new();
    for (index, raw) in text.lines().enumerate() {
        let number = index + 1;
        let error = |problem| SymbolFileError { line: number, problem };
        if raw.starts_with('@') {
            let line = parse_source_line(raw, number, source_map.len(), source_map.last())?;
            source_map.push(line);
            continue;
        }
        let line = raw.split("//").next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let fields: Vec<&str> = line.split_whitespace().collect();
        let &[name, address] = fields.as_slice() else {
            return Err(error(SymbolProblem::NotLabelAddress(line.to_string())));
        };
        if !is_label(name) {
            return Err(error(SymbolProblem::NotALabel(name.to_string())));
        }
        let address = parse_number(address)
            .and_then(|a| u32::try_from(a).ok())
            .ok_or_else(|| error(SymbolProblem::NotAnAddress(address.to_string())))?;
        if out.insert(name.to_string(), address).is_some() {
            return Err(error(SymbolProblem::Twice(name.to_string())));
        }
    }
    Ok((out, source_map))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sorted_by_address_and_read_back() {
        let symbols: BTreeMap<String, u32> = [("Loop".to_string(), 10), ("Func1".to_string(), 0), ("Alpha".to_string(), 10)].into();
        let text = write(&symbols, &[]);
        assert_eq!(text, "Func1 0\nAlpha 10\nLoop 10\n");
        assert_eq!(parse(&text).unwrap(), symbols);
    }

    #[test]
    fn the_source_map_follows_the_labels_and_reads_back() {
        let symbols: BTreeMap<String, u32> = [("Loop".to_string(), 1)].into();
        let map = vec![
            SourceLine { file: "a b.tmc".into(), line: 3, column: 5, text: "ROR 0, 500".into() },
            SourceLine { file: "lib.tmc".into(), line: 1, column: 7, text: "Loop: MST 0".into() },
        ];
        let text = write(&symbols, &map);
        assert_eq!(
            text,
            "Loop 1\n// source map: @address, file, line, column, source text\n@0\ta b.tmc\t3\t5\tROR 0, 500\n@1\tlib.tmc\t1\t7\tLoop: MST 0\n"
        );
        assert_eq!(parse_all(&text).unwrap(), (symbols.clone(), map));
        assert_eq!(parse(&text).unwrap(), symbols);
    }

    #[test]
    fn bad_source_map_lines() {
        assert!(parse_all("@1\ta\t1\t1\tx").unwrap_err().to_string().contains("line 1: expected the source of address 0"));
        assert!(parse_all("@0\ta\t1").unwrap_err().to_string().contains("five tab-separated fields"));
        assert!(parse_all("@0\ta\tx\t1\tt").unwrap_err().to_string().contains("'x' is not a line number"));
        assert!(parse_all("@\ta\t1\t1\tt").unwrap_err().to_string().contains("found '@'"));
    }

    #[test]
    fn bad_lines() {
        assert!(parse("Loop").unwrap_err().to_string().starts_with("line 1:"));
        assert!(parse("\n// c\nLoop x").unwrap_err().to_string().starts_with("line 3:"));
        assert!(parse("1abc 3").is_err());
        assert!(parse("A 1\nA 2").unwrap_err().to_string().contains("twice"));
        assert!(parse("A -1").is_err());
        assert_eq!(parse("  // nothing\n\nA $10 // hex\n").unwrap()["A"], 16);
    }
}
