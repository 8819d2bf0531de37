//! The control socket's line protocol: commands change the world and the
//! link; bad lines get a readable error.

use crate::common;

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::time::Duration;
use tmclsim_firmware::{Eeprom, Module, Profile, World};
use tmclsim_protocol::Reply;
use tmclsim_server::{ServerConfig, start};

#[test]
fn control_lines_change_the_world_and_the_link() {
    let profile = Profile::built_in("tmcm-1141").unwrap();
    let module = Module::with_world(profile.clone(), Eeprom::new("TMCM-1141"), World::stage(1));
    let config = ServerConfig {
        tcp: Some("127.0.0.1:0".parse().unwrap()),
        control: Some("127.0.0.1:0".parse().unwrap()),
        ..ServerConfig::default()
    };
    let server = start(module, config).unwrap();
    let control = TcpStream::connect(server.endpoints().control.unwrap()).unwrap();
    let mut answers = BufReader::new(control.try_clone().unwrap());
    let mut say = |line: &str| -> String {
        (&control).write_all(format!("{line}\n").as_bytes()).unwrap();
        let mut a = String::new();
        answers.read_line(&mut a).unwrap();
        a.trim().to_string()
    };
    assert_eq!(say("input 3 1"), "ok");
    assert_eq!(say("temperature 130"), "ok");
    assert_eq!(say("fault 0 open-a on"), "ok");
    assert!(say("show").contains("home 0"));
    let shown = say("show");
    assert!(shown.contains("load 0 %"), "no load yet: {shown}");
    assert_eq!(say("load 0 80"), "ok");
    assert!(say("show 0").ends_with("home 0 load 80 %"), "the load the world puts on the axis");
    assert!(say("input x 1").starts_with("error: 'x' is not a valid input number"));
    assert!(say("switch 3 left press").contains("axis 3 does not exist"));
    assert!(say("frobnicate").starts_with("error: unknown command"));
    assert!(say("link jam").starts_with("error: link jam"));

    let mut s = TcpStream::connect(server.endpoints().tcp.unwrap()).unwrap();
    s.set_read_timeout(Some(Duration::from_millis(300))).unwrap();
    let mut ask = |line: &str| -> Option<[u8; 9]> {
        s.write_all(&common::frame(line)).unwrap();
        let mut b = [0u8; 9];
        s.read_exact(&mut b).ok().map(|_| b)
    };
    assert_eq!(Reply::decode(&ask("GIO 3, 0").unwrap()).unwrap().value, 1);
    assert_eq!(Reply::decode(&ask("GAP 208, 0").unwrap()).unwrap().value & 0x24, 0x24, "pre-warning and open load A");
    assert_eq!(say("link drop 2"), "ok");
    assert!(ask("GAP 4, 0").is_none());
    assert!(ask("GAP 4, 0").is_none());
    assert!(ask("GAP 4, 0").is_some());
    assert_eq!(say("link mute on"), "ok");
    assert!(ask("GAP 4, 0").is_none());
    assert_eq!(say("link clear"), "ok");
    assert!(Reply::decode(&ask("GAP 4, 0").unwrap()).is_some());
    server.stop();
}
