//! "Did you mean …?" for mistyped names: the known name closest to what was
//! given, by the optimal-string-alignment distance (Levenshtein with
//! adjacent transpositions; Damerau 1964), case-insensitive, when it is
//! close enough to be the likely intent and no other name is as close.

/// " (did you mean `NAME`?)" for the one known name within
/// max(1, ⌊len/3⌋) edits of a `given` of three characters or more (a
/// one-letter key is one edit from every other: `n` is no typo of `m`), or
/// the one known name that such a `given` begins, else the empty string: a
/// message reads the same with or without it.
pub fn did_you_mean<'a>(given: &str, known: impl IntoIterator<Item = &'a str>) -> String {
    let given = given.trim().to_lowercase();
    if given.is_empty() {
        return String::new();
    }
    let length = given.chars().count();
    let limit = if length >= 3 { (length / 3).max(1) } else { 0 };
    let mut best: Option<(usize, &str)> = None;
    let mut tie = false;
    let mut prefixed = Vec::new();
    for name in known {
        let lower = name.to_lowercase();
        if length >= 3 && lower.starts_with(&given) {
            prefixed.push(name);
        }
        let d = distance(&given, &lower);
        match best {
            Some((b, _)) if d > b => {}
            Some((b, _)) if d == b => tie = true,
            _ => {
                best = Some((d, name));
                tie = false;
            }
        }
    }
    let chosen = match best {
        Some((d, name)) if d <= limit && !tie => Some(name),
        _ if prefixed.len() == 1 => Some(prefixed[0]),
        _ => None,
    };
    chosen.map_or(String::new(), |name| format!(" (did you mean `{name}`?)"))
}

/// The optimal-string-alignment distance between `a` and `b` (insertions,
/// deletions, substitutions and swaps of adjacent characters, each 1).
fn distance(a: &str, b: &str) -> usize {
    let (a, b): (Vec<char>, Vec<char>) = (a.chars().collect(), b.chars().collect());
    // Three rows of the dynamic programme: i − 2, i − 1 and i.
    let mut before: Vec<usize> = vec![0; b.len() + 1];
    let mut previous: Vec<usize> = (0..=b.len()).collect();
    let mut current = vec![0; b.len() + 1];
    for i in 1..=a.len() {
        current[0] = i;
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            let mut d = (previous[j] + 1)
                .min(current[j - 1] + 1)
                .min(previous[j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                d = d.min(before[j - 2] + 1);
            }
            current[j] = d;
        }
        std::mem::swap(&mut before, &mut previous);
        std::mem::swap(&mut previous, &mut current);
    }
    previous[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    const SAMPLERS: [&str; 6] = [
        "random",
        "jitter",
        "uniform-jitter",
        "cmj",
        "poisson-disk",
        "sobol",
    ];

    #[test]
    fn distances_count_edits_and_swaps() {
        assert_eq!(distance("jitter", "jitter"), 0);
        assert_eq!(distance("jiter", "jitter"), 1);
        assert_eq!(distance("jtiter", "jitter"), 1);
        assert_eq!(distance("", "cmj"), 3);
        assert_eq!(distance("kitten", "sitting"), 3);
    }

    #[test]
    fn close_names_are_suggested() {
        assert_eq!(did_you_mean("jiter", SAMPLERS), " (did you mean `jitter`?)");
        assert_eq!(
            did_you_mean("Poison-Disk", SAMPLERS),
            " (did you mean `poisson-disk`?)"
        );
        assert_eq!(
            did_you_mean("poisson", SAMPLERS),
            " (did you mean `poisson-disk`?)"
        );
        assert_eq!(did_you_mean("cjm", SAMPLERS), " (did you mean `cmj`?)");
        // Names are case-sensitive: a capital is a typo too.
        assert_eq!(did_you_mean("CMJ", SAMPLERS), " (did you mean `cmj`?)");
    }

    #[test]
    fn far_or_ambiguous_names_are_not() {
        assert_eq!(did_you_mean("halton", SAMPLERS), "");
        assert_eq!(did_you_mean("", SAMPLERS), "");
        assert_eq!(did_you_mean("xy", ["xu", "xv"]), "");
        assert_eq!(did_you_mean("n", ["m"]), "");
    }
}
