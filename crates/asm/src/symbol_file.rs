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

/// Reads the labels of a symbol file (its source map is checked, not kept).
pub fn parse(text: &str) -> Result<BTreeMap<String, u32>, String> {
    parse_all(text).map(|(labels, _)| labels)
}

/// Reads a source map line: `@address\tfile\tline\tcolumn\ttext`; its file
/// shares the `previous` line's copy of the name when they are the same.
fn parse_source_line(line: &str, number: usize, expected: usize, previous: Option<&SourceLine>) -> Result<SourceLine, String> {
    let fields: Vec<&str> = line.splitn(5, '\t').collect();
    let &[address, file, at, column, text] = fields.as_slice() else {
        return Err(format!("line {number}: a source map line has five tab-separated fields (@address, file, line, column, text)"));
    };
    if address[1..].parse::<usize>().ok() != Some(expected) {
        return Err(format!("line {number}: expected the source of address {expected}, found '{address}'"));
    }
    let number_field = |what: &str, v: &str| v.parse::<u32>().map_err(|_| format!("line {number}: '{v}' is not a {what}"));
    Ok(SourceLine {
        file: previous.filter(|p| *p.file == *file).map_or_else(|| Arc::from(file), |p| p.file.clone()),
        line: number_field("line number", at)?,
        column: number_field("column", column)?,
        text: text.trim_end_matches('\r').to_string(),
    })
}

/// Reads a symbol file: its labels and its source map (empty when it has
/// none).
pub fn parse_all(text: &str) -> Result<(BTreeMap<String, u32>, Vec<SourceLine>), String> {
    let mut out = BTreeMap::new();
    let mut source_map = Vec::new();
    for (index, raw) in text.lines().enumerate() {
        let number = index + 1;
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
            return Err(format!("line {number}: expected 'label address', found '{line}'"));
        };
        if !is_label(name) {
            return Err(format!("line {number}: '{name}' is not a label name"));
        }
        let address = parse_number(address)
            .and_then(|a| u32::try_from(a).ok())
            .ok_or_else(|| format!("line {number}: '{address}' is not an address"))?;
        if out.insert(name.to_string(), address).is_some() {
            return Err(format!("line {number}: label '{name}' appears twice"));
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
        assert!(parse_all("@1\ta\t1\t1\tx").unwrap_err().contains("line 1: expected the source of address 0"));
        assert!(parse_all("@0\ta\t1").unwrap_err().contains("five tab-separated fields"));
        assert!(parse_all("@0\ta\tx\t1\tt").unwrap_err().contains("'x' is not a line number"));
        assert!(parse_all("@\ta\t1\t1\tt").unwrap_err().contains("found '@'"));
    }

    #[test]
    fn bad_lines() {
        assert!(parse("Loop").unwrap_err().starts_with("line 1:"));
        assert!(parse("\n// c\nLoop x").unwrap_err().starts_with("line 3:"));
        assert!(parse("1abc 3").is_err());
        assert!(parse("A 1\nA 2").unwrap_err().contains("twice"));
        assert!(parse("A -1").is_err());
        assert_eq!(parse("  // nothing\n\nA $10 // hex\n").unwrap()["A"], 16);
    }
}
