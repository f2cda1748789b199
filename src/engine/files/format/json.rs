//! The strict JSON machinery both file kinds share: a reader that names
//! the key path, the measurement and the line and column of every problem
//! (raw slices parsed one key at a time, keys given twice rejected), the
//! settling of 4×4 matrices so that a loaded transform survives its own
//! save, and the pretty writer of the file layout (arrays of numbers and
//! small flat objects on one line).

use std::fmt;
use std::path::Path;

use nalgebra::{Isometry3, Matrix3, Quaternion, Rotation3, Translation3, UnitQuaternion};
use serde::de::{self, Deserializer, MapAccess, SeqAccess, Visitor};
use serde::{Deserialize, Serialize};
use serde_json::value::RawValue;
use serde_json::{Map, Value};

use super::read::{Cap, read_text as read_capped};
use super::{FORMAT_VERSION, FileError, RESULT_FORMAT, SESSION_FORMAT};
use crate::engine::base::geometry::{isometry_from_rows, rows_from_isometry};

/// Write-and-read rounds [`settle`] tries before searching: about 96 % of
/// rotations reach a fixed point within them.
const SETTLE_ROUNDS: usize = 10;
/// Largest change (ulps per quaternion component) [`settle`] searches for a
/// fixed point; 4 was the most needed in 20 000 random rotations.
const SETTLE_ULPS: i32 = 5;

/// Deserialises a present key as `Some(raw)`, so that `null` is not taken
/// for an absent key (`default` gives `None` for the absent ones).
pub(super) fn present<'de, D: Deserializer<'de>>(d: D) -> Result<Option<&'de RawValue>, D::Error> {
    <&'de RawValue>::deserialize(d).map(Some)
}

/// A struct of raw JSON slices, one per allowed key: serde's derive rejects
/// unknown keys and keys given twice; the values are parsed one by one.
macro_rules! keys_struct {
    ($name:ident, $expecting:literal {
        $($(#[$attr:meta])* $field:ident $(as $rename:literal)?),* $(,)?
    }) => {
        #[derive(Deserialize)]
        #[serde(deny_unknown_fields, expecting = $expecting)]
        struct $name<'a> {
            $(
                $(#[$attr])*
                #[serde(borrow, default, deserialize_with = "present")]
                $(#[serde(rename = $rename)])?
                $field: Option<&'a RawValue>,
            )*
        }
    };
}
pub(super) use keys_struct;

/// The header of any file: read leniently (other keys ignored) first, so a
/// file of the wrong kind or version is named as such.
#[derive(Deserialize)]
#[serde(expecting = "a JSON object")]
pub(super) struct Header<'a> {
    #[serde(borrow, default, deserialize_with = "present")]
    format: Option<&'a RawValue>,
    #[serde(borrow, default, deserialize_with = "present")]
    version: Option<&'a RawValue>,
}

/// A present optional key: `null` is an error, not "absent".
pub(super) fn some<'de, D: Deserializer<'de>, T: Deserialize<'de>>(
    d: D,
) -> Result<Option<T>, D::Error> {
    T::deserialize(d).map(Some)
}

/// Builds a [`Value`] like serde_json does, but a key given twice is an
/// error (serde_json's own `Map` keeps the last one silently).
pub(super) struct UniqueVisitor;

/// A [`Value`] read through [`UniqueVisitor`].
pub(super) struct UniqueValue(pub(super) Value);

impl<'de> Deserialize<'de> for UniqueValue {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(UniqueVisitor).map(UniqueValue)
    }
}

impl<'de> Visitor<'de> for UniqueVisitor {
    type Value = Value;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("any JSON value")
    }

    fn visit_bool<E: de::Error>(self, v: bool) -> Result<Value, E> {
        Ok(Value::Bool(v))
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<Value, E> {
        Ok(Value::from(v))
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<Value, E> {
        Ok(Value::from(v))
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<Value, E> {
        serde_json::Number::from_f64(v)
            .map(Value::Number)
            .ok_or_else(|| E::custom("a number is not finite"))
    }

    fn visit_str<E: de::Error>(self, v: &str) -> Result<Value, E> {
        Ok(Value::String(v.to_owned()))
    }

    fn visit_string<E: de::Error>(self, v: String) -> Result<Value, E> {
        Ok(Value::String(v))
    }

    fn visit_unit<E: de::Error>(self) -> Result<Value, E> {
        Ok(Value::Null)
    }

    fn visit_none<E: de::Error>(self) -> Result<Value, E> {
        Ok(Value::Null)
    }

    fn visit_some<D: Deserializer<'de>>(self, d: D) -> Result<Value, D::Error> {
        UniqueValue::deserialize(d).map(|v| v.0)
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Value, A::Error> {
        let mut out = Vec::new();
        while let Some(UniqueValue(v)) = seq.next_element()? {
            out.push(v);
        }
        Ok(Value::Array(out))
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Value, A::Error> {
        let mut out = Map::new();
        while let Some(key) = map.next_key::<String>()? {
            if out.contains_key(&key) {
                return Err(de::Error::custom(format!("duplicate key `{key}`")));
            }
            let UniqueValue(v) = map.next_value()?;
            out.insert(key, v);
        }
        Ok(Value::Object(out))
    }
}

/// The text being read and its path, for messages.
pub(super) struct Ctx<'a> {
    pub(super) text: &'a str,
    pub(super) path: &'a Path,
}

/// `parent: ` or nothing, to start a message about a key of `parent`.
pub(super) fn prefix(parent: &str) -> String {
    if parent.is_empty() {
        String::new()
    } else {
        format!("{parent}: ")
    }
}

/// The path of key `key` under `parent`.
pub(super) fn join(parent: &str, key: &str) -> String {
    if parent.is_empty() {
        key.to_owned()
    } else {
        format!("{parent}.{key}")
    }
}

/// What kind of JSON value `raw` is, for messages.
pub(super) fn kind(raw: &RawValue) -> &'static str {
    match raw.get().as_bytes().first() {
        Some(b'{') => "an object",
        Some(b'[') => "an array",
        Some(b'"') => "a string",
        Some(b'n') => "null",
        Some(b't' | b'f') => "a boolean",
        _ => "a number",
    }
}

/// serde_json's message without its position, in FORMAT.md's words.
pub(super) fn describe(err: &serde_json::Error) -> String {
    let full = err.to_string();
    let position = format!(" at line {} column {}", err.line(), err.column());
    let message = full.strip_suffix(&position).unwrap_or(&full);
    message
        .replace("missing field", "missing key")
        .replace("unknown field", "unknown key")
        .replace("duplicate field", "duplicate key")
        .replace("expected f64", "expected a number")
        .replace(
            "struct Joint",
            "a joint object with alpha, a, beta, theta and d",
        )
}

impl<'a> Ctx<'a> {
    pub(super) fn new(text: &'a str, path: &'a Path) -> Self {
        // A UTF-8 byte-order mark is not JSON but some editors write one.
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        Self { text, path }
    }

    pub(super) fn invalid(
        &self,
        measurement: Option<&str>,
        message: impl Into<String>,
    ) -> FileError {
        FileError::Invalid {
            path: self.path.to_path_buf(),
            measurement: measurement.map(str::to_owned),
            message: message.into(),
        }
    }

    /// Line and column (1-based) of the start of `raw` in the text.
    pub(super) fn line_column(&self, raw: &RawValue) -> Option<(usize, usize)> {
        let offset = (raw.get().as_ptr() as usize).checked_sub(self.text.as_ptr() as usize)?;
        let before = self.text.get(..offset)?;
        let line = before.bytes().filter(|&b| b == b'\n').count() + 1;
        let column = offset - before.rfind('\n').map_or(0, |i| i + 1) + 1;
        Some((line, column))
    }

    /// ` at line L column C` for the start of `raw`.
    pub(super) fn at(&self, raw: &RawValue) -> String {
        self.line_column(raw)
            .map(|(l, c)| format!(" at line {l} column {c}"))
            .unwrap_or_default()
    }

    /// The whole text as one JSON value, after a full syntax check (one
    /// pass: the raw value's parse checks the whole text).
    pub(super) fn document(&self) -> Result<&'a RawValue, FileError> {
        serde_json::from_str::<&RawValue>(self.text).map_err(|e| {
            let mut message = format!(
                "not valid JSON: {} at line {} column {}",
                describe(&e),
                e.line(),
                e.column()
            );
            if self.non_finite_literal_at(e.line(), e.column()) {
                message.push_str("; NaN and Infinity are not JSON numbers");
            }
            self.invalid(None, message)
        })
    }

    /// Whether a `NaN` or `Infinity` literal sits at the position of a
    /// syntax error (serde_json points at it, or just after a sign).
    pub(super) fn non_finite_literal_at(&self, line: usize, column: usize) -> bool {
        let Some(text) = self.text.lines().nth(line.saturating_sub(1)) else {
            return false;
        };
        let near = text.get(column.saturating_sub(2)..).unwrap_or("");
        let near = near.trim_start_matches(|c: char| c == '-' || c == '+' || c.is_whitespace());
        ["NaN", "nan", "Infinity", "inf"]
            .iter()
            .any(|w| near.starts_with(w))
    }

    /// Parses `raw` as `T`; an error names `key` and the position in the file.
    pub(super) fn parse<T: Deserialize<'a>>(
        &self,
        raw: &'a RawValue,
        key: &str,
        measurement: Option<&str>,
    ) -> Result<T, FileError> {
        serde_json::from_str(raw.get()).map_err(|e| {
            let position = match (self.line_column(raw), e.line()) {
                (Some((line, column)), l) if l > 0 => {
                    let (l, c) = if l == 1 {
                        (line, column + e.column() - 1)
                    } else {
                        (line + l - 1, e.column())
                    };
                    format!(" at line {l} column {c}")
                }
                _ => String::new(),
            };
            self.invalid(
                measurement,
                format!("{}{}{position}", prefix(key), describe(&e)),
            )
        })
    }

    /// Parses a JSON object as `T`. serde's derive would also take an array
    /// of the values in field order; FORMAT.md objects must be objects.
    pub(super) fn object<T: Deserialize<'a>>(
        &self,
        raw: &'a RawValue,
        key: &str,
        measurement: Option<&str>,
    ) -> Result<T, FileError> {
        if !raw.get().starts_with('{') {
            return Err(self.invalid(
                measurement,
                format!(
                    "{}expected an object, found {}{}",
                    prefix(key),
                    kind(raw),
                    self.at(raw)
                ),
            ));
        }
        self.parse(raw, key, measurement)
    }

    /// `raw` or "missing key" naming the key and the object it belongs in.
    pub(super) fn required(
        &self,
        raw: Option<&'a RawValue>,
        object: &RawValue,
        parent: &str,
        key: &str,
        measurement: Option<&str>,
    ) -> Result<&'a RawValue, FileError> {
        raw.ok_or_else(|| {
            self.invalid(
                measurement,
                format!("{}missing key `{key}`{}", prefix(parent), self.at(object)),
            )
        })
    }

    /// Parses a JSON array element by element, each under `key[i]`.
    pub(super) fn array<T: Deserialize<'a>>(
        &self,
        raw: &'a RawValue,
        key: &str,
        measurement: Option<&str>,
    ) -> Result<Vec<T>, FileError> {
        let items: Vec<&'a RawValue> = self.parse(raw, key, measurement)?;
        items
            .into_iter()
            .enumerate()
            .map(|(i, item)| self.parse(item, &format!("{key}[{i}]"), measurement))
            .collect()
    }

    /// Exactly `N` numbers (serde's fixed-size arrays report a wrong length
    /// as "trailing characters").
    pub(super) fn numbers<const N: usize>(
        &self,
        raw: &'a RawValue,
        key: &str,
        what: &str,
        measurement: Option<&str>,
    ) -> Result<[f64; N], FileError> {
        let values: Vec<f64> = self.parse(raw, key, measurement)?;
        <[f64; N]>::try_from(values.as_slice()).map_err(|_| {
            self.invalid(
                measurement,
                format!(
                    "{key} must hold {N} numbers{what}, found {}{}",
                    values.len(),
                    self.at(raw)
                ),
            )
        })
    }

    /// A 4×4 rigid transform (FORMAT.md "Units and frames").
    pub(super) fn matrix(&self, raw: &'a RawValue, key: &str) -> Result<Isometry3<f64>, FileError> {
        self.matrix_in(raw, key, None)
    }

    /// A 4×4 rigid transform inside a measurement (named in messages).
    pub(super) fn matrix_in(
        &self,
        raw: &'a RawValue,
        key: &str,
        measurement: Option<&str>,
    ) -> Result<Isometry3<f64>, FileError> {
        let items: Vec<&'a RawValue> = self.parse(raw, key, measurement)?;
        if items.len() != 4 {
            return Err(self.invalid(
                measurement,
                format!(
                    "{key} must be 4 rows of 4 numbers, found {} rows{}",
                    items.len(),
                    self.at(raw)
                ),
            ));
        }
        let mut rows = [[0.0; 4]; 4];
        for (i, (row, item)) in rows.iter_mut().zip(items).enumerate() {
            *row = self.numbers(item, &format!("{key}[{i}]"), "", measurement)?;
        }
        let iso = isometry_from_rows(&rows)
            .map_err(|e| self.invalid(measurement, format!("{key}: {e}{}", self.at(raw))))?;
        crate::engine::base::session::rules::transform(key, &iso)
            .map_err(|e| self.invalid(measurement, format!("{e}{}", self.at(raw))))?;
        Ok(settle(&rows, iso))
    }

    /// `side`: +1 or −1, written as any JSON number.
    pub(super) fn side(
        &self,
        raw: &'a RawValue,
        key: &str,
        measurement: Option<&str>,
    ) -> Result<i8, FileError> {
        let v: f64 = self.parse(raw, key, measurement)?;
        if v == 1.0 {
            Ok(1)
        } else if v == -1.0 {
            Ok(-1)
        } else {
            Err(self.invalid(
                measurement,
                format!("{key} must be 1 or -1, found {v}{}", self.at(raw)),
            ))
        }
    }

    /// Whether `format` and `version` name a version 1 file of kind
    /// `expected` (the fast check; [`Self::header`] says what is wrong).
    #[allow(
        clippy::unused_self,
        reason = "the fast twin of `Self::header`, which needs the context for its message"
    )]
    pub(super) fn is_header(
        &self,
        format: Option<&'a RawValue>,
        version: Option<&'a RawValue>,
        expected: &str,
    ) -> bool {
        let format = format.and_then(|r| serde_json::from_str::<&str>(r.get()).ok());
        let version = version.and_then(|r| serde_json::from_str::<f64>(r.get()).ok());
        format == Some(expected) && version == Some(f64::from(FORMAT_VERSION))
    }

    /// `format` and `version` (FORMAT.md: a later version is a new number).
    pub(super) fn header(&self, top: &'a RawValue, expected: &str) -> Result<(), FileError> {
        let header: Header = self.object(top, "", None)?;
        let kind = if expected == SESSION_FORMAT {
            "session"
        } else {
            "result"
        };
        let Some(format_raw) = header.format else {
            return Err(self.invalid(
                None,
                format!("missing key `format`: not a spherecal {kind} file (expected \"format\": \"{expected}\")"),
            ));
        };
        let format: String = self.parse(format_raw, "format", None)?;
        if format != expected {
            let hint = match format.as_str() {
                SESSION_FORMAT => " (this is a session file, not a result file)",
                RESULT_FORMAT => " (this is a result file, not a session file)",
                _ => "",
            };
            return Err(self.invalid(
                None,
                format!(
                    "format is \"{format}\", expected \"{expected}\"{hint}{}",
                    self.at(format_raw)
                ),
            ));
        }
        let Some(version_raw) = header.version else {
            return Err(self.invalid(None, "missing key `version`"));
        };
        let version: f64 = self.parse(version_raw, "version", None)?;
        if version == f64::from(FORMAT_VERSION) {
            Ok(())
        } else if version.fract() == 0.0 && version > f64::from(FORMAT_VERSION) {
            Err(self.invalid(
                None,
                format!(
                    "version {version} is newer than this build of spherecal reads (it reads version {FORMAT_VERSION}); use a newer spherecal"
                ),
            ))
        } else {
            Err(self.invalid(
                None,
                format!("version {version} is not a {kind} format version; this build reads version {FORMAT_VERSION}"),
            ))
        }
    }
}

/// The rotation of a row-major matrix in closed form (nalgebra's
/// `from_rotation_matrix`, Shepperd's method); deterministic and without
/// the drift of the iterative projection in [`isometry_from_rows`].
pub(super) fn rotation_from_rows(rows: &[[f64; 4]; 4]) -> UnitQuaternion<f64> {
    let r = Matrix3::from_fn(|i, j| rows[i][j]);
    UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r))
}

/// The rotation as it reads back after being written (`rows_from_isometry`
/// then [`rotation_from_rows`]).
pub(super) fn reread(q: &UnitQuaternion<f64>) -> UnitQuaternion<f64> {
    rotation_from_rows(&rows_from_isometry(&Isometry3::from_parts(
        Translation3::identity(),
        *q,
    )))
}

/// `v` moved by `n` ulps (toward +∞ for positive `n`).
pub(super) fn ulps(v: f64, n: i32) -> f64 {
    let mut out = v;
    for _ in 0..n.unsigned_abs() {
        out = if n > 0 {
            out.next_up()
        } else {
            out.next_down()
        };
    }
    out
}

/// The transform of file matrix `rows` (already checked into `iso` by
/// [`isometry_from_rows`]) as a value that survives its own write and read
/// bit for bit. The file holds 16 numbers, the engine a quaternion;
/// converting back and forth may move the last bits.
///
/// A matrix this module wrote reads back exactly in closed form. Otherwise,
/// starting from the checked transform, write and read are repeated until
/// nothing moves; failing that, the quaternions within [`SETTLE_ULPS`] ulps
/// per component are searched for one that reads back to itself. The
/// translation always survives exactly. If no fixed point is found the first
/// reading is kept (a later save and load may then differ by ulps).
pub(super) fn settle(rows: &[[f64; 4]; 4], iso: Isometry3<f64>) -> Isometry3<f64> {
    let with = |q: UnitQuaternion<f64>| Isometry3::from_parts(iso.translation, q);
    let direct = rotation_from_rows(rows);
    if reread(&direct) == direct {
        return with(direct);
    }
    let start = reread(&iso.rotation);
    let mut q = start;
    for _ in 0..SETTLE_ROUNDS {
        let next = reread(&q);
        if next == q {
            return with(q);
        }
        q = next;
    }
    let c = start.into_inner().coords;
    for k in 1..=SETTLE_ULPS {
        for a in -k..=k {
            for b in -k..=k {
                for d in -k..=k {
                    for e in -k..=k {
                        // Only the shell at distance k; the inside was tried.
                        if a.abs().max(b.abs()).max(d.abs()).max(e.abs()) != k {
                            continue;
                        }
                        let candidate = UnitQuaternion::new_unchecked(Quaternion::new(
                            ulps(c.w, a),
                            ulps(c.x, b),
                            ulps(c.y, d),
                            ulps(c.z, e),
                        ));
                        if reread(&candidate) == candidate {
                            return with(candidate);
                        }
                    }
                }
            }
        }
    }
    with(start)
}

pub(super) fn read_text(path: &Path) -> Result<String, FileError> {
    read_capped(path, Cap::SESSION).map_err(|source| FileError::Io {
        action: "reading",
        path: path.to_path_buf(),
        source,
    })
}

/// Pretty JSON of `value` in the file layout, with a trailing newline.
pub(super) fn try_render<T: Serialize>(value: &T) -> Result<String, serde_json::Error> {
    let mut out = Vec::with_capacity(4096);
    let mut ser =
        serde_json::Serializer::with_formatter(&mut out, super::layout::Layout::default());
    value.serialize(&mut ser)?;
    out.push(b'\n');
    String::from_utf8(out)
        .map_err(|e| serde_json::Error::io(std::io::Error::new(std::io::ErrorKind::InvalidData, e)))
}

/// [`try_render`] for saving: a failure is reported, never written.
pub(super) fn render<T: Serialize>(value: &T, path: &Path) -> Result<String, FileError> {
    try_render(value).map_err(|e| FileError::Invalid {
        path: path.to_path_buf(),
        measurement: None,
        message: format!("cannot be written as JSON: {e}"),
    })
}

/// [`try_render`] where no error is possible: the output types hold only
/// strings, numbers and string-keyed maps, serialised to memory. Should it
/// ever fail, the text says so and will not load.
pub(super) fn render_lossy<T: Serialize>(value: &T) -> String {
    try_render(value).unwrap_or_else(|e| format!("serialisation failed: {e}\n"))
}

#[cfg(test)]
mod tests {
    use super::*;

    // The layout as it was made before the one-pass formatter: serde_json's
    // pretty output, then arrays of scalars collapsed, then objects of
    // scalars within 120 bytes. The formatter must give the same bytes.
    /// Longest object line [`collapse`] makes, indent included.
    const MAX_COLLAPSED_LINE: usize = 120;

    /// Puts each `open … close` container whose entries are all scalars on one
    /// line, if the line stays within `max` characters: arrays of numbers
    /// (`[y, z]`, a matrix row, joint readings) and flat objects
    /// (`{"alpha": 0.0, "a": 0.0, …}`, `{"epsilon": 0.466}`), as FORMAT.md shows
    /// them. It works on serde_json's pretty output, where a container that
    /// opens a line ends it with `open`, each entry has its own line two spaces
    /// deeper, and `close` sits at the opening line's indent; only whitespace
    /// changes.
    fn collapse(text: &str, open: char, close: char, max: usize) -> String {
        let lines: Vec<&str> = text.lines().collect();
        let mut out: Vec<String> = Vec::with_capacity(lines.len());
        let mut i = 0;
        while i < lines.len() {
            let line = lines[i];
            if let Some((collapsed, used)) = flat_container(&lines[i..], open, close, max) {
                out.push(collapsed);
                i += used;
            } else {
                out.push(line.to_owned());
                i += 1;
            }
        }
        out.join("\n")
    }

    /// Indent of a line of pretty JSON.
    fn indent(line: &str) -> usize {
        line.len() - line.trim_start_matches(' ').len()
    }

    /// The one-line form of the container opened at the end of `lines[0]` and
    /// the number of lines it replaces, if its entries are all scalars and it
    /// fits in `max` characters.
    fn flat_container(
        lines: &[&str],
        open: char,
        close: char,
        max: usize,
    ) -> Option<(String, usize)> {
        let first = lines.first()?;
        if !first.ends_with(open) {
            return None;
        }
        let depth = indent(first);
        let mut entries = Vec::new();
        for (n, line) in lines.iter().enumerate().skip(1) {
            let trimmed = line.trim_start_matches(' ');
            let closing = trimmed
                .strip_prefix(close)
                .is_some_and(|rest| rest.is_empty() || rest == ",");
            if indent(line) == depth && closing {
                let collapsed = format!("{first}{}{trimmed}", entries.join(", "));
                return (!entries.is_empty() && collapsed.len() <= max)
                    .then_some((collapsed, n + 1));
            }
            let entry = trimmed.strip_suffix(',').unwrap_or(trimmed);
            let value = if open == '{' {
                object_value(entry)?
            } else {
                entry
            };
            if indent(line) != depth + 2 || value.starts_with(['[', '{']) || value.is_empty() {
                return None;
            }
            entries.push(entry);
        }
        None
    }

    /// The value of an object entry `"key": value`, minding escapes in the key.
    fn object_value(entry: &str) -> Option<&str> {
        let mut escaped = false;
        for (i, c) in entry.char_indices().skip(1) {
            match c {
                '\\' if !escaped => escaped = true,
                '"' if !escaped => return entry.get(i + 1..)?.strip_prefix(": "),
                _ => escaped = false,
            }
        }
        None
    }

    fn reference_layout<T: Serialize>(value: &T) -> String {
        let pretty = serde_json::to_string_pretty(value).unwrap();
        let arrays = collapse(&pretty, '[', ']', usize::MAX);
        let mut text = collapse(&arrays, '{', '}', MAX_COLLAPSED_LINE);
        text.push('\n');
        text
    }

    #[test]
    fn the_one_pass_layout_is_the_reference_layout() {
        let demo: serde_json::Value = serde_json::from_str(crate::DEMO_SESSION_JSON).unwrap();
        assert_eq!(try_render(&demo).unwrap(), reference_layout(&demo));
        // Objects around the 120-byte limit, with and without a comma
        // after them, nested, empty containers, strings with brackets.
        for width in 90..130 {
            let long = "x".repeat(width - 40);
            let v = serde_json::json!({
                "a": [{"k": long, "n": 1.5}, {"k": long, "n": 2}],
                "b": {"inner": {"k": long, "m": [1, 2, 3]}, "last": {"k": long}},
                "c": [[], {}, [1.0, -2e-7], {"s": "[{\"]"}],
                "d": {"k": long, "z": null}
            });
            assert_eq!(
                try_render(&v).unwrap(),
                reference_layout(&v),
                "width {width}"
            );
        }
    }
    use crate::engine::base::geometry::isometry_from_twist;

    #[test]
    fn numbers_round_trip_bit_for_bit() {
        // A spread of magnitudes and bit patterns, through the writer and
        // the reader.
        let mut x: u64 = 0x9e37_79b9_7f4a_7c15;
        let mut values = vec![
            0.0,
            -0.0,
            1.0,
            0.1,
            1e-300,
            5e-324,
            f64::MAX,
            f64::MIN_POSITIVE,
            615.0,
            38.1,
        ];
        for _ in 0..2000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let v = f64::from_bits(x);
            if v.is_finite() {
                values.push(v);
            }
        }
        let text = render_lossy(&values);
        let back: Vec<f64> = serde_json::from_str(&text).unwrap_or_default();
        assert_eq!(back.len(), values.len());
        for (a, b) in values.iter().zip(&back) {
            assert!(
                a.to_bits() == b.to_bits() || (*a == 0.0 && *b == 0.0),
                "{a:e} read back as {b:e}"
            );
        }
    }

    #[test]
    fn settled_matrices_survive_write_and_read() {
        let read =
            |rows: &[[f64; 4]; 4]| settle(rows, isometry_from_rows(rows).unwrap_or_default());
        let mut misses = 0;
        for k in 0..2000 {
            let t = f64::from(k);
            let iso = isometry_from_twist(&[
                t,
                -2.0 * t,
                0.5,
                0.013 * t,
                -0.7 + 0.003 * t,
                3.0 * t.sin(),
            ]);
            let settled = read(&rows_from_isometry(&iso));
            if read(&rows_from_isometry(&settled)) != settled {
                misses += 1;
            }
            // Settling moves a transform by rounding only.
            assert!(
                (settled.to_homogeneous() - iso.to_homogeneous())
                    .abs()
                    .max()
                    < 1e-14
            );
        }
        assert_eq!(misses, 0);
    }

    #[test]
    fn layout_keeps_number_arrays_on_one_line() {
        let value = serde_json::json!({
            "a": [[1.0, 2.0], [3.5, -4.0]],
            "b": [],
            "c": {},
            "d": [{"x": 1, "y\\\"{": "}, ["}, {"z": [1]}],
            "e": {"f": {"g": null}}
        });
        let text = render_lossy(&value);
        let expected = r#"{
  "a": [
    [1.0, 2.0],
    [3.5, -4.0]
  ],
  "b": [],
  "c": {},
  "d": [
    {"x": 1, "y\\\"{": "}, ["},
    {
      "z": [1]
    }
  ],
  "e": {
    "f": {"g": null}
  }
}
"#;
        assert_eq!(text, expected);
        assert_eq!(serde_json::from_str::<Value>(&text).ok(), Some(value));
    }
}
