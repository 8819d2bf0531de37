//! Careless and hostile command lines and input files: each gets a clear
//! refusal (exit status 2 and one message), never a panic, a hang or a
//! server that starts wrong (docs/robustness.md).

use std::io::Read;
use std::process::{Command, Stdio};

use crate::common;

use common::tmclsim;

/// Asserts a refusal: exit status 2, no panic, and `expected` in stderr.
fn refused(args: &[&str], expected: &str) {
    let out = tmclsim(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
    assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    assert!(stderr.contains(expected), "{args:?}: expected '{expected}' in: {stderr}");
}

fn fleet_file(name: &str, text: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("tmclsim-hostile-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn a_fleet_past_the_module_limit_is_refused_before_it_grows() {
    let f = fleet_file("huge.toml", "[[link]]\ntcp = \"127.0.0.1:0\"\ncount = 1000000000\nmodules = [\"tmcm-1141@1\"]\n");
    refused(&["serve", "--fleet", f.to_str().unwrap()], "the fleet would have more than 10000 modules, the limit of one fleet");
    let f = fleet_file("bus.toml", "[[link]]\ntcp = \"127.0.0.1:0\"\ncount = 41\nbus = \"tmcm-1141\"\nsize = 250\n");
    refused(&["serve", "--fleet", f.to_str().unwrap()], "link 1: the fleet would have more than 10000 modules");
}

#[test]
fn fleet_ports_past_65535_are_refused_not_wrapped() {
    let f = fleet_file("ports.toml", "[[link]]\ntcp = \"127.0.0.1:65530\"\ncount = 10\nmodules = [\"tmcm-1141@1\"]\n");
    refused(&["serve", "--fleet", f.to_str().unwrap()], "link 1: 10 links from port 65530 would pass port 65535");
    let f = fleet_file("zero.toml", "[[link]]\ntcp = \"127.0.0.1:0\"\ncount = 0\nmodules = [\"tmcm-1141@1\"]\n");
    refused(&["serve", "--fleet", f.to_str().unwrap()], "count is at least 1");
}

#[test]
fn two_modules_at_one_address_are_refused() {
    refused(&["serve", "--tcp", "127.0.0.1:0", "--bus", "tmcm-1141@1,tmcm-1141@1"], "--bus: two modules at address 1");
    refused(&["serve", "--tcp", "127.0.0.1:0", "--bus", "tmcm-1141@3, tmcm-351@2 ,tmcm-1141@3"], "two modules at address 3");
    let f = fleet_file("dup.toml", "[[link]]\ntcp = \"127.0.0.1:0\"\nmodules = [\"tmcm-1141@1\", \"tmcm-351@1\"]\n");
    refused(&["serve", "--fleet", f.to_str().unwrap()], "link 1: two modules at address 1");
}

#[test]
#[cfg_attr(windows, ignore = "/dev/zero: Windows has no endless device file")]
fn endless_input_files_are_refused_unread() {
    refused(&["serve", "--fleet", "/dev/zero"], "/dev/zero: larger than 1 MiB, the limit for a fleet file");
    refused(&["serve", "--tcp", "127.0.0.1:0", "--world", "/dev/zero"], "/dev/zero: larger than 1 MiB, the limit for a world file");
    refused(&["run", "/dev/zero"], "cannot read the file: larger than 2 MiB, the limit for a source file");
    refused(&["disasm", "/dev/zero"], "/dev/zero: larger than 1 MiB, the limit for a program binary");
    refused(&["asm", "/dev/zero"], "cannot read the file: larger than 2 MiB, the limit for a source file");
    let bin = fleet_file("p.bin", "");
    refused(&["disasm", bin.to_str().unwrap(), "--symbols", "/dev/zero"], "/dev/zero: larger than 1 MiB, the limit for a symbol file");
}

#[test]
fn fleet_bench_refuses_a_rate_it_cannot_send() {
    for rate in ["0", "-5", "nan", "inf", "1e9"] {
        let out = tmclsim(&["fleet-bench", "--fleet", "/nonexistent.toml", &format!("--rate={rate}")]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "--rate {rate}: {stderr}");
        assert!(!stderr.contains("panicked"), "--rate {rate}: {stderr}");
        assert!(stderr.contains("--rate"), "--rate {rate}: {stderr}");
    }
}

#[test]
#[cfg_attr(windows, ignore = "Windows has no SIGPIPE: a write to a closed pipe is an error there, which println! reports")]
fn a_reader_that_stops_early_ends_the_output_quietly() {
    let program = concat!(env!("CARGO_MANIFEST_DIR"), "/../asm/tests/programs/main_loop_8_2.tmc");
    for args in [&["profile", "tmcm-1141"][..], &["asm", "--list", program][..]] {
        let mut child =
            Command::new(env!("CARGO_BIN_EXE_tmclsim")).args(args).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
        // The reader is gone before the first line is written (as `| head`
        // that has had enough).
        drop(child.stdout.take());
        let mut stderr = String::new();
        child.stderr.take().unwrap().read_to_string(&mut stderr).unwrap();
        let status = child.wait().unwrap();
        assert!(stderr.is_empty(), "{args:?}: {stderr}");
        assert!(status.code().is_none_or(|c| c == 0), "{args:?}: {status:?}");
    }
}
