//! Mistakes users make get an answer that says what to do: typos get a
//! suggestion, host names work where addresses do, the endpoints can be
//! read by scripts, a wrong port is named as such.

use crate::common;

/// Exit status and everything printed.
fn tmclsim(args: &[&str]) -> (Option<i32>, String) {
    let o = common::tmclsim(args);
    (o.status.code(), common::text(&o))
}

#[test]
fn a_mistyped_command_gets_a_suggestion() {
    let (code, text) = tmclsim(&["send", "--tcp", "127.0.0.1:9", "GAPP", "1,", "0"]);
    assert_eq!(code, Some(2), "{text}");
    assert!(text.contains("unknown command 'GAPP' (did you mean 'GAP'?)"), "{text}");
}

#[test]
fn an_unknown_world_lists_the_built_in_ones() {
    let (code, text) = tmclsim(&["serve", "--tcp", "127.0.0.1:0", "--world", "stages"]);
    assert_eq!(code, Some(2), "{text}");
    assert!(text.contains("--world stages: no such world file; the built-in worlds are stage (the default) and free"), "{text}");
}

#[test]
fn host_names_serve_and_the_endpoints_file_tells_scripts_where() {
    let file = std::env::temp_dir().join(format!("tmclsim-endpoints-{}.toml", std::process::id()));
    let server = common::Server::start(&["--tcp", "localhost:0", "--control", "localhost:0", "--endpoints", file.to_str().unwrap()]);
    let printed = server.banner.join("\n");
    let endpoints: toml::Table = toml::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
    let tcp = endpoints["tcp"].as_str().unwrap().to_string();
    let control = endpoints["control"].as_str().unwrap().to_string();
    assert!(tcp.starts_with("127.0.0.1:") && control.starts_with("127.0.0.1:"), "{endpoints:?}");
    assert!(printed.contains(&format!("tcp: {tcp}")), "the file says what the server printed: {printed}");
    let mut s = std::net::TcpStream::connect(&tcp).unwrap();
    assert_eq!(common::ask(&mut s, "GAP 4, 0").unwrap().status, 100);
    // `world` pointed at the TMCL port says so.
    let (code, text) = tmclsim(&["world", "--control", &tcp, "show"]);
    assert_eq!(code, Some(2), "{text}");
    assert!(text.contains("did not answer as a control socket (a TMCL port?)"), "{text}");
    let (code, text) = tmclsim(&["world", "--control", &control, "show"]);
    assert_eq!(code, Some(0), "{text}");
    server.stop();
    // Removed at a clean stop, which Ctrl-C makes (a test on Windows can
    // only kill the server).
    #[cfg(unix)]
    assert!(!file.exists(), "the endpoints file goes with the server");
}

#[test]
#[cfg_attr(windows, ignore = "the SLCAN adapter lives on a pty: Windows refuses --slcan")]
fn bus_and_can_hints_say_how_to_reach_each_module() {
    let slcan = std::env::temp_dir().join(format!("tmclsim-hint-slcan-{}", std::process::id()));
    let server = common::Server::start(&["--tcp", "127.0.0.1:0", "--bus", "tmcm-1141@1,tmcm-1141@2", "--slcan", slcan.to_str().unwrap()]);
    let printed = server.banner.join("\n");
    server.stop();
    assert!(printed.contains("PyTrinamic reaches module 2 with --module-id 2"), "{printed}");
    assert!(printed.contains(&format!("--interface slcan_tmcl --port {} --data-rate 1000000 --module-id 1", slcan.display())), "{printed}");
}

#[test]
fn log_frames_shows_the_traffic_decoded() {
    let server = common::Server::start(&["--tcp", "127.0.0.1:0", "--log-frames"]);
    let mut s = server.connect();
    assert_eq!(common::ask(&mut s, "SAP 4, 0, 1234").unwrap().status, 100);
    assert_eq!(common::ask(&mut s, "GAP 4, 0").unwrap().value, 1234);
    server.logged(&["← 02 01 64 06"]).expect("the reply to GAP logged");
    let log = server.log.lock().unwrap().join("\n");
    let lines: Vec<&str> = log.lines().filter(|l| l.contains(" tcp 127.0.0.1:")).collect();
    assert_eq!(lines.len(), 4, "{log}");
    assert!(lines[0].ends_with("→ 01 05 04 00 00 00 04 D2 E0  to 1: SAP 4, 0, 1234"), "{}", lines[0]);
    assert!(lines[3].contains("← 02 01 64 06 00 00 04 D2") && lines[3].ends_with("from 1: status 100 (ok), value 1234"), "{}", lines[3]);
    assert!(lines[0].starts_with("tmclsim: ") && lines[0].contains(" s tcp 127.0.0.1:"), "a time and the link: {}", lines[0]);
}

#[test]
#[cfg_attr(windows, ignore = "raw Ethernet is Linux's: Windows refuses --ethercat first")]
fn ethercat_needs_a_module_that_is_an_ethercat_slave() {
    let out = common::tmclsim(&["serve", "--module", "tmcm-1141", "--ethercat", "lo"]);
    assert!(!out.status.success());
    assert!(
        common::text(&out).contains("TMCM-1141 is no EtherCAT slave (its profile has no [features.ethercat])"),
        "{}",
        common::text(&out)
    );
}

#[test]
fn a_link_the_module_has_no_interface_for_is_refused() {
    // The SLCAN adapter lives on a pty: Unix only.
    #[cfg(unix)]
    {
        let dir = tempfile::tempdir().unwrap();
        let can = dir.path().join("can");
        let out = common::tmclsim(&["serve", "--module", "tmcm-1310", "--tcp", "127.0.0.1:0", "--slcan", can.to_str().unwrap()]);
        assert_eq!(out.status.code(), Some(2), "{}", common::text(&out));
        assert!(common::text(&out).contains("TMCM-1310 has no CAN interface (its interfaces: USB, EtherCAT)"), "{}", common::text(&out));
        assert!(!can.exists(), "no adapter was left behind");
    }
    let out = common::tmclsim(&["serve", "--bus", "tmcm-1141@1,tmcm-1310@2", "--tcp", "127.0.0.1:0"]);
    assert_eq!(out.status.code(), Some(2), "{}", common::text(&out));
    assert!(common::text(&out).contains("TMCM-1310 has no RS-485 interface"), "{}", common::text(&out));
}

/// What only Unix has (a pty, the SLCAN adapter on one, raw Ethernet) is
/// refused on Windows before anything is opened, naming what to use there.
#[test]
#[cfg(windows)]
fn links_only_unix_has_are_refused_on_windows_naming_the_alternative() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("x");
    let path = path.to_str().unwrap();
    for (args, expected) in [
        (&["--pty", path][..], "a pty is a Unix device; on Windows serve the module on a COM port with --serial COMn (a com0com"),
        (&["--tcp", "127.0.0.1:0", "--slcan", path][..], "on Windows serve the modules on --tcp"),
        (&["--module", "tmcm-1310", "--ethercat", "eth0"][..], "--ethercat eth0: raw Ethernet (an AF_PACKET socket) needs Linux"),
    ] {
        let (code, text) = tmclsim(&[&["serve"][..], args].concat());
        assert_eq!(code, Some(2), "{args:?}: {text}");
        assert!(text.contains(expected) && !text.contains("panicked"), "{args:?}: {text}");
        assert!(!dir.path().join("x").exists(), "nothing was made");
    }
}

#[test]
fn send_takes_parameter_names_as_the_console_does() {
    let server = common::Server::start(&["--tcp", "127.0.0.1:0", "--log-frames"]);
    let tcp = server.tcp();
    let (code, text) = tmclsim(&["send", "--tcp", &tcp, "SAP", "maximum_positioning_speed,", "0,", "1234"]);
    assert_eq!(code, Some(0), "{text}");
    assert!(text.contains("(SAP 4, 0, 1234)") && text.contains("status 100 (ok)"), "{text}");
    // The profile of the type the module reports (136 type 1) was asked,
    // because a name was given.
    assert_eq!(server.log_has("to 1: #136 1 0 0"), 1, "one 136 to find the profile");
    let (code, text) = tmclsim(&["send", "--tcp", &tcp, "--module", "tmcm-1141", "GAP", "max_pos_speed", "0"]);
    assert_eq!(code, Some(2), "{text}");
    assert!(text.contains("column 5: the TMCM-1141 has no axis parameter 'max_pos_speed'"), "{text}");
    let (code, text) = tmclsim(&["send", "--tcp", &tcp, "--module", "tmcm-1141", "GAP", "maximum_positioning_speed,", "0"]);
    assert_eq!(code, Some(0), "{text}");
    assert!(text.contains("value 1234"), "{text}");
    // Numbers need no profile: no 136 is sent for them.
    let (code, text) = tmclsim(&["send", "--tcp", &tcp, "GAP", "4,", "0"]);
    assert!(code == Some(0) && text.contains("value 1234"), "{text}");
    assert_eq!(server.log_has("to 1: #136 1 0 0"), 1, "still the one 136");
    server.stop();
}

#[test]
fn world_lists_its_commands_a_line_each_and_shows_the_load() {
    let (code, text) = tmclsim(&["world", "--help"]);
    assert_eq!(code, Some(0), "{text}");
    for command in ["  show [AXIS]", "  load AXIS TORQUE [FROM TO]", "  link mute on|off"] {
        assert!(text.lines().any(|l| l == command), "{command} on a line of its own: {text}");
    }
    let server = common::Server::start(&["--tcp", "127.0.0.1:0"]);
    let control = server.control();
    let (code, text) = tmclsim(&["world", "--control", &control, "help"]);
    assert_eq!(code, Some(0), "{text}");
    assert!(text.lines().any(|l| l == "  switch AXIS left|right|home press|release|auto"), "{text}");
    assert_eq!(tmclsim(&["world", "--control", &control, "load", "0", "80"]).0, Some(0));
    let (code, text) = tmclsim(&["world", "--control", &control, "show"]);
    assert!(code == Some(0) && text.trim_end().ends_with("load 80 %"), "{text}");
    server.stop();
}
