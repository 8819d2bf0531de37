//! "Did you mean …?": the closest known name to a mistyped one, for the
//! assembler's diagnostics and the command-line parsers.

/// The candidate closest to `name` (case-insensitive edit distance), if it
/// is close enough to be a likely typo. Of equally close candidates, the
/// first wins.
pub fn closest<'a>(name: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let mut unlimited = u64::MAX;
    closest_within(name, candidates, &mut unlimited)
}

/// [`closest`] with a limit on the work: comparing a candidate costs the
/// cells of the distance table it fills (at most the product of the two
/// lengths in characters plus one), taken from `budget`. When the budget could not
/// pay for the next candidate, it is spent (set to 0) and nothing is
/// found, so a search over huge name tables stays bounded and its answer
/// does not depend on timing.
pub fn closest_within<'a>(name: &str, candidates: impl IntoIterator<Item = &'a str>, budget: &mut u64) -> Option<&'a str> {
    let wanted: Vec<char> = name.chars().map(|c| c.to_ascii_lowercase()).collect();
    let limit = (wanted.len() / 3).max(1);
    let mut rows = Rows::default();
    let mut other: Vec<char> = Vec::new();
    let mut best: Option<(usize, &str)> = None;
    for candidate in candidates {
        if candidate == name {
            continue;
        }
        // The distance is at least the difference of the lengths.
        let length = candidate.chars().count();
        if length.abs_diff(wanted.len()) > limit {
            continue;
        }
        let most = (wanted.len() as u64 + 1) * (length as u64 + 1);
        if most > *budget {
            *budget = 0;
            return None;
        }
        other.clear();
        other.extend(candidate.chars().map(|c| c.to_ascii_lowercase()));
        let (d, cost) = rows.distance_within(&wanted, &other, limit);
        *budget -= cost;
        if let Some(d) = d
            && best.is_none_or(|(bd, _)| d < bd)
        {
            best = Some((d, candidate));
        }
    }
    best.map(|(_, c)| c)
}

/// ` (did you mean 'Loop'?)` or nothing.
pub fn suggestion<'a>(name: &str, candidates: impl IntoIterator<Item = &'a str>) -> String {
    closest(name, candidates).map_or(String::new(), |c| format!(" (did you mean '{c}'?)"))
}

/// The three rows of the distance table an edit distance needs, kept from
/// one candidate to the next.
#[derive(Default)]
struct Rows {
    before: Vec<usize>,
    last: Vec<usize>,
    this: Vec<usize>,
}

impl Rows {
    /// Edit distance over characters where swapping two neighbours counts
    /// as one edit (optimal string alignment), so `Strat` is one edit from
    /// `Start`; `None` once it is sure to pass `limit`. Also returns the
    /// cells of the table filled.
    fn distance_within(&mut self, a: &[char], b: &[char], limit: usize) -> (Option<usize>, u64) {
        let width = b.len() + 1;
        for row in [&mut self.before, &mut self.last, &mut self.this] {
            row.clear();
            row.resize(width, 0);
        }
        for (j, cell) in self.last.iter_mut().enumerate() {
            *cell = j;
        }
        let mut cells = width as u64;
        let mut last_min = 0;
        for i in 1..=a.len() {
            self.this[0] = i;
            let mut this_min = i;
            for j in 1..=b.len() {
                let cost = usize::from(a[i - 1] != b[j - 1]);
                let mut best = (self.last[j] + 1).min(self.this[j - 1] + 1).min(self.last[j - 1] + cost);
                if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                    best = best.min(self.before[j - 2] + 1);
                }
                self.this[j] = best;
                this_min = this_min.min(best);
            }
            cells += width as u64;
            // A cell is at least the smallest of the row above, or of the
            // row two above plus one: once two rows in a row pass the
            // limit, every later one does.
            if this_min > limit && last_min > limit {
                return (None, cells);
            }
            last_min = this_min;
            std::mem::swap(&mut self.before, &mut self.last);
            std::mem::swap(&mut self.last, &mut self.this);
        }
        let d = self.last[b.len()];
        ((d <= limit).then_some(d), cells)
    }
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

    #[test]
    fn the_first_of_equally_close_candidates_wins() {
        assert_eq!(closest("Lap", ["Lip", "Lop"]), Some("Lip"));
        assert_eq!(closest("Lap", ["Lop", "Lip"]), Some("Lop"));
    }

    #[test]
    fn a_spent_budget_finds_nothing() {
        let mut budget = 2 * (4 * 5);
        assert_eq!(closest_within("Lop", ["Loop", "Stop"], &mut budget), Some("Loop"));
        assert_eq!(budget, 0);
        // Too long or too short to be close: not compared, nothing spent.
        let mut budget = 1;
        assert_eq!(closest_within("Lop", ["LongLabel", "L"], &mut budget), None);
        assert_eq!(budget, 1);
        assert_eq!(closest_within("Lop", ["Loop"], &mut budget), None);
        assert_eq!(budget, 0);
    }

    #[test]
    fn a_distance_stops_once_it_passes_the_limit() {
        let mut rows = Rows::default();
        let chars = |s: &str| s.chars().collect::<Vec<char>>();
        let (a, b) = (chars("abcdefghijkl"), chars("zyxwvutsrqpo"));
        let (d, cells) = rows.distance_within(&a, &b, 4);
        assert_eq!(d, None);
        // Rows 0 to 6: the smallest cell of row i is i here.
        assert_eq!(cells, 13 * 7);
        assert_eq!(rows.distance_within(&a, &b, 12), (Some(12), 13 * 13));
        assert_eq!(rows.distance_within(&chars("strat"), &chars("start"), 1).0, Some(1));
    }
}
