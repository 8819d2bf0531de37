//! The evaluator: the table of labels and constants, and the values of
//! expressions over them.
//!
//! Labels get their addresses in the first pass. Constants are evaluated on
//! first use (or, at the latest, in source order after the first pass), so
//! they may be used before they are defined and may refer to each other and
//! to labels. An error inside a constant's definition is reported once, at
//! the definition; its uses then fail silently.
//!
//! The table stays a small multiple of the source in memory: names are kept
//! once, back to back in one string, with a hash index into them, and a
//! constant's expression is kept compiled into a few bytes per operator
//! (`compile`), not as a tree. Once every constant has its value and
//! nothing is wrong, the table becomes the program's two maps
//! ([`Evaluator::finish_definitions`]), which answer the lookups from then
//! on.

use std::collections::BTreeMap;
use std::hash::{BuildHasher, RandomState};

use crate::diagnostic::{Loc, Reporter, suggestion};
use crate::expr::{ArithmeticError, BinaryOp, Expr, ExprKind, apply};
use crate::limits::MAX_LINE_BYTES;

/// An error that has already been reported.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Reported;

/// How deep evaluation may recurse (expression levels plus constants
/// defined through other constants).
const MAX_DEPTH: usize = 600;

// Names and columns fit into 15 bits (a name or column is at most a line).
const _: () = assert!(MAX_LINE_BYTES < 1 << 15);

/// What an unknown name was expected to be, for the error message.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Expect {
    Label,
    Number,
}

/// A defined name: where it is in the name string, where it was defined
/// (for "already defined at …") and what it is.
#[derive(Clone, Copy, Debug)]
struct Entry {
    name: u32,
    /// The name's length; [`CONSTANT`] marks a constant.
    len: u16,
    column: u16,
    file: u32,
    line: u32,
    /// A label's address, or a constant's number in [`Table::constants`].
    data: u32,
}

const CONSTANT: u16 = 1 << 15;

impl Entry {
    fn is_constant(&self) -> bool {
        self.len & CONSTANT != 0
    }

    fn name_range(&self) -> std::ops::Range<usize> {
        self.name as usize..self.name as usize + (self.len & !CONSTANT) as usize
    }
}

#[derive(Clone, Copy, Debug)]
enum State {
    /// Not evaluated yet; its expression starts here in [`Table::code`].
    Pending(u32),
    Evaluating,
    Done(i64),
    Failed,
}

#[derive(Clone, Copy, Debug)]
struct Constant {
    entry: u32,
    /// The statement that defines it (its errors are reported there).
    seq: u32,
    state: State,
}

/// Labels and constants while the program is read.
#[derive(Debug, Default)]
struct Table {
    /// Every defined name, back to back, in the order of definition.
    names: String,
    /// Open addressing over `entries`: the top 32 bits of a name's hash,
    /// then its entry + 1; 0 for a free slot.
    index: Vec<u64>,
    entries: Vec<Entry>,
    constants: Vec<Constant>,
    /// The compiled expressions of the constants.
    code: Vec<u8>,
    hasher: RandomState,
    /// The entries sorted for suggestions (labels first, then constants,
    /// each by name), made when a suggestion is first needed.
    sorted: Option<Vec<u32>>,
}

/// Room for `more` items in `v`: a quarter more than it holds, so that a
/// table grown item by item stays near its size (a doubling one may be
/// twice as large as needed).
fn reserve<T>(v: &mut Vec<T>, more: usize) {
    if v.capacity() - v.len() < more {
        v.reserve_exact(more.max(v.len() / 4).max(16));
    }
}

fn reserve_text(s: &mut String, more: usize) {
    if s.capacity() - s.len() < more {
        s.reserve_exact(more.max(s.len() / 4).max(64));
    }
}

impl Table {
    fn name(&self, entry: usize) -> &str {
        &self.names[self.entries[entry].name_range()]
    }

    fn hash(&self, name: &str) -> u32 {
        (self.hasher.hash_one(name) >> 32) as u32
    }

    /// The first slot to look at for a hash.
    fn home(&self, hash: u32) -> usize {
        ((u64::from(hash) * self.index.len() as u64) >> 32) as usize
    }

    fn find(&self, name: &str) -> Option<usize> {
        if self.index.is_empty() {
            return None;
        }
        let hash = self.hash(name);
        let mut slot = self.home(hash);
        loop {
            let s = self.index[slot];
            if s == 0 {
                return None;
            }
            let e = (s as u32) as usize - 1;
            if (s >> 32) as u32 == hash && self.name(e) == name {
                return Some(e);
            }
            slot = if slot + 1 == self.index.len() { 0 } else { slot + 1 };
        }
    }

    /// Adds a name that is not in the table yet.
    fn insert(&mut self, name: &str, mut entry: Entry) -> usize {
        // At most three quarters of the slots are taken.
        if (self.entries.len() + 1) * 4 > self.index.len() * 3 {
            let size = (self.index.len() + self.index.len() / 4).max(64);
            let old = std::mem::replace(&mut self.index, vec![0; size]);
            for s in old.into_iter().filter(|&s| s != 0) {
                let slot = self.home((s >> 32) as u32);
                place(&mut self.index, slot, s);
            }
        }
        reserve_text(&mut self.names, name.len());
        entry.name = self.names.len() as u32;
        entry.len |= name.len() as u16;
        self.names.push_str(name);
        reserve(&mut self.entries, 1);
        self.entries.push(entry);
        let hash = self.hash(name);
        let slot = self.home(hash);
        place(&mut self.index, slot, u64::from(hash) << 32 | self.entries.len() as u64);
        self.sorted = None;
        self.entries.len() - 1
    }

    fn loc_of(&self, constant: usize) -> Loc {
        let c = &self.constants[constant];
        let e = &self.entries[c.entry as usize];
        Loc { seq: c.seq as usize, file: e.file as usize, line: e.line as usize }
    }

    /// Every name, labels first, then constants, each sorted.
    fn sorted_names(&mut self) -> impl Iterator<Item = &str> {
        if self.sorted.is_none() {
            let mut order: Vec<u32> = (0..self.entries.len() as u32).collect();
            order.sort_unstable_by(|&a, &b| {
                let key = |e: u32| (self.entries[e as usize].is_constant(), self.name(e as usize));
                key(a).cmp(&key(b))
            });
            self.sorted = Some(order);
        }
        let this = &*self;
        this.sorted.iter().flatten().map(move |&e| this.name(e as usize))
    }

    /// The program's maps: labels → address, constants → value (those that
    /// have one). The table is taken apart from its end while the maps
    /// grow, so that the two are not both whole at once.
    fn into_maps(self) -> (BTreeMap<String, u32>, BTreeMap<String, i64>) {
        let Table { mut names, mut entries, mut constants, .. } = self;
        let mut labels = BTreeMap::new();
        let mut values = BTreeMap::new();
        let part = entries.len() / 8 + 1;
        while !entries.is_empty() {
            let (mut some_labels, mut some_values) = (BTreeMap::new(), BTreeMap::new());
            for _ in 0..part {
                let Some(e) = entries.pop() else { break };
                let name = names[e.name_range()].to_string();
                names.truncate(e.name as usize);
                if !e.is_constant() {
                    some_labels.insert(name, e.data);
                } else if let State::Done(v) = constants[e.data as usize].state {
                    some_values.insert(name, v);
                }
                if e.is_constant() {
                    constants.truncate(e.data as usize);
                }
            }
            entries.shrink_to_fit();
            names.shrink_to_fit();
            constants.shrink_to_fit();
            // Appending rebuilds a map with full nodes: inserted one by one,
            // its nodes would be half empty.
            labels.append(&mut some_labels);
            values.append(&mut some_values);
        }
        (labels, values)
    }
}

/// Puts a slot's value into the first free slot from `slot` on.
fn place(index: &mut [u64], mut slot: usize, value: u64) {
    while index[slot] != 0 {
        slot = if slot + 1 == index.len() { 0 } else { slot + 1 };
    }
    index[slot] = value;
}

/// Where the names are looked up.
#[derive(Debug)]
enum Names {
    Table(Table),
    /// Every constant has its value and nothing is wrong: the program's
    /// own maps.
    Maps {
        labels: BTreeMap<String, u32>,
        constants: BTreeMap<String, i64>,
    },
}

/// What a definition defines.
#[derive(Clone, Copy)]
enum Defined {
    /// A label at this address.
    Label(u32),
    /// The constant of this number.
    Constant(u32),
}

/// What a name is.
enum Found {
    Value(i64),
    /// A constant of the table, by number.
    Constant(usize),
    Unknown,
}

#[derive(Debug)]
pub struct Evaluator {
    names: Names,
    /// Constants being evaluated, outermost first (to name a cycle).
    evaluating: Vec<u32>,
    depth: usize,
    /// The compiled form of the expression being evaluated.
    scratch: Vec<u8>,
}

impl Default for Evaluator {
    fn default() -> Evaluator {
        Evaluator { names: Names::Table(Table::default()), evaluating: Vec::new(), depth: 0, scratch: Vec::new() }
    }
}

impl Evaluator {
    pub fn new() -> Evaluator {
        Evaluator::default()
    }

    fn find(&self, name: &str) -> Found {
        match &self.names {
            Names::Table(t) => match t.find(name) {
                Some(e) if t.entries[e].is_constant() => Found::Constant(t.entries[e].data as usize),
                Some(e) => Found::Value(i64::from(t.entries[e].data)),
                None => Found::Unknown,
            },
            Names::Maps { labels, constants } => match (labels.get(name), constants.get(name)) {
                (Some(&address), _) => Found::Value(i64::from(address)),
                (_, Some(&value)) => Found::Value(value),
                _ => Found::Unknown,
            },
        }
    }

    pub fn is_defined(&self, name: &str) -> bool {
        !matches!(self.find(name), Found::Unknown)
    }

    /// Adds a definition, or reports the name's earlier one.
    fn define(&mut self, name: &str, what: Defined, loc: Loc, column: usize, reporter: &mut Reporter) -> Option<usize> {
        let Names::Table(t) = &mut self.names else { return None };
        if let Some(e) = t.find(name) {
            let first = t.entries[e];
            let kind = if first.is_constant() { "constant" } else { "label" };
            let file = reporter.files.get(first.file as usize).cloned();
            reporter.error_with(loc, column, |_| {
                let new = match what {
                    Defined::Label(_) => "label",
                    Defined::Constant(_) => "constant",
                };
                let place = format!("{}:{}:{}", file.as_deref().unwrap_or(""), first.line, first.column);
                format!("duplicate {new} '{name}' (already defined as a {kind} at {place})")
            });
            return None;
        }
        let (len, data) = match what {
            Defined::Label(address) => (0, address),
            Defined::Constant(number) => (CONSTANT, number),
        };
        let entry = Entry { name: 0, len, column: column as u16, file: loc.file as u32, line: loc.line as u32, data };
        Some(t.insert(name, entry))
    }

    pub fn define_label(&mut self, name: &str, address: u32, loc: Loc, column: usize, reporter: &mut Reporter) {
        self.define(name, Defined::Label(address), loc, column, reporter);
    }

    pub fn define_constant(&mut self, name: &str, value: Option<Expr>, loc: Loc, column: usize, reporter: &mut Reporter) {
        let number = match &self.names {
            Names::Table(t) => t.constants.len() as u32,
            Names::Maps { .. } => return,
        };
        let Some(entry) = self.define(name, Defined::Constant(number), loc, column, reporter) else { return };
        let Names::Table(t) = &mut self.names else { return };
        let state = match &value {
            Some(expr) => {
                self.scratch.clear();
                compile(expr, &mut self.scratch);
                reserve(&mut t.code, self.scratch.len());
                let start = t.code.len() as u32;
                t.code.extend_from_slice(&self.scratch);
                State::Pending(start)
            }
            None => State::Failed,
        };
        reserve(&mut t.constants, 1);
        t.constants.push(Constant { entry: entry as u32, seq: loc.seq as u32, state });
    }

    /// Evaluates every constant not evaluated yet, in source order, so
    /// that errors in unused constants are reported too.
    pub fn evaluate_constants(&mut self, reporter: &mut Reporter) {
        let Names::Table(t) = &mut self.names else { return };
        // Every expression is evaluated now: their code is not needed after.
        let code = std::mem::take(&mut t.code);
        let count = t.constants.len();
        for number in 0..count {
            let _ = self.constant(&code, number, reporter);
        }
    }

    /// Once every constant is evaluated and nothing is wrong, the table
    /// becomes the program's maps, which are smaller.
    pub fn finish_definitions(&mut self) {
        if let Names::Table(t) = &mut self.names {
            let (labels, constants) = std::mem::take(t).into_maps();
            self.names = Names::Maps { labels, constants };
        }
    }

    /// Label → address and constant → value (constants with a value).
    pub fn into_maps(self) -> (BTreeMap<String, u32>, BTreeMap<String, i64>) {
        match self.names {
            Names::Table(t) => t.into_maps(),
            Names::Maps { labels, constants } => (labels, constants),
        }
    }

    /// The value of an expression at `loc`.
    pub fn eval(&mut self, expr: &Expr, loc: Loc, expect: Expect, reporter: &mut Reporter) -> Result<i64, Reported> {
        let mut scratch = std::mem::take(&mut self.scratch);
        scratch.clear();
        compile(expr, &mut scratch);
        let code = match &mut self.names {
            Names::Table(t) => std::mem::take(&mut t.code),
            Names::Maps { .. } => Vec::new(),
        };
        let mut pos = 0;
        let result = self.node(&code, &scratch, &mut pos, loc, expect, reporter);
        if let Names::Table(t) = &mut self.names {
            t.code = code;
        }
        self.scratch = scratch;
        result
    }

    /// Evaluates the expression at `pos` in `code` and moves `pos` past it,
    /// whatever the outcome. `constants` holds the compiled constants.
    fn node(
        &mut self,
        constants: &[u8],
        code: &[u8],
        pos: &mut usize,
        loc: Loc,
        expect: Expect,
        reporter: &mut Reporter,
    ) -> Result<i64, Reported> {
        self.depth += 1;
        let result = self.node_inner(constants, code, pos, loc, expect, reporter);
        self.depth -= 1;
        result
    }

    fn node_inner(
        &mut self,
        constants: &[u8],
        code: &[u8],
        pos: &mut usize,
        loc: Loc,
        expect: Expect,
        reporter: &mut Reporter,
    ) -> Result<i64, Reported> {
        let start = *pos;
        let node = Node::read(code, pos);
        if self.depth > MAX_DEPTH {
            reporter.error(
                loc,
                node.column,
                format!("expression nested too deeply (more than {MAX_DEPTH} levels, counting constants defined through other constants)"),
            );
            *pos = start;
            Node::skip(code, pos);
            return Err(Reported);
        }
        let fail = |reporter: &mut Reporter, column: usize, message: String| {
            reporter.error(loc, column, message);
            Err(Reported)
        };
        match node.kind {
            Kind::Number(v) => Ok(v),
            Kind::Name(name) => self.name(constants, name, loc, node.column, expect, reporter),
            Kind::Negate => {
                let v = self.node(constants, code, pos, loc, expect, reporter)?;
                v.checked_neg().map_or_else(|| fail(reporter, node.column, ArithmeticError::Overflow.to_string()), Ok)
            }
            Kind::Complement => Ok(!self.node(constants, code, pos, loc, expect, reporter)?),
            Kind::Binary(op, operator_column) => {
                let a = self.node(constants, code, pos, loc, expect, reporter);
                let b = self.node(constants, code, pos, loc, expect, reporter);
                let (a, b) = (a?, b?);
                apply(op, a, b).or_else(|e| fail(reporter, operator_column, e.to_string()))
            }
        }
    }

    fn name(
        &mut self,
        constants: &[u8],
        name: &str,
        loc: Loc,
        column: usize,
        expect: Expect,
        reporter: &mut Reporter,
    ) -> Result<i64, Reported> {
        match self.find(name) {
            Found::Value(v) => Ok(v),
            Found::Constant(number) => {
                let Names::Table(t) = &self.names else { return Err(Reported) };
                if matches!(t.constants[number].state, State::Evaluating) {
                    let start = self.evaluating.iter().position(|&n| n as usize == number).unwrap_or(0);
                    let chain = &self.evaluating[start..];
                    reporter.error_with(loc, column, |_| {
                        let mut names: Vec<&str> = chain.iter().map(|&n| t.name(t.constants[n as usize].entry as usize)).collect();
                        names.push(name);
                        format!("constant '{name}' is defined through itself ({})", names.join(" -> "))
                    });
                    return Err(Reported);
                }
                self.constant(constants, number, reporter)
            }
            Found::Unknown => {
                let what = match expect {
                    Expect::Label => "label",
                    Expect::Number => "constant or label",
                };
                let names = &mut self.names;
                reporter.error_with(loc, column, |budget| {
                    let hint = match names {
                        Names::Table(t) => suggestion(name, t.sorted_names(), budget),
                        Names::Maps { labels, constants } => {
                            suggestion(name, labels.keys().chain(constants.keys()).map(String::as_str), budget)
                        }
                    };
                    format!("unknown {what} '{name}'{hint}")
                });
                Err(Reported)
            }
        }
    }

    fn constant(&mut self, constants: &[u8], number: usize, reporter: &mut Reporter) -> Result<i64, Reported> {
        let Names::Table(t) = &mut self.names else { return Err(Reported) };
        let Some(c) = t.constants.get_mut(number) else { return Err(Reported) };
        let start = match c.state {
            State::Done(v) => return Ok(v),
            State::Failed | State::Evaluating => return Err(Reported),
            State::Pending(start) => start,
        };
        c.state = State::Evaluating;
        let loc = t.loc_of(number);
        self.evaluating.push(number as u32);
        let mut pos = start as usize;
        let result = self.node(constants, constants, &mut pos, loc, Expect::Number, reporter);
        self.evaluating.pop();
        if let Names::Table(t) = &mut self.names {
            t.constants[number].state = match result {
                Ok(v) => State::Done(v),
                Err(_) => State::Failed,
            };
        }
        result
    }

    /// Every constant that has a value.
    #[cfg(test)]
    pub fn constant_values(&self) -> BTreeMap<String, i64> {
        match &self.names {
            Names::Table(t) => t
                .constants
                .iter()
                .filter_map(|c| match c.state {
                    State::Done(v) => Some((t.name(c.entry as usize).to_string(), v)),
                    _ => None,
                })
                .collect(),
            Names::Maps { constants, .. } => constants.clone(),
        }
    }
}

// The compiled form of an expression: its nodes in prefix order (a node,
// then its operands), each a tag byte and its fields as variable-length
// numbers (7 bits a byte), so `1 + 2` takes 3 bytes per node.
const NUMBER: u8 = 0;
const NAME: u8 = 1;
const NEGATE: u8 = 2;
const COMPLEMENT: u8 = 3;
/// Followed by the operator's number.
const BINARY: u8 = 4;

fn put(out: &mut Vec<u8>, mut v: u64) {
    while v >= 0x80 {
        out.push(v as u8 | 0x80);
        v >>= 7;
    }
    out.push(v as u8);
}

fn get(code: &[u8], pos: &mut usize) -> u64 {
    let mut v = 0u64;
    let mut shift = 0;
    while let Some(&b) = code.get(*pos) {
        *pos += 1;
        v |= u64::from(b & 0x7f).checked_shl(shift).unwrap_or(0);
        shift += 7;
        if b < 0x80 {
            break;
        }
    }
    v
}

fn compile(expr: &Expr, out: &mut Vec<u8>) {
    let column = expr.column as u64;
    match &expr.kind {
        ExprKind::Number(v) => {
            out.push(NUMBER);
            put(out, column);
            // Zigzag: small negative numbers stay short.
            put(out, ((v << 1) ^ (v >> 63)) as u64);
        }
        ExprKind::Name(name) => {
            out.push(NAME);
            put(out, column);
            put(out, name.len() as u64);
            out.extend_from_slice(name.as_bytes());
        }
        ExprKind::Negate(inner) | ExprKind::Complement(inner) => {
            out.push(if matches!(expr.kind, ExprKind::Negate(_)) { NEGATE } else { COMPLEMENT });
            put(out, column);
            compile(inner, out);
        }
        ExprKind::Binary(op, a, b, operator_column) => {
            out.push(BINARY + *op as u8);
            put(out, column);
            put(out, *operator_column as u64);
            compile(a, out);
            compile(b, out);
        }
    }
}

/// One compiled node.
struct Node<'c> {
    column: usize,
    kind: Kind<'c>,
}

enum Kind<'c> {
    Number(i64),
    Name(&'c str),
    Negate,
    Complement,
    /// The operator and its column.
    Binary(BinaryOp, usize),
}

impl<'c> Node<'c> {
    fn read(code: &'c [u8], pos: &mut usize) -> Node<'c> {
        let tag = code.get(*pos).copied().unwrap_or(NUMBER);
        *pos += 1;
        let column = get(code, pos) as usize;
        let kind = match tag {
            NUMBER => {
                let z = get(code, pos);
                Kind::Number(((z >> 1) as i64) ^ -((z & 1) as i64))
            }
            NAME => {
                let len = get(code, pos) as usize;
                let end = (*pos + len).min(code.len());
                let name = std::str::from_utf8(&code[(*pos).min(end)..end]).unwrap_or_default();
                *pos = end;
                Kind::Name(name)
            }
            NEGATE => Kind::Negate,
            COMPLEMENT => Kind::Complement,
            _ => {
                let operator_column = get(code, pos) as usize;
                let op = BinaryOp::ALL.get((tag - BINARY) as usize).copied().unwrap_or(BinaryOp::Or);
                Kind::Binary(op, operator_column)
            }
        };
        Node { column, kind }
    }

    /// Moves `pos` past the node there and its operands.
    fn skip(code: &[u8], pos: &mut usize) {
        let mut pending = 1usize;
        while pending > 0 && *pos < code.len() {
            pending -= 1;
            pending += match Node::read(code, pos).kind {
                Kind::Number(_) | Kind::Name(_) => 0,
                Kind::Negate | Kind::Complement => 1,
                Kind::Binary(..) => 2,
            };
        }
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
