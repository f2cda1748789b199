//! URScript programs (Universal Robots): the pose literals
//! `p[x, y, z, rx, ry, rz]` (m, rotation vector in rad), the joint lists
//! `[j1, …, j6]` (rad) given to `movej`/`movel`/`movep`/`servoj`, named
//! (`global p1 = p[…]`, `q1 = […]`) or inline, and the order the move
//! calls go to them. Comments run from `#` to the end of the line.

use std::collections::HashMap;
use std::ops::Range;

use super::lex::{
    Lines, computed_motion, inside, line_comments, number_at, skip_space, ur_pose_starts,
};
use super::{ParseError, Parsed, Target, TargetValue};
use crate::engine::base::robot::controller::FlangeConvention;

/// Move calls and how many targets each takes first.
const MOVES: [(&str, usize); 5] = [
    ("movej", 1),
    ("movel", 1),
    ("movep", 1),
    ("servoj", 1),
    ("movec", 2),
];

/// Numbers with their byte ranges.
type Numbers = Vec<(f64, Range<usize>)>;

/// The numbers of the list whose `[` is at `at`, with their ranges, and
/// the byte after `]`; `None` when it is not a flat list of numbers.
fn numbers(text: &str, at: usize) -> Option<(Numbers, usize)> {
    let bytes = text.as_bytes();
    let mut out = Vec::new();
    let mut i = at + 1;
    loop {
        i = skip_space(text, i);
        match bytes.get(i)? {
            b']' => return Some((out, i + 1)),
            b',' => i += 1,
            _ => {
                let (v, r) = number_at(text, i)?;
                i = r.end;
                out.push((v, r));
            }
        }
    }
}

/// The name assigned at `at` (`name = ` before it, `global`/`local` allowed).
fn assigned_name(text: &str, at: usize) -> Option<String> {
    let before = text[..at].trim_end();
    let before = before.strip_suffix('=')?;
    if before.ends_with(['=', '!', '<', '>']) {
        return None;
    }
    let before = before.trim_end();
    let start = before
        .rfind(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .map_or(0, |i| i + 1);
    let name = &before[start..];
    (!name.is_empty() && !name.starts_with(|c: char| c.is_ascii_digit())).then(|| name.to_string())
}

/// Reads the targets of `text`.
pub(super) fn read(text: &str) -> Result<Parsed, ParseError> {
    let lines = Lines::new(text);
    let comments = line_comments(text, b'#');
    let mut targets: Vec<Target> = Vec::new();
    for start in ur_pose_starts(text) {
        if inside(&comments, start) {
            continue;
        }
        let line = lines.line(start);
        let Some((values, _)) = numbers(text, start + 1) else {
            return Err((
                line,
                "`p[` is not followed by a list of numbers (x, y, z in m, rx, ry, rz in rad)"
                    .to_string(),
            ));
        };
        if values.len() != 6 {
            return Err((
                line,
                format!(
                    "a pose `p[…]` has {} numbers, it needs 6 (x, y, z in m, rx, ry, rz in rad)",
                    values.len()
                ),
            ));
        }
        let name = assigned_name(text, start).unwrap_or_else(|| format!("line {line}"));
        let (values, spans) = values.into_iter().unzip();
        targets.push(Target::new(
            name,
            line,
            TargetValue::Pose {
                values,
                convention: FlangeConvention::UrRotationVector,
            },
            spans,
        ));
    }
    // Joint lists: inline in a move call, or assigned to a name.
    let bytes = text.as_bytes();
    let mut joint_names: HashMap<String, usize> = HashMap::new();
    for (i, _) in text.match_indices('[') {
        if inside(&comments, i)
            || (i > 0
                && (bytes[i - 1] == b'p'
                    || bytes[i - 1].is_ascii_alphanumeric()
                    || bytes[i - 1] == b'_'))
        {
            continue;
        }
        let Some((values, _)) = numbers(text, i) else {
            continue;
        };
        if values.len() != 6 {
            continue;
        }
        let assigned = assigned_name(text, i);
        let in_move = move_before(text, i).is_some();
        if assigned.is_none() && !in_move {
            continue;
        }
        let line = lines.line(i);
        let name = assigned.clone().unwrap_or_else(|| format!("line {line}"));
        let (rad, spans): (Vec<f64>, Vec<Range<usize>>) = values.into_iter().unzip();
        if let Some(n) = &assigned {
            joint_names.insert(n.clone(), targets.len());
        }
        targets.push(Target::new(
            name,
            line,
            TargetValue::Joints {
                deg: rad.iter().map(|r| r.to_degrees()).collect(),
                radians: true,
            },
            spans,
        ));
    }
    targets.sort_by_key(|t| t.spans.first().map_or(0, |s| s.start));
    let visits = motion_visits(text, &comments, &targets)
        .map_err(|call| computed_motion(text, &Lines::new(text), call))?;
    // Named joint lists never moved to are variables, not targets.
    let moved: Vec<bool> = (0..targets.len()).map(|i| visits.contains(&i)).collect();
    let keep: Vec<usize> = (0..targets.len())
        .filter(|&i| {
            !(matches!(targets[i].value, TargetValue::Joints { .. })
                && joint_names.contains_key(&targets[i].name)
                && !moved[i])
        })
        .collect();
    if keep.len() == targets.len() {
        return Ok(Parsed {
            targets,
            visits,
            warnings: Vec::new(),
        });
    }
    let remap: HashMap<usize, usize> = keep
        .iter()
        .enumerate()
        .map(|(new, &old)| (old, new))
        .collect();
    let visits = visits
        .iter()
        .filter_map(|v| remap.get(v).copied())
        .collect();
    let targets = keep.into_iter().map(|i| targets[i].clone()).collect();
    Ok(Parsed {
        targets,
        visits,
        warnings: Vec::new(),
    })
}

/// The move call whose first argument starts at `at`, if any.
fn move_before(text: &str, at: usize) -> Option<&'static str> {
    let before = text[..at].trim_end().strip_suffix('(')?.trim_end();
    let start = before
        .rfind(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .map_or(0, |i| i + 1);
    MOVES
        .iter()
        .find(|(m, _)| *m == &before[start..])
        .map(|(m, _)| *m)
}

/// The targets the move calls go to, in program order.
///
/// # Errors
/// The byte range of a function called where a target should be
/// (`pose_trans(p2, …)`, `pose_add(…)`): a position computed at run time.
fn motion_visits(
    text: &str,
    comments: &[Range<usize>],
    targets: &[Target],
) -> Result<Vec<usize>, Range<usize>> {
    let by_name: HashMap<&str, usize> = targets
        .iter()
        .enumerate()
        .map(|(i, t)| (t.name.as_str(), i))
        .collect();
    // A literal is known by the byte of its first number.
    let by_first: HashMap<usize, usize> = targets
        .iter()
        .enumerate()
        .filter_map(|(i, t)| t.spans.first().map(|s| (s.start, i)))
        .collect();
    let bytes = text.as_bytes();
    let mut visits = Vec::new();
    for (name, count) in MOVES {
        for (at, _) in text.match_indices(name) {
            if inside(comments, at)
                || (at > 0 && (bytes[at - 1].is_ascii_alphanumeric() || bytes[at - 1] == b'_'))
            {
                continue;
            }
            let mut i = skip_space(text, at + name.len());
            if bytes.get(i) != Some(&b'(') {
                continue;
            }
            i = skip_space(text, i + 1);
            for _ in 0..count {
                let literal = match (bytes.get(i), bytes.get(i + 1)) {
                    (Some(b'p'), Some(b'[')) => Some(i + 2),
                    (Some(b'['), _) => Some(i + 1),
                    _ => None,
                };
                if let Some(open) = literal {
                    if let Some(&t) = by_first.get(&skip_space(text, open)) {
                        visits.push((at, t));
                    }
                } else {
                    let end = i + bytes[i..]
                        .iter()
                        .take_while(|b| b.is_ascii_alphanumeric() || **b == b'_')
                        .count();
                    if end > i && bytes.get(skip_space(text, end)) == Some(&b'(') {
                        return Err(i..end);
                    }
                    if let Some(&t) = by_name.get(&text[i..end]) {
                        visits.push((at, t));
                    }
                }
                // The next argument.
                let Some(comma) = next_argument(text, i) else {
                    break;
                };
                i = skip_space(text, comma + 1);
            }
        }
    }
    visits.sort_by_key(|(at, _)| *at);
    Ok(visits.into_iter().map(|(_, t)| t).collect())
}

/// The `,` after the argument that starts at `at` (brackets balanced),
/// or `None` at the call's `)`.
fn next_argument(text: &str, at: usize) -> Option<usize> {
    let mut depth = 0_i32;
    for (k, b) in text.as_bytes()[at..].iter().enumerate() {
        match b {
            b'[' | b'(' => depth += 1,
            b']' => depth -= 1,
            b')' if depth == 0 => return None,
            b')' => depth -= 1,
            b',' if depth == 0 => return Some(at + k),
            b'\n' => return None,
            _ => {}
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCRIPT: &str = "def calib():\n  # p[1, 2, 3, 0, 0, 0] in a comment\n  global home = [0, -1.5708, 1.5708, 0, 1.5708, 0]\n  global p1 = p[0.4125, 0.30125, 0.33, 3.0, -0.1, 0.05]\n  unused = [1, 2, 3, 4, 5, 6]\n  movej(home, a=1.2, v=0.25)\n  movel(p1, a=1.2, v=0.25)\n  movej([0.1, -1.2, 1.3, 0, 1.5, 0], a=0.5, v=0.25)  # inline\n  movel(p[0.5, 0, 0.4, 3.14, 0, 0], a=1.2, v=0.25)\nend\n";

    #[test]
    fn poses_joints_and_moves() {
        let p = read(SCRIPT).unwrap();
        let names: Vec<&str> = p.targets.iter().map(|t| t.name.as_str()).collect();
        assert_eq!(names, ["home", "p1", "line 8", "line 9"]);
        let TargetValue::Joints { deg, radians } = &p.targets[0].value else {
            panic!()
        };
        assert!(*radians);
        assert!((deg[1] + 90.0).abs() < 1e-3);
        let TargetValue::Pose { values, .. } = &p.targets[1].value else {
            panic!()
        };
        assert_eq!(values[0], 0.4125);
        assert_eq!(&SCRIPT[p.targets[1].spans[4].clone()], "-0.1");
        assert_eq!(p.visits, vec![0, 1, 2, 3]);
        let (line, m) = read("movel(p[1, 2, 3], a=1)\n").unwrap_err();
        assert_eq!(line, 1);
        assert!(m.contains("3 numbers"), "{m}");
    }
}
