//! What the import of a pose file will do, told before it reads a
//! profile: the pose file's layout (detected or forced) and the order of
//! its poses, what its reader noticed (a non-zero user frame, positions
//! never moved to), which pose goes with which profile file or centre
//! row, what is left over on either side, the files of the folder
//! skipped and why, and whether the paper's eq. 6-9 can give the initial
//! hand-eye. The pairing is the import's own ([`pairing`](crate::engine::files::import::pairing),
//! [`paired_by_id`](crate::engine::files::import::poses::paired_by_id)); nothing is decided here that the
//! import decides otherwise.
//!
//! Cheap on a folder of thousands of profiles: the pose file is read and
//! the folder listed, no profile is read (a single profile file with a
//! pose column and a centres table are read, being one file each). The
//! workbench runs it on a background job when the pose file is chosen.

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

use nalgebra::Isometry3;

use super::initial::eq69_group;
use crate::engine::files::import::pairing::list_profiles;
use crate::engine::files::import::poses::{
    NUMBERS_DIFFER_WARNING, Observations, PoseImportSpec, PoseRecord, PoseValue, centre_rows,
    numbers_differ, paired_by_id, program_error, records_of,
};
use crate::engine::files::import::profiles::{self, ProfileSource};
use crate::engine::files::import::{ImportError, load_robot};
use crate::engine::files::program::{self, PoseFormat, ReadSpec};

/// The pose file as the import will read it, and the pairing.
#[derive(Debug, Clone, PartialEq)]
pub struct PosePreview {
    /// The pose file.
    pub path: PathBuf,
    /// Its layout.
    pub format: PoseFormat,
    /// Whether the layout was detected from the content (not forced).
    pub detected: bool,
    /// Which order the poses are in, in words (from the reader).
    pub order_note: String,
    /// What the reader noticed, in words (a non-zero UF/UT, positions
    /// never moved to, targets moved to twice).
    pub warnings: Vec<String>,
    /// The poses in the order the robot went to them: name and 1-based
    /// line in the pose file.
    pub poses: Vec<(String, usize)>,
    /// True for joint targets (a session with joints), false for flange
    /// poses (a pose-only session).
    pub joints: bool,
    /// The file gives every pose its use: the import computes no initial
    /// hand-eye.
    pub uses_given: bool,
    /// The pairing with the sensor's observations, or why it cannot be
    /// shown (no profiles chosen, a folder that cannot be read).
    pub pairing: Result<PairingPreview, String>,
    /// The group of one orientation eq. 6-9 start from (indices into
    /// `poses`), or why there is none; `None` when the poses cannot be
    /// placed (joint targets without a robot).
    pub translation_group: Option<Result<Vec<usize>, String>>,
}

impl PosePreview {
    /// One line: "FANUC TP program (.ls), detected from its content: 12
    /// poses in the order …".
    #[must_use]
    pub fn summary(&self) -> String {
        format!(
            "{}, {}: {}",
            self.format.describe(),
            if self.detected {
                "detected from its content"
            } else {
                "as forced"
            },
            self.order_note
        )
    }
}

/// Which pose goes with which observation.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PairingPreview {
    /// How the poses are paired, in words.
    pub how: String,
    /// Each pair: the index of the pose (into [`PosePreview::poses`]) and
    /// its observation (a profile file's name, or a centre row's line).
    pub pairs: Vec<(usize, String)>,
    /// Poses without an observation (indices into [`PosePreview::poses`]).
    pub poses_without: Vec<usize>,
    /// Observations without a pose.
    pub unpaired: Vec<String>,
    /// Files of the profile folder that are not profiles, with why (the
    /// pose file, another tool's output, notes, files named otherwise).
    pub skipped: Vec<(String, String)>,
    /// Why the import will refuse this pairing, when it will.
    pub problem: Option<String>,
    /// Something to check (pose numbers that differ from their profile's).
    pub warning: Option<String>,
}

fn file_name(p: &Path) -> String {
    p.file_name().map_or_else(
        || p.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}

/// Reads the pose file of `spec` and pairs its poses with the
/// observations as the import will, reading no profile. A profile source
/// with an empty path counts as not chosen yet.
///
/// # Errors
/// The pose file cannot be read (naming the file and line): the import
/// would fail the same way. A pairing that cannot be shown is
/// [`PosePreview::pairing`]'s error, not this one.
pub fn preview_pose_import(spec: &PoseImportSpec) -> Result<PosePreview, ImportError> {
    let file = program::read_pose_file(
        &spec.poses,
        &ReadSpec {
            format: spec.format,
            convention: spec.convention,
            columns: spec.pose_columns.clone(),
        },
    )
    .map_err(program_error)?;
    let records = records_of(&file)?;
    let joints = records
        .iter()
        .any(|r| matches!(r.value, PoseValue::Joints(_)));
    let pairing = pairing(spec, &records).map_err(|e| e.to_string());
    let translation_group =
        flange_poses(spec, &records).map(|poses| eq69_group(&poses).map_err(|e| e.to_string()));
    Ok(PosePreview {
        path: spec.poses.clone(),
        format: file.format,
        detected: file.detected,
        order_note: file.order_note.clone(),
        warnings: file.warnings.clone(),
        poses: records.iter().map(|r| (r.name.clone(), r.line)).collect(),
        joints,
        uses_given: !records.is_empty() && records.iter().all(|r| r.usage.is_some()),
        pairing,
        translation_group,
    })
}

/// The flange poses of the records: as given, or joint targets placed by
/// the nominal robot's forward kinematics; `None` when they cannot be.
fn flange_poses(spec: &PoseImportSpec, records: &[PoseRecord]) -> Option<Vec<Isometry3<f64>>> {
    let robot = if records
        .iter()
        .any(|r| matches!(r.value, PoseValue::Joints(_)))
    {
        Some(load_robot(spec.robot.as_ref()?).ok()?)
    } else {
        None
    };
    records
        .iter()
        .map(|r| match &r.value {
            PoseValue::Flange(p) => Some(*p),
            PoseValue::Joints(q) => robot
                .as_ref()
                .filter(|robot| robot.dof() == q.len())
                .map(|robot| robot.base_from_flange(q)),
        })
        .collect()
}

/// Pairs in order: pose `k` with observation `k`; the rest on either side
/// left over.
fn in_order(how: String, records: &[PoseRecord], names: Vec<String>) -> PairingPreview {
    let n = records.len().min(names.len());
    let problem = (records.len() != names.len()).then(|| {
        format!(
            "{} poses and {} observations: pose k goes with the k-th, so the counts must match; the import will refuse",
            records.len(),
            names.len()
        )
    });
    PairingPreview {
        how,
        pairs: names.iter().take(n).cloned().enumerate().collect(),
        poses_without: (n..records.len()).collect(),
        unpaired: names[n..].to_vec(),
        skipped: Vec::new(),
        problem,
        warning: None,
    }
}

/// Pairs by id: each pose with the observation of its id.
fn by_id(how: String, ids: &[String], names: &[(String, String)]) -> PairingPreview {
    let index: HashMap<&str, &str> = names
        .iter()
        .map(|(id, n)| (id.as_str(), n.as_str()))
        .collect();
    let mut pairs = Vec::new();
    let mut poses_without = Vec::new();
    for (k, id) in ids.iter().enumerate() {
        match index.get(id.as_str()) {
            Some(n) => pairs.push((k, (*n).to_string())),
            None => poses_without.push(k),
        }
    }
    let wanted: HashSet<&str> = ids.iter().map(String::as_str).collect();
    let unpaired: Vec<String> = names
        .iter()
        .filter(|(id, _)| !wanted.contains(id.as_str()))
        .map(|(_, n)| n.clone())
        .collect();
    let problem = (!poses_without.is_empty()).then(|| {
        format!(
            "{} poses have no observation of their id; the import will refuse",
            poses_without.len()
        )
    });
    PairingPreview {
        how,
        pairs,
        poses_without,
        unpaired,
        skipped: Vec::new(),
        problem,
        warning: None,
    }
}

/// The pairing the import will make, reading no profile.
fn pairing(spec: &PoseImportSpec, records: &[PoseRecord]) -> Result<PairingPreview, ImportError> {
    match &spec.observations {
        Observations::Centres(path) => {
            if path.as_os_str().is_empty() {
                return Err(ImportError::Spec("no centres file chosen yet".into()));
            }
            let rows = centre_rows(path)?;
            let ids: Option<Vec<String>> = records.iter().map(|r| r.id.clone()).collect();
            let name = |r: &program::Row| format!("centre at line {}", r.line);
            match ids.filter(|_| rows.iter().all(|r| r.id.is_some())) {
                Some(ids) => {
                    let names: Vec<(String, String)> = rows
                        .iter()
                        .map(|r| (r.id.clone().unwrap_or_default(), name(r)))
                        .collect();
                    Ok(by_id(
                        format!("sphere centres of {} by pose id", file_name(path)),
                        &ids,
                        &names,
                    ))
                }
                None => Ok(in_order(
                    format!(
                        "sphere centres of {} in order: pose k with the k-th row",
                        file_name(path)
                    ),
                    records,
                    rows.iter().map(name).collect(),
                )),
            }
        }
        Observations::Profiles(source) => {
            let chosen = match source {
                ProfileSource::Folder(dir) => dir,
                ProfileSource::File { path, .. } => path,
            };
            if chosen.as_os_str().is_empty() {
                return Err(ImportError::Spec("no profiles chosen yet".into()));
            }
            if let Some(ids) = paired_by_id(source, records) {
                let names: Vec<(String, String)> = match source {
                    ProfileSource::Folder(dir) => ids
                        .iter()
                        .filter_map(|id| {
                            profiles::file_of(dir, id).map(|p| (id.clone(), file_name(&p)))
                        })
                        .collect(),
                    ProfileSource::File { path, pose_column } => {
                        let (order, _) =
                            profiles::read_profile_table(path, pose_column, &spec.profile_format)?;
                        order
                            .into_iter()
                            .map(|id| {
                                let n = format!("{} `{pose_column}` {id}", file_name(path));
                                (id, n)
                            })
                            .collect()
                    }
                };
                return Ok(by_id(
                    "profiles by pose id (the pose file's ids name them)".into(),
                    &ids,
                    &names,
                ));
            }
            match source {
                ProfileSource::Folder(dir) => {
                    let listing = list_profiles(dir, &[spec.poses.as_path()], Some(records.len()))?;
                    let mut p = in_order(
                        "pose k with the k-th profile in the order of the number in their names"
                            .into(),
                        records,
                        listing.profiles.iter().map(|p| file_name(p)).collect(),
                    );
                    p.skipped = listing
                        .skipped
                        .iter()
                        .map(|(path, why)| (file_name(path), why.clone()))
                        .collect();
                    p.warning = numbers_differ(records, &listing).then(|| {
                        NUMBERS_DIFFER_WARNING
                            .trim_start_matches("; warning: ")
                            .to_string()
                    });
                    Ok(p)
                }
                ProfileSource::File { path, pose_column } => {
                    let (order, _) =
                        profiles::read_profile_table(path, pose_column, &spec.profile_format)?;
                    Ok(in_order(
                        format!(
                            "pose k with the k-th pose of {}'s `{pose_column}` column",
                            file_name(path)
                        ),
                        records,
                        order
                            .into_iter()
                            .map(|id| format!("`{pose_column}` {id}"))
                            .collect(),
                    ))
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::files::import::{FlangeConvention, ProfileFormat, SideChoice};

    fn spec(poses: &Path, observations: Observations) -> PoseImportSpec {
        PoseImportSpec {
            poses: poses.to_path_buf(),
            format: None,
            convention: Some(FlangeConvention::FanucWpr),
            pose_columns: None,
            observations,
            profile_format: ProfileFormat::default(),
            robot: None,
            sphere_diameter: 38.1,
            side: SideChoice::Auto,
            hand_eye: None,
            name: None,
            references: None,
        }
    }

    #[test]
    fn a_folder_with_the_pose_file_in_it_pairs_in_number_order() {
        let dir = tempfile::tempdir().unwrap();
        // Four poses, three turned about x by 10° steps: no group.
        let table = "0 0 500 180 0 0\n10 0 500 170 0 0\n20 0 500 160 0 0\n30 0 500 150 0 0\n";
        let poses = dir.path().join("rob.txt");
        std::fs::write(&poses, table).unwrap();
        for k in [1, 2, 10] {
            std::fs::write(dir.path().join(format!("{k}_3C_line.yml")), "x").unwrap();
        }
        std::fs::write(dir.path().join("calibration.sec"), "{}").unwrap();
        let p = preview_pose_import(&spec(
            &poses,
            Observations::Profiles(ProfileSource::Folder(dir.path().to_path_buf())),
        ))
        .unwrap();
        assert_eq!(p.format, PoseFormat::Table);
        assert!(p.detected && !p.joints && !p.uses_given);
        assert_eq!(p.poses.len(), 4);
        let pairing = p.pairing.unwrap();
        assert_eq!(
            pairing.pairs,
            vec![
                (0, "1_3C_line.yml".to_string()),
                (1, "2_3C_line.yml".to_string()),
                (2, "10_3C_line.yml".to_string())
            ]
        );
        assert_eq!(pairing.poses_without, vec![3]);
        assert!(pairing.unpaired.is_empty());
        assert!(pairing.problem.unwrap().contains("4 poses and 3"));
        let skipped: Vec<&str> = pairing.skipped.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(skipped, ["calibration.sec", "rob.txt"]);
        let group = p.translation_group.unwrap().unwrap_err();
        assert!(group.contains("has 1 poses and 3 others"), "{group}");
        // Not chosen yet: the pose file is still shown.
        let p = preview_pose_import(&spec(
            &poses,
            Observations::Profiles(ProfileSource::Folder(PathBuf::new())),
        ))
        .unwrap();
        assert!(p.pairing.unwrap_err().contains("no profiles chosen"));
    }
}
