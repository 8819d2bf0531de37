//! "Did you mean …?": the closest known name to a mistyped one, for the
//! assembler's diagnostics and the command-line parsers.

/// The candidate closest to `name` (case-insensitive edit distance), if it
/// is close enough to be a likely typo.
pub fn closest<'a>(name: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let wanted = name.to_ascii_lowercase();
    let limit = (wanted.chars().count() / 3).max(1);
    let mut best: Option<(usize, &str)> = None;
    for candidate in candidates {
        if candidate == name {
            continue;
        }
        let d = edit_distance(&wanted, &candidate.to_ascii_lowercase());
        if d <= limit && best.is_none_or(|(bd, _)| d < bd) {
            best = Some((d, candidate));
        }
    }
    best.map(|(_, c)| c)
}

/// ` (did you mean 'Loop'?)` or nothing.
pub fn suggestion<'a>(name: &str, candidates: impl IntoIterator<Item = &'a str>) -> String {
    closest(name, candidates).map_or(String::new(), |c| format!(" (did you mean '{c}'?)"))
}

/// Edit distance over characters where swapping two neighbours counts as
/// one edit (optimal string alignment), so `Strat` is one edit from `Start`.
fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    let mut d = vec![vec![0usize; b.len() + 1]; a.len() + 1];
    for (i, row) in d.iter_mut().enumerate() {
        row[0] = i;
    }
    for (j, cell) in d[0].iter_mut().enumerate() {
        *cell = j;
    }
    for i in 1..=a.len() {
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            let mut best = (d[i - 1][j] + 1).min(d[i][j - 1] + 1).min(d[i - 1][j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                best = best.min(d[i - 2][j - 2] + 1);
            }
            d[i][j] = best;
        }
    }
    d[a.len()][b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn typos_find_their_name() {
        assert_eq!(closest("GAPP", ["GAP", "SAP", "MVP"]), Some("GAP"));
        assert_eq!(closest("mvp", ["MVP"]), Some("MVP"));
        assert_eq!(closest("Strat", ["Start"]), Some("Start"), "a swap is one edit");
        assert_eq!(closest("XYZZY", ["GAP"]), None);
        assert_eq!(suggestion("ROLL", ["ROL", "ROR"]), " (did you mean 'ROL'?)");
    }

    #[test]
    fn suggestions_for_labels() {
        assert_eq!(closest("Lop", ["Start", "Loop"]), Some("Loop"));
        assert_eq!(closest("loop", ["Loop"]), Some("Loop"));
        assert_eq!(closest("MVPP", ["MVP", "MST"]), Some("MVP"));
        assert_eq!(closest("Strat", ["Start"]), Some("Start"));
        assert_eq!(closest("Zebra", ["Loop"]), None);
        assert_eq!(suggestion("Zebra", ["Loop"]), "");
    }
}
