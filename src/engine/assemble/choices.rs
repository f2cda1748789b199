//! Every choice of an import in one place, [`ImportChoices`], with its
//! default and its validation: `spherecal import` maps its flags onto it,
//! the workbench's Import form edits it directly, and both turn it into
//! the one entry's [`ImportRequest`] with [`ImportChoices::request`]. The
//! paths are as given (empty: not chosen); a choice that does not apply to
//! the pose log or the mount is ignored.

use std::path::{Path, PathBuf};

use nalgebra::{Isometry3, Translation3};

use super::entry::{ImportRequest, PoseLog};
use crate::engine::base::session::{Mount, SensorRange};
use crate::engine::files::import::tracker::{FixedPoints, FixedPoses, TrackerSpec};
use crate::engine::files::import::{
    AngleUnit, AxisMap, ColumnMap, DEFAULT_POSITION_TOLERANCE_MM, DEFAULT_ROTATION_TOLERANCE_DEG,
    DEFAULT_SPHERE_DIAMETER, FlangeCheck, FlangeConvention, ImportError, ImportSpec, LengthUnit,
    Observations, PoseFormat, PoseImportSpec, ProfileFormat, ProfileSource, RobotSource,
    SideChoice,
};
use crate::engine::files::robot_import::DhConvention;

/// Joint columns of the default mapping (the presets are all 6-axis; a
/// robot with another count is reported by the import).
pub const JOINTS: usize = 6;

/// The pose log an import reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LogKind {
    /// A joint log CSV (id, station, use, joints a row).
    Joints,
    /// A pose file in any layout the engine reads (a table with or
    /// without a header, JSON/`.rob`, FANUC `.ls`, RAPID, KUKA, URScript):
    /// flange poses give a pose-only session.
    FlangePoses,
}

/// Whether the stripe profiles are a folder or one file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProfilesKind {
    /// A folder, one file a pose (`<id>.csv|txt|yml|yaml|json`).
    Folder,
    /// One CSV with a pose column.
    File,
}

/// What the sensor gave for each pose.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ObservationKind {
    /// Stripe profiles (a folder or one file).
    Profiles,
    /// Points the sensor measured itself, one table: sphere centres
    /// beside a pose file (`--centres`, sensor frame, mm), or a fixed
    /// sensor's target points (`--mount fixed --centres`).
    Centres,
}

/// Where the initial hand-eye (`base_from_sensor` for a fixed sensor)
/// comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HandEyeChoice {
    /// Computed by the import or the calibration.
    Computed,
    /// A guess typed in: x y z mm, roll pitch yaw deg.
    Numbers,
    /// A guess from a file, as `spherecal import --hand-eye FILE`: a 4×4
    /// JSON matrix (rows, mm) or a session/result file's `hand_eye`.
    File,
}

/// Every choice of an import (see the module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct ImportChoices {
    /// Where the sensor stands (`--mount`).
    pub mount: Mount,
    /// A joint log or a pose file.
    pub log_kind: LogKind,
    /// The joint log CSV (`--joints`).
    pub joints: PathBuf,
    /// The pose file (`--poses`).
    pub poses: PathBuf,
    /// The pose file's layout forced (`--pose-format`); `None`: detected.
    pub pose_format: Option<PoseFormat>,
    /// How a pose table or JSON list writes a pose (`--pose-convention`);
    /// `None`: as the program's language fixes it.
    pub pose_convention: Option<FlangeConvention>,
    /// A pose table's columns (`--pose-columns`); empty: the convention's.
    pub pose_columns: Vec<String>,
    /// Profiles or points (`--profiles` or `--centres`).
    pub observations: ObservationKind,
    /// Folder or file of the stripe profiles.
    pub profiles: PathBuf,
    /// Whether `profiles` is a folder or one file.
    pub profiles_kind: ProfilesKind,
    /// Pose-id column of a single profile file.
    pub pose_column: String,
    /// Unit of the profile coordinates.
    pub profile_unit: LengthUnit,
    /// Axis map of the profiles: `auto` (or empty) or e.g. `-y,x,z`.
    pub axes: String,
    /// The sensor's no-return value in the profiles' units (empty: none).
    pub no_return: String,
    /// Key of the point list in OpenCV YAML/JSON profiles.
    pub profile_key: Option<String>,
    /// The points table (`--centres`).
    pub centres: PathBuf,
    /// Unit of a fixed sensor's points (`--centre-unit`).
    pub centre_unit: LengthUnit,
    /// Side of the laser plane the centres lie on, without a side column.
    pub side: SideChoice,
    /// The preset of a joint log's robot when `robot` is empty.
    pub robot_preset: String,
    /// The robot given (`--robot`): a preset key, a session/result file,
    /// a URDF or a DH table; empty: the preset for a joint log, none for a
    /// pose file.
    pub robot: String,
    /// The tip link of a URDF robot.
    pub urdf_tip: Option<String>,
    /// The convention of a DH table robot.
    pub dh: Option<DhConvention>,
    /// Unit of the joint columns.
    pub joint_unit: AngleUnit,
    /// Sphere (target) diameter, mm.
    pub sphere_diameter: f64,
    /// The sensor's measuring range `[y0, y1, z0, z1]` mm to write as
    /// `sensor.range`; `None`: not known.
    pub range: Option<[f64; 4]>,
    /// Session name (empty: the pose log's file stem).
    pub name: String,
    /// The joint log's columns.
    pub columns: ColumnMap,
    /// Check the controller's flange poses in this convention.
    pub flange: Option<FlangeConvention>,
    /// The flange-pose columns, comma separated (empty: the convention's).
    pub flange_columns: String,
    /// Position tolerance of the flange check, mm.
    pub tolerance_mm: f64,
    /// Rotation tolerance of the flange check, deg.
    pub tolerance_deg: f64,
    /// Laser-tracker reference distances CSV (`from,to,distance`, mm).
    pub references: PathBuf,
    /// Where the initial hand-eye comes from.
    pub hand_eye: HandEyeChoice,
    /// The typed guess: x y z mm, roll pitch yaw deg.
    pub hand_eye_numbers: [f64; 6],
    /// The guess's file.
    pub hand_eye_file: PathBuf,
}

impl Default for ImportChoices {
    fn default() -> Self {
        Self {
            mount: Mount::Flange,
            log_kind: LogKind::Joints,
            joints: PathBuf::new(),
            poses: PathBuf::new(),
            pose_format: None,
            pose_convention: None,
            pose_columns: Vec::new(),
            observations: ObservationKind::Profiles,
            profiles: PathBuf::new(),
            profiles_kind: ProfilesKind::Folder,
            pose_column: "pose".into(),
            profile_unit: LengthUnit::Mm,
            axes: "auto".into(),
            no_return: String::new(),
            profile_key: None,
            centres: PathBuf::new(),
            centre_unit: LengthUnit::Mm,
            side: SideChoice::Auto,
            robot_preset: "irb2400".into(),
            robot: String::new(),
            urdf_tip: None,
            dh: None,
            joint_unit: AngleUnit::Deg,
            sphere_diameter: DEFAULT_SPHERE_DIAMETER,
            range: None,
            name: String::new(),
            columns: ColumnMap {
                id: "id".into(),
                station: "station".into(),
                usage: "use".into(),
                side: None,
                joints: (1..=JOINTS).map(|k| format!("j{k}")).collect(),
            },
            flange: None,
            flange_columns: String::new(),
            tolerance_mm: DEFAULT_POSITION_TOLERANCE_MM,
            tolerance_deg: DEFAULT_ROTATION_TOLERANCE_DEG,
            references: PathBuf::new(),
            hand_eye: HandEyeChoice::Computed,
            hand_eye_numbers: [0.0; 6],
            hand_eye_file: PathBuf::new(),
        }
    }
}

/// A path as given, trimmed; `None` when empty.
fn given(path: &Path) -> Option<PathBuf> {
    let path = path.to_str().map_or(path, |s| Path::new(s.trim()));
    (!path.as_os_str().is_empty()).then(|| path.to_path_buf())
}

/// `path` given, or the sentence saying to choose `what`.
fn chosen(path: &Path, what: &str) -> Result<PathBuf, ImportError> {
    given(path).ok_or_else(|| ImportError::Spec(format!("choose the {what} first")))
}

/// The sensor's no-return value as written (profile file units): `None`
/// when the text is empty.
///
/// # Errors
/// The sentence to show when the text is not a finite number.
pub fn no_return(text: &str) -> Result<Option<f64>, String> {
    match text.trim() {
        "" => Ok(None),
        text => text
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .map(Some)
            .ok_or_else(|| format!("the no-return value `{text}` is not a number")),
    }
}

impl ImportChoices {
    /// The pose log's file.
    #[must_use]
    pub fn log(&self) -> &Path {
        match self.log_kind {
            LogKind::Joints => &self.joints,
            LogKind::FlangePoses => &self.poses,
        }
    }

    /// The request of the one import entry: the pose log by its kind and
    /// the mount, the measuring range, the hand-eye guess (read from its
    /// file here), the robot of a fixed sensor (loaded here).
    ///
    /// # Errors
    /// A file not chosen, a bad axis map, no-return value, range, robot,
    /// diameter or guess: [`ImportError`] with a sentence for the operator.
    pub fn request(&self) -> Result<ImportRequest, ImportError> {
        crate::engine::files::import::check_sphere_diameter(self.sphere_diameter)?;
        let log = match (self.mount, self.log_kind) {
            (Mount::Fixed, _) => PoseLog::Fixed(self.tracker_spec()?),
            (Mount::Flange, LogKind::Joints) => PoseLog::Joints(self.joint_spec()?),
            (Mount::Flange, LogKind::FlangePoses) => PoseLog::Poses(self.pose_spec(true)?),
        };
        let range = self
            .range
            .map(|[y0, y1, z0, z1]| {
                (y0 < y1 && z0 < z1)
                    .then_some(SensorRange {
                        y: [y0, y1],
                        z: [z0, z1],
                    })
                    .ok_or_else(|| {
                        ImportError::Spec("measuring range: each side needs from < to".into())
                    })
            })
            .transpose()?;
        Ok(ImportRequest {
            log,
            range,
            hand_eye: self.hand_eye_guess()?,
        })
    }

    /// The profiles' source and format; an empty path when none is chosen
    /// unless `needed`.
    fn profile_choices(&self, needed: bool) -> Result<(ProfileSource, ProfileFormat), ImportError> {
        let path = if needed {
            chosen(&self.profiles, "stripe profiles (a folder or one file)")?
        } else {
            given(&self.profiles).unwrap_or_default()
        };
        let source = match self.profiles_kind {
            ProfilesKind::Folder => ProfileSource::Folder(path),
            ProfilesKind::File => ProfileSource::File {
                path,
                pose_column: self.pose_column.trim().to_string(),
            },
        };
        let axes = match self.axes.trim() {
            "" => None,
            text if text.eq_ignore_ascii_case("auto") => None,
            text => {
                Some(AxisMap::parse(text).map_err(|e| ImportError::Spec(format!("axes: {e}")))?)
            }
        };
        let format = ProfileFormat {
            unit: self.profile_unit,
            axes,
            no_return: no_return(&self.no_return).map_err(ImportError::Spec)?,
            key: self.profile_key.clone(),
        };
        Ok((source, format))
    }

    /// The nominal robot given, if any.
    fn robot_given(&self) -> Result<Option<RobotSource>, ImportError> {
        let text = self.robot.trim();
        (!text.is_empty())
            .then(|| RobotSource::from_text(text, self.urdf_tip.clone(), self.dh))
            .transpose()
            .map_err(|e| ImportError::Spec(e.to_string()))
    }

    /// A joint log's nominal robot: the one given, else the preset.
    fn robot_needed(&self) -> Result<RobotSource, ImportError> {
        match (self.robot_given()?, self.robot_preset.trim()) {
            (Some(robot), _) => Ok(robot),
            (None, "") => Err(ImportError::Spec(
                "a joint log needs the nominal robot: a preset key, a session/result file, a URDF or a DH table".into(),
            )),
            (None, preset) => Ok(RobotSource::Preset(preset.to_string())),
        }
    }

    /// The joint log's spec (also what its preview maps the rows with).
    ///
    /// # Errors
    /// No joint log or profiles chosen, tolerances not positive, a bad
    /// axis map or robot.
    pub fn joint_spec(&self) -> Result<ImportSpec, ImportError> {
        let joint_log = chosen(&self.joints, "joint log CSV")?;
        if !(self.tolerance_mm > 0.0 && self.tolerance_deg > 0.0) {
            return Err(ImportError::Spec(
                "the flange-check tolerances must be positive".into(),
            ));
        }
        let (profiles, profile_format) = self.profile_choices(true)?;
        let robot = self.robot_needed()?;
        let flange = self.flange.map(|convention| {
            let mut check = FlangeCheck::new(convention);
            let columns = words(&self.flange_columns);
            if !columns.is_empty() {
                check.columns = columns;
            }
            check.tolerance_mm = self.tolerance_mm;
            check.tolerance_deg = self.tolerance_deg;
            check
        });
        let c = &self.columns;
        let trim = |s: &String| s.trim().to_string();
        Ok(ImportSpec {
            joint_log,
            columns: ColumnMap {
                id: trim(&c.id),
                station: trim(&c.station),
                usage: trim(&c.usage),
                side: c.side.as_ref().map(trim).filter(|s| !s.is_empty()),
                joints: c.joints.iter().map(trim).collect(),
            },
            joint_unit: self.joint_unit,
            profiles,
            profile_format,
            robot,
            sphere_diameter: self.sphere_diameter,
            name: self.name(),
            flange,
            references: given(&self.references),
        })
    }

    /// The session name given.
    fn name(&self) -> Option<String> {
        let name = self.name.trim();
        (!name.is_empty()).then(|| name.to_string())
    }

    /// The pose file's spec; unless `needed`, for its preview (the layout
    /// and the pairing): observations not chosen yet left empty (the
    /// preview says so).
    ///
    /// # Errors
    /// No pose file (or, when `needed`, profiles or centres) chosen, a bad
    /// axis map or robot.
    pub fn pose_spec(&self, needed: bool) -> Result<PoseImportSpec, ImportError> {
        let poses = chosen(&self.poses, "pose file")?;
        let (source, profile_format) = self.profile_choices(needed && !self.centres_read())?;
        let observations = match self.observations {
            ObservationKind::Profiles => Observations::Profiles(source),
            ObservationKind::Centres if needed => {
                Observations::Centres(chosen(&self.centres, "centres file")?)
            }
            ObservationKind::Centres => {
                Observations::Centres(given(&self.centres).unwrap_or_default())
            }
        };
        Ok(PoseImportSpec {
            poses,
            format: self.pose_format,
            convention: self.pose_convention,
            pose_columns: (!self.pose_columns.is_empty()).then(|| self.pose_columns.clone()),
            observations,
            profile_format,
            robot: self.robot_given()?,
            sphere_diameter: self.sphere_diameter,
            side: self.side,
            hand_eye: None,
            name: self.name(),
            references: given(&self.references),
        })
    }

    /// True when the sensor's points are read instead of profiles.
    fn centres_read(&self) -> bool {
        self.observations == ObservationKind::Centres
    }

    /// What the pose file's preview depends on (its spec without the
    /// fields it does not read); `None` when there is nothing to preview
    /// (a joint log, a fixed sensor, no pose file, a bad field).
    #[must_use]
    pub fn pose_scan_key(&self) -> Option<PoseImportSpec> {
        if self.log_kind != LogKind::FlangePoses || self.mount == Mount::Fixed {
            return None;
        }
        let mut spec = self.pose_spec(false).ok()?;
        spec.sphere_diameter = 0.0;
        spec.side = SideChoice::Auto;
        spec.name = None;
        spec.references = None;
        Some(spec)
    }

    /// A fixed sensor's spec: the poses from the joint log or the pose
    /// file, the points table or a fixed line scanner's profiles.
    ///
    /// # Errors
    /// A file not chosen, a robot that does not load.
    pub fn tracker_spec(&self) -> Result<TrackerSpec, ImportError> {
        let (poses, robot) = match self.log_kind {
            LogKind::Joints => {
                let c = &self.columns;
                let poses = FixedPoses::Joints {
                    path: chosen(&self.joints, "joint log CSV")?,
                    id_column: c.id.trim().to_string(),
                    joint_columns: c.joints.iter().map(|j| j.trim().to_string()).collect(),
                    angle_unit: self.joint_unit,
                };
                (poses, Some(self.robot_needed()?))
            }
            LogKind::FlangePoses => {
                let poses = FixedPoses::File {
                    path: chosen(&self.poses, "pose file")?,
                    format: self.pose_format,
                    convention: self.pose_convention,
                    pose_columns: (!self.pose_columns.is_empty())
                        .then(|| self.pose_columns.clone()),
                };
                (poses, self.robot_given()?)
            }
        };
        let points = if self.centres_read() {
            FixedPoints::Table {
                path: chosen(&self.centres, "points table (the fixed sensor's x y z)")?,
                unit: self.centre_unit,
            }
        } else {
            let (source, format) = self.profile_choices(true)?;
            // `auto`: decided from the data (both sides calibrated) unless
            // the log says.
            let side = match self.side {
                SideChoice::Minus => Some(-1),
                SideChoice::Plus => Some(1),
                SideChoice::Auto => None,
            };
            FixedPoints::Profiles {
                source,
                format,
                side,
            }
        };
        let robot = robot
            .map(|r| crate::engine::files::import::load_robot(&r))
            .transpose()?;
        let name = self.name().unwrap_or_else(|| {
            poses
                .path()
                .file_stem()
                .map_or_else(|| "imported".into(), |s| s.to_string_lossy().into_owned())
        });
        Ok(TrackerSpec {
            poses,
            points,
            robot,
            diameter: self.sphere_diameter,
            hand_eye: None,
            name,
        })
    }

    /// The typed guess as a transform (`eT_s`, or `bT_s` for a fixed
    /// sensor): R = Rz(yaw)·Ry(pitch)·Rx(roll).
    ///
    /// # Errors
    /// A number that is not finite.
    pub fn typed_hand_eye(&self) -> Result<Isometry3<f64>, ImportError> {
        let [x, y, z, roll, pitch, yaw] = self.hand_eye_numbers;
        if self.hand_eye_numbers.iter().any(|v| !v.is_finite()) {
            return Err(ImportError::Spec(
                "the hand-eye guess has a number that is not finite".into(),
            ));
        }
        Ok(Isometry3::from_parts(
            Translation3::new(x, y, z),
            crate::engine::base::geometry::rotation_from_rpy_deg([roll, pitch, yaw]),
        ))
    }

    /// The guess the import starts from: typed, or read from its file;
    /// `None`: computed.
    ///
    /// # Errors
    /// No file chosen, or it holds no 4×4 `hand_eye`.
    pub fn hand_eye_guess(&self) -> Result<Option<Isometry3<f64>>, ImportError> {
        match self.hand_eye {
            HandEyeChoice::Computed => Ok(None),
            HandEyeChoice::Numbers => self.typed_hand_eye().map(Some),
            HandEyeChoice::File => {
                let path = chosen(&self.hand_eye_file, "hand-eye guess file")?;
                crate::engine::files::format::read_transform(&path, "hand_eye")
                    .map(Some)
                    .map_err(|e| ImportError::File {
                        message: format!("hand-eye guess: {e}"),
                        path,
                    })
            }
        }
    }

    /// Fills the mapping from a joint log's header where a column's name
    /// is an obvious match (case-insensitive: `id`/`pose`, `station`/
    /// `sphere`, `use`, `side`, `j1`/`a1`/`joint1`…), leaving the other
    /// columns as they are. Returns how many it set.
    pub fn guess_mapping(&mut self, header: &[String]) -> usize {
        let find = |names: &[String]| -> Option<String> {
            header
                .iter()
                .find(|h| names.iter().any(|n| h.eq_ignore_ascii_case(n)))
                .cloned()
        };
        let words = |list: &[&str]| -> Vec<String> { list.iter().map(|s| (*s).into()).collect() };
        let c = &mut self.columns;
        let mut set = 0;
        let mut assign = |field: &mut String, names: &[String]| {
            if let Some(f) = find(names) {
                *field = f;
                set += 1;
            }
        };
        assign(&mut c.id, &words(&["id", "pose", "pose_id", "measurement"]));
        assign(&mut c.station, &words(&["station", "sphere", "station_id"]));
        assign(&mut c.usage, &words(&["use", "usage", "group"]));
        for (k, slot) in (1..).zip(c.joints.iter_mut()) {
            assign(
                slot,
                &["j", "a", "joint", "joint_", "axis"].map(|p| format!("{p}{k}")),
            );
        }
        if let Some(side) = find(&words(&["side"])) {
            c.side = Some(side);
            set += 1;
        }
        set
    }
}

/// The comma-separated names of `text`, trimmed, empty ones dropped.
fn words(text: &str) -> Vec<String> {
    text.split(',')
        .map(|c| c.trim().to_string())
        .filter(|c| !c.is_empty())
        .collect()
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;

    fn spec_error(r: Result<impl std::fmt::Debug, ImportError>) -> String {
        r.unwrap_err().to_string()
    }

    #[test]
    fn mapping_is_guessed_from_a_kuka_style_header() {
        let mut f = ImportChoices::default();
        let header: Vec<String> = ["Pose", "Sphere", "Use", "A1", "A2", "A3", "A4", "A5", "A6"]
            .iter()
            .map(|s| (*s).to_string())
            .collect();
        assert_eq!(f.guess_mapping(&header), 9);
        assert_eq!(f.columns.id, "Pose");
        assert_eq!(f.columns.station, "Sphere");
        assert_eq!(f.columns.joints[5], "A6");
        assert!(f.columns.side.is_none(), "no side column in the header");
    }

    #[test]
    fn a_pose_file_spec_carries_the_layout_centres_and_the_typed_guess() {
        let mut f = ImportChoices {
            log_kind: LogKind::FlangePoses,
            ..ImportChoices::default()
        };
        assert!(spec_error(f.pose_spec(true)).contains("pose file"));
        f.poses = "calib.ls".into();
        assert!(spec_error(f.pose_spec(true)).contains("profiles"));
        // The preview needs only the pose file.
        let p = f.pose_spec(false).unwrap();
        assert_eq!(p.convention, None, "a program's language fixes it");
        f.observations = ObservationKind::Centres;
        assert!(spec_error(f.pose_spec(true)).contains("centres"));
        f.centres = "centres.txt".into();
        f.pose_format = Some(PoseFormat::FanucLs);
        f.hand_eye = HandEyeChoice::Numbers;
        f.hand_eye_numbers = [10.0, -20.0, 150.0, 0.0, 0.0, 90.0];
        let r = f.request().unwrap();
        let PoseLog::Poses(s) = &r.log else {
            panic!("{:?}", r.log)
        };
        assert_eq!(s.format, Some(PoseFormat::FanucLs));
        assert_eq!(s.observations, Observations::Centres("centres.txt".into()));
        let he = r.hand_eye.unwrap();
        assert_eq!(
            he.translation.vector,
            nalgebra::Vector3::new(10.0, -20.0, 150.0)
        );
        // yaw 90°: the sensor's x is the flange's y.
        let x = he.rotation * nalgebra::Vector3::x();
        assert!((x - nalgebra::Vector3::y()).norm() < 1e-12, "{x}");
        f.hand_eye = HandEyeChoice::File;
        assert!(spec_error(f.request()).contains("hand-eye guess file"));
    }

    #[test]
    fn spec_needs_the_files_and_carries_the_choices() {
        let mut f = ImportChoices::default();
        assert!(spec_error(f.joint_spec()).contains("joint log"));
        f.joints = "log.csv".into();
        assert!(spec_error(f.joint_spec()).contains("profiles"));
        f.profiles = "p.csv".into();
        f.profiles_kind = ProfilesKind::File;
        f.columns.side = Some("side".into());
        f.flange = Some(FlangeConvention::KukaAbc);
        f.references = " refs.csv ".into();
        let s = f.joint_spec().unwrap();
        assert_eq!(s.columns.side.as_deref(), Some("side"));
        assert_eq!(s.flange.unwrap().columns.len(), 6);
        assert_eq!(s.references, Some(PathBuf::from("refs.csv")));
        assert!(matches!(s.profiles, ProfileSource::File { .. }));
        f.sphere_diameter = 0.0;
        assert!(spec_error(f.request()).contains("diameter"));
        f.sphere_diameter = DEFAULT_SPHERE_DIAMETER;
        f.range = Some([40.0, -40.0, -40.0, 40.0]);
        assert!(spec_error(f.request()).contains("from < to"));
        f.no_return = "x".into();
        assert!(spec_error(f.joint_spec()).contains("no-return"));
    }

    #[test]
    fn a_fixed_sensor_reads_its_points_beside_the_joint_log() {
        let mut f = ImportChoices {
            mount: Mount::Fixed,
            joints: "joints.csv".into(),
            ..ImportChoices::default()
        };
        // Profiles by default: a fixed line scanner's.
        assert!(spec_error(f.tracker_spec()).contains("profiles"));
        f.observations = ObservationKind::Centres;
        assert!(spec_error(f.tracker_spec()).contains("points table"));
        f.centres = "points.csv".into();
        f.centre_unit = LengthUnit::M;
        let s = f.tracker_spec().unwrap();
        assert_eq!(
            s.points,
            FixedPoints::Table {
                path: "points.csv".into(),
                unit: LengthUnit::M
            }
        );
        assert!(matches!(s.poses, FixedPoses::Joints { .. }));
        assert_eq!(s.robot.unwrap().dof(), 6, "the preset loaded");
        assert_eq!(s.name, "joints");
    }
}
