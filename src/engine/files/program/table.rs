//! Pose tables as controllers and scripts write them: one pose a row, the
//! convention's numbers, separated by `,`, `;`, tabs or spaces, with or
//! without a header; a table not separated by commas may write its
//! numbers with decimal commas (`1000,5;20,25;…`, European locales).
//!
//! - **With a header** (any field of the first row not a number): the
//!   pose columns by name (the convention's default names, any case, or
//!   the names given), and optionally `id`, `station`, `use`, `side`.
//! - **Without a header**: the convention's numbers in its order, e.g.
//!   `x y z w p r` for FANUC; a row with one more field whose first is
//!   text takes it as the pose id. All numbers, the row reads two ways
//!   (an id first, or an extra column last): the id reading is taken only
//!   when the first column counts up by a fixed integer step and the other
//!   reading is no pose (angles beyond a turn, a quaternion not unit);
//!   otherwise the table is refused, and `--pose-columns` says which
//!   (`id,x,y,z,w,p,r`, or `x,y,z,w,p,r,-` with `-` a column skipped).
//!
//! Blank lines and lines starting with `#` or `//` are skipped; a UTF-8
//! byte-order mark is allowed; fields may be quoted. Pose `k` of a table
//! without ids has number `k` (1-based), for pairing with numbered
//! profiles.

use std::collections::HashMap;
use std::ops::Range;

use super::lex::shown;
use super::{ParseError, Parsed, Target, TargetValue};
use crate::engine::base::robot::controller::FlangeConvention;
use crate::engine::base::session::Use;
use crate::engine::files::table::{
    decimal_comma, parse_number, side_cell, spaced_with_decimal_commas,
};

/// How the fields of a row are separated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Separator {
    Char(u8),
    Whitespace,
}

impl Separator {
    /// From the first row: `;` when it has one, else a tab when the row's
    /// commas (if any) are decimal commas, else `,` when it has one
    /// (unless it is a row of space-separated numbers with decimal
    /// commas), else runs of spaces.
    fn of(line: &str) -> Self {
        let commas_are_decimal = |mut fields: std::str::Split<'_, char>| {
            fields.all(|f| !f.contains(',') || decimal_comma(f.trim()))
        };
        if line.contains(';') {
            Self::Char(b';')
        } else if line.contains('\t') && commas_are_decimal(line.split('\t')) {
            Self::Char(b'\t')
        } else if line.contains(',') && !spaced_with_decimal_commas(line) {
            Self::Char(b',')
        } else {
            Self::Whitespace
        }
    }

    fn describe(self) -> &'static str {
        match self {
            Self::Char(b';') => "semicolons",
            Self::Char(b'\t') => "tabs",
            Self::Char(_) => "commas",
            Self::Whitespace => "spaces",
        }
    }
}

/// A cell's number: with a decimal point, or, in a table whose fields are
/// not separated by commas, a decimal comma.
fn number(cell: &str, sep: Separator) -> Option<f64> {
    parse_number(cell, sep != Separator::Char(b','))
}

/// A row's fields as byte ranges into the text (trimmed, unquoted).
fn fields(text: &str, line: Range<usize>, sep: Separator) -> Vec<Range<usize>> {
    let bytes = text.as_bytes();
    let mut out = Vec::new();
    let trim = |mut r: Range<usize>| {
        while r.start < r.end && bytes[r.start].is_ascii_whitespace() {
            r.start += 1;
        }
        while r.end > r.start && bytes[r.end - 1].is_ascii_whitespace() {
            r.end -= 1;
        }
        if r.end >= r.start + 2 && bytes[r.start] == b'"' && bytes[r.end - 1] == b'"' {
            r.start += 1;
            r.end -= 1;
        }
        r
    };
    match sep {
        Separator::Char(c) => {
            let mut start = line.start;
            for i in line.clone() {
                if bytes[i] == c {
                    out.push(trim(start..i));
                    start = i + 1;
                }
            }
            out.push(trim(start..line.end));
        }
        Separator::Whitespace => {
            let mut start = None;
            for i in line.clone() {
                let blank = bytes[i].is_ascii_whitespace();
                match (start, blank) {
                    (None, false) => start = Some(i),
                    (Some(s), true) => {
                        out.push(trim(s..i));
                        start = None;
                    }
                    _ => {}
                }
            }
            if let Some(s) = start {
                out.push(trim(s..line.end));
            }
        }
    }
    out
}

/// The rows of `text` that are not blank or comments: `(line, range)`.
fn rows(text: &str) -> Vec<(usize, Range<usize>)> {
    let mut out = Vec::new();
    let mut at = 0;
    for (k, raw) in text.split_inclusive('\n').enumerate() {
        let start = if k == 0 && raw.starts_with('\u{feff}') {
            at + '\u{feff}'.len_utf8()
        } else {
            at
        };
        let end = at + raw.trim_end_matches(['\n', '\r']).len();
        at += raw.len();
        let body = text[start..end].trim();
        if body.is_empty() || body.starts_with('#') || body.starts_with("//") {
            continue;
        }
        out.push((k + 1, start..end));
    }
    out
}

/// One row of a numeric table.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// 1-based line.
    pub line: usize,
    /// The row's 1-based ordinal among the data rows.
    pub ordinal: usize,
    /// The numbers of the wanted columns, in their order.
    pub values: Vec<f64>,
    /// Their byte ranges.
    pub spans: Vec<Range<usize>>,
    /// The `id` column, or the leading id of a headerless row.
    pub id: Option<String>,
    /// The `station` column.
    pub station: Option<String>,
    /// The `use` column.
    pub usage: Option<Use>,
    /// The `side` column, when it has a value.
    pub side: Option<i8>,
}

/// The name, in `--pose-columns`, of a headerless table's id column.
pub const ID_COLUMN: &str = "id";
/// The name, in `--pose-columns`, of a headerless table's column to skip.
pub const SKIPPED_COLUMN: &str = "-";

/// Whether a given column name is a value column (not `id` or `-`).
fn is_value_name(n: &str) -> bool {
    !(n.trim().eq_ignore_ascii_case(ID_COLUMN) || n.trim() == SKIPPED_COLUMN)
}

/// The value columns of given column names: without `id` and `-`.
#[must_use]
pub fn value_names(names: &[String]) -> Vec<String> {
    names.iter().filter(|n| is_value_name(n)).cloned().collect()
}

/// Reads a table of numbers: the columns `names` (by name when the table
/// has a header; in order without one, where given names may also hold
/// `id` and `-` for a column to skip), and optionally `id`, `station`,
/// `use`, `side`. `what` names the numbers in messages ("FANUC x, y, z
/// (mm), W, P, R (deg)"); `fits` says whether a row's numbers can be
/// the values at all (for a headerless row with one number more than the
/// values: the id-first reading is taken only when the first column
/// counts up by a fixed integer step and the values-first reading does
/// not fit).
///
/// # Errors
/// No rows, a missing column, a row of another width, a cell that is not
/// a number, a headerless table with one number more that can be read
/// two ways: each naming the line.
pub fn read_rows(
    text: &str,
    names: &[String],
    names_given: bool,
    what: &str,
    fits: &dyn Fn(&[f64]) -> bool,
    hint: &str,
) -> Result<Vec<Row>, ParseError> {
    let all_names = names;
    let rows = rows(text);
    let Some((first_line, first)) = rows.first().cloned() else {
        return Err((0, "the table has no rows".to_string()));
    };
    let sep = Separator::of(&text[first.clone()]);
    // A separator closing every row (`1000.5;20.25;…;0;`, as spreadsheets
    // export) leaves no field after it.
    let trailing = matches!(sep, Separator::Char(_))
        && fields(text, first.clone(), sep)
            .last()
            .is_some_and(Range::is_empty);
    let row_fields = |range: Range<usize>| {
        let mut f = fields(text, range, sep);
        if trailing && f.len() > 1 && f.last().is_some_and(Range::is_empty) {
            f.pop();
        }
        f
    };
    let first_fields = row_fields(first);
    let is_number = |r: &Range<usize>| number(&text[r.clone()], sep).is_some();
    let value_names = value_names(names);
    let names = value_names.as_slice();
    let n = names.len();
    // A header has names; a first row whose only text is its first field
    // with one field more than the numbers need is data with an id first.
    let text_fields: Vec<usize> = (0..first_fields.len())
        .filter(|&i| !is_number(&first_fields[i]))
        .collect();
    let has_header =
        !(text_fields.is_empty() || (text_fields == [0] && first_fields.len() == n + 1));
    let layout = if has_header {
        let header: Vec<String> = first_fields
            .iter()
            .map(|r| text[r.clone()].to_string())
            .collect();
        Layout::named(&header, names, what).map_err(|m| (first_line, m))?
    } else if names_given {
        Layout::positional(all_names, first_fields.len(), sep).map_err(|m| (first_line, m))?
    } else {
        match first_fields.len() {
            w if w == n => Layout::ordered(0, None, w),
            w if w == n + 1 && text_fields == [0] => Layout::ordered(1, Some(0), w),
            w if w == n + 1 => {
                let numbers = |line: &Range<usize>| -> Vec<f64> {
                    row_fields(line.clone())
                        .iter()
                        .map(|r| number(&text[r.clone()], sep).unwrap_or(f64::NAN))
                        .collect()
                };
                let table: Vec<Vec<f64>> = rows.iter().map(|(_, r)| numbers(r)).collect();
                two_readings(&table, n, fits).map_err(|m| {
                    (
                        first_line,
                        format!(
                            "{w} numbers a row separated by {} and no header: one more than {what}, so two readings: an id first (`id,{names}`) or an extra column last (`{names},-`); {m}; {hint}",
                            sep.describe(),
                            names = names.join(",")
                        ),
                    )
                })?;
                Layout::ordered(1, Some(0), w)
            }
            w => {
                return Err((
                    first_line,
                    format!(
                        "{w} numbers separated by {}: a table without a header has {n} a row ({what}), or {} with an id first",
                        sep.describe(),
                        n + 1
                    ),
                ));
            }
        }
    };
    let data = if has_header { &rows[1..] } else { &rows[..] };
    let mut out = Vec::with_capacity(data.len());
    for (k, (line, range)) in data.iter().enumerate() {
        let f = row_fields(range.clone());
        if f.len() != layout.width {
            return Err((
                *line,
                format!(
                    "{} fields separated by {}, the {} has {}",
                    f.len(),
                    sep.describe(),
                    if has_header { "header" } else { "first row" },
                    layout.width
                ),
            ));
        }
        let mut values = Vec::with_capacity(n);
        let mut spans = Vec::with_capacity(n);
        for (c, &col) in layout.numbers.iter().enumerate() {
            let r = f[col].clone();
            let v = number(&text[r.clone()], sep).ok_or_else(|| {
                (
                    *line,
                    format!(
                        "column {}: `{}` is not a number",
                        layout
                            .names
                            .get(c)
                            .map_or_else(|| (col + 1).to_string(), |n| format!("`{n}`")),
                        shown(&text[r.clone()])
                    ),
                )
            })?;
            values.push(v);
            spans.push(r);
        }
        let cell = |c: Option<usize>| c.map(|c| text[f[c].clone()].to_string());
        let usage = match cell(layout.usage) {
            Some(u) => Some(Use::parse(&u).ok_or_else(|| {
                (
                    *line,
                    format!(
                        "column `use`: `{}` is not translation, rotation, identify or validate",
                        shown(&u)
                    ),
                )
            })?),
            None => None,
        };
        let side = match cell(layout.side) {
            Some(s) => side_cell(&s).map_err(|m| (*line, format!("column `side`: {m}")))?,
            None => None,
        };
        out.push(Row {
            line: *line,
            ordinal: k + 1,
            values,
            spans,
            id: cell(layout.id).filter(|s| !s.is_empty()),
            station: cell(layout.station).filter(|s| !s.is_empty()),
            usage,
            side,
        });
    }
    Ok(out)
}

/// Reads a pose table in `convention`, with the pose columns named
/// `columns` when given.
pub(super) fn read(
    text: &str,
    convention: FlangeConvention,
    columns: Option<&[String]>,
) -> Result<Parsed, ParseError> {
    let names = columns.map_or_else(|| convention.default_columns(), <[String]>::to_vec);
    let values = value_names(&names);
    if values.len() != convention.n_columns() {
        return Err((
            0,
            format!(
                "{} pose columns named, {} needs {}",
                values.len(),
                convention.describe(),
                convention.n_columns()
            ),
        ));
    }
    let hint = format!(
        "say which with --pose-columns (e.g. `id,{v}` or `{v},-`: `id` names the id column, `-` a column to skip)",
        v = values.join(",")
    );
    let rows = read_rows(
        text,
        &names,
        columns.is_some(),
        convention.describe(),
        &|v| pose_fits(convention, v),
        &hint,
    )?;
    // An id given twice: which pose is meant?
    let mut lines_of: HashMap<&str, usize> = HashMap::new();
    for row in &rows {
        if let Some(id) = row.id.as_deref()
            && let Some(first) = lines_of.insert(id, row.line)
        {
            return Err((
                row.line,
                format!(
                    "the id `{}` is given twice (also at line {first})",
                    shown(id)
                ),
            ));
        }
    }
    let targets = rows
        .into_iter()
        .map(|row| {
            let name = row
                .id
                .clone()
                .unwrap_or_else(|| format!("line {}", row.line));
            let mut t = Target::new(
                name,
                row.line,
                TargetValue::Pose {
                    values: row.values,
                    convention,
                },
                row.spans,
            );
            if row.id.is_none() {
                t.number = Some(row.ordinal as u64);
            }
            t.id = row.id;
            t.station = row.station;
            t.usage = row.usage;
            t.side = row.side;
            t
        })
        .collect();
    Ok(Parsed {
        targets,
        visits: Vec::new(),
        warnings: Vec::new(),
    })
}

/// Whether a headerless table with one number more than the values reads
/// as an id first: only when the first column holds distinct integers
/// counting up by a fixed step and the values-first reading does not fit;
/// else what speaks against it.
fn two_readings(table: &[Vec<f64>], n: usize, fits: &dyn Fn(&[f64]) -> bool) -> Result<(), String> {
    let first: Vec<f64> = table
        .iter()
        .map(|r| r.first().copied().unwrap_or(f64::NAN))
        .collect();
    let integers = first
        .iter()
        .all(|v| v.is_finite() && v.fract() == 0.0 && v.abs() < 1e15);
    let step = if first.len() > 1 {
        first[1] - first[0]
    } else {
        1.0
    };
    let counting = integers && step > 0.0 && first.windows(2).all(|w| w[1] - w[0] == step);
    let values_fit = table.iter().all(|r| r.len() > n && fits(&r[..n]));
    match (counting, values_fit) {
        (true, false) => Ok(()),
        (false, _) => Err(format!(
            "the first column ({}) does not count up by a fixed integer step, so it is no id",
            shown_numbers(&first)
        )),
        (true, true) => Err(
            "the first column counts up like an id, but the other numbers also read as values with an extra column last"
                .to_string(),
        ),
    }
}

/// The first numbers of a column, for messages.
fn shown_numbers(v: &[f64]) -> String {
    let mut s: Vec<String> = v.iter().take(4).map(|x| format!("{x}")).collect();
    if v.len() > 4 {
        s.push("…".to_string());
    }
    s.join(", ")
}

/// Whether `v` can be a pose in `convention` at all: a rigid transform
/// whose angles are within a turn (Euler angles within ±360°, a rotation
/// vector within 2π rad).
fn pose_fits(convention: FlangeConvention, v: &[f64]) -> bool {
    if convention.pose_from_values(v).is_err() {
        return false;
    }
    match convention {
        FlangeConvention::KukaAbc | FlangeConvention::FanucWpr => {
            v[3..6].iter().all(|a| a.abs() <= 360.0)
        }
        FlangeConvention::UrRotationVector => {
            v[3..6].iter().map(|a| a * a).sum::<f64>().sqrt() <= std::f64::consts::TAU
        }
        FlangeConvention::AbbQuaternion | FlangeConvention::Matrix => true,
    }
}

/// Where a table's values are.
struct Layout {
    width: usize,
    numbers: Vec<usize>,
    names: Vec<String>,
    id: Option<usize>,
    station: Option<usize>,
    usage: Option<usize>,
    side: Option<usize>,
}

impl Layout {
    fn ordered(first: usize, id: Option<usize>, width: usize) -> Self {
        Self {
            width,
            numbers: (first..width).collect(),
            names: Vec::new(),
            id,
            station: None,
            usage: None,
            side: None,
        }
    }

    /// A headerless table's columns as given, in order: value names,
    /// `id` and `-` (skipped).
    fn positional(given: &[String], width: usize, sep: Separator) -> Result<Self, String> {
        if given.len() != width {
            return Err(format!(
                "{} columns named ({}), the table's first row has {width} numbers separated by {}",
                given.len(),
                given.join(","),
                sep.describe()
            ));
        }
        let ids: Vec<usize> = (0..width)
            .filter(|&i| given[i].trim().eq_ignore_ascii_case(ID_COLUMN))
            .collect();
        if ids.len() > 1 {
            return Err(format!(
                "`{ID_COLUMN}` named {} times in the columns",
                ids.len()
            ));
        }
        Ok(Self {
            width,
            numbers: (0..width).filter(|&i| is_value_name(&given[i])).collect(),
            names: value_names(given),
            id: ids.first().copied(),
            station: None,
            usage: None,
            side: None,
        })
    }

    fn named(header: &[String], names: &[String], what: &str) -> Result<Self, String> {
        // A column named twice: which one is meant?
        for (k, h) in header.iter().enumerate() {
            let h = h.trim();
            if !h.is_empty()
                && let Some(j) = header[..k]
                    .iter()
                    .position(|o| o.trim().eq_ignore_ascii_case(h))
            {
                return Err(format!(
                    "the header names `{}` twice (columns {} and {}): rename one, or skip it with --pose-columns",
                    shown(h),
                    j + 1,
                    k + 1
                ));
            }
        }
        let find = |n: &str| header.iter().position(|h| h.trim().eq_ignore_ascii_case(n));
        let numbers = names
            .iter()
            .map(|n| {
                find(n).ok_or_else(|| {
                    format!(
                        "no column `{n}` (the header has: {}); the columns of {what} are {} (--pose-columns names others)",
                        shown(&header.join(", ")),
                        names.join(", ")
                    )
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self {
            width: header.len(),
            numbers,
            names: names.to_vec(),
            id: find("id"),
            station: find("station"),
            usage: find("use"),
            side: find("side"),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn values(p: &Parsed, k: usize) -> Vec<f64> {
        match &p.targets[k].value {
            TargetValue::Pose { values, .. } => values.clone(),
            TargetValue::Joints { .. } => panic!(),
        }
    }

    #[test]
    fn headerless_whitespace_rows() {
        let text = "-683.432 1182.213 591.413 178.562 -0.060 177.524\n  -669.571\t1182.217 591.370 178.563 -0.059 177.524  \n\n";
        let p = read(text, FlangeConvention::FanucWpr, None).unwrap();
        assert_eq!(p.targets.len(), 2);
        assert_eq!(values(&p, 1)[0], -669.571);
        assert_eq!(p.targets[1].number, Some(2));
        assert_eq!(&text[p.targets[0].spans[4].clone()], "-0.060");
    }

    #[test]
    fn decimal_commas_where_commas_do_not_separate() {
        let want = [1000.5, -20.25, 500.0, 180.0, 0.125, 1.5e-3];
        for text in [
            "1000,5;-20,25;500;180,0;0,125;1,5e-3\n1010,5;-20,25;500;180,0;0,125;1,5e-3\n",
            "1000,5\t-20,25\t500\t180,0\t0,125\t1,5e-3\n",
            "1000,5 -20,25 500 180,0 0,125 1,5e-3\n",
            "x;y;z;a;b;c\n1000,5;-20,25;500;180,0;0,125;1,5e-3\n",
            "p1 1000,5 -20,25 500 180,0 0,125 1,5e-3\n",
        ] {
            let p = read(text, FlangeConvention::KukaAbc, None).unwrap();
            assert_eq!(values(&p, 0), want, "{text:?}");
            assert_eq!(&text[p.targets[0].spans[1].clone()], "-20,25");
        }
        // A separator closing every row, as spreadsheets export.
        let p = read(
            "1000,5;-20,25;500;180,0;0,125;1,5e-3;\n1,0;2;3;4;5;6;\n",
            FlangeConvention::KukaAbc,
            None,
        )
        .unwrap();
        assert_eq!(values(&p, 0), want);
        assert_eq!(values(&p, 1), [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        // Commas that separate stay separators, spaces or not.
        let p = read(
            "1000, 20, 500, 180, 0, 0\n",
            FlangeConvention::KukaAbc,
            None,
        )
        .unwrap();
        assert_eq!(values(&p, 0), [1000.0, 20.0, 500.0, 180.0, 0.0, 0.0]);
        let p = read("1000,5,20,25,500,0\n", FlangeConvention::KukaAbc, None).unwrap();
        assert_eq!(values(&p, 0), [1000.0, 5.0, 20.0, 25.0, 500.0, 0.0]);
        for (cell, yes) in [
            ("1000,5", true),
            ("-0,25", true),
            ("1,5E+3", true),
            ("1,", false),
            (",5", false),
            ("1,2,3", false),
            ("a,b", false),
        ] {
            assert_eq!(decimal_comma(cell), yes, "{cell}");
        }
    }

    #[test]
    fn headers_in_any_separator_and_ids() {
        for sep in [",", ";", "\t", " "] {
            let text = format!(
                "\u{feff}id{sep}X{sep}Y{sep}Z{sep}W{sep}P{sep}R\np7{sep}1{sep}2{sep}3{sep}4{sep}5{sep}6\n"
            );
            let p = read(&text, FlangeConvention::FanucWpr, None).unwrap();
            assert_eq!(p.targets[0].id.as_deref(), Some("p7"), "{sep:?}");
            assert_eq!(p.targets[0].number, Some(7));
            assert_eq!(values(&p, 0), [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        }
        let p = read(
            "1, 10,20,530,0,0,0\n2, 11,21,531,0,0,1\n",
            FlangeConvention::KukaAbc,
            None,
        )
        .unwrap();
        assert_eq!(p.targets[1].id.as_deref(), Some("2"));
        // Ids whose other reading is also a pose, or a first column that
        // does not count: refused, naming both readings and the option.
        for text in [
            "1, 10,20,30,0,0,0\n2, 11,21,31,0,0,1\n",
            "10,20,530,0,0,0,100\n11,21,531,0,0,1,100\n",
        ] {
            let (line, m) = read(text, FlangeConvention::KukaAbc, None).unwrap_err();
            assert_eq!(line, 1);
            assert!(
                m.contains("`id,x,y,z,a,b,c`")
                    && m.contains("`x,y,z,a,b,c,-`")
                    && m.contains("--pose-columns"),
                "{m}"
            );
        }
        let given = |c: &str| c.split(',').map(str::to_string).collect::<Vec<_>>();
        let p = read(
            "10,20,530,0,0,0,100\n11,21,531,0,0,1,100\n",
            FlangeConvention::KukaAbc,
            Some(&given("x,y,z,a,b,c,-")),
        )
        .unwrap();
        assert_eq!(values(&p, 1), [11.0, 21.0, 531.0, 0.0, 0.0, 1.0]);
        assert_eq!(p.targets[1].id, None);
        let p = read(
            "1, 10,20,30,0,0,0\n2, 11,21,31,0,0,1\n",
            FlangeConvention::KukaAbc,
            Some(&given("id,x,y,z,a,b,c")),
        )
        .unwrap();
        assert_eq!(p.targets[1].id.as_deref(), Some("2"));
        assert_eq!(values(&p, 1), [11.0, 21.0, 31.0, 0.0, 0.0, 1.0]);
        let p = read(
            "p1 10 20 30 0 0 0\np2 11 21 31 0 0 1\n",
            FlangeConvention::KukaAbc,
            None,
        )
        .unwrap();
        assert_eq!(p.targets[1].id.as_deref(), Some("p2"));
    }

    #[test]
    fn bad_rows_name_their_line() {
        let (line, m) = read("1 2 3 4 5\n", FlangeConvention::FanucWpr, None).unwrap_err();
        assert_eq!(line, 1);
        assert!(m.contains("5 numbers") && m.contains("6 a row"), "{m}");
        let (line, m) = read(
            "x,y,z,w,p,r\n1,2,3,4,5,6\n1,2,x3,4,5,6\n",
            FlangeConvention::FanucWpr,
            None,
        )
        .unwrap_err();
        assert_eq!(line, 3);
        assert!(m.contains("`z`") && m.contains("x3"), "{m}");
        let (_, m) = read("a,b\n1,2\n", FlangeConvention::FanucWpr, None).unwrap_err();
        assert!(m.contains("no column `x`"), "{m}");
        let (line, m) = read(
            "1 2 3 4 5 6\n1 2 3 4 5 6 7 8\n",
            FlangeConvention::FanucWpr,
            None,
        )
        .unwrap_err();
        assert_eq!(line, 2);
        assert!(m.contains("8 fields"), "{m}");
    }
}
