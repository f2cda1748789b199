//! The cloud's files, chosen by the output's extension, each written
//! through the atomic writer (a temporary file renamed into place; nothing
//! is left on an error):
//!
//! - `.ply` ([`ply`]): binary little-endian, per point `x y z` (double,
//!   mm), `sigma_mm` (float) and `pose` (uint, the index of the pose in
//!   scan order); header comments name the result, the model, the frame
//!   and each pose's id.
//! - `.e57` ([`e57_scans`]): one scan (`data3D`) per pose, its points in
//!   the sensor frame and its pose the sensor pose in the output frame
//!   (E57 stores metres: every length is divided by 1000), the σ (mm) as
//!   the extension attribute `spherecal:sigma_mm`.
//! - `.csv` ([`csv_rows`]): `id,x,y,z,sigma_mm`, mm, `id` the measurement
//!   or pose id, every number at full round-trip precision (Rust's
//!   shortest representation of the f64).
//!
//! Without σ (`--no-sigma`) `sigma_mm` is written as NaN in PLY and CSV,
//! and left out of E57.

pub mod csv_rows;
pub mod e57_scans;
pub mod ply;

use std::path::Path;

use super::cloud::Cloud;
use crate::engine::files::format::{FileError, write_atomic_with};

/// The file formats of a cloud.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CloudFormat {
    /// Binary PLY.
    Ply,
    /// ASTM E57.
    E57,
    /// CSV text.
    Csv,
}

impl CloudFormat {
    /// The format of a file by its extension (case-insensitive); `None`
    /// for any other.
    #[must_use]
    pub fn of_path(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_string_lossy().to_ascii_lowercase();
        match ext.as_str() {
            "ply" => Some(Self::Ply),
            "e57" => Some(Self::E57),
            "csv" => Some(Self::Csv),
            _ => None,
        }
    }
}

/// What a file's header says about where the cloud came from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Provenance {
    /// The result file the model came from.
    pub result: String,
    /// The scan (session or pose log).
    pub scan: String,
}

/// A header text without line breaks (a comment line of PLY).
fn one_line(text: &str) -> String {
    text.replace(['\n', '\r'], " ")
}

/// Writes `cloud` to `path` in `format`, atomically.
///
/// # Errors
/// [`FileError::Io`] naming the path: the file cannot be written, or the
/// format cannot hold the cloud (more than 2³² poses in PLY).
pub fn write_cloud(
    cloud: &Cloud,
    path: &Path,
    format: CloudFormat,
    provenance: &Provenance,
) -> Result<(), FileError> {
    write_atomic_with(path, |file| match format {
        CloudFormat::Ply => ply::write(file, cloud, provenance),
        CloudFormat::Csv => csv_rows::write(file, cloud),
        CloudFormat::E57 => e57_scans::write(file, cloud, provenance),
    })
}
