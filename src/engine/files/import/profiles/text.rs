//! CSV and TXT profiles: named `x`, `y`, `z` columns, or two or three
//! numbers a row without a header.

use std::path::Path;

use super::{AXIS_NAMES, Collector, ProfileFormat, RawProfile, number_in};
use crate::engine::files::import::ImportError;
use crate::engine::files::import::csv_file::CsvFile;
use crate::engine::files::table::{
    excerpt, overlong_line, overlong_line_message, spaced_with_decimal_commas,
};

/// A CSV/TXT profile with or without a header.
pub(super) fn read_text_profile(
    text: &str,
    path: &Path,
    format: &ProfileFormat,
) -> Result<RawProfile, ImportError> {
    let first = text
        .trim_start_matches('\u{feff}')
        .lines()
        .find(|l| !l.trim().is_empty() && !l.trim_start().starts_with('#'))
        .unwrap_or("");
    if let Some((line, length)) = overlong_line(text) {
        return Err(ImportError::Csv {
            path: path.to_path_buf(),
            line,
            message: overlong_line_message(length),
        });
    }
    let (first_fields, commas) = split_fields(first);
    let has_header = first_fields.iter().any(|f| number_in(f, commas).is_none());
    let mut out = Collector::new(format);
    if has_header {
        // Row by row: a profile of millions of points is never held as
        // text fields.
        let mut columns = None;
        CsvFile::stream(text, path, |csv, line, row| {
            let columns = match columns {
                Some(c) => c,
                None => *columns.insert(xyz_columns(csv)?),
            };
            out.push(xyz_of(csv, line, row, &columns)?)
                .map_err(|message| ImportError::Csv {
                    path: path.to_path_buf(),
                    line,
                    message,
                })
        })
        .and_then(|csv| match columns {
            // A header and no rows: the columns are still checked.
            None => xyz_columns(&csv).map(|_| ()),
            Some(_) => Ok(()),
        })?;
    } else {
        let mut width = None;
        for (i, line) in text.trim_start_matches('\u{feff}').lines().enumerate() {
            let l = line.trim();
            if l.is_empty() || l.starts_with('#') {
                continue;
            }
            let (fields, commas) = split_fields(l);
            let values: Vec<f64> = fields
                .iter()
                .map(|f| number_in(f, commas))
                .collect::<Option<_>>()
                .ok_or_else(|| ImportError::Csv {
                    path: path.to_path_buf(),
                    line: i + 1,
                    message: format!("`{}` is not a row of numbers", excerpt(l)),
                })?;
            let w = *width.get_or_insert(values.len());
            if values.len() != w || !(2..=3).contains(&w) {
                return Err(ImportError::Csv {
                    path: path.to_path_buf(),
                    line: i + 1,
                    message: format!(
                        "{} numbers; a profile row without a header has 2 (y, z) or 3 (x, y, z), the first row had {w}",
                        values.len()
                    ),
                });
            }
            out.push(if w == 2 {
                [0.0, values[0], values[1]]
            } else {
                [values[0], values[1], values[2]]
            })
            .map_err(|message| ImportError::Csv {
                path: path.to_path_buf(),
                line: i + 1,
                message,
            })?;
        }
    }
    Ok(out.finish(path))
}

/// Fields of a headerless row, and whether their commas are decimal
/// commas: separated by `;` (then so), by spaces or tabs with decimal
/// commas (`1,5 -20,25`), else by `,`, `;`, tabs or spaces.
fn split_fields(line: &str) -> (Vec<&str>, bool) {
    if line.contains(';') {
        let fields = line
            .split(|c: char| c == ';' || c.is_whitespace())
            .filter(|f| !f.is_empty())
            .collect();
        (fields, true)
    } else if spaced_with_decimal_commas(line) {
        (line.split_whitespace().collect(), true)
    } else {
        let fields = line
            .split(|c: char| c == ',' || c.is_whitespace())
            .filter(|f| !f.is_empty())
            .collect();
        (fields, false)
    }
}

/// The columns of `x`, `y`, `z` a profile CSV has (at least two).
pub(super) fn xyz_columns(csv: &CsvFile) -> Result<[Option<usize>; 3], ImportError> {
    let columns = AXIS_NAMES.map(|n| csv.optional_column(n));
    if columns.iter().flatten().count() < 2 {
        return Err(ImportError::File {
            path: csv.path.clone(),
            message: format!(
                "a profile needs two or three of the columns x, y, z (the header has: {})",
                excerpt(&csv.header.join(", "))
            ),
        });
    }
    Ok(columns)
}

/// One point of a profile CSV row; a non-finite cell stays non-finite (it
/// is dropped and counted), text is an error naming the line.
pub(super) fn xyz_of(
    csv: &CsvFile,
    line: usize,
    row: &csv::StringRecord,
    columns: &[Option<usize>; 3],
) -> Result<[f64; 3], ImportError> {
    let mut p = [0.0; 3];
    for (v, c) in p.iter_mut().zip(columns) {
        if let Some(c) = *c {
            let cell = row.get(c).unwrap_or("");
            *v = number_in(cell, csv.decimal_commas).ok_or_else(|| ImportError::Csv {
                path: csv.path.clone(),
                line,
                message: format!(
                    "column `{}`: `{}` is not a number",
                    excerpt(&csv.header[c]),
                    excerpt(cell)
                ),
            })?;
        }
    }
    Ok(p)
}
