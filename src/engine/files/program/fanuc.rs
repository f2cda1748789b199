//! FANUC TP programs in their text form (`.ls`): the positions of the
//! `/POS` section and the order the `/MN` section moves through them.
//!
//! ```text
//! /MN
//!    7:J P[1] 100% FINE    ;
//!    9:L P[2:REF] 100mm/sec CNT100    ;
//! /POS
//! P[1]{
//!    GP1:
//!     UF : 0, UT : 0,     CONFIG : 'N U T, 0, 0, -1',
//!     X =   411.912  mm,  Y =   331.036  mm,  Z =   331.032  mm,
//!     W =  -177.169 deg,  P =    -1.812 deg,  R =   176.443 deg
//!    GP2:
//!     UF : 0, UT : 0,
//!     J1=     6.207 deg
//! };
//! ```
//!
//! Only group 1 (the robot) is read; later groups (extended axes) are
//! skipped. A position in joints (`J1 = … deg` in GP1) is a joint target.
//! Positions are sorted by their index, so "the order written" is the
//! P-index order.

use std::collections::HashMap;
use std::ops::Range;

use super::lex::{Lines, number_at, shown, skip_blanks};
use super::{ParseError, Parsed, Target, TargetValue};
use crate::engine::base::robot::controller::FlangeConvention;

/// The Cartesian labels of a FANUC position, in the convention's order.
const POSE_LABELS: [&str; 6] = ["X", "Y", "Z", "W", "P", "R"];

/// Reads the positions of `text`.
pub(super) fn read(text: &str) -> Result<Parsed, ParseError> {
    let lines = Lines::new(text);
    let section = |name: &str| -> Option<usize> {
        let mut at = 0;
        for line in text.split_inclusive('\n') {
            if line
                .trim_start_matches('\u{feff}')
                .trim_end()
                .eq_ignore_ascii_case(name)
                || line
                    .trim_start_matches('\u{feff}')
                    .starts_with(&format!("{name} "))
            {
                return Some(at);
            }
            at += line.len();
        }
        None
    };
    let Some(pos_start) = section("/POS") else {
        return Err((
            0,
            "no /POS section: a FANUC TP program lists its positions there".to_string(),
        ));
    };
    let pos_end = section("/END")
        .filter(|&e| e > pos_start)
        .unwrap_or(text.len());
    let mut targets = Vec::new();
    let mut warnings = Vec::new();
    let mut frames_seen: Vec<(i64, i64)> = Vec::new();
    let mut extended = 0_usize;
    let mut at = pos_start;
    while let Some(found) = text[at..pos_end].find("P[") {
        let start = at + found;
        let line = lines.line(start);
        let close = text[start..pos_end]
            .find(']')
            .map(|i| start + i)
            .ok_or_else(|| (line, "a position `P[` without its `]`".to_string()))?;
        let label = &text[start + 2..close];
        let index_text = label.split(':').next().unwrap_or("").trim();
        let index: u64 = index_text.parse().map_err(|_| {
            (
                line,
                format!("`P[{}]`: the position index is not a number", shown(label)),
            )
        })?;
        let open = skip_blanks(text, close + 1);
        if text.as_bytes().get(open) != Some(&b'{') {
            // A position's head starts its line: anything but its `{`
            // after it is a malformed block, never skipped.
            let line_start = text[..start].rfind('\n').map_or(0, |i| i + 1);
            if text[line_start..start]
                .trim_start_matches('\u{feff}')
                .trim()
                .is_empty()
            {
                let rest: String = text[close + 1..]
                    .chars()
                    .take_while(|c| *c != '\n')
                    .collect();
                return Err((
                    line,
                    format!(
                        "position P[{index}]: `{}` where its block's `{{` should be",
                        shown(rest.trim())
                    ),
                ));
            }
            // A reference such as `P[1]` inside a comment: not a block.
            at = close + 1;
            continue;
        }
        let end = text[open..pos_end]
            .find("};")
            .or_else(|| text[open..pos_end].find('}'))
            .map(|i| open + i)
            .ok_or_else(|| (line, format!("position P[{index}] has no closing `}};`")))?;
        let block = open + 1..end;
        let (group1, others) = groups(text, block);
        extended += others;
        let mut target = position(text, &lines, group1, index, line)?;
        if let Some(frames) = target.frames
            && !frames_seen.contains(&frames)
        {
            frames_seen.push(frames);
        }
        target.name = format!("P[{index}]");
        targets.push(target);
        at = end + 1;
    }
    targets.sort_by_key(|t| t.number);
    if let Some(w) = targets
        .windows(2)
        .find(|w| w[0].number.is_some() && w[0].number == w[1].number)
    {
        return Err((
            w[1].line,
            format!(
                "position {} is written twice (also at line {})",
                w[1].name, w[0].line
            ),
        ));
    }
    for (uf, ut) in &frames_seen {
        if *uf != 0 || *ut != 0 {
            warnings.push(format!(
                "positions recorded with user frame UF {uf} and tool UT {ut}: they are then not flange poses in the robot's base frame{}{}; every pose must share one frame and tool for a calibration (the hand-eye is then to that tool, in that frame)",
                if *uf != 0 { " (UF ≠ 0: a user frame)" } else { "" },
                if *ut != 0 { " (UT ≠ 0: a tool centre point, not the flange)" } else { "" },
            ));
        }
    }
    if frames_seen.len() > 1 {
        warnings.push(format!(
            "positions use {} different UF/UT combinations: poses in different frames do not make one calibration",
            frames_seen.len()
        ));
    }
    if extended > 0 {
        warnings.push(format!(
            "{extended} extended-axis groups (GP2…) skipped: only group 1, the robot, is read"
        ));
    }
    let by_index: HashMap<u64, usize> = targets
        .iter()
        .enumerate()
        .filter_map(|(i, t)| t.number.map(|n| (n, i)))
        .collect();
    let visits = motion_visits(text, &lines, pos_start, &by_index)?;
    Ok(Parsed {
        targets,
        visits,
        warnings,
    })
}

/// The byte range of group 1 in a position block, and how many other
/// groups follow it. A block without `GP` labels is all group 1.
fn groups(text: &str, block: Range<usize>) -> (Range<usize>, usize) {
    let body = &text[block.clone()];
    let labels: Vec<usize> = body
        .match_indices("GP")
        .filter(|(i, _)| {
            let rest = &body[i + 2..];
            let digits = rest.bytes().take_while(u8::is_ascii_digit).count();
            digits > 0 && rest[digits..].trim_start().starts_with(':')
        })
        .map(|(i, _)| i)
        .collect();
    let Some(&first) = labels.first() else {
        return (block, 0);
    };
    let colon = body[first..].find(':').map_or(first, |c| first + c + 1);
    let end = labels.get(1).copied().unwrap_or(body.len());
    (
        block.start + colon..block.start + end,
        labels.len().saturating_sub(1),
    )
}

/// One position from its group-1 text.
fn position(
    text: &str,
    lines: &Lines,
    group: Range<usize>,
    index: u64,
    line: usize,
) -> Result<Target, ParseError> {
    let mut values: HashMap<String, (f64, Range<usize>, usize)> = HashMap::new();
    let mut frames = (None, None);
    let mut config = None;
    let body = &text[group.clone()];
    let bytes = body.as_bytes();
    let mut i = 0;
    while i < bytes.len() {
        if !bytes[i].is_ascii_alphabetic() || (i > 0 && bytes[i - 1].is_ascii_alphanumeric()) {
            i += 1;
            continue;
        }
        let name_end = i + bytes[i..]
            .iter()
            .take_while(|b| b.is_ascii_alphanumeric() || **b == b'_')
            .count();
        let name = body[i..name_end].to_ascii_uppercase();
        let after = skip_blanks(body, name_end);
        let sep = bytes.get(after).copied();
        if sep != Some(b'=') && sep != Some(b':') {
            i = name_end;
            continue;
        }
        let value_at = skip_blanks(body, after + 1);
        let here = lines.line(group.start + i);
        if name == "CONFIG" {
            if bytes.get(value_at) == Some(&b'\'') {
                let close = body[value_at + 1..]
                    .find('\'')
                    .map_or(body.len(), |c| value_at + 1 + c);
                config = Some((
                    body[value_at + 1..close].to_string(),
                    group.start + value_at + 1..group.start + close,
                ));
                i = close + 1;
            } else {
                i = value_at;
            }
            continue;
        }
        let Some((value, span)) = number_at(body, value_at) else {
            if POSE_LABELS.contains(&name.as_str()) || name.starts_with('J') {
                let bad: String = body[value_at..]
                    .chars()
                    .take_while(|c| !matches!(c, ',' | '\n' | ';'))
                    .collect();
                return Err((
                    here,
                    format!(
                        "position P[{index}]: `{name}` is `{}`, not a number{}",
                        shown(&bad),
                        if bad.contains('*') {
                            " (an unrecorded position)"
                        } else {
                            ""
                        }
                    ),
                ));
            }
            i = value_at.max(name_end);
            continue;
        };
        match name.as_str() {
            "UF" => frames.0 = integer(value),
            "UT" => frames.1 = integer(value),
            _ => {
                if let Some((_, _, first)) = values.get(&name) {
                    return Err((
                        here,
                        format!("position P[{index}]: `{name}` given twice (also at line {first})"),
                    ));
                }
                values.insert(
                    name,
                    (
                        value,
                        group.start + span.start..group.start + span.end,
                        here,
                    ),
                );
            }
        }
        i = span.end;
    }
    let take = |labels: &[String]| -> Option<(Vec<f64>, Vec<Range<usize>>)> {
        labels
            .iter()
            .map(|l| values.get(l).map(|(v, s, _)| (*v, s.clone())))
            .collect::<Option<Vec<_>>>()
            .map(|v| v.into_iter().unzip())
    };
    let pose_labels: Vec<String> = POSE_LABELS.iter().map(|s| (*s).to_string()).collect();
    let value = if let Some((v, spans)) = take(&pose_labels) {
        (
            TargetValue::Pose {
                values: v,
                convention: FlangeConvention::FanucWpr,
            },
            spans,
        )
    } else {
        let joints: Vec<String> = (1..=9)
            .map(|k| format!("J{k}"))
            .take_while(|l| values.contains_key(l))
            .collect();
        if joints.is_empty() {
            let missing: Vec<&str> = POSE_LABELS
                .iter()
                .copied()
                .filter(|l| !values.contains_key(*l))
                .collect();
            return Err((
                line,
                format!(
                    "position P[{index}]: group 1 has neither X, Y, Z, W, P, R (missing {}) nor joints J1…",
                    missing.join(", ")
                ),
            ));
        }
        let (v, spans) = take(&joints).unwrap_or_default();
        (
            TargetValue::Joints {
                deg: v,
                radians: false,
            },
            spans,
        )
    };
    let mut target = Target::new(format!("P[{index}]"), line, value.0, value.1);
    target.config = config;
    if let (Some(uf), Some(ut)) = frames {
        target.frames = Some((uf, ut));
    }
    Ok(target)
}

/// An integral value as an integer.
fn integer(v: f64) -> Option<i64> {
    let n = v as i64;
    ((n as f64 - v).abs() < 1e-9).then_some(n)
}

/// Motion options that send the robot elsewhere than the position
/// written: incremental motion and offsets by a position register.
const MOVED_ELSEWHERE: [&str; 4] = ["INC", "OFFSET", "TOOL_OFFSET", "VOFFSET"];

/// The positions the `/MN` lines move to, in program order (indices into
/// the targets by P number). Remarks (`!…`) are skipped; position
/// registers (`PR[n]`) are not positions of this program.
///
/// # Errors
/// A motion to a position `/POS` does not hold, or one that `INC` or an
/// offset (`Offset,PR[n]`, `Tool_Offset,PR[n]`) moves elsewhere than the
/// position written: naming the line.
fn motion_visits(
    text: &str,
    lines: &Lines,
    pos_start: usize,
    by_index: &HashMap<u64, usize>,
) -> Result<Vec<usize>, ParseError> {
    let Some(mn) = text[..pos_start]
        .find("\n/MN")
        .map(|i| i + 1)
        .or_else(|| text.starts_with("/MN").then_some(0))
    else {
        return Ok(Vec::new());
    };
    let mut visits = Vec::new();
    let first_line = lines.line(mn);
    for (k, line) in text[mn..pos_start].lines().enumerate().skip(1) {
        let here = first_line + k;
        let body = line.split_once(':').map_or(line, |(n, rest)| {
            if n.trim().chars().all(|c| c.is_ascii_digit()) {
                rest
            } else {
                line
            }
        });
        let body = body.trim_start();
        if body.starts_with('!') || body.starts_with("//") {
            continue;
        }
        let bytes = body.as_bytes();
        for (i, _) in body.match_indices("P[") {
            if i > 0 && (bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == b'_') {
                continue;
            }
            let digits: String = body[i + 2..]
                .chars()
                .take_while(char::is_ascii_digit)
                .collect();
            let Ok(n) = digits.parse::<u64>() else {
                continue;
            };
            let Some(&t) = by_index.get(&n) else {
                return Err((
                    here,
                    format!("a motion to P[{n}], which /POS does not hold"),
                ));
            };
            if let Some(option) = body
                .split(|c: char| c.is_whitespace() || c == ',' || c == ';')
                .find(|w| MOVED_ELSEWHERE.iter().any(|o| w.eq_ignore_ascii_case(o)))
            {
                return Err((
                    here,
                    format!(
                        "the motion to P[{n}] has `{}`: the robot goes elsewhere than P[{n}] as written, so its pose is not known; remove the option or record the pose reached",
                        shown(option)
                    ),
                ));
            }
            visits.push(t);
        }
    }
    Ok(visits)
}

#[cfg(test)]
mod tests {
    use super::*;

    const PROGRAM: &str = "/PROG  CALIB\n/ATTR\nOWNER\t\t= MNEDITOR;\n/MN\n   1:  UFRAME_NUM=0 ;\n   2:  !P[9] in a remark ;\n   3:J P[2] 100% FINE    ;\n   4:L P[1:\"REF\"] 100mm/sec CNT100    ;\n   5:  PR[1]=LPOS ;\n/POS\nP[1:\"REF\"]{\n   GP1:\n\tUF : 0, UT : 0,\t\tCONFIG : 'N U T, 0, 0, -1',\n\tX =   412.500  mm,\tY =   301.250  mm,\tZ =   330.000  mm,\n\tW =  -177.000 deg,\tP =    -1.800 deg,\tR =   176.400 deg\n   GP2:\n\tUF : 0, UT : 0,\t\n\tJ1=     6.207 deg\n};\nP[2]{\n   GP1:\n\tUF : 1, UT : 4,\n\tJ1=    10.000 deg,\tJ2=   -.500 deg,\tJ3=    20.000 deg,\n\tJ4=     0.000 deg,\tJ5=    45.000 deg,\tJ6=     1.000 deg\n};\n/END\n";

    #[test]
    fn positions_joints_groups_and_motion_order() {
        let p = read(PROGRAM).unwrap();
        assert_eq!(p.targets.len(), 2);
        let t = &p.targets[0];
        assert_eq!(t.name, "P[1]");
        assert_eq!(t.line, 11);
        let TargetValue::Pose { values, .. } = &t.value else {
            panic!("pose expected")
        };
        assert_eq!(values, &vec![412.5, 301.25, 330.0, -177.0, -1.8, 176.4]);
        assert_eq!(&PROGRAM[t.spans[4].clone()], "-1.800");
        assert_eq!(t.config.as_ref().unwrap().0, "N U T, 0, 0, -1");
        let TargetValue::Joints { deg, .. } = &p.targets[1].value else {
            panic!("joints expected")
        };
        assert_eq!(deg[1], -0.5);
        assert_eq!(p.targets[1].frames, Some((1, 4)));
        // /MN moves to P[2] first, then P[1]; the remark and PR[1] do not count.
        assert_eq!(p.visits, vec![1, 0]);
        assert!(
            p.warnings.iter().any(|w| w.contains("UT 4")),
            "{:?}",
            p.warnings
        );
        assert!(
            p.warnings.iter().any(|w| w.contains("GP2")),
            "{:?}",
            p.warnings
        );
    }

    #[test]
    fn bad_positions_name_their_line() {
        let bad = PROGRAM.replace("Y =   301.250", "Y =   *******");
        let (line, message) = read(&bad).unwrap_err();
        assert_eq!(line, 14);
        assert!(
            message.contains("P[1]") && message.contains("unrecorded"),
            "{message}"
        );
        let (_, message) = read("/PROG X\n/MN\n").unwrap_err();
        assert!(message.contains("/POS"), "{message}");
        let missing = PROGRAM.replace("\tW =  -177.000 deg,", "");
        let (line, message) = read(&missing).unwrap_err();
        assert_eq!(line, 11);
        assert!(message.contains("missing W"), "{message}");
    }
}
