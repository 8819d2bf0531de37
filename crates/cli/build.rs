//! Names the git revision the binary is built from, for `--version`:
//! `TMCLSIM_GIT` is the short hash of HEAD, or `unknown` outside a git
//! checkout (a source archive, a registry download) or without git.

use std::path::Path;
use std::process::Command;

fn git(args: &[&str]) -> Option<String> {
    let out = Command::new("git").args(args).current_dir(env!("CARGO_MANIFEST_DIR")).output().ok()?;
    if !out.status.success() {
        return None;
    }
    let text = String::from_utf8(out.stdout).ok()?.trim().to_string();
    (!text.is_empty()).then_some(text)
}

/// Rebuilds when `file` (a path git printed, relative to the crate) changes;
/// a file that does not exist is not named, since cargo would then rerun
/// this script on every build.
fn watch(file: &str) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(file);
    if path.exists() {
        println!("cargo:rerun-if-changed={}", path.display());
    }
}

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    let revision = git(&["rev-parse", "--short", "HEAD"]);
    if revision.is_some() {
        // HEAD moves on checkout; the branch it names moves on commit
        // (a loose ref, or packed-refs once git has packed it).
        if let Some(head) = git(&["rev-parse", "--git-path", "HEAD"]) {
            watch(&head);
        }
        if let Some(branch) = git(&["symbolic-ref", "-q", "HEAD"])
            && let Some(file) = git(&["rev-parse", "--git-path", &branch])
        {
            watch(&file);
        }
        if let Some(packed) = git(&["rev-parse", "--git-path", "packed-refs"]) {
            watch(&packed);
        }
    }
    println!("cargo:rustc-env=TMCLSIM_GIT={}", revision.as_deref().unwrap_or("unknown"));
}
