//! CSV tables as the engine reads them (joint logs, pose logs, profiles,
//! reference distances, plans, station lists), through the `csv` crate:
//! quoted fields, a UTF-8 byte-order mark (Excel's "CSV UTF-8"), and the
//! 1-based line of every row for messages.
//!
//! Conventions: blank lines and lines starting with `#` are skipped; the
//! first other line is the header; the separator is `;` when the header
//! has one, else a tab when it has one and no comma, else `,`; fields are
//! trimmed. Column names match case-insensitively.

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

/// The separator the header line implies.
fn separator(text: &str) -> u8 {
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

impl Table {
    /// Parses `text`.
    ///
    /// # Errors
    /// No header row, a malformed quoted field, or a data row whose field
    /// count differs from the header's.
    pub fn parse(text: &str) -> Result<Self, TableError> {
        let mut reader = csv::ReaderBuilder::new()
            .has_headers(false)
            .flexible(true)
            .comment(Some(b'#'))
            .delimiter(separator(text))
            .trim(csv::Trim::All)
            .from_reader(text.as_bytes());
        // The crate reports where it started reading a record, before the
        // comment and blank lines it skipped, and does not count comment
        // lines: the record's line is the first line from there on that
        // is neither.
        let lines: Vec<&str> = text.split('\n').collect();
        let line_starts: Vec<usize> = std::iter::once(0)
            .chain(text.match_indices('\n').map(|(i, _)| i + 1))
            .collect();
        let line_at = |byte: u64| {
            let byte = usize::try_from(byte).unwrap_or(usize::MAX);
            let mut line = line_starts.partition_point(|&start| start <= byte);
            while let Some(l) = lines.get(line - 1) {
                let l = l.trim_start_matches('\u{feff}');
                if l.trim().is_empty() || l.starts_with('#') {
                    line += 1;
                } else {
                    break;
                }
            }
            line
        };
        let mut header: Option<(usize, Vec<String>)> = None;
        let mut rows = Vec::new();
        for record in reader.records() {
            let record = record.map_err(|e| TableError {
                line: e.position().map_or(1, |p| line_at(p.byte())),
                message: format!("not valid CSV: {e}"),
            })?;
            let line = record.position().map_or(1, |p| line_at(p.byte()));
            if record.iter().all(str::is_empty) {
                continue;
            }
            let fields: Vec<String> = record.iter().map(str::to_string).collect();
            match &header {
                None => header = Some((line, fields)),
                Some((_, h)) if fields.len() != h.len() => {
                    return Err(TableError {
                        line,
                        message: format!("{} fields, the header has {}", fields.len(), h.len()),
                    });
                }
                Some(_) => rows.push((line, fields)),
            }
        }
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

    #[test]
    fn a_byte_order_mark_quotes_and_tabs_are_read() {
        let t = Table::parse("\u{feff}id,note\r\nc1,\"a, b\"\r\n").unwrap();
        assert_eq!(t.header, ["id", "note"]);
        assert_eq!(t.rows[0].1, ["c1", "a, b"]);
        let t = Table::parse("x\tz\n1.5\t2\n").unwrap();
        assert_eq!(t.rows[0].1, ["1.5", "2"]);
    }
}
