//! KUKA KRL files: the `E6POS`, `POS` and `FRAME` aggregates
//! `{X 100.0,Y 200.0,Z 300.0,A 0.0,B 90.0,C 0.0,S 6,T 27,E1 0.0,…}` and
//! the joint aggregates `E6AXIS`/`AXIS` `{A1 0.0,A2 -90.0,…}` of a `.dat`
//! (`DECL E6POS XP1={…}`) or written inline in a `.src` (`PTP {…}`), and
//! the order the motion instructions (`PTP`, `LIN`, `CIRC`, `SPTP`,
//! `SLIN`, `SCIRC`) go to them.
//!
//! `X Y Z` in mm, `A B C` in deg with `R = Rz(A)·Ry(B)·Rx(C)`; `S`
//! (status) and `T` (turn) are the configuration. Comments run from `;`
//! to the end of the line; names are not case sensitive. A `FDAT`'s
//! `TOOL_NO`/`BASE_NO` other than 0 is reported: the poses are then of a
//! tool in a base, not of the flange in the robot's base frame.

use std::collections::HashMap;
use std::ops::Range;

use super::lex::{
    Lines, MotionArguments, computed_motion, inside, line_comments, number_at, shown, skip_space,
};
use super::{ParseError, Parsed, Target, TargetValue};
use crate::engine::base::robot::controller::FlangeConvention;

/// The Cartesian keys of a KUKA pose, in the convention's order.
const POSE_KEYS: [&str; 6] = ["X", "Y", "Z", "A", "B", "C"];

/// Motion instructions and how many targets each names.
const MOTIONS: [(&str, usize); 6] = [
    ("PTP", 1),
    ("LIN", 1),
    ("CIRC", 2),
    ("SPTP", 1),
    ("SLIN", 1),
    ("SCIRC", 2),
];

/// One `KEY value` of an aggregate: the value's number and range when it
/// is a number, its text otherwise.
struct Field {
    key: String,
    number: Option<(f64, Range<usize>)>,
    text: Range<usize>,
}

/// The fields of the aggregate whose `{` is at `at`, and the byte after
/// its `}`. Nested aggregates are kept as text.
fn aggregate(text: &str, at: usize, lines: &Lines) -> Result<(Vec<Field>, usize), ParseError> {
    let bytes = text.as_bytes();
    let mut fields = Vec::new();
    let mut i = at + 1;
    loop {
        i = skip_space(text, i);
        match bytes.get(i) {
            None => return Err((lines.line(at), "`{` without its `}`".to_string())),
            Some(b'}') => return Ok((fields, i + 1)),
            Some(b',') => {
                i += 1;
                continue;
            }
            Some(_) => {}
        }
        let key_end = i + bytes[i..]
            .iter()
            .take_while(|b| b.is_ascii_alphanumeric() || **b == b'_' || **b == b'[' || **b == b']')
            .count();
        if key_end == i {
            return Err((
                lines.line(i),
                format!(
                    "`{}` is not a KRL aggregate field",
                    shown(&text[i..(i + 20).min(text.len())])
                ),
            ));
        }
        let key = text[i..key_end].to_ascii_uppercase();
        if fields.iter().any(|f: &Field| f.key == key) {
            return Err((
                lines.line(i),
                format!("the field `{key}` is given twice in one aggregate: which is meant?"),
            ));
        }
        let value_at = skip_space(text, key_end);
        // The value runs to the next `,` or `}` at this level.
        let mut depth = 0_usize;
        let mut in_string = false;
        let mut end = value_at;
        while end < bytes.len() {
            match bytes[end] {
                b'"' => in_string = !in_string,
                b'{' if !in_string => depth += 1,
                b'}' if !in_string && depth == 0 => break,
                b'}' if !in_string => depth -= 1,
                b',' if !in_string && depth == 0 => break,
                b'\n' if depth == 0 && !in_string => break,
                _ => {}
            }
            end += 1;
        }
        if end >= bytes.len() || bytes[end] == b'\n' {
            return Err((lines.line(at), "`{` without its `}`".to_string()));
        }
        let number = number_at(text, value_at)
            .filter(|(_, r)| skip_space(text, r.end) == end || text[r.end..end].trim().is_empty());
        fields.push(Field {
            key,
            number,
            text: value_at..end,
        });
        i = end;
    }
}

/// The declared name before an aggregate at `at` (`DECL E6POS XP1=`,
/// `XP1=`), if there is one.
fn declared_name(text: &str, at: usize) -> Option<String> {
    let before = text[..at].trim_end().strip_suffix('=')?.trim_end();
    let start = before
        .rfind(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == '$'))
        .map_or(0, |i| i + 1);
    let name = &before[start..];
    (!name.is_empty()).then(|| name.to_string())
}

/// Reads the targets of `text`.
pub(super) fn read(text: &str) -> Result<Parsed, ParseError> {
    let lines = Lines::new(text);
    let comments = line_comments(text, b';');
    let bytes = text.as_bytes();
    let mut targets = Vec::new();
    let mut inline_at: HashMap<usize, usize> = HashMap::new();
    let mut frames: Vec<(i64, i64)> = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] != b'{' || inside(&comments, i) {
            i += 1;
            continue;
        }
        let line = lines.line(i);
        let (fields, next) = aggregate(text, i, &lines)?;
        let get = |k: &str| fields.iter().find(|f| f.key == k);
        let declared = declared_name(text, i);
        let name = declared.clone().unwrap_or_else(|| format!("line {line}"));
        let present: Vec<&str> = POSE_KEYS
            .iter()
            .copied()
            .filter(|k| get(k).is_some())
            .collect();
        if !present.is_empty() && present.len() < POSE_KEYS.len() {
            let missing: Vec<&str> = POSE_KEYS
                .iter()
                .copied()
                .filter(|k| get(k).is_none())
                .collect();
            return Err((
                line,
                format!(
                    "{name}: a position with {} but no {}: a position needs X, Y, Z, A, B, C (a relative motion such as LIN_REL is not a pose either)",
                    present.join(", "),
                    missing.join(", ")
                ),
            ));
        }
        let target = if present.len() == POSE_KEYS.len() {
            let mut values = Vec::new();
            let mut spans = Vec::new();
            for k in POSE_KEYS {
                let f = get(k).ok_or_else(|| (line, format!("{name}: no {k}")))?;
                let (v, r) = f.number.clone().ok_or_else(|| {
                    (
                        line,
                        format!(
                            "{name}: `{k}` is `{}`, not a number",
                            shown(&text[f.text.clone()])
                        ),
                    )
                })?;
                values.push(v);
                spans.push(r);
            }
            let mut t = Target::new(
                name,
                line,
                TargetValue::Pose {
                    values,
                    convention: FlangeConvention::KukaAbc,
                },
                spans,
            );
            if let (Some(s), Some(tt)) = (get("S"), get("T")) {
                let range = s.text.start.min(tt.text.start)..s.text.end.max(tt.text.end);
                t.config = Some((
                    format!(
                        "S {}, T {}",
                        text[s.text.clone()].trim(),
                        text[tt.text.clone()].trim()
                    ),
                    range,
                ));
            }
            Some(t)
        } else if get("A1").is_some() && get("X").is_none() {
            let mut deg = Vec::new();
            let mut spans = Vec::new();
            for k in 1..=6 {
                let key = format!("A{k}");
                let Some(f) = get(&key) else { break };
                let (v, r) = f.number.clone().ok_or_else(|| {
                    (
                        line,
                        format!(
                            "{name}: `{key}` is `{}`, not a number",
                            shown(&text[f.text.clone()])
                        ),
                    )
                })?;
                deg.push(v);
                spans.push(r);
            }
            Some(Target::new(
                name,
                line,
                TargetValue::Joints {
                    deg,
                    radians: false,
                },
                spans,
            ))
        } else {
            let number = |k: &str| {
                get(k)
                    .and_then(|f| f.number.as_ref())
                    .map(|(v, _)| *v as i64)
            };
            if let (Some(tool), Some(base)) = (number("TOOL_NO"), number("BASE_NO"))
                && !frames.contains(&(base, tool))
            {
                frames.push((base, tool));
            }
            None
        };
        if let Some(t) = target {
            if declared.is_none() {
                inline_at.insert(i, targets.len());
            }
            targets.push(t);
        }
        i = next;
    }
    let mut warnings = Vec::new();
    for (base, tool) in &frames {
        if *base != 0 || *tool != 0 {
            warnings.push(format!(
                "motion data name BASE_NO {base} and TOOL_NO {tool}: the positions are then not flange poses in the robot's base frame; every pose must share one base and tool for a calibration"
            ));
        }
    }
    let visits = motion_visits(text, &comments, &targets, &inline_at)
        .map_err(|call| computed_motion(text, &lines, call))?;
    Ok(Parsed {
        targets,
        visits,
        warnings,
    })
}

/// The targets the motion instructions go to, in program order.
fn motion_visits(
    text: &str,
    comments: &[Range<usize>],
    targets: &[Target],
    inline_at: &HashMap<usize, usize>,
) -> Result<Vec<usize>, Range<usize>> {
    let by_name: HashMap<String, usize> = targets
        .iter()
        .enumerate()
        .map(|(i, t)| (t.name.to_ascii_uppercase(), i))
        .collect();
    let upper = text.to_ascii_uppercase();
    let bytes = upper.as_bytes();
    let arguments = MotionArguments {
        folded: &upper,
        opener: b'{',
        inline_at,
    };
    let mut visits = Vec::new();
    let mut at = 0;
    while at < bytes.len() {
        let start = at;
        if !bytes[at].is_ascii_alphabetic()
            || (at > 0
                && (bytes[at - 1].is_ascii_alphanumeric()
                    || bytes[at - 1] == b'_'
                    || bytes[at - 1] == b'$'))
        {
            at += 1;
            continue;
        }
        let end = at
            + bytes[at..]
                .iter()
                .take_while(|b| b.is_ascii_alphanumeric() || **b == b'_')
                .count();
        at = end;
        let Some(&(_, count)) = MOTIONS.iter().find(|(m, _)| *m == &upper[start..end]) else {
            continue;
        };
        if inside(comments, start) {
            continue;
        }
        arguments.read(
            end,
            count,
            |b| b.is_ascii_alphanumeric() || b == b'_',
            |name| by_name.get(name).copied(),
            &mut visits,
        )?;
    }
    Ok(visits)
}

#[cfg(test)]
mod tests {
    use super::*;

    const DAT: &str = "&ACCESS RVP\nDEFDAT  CALIB\n;FOLD EXTERNAL DECLARATIONS\nDECL E6POS XP1={X 412.5,Y 301.25,Z 330.0,A 176.4,B -1.8,C -177.0,S 6,T 27,E1 0.0,E2 0.0,E3 0.0,E4 0.0,E5 0.0,E6 0.0}\nDECL FDAT FP1={TOOL_NO 0,BASE_NO 0,IPO_FRAME #BASE,POINT2[] \" \",TQ_STATE FALSE}\nDECL POS XP2={X 400,Y 300,Z 320,A 170,B -2,C 180}\nDECL E6AXIS XHOME={A1 0.0,A2 -90.0,A3 90.0,A4 0.0,A5 0.0,A6 0.0,E1 0.0,E2 0.0,E3 0.0,E4 0.0,E5 0.0,E6 0.0}\nDECL PDAT PPDAT1={VEL 100,ACC 100,APO_DIST 100}\nENDDAT\n";

    #[test]
    fn dat_aggregates_are_read() {
        let p = read(DAT).unwrap();
        let names: Vec<&str> = p.targets.iter().map(|t| t.name.as_str()).collect();
        assert_eq!(names, ["XP1", "XP2", "XHOME"]);
        let TargetValue::Pose { values, .. } = &p.targets[0].value else {
            panic!()
        };
        assert_eq!(values, &vec![412.5, 301.25, 330.0, 176.4, -1.8, -177.0]);
        assert_eq!(&DAT[p.targets[0].spans[4].clone()], "-1.8");
        assert_eq!(p.targets[0].config.as_ref().unwrap().0, "S 6, T 27");
        assert!(p.targets[1].config.is_none());
        assert!(matches!(p.targets[2].value, TargetValue::Joints { .. }));
        assert!(p.visits.is_empty());
        assert!(p.warnings.is_empty());
    }

    #[test]
    fn src_moves_and_inline_targets() {
        let src = "DEF calib( )\n;FOLD PTP P1 Vel=100 % PDAT1 ;%{PE}\nPTP {A1 0,A2 -90,A3 90,A4 0,A5 0,A6 0}\nLIN {X 500,Y 0,Z 400,A 0,B 90,C 0} C_DIS\nSPTP {X 510,Y 0,Z 400,A 0,B 90,C 0}\nEND\n";
        let p = read(src).unwrap();
        assert_eq!(p.targets.len(), 3);
        assert_eq!(p.visits, vec![0, 1, 2]);
        let (line, m) = read("DECL POS XP1={X 1,Y 2,Z 3,A 0,B 0,C zero}\n").unwrap_err();
        assert_eq!(line, 1);
        assert!(m.contains("`C`"), "{m}");
        assert!(read("DECL POS XP1={X 1,Y 2\n").is_err());
    }
}
