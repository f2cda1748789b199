//! The record of a re-check (`spherecal check`, issue 33): what was
//! checked against which result, when, the verdict and what moved. A
//! small JSON file (`"format": "spherecal-check"`) written next to the
//! check's session (`X.check.json` for `X.json`) that `history` lists
//! beside the calibrations.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::json::read_text;
use super::{FORMAT_VERSION, FileError, write_atomic};

/// The `format` of a check record.
pub const CHECK_FORMAT: &str = "spherecal-check";

/// One station's fitted sphere centre (base frame, mm).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CheckCentre {
    /// Station id.
    pub station: String,
    /// The centre, mm.
    pub centre: [f64; 3],
}

/// A re-check's record (formats.md).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CheckRecord {
    /// [`CHECK_FORMAT`].
    pub format: String,
    /// [`FORMAT_VERSION`].
    pub version: u32,
    /// When the check was made, UTC, `YYYY-MM-DDTHH:MM:SSZ`.
    pub date: String,
    /// The robot's name (the result's).
    pub robot: String,
    /// The check session's name.
    pub session: String,
    /// The check session's file, as given.
    pub session_file: String,
    /// The result checked against, as given.
    pub result_file: String,
    /// The result's session name (the calibration checked).
    pub result_session: String,
    /// The false-alarm rate.
    pub alpha: f64,
    /// The cell still holds its calibration.
    pub holds: bool,
    /// Only the hand-eye was checked (flange poses).
    pub hand_eye_only: bool,
    /// Sightings used.
    pub sightings: usize,
    /// The omnibus statistic `T`, its degrees of freedom and threshold.
    pub statistic: f64,
    /// Degrees of freedom of `statistic`.
    pub dof: usize,
    /// Threshold of `statistic`.
    pub threshold: f64,
    /// The directed statistic `T_d`.
    pub directed: f64,
    /// Degrees of freedom of `directed`.
    pub directed_dof: usize,
    /// Threshold of `directed` (`null` when the check sees no change).
    pub directed_threshold: Option<f64>,
    /// RMS of the predicted centres about their station's fit, mm.
    pub rms_mm: f64,
    /// What moved, in words (`null` when the cell holds).
    pub moved: Option<String>,
    /// The fitted sphere centres.
    pub centres: Vec<CheckCentre>,
}

/// The record's path for a check session `X.json`: `X.check.json` beside
/// it (`X.check.json` for a session file without `.json`, too).
#[must_use]
pub fn check_record_path(session: &Path) -> std::path::PathBuf {
    let name = session
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let stem = name
        .strip_suffix(".json")
        .or_else(|| name.strip_suffix(".JSON"))
        .unwrap_or(&name);
    session.with_file_name(format!("{stem}.check.json"))
}

/// Reads a check record from its text.
///
/// # Errors
/// [`FileError::Invalid`] naming the file: not JSON of this format and
/// version, a key missing or unknown.
pub fn parse_check_record(text: &str, path: &Path) -> Result<CheckRecord, FileError> {
    let invalid = |message: String| FileError::Invalid {
        path: path.to_path_buf(),
        measurement: None,
        message,
    };
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let record: CheckRecord =
        serde_json::from_str(text).map_err(|e| invalid(format!("not a check record: {e}")))?;
    if record.format != CHECK_FORMAT {
        return Err(invalid(format!(
            "format {:?}, expected {CHECK_FORMAT:?}",
            record.format
        )));
    }
    if record.version != FORMAT_VERSION {
        return Err(invalid(format!(
            "version {}, this build reads version {FORMAT_VERSION}",
            record.version
        )));
    }
    Ok(record)
}

/// Reads a check record file (the capped reader).
///
/// # Errors
/// [`FileError::Io`] when it cannot be read, else as [`parse_check_record`].
pub fn load_check_record(path: &Path) -> Result<CheckRecord, FileError> {
    parse_check_record(&read_text(path)?, path)
}

/// The record's JSON text (pretty, newline-terminated); numbers that are
/// not finite are written as `null` by serde and refused on reading, so a
/// record's statistic is clamped by the caller.
#[must_use]
pub fn check_record_json(record: &CheckRecord) -> String {
    let mut text = serde_json::to_string_pretty(record).unwrap_or_default();
    text.push('\n');
    text
}

/// Writes the record atomically.
///
/// # Errors
/// [`FileError::Io`] when it cannot be written.
pub fn save_check_record(path: &Path, record: &CheckRecord) -> Result<(), FileError> {
    write_atomic(path, check_record_json(record).as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_record_path_is_beside_the_session() {
        assert_eq!(
            check_record_path(Path::new("a/check 2026-11-28.json")),
            Path::new("a/check 2026-11-28.check.json")
        );
        assert_eq!(check_record_path(Path::new("x")), Path::new("x.check.json"));
    }
}
