//! Laser-tracker reference distances between validate stations: a CSV
//! with columns `from`, `to`, `distance` (mm).

use std::path::Path;

use super::ImportError;
use super::csv_file::CsvFile;
use crate::engine::session::ReferenceDistance;

/// The reference distances of a CSV with columns `from`, `to`, `distance`
/// (mm). Whether the stations exist and have validate measurements is
/// the session loader's check.
///
/// # Errors
/// Unreadable file, missing column, a distance that is not a positive
/// finite number, an empty station id or no rows at all.
pub fn read_references(path: &Path) -> Result<Vec<ReferenceDistance>, ImportError> {
    Ok(reference_rows(path)?.into_iter().map(|(_, r)| r).collect())
}

/// [`read_references`] with the 1-based line of each row in the file.
///
/// # Errors
/// As [`read_references`].
pub fn reference_rows(path: &Path) -> Result<Vec<(usize, ReferenceDistance)>, ImportError> {
    let csv = CsvFile::read(path)?;
    let from = csv.column("from")?;
    let to = csv.column("to")?;
    let distance = csv.column("distance")?;
    let mut out = Vec::with_capacity(csv.rows.len());
    for (line, row) in &csv.rows {
        let d = csv.number(*line, row, distance)?;
        let fail = |message: String| ImportError::Csv {
            path: path.to_path_buf(),
            line: *line,
            message,
        };
        if d <= 0.0 {
            return Err(fail(format!("distance {d} mm is not positive")));
        }
        if row[from].is_empty() || row[to].is_empty() {
            return Err(fail("empty station id".into()));
        }
        if row[from] == row[to] {
            return Err(fail(format!("from and to are both `{}`", row[from])));
        }
        out.push((
            *line,
            ReferenceDistance {
                from: row[from].clone(),
                to: row[to].clone(),
                distance: d,
            },
        ));
    }
    if out.is_empty() {
        return Err(ImportError::File {
            path: path.to_path_buf(),
            message: "no reference distances (only a header)".into(),
        });
    }
    Ok(out)
}
