//! A rigid transform in a file of its own: a JSON 4×4 matrix (rows, mm,
//! FORMAT.md's matrix rules), or a session or result file whose
//! `hand_eye` is taken. Read by the import (`--hand-eye`, a guess to
//! start from), the planner (the sensor's hand-eye) and the measuring
//! command (a workpiece frame).

use std::path::Path;

use nalgebra::Isometry3;
use serde_json::Value;

use crate::engine::base::geometry::isometry_from_rows;

/// Largest transform file read, bytes: a 4×4 is a few hundred bytes, a
/// session holding one may be large but is read as a whole anyway.
const MAX_TRANSFORM_FILE_BYTES: u64 = 1 << 30;

/// The transform in `path`: a 4×4 matrix (JSON rows), an object with the
/// key `key` (e.g. `hand_eye` of a session or result), or an object with
/// `matrix`.
///
/// # Errors
/// A message (without the path: the caller names the file and what it
/// is): unreadable, not JSON, no matrix, not a rigid transform.
pub fn read_transform(path: &Path, key: &str) -> Result<Isometry3<f64>, String> {
    let size = std::fs::metadata(path)
        .map_err(|e| format!("reading failed: {e}"))?
        .len();
    if size > MAX_TRANSFORM_FILE_BYTES {
        return Err(format!("{size} bytes is not a transform file"));
    }
    let text = std::fs::read_to_string(path).map_err(|e| format!("reading failed: {e}"))?;
    let value: Value = serde_json::from_str(text.trim_start_matches('\u{feff}'))
        .map_err(|e| format!("not valid JSON: {e}"))?;
    let matrix = match &value {
        Value::Object(map) => map
            .get(key)
            .or_else(|| map.get("matrix"))
            .cloned()
            .ok_or_else(|| format!("the file has no `{key}` (nor `matrix`)"))?,
        other => other.clone(),
    };
    if matrix.is_null() {
        return Err(format!("its `{key}` is null"));
    }
    let rows: [[f64; 4]; 4] = serde_json::from_value(matrix)
        .map_err(|e| format!("expected a 4x4 matrix of numbers: {e}"))?;
    isometry_from_rows(&rows).map_err(|e| e.to_string())
}
