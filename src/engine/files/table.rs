//! CSV tables as the engine reads them (joint logs, pose logs, profiles,
//! reference distances, plans, station lists), through the `csv` crate:
//! quoted fields, a UTF-8 byte-order mark (Excel's "CSV UTF-8"), and the
//! 1-based line of every row for messages.
//!
//! Conventions: blank lines and lines starting with `#` are skipped; the
//! first other line is the header; the separator is `;` when the header
//! has one, else a tab when it has one and no comma, else `,`; fields are
//! trimmed. Column names match case-insensitively.

/// Longest piece of an input (a cell, a name, a line) echoed in a
/// message, characters: enough to recognise it, bounded whatever the file
/// holds (a line of a gigabyte).
pub const MAX_ECHO_CHARS: usize = 80;

/// Longest line of a CSV table, bytes (1 MiB): a row of a joint log,
/// profile, DH table or plan is at most a few hundred bytes. Longer lines
/// are refused before they are parsed, so a file of one huge line costs
/// no more than its text.
pub const MAX_LINE_BYTES: usize = 1 << 20;

/// `text` as one CSV field, the one field writer of the crate (histories,
/// clouds, the workbench's exports): as it is when a reader of any of the
/// separators above takes it back unchanged, else quoted with its quotes
/// doubled: when it holds a separator (`,` `;` tab), a quote or a line
/// break, has surrounding spaces (fields are trimmed) or starts with `#`
/// (a skipped line).
#[must_use]
pub fn csv_field(text: &str) -> String {
    let plain = !text.contains([',', '"', '\n', '\r', ';', '\t'])
        && text.trim() == text
        && !text.starts_with('#');
    if plain {
        text.to_string()
    } else {
        format!("\"{}\"", text.replace('"', "\"\""))
    }
}

/// A side cell that is not one.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("side `{}` is not +1, -1 or blank", excerpt(.0))]
pub struct SideCellError(pub String);

/// A `side` cell of a table (joint logs, pose tables, plans): `+1`, `1`,
/// `-1` (also `1.0`, `+1.0`, `-1.0`), or blank (`None`: not given).
///
/// # Errors
/// [`SideCellError`] for anything else.
pub fn side_cell(cell: &str) -> Result<Option<i8>, SideCellError> {
    match cell.trim() {
        "" => Ok(None),
        "1" | "+1" | "1.0" | "+1.0" => Ok(Some(1)),
        "-1" | "-1.0" => Ok(Some(-1)),
        other => Err(SideCellError(other.to_string())),
    }
}

/// `text` cut to at most `max` characters for a message: the start, then
/// `…` and how many characters were left out.
#[must_use]
pub fn clip(text: &str, max: usize) -> String {
    match text.char_indices().nth(max) {
        None => text.to_owned(),
        Some((cut, _)) => format!(
            "{}… ({} more characters)",
            &text[..cut],
            text[cut..].chars().count()
        ),
    }
}

/// A piece of an input for a message, cut to [`MAX_ECHO_CHARS`].
#[must_use]
pub fn excerpt(text: &str) -> String {
    clip(text, MAX_ECHO_CHARS)
}

/// The first line of `text` longer than [`MAX_LINE_BYTES`]: its 1-based
/// number and length in bytes. One linear pass.
#[must_use]
pub fn overlong_line(text: &str) -> Option<(usize, usize)> {
    (1..)
        .zip(text.as_bytes().split(|&b| b == b'\n'))
        .find(|(_, chunk)| chunk.len() > MAX_LINE_BYTES)
        .map(|(line, chunk)| (line, chunk.len()))
}

/// The error of a line beyond [`MAX_LINE_BYTES`] (see [`overlong_line`]).
#[must_use]
pub fn overlong_line_message(length: usize) -> String {
    format!(
        "the line has {length} bytes, more than the {} MiB a row may have: not a table of this kind",
        MAX_LINE_BYTES >> 20
    )
}

/// A CSV table as read: header and data rows with their 1-based line
/// numbers.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Table {
    /// Line of the header row.
    pub header_line: usize,
    /// Column names as written.
    pub header: Vec<String>,
    /// `(line, fields)`, one per data row, each with as many fields as the header.
    pub rows: Vec<(usize, Vec<String>)>,
}

/// Why a text is not a [`Table`]: the line and what is wrong.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{message} (line {line})")]
pub struct TableError {
    /// 1-based line.
    pub line: usize,
    /// What is wrong.
    pub message: String,
}

/// Whether `s` is a number written with a decimal comma (`1000,5`,
/// `-0,25`, `1,5e-3`), as spreadsheets and controllers in many European
/// locales write them.
#[must_use]
pub fn decimal_comma(s: &str) -> bool {
    let unsigned = s.strip_prefix(['+', '-']).unwrap_or(s);
    let Some((int, frac)) = unsigned.split_once(',') else {
        return false;
    };
    let digits = |t: &str| !t.is_empty() && t.bytes().all(|b| b.is_ascii_digit());
    let (frac, exponent) = match frac.split_once(['e', 'E']) {
        Some((f, e)) => (f, Some(e.strip_prefix(['+', '-']).unwrap_or(e))),
        None => (frac, None),
    };
    digits(int) && digits(frac) && exponent.is_none_or(digits)
}

/// Whether `line` is fields separated by spaces or tabs whose commas are
/// all decimal commas (`1000,5 -20,25 500`): at least two fields and one
/// comma.
#[must_use]
pub fn spaced_with_decimal_commas(line: &str) -> bool {
    let fields: Vec<&str> = line.split_whitespace().collect();
    fields.len() > 1
        && fields.iter().any(|f| f.contains(','))
        && fields.iter().all(|f| !f.contains(',') || decimal_comma(f))
}

/// A cell's number: with a decimal point, or, when `commas_decimal` (a
/// table whose fields are not separated by commas), a decimal comma.
#[must_use]
pub fn parse_number(cell: &str, commas_decimal: bool) -> Option<f64> {
    if let Ok(v) = cell.parse() {
        return Some(v);
    }
    if commas_decimal && decimal_comma(cell) {
        return cell.replacen(',', ".", 1).parse().ok();
    }
    None
}

/// The separator the header line implies.
#[must_use]
pub fn separator(text: &str) -> u8 {
    let header = text
        .trim_start_matches('\u{feff}')
        .lines()
        .find(|l| !l.trim().is_empty() && !l.starts_with('#'))
        .unwrap_or("");
    if header.contains(';') {
        b';'
    } else if header.contains('\t') && !header.contains(',') {
        b'\t'
    } else {
        b','
    }
}

/// The line of a byte offset, for offsets that mostly grow: counted on
/// from the last answer (linear in the text overall, no table of line
/// starts). The `csv` crate reports where it started reading a record,
/// before the comment and blank lines it skipped, and does not count
/// comment lines: the record's line is the first line from there on that
/// is neither.
struct LineCounter<'a> {
    text: &'a str,
    /// Byte offset of the start of line `line`.
    start: usize,
    line: usize,
}

impl<'a> LineCounter<'a> {
    fn new(text: &'a str) -> Self {
        Self {
            text,
            start: 0,
            line: 1,
        }
    }

    fn line_at(&mut self, byte: u64) -> usize {
        let byte = usize::try_from(byte)
            .unwrap_or(usize::MAX)
            .min(self.text.len());
        if byte < self.start {
            *self = Self::new(self.text);
        }
        let bytes = self.text.as_bytes();
        // After a `\r\n`, the reader says its record starts at the `\n`
        // (the `\r` ended the row): no record starts at a line's end.
        let byte = if bytes.get(byte) == Some(&b'\n') {
            byte + 1
        } else {
            byte
        };
        while let Some(nl) = bytes[self.start..byte].iter().position(|&b| b == b'\n') {
            self.start += nl + 1;
            self.line += 1;
        }
        // Skip the comment and blank lines the reader passed over.
        let mut start = self.start;
        let mut line = self.line;
        loop {
            let end = bytes[start..]
                .iter()
                .position(|&b| b == b'\n')
                .map_or(bytes.len(), |i| start + i);
            let l = self.text.get(start..end).unwrap_or("");
            let l = l.trim_start_matches('\u{feff}');
            if end < bytes.len() && (l.trim().is_empty() || l.starts_with('#')) {
                start = end + 1;
                line += 1;
            } else {
                return line;
            }
        }
    }
}

impl Table {
    /// Parses `text`.
    ///
    /// # Errors
    /// No header row, a malformed quoted field, or a data row whose field
    /// count differs from the header's.
    pub fn parse(text: &str) -> Result<Self, TableError> {
        let mut header: Option<(usize, Vec<String>)> = None;
        let mut rows = Vec::new();
        Self::for_each_record(text, |line, record| {
            let fields: Vec<String> = record.iter().map(str::to_string).collect();
            if header.is_none() {
                header = Some((line, fields));
            } else {
                rows.push((line, fields));
            }
            Ok::<(), TableError>(())
        })?;
        let Some((header_line, header)) = header else {
            return Err(TableError {
                line: 1,
                message: "no header row".into(),
            });
        };
        Ok(Self {
            header_line,
            header,
            rows,
        })
    }

    /// Reads `text` record by record without keeping the rows: `each` gets
    /// the 1-based line and the fields of the header (the first record)
    /// and then of every data row, in order. Memory stays that of one row,
    /// whatever the size of the file (a profile of millions of points).
    ///
    /// # Errors
    /// A line longer than [`MAX_LINE_BYTES`], a malformed quoted field, or
    /// a data row whose field count differs from the header's; or the
    /// first error `each` returns. No header row
    /// is not an error here (`each` is then never called).
    pub fn for_each_record<E: From<TableError>>(
        text: &str,
        mut each: impl FnMut(usize, &csv::StringRecord) -> Result<(), E>,
    ) -> Result<(), E> {
        if let Some((line, length)) = overlong_line(text) {
            return Err(TableError {
                line,
                message: overlong_line_message(length),
            }
            .into());
        }
        let mut reader = csv::ReaderBuilder::new()
            .has_headers(false)
            .flexible(true)
            .comment(Some(b'#'))
            .delimiter(separator(text))
            .trim(csv::Trim::All)
            .from_reader(text.as_bytes());
        let mut lines = LineCounter::new(text);
        let mut width: Option<usize> = None;
        let mut record = csv::StringRecord::new();
        loop {
            match reader.read_record(&mut record) {
                Ok(false) => return Ok(()),
                Ok(true) => {}
                Err(e) => {
                    return Err(TableError {
                        line: e.position().map_or(1, |p| lines.line_at(p.byte())),
                        message: format!("not valid CSV: {e}"),
                    }
                    .into());
                }
            }
            let line = record.position().map_or(1, |p| lines.line_at(p.byte()));
            if record.iter().all(str::is_empty) {
                continue;
            }
            match width {
                None => width = Some(record.len()),
                Some(w) if record.len() != w => {
                    return Err(TableError {
                        line,
                        message: format!("{} fields, the header has {w}", record.len()),
                    }
                    .into());
                }
                Some(_) => {}
            }
            each(line, &record)?;
        }
    }

    /// The index of the column named `name` (case-insensitive).
    #[must_use]
    pub fn column(&self, name: &str) -> Option<usize> {
        self.header
            .iter()
            .position(|h| h.eq_ignore_ascii_case(name))
    }

    /// "no column `name` (the header has: …)".
    #[must_use]
    pub fn no_column(&self, name: &str) -> String {
        format!(
            "no column `{name}` (the header has: {})",
            self.header.join(", ")
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_are_quoted_when_needed() {
        assert_eq!(csv_field("c17"), "c17");
        assert_eq!(csv_field("a,b"), "\"a,b\"");
        assert_eq!(csv_field("say \"x\""), "\"say \"\"x\"\"\"");
        assert_eq!(csv_field(" lead"), "\" lead\"");
    }

    #[test]
    fn tables_parse_and_name_lines() {
        let t = Table::parse("# c\nid;\"use\"\n\na;identify\n").unwrap();
        assert_eq!(t.header, ["id", "use"]);
        assert_eq!(t.header_line, 2);
        assert_eq!(t.rows, [(4, vec!["a".to_string(), "identify".to_string()])]);
        assert_eq!(t.column("USE"), Some(1));
        let e = Table::parse("id,use\na\n").unwrap_err();
        assert_eq!(e.line, 2);
        assert!(Table::parse("# only a comment\n").is_err());
    }

    /// Issue 31: in CRLF files (joint logs, profiles, references) every
    /// error's line was one too low.
    #[test]
    fn crlf_files_name_the_right_line() {
        let t = Table::parse("# c\r\nid,use\r\n\r\na,identify\r\nb,validate\r\n").unwrap();
        assert_eq!(t.header_line, 2);
        assert_eq!(t.rows[0].0, 4);
        assert_eq!(t.rows[1].0, 5);
        let e = Table::parse("id,use\r\na,identify\r\nb\r\n").unwrap_err();
        assert_eq!(e.line, 3);
    }

    #[test]
    fn a_byte_order_mark_quotes_and_tabs_are_read() {
        let t = Table::parse("\u{feff}id,note\r\nc1,\"a, b\"\r\n").unwrap();
        assert_eq!(t.header, ["id", "note"]);
        assert_eq!(t.rows[0].1, ["c1", "a, b"]);
        let t = Table::parse("x\tz\n1.5\t2\n").unwrap();
        assert_eq!(t.rows[0].1, ["1.5", "2"]);
    }
}
