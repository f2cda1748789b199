//! A rigid transform in a file of its own, the one reader of every 4×4
//! the commands take: a JSON 4×4 matrix (rows, mm, FORMAT.md's matrix
//! rules), bare or under its key, or a session or result file whose key
//! (`hand_eye`) is taken. Read by the import (`--hand-eye`, a guess to
//! start from), the planner and the simulator (the sensor's hand-eye),
//! the measuring command (`--frame`, `base_from_workpiece`) and
//! compensation (`--tcp`, `flange_from_tcp`). Through the capped reader
//! ([`Cap::SESSION`]), and with the session rules' plausibility caps
//! (a translation beyond 100 m is refused at once, naming the key, before
//! anything computes with it).

use std::path::Path;

use nalgebra::Isometry3;
use serde_json::Value;

use super::read::{Cap, read_text};
use crate::engine::base::geometry::{
    MatrixError, ROTATION_TOLERANCE, TYPED_ROTATION_TOLERANCE, isometry_from_rows_within,
};
use crate::engine::base::session::rules::{self, RuleViolation};

/// Why a transform file gives no transform. The messages name no file:
/// the caller names the file and what it is.
#[derive(Debug, thiserror::Error)]
pub enum TransformError {
    /// The file cannot be read, or is beyond the cap.
    #[error("reading failed: {0}")]
    Read(#[source] std::io::Error),
    /// Not JSON.
    #[error("not valid JSON: {0}")]
    Json(String),
    /// A JSON object without the key (nor `matrix`).
    #[error("the file has no `{0}` (nor `matrix`)")]
    NoKey(String),
    /// The key is `null` (a session without a hand-eye).
    #[error("its `{0}` is null")]
    Null(String),
    /// Not four rows of four numbers.
    #[error("expected a 4x4 matrix of numbers (4 rows of 4, mm): {0}")]
    NotMatrix(String),
    /// Not a rigid transform.
    #[error("not a rigid transform: {0}")]
    NotRigid(#[from] MatrixError),
    /// Beyond the session rules' plausibility caps (names the key).
    #[error(transparent)]
    Implausible(#[from] RuleViolation),
}

/// The transform in `path`: a 4×4 matrix (JSON rows), an object with the
/// key `key` (e.g. `hand_eye` of a session or result, `flange_from_tcp`
/// of a tool), or an object with `matrix`; finite, rigid and plausible
/// ([`rules::transform`], naming `key`).
///
/// # Errors
/// [`TransformError`]: unreadable, not JSON, no matrix, not a rigid
/// transform, not plausible.
pub fn read_transform(path: &Path, key: &str) -> Result<Isometry3<f64>, TransformError> {
    read_typed_transform(path, key).map(|(transform, _)| transform)
}

/// [`read_transform`], and a note when the rotation was re-orthonormalised:
/// a 4×4 typed by a person (rotation written to a few decimals) is
/// accepted up to [`TYPED_ROTATION_TOLERANCE`] from orthonormal and made
/// exactly rigid, the note saying by how much.
///
/// # Errors
/// As [`read_transform`].
pub fn read_typed_transform(
    path: &Path,
    key: &str,
) -> Result<(Isometry3<f64>, Option<String>), TransformError> {
    let text = read_text(path, Cap::SESSION).map_err(TransformError::Read)?;
    // A key given twice is refused: which of the two is meant? (The
    // JSON map keeps the last one silently.)
    let super::json::UniqueValue(value) = serde_json::from_str(text.trim_start_matches('\u{feff}'))
        .map_err(|e| TransformError::Json(e.to_string()))?;
    let matrix = match value {
        Value::Object(mut map) => map
            .remove(key)
            .or_else(|| map.remove("matrix"))
            .ok_or_else(|| TransformError::NoKey(key.to_string()))?,
        other => other,
    };
    if matrix.is_null() {
        return Err(TransformError::Null(key.to_string()));
    }
    let rows: [[f64; 4]; 4] =
        serde_json::from_value(matrix).map_err(|e| TransformError::NotMatrix(e.to_string()))?;
    let (transform, off) = isometry_from_rows_within(&rows, TYPED_ROTATION_TOLERANCE)?;
    rules::transform(key, &transform)?;
    let note = (off > ROTATION_TOLERANCE).then(|| {
        format!(
            "{key}: the rotation is {off:.1e} from orthonormal (|RᵀR − I|, numbers rounded as written): taken as the nearest rotation"
        )
    });
    Ok((transform, note))
}
