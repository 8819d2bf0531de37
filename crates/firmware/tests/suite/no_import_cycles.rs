//! The files of a crate depend on each other without cycles, so that each
//! crate reads top-down: a module uses only modules below it, and what two
//! modules share lies in a module of its own below both. Checked for the
//! firmware and the crates around it (protocol, ethercat, host, server,
//! web, cli, wasm). In the firmware, besides, the state files, the motor
//! model and the leaf types know nothing of `Module` (`module/`), and the
//! files that extend `Module` call each other without cycles too.
//!
//! The graph is read from the sources: a file depends on every file whose
//! module a `use` (with `crate::`, `super::`, `self::` or a child module)
//! or a `crate::…` path in it names.

use crate::rust_source;

use rust_source::{Token, ident, rust_files, tokens, use_tree};
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

type Graph = BTreeMap<String, BTreeSet<String>>;

/// Module path of a source file (`state/axis.rs` → `state::axis`, `lib.rs`
/// → the root, ``).
fn module_of(src: &Path, file: &Path) -> String {
    let rel = file.strip_prefix(src).unwrap().with_extension("");
    let mut parts: Vec<String> = rel.iter().map(|p| p.to_string_lossy().into_owned()).collect();
    if matches!(parts.last().map(String::as_str), Some("lib" | "mod")) {
        parts.pop();
    }
    parts.join("::")
}

fn join(base: &[String], rest: &[String]) -> Vec<String> {
    base.iter().chain(rest).cloned().collect()
}

/// The file module a path (from the crate root) lies in: its longest
/// prefix that is a file.
fn file_of(path: &[String], files: &BTreeSet<String>) -> String {
    (0..=path.len()).rev().map(|n| path[..n].join("::")).find(|m| files.contains(m)).unwrap_or_default()
}

/// The files one source file depends on.
fn dependencies(text: &str, module: &str, files: &BTreeSet<String>) -> BTreeSet<String> {
    let t = tokens(text);
    let file_path: Vec<String> = if module.is_empty() { vec![] } else { module.split("::").map(String::from).collect() };
    // Inline modules (`mod tests { … }`) open at a brace depth.
    let mut inline: Vec<(usize, String)> = Vec::new();
    let mut depth = 0;
    let mut paths: Vec<(Vec<String>, Vec<String>, bool)> = Vec::new();
    let mut i = 0;
    while i < t.len() {
        let here = join(&file_path, &inline.iter().map(|(_, n)| n.clone()).collect::<Vec<_>>());
        match &t[i] {
            Token::Punct('{') => depth += 1,
            Token::Punct('}') => {
                if inline.last().is_some_and(|(d, _)| *d == depth) {
                    inline.pop();
                }
                depth -= 1;
            }
            Token::Ident(k) if k == "mod" => {
                if let (Some(name), Some(Token::Punct('{'))) = (ident(t.get(i + 1)), t.get(i + 2)) {
                    inline.push((depth + 1, name.to_string()));
                }
            }
            Token::Ident(k) if k == "use" => {
                let mut found = Vec::new();
                i = use_tree(&t, i + 1, &[], &mut found);
                paths.extend(found.into_iter().map(|p| (here.clone(), p, true)));
                continue;
            }
            Token::Ident(k) if matches!(k.as_str(), "crate" | "super") && t.get(i + 1) == Some(&Token::PathSep) => {
                let mut found = Vec::new();
                i = use_tree(&t, i, &[], &mut found);
                paths.extend(found.into_iter().map(|p| (here.clone(), p, false)));
                continue;
            }
            _ => {}
        }
        i += 1;
    }
    let mut deps = BTreeSet::new();
    for (here, path, in_use) in paths {
        let mut base = here.clone();
        let mut rest = &path[..];
        let absolute = match rest.first().map(String::as_str) {
            Some("crate") => join(&[], &rest[1..]),
            Some("super" | "self") => {
                while let Some(s) = rest.first().map(String::as_str) {
                    match s {
                        "super" => {
                            base.pop();
                        }
                        "self" => {}
                        _ => break,
                    }
                    rest = &rest[1..];
                }
                join(&base, rest)
            }
            // `use child::…` of a module declared in this one.
            Some(first) if in_use && files.contains(&join(&here, &[first.to_string()]).join("::")) => join(&here, rest),
            _ => continue,
        };
        deps.insert(file_of(&absolute, files));
    }
    deps.remove(module);
    deps
}

/// The graph of crate `krate` (a directory under crates/).
fn crate_graph(krate: &str) -> Graph {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(krate).join("src");
    let mut paths = Vec::new();
    rust_files(&src, &mut paths);
    let files: BTreeSet<String> = paths.iter().map(|p| module_of(&src, p)).collect();
    paths
        .iter()
        .map(|p| {
            let module = module_of(&src, p);
            let deps = dependencies(&std::fs::read_to_string(p).unwrap(), &module, &files);
            (module, deps)
        })
        .collect()
}

fn name(module: &str) -> &str {
    if module.is_empty() { "lib" } else { module }
}

/// A cycle of the graph, if it has one.
fn find_cycle(graph: &Graph) -> Option<Vec<String>> {
    fn visit(n: &str, graph: &Graph, done: &mut BTreeSet<String>, stack: &mut Vec<String>) -> Option<Vec<String>> {
        if let Some(at) = stack.iter().position(|s| s == n) {
            let mut cycle = stack[at..].to_vec();
            cycle.push(n.to_string());
            return Some(cycle);
        }
        if done.contains(n) {
            return None;
        }
        stack.push(n.to_string());
        for d in graph.get(n).into_iter().flatten() {
            if let Some(c) = visit(d, graph, done, stack) {
                return Some(c);
            }
        }
        stack.pop();
        done.insert(n.to_string());
        None
    }
    let mut done = BTreeSet::new();
    graph.keys().find_map(|n| visit(n, graph, &mut done, &mut Vec::new()))
}

/// Cycles of the graph, one for each edge that breaks one: every cycle
/// found, its last edge taken out, until none is left.
fn cycles(graph: &Graph) -> Vec<Vec<String>> {
    let mut graph = graph.clone();
    let mut found = Vec::new();
    while let Some(cycle) = find_cycle(&graph) {
        let [.., from, to] = &cycle[..] else { unreachable!("a cycle has an edge") };
        graph.get_mut(from).expect("a node of the graph").remove(to);
        found.push(cycle);
    }
    found
}

fn reaches(graph: &Graph, from: &str, to: &str) -> bool {
    let mut seen = BTreeSet::new();
    let mut todo = vec![from.to_string()];
    while let Some(n) = todo.pop() {
        if n == to {
            return true;
        }
        if seen.insert(n.clone()) {
            todo.extend(graph.get(&n).into_iter().flatten().cloned());
        }
    }
    false
}

/// The crates checked.
const CRATES: [&str; 11] = ["protocol", "profile", "asm", "firmware", "ethercat", "host", "ide", "server", "web", "cli", "wasm"];

#[test]
fn no_crate_has_import_cycles() {
    let mut found = Vec::new();
    for krate in CRATES {
        let graph = crate_graph(krate);
        assert!(graph.len() > 1, "the sources of crates/{krate} are found");
        for cycle in self::cycles(&graph) {
            let cycle: Vec<&str> = cycle.iter().map(|m| name(m)).collect();
            found.push(format!("crates/{krate}: {}", cycle.join(" → ")));
        }
    }
    assert!(found.is_empty(), "import cycles (move what both sides use down into a module of its own):\n{}", found.join("\n"));
}

#[test]
fn state_and_leaf_types_do_not_depend_on_module() {
    let graph = crate_graph("firmware");
    let leaves = [
        "outcome",
        "parameter_numbers",
        "program",
        "motion",
        "reference_search",
        "eeprom",
        "world",
        "world_file",
        "world_rules",
        // The motor model: it sees an axis, its world and its surroundings.
        "motor",
        "mechanics",
        "driver",
        "closed_loop",
    ];
    let checked: Vec<&String> = graph.keys().filter(|m| m.starts_with("state") || leaves.contains(&m.as_str())).collect();
    assert!(checked.iter().any(|m| m.starts_with("state::")), "the state files are found");
    for m in checked {
        assert!(!reaches(&graph, m, "module"), "{m} depends on module/mod.rs");
    }
}

/// The files of the firmware that extend `Module` (`impl Module { … }`),
/// each with the methods it defines there and the `self.method(…)` calls
/// its blocks make.
fn module_methods() -> BTreeMap<String, (BTreeSet<String>, BTreeSet<String>)> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut paths = Vec::new();
    rust_files(&src, &mut paths);
    let mut out = BTreeMap::new();
    for p in paths {
        let t = tokens(&std::fs::read_to_string(&p).unwrap());
        let (mut defined, mut called) = (BTreeSet::new(), BTreeSet::new());
        let mut i = 0;
        while i + 2 < t.len() {
            let opens = ident(t.get(i)) == Some("impl") && ident(t.get(i + 1)) == Some("Module") && t[i + 2] == Token::Punct('{');
            if !opens {
                i += 1;
                continue;
            }
            i += 3;
            let mut depth = 1;
            while i < t.len() && depth > 0 {
                match (&t[i], t.get(i + 1), t.get(i + 2), t.get(i + 3)) {
                    (Token::Punct('{'), ..) => depth += 1,
                    (Token::Punct('}'), ..) => depth -= 1,
                    (Token::Ident(f), Some(name), ..) if f == "fn" && depth == 1 => {
                        defined.extend(ident(Some(name)).map(String::from));
                    }
                    (Token::Ident(s), Some(Token::Punct('.')), Some(name), Some(Token::Punct('('))) if s == "self" => {
                        called.extend(ident(Some(name)).map(String::from));
                    }
                    _ => {}
                }
                i += 1;
            }
        }
        if !defined.is_empty() {
            out.insert(module_of(&src, &p), (defined, called));
        }
    }
    out
}

/// Which `impl Module` file calls which: a file depends on each other
/// file that defines a method its blocks call.
fn call_graph() -> Graph {
    let files = module_methods();
    files
        .iter()
        .map(|(file, (_, called))| {
            let deps = files.iter().filter(|(f, (defined, _))| *f != file && !defined.is_disjoint(called)).map(|(f, _)| f.clone());
            (file.clone(), deps.collect())
        })
        .collect()
}

/// The `impl Module` files call each other top-down too: the links on the
/// direct mode, the direct mode on the interpreter, the interpreter on the
/// one dispatch, the dispatch on the command families, the families on the
/// module's accessors; time on the interpreter and the families.
#[test]
fn the_module_files_call_each_other_without_cycles() {
    let graph = call_graph();
    let calls = |from: &str, to: &str| graph.get(&format!("module::{from}")).is_some_and(|d| d.contains(&format!("module::{to}")));
    assert!(calls("time", "interpreter"), "the graph sees time.rs run the interpreter: {graph:?}");
    assert!(calls("interpreter", "executor"), "and the interpreter dispatch");
    let found: Vec<String> = cycles(&graph).iter().map(|c| c.join(" → ")).collect();
    assert!(found.is_empty(), "call cycles between `impl Module` files:\n{}", found.join("\n"));
}

#[test]
fn the_graph_sees_the_dependencies() {
    let graph = crate_graph("firmware");
    let deps = |m: &str| graph.get(m).unwrap_or_else(|| panic!("no file {m}"));
    assert!(deps("module::commands::motion").contains("module"), "use crate::module::Module");
    assert!(deps("module").contains("state::axis"), "pub use crate::state::axis::Axis");
    assert!(deps("").contains("module"), "pub use module::{{…}} in lib.rs");
}

#[test]
fn a_cycle_is_found() {
    let files: BTreeSet<String> = ["", "a", "b", "b::c"].map(String::from).into();
    let a = dependencies("use crate::b::c::Thing; // crate::x\nfn f() { let s = \"crate::a\"; }", "a", &files);
    let c = dependencies("use super::Y;\nmod tests {\n    use super::X;\n}\nfn g() { crate::a::f() }", "b::c", &files);
    assert_eq!(a, ["b::c".to_string()].into());
    assert_eq!(c, ["a".to_string(), "b".to_string()].into(), "super in an inline module names the file itself");
    let graph: Graph = [("a".to_string(), a), ("b::c".to_string(), c)].into();
    assert_eq!(find_cycle(&graph), Some(vec!["a".to_string(), "b::c".to_string(), "a".to_string()]));
    assert_eq!(cycles(&graph).len(), 1, "one edge out breaks it");
    let two: Graph = [("a", vec!["b", "c"]), ("b", vec!["a"]), ("c", vec!["a"])]
        .into_iter()
        .map(|(n, d)| (n.to_string(), d.into_iter().map(String::from).collect()))
        .collect();
    assert_eq!(cycles(&two).len(), 2, "every cycle is reported");
}
