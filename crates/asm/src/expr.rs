//! Integer expressions in operands and constant definitions, and their
//! parser.
//!
//! Precedence, lowest first (as in C): `|`, `^`, `&`, `<< >>`, `+ -`,
//! `* / %`, then the unary operators `-`, `+`, `~` and parentheses. Names
//! stand for constants and labels; the evaluator (`eval.rs`) looks them up.

use crate::lexer::{Punct, Token, TokenKind};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BinaryOp {
    Or,
    Xor,
    And,
    ShiftLeft,
    ShiftRight,
    Add,
    Sub,
    Mul,
    Div,
    Rem,
}

impl BinaryOp {
    /// Every operator, in the order of their discriminants (`op as u8`).
    pub const ALL: [BinaryOp; 10] = [
        BinaryOp::Or,
        BinaryOp::Xor,
        BinaryOp::And,
        BinaryOp::ShiftLeft,
        BinaryOp::ShiftRight,
        BinaryOp::Add,
        BinaryOp::Sub,
        BinaryOp::Mul,
        BinaryOp::Div,
        BinaryOp::Rem,
    ];

    fn of(p: Punct) -> Option<(BinaryOp, u8)> {
        Some(match p {
            Punct::Pipe => (BinaryOp::Or, 1),
            Punct::Caret => (BinaryOp::Xor, 2),
            Punct::Amp => (BinaryOp::And, 3),
            Punct::ShiftLeft => (BinaryOp::ShiftLeft, 4),
            Punct::ShiftRight => (BinaryOp::ShiftRight, 4),
            Punct::Plus => (BinaryOp::Add, 5),
            Punct::Minus => (BinaryOp::Sub, 5),
            Punct::Star => (BinaryOp::Mul, 6),
            Punct::Slash => (BinaryOp::Div, 6),
            Punct::Percent => (BinaryOp::Rem, 6),
            _ => return None,
        })
    }
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ExprKind {
    Number(i64),
    Name(String),
    Negate(Box<Expr>),
    Complement(Box<Expr>),
    /// The operator, its operands, and the operator's column.
    Binary(BinaryOp, Box<Expr>, Box<Expr>, usize),
}

/// An expression and the column where it starts.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Expr {
    pub kind: ExprKind,
    pub column: usize,
}

impl Expr {
    /// The name, when the whole expression is a single name.
    pub fn as_name(&self) -> Option<&str> {
        match &self.kind {
            ExprKind::Name(n) => Some(n),
            _ => None,
        }
    }
}

/// A syntax error: column and message.
pub type SyntaxError = (usize, String);

/// Deepest nesting of parentheses and unary operators, and the most
/// operators one expression may have: enough for any real program, small
/// enough that evaluating never exhausts the stack.
const MAX_DEPTH: usize = 100;
const MAX_NODES: usize = 500;

/// Parses expressions from a token slice.
pub struct ExprParser<'t> {
    tokens: &'t [Token],
    pub pos: usize,
    /// Operands are separated by blanks only (no comma on the line): then
    /// `2 -1` is two operands, `2 - 1` and `2-1` one.
    blank_separated: bool,
    depth: usize,
    nodes: usize,
    end_column: usize,
}

impl<'t> ExprParser<'t> {
    /// `end_column`: the column just after the last token, for "expected an
    /// expression" at the end of a line.
    pub fn new(tokens: &'t [Token], pos: usize, blank_separated: bool, end_column: usize) -> Self {
        ExprParser { tokens, pos, blank_separated, depth: 0, nodes: 0, end_column }
    }

    fn peek(&self) -> Option<&'t Token> {
        self.tokens.get(self.pos)
    }

    fn here(&self) -> usize {
        self.peek().map_or(self.end_column, |t| t.column)
    }

    /// Parses one expression starting at the current token.
    pub fn expression(&mut self) -> Result<Expr, SyntaxError> {
        self.nodes = 0;
        self.binary(1)
    }

    fn count_node(&mut self, column: usize) -> Result<(), SyntaxError> {
        self.nodes += 1;
        if self.nodes > MAX_NODES {
            return Err((column, format!("expression too long (more than {MAX_NODES} operators)")));
        }
        Ok(())
    }

    fn binary(&mut self, min_precedence: u8) -> Result<Expr, SyntaxError> {
        let mut left = self.unary()?;
        while let Some(token) = self.peek() {
            let TokenKind::Punct(p) = token.kind else { break };
            let Some((op, precedence)) = BinaryOp::of(p) else { break };
            if precedence < min_precedence {
                break;
            }
            let starts_new_operand =
                self.blank_separated && matches!(p, Punct::Plus | Punct::Minus) && token.space_before && !token.space_after;
            if starts_new_operand {
                break;
            }
            self.pos += 1;
            self.count_node(token.column)?;
            let right = self.binary(precedence + 1)?;
            let column = left.column;
            left = Expr { kind: ExprKind::Binary(op, Box::new(left), Box::new(right), token.column), column };
        }
        Ok(left)
    }

    fn unary(&mut self) -> Result<Expr, SyntaxError> {
        let Some(token) = self.peek() else {
            return Err((self.end_column, "expected a number, name or expression".into()));
        };
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return Err((token.column, format!("expression nested too deeply (more than {MAX_DEPTH} levels)")));
        }
        let column = token.column;
        let result = match &token.kind {
            TokenKind::Number(v) => {
                self.pos += 1;
                Ok(Expr { kind: ExprKind::Number(*v), column })
            }
            TokenKind::Ident(name) => {
                self.pos += 1;
                Ok(Expr { kind: ExprKind::Name(name.clone()), column })
            }
            TokenKind::Punct(Punct::Minus) => {
                self.pos += 1;
                self.count_node(column)?;
                let inner = self.unary()?;
                Ok(Expr { kind: ExprKind::Negate(Box::new(inner)), column })
            }
            TokenKind::Punct(Punct::Plus) => {
                self.pos += 1;
                self.unary()
            }
            TokenKind::Punct(Punct::Tilde) => {
                self.pos += 1;
                self.count_node(column)?;
                let inner = self.unary()?;
                Ok(Expr { kind: ExprKind::Complement(Box::new(inner)), column })
            }
            TokenKind::Punct(Punct::LeftParen) => {
                self.pos += 1;
                let inner = self.binary(1)?;
                match self.peek() {
                    Some(t) if t.is(Punct::RightParen) => {
                        self.pos += 1;
                        Ok(inner)
                    }
                    _ => Err((self.here(), format!("missing ')' for the '(' at column {column}"))),
                }
            }
            TokenKind::BadNumber(text) => Err((column, format!("'{text}' is not a number"))),
            TokenKind::Bad(c) => Err((column, format!("unexpected character '{c}'"))),
            TokenKind::Directive(d) => Err((column, format!("unexpected '#{d}' inside an expression"))),
            TokenKind::Punct(p) => Err((column, format!("expected a number or name, found '{}'", punct_text(*p)))),
        };
        self.depth -= 1;
        result
    }
}

pub fn punct_text(p: Punct) -> &'static str {
    match p {
        Punct::Comma => ",",
        Punct::Colon => ":",
        Punct::Equals => "=",
        Punct::Hash => "#",
        Punct::Plus => "+",
        Punct::Minus => "-",
        Punct::Star => "*",
        Punct::Slash => "/",
        Punct::Percent => "%",
        Punct::Amp => "&",
        Punct::Pipe => "|",
        Punct::Caret => "^",
        Punct::Tilde => "~",
        Punct::ShiftLeft => "<<",
        Punct::ShiftRight => ">>",
        Punct::LeftParen => "(",
        Punct::RightParen => ")",
    }
}

/// Why a binary operator has no 64-bit result.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ArithmeticError {
    /// The result does not fit in 64 bits.
    Overflow,
    /// A shift by this many bits (outside 0…63).
    Shift(i64),
    /// `/` or `%` by 0.
    DivisionByZero,
}

impl std::fmt::Display for ArithmeticError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ArithmeticError::Overflow => write!(f, "arithmetic overflow in expression"),
            ArithmeticError::Shift(b) => write!(f, "shift by {b} (must be 0...63)"),
            ArithmeticError::DivisionByZero => write!(f, "division by zero"),
        }
    }
}

impl std::error::Error for ArithmeticError {}

/// Applies a binary operator with 64-bit checks.
pub fn apply(op: BinaryOp, a: i64, b: i64) -> Result<i64, ArithmeticError> {
    let overflow = || ArithmeticError::Overflow;
    match op {
        BinaryOp::Or => Ok(a | b),
        BinaryOp::Xor => Ok(a ^ b),
        BinaryOp::And => Ok(a & b),
        BinaryOp::ShiftLeft | BinaryOp::ShiftRight => {
            if !(0..64).contains(&b) {
                return Err(ArithmeticError::Shift(b));
            }
            if op == BinaryOp::ShiftRight {
                Ok(a >> b)
            } else {
                let r = a.checked_shl(b as u32).ok_or_else(overflow)?;
                if r >> b != a { Err(overflow()) } else { Ok(r) }
            }
        }
        BinaryOp::Add => a.checked_add(b).ok_or_else(overflow),
        BinaryOp::Sub => a.checked_sub(b).ok_or_else(overflow),
        BinaryOp::Mul => a.checked_mul(b).ok_or_else(overflow),
        BinaryOp::Div | BinaryOp::Rem => {
            if b == 0 {
                return Err(ArithmeticError::DivisionByZero);
            }
            let r = if op == BinaryOp::Div { a.checked_div(b) } else { a.checked_rem(b) };
            r.ok_or_else(overflow)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lexer::tokenize;

    fn eval(e: &Expr) -> i64 {
        match &e.kind {
            ExprKind::Number(v) => *v,
            ExprKind::Name(_) => 0,
            ExprKind::Negate(x) => -eval(x),
            ExprKind::Complement(x) => !eval(x),
            ExprKind::Binary(op, a, b, _) => apply(*op, eval(a), eval(b)).unwrap(),
        }
    }

    fn parse(text: &str) -> Result<i64, SyntaxError> {
        let tokens = tokenize(text);
        let mut p = ExprParser::new(&tokens, 0, false, text.len() + 1);
        let e = p.expression()?;
        assert_eq!(p.pos, tokens.len(), "{text}");
        Ok(eval(&e))
    }

    #[test]
    fn precedence_like_c() {
        assert_eq!(parse("1 + 2 * 3").unwrap(), 7);
        assert_eq!(parse("(1 + 2) * 3").unwrap(), 9);
        assert_eq!(parse("-2 * -3").unwrap(), 6);
        assert_eq!(parse("1 << 4 | 1").unwrap(), 17);
        assert_eq!(parse("7 % 4 ^ 1 & 3").unwrap(), 2);
        assert_eq!(parse("100 / 7 - -1").unwrap(), 15);
        assert_eq!(parse("~0").unwrap(), -1);
        assert_eq!(parse("$10 + 0x10").unwrap(), 32);
    }

    #[test]
    fn syntax_errors_have_columns() {
        assert_eq!(parse("(1 + 2").unwrap_err().0, 7);
        assert_eq!(parse("1 + ").unwrap_err().0, 5);
        assert_eq!(parse("1 + @").unwrap_err(), (5, "unexpected character '@'".into()));
        let deep = "(".repeat(1000) + "1" + &")".repeat(1000);
        assert!(parse(&deep).unwrap_err().1.contains("nested too deeply"));
        let long = vec!["1"; 2000].join("+");
        assert!(parse(&long).unwrap_err().1.contains("too long"));
    }

    #[test]
    fn operators_by_number() {
        for (i, op) in BinaryOp::ALL.iter().enumerate() {
            assert_eq!(*op as usize, i);
        }
    }

    #[test]
    fn overflow_and_division_are_errors() {
        assert!(apply(BinaryOp::Div, 1, 0).is_err());
        assert!(apply(BinaryOp::Rem, 1, 0).is_err());
        assert!(apply(BinaryOp::Mul, i64::MAX, 2).is_err());
        assert!(apply(BinaryOp::ShiftLeft, 1, 64).is_err());
        assert!(apply(BinaryOp::ShiftLeft, 1, 63).is_err());
        assert_eq!(apply(BinaryOp::ShiftLeft, 1, 62), Ok(1 << 62));
        assert!(apply(BinaryOp::Div, i64::MIN, -1).is_err());
    }
}
