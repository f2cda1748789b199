//! Small lexing tools the program readers share: numbers with their byte
//! ranges, line numbers of byte offsets, the motion order, and rewriting
//! byte ranges with every other byte kept.

use std::collections::HashMap;
use std::ops::Range;

use super::{ParseError, Target};
use crate::engine::base::numeric::plural;

/// Longest piece of a file quoted in a message, characters: a message
/// names what is wrong, it does not echo a megabyte line.
pub const MAX_SHOWN_CHARS: usize = 60;

/// `text` cut to [`MAX_SHOWN_CHARS`] with `…` when longer.
pub(super) fn shown(text: &str) -> String {
    let text = text.trim();
    let mut out: String = text.chars().take(MAX_SHOWN_CHARS).collect();
    if text.chars().count() > MAX_SHOWN_CHARS {
        out.push('…');
    }
    out
}

/// 1-based line numbers of byte offsets, by binary search over the line
/// starts (built once, linear in the text).
pub(super) struct Lines {
    starts: Vec<usize>,
}

impl Lines {
    pub(super) fn new(text: &str) -> Self {
        let mut starts = vec![0];
        starts.extend(
            text.bytes()
                .enumerate()
                .filter(|(_, b)| *b == b'\n')
                .map(|(i, _)| i + 1),
        );
        Self { starts }
    }

    /// The 1-based line of byte `at`.
    pub(super) fn line(&self, at: usize) -> usize {
        match self.starts.binary_search(&at) {
            Ok(i) => i + 1,
            Err(i) => i,
        }
    }
}

/// The number literal that starts at byte `at` of `text` (an optional
/// sign, digits with an optional point, an optional exponent: `-12`,
/// `.5`, `-.858`, `9E+09`), with its byte range, or `None`.
pub(super) fn number_at(text: &str, at: usize) -> Option<(f64, Range<usize>)> {
    let bytes = text.as_bytes();
    let mut i = at;
    if i < bytes.len() && (bytes[i] == b'-' || bytes[i] == b'+') {
        i += 1;
    }
    let digits_start = i;
    while i < bytes.len() && bytes[i].is_ascii_digit() {
        i += 1;
    }
    let mut mantissa_digits = i - digits_start;
    if i < bytes.len() && bytes[i] == b'.' {
        i += 1;
        let frac = i;
        while i < bytes.len() && bytes[i].is_ascii_digit() {
            i += 1;
        }
        mantissa_digits += i - frac;
    }
    if mantissa_digits == 0 {
        return None;
    }
    if i < bytes.len() && (bytes[i] == b'e' || bytes[i] == b'E') {
        let mut j = i + 1;
        if j < bytes.len() && (bytes[j] == b'-' || bytes[j] == b'+') {
            j += 1;
        }
        let exp_start = j;
        while j < bytes.len() && bytes[j].is_ascii_digit() {
            j += 1;
        }
        if j > exp_start {
            i = j;
        }
    }
    let value: f64 = text.get(at..i)?.parse().ok()?;
    Some((value, at..i))
}

/// Skips spaces and tabs (not newlines) from `at`.
pub(super) fn skip_blanks(text: &str, mut at: usize) -> usize {
    let bytes = text.as_bytes();
    while at < bytes.len() && (bytes[at] == b' ' || bytes[at] == b'\t' || bytes[at] == b'\r') {
        at += 1;
    }
    at
}

/// Skips any whitespace, newlines included, from `at`.
pub(super) fn skip_space(text: &str, mut at: usize) -> usize {
    let bytes = text.as_bytes();
    while at < bytes.len() && bytes[at].is_ascii_whitespace() {
        at += 1;
    }
    at
}

/// The last run of digits in `name` as a number (`P[3]` → 3, `p10` →
/// 10, `XP12` → 12).
pub(super) fn last_number(name: &str) -> Option<u64> {
    let mut last = None;
    let mut current = String::new();
    for c in name.chars().chain(std::iter::once(' ')) {
        if c.is_ascii_digit() {
            current.push(c);
        } else if !current.is_empty() {
            last = current.parse().ok();
            current.clear();
        }
    }
    last
}

/// Whether `text` holds a URScript pose literal `p[` (the `p` not part of
/// a longer name).
pub(super) fn contains_ur_pose(text: &str) -> bool {
    ur_pose_starts(text).next().is_some()
}

/// Byte offsets of each `p[` that starts a URScript pose literal.
pub(super) fn ur_pose_starts(text: &str) -> impl Iterator<Item = usize> + '_ {
    let bytes = text.as_bytes();
    text.match_indices("p[").map(|(i, _)| i).filter(move |&i| {
        i == 0 || {
            let b = bytes[i - 1];
            !(b.is_ascii_alphanumeric() || b == b'_')
        }
    })
}

/// `text` with each range replaced by its text; ranges must not overlap.
pub(super) fn replace_ranges(text: &str, mut edits: Vec<(Range<usize>, &str)>) -> String {
    edits.sort_by_key(|(r, _)| r.start);
    let mut out = String::with_capacity(text.len() + 16 * edits.len());
    let mut at = 0;
    for (range, new) in edits {
        if range.start < at || range.end > text.len() {
            continue;
        }
        out.push_str(&text[at..range.start]);
        out.push_str(new);
        at = range.end;
    }
    out.push_str(&text[at..]);
    out
}

/// The order the robot went to the targets: the first move to each, when
/// the program's motion instructions name any (`visits`), else the order
/// written. With the order, a sentence saying which it is, and warnings
/// for targets never moved to or moved to twice.
pub(super) fn motion_order(
    targets: &[Target],
    visits: &[usize],
) -> (Vec<usize>, String, Vec<String>) {
    let written: Vec<usize> = (0..targets.len()).collect();
    if visits.is_empty() {
        return (
            written,
            format!(
                "{} in the order written",
                plural(targets.len(), "pose", "poses")
            ),
            Vec::new(),
        );
    }
    let mut seen: HashMap<usize, usize> = HashMap::new();
    let mut order = Vec::new();
    for &v in visits {
        let count = seen.entry(v).or_insert(0);
        if *count == 0 {
            order.push(v);
        }
        *count += 1;
    }
    let mut warnings = Vec::new();
    let never: Vec<&str> = targets
        .iter()
        .enumerate()
        .filter(|(i, _)| !seen.contains_key(i))
        .map(|(_, t)| t.name.as_str())
        .collect();
    if !never.is_empty() {
        warnings.push(format!(
            "{} never moved to by the program's motion instructions: left out ({})",
            if never.len() == 1 {
                "1 position is".to_string()
            } else {
                format!("{} positions are", never.len())
            },
            name_list(&never)
        ));
    }
    let mut repeated: Vec<(usize, usize)> = seen.into_iter().filter(|(_, c)| *c > 1).collect();
    repeated.sort_unstable();
    if !repeated.is_empty() {
        let names: Vec<String> = repeated
            .iter()
            .map(|(i, c)| format!("{} ({c}×)", targets[*i].name))
            .collect();
        warnings.push(format!(
            "moved to more than once, the first move counts: {}",
            names.join(", ")
        ));
    }
    let note = if order == written {
        format!(
            "{} in the order written, which is the order the motion instructions move through them",
            plural(order.len(), "pose", "poses")
        )
    } else {
        format!(
            "{} in the order the motion instructions first move to them (it differs from the order written: {})",
            plural(order.len(), "pose", "poses"),
            name_list(
                &order
                    .iter()
                    .map(|&i| targets[i].name.as_str())
                    .collect::<Vec<_>>()
            )
        )
    };
    (order, note, warnings)
}

/// Up to 12 names joined with commas, then "… (n in all)".
pub fn name_list<S: AsRef<str>>(names: &[S]) -> String {
    let names: Vec<&str> = names.iter().map(AsRef::as_ref).collect();
    if names.len() <= 12 {
        names.join(", ")
    } else {
        format!("{}, … ({} in all)", names[..12].join(", "), names.len())
    }
}

/// Byte ranges of the comments of `text` for a language whose comments
/// run from `marker` to the end of the line, outside double-quoted
/// strings; `inside(ranges, at)` then says whether a byte is in one.
pub(super) fn line_comments(text: &str, marker: u8) -> Vec<Range<usize>> {
    let bytes = text.as_bytes();
    let mut out = Vec::new();
    let mut in_string = false;
    let mut i = 0;
    while i < bytes.len() {
        let b = bytes[i];
        if b == b'\n' {
            in_string = false;
        } else if b == b'"' {
            in_string = !in_string;
        } else if b == marker && !in_string {
            let end = bytes[i..]
                .iter()
                .position(|&c| c == b'\n')
                .map_or(bytes.len(), |p| i + p);
            out.push(i..end);
            i = end;
            continue;
        }
        i += 1;
    }
    out
}

/// Where a motion instruction's arguments read their targets: the
/// program's text case-folded (names are matched without case), the byte
/// an inline literal opens with, and the targets of those literals by the
/// offset of that byte.
pub(super) struct MotionArguments<'a> {
    /// The whole text, upper- or lower-cased (the same byte offsets).
    pub folded: &'a str,
    /// `[` for RAPID's `[[x,y,z],…]`, `{` for KRL's `{X …}`.
    pub opener: u8,
    /// An inline literal's target by the offset of its opener.
    pub inline_at: &'a HashMap<usize, usize>,
}

impl MotionArguments<'_> {
    /// The targets of up to `count` comma-separated arguments from `at`
    /// (just after the instruction's word), pushed onto `visits`: an
    /// inline literal (which ends the list), or a name of `name_byte`
    /// bytes that `lookup` knows. Anything but a comma after a name ends
    /// the list.
    ///
    /// # Errors
    /// The byte range of a function called where a target should be
    /// (`Offs(p2, 0, 0, 10)`, `RelTool(…)`, `pose_trans(…)`): the robot
    /// goes to a position computed at run time, not to one in the file.
    pub(super) fn read(
        &self,
        at: usize,
        count: usize,
        name_byte: impl Fn(u8) -> bool,
        lookup: impl Fn(&str) -> Option<usize>,
        visits: &mut Vec<usize>,
    ) -> Result<(), Range<usize>> {
        let bytes = self.folded.as_bytes();
        let mut i = skip_space(self.folded, at);
        for _ in 0..count {
            if bytes.get(i) == Some(&self.opener) {
                if let Some(&t) = self.inline_at.get(&i) {
                    visits.push(t);
                }
                return Ok(());
            }
            let end = i + bytes[i..].iter().take_while(|b| name_byte(**b)).count();
            if end > i && bytes.get(skip_space(self.folded, end)) == Some(&b'(') {
                return Err(i..end);
            }
            if let Some(t) = lookup(&self.folded[i..end]) {
                visits.push(t);
            }
            i = skip_space(self.folded, end);
            if bytes.get(i) == Some(&b',') {
                i = skip_space(self.folded, i + 1);
            } else {
                return Ok(());
            }
        }
        Ok(())
    }
}

/// The error of a motion to a computed position: naming the function and
/// its line.
pub(super) fn computed_motion(text: &str, lines: &Lines, call: Range<usize>) -> ParseError {
    (
        lines.line(call.start),
        format!(
            "a motion to `{}(…)`, a position computed when the program runs (an offset or a tool-relative move): its pose is not in the file; write the position reached as a target",
            shown(&text[call])
        ),
    )
}

/// Whether byte `at` lies in one of the sorted, disjoint `ranges`.
pub(super) fn inside(ranges: &[Range<usize>], at: usize) -> bool {
    let i = ranges.partition_point(|r| r.end <= at);
    ranges.get(i).is_some_and(|r| r.start <= at)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_keep_their_ranges() {
        let t = "X =  -.858 mm, 9E+09, 1.5e-3x, -12";
        assert_eq!(number_at(t, 5), Some((-0.858, 5..10)));
        assert_eq!(number_at(t, 15), Some((9e9, 15..20)));
        assert_eq!(number_at(t, 22), Some((1.5e-3, 22..28)));
        assert_eq!(number_at(t, 31), Some((-12.0, 31..34)));
        assert_eq!(number_at(t, 0), None);
        assert_eq!(number_at("-.", 0), None);
    }

    #[test]
    fn lines_of_offsets() {
        let l = Lines::new("a\nbc\n\nd");
        assert_eq!(l.line(0), 1);
        assert_eq!(l.line(2), 2);
        assert_eq!(l.line(5), 3);
        assert_eq!(l.line(6), 4);
    }

    #[test]
    fn names_give_numbers() {
        assert_eq!(last_number("P[3]"), Some(3));
        assert_eq!(last_number("XP12"), Some(12));
        assert_eq!(last_number("jt_p4"), Some(4));
        assert_eq!(last_number("home"), None);
    }

    #[test]
    fn ranges_are_replaced_and_the_rest_kept() {
        let t = "a=1, b=22, c=333";
        let out = replace_ranges(t, vec![(13..16, "4"), (2..3, "55")]);
        assert_eq!(out, "a=55, b=22, c=4");
    }

    #[test]
    fn comments_are_found_outside_strings() {
        let t = "x := 1; ! one\ns := \"a!b\"; ! two\n";
        let c = line_comments(t, b'!');
        assert_eq!(c.len(), 2);
        assert!(inside(&c, 9));
        assert!(!inside(&c, 22));
    }
}
