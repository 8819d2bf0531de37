//! Only the bus moves time: every front end (the command line's run,
//! debugger, bench and trace, the JavaScript binding, the server, the
//! Python package) asks a [`tmclsim_firmware::Bus`], with its clock, and
//! no front end moves a `Module`'s time on its own.
//!
//! The methods of `Module` that move its time are found in the firmware's
//! sources: those that set `self.now_ns`, and those that call one of them.
//! None of them may be `pub`; the compiler then refuses a call from any
//! other crate.

use crate::rust_source;

use rust_source::{Token, ident, rust_files, tokens};
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// A method of an `impl Module` block.
#[derive(Debug, Default)]
struct Method {
    /// `pub` without a restriction (`pub(crate)` is not).
    public: bool,
    /// It sets `self.now_ns`.
    sets_now: bool,
    /// The methods it calls on `self`.
    calls: BTreeSet<String>,
}

/// The index after the brace block that opens at `i`.
fn block_end(t: &[Token], i: usize) -> usize {
    let mut depth = 0;
    for (j, token) in t.iter().enumerate().skip(i) {
        match token {
            Token::Punct('{') => depth += 1,
            Token::Punct('}') => {
                depth -= 1;
                if depth == 0 {
                    return j + 1;
                }
            }
            _ => {}
        }
    }
    t.len()
}

/// The methods of the `impl Module` blocks of one source file.
fn methods_of_module(text: &str, out: &mut BTreeMap<String, Method>) {
    let t = tokens(text);
    let mut i = 0;
    while i + 2 < t.len() {
        let is_impl = ident(t.get(i)) == Some("impl") && ident(t.get(i + 1)) == Some("Module") && t[i + 2] == Token::Punct('{');
        if !is_impl {
            i += 1;
            continue;
        }
        let end = block_end(&t, i + 2);
        let mut j = i + 3;
        while j < end {
            if ident(t.get(j)) != Some("fn") {
                j += 1;
                continue;
            }
            let Some(name) = ident(t.get(j + 1)) else { break };
            let public = j >= 1 && ident(t.get(j - 1)) == Some("pub");
            let body = (j..end).find(|&k| t[k] == Token::Punct('{')).unwrap_or(end);
            let body_end = block_end(&t, body);
            let mut method = Method { public, ..Method::default() };
            for k in body..body_end {
                if ident(t.get(k)) != Some("self") || t.get(k + 1) != Some(&Token::Punct('.')) {
                    continue;
                }
                match (ident(t.get(k + 2)), t.get(k + 3)) {
                    (Some("now_ns"), Some(Token::Punct(op))) => {
                        // `=`, `+=` or `-=`; not `==`.
                        let then_eq = t.get(k + 4) == Some(&Token::Punct('='));
                        method.sets_now |= match op {
                            '=' => !then_eq,
                            '+' | '-' => then_eq,
                            _ => false,
                        };
                    }
                    (Some(called), Some(Token::Punct('('))) => {
                        method.calls.insert(called.to_string());
                    }
                    _ => {}
                }
            }
            out.insert(name.to_string(), method);
            j = body_end;
        }
        i = end;
    }
}

fn firmware_methods() -> BTreeMap<String, Method> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut paths = Vec::new();
    rust_files(&src, &mut paths);
    let mut methods = BTreeMap::new();
    for path in paths {
        methods_of_module(&std::fs::read_to_string(&path).unwrap(), &mut methods);
    }
    methods
}

/// The methods that move time: those that set it, and their callers.
fn time_moving(methods: &BTreeMap<String, Method>) -> BTreeSet<String> {
    let mut moving: BTreeSet<String> = methods.iter().filter(|(_, m)| m.sets_now).map(|(n, _)| n.clone()).collect();
    loop {
        let callers: Vec<String> = methods
            .iter()
            .filter(|(n, m)| !moving.contains(*n) && m.calls.iter().any(|c| moving.contains(c)))
            .map(|(n, _)| n.clone())
            .collect();
        if callers.is_empty() {
            return moving;
        }
        moving.extend(callers);
    }
}

#[test]
fn no_time_moving_method_of_a_module_is_public() {
    let methods = firmware_methods();
    let moving = time_moving(&methods);
    for expected in ["advance", "advance_to", "step_instruction"] {
        assert!(moving.contains(expected), "Module::{expected} is found to move time ({moving:?})");
    }
    let public: Vec<&String> = moving.iter().filter(|n| methods[*n].public).collect();
    assert!(
        public.is_empty(),
        "Module methods that move time are public: {public:?}; only the bus moves time (make them pub(crate), give the Bus what front ends need)"
    );
}

#[test]
fn the_methods_and_their_calls_are_read() {
    let source = r#"
        impl Module {
            pub fn tick(&mut self) { self.now_ns = 5; }
            pub(crate) fn later(&mut self) { if self.now_ns == 3 { self.tick(); } }
            fn on(&mut self) { self.now_ns += 1; }
            pub fn looks(&self) -> u64 { self.now_ns }
        }
        impl Other {
            pub fn tick(&mut self) {}
        }
    "#;
    let mut methods = BTreeMap::new();
    methods_of_module(source, &mut methods);
    assert_eq!(methods.keys().collect::<Vec<_>>(), ["later", "looks", "on", "tick"]);
    assert!(methods["tick"].public && methods["tick"].sets_now);
    assert!(!methods["later"].public && !methods["later"].sets_now, "a comparison sets nothing");
    assert_eq!(time_moving(&methods), ["later", "on", "tick"].map(String::from).into());
}
