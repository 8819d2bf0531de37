//! The evaluator: the table of labels and constants, and the values of
//! expressions over them.
//!
//! Labels get their addresses in the first pass. Constants are evaluated on
//! first use (or, at the latest, in source order after the first pass), so
//! they may be used before they are defined and may refer to each other and
//! to labels. An error inside a constant's definition is reported once, at
//! the definition; its uses then fail silently.

use std::collections::{BTreeMap, HashMap};

use crate::diagnostic::{Loc, Reporter, suggestion};
use crate::expr::{Expr, ExprKind, apply};

/// An error that has already been reported.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Reported;

/// How deep evaluation may recurse (expression levels plus constants
/// defined through other constants).
const MAX_DEPTH: usize = 600;

#[derive(Clone, Debug)]
struct Label {
    address: u32,
    loc: Loc,
    column: usize,
}

#[derive(Clone, Debug)]
enum State {
    Pending,
    Evaluating,
    Done(i64),
    Failed,
}

#[derive(Clone, Debug)]
struct Constant {
    value: Option<Expr>,
    loc: Loc,
    column: usize,
    state: State,
}

/// What an unknown name was expected to be, for the error message.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Expect {
    Label,
    Number,
}

#[derive(Debug, Default)]
pub struct Evaluator {
    labels: HashMap<String, Label>,
    constants: HashMap<String, Constant>,
    constant_order: Vec<String>,
    /// Constants being evaluated, outermost first (to name a cycle).
    evaluating: Vec<String>,
    depth: usize,
}

impl Evaluator {
    pub fn new() -> Evaluator {
        Evaluator::default()
    }

    pub fn is_defined(&self, name: &str) -> bool {
        self.labels.contains_key(name) || self.constants.contains_key(name)
    }

    fn first_definition(&self, name: &str, reporter: &Reporter) -> Option<String> {
        if let Some(l) = self.labels.get(name) {
            return Some(format!("label at {}", reporter.place(l.loc, l.column)));
        }
        self.constants.get(name).map(|c| format!("constant at {}", reporter.place(c.loc, c.column)))
    }

    pub fn define_label(&mut self, name: &str, address: u32, loc: Loc, column: usize, reporter: &mut Reporter) {
        if let Some(first) = self.first_definition(name, reporter) {
            reporter.error(loc, column, format!("duplicate label '{name}' (already defined as a {first})"));
            return;
        }
        self.labels.insert(name.to_string(), Label { address, loc, column });
    }

    pub fn define_constant(&mut self, name: &str, value: Option<Expr>, loc: Loc, column: usize, reporter: &mut Reporter) {
        if let Some(first) = self.first_definition(name, reporter) {
            reporter.error(loc, column, format!("duplicate constant '{name}' (already defined as a {first})"));
            return;
        }
        let state = if value.is_some() { State::Pending } else { State::Failed };
        self.constants.insert(name.to_string(), Constant { value, loc, column, state });
        self.constant_order.push(name.to_string());
    }

    /// Evaluates every constant not evaluated yet, in source order, so
    /// that errors in unused constants are reported too.
    pub fn evaluate_constants(&mut self, reporter: &mut Reporter) {
        for name in self.constant_order.clone() {
            let _ = self.constant(&name, reporter);
        }
    }

    /// The value of an expression at `loc`.
    pub fn eval(&mut self, expr: &Expr, loc: Loc, expect: Expect, reporter: &mut Reporter) -> Result<i64, Reported> {
        self.depth += 1;
        let result = self.eval_inner(expr, loc, expect, reporter);
        self.depth -= 1;
        result
    }

    fn eval_inner(&mut self, expr: &Expr, loc: Loc, expect: Expect, reporter: &mut Reporter) -> Result<i64, Reported> {
        if self.depth > MAX_DEPTH {
            reporter.error(
                loc,
                expr.column,
                format!("expression nested too deeply (more than {MAX_DEPTH} levels, counting constants defined through other constants)"),
            );
            return Err(Reported);
        }
        let fail = |reporter: &mut Reporter, column: usize, message: String| {
            reporter.error(loc, column, message);
            Err(Reported)
        };
        match &expr.kind {
            ExprKind::Number(v) => Ok(*v),
            ExprKind::Name(name) => self.name(name, loc, expr.column, expect, reporter),
            ExprKind::Negate(inner) => {
                let v = self.eval(inner, loc, expect, reporter)?;
                v.checked_neg().map_or_else(|| fail(reporter, expr.column, "arithmetic overflow in expression".into()), Ok)
            }
            ExprKind::Complement(inner) => Ok(!self.eval(inner, loc, expect, reporter)?),
            ExprKind::Binary(op, a, b, operator_column) => {
                let a = self.eval(a, loc, expect, reporter);
                let b = self.eval(b, loc, expect, reporter);
                let (a, b) = (a?, b?);
                apply(*op, a, b).or_else(|message| fail(reporter, *operator_column, message))
            }
        }
    }

    fn name(&mut self, name: &str, loc: Loc, column: usize, expect: Expect, reporter: &mut Reporter) -> Result<i64, Reported> {
        if let Some(label) = self.labels.get(name) {
            return Ok(label.address as i64);
        }
        if self.constants.contains_key(name) {
            if self.evaluating.iter().any(|n| n == name) {
                let start = self.evaluating.iter().position(|n| n == name).unwrap_or(0);
                let mut chain: Vec<&str> = self.evaluating[start..].iter().map(String::as_str).collect();
                chain.push(name);
                reporter.error(loc, column, format!("constant '{name}' is defined through itself ({})", chain.join(" -> ")));
                return Err(Reported);
            }
            return self.constant(name, reporter);
        }
        let what = match expect {
            Expect::Label => "label",
            Expect::Number => "constant or label",
        };
        let (labels, constants) = (&self.labels, &self.constants);
        reporter.error_with(loc, column, |budget| {
            // Of equally close names, labels come first, each by name.
            let mut label_names: Vec<&str> = labels.keys().map(String::as_str).collect();
            let mut constant_names: Vec<&str> = constants.keys().map(String::as_str).collect();
            label_names.sort_unstable();
            constant_names.sort_unstable();
            let candidates = label_names.into_iter().chain(constant_names);
            format!("unknown {what} '{name}'{}", suggestion(name, candidates, budget))
        });
        Err(Reported)
    }

    fn constant(&mut self, name: &str, reporter: &mut Reporter) -> Result<i64, Reported> {
        let Some(c) = self.constants.get_mut(name) else { return Err(Reported) };
        match c.state {
            State::Done(v) => return Ok(v),
            State::Failed | State::Evaluating => return Err(Reported),
            State::Pending => {}
        }
        c.state = State::Evaluating;
        let (value, loc) = (c.value.take(), c.loc);
        self.evaluating.push(name.to_string());
        let result = match &value {
            Some(expr) => self.eval(expr, loc, Expect::Number, reporter),
            None => Err(Reported),
        };
        self.evaluating.pop();
        if let Some(c) = self.constants.get_mut(name) {
            c.value = value;
            c.state = match result {
                Ok(v) => State::Done(v),
                Err(_) => State::Failed,
            };
        }
        result
    }

    /// Every constant that has a value.
    pub fn constant_values(&self) -> BTreeMap<String, i64> {
        self.constants
            .iter()
            .filter_map(|(n, c)| match c.state {
                State::Done(v) => Some((n.clone(), v)),
                _ => None,
            })
            .collect()
    }

    pub fn label_addresses(&self) -> BTreeMap<String, u32> {
        self.labels.iter().map(|(n, l)| (n.clone(), l.address)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::parser::{Body, parse_line};

    fn expr(text: &str) -> Expr {
        match parse_line(&format!("X = {text}")).0.body {
            Body::Constant { value: Some(e), .. } => e,
            other => panic!("{other:?}"),
        }
    }

    fn setup() -> (Evaluator, Reporter) {
        let mut r = Reporter::default();
        r.add_file("t.tmc");
        (Evaluator::new(), r)
    }

    fn at(line: usize) -> Loc {
        Loc { seq: line, file: 0, line }
    }

    #[test]
    fn constants_before_and_after_use() {
        let (mut ev, mut r) = setup();
        ev.define_constant("A", Some(expr("B * 2")), at(1), 1, &mut r);
        ev.define_label("Loop", 7, at(2), 1, &mut r);
        ev.define_constant("B", Some(expr("Loop + 1")), at(3), 1, &mut r);
        assert_eq!(ev.eval(&expr("A - 1"), at(4), Expect::Number, &mut r), Ok(15));
        ev.evaluate_constants(&mut r);
        assert!(r.is_empty());
        assert_eq!(ev.constant_values().get("B"), Some(&8));
    }

    #[test]
    fn cycles_and_unknown_names_reported_once() {
        let (mut ev, mut r) = setup();
        ev.define_constant("A", Some(expr("B + 1")), at(1), 1, &mut r);
        ev.define_constant("B", Some(expr("A + 1")), at(2), 1, &mut r);
        ev.define_constant("C", Some(expr("Lop")), at(3), 1, &mut r);
        ev.define_label("Loop", 0, at(4), 1, &mut r);
        ev.evaluate_constants(&mut r);
        assert!(ev.eval(&expr("A + C"), at(5), Expect::Number, &mut r).is_err());
        let d = r.finish();
        assert_eq!(d.len(), 2, "{d:?}");
        assert!(d[0].message.contains("A -> B -> A"), "{}", d[0]);
        assert_eq!(d[1].message, "unknown constant or label 'Lop' (did you mean 'Loop'?)");
    }

    #[test]
    fn duplicates() {
        let (mut ev, mut r) = setup();
        ev.define_label("Loop", 0, at(1), 1, &mut r);
        ev.define_label("Loop", 3, at(2), 1, &mut r);
        ev.define_constant("Loop", Some(expr("1")), at(3), 1, &mut r);
        let d = r.finish();
        assert_eq!(d[0].to_string(), "t.tmc:2:1: error: duplicate label 'Loop' (already defined as a label at t.tmc:1:1)");
        assert!(d[1].message.starts_with("duplicate constant 'Loop'"));
    }

    #[test]
    fn long_constant_chains_stop_without_overflowing_the_stack() {
        let (mut ev, mut r) = setup();
        for i in 0..5000 {
            ev.define_constant(&format!("C{i}"), Some(expr(&format!("C{} + 1", i + 1))), at(i + 1), 1, &mut r);
        }
        ev.define_constant("C5000", Some(expr("0")), at(5001), 1, &mut r);
        ev.evaluate_constants(&mut r);
        assert!(!r.is_empty());
    }
}
