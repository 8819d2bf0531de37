//! `tmclsim profile`: every row the module's manual states shows `manual`.

use crate::common;

use common::tmclsim;

/// The rows of `tmclsim profile NAME` in one section (a heading line), as
/// (number, source of the default).
fn rows(name: &str, heading: &str) -> Vec<(u8, String)> {
    let o = tmclsim(&["profile", name]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8(o.stdout).unwrap();
    let section = text.split("\n\n").find(|s| s.starts_with(heading)).unwrap_or_else(|| panic!("no section {heading}:\n{text}"));
    section
        .lines()
        .skip(1)
        .map(|l| {
            let words: Vec<&str> = l.split_whitespace().collect();
            let source = words.iter().find(|w| ["manual", "sibling", "assumed"].contains(w)).expect("a source");
            (words[0].parse().unwrap(), source.to_string())
        })
        .collect()
}

/// The TMCM-351 V4.45 manual states these defaults (docs/modules.md): in
/// its tables (GP 65, 69, 70, 71, 77, 85 "default"), in its text (AP 130
/// "should always be set 1", AP 194 and 195 in §7.1, AP 214 "standard
/// value", GP 64 $E4, GP 84 in the SCO pages, GP 67 in §4.5.4) and by
/// its examples (GP 66 and 76: requests to 1, replies from 2).
#[test]
fn the_351_rows_its_manual_states_show_manual() {
    let axis = rows("tmcm-351", "Axis parameters");
    for n in [130, 194, 195, 214] {
        let (_, source) = axis.iter().find(|(m, _)| *m == n).unwrap_or_else(|| panic!("AP {n}"));
        assert_eq!(source, "manual", "AP {n}");
    }
    let bank0 = rows("tmcm-351", "Global parameters, bank 0");
    for n in [64, 65, 66, 67, 69, 70, 71, 76, 77, 84, 85] {
        let (_, source) = bank0.iter().find(|(m, _)| *m == n).unwrap_or_else(|| panic!("GP {n}"));
        assert_eq!(source, "manual", "GP {n}");
    }
    // Every AP of §5 (pp.67-70) and 197 (p.80) is there.
    let numbers: Vec<u8> = axis.iter().map(|(n, _)| *n).collect();
    let manual = [
        0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 130, 135, 138, 140, 141, 149, 153, 154, 193, 194, 195, 196, 197, 200, 203, 204, 205,
        206, 207, 208, 209, 210, 211, 212, 213, 214,
    ];
    assert_eq!(numbers, manual);
}
