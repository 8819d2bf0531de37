//! The parser: one source line into labels and a body (an instruction with
//! its operand expressions, a constant definition, a raw word or an
//! `#include`).
//!
//! ```text
//! line      := label* body?
//! label     := NAME ':'
//! body      := NAME '=' expr                       constant
//!            | MNEMONIC operands                   instruction
//!            | '#db' expr ',' expr ',' expr ',' expr   raw word
//!            | '#' expr expr expr expr             raw word (protocol form)
//!            | '#include' FILE                     (quoted or bare)
//! operands  := expr (','? expr)*
//! ```
//!
//! Operands are separated by commas; a comma may be left out where that is
//! unambiguous (`MVP ABS 2, 10000`, `JC NZ Label`, `SAP 4 0 1000`).

use crate::expr::{Expr, ExprParser, SyntaxError, punct_text};
use crate::lexer::{Punct, Token, TokenKind, tokenize};

/// What a line holds besides its labels.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Body {
    None,
    Constant {
        name: String,
        column: usize,
        value: Option<Expr>,
    },
    Instruction {
        mnemonic: String,
        column: usize,
        operands: Vec<Expr>,
        end_column: usize,
    },
    Raw {
        column: usize,
        fields: Vec<Expr>,
        end_column: usize,
    },
    Include {
        file: String,
        column: usize,
    },
    /// A line that would have been an instruction but has a syntax error
    /// (already reported). It still takes one word so that the addresses of
    /// the labels after it stay right.
    BrokenInstruction,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Line {
    pub labels: Vec<(String, usize)>,
    pub body: Body,
}

/// Parses one comment-free line. Syntax errors are returned beside the
/// line, which keeps whatever could be understood.
pub fn parse_line(text: &str) -> (Line, Option<SyntaxError>) {
    let tokens = tokenize(text);
    let end_column = tokens.last().map_or(1, |t| t.end_column);
    let mut labels = Vec::new();
    let mut pos = 0;
    while pos + 1 < tokens.len() && tokens[pos].ident().is_some() && tokens[pos + 1].is(Punct::Colon) {
        labels.push((tokens[pos].ident().unwrap_or_default().to_string(), tokens[pos].column));
        pos += 2;
    }
    let rest = &tokens[pos..];
    let (body, error) = match parse_body(text, rest, end_column) {
        Ok(body) => (body, None),
        Err((body, e)) => (body, Some(e)),
    };
    (Line { labels, body }, error)
}

type BodyResult = Result<Body, (Body, SyntaxError)>;

fn parse_body(text: &str, tokens: &[Token], end_column: usize) -> BodyResult {
    let Some(first) = tokens.first() else { return Ok(Body::None) };
    let column = first.column;
    match &first.kind {
        TokenKind::Ident(name) if tokens.get(1).is_some_and(|t| t.is(Punct::Equals)) => match whole_expression(&tokens[2..], end_column) {
            Ok(value) => Ok(Body::Constant { name: name.clone(), column, value: Some(value) }),
            Err(e) => Err((Body::Constant { name: name.clone(), column, value: None }, e)),
        },
        TokenKind::Ident(name) => match operands(&tokens[1..], end_column) {
            Ok(operands) => Ok(Body::Instruction { mnemonic: name.clone(), column, operands, end_column }),
            Err(e) => Err((Body::BrokenInstruction, e)),
        },
        TokenKind::Directive(d) if d.eq_ignore_ascii_case("include") => {
            let after = &text[first.end..];
            let file = after.trim();
            let file_column = column + first.end - first.start + (after.chars().count() - after.trim_start().chars().count());
            include_name(file, file_column)
        }
        TokenKind::Directive(d) if d.eq_ignore_ascii_case("db") => raw(&tokens[1..], column, true, end_column),
        TokenKind::Punct(Punct::Hash) => raw(&tokens[1..], column, false, end_column),
        TokenKind::Directive(d) => Err((Body::None, (column, format!("unknown directive '#{d}' (known: #include, #db)")))),
        TokenKind::Number(_) | TokenKind::BadNumber(_) => Err((
            Body::BrokenInstruction,
            (column, "a line starts with an instruction, a label ('Name:') or a constant ('Name = value'), not a number".into()),
        )),
        TokenKind::Bad(c) => Err((Body::BrokenInstruction, (column, format!("unexpected character '{c}'")))),
        TokenKind::Punct(p) => {
            Err((Body::BrokenInstruction, (column, format!("unexpected '{}' at the start of an instruction", punct_text(*p)))))
        }
    }
}

fn include_name(file: &str, column: usize) -> BodyResult {
    if file.is_empty() {
        return Err((Body::None, (column, "#include needs a file name".into())));
    }
    let quoted = |open: char, close: char| file.strip_prefix(open).map(|f| f.strip_suffix(close).ok_or(close));
    let name = match quoted('"', '"').or_else(|| quoted('<', '>')) {
        Some(Ok(name)) => (name, column + 1),
        Some(Err(close)) => return Err((Body::None, (column, format!("missing closing '{close}' after the file name")))),
        None => (file, column),
    };
    if name.0.trim().is_empty() {
        return Err((Body::None, (column, "#include needs a file name".into())));
    }
    Ok(Body::Include { file: name.0.to_string(), column: name.1 })
}

fn raw(tokens: &[Token], column: usize, commas: bool, end_column: usize) -> BodyResult {
    let fields = if commas { operands(tokens, end_column) } else { operands_blank_separated(tokens, end_column) };
    match fields {
        Ok(fields) => Ok(Body::Raw { column, fields, end_column }),
        Err(e) => Err((Body::BrokenInstruction, e)),
    }
}

/// A constant's value: one expression and nothing after it.
fn whole_expression(tokens: &[Token], end_column: usize) -> Result<Expr, SyntaxError> {
    let mut p = ExprParser::new(tokens, 0, false, end_column);
    let e = p.expression()?;
    match tokens.get(p.pos) {
        None => Ok(e),
        Some(t) => Err((t.column, "unexpected text after the value".into())),
    }
}

/// Operand list of an instruction.
pub fn operands(tokens: &[Token], end_column: usize) -> Result<Vec<Expr>, SyntaxError> {
    let blank_separated = !tokens.iter().any(|t| t.is(Punct::Comma));
    parse_operands(tokens, blank_separated, end_column)
}

fn operands_blank_separated(tokens: &[Token], end_column: usize) -> Result<Vec<Expr>, SyntaxError> {
    parse_operands(tokens, true, end_column)
}

fn parse_operands(tokens: &[Token], blank_separated: bool, end_column: usize) -> Result<Vec<Expr>, SyntaxError> {
    let mut out = Vec::new();
    let mut pos = 0;
    while pos < tokens.len() {
        if tokens[pos].is(Punct::Comma) {
            return Err((tokens[pos].column, "missing operand before ','".into()));
        }
        let mut p = ExprParser::new(tokens, pos, blank_separated, end_column);
        out.push(p.expression()?);
        pos = p.pos;
        if let Some(t) = tokens.get(pos) {
            if t.is(Punct::Comma) {
                pos += 1;
                if pos == tokens.len() {
                    return Err((t.column, "missing operand after ','".into()));
                }
            } else if let TokenKind::Punct(p @ (Punct::RightParen | Punct::Colon | Punct::Equals | Punct::Hash)) = t.kind {
                return Err((t.column, format!("unexpected '{}'", punct_text(p))));
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::expr::ExprKind;

    fn names(ops: &[Expr]) -> Vec<String> {
        ops.iter()
            .map(|e| match &e.kind {
                ExprKind::Name(n) => n.clone(),
                ExprKind::Number(v) => v.to_string(),
                ExprKind::Negate(x) => match x.kind {
                    ExprKind::Number(v) => (-v).to_string(),
                    _ => "?".into(),
                },
                _ => "expr".into(),
            })
            .collect()
    }

    fn instruction(text: &str) -> (Vec<(String, usize)>, String, Vec<String>) {
        let (line, err) = parse_line(text);
        assert_eq!(err, None, "{text}");
        match line.body {
            Body::Instruction { mnemonic, operands, .. } => (line.labels, mnemonic, names(&operands)),
            other => panic!("{text}: {other:?}"),
        }
    }

    #[test]
    fn lenient_operand_spellings() {
        assert_eq!(instruction("MVP ABS 2, 10000").2, ["ABS", "2", "10000"]);
        assert_eq!(instruction("WAIT POS , 0 , 0").2, ["POS", "0", "0"]);
        assert_eq!(instruction("JC NZ PosReached1").2, ["NZ", "PosReached1"]);
        assert_eq!(instruction("SIO 255 2 -1").2, ["255", "2", "-1"]);
        assert_eq!(instruction("SAP 4, 0, 2 -1").2, ["4", "0", "expr"]);
        assert_eq!(instruction("RSUB").2, Vec::<String>::new());
    }

    #[test]
    fn labels_before_instructions() {
        let (labels, m, _) = instruction("Label: ROL 0, 1000");
        assert_eq!(labels, [("Label".to_string(), 1)]);
        assert_eq!(m, "ROL");
        let (line, _) = parse_line("Loop :");
        assert_eq!(line.labels, [("Loop".to_string(), 1)]);
        assert_eq!(line.body, Body::None);
    }

    #[test]
    fn constants_includes_and_raw_words() {
        let (line, _) = parse_line("MaxSpeed = 50000");
        assert!(matches!(line.body, Body::Constant { ref name, column: 1, value: Some(_) } if name == "MaxSpeed"));
        assert_eq!(parse_line("#include Interrupts.inc").0.body, Body::Include { file: "Interrupts.inc".into(), column: 10 });
        assert_eq!(parse_line("  #include \"my file.inc\"  ").0.body, Body::Include { file: "my file.inc".into(), column: 13 });
        assert!(matches!(parse_line("#db 138, 1, 0, 1").0.body, Body::Raw { ref fields, .. } if fields.len() == 4));
        assert!(matches!(parse_line("#136 1 0 0").0.body, Body::Raw { ref fields, .. } if fields.len() == 4));
    }

    #[test]
    fn syntax_errors() {
        assert_eq!(parse_line("SAP 4,, 0").1.unwrap().0, 7);
        assert_eq!(parse_line("SAP 4, 0,").1.unwrap().0, 9);
        assert_eq!(parse_line("X =     ").1.unwrap().0, 4);
        assert_eq!(parse_line("X = 1 2").1.unwrap().0, 7);
        assert_eq!(parse_line("#include").1.unwrap().0, 9);
        assert_eq!(parse_line("#include \"a.inc").1.unwrap().0, 10);
        assert!(parse_line("#define X 1").1.unwrap().1.contains("unknown directive"));
        let (line, e) = parse_line("Here: ROL 0 @");
        assert_eq!(line.labels.len(), 1);
        assert_eq!(line.body, Body::BrokenInstruction);
        assert_eq!(e.unwrap().0, 13);
    }
}
