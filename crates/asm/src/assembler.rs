//! The assembler driver: reads the source and its includes into one list
//! of statements, gives labels their addresses (pass 1), then evaluates
//! constants and encodes and checks every instruction (pass 2).

use std::collections::HashSet;

use tmclsim_profile::Profile;
use tmclsim_protocol::{Instruction, opcode as op};

use crate::Program;
use crate::check::check;
use crate::diagnostic::{Diagnostic, Loc, Reporter};
use crate::encoder::{encode, encode_raw};
use crate::eval::Evaluator;
use crate::include::{IncludeResolver, built_in};
use crate::lexer::strip_comments;
use crate::limits::{MAX_LINE_BYTES, MAX_STATEMENTS, MAX_TOTAL_SOURCE_BYTES};
use crate::parser::{Body, parse_line};
use crate::source_map::SourceLine;

/// How deeply includes may nest (a cycle is reported before this).
const MAX_INCLUDE_DEPTH: usize = 64;

/// One source line that holds something, with where it came from.
struct Statement {
    loc: Loc,
    labels: Vec<(String, usize)>,
    body: Body,
    /// The line without its comment, for the source map.
    text: String,
}

/// Reads a file and, recursively, the files it includes.
struct Loader<'r> {
    resolver: &'r dyn IncludeResolver,
    reporter: Reporter,
    statements: Vec<Statement>,
    /// Keys and names of the files being read, outermost first.
    stack: Vec<(String, String)>,
    /// Keys of every file read so far (each file is read once).
    seen: HashSet<String>,
    /// Bytes of source read so far.
    loaded: usize,
    /// The statement limit was reached: nothing more is read.
    full: bool,
}

impl Loader<'_> {
    fn next_loc(&self, file: usize, line: usize) -> Loc {
        Loc { seq: self.statements.len(), file, line }
    }

    fn load(&mut self, key: String, name: &str, text: &str) {
        let file = self.reporter.add_file(name);
        self.seen.insert(key.clone());
        self.loaded += text.len();
        if self.loaded > MAX_TOTAL_SOURCE_BYTES {
            let loc = self.next_loc(file, 0);
            return self.reporter.error(
                loc,
                0,
                format!("the sources pass {} MiB, the limit of one assembly", MAX_TOTAL_SOURCE_BYTES >> 20),
            );
        }
        self.stack.push((key, name.to_string()));
        let (lines, unterminated, too_long) = strip_comments(text, MAX_LINE_BYTES);
        for (index, line) in lines.iter().enumerate() {
            if self.full {
                break;
            }
            let number = index + 1;
            if too_long.binary_search(&number).is_ok() {
                let loc = self.next_loc(file, number);
                self.reporter.error(loc, 1, format!("line longer than {MAX_LINE_BYTES} bytes"));
                continue;
            }
            let (parsed, error) = parse_line(line);
            let loc = self.next_loc(file, number);
            if let Some((column, message)) = error {
                self.reporter.error(loc, column, message);
            }
            if parsed.labels.is_empty() && parsed.body == Body::None {
                continue;
            }
            let include = match &parsed.body {
                Body::Include { file, column } => Some((file.clone(), *column)),
                _ => None,
            };
            if self.statements.len() == MAX_STATEMENTS {
                self.reporter.error(loc, 1, format!("more than {MAX_STATEMENTS} statements, the limit of one assembly"));
                self.full = true;
                break;
            }
            self.statements.push(Statement { loc, labels: parsed.labels, body: parsed.body, text: line.trim().to_string() });
            if let Some((wanted, column)) = include {
                self.include(name, &wanted, loc, column);
            }
        }
        if let Some(open) = unterminated {
            let loc = self.next_loc(file, open.line);
            self.reporter.error(loc, open.column, "comment '/*' is never closed with '*/'");
        }
        self.stack.pop();
    }

    fn include(&mut self, from: &str, wanted: &str, loc: Loc, column: usize) {
        let found = match self.resolver.resolve(from, wanted) {
            Ok(f) => f,
            Err(message) => match built_in(wanted) {
                Some(f) => f,
                None => {
                    let shipped: Vec<&str> = crate::include::BUILT_IN.iter().map(|(n, _)| *n).collect();
                    let hint = format!(
                        "; the include files shipped with tmclsim are {} (their names: crates/asm/README.md)",
                        shipped.join(" and ")
                    );
                    return self.reporter.error(loc, column, format!("{message}{hint}"));
                }
            },
        };
        if let Some(start) = self.stack.iter().position(|(key, _)| *key == found.key) {
            let mut chain: Vec<&str> = self.stack[start..].iter().map(|(_, n)| n.as_str()).collect();
            chain.push(&found.name);
            let message = if chain.len() == 2 {
                format!("'{}' includes itself", found.name)
            } else {
                format!("include cycle: {}", chain.join(" -> "))
            };
            return self.reporter.error(loc, column, message);
        }
        if self.seen.contains(&found.key) {
            return;
        }
        if self.stack.len() >= MAX_INCLUDE_DEPTH {
            return self.reporter.error(loc, column, format!("includes nested more than {MAX_INCLUDE_DEPTH} deep"));
        }
        self.load(found.key, &found.name, &found.text);
    }
}

/// Assembles a TMCL source text. `file_name` names it in diagnostics and
/// is the base for relative `#include`s. With a profile, every instruction
/// is also checked against that module.
pub fn assemble(
    source: &str,
    file_name: &str,
    resolver: &dyn IncludeResolver,
    profile: Option<&Profile>,
) -> Result<Program, Vec<Diagnostic>> {
    let mut loader = Loader {
        resolver,
        reporter: Reporter::default(),
        statements: Vec::new(),
        stack: Vec::new(),
        seen: HashSet::new(),
        loaded: 0,
        full: false,
    };
    loader.load(resolver.key(file_name), file_name, source);
    let Loader { mut reporter, statements, .. } = loader;
    let mut evaluator = Evaluator::new();

    // Pass 1: addresses of labels, definitions of constants.
    let mut address: u32 = 0;
    for st in &statements {
        for (name, column) in &st.labels {
            evaluator.define_label(name, address, st.loc, *column, &mut reporter);
        }
        match &st.body {
            Body::Constant { name, column, value } => evaluator.define_constant(name, value.clone(), st.loc, *column, &mut reporter),
            Body::Instruction { mnemonic, column, operands, .. } => {
                // A lone unknown word is most likely a label without its
                // colon: the error says so, and defining it here keeps its
                // uses from being reported too.
                if operands.is_empty() && op::from_mnemonic(mnemonic).is_none() && !evaluator.is_defined(mnemonic) {
                    evaluator.define_label(mnemonic, address, st.loc, *column, &mut reporter);
                }
                address += 1;
            }
            Body::Raw { .. } | Body::BrokenInstruction => address += 1,
            Body::None | Body::Include { .. } => {}
        }
    }

    // Pass 2: values of constants, then the instructions.
    evaluator.evaluate_constants(&mut reporter);
    if reporter.is_empty() {
        evaluator.finish_definitions();
    }
    let mut instructions = Vec::new();
    let mut source_map = Vec::new();
    for st in &statements {
        let word = match &st.body {
            Body::Instruction { mnemonic, column, operands, end_column } => {
                let encoded = encode(mnemonic, *column, operands, *end_column, st.loc, &mut evaluator, &mut reporter);
                if let (Ok(e), Some(profile)) = (&encoded, profile) {
                    for (column, message) in check(e, profile) {
                        reporter.error(st.loc, column, message);
                    }
                }
                encoded.map(|e| e.instruction).unwrap_or_default()
            }
            Body::Raw { fields, end_column, column } => {
                let word = encode_raw(fields, *end_column, st.loc, &mut evaluator, &mut reporter).unwrap_or_default();
                if profile.is_some() && op::is_control(word.opcode) {
                    let message = format!(
                        "control command {} ({}) cannot be stored in a program: during download the module executes it",
                        word.opcode,
                        op::name(word.opcode)
                    );
                    reporter.error(st.loc, *column, message);
                }
                word
            }
            Body::BrokenInstruction => Instruction::default(),
            Body::None | Body::Constant { .. } | Body::Include { .. } => continue,
        };
        if let Some(profile) = profile {
            let capacity = profile.module.program_memory as usize;
            if instructions.len() == capacity {
                let message = format!(
                    "the program has more than {capacity} instructions; the program memory of the {} holds {capacity}",
                    profile.module.name
                );
                reporter.error(st.loc, first_column(&st.body), message);
            }
        }
        instructions.push(word);
        source_map.push(SourceLine {
            file: reporter.files.get(st.loc.file).cloned().unwrap_or_else(|| "".into()),
            line: st.loc.line as u32,
            column: first_column(&st.body) as u32,
            text: st.text.clone(),
        });
    }

    if !reporter.is_empty() {
        return Err(reporter.finish());
    }
    let (symbols, constants) = evaluator.into_maps();
    Ok(Program { instructions, symbols, constants, source_map })
}

fn first_column(body: &Body) -> usize {
    match body {
        Body::Instruction { column, .. } | Body::Raw { column, .. } => *column,
        _ => 1,
    }
}
