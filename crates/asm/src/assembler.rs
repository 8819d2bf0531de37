//! The assembler driver: two passes over the source and its includes.
//! Pass 1 reads every line: syntax errors, includes, the addresses of the
//! labels, the definitions of the constants. Pass 2 evaluates the
//! constants, then reads the same lines again and encodes and checks every
//! instruction. One line is parsed at a time, so memory holds the source
//! texts, the names and the program, never all lines' tokens or trees.

use std::collections::HashSet;
use std::rc::Rc;

use tmclsim_profile::Profile;
use tmclsim_protocol::{Instruction, opcode as op};

use crate::binary;
use crate::check::check;
use crate::diagnostic::{Diagnostic, Loc, Reporter};
use crate::encoder::{encode, encode_raw};
use crate::eval::Evaluator;
use crate::include::{IncludeResolver, built_in};
use crate::lexer::Lines;
use crate::limits::{MAX_LINE_BYTES, MAX_STATEMENTS, MAX_TOTAL_SOURCE_BYTES};
use crate::parser::{Body, Line, parse_line};
use crate::program::Program;
use crate::source_map::SourceLine;

/// How deeply includes may nest (a cycle is reported before this).
const MAX_INCLUDE_DEPTH: usize = 64;

/// A source file's text: the one given to `assemble`, or an included one.
#[derive(Clone)]
enum Text<'s> {
    Given(&'s str),
    Included(Rc<String>),
}

impl Text<'_> {
    fn as_str(&self) -> &str {
        match self {
            Text::Given(text) => text,
            Text::Included(text) => text,
        }
    }
}

/// Pass 1: reads a file and, recursively, the files it includes.
struct Reader<'r, 's> {
    resolver: &'r dyn IncludeResolver,
    reporter: Reporter,
    evaluator: Evaluator,
    /// The text of every file by number (the reporter's file numbers);
    /// `None` for a file not read (past the size limit).
    texts: Vec<Option<Text<'s>>>,
    /// The file each `#include` statement led into, in reading order.
    included: Vec<Option<usize>>,
    /// Keys and numbers of the files being read, outermost first.
    stack: Vec<(String, usize)>,
    /// Keys of every file read so far (each file is read once).
    seen: HashSet<String>,
    /// Bytes of source read so far.
    loaded: usize,
    /// Statements so far (lines with a label, an instruction, a constant or
    /// an include).
    statements: usize,
    /// The statement limit was reached: nothing more is read.
    full: bool,
    /// The address of the next instruction.
    address: u32,
}

impl<'s> Reader<'_, 's> {
    fn next_loc(&self, file: usize, line: usize) -> Loc {
        Loc { seq: self.statements, file, line }
    }

    /// Reads a file; its number, unless it is past the size limit.
    fn load(&mut self, key: String, name: &str, text: Text<'s>) -> Option<usize> {
        let file = self.reporter.add_file(name);
        self.seen.insert(key.clone());
        self.loaded += text.as_str().len();
        if self.loaded > MAX_TOTAL_SOURCE_BYTES {
            let loc = self.next_loc(file, 0);
            self.reporter.error(loc, 0, format!("the sources pass {} MiB, the limit of one assembly", MAX_TOTAL_SOURCE_BYTES >> 20));
            self.texts.push(None);
            return None;
        }
        self.texts.push(Some(text.clone()));
        self.stack.push((key, file));
        let mut lines = Lines::new(text.as_str(), MAX_LINE_BYTES);
        while let Some((number, line)) = lines.next_line() {
            if self.full {
                // The rest is not read, but a comment it leaves open is
                // still reported.
                while lines.next_line().is_some() {}
                break;
            }
            let loc = self.next_loc(file, number);
            let Some(line) = line else {
                self.reporter.error(loc, 1, format!("line longer than {MAX_LINE_BYTES} bytes"));
                continue;
            };
            let (parsed, error) = parse_line(line);
            if let Some((column, message)) = error {
                self.reporter.error(loc, column, message);
            }
            if parsed.labels.is_empty() && parsed.body == Body::None {
                continue;
            }
            if self.statements == MAX_STATEMENTS {
                self.reporter.error(loc, 1, format!("more than {MAX_STATEMENTS} statements, the limit of one assembly"));
                self.full = true;
                continue;
            }
            self.statements += 1;
            self.statement(parsed, loc, name);
        }
        if let Some(open) = lines.unterminated() {
            let loc = self.next_loc(file, open.line);
            self.reporter.error(loc, open.column, "comment '/*' is never closed with '*/'");
        }
        self.stack.pop();
        Some(file)
    }

    /// Labels get their addresses, constants their definitions, includes
    /// are read.
    fn statement(&mut self, parsed: Line, loc: Loc, file_name: &str) {
        let Reader { evaluator, reporter, .. } = self;
        for (name, column) in &parsed.labels {
            evaluator.define_label(name, self.address, loc, *column, reporter);
        }
        match parsed.body {
            Body::Constant { name, column, value } => evaluator.define_constant(&name, value, loc, column, reporter),
            Body::Instruction { mnemonic, column, operands, .. } => {
                // A lone unknown word is most likely a label without its
                // colon: the error says so, and defining it here keeps its
                // uses from being reported too.
                if operands.is_empty() && op::from_mnemonic(&mnemonic).is_none() && !evaluator.is_defined(&mnemonic) {
                    evaluator.define_label(&mnemonic, self.address, loc, column, reporter);
                }
                self.address += 1;
            }
            Body::Raw { .. } | Body::BrokenInstruction => self.address += 1,
            Body::Include { file, column } => {
                // Pass 2 follows the same includes in the same order.
                let slot = self.included.len();
                self.included.push(None);
                self.included[slot] = self.include(file_name, &file, loc, column);
            }
            Body::None => {}
        }
    }

    fn include(&mut self, from: &str, wanted: &str, loc: Loc, column: usize) -> Option<usize> {
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
                    self.reporter.error(loc, column, format!("{message}{hint}"));
                    return None;
                }
            },
        };
        if let Some(start) = self.stack.iter().position(|(key, _)| *key == found.key) {
            let mut chain: Vec<&str> = self.stack[start..].iter().map(|&(_, file)| &*self.reporter.files[file]).collect();
            chain.push(&found.name);
            let message = if chain.len() == 2 {
                format!("'{}' includes itself", found.name)
            } else {
                format!("include cycle: {}", chain.join(" -> "))
            };
            self.reporter.error(loc, column, message);
            return None;
        }
        if self.seen.contains(&found.key) {
            return None;
        }
        if self.stack.len() >= MAX_INCLUDE_DEPTH {
            self.reporter.error(loc, column, format!("includes nested more than {MAX_INCLUDE_DEPTH} deep"));
            return None;
        }
        self.load(found.key, &found.name, Text::Included(Rc::new(found.text)))
    }
}

/// Pass 2: reads the files again in the order of pass 1 and encodes the
/// instructions.
struct Writer<'a, 's> {
    texts: &'a [Option<Text<'s>>],
    /// Where pass 1's includes led, consumed in the same order.
    included: std::slice::Iter<'a, Option<usize>>,
    reporter: Reporter,
    evaluator: Evaluator,
    profile: Option<&'a Profile>,
    /// The statement being read, and how many pass 1 read.
    seq: usize,
    statements: usize,
    /// Program words so far.
    words: usize,
    /// The program, while no error has been found (after one, it is not
    /// kept: it would not be returned).
    instructions: Vec<Instruction>,
    source_map: Vec<SourceLine>,
    /// Where the last instruction stands, and its column.
    last: Option<(Loc, usize)>,
}

impl Writer<'_, '_> {
    /// Reads a file; false once the statements pass 1 read are done.
    fn walk(&mut self, file: usize) -> bool {
        let Some(text) = self.texts.get(file).cloned().flatten() else { return true };
        let mut lines = Lines::new(text.as_str(), MAX_LINE_BYTES);
        while let Some((number, line)) = lines.next_line() {
            let Some(line) = line else { continue };
            let (parsed, _) = parse_line(line);
            if parsed.labels.is_empty() && parsed.body == Body::None {
                continue;
            }
            if self.seq == self.statements {
                return false;
            }
            let loc = Loc { seq: self.seq, file, line: number };
            self.seq += 1;
            if let Body::Include { .. } = parsed.body {
                if let Some(&Some(target)) = self.included.next()
                    && !self.walk(target)
                {
                    return false;
                }
                continue;
            }
            self.instruction(&parsed.body, loc, line);
        }
        true
    }

    fn instruction(&mut self, body: &Body, loc: Loc, line: &str) {
        let (reporter, evaluator) = (&mut self.reporter, &mut self.evaluator);
        let word = match body {
            Body::Instruction { mnemonic, column, operands, end_column } => {
                let encoded = encode(mnemonic, *column, operands, *end_column, loc, evaluator, reporter);
                if let (Ok(e), Some(profile)) = (&encoded, self.profile) {
                    for (column, message) in check(e, profile) {
                        reporter.error(loc, column, message);
                    }
                }
                encoded.map(|e| e.instruction).unwrap_or_default()
            }
            Body::Raw { fields, end_column, column } => {
                let word = encode_raw(fields, *end_column, loc, evaluator, reporter).unwrap_or_default();
                if self.profile.is_some() && op::is_control(word.opcode) {
                    let message = format!(
                        "control command {} ({}) cannot be stored in a program: during download the module executes it",
                        word.opcode,
                        op::name(word.opcode)
                    );
                    reporter.error(loc, *column, message);
                }
                word
            }
            Body::BrokenInstruction => Instruction::default(),
            Body::None | Body::Constant { .. } | Body::Include { .. } => return,
        };
        if let Some(profile) = self.profile {
            let capacity = profile.module.program_memory as usize;
            if self.words == capacity {
                let message = format!(
                    "the program has more than {capacity} instructions; the program memory of the {} holds {capacity}",
                    profile.module.name
                );
                reporter.error(loc, first_column(body), message);
            }
        }
        self.words += 1;
        self.last = Some((loc, first_column(body)));
        if !self.reporter.is_empty() {
            self.instructions = Vec::new();
            self.source_map = Vec::new();
            return;
        }
        self.instructions.push(word);
        self.source_map.push(SourceLine {
            file: self.reporter.files.get(loc.file).cloned().unwrap_or_else(|| "".into()),
            line: loc.line as u32,
            column: first_column(body) as u32,
            text: line.trim().to_string(),
        });
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
    let mut reader = Reader {
        resolver,
        reporter: Reporter::default(),
        evaluator: Evaluator::new(),
        texts: Vec::new(),
        included: Vec::new(),
        stack: Vec::new(),
        seen: HashSet::new(),
        loaded: 0,
        statements: 0,
        full: false,
        address: 0,
    };
    let main = reader.load(resolver.key(file_name), file_name, Text::Given(source));
    let Reader { mut reporter, mut evaluator, texts, included, statements, address, .. } = reader;

    evaluator.evaluate_constants(&mut reporter);
    // From here on only a program without errors is kept, in vectors of
    // its exact size (and room for the STOP that may be appended).
    let words = if reporter.is_empty() {
        evaluator.finish_definitions();
        address as usize
    } else {
        0
    };
    let mut writer = Writer {
        texts: &texts,
        included: included.iter(),
        reporter,
        evaluator,
        profile,
        seq: 0,
        statements,
        words: 0,
        instructions: Vec::with_capacity(words + 1),
        source_map: Vec::with_capacity(words),
        last: None,
    };
    if let Some(main) = main {
        writer.walk(main);
    }
    let Writer { mut reporter, evaluator, mut instructions, source_map, last, .. } = writer;
    // A program that does not end in STOP gets one after its last
    // instruction, as TMCL-IDE writes it (docs/behaviour.md rule 93); it
    // must fit the program memory too.
    let appended_stop = reporter.is_empty() && binary::needs_end_stop(&instructions);
    if appended_stop
        && let (Some(profile), Some((loc, column))) = (profile, last)
        && instructions.len() >= profile.module.program_memory as usize
    {
        let capacity = profile.module.program_memory;
        let message = format!(
            "the program has {capacity} instructions and does not end in STOP: the STOP appended after its last one \
             makes {}, and the program memory of the {} holds {capacity}",
            instructions.len() + 1,
            profile.module.name
        );
        reporter.error(loc, column, message);
    }
    if !reporter.is_empty() {
        return Err(reporter.finish());
    }
    if appended_stop {
        instructions.push(binary::END_STOP);
    }
    let (symbols, constants) = evaluator.into_maps();
    Ok(Program { instructions, symbols, constants, source_map, appended_stop })
}

fn first_column(body: &Body) -> usize {
    match body {
        Body::Instruction { column, .. } | Body::Raw { column, .. } => *column,
        _ => 1,
    }
}
