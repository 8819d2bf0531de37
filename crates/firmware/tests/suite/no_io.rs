//! The pure crates (protocol, profile, firmware, asm, ide, the browser
//! IDE's answers, and wasm, their JavaScript binding) do no I/O, so that
//! they build for `wasm32-unknown-unknown` (scripts/test builds them for
//! it) and behave the same wherever they run: no files, sockets, threads,
//! processes, environment or standard streams in their sources, and no
//! dependency that brings them. Files and links are the server crate's
//! (`tmclsim_server::eeprom_file`, `files`, `sources`). Code under
//! `#[cfg(test)]` may use anything.
//!
//! One exception is counted here: the wall clock (`std::time::Instant`),
//! only in the firmware's clock.rs (`Clock::Wall`). It compiles for wasm32
//! but panics there when it is read; a stepped clock never reads it.

use crate::rust_source;

use rust_source::{Token, ident, rust_files, tokens, use_tree};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

const CRATES: [&str; 6] = ["protocol", "profile", "firmware", "asm", "ide", "wasm"];

/// Modules of `std` (`core`, `alloc`) that do I/O.
const STD_IO: [&str; 6] = ["fs", "net", "thread", "os", "process", "env"];
/// Items of `std::io` that are the process's standard streams.
const STD_STREAMS: [&str; 3] = ["stdin", "stdout", "stderr"];
/// Crates that do I/O.
const IO_CRATES: [&str; 10] = ["tokio", "libc", "tempfile", "mio", "socket2", "nix", "rustix", "serialport", "getrandom", "memmap2"];
/// Macros that write to the standard streams.
const PRINTS: [&str; 5] = ["print", "println", "eprint", "eprintln", "dbg"];
/// Types that read the wall clock.
const WALL_CLOCK: [&str; 3] = ["Instant", "SystemTime", "UNIX_EPOCH"];
/// The files that may read the wall clock.
const WALL_CLOCK_FILES: [&str; 1] = ["firmware/src/clock.rs"];

fn crates_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Whether the tokens at `i` are `#[cfg(test)]`.
fn cfg_test_at(t: &[Token], i: usize) -> bool {
    let want = [
        Token::Punct('#'),
        Token::Punct('['),
        Token::Ident("cfg".into()),
        Token::Punct('('),
        Token::Ident("test".into()),
        Token::Punct(')'),
        Token::Punct(']'),
    ];
    t.get(i..i + want.len()) == Some(&want[..])
}

/// The tokens without the items under `#[cfg(test)]`, and the names of the
/// file modules declared under it (`#[cfg(test)] mod test_support;`).
fn without_tests(t: &[Token]) -> (Vec<Token>, Vec<String>) {
    let mut out = Vec::new();
    let mut test_files = Vec::new();
    let mut i = 0;
    while i < t.len() {
        if !cfg_test_at(t, i) {
            out.push(t[i].clone());
            i += 1;
            continue;
        }
        i += 7;
        if let (Some(Token::Ident(m)), Some(name), Some(Token::Punct(';'))) = (t.get(i), ident(t.get(i + 1)), t.get(i + 2))
            && m == "mod"
        {
            test_files.push(name.to_string());
        }
        // The item ends at a `;` outside brackets, or where its first
        // brace block closes.
        let mut depth = 0usize;
        while i < t.len() {
            match &t[i] {
                Token::Punct('(' | '[' | '{') => depth += 1,
                Token::Punct(')' | ']') => depth -= 1,
                Token::Punct('}') => {
                    depth -= 1;
                    if depth == 0 {
                        i += 1;
                        break;
                    }
                }
                Token::Punct(';') if depth == 0 => {
                    i += 1;
                    break;
                }
                _ => {}
            }
            i += 1;
        }
    }
    (out, test_files)
}

/// What in a source file does I/O, one line per finding, and the file
/// modules only tests compile.
fn io_in(text: &str, wall_clock_allowed: bool) -> (Vec<String>, Vec<String>) {
    let (t, test_files) = without_tests(&tokens(text));
    let mut found = Vec::new();
    for (i, token) in t.iter().enumerate() {
        let Token::Ident(name) = token else { continue };
        if PRINTS.contains(&name.as_str()) && t.get(i + 1) == Some(&Token::Punct('!')) {
            found.push(format!("{name}!"));
        }
        if WALL_CLOCK.contains(&name.as_str()) && !wall_clock_allowed {
            found.push(format!("{name} (the wall clock)"));
        }
    }
    let mut paths: Vec<Vec<String>> = Vec::new();
    let mut i = 0;
    while i < t.len() {
        match &t[i] {
            Token::Ident(k) if k == "use" => {
                i = use_tree(&t, i + 1, &[], &mut paths);
                continue;
            }
            Token::Ident(k) if k == "extern" && ident(t.get(i + 1)) == Some("crate") => {
                paths.extend(ident(t.get(i + 2)).map(|name| vec![name.to_string()]));
            }
            // A path's first segment: not one after `a::` or `<T>::`
            // (`::std::…` is a first segment).
            Token::Ident(first)
                if t.get(i + 1) == Some(&Token::PathSep)
                    && !(i >= 2 && t[i - 1] == Token::PathSep && matches!(t[i - 2], Token::Ident(_) | Token::Punct('>'))) =>
            {
                let mut path = vec![first.clone()];
                let mut j = i + 1;
                while t.get(j) == Some(&Token::PathSep)
                    && let Some(next) = ident(t.get(j + 1))
                {
                    path.push(next.to_string());
                    j += 2;
                }
                paths.push(path);
            }
            _ => {}
        }
        i += 1;
    }
    for p in paths {
        let s: Vec<&str> = p.iter().map(String::as_str).collect();
        let io = match s.as_slice() {
            ["std" | "core" | "alloc", m, ..] if STD_IO.contains(m) => true,
            ["std", "io", item, ..] if STD_STREAMS.contains(item) => true,
            [first, ..] => IO_CRATES.contains(first),
            [] => false,
        };
        if io {
            found.push(s.join("::"));
        }
    }
    (found, test_files)
}

/// The source files of a crate, without those only tests compile.
fn source_files(krate: &str) -> Vec<(PathBuf, String)> {
    let src = crates_dir().join(krate).join("src");
    let mut paths = Vec::new();
    rust_files(&src, &mut paths);
    paths.sort();
    let texts: Vec<(PathBuf, String)> = paths.into_iter().map(|p| (p.clone(), std::fs::read_to_string(&p).unwrap())).collect();
    let mut test_only: BTreeSet<PathBuf> = BTreeSet::new();
    for (path, text) in &texts {
        let (_, test_files) = without_tests(&tokens(text));
        let dir = match path.file_stem().and_then(|s| s.to_str()) {
            Some("lib" | "mod") => path.parent().unwrap().to_path_buf(),
            Some(stem) => path.parent().unwrap().join(stem),
            None => continue,
        };
        for name in test_files {
            test_only.insert(dir.join(format!("{name}.rs")));
            test_only.insert(dir.join(&name));
        }
    }
    texts.into_iter().filter(|(p, _)| !test_only.iter().any(|t| p.starts_with(t))).collect()
}

#[test]
fn the_pure_crates_do_no_io() {
    let mut problems = Vec::new();
    let mut files = 0;
    for krate in CRATES {
        for (path, text) in source_files(krate) {
            // Named with `/` on every system (Windows' paths have `\`).
            let name = path.strip_prefix(crates_dir()).unwrap().to_string_lossy().replace('\\', "/");
            let (found, _) = io_in(&text, WALL_CLOCK_FILES.contains(&name.as_str()));
            problems.extend(found.into_iter().map(|f| format!("crates/{name}: {f}")));
            files += 1;
        }
    }
    assert!(files > 40, "the sources are found ({files} files)");
    assert!(problems.is_empty(), "I/O in a crate that builds for wasm32 (it belongs in the server crate):\n{}", problems.join("\n"));
}

#[test]
fn the_pure_crates_depend_on_nothing_that_does_io() {
    for krate in CRATES {
        let path = crates_dir().join(krate).join("Cargo.toml");
        let manifest: toml::Table = toml::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        let mut sections: Vec<&toml::Table> = manifest.get("dependencies").and_then(|d| d.as_table()).into_iter().collect();
        for target in manifest.get("target").and_then(|t| t.as_table()).into_iter().flat_map(|t| t.values()) {
            sections.extend(target.get("dependencies").and_then(|d| d.as_table()));
        }
        for name in sections.iter().flat_map(|s| s.keys()) {
            assert!(!IO_CRATES.contains(&name.as_str()), "crates/{krate}/Cargo.toml depends on {name}");
            assert!(["tmclsim-server", "tmclsim-host", "tmclsim-web"].iter().all(|c| c != name), "crates/{krate} depends on {name}");
        }
    }
}

#[test]
fn io_is_found_in_every_spelling_and_tests_are_left_out() {
    let source = r#"
        use std::{collections::BTreeMap, fs::File};
        use std::io::{Read, stdout};
        use tokio::sync::Mutex;
        // std::net::TcpStream in a comment is no I/O
        fn f() -> String {
            let _ = "std::thread::spawn in a string is none either";
            let _ = ::std::process::id();
            std::env::var("X").unwrap_or_default()
        }
        fn g() { println!("x"); let _ = std::time::Instant::now(); }
        #[cfg(test)]
        mod tests {
            use std::fs;
            #[test]
            fn t() { let _ = tempfile::tempdir(); }
        }
        #[cfg(test)]
        mod test_support;
    "#;
    let (found, test_files) = io_in(source, false);
    assert_eq!(
        found,
        [
            "println!",
            "Instant (the wall clock)",
            "std::fs::File",
            "std::io::stdout",
            "tokio::sync::Mutex",
            "std::process::id",
            "std::env::var"
        ]
    );
    assert_eq!(test_files, ["test_support"]);
    assert_eq!(io_in(source, true).0.len(), 6, "the wall clock where it is allowed");
}
