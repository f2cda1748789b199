//! Stripe profiles as sensors write them, into FORMAT.md's laser plane.
//!
//! # Files
//!
//! - **CSV or TXT**, one file a pose: columns named `x`, `y`, `z` (any two
//!   or three of them, any case; a missing one is 0), or without a header
//!   two numbers a row (`y, z`, FORMAT's plane) or three (`x, y, z`),
//!   separated by `,`, `;`, tabs or spaces; or one CSV for all poses with a
//!   pose column.
//! - **OpenCV FileStorage YAML** (`%YAML:1.0`, `.yml`/`.yaml`) or **JSON**
//!   (`.json`): a flat list of numbers under a key (`scan_line`,
//!   `profile`, `points`, `data`, or the only list in the file), read as
//!   `x, y, z` triplets when one coordinate of the triplets is constant,
//!   else as `y, z` pairs; or an `opencv-matrix` with 2 or 3 columns.
//!
//! # Axes and units
//!
//! A sensor measures in its own plane, e.g. `y = 0` with `x` along the
//! line and `z` in depth. An [`AxisMap`] maps the sensor's axes onto
//! FORMAT.md's frame, where the laser plane is `x = 0`: given
//! (`-y,x,z`: spherecal `x = −y`, `y = x`, `z = z`), or guessed from the
//! data: the coordinate that is constant (zero) in every profile is the
//! plane's normal and becomes `x`; the other two keep their order as `y`,
//! `z`; the sign of `x` makes the map a rotation. A map that mirrors the
//! frame (determinant −1) is refused: it would turn the calibrated
//! hand-eye into a reflection. Coordinates are scaled from the file's unit
//! to mm.
//!
//! # No-return points
//!
//! Points with a NaN or infinite coordinate (`nan`, `.nan`, `inf`, …) and
//! points with the sensor's no-return sentinel (a value given by the user,
//! in the file's unit) are dropped and counted per pose.

mod axes;
mod opencv;
mod text;

use std::collections::HashMap;
use std::fs;
use std::path::{Path, PathBuf};

pub use self::axes::{AxisMap, AxisMapError};
use super::csv_file::CsvFile;
use super::{ImportError, LengthUnit};
use crate::engine::base::limits;
use crate::engine::base::numeric::show;
use crate::engine::files::format::{Cap, read_text};
use crate::engine::files::table::parse_number;

/// Names of the sensor's axes, in order.
const AXIS_NAMES: [&str; 3] = ["x", "y", "z"];

/// File extensions read as profiles, in the order a pose's file is looked
/// for (`<id>.csv` first).
pub const PROFILE_EXTENSIONS: [&str; 5] = ["csv", "txt", "yml", "yaml", "json"];

/// Keys looked for, in order, in an OpenCV YAML or JSON profile.
pub const PROFILE_KEYS: [&str; 4] = ["scan_line", "profile", "points", "data"];

/// Largest |coordinate| of a profile point accepted by the readers, mm:
/// the session's sensor field ([`limits::SENSOR_COORDINATE_MM`], 10 m)
/// times the thousand of a unit read wrong (µm as mm). Beyond it a value
/// is nonsense in every unit and is refused with its line; within it a
/// unit mistake is caught by the profile size check, which names the
/// `--profile-unit` to give, and a stray point by the session's rules.
pub const MAX_PROFILE_COORDINATE_MM: f64 = limits::SENSOR_COORDINATE_MM * 1000.0;

/// Largest |coordinate| (mm) along the plane's normal accepted as "on the
/// plane" after the axis map: rounding of the file's numbers.
const PLANE_TOLERANCE_MM: f64 = 1e-6;

/// Where the stripe profiles are.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ProfileSource {
    /// A folder with one profile file per pose: `<id>.csv` (or `.txt`,
    /// `.yml`, `.yaml`, `.json`); for a pose log without ids, every
    /// profile file of the folder, paired with the poses in the natural
    /// order of their names (`p2` before `p10`).
    Folder(PathBuf),
    /// One CSV with columns `<pose_column>` and two or three of `x, y, z`.
    File {
        /// The file.
        path: PathBuf,
        /// Name of the column holding the pose id.
        pose_column: String,
    },
}

/// How to read the profiles' numbers.
#[derive(Debug, Clone, PartialEq)]
pub struct ProfileFormat {
    /// Unit of the coordinates in the files.
    pub unit: LengthUnit,
    /// The sensor-to-FORMAT axis map; `None`: guessed from the data.
    pub axes: Option<AxisMap>,
    /// The sensor's no-return value (file units), dropped like NaN.
    pub no_return: Option<f64>,
    /// Key of the point list in OpenCV YAML/JSON files; `None`: the first
    /// of [`PROFILE_KEYS`] present, else the only list.
    pub key: Option<String>,
}

impl Default for ProfileFormat {
    fn default() -> Self {
        Self {
            unit: LengthUnit::Mm,
            axes: None,
            no_return: None,
            key: None,
        }
    }
}

/// A profile as read: points in the sensor's axes (mm), with what was
/// dropped.
#[derive(Debug, Clone, PartialEq)]
pub struct RawProfile {
    /// The file it came from.
    pub source: PathBuf,
    /// Points `[x, y, z]` in the sensor's axes, mm (a coordinate the file
    /// does not have is 0).
    pub points: Vec<[f64; 3]>,
    /// Points dropped for a NaN or infinite coordinate.
    pub non_finite: usize,
    /// Points dropped for the no-return value.
    pub no_return: usize,
}

/// A profile in the laser plane: FORMAT.md stripe points `[y, z]` (mm).
#[derive(Debug, Clone, PartialEq)]
pub struct PlaneProfile {
    /// The file it came from.
    pub source: PathBuf,
    /// Stripe points `[y, z]`, mm.
    pub points: Vec<[f64; 2]>,
    /// Points dropped for a NaN or infinite coordinate.
    pub non_finite: usize,
    /// Points dropped for the no-return value.
    pub no_return: usize,
}

impl RawProfile {
    /// The profile in the laser plane under `map`.
    ///
    /// # Errors
    /// A point off the plane (`|x| > 1e-6 mm` after the map).
    pub fn to_plane(&self, map: &AxisMap) -> Result<PlaneProfile, ImportError> {
        let mut points = Vec::with_capacity(self.points.len());
        for (i, p) in self.points.iter().enumerate() {
            let q = map.apply(*p);
            if q[0].abs() > PLANE_TOLERANCE_MM {
                return Err(ImportError::File {
                    path: self.source.clone(),
                    message: format!(
                        "point {} lies {} mm off the laser plane under the axis map {map} ({}): the plane's normal is the sensor axis {}; choose another map",
                        i + 1,
                        show(q[0]),
                        map.describe(),
                        AXIS_NAMES[map.normal_axis()]
                    ),
                });
            }
            points.push([q[1], q[2]]);
        }
        Ok(PlaneProfile {
            source: self.source.clone(),
            points,
            non_finite: self.non_finite,
            no_return: self.no_return,
        })
    }
}

impl PlaneProfile {
    /// The diagonal of the points' bounding box, mm (0 without points).
    #[must_use]
    pub fn extent(&self) -> f64 {
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for p in &self.points {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        if self.points.is_empty() {
            0.0
        } else {
            (hi[0] - lo[0]).hypot(hi[1] - lo[1])
        }
    }
}

/// Collects points, dropping non-finite ones and the no-return value,
/// refusing implausible ones.
struct Collector<'a> {
    format: &'a ProfileFormat,
    /// Finite points, file units until [`Self::finish`].
    points: Vec<[f64; 3]>,
    non_finite: usize,
}

impl<'a> Collector<'a> {
    fn new(format: &'a ProfileFormat) -> Self {
        Self {
            format,
            points: Vec::new(),
            non_finite: 0,
        }
    }

    /// Adds one point given in file units; a point with a NaN or infinite
    /// coordinate is dropped and counted.
    ///
    /// # Errors
    /// A coordinate (other than the no-return value) beyond
    /// [`MAX_PROFILE_COORDINATE_MM`]: the message, for the caller to give
    /// its line or point.
    fn push(&mut self, p: [f64; 3]) -> Result<(), String> {
        if p.iter().any(|v| !v.is_finite()) {
            self.non_finite += 1;
            return Ok(());
        }
        for (k, &v) in p.iter().enumerate() {
            let mm = self.format.unit.to_mm(v);
            if mm.abs() > MAX_PROFILE_COORDINATE_MM && self.format.no_return != Some(v) {
                return Err(format!(
                    "{} = {} {} is not plausible for a stripe point in any unit (a sensor sees at most {} mm)",
                    AXIS_NAMES[k],
                    show(v),
                    self.format.unit.symbol(),
                    limits::SENSOR_COORDINATE_MM
                ));
            }
        }
        self.points.push(p);
        Ok(())
    }

    /// The profile: points with the no-return value dropped and counted,
    /// in mm. The value is looked for only on the measured coordinates: a
    /// coordinate that is the same in every point (the plane's normal, or
    /// one the file does not have, 0) is not a reading, so `--no-return 0`
    /// keeps the points of a profile in the plane `y = 0`.
    fn finish(mut self, source: &Path) -> RawProfile {
        let mut no_return = 0;
        if let Some(sentinel) = self.format.no_return {
            let constant: [bool; 3] = std::array::from_fn(|k| {
                self.points
                    .first()
                    .is_some_and(|f| self.points.iter().all(|p| p[k] == f[k]))
            });
            // A profile of one repeated point has no plane to spare.
            let constant = if constant.iter().all(|&c| c) {
                [false; 3]
            } else {
                constant
            };
            let before = self.points.len();
            self.points
                .retain(|p| !(0..3).any(|k| !constant[k] && p[k] == sentinel));
            no_return = before - self.points.len();
        }
        let unit = self.format.unit;
        for p in &mut self.points {
            *p = p.map(|v| unit.to_mm(v));
        }
        RawProfile {
            source: source.to_path_buf(),
            points: self.points,
            non_finite: self.non_finite,
            no_return,
        }
    }
}

/// A number as sensors and OpenCV write it: Rust's forms plus OpenCV's
/// `.nan`, `.inf`, `-.inf`.
fn number(text: &str) -> Option<f64> {
    number_in(text, false)
}

/// [`number`], also with a decimal comma when `decimal_commas` (a file
/// whose fields are not separated by commas).
fn number_in(text: &str, decimal_commas: bool) -> Option<f64> {
    let t = text.trim();
    match t.to_ascii_lowercase().as_str() {
        ".nan" => Some(f64::NAN),
        ".inf" | "+.inf" => Some(f64::INFINITY),
        "-.inf" => Some(f64::NEG_INFINITY),
        _ => parse_number(t, decimal_commas),
    }
}

/// Reads one profile file, by its extension: `.yml`/`.yaml` as OpenCV
/// YAML, `.json` as OpenCV JSON, anything else as CSV/TXT.
///
/// # Errors
/// An unreadable file, or content that is not a profile (naming the file
/// and the line or key).
pub fn read_profile(path: &Path, format: &ProfileFormat) -> Result<RawProfile, ImportError> {
    let text = read_text(path, Cap::TABLE).map_err(|source| ImportError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "yml" | "yaml" => opencv::read_yaml(&text, path, format),
        "json" => opencv::read_json(&text, path, format),
        _ => text::read_text_profile(&text, path, format),
    }
}

/// Profile files of a folder, in natural order of their names (digit runs
/// compared as numbers: `p2` before `p10`).
///
/// # Errors
/// The folder cannot be read.
pub fn profile_files(dir: &Path) -> Result<Vec<PathBuf>, ImportError> {
    let entries = fs::read_dir(dir).map_err(|source| ImportError::Io {
        path: dir.to_path_buf(),
        source,
    })?;
    let mut files: Vec<PathBuf> = entries
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| {
            p.is_file()
                && p.extension().is_some_and(|e| {
                    PROFILE_EXTENSIONS.contains(&e.to_string_lossy().to_ascii_lowercase().as_str())
                })
        })
        .collect();
    files.sort_by_key(|p| natural_key(p));
    Ok(files)
}

/// A name split into text and number runs, for natural ordering.
fn natural_key(path: &Path) -> Vec<(String, u128)> {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut out = Vec::new();
    let mut text = String::new();
    let mut digits = String::new();
    for c in name.chars() {
        if c.is_ascii_digit() {
            digits.push(c);
        } else {
            if !digits.is_empty() {
                out.push((
                    std::mem::take(&mut text),
                    digits.parse().unwrap_or(u128::MAX),
                ));
                digits.clear();
            }
            text.push(c);
        }
    }
    out.push((text, digits.parse().unwrap_or(0)));
    out
}

/// The profile file of pose `id` in `dir`: `<id>.<ext>` for the first of
/// [`PROFILE_EXTENSIONS`] present.
#[must_use]
pub fn file_of(dir: &Path, id: &str) -> Option<PathBuf> {
    PROFILE_EXTENSIONS
        .iter()
        .map(|ext| dir.join(format!("{id}.{ext}")))
        .find(|p| p.is_file())
}

/// Every pose's profile of one CSV with a pose column: points by pose id,
/// in file order, and the pose ids in order of first appearance.
///
/// # Errors
/// Unreadable file, missing columns, a cell that is not a number.
pub fn read_profile_table(
    path: &Path,
    pose_column: &str,
    format: &ProfileFormat,
) -> Result<(Vec<String>, HashMap<String, RawProfile>), ImportError> {
    let text = read_text(path, Cap::TABLE).map_err(|source| ImportError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let mut order: Vec<String> = Vec::new();
    let mut collectors: HashMap<String, Collector> = HashMap::new();
    let mut columns: Option<(usize, [Option<usize>; 3])> = None;
    let csv = CsvFile::stream(&text, path, |csv, line, row| {
        let (pose, columns) = match columns {
            Some(c) => c,
            None => *columns.insert((csv.column(pose_column)?, text::xyz_columns(csv)?)),
        };
        let id = row.get(pose).unwrap_or("");
        let p = text::xyz_of(csv, line, row, &columns)?;
        let pushed = if let Some(c) = collectors.get_mut(id) {
            c.push(p)
        } else {
            order.push(id.to_string());
            let mut c = Collector::new(format);
            let pushed = c.push(p);
            collectors.insert(id.to_string(), c);
            pushed
        };
        pushed.map_err(|message| ImportError::Csv {
            path: path.to_path_buf(),
            line,
            message,
        })
    })?;
    if columns.is_none() {
        csv.column(pose_column)?;
        text::xyz_columns(&csv)?;
    }
    let profiles = collectors
        .into_iter()
        .map(|(id, c)| (id, c.finish(path)))
        .collect();
    Ok((order, profiles))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axis_maps_parse_and_refuse_mirrors() {
        let m = AxisMap::parse("-y,x,z").unwrap();
        assert_eq!(m.to_string(), "-y,x,z");
        assert_eq!(m.apply([1.0, 2.0, 3.0]), [-2.0, 1.0, 3.0]);
        assert!((m.rotation().determinant() - 1.0).abs() < 1e-12);
        let e = AxisMap::parse("y,x,z").unwrap_err().to_string();
        assert!(e.contains("mirrors") && e.contains("-y,x,z"), "{e}");
        assert!(
            AxisMap::parse("x,x,z")
                .unwrap_err()
                .to_string()
                .contains("twice")
        );
        assert!(AxisMap::parse("x,y").is_err());
        assert_eq!(AxisMap::parse("X,+Y,z").unwrap(), AxisMap::IDENTITY);
    }

    fn raw(points: Vec<[f64; 3]>) -> RawProfile {
        RawProfile {
            source: PathBuf::from("p.yml"),
            points,
            non_finite: 0,
            no_return: 0,
        }
    }

    #[test]
    fn the_constant_axis_is_the_normal() {
        let p = raw(vec![[1.0, 0.0, 2.0], [3.0, 0.0, -1.0]]);
        let m = AxisMap::guess(std::slice::from_ref(&p)).unwrap();
        assert_eq!(m.to_string(), "-y,x,z");
        let plane = p.to_plane(&m).unwrap();
        assert_eq!(plane.points, [[1.0, 2.0], [3.0, -1.0]]);
        let flat = raw(vec![[0.0, 1.0, 2.0], [0.0, 3.0, 4.0]]);
        assert_eq!(AxisMap::guess(&[flat]).unwrap(), AxisMap::IDENTITY);
        let off = raw(vec![[1.0, 5.0, 2.0], [3.0, 5.0, -1.0]]);
        assert!(
            AxisMap::guess(&[off])
                .unwrap_err()
                .to_string()
                .contains("y = 5")
        );
        let cloud = raw(vec![[1.0, 5.0, 2.0], [3.0, 4.0, -1.0]]);
        assert!(
            AxisMap::guess(&[cloud])
                .unwrap_err()
                .to_string()
                .contains("--axes")
        );
    }

    #[test]
    fn opencv_yaml_lists_and_matrices_are_read() {
        let format = ProfileFormat {
            no_return: Some(-99999.0),
            ..ProfileFormat::default()
        };
        let text = "%YAML:1.0\n---\nscan_line: [ 1.5, 0., -2.0e+00, 1.6, 0.,\n    .nan, 1.7, 0., -99999., 1.8,\n    0., 2. ]\n";
        let p = opencv::read_yaml(text, Path::new("p.yml"), &format).unwrap();
        assert_eq!(p.points, [[1.5, 0.0, -2.0], [1.8, 0.0, 2.0]]);
        assert_eq!((p.non_finite, p.no_return), (1, 1));
        let m = "%YAML:1.0\nprofile: !!opencv-matrix\n   rows: 2\n   cols: 2\n   dt: d\n   data: [ 1., 2., 3.,\n       4. ]\n";
        let p = opencv::read_yaml(m, Path::new("m.yml"), &ProfileFormat::default()).unwrap();
        assert_eq!(p.points, [[0.0, 1.0, 2.0], [0.0, 3.0, 4.0]]);
        let e = opencv::read_yaml(
            "a: [1, 2, x]\n",
            Path::new("e.yml"),
            &ProfileFormat::default(),
        )
        .unwrap_err();
        assert!(e.to_string().contains("`x` is not a number"), "{e}");
        let e = opencv::read_yaml("a: [1, 2\n", Path::new("e.yml"), &ProfileFormat::default())
            .unwrap_err();
        assert!(e.to_string().contains("never closed"), "{e}");
    }

    #[test]
    fn json_and_text_profiles_are_read() {
        let f = ProfileFormat::default();
        let p = opencv::read_json(
            r#"{"scan_line": [1, 0, 2, 3, 0, 4]}"#,
            Path::new("p.json"),
            &f,
        )
        .unwrap();
        assert_eq!(p.points, [[1.0, 0.0, 2.0], [3.0, 0.0, 4.0]]);
        let p =
            opencv::read_json(r#"{"pts": [[1, 2], [3, null]]}"#, Path::new("q.json"), &f).unwrap();
        assert_eq!((p.points.len(), p.non_finite), (1, 1));
        let p = text::read_text_profile("x;z\n1;2\n3;nan\n", Path::new("a.csv"), &f).unwrap();
        assert_eq!((p.points.clone(), p.non_finite), (vec![[1.0, 0.0, 2.0]], 1));
        let p = text::read_text_profile("1 2\n3\t4\n", Path::new("a.txt"), &f).unwrap();
        assert_eq!(p.points, [[0.0, 1.0, 2.0], [0.0, 3.0, 4.0]]);
        let e = text::read_text_profile("1 2\n3 4 5\n", Path::new("a.txt"), &f).unwrap_err();
        assert!(e.to_string().contains("line 2"), "{e}");
        let um = ProfileFormat {
            unit: LengthUnit::Um,
            ..ProfileFormat::default()
        };
        let p = text::read_text_profile("y,z\n1000,2000\n", Path::new("b.csv"), &um).unwrap();
        assert_eq!(p.points, [[0.0, 1.0, 2.0]]);
    }

    #[test]
    fn files_sort_naturally() {
        let mut v = [
            PathBuf::from("p10.yml"),
            PathBuf::from("p2.yml"),
            PathBuf::from("p1.yml"),
        ];
        v.sort_by_key(|p| natural_key(p));
        assert_eq!(v[0], PathBuf::from("p1.yml"));
        assert_eq!(v[2], PathBuf::from("p10.yml"));
    }
}
