//! JSON pose lists: a list of poses at the top level or under a key
//! (`RobPoses` as RobCalibrator's `.rob` writes it, `poses`, or the only
//! list), each pose a list of the convention's numbers (a matrix also as
//! 4 rows of 4). The syntax is checked by `serde_json` first (its message
//! names the line); the numbers are then found with their byte ranges by
//! a small scanner of our own, nesting bounded.

use std::ops::Range;

use super::lex::{Lines, number_at, shown, skip_space};
use super::{ParseError, Parsed, Target, TargetValue};
use crate::engine::base::robot::controller::FlangeConvention;

/// Deepest nesting read: a list of matrices is 3 deep.
const MAX_DEPTH: usize = 16;

/// A JSON value with the byte ranges of its numbers.
enum Node {
    Number(f64, Range<usize>),
    List(Vec<Node>),
    Object(Vec<(String, Node)>),
    Other,
}

/// Scans the value at `at`; returns it and the byte after it. The text is
/// known to be valid JSON.
fn value(text: &str, at: usize, depth: usize, lines: &Lines) -> Result<(Node, usize), ParseError> {
    if depth > MAX_DEPTH {
        return Err((
            lines.line(at),
            format!("nested deeper than {MAX_DEPTH}: not a pose list"),
        ));
    }
    let bytes = text.as_bytes();
    let i = skip_space(text, at);
    match bytes.get(i) {
        Some(b'[') => {
            let mut items = Vec::new();
            let mut j = skip_space(text, i + 1);
            if bytes.get(j) == Some(&b']') {
                return Ok((Node::List(items), j + 1));
            }
            loop {
                let (v, next) = value(text, j, depth + 1, lines)?;
                items.push(v);
                j = skip_space(text, next);
                match bytes.get(j) {
                    Some(b',') => j += 1,
                    Some(b']') => return Ok((Node::List(items), j + 1)),
                    _ => return Err((lines.line(j), "malformed list".to_string())),
                }
            }
        }
        Some(b'{') => {
            let mut members = Vec::new();
            let mut j = skip_space(text, i + 1);
            if bytes.get(j) == Some(&b'}') {
                return Ok((Node::Object(members), j + 1));
            }
            loop {
                let (key, after) =
                    string(text, j).ok_or_else(|| (lines.line(j), "malformed key".to_string()))?;
                if members.iter().any(|(k, _)| *k == key) {
                    return Err((
                        lines.line(j),
                        format!(
                            "the key `{}` is given twice in one object: which is meant?",
                            shown(&key)
                        ),
                    ));
                }
                let colon = skip_space(text, after);
                let (v, next) = value(text, colon + 1, depth + 1, lines)?;
                members.push((key, v));
                j = skip_space(text, next);
                match bytes.get(j) {
                    Some(b',') => j = skip_space(text, j + 1),
                    Some(b'}') => return Ok((Node::Object(members), j + 1)),
                    _ => return Err((lines.line(j), "malformed object".to_string())),
                }
            }
        }
        Some(b'"') => {
            let (_, after) =
                string(text, i).ok_or_else(|| (lines.line(i), "malformed string".to_string()))?;
            Ok((Node::Other, after))
        }
        Some(_) => {
            if let Some((v, r)) = number_at(text, i) {
                let end = r.end;
                return Ok((Node::Number(v, r), end));
            }
            let end = i + bytes[i..]
                .iter()
                .take_while(|b| b.is_ascii_alphabetic())
                .count();
            Ok((Node::Other, end.max(i + 1)))
        }
        None => Err((lines.line(i), "unexpected end".to_string())),
    }
}

/// The string whose `"` is at `at` (escapes kept as written) and the byte
/// after its closing quote.
fn string(text: &str, at: usize) -> Option<(String, usize)> {
    let bytes = text.as_bytes();
    if bytes.get(at) != Some(&b'"') {
        return None;
    }
    let mut i = at + 1;
    while i < bytes.len() {
        match bytes[i] {
            b'\\' => i += 2,
            b'"' => return Some((text[at + 1..i].to_string(), i + 1)),
            _ => i += 1,
        }
    }
    None
}

/// The numbers of a pose: a flat list, or a list of rows.
fn flat(node: &Node, out: &mut Vec<(f64, Range<usize>)>) -> bool {
    match node {
        Node::Number(v, r) => {
            out.push((*v, r.clone()));
            true
        }
        Node::List(items) => items.iter().all(|i| flat(i, out)),
        _ => false,
    }
}

/// Reads the poses of a JSON list in `convention`.
pub(super) fn read(text: &str, convention: FlangeConvention) -> Result<Parsed, ParseError> {
    let body = text.trim_start_matches('\u{feff}');
    if let Err(e) = serde_json::from_str::<serde::de::IgnoredAny>(body) {
        return Err((e.line(), format!("not valid JSON: {e}")));
    }
    let offset = text.len() - body.len();
    let lines = Lines::new(text);
    let (root, _) = value(text, offset, 0, &lines)?;
    let list = match root {
        Node::List(items) => items,
        Node::Object(members) => {
            let keys: Vec<String> = members.iter().map(|(k, _)| k.clone()).collect();
            let lists: Vec<(String, Node)> = members
                .into_iter()
                .filter(|(_, v)| matches!(v, Node::List(_)))
                .collect();
            let pick = lists
                .iter()
                .position(|(k, _)| {
                    k.eq_ignore_ascii_case("RobPoses") || k.eq_ignore_ascii_case("poses")
                })
                .or_else(|| (lists.len() == 1).then_some(0));
            match pick.and_then(|k| lists.into_iter().nth(k)) {
                Some((_, Node::List(items))) => items,
                _ => {
                    return Err((
                        0,
                        format!(
                            "no pose list: expected a key `RobPoses` or `poses`, or one list (the file has: {})",
                            keys.join(", ")
                        ),
                    ));
                }
            }
        }
        _ => return Err((0, "expected a JSON list of poses".to_string())),
    };
    let mut targets = Vec::with_capacity(list.len());
    for (k, item) in list.iter().enumerate() {
        let mut numbers = Vec::new();
        let first = match item {
            Node::List(_) | Node::Number(..) => {
                let ok = flat(item, &mut numbers);
                numbers.first().map(|(_, r)| r.start).filter(|_| ok)
            }
            _ => None,
        };
        let line = first.map_or(0, |b| lines.line(b));
        let Some(_) = first else {
            return Err((
                line,
                format!(
                    "pose {}: not a list of numbers ({})",
                    k + 1,
                    convention.describe()
                ),
            ));
        };
        if numbers.len() != convention.n_columns() {
            return Err((
                line,
                format!(
                    "pose {}: {} values given, the convention needs {} ({})",
                    k + 1,
                    numbers.len(),
                    convention.n_columns(),
                    convention.describe()
                ),
            ));
        }
        let (values, spans) = numbers.into_iter().unzip();
        let mut t = Target::new(
            format!("pose {}", k + 1),
            line,
            TargetValue::Pose { values, convention },
            spans,
        );
        t.number = Some(k as u64 + 1);
        targets.push(t);
    }
    Ok(Parsed {
        targets,
        visits: Vec::new(),
        warnings: Vec::new(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn robcalibrator_lists_and_matrices() {
        let text = "{ \"RobPoses\": [ [ -195.8, 1363.305, 524.812, -179.924, 0.889, 179.635 ],\n [ -185.745, 1363.314, 524.772, -179.923, 0.889, 179.636 ] ] }";
        let p = read(text, FlangeConvention::FanucWpr).unwrap();
        assert_eq!(p.targets.len(), 2);
        assert_eq!(p.targets[1].line, 2);
        assert_eq!(&text[p.targets[0].spans[0].clone()], "-195.8");
        let m = "[[[1,0,0,10],[0,1,0,20],[0,0,1,30],[0,0,0,1]]]";
        assert_eq!(read(m, FlangeConvention::Matrix).unwrap().targets.len(), 1);
        let (_, e) = read(
            r#"{"RobPoses": [[1, 2, 3, 4, 5]]}"#,
            FlangeConvention::FanucWpr,
        )
        .unwrap_err();
        assert!(e.contains("pose 1") && e.contains("5 values"), "{e}");
        let (line, e) = read("[\n[1,2,\n", FlangeConvention::FanucWpr).unwrap_err();
        assert!(line >= 2 && e.contains("not valid JSON"), "{e}");
    }
}
