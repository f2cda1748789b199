//! A CSV file of the import: a [`Table`] (the `csv` crate: quotes, a UTF-8
//! byte-order mark, line numbers) with its path, so that every message
//! names the file and the line.

use std::path::{Path, PathBuf};

use super::ImportError;
use crate::engine::files::format::{Cap, read_text};
use crate::engine::files::table::{Table, TableError, excerpt, parse_number, separator};

/// A parsed CSV file: header and data rows with their 1-based lines.
pub(super) struct CsvFile {
    /// The file.
    pub path: PathBuf,
    /// Column names as written.
    pub header: Vec<String>,
    /// `(line, fields)` of every data row.
    pub rows: Vec<(usize, Vec<String>)>,
    /// Fields not separated by commas (`;`, tabs): numbers may have
    /// decimal commas (`12,5`).
    pub decimal_commas: bool,
}

impl CsvFile {
    /// Reads and parses `path`.
    pub fn read(path: &Path) -> Result<Self, ImportError> {
        let text = read_text(path, Cap::TABLE).map_err(|source| ImportError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::parse(&text, path)
    }

    /// Parses `text`, the content of `path`.
    pub fn parse(text: &str, path: &Path) -> Result<Self, ImportError> {
        let table = Table::parse(text).map_err(|e| ImportError::Csv {
            path: path.to_path_buf(),
            line: e.line,
            message: e.message,
        })?;
        Ok(Self {
            path: path.to_path_buf(),
            header: table.header,
            rows: table.rows,
            decimal_commas: separator(text) != b',',
        })
    }

    /// Reads `text` (the content of `path`) row by row without keeping the
    /// rows: `each` gets the file (header, no rows), the 1-based line and
    /// the fields of every data row. Memory is that of one row, whatever
    /// the file's size.
    ///
    /// # Errors
    /// No header row, malformed CSV, a row with the wrong field count (all
    /// naming the file and line), or the first error `each` returns.
    pub fn stream(
        text: &str,
        path: &Path,
        mut each: impl FnMut(&Self, usize, &csv::StringRecord) -> Result<(), ImportError>,
    ) -> Result<Self, ImportError> {
        /// A table error (still to be given its file) or the caller's.
        enum Fail {
            Table(TableError),
            Row(ImportError),
        }
        impl From<TableError> for Fail {
            fn from(e: TableError) -> Self {
                Self::Table(e)
            }
        }
        let mut file: Option<Self> = None;
        let scanned = Table::for_each_record(text, |line, record| {
            match &file {
                None => {
                    file = Some(Self {
                        path: path.to_path_buf(),
                        header: record.iter().map(str::to_string).collect(),
                        rows: Vec::new(),
                        decimal_commas: separator(text) != b',',
                    });
                }
                Some(f) => each(f, line, record).map_err(Fail::Row)?,
            }
            Ok::<(), Fail>(())
        });
        match scanned {
            Ok(()) => {}
            Err(Fail::Row(e)) => return Err(e),
            Err(Fail::Table(e)) => {
                return Err(ImportError::Csv {
                    path: path.to_path_buf(),
                    line: e.line,
                    message: e.message,
                });
            }
        }
        file.ok_or_else(|| ImportError::Csv {
            path: path.to_path_buf(),
            line: 1,
            message: "no header row".into(),
        })
    }

    /// The index of column `name` (case-insensitive), or "no column".
    pub fn column(&self, name: &str) -> Result<usize, ImportError> {
        self.optional_column(name).ok_or_else(|| ImportError::File {
            path: self.path.clone(),
            message: format!(
                "no column `{}` (the header has: {})",
                excerpt(name),
                excerpt(&self.header.join(", "))
            ),
        })
    }

    /// The index of column `name` (case-insensitive), if there is one.
    pub fn optional_column(&self, name: &str) -> Option<usize> {
        self.header
            .iter()
            .position(|h| h.eq_ignore_ascii_case(name))
    }

    /// The finite number in `row[col]`, or a message naming line and column.
    pub fn number(&self, line: usize, row: &[String], col: usize) -> Result<f64, ImportError> {
        let s = &row[col];
        match parse_number(s, self.decimal_commas) {
            Some(v) if v.is_finite() => Ok(v),
            _ => Err(ImportError::Csv {
                path: self.path.clone(),
                line,
                message: format!(
                    "column `{}`: `{}` is not a finite number",
                    excerpt(&self.header[col]),
                    excerpt(s)
                ),
            }),
        }
    }
}
