//! Parameter names as the console takes them: the profile's name in lower
//! case with `_` between words (`actual_position`, `max_current`).

use tmclsim_profile::Parameter;
use tmclsim_profile::Profile;

/// `Actual position` → `actual_position`; `Maximum speed (pps)` →
/// `maximum_speed_pps`.
pub fn snake(name: &str) -> String {
    let mut out = String::new();
    for c in name.chars() {
        if c.is_ascii_alphanumeric() {
            out.push(c.to_ascii_lowercase());
        } else if !out.is_empty() && !out.ends_with('_') {
            out.push('_');
        }
    }
    out.trim_end_matches('_').to_string()
}

/// Which table a command's type operand names.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Table {
    Axis,
    Global,
}

/// The table of the opcode's type operand, if it names a parameter.
pub fn table_of(opcode: u8) -> Option<Table> {
    use tmclsim_protocol::opcode as op;
    match opcode {
        op::SAP | op::GAP | op::STAP | op::RSAP | op::AAP => Some(Table::Axis),
        op::SGP | op::GGP | op::STGP | op::RSGP | op::AGP => Some(Table::Global),
        _ => None,
    }
}

/// Every parameter of a table with its bank (0 for axis parameters).
pub fn parameters(profile: &Profile, table: Table) -> Vec<(u8, &Parameter)> {
    match table {
        Table::Axis => profile.axis_parameters().map(|p| (0, p)).collect(),
        Table::Global => (0..=3u8).flat_map(|b| profile.global_parameters(b).map(move |p| (b, p))).collect(),
    }
}

/// A parameter by its console name (or its number), in `bank` when given.
pub fn find<'p>(profile: &'p Profile, table: Table, word: &str, bank: Option<u8>) -> Option<(u8, &'p Parameter)> {
    let number = tmclsim_protocol::mnemonic::parse_number(word);
    parameters(profile, table)
        .into_iter()
        .find(|(b, p)| bank.is_none_or(|x| x == *b) && number.map_or_else(|| snake(p.label()) == snake(word), |n| n == i64::from(p.number)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_in_snake_case() {
        assert_eq!(snake("Actual position"), "actual_position");
        assert_eq!(snake("Maximum speed (pps)"), "maximum_speed_pps");
        assert_eq!(snake("User variables #0…#55"), "user_variables_0_55");
    }

    #[test]
    fn found_by_name_or_number_in_their_table() {
        let p = Profile::built_in("tmcm-1141").unwrap();
        assert_eq!(find(&p, Table::Axis, "actual_position", None).map(|(_, q)| q.number), Some(1));
        assert_eq!(find(&p, Table::Axis, "Actual_Position", None).map(|(_, q)| q.number), Some(1));
        assert_eq!(find(&p, Table::Axis, "4", None).map(|(_, q)| q.number), Some(4));
        assert!(find(&p, Table::Axis, "tmcl_tick_timer", None).is_none());
        assert_eq!(find(&p, Table::Global, "tmcl_tick_timer", None).map(|(b, q)| (b, q.number)), Some((0, 132)));
        assert_eq!(find(&p, Table::Global, "user_variable_17", Some(2)).map(|(b, q)| (b, q.number)), Some((2, 17)));
    }
}
