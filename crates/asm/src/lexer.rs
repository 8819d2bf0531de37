//! The lexer: comments out, then each source line cut into tokens that
//! remember their column.
//!
//! Comments are `// …` to the end of the line and `/* … */` (which may span
//! lines). They are replaced by blanks so that every column stays where the
//! author sees it.

use tmclsim_protocol::mnemonic::parse_number;

/// Punctuation and operators.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Punct {
    Comma,
    Colon,
    Equals,
    Hash,
    Plus,
    Minus,
    Star,
    Slash,
    Percent,
    Amp,
    Pipe,
    Caret,
    Tilde,
    ShiftLeft,
    ShiftRight,
    LeftParen,
    RightParen,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub enum TokenKind {
    /// A name: mnemonic, label, constant or symbolic operand.
    Ident(String),
    /// A number (`42`, `$2A`, `0x2A`, `0b101010`); signs are operators.
    Number(i64),
    /// Something that starts like a number but is not one (`12abc`, `0x`).
    BadNumber(String),
    /// `#include`, `#db`: the name after the `#`.
    Directive(String),
    Punct(Punct),
    /// A character no token starts with.
    Bad(char),
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Token {
    pub kind: TokenKind,
    /// 1-based character column, and the column just after the token.
    pub column: usize,
    pub end_column: usize,
    /// Byte offsets of the token in its line.
    pub start: usize,
    pub end: usize,
    /// Whether blank space separates the token from its neighbours.
    pub space_before: bool,
    pub space_after: bool,
}

impl Token {
    pub fn is(&self, p: Punct) -> bool {
        self.kind == TokenKind::Punct(p)
    }

    pub fn ident(&self) -> Option<&str> {
        match &self.kind {
            TokenKind::Ident(s) => Some(s),
            _ => None,
        }
    }
}

/// Where an unterminated `/*` starts (1-based line and column).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Unterminated {
    pub line: usize,
    pub column: usize,
}

/// The lines of a source text with comments blanked out, one at a time
/// (only one line is held at once). A `/*` without `*/` blanks the rest of
/// the text; [`Lines::unterminated`] tells where it started. A line longer
/// than `max_line` bytes is not read: it comes as `None`.
pub struct Lines<'t> {
    rest: Option<&'t str>,
    number: usize,
    max_line: usize,
    open: Option<Unterminated>,
    line: String,
}

impl<'t> Lines<'t> {
    pub fn new(source: &'t str, max_line: usize) -> Lines<'t> {
        Lines { rest: Some(source), number: 0, max_line, open: None, line: String::new() }
    }

    /// The next line: its 1-based number and its text (`None`: too long).
    pub fn next_line(&mut self) -> Option<(usize, Option<&str>)> {
        let rest = self.rest?;
        let (raw, rest) = match rest.split_once('\n') {
            Some((raw, rest)) => (raw, Some(rest)),
            None => (rest, None),
        };
        self.rest = rest;
        self.number += 1;
        let raw = raw.strip_suffix('\r').unwrap_or(raw);
        if raw.len() > self.max_line {
            return Some((self.number, None));
        }
        self.line.clear();
        // Most lines hold no comment: taken as they are.
        if self.open.is_none() && !raw.contains('/') {
            self.line.push_str(raw);
            return Some((self.number, Some(&self.line)));
        }
        let mut chars = raw.chars().peekable();
        let mut column = 0;
        while let Some(c) = chars.next() {
            let next = chars.peek().copied();
            column += 1;
            if self.open.is_some() {
                if c == '*' && next == Some('/') {
                    self.open = None;
                    self.line.push_str("  ");
                    chars.next();
                    column += 1;
                } else {
                    self.line.push(' ');
                }
            } else if c == '/' && next == Some('/') {
                self.line.extend(std::iter::repeat_n(' ', 1 + chars.count()));
                break;
            } else if c == '/' && next == Some('*') {
                self.open = Some(Unterminated { line: self.number, column });
                self.line.push_str("  ");
                chars.next();
                column += 1;
            } else {
                self.line.push(c);
            }
        }
        Some((self.number, Some(&self.line)))
    }

    /// Where a `/*` that is still open started.
    pub fn unterminated(&self) -> Option<Unterminated> {
        self.open
    }
}

/// Splits a source text into lines with comments blanked out (all of
/// [`Lines`] at once). A line longer than `max_line` bytes is left empty;
/// its number is in the third part.
#[cfg(test)]
pub fn strip_comments(source: &str, max_line: usize) -> (Vec<String>, Option<Unterminated>, Vec<usize>) {
    let mut lines = Lines::new(source, max_line);
    let (mut out, mut too_long) = (Vec::new(), Vec::new());
    while let Some((number, line)) = lines.next_line() {
        match line {
            Some(text) => out.push(text.to_string()),
            None => {
                too_long.push(number);
                out.push(String::new());
            }
        }
    }
    (out, lines.unterminated(), too_long)
}

fn is_name_start(c: char) -> bool {
    c.is_ascii_alphabetic() || c == '_'
}

fn is_name_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_'
}

/// Cuts one (comment-free) line into tokens. Never fails: characters that
/// start no token become [`TokenKind::Bad`] for the parser to report.
pub fn tokenize(line: &str) -> Vec<Token> {
    let chars: Vec<(usize, char)> = line.char_indices().collect();
    let byte_at = |i: usize| chars.get(i).map_or(line.len(), |&(b, _)| b);
    let mut tokens: Vec<Token> = Vec::new();
    let mut i = 0;
    let mut space_before = true;
    while i < chars.len() {
        let c = chars[i].1;
        if c.is_whitespace() {
            if let Some(last) = tokens.last_mut() {
                last.space_after = true;
            }
            space_before = true;
            i += 1;
            continue;
        }
        let start = i;
        let next = chars.get(i + 1).map(|&(_, c)| c);
        let kind = if is_name_start(c) {
            while i < chars.len() && is_name_char(chars[i].1) {
                i += 1;
            }
            TokenKind::Ident(line[byte_at(start)..byte_at(i)].to_string())
        } else if c.is_ascii_digit() || (c == '$' && next.is_some_and(|n| n.is_ascii_alphanumeric())) {
            i += 1;
            while i < chars.len() && is_name_char(chars[i].1) {
                i += 1;
            }
            let text = &line[byte_at(start)..byte_at(i)];
            match parse_number(text) {
                Some(v) => TokenKind::Number(v),
                None => TokenKind::BadNumber(text.to_string()),
            }
        } else if c == '#' && next.is_some_and(is_name_start) {
            i += 1;
            while i < chars.len() && is_name_char(chars[i].1) {
                i += 1;
            }
            TokenKind::Directive(line[byte_at(start + 1)..byte_at(i)].to_string())
        } else {
            let (p, len) = match (c, next) {
                ('<', Some('<')) => (Some(Punct::ShiftLeft), 2),
                ('>', Some('>')) => (Some(Punct::ShiftRight), 2),
                (',', _) => (Some(Punct::Comma), 1),
                (':', _) => (Some(Punct::Colon), 1),
                ('=', _) => (Some(Punct::Equals), 1),
                ('#', _) => (Some(Punct::Hash), 1),
                ('+', _) => (Some(Punct::Plus), 1),
                ('-', _) => (Some(Punct::Minus), 1),
                ('*', _) => (Some(Punct::Star), 1),
                ('/', _) => (Some(Punct::Slash), 1),
                ('%', _) => (Some(Punct::Percent), 1),
                ('&', _) => (Some(Punct::Amp), 1),
                ('|', _) => (Some(Punct::Pipe), 1),
                ('^', _) => (Some(Punct::Caret), 1),
                ('~', _) => (Some(Punct::Tilde), 1),
                ('(', _) => (Some(Punct::LeftParen), 1),
                (')', _) => (Some(Punct::RightParen), 1),
                _ => (None, 1),
            };
            i += len;
            p.map_or(TokenKind::Bad(c), TokenKind::Punct)
        };
        tokens.push(Token {
            kind,
            column: start + 1,
            end_column: i + 1,
            start: byte_at(start),
            end: byte_at(i),
            space_before,
            space_after: false,
        });
        space_before = false;
    }
    if let Some(last) = tokens.last_mut() {
        last.space_after = true;
    }
    tokens
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kinds(line: &str) -> Vec<TokenKind> {
        tokenize(line).into_iter().map(|t| t.kind).collect()
    }

    #[test]
    fn comments_become_blanks() {
        let (lines, open, _) = strip_comments("ROL 0, 1000 // spin\n/* a\nb */ MST 0\r\nSTOP", 100);
        assert_eq!(lines, vec!["ROL 0, 1000        ", "    ", "     MST 0", "STOP"]);
        assert_eq!(open, None);
        let (_, open, _) = strip_comments("STOP\n  /* never closed", 100);
        assert_eq!(open, Some(Unterminated { line: 2, column: 3 }));
    }

    #[test]
    fn tokens_with_columns() {
        let t = tokenize("Loop: MVP ABS, 0, $10");
        assert_eq!(t.iter().map(|t| t.column).collect::<Vec<_>>(), vec![1, 5, 7, 11, 14, 16, 17, 19]);
        assert_eq!(t[7].kind, TokenKind::Number(16));
        assert_eq!(kinds("#include x"), vec![TokenKind::Directive("include".into()), TokenKind::Ident("x".into())]);
        assert_eq!(
            kinds("1<<2 0x1F 12ab"),
            vec![
                TokenKind::Number(1),
                TokenKind::Punct(Punct::ShiftLeft),
                TokenKind::Number(2),
                TokenKind::Number(31),
                TokenKind::BadNumber("12ab".into()),
            ]
        );
        assert_eq!(kinds("@ ä"), vec![TokenKind::Bad('@'), TokenKind::Bad('ä')]);
    }

    #[test]
    fn spacing_is_recorded() {
        let t = tokenize("SIO 255 2 -1");
        assert!(t[3].space_before && !t[3].space_after);
        let t = tokenize("1 - 2");
        assert!(t[1].space_before && t[1].space_after);
    }
}
