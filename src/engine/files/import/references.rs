//! Laser-tracker reference distances between validate stations: a CSV
//! with columns `from`, `to`, `distance` (mm).

use std::path::Path;

use super::ImportError;
use super::csv_file::CsvFile;
use crate::engine::base::session::ReferenceDistance;

/// The reference distances of a CSV with columns `from`, `to`, `distance`
/// (mm). Whether the stations exist and have validate measurements is
/// the session loader's check.
///
/// # Errors
/// Unreadable file, missing column, a distance that is not a positive
/// finite number, an empty station id, a pair of stations given twice
/// (either way round: two distances for one pair contradict, or count it
/// twice) or no rows at all.
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
    // Each pair of stations (in name order) with its first line and distance.
    let mut seen: std::collections::HashMap<(String, String), (usize, f64)> =
        std::collections::HashMap::new();
    for (line, row) in &csv.rows {
        let d = csv.number(*line, row, distance)?;
        let fail = |message: String| ImportError::Csv {
            path: path.to_path_buf(),
            line: *line,
            message,
        };
        if d <= 0.0 {
            return Err(fail(format!(
                "distance {} mm is not positive",
                crate::engine::base::numeric::show(d)
            )));
        }
        if row[from].is_empty() || row[to].is_empty() {
            return Err(fail("empty station id".into()));
        }
        if row[from] == row[to] {
            return Err(fail(format!(
                "from and to are both `{}`",
                crate::engine::files::table::excerpt(&row[from])
            )));
        }
        let key = if row[from] < row[to] {
            (row[from].clone(), row[to].clone())
        } else {
            (row[to].clone(), row[from].clone())
        };
        if let Some(&(first, earlier)) = seen.get(&key) {
            let verdict = if earlier == d {
                "the same distance twice would count its pairs twice".to_owned()
            } else {
                format!(
                    "{} mm there against {} mm here: they contradict each other",
                    crate::engine::base::numeric::show(earlier),
                    crate::engine::base::numeric::show(d)
                )
            };
            return Err(fail(format!(
                "the pair {} – {} is given a second time (first on line {first}): {verdict}; keep one",
                crate::engine::files::table::excerpt(&row[from]),
                crate::engine::files::table::excerpt(&row[to])
            )));
        }
        seen.insert(key, (*line, d));
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
