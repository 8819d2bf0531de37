//! ASCII mode (TMCM-1141 manual 3.4): entering and leaving, the three echo
//! modes, backspace editing, addressing, permitted commands, replies.

use crate::common;

use common::BusOfOne;
use tmclsim_protocol::mnemonic::parse_line;
use tmclsim_protocol::{Reply, Request};

fn binary(m: &mut BusOfOne, line: &str) -> Option<Reply> {
    m.handle_frame(&Request::new(1, parse_line(line).unwrap()).encode()).map(|f| Reply::decode(&f).unwrap())
}

fn type_text(m: &mut BusOfOne, text: &str) -> String {
    let mut out = Vec::new();
    for b in text.bytes() {
        m.ascii_byte(b, &mut out);
    }
    String::from_utf8(out).unwrap()
}

fn ascii_module() -> BusOfOne {
    let mut m = BusOfOne::built_in("tmcm-1141");
    assert_eq!(binary(&mut m, "#139 0 0 0").unwrap().status, 100);
    assert!(m.ascii_mode());
    m
}

#[test]
fn reply_format_and_echo_each_character() {
    let mut m = ascii_module();
    binary_free_sap(&mut m);
    // Echo mode 00: every character as it comes, then CR and the reply.
    assert_eq!(type_text(&mut m, "AGAP 1, 0\r"), "AGAP 1, 0\rBA 100 -5000\r");
    // Spaces after the address character are allowed.
    assert_eq!(type_text(&mut m, "A GAP 1, 0\r"), "A GAP 1, 0\rBA 100 -5000\r");
}

fn binary_free_sap(m: &mut BusOfOne) {
    // ASCII mode is on; set the position through ASCII too.
    let out = type_text(m, "ASAP 1, 0, -5000\r");
    assert!(out.ends_with("BA 100 -5000\r"), "{out:?}");
}

#[test]
fn echo_whole_line_and_no_echo() {
    let mut m = ascii_module();
    type_text(&mut m, "ASGP 67, 0, 16\r"); // bit 4: echo the line after CR
    assert_eq!(type_text(&mut m, "AGGP 67, 0\r"), "AGGP 67, 0\rBA 100 16\r");
    type_text(&mut m, "ASGP 67, 0, 32\r"); // bit 5: no echo
    assert_eq!(type_text(&mut m, "AGGP 67, 0\r"), "BA 100 32\r");
}

#[test]
fn backspace_editing() {
    let mut m = ascii_module();
    let out = type_text(&mut m, "AGAP 5\x08\x08 1, 0\r");
    assert!(out.ends_with("BA 100 0\r"), "{out:?}");
    assert!(out.contains('\x08'), "backspaces are echoed: {out:?}");
}

#[test]
fn other_addresses_are_ignored() {
    let mut m = ascii_module();
    assert_eq!(type_text(&mut m, "BGAP 1, 0\r"), "");
    m.handle_frame(&[0; 9]); // binary bytes are not for a module in ASCII mode
    type_text(&mut m, "ASGP 66, 0, 3\r");
    assert!(type_text(&mut m, "CGAP 4, 0\r").ends_with("BC 100 1000\r"));
}

#[test]
fn only_permitted_commands_run() {
    let mut m = ascii_module();
    assert_eq!(type_text(&mut m, "ACALC ADD, 5\r"), "ACALC ADD, 5\rBA 2 5\r");
    assert_eq!(m.registers().accumulator, 0);
    assert_eq!(type_text(&mut m, "AFOO 1\r"), "AFOO 1\rBA 2 0\r");
    assert_eq!(type_text(&mut m, "AGAP x\r"), "AGAP x\rBA 3 0\r");
    // Manual's examples of valid lines (motor numbers of this module).
    assert!(type_text(&mut m, "AMVP ABS, 0, 50000\r").ends_with("BA 100 50000\r"));
    assert!(type_text(&mut m, "A MVP ABS, 0, 50000\r").ends_with("BA 100 50000\r"));
    assert!(type_text(&mut m, "AROL 0, 500\r").ends_with("BA 100 500\r"));
    assert!(type_text(&mut m, "A MST 0\r").ends_with("BA 100 0\r"));
}

#[test]
fn run_stop_and_bin() {
    let mut m = ascii_module();
    // A program downloaded earlier runs with RUN and stops with STOP.
    m.load_program(&[parse_line("CALCV ADD, 5, 1").unwrap(), parse_line("JA 0").unwrap()]).unwrap();
    type_text(&mut m, "ARUN\r");
    m.advance(1_000_000);
    assert!(m.user_variable_value(5) > 0);
    type_text(&mut m, "ASTOP\r");
    let v = m.user_variable_value(5);
    m.advance(1_000_000);
    assert_eq!(m.user_variable_value(5), v);
    assert!(type_text(&mut m, "ABIN\r").ends_with("BA 100 0\r"));
    assert!(!m.ascii_mode());
    assert_eq!(binary(&mut m, "GAP 4, 0").unwrap().value, 1000);
}

#[test]
fn start_up_in_ascii_mode_with_gp67() {
    let mut m = BusOfOne::built_in("tmcm-1141");
    binary(&mut m, "SGP 67, 0, 1");
    assert!(!m.ascii_mode(), "takes effect at the next start");
    binary(&mut m, "#255 0 0 1234");
    assert!(m.ascii_mode());
}

/// docs/behaviour.md rule 83: two links type two lines; neither joins the
/// other's characters, and a line left over from before the module last
/// entered ASCII mode is dropped.
#[test]
fn each_link_types_its_own_line() {
    use tmclsim_firmware::ascii::AsciiLine;
    let mut m = ascii_module();
    assert_eq!(type_text(&mut m, "ASGP 67, 0, 32\r"), "ASGP 67, 0, 32\rBA 100 32\r");
    let (mut a, mut b) = (AsciiLine::default(), AsciiLine::default());
    let typed = |m: &mut BusOfOne, line: &mut AsciiLine, text: &str| {
        let mut out = Vec::new();
        for byte in text.bytes() {
            m.ascii_byte_on(line, byte, &mut out);
        }
        String::from_utf8(out).unwrap()
    };
    assert_eq!(typed(&mut m, &mut a, "AGAP 4"), "");
    assert_eq!(typed(&mut m, &mut b, "ASAP 4, 0, 321\r"), "BA 100 321\r");
    assert_eq!(typed(&mut m, &mut a, ", 0\r"), "BA 100 321\r");
    // A partial line, then BIN from the other link and ASCII mode again.
    assert_eq!(typed(&mut m, &mut a, "AGAP 4"), "");
    assert_eq!(typed(&mut m, &mut b, "ABIN\r"), "BA 100 0\r");
    assert_eq!(binary(&mut m, "#139 0 0 0").unwrap().status, 100);
    assert_eq!(typed(&mut m, &mut a, ", 0\r"), "", "', 0' alone is addressed to nobody");
    assert_eq!(typed(&mut m, &mut a, "AGAP 4, 0\r"), "BA 100 321\r");
}
