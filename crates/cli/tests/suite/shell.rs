//! tmclsim as a shell expects a command to be: completions, a manual
//! page, a version naming its revision, NO_COLOR, and the exit statuses
//! README.md lists.

use crate::common;

use std::process::{Command, Stdio};

/// `tmclsim ARGS` with extra environment variables, CLICOLOR_FORCE and
/// NO_COLOR removed unless given.
fn tmclsim_with(env: &[(&str, &str)], args: &[&str]) -> std::process::Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_tmclsim"));
    c.args(args).stdin(Stdio::null()).env_remove("NO_COLOR").env_remove("CLICOLOR_FORCE").env_remove("CLICOLOR");
    c.envs(env.iter().copied()).output().unwrap()
}

fn stdout(o: &std::process::Output) -> String {
    String::from_utf8(o.stdout.clone()).expect("UTF-8 on standard output")
}

#[test]
fn completions_for_each_shell_name_the_commands() {
    for shell in ["bash", "zsh", "fish"] {
        let o = common::tmclsim(&["completions", shell]);
        assert!(o.status.success(), "{shell}: {}", common::text(&o));
        let script = stdout(&o);
        for command in ["serve", "trace", "upload", "completions"] {
            assert!(script.contains(command), "{shell} completions lack {command}");
        }
        // The options of a command, and of a command's command.
        assert!(script.contains("log-frames") && script.contains("listen"), "{shell} completions lack options");
    }
    let o = common::tmclsim(&["completions", "tcsh"]);
    assert_eq!(o.status.code(), Some(2), "{}", common::text(&o));
}

#[test]
fn the_manual_page_is_roff_made_from_the_help() {
    let o = common::tmclsim(&["man"]);
    assert!(o.status.success(), "{}", common::text(&o));
    let page = stdout(&o);
    assert!(page.lines().any(|l| l.starts_with(".TH TMCLSIM 1")), "{page}");
    for section in [".SH NAME", ".SH SYNOPSIS", ".SH SUBCOMMANDS", ".SH \"EXIT STATUS\"", ".SH VERSION"] {
        assert!(page.contains(section), "no {section}: {page}");
    }
    assert!(page.contains("tmclsim\\-serve(1)"), "{page}");
    // A command's own page.
    let o = common::tmclsim(&["man", "trace", "check"]);
    assert!(o.status.success(), "{}", common::text(&o));
    let page = stdout(&o);
    assert!(page.lines().any(|l| l.starts_with(".TH TMCLSIM-TRACE-CHECK 1")), "{page}");
    assert!(page.contains("\\-\\-module"), "{page}");
    let o = common::tmclsim(&["man", "trace", "replay"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(common::text(&o).contains("'tmclsim trace' has no command 'replay'; its commands are record, check"), "{}", common::text(&o));
}

#[test]
fn the_version_names_the_git_revision() {
    let o = common::tmclsim(&["--version"]);
    assert!(o.status.success());
    let version = stdout(&o);
    let rest = version.trim().strip_prefix(&format!("tmclsim {} (git ", env!("CARGO_PKG_VERSION"))).unwrap_or_else(|| panic!("{version}"));
    let revision = rest.strip_suffix(')').unwrap_or_else(|| panic!("{version}"));
    assert!(revision == "unknown" || (revision.len() >= 7 && revision.chars().all(|c| c.is_ascii_hexdigit())), "{version}");
}

#[test]
fn no_color_makes_every_output_plain() {
    // Forced, the help has styles: the check below would see them.
    let forced = tmclsim_with(&[("CLICOLOR_FORCE", "1")], &["--help"]);
    assert!(stdout(&forced).contains("\x1b["), "CLICOLOR_FORCE=1 styles the help");
    for args in [&["--help"][..], &["serve", "--help"], &["trace", "check", "--help"], &["serve", "--no-such-option"], &["man"]] {
        let o = tmclsim_with(&[("NO_COLOR", "1"), ("CLICOLOR_FORCE", "1")], args);
        let all = common::text(&o);
        assert!(!all.contains("\x1b["), "tmclsim {args:?} with NO_COLOR: {all:?}");
    }
}

#[test]
fn exit_status_two_for_usage_errors_and_bad_input() {
    let (code, text) = {
        let o = common::tmclsim(&["serve", "--no-such-option"]);
        (o.status.code(), common::text(&o))
    };
    assert_eq!(code, Some(2), "{text}");
    assert!(text.contains("--no-such-option"), "{text}");
    let o = common::tmclsim(&["frobnicate"]);
    assert_eq!(o.status.code(), Some(2), "{}", common::text(&o));

    let dir = tempfile::tempdir().unwrap();
    let trace = dir.path().join("session.jsonl");
    std::fs::write(&trace, "this is not a trace\n").unwrap();
    let o = common::tmclsim(&["trace", "check", trace.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", common::text(&o));
    let program = dir.path().join("p.tmc");
    std::fs::write(&program, "MVP ABS, 0, 1\nNOSUCHOP 1, 2\n").unwrap();
    let o = common::tmclsim(&["asm", program.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", common::text(&o));
    let o = common::tmclsim(&["run", dir.path().join("missing.tmc").to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", common::text(&o));
}

#[test]
fn exit_status_one_when_the_module_refuses_or_does_not_answer() {
    let server = common::Server::start(&[]);
    let tcp = server.tcp();
    // Refused: a type GAP does not have.
    let o = common::tmclsim(&["send", "--tcp", &tcp, "GAP", "250,", "0"]);
    assert_eq!(o.status.code(), Some(1), "{}", common::text(&o));
    // Not answered: no module at address 2.
    let o = common::tmclsim(&["send", "--tcp", &tcp, "--address", "2", "--timeout", "200", "GAP", "1,", "0"]);
    assert_eq!(o.status.code(), Some(1), "{}", common::text(&o));
    assert!(common::text(&o).contains("no reply"), "{}", common::text(&o));
    // A program longer than the module's memory: the word after the last
    // is refused, as `send` would have it refused.
    let dir = tempfile::tempdir().unwrap();
    let source = dir.path().join("long.tmc");
    std::fs::write(&source, "MVP ABS, 0, 1\n".repeat(1025) + "STOP\n").unwrap();
    let binary = dir.path().join("long.bin");
    let o = common::tmclsim(&["asm", source.to_str().unwrap(), "--module", "tmcm-6110", "-o", binary.to_str().unwrap()]);
    assert!(o.status.success(), "{}", common::text(&o));
    let o = common::tmclsim(&["upload", binary.to_str().unwrap(), "--tcp", &tcp]);
    assert_eq!(o.status.code(), Some(1), "{}", common::text(&o));
    assert!(common::text(&o).contains("word 1024 (MVP ABS, 0, 1) was not stored"), "{}", common::text(&o));
    server.stop();
    // A link that cannot be opened is not a failed check.
    let port = dir.path().join("no-such-port");
    let o = common::tmclsim(&["send", "--port", port.to_str().unwrap(), "GAP", "1,", "0"]);
    assert_eq!(o.status.code(), Some(2), "{}", common::text(&o));
}
