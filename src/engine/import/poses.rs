//! Flange-pose logs: the flange poses a controller reports (no joint
//! readings) plus one profile a pose become a **pose-only** session
//! (FORMAT.md "Additions to version 1": `measurements[].flange`). Such a
//! session calibrates the hand-eye and the station centres; no kinematic
//! parameter can be identified from it.
//!
//! # Pose logs
//!
//! - JSON (`.json`, RobCalibrator's `.rob`): a list of poses, top level or
//!   under a key (`RobPoses`, or the only list), each a list of the
//!   convention's numbers (a matrix also as 4 rows of 4).
//! - CSV: the convention's columns ([`FlangeConvention::default_columns`]
//!   or as named), and optionally `id`, `station`, `use`, `side`.
//!
//! Poses without ids are paired with the profile files of the folder in
//! the natural order of the file names (`p1`, `p2`, …, `p10`), and take
//! their ids from the file names; poses with ids find `<id>.<ext>`.
//!
//! # What the import decides, and says
//!
//! - **Stations**: the log's `station` column, else one station `S1` (one
//!   fixed sphere).
//! - **Uses**: the log's `use` column; else the initial hand-eye is made
//!   here, by the paper's eq. 6-9 on the flange poses: the poses sharing
//!   the most common orientation (within [`SAME_ORIENTATION_DEG`]) form the
//!   translation group, the others the rotation group. The session then
//!   holds that hand-eye as its `hand_eye` and every pose as `identify`,
//!   so that all of them serve the calibration.
//! - **Side**: the log's `side` column, or the side given; or, with
//!   [`SideChoice::Auto`], both sides are calibrated and the one with the
//!   clearly smaller scatter (ε at least [`SIDE_EVIDENCE_RATIO`] times
//!   smaller) is chosen; when the data cannot tell, the import refuses and
//!   says why.

use std::collections::HashMap;
use std::fs;
use std::path::{Path, PathBuf};

use nalgebra::Isometry3;
use serde_json::Value;

use super::csv_file::CsvFile;
use super::profiles::{self, PlaneProfile, ProfileFormat, ProfileSource};
use super::{FlangeConvention, ImportError, Imported, ProfileReport, RobotSource, load_robot, log};
use crate::engine::robot::Robot;
use crate::engine::session::{Measurement, Observation, Session, Use};
use crate::engine::solve::{self, Options};

/// Largest orientation difference (deg) between poses counted as "the
/// same orientation" when the translation group is found: controllers
/// report a kept orientation to a few thousandths of a degree.
pub const SAME_ORIENTATION_DEG: f64 = 0.1;

/// How many times smaller the scatter ε of one side must be than the
/// other's for [`SideChoice::Auto`] to choose it.
pub const SIDE_EVIDENCE_RATIO: f64 = 1.5;

/// The station of a log without a `station` column.
pub const DEFAULT_STATION: &str = "S1";

/// On which side of the laser plane the sphere centres lie.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SideChoice {
    /// `x > 0` in the sensor frame (FORMAT.md `side` +1).
    Plus,
    /// `x < 0` (side −1).
    Minus,
    /// Decided from the data: both are calibrated, the clearly better
    /// one is chosen.
    Auto,
}

impl SideChoice {
    /// Parses `+1`/`1`/`plus`, `-1`/`minus` or `auto`.
    #[must_use]
    pub fn parse(s: &str) -> Option<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "+1" | "1" | "plus" => Some(Self::Plus),
            "-1" | "minus" => Some(Self::Minus),
            "auto" => Some(Self::Auto),
            _ => None,
        }
    }
}

/// Everything the import of a flange-pose log needs.
#[derive(Debug, Clone, PartialEq)]
pub struct PoseImportSpec {
    /// The pose log (JSON, `.rob` or CSV).
    pub poses: PathBuf,
    /// How the controller writes a pose.
    pub convention: FlangeConvention,
    /// The pose columns of a CSV log, in the convention's order; `None`:
    /// [`FlangeConvention::default_columns`].
    pub pose_columns: Option<Vec<String>>,
    /// The stripe profiles.
    pub profiles: ProfileSource,
    /// How to read the profiles.
    pub profile_format: ProfileFormat,
    /// A robot model to keep in the session (not needed: none is
    /// identified).
    pub robot: Option<RobotSource>,
    /// Sphere diameter, mm.
    pub sphere_diameter: f64,
    /// Side of the sphere centres when the log has no `side` column.
    pub side: SideChoice,
    /// Session name; `None` gives the pose log's file stem.
    pub name: Option<String>,
    /// Optional reference distances between validate stations.
    pub references: Option<PathBuf>,
}

/// One pose of a log.
#[derive(Debug, Clone, PartialEq)]
pub struct PoseRecord {
    /// Its id, when the log has an id column.
    pub id: Option<String>,
    /// Its station, when the log has a station column.
    pub station: Option<String>,
    /// Its use, when the log has a use column.
    pub usage: Option<Use>,
    /// Its side, when the log has a side column with a value.
    pub side: Option<i8>,
    /// The flange pose `bT_e`, mm.
    pub pose: Isometry3<f64>,
    /// Where it is, for messages: "line 12" or "pose 3".
    pub at: String,
}

/// Reads a pose log: JSON (`.json`, `.rob`) or CSV, by extension.
///
/// # Errors
/// An unreadable file, a pose with the wrong count of numbers or not a
/// rigid transform (naming the file and the line or pose), an empty log.
pub fn read_pose_log(
    path: &Path,
    convention: FlangeConvention,
    columns: Option<&[String]>,
) -> Result<Vec<PoseRecord>, ImportError> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let records = if ext == "json" || ext == "rob" {
        let text = fs::read_to_string(path).map_err(|source| ImportError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        json_poses(&text, path, convention)?
    } else {
        csv_poses(path, convention, columns)?
    };
    if records.is_empty() {
        return Err(ImportError::File {
            path: path.to_path_buf(),
            message: "the pose log has no poses".into(),
        });
    }
    Ok(records)
}

/// The poses of a JSON log.
fn json_poses(
    text: &str,
    path: &Path,
    convention: FlangeConvention,
) -> Result<Vec<PoseRecord>, ImportError> {
    let value = super::json_value(text, path)?;
    let file_error = |message: String| ImportError::File {
        path: path.to_path_buf(),
        message,
    };
    let list = match &value {
        Value::Array(items) => items,
        Value::Object(map) => {
            let arrays: Vec<(&String, &Vec<Value>)> = map
                .iter()
                .filter_map(|(k, v)| v.as_array().map(|a| (k, a)))
                .collect();
            let chosen = arrays
                .iter()
                .find(|(k, _)| {
                    k.eq_ignore_ascii_case("RobPoses") || k.eq_ignore_ascii_case("poses")
                })
                .or_else(|| (arrays.len() == 1).then(|| &arrays[0]));
            match chosen {
                Some((_, a)) => *a,
                None => {
                    let keys: Vec<&str> = map.keys().map(String::as_str).collect();
                    return Err(file_error(format!(
                        "no pose list: expected a key `RobPoses` or `poses`, or one list (the file has: {})",
                        keys.join(", ")
                    )));
                }
            }
        }
        _ => return Err(file_error("expected a JSON list of poses".into())),
    };
    list.iter()
        .enumerate()
        .map(|(i, item)| {
            let at = format!("pose {}", i + 1);
            let values = flat_numbers(item).ok_or_else(|| {
                file_error(format!(
                    "{at}: not a list of numbers ({})",
                    convention.describe()
                ))
            })?;
            let pose = convention
                .pose_from_values(&values)
                .map_err(|m| file_error(format!("{at}: {m} ({})", convention.describe())))?;
            Ok(PoseRecord {
                id: None,
                station: None,
                usage: None,
                side: None,
                pose,
                at,
            })
        })
        .collect()
}

/// The numbers of a JSON pose: a list of numbers, or a list of rows.
fn flat_numbers(v: &Value) -> Option<Vec<f64>> {
    let items = v.as_array()?;
    let mut out = Vec::new();
    for x in items {
        match x {
            Value::Number(n) => out.push(n.as_f64()?),
            Value::Array(_) => out.extend(flat_numbers(x)?),
            _ => return None,
        }
    }
    Some(out)
}

/// The poses of a CSV log.
fn csv_poses(
    path: &Path,
    convention: FlangeConvention,
    columns: Option<&[String]>,
) -> Result<Vec<PoseRecord>, ImportError> {
    let csv = CsvFile::read(path)?;
    let names = columns.map_or_else(|| convention.default_columns(), <[String]>::to_vec);
    if names.len() != convention.n_columns() {
        return Err(ImportError::Spec(format!(
            "{} pose columns given, {} needs {}",
            names.len(),
            convention.describe(),
            convention.n_columns()
        )));
    }
    let pose_cols: Vec<usize> = names
        .iter()
        .map(|n| csv.column(n))
        .collect::<Result<_, _>>()?;
    let id = csv.optional_column("id");
    let station = csv.optional_column("station");
    let usage = csv.optional_column("use");
    let side = csv.optional_column(log::DEFAULT_SIDE_COLUMN);
    let mut out = Vec::with_capacity(csv.rows.len());
    for (line, row) in &csv.rows {
        let fail = |message: String| ImportError::Csv {
            path: path.to_path_buf(),
            line: *line,
            message,
        };
        let values: Vec<f64> = pose_cols
            .iter()
            .map(|&c| csv.number(*line, row, c))
            .collect::<Result<_, _>>()?;
        let pose = convention
            .pose_from_values(&values)
            .map_err(|m| fail(format!("flange pose: {m} ({})", convention.describe())))?;
        let usage = match usage {
            Some(c) => Some(Use::parse(&row[c]).ok_or_else(|| {
                fail(format!(
                    "column `use`: `{}` is not translation, rotation, identify or validate",
                    row[c]
                ))
            })?),
            None => None,
        };
        let side = match side {
            Some(c) => log::side_cell(&row[c]).map_err(|m| fail(format!("column `side`: {m}")))?,
            None => None,
        };
        out.push(PoseRecord {
            id: id.map(|c| row[c].clone()),
            station: station.map(|c| row[c].clone()),
            usage,
            side,
            pose,
            at: format!("line {line}"),
        });
    }
    Ok(out)
}

/// Pose ids and their profiles: by id when the log has ids, else the
/// profile files in natural order.
fn pair_profiles(
    spec: &PoseImportSpec,
    records: &[PoseRecord],
) -> Result<(Vec<String>, Vec<PlaneProfile>, ProfileReport), ImportError> {
    let with_ids = records.iter().all(|r| r.id.is_some());
    if with_ids {
        let ids: Vec<String> = records.iter().filter_map(|r| r.id.clone()).collect();
        let mut first: HashMap<&str, &str> = HashMap::new();
        for (r, id) in records.iter().zip(&ids) {
            if let Some(at) = first.insert(id, &r.at) {
                return Err(ImportError::File {
                    path: spec.poses.clone(),
                    message: format!("{}: pose id `{id}` is used twice (first at {at})", r.at),
                });
            }
        }
        let (planes, report) = super::read_profiles(&spec.profiles, &spec.profile_format, &ids)?;
        return Ok((ids, planes, report));
    }
    let raws = match &spec.profiles {
        ProfileSource::Folder(dir) => profiles::profile_files(dir)?
            .iter()
            .map(|p| profiles::read_profile(p, &spec.profile_format))
            .collect::<Result<Vec<_>, _>>()?,
        ProfileSource::File { path, pose_column } => {
            let (order, mut by_id) =
                profiles::read_profile_table(path, pose_column, &spec.profile_format)?;
            order.iter().filter_map(|id| by_id.remove(id)).collect()
        }
    };
    if raws.len() != records.len() {
        let where_ = match &spec.profiles {
            ProfileSource::Folder(dir) => dir.clone(),
            ProfileSource::File { path, .. } => path.clone(),
        };
        return Err(ImportError::File {
            path: where_,
            message: format!(
                "{} profiles for {} poses of {}: a log without ids pairs pose k with the k-th profile file (natural order of names), so the counts must match",
                raws.len(),
                records.len(),
                spec.poses.display()
            ),
        });
    }
    let ids: Vec<String> = raws
        .iter()
        .map(|r| {
            r.source
                .file_stem()
                .map_or_else(|| "pose".into(), |s| s.to_string_lossy().into_owned())
        })
        .collect();
    let (planes, report) = super::planar(raws, &spec.profile_format, &ids)?;
    Ok((ids, planes, report))
}

/// The translation group: the poses sharing the most common orientation
/// (within [`SAME_ORIENTATION_DEG`]), in log order.
fn translation_group(records: &[PoseRecord]) -> Vec<usize> {
    let mut best: Vec<usize> = Vec::new();
    for a in records {
        let group: Vec<usize> = records
            .iter()
            .enumerate()
            .filter(|(_, b)| {
                a.pose.rotation.angle_to(&b.pose.rotation).to_degrees() <= SAME_ORIENTATION_DEG
            })
            .map(|(i, _)| i)
            .collect();
        if group.len() > best.len() {
            best = group;
        }
    }
    best
}

/// The session before the initial hand-eye is settled: every measurement
/// with its use (given, or translation/rotation by orientation) and side.
struct Draft {
    session: Session,
    /// Whether the uses were found by orientation (the import then makes
    /// the initial hand-eye and turns every pose into `identify`).
    auto_uses: bool,
    /// What was decided, in words.
    notes: Vec<String>,
}

fn draft(
    spec: &PoseImportSpec,
    records: &[PoseRecord],
    ids: Vec<String>,
    planes: Vec<PlaneProfile>,
    robot: Option<Robot>,
    side: i8,
) -> Result<Draft, ImportError> {
    super::check_profile_size(&planes, &spec.profile_format, spec.sphere_diameter)?;
    let mut notes = Vec::new();
    let given_uses = records.iter().filter(|r| r.usage.is_some()).count();
    if given_uses != 0 && given_uses != records.len() {
        return Err(ImportError::File {
            path: spec.poses.clone(),
            message: "some poses have a use and some not: give every pose a use, or none".into(),
        });
    }
    let auto_uses = given_uses == 0;
    let mut uses: Vec<Use> = records
        .iter()
        .map(|r| r.usage.unwrap_or(Use::Rotation))
        .collect();
    if auto_uses {
        let group = translation_group(records);
        if group.len() < 3 || records.len() - group.len() < 2 {
            return Err(ImportError::File {
                path: spec.poses.clone(),
                message: format!(
                    "cannot find the initial hand-eye's pose groups: the largest set of poses with one orientation (within {SAME_ORIENTATION_DEG}°) has {} poses and {} others change orientation; eq. 6-9 need at least 3 of the one and 2 of the other (or give a `use` column)",
                    group.len(),
                    records.len() - group.len()
                ),
            });
        }
        for &i in &group {
            uses[i] = Use::Translation;
        }
        let names = |u: Use| -> String {
            ids.iter()
                .zip(&uses)
                .filter(|(_, x)| **x == u)
                .map(|(id, _)| id.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        };
        notes.push(format!(
            "initial hand-eye groups (paper eq. 6-9): translation {} (one orientation), rotation {}",
            names(Use::Translation),
            names(Use::Rotation)
        ));
    }
    let measurements = records
        .iter()
        .zip(ids)
        .zip(planes)
        .zip(&uses)
        .map(|(((r, id), plane), &usage)| Measurement {
            id,
            station: r
                .station
                .clone()
                .unwrap_or_else(|| DEFAULT_STATION.to_string()),
            usage,
            side_given: r.side,
            side: r.side.unwrap_or(side),
            joints: Vec::new(),
            flange: Some(r.pose),
            observation: Observation::Stripe(plane.points),
        })
        .collect();
    let name = spec.name.clone().unwrap_or_else(|| {
        spec.poses
            .file_stem()
            .map_or_else(|| "imported".into(), |s| s.to_string_lossy().into_owned())
    });
    let session = super::new_session(
        name,
        robot,
        spec.sphere_diameter,
        Some(side),
        spec.references.as_deref(),
        measurements,
    )?;
    Ok(Draft {
        session,
        auto_uses,
        notes,
    })
}

/// With uses found by orientation: the initial hand-eye by eq. 6-9 on the
/// draft, written into the session, and every pose turned `identify`.
fn settle_hand_eye(mut draft: Draft, path: &Path) -> Result<Draft, ImportError> {
    if !draft.auto_uses {
        return Ok(draft);
    }
    let analysis = solve::analyse(&draft.session);
    let (hand_eye, _) = analysis.hand_eye.map_err(|e| ImportError::File {
        path: path.to_path_buf(),
        message: format!("the initial hand-eye (paper eq. 6-9 on the flange poses) failed: {e}"),
    })?;
    draft.session.hand_eye = Some(hand_eye);
    for m in &mut draft.session.measurements {
        m.usage = Use::Identify;
    }
    let t = hand_eye.translation.vector;
    draft.notes.push(format!(
        "initial hand-eye written to the session (translation [{:.2}, {:.2}, {:.2}] mm); every pose is `identify`",
        t.x, t.y, t.z
    ));
    Ok(draft)
}

/// The side with the clearly smaller scatter, or why none can be told.
fn decide_side(
    spec: &PoseImportSpec,
    records: &[PoseRecord],
    ids: &[String],
    planes: &[PlaneProfile],
    robot: Option<&Robot>,
) -> Result<(Draft, String), ImportError> {
    let mut tried = Vec::new();
    for side in [1_i8, -1] {
        let d = draft(
            spec,
            records,
            ids.to_vec(),
            planes.to_vec(),
            robot.cloned(),
            side,
        )
        .and_then(|d| settle_hand_eye(d, &spec.poses));
        let epsilon = d.as_ref().ok().and_then(|d| {
            let options = Options::from_session(&d.session);
            solve::calibrate(&d.session, &options)
                .ok()
                .map(|(_, cal)| cal.epsilon_after())
        });
        tried.push((side, d, epsilon));
    }
    let text =
        |e: Option<f64>| e.map_or_else(|| "no calibration".to_string(), |v| format!("ε {v:.3} mm"));
    let evidence = format!(
        "side +1: {}, side −1: {}",
        text(tried[0].2),
        text(tried[1].2)
    );
    let (plus, minus) = (tried[0].2, tried[1].2);
    let choice = match (plus, minus) {
        (Some(p), Some(m)) if m * SIDE_EVIDENCE_RATIO <= p => Some(1),
        (Some(p), Some(m)) if p * SIDE_EVIDENCE_RATIO <= m => Some(0),
        (Some(_), None) => Some(0),
        (None, Some(_)) => Some(1),
        _ => None,
    };
    let Some(k) = choice else {
        return Err(ImportError::File {
            path: spec.poses.clone(),
            message: format!(
                "cannot tell from the data on which side of the laser plane the sphere lies ({evidence}; one must be {SIDE_EVIDENCE_RATIO}× smaller): give the side (--side +1 or --side -1)"
            ),
        });
    };
    let (side, d, _) = tried.swap_remove(k);
    let d = d?;
    Ok((
        d,
        format!(
            "side {} chosen from the data ({evidence})",
            if side > 0 { "+1" } else { "−1" }
        ),
    ))
}

/// Builds the pose-only session of a flange-pose log.
///
/// # Errors
/// [`ImportError`] naming the file and the line, pose or key: unreadable
/// files, poses that are not rigid transforms, missing or unusable
/// profiles, pose groups that cannot give the initial hand-eye, a side the
/// data cannot tell.
pub fn import_poses(spec: &PoseImportSpec) -> Result<Imported, ImportError> {
    super::check_sphere_diameter(spec.sphere_diameter)?;
    let records = read_pose_log(&spec.poses, spec.convention, spec.pose_columns.as_deref())?;
    let robot = spec.robot.as_ref().map(load_robot).transpose()?;
    let (ids, planes, report) = pair_profiles(spec, &records)?;
    let all_sides_given = records.iter().all(|r| r.side.is_some());
    let (draft, side_note) = match spec.side {
        SideChoice::Auto if !all_sides_given => {
            let (d, note) = decide_side(spec, &records, &ids, &planes, robot.as_ref())?;
            (d, Some(note))
        }
        choice => {
            let side = if choice == SideChoice::Minus { -1 } else { 1 };
            let d = draft(spec, &records, ids, planes, robot, side)?;
            (settle_hand_eye(d, &spec.poses)?, None)
        }
    };
    let mut notes = vec![report.summary()];
    notes.push(format!(
        "{} flange poses ({}), pose-only: only the hand-eye and the station centres are calibrated, no kinematic parameter",
        records.len(),
        spec.convention.describe()
    ));
    notes.extend(draft.notes);
    notes.extend(side_note);
    let lines: HashMap<&str, usize> = records
        .iter()
        .filter_map(|r| {
            let line = r.at.strip_prefix("line ")?.parse().ok()?;
            Some((r.id.as_deref()?, line))
        })
        .collect();
    let session = super::recheck(
        &draft.session,
        &super::Sources {
            log: &spec.poses,
            lines: &lines,
            profiles: &report,
            references: spec.references.as_deref(),
        },
    )?;
    Ok(Imported {
        session,
        checks: Vec::new(),
        profiles: report,
        notes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn robcalibrator_style_json_is_read() {
        let text = r#"{ "RobPoses": [ [ -195.8, 1363.305, 524.812, -179.924, 0.889, 179.635 ],
            [ -185.745, 1363.314, 524.772, -179.923, 0.889, 179.636 ] ] }"#;
        let poses =
            json_poses(text, Path::new("RobPoses.rob"), FlangeConvention::FanucWpr).unwrap();
        assert_eq!(poses.len(), 2);
        assert!((poses[0].pose.translation.vector.x + 195.8).abs() < 1e-12);
        let e = json_poses(
            r#"{"RobPoses": [[1, 2, 3, 4, 5]]}"#,
            Path::new("bad.rob"),
            FlangeConvention::FanucWpr,
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("pose 1") && e.contains("5 values"), "{e}");
    }

    #[test]
    fn sides_parse() {
        assert_eq!(SideChoice::parse("+1"), Some(SideChoice::Plus));
        assert_eq!(SideChoice::parse("-1"), Some(SideChoice::Minus));
        assert_eq!(SideChoice::parse("AUTO"), Some(SideChoice::Auto));
        assert_eq!(SideChoice::parse("2"), None);
    }
}
