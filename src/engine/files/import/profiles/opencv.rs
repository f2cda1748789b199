//! OpenCV FileStorage profiles: YAML (`%YAML:1.0`, a flow list or an
//! `!!opencv-matrix`) and JSON (a list, an `opencv-matrix` object, or a
//! list of points).

use std::collections::HashMap;
use std::path::Path;

use serde_json::Value;

use super::{Collector, PROFILE_KEYS, ProfileFormat, RawProfile, number};
use crate::engine::files::import::ImportError;
use crate::engine::files::table::{excerpt, overlong_line, overlong_line_message};

/// The flat numbers of a profile and how many make a point (2 or 3, when
/// the file says).
struct NumberList {
    values: Vec<f64>,
    width: Option<usize>,
    /// The 1-based line where the list starts (YAML; 1 for JSON).
    line: usize,
}

/// Points of a flat list: triplets when one coordinate of the triplets is
/// constant (a plane; a NaN or infinity there, a point the sensor did not
/// see, does not break it: that point is dropped like any non-finite one),
/// else pairs `y, z`.
fn points_of_list(list: &NumberList, path: &Path, key: &str) -> Result<Vec<[f64; 3]>, ImportError> {
    let n = list.values.len();
    let triplets_in_plane = || {
        n.is_multiple_of(3)
            && n > 0
            && (0..3).any(|k| {
                let mut finite = list
                    .values
                    .iter()
                    .skip(k)
                    .step_by(3)
                    .filter(|v| v.is_finite());
                finite
                    .next()
                    .is_some_and(|&first| finite.all(|&v| v == first))
            })
    };
    let width = match list.width {
        Some(w) => w,
        None if triplets_in_plane() => 3,
        None if n.is_multiple_of(2) => 2,
        None => 3,
    };
    if !(2..=3).contains(&width) || !n.is_multiple_of(width) {
        return Err(ImportError::File {
            path: path.to_path_buf(),
            message: format!(
                "`{}` holds {n} numbers: not a whole number of points of {width} coordinates",
                excerpt(key)
            ),
        });
    }
    Ok(list
        .values
        .chunks(width)
        .map(|c| {
            if width == 2 {
                [0.0, c[0], c[1]]
            } else {
                [c[0], c[1], c[2]]
            }
        })
        .collect())
}

/// The key to read: the format's, else the first known one, else the only
/// list in the file.
fn choose_key<'k>(
    keys: &'k [String],
    format: &ProfileFormat,
    path: &Path,
) -> Result<&'k str, ImportError> {
    let found = match &format.key {
        Some(k) => keys.iter().find(|c| *c == k),
        None => PROFILE_KEYS
            .iter()
            .find_map(|k| keys.iter().find(|c| c.as_str() == *k))
            .or_else(|| (keys.len() == 1).then(|| &keys[0])),
    };
    found.map(String::as_str).ok_or_else(|| ImportError::File {
        path: path.to_path_buf(),
        message: match &format.key {
            Some(k) => format!(
                "no key `{k}` with a list of numbers (the file has: {})",
                excerpt(&keys.join(", "))
            ),
            None => format!(
                "no point list: none of the keys {} (the file has: {}); name the key with --profile-key",
                PROFILE_KEYS.join(", "),
                excerpt(&keys.join(", "))
            ),
        },
    })
}

/// An OpenCV FileStorage YAML profile: `key: [ … ]` or an
/// `!!opencv-matrix` with `rows`, `cols` and `data: [ … ]`.
pub(super) fn read_yaml(
    text: &str,
    path: &Path,
    format: &ProfileFormat,
) -> Result<RawProfile, ImportError> {
    let lists = yaml_lists(text, path)?;
    let keys: Vec<String> = lists.iter().map(|(k, _)| k.clone()).collect();
    let key = choose_key(&keys, format, path)?;
    let Some((_, list)) = lists.iter().find(|(k, _)| k == key) else {
        return Err(ImportError::File {
            path: path.to_path_buf(),
            message: format!("no key `{key}`"),
        });
    };
    let mut out = Collector::new(format);
    for (i, p) in points_of_list(list, path, key)?.into_iter().enumerate() {
        out.push(p).map_err(|message| ImportError::Csv {
            path: path.to_path_buf(),
            line: list.line,
            message: format!("`{}`, point {}: {message}", excerpt(key), i + 1),
        })?;
    }
    Ok(out.finish(path))
}

/// The number lists of an OpenCV YAML file, by top-level key, in file
/// order.
fn yaml_lists(text: &str, path: &Path) -> Result<Vec<(String, NumberList)>, ImportError> {
    if let Some((line, length)) = overlong_line(text) {
        return Err(ImportError::Csv {
            path: path.to_path_buf(),
            line,
            message: overlong_line_message(length),
        });
    }
    let lines: Vec<&str> = text.trim_start_matches('\u{feff}').lines().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        let line = lines[i];
        let top_level = !line.starts_with([' ', '\t', '%', '#', '-']) && line.contains(':');
        if !top_level {
            i += 1;
            continue;
        }
        let (key, rest) = line.split_once(':').unwrap_or((line, ""));
        let key = key.trim().trim_matches('"').to_string();
        let rest = rest.trim();
        if rest.starts_with('[') {
            let (body, next) = flow_list(&lines, i, rest, path)?;
            out.push((
                key.clone(),
                NumberList {
                    values: numbers_in(&body, path, &key, i + 1)?,
                    width: None,
                    line: i + 1,
                },
            ));
            i = next;
        } else if rest.starts_with("!!opencv-matrix") {
            let mut fields: HashMap<String, String> = HashMap::new();
            let mut j = i + 1;
            let mut data = None;
            while j < lines.len() && lines[j].starts_with([' ', '\t']) {
                let (k, v) = lines[j].split_once(':').unwrap_or((lines[j], ""));
                let (k, v) = (k.trim().to_string(), v.trim());
                if k == "data" {
                    let (body, next) = flow_list(&lines, j, v, path)?;
                    data = Some((numbers_in(&body, path, &key, j + 1)?, j + 1));
                    j = next;
                } else {
                    fields.insert(k, v.to_string());
                    j += 1;
                }
            }
            let Some((values, data_line)) = data else {
                return Err(ImportError::Csv {
                    path: path.to_path_buf(),
                    line: i + 1,
                    message: format!("`{}` is an opencv-matrix without `data`", excerpt(&key)),
                });
            };
            let cols = fields.get("cols").and_then(|c| c.parse::<usize>().ok());
            out.push((
                key,
                NumberList {
                    values,
                    width: cols,
                    line: data_line,
                },
            ));
            i = j;
        } else {
            i += 1;
        }
    }
    Ok(out)
}

/// The text between `[` and the matching `]` of a flow list starting on
/// line `start` with `rest`; returns the body and the line after it.
fn flow_list(
    lines: &[&str],
    start: usize,
    rest: &str,
    path: &Path,
) -> Result<(String, usize), ImportError> {
    let mut body = String::new();
    let mut text = rest.trim_start_matches('[').to_string();
    let mut j = start;
    loop {
        if let Some(end) = text.find(']') {
            body.push_str(&text[..end]);
            return Ok((body, j + 1));
        }
        body.push_str(&text);
        body.push(' ');
        j += 1;
        let Some(next) = lines.get(j) else {
            return Err(ImportError::Csv {
                path: path.to_path_buf(),
                line: start + 1,
                message: "a list `[` that is never closed with `]`".into(),
            });
        };
        text = (*next).to_string();
    }
}

/// The numbers of a list body, or the first one that is not a number.
fn numbers_in(body: &str, path: &Path, key: &str, line: usize) -> Result<Vec<f64>, ImportError> {
    body.split(|c: char| c == ',' || c.is_whitespace())
        .filter(|s| !s.is_empty())
        .map(|s| {
            number(s).ok_or_else(|| ImportError::Csv {
                path: path.to_path_buf(),
                line,
                message: format!("`{}`: `{}` is not a number", excerpt(key), excerpt(s)),
            })
        })
        .collect()
}

/// An OpenCV FileStorage JSON profile: `{"key": [ … ]}`, an
/// `opencv-matrix` object, or an array of `[x, y, z]` / `[y, z]` points.
pub(super) fn read_json(
    text: &str,
    path: &Path,
    format: &ProfileFormat,
) -> Result<RawProfile, ImportError> {
    let value = crate::engine::files::import::json_value(text, path)?;
    let Value::Object(map) = value else {
        return Err(ImportError::File {
            path: path.to_path_buf(),
            message: "expected a JSON object with a point list".into(),
        });
    };
    let keys: Vec<String> = map
        .iter()
        .filter(|(_, v)| v.is_array() || v.is_object())
        .map(|(k, _)| k.clone())
        .collect();
    let key = choose_key(&keys, format, path)?;
    let bad = |message: String| ImportError::File {
        path: path.to_path_buf(),
        message: format!("`{}`: {message}", excerpt(key)),
    };
    let list = match map.get(key) {
        Some(Value::Array(items)) if items.iter().all(Value::is_array) => {
            let mut values = Vec::new();
            let mut width = None;
            for (i, item) in items.iter().enumerate() {
                let p =
                    json_numbers(item).ok_or_else(|| bad(format!("point {i} is not numbers")))?;
                if *width.get_or_insert(p.len()) != p.len() {
                    return Err(bad(format!("point {i} has {} numbers", p.len())));
                }
                values.extend(p);
            }
            NumberList {
                values,
                width,
                line: 1,
            }
        }
        Some(v @ Value::Array(_)) => NumberList {
            values: json_numbers(v).ok_or_else(|| bad("not a list of numbers".into()))?,
            width: None,
            line: 1,
        },
        Some(Value::Object(m)) => NumberList {
            values: m
                .get("data")
                .and_then(json_numbers)
                .ok_or_else(|| bad("an opencv-matrix without numeric `data`".into()))?,
            width: m
                .get("cols")
                .and_then(Value::as_u64)
                .and_then(|c| usize::try_from(c).ok()),
            line: 1,
        },
        _ => return Err(bad("not a list of numbers".into())),
    };
    let mut out = Collector::new(format);
    for (i, p) in points_of_list(&list, path, key)?.into_iter().enumerate() {
        out.push(p)
            .map_err(|message| bad(format!("point {}: {message}", i + 1)))?;
    }
    Ok(out.finish(path))
}

/// The numbers of a JSON array (`null` and strings like `.nan` read as
/// NaN, so that they are dropped and counted).
fn json_numbers(v: &Value) -> Option<Vec<f64>> {
    v.as_array()?
        .iter()
        .map(|x| match x {
            Value::Number(n) => n.as_f64(),
            Value::Null => Some(f64::NAN),
            Value::String(s) => number(s),
            _ => None,
        })
        .collect()
}
