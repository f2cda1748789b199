//! ABB RAPID modules: `robtarget` and `jointtarget` values, declared
//! (`CONST robtarget p10 := [[x,y,z],[q1,q2,q3,q4],[cf1,cf4,cf6,cfx],[eax_a,…]];`,
//! also `PERS`/`VAR`, arrays `{n}`) or written inline in a move
//! instruction, and the order the `Move…` instructions go to them.
//!
//! A robtarget is `x, y, z` (mm) and the quaternion `q1..q4` (w, x, y, z)
//! of the TCP in the work object; a jointtarget `[[j1..j6],[eax…]]` (deg).
//! Comments run from `!` to the end of the line; RAPID names are not case
//! sensitive.

use std::collections::HashMap;
use std::ops::Range;

use super::lex::{
    Lines, MotionArguments, computed_motion, inside, line_comments, number_at, shown, skip_space,
};
use super::{ParseError, Parsed, Target, TargetValue};
use crate::engine::base::robot::controller::FlangeConvention;

/// Deepest nesting of `[` read: a robtarget array is 4 deep; deeper is
/// not a target and is refused rather than recursed into.
const MAX_DEPTH: usize = 8;

/// A value of a RAPID aggregate literal.
enum Node {
    /// A number and its byte range.
    Number(f64, Range<usize>),
    /// A bracketed list and its byte range.
    List(Vec<Node>, Range<usize>),
    /// Anything else (a name, a string, `TRUE`).
    Other,
}

impl Node {
    fn numbers(&self, n: usize) -> Option<Vec<(f64, Range<usize>)>> {
        let Self::List(items, _) = self else {
            return None;
        };
        if items.len() != n {
            return None;
        }
        items
            .iter()
            .map(|i| match i {
                Self::Number(v, r) => Some((*v, r.clone())),
                _ => None,
            })
            .collect()
    }

    fn range(&self) -> Option<Range<usize>> {
        match self {
            Self::List(_, r) | Self::Number(_, r) => Some(r.clone()),
            Self::Other => None,
        }
    }
}

/// Parses the list that opens at byte `at` (`[`); returns it and the
/// byte after its `]`.
fn list(text: &str, at: usize, depth: usize, lines: &Lines) -> Result<(Node, usize), ParseError> {
    if depth > MAX_DEPTH {
        return Err((
            lines.line(at),
            format!("brackets nested deeper than {MAX_DEPTH}: not a RAPID target"),
        ));
    }
    let bytes = text.as_bytes();
    let mut items = Vec::new();
    let mut i = at + 1;
    loop {
        i = skip_space(text, i);
        match bytes.get(i) {
            None => return Err((lines.line(at), "`[` without its `]`".to_string())),
            Some(b']') => return Ok((Node::List(items, at..i + 1), i + 1)),
            Some(b',') => i += 1,
            Some(b'[') => {
                let (node, next) = list(text, i, depth + 1, lines)?;
                items.push(node);
                i = next;
            }
            Some(_) => {
                if let Some((v, r)) = number_at(text, i) {
                    let end = skip_space(text, r.end);
                    if matches!(bytes.get(end), Some(b',' | b']')) {
                        i = r.end;
                        items.push(Node::Number(v, r));
                        continue;
                    }
                }
                let end = bytes[i..]
                    .iter()
                    .position(|&b| matches!(b, b',' | b']' | b'[' | b';'))
                    .map_or(bytes.len(), |p| i + p);
                if bytes.get(end) == Some(&b';') || end == i {
                    return Err((
                        lines.line(i),
                        format!("`{}` ends a list without `]`", shown(&text[i..end])),
                    ));
                }
                items.push(Node::Other);
                i = end;
            }
        }
    }
}

/// A robtarget or jointtarget of a literal, if it is one.
fn target_of(node: &Node, name: String, line: usize) -> Option<Target> {
    let Node::List(items, _) = node else {
        return None;
    };
    if items.len() == 4
        && let (Some(xyz), Some(q), Some(_), Some(_)) = (
            items[0].numbers(3),
            items[1].numbers(4),
            items[2].numbers(4),
            items[3].numbers(6),
        )
    {
        let (values, spans): (Vec<f64>, Vec<Range<usize>>) = xyz.into_iter().chain(q).unzip();
        let mut t = Target::new(
            name,
            line,
            TargetValue::Pose {
                values,
                convention: FlangeConvention::AbbQuaternion,
            },
            spans,
        );
        t.config = items[2].range().map(|r| (String::new(), r));
        return Some(t);
    }
    if items.len() == 2
        && let (Some(j), Some(_)) = (items[0].numbers(6), items[1].numbers(6))
    {
        let (deg, spans): (Vec<f64>, Vec<Range<usize>>) = j.into_iter().unzip();
        return Some(Target::new(
            name,
            line,
            TargetValue::Joints {
                deg,
                radians: false,
            },
            spans,
        ));
    }
    None
}

/// The declared name before a literal at `at` (`… robtarget NAME :=` or
/// `… jointtarget NAME{n} :=`), if there is one.
fn declared_name(text: &str, at: usize) -> Option<String> {
    let before = text[..at].trim_end();
    let before = before.strip_suffix(":=")?.trim_end();
    let name_start = before
        .rfind(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == '{' || c == '}'))
        .map_or(0, |i| i + 1);
    let name = &before[name_start..];
    let kind = before[..name_start].split_whitespace().last()?;
    (kind.eq_ignore_ascii_case("robtarget") || kind.eq_ignore_ascii_case("jointtarget"))
        .then(|| name.split('{').next().unwrap_or(name).to_string())
        .filter(|n| !n.is_empty())
}

/// Reads the targets of `text`.
pub(super) fn read(text: &str) -> Result<Parsed, ParseError> {
    let lines = Lines::new(text);
    let comments = line_comments(text, b'!');
    let bytes = text.as_bytes();
    let mut targets: Vec<Target> = Vec::new();
    // Start byte of each inline literal that is a target, for the visits.
    let mut inline_at: HashMap<usize, usize> = HashMap::new();
    let mut in_string = false;
    let mut i = 0;
    while i < bytes.len() {
        let b = bytes[i];
        if b == b'\n' {
            in_string = false;
        }
        if b == b'"' && !inside(&comments, i) {
            in_string = !in_string;
        }
        if b != b'[' || in_string || inside(&comments, i) {
            i += 1;
            continue;
        }
        let line = lines.line(i);
        let (node, next) = list(text, i, 0, &lines)?;
        let declared = declared_name(text, i);
        let name = declared.clone().unwrap_or_else(|| format!("line {line}"));
        if let Some(t) = target_of(&node, name.clone(), line) {
            if declared.is_none() {
                inline_at.insert(i, targets.len());
            }
            targets.push(t);
        } else if let Some(base) = &declared {
            // An array of targets: `robtarget pts{3} := [[…], […], […]]`.
            let array: Option<Vec<Target>> = match &node {
                Node::List(items, _) if !items.is_empty() => items
                    .iter()
                    .enumerate()
                    .map(|(k, item)| target_of(item, format!("{base}{{{}}}", k + 1), line))
                    .collect(),
                _ => None,
            };
            // A declared target the reader cannot take is named, never
            // skipped (a skipped one shifts every later pairing).
            let Some(array) = array else {
                return Err((
                    line,
                    format!(
                        "`{}` is declared as a target but its value is not [[x,y,z],[q1,q2,q3,q4],[cf1,cf4,cf6,cfx],[eax_a,…,eax_f]] (robtarget) or [[j1,…,j6],[eax_a,…,eax_f]] (jointtarget) of numbers",
                        shown(base)
                    ),
                ));
            };
            targets.extend(array);
        }
        i = next;
    }
    let mut first: HashMap<String, usize> = HashMap::new();
    for t in &targets {
        if let Some(line) = first.insert(t.name.to_ascii_lowercase(), t.line)
            && !t.name.starts_with("line ")
        {
            return Err((
                t.line,
                format!(
                    "target `{}` is declared twice (also at line {line}): which one the robot goes to is not known",
                    shown(&t.name)
                ),
            ));
        }
    }
    let (visits, warnings) = motion_visits(text, &lines, &comments, &targets, &inline_at)?;
    Ok(Parsed {
        targets,
        visits,
        warnings,
    })
}

/// A `Move…` instruction's tool and `\WObj`, from the byte after its
/// word to its `;` (in the lower-cased text): the last argument, without
/// its optional arguments, and the work object named.
fn tool_and_wobj(lower: &str, from: usize) -> (Option<String>, Option<String>) {
    let end = lower[from..].find(';').map_or(lower.len(), |i| from + i);
    let statement = &lower[from..end];
    let mut depth = 0_i32;
    let mut last = 0;
    for (i, b) in statement.bytes().enumerate() {
        match b {
            b'[' | b'(' => depth += 1,
            b']' | b')' => depth -= 1,
            b',' if depth == 0 => last = i + 1,
            _ => {}
        }
    }
    let tail = &statement[last..];
    let tool = tail.split('\\').next().unwrap_or("").trim();
    let wobj = statement.find("\\wobj").map(|i| {
        statement[i + 5..]
            .trim_start_matches([' ', ':', '='])
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect::<String>()
    });
    (
        (!tool.is_empty() && last > 0).then(|| tool.to_string()),
        wobj.filter(|w| !w.is_empty()),
    )
}

/// The targets the `Move…` instructions go to, in program order: a named
/// target, or an inline literal (`MoveC` names two).
///
/// # Errors
/// A motion to a computed position (`Offs(…)`, `RelTool(…)`), naming its
/// line. A work object other than `wobj0`, or moves with more than one
/// tool, are warned about (the targets are then not flange poses in the
/// base frame, or not of one tool).
fn motion_visits(
    text: &str,
    lines: &Lines,
    comments: &[Range<usize>],
    targets: &[Target],
    inline_at: &HashMap<usize, usize>,
) -> Result<(Vec<usize>, Vec<String>), ParseError> {
    let mut tools: Vec<(String, usize)> = Vec::new();
    let mut wobjs: Vec<(String, usize)> = Vec::new();
    let by_name: HashMap<String, usize> = targets
        .iter()
        .enumerate()
        .map(|(i, t)| (t.name.to_ascii_lowercase(), i))
        .collect();
    let mut visits = Vec::new();
    let lower = text.to_ascii_lowercase();
    let arguments = MotionArguments {
        folded: &lower,
        opener: b'[',
        inline_at,
    };
    for (at, _) in lower.match_indices("move") {
        if inside(comments, at)
            || (at > 0 && {
                let b = lower.as_bytes()[at - 1];
                b.is_ascii_alphanumeric() || b == b'_'
            })
        {
            continue;
        }
        let word_end = at
            + lower[at..]
                .bytes()
                .take_while(|b| b.is_ascii_alphanumeric() || *b == b'_')
                .count();
        let instruction = &lower[at..word_end];
        let count = if instruction.starts_with("movec") {
            2
        } else {
            1
        };
        arguments
            .read(
                word_end,
                count,
                |b| b.is_ascii_alphanumeric() || b == b'_' || b == b'{' || b == b'}',
                // An indexed name (`p{3}`) as itself, or its array.
                |indexed| {
                    let name = indexed.split('{').next().unwrap_or("");
                    by_name.get(indexed).or_else(|| by_name.get(name)).copied()
                },
                &mut visits,
            )
            .map_err(|call| computed_motion(text, lines, call))?;
        let (tool, wobj) = tool_and_wobj(&lower, word_end);
        let line = lines.line(at);
        // A joint move's tool does not change where the joints go.
        if let Some(tool) = tool.filter(|_| !instruction.starts_with("moveabsj"))
            && !tools.iter().any(|(t, _)| *t == tool)
        {
            tools.push((tool, line));
        }
        if let Some(w) = wobj
            && w != "wobj0"
            && !wobjs.iter().any(|(x, _)| *x == w)
        {
            wobjs.push((w, line));
        }
    }
    let mut warnings = Vec::new();
    for (w, line) in &wobjs {
        warnings.push(format!(
            "line {line}: moves in work object `{w}`: their targets are then not in the robot's base frame; every pose must share one frame for a calibration"
        ));
    }
    if tools.len() > 1 {
        let named: Vec<String> = tools
            .iter()
            .map(|(t, line)| format!("`{t}` (line {line})"))
            .collect();
        warnings.push(format!(
            "moves with {} tools, {}: targets of different tools are not poses of one flange or sensor",
            tools.len(),
            named.join(", ")
        ));
    }
    Ok((visits, warnings))
}

#[cfg(test)]
mod tests {
    use super::*;

    const MODULE: &str = "MODULE Cell\n  ! a robtarget in a comment: [[1,2,3],[1,0,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]]\n  CONST robtarget p20 := [[600.5,-10,450],[0.6,0,0.8,0],[0,-1,0,1],[9E+09,9E+09,9E9,9E9,9E9,9E9]];\n  PERS robtarget p10:=[[500,0,400],[1,0,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];\n  CONST jointtarget jhome := [[0,-10.5,20,0,45,0],[9E9,9E9,9E9,9E9,9E9,9E9]];\n  PERS tooldata tSensor := [TRUE,[[0,0,100],[1,0,0,0]],[1,[0,0,1],[1,0,0,0],0,0,0]];\n  PROC main()\n    MoveAbsJ jhome, v100, fine, tool0;\n    MoveL p10, v100, fine, tSensor;\n    MoveJ P20, v100, z10, tSensor;\n    MoveL [[700,0,400],[1,0,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]], v100, fine, tool0;\n  ENDPROC\nENDMODULE\n";

    #[test]
    fn targets_names_and_moves() {
        let p = read(MODULE).unwrap();
        let names: Vec<&str> = p.targets.iter().map(|t| t.name.as_str()).collect();
        assert_eq!(names, ["p20", "p10", "jhome", "line 11"]);
        let TargetValue::Pose { values, .. } = &p.targets[0].value else {
            panic!()
        };
        assert_eq!(values[..4], [600.5, -10.0, 450.0, 0.6]);
        assert_eq!(&MODULE[p.targets[0].spans[1].clone()], "-10");
        assert_eq!(
            &MODULE[p.targets[0].config.clone().unwrap().1],
            "[0,-1,0,1]"
        );
        assert!(matches!(p.targets[2].value, TargetValue::Joints { .. }));
        // jhome, p10, p20 (case-insensitive), then the inline literal.
        assert_eq!(p.visits, vec![2, 1, 0, 3]);
    }

    #[test]
    fn arrays_and_errors() {
        let p = read("VAR robtarget pts{2} := [[[1,2,3],[1,0,0,0],[0,0,0,0],[0,0,0,0,0,0]],[[4,5,6],[1,0,0,0],[0,0,0,0],[0,0,0,0,0,0]]];").unwrap();
        assert_eq!(p.targets.len(), 2);
        assert_eq!(p.targets[1].name, "pts{2}");
        let (line, m) = read("MODULE m\nCONST robtarget p := [[1,2,3],[1,0,0,0];\n").unwrap_err();
        assert_eq!(line, 2);
        assert!(m.contains("without"), "{m}");
        // A declared target with a value the reader cannot take is named,
        // not skipped.
        let (line, m) = read(
            "MODULE m\n\nCONST robtarget p2 := [[zz,1,2],[1,0,0,0],[0,0,0,0],[0,0,0,0,0,0]];\n",
        )
        .unwrap_err();
        assert_eq!(line, 3);
        assert!(m.contains("`p2` is declared as a target"), "{m}");
        let (_, m) = read("VAR robtarget pts{2} := [[[1,2,3],[1,0,0,0],[0,0,0,0],[0,0,0,0,0,0]],[[4,5],[1,0,0,0],[0,0,0,0],[0,0,0,0,0,0]]];").unwrap_err();
        assert!(m.contains("`pts`"), "{m}");
        let deep = format!("x := {}{};", "[".repeat(50), "]".repeat(50));
        assert!(read(&deep).unwrap_err().1.contains("nested"));
    }
}
