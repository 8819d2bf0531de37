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

use std::collections::BTreeMap;

use tmclsim_protocol::mnemonic::parse_number;

/// Writes the symbol file of a label table.
pub fn write(symbols: &BTreeMap<String, u32>) -> String {
    let mut pairs: Vec<(&String, &u32)> = symbols.iter().collect();
    pairs.sort_by(|a, b| a.1.cmp(b.1).then_with(|| a.0.cmp(b.0)));
    pairs.iter().map(|(name, address)| format!("{name} {address}\n")).collect()
}

fn is_label(name: &str) -> bool {
    let mut chars = name.chars();
    chars.next().is_some_and(|c| c.is_ascii_alphabetic() || c == '_') && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// Reads a symbol file.
pub fn parse(text: &str) -> Result<BTreeMap<String, u32>, String> {
    let mut out = BTreeMap::new();
    for (index, raw) in text.lines().enumerate() {
        let line = raw.split("//").next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let number = index + 1;
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
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sorted_by_address_and_read_back() {
        let symbols: BTreeMap<String, u32> = [("Loop".to_string(), 10), ("Func1".to_string(), 0), ("Alpha".to_string(), 10)].into();
        let text = write(&symbols);
        assert_eq!(text, "Func1 0\nAlpha 10\nLoop 10\n");
        assert_eq!(parse(&text).unwrap(), symbols);
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
